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

pytestmark = pytest.mark.slow  # each test exports the bird with its build check (over 0.5 s CPU)

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


def export_bird(tmp_path: Path, extra: str = "", thickness_mm: float = 3.0) -> dict:
    """Export the bird with ``extra`` lines in its ``[fabrication]`` table; the files' texts by kind."""
    toml = tmp_path / "bird.toml"
    toml.write_text(BIRD.replace("thickness_mm = 3.0", f"thickness_mm = {thickness_mm}") + extra)
    fab = export_scene(
        load_scene(toml),
        dxf=tmp_path / "parts.dxf",
        bom=tmp_path / "bom.csv",
        plan=tmp_path / "plan.json",
        steps=tmp_path / "steps.svg",
        assembly=tmp_path / "assembly.svg",
    )
    steps = [p.read_text() for p in sorted(tmp_path.glob("steps-*.svg"), key=lambda p: int(p.stem.split("-")[1]))]
    return {
        "fab": fab,
        "bom": list(csv.DictReader((tmp_path / "bom.csv").read_text().splitlines())),
        "plan": json.loads((tmp_path / "plan.json").read_text()),
        "assembly": re.sub(r"<[^>]+>", "\n", (tmp_path / "assembly.svg").read_text()),
        "steps": [re.sub(r"<[^>]+>", "\n", s) for s in steps],
    }


def _step_lines(out: dict) -> list[str]:
    """Every line of the step pages, an action's number taken off (``3. close pin B ...`` -> ``close pin B ...``)."""
    return [re.sub(r"^\d+\. ", "", ln.strip()) for page in out["steps"] for ln in page.splitlines() if ln.strip()]


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
    buy = {(r["id"], r["size_mm"]): r for r in out["bom"] if r["item"] == "buy"}
    for k, qty in want.items():  # items the mounting screws use too are counted with theirs
        assert int(buy[k]["qty"]) == qty if "mounting" not in buy[k]["notes"] else int(buy[k]["qty"]) > qty
    if hardware == "rod-eclip":  # a rod holds its clips only in grooves: the row says so
        assert all("groove" in r["notes"] for r in out["bom"] if r["item"] == "pin")


@pytest.mark.parametrize("thickness", [3.0, 6.0])
def test_bom_buys_the_motor_its_screws_and_the_mounting_screws_with_lengths(tmp_path, thickness):
    out = export_bird(tmp_path, 'hardware = "screw"\n', thickness_mm=thickness)
    bom = out["bom"]
    buy = [r for r in bom if r["item"] == "buy"]
    assert [int(r["qty"]) for r in buy if r["id"] == "N20 gearmotor"] == [1]
    motor_screw = next(r for r in bom if r["item"] == "motor screw")
    assert motor_screw["size_mm"].startswith("M1.6 x ") and "check your motor" in motor_screw["size_mm"]
    length = float(motor_screw["size_mm"].split(" x ")[1].split()[0])
    t = out["plan"]["thickness_mm"]
    assert t == thickness
    assert t + 1 <= length <= t + 3  # through the plate and 1-3 mm into the motor's face (holes 2-3 mm deep)
    assert any(r["size_mm"] == motor_screw["size_mm"] and int(r["qty"]) == 2 for r in buy)
    mounting = next(r for r in bom if r["item"] == "mounting screw")
    plates = [p for p in out["plan"]["parts"] if p["name"] == "ground"]
    assert int(mounting["qty"]) == 4 * len(plates)  # two into the standoffs' tops, two from a base board below
    m, length_text = mounting["size_mm"].split(" x ")
    assert m == "M3"  # 3.2 mm holes
    # plate + washer (0.5) + at least 3 mm of thread into the standoff, and no longer than a standoff's half
    standoff = next(r for r in bom if r["item"] == "standoff")
    assert t + 0.5 + 3.0 <= float(length_text) <= t + 0.5 + float(standoff["size_mm"].split(" x ")[1]) / 2
    assert any(r["size_mm"] == mounting["size_mm"] for r in buy)


def test_reference_square_is_listed_everywhere_and_counted_nowhere_as_a_part(tmp_path):
    import ezdxf

    from planar.fabrication.build import summary

    out = export_bird(tmp_path, "reference_square_mm = 20\n")
    groups = set(dict(ezdxf.readfile(tmp_path / "parts.dxf").groups))
    parts = [p["name"] for p in out["plan"]["parts"]]
    assert [e["name"] for e in out["plan"]["extras"]] == ["reference square"]
    assert any("reference" in g and "square" in g for g in groups)
    assert [r["item"] for r in out["bom"] if "reference" in r["item"]] == ["reference square"]
    assert len([r for r in out["bom"] if r["item"] == "part"]) == len(parts)
    assert summary(out["fab"]).startswith(f"{len(parts)} parts")


def test_fabrication_value_error_starts_with_the_scene_file(tmp_path, capsys):
    from planar.cli.main import main

    toml = tmp_path / "bird.toml"
    toml.write_text(BIRD.replace("pin_diameter_mm = 3.0", "pin_diameter_mm = 3.5"))
    assert main(["export", str(toml), "-o", str(tmp_path / "p.dxf")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "bird.toml: fabrication.pin_diameter_mm = 3.5: " in err[0], err
    assert not (tmp_path / "p.dxf").exists()


def test_legend_names_what_fills_an_empty_layer(tmp_path):
    out = export_bird(tmp_path)
    layers = [ln.strip() for ln in out["assembly"].splitlines() if ln.strip().startswith("layer ")]
    assert layers and all(not ln.endswith(":") for ln in layers), layers
    used = {p["layer"] for p in out["plan"]["parts"]}
    for s in out["plan"]["spacers"]:
        if s["layer"] not in used:
            assert any(ln.startswith(f"layer {s['layer']}: spacers") for ln in layers), layers
