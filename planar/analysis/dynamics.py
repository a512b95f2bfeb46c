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

Derivatives are central differences in time of the closed-form solve
(step ``1e-4`` of the period), so any sample times work, not only a whole
cycle.  Nothing here imports pymunk.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import NDArray

from planar.core.geometry import poses_apply

__all__ = ["gravity_and_damping", "inverse_dynamics_torque", "mass_properties", "part_mass_table", "plane_gravity"]

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


def part_mass_table(
    mech: Any, effects: Any, densities: dict[str, float] | None = None
) -> dict[str, tuple[float, tuple[float, float], float]]:
    """``mass_properties`` of every moving part at the scene's (or the per-part) density."""
    density = effects.density if effects is not None else 1.0
    return {p.name: mass_properties(p, (densities or {}).get(p.name, density)) for p in mech.parts if not p.ground}


def _wrapped(d: Array) -> Array:
    return np.remainder(d + np.pi, 2 * np.pi) - np.pi


def _spring_length(s: Any, m: Any) -> Array:
    pa = poses_apply(m.poses[s.a], np.asarray(s.anchor_a, float))
    pb = poses_apply(m.poses[s.b], np.asarray(s.anchor_b, float))
    return np.hypot(*(pb - pa).T)


def inverse_dynamics_torque(
    mech: Any, t: Array, effects: Any = None, densities: dict[str, float] | None = None, t_rest: float | None = None
) -> Array:
    """Motor torque needed at times ``t`` (s) for a driver turning at its constant rate.

    ``effects``: an :class:`~planar.core.effects.Effects`-like record (gravity,
    loads, springs, damping, density) or ``None``; ``densities`` overrides
    the density per part; ``t_rest``: the time at which a spring with no
    rest length has its rest length (default ``t[0]``, as the rebuild does).
    """
    t = np.asarray(t, float)
    drv = mech.driver
    w = float(drv.rate)
    h = 1e-4 * drv.period
    m0 = mech.solve(drv.value(t))
    mp = mech.solve(drv.value(t + h))
    mm = mech.solve(drv.value(t - h))
    g, lam = gravity_and_damping(effects)
    tau = np.zeros(t.size)
    for name, (mass, cog, inertia) in part_mass_table(mech, effects, densities).items():
        gp = plane_gravity(getattr(mech.part(name), "plane", "xy"), g)
        c = np.asarray(cog, float)
        X0, Xp, Xm = (poses_apply(m.poses[name], c) for m in (m0, mp, mm))
        v = (Xp - Xm) / (2 * h)  # d X_G / dt
        a = (Xp - 2 * X0 + Xm) / (h * h)
        fwd = _wrapped(mp.poses[name][:, 2] - m0.poses[name][:, 2])
        back = _wrapped(m0.poses[name][:, 2] - mm.poses[name][:, 2])
        om = (fwd + back) / (2 * h)
        al = (fwd - back) / (h * h)
        # power balance divided by the driver rate: tau w = sum (m a - m g + lam m v) . v + I (alpha + lam om) om
        tau += (mass * ((a - gp + lam * v) * v).sum(-1) + inertia * (al + lam * om) * om) / w
    if effects is not None:
        for load in effects.loads:
            vp = (mp.points[load.point] - mm.points[load.point]) / (2 * h)
            tau += (np.asarray(load.force, float) * vp).sum(-1) / w
        t_r = float(t[0]) if t_rest is None else float(t_rest)
        for s in effects.springs:
            L0, Lp, Lm = (_spring_length(s, m) for m in (m0, mp, mm))
            rest = s.rest_length
            if rest is None:
                rest = float(_spring_length(s, mech.solve(drv.value(np.array([t_r]))))[0])
            dL = (Lp - Lm) / (2 * h)
            f = s.stiffness * (L0 - rest) + s.damping * dL
            tau += f * dL / w
    return tau
