"""Velocities three ways, torque by power and by virtual work, foot loads."""

import numpy as np
import pytest

from planar import InputError
from planar.analysis import statics as an
from planar.linkages import FourBar, SliderCrank
from planar.scene.catalog import jansen_leg

N = 3600
TH = np.linspace(0, 2 * np.pi, N, endpoint=False)
STEP = TH[1] - TH[0]


@pytest.fixture(params=[{"placement": (0, 0, 0)}, {"placement": (1.0, 2.0, 0.3)}])
def fb(request):
    return FourBar(4.0, 1.0, 4.0, 3.0, coupler_point=(2.0, 1.0), **request.param)


def test_loop_equation_velocities_match_dyad_velocities(fb):
    w3, w4, ok = an.fourbar_velocities(fb, TH, omega2=2.5)
    vel, ok2 = an.node_velocities(fb, TH, qdot=2.5)
    pos, _ = fb.solve_nodes(TH)
    d = pos["C"] - pos["B"]
    dv = vel["C"] - vel["B"]
    w3_nodes = (d[:, 0] * dv[:, 1] - d[:, 1] * dv[:, 0]) / (d * d).sum(1)
    assert ok.all() and ok2.all()
    np.testing.assert_allclose(w3, w3_nodes, atol=1e-12)
    r = pos["C"] - pos["O4"]
    w4_nodes = (r[:, 0] * vel["C"][:, 1] - r[:, 1] * vel["C"][:, 0]) / (r * r).sum(1)
    np.testing.assert_allclose(w4, w4_nodes, atol=1e-12)


def test_algebraic_velocity_matches_finite_differences(fb):
    m = fb.solve(TH)
    v, _ = an.point_velocities(fb, TH)
    fd = an.finite_difference(m.points["coupler_point"], STEP)
    # central differences: error ~ step^2 * |x'''| / 6
    assert np.abs(v["coupler_point"] - fd).max() < 5e-6
    # and the error shrinks as step^2
    th2 = np.linspace(0, 2 * np.pi, 2 * N, endpoint=False)
    fd2 = an.finite_difference(fb.solve(th2).points["coupler_point"], th2[1] - th2[0])
    v2, _ = an.point_velocities(fb, th2)
    e1, e2 = np.abs(v["coupler_point"] - fd).max(), np.abs(v2["coupler_point"] - fd2).max()
    assert 3.5 < e1 / e2 < 4.5


def test_instant_centre_matches_algebraic(fb):
    ic, omega, ok = an.fourbar_instant_centre(fb, TH)
    w3, _, _ = an.fourbar_velocities(fb, TH)
    vel, _ = an.node_velocities(fb, TH)
    pos, _ = fb.solve_nodes(TH)
    assert ok.mean() > 0.99  # only where crank and rocker are parallel is the centre at infinity
    np.testing.assert_allclose(omega[ok], w3[ok], atol=1e-12)
    v_ic = an.velocity_about_centre(pos["P"], ic, omega)
    assert np.abs(v_ic - vel["P"])[ok].max() < 1e-9
    # notes 2.1.1: |v_B| = omega_c |L_2c|
    np.testing.assert_allclose(np.abs(omega[ok]) * np.hypot(*(pos["B"] - ic).T)[ok], 1.0 * 1.0, rtol=1e-9)


def test_generic_instant_centre_of_a_rotating_body():
    c = np.array([0.3, -0.7])
    w = 1.7
    p1, p2 = np.array([[1.0, 2.0]]), np.array([[-2.0, 0.5]])
    v1 = w * np.stack([-(p1 - c)[:, 1], (p1 - c)[:, 0]], -1)
    v2 = w * np.stack([-(p2 - c)[:, 1], (p2 - c)[:, 0]], -1)
    centre, omega, ok = an.instant_centre(p1, v1, p2, v2)
    assert ok.all()
    np.testing.assert_allclose(centre[0], c, atol=1e-12)
    np.testing.assert_allclose(omega, w, atol=1e-12)
    # a translating body has no finite centre
    _, om, ok = an.instant_centre(p1, [[1.0, 0.0]], p2, [[1.0, 0.0]])
    assert not ok.any() and om[0] == 0


def test_multi_loop_velocities_match_finite_differences():
    leg = jansen_leg()
    m = leg.solve(TH)
    v, ok = an.point_velocities(leg, TH)
    fd = an.finite_difference(m.points["foot"], STEP)
    assert ok.all()
    assert np.abs(v["foot"] - fd).max() < 1e-4 * np.abs(v["foot"]).max()


def test_slider_velocity_matches_derivative_of_formula():
    sc = SliderCrank(1.0, 3.0, offset=0.4)
    v, _ = an.point_velocities(sc, TH)
    h = 1e-6
    dx = (sc.slider_position(TH + h) - sc.slider_position(TH - h)) / (2 * h)
    np.testing.assert_allclose(v["slider_pin"][:, 0], dx, atol=1e-7)
    np.testing.assert_allclose(v["slider_pin"][:, 1], 0.0, atol=1e-12)


def test_moving_frame_adds_machine_velocity():
    v_rel = np.array([[1.0, 2.0]])
    np.testing.assert_allclose(an.world_velocity(v_rel, [0.5, 0.0]), [[1.5, 2.0]])
    np.testing.assert_allclose(an.world_velocity(v_rel, [0.0, 0.0], 2.0, [[1.0, 0.0]]), [[1.0, 4.0]])


def test_torque_times_speed_equals_load_power_over_efficiency(fb):
    omega = 3.0
    forces = {"coupler_point": np.stack([0.2 * np.sin(TH), -1.0 + 0 * TH], -1)}
    tau, _ok = an.motor_torque(fb, TH, forces, eta_trans=0.8, eta_link=0.9)
    v, _ = an.point_velocities(fb, TH, omega)
    power = (forces["coupler_point"] * v["coupler_point"]).sum(-1)
    # the motor supplies the losses where it drives; where the load drives it (power < 0), the losses
    # reduce what comes back: multiplied by the efficiency, not divided
    assert (power > 0).any() and (power < 0).any()
    np.testing.assert_allclose(tau * omega, np.where(power >= 0, power / (0.8 * 0.9), power * 0.8 * 0.9), atol=1e-12)


def test_torque_by_virtual_work_matches_power_method(fb):
    m = fb.solve(TH)
    F = np.array([[0.0, -2.0]])
    tau, _ = an.motor_torque(fb, TH, {"coupler_point": F[0]})
    tvw, _ = an.virtual_work_torque(m.points["coupler_point"][:, None, :], TH, F)
    assert np.abs(tau - tvw).max() < 1e-5 * np.abs(tau).max()


def test_two_feet_on_one_motor_sum():
    leg = jansen_leg()
    W = np.array([0.0, 5.0])
    # two legs half a turn apart on one crank: torque of each, summed, equals virtual work of both
    t1, _ = an.motor_torque(leg, TH, {"foot": W})
    t2, _ = an.motor_torque(leg, TH + np.pi, {"foot": W})
    pts = np.stack([leg.solve(TH).points["foot"], leg.solve(TH + np.pi).points["foot"]], 1)
    tvw, _ = an.virtual_work_torque(pts, TH, np.stack([W, W]))
    assert np.abs((t1 + t2) - tvw).max() < 1e-4 * np.abs(t1 + t2).max()


def test_bad_efficiency_is_named():
    with pytest.raises(InputError, match="eta_link"):
        an.input_torque(np.zeros((1, 1, 2)), np.zeros((1, 2)), 1.0, 1.5)


def test_static_foot_loads_balance_force_and_moment():
    fx = np.array([[-1.0, 2.0], [-1.0, 2.0], [0.0, 3.0]])
    on = np.array([[True, True], [True, False], [True, True]])
    f, stable = an.static_foot_loads(9.0, np.array([0.0, 0.0, -1.0]), fx, on)
    np.testing.assert_allclose(f[0], [6.0, 3.0])  # lever rule
    np.testing.assert_allclose(f[1], [9.0, 0.0])
    assert stable[0] and not stable[1]  # one foot off-centre: the machine tips
    assert not stable[2]  # centre of mass outside the feet
    np.testing.assert_allclose(f.sum(1), 9.0)


def test_fourier_acceleration_peak_and_notes_bound():
    t = np.linspace(0, 0.5, 20001)
    acc = an.fourier_acceleration([0.01, 0.01], 2.0, t)
    bound = an.fourier_peak_bound([0.01, 0.01], 2.0)
    assert abs(bound - 5 * (4 * np.pi) ** 2 * 0.01) < 1e-12  # notes eq. (11): about 7.9 m/s^2
    assert abs(bound - 7.9) < 0.05
    assert np.abs(acc).max() < bound  # the true peak is lower than the notes' bound
    # single harmonic: notes' 1.6 m/s^2
    assert abs(np.abs(an.fourier_acceleration([0.01], 2.0, t)).max() - 1.579) < 1e-3
    # cross-check eq (10) against a numerical second derivative of eq (9)
    y = 0.01 * np.sin(4 * np.pi * t) + 0.01 * np.sin(8 * np.pi * t)
    d2 = np.gradient(np.gradient(y, t), t)
    assert np.abs(d2[5:-5] - acc[5:-5]).max() < 1e-3 * bound


def test_friction_limit():
    ft, slip = an.friction_limit([3.0, -0.5, -4.0], [10.0, 10.0, 10.0], 0.3)
    np.testing.assert_allclose(ft, [3.0, -0.5, -3.0])
    assert slip.tolist() == [False, False, True]
