"""Issue 13: the public Python API under bad input, at extreme scales, and one validity rule.

Bad input raises a :class:`planar.errors.PlanarError` that is also a
``ValueError``, with a message naming the argument.  Results are checked
against a second method where one exists (circle-circle geometry by hand,
finite differences of positions for velocities and power).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from planar.analysis import statics as analysis
from planar.errors import InputError, LimitError, PlanarError
from planar.linkages import FourBar, SliderCrank
from planar.windup import elemental
from planar.windup.chain import ToyMechanism

TH = np.linspace(0.0, 2 * np.pi, 360, endpoint=False)


@pytest.fixture(scope="module")
def leg() -> FourBar:
    return FourBar(4.0, 1.0, 4.0, 3.0, coupler_point=(5.5, -2.0))


@pytest.mark.parametrize(
    "call,needle",
    [
        (lambda m: m.solve(np.zeros((4, 2))), "solve(q)"),
        (lambda m: m.solve(np.zeros((3, 3))), "solve(q)"),
        (lambda m: m.solve(np.zeros(4), t=np.zeros(5)), "solve(t)"),
        (lambda m: m.solve(np.zeros(4), t=np.zeros((4, 1))), "solve(t)"),
        (lambda m: m.solve([0.0, math.nan]), "solve(q)"),
        (lambda m: m.solve(["a"]), "solve(q)"),
        (lambda m: m.run(cycles=math.nan), "cycles"),
        (lambda m: m.run(cycles=-1.0), "cycles"),
        (lambda m: m.run(cycles=1e308), "PLANAR_MAX_SAMPLES"),
        (lambda m: m.run(samples_per_cycle=0), "samples_per_cycle"),
        (lambda m: m.run(samples_per_cycle=math.inf), "samples_per_cycle"),
        (lambda m: FourBar(4, 1, 4, 3, coupler_point=5.5), "coupler_point"),
        (lambda m: FourBar(4, 1, 4, 3, coupler_point=(1.0, 2.0, 3.0)), "coupler_point"),
        (lambda m: FourBar(4, 1, 4, 3, coupler_point=("a", 1.0)), "coupler_point"),
        (lambda m: FourBar(4, 1, 4, 3, coupler_point=(math.nan, 1.0)), "coupler_point"),
        (lambda m: FourBar(4, "x", 4, 3), "crank"),
        (lambda m: FourBar(4, 1, 4, 3, placement=(0.0, 0.0)), "placement"),
        (lambda m: SliderCrank(1.0, 3.0, branch=2), "branch"),
        (lambda m: elemental(5.0), "mechanism"),
        (lambda m: elemental("5"), "mechanism"),
        (lambda m: elemental(1, D_jc=0.5), "D_jc"),
        (lambda m: elemental(1, D_o=[0.0]), "D_o"),
        (lambda m: elemental(1, F_o=(0.3, 0.0, 0.0, 0.0)), "F_o"),
        (lambda m: elemental(1, D_jr=(0.1, 0.2)), "D_jr"),
        (lambda m: elemental(1, D_jr=math.nan), "D_jr"),
        (lambda m: elemental(1, D_jr=True), "D_jr"),
        (lambda m: elemental(10, D_theta=(0.3,)), "D_theta"),
        (lambda m: ToyMechanism({"left": [("Rz->Tx",)]}, phase=math.nan), "phase"),
        (lambda m: ToyMechanism({"left": [("Rz->Tx", "Oz->Ox")]}), "left[0][1]"),
        (lambda m: analysis.motor_torque(m, TH, {"coupler_point": [math.nan, 1.0]}), "coupler_point"),
        (lambda m: analysis.motor_torque(m, TH, {"coupler_point": np.zeros((3, 2))}), "coupler_point"),
        (lambda m: analysis.motor_torque(m, TH, {"coupler_point": [0.0, 1.0]}, eta_trans=math.nan), "eta_trans"),
        (lambda m: analysis.virtual_work_torque(np.zeros((5, 1, 2)), np.zeros(4), [0.0, 1.0]), "points"),
    ],
)
def test_bad_input_raises_a_named_planar_error(leg: FourBar, call, needle: str) -> None:
    with pytest.raises(PlanarError) as info:
        call(leg)
    assert isinstance(info.value, ValueError)
    assert needle in str(info.value)
    assert "\n" not in str(info.value)


@pytest.mark.parametrize("number", [1, 10])
def test_solve_takes_one_driver_value_per_sample(number: int) -> None:
    mech = elemental(number)
    for shape in ((4, 3), (4, 1), (2, 2, 2)):
        with pytest.raises(InputError, match="1-D array"):
            mech.solve(np.zeros(shape))
    m = mech.solve(np.linspace(0.0, 1.0, 4))
    assert {v.shape[0] for v in m.poses.values()} == {4}


def test_long_values_are_summarised_in_messages(leg: FourBar) -> None:
    with pytest.raises(InputError) as info:
        leg.solve(np.r_[np.zeros(1000), math.nan])
    assert len(str(info.value)) < 200


def test_limit_error_is_an_input_error(leg: FourBar, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("PLANAR_MAX_SAMPLES", "100")
    with pytest.raises(LimitError, match="PLANAR_MAX_SAMPLES"):
        leg.run(samples_per_cycle=101)
    assert len(leg.run(samples_per_cycle=100)) == 100


@pytest.mark.filterwarnings("ignore::RuntimeWarning")  # squares overflow in passing; the results are exact
@pytest.mark.parametrize("scale", [1e-300, 1e-170, 1e-80, 1e80, 1e154, 1e200, 1e300])
def test_fourbar_at_any_scale_is_the_scaled_unit_fourbar(leg: FourBar, scale: float) -> None:
    big = FourBar(4.0 * scale, 1.0 * scale, 4.0 * scale, 3.0 * scale, coupler_point=(5.5 * scale, -2.0 * scale))
    m, ref = big.solve(TH), leg.solve(TH)
    assert m.valid.all() and ref.valid.all()
    np.testing.assert_allclose(m.points["coupler_point"] / scale, ref.points["coupler_point"], rtol=0, atol=1e-12)
    for part in ("crank", "coupler", "rocker"):
        np.testing.assert_allclose(m.poses[part][:, 2], ref.poses[part][:, 2], atol=1e-12)


def test_nothing_non_finite_is_valid() -> None:
    """Elemental parameters near the float64 limit: samples are finite, or marked invalid with a reason."""
    for number, kw in ((1, {"F_o": (1e308, 0.0)}), (2, {"D_jr": 1e300}), (7, {"D_jc": (1e308, 1e308)})):
        try:  # refused (at construction, or at the solve: a placement float64 cannot resolve) is fine too
            with np.errstate(all="ignore"):
                m = elemental(number, **kw).run(36)
        except PlanarError:
            continue
        for arr in (*m.poses.values(), *m.points.values()):
            assert np.isfinite(arr).all()


def test_one_validity_rule_for_velocities_and_instant_centres() -> None:
    """A double-rocker: outside its range nothing is valid, at a toggle nothing is valid, and where valid
    the rocker speed agrees with finite differences of the solved rocker angle (a second method)."""
    dr = FourBar(4.0, 3.0, 1.2, 2.5)
    m = dr.solve(TH)
    assert 0 < m.valid.sum() < len(TH)
    w3, w4, ok = analysis.fourbar_velocities(dr, TH)
    _, w_ic, ok_ic = analysis.fourbar_instant_centre(dr, TH)
    assert not (ok & ~m.valid).any() and not (ok_ic & ~m.valid).any()
    assert (w3[~ok] == 0).all() and (w_ic[~ok_ic] == 0).all()
    np.testing.assert_allclose(w_ic[ok_ic], w3[ok_ic], rtol=1e-9, atol=1e-9)
    toggles = dr.toggle_angles()
    _, _, at_toggle = analysis.fourbar_velocities(dr, toggles)
    assert not at_toggle.any()
    # the same rule through the general linkage path (node velocities, motor torque), toggles included
    q = np.sort(np.r_[TH, toggles, toggles + 1e-9, toggles - 1e-9])
    _, _, ok_fb = analysis.fourbar_velocities(dr, q)
    tau, ok_tau = analysis.motor_torque(dr, q, {"coupler_point": [0.0, 1.0]})
    assert (ok_fb == ok_tau).all() and np.isfinite(tau).all() and (tau[~ok_tau] == 0).all()
    # where valid: central differences of the solved rocker angle, a step of 1e-6 either side
    h = 1e-6
    up, down = dr.solve(TH + h), dr.solve(TH - h)
    both = ok & up.valid & down.valid
    d = np.angle(np.exp(1j * (up.poses["rocker"][:, 2] - down.poses["rocker"][:, 2])))
    fd = d / (2 * h)
    assert both.sum() > 50
    assert np.all(np.abs(fd[both] - w4[both]) <= 1e-5 * (1 + np.abs(w4[both])))


def test_virtual_work_torque_has_a_validity_mask() -> None:
    dr = FourBar(4.0, 3.0, 1.2, 2.5)
    m = dr.solve(TH)
    tau, ok = analysis.virtual_work_torque(m.points["coupler_point"][:, None, :], TH, [0.0, -1.0], valid=m.valid)
    assert ok.any() and not (ok & ~m.valid).any()
    assert (tau[~ok] == 0).all() and np.isfinite(tau).all()


def test_regenerative_samples_multiply_by_the_efficiency(leg: FourBar) -> None:
    """Power by finite differences of the foot's path (a second method): where the load takes power the motor
    supplies it over the efficiency; where the load gives power back the motor receives it times the efficiency."""
    F = np.array([0.0, 10.0])
    eta = 0.8 * 0.9
    tau, ok = analysis.motor_torque(leg, TH, {"coupler_point": F}, eta_trans=0.8, eta_link=0.9)
    foot = leg.solve(TH).points["coupler_point"]
    step = TH[1] - TH[0]
    p = ((np.roll(foot, -1, 0) - np.roll(foot, 1, 0)) / (2 * step) * F).sum(-1)  # power per unit crank speed
    assert ok.all() and (p > 0).any() and (p < 0).any()
    expect = np.where(p >= 0, p / eta, p * eta)
    assert np.abs(tau - expect).max() < 1e-3 * np.abs(expect).max()
    assert tau.min() == pytest.approx(-5.5776, abs=1e-3)  # the README example: no longer -10.76


def test_slider_position_honours_branch() -> None:
    for branch in (1, -1):
        sc = SliderCrank(1.0, 3.0, offset=0.5, branch=branch)
        m = sc.solve(TH)
        np.testing.assert_allclose(sc.slider_position(TH), m.points["slider_pin"][:, 0], atol=1e-12)
    assert SliderCrank(1.0, 3.0, branch=-1).slider_position(np.pi / 2) == pytest.approx(-math.sqrt(8.0))


# ----------------------------------------------------------------------------- issue 26: the entrances


def _motion():
    leg = FourBar(4.0, 1.0, 4.0, 3.0, coupler_point=(5.5, -2.0))
    return leg.solve(np.linspace(0.0, 1.0, 5))


@pytest.mark.parametrize(
    "call,needle",
    [
        (lambda: __import__("planar").Driver("a", phase=math.nan), "driver.phase"),
        (lambda: __import__("planar").Driver("a", kind="translation", axis=(0, 0), amplitude=1.0), "driver.axis"),
        (lambda: __import__("planar").Driver("a", axis=(1.0, 2.0, 3.0)), "driver.axis"),
        (lambda: __import__("planar").Driver("a", origin=(math.inf, 0.0)), "driver.origin"),
        (lambda: __import__("planar").Driver("a", amplitude=math.nan), "driver.amplitude"),
        (lambda: __import__("planar").Driver("a", centre="0"), "driver.centre"),
        (lambda: __import__("planar").Driver(5), "driver.part"),
        (lambda: __import__("planar").Driver("a", rate="1"), "driver.rate"),
        (lambda: __import__("planar").Part("p", hull=((math.nan, 0, 1),)), "hull"),
        (lambda: __import__("planar").Part("p", hull=((0, 0, -1),)), "hull"),
        (lambda: __import__("planar").Part("p", hull=((0, 0),)), "hull"),
        (lambda: __import__("planar").Part("p", hull="abc"), "hull"),
        (lambda: __import__("planar").Part("", hull=()), "Part.name"),
        (lambda: __import__("planar").Part("p", hull=((0, 0, 1),), plane="xw"), "plane"),
        (lambda: __import__("planar").Part("p", hull=((0, 0, 1),), offset=math.nan), "offset"),
        (lambda: __import__("planar").Part("p", hull=(), polygon=((0, 0), (1, math.nan), (0, 1))), "polygon"),
        (lambda: __import__("planar").Mechanism("m", "abc", [], __import__("planar").Driver("a")), "m.parts"),
        (lambda: __import__("planar").Mechanism("m", [], [], "a"), "m.driver"),
        (lambda: __import__("planar").Mechanism("m", [], [1], __import__("planar").Driver("a")), "m.joints"),
        (lambda: __import__("planar").Mechanism(None, [], [], __import__("planar").Driver("a")), "Mechanism.name"),
        (lambda: _motion().take([99]), "take"),
        (lambda: _motion().take([-6]), "take"),
        (lambda: _motion().take("a"), "take"),
        (lambda: _motion().take([0.5]), "take"),
        (lambda: _motion().take(np.ones(3, bool)), "take"),
        (lambda: FourBar(4, 1, 4, 3).solve("1.0"), "solve(q)"),
        (lambda: FourBar(4, 1, 4, 3).solve([True, False]), "solve(q)"),
        (lambda: FourBar(4, 1, 4, 3).solve([0.0, 1.0], t=[math.nan, 0.0]), "solve(t)"),
        (lambda: FourBar(4, 1, 4, 3).solve([0.0, 1.0], t=["a", "b"]), "solve(t)"),
        (lambda: FourBar(4, 1, 4, 3).run(samples_per_cycle="36"), "samples_per_cycle"),
        (lambda: FourBar(4, 1, 4, 3).run(cycles="1"), "cycles"),
        (lambda: FourBar(4, 1, 4, 3).run(samples_per_cycle=True), "samples_per_cycle"),
    ],
)
def test_entrances_raise_a_named_planar_error(call, needle: str) -> None:
    with pytest.raises(PlanarError) as info:
        call()
    assert isinstance(info.value, ValueError) and needle in str(info.value) and "\n" not in str(info.value)


def test_geared_ratio_and_mesh_are_checked() -> None:
    from planar.linkages.gears import Geared

    for kw, needle in (({"ratio": "-1"}, "ratio"), ({"ratio": 1.0}, "negative"), ({"mesh": "B"}, "itself")):
        args = {"name": "B", "centre": "O", "radius": 1.0, "mesh": "A", "ratio": -1.0, **kw}
        with pytest.raises(PlanarError, match=needle):
            Geared(**args).validate("B")


@pytest.mark.parametrize(
    "phi,psi,ground,needle",
    [
        ([0.0, math.nan, 1.0], [0.0, 1.0, 2.0], 1.0, "phi"),  # the Python arguments' names
        ([0.0, 0.5, 1.0], [0.0, math.inf, 2.0], 1.0, "psi"),
        ([0.0, 0.5, 1.0], [0.0, 1.0, 2.0], 1e300, "ground"),
        ([0.0, 0.5, 1.0], [0.0, 1.0, 2.0], "1", "ground"),
        (["a", 0.5, 1.0], [0.0, 1.0, 2.0], 1.0, "phi"),
    ],
)
def test_synthesise_function_entrance(phi, psi, ground, needle: str) -> None:
    from planar.synth.function import synthesise_function

    with pytest.raises(PlanarError, match=needle):
        synthesise_function(phi, psi, ground)


def test_export_checks_that_the_suffix_names_the_format(tmp_path) -> None:
    """``export_mechanism(leg, "x.svg")`` wrote DXF bytes into x.svg; now refused, nothing written."""
    from planar.app.pipeline import export_mechanism

    leg = FourBar(4.0, 1.0, 4.0, 3.0, coupler_point=(5.5, -2.0))
    for kw in ({"dxf": tmp_path / "x.svg"}, {"svg": tmp_path / "x.dxf"}, {"bom": tmp_path / "b.txt"}):
        with pytest.raises(InputError, match="ending in"):
            export_mechanism(leg, fabrication={"unit_mm": 15.0}, **kw)
    assert list(tmp_path.iterdir()) == []


def test_check_scale_refuses_coarse_placements() -> None:
    from planar.core.limits import check_scale

    check_scale("leg", FourBar(4.0, 1.0, 4.0, 3.0, placement=(0.0, 1e5, 0.0)))
    for place in ((0.0, 1e16, 0.0), (1e308, 0.0, 0.0)):
        with pytest.raises(InputError, match="float64"):
            check_scale("leg", FourBar(4.0, 1.0, 4.0, 3.0, placement=place))


def _leg() -> FourBar:
    return FourBar(4.0, 1.0, 4.0, 3.0, coupler_point=(5.5, -2.0))


@pytest.mark.parametrize(
    "call,needle",
    [
        (lambda p: __import__("planar").render(5, p / "r.gif"), "obj"),
        (lambda p: __import__("planar").render(None, p / "r.gif"), "obj"),
        (lambda p: __import__("planar").export("x", p / "e.dxf"), "obj"),
        (lambda p: __import__("planar").compare(5), "obj"),
        (lambda p: __import__("planar").scene_from_mechanism(None), "mech"),
        (lambda p: __import__("planar").render(_leg(), p / "r.gif", bogus={}), "bogus"),
        (lambda p: __import__("planar").compare(_leg(), bogus={}), "bogus"),
        (lambda p: __import__("planar").scene_from_mechanism(_leg(), foo={}), "foo"),
        (lambda p: __import__("planar").render(_leg(), p / "r.gif", render="x"), "render"),
        (lambda p: __import__("planar").export(_leg(), p / "e.dxf", fabrication="x"), "fabrication"),
        (lambda p: __import__("planar").export(_leg(), p / "e.dxf", bogus=p / "x.csv"), "bogus"),
        (lambda p: __import__("planar").render(_leg(), None), "out"),
        (lambda p: __import__("planar").render(_leg(), p / "r.gif", fps="25"), "fps"),
        (lambda p: __import__("planar").compare(_leg(), settings="x"), "settings"),
        (lambda p: __import__("planar").compare(_leg(), threshold="0.1"), "threshold"),
        (lambda p: __import__("planar").compare(_leg(), threshold=math.nan), "threshold = nan"),
        (lambda p: __import__("planar").compare(_leg(), torque_threshold=math.nan), "torque_threshold"),
        (lambda p: __import__("planar").compare(_leg(), torque_threshold=-1), "torque_threshold"),
        (lambda p: __import__("planar").compare(_leg(), torque_threshold=math.inf), "torque_threshold"),
        (lambda p: __import__("planar").SimSettings(substeps=math.nan), "substeps"),
        (lambda p: __import__("planar").SimSettings(iterations=2.5), "iterations"),
        (lambda p: __import__("planar").SimSettings(blowup_tol=math.inf), "blowup_tol"),
        (lambda p: _motion().take([[0]]), "take"),
        (lambda p: _motion().reason(99), "reason"),
        (lambda p: _motion().reason("x"), "reason"),
        (lambda p: __import__("planar").Mechanism("m", 5, [], __import__("planar").Driver("a")), "m.parts"),
        (lambda p: __import__("planar").Mechanism("m", [], [], __import__("planar").Driver("crank")), "driver.part"),
        (
            lambda p: __import__("planar").Mechanism("m", _leg().parts, _leg().joints, __import__("planar").Driver("nope")),
            "driver.part",
        ),
    ],
)
def test_api_entrances_of_the_second_trial(tmp_path, call, needle: str) -> None:
    """Each raised a raw TypeError/AttributeError/IndexError or was accepted; nothing is written."""
    with pytest.raises(PlanarError) as info:
        call(tmp_path)
    assert isinstance(info.value, ValueError) and needle in str(info.value) and "\n" not in str(info.value)
    assert not list(tmp_path.iterdir())


def test_a_bare_mechanism_says_why_it_cannot_solve() -> None:
    import planar

    leg = _leg()
    with pytest.raises(PlanarError, match="no solver"):
        planar.Mechanism("m", leg.parts, leg.joints, leg.driver).solve([0.0])


@pytest.mark.parametrize(
    "call,needle",
    [
        (lambda: FourBar(4, 1, 4, 3, name="a\x00b"), "name"),
        (lambda: __import__("planar").Part("a\nb", hull=((0, 0, 1),)), "Part.name"),
        (lambda: __import__("planar").Part("p", hull=()), "hull"),
        (lambda: __import__("planar").Part("p", hull=((0, 0, 1),), ground="yes"), "ground"),
        (lambda: __import__("planar").Driver("crank", amplitude=-1), "amplitude"),
        (lambda: __import__("planar").Link("l", "OA"), "nodes"),
        (lambda: __import__("planar").Fixed("O", (math.nan, 0)), "xy"),
        (lambda: __import__("planar.linkages.gears").linkages.gears.Geared("B", "O", 1.0, mesh="A", ratio=math.nan), "ratio"),
        (lambda: __import__("planar.linkages.gears").linkages.gears.Geared("B", "O", 1.0, mesh="A", ratio=1.0), "ratio"),
    ],
)
def test_constructors_refuse_at_once(call, needle: str) -> None:
    with pytest.raises(PlanarError) as info:
        call()
    assert needle in str(info.value) and "\n" not in str(info.value)


@pytest.mark.parametrize(
    "call,needle",
    [
        (lambda p: __import__("planar").export(_leg(), p / "e.dxf", steps=p / "s.png"), "steps"),
        (lambda p: __import__("planar").export(_leg(), p / "e.dxf", plan=p / "p.txt"), "plan"),
        (lambda p: __import__("planar").export(_leg(), p / "e.dxf", motion=p / "m.txt"), "motion"),
        (lambda p: __import__("planar").export(_leg()), "an output"),
        (lambda p: __import__("planar").scene_from_mechanism(_leg()).save(p / "s.csv"), ".toml"),
    ],
)
def test_python_writers_check_the_suffix(tmp_path, call, needle: str) -> None:
    """SVG went into s.png, TOML into s.csv; an export with no output returned silently."""
    with pytest.raises(PlanarError, match=needle):
        call(tmp_path)
    assert not list(tmp_path.iterdir())


@pytest.mark.parametrize("spc", [3, 2.5, np.float64(36.0)])
def test_run_takes_a_whole_number_of_at_least_four_samples(spc) -> None:
    with pytest.raises(InputError, match="samples_per_cycle"):
        _leg().run(samples_per_cycle=spc)


@pytest.mark.parametrize("q", [[0.0], np.zeros(3)])
def test_a_placement_float64_cannot_resolve_is_refused_from_python(q) -> None:
    """As a scene's: at 1e17 float64 spaces numbers 16 apart, coarser than the links themselves."""
    with pytest.raises(InputError, match="placement"):
        FourBar(4.0, 1.0, 4.0, 3.0, placement=(1e17, 0.0, 0.0)).solve(q)
    assert FourBar(4e200, 1e200, 4e200, 3e200).solve(q).valid.all()  # any size still solves, scaled


def test_size_for_range_far_out_warns_nothing() -> None:
    import warnings

    from planar.windup.sizing import size_for_range

    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the overflow of a product of two differences was a RuntimeWarning
        with pytest.raises(InputError, match="target"):
            size_for_range(1, 1e300)


@pytest.mark.parametrize("kw,needle", [({"out": "r.txt"}, "out = "), ({"fps": 1e9}, "fps = ")])
def test_render_names_the_python_argument(tmp_path, kw, needle: str) -> None:
    import planar

    args = {"out": "r.gif", **kw}
    with pytest.raises(InputError) as info:
        planar.render(_leg(), tmp_path / args.pop("out"), **args)
    assert str(info.value).startswith(needle) and "--fps" not in str(info.value)
    assert not list(tmp_path.iterdir())
