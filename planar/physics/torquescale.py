"""The torque scale a motor torque comparison is judged against (:func:`torque_scale`): the inverse-dynamics
torque over the run, sampled between its toggles and change points, capped against singular spikes."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from planar.analysis.dynamics import inverse_dynamics_torque
from planar.core.effects import Effects
from planar.core.geometry import poses_apply
from planar.core.model import Mechanism
from planar.physics.stepping import _STEP_CHUNK

Array = NDArray[np.float64]

#: samples of the run over which :func:`torque_scale` is measured (a cycle's worth is enough)
_SCALE_SAMPLES = 4096


def _interval_torque(mech: Mechanism, t: Array, K: int, effects: Effects | None, densities: dict[str, float] | None) -> Array:
    """Analytic torque averaged over the ``K`` steps' ends of the interval ending at each sample, in chunks.

    A step's impulse is what holds the motion at the step's end (symplectic
    Euler), so the steps' ends are where pymunk's torque is compared.
    """
    dt = float(t[1] - t[0])
    out = np.empty(t.size)
    chunk = max(1, _STEP_CHUNK // K)
    for i0 in range(0, t.size, chunk):
        m = min(chunk, t.size - i0)
        t_fine = t[i0] - dt + (np.arange(m * K) + 1.0) * (dt / K)
        fine = inverse_dynamics_torque(mech, t_fine, effects, densities, t_rest=float(t[0] - dt))
        out[i0 : i0 + m] = fine.reshape(m, K).mean(axis=1)
    return out


def torque_scale(mech: Mechanism, t: Array, effects: Effects | None = None, densities: dict[str, float] | None = None) -> float:
    """The mechanism's own torque scale at times ``t`` (force x length), for judging a torque difference.

    The largest over ``t`` of ``sum (m |a . v| + m |g . v| + I |alpha omega|) / w``
    over the moving parts plus ``sum |F . v| / w`` over the loads (``w`` the
    driver's rate): the torque each inertial and load term alone asks of the
    motor, without the cancellations that can leave the true torque at zero
    (a crank driving a slider at constant speed); and at least the largest
    kinetic energy per radian of the driver, ``sum (m |v|^2 + I omega^2) / 2``.
    A torque difference is reported as a fraction of this, never of a peak
    that may be round-off.  Only samples whose rates are defined count, not
    those within :data:`_SCALE_GUARD` samples of a change point or toggle
    (where differenced rates are singular), and the scale is at most
    :data:`_SCALE_SPREAD` times the 90th percentile of the samples kept.
    """
    from planar.analysis.dynamics import _wrapped, gravity_and_damping, part_mass_table, plane_gravity

    t = np.asarray(t, float)
    drv = mech.driver
    w = float(drv.rate)
    h = 1e-4 * drv.period
    m0, mp, mm = (mech.solve(drv.value(t + d)) for d in (0.0, h, -h))
    g, _ = gravity_and_damping(effects)
    work = np.zeros(t.size)
    energy = np.zeros(t.size)
    for name, (mass, cog, inertia) in part_mass_table(mech, effects, densities).items():
        gp = plane_gravity(getattr(mech.part(name), "plane", "xy"), g)
        X0, Xp, Xm = (poses_apply(m.poses[name], np.asarray(cog, float)) for m in (m0, mp, mm))
        v = (Xp - Xm) / (2 * h)
        a = (Xp - 2 * X0 + Xm) / (h * h)
        fwd = _wrapped(mp.poses[name][:, 2] - m0.poses[name][:, 2])
        back = _wrapped(m0.poses[name][:, 2] - mm.poses[name][:, 2])
        om = (fwd + back) / (2 * h)
        al = (fwd - back) / (h * h)
        work += (mass * (np.abs((a * v).sum(-1)) + np.abs((gp * v).sum(-1))) + inertia * np.abs(al * om)) / w
        energy += 0.5 * (mass * (v * v).sum(-1) + inertia * om * om)
    if effects is not None:
        for load in effects.loads:
            vp = (mp.points[load.point] - mm.points[load.point]) / (2 * h)
            work += np.abs((np.asarray(load.force, float) * vp).sum(-1)) / w
    keep = _scale_samples(mech, t) & np.isfinite(work) & np.isfinite(energy)
    return float(max(_robust_max(work[keep]), _robust_max(energy[keep])))


#: samples either side of one whose rates are undefined (a change point or toggle) left out of the torque scale
_SCALE_GUARD = 3

#: the torque scale is at most this many times the 90th percentile of its samples (a singular spike at a
#: few samples is not a scale; a quick return's genuine peak, ~2x its 90th percentile, is kept)
_SCALE_SPREAD = 10.0


def _scale_samples(mech: Mechanism, t: Array) -> NDArray[np.bool_]:
    """Samples where the rates are defined and at least :data:`_SCALE_GUARD` samples from where they are not.

    At a change point or toggle the differenced rates are singular (NaN or
    huge); they measure the singularity, not the mechanism.  A kind without
    closed-form rates keeps every sample (the finiteness check still applies).
    """
    from planar.analysis.rates import mechanism_rates
    from planar.core.registry import UnsupportedError

    try:
        _, valid, _ = mechanism_rates(mech, mech.driver.value(t), 1.0, 0.0)
    except UnsupportedError:
        return np.ones(t.size, bool)
    valid = np.asarray(valid, bool)
    bad = np.flatnonzero(~valid)
    keep = valid.copy()
    for d in range(1, _SCALE_GUARD + 1):
        keep[np.clip(bad - d, 0, t.size - 1)] = False
        keep[np.clip(bad + d, 0, t.size - 1)] = False
    return keep if keep.any() else valid


def _robust_max(x: Array) -> float:
    """The largest of ``x``, capped at :data:`_SCALE_SPREAD` times its 90th percentile (0 for none)."""
    if not x.size:
        return 0.0
    p90 = float(np.percentile(x, 90))
    return float(min(x.max(), _SCALE_SPREAD * p90)) if p90 > 0 else float(x.max())
