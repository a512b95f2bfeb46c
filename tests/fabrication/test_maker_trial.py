"""What a maker's trial of the virtual build found (a Watt-II six-bar waving arm), each fixed and held here.

The exported files are read back as text, CSV, JSON and (the DXF) with ezdxf, not through planar's objects:
the steps name the motor screws and the standoffs, the standoffs clear what hangs below the plate, each step is
an ordered list of actions, the motor shaft's length is checked against the motor's, the links' width can be set,
the BOM lists the sheet, and the motor screw holes are cut at the size the BOM says.
"""

import csv
import json
import math
import re
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

WAVER = """name = "waver"

[mechanism]
type = "linkage"
points = { hand = "H" }

[[mechanism.nodes]]
name = "O"
kind = "fixed"
at = [0.0, 0.0]

[[mechanism.nodes]]
name = "Q"
kind = "fixed"
at = [4.0, 0.0]

[[mechanism.nodes]]
name = "R"
kind = "fixed"
at = [5.5, 5.0]

[[mechanism.nodes]]
name = "A"
kind = "crank"
centre = "O"
radius = 1.0

[[mechanism.nodes]]
name = "B"
kind = "rrr"
a = "A"
ra = 3.5
b = "Q"
rb = 3.0
branch = 1

[[mechanism.nodes]]
name = "C"
kind = "rigid"
a = "Q"
b = "B"
local = [4.0, 0.0]

[[mechanism.nodes]]
name = "D"
kind = "rrr"
a = "C"
ra = 3.5
b = "R"
rb = 2.0
branch = -1

[[mechanism.nodes]]
name = "H"
kind = "rigid"
a = "R"
b = "D"
local = [-3.0, 0.0]

[[mechanism.links]]
name = "crank"
nodes = ["O", "A"]

[[mechanism.links]]
name = "coupler"
nodes = ["A", "B"]

[[mechanism.links]]
name = "rocker"
nodes = ["Q", "B", "C"]

[[mechanism.links]]
name = "link2"
nodes = ["C", "D"]

[[mechanism.links]]
name = "arm"
nodes = ["R", "D", "H"]

[driver]
speed = 0.5
samples_per_cycle = 36

[fabrication]
unit_mm = 12.0
"""


def _scene(tmp_path: Path, extra: str = "") -> Path:
    p = tmp_path / "waver.toml"
    p.write_text(WAVER + extra)
    return p


def _export(tmp_path: Path, extra: str = "", capsys=None) -> dict:
    """``planar export`` of the waver with ``extra`` lines in ``[fabrication]``: exit status, stdout and the files."""
    from planar.cli.main import main

    out = tmp_path / "out"
    out.mkdir()
    rc = main(
        [
            "export",
            str(_scene(tmp_path, extra)),
            "-o",
            str(out / "parts.dxf"),
            "--bom",
            str(out / "bom.csv"),
            "--plan",
            str(out / "plan.json"),
            "--steps",
            str(out / "steps.svg"),
            "--assembly",
            str(out / "assembly.svg"),
        ]
    )
    pages = sorted(out.glob("steps-*.svg"), key=lambda p: int(p.stem.split("-")[1]))
    return {
        "rc": rc,
        "stdout": capsys.readouterr().out if capsys is not None else "",
        "dir": out,
        "bom": list(csv.DictReader((out / "bom.csv").read_text().splitlines())),
        "plan": json.loads((out / "plan.json").read_text()),
        "steps": [_texts(p) for p in pages],
        "assembly": _texts(out / "assembly.svg"),
    }


def _texts(path: Path) -> list[str]:
    """The text lines of an SVG page (its ``<text>`` elements, read with the standard library's XML parser)."""
    import xml.etree.ElementTree as ET

    return [(e.text or "").strip() for e in ET.parse(path).iter("{http://www.w3.org/2000/svg}text") if (e.text or "").strip()]


def _actions(page: list[str]) -> list[str]:
    """A step page's numbered actions, numbers checked (1, 2, 3, ...) and taken off."""
    acts = [ln for ln in page if re.match(r"^\d+\. ", ln)]
    assert [int(a.split(".")[0]) for a in acts] == list(range(1, len(acts) + 1)), page
    return [a.split(". ", 1)[1] for a in acts]


# --- fast: the hardware rules themselves ------------------------------------------------------------------------


def _settings(**kw):
    from planar.fabrication.parts import FabSettings

    return FabSettings(**kw)


def _pin(letter, layers, shaft=False, d=3.0):
    return SimpleNamespace(letter=letter, layers=layers, shaft=shaft, diameter_mm=d)


@pytest.mark.parametrize("hardware", ["rod-eclip", "screw"])
def test_below_and_standoff_clear_the_motor_and_the_lower_ends(hardware):
    from planar.fabrication.hardware import STANDOFF_LENGTHS, below_mm, mounting_items, pin_ends, standoff_length

    rng = np.random.default_rng(21)
    for body in rng.uniform(0.5, 45.0, 12):
        s = _settings(hardware=hardware, motor_body_mm=float(body))
        pins = [_pin("A", (0, 2), shaft=True), _pin("B", (0, 1)), _pin("C", (2, 4))]
        low = below_mm(s, pins)
        lower_end = max(tier.height for tier in pin_ends(s, pins[1])[0])  # pin C starts on layer 3: nothing of it hangs below
        assert low == pytest.approx(max(body, lower_end))
        n = standoff_length(s, low)
        assert n >= low + 1.0 and n in STANDOFF_LENGTHS
        into = float(next(i for i in mounting_items(s, low) if "screw" in i.item).size.split(" x ")[1]) - 3.5
        least = max(low + 1.0, 2 * into + 1.0)  # clear of what hangs, and room for a screw from each end
        assert all(m < least for m in STANDOFF_LENGTHS if m < n)  # the shortest that does
        no_motor = below_mm(s, pins[1:])
        assert no_motor == pytest.approx(lower_end)  # without a motor only the pins' lower ends hang


def test_standoffs_stack_past_the_longest_sold_and_clear_pieces_hanging_below():
    from planar.fabrication.hardware import STANDOFF_LENGTHS, below_mm, mounting_items, standoffs

    longest = STANDOFF_LENGTHS[-1]
    rng = np.random.default_rng(6)
    for below in np.concatenate([rng.uniform(0.0, 4 * longest, 40), [0.0, 1.1, 5.5]]):
        t = float(rng.choice([2.0, 3.0, 4.0, 6.0]))
        s = _settings(thickness_mm=t)
        k, n = standoffs(s, float(below))
        assert k * n >= below + 1.0 and n in STANDOFF_LENGTHS
        assert (k - 1) * longest < max(below + 1.0, 2 * longest)  # no more stacked than needed
        items = mounting_items(s, float(below))
        stands = [i for i in items if "standoff" in i.item]
        assert sum(i.qty for i in stands) == 2 * k and all(i.size == f"M3 x {n:g}" for i in stands)
        screw = next(i for i in items if "screw" in i.item)
        into = float(screw.size.split(" x ")[1]) - t - 0.5  # through the plate and a washer into the standoff
        assert into >= 3.0 and (k > 1 or 2 * into < n), (below, t, screw.size, n)  # the two screws never meet
    s = _settings(motor_body_mm=26.0)
    assert below_mm(s, [_pin("A", (0, 1), shaft=True)], hang=84.5) == pytest.approx(84.5)  # a bracket hanging lower


def test_short_shaft_is_a_violation_naming_both_lengths_and_the_option():
    from planar.fabrication.hardware import shaft_check

    for t, hi, have in [(3.0, 2, 9.0), (6.0, 2, 9.0), (3.0, 3, 9.0), (4.0, 3, 20.0), (2.0, 4, 9.0)]:
        s = _settings(thickness_mm=t, motor_shaft_mm=have)
        need = (hi + 1) * t
        got = shaft_check(s, [_pin("A", (0, hi), shaft=True), _pin("B", (0, hi))])
        if need <= have:
            assert got == []
        else:
            assert len(got) == 1
            text = got[0].text()
            assert f"{need:g} mm" in text and f"{have:g} mm" in text and "motor_shaft_mm" in text, text


@pytest.mark.slow  # two scenes built (about 1 s CPU)
def test_link_width_below_the_wall_is_exit_2_naming_it(tmp_path, capsys):
    from planar.cli.main import main

    for extra, needle in [
        ("link_width_mm = 6.0\n", "at least 6.1 mm"),
        ("link_width_mm = 7.0\nmin_wall_mm = 2.0\n", "at least 7.1 mm"),
    ]:
        out = tmp_path / "p.dxf"
        assert main(["export", str(_scene(tmp_path, extra)), "-o", str(out)]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and "fabrication.link_width_mm" in err[0] and needle in err[0], err
        assert not out.exists()


@pytest.mark.slow  # the command line and a scene loaded (about 1 s CPU in a fresh process)
def test_link_width_in_a_scene_that_is_no_linkage_is_exit_2(tmp_path, capsys):
    from planar.cli.main import main

    p = tmp_path / "fb.toml"
    p.write_text(
        '[mechanism]\ntype = "fourbar"\nground = 5.0\ncrank = 1.2\ncoupler = 4.5\nrocker = 3.5\n'
        "[fabrication]\nlink_width_mm = 8.0\n"
    )
    assert main(["export", str(p), "-o", str(tmp_path / "p.dxf")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "fabrication.link_width_mm" in err[0] and "fourbar" in err[0], err


def test_help_says_export_exits_3_with_its_outputs():
    from planar.cli.main import build_parser

    text = " ".join(build_parser().format_help().split())
    three = text[text.index("3 a result") :]
    assert "export" in three[:200] and "write their outputs" in three[:250], three[:250]


# --- slow: the waver exported, its files read back ---------------------------------------------------------------


@pytest.mark.slow
def test_steps_screw_the_motor_and_the_standoffs_before_the_shaft_part(tmp_path, capsys):
    out = _export(tmp_path, capsys=capsys)
    assert out["rc"] == 0, out["stdout"]
    bom = out["bom"]
    motor_screw = next(r for r in bom if r["item"] == "motor screw")
    standoff = next(r for r in bom if r["item"] == "standoff")
    mounting = next(r for r in bom if r["item"] == "mounting screw")
    names = {
        "motor screw": f"{motor_screw['notes'].split(',')[0]} {motor_screw['size_mm']}",
        "standoff": standoff["size_mm"],
        "mounting screw": mounting["size_mm"],
    }
    first = _actions(out["steps"][0])
    for what, name in names.items():
        assert any(name in a for a in first), (what, name, first)
    shaft = out["plan"]["motor_shaft"]
    driven = next(p for p in shaft["parts"] if p != "ground")
    everything = [a for page in out["steps"] for a in _actions(page)]
    screw_at = next(i for i, a in enumerate(everything) if names["motor screw"] in a)
    lay_driven = next(i for i, a in enumerate(everything) if a.startswith(f"lay {driven} "))
    assert screw_at < lay_driven  # the motor is screwed on before the part on its shaft
    assert any("base board" in a and mounting["size_mm"] in a for a in _actions(out["steps"][-1]))
    legend = " ".join(out["assembly"])
    assert names["motor screw"] in legend and standoff["size_mm"] in legend and mounting["size_mm"] in legend
    # the drawing marks where they go: two standoffs (S) and two motor screws (m) on the first page
    labels = out["steps"][0]
    assert labels.count("S") == 2 and labels.count("m") == 2


@pytest.mark.slow
@pytest.mark.parametrize(("hardware", "body"), [("rod-eclip", 26.0), ("screw", 7.5), ("rod-eclip", 0.5)])
def test_standoffs_clear_the_lowest_extent_below_the_plate(tmp_path, hardware, body):
    out = _export(tmp_path, f'hardware = "{hardware}"\nmotor_body_mm = {body}\n')
    plan = out["plan"]
    lowest = plan["motor"]["body_mm"] if plan["motor_shaft"] is not None else 0.0
    for p in plan["pins"]:
        if p["layers"][0] == 1:
            lowest = max(lowest, p["ends"]["lower"]["height_mm"])
    assert lowest > 0
    mount = plan["mounting"]
    assert mount["below_mm"] == pytest.approx(lowest)
    assert mount["standoff_mm"] >= lowest
    row = next(r for r in out["bom"] if r["item"] == "standoff")
    assert float(row["size_mm"].split(" x ")[1]) * mount["stacked"] == mount["standoff_mm"]
    assert sum(int(r["qty"]) for r in out["bom"] if r["item"] == "standoff") == 2 * mount["stacked"] * len(mount["plates"])
    assert len(mount["plates"][0]["at_mm"]) == 2


@pytest.mark.slow
@pytest.mark.parametrize("hardware", ["rod-eclip", "screw"])
def test_each_pin_goes_in_before_its_part_is_laid_and_closes_on_its_top_layer(tmp_path, hardware):
    out = _export(tmp_path, f'hardware = "{hardware}"\n')
    plan = out["plan"]
    layer_of = {p["name"]: p["layer"] for p in plan["parts"]}
    for pin in plan["pins"]:
        lo, hi = pin["layers"]
        acts = _actions(out["steps"][lo - 1])
        part = next(n for n in pin["parts"] if layer_of[n] == lo)
        body = f"{'rod' if hardware == 'rod-eclip' else 'screw'} {pin['name']} ("
        push = [i for i, a in enumerate(acts) if body in a and f"up through {part}'s hole {pin['name']}" in a]
        assert len(push) == 1, (pin["name"], acts)
        fit = acts[push[0]]
        assert fit.index("washer") < fit.index("push it up")  # the lower end is fitted first, in the same action
        lay = [i for i, a in enumerate(acts) if a.startswith(f"lay {part} ")]
        assert all(push[0] < i for i in lay), acts  # pushed through the part before the part is laid
        top = _actions(out["steps"][hi - 1])
        assert sum(a.startswith(f"close pin {pin['name']} on top") for a in top) == 1, top


@pytest.mark.slow
def test_a_plan_needing_a_longer_shaft_exits_3_and_a_long_enough_motor_passes(tmp_path, capsys):
    out = _export(tmp_path, "thickness_mm = 6.0\n", capsys=capsys)
    assert out["rc"] == 3
    line = next(ln for ln in out["stdout"].splitlines() if "motor shaft too short" in ln)
    need = out["plan"]["motor_shaft"]["length_mm"]
    assert f"{need:g} mm" in line and "9 mm" in line and "motor_shaft_mm" in line, line
    assert any(v["what"] == "motor shaft too short" for v in out["plan"]["violations"])
    import jsonschema

    schema = json.loads((Path(__file__).parents[2] / "docs" / "reference" / "plan.schema.json").read_text())
    jsonschema.validate(out["plan"], schema)  # the shaft's violation is a record the schema allows
    assert (out["dir"] / "parts.dxf").exists()  # the outputs are written, to look at
    long = tmp_path / "long"
    long.mkdir()
    ok = _export(long, "thickness_mm = 6.0\nmotor_shaft_mm = 20.0\n")
    assert ok["rc"] == 0
    assert ok["plan"]["motor"]["shaft_mm"] >= ok["plan"]["motor_shaft"]["length_mm"]
    assert "x 20" in next(r for r in ok["bom"] if r["item"] == "motor")["size_mm"]


@pytest.mark.slow
def test_link_width_sets_every_links_cut_width(tmp_path):
    import ezdxf
    import ezdxf.path
    import shapely
    from shapely.geometry import Polygon

    w = float(np.round(np.random.default_rng(5).uniform(6.5, 13.0), 2))
    out = _export(tmp_path, f"link_width_mm = {w}\n")
    assert out["rc"] == 0
    kerf = out["plan"]["kerf_mm"]
    widths = []
    for e in ezdxf.readfile(out["dir"] / "parts.dxf").modelspace().query("LWPOLYLINE[layer=='CUT_OUTER']"):
        pts = [(p.x, p.y) for p in ezdxf.path.make_path(e).flattening(0.01)]
        rect = shapely.minimum_rotated_rectangle(Polygon(pts))
        xy = np.asarray(rect.exterior.coords)[:4]
        widths.append(min(math.dist(xy[0], xy[1]), math.dist(xy[1], xy[2])))
    # coupler and link2 are two-hole links: their width is the setting (grown by the kerf); so is a three-hole
    # link's narrow side; nothing but the ground plate and the crank (its D hole) is cut otherwise
    near = [x for x in widths if abs(x - (w + kerf)) < 0.03]
    assert len(near) >= 3, (w, sorted(widths))


@pytest.mark.slow
def test_bom_lists_the_sheet_and_the_motor_screw_holes_as_cut(tmp_path):
    import ezdxf

    out = _export(tmp_path, "sheet_mm = [250.0, 180.0]\nthickness_mm = 4.0\n")
    plan = out["plan"]
    sheet = next(r for r in out["bom"] if r["item"] == "sheet")
    assert int(sheet["qty"]) == plan["sheets"]
    assert sheet["size_mm"] == "250 x 180 x 4"
    hole = plan["motor"]["screws"]["hole_mm"]
    assert hole == 1.8  # ISO 273 medium clearance for M1.6
    notes = next(r for r in out["bom"] if r["item"] == "motor screw")["notes"]
    assert f"{hole:g} mm" in notes
    circles = [
        e
        for e in ezdxf.readfile(out["dir"] / "parts.dxf").modelspace().query("CIRCLE[layer=='CUT_INNER']")
        if abs(2 * e.dxf.radius + plan["kerf_mm"] - hole) < 1e-6
    ]
    assert len(circles) == 2
    a, b = (c.dxf.center for c in circles)
    assert math.dist((a.x, a.y), (b.x, b.y)) == pytest.approx(plan["motor"]["screws"]["spacing_mm"], abs=1e-6)


@pytest.mark.slow
def test_kerf_test_message_says_what_each_file_holds(tmp_path, capsys):
    from planar.cli.main import main

    kerf = tmp_path / "kerf.svg"
    assert main(["export", str(_scene(tmp_path)), "--kerf-test", str(kerf)]) == 0
    lines = capsys.readouterr().out.splitlines()
    parts_line = next(ln for ln in lines if " parts " in ln and "->" in ln)
    assert str(kerf) not in parts_line and "no part file written" in parts_line, parts_line
    assert any(ln.startswith("kerf test piece") and ln.endswith(str(kerf)) for ln in lines), lines


def test_the_motor_screws_are_countersunk_flush():
    """The build check models nothing above the ground plate's top face at the motor screws: true only if their
    heads sink flush (a pan head stands 1.3 mm proud, under the part turning on the layer above). The BOM's motor
    screws are a countersunk kind whose head height (ISO 7046: k 0.96 mm for M1.6, 1.2 for M2) fits the sheet."""
    from planar.fabrication.hardware import motor_items

    head = {1.6: 0.96, 2.0: 1.2}
    for t in (1.5, 3.0, 6.0):
        _, screw = motor_items(_settings(thickness_mm=t))
        m = float(screw.size.split(" x ")[0][1:])
        assert "countersunk" in screw.item and "ISO 7046" in screw.item, screw
        assert head[m] < t, (screw, t)
