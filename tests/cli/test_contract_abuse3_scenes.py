"""Issue 26, the third abuse trial's command-line findings on scene files, one case each.

Each case failed before its fix: exit 1 (a standoff or a cut polygon at 1e300), NaN written (a speed of
1e300), a message about something else (``unit_mm = 1e-300`` named a pin hole, a triad's ``ra = 1e300`` an
OverflowError) or garbled, or absurd input accepted (``mirror = "yes"``, ``motor_shaft_mm = 1e300``, a
gravity or a load of 1e300, ``standoffs = []``).  Now each exits 2 with one line naming the scene by the
path the user typed (its folder included), the field and the value as written, and writes nothing.
"""

from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np
import pytest
from clicheck import fails_cleanly

from planar.cli.main import main

ROOT = Path(__file__).resolve().parents[2]
GALLERY = ROOT / "gallery"
WALKER = "jansen-walker-4.toml"
STANDOFFS = "standoffs = [[0.0, -32.0], [0.0, 32.0]]"
BIRD = "points = [[4.9, 4.1], [5.5, 4.45], [6.6, 4.25], [7.7, 4.7], [7.1, 3.4], [6.0, 2.9], [5.0, 3.25]]"


def _variant(folder: Path, scene: str, *edits: tuple[str, str]) -> str:
    """The gallery ``scene`` edited, written to ``folder/in/s.toml``; returns the path as typed from ``folder``."""
    text = (GALLERY / scene).read_text()
    for old, new in edits:
        assert old in text, old
        text = text.replace(old, new, 1)
    (folder / "in").mkdir(exist_ok=True)
    (folder / "in" / "s.toml").write_text(text)
    return "in/s.toml"


def _export(s: str) -> list[str]:
    return ["export", s, "-o", "out/p.dxf", "--plan", "out/plan.json", "--bom", "out/bom.csv"]


CASES = [
    # 1. exit 1 (internal error)
    pytest.param(
        WALKER, [(STANDOFFS, "standoffs = [[1e300, -32.0], [0.0, 32.0]]")], _export,
        ("standoffs[0] = [1e+300, -32.0]", "model units of the crank axis"), id="standoff-1e300",
    ),
    pytest.param(
        "cam-automaton.toml", [(BIRD, "points = [[0,0],[1e300,0],[0,1e300]]")], _export,
        ("mechanism.polygons.bird-body.points = [[0.0, 0.0], [1e+300, 0.0]",), id="cut-polygon-1e300",
        marks=pytest.mark.slow,  # 0.7 s CPU: the cam's profile is built before the polygons are checked
    ),
    # 2. NaN written
    pytest.param(
        "kangaroo-leg.toml", [("speed = 1.0", "speed = 1e300")],
        lambda s: ["motion", s, "-o", "out/m.csv", "--derivatives"],
        ("driver.speed = 1e+300", "1e-09 to 1e+06 cycles per second"), id="speed-1e300",
    ),
    # 3. messages
    pytest.param(
        WALKER, [("unit_mm = 1.0", "unit_mm = 1e-300")], _export,
        ("fabrication.unit_mm = 1e-300", "min_part_mm"), id="unit-1e-300",
    ),
    pytest.param(
        "stephenson-six-bar.toml", [("ra = 3.269557", "ra = 1e300")], lambda s: ["info", s],
        ("mechanism.nodes.T1.ra = 1e+300", "a length from 1e-60 to 1e+60"), id="triad-ra-1e300",
    ),
    pytest.param(
        WALKER, [('kind = "crank"', 'kind = "driven"')], lambda s: ["info", s],
        ("nodes.A.kind = 'driven'", "expected 'crank'"), id="walker-driven-crank",
    ),
    pytest.param(
        "two-input-five-bar.toml", [("radius = 1.5", "")], lambda s: ["info", s],
        ("mechanism.nodes.A: expected the keys a 'driven' node needs (centre, radius): radius missing",),
        id="driven-without-radius",
    ),
    pytest.param(
        "two-input-five-bar.toml", [("amplitude = 35.0", "")], lambda s: ["info", s],
        ("mechanism.nodes.A: expected mean only with amplitude",), id="driven-mean-without-amplitude",
    ),
    # 4. accepted silently
    pytest.param(
        WALKER, [("mirror = true", 'mirror = "yes"')], _export, ("mechanism.mirror = 'yes': expected true or false",),
        id="mirror-yes",
    ),
    pytest.param(
        WALKER, [("unit_mm = 1.0", "unit_mm = 1.0\nmotor_shaft_mm = 1e300")], _export,
        ("fabrication.motor_shaft_mm = 1e+300", "greater than 0 and at most 100 mm"), id="motor-shaft-1e300",
    ),
    pytest.param(
        "bunny.toml", [("gravity = [69.367175, -69.367175]", "gravity = [1e300, 0]")], lambda s: ["toy", s],
        ("effects.gravity = [1e+300, 0.0]", "at most 1000 g"), id="gravity-1e300",
    ),
    pytest.param(
        "kangaroo-leg.toml", [("force = [0.0, 10.0]", "force = [0.0, 1e300]")], lambda s: ["compare", s],
        ("effects.loads[0].force = [0.0, 1e+300]", "at most 1e+60"), id="load-1e300",
    ),
    pytest.param(
        WALKER, [(STANDOFFS, "standoffs = []")], _export,
        ("mechanism.standoffs = []", "leave the key out to have two chosen"), id="standoffs-empty",
    ),
    pytest.param(  # exported as one rod (30 pins, not 31), exit 0
        WALKER, [(STANDOFFS, "standoffs = [[0.0, 32.0], [0.0, 32.0]]")], _export,
        ("mechanism.standoffs = [[0.0, 32.0], [0.0, 32.0]]", "distinct points (item 1 repeats item 0"),
        id="standoffs-repeated",
    ),
    # 5. the file named by the path as typed
    pytest.param(
        "kangaroo-leg.toml", [("unit_mm = 15.0", "unit_mm = 15.0\npin_diameter_mm = 3.3")], _export,
        ("in/s.toml: fabrication.pin_diameter_mm = 3.3",), id="pin-diameter-path",
        marks=pytest.mark.slow,  # 0.3 s CPU: refused where the hardware is chosen, after the parts are cut
    ),
    pytest.param(
        "kangaroo-leg.toml", [("cut = true", 'cut = "part"')], _export,
        ("in/s.toml: mechanism.polygons[0] 'foot': no room for two",), id="rider-no-room-names-the-file",
    ),
]  # fmt: skip


@pytest.mark.parametrize("scene,edits,argv,needles", CASES)
def test_a_trial_scene_is_refused_naming_file_field_and_value(
    tmp_path: Path, capsys, monkeypatch, scene: str, edits, argv, needles: tuple[str, ...]
) -> None:
    monkeypatch.chdir(tmp_path)
    (tmp_path / "out").mkdir()
    s = _variant(tmp_path, scene, *edits)
    err = fails_cleanly(capsys, argv(s), "in/s.toml: ", *needles)
    assert not any((tmp_path / "out").iterdir()), err


def test_a_driven_node_without_amplitude_turns_fully(tmp_path: Path) -> None:
    """The how-to says so; the schema refused it ("expected a 'driven' node needs amplitude")."""
    from planar.scene.load import load_scene

    s = _variant(tmp_path, "two-input-five-bar.toml", ("amplitude = 35.0", ""), ("mean = 70.0", ""))
    scene = load_scene(tmp_path / s)
    node = next(n for n in scene.mechanism.nodes if n.name == "A")
    theta = np.linspace(0.0, 2 * np.pi, 9)
    cycles = float(node.cycles)
    np.testing.assert_allclose(node.input_angle(theta), node.phase + cycles * theta)  # phase + cycles theta
    assert node.input_angle(theta)[-1] - node.input_angle(theta)[0] == pytest.approx(2 * np.pi * cycles)


def test_invalid_samples_hold_0_in_the_rate_columns_never_nan(tmp_path: Path) -> None:
    """A non-Grashof four-bar driven round a full turn: its unassembled samples' rates were written as nan."""
    p = tmp_path / "ng.toml"
    p.write_text(
        '[mechanism]\ntype = "fourbar"\nground = 2.0\ncrank = 1.9\ncoupler = 1.0\nrocker = 1.5\n'
        "[driver]\nsamples_per_cycle = 48\n"
    )
    out = tmp_path / "m.csv"
    assert main(["motion", str(p), "-o", str(out), "--derivatives"]) == 0
    rows = list(csv.DictReader(out.open()))
    assert "nan" not in out.read_text().lower()
    bad = [r for r in rows if r["rates_valid"] == "0"]
    assert bad and any(r["valid"] == "0" for r in bad)  # the case holds invalid samples
    for r in bad:
        for k in ("crank.omega", "coupler.alpha", "coupler_point.vx", "torque"):
            assert float(r[k]) == 0.0
    assert all(math.isfinite(float(v)) for r in rows for v in r.values())


def test_toy_speeds_of_0_says_the_real_range(capsys) -> None:
    err = fails_cleanly(capsys, ["toy", str(GALLERY / "horse.toml"), "--speeds", "0"], "--speeds = '0'")
    assert "greater than 0 and at most 1000" in err and "from 0" not in err


@pytest.mark.parametrize("target", ["ox", pytest.param("Rz", marks=pytest.mark.slow)])
def test_chains_names_the_same_motions_it_accepts(capsys, target: str) -> None:
    """``chains ox`` listed Rz among the valid motions, and ``chains Rz`` was refused."""
    err = fails_cleanly(capsys, ["chains", target], f"target = {target!r}", "one of Ox, Oy, Oz, Tx, Ty, Tz, OzT")
    assert "Rz" not in err.split("expected", 1)[1]
