"""The same mechanism rebuilt as pymunk bodies and joints, driven by the analytic input.

Rebuild:

* every part becomes a body whose mass and moment come from its outline
  (area x density, second moment of the polygon with its holes); the ground
  is the space's static body;
* each joint kind is rebuilt by the handler registered for it in
  :data:`REBUILDERS`: :class:`~planar.core.model.Pivot` -> ``PivotJoint``;
  :class:`~planar.core.model.PinInSlot` -> ``GrooveJoint`` (groove on the slot's
  part); :class:`~planar.core.model.Slide` -> ``GrooveJoint`` plus a ``GearJoint``
  (ratio 1) locking the rotation; :class:`~planar.core.model.PinInArcSlot` -> the
  equivalent link (a ``PinJoint`` holding the pin at the arc's radius);
  :class:`~planar.core.model.CamOnLine` -> ``GrooveJoint``, allowed only when the
  scene names what holds it there (gravity or a spring);
* grooves hold a pin that is a small body of its own; its mass is taken out
  of the part it rides on (mass, centre of gravity and moment of the pair are
  the part's), so the rebuilt mechanism has the model's inertia;
* the driver follows the analytic input: a kinematic body whose velocity is
  set so that it reaches the analytic pose at the end of each step
  (``mode="kinematic"``, the default); or a dynamic body turned by a
  ``SimpleMotor`` at the driver's rate (``mode="motor"``), whose signed
  torque is read every step (and checked against the motor's force limit).

Time is scaled so that one pymunk time unit is one step: the joint error
correction is then a fraction per step (:attr:`SimSettings.correction`),
the same at any rate and step, and never underflows (pymunk's per-second
``error_bias`` cannot express more than ~3 % per step at 64 substeps of a
1 s cycle).  Velocities, forces, stiffnesses and damping are scaled to match.

Only the effects a scene names exist in the space: no gravity, damping,
springs or loads otherwise (``SimResult.built`` lists what was built).
Wind-up #6 and #9 are spatial and are refused.  There are no collisions:
the parts of a mechanism sit on layers and never touch (a scene's
``contact`` and ``friction`` keys are refused when the scene is read).

Failures are found by comparing poses, in blocks of samples with arrays:
a sample where any part leaves its analytic pose by more than
``tolerance`` of the mechanism's size (worst hull point), or whose state is
not finite, stops the run and is reported with its sample and part, and
whether the joints came apart (a blow-up) or still hold (the mechanism took
another assembly branch).
"""

from __future__ import annotations

import ctypes
import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from planar.analysis.dynamics import inverse_dynamics_torque, mass_properties
from planar.cams.joint import CamContact
from planar.core.effects import Effects
from planar.core.geometry import poses_apply, wrap_angle
from planar.core.model import CamOnLine, Mechanism, Motion, PinInArcSlot, PinInSlot, Pivot, Slide, joint_residuals
from planar.core.registry import Registry
from planar.errors import PlanarError
from planar.linkages.gears import GearMesh
from planar.toys.assembly import KeyedShaft

if TYPE_CHECKING:
    from planar.scene.load import Scene

__all__ = [
    "DEFAULT_SETTINGS",
    "SimFailure",
    "SimResult",
    "SimSettings",
    "SimulationError",
    "inverse_dynamics_torque",
    "joint_drift",
    "mass_properties",
    "simulate",
    "simulate_scene",
    "substeps_for",
    "torque_comparison",
]

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
    all of it in one step; lowered for mass ratios and, in motor mode, past
    2400 steps per turn, unless ``adaptive`` is off); ``error_bias``: pymunk's
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
        from planar.errors import InputError

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
        if self.step_drift is not None and not (self.step_drift > 0.0):
            raise InputError("step_drift", self.step_drift, "a positive fraction of the size")

    def step_correction(self, dt: float) -> float:
        """Fraction of joint error corrected per step of ``dt`` seconds."""
        if self.error_bias is None:
            return self.correction
        return 1.0 - self.error_bias**dt


DEFAULT_SETTINGS = SimSettings()


@dataclass(frozen=True)
class SimFailure:
    """Where and how a simulation left its analytic motion.

    ``kind``: ``"blow-up"`` (non-finite state or a joint came apart),
    ``"branch"`` (every joint holds but a part is more than ten tolerances
    elsewhere: another assembly branch) or ``"drift"`` (the part is off by
    more than ``tolerance``, the joints by less than ``blowup_tol``).  ``error``: the part's distance from its
    analytic pose as a fraction of the size.
    """

    sample: int
    time: float
    part: str
    kind: str
    error: float
    message: str


@dataclass
class SimResult:
    """A simulated motion and what it took."""

    motion: Motion
    settings: SimSettings
    mode: str
    built: dict[str, Any]
    wall_time: float
    steps: int
    torque: Array | None = None
    failure: SimFailure | None = None
    #: the rebuild's pin bodies: (part, point in its frame, mass)
    pins: list[tuple[str, tuple[float, float], float]] = field(default_factory=list)
    residuals: dict[str, Array] = field(default_factory=dict)
    #: samples whose interval had a step with the motor at its force limit (motor mode)
    saturated: NDArray[np.intp] = field(default_factory=lambda: np.zeros(0, dtype=np.intp))
    #: largest deviation of every part from its analytic pose over the simulated samples, / size
    pose_error: dict[str, float] = field(default_factory=dict)

    @property
    def blowup(self) -> tuple[int, str] | None:
        """``(sample, message)`` of the failure, if any (any kind, not only blow-ups)."""
        return None if self.failure is None else (self.failure.sample, self.failure.message)


# --------------------------------------------------------------------------- building


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

#: in motor mode, past this many steps per turn of the driver the correction is at most
#: :data:`_MOTOR_FINE_CORRECTION`.  Measured on the Jansen leg (40 iterations, correction 0.2): 2304 steps per
#: turn hold (7.6e-5 of the size), 3456 err 3e-4 with the torque 28 % off, 4608 and 9216 fly off, whether the
#: steps come from substeps or from samples; at 0.1 per step 4608 and 9216 hold (3.3e-5, 7.6e-6).  The
#: kinematic mode holds at 0.2 throughout.
_MOTOR_STEPS_PER_TURN = 2400.0
_MOTOR_FINE_CORRECTION = 0.1


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


_PIN_FRACTION = 0.1  # pin mass / its part's mass (see _Rebuild._pin)


def _compensated(
    mass: float, cog: tuple[float, float], moment: float, pins: list[tuple[tuple[float, float], float]]
) -> tuple[float, tuple[float, float], float, float]:
    """The part without its pins, so that part + pins has the part's mass, centre and moment.

    Returns ``(mass, cog, moment, scale)`` with ``scale`` the factor applied
    to every pin mass (1, or less where the pins would take too much of the
    part: at most half its mass and half its moment).
    """
    scale = 1.0
    c = np.asarray(cog, float)
    for _ in range(60):
        mp = np.array([m * scale for _, m in pins])
        xy = np.array([p for p, _ in pins], float).reshape(-1, 2)
        m2 = mass - mp.sum()
        c2 = (mass * c - (mp[:, None] * xy).sum(0)) / m2
        i2 = moment - m2 * float(((c2 - c) ** 2).sum()) - float((mp * ((xy - c) ** 2).sum(1)).sum())
        if m2 >= 0.5 * mass and i2 >= 0.5 * moment:
            return m2, (float(c2[0]), float(c2[1])), i2, scale
        scale *= 0.5
    return mass, cog, moment, 0.0  # pragma: no cover - a vanishing pin mass always fits


def _motor_impulse_offset() -> int:
    """Offset (in doubles) of ``jAcc`` in Chipmunk's ``cpSimpleMotor``, found by probing.

    pymunk reports a motor's impulse as a magnitude only; the signed value
    (the accumulated impulse ``jAcc``) sits after the ``rate`` and ``iSum``
    fields.  Found here on a probe with known values, and every reading in
    :func:`simulate` is checked against pymunk's magnitude, so a different
    layout fails loudly instead of reading garbage.
    """
    import pymunk
    from pymunk._chipmunk import ffi

    space = pymunk.Space()
    body = pymunk.Body(1.0, 1.0)
    space.add(body)
    motor = pymunk.SimpleMotor(space.static_body, body, 1.375)
    space.add(motor)
    body.torque = 5.0
    space.step(0.01)  # body b wants w = -rate = -1.375, torque gives +0.05: jAcc = -1.425
    addr = int(ffi.cast("uintptr_t", motor._constraint))
    vals = (ctypes.c_double * 32).from_address(addr)
    for k in range(2, 32):
        if vals[k] == -motor.impulse and vals[k - 2] == 1.375 and motor.impulse == 1.425:
            return k
    raise SimulationError("this pymunk version's motor layout is unknown: the motor torque's sign cannot be read")


_JACC: list[int] = []


class _Rebuild:
    """pymunk space, bodies and constraints for one mechanism.

    Units inside the space are scaled to one time unit per step (``dt``
    seconds): velocities x dt, forces and gravity x dt^2, damping per step.
    """

    def __init__(
        self,
        mech: Mechanism,
        analytic: Motion,
        effects: Effects | None,
        settings: SimSettings,
        mode: str,
        dt: float,
        densities: dict[str, float] | None = None,
        overrides: dict[str, tuple[float, tuple[float, float], float, float]] | None = None,
    ) -> None:
        import pymunk

        self.pymunk = pymunk
        self.mech = mech
        self.settings = settings
        self.mode = mode
        self.dt = dt
        space = pymunk.Space()
        built: dict[str, Any] = {"gravity": None, "damping": None, "springs": 0, "loads": 0, "constraints": 0, "bodies": 0}
        if effects is not None and effects.gravity is not None:
            space.gravity = (float(effects.gravity[0]) * dt * dt, float(effects.gravity[1]) * dt * dt)
            built["gravity"] = tuple(effects.gravity)
        if effects is not None and effects.damping is not None:
            space.damping = float(effects.damping) ** dt
            built["damping"] = effects.damping
        density = effects.density if effects is not None else 1.0
        self.bodies: dict[str, Any] = {}
        self.cog: dict[str, tuple[float, float]] = {}
        self.driven = list(_driven_parts(mech))
        #: per part: (mass, cog, moment, pin scale) of the part without its pins (see _compensated)
        self.overrides = dict(overrides or {})
        self.true_mass: dict[str, tuple[float, tuple[float, float], float]] = {}
        masses = []
        for p in mech.parts:
            pose0 = analytic.poses[p.name][0]
            if p.ground:
                if p.name not in self.bodies:
                    self.bodies[p.name] = space.static_body
                continue
            if p.name in self.driven and mode == "kinematic":
                body = pymunk.Body(body_type=pymunk.Body.KINEMATIC)
                self.cog[p.name] = (0.0, 0.0)
            else:
                d = (densities or {}).get(p.name, density)
                m, cog, inertia = mass_properties(p, d)
                self.true_mass[p.name] = (m, cog, inertia)
                if p.name in self.overrides:
                    m, cog, inertia, _ = self.overrides[p.name]
                if not (math.isfinite(m) and m > 0 and math.isfinite(inertia) and inertia > 0):
                    # Chipmunk aborts the process on a mass it cannot use: say which part and why, first
                    raise SimulationError(
                        f"part {p.name!r}: mass {m:.4g} and moment {inertia:.4g} from [effects] "
                        f"density {d:.4g}: expected a positive, finite mass and moment (a density "
                        "or size this large or small leaves float64)"
                    )
                body = pymunk.Body(m, inertia)
                masses.append(m)
                # The body's frame is put at the part's centre of gravity (``center_of_gravity``
                # stays (0, 0)): with an offset centre of gravity pymunk 7.3's GrooveJoint lets the
                # pin leave its groove, so part-frame anchors are shifted by ``cog`` instead.
                self.cog[p.name] = cog
            plane = getattr(p, "plane", "xy")
            if plane != "xy" and body.body_type == pymunk.Body.DYNAMIC and effects is not None and effects.gravity is not None:
                # a toy's piece in another plane feels the part of the toy's gravity in its plane
                from planar.analysis.dynamics import plane_gravity

                gp = plane_gravity(plane, effects.gravity) * dt * dt
                own = (float(gp[0]), float(gp[1]))

                def _velocity(b: Any, _g: Any, damping: float, step: float, own: tuple[float, float] = own) -> None:
                    pymunk.Body.update_velocity(b, own, damping, step)

                body.velocity_func = _velocity
            c, s_ = math.cos(pose0[2]), math.sin(pose0[2])
            cx, cy = self.cog[p.name]
            body.position = (float(pose0[0] + c * cx - s_ * cy), float(pose0[1] + s_ * cx + c * cy))
            body.angle = float(pose0[2])
            space.add(body)
            self.bodies[p.name] = body
            built["bodies"] += 1
        self.iterations = solver_iterations(settings, masses, mode)
        amplify = _lever_factor(mech, analytic.poses)
        if settings.adaptive and amplify > 1.0:
            # a part far larger than its joints' spacing: its joints' rows are nearly parallel and the solver
            # converges slowly (the kangaroo leg with its coupler point 10x further out, lever 15: the motor run
            # flew off at 91 iterations, holds to 1.3e-5 of the size at 347)
            self.iterations = math.ceil(self.iterations * amplify)
        space.iterations = self.iterations
        built["iterations"] = self.iterations
        self.static_pose = {p.name: analytic.poses[p.name][0] for p in mech.parts if p.ground}
        self.constraints: list[Any] = []
        self.pins: list[tuple[Any, str, tuple[float, float]]] = []
        self.space_pending: list[Any] = []
        built["imposed"] = []
        self.correction = settings.step_correction(dt)
        if settings.adaptive and self.iterations > settings.iterations:
            self.correction = min(self.correction, _MASS_RATIO_CORRECTION)
        if (
            settings.adaptive
            and mode == "motor"
            and mech.driver.rate != 0.0
            and 2.0 * math.pi / (abs(mech.driver.rate) * dt) > _MOTOR_STEPS_PER_TURN
        ):
            self.correction = min(self.correction, _MOTOR_FINE_CORRECTION)
        built["correction"] = self.correction
        bias = 1.0 - self.correction  # error left per step = per time unit here
        for j in mech.joints:
            rebuild = REBUILDERS.get(j, f"joint {j.name!r} of {mech.name}")
            if all(self.bodies[p].body_type != pymunk.Body.DYNAMIC for p in (j.a, j.b)):
                # e.g. the driver's axle: both sides move as imposed (pymunk 7 allows no joint there)
                built["imposed"].append(j.name)
                continue
            for c in rebuild(self, j, effects):
                for body in self.space_pending:
                    space.add(body)
                self.space_pending.clear()
                c.error_bias = bias
                space.add(c)
                self.constraints.append(c)
        built["constraints"] = len(self.constraints)
        self.loads: list[tuple[str, tuple[float, float], Array]] = []
        if effects is not None:
            for s in effects.springs:
                a, b = self.bodies[s.a], self.bodies[s.b]
                aa = self._local(s.a, s.anchor_a)
                bb = self._local(s.b, s.anchor_b)
                rest = s.rest_length
                if rest is None:
                    pa = a.local_to_world(aa)
                    pb = b.local_to_world(bb)
                    rest = float(np.hypot(pa[0] - pb[0], pa[1] - pb[1]))
                space.add(pymunk.DampedSpring(a, b, aa, bb, rest, s.stiffness * dt * dt, s.damping * dt))
                built["springs"] += 1
            self.loads = [
                (mech.points[ld.point][0], mech.points[ld.point][1], np.asarray(ld.force, float)) for ld in effects.loads
            ]
            built["loads"] = len(self.loads)
        self.motor = None
        self.motor_limit: float | None = None
        if mode == "motor":
            drv = self.bodies[mech.driver.part]
            # Chipmunk drives w_b - w_a = -rate (per time unit: per step here)
            self.motor = pymunk.SimpleMotor(space.static_body, drv, -mech.driver.rate * dt)
            if effects is not None and effects.motor_force_limit is not None:
                self.motor_limit = float(effects.motor_force_limit)
                self.motor.max_force = self.motor_limit * dt * dt
            space.add(self.motor)
        self.space = space
        self.built = built

    def _local(self, part: str, xy) -> tuple[float, float]:
        """A point in ``part``'s frame, in the frame of its pymunk body (static parts: world)."""
        if part in self.static_pose:
            w = poses_apply(np.asarray(self.static_pose[part]), np.asarray(xy, float))
            return (float(w[0]), float(w[1]))
        cx, cy = self.cog[part]
        return (float(xy[0] - cx), float(xy[1] - cy))

    def _groove(self, slot_part: str, a, b, part: str, xy) -> list:
        pm = self.pymunk
        slot_body = self.bodies[slot_part]
        ref = self.true_mass[slot_part][0] if slot_part in self.true_mass else None
        pin, pivot = self._pin(part, xy, ref)
        return [pm.GrooveJoint(slot_body, pin, a, b, (0.0, 0.0)), pivot]

    def _pin(self, part: str, xy, ref_mass: float | None = None) -> tuple[Any, Any]:
        """A pin as a body of its own, pivoted to ``part`` at ``xy``.

        Grooves hold it by its own origin: pymunk 7.3's GrooveJoint lets an
        anchor that is offset from its body's origin leave the groove when
        the body is turned (measured: 0.17 units off after 0.5 rad), while a
        groove on a body's origin plus a pivot holds to 1e-7.  The pin weighs
        a tenth of its part (of the slotted part when its own is driven): at
        1/1000 the solver needed 4x the substeps for the same error (wind-up
        #4: 8e-2 vs 5e-4 of the size at 16 substeps).  Its mass is taken out
        of its part (:func:`_compensated`), so the inertia is the model's.
        """
        pm = self.pymunk
        owner = self.bodies[part]
        if part in self.true_mass:
            scale = self.overrides[part][3] if part in self.overrides else 1.0
            mass = _PIN_FRACTION * self.true_mass[part][0] * scale
        else:
            mass = _PIN_FRACTION * (ref_mass or 1.0)
        mass = max(mass, 1e-12)
        r = 1e-2 * max(self.mech.size, 1e-12)
        body = pm.Body(mass, 0.5 * mass * r * r)
        local = self._local(part, xy)
        w = owner.local_to_world(local)
        body.position = (float(w[0]), float(w[1]))
        self.space_pending.append(body)
        self.pins.append((body, part, (float(xy[0]), float(xy[1]))))
        return body, pm.PivotJoint(body, owner, (0.0, 0.0), local)

    def compensation(self) -> dict[str, tuple[float, tuple[float, float], float, float]]:
        """Per dynamic part carrying pins: itself without them (see :func:`_compensated`)."""
        per: dict[str, list[tuple[tuple[float, float], float]]] = {}
        for body, part, xy in self.pins:
            if part in self.true_mass:
                per.setdefault(part, []).append((xy, body.mass))
        return {p: _compensated(*self.true_mass[p], pins) for p, pins in per.items()}

    def set_state(self, poses: dict[str, Array], vel: dict[str, Array]) -> None:
        """Place every moving body at a pose with a velocity (origin velocity, angular velocity; per s)."""
        dt = self.dt
        for name, body in self.bodies.items():
            if body is self.space.static_body:
                continue
            x, y, a = poses[name]
            vx, vy, w = vel[name] * dt
            cx, cy = self.cog[name]
            c, s = math.cos(a), math.sin(a)
            rx, ry = c * cx - s * cy, s * cx + c * cy
            body.position = (float(x + rx), float(y + ry))
            body.angle = float(a)
            body.velocity = (float(vx - w * ry), float(vy + w * rx))
            body.angular_velocity = float(w)
        for body, part, xy in self.pins:
            x, y, a = poses[part]
            vx, vy, w = vel[part] * dt
            c, s = math.cos(a), math.sin(a)
            rx, ry = c * xy[0] - s * xy[1], s * xy[0] + c * xy[1]
            body.position = (float(x + rx), float(y + ry))
            body.velocity = (float(vx - w * ry), float(vy + w * rx))
            body.angular_velocity = 0.0

    def moving(self) -> list[str]:
        """Names of the parts with a body of their own, in a fixed order."""
        return [n for n, b in self.bodies.items() if b is not self.space.static_body]


#: pymunk constraints for each joint kind: (rebuild, joint, effects) -> constraints
REBUILDERS: Registry[Callable[[_Rebuild, Any, Effects | None], list[Any]]] = Registry("simulate")


@REBUILDERS.register(Pivot)
def _pivot(rb: _Rebuild, j: Pivot, effects: Effects | None) -> list[Any]:
    B = rb.bodies
    return [rb.pymunk.PivotJoint(B[j.a], B[j.b], rb._local(j.a, j.anchor_a), rb._local(j.b, j.anchor_b))]


@REBUILDERS.register(PinInSlot)
def _pin_in_slot(rb: _Rebuild, j: PinInSlot, effects: Effects | None) -> list[Any]:
    """``GrooveJoint`` with the groove on the slot's part ``a``, the pin a body pivoted to ``b``."""
    s0, s1 = _padded(rb._local(j.a, j.start), rb._local(j.a, j.end))
    return rb._groove(j.a, s0, s1, j.b, j.pin)


@REBUILDERS.register(Slide)
def _slide(rb: _Rebuild, j: Slide, effects: Effects | None) -> list[Any]:
    """A groove plus a ``GearJoint`` (ratio 1) locking ``b``'s rotation to ``a``'s."""
    B = rb.bodies
    s0, s1 = _padded(rb._local(j.a, j.start), rb._local(j.a, j.end))
    phase = B[j.b].angle - B[j.a].angle
    return rb._groove(j.a, s0, s1, j.b, j.anchor) + [rb.pymunk.GearJoint(B[j.a], B[j.b], phase, 1.0)]


@REBUILDERS.register(GearMesh)
def _gear_mesh(rb: _Rebuild, j: GearMesh, effects: Effects | None) -> list[Any]:
    """A ``GearJoint``: pymunk holds ``ratio_pm * angle_b - angle_a = phase``, so ``ratio_pm = 1 / ratio``."""
    B = rb.bodies
    r = 1.0 / j.ratio
    return [rb.pymunk.GearJoint(B[j.a], B[j.b], r * B[j.b].angle - B[j.a].angle, r)]


@REBUILDERS.register(PinInArcSlot)
def _pin_in_arc_slot(rb: _Rebuild, j: PinInArcSlot, effects: Effects | None) -> list[Any]:
    """The equivalent link: a ``PinJoint`` holding the pin at the arc's radius from its centre."""
    B = rb.bodies
    return [rb.pymunk.PinJoint(B[j.a], B[j.b], rb._local(j.a, j.centre), rb._local(j.b, j.pin))]


@REBUILDERS.register(CamOnLine)
def _cam_on_line(rb: _Rebuild, j: CamOnLine, effects: Effects | None) -> list[Any]:
    """The contact point held on the face by a groove; only where the scene names what holds it."""
    if not _holding_effect(effects):
        raise SimulationError(
            f"{rb.mech.name}: joint {j.name!r} is a contact held by gravity or a spring; "
            "name one in the scene's [effects] (gravity = [...] or springs = [...])"
        )
    if j.radius != 0.0:
        raise SimulationError(f"{rb.mech.name}: joint {j.name!r}: a round cam on a face is not rebuilt")
    s0, s1 = _padded(rb._local(j.a, j.start), rb._local(j.a, j.end))
    return rb._groove(j.a, s0, s1, j.b, j.centre)


@REBUILDERS.register(KeyedShaft)
def _keyed_shaft(rb: _Rebuild, j: KeyedShaft, effects: Effects | None) -> list[Any]:
    """A pivot on the shaft and a ``GearJoint`` (ratio 1) holding the phase."""
    B = rb.bodies
    phase = B[j.b].angle - B[j.a].angle
    return [
        rb.pymunk.PivotJoint(B[j.a], B[j.b], rb._local(j.a, j.anchor_a), rb._local(j.b, j.anchor_b)),
        rb.pymunk.GearJoint(B[j.a], B[j.b], phase, 1.0),
    ]


@REBUILDERS.register(CamContact)
def _cam_profile(rb: _Rebuild, j: CamContact, effects: Effects | None) -> list[Any]:
    """Refused: no pymunk constraint keeps a follower on a cam's profile without being told the answer."""
    raise SimulationError(
        f"{rb.mech.name}: joint {j.name!r} is a profile cam (joint kind 'cam-profile'), which is not rebuilt in "
        "pymunk: holding the follower on the outline would take collision contact, which the rebuild does not use "
        "(parts sit in layers), and a groove along the analytic profile would only replay the analytic motion; "
        "no comparison is made"
    )


def _padded(a, b, frac: float = 0.1) -> tuple[tuple[float, float], tuple[float, float]]:
    """A groove ``frac`` of its length longer at each end.

    A slot exactly as long as the pin's travel puts the pin on its end stop
    at both extremes; the solver's round-off then clamps it there and drags
    the part sideways (measured: 1.5 % of the size on wind-up #4).  Real slots
    have that clearance too.
    """
    ax, ay = a
    bx, by = b
    dx, dy = (bx - ax) * frac, (by - ay) * frac
    return (ax - dx, ay - dy), (bx + dx, by + dy)


def _analytic_pose_velocity(mech: Mechanism, t: Array) -> tuple[dict[str, Array], dict[str, Array], Any]:
    """Analytic poses at times ``t`` and their time derivatives (central differences, h = 1e-6 period)."""
    drv = mech.driver
    h = 1e-6 * drv.period
    m0 = mech.solve(drv.value(t), t=t)
    mp = mech.solve(drv.value(t + h))
    mm = mech.solve(drv.value(t - h))
    vel = {}
    for k in m0.poses:
        d = mp.poses[k] - mm.poses[k]
        d[:, 2] = np.angle(np.exp(1j * d[:, 2]))
        vel[k] = d / (2 * h)
    return m0.poses, vel, m0


def _hull_points(mech: Mechanism, part: str) -> Array:
    """Points that stand for a part: its hull circle centres (so rotation errors count too)."""
    p = mech.part(part)
    return np.array([(x, y) for x, y, _ in p.hull] or [(0.0, 0.0)], float)


class _PoseCheck:
    """Deviation of simulated poses from the analytic ones, a block of samples at a time."""

    def __init__(self, mech: Mechanism, analytic: dict[str, Array], names: list[str], cogs: Array, settings: SimSettings) -> None:
        self.mech = mech
        self.names = names
        self.cogs = cogs  # (B, 2) body frame origin in the part frame
        self.pts = {n: _hull_points(mech, n) for n in names}
        self.ref = {n: poses_apply(analytic[n], self.pts[n]) for n in names}  # (N, M, 2)
        self.size = mech.size
        self.tol = settings.tolerance * self.size
        self.worst = dict.fromkeys(names, 0.0)

    def part_poses(self, raw: Array) -> Array:
        """``(N, B, 3)`` body states (centre of gravity, angle) -> part frame poses."""
        a = raw[..., 2]
        c, s = np.cos(a), np.sin(a)
        cx, cy = self.cogs[:, 0], self.cogs[:, 1]
        out = np.empty_like(raw)
        out[..., 0] = raw[..., 0] - (c * cx - s * cy)
        out[..., 1] = raw[..., 1] - (s * cx + c * cy)
        out[..., 2] = a
        return out

    def block(self, poses: Array, i0: int) -> tuple[int, str, float] | None:
        """First sample of the block (absolute index) where a part is off, that part and its error."""
        n = poses.shape[0]
        dev = np.empty((n, len(self.names)))
        for k, name in enumerate(self.names):
            pts = poses_apply(poses[:, k], self.pts[name])
            d = np.hypot(*(pts - self.ref[name][i0 : i0 + n]).transpose(2, 0, 1)).max(axis=1)
            dev[:, k] = np.where(np.isfinite(d), d, np.inf)
        bad = (dev > self.tol).any(axis=1)
        if not bad.any():
            for k, name in enumerate(self.names):
                self.worst[name] = max(self.worst[name], float(dev[:, k].max()))
            return None
        i = int(np.flatnonzero(bad)[0])
        for k, name in enumerate(self.names):
            self.worst[name] = max(self.worst[name], float(dev[: i + 1, k].max()))
        k = int(np.argmax(dev[i]))
        return i0 + i, self.names[k], float(dev[i, k])


def _classify(
    mech: Mechanism, poses: dict[str, Array], i: int, part: str, err: float, t: float, settings: SimSettings
) -> SimFailure:
    size = mech.size
    one = {k: v[i : i + 1] for k, v in poses.items()}
    finite = all(np.isfinite(v).all() for v in one.values())
    res = {j.name: float(np.max(j.residual(one))) for j in mech.joints} if finite else {}
    worst_joint = max(res, key=lambda k: res[k]) if res else None
    worst = res[worst_joint] if worst_joint is not None else math.inf
    where = f"at sample {i} (t = {t:.6g} s) part {part!r}"
    if not finite or not math.isfinite(err):
        return SimFailure(i, t, part, "blow-up", math.inf, f"blew up {where}: non-finite body state")
    rel = err / size
    if worst > settings.blowup_tol * size:
        return SimFailure(
            i,
            t,
            part,
            "blow-up",
            rel,
            f"blew up {where}: joint {worst_joint!r} residual {worst / size:.3g} of the size "
            f"(part off its analytic pose by {rel:.3g} of the size)",
        )
    if worst < 0.1 * err and rel > 10.0 * settings.tolerance:
        # every joint holds and the part is far off: another assembly branch (an offset of a few tolerances
        # with the joints holding is drift amplified by a long lever, reported below)
        return SimFailure(
            i,
            t,
            part,
            "branch",
            rel,
            f"switched assembly branch {where}: the part is {rel:.3g} of the size from its "
            f"analytic pose while every joint holds (worst residual {worst / size:.2g} of the size)",
        )
    return SimFailure(
        i,
        t,
        part,
        "drift",
        rel,
        f"left the analytic motion {where}: {rel:.3g} of the size off (tolerance "
        f"{settings.tolerance:g}); joint {worst_joint!r} residual {worst / size:.3g} of the size",
    )


def simulate(
    mech: Mechanism,
    t: Array,
    effects: Effects | None = None,
    settings: SimSettings = DEFAULT_SETTINGS,
    mode: str = "kinematic",
    densities: dict[str, float] | None = None,
) -> SimResult:
    """Simulate ``mech`` at output times ``t`` (s, evenly spaced), driven by the analytic input.

    ``mode="motor"`` turns the driver with a ``SimpleMotor`` at the driver's
    rate; ``SimResult.torque[i]`` is the mean torque the motor applied to the
    driven part over the interval ending at sample ``i`` (counter-clockwise
    positive, model force x length units), and ``SimResult.saturated`` the
    samples where it reached ``effects.motor_force_limit``.  ``densities``
    overrides the density per part.  The run stops at the first failure
    (:class:`SimFailure`); later samples are marked invalid.
    """
    _check_mechanism(mech)
    if mode not in ("kinematic", "motor"):
        raise SimulationError(f"{mech.name}: mode {mode!r} is neither 'kinematic' nor 'motor'")
    t = np.asarray(t, float)
    if t.size < 2:
        raise PlanarError("simulate: needs at least two output times")
    dt_out = float(t[1] - t[0])
    if mode == "motor" and (mech.driver.kind != "rotation" or mech.driver.amplitude is not None):
        raise SimulationError(f"{mech.name}: motor mode needs a driver turning at a constant rate")
    if mode == "motor" and getattr(mech, "extra_driven_parts", []):
        raise SimulationError(
            f"{mech.name}: motor mode drives one part; this linkage has more inputs "
            f"({', '.join(mech.extra_driven_parts)}), each imposed kinematically"  # type: ignore[attr-defined]
        )
    if mode == "motor" and len(_driven_parts(mech)) > 1:
        raise SimulationError(
            f"{mech.name}: motor mode drives one part; this toy's stages are drawn apart, "
            "so each stage's driver must follow its parent kinematically"
        )
    poses_a, vel_a, analytic = _analytic_pose_velocity(mech, t)
    if not analytic.valid.all():
        i = int(np.flatnonzero(~analytic.valid)[0])
        raise SimulationError(
            f"{mech.name}: the analytic motion is invalid at sample {i} "
            f"({analytic.reason(i)}); the rebuild needs an assemblable cycle"
        )
    sub = substeps_for(
        mech,
        poses_a,
        vel_a,
        dt_out,
        settings,
        mass_ratio_correction(settings, moving_masses(mech, mode, effects, densities), mode),
    )
    dt = dt_out / sub
    rb = _Rebuild(mech, analytic, effects, settings, mode, dt, densities)
    comp = rb.compensation()
    if comp:  # rebuild with the pins' mass taken out of their parts
        rb = _Rebuild(mech, analytic, effects, settings, mode, dt, densities, overrides=comp)
    rb.set_state({k: v[0] for k, v in poses_a.items()}, {k: v[0] for k, v in vel_a.items()})
    n = t.size
    size = mech.size
    names = rb.moving()
    bodies = [rb.bodies[k] for k in names]
    check = _PoseCheck(mech, poses_a, names, np.array([rb.cog[k] for k in names], float).reshape(-1, 2), settings)
    raw = np.empty((n, len(names), 3))
    raw[0] = [(b.position.x, b.position.y, b.angle) for b in bodies]

    # imposed parts (kinematic mode): steady ones (fixed position, constant angular rate) get one velocity per
    # sample; the others one per step, closing on the analytic pose at the end of each step
    steady: list[tuple[Any, float, float, float]] = []
    per_step: list[tuple[Any, list[float], list[float], list[float]]] = []
    step_targets: dict[str, Array] = {}
    if mode == "kinematic":
        t_steps = t[0] + dt * np.arange(1, (n - 1) * sub + 1)
        m_steps = mech.solve(mech.driver.value(t_steps))
        for name in rb.driven:
            if name not in rb.bodies or rb.bodies[name] is rb.space.static_body:
                continue
            tg = m_steps.poses[name]
            step_targets[name] = tg
            inc = np.diff(np.vstack([poses_a[name][:1], tg]), axis=0)
            inc[:, 2] = wrap_angle(inc[:, 2])
            if np.abs(inc[:, :2]).max() <= 1e-12 * size and np.ptp(inc[:, 2]) <= 1e-9 * abs(inc[0, 2]) + 1e-15:
                steady.append((rb.bodies[name], float(tg[0, 0]), float(tg[0, 1]), float(tg[0, 2])))
            else:
                per_step.append((rb.bodies[name], tg[:, 0].tolist(), tg[:, 1].tolist(), tg[:, 2].tolist()))
    loads = [(rb.bodies[part], rb._local(part, xy), (float(-F[0]) * dt * dt, float(-F[1]) * dt * dt)) for part, xy, F in rb.loads]
    motor = rb.motor
    torque = np.full(n, np.nan) if mode == "motor" else None
    sat = np.zeros(n, dtype=bool)
    jacc = None
    jmax = math.inf
    if motor is not None:
        if not _JACC:
            _JACC.append(_motor_impulse_offset())
        from pymunk._chipmunk import ffi

        jacc = ctypes.c_double.from_address(int(ffi.cast("uintptr_t", motor._constraint)) + 8 * _JACC[0])
        if rb.motor_limit is not None:
            jmax = rb.motor_limit * dt * dt * (1.0 - 1e-9)
    angle0 = {id(b): a for b, _, _, a in steady}
    rate = {
        id(b): wrap_angle(step_targets[nm][0, 2] - poses_a[nm][0, 2]) for nm, b in ((nm, rb.bodies[nm]) for nm in step_targets)
    }
    space = rb.space
    step = space.step
    simple = not per_step and not loads and motor is None
    block = max(4, min(64, 1024 // sub))
    failure: SimFailure | None = None
    checked = 1
    steps = 0
    t0 = time.perf_counter()
    for i in range(1, n):
        k0 = (i - 1) * sub
        for body, _, _, _ in steady:
            # one velocity per sample: exact for a steady turn, closing on the analytic angle at the sample's end
            target = angle0[id(body)] + rate[id(body)] * (k0 + sub - 1)
            body.angular_velocity = math.remainder(target - body.angle, 2 * math.pi) / sub
            body.velocity = (0.0, 0.0)
        if simple:
            for _ in range(sub):
                step(1.0)
        else:
            jsum = 0.0
            jbig = 0.0
            for s in range(sub):
                k = k0 + s
                for body, xs, ys, angs in per_step:
                    p = body.position
                    body.velocity = (xs[k] - p.x, ys[k] - p.y)
                    body.angular_velocity = math.remainder(angs[k] - body.angle, 2 * math.pi)
                for body, xy, F in loads:
                    # the mechanism exerts F on its load: the load pushes back with -F
                    body.apply_force_at_world_point(F, body.local_to_world(xy))
                step(1.0)
                if jacc is not None:
                    j = jacc.value
                    jsum += j
                    jbig = max(jbig, abs(j))
            if jacc is not None and motor is not None:
                if abs(jacc.value) != motor.impulse:
                    raise SimulationError(
                        "the motor's signed impulse does not match pymunk's magnitude: unknown pymunk motor layout"
                    )
                torque[i] = jsum / (sub * dt * dt)  # type: ignore[index]
                sat[i] = jbig >= jmax
        steps += sub
        raw[i] = [(b.position.x, b.position.y, b.angle) for b in bodies]
        if i + 1 - checked >= block or i == n - 1:
            hit = check.block(check.part_poses(raw[checked : i + 1]), checked)
            checked = i + 1
            if hit is not None:
                done = hit[0]
                poses_all = check.part_poses(raw[: done + 1])
                pp = {nm: poses_all[:, kk] for kk, nm in enumerate(names)}
                for p in mech.parts:
                    if p.name not in pp:
                        pp[p.name] = np.repeat(rb.static_pose[p.name][None, :], done + 1, axis=0)
                failure = _classify(mech, pp, done, hit[1], hit[2], float(t[done]), settings)
                break
    wall = time.perf_counter() - t0
    done = n if failure is None else failure.sample + 1
    poses_all = check.part_poses(raw[:done])
    out: dict[str, Array] = {}
    for p in mech.parts:
        if p.name in names:
            track = poses_all[:, names.index(p.name)]
        else:
            track = np.repeat(np.asarray(rb.static_pose[p.name], float)[None, :], done, axis=0)
        full = np.empty((n, 3))
        full[:done] = track
        full[done:] = track[-1]
        full[~np.isfinite(full)] = 0.0
        out[p.name] = full
    valid = np.ones(n, dtype=bool)
    code = np.full(n, -1, dtype=np.int16)
    table: list[tuple[str, str]] = []
    if failure is not None:
        valid[failure.sample :] = False
        code[failure.sample :] = 0
        table.append(("simulation", failure.message))
    pts = {nm: poses_apply(out[part], xy) for nm, (part, xy) in mech.points.items()}
    motion = Motion(driver=analytic.driver, poses=out, valid=valid, fail_code=code, fail_table=table, points=pts, t=t)
    res = joint_residuals(mech, motion)
    built = dict(rb.built, mode=mode, pins_compensated=sorted(comp), substeps=sub)
    pins = [(part, xy, body.mass) for body, part, xy in rb.pins]
    pose_error = {k: v / size for k, v in check.worst.items()}
    return SimResult(
        motion,
        settings,
        mode,
        built,
        wall,
        steps,
        torque,
        failure,
        pins=pins,
        residuals=res,
        saturated=np.flatnonzero(sat),
        pose_error=pose_error,
    )


def simulate_scene(scene: Scene, settings: SimSettings = DEFAULT_SETTINGS, mode: str | None = None) -> SimResult:
    """Simulate a scene over its cycles with its effects (kinematic driver unless a motor limit is named)."""
    e = scene.effects
    if mode is None:
        mode = "motor" if e.motor_force_limit is not None else "kinematic"
    motion = scene.motion()
    assert motion.t is not None  # a scene's motion is sampled in time
    return simulate(scene.mechanism, motion.t, e, settings, mode)


# --------------------------------------------------------------------------- torque


def torque_comparison(
    mech: Mechanism,
    t: Array,
    effects: Effects | None,
    settings: SimSettings = DEFAULT_SETTINGS,
    densities: dict[str, float] | None = None,
) -> dict[str, Any]:
    """pymunk's motor torque (signed, read every step) against inverse dynamics with every named effect.

    pymunk's torque over an output interval is the mean of its step
    impulses; it is compared with the mean of the analytic torque
    (:func:`planar.analysis.dynamics.inverse_dynamics_torque`) over the same interval,
    sampled at the steps' ends, after one sample of lead-in.  Only samples before a simulation
    failure are compared.  ``saturated`` lists the samples where the motor
    reached ``effects.motor_force_limit``.
    """
    t = np.asarray(t, float)
    dt = float(t[1] - t[0])
    # one sample of lead-in, so that the first compared interval starts with settled joint forces
    sim = simulate(mech, np.concatenate([[t[0] - dt], t]), effects, settings, mode="motor", densities=densities)
    K = int(sim.built["substeps"])
    # a step's impulse is what holds the motion at the step's end (symplectic Euler): compare with the
    # analytic torque at the ends of the steps of the interval ending at each sample, averaged
    t_fine = t[0] - dt + (np.arange(t.size * K) + 1.0) * (dt / K)
    fine = inverse_dynamics_torque(mech, t_fine, effects, densities, t_rest=float(t[0] - dt))
    analytic = fine.reshape(t.size, K).mean(axis=1)
    tau = np.asarray(sim.torque, float)[1:]
    upto = t.size if sim.failure is None else sim.failure.sample - 1
    peak = float(np.abs(analytic[1:]).max()) or 1.0
    diff = np.abs(tau[1:upto] - analytic[1:upto]) if upto > 1 else np.zeros(1)
    limit = effects.motor_force_limit if effects is not None else None
    out = {
        "analytic": analytic.tolist(),
        "simulated": [None] + [None if not np.isfinite(v) else float(v) for v in tau[1:]],
        "peak": peak,
        "max_abs_diff": float(diff.max()),
        "max_rel_diff": float(diff.max() / peak),
        "samples_compared": max(upto - 1, 0),
        "motor_force_limit": limit,
        "saturated": (sim.saturated[sim.saturated > 0] - 1).tolist(),
        "failure": None if sim.failure is None else sim.failure.message,
        "pose_error": max(sim.pose_error.values(), default=0.0),
        "pins": "each groove's pin is a body of its own whose mass is taken out of its part "
        "(same mass, centre and moment), so both sides model the same inertia",
        "note": "simulated torque: the motor's signed impulse per step / dt (mean over the interval)",
        "wall_time": sim.wall_time,
        "substeps": K,
        "iterations": sim.built["iterations"],
    }
    return out
