"""Closed-form forward kinematics of the 11 elemental mechanisms, vectorised.

Each ``forward_N(P, u)`` maps the driver's motion ``u`` (all samples at once)
to the follower's motion, and returns a :class:`Stage` with the validity mask,
the reason for invalid samples and the contact points the joints need.

Parameters are given in the supplement's frames (``D_o`` world, ``D_jc`` and
``F_o`` in the driver's frame, the rest in the follower's; see
:mod:`planar.windup.params`); each ``forward_N`` resolves them with
:func:`~planar.windup.params.in_world` first, so moving ``D_o`` moves the
mechanism and leaves the motion unchanged.

Motion values (radians, model units; counter-clockwise positive about the
named axis, right-handed):

* ``Rz``, ``Oz``, ``Ox``, ``Oy`` — an angle ``(N,)``;
* ``Tx``, ``Ty`` — a displacement ``(N,)``;
* ``OzT`` — ``(N, 3)``: the follower reference point's displacement
  ``(dx, dy)`` and its rotation ``alpha``.

Every formula was checked against an independent numerical solution of the
mechanism's joint conditions (``tests/test_windup_kinematics.py``); where the
supplement's equation was wrong, the correction is noted here (``ERRATA:``)
and listed in ``ERRATA.md``.  No formula divides by a coordinate difference
that can vanish; angles come from ``atan2``; square roots of discriminants
are clamped at zero, and the sample is marked invalid, only beyond round-off.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from planar.core.geometry import circle_circle, line_circle, wrap_angle
from planar.windup import params as P_

__all__ = [
    "Stage",
    "cam_centre",
    "forward_1",
    "forward_2",
    "forward_3",
    "forward_4",
    "forward_5",
    "forward_6",
    "forward_7",
    "forward_8",
    "forward_9",
    "forward_10",
    "forward_11",
    "rot",
]

Array = NDArray[np.float64]


@dataclass
class Stage:
    """Result of one elemental mechanism's forward kinematics."""

    out: Array
    valid: NDArray[np.bool_]
    why: str = ""
    #: named auxiliary points (N, 2) (contact points, cam centres) in the mechanism's view plane
    aux: dict[str, Array] = field(default_factory=dict)


def rot(v, theta: Array) -> Array:
    """Vectors ``v`` (2,) or (N, 2) rotated by ``theta`` (N,): returns (N, 2)."""
    v = np.asarray(v, float)
    c, s = np.cos(theta), np.sin(theta)
    return np.stack([c * v[..., 0] - s * v[..., 1], s * v[..., 0] + c * v[..., 1]], -1)


def cam_centre(D_o, D_jc, theta: Array) -> Array:
    """Cam centre ``m = D_o + R(theta) (D_jc - D_o)``, ``D_jc`` in world (#2: ``m = (q_x - d sin, q_y + d cos)``)."""
    o = np.asarray(D_o, float)[:2]
    return o + rot(np.asarray(D_jc, float) - o, theta)


def _ones(n: int) -> NDArray[np.bool_]:
    return np.ones(n, dtype=bool)


def _xy(v) -> Array:
    return np.asarray(v, float)[:2]


# ---------------------------------------------------------------- #1 Rz -> Tx
def forward_1(P: P_.P1, theta: Array) -> Stage:
    """Scotch yoke: the window follows the cam centre's x.

    ERRATA: the supplement's ``dx = d sin(theta)`` holds for a clockwise
    theta; with counter-clockwise theta and the cam at ``(0, d)`` at rest,
    ``dx = m_x - m0_x = -d sin(theta)`` (computed here for any ``D_jc``).
    """
    P = P_.in_world(P)  # D_jc, F_o: driver frame -> world
    m = cam_centre(P.D_o, P.D_jc, theta)
    m0 = _xy(P.D_jc)
    return Stage(m[:, 0] - m0[0], _ones(theta.size), aux={"m": m})


# ---------------------------------------------------------------- #2 Rz -> Oz
def _window_angle(m: Array, m0, s) -> tuple[Array, NDArray[np.bool_]]:
    """Rotation about ``s`` that keeps the window's mid-line (through ``m0``, along x at rest) on ``m``.

    The line stays at the signed distance ``h0 = (m0 - s)_y`` from ``s``; with
    ``m - s = D (cos phi, sin phi)`` the condition ``D sin(phi - alpha) = h0``
    gives ``alpha = phi - atan2(h0, l)``, ``l = +/-sqrt(D^2 - h0^2)`` the
    along-line coordinate (sign kept from rest).
    """
    s = _xy(s)
    w0 = _xy(m0) - s
    h0 = w0[1]
    sign = 1.0 if w0[0] >= 0 else -1.0
    w = m - s
    D2 = (w * w).sum(-1)
    l2 = (np.sqrt(D2) - abs(h0)) * (np.sqrt(D2) + abs(h0))
    ok = l2 >= -1e-12 * D2
    phi = np.arctan2(w[:, 1], w[:, 0])
    # at rest atan2(h0, sign |w0_x|) = atan2(w0) = phi, so alpha = 0 there
    alpha = phi - np.arctan2(h0, sign * np.sqrt(np.maximum(l2, 0.0)))
    return wrap_angle(alpha), ok


def forward_2(P: P_.P2, theta: Array) -> Stage:
    """Round cam in the window of a pivoted follower.

    ERRATA: the supplement's ``alpha = 90deg - (alpha1 + alpha2)`` with
    ``alpha1 = acos(D1/D)``, ``alpha2 = acos(D2/D)`` is not zero at rest
    (-78.6 deg at the defaults) and does not follow the window.  Corrected:
    ``alpha = phi - atan2(h0, l)`` (see :func:`_window_angle`).
    """
    P = P_.in_world(P)  # D_jc, F_o: driver frame -> world
    m = cam_centre(P.D_o, P.D_jc, theta)
    alpha, ok = _window_angle(m, P.D_jc, P.F_o)
    return Stage(alpha, ok, "the cam centre comes closer to the pivot than the window line", aux={"m": m})


# ---------------------------------------------------------------- #3 Rz -> OzT
def _branch(c1, c2, p0) -> float:
    c1, c2, p0 = _xy(c1), _xy(c2), _xy(p0)
    d, w = c2 - c1, p0 - c1
    return 1.0 if d[0] * w[1] - d[1] * w[0] >= 0 else -1.0


def forward_3(P: P_.P3, theta: Array) -> Stage:
    """Cam in the follower's round hole; the follower's pin ``p`` runs in a track about ``s``.

    ``p`` is the intersection of the circles ``(m, R = |p0 - m0|)`` and
    ``(s, r = |p0 - s|)``.  ERRATA: the supplement's ``c = (...)^2 - (2 m'_x R)^2``
    must use ``r`` (the circle about ``s``); its ``p_x`` divides by
    ``m'_x = m_x - s_x`` (zero when the cam centre passes above ``s``) and its
    angles use ``atan`` of quotients.  Here: the stable circle-circle of
    :func:`planar.core.geometry.circle_circle`, branch fixed at rest, ``atan2``.
    """
    P = P_.in_world(P)  # D_jc, F_o: driver frame -> world
    m0 = _xy(P.D_jc)
    p0 = _xy(P.F_o)
    s = p0 + _xy(P.S_c)
    R = float(np.hypot(*(p0 - m0)))
    r = float(np.hypot(*(p0 - s)))
    m = cam_centre(P.D_o, P.D_jc, theta)
    br = _branch(m0, s, p0)
    p, ok = circle_circle(m, R, np.broadcast_to(s, m.shape), r, br)
    a0 = np.arctan2(*(p0 - m0)[::-1])
    alpha = wrap_angle(np.arctan2(p[:, 1] - m[:, 1], p[:, 0] - m[:, 0]) - a0)
    out = np.column_stack([p[:, 0] - p0[0], p[:, 1] - p0[1], alpha])
    return Stage(out, ok, f"the cam circle (R={R:.4g}) and the track (r={r:.4g}) do not meet", aux={"m": m, "p": p})


# ---------------------------------------------------------------- #4 Oz -> Ty
def forward_4(P: P_.P4, theta: Array) -> Stage:
    """Follower pin (moving along y) in a driver slot parallel to x at rest.

    ``Y = Y0 / cos(theta) + D_x tan(theta)`` (supplement, correct), evaluated
    as ``dy = (D_x sin(theta) + 2 Y0 sin^2(theta/2)) / cos(theta)`` to avoid
    cancellation near rest.  Invalid where the slot turns parallel to the
    follower's path (``cos(theta) = 0``).
    """
    P = P_.in_world(P)  # D_jc, F_o: driver frame -> world
    q = _xy(P.D_o)
    p0 = _xy(P.F_o) + _xy(P.F_jc)
    Dx, Y0 = p0 - q
    c = np.cos(theta)
    ok = np.abs(c) > 1e-9
    dy = (Dx * np.sin(theta) + 2.0 * Y0 * np.sin(0.5 * theta) ** 2) / np.where(ok, c, 1.0)
    p = np.column_stack([np.full_like(theta, p0[0]), p0[1] + dy])
    return Stage(dy, ok, "the slot is parallel to the follower's guide", aux={"p": p})


# ---------------------------------------------------------------- #5 Oz -> Oz
def forward_5(P: P_.P5, theta: Array) -> Stage:
    """Driver slot (a line through ``q + R(theta)(0, d)`` at angle theta) on the follower's pin.

    ERRATA: the supplement's ``p_y = tan(p_x - q'_x) + q'_y`` applies the
    tangent to a coordinate difference (should be ``tan(theta) (p_x - q'_x)``);
    its quadratic's ``b`` lacks ``tan(theta)`` on the intercept and its ``c``
    lacks ``- R^2``; ``tan(theta)`` is unbounded at 90 deg.  Here: line-circle
    with the direction ``(cos, sin)``, branch fixed at rest, ``atan2`` angles.
    """
    P = P_.in_world(P)  # D_jc, F_o: driver frame -> world
    q = _xy(P.D_o)
    s = _xy(P.F_o)
    p0 = s + _xy(P.F_jc)
    R = float(np.hypot(*P.F_jc))
    d = p0[1] - q[1]
    base = q + rot((0.0, d), theta)  # q'
    u = rot((1.0, 0.0), theta)
    # branch: p0 lies on the side of the foot of the perpendicular from s at rest
    s0 = (p0 - q - np.array([0.0, d]))[0]
    foot0 = (s - q - np.array([0.0, d]))[0]
    br = 1.0 if s0 >= foot0 else -1.0
    p, ok, _ = line_circle(base, u, np.broadcast_to(s, base.shape), R, br)
    a0 = np.arctan2(p0[1] - s[1], p0[0] - s[0])
    alpha = wrap_angle(np.arctan2(p[:, 1] - s[1], p[:, 0] - s[0]) - a0)
    return Stage(alpha, ok, f"the driver's slot misses the follower pin's circle (R={R:.4g})", aux={"p": p})


# ---------------------------------------------------------------- #6, #9: line tangent to an oval
def _oval_tangent(e0: Array, e: Array, p0, N: float, r: float, side: float) -> tuple[Array, NDArray[np.bool_]]:
    """Tilt ``alpha`` (about +x) of an upright pin of radius ``r`` touching an edge line.

    The pin's axis passes through ``(p0x, p0y)`` on the follower's pivot axis
    (parallel to x, at height ``N`` relative to the driver's plane) and tilts
    to direction ``(0, -sin a, cos a)``; its section with the driver's plane is
    the supplement's oval (semi-axes ``r`` and ``r / cos a``) centred at
    ``p_y = p0y + N tan a``.  The edge line ``e0 + t e`` (unit ``e``) touches
    the oval iff its distance to the pin's axis is ``r``:
    ``(X - N e_x t)^2 = r^2 (1 + e_x^2 t^2)`` with ``t = tan a`` and ``X`` the
    signed distance of ``p0`` from the line; ``X - N e_x t`` is the signed
    distance of the oval's centre.  A quadratic
    ``e_x^2 (N^2 - r^2) t^2 - 2 X N e_x t + (X^2 - r^2) = 0``, solved in the
    stable form (roots ``q / A`` and ``C / q``); of the two tangencies the pin
    keeps to its side of the edge (``side``, the sign of its centre's distance
    at rest), and if both do, the one nearer rest.

    ERRATA (#6 and #9): the supplement's closed form
    ``alpha = (asin((r^2 - E) / S) - theta') / 2`` has the sign of its
    left-hand side reversed (``E - r^2``, with ``E = (M^2 - L - N^2)/2``); it
    is not zero at rest.  Its ``atan`` also loses the quadrant when ``M N < 0``.
    """
    p0 = _xy(p0)
    w = e0 - p0
    X = e[:, 0] * w[:, 1] - e[:, 1] * w[:, 0]  # cross(e, e0 - p0)
    ex = e[:, 0]
    A = ex * ex * (N * N - r * r)
    B = -2.0 * X * N * ex
    C = X * X - r * r
    disc = B * B - 4 * A * C
    scale = np.maximum(B * B, np.abs(4 * A * C)) + 1e-300
    ok = disc >= -1e-12 * scale
    sq = np.sqrt(np.maximum(disc, 0.0))
    qq = -0.5 * (B + np.where(B >= 0, 1.0, -1.0) * sq)
    safe_q = np.where(qq == 0, 1.0, qq)
    t_near = C / safe_q
    with np.errstate(divide="ignore", invalid="ignore"):
        t_far = np.where(A != 0, qq / np.where(A == 0, 1.0, A), np.inf)
    keeps_near = np.sign(X - N * ex * t_near) == side
    keeps_far = np.isfinite(t_far) & (np.sign(X - N * ex * np.where(np.isfinite(t_far), t_far, 0.0)) == side)
    t = np.where(keeps_near | ~keeps_far, t_near, t_far)
    ok &= (qq != 0) & (keeps_near | keeps_far)
    return np.arctan(t), ok


def forward_6(P: P_.P6, theta: Array) -> Stage:
    """Driver edge (rotating about z) pushing the follower's pin, tilting it about x (spatial)."""
    P = P_.in_world(P)  # D_jc, F_o: driver frame -> world
    q = _xy(P.D_o)
    p0 = _xy(P.F_o)
    r = P.F_jr
    h = p0[1] - q[1] - r  # the edge: the line y = h in the driver's frame (touches the pin at rest)
    e0 = q + rot((0.0, h), theta)
    e = rot((1.0, 0.0), theta)
    N = P.F_o[2] - P.D_o[2]
    side = np.sign(p0[1] - q[1] - h) * -1.0  # cross((1, 0), (0, h) - p0 + q) at rest
    alpha, ok = _oval_tangent(e0, e, p0, N, r, side)
    return Stage(alpha, ok, "the edge cannot touch the tilted pin", aux={"e0": e0})


def forward_9(P: P_.P9, dx: Array) -> Stage:
    """Slanted driver slot (angle phi), translating along x, tilting the follower's pin about x (spatial).

    At rest the slot's edge ``y = -tan(phi) x - r / cos(phi)`` (frame at p0)
    touches the pin, as in the supplement; it translates by ``dx``.
    """
    P = P_.in_world(P)  # D_jc, F_o: driver frame -> world
    p0 = _xy(P.F_o)
    r = P.F_jr
    phi = P.phi
    e = np.broadcast_to(np.array([np.cos(phi), -np.sin(phi)]), (dx.size, 2))
    e0 = np.column_stack([p0[0] + dx, np.full_like(dx, p0[1] - r / np.cos(phi))])
    N = P.F_o[2] - P.D_o[2]
    w0 = np.array([0.0, -r / np.cos(phi)])  # e0 - p0 at rest
    side = float(np.sign(e[0, 0] * w0[1] - e[0, 1] * w0[0]))
    alpha, ok = _oval_tangent(e0, e, p0, N, r, side)
    return Stage(alpha, ok, "the slanted slot cannot touch the tilted pin", aux={"e0": e0})


# ---------------------------------------------------------------- #7 Tx -> Oz
def forward_7(P: P_.P7, dx: Array) -> Stage:
    """Driver pin (moving along x) in a radial slot of the pivoted follower.

    ``alpha = atan2(p - s) - atan2(p0 - s)``.  ERRATA: the supplement's
    ``alpha2 = atan(D_y / (D_x - dx))`` divides by ``D_x - dx``, zero when the
    pin passes under the pivot, and jumps by pi there; atan2 does not.
    """
    P = P_.in_world(P)  # D_jc, F_o: driver frame -> world
    s = _xy(P.F_o)
    p0 = _xy(P.D_jc)
    p = p0 + np.column_stack([dx, np.zeros_like(dx)])
    w = p - s
    ok = np.hypot(w[:, 0], w[:, 1]) > 0
    alpha = wrap_angle(np.arctan2(w[:, 1], w[:, 0]) - np.arctan2(p0[1] - s[1], p0[0] - s[0]))
    return Stage(alpha, ok, "the pin reaches the pivot", aux={"p": p})


# ---------------------------------------------------------------- #8 Tx -> Oy (xz plane)
def forward_8(P: P_.P8, dx: Array) -> Stage:
    """Window edge point ``A`` (moving along x) held against the tab's face (xz plane).

    View coordinates are ``(x, z)``.  The tab pivots about the vertical axis
    ``B``; its face is the line at distance ``D_x = F_jcx`` from ``B``,
    parallel to the tab.  With ``w = A - B``, the face through ``A`` has
    direction ``psi = atan2(w) + atan2(D_x, t)``, ``t = sqrt(|w|^2 - D_x^2)``.
    The returned angle is about +y: ``alpha_y = -(psi - psi0)`` (x toward z
    is a rotation about -y).  ERRATA: the supplement's
    ``alpha = asin(D_x/|BA|) - acos(D_z/|BA|)`` is the face's absolute angle
    from z with unsigned parts; it folds where ``BA`` crosses the z axis.
    """
    P = P_.in_world(P)  # D_jc, F_o: driver frame -> world
    B = np.array([P.F_o[0], P.F_o[2]])
    A0 = B + np.array([P.F_jcx, P.F_jh])
    A = A0 + np.column_stack([dx, np.zeros_like(dx)])
    w = A - B
    n2 = (w * w).sum(-1)
    t2 = n2 - P.F_jcx**2
    ok = t2 >= -1e-12 * n2
    t = np.sqrt(np.maximum(t2, 0.0))
    psi = np.arctan2(w[:, 1], w[:, 0]) + np.arctan2(P.F_jcx, t)
    w0 = A0 - B
    psi0 = np.arctan2(w0[1], w0[0]) + np.arctan2(P.F_jcx, np.sqrt(w0 @ w0 - P.F_jcx**2))
    return Stage(-wrap_angle(psi - psi0), ok, "the contact point is inside the tab's offset", aux={"A": A})


# ---------------------------------------------------------------- #10 OzT -> Tx
def _ozt_centre(D_o, u: Array) -> Array:
    """The driver's arc-slot centre ``m = m0 + (dx, dy)`` (the OzT driver's reference point)."""
    return _xy(D_o) + u[:, :2]


def forward_10(P: P_.P10, u: Array) -> Stage:
    """Follower pin (moving along x at ``y = p0y``) in the driver's arc slot about ``m``.

    ``p_x = m_x + sign * sqrt(R^2 - (p0y - m_y)^2)``.  ERRATA: the supplement's
    ``p_x = sqrt(R^2 - (p0y - m_y)^2)`` is missing the centre ``m_x`` and the
    branch sign.  Computed as a line-circle intersection.
    """
    P = P_.in_world(P)  # D_jc, F_o: driver frame -> world
    m = _ozt_centre(P.D_o, u)
    p0 = _xy(P.F_o) + _xy(P.F_jc)
    R = float(np.hypot(*(p0 - _xy(P.D_o))))
    br = 1.0 if p0[0] >= P.D_o[0] else -1.0
    base = np.broadcast_to(np.array([0.0, p0[1]]), m.shape)
    p, ok, _ = line_circle(base, np.broadcast_to([1.0, 0.0], m.shape), m, R, br)
    return Stage(p[:, 0] - p0[0], ok, f"the arc slot (R={R:.4g}) no longer reaches the pin's guide line", aux={"m": m, "p": p})


# ---------------------------------------------------------------- #11 OzT -> Oz
def forward_11(P: P_.P11, u: Array) -> Stage:
    """Follower pin (on a circle of radius ``r`` about pivot ``s``) in the driver's arc slot about ``m``.

    ERRATA: as #3 (``c`` must use ``r``; division by ``m'_x``); the angles
    ``atan((s_y - p_y) / (s_x - p_x))`` lose the quadrant; atan2 here.
    """
    P = P_.in_world(P)  # D_jc, F_o: driver frame -> world
    m0 = _xy(P.D_o)
    s = _xy(P.F_o)
    p0 = s + _xy(P.F_jc)
    R = float(np.hypot(*(p0 - m0)))
    r = float(np.hypot(*P.F_jc))
    m = _ozt_centre(P.D_o, u)
    br = _branch(m0, s, p0)
    p, ok = circle_circle(m, R, np.broadcast_to(s, m.shape), r, br)
    a0 = np.arctan2(p0[1] - s[1], p0[0] - s[0])
    alpha = wrap_angle(np.arctan2(p[:, 1] - s[1], p[:, 0] - s[0]) - a0)
    return Stage(alpha, ok, f"the arc slot (R={R:.4g}) and the pin's circle (r={r:.4g}) do not meet", aux={"m": m, "p": p})
