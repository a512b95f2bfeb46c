"""Issue 26, third trial: what a careful new user still found on the newer surfaces and the API.

Each case failed before its fix (exit 1, exit 0 on absurd input, a message in the wrong unit or words,
a raw exception from Python); now each exits 2 with one line naming the file, field or option and the
value as the user wrote it, writes nothing, or raises a :class:`planar.errors.PlanarError`.
"""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from planar.cli.main import main
from planar.errors import PlanarError

ROOT = Path(__file__).resolve().parents[2]
GALLERY = ROOT / "gallery"


def _fails_cleanly(capsys: pytest.CaptureFixture[str], argv: list[str], *needles: str, out: Path | None = None) -> str:
    """``main(argv)`` exits 2 with one line holding every needle, and leaves ``out`` unwritten."""
    rc = main(argv)
    err = capsys.readouterr().err.strip()
    assert rc == 2, err
    assert len(err.splitlines()) == 1 and err.startswith("planar: error: "), err
    for n in needles:
        assert n in err, err
    if out is not None:
        assert not out.exists()
    return err


def _variant(tmp_path: Path, scene: str, *edits: tuple[str, str], name: str = "s.toml") -> Path:
    text = (GALLERY / scene).read_text()
    for old, new in edits:
        assert old in text, old
        text = text.replace(old, new, 1)
    p = tmp_path / name
    p.write_text(text)
    return p


# ----------------------------------------------------------------------------- 1. angles float64 cannot resolve


@pytest.mark.parametrize("unit", ["deg", "rad"])
@pytest.mark.parametrize("command", ["info", "motion"])
def test_a_geared_phase_of_1e300_is_refused(tmp_path: Path, capsys, unit: str, command: str) -> None:
    """``info`` divided by zero (exit 1) and ``motion`` wrote 60 'valid' samples of noise."""
    s = _variant(tmp_path, "geared-five-bar.toml", ("phase = 90.0", "phase = 1e300"), ('angle_unit = "deg"', f'angle_unit = "{unit}"'))
    out = tmp_path / "m.csv"
    argv = [command, str(s)] + (["-o", str(out)] if command == "motion" else [])
    bound = "5.73e+07 deg" if unit == "deg" else "1e+06 rad"
    _fails_cleanly(capsys, argv, "nodes.B.phase = 1e+300", bound, out=out)


@pytest.mark.parametrize(
    "scene,old,new,needle",
    [
        ("kangaroo-leg.toml", "\n[driver]\n", "\n[driver]\nphase = 1e300\n", "driver.phase = 1e+300"),
        ("two-input-five-bar.toml", "phase = 90.0", "phase = -1e300", "nodes.B.phase = -1e+300"),
        ("geared-five-bar.toml", "ratio = -1.0", "ratio = -1e300", "nodes.B.ratio = -1e+300"),
    ],
)
def test_every_scene_angle_and_ratio_is_bounded(tmp_path: Path, capsys, scene: str, old: str, new: str, needle: str) -> None:
    s = _variant(tmp_path, scene, (old, new))
    out = tmp_path / "m.csv"
    _fails_cleanly(capsys, ["motion", str(s), "-o", str(out)], needle, out=out)


# ----------------------------------------------------------------------------- 2. values as the user wrote them


def test_driver_amplitude_of_a_clocked_linkage_is_shown_in_degrees(tmp_path: Path, capsys) -> None:
    """``[driver] amplitude = 10.0`` in a degree scene was named as 0.1745."""
    s = _variant(tmp_path, "two-input-five-bar.toml", ("\n[driver]\n", "\n[driver]\namplitude = 10.0\n"))
    err = _fails_cleanly(capsys, ["info", str(s)], "driver.amplitude = 10.0")
    assert "0.174" not in err


def test_a_driven_phase_of_1e300_in_degrees_is_shown_as_written(tmp_path: Path, capsys) -> None:
    s = _variant(tmp_path, "two-input-five-bar.toml", ("phase = 90.0", "phase = 1e300"))
    err = _fails_cleanly(capsys, ["info", str(s)], "nodes.B.phase = 1e+300", "deg")
    assert "e+298" not in err and " rad" not in err


# ----------------------------------------------------------------------------- 1. and 6. from Python


def _linkage_parts():
    from planar.linkages import Crank, Fixed, Link, Linkage, RRR

    nodes = [Fixed("O1", (0.0, 0.0)), Fixed("O2", (4.0, 0.0)), Crank("A", "O1", 1.0), RRR("B", "A", 4.0, "O2", 3.0)]
    links = [Link("crank", ("O1", "A")), Link("coupler", ("A", "B")), Link("rocker", ("O2", "B"))]
    return Linkage, nodes, links


@pytest.mark.parametrize(
    "call,needle",
    [
        (lambda L: L.Link("l\x07", ("O", "A")), "Link.name"),
        (lambda L: L.Driver("cr\x00ank"), "driver.part"),
        (lambda L: L.Crank("A", "O1", math.nan), "nodes.A.radius = nan"),
        (lambda L: L.Crank("A", "O1", -1.0), "nodes.A.radius = -1.0"),
        (lambda L: L.Crank("A", "O1", 1.0, 1e300), "nodes.A.phase"),
        (lambda L: L.RRR("P", "A", -4.0, "B", 4.0), "nodes.P.ra = -4.0"),
        (lambda L: L.RRR("P", "A", 4.0, "B", 4.0, branch=0), "nodes.P.branch = 0"),
        (lambda L: L.Fixed("O", (0, 0, 0)), "nodes.O.xy"),
        (lambda L: L.Triad("T", "A", math.nan, (0, 0), (0, 0)), "nodes.T.ra = nan"),
        (lambda L: L.Triad("T", "A", 1.0, (0, 0, 0), (0, 0)), "nodes.T.local"),
        (lambda L: L.Triad("T", "A", 1.0, (0, 0), (0, 0), members=("T2",)), "nodes.T.members"),
        (lambda L: L.Actuator("S", "O", axis=(0, 0)), "nodes.S.axis"),
        (lambda L: L.Geared("B", "O2", 1.2, "A", -1.0, 1e300), "nodes.B.phase"),
        (lambda L: L.Driver("c", rate=0), "rate (rad/s)"),
        (lambda L: L.Driver("c", phase=1e300), "driver.phase"),
    ],
)
def test_node_constructors_refuse_at_once(call, needle: str) -> None:
    import types

    import planar.linkages as lk
    from planar.core.model import Driver
    from planar.linkages.gears import Geared
    from planar.linkages.triads import Triad

    ns = types.SimpleNamespace(**{**{n: getattr(lk, n) for n in lk.__all__}, "Driver": Driver, "Geared": Geared, "Triad": Triad})
    with pytest.raises(PlanarError) as info:
        call(ns)
    assert needle in str(info.value) and "\n" not in str(info.value), str(info.value)


def test_a_driver_rate_is_not_called_a_length() -> None:
    from planar.core.model import Driver

    with pytest.raises(PlanarError) as info:
        Driver("c", rate=0)
    assert "length" not in str(info.value)


@pytest.mark.parametrize("q", [[1e300], [0.0, 1e7], [-2e7]])
def test_solve_refuses_driver_values_float64_cannot_resolve(q) -> None:
    Linkage, nodes, links = _linkage_parts()
    mech = Linkage("four", nodes, links)
    with pytest.raises(PlanarError, match=r"solve\(q\)"):
        mech.solve(q)
    assert mech.solve([0.0, 8e6]).valid.shape == (2,)  # within the resolution: solved
