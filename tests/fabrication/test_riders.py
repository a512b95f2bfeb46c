"""Polygons cut as parts of their own (``cut = "part"``): pin sites, the export, the check, refusals; shaft letters."""

from __future__ import annotations

import csv
import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import shapely
from shapely.geometry import Point, box

from planar.fabrication.riders import ROOM_MARGIN, pin_sites

GALLERY = Path(__file__).resolve().parents[2] / "gallery"


@pytest.mark.parametrize("seed", range(6))
def test_pin_sites_keep_the_wall_in_both_pieces_and_stand_far_apart(seed):
    """Random rectangles overlapping a random host with a hole: both sites keep a hole and its wall inside both
    pieces and clear of the host's hole, and no two points of the shared room lie further apart."""
    rng = np.random.default_rng(seed)
    w, h = rng.uniform(15, 40), rng.uniform(8, 20)
    host = box(0, 0, w, h).difference(Point(rng.uniform(3, w - 3), h / 2).buffer(1.55, quad_segs=32))
    x0, y0 = rng.uniform(-5, w / 2), rng.uniform(-h / 2, h / 2)
    rider = box(x0, y0, x0 + rng.uniform(10, 30), y0 + rng.uniform(9, 20))
    r, wall = 1.55, 1.5
    got = pin_sites(rider, host, r, wall)
    room = rider.buffer(-(r + wall)).intersection(host.buffer(-(r + wall)))
    if got is None:
        pts = shapely.get_coordinates(shapely.segmentize(room.boundary, 0.1)) if not room.is_empty else np.zeros((0, 2))
        far = max((math.dist(p, q) for p in pts for q in pts), default=0.0) if len(pts) < 400 else None
        assert far is None or far < 2 * r + wall + 0.2
        return
    a, b = got
    for c in (a, b):
        hole = Point(c).buffer(r + wall - 1e-3, quad_segs=64)
        assert rider.contains(hole) and host.contains(hole), c
    assert math.dist(a, b) >= 2 * r + wall
    pts = shapely.get_coordinates(shapely.segmentize(room.buffer(-ROOM_MARGIN).boundary, 1.0))
    best = max(math.dist(p, q) for p in pts for q in pts)
    assert math.dist(a, b) >= best - 0.5


def test_pin_sites_none_for_a_rider_too_thin_for_a_pin():
    host = box(0, 0, 40, 10)
    assert pin_sites(box(5, 2, 35, 7), host, 1.55, 1.5) is None  # 5 mm: less than a 3.1 mm hole and two walls


def test_pin_sites_stay_apart_from_the_hosts_pins_by_an_end_width():
    host, rider = box(0, 0, 40, 20), box(0, 0, 40, 20)
    others = np.array([[20.0, 10.0]])
    a, b = pin_sites(rider, host, 1.55, 1.5, others=others, apart=7.15)
    for c in (a, b):
        assert math.dist(c, (20.0, 10.0)) >= 7.15 - 1e-6
    assert math.dist(a, b) >= 7.15


def _export(scene: Path, out: Path, *extra: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [
            sys.executable,
            "-m",
            "planar",
            "export",
            str(scene),
            "-o",
            str(out / "parts.dxf"),
            "--plan",
            str(out / "plan.json"),
            "--bom",
            str(out / "bom.csv"),
            "--motion",
            str(out / "motion.csv"),
            "--steps",
            str(out / "steps.svg"),
            *extra,
        ],
        capture_output=True,
        text=True,
    )


@pytest.mark.slow
def test_the_bird_body_is_cut_as_its_own_part_pinned_to_the_frame(tmp_path):
    """cam-automaton's bird body (``cut = "part"``): its own part on its own layer, two pins to the frame with
    holes in both pieces (read back from the DXF with ezdxf), in the BOM, plan.json and the steps; it moves with
    the frame in the motion table; the export's check and the files alone find nothing."""
    import ezdxf

    res = _export(GALLERY / "cam-automaton.toml", tmp_path)
    assert res.returncode == 0, res.stdout + res.stderr
    plan = json.loads((tmp_path / "plan.json").read_text())
    parts = {p["name"]: p for p in plan["parts"]}
    assert "bird-body" in parts and parts["bird-body"]["layer"] != parts["ground"]["layer"]
    fixing = [p for p in plan["pins"] if set(p["parts"]) == {"ground", "bird-body"}]
    assert len(fixing) == 2 and {j for p in fixing for j in p["joints"]} == {"bird-body#1", "bird-body#2"}
    k2 = plan["kerf_mm"] / 2
    doc = ezdxf.readfile(tmp_path / "parts.dxf")
    for name in ("ground", "bird-body"):
        x, y, a = parts[name]["placement"]
        c, s = math.cos(math.radians(a)), math.sin(math.radians(a))
        circles = [e for e in doc.groups.get(name.replace(" ", "_")) if e.dxftype() == "CIRCLE"]
        for pin in fixing:
            px, py = pin["anchor"]["at_mm"]  # the anchor is on the frame's own frame: the body's is the same
            want = (x + c * px - s * py, y + s * px + c * py)
            hole = min(circles, key=lambda e: math.dist((e.dxf.center.x, e.dxf.center.y), want))
            assert math.dist((hole.dxf.center.x, hole.dxf.center.y), want) < 1e-3
            assert 2 * (hole.dxf.radius + k2) == pytest.approx(plan["pin_diameter_mm"] + plan["clearance_mm"], abs=1e-6)
    with open(tmp_path / "bom.csv") as fh:
        rows = list(csv.DictReader(fh))
    assert any(r["item"] == "part" and r["id"] == "bird-body" for r in rows)
    assert sum(r["item"] == "pin" and r["joins"] == "ground + bird-body" for r in rows) == 2
    steps = " ".join(p.read_text() for p in sorted(tmp_path.glob("steps-*.svg")))
    assert "bird-body" in steps
    with open(tmp_path / "motion.csv") as fh:
        table = list(csv.reader(fh))
    col = {n: i for i, n in enumerate(table[0])}
    rows_ = np.array(table[1:], float)
    for axis in ("x", "y", "angle"):
        assert np.array_equal(rows_[:, col[f"bird-body.{axis}"]], rows_[:, col[f"ground.{axis}"]])
    assert plan["violations"] == []
    from test_build_independent import independent_check

    dxfs = [tmp_path / "parts.dxf"]
    cols = {n: rows_[:, i] for n, i in col.items()}
    assert independent_check(plan, dxfs, cols) == []


@pytest.mark.slow
def test_the_check_moves_a_rider_with_its_host_and_finds_it_on_a_crowded_layer():
    """Put the bird body on the cam's layer: the check reports the pair (it sweeps the body at the frame's pose)."""
    from types import SimpleNamespace

    from planar.fabrication.build import build
    from planar.fabrication.check import build_check
    from planar.fabrication.parts import FabSettings
    from planar.scene.load import load_scene

    scene = load_scene(GALLERY / "cam-automaton.toml")
    fab = build(scene, FabSettings.from_spec(scene.spec.fabrication))
    assert fab.violations == []
    layers = dict(fab.assembly.layers)
    crowded = next(n for n in ("cam", "follower", "head") if layers[n] != layers["bird-body"])
    layers["bird-body"] = layers[crowded]
    asm = SimpleNamespace(**{**vars(fab.assembly), "layers": layers})
    got = build_check(SimpleNamespace(mechanism=fab.mechanism, assembly=asm, own=fab.own, settings=fab.settings), 60)
    assert any({v.a, v.b} >= {"bird-body"} and v.what in ("parts overlap", "pin through part") for v in got)


def _scene(tmp_path: Path, points: str, name: str = "bird-body", part: str = "ground") -> Path:
    text = (GALLERY / "cam-automaton.toml").read_text()
    start = text.index('name = "bird-body"')
    end = text.index("[driver]")
    poly = f'name = "{name}"\npart = "{part}"\npoints = {points}\ncut = "part"\n\n'
    p = tmp_path / "s.toml"
    p.write_text((text[:start] + poly + text[end:]).replace('sweep = ["bird-head", "bird-body"]', 'sweep = ["bird-head"]'))
    return p


@pytest.mark.slow
@pytest.mark.parametrize(
    ("points", "name", "part", "says"),
    [
        ("[[4.9, 4.1], [7.7, 4.1], [7.7, 4.4], [4.9, 4.4]]", "bird-body", "ground", "no room for two 3.1 mm pin holes"),
        ("[[4.9, 4.1], [7.7, 4.7], [7.1, 3.4]]", "head", "ground", "a name no part has"),
        ("[[4.9, 4.1], [7.7, 4.7], [7.1, 3.4]]", "bird-body", "wing", "no part 'wing'"),
    ],
)
def test_a_rider_that_cannot_be_pinned_is_refused_in_one_line(tmp_path, points, name, part, says):
    out = tmp_path / "out"
    out.mkdir()
    res = _export(_scene(tmp_path, points, name, part), out)
    assert res.returncode == 2, res.stdout
    assert len(res.stderr.strip().splitlines()) == 1 and says in res.stderr and "Traceback" not in res.stderr
    assert not any(out.iterdir())


def test_the_motor_shaft_holes_carry_the_shafts_letter():
    """The driven part's D hole and the plate's shaft hole are lettered with the motor shaft's letter (the
    BOM's motor shaft row): the letter of the pin stack the shaft is in."""
    from planar.fabrication.build import _hole_letters, _shaft_pin
    from planar.fabrication.joints import joint_pins
    from planar.fabrication.layers import letter, pin_stacks
    from planar.scene.load import load_scene

    mech = load_scene(GALLERY / "slider-crank.toml").mechanism
    pins, _ = joint_pins(mech)
    shaft = _shaft_pin(mech, pins)
    assert shaft is not None
    k = next(i for i, st in enumerate(pin_stacks(pins)) if any(pins[j] is shaft for j in st))
    got = _hole_letters(mech, pins, shaft)
    for side in (0, 1):
        assert (shaft.at[side], letter(k)) in got[shaft.parts[side]]
