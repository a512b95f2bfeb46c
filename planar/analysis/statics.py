"""Velocity, power, virtual work and foot loads (course notes, seed 004, sections 2-3).

Velocities three ways (notes 2.1):

* **algebraic** — the differentiated closure equations, solved as a 2x2 linear
  system per sample (:func:`fourbar_velocities`, :func:`node_velocities`);
* **numerical** — differences along a sampled curve (:func:`finite_difference`);
* **instant centre** — the body's instantaneous centre of rotation from two
  points whose velocity directions are known (:func:`instant_centre`).

Corrections to the notes (verified in ``tests/test_analysis.py``):

* eq. (6) carries a stray ``- r_1`` term; the ground link does not move, so
  the x-equation is ``-r2 sin(t2) w2 - r3 sin(t3) w3 + r4 sin(t4) w4 = 0``.
* eq. (8) is a forward difference, first-order accurate and lagging by half a
  step; :func:`finite_difference` uses central differences (second order,
  periodic wrap for a closed cycle).
* eq. (11) ``5 (4 pi)^2 0.01`` is an upper bound (amplitudes added);
  :func:`fourier_acceleration` gives the true peak, which is lower.

Power (notes eq. 5): with ``F_i`` the force the mechanism exerts on its load
at point ``i`` (so ``F . V > 0`` is work done on the load) and the motor
turning at ``w``, ``tau w eta_trans eta_link = sum_i F_i . V_i`` where the
motor drives the load; where the load drives the motor (regenerative, power
flowing back) the losses reduce what reaches the motor:
``tau w = eta_trans eta_link sum_i F_i . V_i``.  Angles in radians, angular
speeds in rad/s, torques in force x model-unit.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from planar.core.fields import check_driver_rates, check_finite, check_kind, check_number, check_samples
from planar.errors import InputError

if TYPE_CHECKING:
    from planar.linkages.fourbar import FourBar
    from planar.linkages.linkage import Linkage

__all__ = [
    "TOGGLE_SINE",
    "finite_difference",
    "fourbar_accelerations",
    "fourbar_instant_centre",
    "fourbar_velocities",
    "fourier_acceleration",
    "fourier_peak_bound",
    "friction_limit",
    "input_torque",
    "instant_centre",
    "motor_torque",
    "node_velocities",
    "point_velocities",
    "static_foot_loads",
    "velocity_about_centre",
    "virtual_work_torque",
    "world_velocity",
]

Array = NDArray[np.float64]


def _cross(a: Array, b: Array) -> Array:
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def _perp(v: Array) -> Array:
    return np.stack([-v[..., 1], v[..., 0]], axis=-1)


# --------------------------------------------------------------------------
# algebraic velocities
# --------------------------------------------------------------------------


#: the one validity rule of the four-bar's velocity analysis: a sample is valid where the linkage
#: assembles, the coupler and rocker are not within this sine of being in line (a toggle, where the
#: velocities grow without bound) and every number is finite
TOGGLE_SINE = 1e-6


def fourbar_velocities(fb: FourBar, theta: ArrayLike, omega2: ArrayLike = 1.0) -> tuple[Array, Array, NDArray[np.bool_]]:
    """Coupler and rocker angular velocities ``(omega3, omega4, valid)``.

    Notes eqs. (6)-(7), corrected (no ``r_1`` term), solved per sample with
    ``numpy.linalg.solve`` on an ``(N, 2, 2)`` stack, in units of the crank
    (scale-free: lengths divided by the crank).  ``valid`` is false where
    the linkage does not assemble, within :data:`TOGGLE_SINE` of a toggle
    (coupler and rocker in line) or where a result is not finite; invalid
    samples hold 0.
    """
    _check_fourbar("fourbar_velocities(fb)", fb)
    th2 = check_samples("fourbar_velocities(theta)", theta)
    w2 = np.broadcast_to(check_samples("fourbar_velocities(omega2)", omega2, th2.shape[0]), th2.shape)
    th3, th4, ok = fb.angles(th2)
    g = fb.dims
    b, c = g.b / g.a, g.c / g.a  # scale-free: lengths in crank lengths
    m = np.empty(th2.shape + (2, 2))
    m[..., 0, 0] = -b * np.sin(th3)
    m[..., 0, 1] = c * np.sin(th4)
    m[..., 1, 0] = b * np.cos(th3)
    m[..., 1, 1] = -c * np.cos(th4)
    rhs = np.stack([np.sin(th2) * w2, -np.cos(th2) * w2], axis=-1)
    det = m[..., 0, 0] * m[..., 1, 1] - m[..., 0, 1] * m[..., 1, 0]  # = b c sin(th4 - th3)
    sing = ~(np.abs(det) > TOGGLE_SINE * b * c)
    m[sing] = np.eye(2)
    sol = np.linalg.solve(m, rhs[..., None])[..., 0]
    valid = ok & ~sing & np.isfinite(sol).all(-1) & np.isfinite(w2)
    w3 = np.where(valid, sol[..., 0], 0.0)
    w4 = np.where(valid, sol[..., 1], 0.0)
    return w3, w4, valid


def fourbar_accelerations(
    fb: FourBar, theta: ArrayLike, omega2: ArrayLike = 1.0, alpha2: ArrayLike = 0.0
) -> tuple[Array, Array, NDArray[np.bool_]]:
    """Coupler and rocker angular accelerations ``(alpha3, alpha4, valid)`` (rad/s^2).

    The loop ``a e^(i t2) + b e^(i t3) - c e^(i t4) - d = 0`` differentiated
    twice, in the link angles (Norton's formulation, independent of the node
    kinds' point formulation)::

        -b sin t3 al3 + c sin t4 al4 = a al2 sin t2 + a w2^2 cos t2 + b w3^2 cos t3 - c w4^2 cos t4
         b cos t3 al3 - c cos t4 al4 = -a al2 cos t2 + a w2^2 sin t2 + b w3^2 sin t3 - c w4^2 sin t4

    with ``w3, w4`` from :func:`fourbar_velocities`; the same matrix, singular
    at a toggle.
    """
    th2 = np.atleast_1d(np.asarray(theta, float))
    w2 = np.broadcast_to(np.asarray(omega2, float), th2.shape)
    al2 = np.broadcast_to(np.asarray(alpha2, float), th2.shape)
    th3, th4, ok = fb.angles(th2)
    w3, w4, okv = fourbar_velocities(fb, th2, w2)
    g = fb.dims
    s2, c2, s3, c3, s4, c4 = np.sin(th2), np.cos(th2), np.sin(th3), np.cos(th3), np.sin(th4), np.cos(th4)
    r1 = g.a * al2 * s2 + g.a * w2**2 * c2 + g.b * w3**2 * c3 - g.c * w4**2 * c4
    r2 = -g.a * al2 * c2 + g.a * w2**2 * s2 + g.b * w3**2 * s3 - g.c * w4**2 * s4
    det = (-g.b * s3) * (-g.c * c4) - (g.c * s4) * (g.b * c3)
    sing = np.abs(det) <= 1e-12 * g.b * g.c
    det = np.where(sing, 1.0, det)
    al3 = (r1 * (-g.c * c4) - (g.c * s4) * r2) / det
    al4 = ((-g.b * s3) * r2 - (g.b * c3) * r1) / det
    return al3, al4, ok & okv & ~sing


def node_velocities(link: Linkage, q: ArrayLike, qdot: ArrayLike = 1.0) -> tuple[dict[str, Array], NDArray[np.bool_]]:
    """Velocity ``(N, 2)`` of every node of a :class:`~planar.linkages.Linkage`.

    Each dyad's closure conditions are differentiated and solved as a 2x2
    linear system per sample (Cramer's rule, vectorised):

    * RRR ``P``: ``(P - A) . (vP - vA) = 0`` and ``(P - B) . (vP - vB) = 0``;
    * RRP ``P`` on the line ``p + s w`` (offset ``e``): the distance condition
      to ``A`` and ``cross(w, P - p) = e |w|`` differentiated;
    * Rigid: ``vP = vA + omega perp(P - A)`` with the frame's ``omega``.

    With ``qdot = 1`` the results are velocity coefficients ``dX/dq``.
    ``valid`` is false where the position does not close, within
    :data:`TOGGLE_SINE` of a dyad's toggle (the rule of
    :func:`fourbar_velocities`) or where a velocity is not finite; invalid
    samples hold 0.  Velocities are in the linkage's own frame before
    placement; rotate them by ``placement[2]`` for the world.
    """
    _check_linkage("node_velocities(link)", link)
    q, qdot = check_driver_rates("node_velocities", q, qdot)  # named as the caller wrote them
    vel, valid = link.node_velocities(q, qdot)
    ok = np.asarray(valid, bool) & _dyad_mask(link, q)
    for v in vel.values():
        ok &= np.isfinite(v).all(-1)
    return {k: np.where(ok[:, None], v, 0.0) for k, v in vel.items()}, ok


def _dyad_mask(link: Linkage, q: ArrayLike) -> NDArray[np.bool_]:
    """The one validity rule for a linkage's velocities: no dyad within :data:`TOGGLE_SINE` of its toggle.

    An RRR node ``P`` (links from ``A`` and ``B``) toggles where ``P - A`` and ``P - B`` fall into
    line; an RRP node where its rod ``P - A`` stands square to the slide line ``p -> q``.  Scale-free:
    sines of angles, not lengths.
    """
    qa = np.atleast_1d(np.asarray(q, float))
    pos, _ = link.solve_nodes(qa)
    ok = np.ones(qa.shape[0], bool)
    P: dict[str, Array] = {k: np.asarray(v, float) for k, v in pos.items()}
    for node in link.nodes:
        margin = node.toggle_margin(P)  # each kind knows its toggle (None: it has none)
        if margin is not None:
            ok &= margin > TOGGLE_SINE
    return ok


def point_velocities(link: Linkage, q: ArrayLike, qdot: ArrayLike = 1.0) -> tuple[dict[str, Array], NDArray[np.bool_]]:
    """World velocities ``(N, 2)`` of the linkage's named points (placement applied)."""
    _check_linkage("point_velocities(link)", link)
    q, qdot = check_driver_rates("point_velocities", q, qdot)  # named as the caller wrote them
    vel, valid = node_velocities(link, q, qdot)
    ang = link.placement[2]
    c, s = np.cos(ang), np.sin(ang)
    out = {}
    for pname, node in link.point_nodes.items():
        v = vel[node]
        out[pname] = np.stack([c * v[:, 0] - s * v[:, 1], s * v[:, 0] + c * v[:, 1]], -1)
    return out, valid


# --------------------------------------------------------------------------
# numerical velocities and instant centres
# --------------------------------------------------------------------------


def finite_difference(x: ArrayLike, step: float, periodic: bool = True) -> Array:
    """Derivative of samples ``x`` (axis 0) spaced ``step`` apart, central differences.

    ``periodic=True`` treats the samples as one closed cycle (the last sample
    is followed by the first); otherwise the ends use one-sided second-order
    differences.  Error is ``O(step^2)``.
    """
    x = np.asarray(x, float)
    if periodic:
        return (np.roll(x, -1, axis=0) - np.roll(x, 1, axis=0)) / (2.0 * step)
    return np.gradient(x, step, axis=0, edge_order=2)


def instant_centre(p1: ArrayLike, v1: ArrayLike, p2: ArrayLike, v2: ArrayLike) -> tuple[Array, Array, NDArray[np.bool_]]:
    """Instant centre of a body from two of its points and their velocities.

    The centre lies on the normal to each velocity (notes 2.1.1).  Returns
    ``(centre, omega, valid)``; ``omega`` (rad/s, CCW positive) follows from
    ``v1 = omega perp(p1 - centre)``.  ``valid`` is false where the normals
    are parallel (the body translates: centre at infinity, ``omega = 0``).
    """
    p1, v1, p2, v2 = (
        check_finite(f"instant_centre({k})", a) for k, a in zip(("p1", "v1", "p2", "v2"), (p1, v1, p2, v2), strict=True)
    )
    if p1.shape[-1:] != (2,) or not p1.shape == v1.shape == p2.shape == v2.shape:
        shapes = ", ".join(str(a.shape) for a in (p1, v1, p2, v2))
        raise InputError(
            "instant_centre(p1, v1, p2, v2)", f"arrays of shapes {shapes}", "points and velocities of one shape (..., 2)"
        )
    with np.errstate(over="ignore", invalid="ignore"):  # beyond float64: marked invalid below, not printed
        n1, n2 = _perp(v1), _perp(v2)  # directions of the normals
        den = _cross(n1, n2)
        scale = np.hypot(*n1.T) * np.hypot(*n2.T)
        ok = np.abs(den) > 1e-12 * np.maximum(scale, np.finfo(float).tiny)
        s = _cross(p2 - p1, n2) / np.where(ok, den, 1.0)
        centre = p1 + s[..., None] * n1
        r1 = p1 - centre
        omega = np.where(ok, _cross(r1, v1) / np.maximum((r1 * r1).sum(-1), np.finfo(float).tiny), 0.0)
    ok = ok & np.isfinite(centre).all(-1) & np.isfinite(omega) & np.isfinite(den)  # beyond float64: no centre
    return np.where(ok[..., None], centre, 0.0), np.where(ok, omega, 0.0), ok


def velocity_about_centre(point: ArrayLike, centre: ArrayLike, omega: ArrayLike) -> Array:
    """Velocity ``omega perp(point - centre)`` of a point of a body rotating about ``centre``."""
    point, centre = np.asarray(point, float), np.asarray(centre, float)
    return np.asarray(omega, float)[..., None] * _perp(point - centre)


def fourbar_instant_centre(fb: FourBar, theta: ArrayLike, omega2: float = 1.0) -> tuple[Array, Array, NDArray[np.bool_]]:
    """The coupler's instant centre (intersection of lines O2-B and O4-C) and its omega.

    Graphical method of notes 2.1.1, in the linkage's own frame.  ``valid``
    follows :func:`fourbar_velocities`' rule (assembled, not at a toggle,
    finite) and is also false where the two lines are parallel (the coupler
    translates: ``omega = 0``, centre at infinity).  ``omega`` is 0 where
    invalid.
    """
    _check_fourbar("fourbar_instant_centre(fb)", fb)
    th = check_samples("fourbar_instant_centre(theta)", theta)
    omega2 = check_number("fourbar_instant_centre(omega2)", omega2)
    pos, _ = fb.solve_nodes(th)
    B, C, O2, O4 = pos["B"], pos["C"], pos["O2"], pos["O4"]
    vB = omega2 * _perp(B - O2)
    vC_dir = _perp(C - O4)  # direction only; the magnitude is unknown
    centre, _, ok = instant_centre(B, vB, C, vC_dir)
    _, _, vok = fourbar_velocities(fb, th, omega2)
    r = B - centre
    omega = _cross(r, vB) / np.maximum((r * r).sum(-1), np.finfo(float).tiny)
    valid = ok & vok & np.isfinite(centre).all(-1) & np.isfinite(omega)
    return np.where(valid[..., None], centre, 0.0), np.where(valid, omega, 0.0), valid


def world_velocity(
    v_relative: ArrayLike, v_frame: ArrayLike, omega_frame: ArrayLike = 0.0, r_from_frame_origin: ArrayLike | None = None
) -> Array:
    """Absolute velocity of a point on a moving machine (notes 2.1.4).

    ``v_world = v_frame + omega_frame x r + v_relative``; with a machine that
    only translates (``omega_frame = 0``) this is the notes' vector sum.
    """
    v = np.asarray(v_frame, float) + np.asarray(v_relative, float)
    if r_from_frame_origin is not None:
        v = v + np.asarray(omega_frame, float)[..., None] * _perp(np.asarray(r_from_frame_origin, float))
    return v


# --------------------------------------------------------------------------
# power and virtual work
# --------------------------------------------------------------------------


def _check_eff(name: str, eta: float) -> float:
    try:
        e = float(eta)
    except (TypeError, ValueError):
        raise InputError(name, eta, "an efficiency in (0, 1]") from None
    if not (0.0 < e <= 1.0):
        raise InputError(name, eta, "an efficiency in (0, 1]")
    return float(eta)


def input_torque(coefficients: ArrayLike, forces: ArrayLike, eta_trans: float = 1.0, eta_link: float = 1.0) -> Array:
    """Motor torque per sample from velocity coefficients and loads (notes eq. 5).

    ``coefficients`` ``(N, k, 2)`` holds ``dX_i/dq`` for ``k`` load points;
    ``forces`` ``(N, k, 2)`` or ``(k, 2)`` the forces the mechanism exerts on
    them.  With ``P = sum_i F_i . dX_i/dq`` (the power per unit input speed
    the loads take):

    * ``P >= 0`` (the motor drives the load): ``tau = P / (eta_trans eta_link)``,
      the motor supplies the losses too;
    * ``P < 0`` (regenerative: the load drives the motor, as a foot pushed
      back): ``tau = P eta_trans eta_link``, the losses eat into what reaches
      the motor, so it is held back by less than the lossless ``P``.

    Efficiencies in ``(0, 1]``; non-finite coefficients or forces raise
    :class:`InputError`.
    """
    eta = _check_eff("eta_trans", eta_trans) * _check_eff("eta_link", eta_link)
    c = np.asarray(coefficients, float)
    f = np.asarray(forces, float)
    if not np.isfinite(f).all():
        raise InputError("forces", f, "finite forces")
    if c.ndim != 3 or c.shape[-1] != 2:
        raise InputError("coefficients", f"an array of shape {c.shape}", "shape (N, k, 2)")
    try:
        f = np.broadcast_to(f, c.shape)
    except ValueError:
        raise InputError("forces", f"an array of shape {f.shape}", f"shape (k, 2) or (N, k, 2) with {c.shape}") from None
    p = (c * f).sum(axis=(-1, -2))
    return _with_losses(p, eta)


def virtual_work_torque(
    points: ArrayLike,
    q: ArrayLike,
    forces: ArrayLike,
    periodic: bool = True,
    valid: ArrayLike | None = None,
) -> tuple[Array, NDArray[np.bool_]]:
    """Torque by virtual work (notes eqs. 12-13): ``tau dq = sum_i F_i . dX_i``; returns ``(tau, valid)``.

    ``points`` ``(N, k, 2)`` sampled at evenly spaced driver values ``q``;
    displacements by central differences (``O(dq^2)``).  Ideal (no losses).
    ``valid`` (the motion's mask, default all) marks usable samples; a
    torque is valid where its sample and both neighbours of the difference
    are valid and it is finite (0 where not).
    """
    P = check_finite("virtual_work_torque(points)", points)
    qa = check_finite("virtual_work_torque(q)", q)
    if not isinstance(periodic, (bool, np.bool_)):
        raise InputError("virtual_work_torque(periodic)", periodic, "True or False")
    if P.ndim != 3 or P.shape[-1] != 2 or qa.shape != P.shape[:1] or len(qa) < 3:
        raise InputError("points, q", f"arrays of shapes {P.shape}, {qa.shape}", "points (N, k, 2) and q (N,) with N >= 3")
    f = check_finite("virtual_work_torque(forces)", forces)
    try:
        np.broadcast_shapes(f.shape, P.shape)
    except ValueError:
        raise InputError(
            "virtual_work_torque(forces)", f"an array of shape {f.shape}", f"forces of a shape that fits points {P.shape}"
        ) from None
    dq = float(qa[1] - qa[0])
    if not (np.isfinite(dq) and dq != 0):
        raise InputError("q", qa, "evenly spaced, distinct driver values")
    dX = finite_difference(P, dq, periodic)
    f = np.broadcast_to(f, P.shape)
    tau = (dX * f).sum(axis=(-1, -2))
    if valid is not None and (np.asarray(valid).dtype != bool or np.shape(valid) != qa.shape):
        raise InputError("virtual_work_torque(valid)", valid, f"truth values, one per driver value ({len(qa)})")
    ok = np.ones(len(qa), bool) if valid is None else np.asarray(valid, bool).copy()
    ok &= np.isfinite(P).all(axis=(-1, -2))
    if periodic:
        near = ok & np.roll(ok, 1) & np.roll(ok, -1)
    else:
        near = ok.copy()
        near[1:-1] &= ok[:-2] & ok[2:]
        near[0] &= ok[1] & ok[2]
        near[-1] &= ok[-2] & ok[-3]
    near &= np.isfinite(tau)
    return np.where(near, tau, 0.0), near


def motor_torque(
    link: Linkage,
    q: ArrayLike,
    loads: Mapping[str, ArrayLike],
    eta_trans: float = 1.0,
    eta_link: float = 1.0,
) -> tuple[Array, NDArray[np.bool_]]:
    """Input torque a linkage needs for forces at its named points (several feet, one motor).

    ``loads`` maps a named point to the force ``(2,)`` or ``(N, 2)`` the
    mechanism exerts there (world frame).  Returns ``(tau, valid)``; each
    load's ideal share is the one load term of the motor torque
    (:func:`planar.analysis.dynamics.load_torque`, with the linkage's exact
    velocity coefficients), losses as :func:`input_torque` (divided by the
    efficiency where the motor drives, multiplied where the load drives the
    motor).  ``valid`` is the velocity analysis' mask (:func:`point_velocities`) and false where
    the torque is not finite.
    """
    from planar.analysis.dynamics import load_torque
    from planar.analysis.rates import mechanism_rates

    eta = _check_eff("eta_trans", eta_trans) * _check_eff("eta_link", eta_link)
    from planar.core.model import check_finite

    qa = np.atleast_1d(check_finite(f"{link.name}: q", q))
    for name in loads:
        if name not in link.points:
            raise InputError(f"{link.name}.loads", name, f"a named point, one of {sorted(link.points)}")
    forces = {}
    for n, f0 in loads.items():
        f = check_finite(f"{link.name}.loads[{n!r}]", f0)
        if not np.isfinite(f).all():
            raise InputError(f"{link.name}.loads[{n!r}]", f0, "a finite force (x, y)")
        try:
            forces[n] = np.broadcast_to(f, qa.shape + (2,))
        except ValueError:
            raise InputError(
                f"{link.name}.loads[{n!r}]", f"an array of shape {f.shape}", f"a force of shape (2,) or ({len(qa)}, 2)"
            ) from None
    coef, ok_rates, _ = mechanism_rates(link, qa, 1.0, 0.0)
    _, valid = point_velocities(link, qa, 1.0)  # the velocity analysis' rule near toggles (as fourbar_velocities)
    valid = np.asarray(valid, bool) & ok_rates
    if not forces:
        return np.zeros(qa.shape), np.asarray(valid, bool)
    motion = link.solve(qa)
    p = np.zeros(qa.shape)
    for n, f in forces.items():
        p += load_torque(link, motion, coef, n, f)
    tau = _with_losses(p, eta)
    ok = np.asarray(valid, bool) & motion.valid & np.isfinite(tau)
    return np.where(ok, tau, 0.0), ok


def _with_losses(p: Array, eta: float) -> Array:
    """The motor's torque for an ideal ``p`` with efficiency ``eta``: ``p / eta`` where the motor drives
    (``p >= 0``), ``p eta`` where the load drives the motor."""
    return np.where(p >= 0, p / eta, p * eta)


# --------------------------------------------------------------------------
# foot forces (notes 2.2)
# --------------------------------------------------------------------------


def static_foot_loads(weight: float, com_x: ArrayLike, foot_x: ArrayLike, contact: ArrayLike) -> tuple[Array, NDArray[np.bool_]]:
    """Normal load on each foot in contact, from weight and the centre of mass.

    Vertical force balance ``sum f_i = W`` and moment balance about the
    centre of mass ``sum f_i (x_i - x_c) = 0``, least-norm over the feet in
    contact (statically indeterminate with three or more).  ``foot_x`` and
    ``contact`` are ``(N, k)``.  Returns ``(loads (N, k), stable)``:
    ``stable`` is false where the centre of mass is outside the feet's span
    (the balance needs a negative, pulling foot) or no foot touches.
    """
    if check_number("static_foot_loads(weight)", weight) < 0:  # a negative weight pulls the feet up
        raise InputError("static_foot_loads(weight)", weight, "a weight >= 0 (force units)")
    weight = float(weight)
    fx = np.atleast_2d(check_finite("static_foot_loads(foot_x)", foot_x))
    if fx.ndim != 2:
        raise InputError("static_foot_loads(foot_x)", f"an array of shape {fx.shape}", "foot positions (N, k)")
    if np.asarray(contact).dtype != bool or np.atleast_2d(contact).shape != fx.shape:
        raise InputError("static_foot_loads(contact)", contact, f"truth values of foot_x's shape {fx.shape}")
    on = np.atleast_2d(np.asarray(contact, bool))
    xc = np.broadcast_to(check_samples("static_foot_loads(com_x)", com_x, fx.shape[0]), fx.shape[:1])
    n, k = fx.shape
    A = np.zeros((n, 2, k))
    A[:, 0, :] = on
    A[:, 1, :] = on * (fx - xc[:, None])
    b = np.zeros((n, 2))
    b[:, 0] = weight
    f = np.einsum("nkj,nj->nk", np.linalg.pinv(A), b)
    f = np.where(on, f, 0.0)
    # one foot down: it carries the whole weight (moment balance is impossible: the machine tips
    # unless the centre of mass is right above it)
    one = on.sum(1) == 1
    f[one] = np.where(on[one], weight, 0.0)
    moment = np.where(on, f * (fx - xc[:, None]), 0.0).sum(1)
    stable = (
        on.any(1)
        & np.all(f >= -1e-9 * abs(weight), axis=1)
        & np.isclose(f.sum(1), weight)
        & (np.abs(moment) <= 1e-9 * abs(weight) * (1 + np.abs(fx).max(1)))
    )
    return f, stable


def fourier_acceleration(amplitudes: ArrayLike, freq_hz: float, t: ArrayLike, phases: ArrayLike | None = None) -> Array:
    """Vertical acceleration of ``y = sum_k Y_k sin(k w t + phi_k)`` (notes eqs. 9-10).

    ``y'' = -sum_k k^2 w^2 Y_k sin(k w t + phi_k)``, ``w = 2 pi freq``.
    """
    Y = np.asarray(amplitudes, float)
    ph = np.zeros_like(Y) if phases is None else np.asarray(phases, float)
    w = 2 * np.pi * freq_hz
    k = np.arange(1, Y.size + 1)
    tt = np.asarray(t, float)[..., None]
    return -(k**2 * w**2 * Y * np.sin(k * w * tt + ph)).sum(-1)


def fourier_peak_bound(amplitudes: ArrayLike, freq_hz: float) -> float:
    """Upper bound ``w^2 sum k^2 |Y_k|`` of the peak acceleration (the notes' eq. 11)."""
    Y = np.abs(np.asarray(amplitudes, float))
    k = np.arange(1, Y.size + 1)
    return float((2 * np.pi * freq_hz) ** 2 * (k**2 * Y).sum())


def friction_limit(f_t: ArrayLike, f_n: ArrayLike, mu: float) -> tuple[Array, NDArray[np.bool_]]:
    """Clip tangential forces to the friction cone ``|f_t| <= mu f_n``; also return where a foot slips."""
    if mu < 0:
        raise InputError("mu", mu, "a friction coefficient >= 0")
    ft = np.asarray(f_t, float)
    cap = mu * np.maximum(np.asarray(f_n, float), 0.0)
    return np.clip(ft, -cap, cap), np.abs(ft) > cap


def _check_fourbar(field: str, fb: object) -> None:
    from planar.linkages.fourbar import FourBar

    check_kind(field, fb, FourBar)


def _check_linkage(field: str, link: object) -> None:
    from planar.linkages.linkage import Linkage

    check_kind(field, link, Linkage)
