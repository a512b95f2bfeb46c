"""Inverse dynamics of a driven mechanism from its analytic motion: the torque the driver needs.

Every effect a scene names enters: inertia of every moving part (mass and
moment from its outline), gravity, loads at named points, springs (stiffness
and their own damping) and the space's velocity damping.  By virtual work
(d'Alembert), for a driver turning at ``w = dq/dt``::

    tau = sum_parts [ m (a_G - g + lam v_G) . dX_G/dq + I (alpha + lam omega) dphi/dq ]
          + sum_loads F . dX/dq + sum_springs f dL/dq

with ``lam = -ln(damping)`` (pymunk keeps ``damping ** dt`` of every body's
velocity per step, i.e. a drag ``-lam m v`` on every mass element), ``f``
the spring's tension ``k (L - rest) + c dL/dt`` and ``L`` its length.
Torque in model force units x model units, counter-clockwise positive, the
torque the motor applies to the driven part.

The sum is written once, :func:`motor_torque_from_rates`; it takes the rates
and velocity coefficients from its caller: exact ones from the kinds' closed
forms (:func:`planar.analysis.rates.motor_torque`, the motion tables'
``torque`` column) or central differences in time of the closed-form solve
(:func:`inverse_dynamics_torque`, step ``1e-4`` of the period, for any
mechanism and any sample times; the physics comparison uses it).  Nothing
here imports pymunk.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from planar.core.geometry import poses_apply
from planar.core.model import Mechanism, Motion
from planar.core.rates import PartRates, point_rates
from planar.errors import InputError

__all__ = [
    "gravity_and_damping",
    "inverse_dynamics_torque",
    "load_torque",
    "mass_properties",
    "motor_torque_from_rates",
    "part_mass_table",
    "plane_gravity",
]

Array = NDArray[np.float64]


def gravity_and_damping(effects: Any) -> tuple[Array, float]:
    """The scene's gravity ``(gx, gy)`` (zero if none) and its damping as a rate ``lam = -ln(damping)`` (1/s:
    pymunk keeps ``damping`` of every velocity per second, so the drag force is ``lam m v``; 0 if none)."""
    g = np.zeros(2)
    lam = 0.0
    if effects is not None:
        if effects.gravity is not None:
            g = np.asarray(effects.gravity, float)
        if effects.damping is not None:
            lam = -math.log(float(effects.damping))
    return g, lam


def plane_gravity(plane: str, g: Any) -> Array:
    """The scene's gravity ``(gx, gy)`` as it acts on a part moving in ``plane`` (that plane's two axes).

    A toy's gravity is the 3D vector ``(gx, gy, 0)`` in the toy's frame (the
    scene names no z).  ``"xy"`` takes it as given; ``"xz"`` (the pieces of
    wind-up #8) feels ``(gx, 0)``: ``gy`` runs along the plane's normal, the
    axis the piece turns about, where it does no work; ``"yz"`` (the followers
    of #6/#9) feels ``(gy, 0)``: ``gx`` is that plane's normal.  (Until
    2026-11-22 an xz piece took ``gy`` along z, so a toy lying with gravity
    along -y had its #8 tabs held by a gravity that cannot reach them.)
    """
    g = np.asarray(g, float)
    if plane == "yz":
        return np.array([g[1], 0.0])
    if plane == "xz":
        return np.array([g[0], 0.0])
    return g


def _ring_moments(xy: Array) -> tuple[float, float, float, float]:
    """Signed area, first moments and polar second moment (about the origin) of a closed ring."""
    x, y = xy[:, 0], xy[:, 1]
    x1, y1 = np.roll(x, -1), np.roll(y, -1)
    cross = x * y1 - x1 * y
    a = 0.5 * cross.sum()
    sx = (cross * (x + x1)).sum() / 6.0
    sy = (cross * (y + y1)).sum() / 6.0
    jz = (cross * (x * x + x * x1 + x1 * x1 + y * y + y * y1 + y1 * y1)).sum() / 12.0
    return a, sx, sy, jz


def mass_properties(part: Any, density: float) -> tuple[float, tuple[float, float], float]:
    """``(mass, centre of gravity, moment about it)`` of a part's outline (holes removed).

    Polygon formulas (Green's theorem) over the exterior (counter-clockwise)
    and the holes (clockwise), so the holes subtract.  Part frame, model units.
    """
    from shapely.geometry.polygon import orient

    from planar.core.fields import check_kind, check_number
    from planar.core.model import Part

    check_kind("mass_properties(part)", part, Part)
    if check_number("mass_properties(density)", density) < 0:  # 0: a massless part
        raise InputError("mass_properties(density)", density, "a density >= 0")
    poly = orient(part.outline, sign=1.0)  # exterior counter-clockwise, holes clockwise: signed sums
    rings = [np.asarray(poly.exterior.coords)[:-1]] + [np.asarray(r.coords)[:-1] for r in poly.interiors]
    A = Sx = Sy = J = 0.0
    for r in rings:
        a, sx, sy, jz = _ring_moments(r)
        A += a
        Sx += sx
        Sy += sy
        J += jz
    cx, cy = Sx / A, Sy / A
    mass = density * A
    moment = density * (J - A * (cx * cx + cy * cy))
    return mass, (cx, cy), moment


def check_densities(densities: object, mech: Mechanism, where: str = "densities") -> dict[str, float]:
    """The per-part densities ``densities`` (``{part name: density}`` or ``None``) checked against ``mech``.

    The one check of every function that takes them (:func:`inverse_dynamics_torque`,
    :func:`planar.physics.simulate`, ...): each key a part of ``mech``, each density a finite number
    ``>= 0`` (0: a massless part).  An :class:`~planar.errors.InputError` names the entry as the caller
    wrote it (``densities['crank'] = -1``); returns the densities as floats (``{}`` for ``None``).
    """
    from planar.core.fields import check_kind, check_number

    if densities is None:
        return {}
    check_kind(where, densities, dict, "a dict of part name to density (or None)")
    names = [p.name for p in mech.parts]
    out: dict[str, float] = {}
    for part, rho in densities.items():  # type: ignore[attr-defined]
        if part not in names:
            raise InputError(f"{where} key", part, f"the name of a part of {mech.name!r} (one of {', '.join(names)})")
        if check_number(f"{where}[{part!r}]", rho) < 0:
            raise InputError(f"{where}[{part!r}]", rho, "a density >= 0 (0: a massless part)")
        out[part] = float(rho)
    return out


def part_mass_table(
    mech: Mechanism, effects: Any, densities: dict[str, float] | None = None
) -> dict[str, tuple[float, tuple[float, float], float]]:
    """``mass_properties`` of every moving part at the scene's (or the per-part) density."""
    density = effects.density if effects is not None else 1.0
    return {p.name: mass_properties(p, (densities or {}).get(p.name, density)) for p in mech.parts if not p.ground}


def _wrapped(d: Array) -> Array:
    return np.remainder(d + np.pi, 2 * np.pi) - np.pi


def _spring_length(s: Any, poses: Mapping[str, Array]) -> Array:
    pa = poses_apply(poses[s.a], np.asarray(s.anchor_a, float))
    pb = poses_apply(poses[s.b], np.asarray(s.anchor_b, float))
    return np.hypot(*(pb - pa).T)


def inverse_dynamics_torque(
    mech: Mechanism, t: Array, effects: Any = None, densities: dict[str, float] | None = None, t_rest: float | None = None
) -> Array:
    """Motor torque needed at times ``t`` (s) for a driver turning at its constant rate, for any mechanism.

    The one virtual-work sum (:func:`motor_torque_from_rates`) with every part's rates taken by central
    differences in time of the closed-form solve (step ``1e-4`` of the period), and the velocity
    coefficients as those rates over the driver's rate: this works for a mechanism kind without
    closed-form rates too.  :func:`planar.analysis.rates.motor_torque` feeds the same sum exact rates.

    ``effects``: an :class:`~planar.core.effects.Effects`-like record (gravity,
    loads, springs, damping, density) or ``None``; ``densities`` overrides
    the density per part; ``t_rest``: the time at which a spring with no
    rest length has its rest length (default ``t[0]``, as the rebuild does).
    """
    from planar.core.fields import check_kind, check_number, check_samples
    from planar.core.model import Mechanism

    check_kind("inverse_dynamics_torque(mech)", mech, Mechanism)
    mech._check_rates_scale("inverse_dynamics_torque(mech)")
    t = check_samples("inverse_dynamics_torque(t)", t)
    if effects is not None and not all(hasattr(effects, a) for a in ("gravity", "loads", "springs", "damping", "density")):
        raise InputError(
            "inverse_dynamics_torque(effects)", effects, "an Effects (gravity, loads, springs, damping, density) or None"
        )
    check_densities(densities, mech)  # named as the caller wrote it, not as mass_properties takes it
    if t_rest is not None:
        check_number("inverse_dynamics_torque(t_rest)", t_rest)
    drv = mech.driver
    w = float(drv.rate)
    h = 1e-4 * drv.period
    m0 = mech.solve(drv.value(t), t=t)
    mp = mech.solve(drv.value(t + h))
    mm = mech.solve(drv.value(t - h))
    rates: dict[str, PartRates] = {}
    coef: dict[str, PartRates] = {}
    for name in m0.poses:
        P0, Pp, Pm = m0.poses[name], mp.poses[name], mm.poses[name]
        fwd = _wrapped(Pp[:, 2] - P0[:, 2])
        back = _wrapped(P0[:, 2] - Pm[:, 2])
        r = PartRates(
            (Pp[:, :2] - Pm[:, :2]) / (2 * h),
            (Pp[:, :2] - 2 * P0[:, :2] + Pm[:, :2]) / (h * h),
            (fwd + back) / (2 * h),
            (fwd - back) / (h * h),
        )
        rates[name] = r
        coef[name] = PartRates(r.v / w, r.a / w, r.omega / w, r.alpha / w)
    return motor_torque_from_rates(mech, m0, rates, coef, effects, t_rest, densities)


def motor_torque_from_rates(
    mech: Mechanism,
    motion: Motion,
    rates: Mapping[str, PartRates],
    coef: Mapping[str, PartRates],
    effects: Any = None,
    t_rest: float | None = None,
    densities: dict[str, float] | None = None,
) -> Array:
    """The motor torque per sample by virtual work (see the module's note): the one definition.

    ``rates``: every part's rates at the motion's samples; ``coef``: its velocity coefficients
    ``d/dq`` (the rates at unit driver speed; only ``v`` and ``omega`` are read); ``motion``: the
    solved motion with its sample times.  ``effects``, ``densities`` as :func:`part_mass_table`;
    ``t_rest``: when a spring without a rest length has it (default the first sample; a time that is
    no sample is solved for).  Force x model unit, counter-clockwise positive, the torque the motor
    applies to the driven part (a force along the axis for a translating input).
    """
    g3, lam = gravity_and_damping(effects)
    tau = np.zeros(len(motion))
    for name, (mass, cog, inertia) in part_mass_table(mech, effects, densities).items():
        if mass == 0.0 and inertia == 0.0:
            continue
        g = plane_gravity(mech.part(name).plane, g3)  # a toy's piece: gravity in its plane
        G = poses_apply(motion.poses[name], np.asarray(cog, float))
        vG, aG = point_rates(motion.poses[name], rates[name], G)
        cG, _ = point_rates(motion.poses[name], coef[name], G)
        r, c = rates[name], coef[name]
        tau += mass * _dot(aG - g + lam * vG, cG) + inertia * (r.alpha + lam * r.omega) * c.omega
    if effects is not None:
        for load in effects.loads:
            tau += load_torque(mech, motion, coef, load.point, load.force)
        rest_poses = _rest_poses(mech, motion, t_rest)
        for s in effects.springs:
            pa = poses_apply(motion.poses[s.a], np.asarray(s.anchor_a, float))
            pb = poses_apply(motion.poses[s.b], np.asarray(s.anchor_b, float))
            va, _ = point_rates(motion.poses[s.a], rates[s.a], pa)
            vb, _ = point_rates(motion.poses[s.b], rates[s.b], pb)
            ca, _ = point_rates(motion.poses[s.a], coef[s.a], pa)
            cb, _ = point_rates(motion.poses[s.b], coef[s.b], pb)
            d = pb - pa
            L = np.hypot(d[:, 0], d[:, 1])
            Ls = np.where(L > 0, L, 1.0)
            rest = float(_spring_length(s, rest_poses)[0]) if s.rest_length is None else s.rest_length
            f = s.stiffness * (L - rest) + s.damping * _dot(d, vb - va) / Ls
            tau += f * _dot(d, cb - ca) / Ls
    return tau


def load_torque(mech: Mechanism, motion: Motion, coef: Mapping[str, PartRates], point: str, force: ArrayLike) -> Array:
    """One load's share of the motor torque, ``F . dX/dq`` per sample: ``force`` ``(2,)`` or ``(N, 2)`` (the
    force the mechanism exerts at the named ``point``, world frame), ``coef`` the parts' velocity
    coefficients.  Ideal (no losses); force x model unit."""
    part, _ = mech.points[point]
    cX, _ = point_rates(motion.poses[part], coef[part], motion.points[point])
    f = np.asarray(force, float)
    return cX @ f if f.ndim == 1 else _dot(cX, f)


def _rest_poses(mech: Mechanism, motion: Motion, t_rest: float | None) -> dict[str, Array]:
    """The poses (one row each) at ``t_rest``: the first sample by default or when it is a sample time, else solved."""
    assert motion.t is not None
    if t_rest is None or np.any(motion.t == t_rest):
        i0 = 0 if t_rest is None else int(np.argmax(motion.t == t_rest))
        return {k: v[i0 : i0 + 1] for k, v in motion.poses.items()}
    return mech.solve(mech.driver.value(np.array([float(t_rest)]))).poses


def _dot(a: Array, b: Array) -> Array:
    return a[:, 0] * b[:, 0] + a[:, 1] * b[:, 1]
