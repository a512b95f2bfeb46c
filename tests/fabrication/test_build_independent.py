"""The build check redone from the exported files alone: the DXF (ezdxf), plan.json and the motion CSV.

Nothing of planar's geometry is used: each part's material is read back from its DXF group (outline and
inner cuts, the kerf taken off with shapely), carried to its own frame by the plan's placement, moved by the
motion table's poses and stacked by the plan's layers; pins, their ends, spacers and the motor shaft are discs
from the plan.  The verdict must agree with planar's own check (the plan's ``violations``).
"""

from __future__ import annotations

import csv
import itertools
import json
import math
import subprocess
import sys
from pathlib import Path

import jsonschema
import numpy as np
import pytest
import shapely
from fabcheck import _dxf_points
from shapely.geometry import Polygon

GALLERY = Path(__file__).resolve().parents[2] / "gallery"
SCHEMA = Path(__file__).resolve().parents[2] / "docs" / "reference" / "plan.schema.json"
#: overlap (mm^2) above which two bodies collide; arcs flattened to 0.01 mm stay far below it
AREA = 0.1
#: scenes planar cannot yet plan without a collision: the independent check must find collisions there too
#: (none since the Horse's second cam tree is turned half a turn, its track across the shaft from the first's)
BLOCKED: set[str] = set()


def _export(scene: Path, out: Path) -> tuple[dict, list[Path], dict[str, np.ndarray]]:
    res = subprocess.run(
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
            "--motion",
            str(out / "motion.csv"),
        ],
        capture_output=True,
        text=True,
    )
    assert res.returncode in (0, 3), res.stderr
    plan = json.loads((out / "plan.json").read_text())
    jsonschema.validate(plan, json.loads(SCHEMA.read_text()))
    assert (res.returncode == 3) == bool(plan["violations"])
    dxfs = [out / "parts.dxf"] if plan["sheets"] == 1 else [out / f"parts-{k + 1}.dxf" for k in range(plan["sheets"])]
    with open(out / "motion.csv") as fh:
        rows = list(csv.reader(fh))
    table = np.array(rows[1:], float)
    cols = {name: table[:, k] for k, name in enumerate(rows[0])}
    return plan, dxfs, cols


def _materials(plan: dict, dxfs: list[Path]) -> dict[str, Polygon]:
    """Each part's material in its own frame (mm): the DXF group's outline minus its inner cuts, kerf removed."""
    import ezdxf

    k2 = plan["kerf_mm"] / 2
    out = {}
    for part in plan["parts"]:
        if part["layer"] is None or part["plane"] != "xy":
            continue
        doc = ezdxf.readfile(dxfs[part["sheet"] - 1])
        group = doc.groups.get(part["name"].replace(" ", "_"))
        outer = [Polygon(_dxf_points(e)) for e in group if e.dxf.layer == "CUT_OUTER"]
        inner = [Polygon(_dxf_points(e)) for e in group if e.dxf.layer == "CUT_INNER"]
        mat = shapely.union_all(outer).buffer(-k2)
        if inner:
            mat = mat.difference(shapely.union_all(inner).buffer(k2))
        x, y, a = part["placement"]
        c, s = math.cos(math.radians(a)), math.sin(math.radians(a))
        # sheet -> own frame: p = R(-a) (q - (x, y))
        mat = shapely.affinity.affine_transform(mat, [c, s, -s, c, -(c * x + s * y), s * x - c * y])
        out[part["name"]] = mat.simplify(0.01)
    return out


def _poses(cols: dict[str, np.ndarray], name: str, u: float) -> np.ndarray:
    ok = cols["valid"] > 0.5
    return np.c_[cols[f"{name}.x"][ok] * u, cols[f"{name}.y"][ok] * u, cols[f"{name}.angle"][ok]]


def _placed(poly: Polygon, poses: np.ndarray) -> np.ndarray:
    """``poly`` at each pose (mm, rad): one shapely call per sample, transformed by shapely.transform."""

    def at(p):
        c, s = math.cos(p[2]), math.sin(p[2])
        return shapely.transform(poly, lambda xy: xy @ np.array([[c, s], [-s, c]]) + p[:2])

    return np.array([at(p) for p in poses], dtype=object)


def _track(pin: dict, cols: dict[str, np.ndarray], u: float) -> np.ndarray:
    poses = _poses(cols, pin["anchor"]["part"], u)
    x, y = pin["anchor"]["at_mm"]
    c, s = np.cos(poses[:, 2]), np.sin(poses[:, 2])
    return np.c_[poses[:, 0] + c * x - s * y, poses[:, 1] + s * x + c * y]


def _hits(discs: np.ndarray, shapes: np.ndarray) -> bool:
    return bool((shapely.area(shapely.intersection(discs, shapes)) > AREA).any())


def independent_check(plan: dict, dxfs: list[Path], cols: dict[str, np.ndarray]) -> list[str]:
    """Collisions found from the files alone, one line each."""
    u, t = plan["unit_mm"], plan["thickness_mm"]
    mats = _materials(plan, dxfs)
    layer = {p["name"]: p["layer"] for p in plan["parts"] if p["name"] in mats}
    placed = {n: _placed(m, _poses(cols, n, u)) for n, m in mats.items()}
    joined = {frozenset(c["parts"]) for c in plan["contacts"]}
    found = []
    for a, b in itertools.combinations(mats, 2):
        if layer[a] == layer[b] and frozenset((a, b)) not in joined and _hits(placed[a], placed[b]):
            found.append(f"parts {a} and {b} overlap on layer {layer[a]}")
    pins = [p for p in plan["pins"] if p["plane"] == "xy"] + ([plan["motor_shaft"]] if plan["motor_shaft"] else [])
    tracks = {p["name"]: _track(p, cols, u) for p in pins}
    for pin in pins:
        lo, hi = pin["layers"]
        shaft = pin is plan["motor_shaft"]
        xy = shapely.points(tracks[pin["name"]])
        r = (pin["flat_mm"] - pin["diameter_mm"] / 2) * 0.99 if shaft else pin["diameter_mm"] / 2
        disc = shapely.buffer(xy, r)
        for n in mats:
            if (1 if shaft else lo) <= layer[n] <= hi and not (shaft and n in pin["parts"]) and _hits(disc, placed[n]):
                found.append(f"pin {pin['name']} through {n} on layer {layer[n]}")
        for side in ("lower", "upper"):
            for z0, z1, dia in _tiers(pin, side, t):
                ring = shapely.buffer(xy, dia / 2)
                for n in mats:
                    if min(z1, layer[n] * t) - max(z0, (layer[n] - 1) * t) > 1e-9 and _hits(ring, placed[n]):
                        found.append(f"pin {pin['name']} {side} end strikes {n} on layer {layer[n]}")
    for sp in plan["spacers"]:
        if sp["pin"] not in tracks:
            continue
        ring = shapely.buffer(shapely.points(tracks[sp["pin"]]), sp["outer_mm"] / 2)
        for n in mats:
            if layer[n] == sp["layer"] and _hits(ring, placed[n]):
                found.append(f"{sp['name']} strikes {n} on layer {layer[n]}")
    cyl = _cylinders(plan, pins)
    for (pn, z0, z1, r), (qn, w0, w1, rq) in itertools.combinations(cyl, 2):
        if pn == qn or min(z1, w1) - max(z0, w0) <= 1e-9:
            continue
        gap = np.hypot(*(tracks[pn] - tracks[qn]).T).min()
        if gap < r + rq + plan["clearance_mm"] - 1e-6:
            found.append(f"pins {pn} and {qn} come {gap:.3f} mm apart between z {max(z0, w0):g} and {min(z1, w1):g}")
    return found


def _cylinders(plan: dict, pins: list[dict]) -> list[tuple[str, float, float, float]]:
    """Each pin's round bodies ``(pin, z0, z1, radius)`` mm: its shaft through its layers (the motor shaft from
    below the bottom), its ends beyond them, its spacer rings."""
    t = plan["thickness_mm"]
    out = []
    for pin in pins:
        lo, hi = pin["layers"]
        shaft = pin is plan["motor_shaft"]
        out.append((pin["name"], -1e3 if shaft else (lo - 1) * t, hi * t, pin["diameter_mm"] / 2))
        for side in ("lower", "upper"):
            out += [(pin["name"], z0, z1, dia / 2) for z0, z1, dia in _tiers(pin, side, t)]
    for sp in plan["spacers"]:
        out.append((sp["pin"], (sp["layer"] - 1) * t, sp["layer"] * t, sp["outer_mm"] / 2))
    return [c for c in out if any(c[0] == p["name"] for p in pins)]


def _tiers(pin: dict, side: str, t: float) -> list[tuple[float, float, float]]:
    """A pin end's round bodies ``(z0, z1, diameter)`` mm (z from the bottom layer's lower face), from plan.json."""
    lo, hi = pin["layers"]
    face, sign = ((lo - 1) * t, -1.0) if side == "lower" else (hi * t, 1.0)
    out, z = [], 0.0
    for tier in pin["ends"][side]["tiers"]:
        if tier["height_mm"] > z + 1e-9:
            a, b = sorted((face + sign * z, face + sign * tier["height_mm"]))
            out.append((a, b, tier["diameter_mm"]))
            z = tier["height_mm"]
    return out


#: M3 fastener sizes by hand from the standards (mm): DIN 125-A washer (outer, thickness), DIN 6799 e-clip
#: (outer, thickness), ISO 7380 button head (diameter, height), DIN 985 nut (across corners, height), ISO 261 pitch
M3 = {"washer": (7.0, 0.5), "eclip": (6.0, 0.6), "head": (5.7, 1.65), "nut": (6.01, 4.0), "pitch": 0.5}


def _bought(pin: dict, word: str) -> dict:
    return next(h for h in pin["hardware"] if word in h["item"])


def expected_ends(pin: dict, plan: dict) -> dict[str, list[tuple[float, float]]]:
    """Each end's tiers ``(height, diameter)`` mm worked out by hand from what plan.json says is bought (the rod's
    or screw's length, the washers) and the M3 tables above: nothing of planar's hardware module."""
    t = plan["thickness_mm"]
    lo, hi = pin["layers"]
    stack = (hi - lo + 1) * t
    wd, wt = M3["washer"]
    if plan["hardware"] == "rod-eclip":
        length = float(_bought(pin, "steel rod")["size"].split(" x ")[1].split()[0])
        cd, ct = M3["eclip"]
        end = [(wt + ct, max(wd, cd)), ((length - stack) / 2, pin["diameter_mm"])]
        return {"lower": end, "upper": end}
    length = float(_bought(pin, "screw")["size"].split(" x ")[1])
    washers = _bought(pin, "washer")["qty"]
    hd, hh = M3["head"]
    ne, nh = M3["nut"]
    nut_top = (washers - 1) * wt + nh  # one washer under the head, the rest under the nut
    tip = length - wt - stack
    # the thread passes the whole nut by at least the chamfered pitch, and by less than a pitch and a washer
    assert M3["pitch"] - 1e-9 <= tip - nut_top < M3["pitch"] + wt, (pin["name"], length, stack)
    return {"lower": [(wt + hh, max(wd, hd))], "upper": [(nut_top, max(wd, ne)), (tip, pin["diameter_mm"])]}


def check_ends(plan: dict) -> None:
    """plan.json's pin ends are the hand sums of what it says is bought (M3 only)."""
    for pin in plan["pins"]:
        if plan["pin_diameter_mm"] != 3.0:
            continue
        want = expected_ends(pin, plan)
        for side in ("lower", "upper"):
            got = [(tr["height_mm"], tr["diameter_mm"]) for tr in pin["ends"][side]["tiers"]]
            assert got == [pytest.approx(w, abs=1e-6) for w in want[side]], (pin["name"], side)
            assert pin["ends"][side]["height_mm"] == pytest.approx(max(h for h, _ in want[side]), abs=1e-6)


SCENES = sorted(GALLERY.glob("*.toml"))


@pytest.mark.slow
@pytest.mark.parametrize("scene", SCENES, ids=[p.stem for p in SCENES])
def test_the_files_alone_agree_with_the_build_check(scene, tmp_path):
    plan, dxfs, cols = _export(scene, tmp_path)
    check_ends(plan)
    found = independent_check(plan, dxfs, cols)
    if scene.stem in BLOCKED:
        assert plan["violations"] and found, "planar and the files should both find the known collisions"
    else:
        assert plan["violations"] == []
        assert found == []


@pytest.mark.slow
def test_the_independent_check_can_fail(tmp_path):
    """Move one part of a clean plan onto its neighbour's layer: the files-only check finds the overlap."""
    plan, dxfs, cols = _export(GALLERY / "double-rocker.toml", tmp_path)
    assert independent_check(plan, dxfs, cols) == []
    parts = [p for p in plan["parts"] if p["layer"] is not None]
    for p in parts:
        p["layer"] = 1
    assert any("overlap" in f for f in independent_check(plan, dxfs, cols))


def _with_screws(name: str, where: Path) -> Path:
    """A copy of a gallery scene cut with ``hardware = "screw"`` (on a motor with a 20 mm shaft: screw ends
    open more layers than the gallery's rods, and this test is about the screws)."""
    text = (GALLERY / f"{name}.toml").read_text()
    text = "\n".join(ln for ln in text.splitlines() if not ln.startswith("motor_shaft_mm")) + "\n"
    line = 'hardware = "screw"\nmotor_shaft_mm = 20.0\n'
    if "[fabrication]\n" in text:
        text = text.replace("[fabrication]\n", "[fabrication]\n" + line)
    else:
        text += "\n[fabrication]\n" + line
    scene = where / f"{name}.toml"
    scene.write_text(text)
    return scene


@pytest.mark.slow
@pytest.mark.parametrize("name", ["slider-crank", "cam-automaton", "stephenson-six-bar"])
def test_screws_stand_their_true_height_and_the_files_alone_agree(name, tmp_path):
    """Scenes cut with screws (their nut ends 6 mm and more above the stack): plan.json's ends are the hand sums
    of the screws, washers and nuts it lists, and the files alone find no fastener striking a neighbour."""
    scene = _with_screws(name, tmp_path)
    plan, dxfs, cols = _export(scene, tmp_path)
    assert plan["hardware"] == "screw"
    check_ends(plan)
    assert max(p["ends"]["upper"]["height_mm"] for p in plan["pins"]) >= 5.5
    assert plan["violations"] == []
    assert independent_check(plan, dxfs, cols) == []


@pytest.mark.slow
def test_the_files_alone_find_a_nut_end_striking_the_layer_above(tmp_path):
    """Take the gap the planner opened over a screw's nut end away (every part above moves down a layer): the
    files-only check sees the nut end (6 mm tall, 7 mm across) strike the part now lying on it."""
    scene = _with_screws("slider-crank", tmp_path)
    plan, dxfs, cols = _export(scene, tmp_path)
    assert independent_check(plan, dxfs, cols) == []
    used = {p["layer"] for p in plan["parts"] if p["layer"] is not None}
    empty = [k for k in range(1, plan["layers"] + 1) if k not in used]
    assert empty, "the planner opened no gap for the screws' nut ends"
    gap = empty[0]
    for p in plan["parts"]:
        if p["layer"] is not None and p["layer"] > gap:
            p["layer"] -= 1
    for pin in plan["pins"] + ([plan["motor_shaft"]] if plan["motor_shaft"] else []):
        lo, hi = pin["layers"]
        pin["layers"] = [lo - (lo > gap), hi - (hi > gap)]
    plan["spacers"] = [{**sp, "layer": sp["layer"] - (sp["layer"] > gap)} for sp in plan["spacers"] if sp["layer"] != gap]
    assert any("end strikes" in f for f in independent_check(plan, dxfs, cols))
