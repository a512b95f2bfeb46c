"""Rates of the wind-up mechanisms and toys: the closed forms differentiated analytically in time.

Each elemental mechanism's forward kinematics (:mod:`planar.windup.kinematics`)
is differentiated twice by hand, sample by sample with arrays, never by
differencing: ``rates_N`` for mechanism ``N``, carried by its record
(:data:`planar.windup.mechanisms.ELEMENTAL`, field ``rates``):

* the cam and slot contacts that are dyads reuse the linkage node kinds'
  differentiated closures: #3 and #11 (pin on two circles) are an RRR dyad,
  #5 and #10 (pin on a line and a circle) an RRP dyad
  (:meth:`planar.linkages.NodeKind.acceleration`);
* angles ``atan2(w)`` of a moving vector: ``omega = cross(w, w') / |w|^2``,
  ``alpha = cross(w, w'') / |w|^2 - 2 omega (w . w') / |w|^2``;
* #2 and #8 (a line at a fixed distance ``c`` from a point, through a moving
  point): ``beta = atan2(c, l)``, ``l^2 = |w|^2 - c^2``, differentiated;
* #4: ``dy = D_x tan(theta) + Y0 (sec(theta) - 1)``, differentiated in theta;
* #6 and #9 (the tilted pin's tangency ``A t^2 + B t + C = 0`` in
  ``t = tan(alpha)``): implicit differentiation of the quadratic, twice.

The OzT driver path ``(a_x sin q, a_y (cos q - 1), theta_max sin q)`` and the
pose maps (driver and follower poses are affine in their motions) are
differentiated directly (:func:`driver_motion_rates`, :func:`stage_part_rates`);
:meth:`ElementalMechanism.part_rates <planar.windup.mechanisms.ElementalMechanism.part_rates>`
assembles them, and a toy composes its stages' rates through the same linear
axis maps as their motions (:meth:`planar.windup.chain.ToyMechanism.part_rates`).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from planar.core.rates import PartRates
from planar.core.registry import UnsupportedError
from planar.linkages.nodes import RRP, RRR, frame_rates
from planar.windup import kinematics as K
from planar.windup import params as P_
from planar.windup.kinematics import Stage

__all__ = [
    "driver_motion_rates",
    "rates_1",
    "rates_2",
    "rates_3",
    "rates_4",
    "rates_5",
    "rates_6",
    "rates_7",
    "rates_8",
    "rates_9",
    "rates_10",
    "rates_11",
    "stage_part_rates",
]

Array = NDArray[np.float64]
Mask = NDArray[np.bool_]
Jet = tuple[Array, Array, Array]  # value, first and second time derivative


def _xy(v: Any) -> Array:
    return np.asarray(v, float)[:2]


def _perp(v: Array) -> Array:
    return np.stack([-v[..., 1], v[..., 0]], axis=-1)


def _turning(o: Array, x: Array, u1: Array, u2: Array) -> tuple[Array, Array]:
    """Velocity and acceleration of points ``x`` (N, 2) turning about the fixed ``o`` at angle rates ``u1, u2``."""
    r = x - o
    return u1[:, None] * _perp(r), u2[:, None] * _perp(r) - (u1 * u1)[:, None] * r


def _zeros(n: int) -> Array:
    return np.zeros((n, 2))


def _angle(w: Array, w1: Array, w2: Array) -> tuple[Array, Array]:
    return frame_rates(w, w1, w2)


def _offset_angle(c: float, sign: float, w: Array, w1: Array, w2: Array) -> tuple[Array, Array]:
    """Rates of ``beta = atan2(c, l)``, ``l = sign sqrt(|w|^2 - c^2)`` (a line at distance ``c`` through ``w``)."""
    n2 = (w * w).sum(-1)
    l = sign * np.sqrt(np.maximum(n2 - c * c, 0.0))
    ls = np.where(l != 0, l, 1.0)
    ww1 = (w * w1).sum(-1)
    l1 = ww1 / ls
    l2 = ((w1 * w1).sum(-1) + (w * w2).sum(-1) - l1 * l1) / ls
    n2s = np.where(n2 > 0, n2, 1.0)
    b1 = -c * l1 / n2s
    b2 = -c * (l2 * n2 - l1 * 2.0 * ww1) / n2s**2
    return b1, b2


def _dyad(node: RRR | RRP, pos: dict[str, Array], vel: dict[str, Array], acc: dict[str, Array]) -> tuple[Array, Array, Mask]:
    """Velocity and acceleration of a contact point solved as a dyad node (``pos`` holds its position)."""
    n = pos[node.name].shape[0]
    one = np.ones(n)
    v, ok1 = node.velocity(pos, vel, one)
    vel = {**vel, node.name: v}
    a, ok2 = node.acceleration(pos, vel, acc, one, np.zeros(n))
    ok = np.ones(n, bool)
    for m in (ok1, ok2):
        if m is not None:
            ok &= m
    return v, a, ok


def _oval_rates(e0: Jet, e: Jet, p0: Array, N: float, r: float, alpha: Array) -> tuple[Array, Array, Mask]:
    """Rates of the tilt ``alpha = atan(t)`` with ``A t^2 + B t + C = 0`` (see ``kinematics._oval_tangent``)."""
    (w, w1, w2), (d, d1, d2) = (e0[0] - p0, e0[1], e0[2]), e
    X = d[:, 0] * w[:, 1] - d[:, 1] * w[:, 0]
    X1 = (d1[:, 0] * w[:, 1] - d1[:, 1] * w[:, 0]) + (d[:, 0] * w1[:, 1] - d[:, 1] * w1[:, 0])
    X2 = (
        (d2[:, 0] * w[:, 1] - d2[:, 1] * w[:, 0])
        + 2 * (d1[:, 0] * w1[:, 1] - d1[:, 1] * w1[:, 0])
        + (d[:, 0] * w2[:, 1] - d[:, 1] * w2[:, 0])
    )
    ex, ex1, ex2 = d[:, 0], d1[:, 0], d2[:, 0]
    K = N * N - r * r
    t = np.tan(alpha)
    A, A1 = ex * ex * K, 2 * ex * ex1 * K
    B1 = -2 * N * (X1 * ex + X * ex1)
    B = -2 * N * X * ex
    Gt = 2 * A * t + B
    GX = -2 * N * ex * t + 2 * X
    Ge = 2 * ex * K * t * t - 2 * X * N * t
    ok = np.abs(Gt) > 1e-12 * (np.abs(B) + np.abs(A * t) + 1e-300)
    Gts = np.where(ok, Gt, 1.0)
    t1 = -(GX * X1 + Ge * ex1) / Gts
    dGt = 2 * A1 * t + 2 * A * t1 + B1
    dGX = -2 * N * (ex1 * t + ex * t1) + 2 * X1
    dGe = 2 * ex1 * K * t * t + 4 * ex * K * t * t1 - 2 * N * (X1 * t + X * t1)
    t2 = -(dGt * t1 + dGX * X1 + GX * X2 + dGe * ex1 + Ge * ex2) / Gts
    s = 1.0 + t * t
    return t1 / s, t2 / s - 2 * t * t1 * t1 / s**2, ok


# ---------------------------------------------------------------- one rule per elemental mechanism
# Each ``rates_N(params, u, u1, u2)`` differentiates ``forward_N`` (same parameters, the supplement's
# frames): ``u`` the driver's motion, ``u1``, ``u2`` its time derivatives; returns ``(out1, out2, ok)``
# shaped like the follower motion, ``ok`` false where a differentiated closure is singular.  Each
# record of :data:`planar.windup.mechanisms.ELEMENTAL` carries its own as ``rates``.


def _cam_centre_rates(params: Any, st: Stage, u1: Array, u2: Array) -> tuple[Any, Array, Array, Array]:
    """#1-3: the cam centre ``m`` turning about ``D_o``, and its rates."""
    P = P_.in_world(params)
    m = st.aux["m"]
    m1, m2 = _turning(_xy(P.D_o), m, u1, u2)
    return P, m, m1, m2


def rates_1(params: Any, u: Array, u1: Array, u2: Array) -> tuple[Array, Array, Mask]:
    """#1 (Rz -> Tx): the window follows the cam centre's x."""
    _, _, m1, m2 = _cam_centre_rates(params, K.forward_1(params, u), u1, u2)
    return m1[:, 0], m2[:, 0], np.ones(u.shape[0], bool)


def rates_2(params: Any, u: Array, u1: Array, u2: Array) -> tuple[Array, Array, Mask]:
    """#2 (Rz -> Oz): a window at distance ``c`` from its pivot through the cam centre."""
    P, m, m1, m2 = _cam_centre_rates(params, K.forward_2(params, u), u1, u2)
    s = _xy(P.F_o)
    w0 = _xy(P.D_jc) - s
    phi1, phi2 = _angle(m - s, m1, m2)
    b1, b2 = _offset_angle(w0[1], 1.0 if w0[0] >= 0 else -1.0, m - s, m1, m2)
    return phi1 - b1, phi2 - b2, np.ones(u.shape[0], bool)


def rates_3(params: Any, u: Array, u1: Array, u2: Array) -> tuple[Array, Array, Mask]:
    """#3 (Rz -> OzT): the pin on two circles, an RRR dyad."""
    st = K.forward_3(params, u)
    P, m, m1, m2 = _cam_centre_rates(params, st, u1, u2)
    n = u.shape[0]
    s = _xy(P.F_o) + _xy(P.S_c)
    p = st.aux["p"]
    node = RRR("p", "m", 1.0, "s", 1.0)
    pv, pa, ok = _dyad(
        node, {"p": p, "m": m, "s": np.broadcast_to(s, m.shape)}, {"m": m1, "s": _zeros(n)}, {"m": m2, "s": _zeros(n)}
    )
    al1, al2 = _angle(p - m, pv - m1, pa - m2)
    return np.column_stack([pv, al1]), np.column_stack([pa, al2]), ok


def rates_4(params: Any, u: Array, u1: Array, u2: Array) -> tuple[Array, Array, Mask]:
    """#4 (Oz -> Ty): ``dy = D_x tan(theta) + Y0 (sec(theta) - 1)`` differentiated in theta."""
    P = P_.in_world(params)
    q = _xy(P.D_o)
    p0 = _xy(P.F_o) + _xy(P.F_jc)
    Dx, Y0 = p0 - q
    c, sn = np.cos(u), np.sin(u)
    ok = np.abs(c) > 1e-9
    sec = 1.0 / np.where(ok, c, 1.0)
    tan = sn * sec
    f1 = Dx * sec * sec + Y0 * sec * tan
    f2 = 2 * Dx * sec * sec * tan + Y0 * (sec * tan * tan + sec**3)
    return f1 * u1, f2 * u1 * u1 + f1 * u2, ok


def rates_5(params: Any, u: Array, u1: Array, u2: Array) -> tuple[Array, Array, Mask]:
    """#5 (Oz -> Oz): the pin on a turning line and a circle, an RRP dyad."""
    P = P_.in_world(params)
    n = u.shape[0]
    q = _xy(P.D_o)
    s = _xy(P.F_o)
    p = K.forward_5(params, u).aux["p"]
    d = (s + _xy(P.F_jc))[1] - q[1]
    c, sn = np.cos(u), np.sin(u)
    base = q + np.column_stack([-d * sn, d * c])
    tip = base + np.column_stack([c, sn])
    bv, ba = _turning(q, base, u1, u2)
    tv, ta = _turning(q, tip, u1, u2)
    z = _zeros(n)
    node5 = RRP("p", "s", 1.0, "b", "t")
    pv, pa, ok = _dyad(
        node5,
        {"p": p, "s": np.broadcast_to(s, p.shape), "b": base, "t": tip},
        {"s": z, "b": bv, "t": tv},
        {"s": z, "b": ba, "t": ta},
    )
    return (*_angle(p - s, pv, pa), ok)


def rates_6(params: Any, u: Array, u1: Array, u2: Array) -> tuple[Array, Array, Mask]:
    """#6 (Oz -> Ox): the tilted pin's tangency to a turning edge, differentiated implicitly."""
    P = P_.in_world(params)
    st = K.forward_6(params, u)
    q = _xy(P.D_o)
    e0 = st.aux["e0"]
    c, sn = np.cos(u), np.sin(u)
    e = np.column_stack([c, sn])
    e0v, e0a = _turning(q, e0, u1, u2)
    ev, ea = _turning(np.zeros(2), e, u1, u2)
    return _oval_rates((e0, e0v, e0a), (e, ev, ea), _xy(P.F_o), P.F_o[2] - P.D_o[2], P.F_jr, st.out)


def rates_9(params: Any, u: Array, u1: Array, u2: Array) -> tuple[Array, Array, Mask]:
    """#9 (Tx -> Ox): the tilted pin's tangency to a sliding edge, differentiated implicitly."""
    P = P_.in_world(params)
    st = K.forward_9(params, u)
    n = u.shape[0]
    e0 = st.aux["e0"]
    e = np.broadcast_to(np.array([np.cos(P.phi), -np.sin(P.phi)]), (n, 2))
    e0v, e0a = np.column_stack([u1, np.zeros(n)]), np.column_stack([u2, np.zeros(n)])
    ev = ea = _zeros(n)
    return _oval_rates((e0, e0v, e0a), (e, ev, ea), _xy(P.F_o), P.F_o[2] - P.D_o[2], P.F_jr, st.out)


def rates_7(params: Any, u: Array, u1: Array, u2: Array) -> tuple[Array, Array, Mask]:
    """#7 (Tx -> Oz): the slot's angle through a sliding pin."""
    P = P_.in_world(params)
    n = u.shape[0]
    s = _xy(P.F_o)
    p = K.forward_7(params, u).aux["p"]
    z = np.zeros(n)
    return (*_angle(p - s, np.column_stack([u1, z]), np.column_stack([u2, z])), np.ones(n, bool))


def rates_8(params: Any, u: Array, u1: Array, u2: Array) -> tuple[Array, Array, Mask]:
    """#8 (Tx -> Oy): a line at distance ``c`` from the pivot through a sliding point (xz plane)."""
    P = P_.in_world(params)
    n = u.shape[0]
    B = np.array([P.F_o[0], P.F_o[2]])
    w = K.forward_8(params, u).aux["A"] - B
    z = np.zeros(n)
    w1, w2 = np.column_stack([u1, z]), np.column_stack([u2, z])
    phi1, phi2 = _angle(w, w1, w2)
    b1, b2 = _offset_angle(P.F_jcx, 1.0, w, w1, w2)
    return -(phi1 + b1), -(phi2 + b2), np.ones(n, bool)


def rates_10(params: Any, u: Array, u1: Array, u2: Array) -> tuple[Array, Array, Mask]:
    """#10 (OzT -> Tx): the arc slot's centre moves with the OzT driver; the pin on a line and a circle."""
    P = P_.in_world(params)
    st = K.forward_10(params, u)
    m, p = st.aux["m"], st.aux["p"]
    m1, m2 = u1[:, :2], u2[:, :2]
    z = _zeros(u.shape[0])
    p0 = _xy(P.F_o) + _xy(P.F_jc)
    g1 = np.broadcast_to(np.array([0.0, p0[1]]), m.shape)
    g2 = np.broadcast_to(np.array([1.0, p0[1]]), m.shape)
    node10 = RRP("p", "m", 1.0, "g1", "g2")
    pv, pa, ok = _dyad(node10, {"p": p, "m": m, "g1": g1, "g2": g2}, {"m": m1, "g1": z, "g2": z}, {"m": m2, "g1": z, "g2": z})
    return pv[:, 0], pa[:, 0], ok


def rates_11(params: Any, u: Array, u1: Array, u2: Array) -> tuple[Array, Array, Mask]:
    """#11 (OzT -> Oz): the arc slot's centre moves with the OzT driver; the pin on two circles."""
    P = P_.in_world(params)
    st = K.forward_11(params, u)
    m, p = st.aux["m"], st.aux["p"]
    m1, m2 = u1[:, :2], u2[:, :2]
    z = _zeros(u.shape[0])
    s = _xy(P.F_o)
    node11 = RRR("p", "m", 1.0, "s", 1.0)
    pv, pa, ok = _dyad(node11, {"p": p, "m": m, "s": np.broadcast_to(s, m.shape)}, {"m": m1, "s": z}, {"m": m2, "s": z})
    return (*_angle(p - s, pv, pa), ok)


def driver_motion_rates(motion_in: str, params: Any, u: Array, q: Array, qd: Array, qdd: Array) -> Jet:
    """The driver's motion ``u`` (for driver values ``q``) and its time derivatives: the OzT path
    ``(a_x sin q, a_y (cos q - 1), theta_max sin q)`` differentiated; any other motion is ``q`` itself."""
    if motion_in != "OzT":
        return u, qd, qdd
    ax, ay = params.path
    th = params.D_theta[1]
    c, s = np.cos(q), np.sin(q)
    d1 = np.column_stack([ax * c, -ay * s, th * c])
    d2 = np.column_stack([-ax * s, -ay * c, -th * s])
    return u, d1 * qd[:, None], d2 * (qd * qd)[:, None] + d1 * qdd[:, None]


def _pose_rates(kind: str, m1: Array, m2: Array) -> PartRates:
    """``(v, a, omega, alpha)`` of a pose affine in a motion, from the motion's rates (``kind``: how it moves)."""
    n = m1.shape[0]
    z, z2 = np.zeros(n), np.zeros((n, 2))
    if kind in ("Rz", "Oz", "Ox", "Ox-yz", "pivot"):
        return PartRates(z2, z2, m1, m2)
    if kind == "-pivot":
        return PartRates(z2, z2, -m1, -m2)
    if kind == "x":
        return PartRates(np.column_stack([m1, z]), np.column_stack([m2, z]), z, z)
    if kind == "y":
        return PartRates(np.column_stack([z, m1]), np.column_stack([z, m2]), z, z)
    if kind == "free":  # (dx, dy, angle)
        return PartRates(m1[:, :2], m2[:, :2], m1[:, 2], m2[:, 2])
    raise UnsupportedError(f"rates: no rule for a pose that moves by {kind!r}")


#: how each driver motion moves the driver's pose (the pose rules of :func:`_pose_rates`)
_DRIVER_KIND = {"Rz": "Rz", "Oz": "Oz", "Tx": "x", "OzT": "free"}


def stage_part_rates(motion_in: str, follower_motion: str, u: Jet, out1: Array, out2: Array) -> dict[str, PartRates]:
    """Rates of an elemental mechanism's three parts from its driver's motion ``u`` (with its rates) and its
    follower motion's rates; ``follower_motion``: how the follower's pose moves with its motion
    (``"x"``, ``"y"``, ``"pivot"``, ``"-pivot"``, ``"free"``: the record's ``follower_motion``)."""
    n = out1.shape[0]
    return {
        "ground": _pose_rates("Rz", np.zeros(n), np.zeros(n)),
        "driver": _pose_rates(_DRIVER_KIND[motion_in], u[1], u[2]),
        "follower": _pose_rates(follower_motion, out1, out2),
    }
