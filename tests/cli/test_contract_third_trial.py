"""Issue 26, third trial: what a careful new user still found on the newer surfaces and the API.

Each case failed before its fix (exit 1, exit 0 on absurd input, a message in the wrong unit or words,
a raw exception from Python); now each exits 2 with one line naming the file, field or option and the
value as the user wrote it, writes nothing, or raises a :class:`planar.errors.PlanarError`.
"""

from __future__ import annotations

import math
from pathlib import Path

import pytest
from clicheck import fails_cleanly as _fails_cleanly

from planar.cli.main import main
from planar.errors import PlanarError

ROOT = Path(__file__).resolve().parents[2]
GALLERY = ROOT / "gallery"


def _variant(tmp_path: Path, scene: str, *edits: tuple[str, str], name: str = "s.toml") -> Path:
    text = (GALLERY / scene).read_text()
    for old, new in edits:
        assert old in text, old
        text = text.replace(old, new, 1)
    p = tmp_path / name
    p.write_text(text)
    return p


# ----------------------------------------------------------------------------- 1. angles float64 cannot resolve


@pytest.mark.parametrize(
    "unit,command",
    [
        ("deg", "info"),
        ("rad", "motion"),
        pytest.param("rad", "info", marks=pytest.mark.slow),
        pytest.param("deg", "motion", marks=pytest.mark.slow),
    ],
)
def test_a_geared_phase_of_1e300_is_refused(tmp_path: Path, capsys, unit: str, command: str) -> None:
    """``info`` divided by zero (exit 1) and ``motion`` wrote 60 'valid' samples of noise."""
    s = _variant(
        tmp_path, "geared-five-bar.toml", ("phase = 90.0", "phase = 1e300"), ('angle_unit = "deg"', f'angle_unit = "{unit}"')
    )
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
    from planar.linkages import RRR, Crank, Fixed, Link, Linkage

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


@pytest.mark.parametrize(
    "q", [[1e300], pytest.param([0.0, 1e7], marks=pytest.mark.slow), pytest.param([-2e7], marks=pytest.mark.slow)]
)
def test_solve_refuses_driver_values_float64_cannot_resolve(q) -> None:
    Linkage, nodes, links = _linkage_parts()
    mech = Linkage("four", nodes, links)
    with pytest.raises(PlanarError, match=r"solve\(q\)"):
        mech.solve(q)
    assert mech.solve([0.0, 8e6]).valid.shape == (2,)  # within the resolution: solved


# ----------------------------------------------------------------------------- 3. and 8. outputs checked first


def _unwritable() -> Path:
    """A folder no file can be created in, even by root (sysfs)."""
    import tempfile

    d = Path("/sys")
    try:
        fd, tmp = tempfile.mkstemp(dir=d)
    except OSError:
        return d
    import os

    os.close(fd)
    os.unlink(tmp)
    pytest.skip("no unwritable folder here")


def test_synth_atlas_into_an_unwritable_folder_is_refused_before_the_build(tmp_path: Path, capsys) -> None:
    """It built for 12.6 s, then failed naming the temporary ``a.npz.15051.tmp.npz`` on 3+ lines."""
    import time

    t0 = time.process_time()
    err = _fails_cleanly(capsys, ["synth", "atlas", "--size", "100000", "-o", str(_unwritable() / "a.npz")], "-o/--output")
    assert time.process_time() - t0 < 0.5 and "tmp" not in err


@pytest.mark.parametrize(
    "argv",
    [
        ["motion", str(GALLERY / "kangaroo-leg.toml"), "-o", "{d}/m.csv"],
        pytest.param(["plot", str(GALLERY / "kangaroo-leg.toml"), "-o", "{d}/p.png"], marks=pytest.mark.slow),
        pytest.param(["design", "{tmp}/req.toml", "-o", "{d}/toy.toml"], marks=pytest.mark.slow),
    ],
)
def test_outputs_are_named_one_way_and_checked_first(tmp_path: Path, capsys, argv: list[str]) -> None:
    (tmp_path / "req.toml").write_text('[[effector]]\nname = "ear"\nmotion = "Oz"\nrange = 20.0\n')
    d = str(_unwritable())
    _fails_cleanly(capsys, [a.format(d=d, tmp=tmp_path) for a in argv], "-o/--output = ", "/sys")


def test_an_output_under_a_regular_file_says_it_is_a_file(tmp_path: Path, capsys) -> None:
    (tmp_path / "afile").write_text("")
    t = tmp_path / "t.csv"
    t.write_text("x,y\n0,0\n1,0.2\n2,0.1\n2.5,1\n1,1.5\n")
    out = tmp_path / "afile" / "s.toml"
    err = _fails_cleanly(capsys, ["synth", "path", str(t), "-o", str(out), "--budget", "quick"], "is a file, not a folder")
    assert "does not exist" not in err


# ----------------------------------------------------------------------------- 4. progress bars only on a terminal


@pytest.mark.slow
def test_progress_bars_are_silent_when_stderr_is_not_a_terminal(tmp_path: Path, capsys) -> None:
    """``synth atlas`` printed tqdm bars into a pipe."""
    out = tmp_path / "a.npz"
    assert main(["synth", "atlas", "--size", "200", "-o", str(out)]) == 0
    assert capsys.readouterr().err == ""


def test_every_progress_bar_comes_from_one_helper() -> None:
    """tqdm is used in one place, which disables it off a terminal."""
    users = [p.relative_to(ROOT) for p in (ROOT / "planar").rglob("*.py") if "tqdm" in p.read_text()]
    assert users == [Path("planar/core/progress.py")], users


# ----------------------------------------------------------------------------- 5. raw exceptions from the API


@pytest.mark.parametrize(
    "call,needle",
    [
        (lambda: __import__("planar.windup.sizing").windup.sizing.size_for_range(1, "0.3"), "target"),
        (lambda: __import__("planar").simulate(None, [0.0, 0.1]), "mech"),
        (lambda: __import__("planar").simulate(_four(), [[0.0, 0.1]]), "t = "),
        (lambda: __import__("planar").simulate(_four(), [0.1, 0.0]), "increasing"),
        (lambda: __import__("planar").simulate(_four(), [0.0, 0.1], settings="fast"), "settings"),
        (lambda: __import__("planar").joint_residuals(None, None), "mech"),
        (lambda: __import__("planar").Linkage("l", None, []), "nodes"),
        (lambda: __import__("planar").Linkage("l", [1, 2], []), "nodes"),
        (lambda: __import__("planar").Pivot("j", "a", "b", (0.0, math.nan), (0.0, 0.0)), "anchor_a"),
        (lambda: __import__("planar").Pivot(None, "a", "b", (0.0, 0.0), (0.0, 0.0)), "Pivot.name"),
        (lambda: __import__("planar").PinInSlot("j", "a", "b", "x", (1.0, 0.0), (0.0, 0.0)), "start"),
        (lambda: __import__("planar").Slide("j", "a", "b", (0, 0), (1, 0), (0, 0), (1, 0), width=-1.0), "width"),
    ],
)
def test_api_entrances_raise_a_planar_error(call, needle: str) -> None:
    with pytest.raises(PlanarError) as info:
        call()
    assert needle in str(info.value) and "\n" not in str(info.value), str(info.value)


def _four():
    from planar.linkages import FourBar

    return FourBar(4.0, 1.0, 4.0, 3.0)


@pytest.mark.slow
def test_plot_mechanism_takes_one_chart_name_and_names_the_python_argument(tmp_path: Path) -> None:
    from planar.app.pipeline import plot_mechanism

    leg = _four()
    assert plot_mechanism(leg, tmp_path / "p.png", what="transmission") == ["transmission"]
    with pytest.raises(PlanarError) as info:
        plot_mechanism(leg, tmp_path / "q.png", what="nonsense")
    assert str(info.value).startswith("what = 'nonsense'")
    assert not (tmp_path / "q.png").exists()


# ----------------------------------------------------------------------------- 7. non-finite SVG coordinates


@pytest.mark.parametrize(
    "name,value",
    [("cx", "nan"), pytest.param("cy", "inf", marks=pytest.mark.slow), pytest.param("r", "NaN", marks=pytest.mark.slow)],
)
def test_an_svg_with_a_nan_coordinate_is_refused(tmp_path: Path, capsys, name: str, value: str) -> None:
    """svgelements reads ``cx="nan"`` as 0: the synthesis ran on a made-up circle and wrote a scene."""
    attrs = {"cx": "30", "cy": "20", "r": "5", name: value}
    circle = "<circle " + " ".join(f'{k}="{v}"' for k, v in attrs.items()) + "/>"
    svg = tmp_path / "nan.svg"
    svg.write_text(f'<svg xmlns="http://www.w3.org/2000/svg" width="60" height="40">{circle}</svg>')
    out = tmp_path / "s.toml"
    _fails_cleanly(capsys, ["synth", "path", str(svg), "-o", str(out), "--budget", "quick"], "nan.svg", "<circle>", name, out=out)


# ----------------------------------------------------------------------------- 8. messages with the right reasons


def test_tiny_targets_give_their_real_size(tmp_path: Path, capsys) -> None:
    t = tmp_path / "tiny.csv"
    t.write_text("x,y\n" + "".join(f"{math.cos(k) * 3e-300},{math.sin(k) * 2e-300}\n" for k in range(12)))
    err = _fails_cleanly(capsys, ["synth", "path", str(t), "-o", str(tmp_path / "s.toml")], "e-300")
    assert "size 0 " not in err


@pytest.mark.parametrize(
    "edit,needle",
    [
        (("local = [", "local = [0.0, "), "mechanism.nodes.T1.local = [0.0, "),
        pytest.param(
            ("members = [", 'members = ["T2"]\n# '),
            "mechanism.nodes.T1.members = ['T2']: expected more items",
            marks=pytest.mark.slow,
        ),
    ],
)
def test_scene_type_errors_name_the_node_in_planars_words(tmp_path: Path, capsys, edit, needle: str) -> None:
    scene = next(p.name for p in GALLERY.glob("*.toml") if 'kind = "triad"' in p.read_text())
    s = _variant(tmp_path, scene, edit)
    err = _fails_cleanly(capsys, ["info", str(s)], needle)
    assert "Tuple should" not in err and "Field required" not in err


def test_a_request_without_a_name_says_it_is_missing(tmp_path: Path, capsys) -> None:
    req = tmp_path / "req.toml"
    req.write_text('[[effector]]\nmotion = "Oz"\nrange = 30.0\n')
    err = _fails_cleanly(capsys, ["design", str(req), "-o", str(tmp_path / "t.toml")], "effector[0].name = (missing)")
    assert "None" not in err


# ----------------------------------------------------------------------------- 9. and 10.


@pytest.mark.slow
def test_synth_path_uses_the_given_atlas_for_timed_targets(tmp_path: Path, capsys, monkeypatch) -> None:
    """``--atlas`` was ignored on timed targets and the default atlas built into the cache."""
    atlas = tmp_path / "a.npz"
    assert main(["synth", "atlas", "--size", "500", "-o", str(atlas)]) == 0
    monkeypatch.setenv("PLANAR_CACHE_DIR", str(tmp_path / "cache"))
    t = tmp_path / "t.csv"
    t.write_text("x,y,theta\n0,0,0\n1,0.2,1\n2,0.1,2\n2.5,1,3\n1,1.5,4\n")
    capsys.readouterr()
    main(["synth", "path", str(t), "-o", str(tmp_path / "s.toml"), "--atlas", str(atlas), "--budget", "quick"])
    assert "building the coupler-curve atlas" not in capsys.readouterr().err
    assert not (tmp_path / "cache").exists()


def test_a_missing_option_value_says_what_the_option_takes(capsys) -> None:
    rc = main(["export", str(GALLERY / "kangaroo-leg.toml"), "-o", "k.dxf", "--sheet", "-5x-5"])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and len(err.splitlines()) == 1, err
    assert "WIDTHxHEIGHT" in err and "--sheet=-5x-5" in err
