"""The checks behind ERRATA.md that test_windup_kinematics does not already make.

Each test evaluates a printed formula of the supplement (seed 000) as printed,
or a derivation step, numerically, against the joint condition or planar's
closed form (which test_windup_kinematics checks against a numerical
solution of the joint conditions).
"""

import numpy as np
import pytest

from planar.windup import elemental, params_for


def test_seed_1_sign_against_the_seeds_own_cam_centre():
    # the seed's #2 defines m_x = q_x - d sin(theta) for the same cam; #1 prints dx = d sin(theta)
    P = params_for(1)
    d = P.D_jc[1]
    th = np.linspace(-3, 3, 13)
    dx_seed_m = (P.D_o[0] - d * np.sin(th)) - P.D_o[0]
    ours = elemental(1).stage(th).out
    np.testing.assert_allclose(ours, dx_seed_m, atol=1e-15)
    assert np.abs(ours - d * np.sin(th)).max() > 0.1  # the printed sign is the other one


def test_seed_4_formula_is_correct():
    P = params_for(4)
    p0 = np.array(P.F_o[:2]) + np.array(P.F_jc)
    Dx, Y0 = p0
    th = np.linspace(-0.35, 0.35, 71)
    seed = Y0 / np.cos(th) + Dx * np.tan(th) - Y0
    np.testing.assert_allclose(elemental(4).forward(th).out, seed, atol=1e-14)


def _seed5(P, th, sign, printed):
    """The seed's #5 root p (``printed``: its b and c as printed, else substituted correctly)."""
    q, s = np.array(P.D_o[:2]), np.array(P.F_o[:2])
    p0 = s + np.array(P.F_jc)
    R = np.hypot(*P.F_jc)
    d = p0[1] - q[1]
    qx, qy = q[0] - d * np.sin(th), q[1] + d * np.cos(th)
    t = np.tan(th)
    c0 = qy - qx * t
    a = 1 + t * t
    if printed:
        b = -2 * s[0] - 2 * c0 - 2 * s[1] * t
        c = s[0] ** 2 + c0**2 - 2 * s[1] * c0 + s[1] ** 2
    else:
        b = -2 * s[0] + 2 * t * (c0 - s[1])
        c = s[0] ** 2 + c0**2 - 2 * s[1] * c0 + s[1] ** 2 - R * R
    px = (-b + sign * np.sqrt(b * b - 4 * a * c)) / (2 * a)
    return np.array([px, t * (px - qx) + qy]), s, R, (qx, qy)


def test_seed_5_quadratic_as_printed_misses_the_circle():
    P = params_for(5)
    th = 0.2
    p, s, R, _ = _seed5(P, th, +1, printed=True)
    assert abs(np.hypot(*(p - s)) - R) > 0.1
    for sign in (+1, -1):
        p, s, R, (qx, qy) = _seed5(P, th, sign, printed=False)
        assert abs(np.hypot(*(p - s)) - R) < 1e-12  # corrected b, c: on the circle
        assert abs((p[1] - qy) - np.tan(th) * (p[0] - qx)) < 1e-12  # and on the slot's line
    # the printed p_y = tan(p_x - q'_x) + q'_y is not on the line through q' at angle theta
    p, _, _, (qx, qy) = _seed5(P, th, -1, printed=False)
    assert abs(np.tan(p[0] - qx) + qy - p[1]) > 0.05


@pytest.mark.parametrize("k", [5, 11])
def test_seed_plus_root_is_the_other_intersection_at_the_defaults(k):
    P = params_for(k)
    if k == 5:
        p_plus, *_ = _seed5(P, 0.0, +1, printed=False)
        p_minus, *_ = _seed5(P, 0.0, -1, printed=False)
        p0 = np.array(P.F_o[:2]) + np.array(P.F_jc)
    else:  # the seed's circle-circle with r (as corrected; R = r = 0.5 at #11's defaults anyway)
        m, s = np.array(P.D_o[:2]), np.array(P.F_o[:2])
        p0 = s + np.array(P.F_jc)
        R, r = np.hypot(*(p0 - m)), np.hypot(*P.F_jc)
        mx, my = m - s
        K = r * r - R * R + mx * mx + my * my
        a, b, c = 4 * (mx * mx + my * my), -4 * my * K, K * K - (2 * mx * r) ** 2

        def root(sign):
            py = (-b + sign * np.sqrt(b * b - 4 * a * c)) / (2 * a) + s[1]
            return np.array([(K - 2 * my * (py - s[1])) / (2 * mx) + s[0], py])

        p_plus, p_minus = root(+1), root(-1)
        np.testing.assert_allclose(p_plus, [0.4, 0.3], atol=1e-12)
    assert np.hypot(*(p_plus - p0)) > 0.1  # "+": the other intersection, not the rest position
    assert np.hypot(*(p_minus - p0)) < 1e-12  # "-": exact


def test_seed_5_angle_is_clockwise():
    # alpha = beta0 + beta with beta = atan((p_y - s_y)/(s_x - p_x)): clockwise positive, a convention
    P = params_for(5)
    th = np.linspace(-0.3, 0.3, 13)
    s = np.array(P.F_o[:2])
    p0 = s + np.array(P.F_jc)
    st = elemental(5).forward(th)
    p = st.aux["p"]
    seed = np.arctan((s[1] - p0[1]) / (s[0] - p0[0])) + np.arctan((p[:, 1] - s[1]) / (s[0] - p[:, 0]))
    np.testing.assert_allclose(seed, -st.out, atol=1e-14)


def _six(k):
    """L, M, N, r of the seed's #6 derivation at mechanism k's defaults, for driver motion u."""
    P = params_for(k)
    p0 = np.array(P.F_o[:2])
    r = P.F_jr
    N = P.F_o[2] - P.D_o[2]
    if k == 6:
        q = np.array(P.D_o[:2])

        def LMN(u):
            kk, c = np.tan(u), (p0[1] - q[1] - r) / np.cos(u)
            return r * r * kk * kk, kk * (p0[0] - q[0]) + c + q[1] - p0[1], N
    else:  # red frame centred at p0, s on the pivot axis under p0

        def LMN(u):
            kk, c = -np.tan(P.phi), -r / np.cos(P.phi) + u * np.tan(P.phi)
            return r * r * kk * kk, c, N

    return P, r, LMN


@pytest.mark.parametrize("k", [6, 9])
def test_seed_6_9_expansion(k):
    # L - (M - N tan a)^2 + r^2 / cos^2 a = 0 expands to MN sin 2a - E cos 2a = E + N^2 - r^2,
    # E = (M^2 - L - N^2) / 2; ERRATA formerly said "E - r^2"
    _, r, LMN = _six(k)
    mech = elemental(k)
    u = mech.driver.value(np.linspace(0, mech.driver.period, 41))
    ours = mech.stage(u).out
    worst_new = worst_old = 0.0
    for ui, a in zip(u, ours):
        L, M, N = LMN(ui)
        E = (M * M - L - N * N) / 2
        assert abs(L - (M - N * np.tan(a)) ** 2 + r * r / np.cos(a) ** 2) < 1e-12  # planar's a solves it
        lhs = M * N * np.sin(2 * a) - E * np.cos(2 * a)
        worst_new = max(worst_new, abs(lhs - (E + N * N - r * r)))
        worst_old = max(worst_old, abs(lhs - (E - r * r)))
        # the corrected closed form: 2a = asin((E + N^2 - r^2) / S) - theta', theta' = atan2(-E, MN)
        S = np.hypot(E, M * N)
        a_closed = (np.arcsin((E + N * N - r * r) / S) - np.arctan2(-E, M * N)) / 2
        assert abs(a_closed - a) < 1e-9
    assert worst_new < 1e-12
    assert worst_old > 0.5 * N * N  # off by N^2 = 0.64 (#6), 0.09 (#9)


def test_seed_8_zero_at_rest_folds_past_the_pivot():
    # gamma - beta with D_x = F_jcx, D_z = F_jh (constant: A moves along x) is zero at rest, equals
    # planar's angle about +y with the opposite orientation while A is right of B, and folds after
    P = params_for(8)
    mech = elemental(8)
    dx = np.linspace(-0.15, 0.15, 31)
    B = np.array([P.F_o[0], P.F_o[2]])
    A = B + np.array([P.F_jcx, P.F_jh]) + np.column_stack([dx, 0 * dx])
    BA = np.hypot(*(A - B).T)
    seed = np.arcsin(P.F_jcx / BA) - np.arccos(P.F_jh / BA)
    ours = mech.forward(dx).out
    assert abs(seed[15]) < 1e-15 and abs(ours[15]) < 1e-15  # rest
    right = (A - B)[:, 0] > 0
    np.testing.assert_allclose(seed[right], -ours[right], atol=1e-14)
    assert np.abs(seed[~right] + ours[~right]).max() > 0.1  # folded where BA crosses the z axis


def test_seed_3_divides_by_zero_where_planar_does_not():
    # with the track centre straight below the cam axis, m'_x = m_x - s_x = 0 at rest
    mech = elemental(3, S_c=(-0.6, -0.2, 0.1), F_o=(0.6, -0.3))
    P = mech.params
    s = np.array(P.F_o) + np.array(P.S_c[:2])
    assert abs(P.D_jc[0] - s[0]) < 1e-15  # the seed's p_x = (...) / (2 m'_x) divides by zero here
    st = mech.stage(np.linspace(-0.1, 0.1, 5))
    assert st.valid.all() and np.all(np.isfinite(st.out)) and abs(st.out[2]).max() < 1e-15
