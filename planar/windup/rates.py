"""Rates of the wind-up mechanisms and toys: the closed forms differentiated analytically in time.

Each elemental mechanism's forward kinematics (:mod:`planar.windup.kinematics`)
is differentiated twice by hand, sample by sample with arrays, never by
differencing (:func:`forward_rates`):

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
differentiated directly; a toy composes its stages' rates through the same
linear axis maps as their motions (:mod:`planar.windup.chain`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from planar.core.registry import UnsupportedError
from planar.linkages.nodes import RRP, RRR, frame_rates
from planar.windup import params as P_
from planar.windup.mechanisms import ELEMENTAL, ElementalMechanism

if TYPE_CHECKING:
    from planar.core.model import Mechanism

__all__ = ["driver_motion_rates", "elemental_rates", "forward_rates", "windup_rates"]

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


def forward_rates(number: int, params: Any, u: Array, u1: Array, u2: Array) -> tuple[Array, Array, Mask]:
    """First and second time derivatives of mechanism ``number``'s follower motion.

    ``u`` is the driver's motion (``(N,)``, or ``(N, 3)`` for OzT), ``u1`` and
    ``u2`` its time derivatives.  Returns ``(out1, out2, ok)`` shaped like the
    follower motion; ``ok`` false where a differentiated closure is singular.
    """
    rec = ELEMENTAL[number]
    P = P_.in_world(params)
    st = rec.forward(params, u)
    n = u.shape[0]
    ok = np.ones(n, bool)
    if number in (1, 2, 3):
        o = _xy(P.D_o)
        m = st.aux["m"]
        m1, m2 = _turning(o, m, u1, u2)
        if number == 1:
            return m1[:, 0], m2[:, 0], ok
        if number == 2:
            s = _xy(P.F_o)
            w0 = _xy(P.D_jc) - s
            phi1, phi2 = _angle(m - s, m1, m2)
            b1, b2 = _offset_angle(w0[1], 1.0 if w0[0] >= 0 else -1.0, m - s, m1, m2)
            return phi1 - b1, phi2 - b2, ok
        p0 = _xy(P.F_o)
        s = p0 + _xy(P.S_c)
        p = st.aux["p"]
        node = RRR("p", "m", 1.0, "s", 1.0)
        pv, pa, ok = _dyad(
            node, {"p": p, "m": m, "s": np.broadcast_to(s, m.shape)}, {"m": m1, "s": _zeros(n)}, {"m": m2, "s": _zeros(n)}
        )
        al1, al2 = _angle(p - m, pv - m1, pa - m2)
        return np.column_stack([pv, al1]), np.column_stack([pa, al2]), ok
    if number == 4:
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
    if number == 5:
        q = _xy(P.D_o)
        s = _xy(P.F_o)
        p = st.aux["p"]
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
    if number in (6, 9):
        p0 = _xy(P.F_o)
        r = P.F_jr
        N = P.F_o[2] - P.D_o[2]
        if number == 6:
            q = _xy(P.D_o)
            e0 = st.aux["e0"]
            c, sn = np.cos(u), np.sin(u)
            e = np.column_stack([c, sn])
            e0v, e0a = _turning(q, e0, u1, u2)
            ev, ea = _turning(np.zeros(2), e, u1, u2)
        else:
            e0 = st.aux["e0"]
            e = np.broadcast_to(np.array([np.cos(P.phi), -np.sin(P.phi)]), (n, 2))
            e0v, e0a = np.column_stack([u1, np.zeros(n)]), np.column_stack([u2, np.zeros(n)])
            ev = ea = _zeros(n)
        return _oval_rates((e0, e0v, e0a), (e, ev, ea), p0, N, r, st.out)
    if number == 7:
        s = _xy(P.F_o)
        p = st.aux["p"]
        z = np.zeros(n)
        return (*_angle(p - s, np.column_stack([u1, z]), np.column_stack([u2, z])), ok)
    if number == 8:
        B = np.array([P.F_o[0], P.F_o[2]])
        w = st.aux["A"] - B
        z = np.zeros(n)
        w1, w2 = np.column_stack([u1, z]), np.column_stack([u2, z])
        phi1, phi2 = _angle(w, w1, w2)
        b1, b2 = _offset_angle(P.F_jcx, 1.0, w, w1, w2)
        return -(phi1 + b1), -(phi2 + b2), ok
    # 10, 11: the arc slot's centre m = D_o + (dx, dy) moves with the OzT driver
    m = st.aux["m"]
    p = st.aux["p"]
    m1, m2 = u1[:, :2], u2[:, :2]
    z = _zeros(n)
    if number == 10:
        p0 = _xy(P.F_o) + _xy(P.F_jc)
        g1 = np.broadcast_to(np.array([0.0, p0[1]]), m.shape)
        g2 = np.broadcast_to(np.array([1.0, p0[1]]), m.shape)
        node10 = RRP("p", "m", 1.0, "g1", "g2")
        pv, pa, ok = _dyad(node10, {"p": p, "m": m, "g1": g1, "g2": g2}, {"m": m1, "g1": z, "g2": z}, {"m": m2, "g1": z, "g2": z})
        return pv[:, 0], pa[:, 0], ok
    s = _xy(P.F_o)
    node11 = RRR("p", "m", 1.0, "s", 1.0)
    pv, pa, ok = _dyad(node11, {"p": p, "m": m, "s": np.broadcast_to(s, m.shape)}, {"m": m1, "s": z}, {"m": m2, "s": z})
    return (*_angle(p - s, pv, pa), ok)


def driver_motion_rates(mech: ElementalMechanism, q: Array, qd: Array, qdd: Array) -> Jet:
    """The driver's motion and its time derivatives (the OzT path differentiated; else ``q`` itself)."""
    u = mech.driver_motion(q)
    if mech.motion_in != "OzT":
        return u, qd, qdd
    ax, ay = mech.params.path
    th = mech.params.D_theta[1]
    c, s = np.cos(q), np.sin(q)
    d1 = np.column_stack([ax * c, -ay * s, th * c])
    d2 = np.column_stack([-ax * s, -ay * c, -th * s])
    return u, d1 * qd[:, None], d2 * (qd * qd)[:, None] + d1 * qdd[:, None]


def _pose_rates(kind: str, m1: Array, m2: Array) -> tuple[Array, Array, Array, Array]:
    """``(v, a, omega, alpha)`` of a pose affine in a motion, from the motion's rates (``kind``: how it moves)."""
    n = m1.shape[0]
    z, z2 = np.zeros(n), np.zeros((n, 2))
    if kind in ("Rz", "Oz", "Ox", "Ox-yz", "pivot"):
        return z2, z2, m1, m2
    if kind == "-pivot":
        return z2, z2, -m1, -m2
    if kind == "x":
        return np.column_stack([m1, z]), np.column_stack([m2, z]), z, z
    if kind == "y":
        return np.column_stack([z, m1]), np.column_stack([z, m2]), z, z
    return m1[:, :2], m2[:, :2], m1[:, 2], m2[:, 2]  # free / OzT: (dx, dy, angle)


_DRIVER_KIND = {"Rz": "Rz", "Oz": "Oz", "Tx": "x", "OzT": "free"}


def _follower_kind(mech: ElementalMechanism) -> str:
    from planar.windup import mechanisms as M

    fp = mech.record.follower_pose
    table = {M._slide_x: "x", M._slide_y: "y", M._free: "free", M._pivot: "pivot", M._tilt_yz: "pivot", M._pivot_xz: "-pivot"}
    if fp not in table:
        raise UnsupportedError(f"rates: no rule for the follower pose {fp.__name__} of mechanism #{mech.number}")
    return table[fp]


def _stage_part_rates(mech: ElementalMechanism, u: Jet, out1: Array, out2: Array) -> dict[str, tuple[Array, ...]]:
    return {
        "ground": _pose_rates("Rz", np.zeros(out1.shape[0]), np.zeros(out1.shape[0])),
        "driver": _pose_rates(_DRIVER_KIND[mech.motion_in], u[1], u[2]),
        "follower": _pose_rates(_follower_kind(mech), out1, out2),
    }


def elemental_rates(mech: ElementalMechanism, q: Array, qd: Array, qdd: Array) -> tuple[dict[str, tuple[Array, ...]], Mask]:
    """Part rates ``(v, a, omega, alpha)`` of an elemental mechanism (its view plane's coordinates)."""
    u = driver_motion_rates(mech, q, qd, qdd)
    out1, out2, ok = forward_rates(mech.number, mech.params, u[0], u[1], u[2])
    return _stage_part_rates(mech, u, out1, out2), ok & mech.forward(u[0]).valid


def toy_rates(toy: Any, q: Array, qd: Array, qdd: Array) -> tuple[dict[str, tuple[Array, ...]], Mask]:
    """Part rates of a :class:`~planar.windup.chain.ToyMechanism`: each stage's input is its parent's output."""
    from planar.windup.chain import _to_base, _to_world

    outs: dict[int, Jet] = {}
    valid = np.ones(q.shape, bool)
    parts: dict[str, tuple[Array, ...]] = {}
    for st in toy.stages:
        r = st.realisation
        if st.parent is None:
            u = (_to_base(r, q + toy.cam_phase[st.cam]), _to_base(r, qd), _to_base(r, qdd))
        else:
            pw = outs[st.parent]
            u = (_to_base(r, pw[0]), _to_base(r, pw[1]), _to_base(r, pw[2]))
        res = st.mech.forward(u[0])
        o1, o2, ok = forward_rates(r.number, st.mech.params, u[0], u[1], u[2])
        valid &= ok & res.valid
        outs[st.index] = (_to_world(r, res.out), _to_world(r, o1), _to_world(r, o2))
        for name, rates in _stage_part_rates(st.mech, u, o1, o2).items():
            parts[f"{st.label}.{name}"] = rates
    return parts, valid


def windup_rates(mech: Mechanism, q: Array, qd: Array, qdd: Array) -> tuple[dict[str, tuple[Array, ...]], Mask, str]:
    """Part rates ``(v, a, omega, alpha)`` of an elemental mechanism or a toy (see the module's note), with the
    validity and the method's name; other mechanisms are refused by name."""
    from planar.windup.chain import ToyMechanism

    if isinstance(mech, ElementalMechanism):
        raw, ok = elemental_rates(mech, q, qd, qdd)
        return raw, ok, "wind-up closed forms differentiated analytically"
    if isinstance(mech, ToyMechanism):
        raw, ok = toy_rates(mech, q, qd, qdd)
        return raw, ok, "wind-up closed forms differentiated analytically, composed through the toy's stages"
    raise UnsupportedError(
        f"rates (velocities, accelerations, torque): no closed-form derivatives for {type(mech).__name__} {mech.name!r}"
    )
