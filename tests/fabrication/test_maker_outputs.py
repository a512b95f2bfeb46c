"""What a maker reads to buy and assemble: the BOM, plan.json and the step pages agree with the hardware chosen.

The scene is a nodding bird (a four-bar with a cut beak) a maker exported; the files are read back as text,
CSV and JSON, not through planar's objects.
"""

import csv
import json
import re
from pathlib import Path

import pytest

from planar.app.pipeline import export_scene
from planar.scene.load import load_scene

BIRD = """name = "nodding-bird"
angle_unit = "deg"

[mechanism]
type = "fourbar"
ground = 5.0
crank = 1.2
coupler = 4.5
rocker = 3.5
coupler_point = [2.5, 1.6]
circuit = "open"
placement = [0.0, 0.0, 0.0]

[[mechanism.polygons]]
name = "beak"
part = "coupler"
points = [[2.3, 1.4], [3.4, 1.7], [2.3, 1.9]]
cut = true

[driver]
speed = 0.5
cycles = 1
samples_per_cycle = 48

[fabrication]
unit_mm = 12.0
thickness_mm = 3.0
kerf_mm = 0.15
pin_diameter_mm = 3.0
clearance_mm = 0.1
sheet_mm = [300.0, 200.0]
"""


def export_bird(tmp_path: Path, extra: str = "") -> dict:
    """Export the bird with ``extra`` lines in its ``[fabrication]`` table; the files' texts by kind."""
    toml = tmp_path / "bird.toml"
    toml.write_text(BIRD + extra)
    fab = export_scene(
        load_scene(toml),
        dxf=tmp_path / "parts.dxf",
        bom=tmp_path / "bom.csv",
        plan=tmp_path / "plan.json",
        steps=tmp_path / "steps.svg",
    )
    steps = [p.read_text() for p in sorted(tmp_path.glob("steps-*.svg"), key=lambda p: int(p.stem.split("-")[1]))]
    return {
        "fab": fab,
        "bom": list(csv.DictReader((tmp_path / "bom.csv").read_text().splitlines())),
        "plan": json.loads((tmp_path / "plan.json").read_text()),
        "steps": [re.sub(r"<[^>]+>", "\n", s) for s in steps],
    }


def _step_lines(out: dict) -> list[str]:
    return [ln.strip() for page in out["steps"] for ln in page.splitlines() if ln.strip()]


@pytest.mark.parametrize(
    ("hardware", "closer", "not_closer"), [("screw", "nylon lock nut", "e-clip"), ("rod-eclip", "e-clip", "nut")]
)
def test_step_lines_name_each_pins_own_closing_hardware(tmp_path, hardware, closer, not_closer):
    out = export_bird(tmp_path, f'hardware = "{hardware}"\n')
    pins = list(out["plan"]["pins"])
    assert pins
    lines = _step_lines(out)
    for p in pins:
        bought = " ".join(h["item"] for h in p["hardware"])
        close = [ln for ln in lines if ln.startswith(f"close pin {p['name']} ")]
        assert len(close) == 1, (p["name"], lines)
        assert closer in close[0] and not_closer not in close[0], close[0]
        assert closer in bought  # the step names an item the plan says to buy for that pin


@pytest.mark.parametrize("hardware", ["screw", "rod-eclip"])
def test_motor_shaft_hardware_agrees_in_bom_plan_and_steps(tmp_path, hardware):
    out = export_bird(tmp_path, f'hardware = "{hardware}"\n')
    shaft = out["plan"]["motor_shaft"]
    assert shaft["hardware"], shaft  # what holds it is listed, and it is no clip (a D shaft has no groove)
    assert not any("clip" in h["item"] for h in shaft["hardware"])
    row = next(r for r in out["bom"] if r["item"] == "motor shaft")
    for h in shaft["hardware"]:
        assert f"{h['qty']} {h['item']} {h['size']}" in row["notes"]
    assert shaft["retention"] in row["notes"]
    assert any(shaft["retention"] in ln for ln in _step_lines(out))
    # ends flush with its top layer: the length above the motor is the layers it passes, nothing stands above
    _lo, hi = shaft["layers"]
    assert shaft["length_mm"] == pytest.approx(hi * out["plan"]["thickness_mm"])
    assert shaft["ends"]["upper"]["height_mm"] == 0
    # the buy totals are the sum of every pin's and the shaft's hardware, item by item
    want: dict = {}
    for p in [*out["plan"]["pins"], shaft]:
        for h in p["hardware"]:
            want[(h["item"], h["size"])] = want.get((h["item"], h["size"]), 0) + h["qty"]
    got = {(r["id"], r["size_mm"]): int(r["qty"]) for r in out["bom"] if r["item"] == "buy"}
    assert {k: v for k, v in got.items() if k in want} == want
    if hardware == "rod-eclip":  # a rod holds its clips only in grooves: the row says so
        assert all("groove" in r["notes"] for r in out["bom"] if r["item"] == "pin")
