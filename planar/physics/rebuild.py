"""The pymunk rebuild of a mechanism: bodies, pins, and one constraint builder per joint kind (:data:`REBUILDERS`)."""

from __future__ import annotations

import ctypes
import math
from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import NDArray

from planar.analysis.dynamics import mass_properties
from planar.cams.joint import CamContact
from planar.core.effects import Effects
from planar.core.geometry import poses_apply
from planar.core.model import CamOnLine, Mechanism, Motion, PinInArcSlot, PinInSlot, Pivot, Slide
from planar.core.registry import Registry
from planar.linkages.gears import GearMesh
from planar.physics.settings import (
    SimSettings,
    SimulationError,
    _driven_parts,
    _holding_effect,
    _lever_factor,
    solver_iterations,
    step_correction,
)
from planar.toys.assembly import KeyedShaft

Array = NDArray[np.float64]


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
        self.space = pymunk.Space()
        self.built: dict[str, Any] = {
            "gravity": None,
            "damping": None,
            "springs": 0,
            "loads": 0,
            "constraints": 0,
            "bodies": 0,
        }
        self._space_effects(effects)
        self.bodies: dict[str, Any] = {}
        self.cog: dict[str, tuple[float, float]] = {}
        self.driven = list(_driven_parts(mech))
        #: per part: (mass, cog, moment, pin scale) of the part without its pins (see _compensated)
        self.overrides = dict(overrides or {})
        self.true_mass: dict[str, tuple[float, tuple[float, float], float]] = {}
        masses = [self._add_body(p, analytic.poses[p.name][0], effects, densities) for p in mech.parts]
        self._solver(settings, [m for m in masses if m is not None], analytic)
        self.static_pose = {p.name: analytic.poses[p.name][0] for p in mech.parts if p.ground}
        self.constraints: list[Any] = []
        self.pins: list[tuple[Any, str, tuple[float, float]]] = []
        self.space_pending: list[Any] = []
        self._joints(effects)
        self.loads: list[tuple[str, tuple[float, float], Array]] = []
        self._springs_and_loads(effects)
        self.motor: Any = None
        self.motor_limit: float | None = None
        if mode == "motor":
            self._motor(effects)

    def _space_effects(self, effects: Effects | None) -> None:
        """Gravity and damping, scaled to one time unit per step."""
        dt, built = self.dt, self.built
        if effects is not None and effects.gravity is not None:
            self.space.gravity = (float(effects.gravity[0]) * dt * dt, float(effects.gravity[1]) * dt * dt)
            built["gravity"] = tuple(effects.gravity)
        if effects is not None and effects.damping is not None:
            self.space.damping = float(effects.damping) ** dt
            built["damping"] = effects.damping

    def _dynamic_body(self, p: Any, d: float) -> tuple[Any, float]:
        """A body with the part's mass and moment (or its override without the pins), and that mass."""
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
        # The body's frame is put at the part's centre of gravity (``center_of_gravity`` stays (0, 0)): with
        # an offset centre of gravity pymunk 7.3's GrooveJoint lets the pin leave its groove, so part-frame
        # anchors are shifted by ``cog`` instead.
        self.cog[p.name] = cog
        return self.pymunk.Body(m, inertia), m

    def _plane_gravity(self, p: Any, body: Any, effects: Effects | None) -> None:
        """A toy's piece in another plane feels the part of the toy's gravity in its plane."""
        pymunk = self.pymunk
        plane = getattr(p, "plane", "xy")
        if plane == "xy" or body.body_type != pymunk.Body.DYNAMIC or effects is None or effects.gravity is None:
            return
        from planar.analysis.dynamics import plane_gravity

        gp = plane_gravity(plane, effects.gravity) * self.dt * self.dt
        own = (float(gp[0]), float(gp[1]))

        def _velocity(b: Any, _g: Any, damping: float, step: float, own: tuple[float, float] = own) -> None:
            pymunk.Body.update_velocity(b, own, damping, step)

        body.velocity_func = _velocity

    def _add_body(self, p: Any, pose0: Array, effects: Effects | None, densities: dict[str, float] | None) -> float | None:
        """The part's body placed at ``pose0``; returns its mass when the solver moves it."""
        pymunk = self.pymunk
        if p.ground:
            self.bodies.setdefault(p.name, self.space.static_body)
            return None
        mass = None
        if p.name in self.driven and self.mode == "kinematic":
            body = pymunk.Body(body_type=pymunk.Body.KINEMATIC)
            self.cog[p.name] = (0.0, 0.0)
        else:
            density = effects.density if effects is not None else 1.0
            body, mass = self._dynamic_body(p, (densities or {}).get(p.name, density))
        self._plane_gravity(p, body, effects)
        c, s_ = math.cos(pose0[2]), math.sin(pose0[2])
        cx, cy = self.cog[p.name]
        body.position = (float(pose0[0] + c * cx - s_ * cy), float(pose0[1] + s_ * cx + c * cy))
        body.angle = float(pose0[2])
        self.space.add(body)
        self.bodies[p.name] = body
        self.built["bodies"] += 1
        return mass

    def _solver(self, settings: SimSettings, masses: list[float], analytic: Motion) -> None:
        """Iterations (for mass ratios and long levers) and the correction per step."""
        self.iterations = solver_iterations(settings, masses, self.mode)
        amplify = _lever_factor(self.mech, analytic.poses)
        if settings.adaptive and amplify > 1.0:
            # a part far larger than its joints' spacing: its joints' rows are nearly parallel and the solver
            # converges slowly (the kangaroo leg with its coupler point 10x further out, lever 15: the motor run
            # flew off at 91 iterations, holds to 1.3e-5 of the size at 347)
            self.iterations = math.ceil(self.iterations * amplify)
        self.space.iterations = self.iterations
        self.built["iterations"] = self.iterations
        self.correction = step_correction(settings, self.mech, self.dt, self.iterations)
        self.built["correction"] = self.correction

    def _joints(self, effects: Effects | None) -> None:
        """Every joint's constraints, from its kind's entry in :data:`REBUILDERS`."""
        pymunk, space, built = self.pymunk, self.space, self.built
        built["imposed"] = []
        bias = 1.0 - self.correction  # error left per step = per time unit here
        for j in self.mech.joints:
            rebuild = REBUILDERS.get(j, f"joint {j.name!r} of {self.mech.name}")
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

    def _springs_and_loads(self, effects: Effects | None) -> None:
        if effects is None:
            return
        dt = self.dt
        for s in effects.springs:
            a, b = self.bodies[s.a], self.bodies[s.b]
            aa = self._local(s.a, s.anchor_a)
            bb = self._local(s.b, s.anchor_b)
            rest = s.rest_length
            if rest is None:
                pa = a.local_to_world(aa)
                pb = b.local_to_world(bb)
                rest = float(np.hypot(pa[0] - pb[0], pa[1] - pb[1]))
            self.space.add(self.pymunk.DampedSpring(a, b, aa, bb, rest, s.stiffness * dt * dt, s.damping * dt))
            self.built["springs"] += 1
        pts = self.mech.points
        self.loads = [(pts[ld.point][0], pts[ld.point][1], np.asarray(ld.force, float)) for ld in effects.loads]
        self.built["loads"] = len(self.loads)

    def _motor(self, effects: Effects | None) -> None:
        mech, dt = self.mech, self.dt
        drv = self.bodies[mech.driver.part]
        # Chipmunk drives w_b - w_a = -rate (per time unit: per step here)
        self.motor = self.pymunk.SimpleMotor(self.space.static_body, drv, -mech.driver.rate * dt)
        if effects is not None and effects.motor_force_limit is not None:
            self.motor_limit = float(effects.motor_force_limit)
            self.motor.max_force = self.motor_limit * dt * dt
        self.space.add(self.motor)

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
        for name, body in self.bodies.items():
            if body is not self.space.static_body:
                xy, v, a, w = _carried(poses[name], vel[name] * self.dt, self.cog[name])
                body.position = xy  # before the angle, as pymunk turns a body about its centre of mass
                body.angle = float(a)
                body.velocity = v
                body.angular_velocity = float(w)
        for body, part, xy in self.pins:  # a pin turns freely on its part: no spin of its own
            body.position, body.velocity, _, _ = _carried(poses[part], vel[part] * self.dt, xy)
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


def _carried(pose: Array, vel: Array, xy: tuple[float, float]) -> tuple[tuple[float, float], tuple[float, float], float, float]:
    """World position and velocity of the point ``xy`` (part frame) of a part at ``pose`` (x, y, angle) moving at
    ``vel`` (origin velocity, angular velocity; per step), with the part's angle and angular velocity."""
    x, y, a = pose
    vx, vy, w = vel
    c, s = math.cos(a), math.sin(a)
    rx, ry = c * xy[0] - s * xy[1], s * xy[0] + c * xy[1]
    return (float(x + rx), float(y + ry)), (float(vx - w * ry), float(vy + w * rx)), a, w


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
