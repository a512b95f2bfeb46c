"""Four-bar and slider-crank: closed forms cross-checked, circuits, limits, bad input."""

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st
from scipy.optimize import fsolve

from planar import AssemblyError, InputError
from planar.core.geometry import wrap_angle
from planar.linkages import FourBar, SliderCrank, grashof_class

length = st.floats(0.2, 10.0)


def _numeric_fourbar(a, b, c, d, theta, guess):
    """Independent solution: Newton on the loop-closure equations."""

    def f(x):
        t3, t4 = x
        return [a * np.cos(theta) + b * np.cos(t3) - c * np.cos(t4) - d, a * np.sin(theta) + b * np.sin(t3) - c * np.sin(t4)]

    return fsolve(f, guess, xtol=1e-13)


@pytest.mark.parametrize("circuit", ["open", "crossed"])
def test_closed_form_matches_numerical_loop_closure(circuit):
    fb = FourBar(4.0, 1.0, 4.0, 3.0, coupler_point=(2.0, 1.0), circuit=circuit)
    th = np.linspace(0, 2 * np.pi, 73)
    m = fb.solve(th)
    t3 = m.poses["coupler"][:, 2]
    t4 = m.poses["rocker"][:, 2]
    for i in range(0, 73, 6):
        n3, n4 = _numeric_fourbar(1.0, 4.0, 3.0, 4.0, th[i], [t3[i] + 0.05, t4[i] - 0.05])
        assert abs(wrap_angle(n3 - t3[i])) < 1e-9
        assert abs(wrap_angle(n4 - t4[i])) < 1e-9


@given(length, length, length, length, st.sampled_from(["open", "crossed"]))
@example(0.2, 0.2, 0.20000000000000004, 0.2, "open")  # found by hypothesis: r1^2 - r2^2 cancelled (now (r1-r2)(r1+r2))
@settings(max_examples=60, deadline=None)
def test_half_angle_agrees_with_circle_circle(a, b, c, d, circuit):
    if max(a, b, c, d) >= (a + b + c + d) - max(a, b, c, d):
        with pytest.raises(InputError):
            FourBar(d, a, b, c, circuit=circuit)
        return
    try:
        fb = FourBar(d, a, b, c, coupler_point=(0.3, 0.2), circuit=circuit)
    except AssemblyError:
        return
    th = np.linspace(0, 2 * np.pi, 181)
    # a scattered batch (not a path) keeps the declared circuit at every sample, as the half-angle
    # form does; along a path a change-point linkage would carry its branch through the flat positions
    order = np.random.default_rng(0).permutation(th.size)
    m_shuffled = fb.solve(th[order])
    inv = np.argsort(order)
    m = type(m_shuffled)(
        th,
        {k: v[inv] for k, v in m_shuffled.poses.items()},
        m_shuffled.valid[inv],
        m_shuffled.fail_code[inv],
        m_shuffled.fail_table,
    )
    t3, t4, ok = fb.angles(th)
    # away from the toggle positions both methods agree tightly
    mu = fb.transmission_angle(th)
    good = m.valid & ok & (np.sin(mu) > 1e-3)
    assert np.array_equal(m.valid[np.sin(mu) > 1e-3], ok[np.sin(mu) > 1e-3])
    scale = max(a, b, c, d)
    assert np.all(np.abs(wrap_angle(t3 - m.poses["coupler"][:, 2]))[good] < 1e-8 * scale / min(a, b, c, d) / np.sin(mu[good]))
    assert np.all(np.abs(wrap_angle(t4 - m.poses["rocker"][:, 2]))[good] < 1e-8 * scale / min(a, b, c, d) / np.sin(mu[good]))


@pytest.mark.parametrize(
    "dims,expected",
    [
        ((1, 4, 3, 4), "crank-rocker"),
        ((3, 3.5, 3.2, 1), "double-crank"),
        ((3, 1, 3.2, 3.5), "double-rocker"),
        ((3, 3.5, 1, 3.2), "rocker-crank"),
        ((2, 2, 2, 2), "change-point"),
        ((1, 3, 2, 4), "change-point"),
        ((3, 3, 3, 4.5), "non-Grashof"),
    ],
)
def test_grashof_classes(dims, expected):
    assert grashof_class(*dims) == expected


def test_crank_rocker_turns_fully_and_keeps_its_circuit():
    fb = FourBar(4.0, 1.0, 4.0, 3.0)
    assert fb.input_range() == [(0.0, 2 * np.pi)]
    assert fb.toggle_angles().size == 0
    th = np.linspace(0, 2 * np.pi, 20001)
    m = fb.solve(th)
    assert m.valid.all()
    # branch continuity: consecutive samples move by at most a Lipschitz step
    step = np.hypot(*np.diff(m.points["coupler_point"], axis=0).T)
    assert step.max() < 10 * (th[1] - th[0]) * fb.size
    # the circuit never flips: C stays left of B -> O4
    pos, _ = fb.solve_nodes(th)
    B, C, O4 = pos["B"], pos["C"], pos["O4"]
    side = (O4 - B)[:, 0] * (C - B)[:, 1] - (O4 - B)[:, 1] * (C - B)[:, 0]
    assert np.all(side > 0)
    # the coupler returns to its start after a revolution
    assert np.allclose(m.poses["coupler"][0], m.poses["coupler"][-1], atol=1e-12)


def test_non_grashof_toggles_and_invalid_samples_with_reasons():
    fb = FourBar(4.5, 3.0, 3.0, 3.0)  # non-Grashof triple rocker
    assert fb.grashof == "non-Grashof"
    ranges = fb.input_range()
    assert len(ranges) == 1
    lo, hi = ranges[0]
    # at the toggle angles coupler and rocker are in line: |B - O4| = b + c
    for t in fb.toggle_angles():
        B = 3.0 * np.array([np.cos(t), np.sin(t)])
        assert abs(np.hypot(*(B - [4.5, 0])) - 6.0) < 1e-9
    th = np.linspace(-np.pi, np.pi, 3601)
    m = fb.solve(th)
    inside = (th > lo + 1e-9) & (th < hi - 1e-9)
    outside = (th < lo - 1e-9) | (th > hi + 1e-9)
    assert m.valid[inside].all() and not m.valid[outside].any()
    assert m.failed_joints == {"C"}
    i = int(np.flatnonzero(~m.valid)[0])
    assert "'C'" in m.reason(i) and "cannot" in m.reason(i)
    assert all(np.isfinite(p).all() for p in m.poses.values())
    # driven exactly to the toggle the solution stays valid and finite
    mt = fb.solve(fb.toggle_angles())
    assert mt.valid.all()


def test_change_point_passes_the_flat_position():
    fb = FourBar(2.0, 1.0, 2.0, 1.0)  # parallelogram: change point
    assert fb.grashof == "change-point"
    th = np.linspace(0, 2 * np.pi, 7201)
    m = fb.solve(th)
    assert m.valid.all()
    assert all(np.isfinite(p).all() for p in m.poses.values())


@pytest.mark.parametrize(
    "kw,field",
    [
        ({"ground": 4, "crank": -1, "coupler": 4, "rocker": 3}, "crank"),
        ({"ground": 4, "crank": 0, "coupler": 4, "rocker": 3}, "crank"),
        ({"ground": 4, "crank": float("nan"), "coupler": 4, "rocker": 3}, "crank"),
        ({"ground": 10, "crank": 1, "coupler": 2, "rocker": 3}, "links"),
        ({"ground": 4, "crank": 1, "coupler": 4, "rocker": 3, "circuit": "sideways"}, "circuit"),
    ],
)
def test_bad_dimensions_are_named(kw, field):
    with pytest.raises(InputError) as e:
        FourBar(**kw)
    assert field in str(e.value)


def test_nan_driver_value_rejected():
    with pytest.raises(InputError):
        FourBar(4, 1, 4, 3).solve([0.0, float("nan")])


def test_placement_moves_everything_rigidly():
    a = FourBar(4.0, 1.0, 4.0, 3.0, coupler_point=(2, 1))
    b = FourBar(4.0, 1.0, 4.0, 3.0, coupler_point=(2, 1), placement=(1.0, 2.0, 0.5))
    th = np.linspace(0, 2 * np.pi, 50)
    pa, pb = a.solve(th).points["coupler_point"], b.solve(th).points["coupler_point"]
    c, s = np.cos(0.5), np.sin(0.5)
    expected = pa @ np.array([[c, s], [-s, c]]) + [1.0, 2.0]
    np.testing.assert_allclose(pb, expected, atol=1e-12)


def test_coupler_pose_sweeps_a_foot_polygon():
    from planar.core.geometry import poses_apply

    fb = FourBar(4.0, 1.0, 4.0, 3.0, coupler_point=(2.0, 1.0))
    th = np.linspace(0, 2 * np.pi, 90)
    m = fb.solve(th)
    foot = np.array([[2.0, 1.0], [2.6, 1.0], [2.6, 1.2], [2.0, 1.2]])  # in the coupler frame
    swept = poses_apply(m.poses["coupler"], foot)
    assert swept.shape == (90, 4, 2)
    # vertex 0 is the coupler point; the foot keeps its shape at every pose
    np.testing.assert_allclose(swept[:, 0], m.points["coupler_point"], atol=1e-12)
    np.testing.assert_allclose(np.hypot(*(swept[:, 1] - swept[:, 0]).T), 0.6, atol=1e-12)


def test_slider_crank_matches_textbook_formula():
    for e in (0.0, 0.4, -0.7):
        sc = SliderCrank(1.0, 3.0, offset=e)
        th = np.linspace(0, 2 * np.pi, 721)
        m = sc.solve(th)
        assert m.valid.all()
        np.testing.assert_allclose(m.points["slider_pin"][:, 0], sc.slider_position(th), atol=1e-12)
        np.testing.assert_allclose(m.points["slider_pin"][:, 1], e, atol=1e-12)
        # the slider block never rotates
        np.testing.assert_allclose(m.poses["slider"][:, 2], m.poses["slider"][0, 2], atol=1e-15)


def test_slider_crank_that_cannot_reach_the_guide():
    with pytest.raises(InputError, match="offset"):
        SliderCrank(1.0, 1.0, offset=3.0)
    sc = SliderCrank(1.0, 1.0, offset=1.5)  # reaches only near the top
    m = sc.solve(np.linspace(0, 2 * np.pi, 361))
    assert m.valid.any() and not m.valid.all()
    assert "S" in m.failed_joints


def _lead_steps_loop(h, h_max, span):
    """The lead-in's steps sample by sample (the recurrence the vectorised lead-in must reproduce)."""
    steps, step, total = [], h, 0.0
    while total < span and len(steps) < 4096:
        step = min(step * 1.4, h_max) if steps else h
        steps.append(step)
        total += step
    return np.cumsum(steps)[::-1]


def test_vectorised_lead_in_is_the_recurrence_bit_for_bit():
    from planar.linkages.linkage import _lead_steps

    rng = np.random.default_rng(11)
    for _ in range(3000):
        h = 10 ** rng.uniform(-9, 0)
        h_max = h if rng.random() < 0.1 else max(h, 10 ** rng.uniform(-4, 0.5))
        span = 10 ** rng.uniform(-10, 3)
        want, got = _lead_steps_loop(h, h_max, span), _lead_steps(h, h_max, span)
        assert want.shape == got.shape and np.array_equal(want, got), (h, h_max, span)


def test_lead_in_only_where_a_circuit_is_carried():
    # a crank-rocker keeps its declared circuit at every sample: no lead-in; a change-point four-bar has one
    q = np.linspace(0.3, 3.0, 100)
    assert FourBar(4, 1, 4, 3)._lead_in(q).size == 0
    cp = FourBar(2.0, 1.0, 2.0, 1.0)
    assert cp.grashof == "change-point"
    lead = cp._lead_in(q)
    assert lead.size > 0 and np.all(np.diff(lead) > 0) and lead[-1] < q[0]


@pytest.mark.parametrize("dims", [(4.0, 1.0, 4.0, 3.0), (2.0, 1.5, 2.0, 2.2), (1.0, 3.0, 2.5, 2.2)])
@pytest.mark.parametrize("scale", [1e-300, 1e300, 2.0**-1000, 2.0**1000])
def test_limits_and_transmission_at_any_scale(dims, scale):
    """input_range, toggle_angles and transmission_angle of a four-bar scaled to 1e+-300 equal the unit one's
    (they overflowed: OverflowError, ZeroDivisionError, all-NaN transmission angles), with no warning."""
    import warnings

    from planar.linkages import FourBar

    th = np.linspace(0, 2 * np.pi, 12)
    unit = FourBar(*dims)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        big = FourBar(*[x * scale for x in dims], coupler_point=(0.5 * scale, 0.0))
        np.testing.assert_allclose(big.transmission_angle(th), unit.transmission_angle(th), rtol=1e-12, atol=1e-14)
        np.testing.assert_allclose(big.toggle_angles(), unit.toggle_angles(), atol=1e-12)
        r_big, r_unit = big.input_range(), unit.input_range()
    assert len(r_big) == len(r_unit)
    np.testing.assert_allclose(r_big, r_unit, atol=1e-12)


@pytest.mark.parametrize("scale", [1e-300, 1e300])
def test_rates_beyond_the_size_range_are_refused_naming_the_call(scale):
    """Rates, transmission angles and dynamics of a four-bar scaled to 1e+-300 are refused (they came back NaN,
    all zero or all invalid, or raised GEOSException), while its motion still solves; at 1e50 they are computed."""
    from planar import analysis

    th = np.linspace(0, 6, 12)
    dims = (4.0, 1.0, 4.0, 3.0)
    fb = FourBar(*[x * scale for x in dims], coupler_point=(5.5 * scale, -2 * scale))
    calls = {
        "transmission_angles(mech)": lambda: analysis.transmission_angles(fb, th),
        "mechanism_rates(mech)": lambda: analysis.mechanism_rates(fb, th),
        "node_accelerations": lambda: fb.part_rates(th, np.ones(12), np.zeros(12)),
        "node_velocities": lambda: analysis.point_velocities(fb, th),
        "inverse_dynamics_torque(mech)": lambda: analysis.inverse_dynamics_torque(fb, np.linspace(0, 1, 12)),
    }
    for where, call in calls.items():
        with pytest.raises(InputError, match="mechanism size") as e:
            call()
        assert where in str(e.value)
    assert fb.solve(th).valid.all()
    ok = FourBar(*[x * 1e50 for x in dims], coupler_point=(5.5e50, -2e50))
    unit = FourBar(*dims, coupler_point=(5.5, -2.0))
    np.testing.assert_allclose(analysis.transmission_angles(ok, th)["C"], analysis.transmission_angles(unit, th)["C"], rtol=1e-12)


@pytest.mark.parametrize("n", [9, 5000])  # the numpy path and the compiled one
@pytest.mark.parametrize("scale", [1e-300, 2.0**-1000, 1e300, 2.0**1000])
def test_slider_crank_at_any_scale(n, scale):
    """A slider-crank scaled to 1e+-300 gives the unit one's motion, scaled (at 1e-300 it was refused as
    'not a rigid link', the line-circle squares underflowing; at 1e300 every sample was invalid), and a rod
    1e300 times the crank is refused naming the rod (it named a pivot's anchor = (nan, nan))."""
    import warnings

    th = np.linspace(0, 6, n)
    unit = SliderCrank(crank=1.0, rod=3.0, offset=0.5).solve(th)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        big = SliderCrank(crank=scale, rod=3 * scale, offset=0.5 * scale).solve(th)
    assert big.valid.all()
    np.testing.assert_allclose(big.points["slider_pin"] / scale, unit.points["slider_pin"], atol=1e-13)
    with pytest.raises(InputError, match=r"slidercrank\.rod"):
        SliderCrank(crank=1.0, rod=1e300)
