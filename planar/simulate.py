"""The same mechanism rebuilt as pymunk bodies and joints, driven by the analytic input.

Rebuild:

* every part becomes a body whose mass and moment come from its outline
  (area x density, second moment of the polygon with its holes); the ground
  is the space's static body;
* :class:`~planar.model.Pivot` -> ``PivotJoint``; :class:`~planar.model.PinInSlot`
  -> ``GrooveJoint`` (groove on the slot's part); :class:`~planar.model.Slide`
  -> ``GrooveJoint`` plus a ``GearJoint`` (ratio 1) locking the rotation;
  :class:`~planar.model.PinInArcSlot` -> the equivalent link: a ``PinJoint``
  holding the pin at the arc's radius from its centre (a pin in an arc slot
  moves exactly like a pin on a link pivoting at the centre);
  :class:`~planar.model.CamOnLine` -> ``GrooveJoint`` (the contact point held
  on the face), allowed only when the scene names what holds it there
  (gravity or a spring), as wind-up #8 needs;
* the driver follows the analytic input: a kinematic body whose velocity (not
  position) is set before every step so that it reaches the analytic pose at
  the end of the step (``mode="kinematic"``, the default); or, where the
  scene asks for dynamics or the motor torque is wanted, a dynamic body
  turned by a ``SimpleMotor`` at the driver's rate (``mode="motor"``).

Only the effects a scene names exist in the space: no gravity, collision
shapes, friction, damping, springs or loads otherwise (``SimResult.built``
lists what was built).  Wind-up #6 and #9 are spatial and are refused.

Blow-ups are detected (non-finite state, or a joint residual above
``blowup_tol`` of the mechanism's size) and reported with the sample.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Callable

import numpy as np
from numpy.typing import NDArray

from .effects import Effects
from .errors import PlanarError
from .model import CamOnLine, Mechanism, Motion, PinInArcSlot, PinInSlot, Pivot, Slide, joint_residuals
from .registry import Registry

if TYPE_CHECKING:
    from .scene import Scene

__all__ = ["SimSettings", "SimResult", "SimulationError", "mass_properties", "simulate", "simulate_scene",
           "DEFAULT_SETTINGS"]

Array = NDArray[np.float64]

DEFAULT_ERROR_BIAS = (1.0 - 0.1) ** 60.0  # pymunk's default: 10 % of the error fixed per 1/60 s


class SimulationError(PlanarError):
    """The mechanism cannot be rebuilt in pymunk (spatial mechanisms, missing effects)."""


@dataclass(frozen=True)
class SimSettings:
    """Settings that trade accuracy for time.

    ``substeps``: physics steps per output sample; ``iterations``: solver
    iterations per step; ``error_bias``: fraction of joint error left
    uncorrected after one second (pymunk's meaning; smaller corrects faster).
    """

    substeps: int = 64
    iterations: int = 20
    error_bias: float = 1e-9
    blowup_tol: float = 0.05

    def __post_init__(self) -> None:
        from .errors import InputError

        if self.substeps < 1:
            raise InputError("substeps", self.substeps, "at least 1")
        if self.iterations < 1:
            raise InputError("iterations", self.iterations, "at least 1")
        if not (0.0 <= self.error_bias < 1.0):
            raise InputError("error_bias", self.error_bias, "a fraction in [0, 1)")


DEFAULT_SETTINGS = SimSettings()


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
    blowup: tuple[int, str] | None = None
    #: the rebuild's pin bodies: (part, point in its frame, mass)
    pins: list[tuple[str, tuple[float, float], float]] = field(default_factory=list)
    residuals: dict[str, Array] = field(default_factory=dict)


# --------------------------------------------------------------------------- mass


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


def mass_properties(part, density: float) -> tuple[float, tuple[float, float], float]:
    """``(mass, centre of gravity, moment about it)`` of a part's outline (holes removed).

    Polygon formulas (Green's theorem) over the exterior (counter-clockwise)
    and the holes (clockwise), so the holes subtract.
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


# --------------------------------------------------------------------------- building


def _check_mechanism(mech: Mechanism) -> None:
    if getattr(mech, "spatial", False):
        raise SimulationError(
            f"{mech.name}: a spatial mechanism (its follower turns about an axis in the driver's plane) "
            "cannot be rebuilt in a 2D physics engine")
    for st in getattr(mech, "stages", []):
        if st.mech.spatial:
            raise SimulationError(
                f"{mech.name}: stage {st.label} ({st.realisation.pattern}, mechanism #{st.realisation.number}) "
                "is spatial and cannot be rebuilt in a 2D physics engine")


def _driven_parts(mech: Mechanism) -> list[str]:
    """Parts whose motion is imposed: the driver, and in toys every stage's driver that has no parent."""
    out = [mech.driver.part]
    for st in getattr(mech, "stages", []):
        name = f"{st.label}.driver"
        if name not in out:
            out.append(name)
    return out


def _holding_effect(effects: Effects | None) -> bool:
    return effects is not None and (effects.gravity is not None or len(effects.springs) > 0)


class _Rebuild:
    """pymunk space, bodies and constraints for one mechanism."""

    def __init__(self, mech: Mechanism, analytic: Motion, effects: Effects | None, settings: SimSettings,
                 mode: str, densities: dict[str, float] | None = None) -> None:
        import pymunk

        self.pymunk = pymunk
        self.mech = mech
        self.settings = settings
        self.mode = mode
        space = pymunk.Space()
        space.iterations = settings.iterations
        built: dict[str, Any] = {"gravity": None, "shapes": 0, "friction": None, "damping": None,
                                 "springs": 0, "loads": 0, "constraints": 0, "bodies": 0}
        if effects is not None and effects.gravity is not None:
            space.gravity = tuple(effects.gravity)
            built["gravity"] = tuple(effects.gravity)
        if effects is not None and effects.damping is not None:
            space.damping = effects.damping
            built["damping"] = effects.damping
        density = effects.density if effects is not None else 1.0
        self.bodies: dict[str, Any] = {}
        self.cog: dict[str, tuple[float, float]] = {}
        self.driven = [p for p in _driven_parts(mech)]
        # every stage of a toy has its own ground part: all are the static body
        for p in mech.parts:
            pose0 = analytic.poses[p.name][0]
            if p.ground:
                body = space.static_body
                if p.name not in self.bodies:
                    self.bodies[p.name] = body
                continue
            if p.name in self.driven and mode == "kinematic":
                body = pymunk.Body(body_type=pymunk.Body.KINEMATIC)
                self.cog[p.name] = (0.0, 0.0)
            else:
                d = (densities or {}).get(p.name, density)
                m, cog, I = mass_properties(p, d)
                body = pymunk.Body(m, I)
                # The body's frame is put at the part's centre of gravity (``center_of_gravity``
                # stays (0, 0)): with an offset centre of gravity pymunk 7.3's GrooveJoint lets the
                # pin leave its groove (measured: 0.07 units off a 1.5-unit groove under a side
                # load), so part-frame anchors are shifted by ``cog`` instead.
                self.cog[p.name] = cog
            c, s_ = math.cos(pose0[2]), math.sin(pose0[2])
            cx, cy = self.cog[p.name]
            body.position = (float(pose0[0] + c * cx - s_ * cy), float(pose0[1] + s_ * cx + c * cy))
            body.angle = float(pose0[2])
            space.add(body)
            self.bodies[p.name] = body
            built["bodies"] += 1
        self.static_pose = {p.name: analytic.poses[p.name][0] for p in mech.parts if p.ground}
        self.constraints = []
        self.pins: list[tuple[Any, str, tuple[float, float]]] = []
        self.space_pending: list[Any] = []
        built["imposed"] = []
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
                c.error_bias = settings.error_bias
                space.add(c)
                self.constraints.append(c)
        built["constraints"] = len(self.constraints)
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
                space.add(pymunk.DampedSpring(a, b, aa, bb, rest, s.stiffness, s.damping))
                built["springs"] += 1
            if effects.contact:
                built["shapes"] = self._shapes(space, effects)
            self.loads = [(mech.points[l.point][0], mech.points[l.point][1], np.asarray(l.force, float))
                          for l in effects.loads]
            built["loads"] = len(self.loads)
        else:
            self.loads = []
        self.motor = None
        if mode == "motor":
            drv = self.bodies[mech.driver.part]
            ground = space.static_body
            # Chipmunk drives w_b - w_a = -rate
            self.motor = pymunk.SimpleMotor(ground, drv, -mech.driver.rate)
            if effects is not None and effects.motor_force_limit is not None:
                self.motor.max_force = effects.motor_force_limit
            space.add(self.motor)
        self.space = space
        self.built = built

    def _local(self, part: str, xy) -> tuple[float, float]:
        """A point in ``part``'s frame, in the frame of its pymunk body (static parts: world)."""
        if part in self.static_pose:
            from .geometry import poses_apply

            w = poses_apply(np.asarray(self.static_pose[part]), np.asarray(xy, float))
            return (float(w[0]), float(w[1]))
        cx, cy = self.cog[part]
        return (float(xy[0] - cx), float(xy[1] - cy))

    def _groove(self, slot_body, a, b, part: str, xy) -> list:
        pm = self.pymunk
        ref = slot_body.mass if slot_body.body_type == pm.Body.DYNAMIC else None
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
        #4: 8e-2 vs 5e-4 of the size at 16 substeps).
        """
        pm = self.pymunk
        owner = self.bodies[part]
        ref = owner.mass if owner.body_type == pm.Body.DYNAMIC else (ref_mass or 1.0)
        mass = max(0.1 * ref, 1e-12)
        r = 1e-2 * max(self.mech.size, 1e-12)
        body = pm.Body(mass, 0.5 * mass * r * r)
        local = self._local(part, xy)
        w = owner.local_to_world(local)
        body.position = (float(w[0]), float(w[1]))
        self.space_pending.append(body)
        self.pins.append((body, part, (float(xy[0]), float(xy[1]))))
        return body, pm.PivotJoint(body, owner, (0.0, 0.0), local)

    def _shapes(self, space, effects) -> int:
        import shapely

        pm = self.pymunk
        n = 0
        for p in self.mech.parts:
            body = self.bodies[p.name]
            tris = shapely.constrained_delaunay_triangles(p.outline)
            for t in getattr(tris, "geoms", []):
                pts = [self._local(p.name, c) for c in list(t.exterior.coords)[:-1]]
                shape = pm.Poly(body, pts)
                shape.friction = effects.friction if effects.friction is not None else 0.0
                # parts of one mechanism pass through each other (they sit in layers); only contact
                # with what the scene adds would collide: one group for the whole mechanism
                shape.filter = pm.ShapeFilter(group=1)
                space.add(shape)
                n += 1
        return n

    def set_state(self, poses: dict[str, Array], vel: dict[str, Array]) -> None:
        """Place every moving body at a pose with a velocity (origin velocity, angular velocity)."""
        for name, body in self.bodies.items():
            if body is self.space.static_body:
                continue
            x, y, a = poses[name]
            vx, vy, w = vel[name]
            cx, cy = self.cog[name]
            c, s = math.cos(a), math.sin(a)
            rx, ry = c * cx - s * cy, s * cx + c * cy
            body.position = (float(x + rx), float(y + ry))
            body.angle = float(a)
            body.velocity = (float(vx - w * ry), float(vy + w * rx))
            body.angular_velocity = float(w)

        for body, part, xy in self.pins:
            x, y, a = poses[part]
            vx, vy, w = vel[part]
            c, s = math.cos(a), math.sin(a)
            rx, ry = c * xy[0] - s * xy[1], s * xy[0] + c * xy[1]
            body.position = (float(x + rx), float(y + ry))
            body.velocity = (float(vx - w * ry), float(vy + w * rx))
            body.angular_velocity = 0.0

    def poses(self) -> dict[str, tuple[float, float, float]]:
        out = {}
        for name, body in self.bodies.items():
            if body is self.space.static_body:
                sp = self.static_pose[name]
                out[name] = (float(sp[0]), float(sp[1]), float(sp[2]))
            else:
                a = body.angle
                cx, cy = self.cog[name]
                c, s = math.cos(a), math.sin(a)
                out[name] = (body.position[0] - (c * cx - s * cy), body.position[1] - (s * cx + c * cy), a)
        return out


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
    return rb._groove(rb.bodies[j.a], s0, s1, j.b, j.pin)


@REBUILDERS.register(Slide)
def _slide(rb: _Rebuild, j: Slide, effects: Effects | None) -> list[Any]:
    """A groove plus a ``GearJoint`` (ratio 1) locking ``b``'s rotation to ``a``'s."""
    B = rb.bodies
    s0, s1 = _padded(rb._local(j.a, j.start), rb._local(j.a, j.end))
    phase = B[j.b].angle - B[j.a].angle
    return rb._groove(B[j.a], s0, s1, j.b, j.anchor) + [rb.pymunk.GearJoint(B[j.a], B[j.b], phase, 1.0)]


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
            "name one in the scene's [effects] (gravity = [...] or springs = [...])")
    if j.radius != 0.0:
        raise SimulationError(f"{rb.mech.name}: joint {j.name!r}: a round cam on a face is not rebuilt")
    s0, s1 = _padded(rb._local(j.a, j.start), rb._local(j.a, j.end))
    return rb._groove(rb.bodies[j.a], s0, s1, j.b, j.centre)


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


def simulate(mech: Mechanism, t: Array, effects: Effects | None = None,
             settings: SimSettings = DEFAULT_SETTINGS, mode: str = "kinematic",
             densities: dict[str, float] | None = None, torque_bias: float | None = None) -> SimResult:
    """Simulate ``mech`` at output times ``t`` (evenly spaced), driven by the analytic input.

    ``mode="motor"`` turns the driver with a ``SimpleMotor`` and measures the
    motor torque from its constraint impulse: pymunk reports an impulse's
    magnitude only, so a known constant torque ``torque_bias`` is applied to
    the driver as well, which the motor must always oppose; the torque the
    mechanism needs is then ``torque_bias - |impulse| / dt``, signed.
    """
    _check_mechanism(mech)
    t = np.asarray(t, float)
    if t.size < 2:
        raise PlanarError("simulate: needs at least two output times")
    dt_out = float(t[1] - t[0])
    sub = settings.substeps
    dt = dt_out / sub
    if mode == "motor" and (mech.driver.kind != "rotation" or mech.driver.amplitude is not None):
        raise SimulationError(f"{mech.name}: motor mode needs a driver turning at a constant rate")
    if mode == "motor" and len(_driven_parts(mech)) > 1:
        raise SimulationError(f"{mech.name}: motor mode drives one part; this toy's stages are drawn apart, "
                              "so each stage's driver must follow its parent kinematically")
    poses_a, vel_a, analytic = _analytic_pose_velocity(mech, t)
    if not analytic.valid.all():
        i = int(np.flatnonzero(~analytic.valid)[0])
        raise SimulationError(f"{mech.name}: the analytic motion is invalid at sample {i} "
                              f"({analytic.reason(i)}); the rebuild needs an assemblable cycle")
    rb = _Rebuild(mech, analytic, effects, settings, mode, densities)
    rb.set_state({k: v[0] for k, v in poses_a.items()}, {k: v[0] for k, v in vel_a.items()})
    # analytic driver poses at every step end, all at once
    t_steps = t[0] + dt * np.arange(1, (t.size - 1) * sub + 1)
    driver_targets = {}
    if mode == "kinematic":
        for name in rb.driven:
            driver_targets[name] = mech.solve(mech.driver.value(t_steps)).poses[name]
    size = mech.size
    n = t.size
    out = {p.name: np.empty((n, 3)) for p in mech.parts}
    cur = rb.poses()
    for k in out:
        out[k][0] = cur[k]
    torque = np.full(n, np.nan) if mode == "motor" else None
    bias = float(torque_bias or 0.0)
    blowup = None
    loads = [(rb.bodies[part], rb._local(part, xy), F) for part, xy, F in rb.loads]
    t0 = time.perf_counter()
    steps = 0
    space = rb.space
    drv_body = rb.bodies[mech.driver.part]
    done = n
    for i in range(1, n):
        imp_sum = 0.0
        for s in range(sub):
            k = (i - 1) * sub + s
            for name, target in driver_targets.items():
                body = rb.bodies[name]
                x, y, a = target[k]
                body.velocity = ((x - body.position[0]) / dt, (y - body.position[1]) / dt)
                da = math.remainder(a - body.angle, 2 * math.pi)
                body.angular_velocity = da / dt
            for body, xy, F in loads:
                # the mechanism exerts F on its load: the load pushes back with -F
                wp = body.local_to_world(xy)
                body.apply_force_at_world_point((float(-F[0]), float(-F[1])), wp)
            if mode == "motor":
                drv_body.torque = bias
            space.step(dt)
            steps += 1
            if mode == "motor":
                imp_sum += rb.motor.impulse
        cur = rb.poses()
        for name in out:
            out[name][i] = cur[name]
        if mode == "motor":
            torque[i] = bias - imp_sum / dt_out
        # blow-up check on this sample
        if not all(np.isfinite(v).all() for v in cur.values()):
            blowup = (i, "non-finite body state")
        else:
            worst = 0.0
            for j in mech.joints:
                r = float(np.max(j.residual({k: v[i:i + 1] for k, v in out.items()})))
                worst = max(worst, r)
            if worst > settings.blowup_tol * size:
                blowup = (i, f"joint residual {worst:.3g} exceeds {settings.blowup_tol:g} of the size {size:.3g}")
        if blowup is not None:
            done = i + 1
            break
    wall = time.perf_counter() - t0
    valid = np.zeros(n, dtype=bool)
    valid[:done] = True
    code = np.full(n, -1, dtype=np.int16)
    table: list[tuple[str, str]] = []
    if blowup is not None:
        valid[blowup[0]:] = False
        code[blowup[0]:] = 0
        table.append(("simulation", f"blew up at sample {blowup[0]} (t = {t[blowup[0]]:.6g} s): {blowup[1]}"))
        for k in out:
            out[k][done:] = out[k][done - 1]
            if not np.isfinite(out[k]).all():
                out[k][~np.isfinite(out[k])] = 0.0
    from .geometry import poses_apply

    pts = {nm: poses_apply(out[part], xy) for nm, (part, xy) in mech.points.items()}
    motion = Motion(driver=analytic.driver, poses=out, valid=valid, fail_code=code, fail_table=table,
                    points=pts, t=t)
    res = joint_residuals(mech, motion)
    built = dict(rb.built, mode=mode)
    pins = [(part, xy, body.mass) for body, part, xy in rb.pins]
    return SimResult(motion, settings, mode, built, wall, steps, torque, blowup, residuals=res, pins=pins)


def simulate_scene(scene: "Scene", settings: SimSettings = DEFAULT_SETTINGS, mode: str | None = None) -> SimResult:
    """Simulate a scene over its cycles with its effects (kinematic driver unless dynamics are asked for)."""
    e = scene.effects
    if mode is None:
        mode = "motor" if e.motor_force_limit is not None else "kinematic"
    motion = scene.motion()
    return simulate(scene.mechanism, motion.t, e, settings, mode)


# --------------------------------------------------------------------------- torque


def inverse_dynamics_torque(mech: Mechanism, t: Array, effects: Effects | None,
                            point_masses: list[tuple[str, tuple[float, float], float]] | None = None) -> Array:
    """Motor torque by virtual work with inertia (d'Alembert), for a driver turning at a constant rate.

    ``tau dq = sum_parts (m (a_G - g) . dX_G + I_G alpha dphi) + sum_loads F . dX``
    over one evenly sampled cycle ``t``; ``dX/dq`` and accelerations by
    periodic central differences of the analytic motion.  ``point_masses``
    adds point masses riding on parts (the rebuild's pin bodies).
    """
    t = np.asarray(t, float)
    drv = mech.driver
    m = mech.solve(drv.value(t), t=t)
    dt = float(t[1] - t[0])
    w = drv.rate
    dq = w * dt
    g = np.asarray(effects.gravity, float) if effects is not None and effects.gravity is not None else np.zeros(2)
    density = effects.density if effects is not None else 1.0
    from .geometry import poses_apply

    def d1(x: Array) -> Array:
        return (np.roll(x, -1, axis=0) - np.roll(x, 1, axis=0)) / (2 * dq)

    def d2(x: Array) -> Array:
        return (np.roll(x, -1, axis=0) - 2 * x + np.roll(x, 1, axis=0)) / (dq * dq)

    tau = np.zeros(t.size)
    masses = []
    for p in mech.parts:
        if p.ground:
            continue
        # (the driver turns steadily about its axle: its inertia terms vanish, its weight does not)
        mass, cog, I = mass_properties(p, density)
        masses.append((p.name, cog, mass, I))
    for part, xy, mass in point_masses or []:
        masses.append((part, xy, mass, 0.0))
    for part, cog, mass, I in masses:
        X = poses_apply(m.poses[part], np.asarray(cog, float))
        phi = m.poses[part][:, 2]
        fwd = np.remainder(np.roll(phi, -1) - phi + np.pi, 2 * np.pi) - np.pi  # wrapped steps
        back = np.roll(fwd, 1)
        dphi = (fwd + back) / (2 * dq)
        ddphi = (fwd - back) / (dq * dq)
        dX = d1(X)
        acc = d2(X) * w * w
        tau += mass * ((acc - g) * dX).sum(-1)
        tau += I * (ddphi * w * w) * dphi
    if effects is not None:
        for load in effects.loads:
            X = m.points[load.point]
            tau += (np.asarray(load.force, float) * d1(X)).sum(-1)
    return tau


def torque_comparison(mech: Mechanism, t: Array, effects: Effects | None,
                      settings: SimSettings = DEFAULT_SETTINGS) -> dict[str, Any]:
    """pymunk's motor torque (from the motor's constraint impulses) against inverse dynamics by virtual work.

    ``t`` must cover exactly one cycle, evenly (the analytic side uses
    periodic differences).
    """
    # pymunk's torque over an output interval is the mean of its substep impulses: compare it with
    # the mean of the analytic torque over the same interval (sampled at the substeps' midpoints)
    K = settings.substeps
    dt = float(t[1] - t[0])
    t_fine = t[0] + (np.arange(t.size * K) + 0.5) * (dt / K)

    def interval_means(pins) -> Array:
        fine = inverse_dynamics_torque(mech, t_fine, effects, pins)
        return np.roll(fine.reshape(t.size, K).mean(axis=1), 1)  # interval ending at sample i

    # the bias only has to exceed the torque; the pins (a tenth of their parts) are added once known
    bias = 3.0 * float(np.abs(interval_means(None)).max()) + 1e-9
    for _ in range(4):
        sim = simulate(mech, t, effects, settings, mode="motor", torque_bias=bias)
        if sim.blowup is not None:
            raise SimulationError(f"{mech.name}: the motor-driven simulation {sim.motion.reason(sim.blowup[0])}")
        tau = sim.torque
        if np.all(tau[1:] < bias * 0.999):
            break
        bias *= 4.0  # the motor must always oppose the bias; give it more room
    analytic = interval_means(sim.pins)
    peak = float(np.abs(analytic).max()) or 1.0
    diff = np.abs(tau[1:] - analytic[1:])
    return {
        "analytic": analytic.tolist(),
        "simulated": [None] + tau[1:].tolist(),
        "peak": peak,
        "max_abs_diff": float(diff.max()),
        "max_rel_diff": float(diff.max() / peak),
        "bias": bias,
        "note": "simulated torque = bias - |motor impulse| / dt (pymunk reports impulse magnitudes)",
    }
