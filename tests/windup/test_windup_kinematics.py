"""Every elemental mechanism's closed form against an independent numerical solution.

Each mechanism's joint condition is written down again directly (a pin on a
line, a point on a circle, a cylinder touching an edge) as a scalar equation
in the follower's motion, and solved by scipy's root finder with
continuation along the driver's cycle; the closed form must agree to 1e-9.
This is how the supplement's typos were found (see ERRATA.md).
"""

import numpy as np
import pytest
from scipy.optimize import brentq, minimize_scalar

from planar import InputError
from planar.windup import elemental, params_for
from planar.windup.kinematics import cam_centre
from planar.windup.mechanisms import ELEMENTAL

TOL = 1e-9


def R(a):
    return np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])


def xy(v):
    return np.asarray(v, float)[:2]


def residual_fn(k, P, u):
    """g(x) whose root x is the follower's motion for driver motion u (one sample)."""
    if k in (1, 2, 3):
        m = cam_centre(P.D_o, P.D_jc, np.array([u]))[0]
    if k == 1:
        return lambda dx: m[0] - (P.D_jc[0] + dx)
    if k == 2:
        s, m0 = xy(P.F_o), xy(P.D_jc)

        def g(a):
            L0 = s + R(a) @ (m0 - s)
            d = R(a) @ [1.0, 0.0]
            return d[0] * (m - L0)[1] - d[1] * (m - L0)[0]

        return g
    if k == 3:
        p0, m0 = xy(P.F_o), xy(P.D_jc)
        s = p0 + xy(P.S_c)
        r = np.hypot(*(p0 - s))
        return lambda a: np.hypot(*(m + R(a) @ (p0 - m0) - s)) - r
    if k == 4:
        q, p0 = xy(P.D_o), xy(P.F_o) + xy(P.F_jc)
        return lambda dy: (R(-u) @ (np.array([p0[0], p0[1] + dy]) - q))[1] - (p0[1] - q[1])
    if k == 5:
        q, s = xy(P.D_o), xy(P.F_o)
        p0 = s + xy(P.F_jc)
        d = p0[1] - q[1]
        return lambda a: (R(-u) @ (s + R(a) @ (p0 - s) - q))[1] - d
    if k in (6, 9):
        return lambda a: _cylinder_clearance(k, P, u, a)
    if k == 7:
        s, p0 = xy(P.F_o), xy(P.D_jc)
        p = p0 + [u, 0.0]

        def g(a):
            d = R(a) @ (p0 - s)
            return d[0] * (p - s)[1] - d[1] * (p - s)[0]

        return g
    if k == 8:
        B = np.array([P.F_o[0], P.F_o[2]])
        A = B + [P.F_jcx + u, P.F_jh]
        # alpha about +y is minus the view angle; the face is x = F_jcx in the tab's frame
        return lambda a: (R(a) @ (A - B))[0] - P.F_jcx
    m = xy(P.D_o) + np.asarray(u)[:2]
    if k == 10:
        p0 = xy(P.F_o) + xy(P.F_jc)
        Rr = np.hypot(*(p0 - xy(P.D_o)))
        return lambda dx: np.hypot(*(np.array([p0[0] + dx, p0[1]]) - m)) - Rr
    if k == 11:
        s = xy(P.F_o)
        p0 = s + xy(P.F_jc)
        Rr = np.hypot(*(p0 - xy(P.D_o)))
        return lambda a: np.hypot(*(s + R(a) @ (p0 - s) - m)) - Rr
    raise AssertionError(k)


def _cylinder_clearance(k, P, u, a):
    """Signed clearance between the driver's edge and the pin (a tilted cylinder), by sampling its section."""
    p0 = xy(P.F_o)
    r = P.F_jr
    zs, zp = P.F_o[2], P.D_o[2]
    if k == 6:
        h = p0[1] - P.D_o[1] - r
        e0 = xy(P.D_o) + R(u) @ [0.0, h]
        e = R(u) @ [1.0, 0.0]
    else:
        e = np.array([np.cos(P.phi), -np.sin(P.phi)])
        e0 = np.array([p0[0] + u, p0[1] - r / np.cos(P.phi)])
    d = np.array([0.0, -np.sin(a), np.cos(a)])  # the pin's axis, tilted about +x
    e1 = np.array([1.0, 0.0, 0.0])
    e2 = np.cross(d, e1)
    base = np.array([p0[0], p0[1], zs])

    def dist(phi):
        """Signed distance from the edge (pin side positive) of rim points at angles ``phi`` (array or scalar)."""
        c, s_ = np.cos(phi)[..., None], np.sin(phi)[..., None]
        rim = base + r * (c * e1 + s_ * e2)
        lam = (zp - rim[..., 2:3]) / d[2]
        w = (rim + lam * d)[..., :2] - e0  # the surface line through the rim point, met with the driver's plane
        return e[0] * w[..., 1] - e[1] * w[..., 0]

    phis = np.linspace(0, 2 * np.pi, 721)
    vals = dist(phis)
    sign = 1.0 if np.median(vals) > 0 else -1.0
    i = int(np.argmin(sign * vals))
    res = minimize_scalar(
        lambda p: float(sign * dist(np.asarray(p, float))),
        bounds=(phis[i] - 0.01, phis[i] + 0.01),
        method="bounded",
        options={"xatol": 1e-14},
    )
    return res.fun


def numeric_sweep(mech, q):
    """Follower motion for each driver value, by root finding with continuation."""
    k = mech.number
    P = mech.params
    u_all = mech.driver_motion(q)
    out = []
    prev = 0.0
    for i in range(q.size):
        g = residual_fn(k, P, u_all[i])
        lo, hi = prev - 0.05, prev + 0.05
        while np.sign(g(lo)) == np.sign(g(hi)):
            lo, hi = lo - 0.05, hi + 0.05
            if hi - lo > 4:
                raise AssertionError(f"#{k}: no bracket at sample {i}")
        x = brentq(g, lo, hi, xtol=1e-15, rtol=4 * np.finfo(float).eps)
        out.append(x)
        prev = x
    return np.array(out)


def closed_scalar(mech, q):
    st = mech.stage(q)
    out = st.out
    if mech.number == 3:
        out = out[:, 2]  # compare the rotation; translation is then p = m + R(alpha)(p0 - m0)
    return out, st.valid


def _check(mech, n=121):
    q = mech.driver.value(np.linspace(0, mech.driver.period, n))
    closed, valid = closed_scalar(mech, q)
    assert valid.all(), f"{mech.name}: invalid samples at the defaults"
    num = numeric_sweep(mech, q)
    err = np.abs(closed - num)
    assert err.max() < TOL, f"{mech.name}: closed form off by {err.max():.3g} at q={q[np.argmax(err)]:.4g}"
    return err.max()


@pytest.mark.slow
@pytest.mark.parametrize("k", sorted(ELEMENTAL))
def test_closed_form_matches_numerical_solution_at_defaults(k):
    _check(elemental(k))


def _perturbed(k, rng):
    base = params_for(k)
    kw = {}
    from dataclasses import fields

    for f in fields(base):
        v = getattr(base, f.name)
        if f.name in ("D_o", "D_theta", "path", "amplitude") or f.name.endswith(("r", "w1", "w2")):
            continue
        arr = np.asarray(v, float)
        pert = arr * rng.uniform(0.8, 1.2, arr.shape) + rng.uniform(-0.03, 0.03, arr.shape)
        kw[f.name] = tuple(pert.tolist()) if arr.ndim else float(pert)
    return kw


@pytest.mark.slow
@pytest.mark.parametrize("k", sorted(ELEMENTAL))
def test_closed_form_matches_numerical_solution_at_random_parameters(k):
    rng = np.random.default_rng(1000 + k)
    done = 0
    for _ in range(12):
        kw = _perturbed(k, rng)
        try:
            mech = elemental(k, **kw)
        except InputError:
            continue
        q = mech.driver.value(np.linspace(0, mech.driver.period, 61))
        if not mech.stage(q).valid.all():
            continue  # a failing assembly is the failure tests' business
        _check(mech, 61)
        done += 1
        if done == 3:
            break
    assert done >= 1, f"#{k}: no valid random parameter set"


def test_seed_formula_2_is_wrong_at_rest():
    # the supplement's alpha = 90 deg - (acos(D1/D) + acos(D2/D)) at theta = 0
    P = params_for(2)
    m0 = np.array(P.D_jc)
    s = np.array(P.F_o)
    D = np.hypot(*(m0 - s))
    seed = np.pi / 2 - 2 * np.arccos(abs(m0[1] - s[1]) / D)
    assert abs(seed) > 1.0  # about -78.6 degrees, where the follower is at rest
    assert abs(elemental(2).stage(np.zeros(1)).out[0]) < 1e-15


def test_seed_formula_3_needs_r_not_R():
    P = params_for(3)
    m0, p0 = np.array(P.D_jc), np.array(P.F_o)
    s = p0 + np.array(P.S_c[:2])
    Rr, r = np.hypot(*(p0 - m0)), np.hypot(*(p0 - s))

    def seed_p(use_R):
        mx, my = m0 - s
        K = r * r - Rr * Rr + mx * mx + my * my
        a, b = 4 * (mx * mx + my * my), -4 * my * K
        c = K * K - (2 * mx * (Rr if use_R else r)) ** 2
        py = (-b + np.sqrt(b * b - 4 * a * c)) / (2 * a) + s[1]
        px = (K - 2 * my * (py - s[1])) / (2 * mx) + s[0]
        return np.array([px, py])

    assert np.hypot(*(seed_p(True) - p0)) > 0.1  # as printed: not even the rest position
    assert np.hypot(*(seed_p(False) - p0)) < 1e-12  # corrected


def test_seed_formula_6_sign():
    # the supplement's closed form for #6 evaluated as printed, against the corrected one
    P = params_for(6)
    q = np.array(P.D_o[:2])
    p0 = np.array(P.F_o[:2])
    r = P.F_jr

    def seed(theta):
        k = np.tan(theta)
        c = (p0[1] - q[1] - r) / np.cos(theta)
        L = r * r * k * k
        M = k * (p0[0] - q[0]) + c + q[1] - p0[1]
        N = P.F_o[2] - q[0] * 0 - P.D_o[2]
        E = (M * M - L - N * N) / 2
        thp = -np.arctan(E / (M * N))
        return (np.arcsin((r * r - E) / np.sqrt(E * E + (M * N) ** 2)) - thp) / 2

    mech = elemental(6)
    th = np.array([0.0, 0.2])
    ours = mech.stage(th).out
    assert abs(ours[0]) < 1e-15
    assert abs(seed(0.0)) > 1e-3  # the printed formula does not give rest at rest
