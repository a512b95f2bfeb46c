"""Issue 26: the API calls the third abuse trial found still raising raw exceptions or naming values badly.

Each call must raise a :class:`planar.errors.PlanarError` naming the argument (these fail on the code
before the fix with ZeroDivisionError, ValueError, TypeError, MemoryError or AttributeError).
"""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np
import pytest

from planar.analysis.info import info
from planar.cams import CamProfile, FollowerGeometry, Program, Segment
from planar.core.model import Slide
from planar.draw import plan_frames
from planar.errors import InputError, LimitError, PlanarError, short_repr
from planar.fabrication import FabSettings, part_cuts
from planar.fabrication.layers import plan_assembly
from planar.linkages import FourBar, GearMesh, Link, freudenstein_angles
from planar.physics.settings import SimSettings
from planar.synth import synthesise_function, synthesise_path
from planar.toys import KeyedShaft

LEG = FourBar(4.0, 1.0, 4.0, 3.0, coupler_point=(5.5, -2.0))
TARGETS = np.c_[np.cos(np.linspace(0.0, 5.0, 10)), np.sin(np.linspace(0.0, 5.0, 10))]


@pytest.mark.parametrize(
    "call,needle",
    [
        (lambda: info(LEG, samples=0), "samples"),
        (lambda: info(LEG, samples=-5), "samples"),
        (lambda: info(LEG, samples=math.nan), "samples"),
        (lambda: info(LEG, samples="10"), "samples"),
        (lambda: info(None), "mech"),
        (lambda: synthesise_path(TARGETS, atlas="atlas.npz"), "atlas"),
        (lambda: synthesise_path(TARGETS, atlas=123), "atlas"),
        (lambda: FourBar(4, 1, 4, 3, bogus=1), "bogus"),
        (lambda: synthesise_function(np.linspace(0, 1, 6), np.sin(np.linspace(0, 1, 6)), tolerance=math.nan), "tolerance"),
        (lambda: synthesise_function(np.linspace(0, 1, 6), np.sin(np.linspace(0, 1, 6)), tolerance=-1), "tolerance"),
        (lambda: synthesise_function(np.linspace(0, 1, 6), np.sin(np.linspace(0, 1, 6)), tolerance=None), "tolerance"),
    ],
)
def test_the_call_raises_a_named_planar_error(call, needle: str) -> None:
    with pytest.raises(PlanarError) as e:
        call()
    assert needle in str(e.value), str(e.value)


def test_a_huge_sample_count_is_refused_before_allocation() -> None:
    with pytest.raises(LimitError, match="PLANAR_MAX_SAMPLES"):
        info(LEG, samples=10**12)


@pytest.mark.slow
def test_info_still_works_at_a_small_count() -> None:
    assert info(LEG, samples=8).dof == 1


def test_array_summaries_show_plain_numbers_and_count_nan() -> None:
    text = short_repr(np.array([[0.0, 0.0, 0.0], [1.0, math.nan, 0.1], [2.0, 0.1, math.inf], [3.0, -0.2, 0.2]]))
    assert text == "<array of shape (4, 3), from -0.2 to 3.0, with 1 NaN, 1 inf>", text


def test_a_long_value_keeps_its_end_and_a_path_stays_whole() -> None:
    path = Path("/tmp") / ("deep-" * 30) / "leg.gif"
    assert short_repr(path).endswith("leg.gif')") and "..." not in short_repr(path)
    text = short_repr("x" * 300 + "the end")
    assert text.endswith("the end'") and "..." in text and len(text) <= 240
    assert short_repr(list(range(100))).endswith("98, 99]") and len(short_repr(list(range(100)))) == 80


def test_an_output_under_a_file_says_it_is_a_file(tmp_path: Path) -> None:
    from planar.fileio import atomic_write

    (tmp_path / "afile").write_text("x")
    with pytest.raises(InputError, match="is a file, not a folder"), atomic_write(tmp_path / "afile" / "x.gif"):
        pass


def _theta() -> np.ndarray:
    return np.linspace(0.0, 6.0, 7)


@pytest.mark.parametrize(
    "call,needle",
    [
        # raw exceptions the fifth trial found (AttributeError, OverflowError, ZeroDivisionError, OSError)
        (lambda: plan_assembly(None, {}, [], [], 10, 3, 3, 1.5), "mech"),
        (lambda: plan_assembly(LEG, {}, [], [], 10, 3, 3, 1.5), "material"),  # a KeyError: 'ground'
        (lambda: plan_assembly(LEG, {p.name: () for p in LEG.parts}, [], [], 10, 3, 3, 1.5, shaft_pin=1e300), "shaft_pin"),
        (lambda: plan_frames(1e-300, 1e300), "duration"),
        (lambda: freudenstein_angles(1e-300, 4, 3e-300, 4, _theta()), "freudenstein_angles(a)"),
        (lambda: freudenstein_angles(1, 4, 3, 4, np.zeros((2, 2))), "theta"),
        # NaN and inf stored silently; a negative pitch radius
        (lambda: KeyedShaft("k", "a", "b", (0, 0), (math.nan, 0), 0), "anchor_b"),
        (lambda: KeyedShaft("k", "a", "b", (0, 0), (0, 0), math.inf), "phase"),
        (lambda: GearMesh("m", "a", "b", math.nan, 0, (0, 0), (1, 0), 0.5, 0.5), "ratio"),
        (lambda: GearMesh("m", "a", "b", -1, 0, (0, 0), (1, 0), -0.5, 0.5), "radius_a"),
    ],
)
def test_the_fifth_trial_call_raises_a_named_planar_error(call, needle: str) -> None:
    with pytest.raises(PlanarError) as e:
        call()
    assert needle in str(e.value), str(e.value)


def test_a_huge_animation_is_a_limit_error() -> None:
    with pytest.raises(LimitError, match="PLANAR_MAX_FRAMES"):
        plan_frames(1e-300, 1e300)


@pytest.mark.slow  # the demo's imports
@pytest.mark.parametrize("where", ["/proc/demo", "FILE/demo"])
def test_the_demo_refuses_a_folder_it_cannot_make(tmp_path: Path, where: str) -> None:
    from planar.app import run_demo

    (tmp_path / "FILE").write_text("x", encoding="utf-8")
    where = where.replace("FILE", str(tmp_path / "FILE"))
    if where.startswith("/proc") and not Path("/proc").is_dir():
        pytest.skip("no /proc here")
    with pytest.raises(InputError, match="output"):
        next(iter(run_demo(where)))


@pytest.mark.parametrize("scale", [1e-300, 1e-3, 1.0, 1e3, 1e300])
def test_freudenstein_angles_do_not_depend_on_the_scale(scale: float) -> None:
    """The angles of a four-bar depend on its ratios only; at 1e300 they were all NaN, at 1e-300 a ZeroDivisionError."""
    th3, th4, ok = freudenstein_angles(1.0 * scale, 4.0 * scale, 3.0 * scale, 4.0 * scale, _theta())
    ref3, ref4, ref_ok = freudenstein_angles(1.0, 4.0, 3.0, 4.0, _theta())
    assert ok.all() and (ok == ref_ok).all()
    np.testing.assert_allclose(np.c_[th3, th4], np.c_[ref3, ref4], rtol=0, atol=1e-12)
    # the closed loop, checked independently: crank tip to rocker tip is the coupler's length
    b = np.hypot(3 * np.cos(th4) + 4 - np.cos(_theta()), 3 * np.sin(th4) - np.sin(_theta()))
    np.testing.assert_allclose(b, 4.0, rtol=1e-12)


def _cam_program() -> Program:
    return Program([Segment("cycloidal", 2.0, 1.0), Segment("cycloidal", 2.0 * math.pi - 2.0, -1.0)])


def _fab(**kw: object) -> FabSettings:
    return FabSettings(**kw)


def _reason(unit: str) -> str:
    return LEG.run(36).reason(0, angle_unit=unit)


@pytest.mark.parametrize(
    "call,needle",
    [
        # out of range, accepted by the constructors until now
        (lambda: _fab(kerf=-1), "kerf"),
        (lambda: _fab(sheet=(1e300, 1)), "sheet"),
        (lambda: _fab(motor_shaft_mm=1e300), "motor_shaft_mm"),
        (lambda: _fab(hardware="glue"), "hardware"),
        (lambda: part_cuts(LEG.parts[1], _fab(), -1), "number"),
        (lambda: Segment("cycloidal", -1), "angle"),
        (lambda: FollowerGeometry(axis=(0, 0)), "axis"),
        (
            lambda: CamProfile(_cam_program(), 1e-300, FollowerGeometry(roller_radius=0.5)),
            "base_radius",
        ),
        (lambda: SimSettings(blowup_tol=0), "blowup_tol"),
        (lambda: Link("l", ()), "nodes"),
        (lambda: Link("l", ("O", "O")), "nodes"),
        (lambda: Slide("s", "a", "b", (0, 0), (1, 0), (0, 0), (0, 0)), "axis"),
        pytest.param(lambda: _reason("furlong"), "angle_unit", marks=pytest.mark.slow),  # a solve: >= 0.5 s CPU
    ],
)
def test_a_value_out_of_range_is_refused_where_it_is_built(call, needle: str) -> None:
    with pytest.raises(PlanarError) as e:
        call()
    assert needle in str(e.value), str(e.value)


def test_the_fabrication_bounds_are_the_scene_files() -> None:
    """One place for both: a scene with the bound's value loads, FabSettings takes it; just past, both refuse."""
    from planar.core.limits import MAX_MOTOR_MM, MAX_SHEET_MM

    assert _fab(motor_shaft_mm=MAX_MOTOR_MM, sheet=(MAX_SHEET_MM, 1.0)).motor_shaft_mm == MAX_MOTOR_MM
    with pytest.raises(InputError):
        _fab(motor_shaft_mm=MAX_MOTOR_MM * 1.001)
    with pytest.raises(InputError):
        _fab(sheet=(1.0, MAX_SHEET_MM * 1.001))


def _kangaroo():  # type: ignore[no-untyped-def]
    from planar import load_scene

    return load_scene(Path(__file__).parents[1] / "gallery" / "kangaroo-leg.toml")


def _plot(tmp: Path) -> None:
    from planar.draw.charts import write_plot

    write_plot(_kangaroo(), tmp / "x.png", samples_per_cycle=2)


def _render(tmp: Path) -> None:
    from planar.app.pipeline import render_scene

    render_scene(_kangaroo(), tmp / "x.bmp")


def _torque() -> None:
    from planar.analysis.dynamics import inverse_dynamics_torque

    inverse_dynamics_torque(LEG, np.linspace(0.0, 1.0, 5), densities={"crank": -1})


@pytest.mark.parametrize(
    "call,starts",
    [
        # each message names the argument as the Python caller wrote it (not an internal or a command-line name)
        (lambda tmp: LEG.solve(None), "fourbar.solve(q) = None"),
        (lambda tmp: LEG.solve("1.0"), "fourbar.solve(q) = '1.0'"),
        (lambda tmp: __import__("planar").load_scene(None), "load_scene(path) = None: expected a path to a scene file"),
        (lambda tmp: __import__("planar").load_scene(123), "load_scene(path) = 123"),
        (lambda tmp: plan_frames(math.nan, 1), "period_s = nan"),
        (lambda tmp: plan_frames(1, -1), "duration_s = -1"),
        (lambda tmp: plan_frames(1.0, 1.0, fps=60), "fps = 60"),
        pytest.param(_plot, "samples_per_cycle = 2", marks=pytest.mark.slow),  # matplotlib's import
        (_render, "out = "),
        (lambda tmp: synthesise_function([0, 0.5, 1], [0, 0.2]), "psi = '2 output angles': expected one output angle per input"),
        (lambda tmp: __import__("planar.fabrication").fabrication.nest([], (math.nan, 1), 1, 1, 1, 1), "sheet = (nan, 1)"),
        (lambda tmp: _torque(), "densities['crank'] = -1"),
    ],
)
def test_the_message_names_the_python_argument(tmp_path: Path, call, starts: str) -> None:
    with pytest.raises(PlanarError) as e:
        call(tmp_path)
    assert str(e.value).startswith(starts), str(e.value)
    assert not list(tmp_path.iterdir())


# ----------------------------------------------------------------------------- the seventh trial (issue 26)

_TH = np.linspace(0.0, 6.0, 12)


def _simulate(**kw: object) -> None:
    import planar

    planar.simulate(LEG, np.linspace(0.0, 1.0, 5), **kw)  # type: ignore[arg-type]


def _design(name: str) -> None:
    from planar.synth.design import Effector, design_toy

    design_toy([Effector("head", "Oz", 30.0)], name=name, physics=False, place=False)


@pytest.mark.parametrize(
    "call,starts",
    [
        # bad values accepted until now
        (lambda tmp: _simulate(densities={"crank": -1}), "densities['crank'] = -1"),
        (lambda tmp: _simulate(densities={"crank": math.nan}), "densities['crank'] = nan"),
        (lambda tmp: _simulate(densities={"nopart": 1.0}), "densities key = 'nopart'"),
        (  # the one check both take
            lambda tmp: __import__("planar").analysis.inverse_dynamics_torque(LEG, _TH, densities={"nopart": 1.0}),
            "densities key = 'nopart'",
        ),
        (lambda tmp: __import__("planar").analysis.static_foot_loads(-1, [0], [1], [True]), "static_foot_loads(weight) = -1"),
        (lambda tmp: __import__("planar.windup").windup.elemental(2, D_jc=(1e300, 0)), "#2.D_jc = (1e+300, 0.0)"),
        (lambda tmp: LEG.input_values("x"), "fourbar.input_values(q) = 'x'"),
        (lambda tmp: _design("a\x00b"), "name = 'a\\x00b'"),
        # messages naming the argument the caller wrote (not another function's, not a command-line option)
        (lambda tmp: plan_frames(1e-300, 1.0), "period_s = 1e-300"),
        (lambda tmp: LEG.part_rates(_TH, np.ones(3), np.zeros(12)), "fourbar.part_rates(qd) = "),
        (lambda tmp: __import__("planar").analysis.point_velocities(LEG, _TH, qdot="a"), "point_velocities(qdot) = 'a'"),
        (lambda tmp: __import__("planar").analysis.node_velocities(LEG, _TH, qdot="a"), "node_velocities(qdot) = 'a'"),
        (lambda tmp: __import__("planar").synth.load_request(None), "load_request(path) = None"),
        (lambda tmp: _simulate(mode="magic"), "mode = 'magic'"),
        (lambda tmp: __import__("planar").simulate(LEG, []), "t = []"),
        # an export with two outputs naming one file, or none at all
        (lambda tmp: __import__("planar.app").app.export_mechanism(LEG), "dxf, svg, ... = None"),
        (
            lambda tmp: __import__("planar").export(LEG, "x.dxf", svg="x.svg", assembly="./x.svg"),
            "assembly = './x.svg': expected a different file from svg",
        ),
        # numbers float64 cannot square, refused where they enter (they overflowed with a printed warning)
        (lambda tmp: __import__("planar").synth.burmester(np.array([[0, 0, 0], [1e300, 0.2, 0.2], [2, 0.1, 0.4]])), "poses = "),
    ],
)
def test_the_seventh_trial_call_raises_a_named_input_error(tmp_path: Path, monkeypatch, call, starts: str) -> None:
    monkeypatch.chdir(tmp_path)  # outputs named relative to it
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no numpy RuntimeWarning on the way to the refusal
        with pytest.raises(InputError) as e:
            call(tmp_path)
    assert str(e.value).startswith(starts), str(e.value)
    assert not list(tmp_path.iterdir())


def test_a_request_that_is_not_toml_is_named_once(tmp_path: Path) -> None:
    from planar.synth import load_request

    (tmp_path / "targets.csv").write_text("x,y\n0,1\n", encoding="utf-8")
    with pytest.raises(InputError) as e:
        load_request(tmp_path / "targets.csv")
    assert str(e.value).count("targets.csv") == 1 and "not TOML" in str(e.value), str(e.value)


def test_a_refusal_without_a_stage_keeps_its_reason() -> None:
    """design_toy's list of trees the assembly refused dropped a reason naming no stage ("(it would ))")."""
    from planar.synth.design.pipeline import _reasons

    assert "Mechanism.name = 'x': expected y" in _reasons(["Mechanism.name = 'x': expected y"])


def test_instant_centre_beyond_float64_is_invalid_and_quiet() -> None:
    from planar.analysis import instant_centre

    big = [[1e300, 0.0]], [[1e300, 0.0]], [[0.0, 1e300]], [[0.0, 1e300]]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        centre, omega, ok = instant_centre(*big)
    assert np.isfinite(centre).all() and np.isfinite(omega).all() and not ok.any()
    # the same bodies at a size float64 holds: the lines x = 1 and y = 1 meet at (1, 1), omega = 1
    centre, omega, ok = instant_centre([[1.0, 0.0]], [[1.0, 0.0]], [[0.0, 1.0]], [[0.0, 1.0]])
    assert ok.all() and np.allclose(centre, [[1.0, 1.0]]) and np.allclose(omega, [1.0])


@pytest.mark.parametrize("name", ["a,b", 'say "hi"'])
def test_a_mechanism_name_a_scene_cannot_hold_still_gets_its_motion_table(tmp_path: Path, name: str) -> None:
    """contract.md: from Python a name with a comma is accepted; the mechanism's name is in no column."""
    import csv

    from planar.app.pipeline import write_mechanism_motion

    named = FourBar(4.0, 1.0, 4.0, 3.0, coupler_point=(5.5, -2.0), name=name)
    write_mechanism_motion(named, tmp_path / "a.csv", driver={"samples_per_cycle": 6})
    write_mechanism_motion(LEG, tmp_path / "b.csv", driver={"samples_per_cycle": 6})
    a, b = (list(csv.reader((tmp_path / f).open(encoding="utf-8"))) for f in ("a.csv", "b.csv"))
    assert a == b and len(a) == 7


def test_the_export_docstring_says_where_the_steps_go() -> None:
    import planar

    assert "st-1.svg" in (planar.export.__doc__ or "") and "no ``st.svg``" in (planar.export.__doc__ or "")
