"""Walkers of N legs (``type = "legs"``) built and checked on legs nobody tuned: random Jansen-like and four-bar
legs, N = 2..8, random phases.  Either the export's build check finds nothing (exit 0) or it exits 3 naming each
collision (the pair and the layer) and, where it is one no layer order can clear, the constraint that blocks
it.  The plan's stack is read back from ``plan.json``: each leg in its own slab between two frame plates."""

from __future__ import annotations

import json
import math
import re
import subprocess
import sys
import zlib
from pathlib import Path

import numpy as np
import pytest
from walkers import fourbar_leg, jansen_leg, scene_tables

from planar.linkages import Linkage
from planar.scene.load import parse_scene
from planar.scene.write import write_scene

GALLERY = Path(__file__).resolve().parents[2] / "gallery"

#: (leg, N, mirror, random phases); the five-legged Jansen-like walker is one the planner cannot clear: its fixed
#: pivot's rod grazes the leg's lower link in every layer order tried, and the export says so
CASES = [
    ("jansen", 2, False, True),
    ("fourbar", 3, False, True),
    ("jansen", 5, False, False),
    ("jansen", 6, True, True),
    ("fourbar", 8, True, False),
]


def _random_scene(kind: str, count: int, mirror: bool, phases: bool, path: Path) -> None:
    rng = np.random.default_rng(zlib.crc32(f"{kind}{count}{mirror}{phases}".encode()))
    for _ in range(50):
        nodes, links = jansen_leg(rng) if kind == "jansen" else fourbar_leg(rng)
        try:
            if Linkage("leg", nodes, links).run(samples_per_cycle=90).valid.all():
                break
        except Exception:
            continue
    nt, lt = scene_tables(nodes, links)
    mech = {"type": "legs", "nodes": nt, "links": lt, "count": count, "mirror": mirror, "points": {"foot": "F"}}
    if phases:
        mech["phases"] = [float(v) for v in rng.uniform(-math.pi, math.pi, count)]
    write_scene(parse_scene({"name": f"{kind}-{count}", "mechanism": mech, "fabrication": {"unit_mm": 1.5}}), path)


def _export(scene: Path, out: Path) -> tuple[subprocess.CompletedProcess, dict]:
    res = subprocess.run(
        [sys.executable, "-m", "planar", "export", str(scene), "-o", str(out / "p.dxf"), "--plan", str(out / "plan.json")],
        capture_output=True,
        text=True,
    )
    assert res.returncode in (0, 3), res.stderr
    return res, json.loads((out / "plan.json").read_text())


def _slabs_apart(plan: dict, count: int) -> None:
    """Every leg's parts lie between two consecutive frame plates, and no pin of a leg reaches another slab."""
    layer = {p["name"]: p["layer"] for p in plan["parts"]}
    plates = sorted(layer[f"frame_{k}"] for k in range(count + 1))
    slab_of = {}
    for name, lay in layer.items():
        m = re.fullmatch(r".*_(\d+)[ab]?", name)
        if m and not name.startswith("frame_"):
            i = int(m.group(1))
            assert plates[i - 1] < lay < plates[i], (name, lay, plates)
            slab_of[name] = i
    for pin in plan["pins"]:
        legs = {slab_of[p] for p in pin["parts"] if p in slab_of}
        webs = {p for p in pin["parts"] if re.fullmatch(r"crank_\d+[ab]", p)}
        if not webs:  # a shaft between slabs joins the webs on either side of one plate; every other pin one leg
            assert len(legs) <= 1, pin


@pytest.mark.slow
@pytest.mark.parametrize("kind,count,mirror,phases", CASES)
def test_random_walkers_build_or_say_what_blocks_them(kind, count, mirror, phases, tmp_path):
    scene = tmp_path / "walker.toml"
    _random_scene(kind, count, mirror, phases, scene)
    res, plan = _export(scene, tmp_path)
    _slabs_apart(plan, count)
    frames = {f"frame_{k}" for k in range(count + 1)}
    assert sum(set(p["parts"]) == frames for p in plan["pins"]) == 2  # the standoffs chosen: rods through every plate
    if res.returncode == 0:
        assert plan["violations"] == [] and "build check: every part" in res.stdout + res.stderr
    else:  # every collision named (its kind, the pair, the layer, the first sample) and the blocking constraint
        out = res.stdout + res.stderr
        lines = [ln for ln in out.splitlines() if ln.startswith("build check: ")]
        assert plan["violations"] and lines
        assert all(re.match(r"build check: [a-z ]+: .+ and .+ on layer \d+, first at sample \d+", ln) for ln in lines), lines
        assert "note: no plan: " in out


@pytest.mark.slow
def test_the_gallery_walker_stacks_its_legs_in_slabs(tmp_path):
    res, plan = _export(GALLERY / "jansen-walker-4.toml", tmp_path)
    assert res.returncode == 0 and plan["violations"] == []
    _slabs_apart(plan, 4)
    assert plan["motor_shaft"]["parts"] == ["frame_0", "crank_1b"], plan["motor_shaft"]
    standoffs = [p for p in plan["pins"] if set(p["parts"]) == {f"frame_{k}" for k in range(5)}]
    assert len(standoffs) == 2
    # the short shafts between slabs: a web, the plate's bearing, the next slab's web, and nothing else
    layer = {p["name"]: p["layer"] for p in plan["parts"]}
    for k in range(1, 4):
        (shaft,) = [p for p in plan["pins"] if f"frame_{k}" in p["parts"] and sum(q[:6] == "crank_" for q in p["parts"]) == 2]
        webs = sorted(layer[w] for w in shaft["parts"] if w.startswith("crank_"))
        assert webs[0] < layer[f"frame_{k}"] < webs[1], shaft


@pytest.mark.slow
def test_a_walker_stands_on_its_motor_plate_and_its_steps_glue_the_crank_webs(tmp_path):
    """A random three-legged four-bar walker, read from its files alone: only the plate holding the motor stands on
    standoffs (one pair in the BOM, one plate in plan.json's mounting); every other frame plate is laid on its layer
    over the rods in a step; and each crank web the export's notes say to glue is glued in the step that lays it."""
    scene = tmp_path / "walker.toml"
    _random_scene("fourbar", 3, False, True, scene)
    out = tmp_path / "out"
    out.mkdir()
    run = subprocess.run(
        [sys.executable, "-m", "planar", "export", str(scene), "-o", str(out / "p.dxf"), "--plan", str(out / "plan.json"),
         "--bom", str(out / "bom.csv"), "--steps", str(out / "steps.svg")],
        capture_output=True, text=True, timeout=600,
    )  # fmt: skip
    assert run.returncode in (0, 3), run.stderr
    plan = json.loads((out / "plan.json").read_text())
    shaft = plan["motor_shaft"]["parts"]
    frames = sorted(p["name"] for p in plan["parts"] if re.fullmatch(r"frame_\d+", p["name"]))
    assert len(frames) == 4
    mounted = [p["part"] for p in plan["mounting"]["plates"]]
    assert mounted == [f for f in frames if f in shaft] and len(mounted) == 1, (mounted, shaft)
    bom = (out / "bom.csv").read_text()
    standoffs = [ln for ln in bom.splitlines() if ln.startswith("standoff,")]
    assert len(standoffs) == 1 and standoffs[0].split(",")[2] == "2", standoffs
    steps = {int(p.stem.split("-")[1]): p.read_text() for p in out.glob("steps-*.svg")}
    text = "\n".join(steps[k] for k in sorted(steps))
    for f in frames:
        if f not in mounted:
            assert re.search(rf"lay {f} on layer \d+", text), f
            assert f"under {f}" not in text  # no standoffs under a plate in the middle of the stack
    glue = re.findall(r"pin (\w): glue (\w+) and (\w+) on it", run.stdout)
    assert glue, run.stdout
    for letter, a, b in glue:
        for web in (a, b):
            assert re.search(rf"lay {web} on layer \d+[^<]*glue it on [^<]*pin {letter}\b", text), (web, letter)
