"""Simulation settings and the quantities they are chosen from.

:class:`SimSettings` holds substeps, iterations and the correction per step;
:func:`substeps_for`, :func:`solver_iterations` and :func:`step_correction`
turn a mechanism's measured scales (joint drift, mass ratio, lever, steps
per turn) into the budget a run starts from; :mod:`planar.physics.converge`
raises it from measured behaviour until two budgets agree.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from planar.analysis.dynamics import mass_properties
from planar.core.effects import Effects
from planar.core.geometry import poses_apply
from planar.core.model import Mechanism
from planar.errors import PlanarError

Array = NDArray[np.float64]


class SimulationError(PlanarError):
    """The mechanism cannot be rebuilt in pymunk (spatial mechanisms, missing effects)."""


#: default :attr:`SimSettings.step_drift`: the Jansen leg's predicted drift at 64 substeps of its 36 samples
#: (measured: 7.6e-5 of the size in motor mode there, 4.2e-4 at 32 substeps)
STEP_DRIFT = 3.5e-6

#: substeps never rise above this many times ``SimSettings.substeps`` (a near-singular cycle would else ask
#: for without bound)
MAX_SUBSTEP_FACTOR = 8


@dataclass(frozen=True)
class SimSettings:
    """Settings that trade accuracy for time.

    ``substeps``: physics steps per output sample; ``iterations``: solver
    iterations per step (raised automatically where the moving parts'
    masses differ a lot, see :func:`solver_iterations`, or a part is a long
    lever, see :func:`lever`, unless ``adaptive`` is off); ``correction``:
    fraction of a joint's position error corrected per step (0 = none, 1 =
    all of it in one step; lowered for mass ratios and, past 2400 steps per
    turn, as 1 / steps, unless ``adaptive`` is off: :func:`step_correction`); ``error_bias``: pymunk's
    fraction of joint error left uncorrected after one second, if given it
    replaces ``correction`` (``correction = 1 - error_bias ** dt``);
    ``tolerance``: a part further than this fraction of the mechanism's size
    from its analytic pose is a failure; ``blowup_tol``: a joint residual
    above this fraction of the size marks the failure as a blow-up;
    ``step_drift``: when given, ``substeps`` is a minimum, raised until the
    joints' predicted drift per step is at most this fraction of the size
    (see :func:`substeps_for`); ``None`` keeps ``substeps`` as it is.
    """

    substeps: int = 28
    iterations: int = 40
    correction: float = 0.2
    error_bias: float | None = None
    tolerance: float = 1e-3
    blowup_tol: float = 0.05
    adaptive: bool = True
    step_drift: float | None = STEP_DRIFT

    def __post_init__(self) -> None:
        import math
        import numbers

        from planar.errors import InputError

        for f in ("substeps", "iterations"):  # whole numbers (numpy's too), never a truth value
            v = getattr(self, f)
            if isinstance(v, bool) or not isinstance(v, numbers.Integral):
                raise InputError(f, v, "a whole number")
        for f in ("correction", "error_bias", "tolerance", "blowup_tol", "step_drift"):
            v = getattr(self, f)
            if v is None and f in ("error_bias", "step_drift"):
                continue
            if isinstance(v, bool) or not isinstance(v, numbers.Real) or not math.isfinite(v):
                raise InputError(f, v, "a finite number")
        if not isinstance(self.adaptive, bool):
            raise InputError("adaptive", self.adaptive, "True or False")
        if self.substeps < 1:
            raise InputError("substeps", self.substeps, "at least 1")
        if self.iterations < 1:
            raise InputError("iterations", self.iterations, "at least 1")
        if not (0.0 <= self.correction <= 1.0):
            raise InputError("correction", self.correction, "a fraction in [0, 1]")
        if self.error_bias is not None and not (0.0 <= self.error_bias < 1.0):
            raise InputError("error_bias", self.error_bias, "a fraction in [0, 1)")
        if not (self.tolerance > 0.0):
            raise InputError("tolerance", self.tolerance, "a positive fraction of the size")
        if not (self.blowup_tol > 0.0):
            raise InputError("blowup_tol", self.blowup_tol, "a positive fraction of the size")
        if self.step_drift is not None and not (self.step_drift > 0.0):
            raise InputError("step_drift", self.step_drift, "a positive fraction of the size")

    def step_correction(self, dt: float) -> float:
        """Fraction of joint error corrected per step of ``dt`` seconds."""
        if self.error_bias is None:
            return self.correction
        return 1.0 - self.error_bias**dt


DEFAULT_SETTINGS = SimSettings()


def _check_mechanism(mech: Mechanism) -> None:
    if mech.spatial:
        raise SimulationError(
            f"{mech.name}: a spatial mechanism (its follower turns about an axis in the driver's plane) "
            "cannot be rebuilt in a 2D physics engine"
        )
    for st in mech.stages:
        if st.mech.spatial:
            raise SimulationError(
                f"{mech.name}: stage {st.label} ({st.realisation.pattern}, mechanism #{st.realisation.number}) "
                "is spatial and cannot be rebuilt in a 2D physics engine"
            )


def _driven_parts(mech: Mechanism) -> list[str]:
    """Parts whose motion is imposed: the driver, and in toys every stage's driver that has no parent."""
    out = [mech.driver.part]
    out += [p for p in getattr(mech, "extra_driven_parts", []) if p not in out]  # a two-input linkage
    for st in mech.stages:
        name = f"{st.label}.driver"
        if name not in out:
            out.append(name)
    return out


def _holding_effect(effects: Effects | None) -> bool:
    return effects is not None and (effects.gravity is not None or len(effects.springs) > 0)


def solver_iterations(settings: SimSettings, masses: list[float], mode: str = "kinematic") -> int:
    """Solver iterations for bodies of these masses: ``settings.iterations``, times
    ``1 + log10`` of the largest mass ratio above 10 when ``settings.adaptive``,
    and in motor mode past a ratio of 100 times ``sqrt(ratio / 100)`` again.

    An iterative (Gauss-Seidel) solver converges more slowly the more the
    masses it couples differ: a four-bar with a 1:1000 coupler/rocker mass
    ratio blew up in motor mode at 20 iterations and holds at 80.  The motor's
    torque needs more: a 100x heavier coupler (ratio 772) gives it 6.8 % off
    at 156 iterations, 0.5 % at 428; a 1000x heavier rocker (ratio 2630)
    4.1 % at 354, 0.17 % at 531.
    """
    m = [x for x in masses if x > 0 and math.isfinite(x)]
    if not settings.adaptive or len(m) < 2:
        return settings.iterations
    ratio = max(m) / min(m)
    if ratio <= 10.0:
        return settings.iterations
    factor = 1.0 + math.log10(ratio)
    if mode == "motor" and ratio > 100.0:
        factor *= math.sqrt(ratio / 100.0)
    return math.ceil(settings.iterations * factor)


def joint_drift(mech: Mechanism, poses: dict[str, Array], vel: dict[str, Array]) -> float:
    """Largest rate at which a linear position update parts a joint's two sides, / size (1/s^2).

    A step moves every body along a straight line with its new velocity, so
    a point at ``r`` from a body's centre that turns at ``w`` (rad/s) ends
    about ``w^2 |r| dt^2`` off its arc; at a joint the two sides' points part
    by ``|w_a^2 r_a - w_b^2 r_b| dt^2``.  Returned: the largest
    ``|w_a^2 r_a - w_b^2 r_b| / size`` over the joints (at their first pin)
    and over the analytic ``poses`` and velocities ``vel`` (per second).
    """
    size = mech.size
    worst = 0.0
    for j in mech.joints:
        pins = j.pins()
        if not pins:
            continue
        part0, xy0 = pins[0]
        w = poses_apply(poses[part0], np.asarray(xy0, float))  # (N, 2) the joint's point, world
        acc = np.zeros_like(w)
        for side, sign in ((j.a, 1.0), (j.b, -1.0)):
            p = mech.part(side)
            if p.ground:
                continue
            c = poses_apply(poses[side], np.asarray(mass_properties(p, 1.0)[1], float))
            acc += sign * (vel[side][:, 2] ** 2)[:, None] * (w - c)
        worst = max(worst, float(np.nanmax(np.hypot(acc[:, 0], acc[:, 1]))))
    return worst / size


#: a lever amplification up to this changes nothing in :func:`substeps_for` (the gallery's largest is 4)
_LEVER_FREE = 4.0


def lever(mech: Mechanism, poses: dict[str, Array]) -> float:
    """Largest factor by which a part turns a joint error into a pose error (at least 1).

    A part whose joints are ``s`` apart turns by ``e / s`` for a joint error
    ``e``, moving a point ``D`` from a joint by ``e D / s``: the largest
    ``D / s`` over the parts with two joints or more (``D`` to the far edge of
    the part's hull), at the first sample of ``poses``.
    """
    points: dict[str, list[Array]] = {}
    for j in mech.joints:
        pins = j.pins()
        if not pins:
            continue
        part0, xy0 = pins[0]
        w = poses_apply(poses[part0][0], np.asarray(xy0, float))
        for side in (j.a, j.b):
            points.setdefault(side, []).append(w)
    best = 1.0
    for p in mech.parts:
        J = np.array(points.get(p.name, []), float).reshape(-1, 2)
        if p.ground or len(J) < 2 or not p.hull:
            continue
        spacing = float(np.hypot(*(J[:, None] - J[None]).transpose(2, 0, 1)).max())
        if spacing <= 0.0:
            continue
        hull = poses_apply(poses[p.name][0], np.array([(x, y) for x, y, _ in p.hull], float))
        radius = np.array([r for _, _, r in p.hull], float)
        reach = float((np.hypot(*(hull[:, None] - J[None]).transpose(2, 0, 1)) + radius[:, None]).max())
        best = max(best, reach / spacing)
    return best


def _lever_factor(mech: Mechanism, poses: dict[str, Array]) -> float:
    """``lever / 4`` where the lever passes 4 (by more than 5 %), else 1."""
    f = lever(mech, poses) / _LEVER_FREE
    return f if f > 1.05 else 1.0


def substeps_for(
    mech: Mechanism,
    poses: dict[str, Array],
    vel: dict[str, Array],
    dt_out: float,
    settings: SimSettings,
    correction: float | None = None,
) -> int:
    """Physics steps per output sample: ``settings.substeps``, raised for fast-turning joints.

    The error correction takes out a fraction ``c`` of a joint's error per
    step, so a drift ``d`` per step (:func:`joint_drift` x step^2) stands at
    ``d (1 - c) / c``, and the pose error it causes with it.  With
    ``settings.step_drift`` given, the substeps are the fewest (at least
    ``settings.substeps``, at most :data:`MAX_SUBSTEP_FACTOR` times it) that
    keep ``d`` at most ``step_drift`` of the size (output samples ``dt_out``
    s apart), or ``d x lever / 4`` where a part's :func:`lever` passes 4.
    ``correction``: the correction per step the solver will use when lower
    than the settings' (see :func:`mass_ratio_correction`); the
    substeps rise so that ``d (1 - c) / c`` stays what the settings ask.
    """
    if correction is None:
        correction = settings.correction
    base = settings.substeps
    if settings.step_drift is None:
        return base
    # a long lever (a part far larger than its joints' spacing) magnifies the joint error into the pose
    amplify = _lever_factor(mech, poses)
    need = dt_out * math.sqrt(joint_drift(mech, poses, vel) * amplify / settings.step_drift)
    c0 = settings.correction
    if settings.error_bias is None and 0.0 < correction < c0 < 1.0:
        # a correction lowered for a mass ratio leaves more of the drift standing, d (1 - c) / c: more
        # substeps keep the standing error where the settings' correction would have it
        need *= math.sqrt(c0 * (1.0 - correction) / (correction * (1.0 - c0)))
    return int(min(max(base, math.ceil(need - 1e-9)), base * MAX_SUBSTEP_FACTOR))


_MASS_RATIO_CORRECTION = 0.05

#: past this many steps per turn of the driver the correction per step falls as 1 / steps, keeping the
#: correction per turn (and so its rate in time) what it is at this many steps.  Measured on the Jansen leg
#: (40 iterations, correction 0.2, motor mode): 2304 steps per turn hold (7.6e-5 of the size), 4608 and 9216
#: fly off at 0.2 per step and hold at 0.1; a 26-part walker flew off at 128 substeps in kinematic mode too.  A
#: fixed rate in time keeps more substeps from making a converged run worse: the standing error, drift per
#: step / correction per step, then falls as the step.
_STEPS_PER_TURN = 2400.0


def step_correction(settings: SimSettings, mech: Mechanism, dt: float, iterations: int) -> float:
    """Fraction of joint error corrected per step of ``dt`` seconds (see :attr:`SimSettings.correction`).

    ``settings.step_correction(dt)``, then, when ``settings.adaptive``: at most
    0.05 when ``iterations`` were raised for a mass ratio, and past
    :data:`_STEPS_PER_TURN` steps per turn of the driver scaled by
    ``_STEPS_PER_TURN / steps per turn`` (the same correction per second at any step).
    """
    c = settings.step_correction(dt)
    if not settings.adaptive:
        return c
    if iterations > settings.iterations:
        c = min(c, _MASS_RATIO_CORRECTION)
    per_turn = mech.driver.period / dt  # steps per cycle of the driver
    if per_turn > _STEPS_PER_TURN:
        c = min(c, settings.step_correction(dt) * _STEPS_PER_TURN / per_turn)
    return c


def mass_ratio_correction(settings: SimSettings, masses: list[float], mode: str = "kinematic") -> float:
    """Correction per step for bodies of these masses (``settings.correction`` unless
    iterations were raised for a mass ratio, then at most 0.05; see :func:`solver_iterations`)."""
    c = settings.correction
    if settings.adaptive and solver_iterations(settings, masses, mode) > settings.iterations:
        # strong correction of a light part against a heavy one overshoots: measured on a four-bar with a
        # 1:1000 rocker/coupler mass ratio, 0.05 per step holds to 3e-4 of the size, 0.1 and more fly off
        c = min(c, _MASS_RATIO_CORRECTION)
    return c


def moving_masses(mech: Mechanism, mode: str, effects: Effects | None, densities: dict[str, float] | None = None) -> list[float]:
    """Masses of the parts that move under the solver (not ground, not an imposed driver)."""
    density = effects.density if effects is not None else 1.0
    driven = _driven_parts(mech)
    return [
        mass_properties(p, (densities or {}).get(p.name, density))[0]
        for p in mech.parts
        if not p.ground and not (p.name in driven and mode == "kinematic")
    ]
