"""Coupled physics of a wind-up toy: one body per rigid piece, the motor the only driver.

* **The toy's plane (xy)**: every xy piece of the :class:`~planar.toys.assembly.ToyAssembly`
  is one pymunk body (merged parts share it), the cams are keyed to the shaft,
  and a ``SimpleMotor`` on the first cam is the only driver
  (:func:`planar.physics.simulate.simulate`, ``mode="motor"``).  The pieces of #8
  stages (xz) join the same space, each tied to its body's xy piece by its x
  (:class:`SharedX`), and so do the yz followers of #6/#9: each in a space of
  its own stepped in lockstep, its contact's load put on its driver every step
  (:func:`_skew_load`).  The motor's signed torque is compared with inverse
  dynamics (:func:`planar.physics.simulate.torque_comparison`), which takes every
  piece's gravity in its plane (:func:`planar.analysis.dynamics.plane_gravity`).
* **#8 in xz** (:func:`contact_hold`): its own 2D space.  The window plate is
  a kinematic body following the slider's x; the tab pivots on the frame and
  touches the window's edge through a pair of collision shapes (a thick segment
  behind the tab's face, a small circle on the edge), so the contact can only
  push: it separates when what holds the tab (gravity or a spring in the
  stage's plane) cannot keep it there.  Lift-off is the first sample where the
  gap exceeds ``1e-3`` of the size; :func:`liftoff_speed` scans speeds, and
  :func:`hold_margin` gives the speed at which inverse dynamics says the
  contact force changes sign (an independent prediction).
* **#6 and #9 alone** (:func:`skew_stage`): rebuilt in the follower's plane (yz).
  The driver's edge meets that plane in a point moving along a line (a
  kinematic body); the pin holds it at the skew-line distance, whose in-plane
  value ``r sqrt(cos^2 a + sin^2 a cos^2 phi) / cos phi`` follows the pin's
  tilt ``a`` (``phi`` the edge's angle to x): the kinematic point is moved
  along the pin's normal by the change every step.  The rebuild is accepted
  when it stays within ``tolerance`` of the size, else refused with the
  measured error.

:func:`simulate_toy` runs all of them and reports, per stage, what was
simulated and what was not (with the reason) instead of refusing the toy.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from planar.core.geometry import poses_apply
from planar.core.model import CamOnLine, Driver, Mechanism, joint_kind
from planar.toys.assembly import ToyAssembly, toy_assembly
from planar.windup.mechanisms import SkewContact

__all__ = [
    "ContactRun",
    "SkewHold",
    "StageReport",
    "ToyPhysics",
    "contact_hold",
    "hold_margin",
    "liftoff_speed",
    "plane_mechanism",
    "simulate_toy",
    "skew_hold",
    "skew_stage",
]

Array = NDArray[np.float64]


class _PlaneView(Mechanism):
    """The pieces of an assembly that move in one plane, and the joints among them."""

    def __init__(self, asm: ToyAssembly, plane: str = "xy") -> None:
        self.asm = asm
        parts = [p for p in asm.parts if p.plane == plane]
        names = {p.name for p in parts}
        joints = [j for j in asm.joints if j.a in names and j.b in names]
        super().__init__(asm.name, parts, joints, asm.driver, {k: v for k, v in asm.points.items() if v[0] in names})
        self.parts = tuple(parts)  # the assembly's parts already carry their joints' features

    def _solve_poses(self, q: Array):
        poses, checks = self.asm._solve_poses(q)
        return {p.name: poses[p.name] for p in self.parts}, checks


def plane_mechanism(asm: ToyAssembly, plane: str = "xy") -> Mechanism:
    """The assembly's pieces in ``plane`` as a mechanism of their own (the motor's plane: ``"xy"``)."""
    return _PlaneView(asm, plane)


@joint_kind
@dataclass(frozen=True)
class SharedX:
    """Two pieces of one rigid body in different planes (xy and xz): they share their x.

    Residual: ``|x of a's origin - x of b's anchor|`` (world x, model units).  In
    one 2D space (pymunk) it is a groove along the second axis on ``a`` through
    its origin, holding ``b``'s anchor: the planes' second axes (y, z) stay
    independent, as they are.
    """

    kind: ClassVar[str] = "shared-x"
    name: str
    a: str  # the piece moving in xz (its x is the body's)
    b: str  # the piece moving in xy
    anchor: tuple[float, float]  # on b, own frame
    reach: float = 10.0

    def residual(self, poses: Any) -> Array:
        return np.abs(poses[self.a][:, 0] - poses_apply(poses[self.b], self.anchor)[:, 0])

    def features(self) -> tuple:
        return ()

    def pins(self) -> tuple:
        return ()


class _CoupledView(Mechanism):
    """The assembly's pieces in one motor run: xy, the yz followers of #6/#9 and (``xz``) the #8 pieces.

    Each xz piece is tied to its body's xy piece by x (:class:`SharedX`); each
    yz follower keeps its stage's :class:`~planar.windup.mechanisms.SkewContact`
    with the driver's edge (rebuilt by co-simulation, see :func:`_skew_load`).
    """

    def __init__(self, asm: ToyAssembly, xz: bool = True) -> None:
        self.asm = asm
        planes = ("xy", "yz", "xz") if xz else ("xy", "yz")
        parts = [p for p in asm.parts if p.plane in planes]
        names = {p.name for p in parts}
        joints: list[Any] = [j for j in asm.joints if j.a in names and j.b in names]
        plane = {p.name: p.plane for p in parts}
        poses0 = asm.solve([0.0]).poses
        for pieces in asm.bodies.values():
            xy = [n for n in pieces if plane.get(n) == "xy"]
            for n in pieces:
                if plane.get(n) == "xz" and xy and not asm.part(n).ground:
                    # b's point with a's x at rest (b's own frame)
                    pb = poses0[xy[0]][0]
                    c, s_ = math.cos(pb[2]), math.sin(pb[2])
                    dx = poses0[n][0, 0] - pb[0]
                    joints.append(SharedX(f"{n}.x", n, xy[0], (c * dx, -s_ * dx), 10.0 * asm.size))
        super().__init__(asm.name, parts, joints, asm.driver, {k: v for k, v in asm.points.items() if v[0] in names})
        self.parts = tuple(parts)
        self.left_out = sorted({p.name for p in asm.parts} - names)

    def _solve_poses(self, q: Array):
        poses, checks = self.asm._solve_poses(q)
        return {p.name: poses[p.name] for p in self.parts}, checks


def coupled_mechanism(asm: ToyAssembly, xz: bool = True) -> Mechanism:
    """The assembly's xy pieces, the yz followers of #6/#9 and (``xz``) the #8 pieces as one mechanism: the
    motor's load includes every stage; pieces left out are named in ``left_out``."""
    return _CoupledView(asm, xz)


def _register() -> None:
    from planar.physics.simulate import REBUILDERS

    @REBUILDERS.register(SharedX)
    def _shared_x(rb: Any, j: SharedX, effects: Any) -> list[Any]:
        """A groove along the second axis through ``a``'s origin holding ``b``'s anchor (a pin body)."""
        return rb._groove(j.a, rb._local(j.a, (0.0, -j.reach)), rb._local(j.a, (0.0, j.reach)), j.b, j.anchor)

    REBUILDERS.register(SkewContact)(_skew_load)


# ---------------------------------------------------------------------------- driving one stage

#: how a stage is driven inside a toy: the toy's driver law and a map from its values to the stage's motion
StageDrive = tuple[Driver, Callable[[Array], Array]]


def _law(mech: Any, drive: StageDrive | None, speed: float) -> Driver:
    """The driver law at ``speed`` cycles/s: the toy's (``drive``) or the stage's standalone one."""
    from dataclasses import replace

    return replace(drive[0] if drive is not None else mech.driver, rate=2 * math.pi * speed)


def _poses(mech: Any, q: Array, drive: StageDrive | None) -> dict[str, Array]:
    """The stage's part poses (its own frames) for driver values ``q``."""
    if drive is None:
        return mech.solve(q).poses
    u = drive[1](np.asarray(q, float))
    return {"ground": np.zeros((len(u), 3)), "driver": mech._driver_pose(u), "follower": mech._follower_pose(mech.forward(u).out)}


# ---------------------------------------------------------------------------- #8: a contact that can let go


@dataclass
class ContactRun:
    """One run of a one-sided contact stage: the gap and where it first let go."""

    speed: float  # cycles per second
    gap: Array  # per sample, model units (positive: apart)
    pose_error: float  # largest follower deviation from its analytic pose / size, before any lift-off
    liftoff: int | None  # first sample whose gap exceeds the tolerance
    liftoff_time: float | None = None


def contact_hold(
    mech: Any,
    speed: float,
    gravity: tuple[float, float],
    cycles: float = 1.0,
    samples_per_cycle: int = 72,
    substeps: int = 64,
    density: float = 1.0,
    tolerance: float = 1e-3,
    drive: StageDrive | None = None,
) -> ContactRun:
    """Simulate an elemental #8 (its own plane) with a contact that can only push.

    ``mech``: an :class:`~planar.windup.mechanisms.ElementalMechanism` #8 driven
    by its standalone law, or inside a toy by ``drive``, at ``speed`` cycles/s; ``gravity``: in the stage's plane
    (model units / s^2).  The window is kinematic; the tab is a dynamic body on
    a pivot; the contact is a segment (the tab's face) and a circle of radius
    ``1e-4`` of the size on the window's edge.
    """
    import pymunk

    from planar.analysis.dynamics import mass_properties

    j = next(j for j in mech.joints if isinstance(j, CamOnLine))
    fol, drv = mech.part(j.a), mech.part(j.b)
    law = _law(mech, drive, speed)
    t = law.times(samples_per_cycle, cycles)
    ana_poses = _poses(mech, law.value(t), drive)
    h = 1e-6 / speed
    fp = _poses(mech, law.value(t + h), drive)
    fm = _poses(mech, law.value(t - h), drive)
    size = mech.size
    m, cog, inertia = mass_properties(fol, density)
    space = pymunk.Space()
    space.gravity = gravity
    space.iterations = 30
    space.collision_slop = 1e-7 * size
    body = pymunk.Body(m, inertia)
    p0 = ana_poses[fol.name][0]
    c, s = math.cos(p0[2]), math.sin(p0[2])
    body.position = (p0[0] + c * cog[0] - s * cog[1], p0[1] + s * cog[0] + c * cog[1])
    body.angle = float(p0[2])
    w0 = float((fp[fol.name][0, 2] - fm[fol.name][0, 2]) / (2 * h))
    body.angular_velocity = w0
    kin = pymunk.Body(body_type=pymunk.Body.KINEMATIC)
    d0 = ana_poses[drv.name][0]
    kin.position = (float(d0[0]), float(d0[1]))
    piv = next(jj for jj in mech.joints if type(jj).__name__ == "Pivot" and fol.name in (jj.a, jj.b))
    anchor = piv.anchor_b if piv.b == fol.name else piv.anchor_a  # the pivot in the tab's own frame
    ga = poses_apply(ana_poses[fol.name][0], anchor)
    body.velocity = (-w0 * (body.position.y - ga[1]), w0 * (body.position.x - ga[0]))
    rc = 1e-4 * size
    rs = 0.02 * size  # a thick face (into the tab, -x of it) so that the edge cannot tunnel through in a step
    face = pymunk.Segment(body, (j.start[0] - rs - cog[0], j.start[1] - cog[1]), (j.end[0] - rs - cog[0], j.end[1] - cog[1]), rs)
    edge = pymunk.Circle(kin, rc, (j.centre[0] + rc, j.centre[1]))  # the window's material lies to +x of its edge
    face.friction = edge.friction = 0.0
    space.add(body, kin, face, edge, pymunk.PivotJoint(space.static_body, body, (float(ga[0]), float(ga[1]))))
    n = t.size
    dt = float(t[1] - t[0]) / substeps
    xs = ana_poses[drv.name][:, 0]
    gap = np.zeros(n)
    err = np.zeros(n)
    track = np.zeros((n, 3))
    for i in range(n):
        if i:
            x_prev = xs[i - 1]
            for k in range(substeps):
                xa = x_prev + (xs[i] - x_prev) * (k + 1) / substeps
                kin.velocity = ((xa - kin.position.x) / dt, 0.0)
                space.step(dt)
        a = body.angle
        c, s = math.cos(a), math.sin(a)
        ox = body.position.x - (c * cog[0] - s * cog[1])
        oy = body.position.y - (s * cog[0] + c * cog[1])
        track[i] = (ox, oy, a)
    # the gap: the edge point's distance from the face line, positive on the window's open side (the tab let go)
    A = poses_apply(ana_poses[drv.name], j.centre)
    s0 = poses_apply(track, j.start)
    s1 = poses_apply(track, j.end)
    d = s1 - s0
    nrm = np.column_stack([d[:, 1], -d[:, 0]]) / np.hypot(d[:, 0], d[:, 1])[:, None]
    gap = ((A - s0) * nrm).sum(1)  # > 0: the face has moved away from the edge (the tab let go, towards -x)
    ref = poses_apply(ana_poses[fol.name], np.asarray(fol.hull)[:, :2])
    got = poses_apply(track, np.asarray(fol.hull)[:, :2])
    err = np.hypot(*(got - ref).transpose(2, 0, 1)).max(1) / size
    bad = np.flatnonzero(np.abs(gap) > tolerance * size)
    lift = int(bad[0]) if bad.size else None
    upto = n if lift is None else lift
    return ContactRun(speed, gap, float(err[:upto].max(initial=0.0)), lift, None if lift is None else float(t[lift]))


def liftoff_speed(
    mech: Any, gravity: tuple[float, float], speeds: Any, refine: int = 5, **kw: Any
) -> tuple[float | None, list[ContactRun]]:
    """Run :func:`contact_hold` at each of ``speeds`` (cycles/s, rising) until one lets go, then bisect ``refine``
    times between the last that held and it; returns the lowest speed seen to let go (None: it always held)
    and every run (the last one is the lowest that let go)."""
    runs: list[ContactRun] = []
    held = 0.0
    for sp in speeds:
        r = contact_hold(mech, float(sp), gravity, **kw)
        runs.append(r)
        if r.liftoff is None:
            held = float(sp)
            continue
        lo, hi, worst = held, float(sp), r
        for _ in range(refine if held > 0 else 0):
            mid = 0.5 * (lo + hi)
            rm = contact_hold(mech, mid, gravity, **kw)
            if rm.liftoff is None:
                lo = mid
            else:
                hi, worst = mid, rm
        runs.append(worst)
        return hi, runs
    return None, runs


def liftoff_resolution(speeds: Any, lift: float, refine: int = 5) -> float:
    """How finely :func:`liftoff_speed` measured ``lift`` (cycles/s): the bracket it bisected, halved ``refine``
    times (the whole first scanned speed when the first one already let go: no bisection then)."""
    sc = [float(x) for x in speeds]
    k = next(i for i, x in enumerate(sc) if x >= lift - 1e-12 * abs(lift))
    if k == 0:
        return sc[0]
    return (sc[k] - sc[k - 1]) / 2**refine


def format_speed(value: float, resolution: float) -> str:
    """``value`` with as many decimals as ``resolution`` supports, e.g. ``3.41`` for a resolution of 0.06."""
    decimals = max(0, -math.floor(math.log10(resolution))) if resolution > 0 else 6
    return f"{value:.{decimals}f}"


def hold_margin(
    mech: Any, gravity: tuple[float, float], density: float = 1.0, samples: int = 720, drive: StageDrive | None = None
) -> float:
    """The speed (cycles/s) above which inverse dynamics needs the #8 contact to pull (it lets go); inf if never,
    0 if gravity cannot hold it even at rest.

    About the tab's pivot, the contact's moment is ``M = I_B alpha - M_g``; with the driver law's shape fixed,
    ``alpha`` scales with speed squared.  The contact can only push (the sign of ``M`` where it does work at
    rest), so the critical speed is ``sqrt(min over samples of M_g / (I_B alpha_1))`` where the two oppose.
    """
    from planar.analysis.dynamics import mass_properties

    j = next(j for j in mech.joints if isinstance(j, CamOnLine))
    fol = mech.part(j.a)
    m, cog, ic = mass_properties(fol, density)
    one = _law(mech, drive, 1.0)
    t = np.linspace(0.0, 1.0, samples, endpoint=False)
    h = 1e-4
    ang = [_poses(mech, one.value(t + k * h), drive)[fol.name][:, 2] for k in (-1, 0, 1)]
    alpha1 = (ang[2] - 2 * ang[1] + ang[0]) / h**2  # at 1 cycle/s
    now = _poses(mech, one.value(t), drive)
    pose = now[fol.name]
    piv = next(jj for jj in mech.joints if type(jj).__name__ == "Pivot" and fol.name in (jj.a, jj.b))
    anchor = piv.anchor_b if piv.b == fol.name else piv.anchor_a  # the pivot in the tab's own frame
    B = poses_apply(pose, anchor)
    G = poses_apply(pose, cog)
    r = G - B
    Mg = m * (r[:, 0] * gravity[1] - r[:, 1] * gravity[0])
    IB = ic + m * float(((np.asarray(cog) - np.asarray(anchor)) ** 2).sum())
    # the push direction: the contact's moment sign from the face normal and the edge point (window side: -x)
    A = poses_apply(now[j.b], j.centre)
    push = np.array([-1.0, 0.0])  # the window's edge pushes the tab's face towards -x
    sgn = np.sign((A[:, 0] - B[:, 0]) * push[1] - (A[:, 1] - B[:, 1]) * push[0])
    # need sgn * M >= 0 with M(s) = s^2 IB alpha1 - Mg
    hold = sgn * (-Mg)  # at rest
    if (hold < 0).any():
        return 0.0
    grow = sgn * IB * alpha1
    crit = np.where(grow < 0, hold / np.maximum(-grow, 1e-300), np.inf)
    return float(np.sqrt(crit.min()))


# ---------------------------------------------------------------------------- #6, #9: in the follower's plane


def skew_stage(
    mech: Any,
    speed: float,
    cycles: float = 1.0,
    samples_per_cycle: int = 72,
    substeps: int = 128,
    density: float = 1.0,
    tolerance: float = 1e-3,
    drive: StageDrive | None = None,
    gravity: tuple[float, float] = (0.0, 0.0),
    record: list[tuple[float, float]] | None = None,
) -> tuple[float, str | None]:
    """Rebuild #6/#9 in its follower's plane (yz) and run it; ``(worst error / size, refusal or None)``.

    ``gravity``: in the follower's plane (y, z).  The rebuilt contact is two-sided (a groove); ``record``,
    when given, gets per step ``(time at the step's end s, the contact's moment on the follower about its
    pivot)``, read from pymunk as the change of the follower's angular momentum about the pivot less
    gravity's moment: where its sign is not the one the edge can push with (:func:`skew_hold`), the groove
    pulled.
    """
    import pymunk

    from planar.analysis.dynamics import mass_properties

    j = next(j for j in mech.joints if isinstance(j, SkewContact))
    fol = mech.part(j.b)
    law = _law(mech, drive, speed)
    t = law.times(samples_per_cycle, cycles)
    n = t.size
    sub_t = t[0] + (np.arange((n - 1) * substeps + 1)) * (float(t[1] - t[0]) / substeps)
    mo = _poses(mech, law.value(sub_t), drive)
    dp = mo[j.a]
    fpose = mo[j.b]
    # the edge's trace on the plane x = pin_x, and its direction's angle phi to x (per step)
    e0 = poses_apply(dp, j.edge_point)
    ang = dp[:, 2] + math.atan2(j.edge_dir[1], j.edge_dir[0])
    ex, ey = np.cos(ang), np.sin(ang)
    if np.abs(ex).min() < 1e-9:
        return math.inf, f"{mech.name}: the edge runs parallel to the follower's plane: no trace point"
    ty = e0[:, 1] + (j.pin_x - e0[:, 0]) * ey / ex
    cphi = np.abs(ex)  # |cos| of the edge's angle to the plane's normal (x)
    size = mech.size
    m, cog, inertia = mass_properties(fol, density)
    space = pymunk.Space()
    space.iterations = 40
    body = pymunk.Body(m, inertia)
    f0 = fpose[0]
    c, s = math.cos(f0[2]), math.sin(f0[2])
    body.position = (f0[0] + c * cog[0] - s * cog[1], f0[1] + s * cog[0] + c * cog[1])
    body.angle = float(f0[2])
    space.gravity = (float(gravity[0]), float(gravity[1]))
    if record is not None:  # start on the path's velocity (else the groove's first step is a kick)
        w0 = float(fpose[1, 2] - fpose[0, 2]) / (float(t[1] - t[0]) / substeps)
        body.angular_velocity = w0
        body.velocity = (-w0 * (body.position.y - f0[1]), w0 * (body.position.x - f0[0]))
    kin = pymunk.Body(body_type=pymunk.Body.KINEMATIC)
    kin.position = (float(ty[0]), float(j.plane_z))
    # the pin's axis in the follower frame runs from the pivot (0, 0) along +y (the follower frame's "up")
    top = max(abs(y) for _, y, _ in fol.hull) or 1.0
    sgn_top = 1.0 if any(y > 0 for _, y, _ in fol.hull) else -1.0

    def r_eff(a: float, cp: float) -> float:
        return j.radius * math.sqrt(math.cos(a) ** 2 + math.sin(a) ** 2 * cp * cp) / cp

    # which side of the axis the trace point is on, at the start
    side = 1.0 if (ty[0] - f0[0]) * math.cos(f0[2]) + (j.plane_z - f0[1]) * math.sin(f0[2]) > 0 else -1.0
    # the groove: the trace point rides on the line parallel to the axis at r_eff(a0) on its side
    r0 = r_eff(float(f0[2]), float(cphi[0]))
    g0 = (side * r0 - cog[0], -0.5 * top * sgn_top - cog[1])
    g1 = (side * r0 - cog[0], 2.0 * top * sgn_top - cog[1])
    dt = float(t[1] - t[0]) / substeps
    cons = [
        pymunk.PivotJoint(space.static_body, body, (float(f0[0]), float(f0[1]))),
        pymunk.GrooveJoint(body, kin, g0, g1, (0.0, 0.0)),
    ]
    for c_ in cons:  # correct a fifth of any joint error per step (pymunk's default leaves ~99 % per step here)
        c_.error_bias = 0.8 ** (1.0 / dt)
    space.add(body, kin, *cons)
    track = np.zeros((n, 3))
    track[0] = f0
    k = 0
    for i in range(1, n):
        for _ in range(substeps):
            k += 1
            a = body.angle + body.angular_velocity * dt  # the tilt at the step's end (predicted)
            # the groove sits at r0; the true in-plane distance is r_eff(a): move the point by the difference
            # along the axis's normal (the contact follows the pin's tilt)
            dr = side * (r_eff(a, float(cphi[k])) - r0)
            tx = ty[k] - dr * math.cos(a)
            tz = j.plane_z - dr * math.sin(a)
            kin.velocity = ((tx - kin.position.x) / dt, (tz - kin.position.y) / dt)
            if record is not None:
                ry, rz = body.position.x - f0[0], body.position.y - f0[1]
                l0 = inertia * body.angular_velocity + m * (ry * body.velocity.y - rz * body.velocity.x)
            space.step(dt)
            if record is not None:  # pymunk moves positions with the new velocities: the lever arm of the step
                v = body.velocity
                l1 = inertia * body.angular_velocity + m * (ry * v.y - rz * v.x)
                record.append((float(sub_t[k]), (l1 - l0) / dt - m * (ry * gravity[1] - rz * gravity[0])))
        a = body.angle
        c, s = math.cos(a), math.sin(a)
        track[i] = (body.position.x - (c * cog[0] - s * cog[1]), body.position.y - (s * cog[0] + c * cog[1]), a)
    ref = fpose[::substeps]
    pts = np.asarray(fol.hull)[:, :2]
    err = float(np.hypot(*(poses_apply(track, pts) - poses_apply(ref, pts)).transpose(2, 0, 1)).max()) / size
    if not err <= tolerance:
        return err, (f"{mech.name}: rebuilt in the follower's plane it strays {err:.3g} of the size (tolerance {tolerance:g})")
    return err, None


# ---------------------------------------------------------------------------- #6, #9: can the edge hold the pin?


@dataclass
class SkewHold:
    """What inverse dynamics says of a #6/#9 contact (the driver's edge can only push the follower's pin).

    Moments about the follower's pivot, in its plane (yz; positive from +y towards +z, i.e. about +x),
    model units at the run's density.
    """

    speed: float  # cycles/s, the speed the samples are taken at
    t: Array  # s, one cycle of samples
    moment: Array  # the moment the edge must exert on the follower, M = I_p phi'' - M_g
    push: Array  # +-1: the sign of the moment the edge can exert (from the contact's geometry)
    letgo: int | None  # the first sample where it would have to pull (sign(M) != push), None: it holds
    critical_speed: float  # cycles/s above which it lets go (inf: never; 0: even at rest)
    gravity: tuple[float, float]  # in the follower's plane (y, z)


def _skew_gap_a(j: SkewContact, fpose: Array, dpose: Array, da: float = 0.0) -> Array:
    """Signed distance between the driver's edge and the pin's axis, per sample, the pin turned by ``da``
    (vectorised :func:`_skew_gap`; ``fpose``: the follower's (y, z, angle), its origin on the pivot axis)."""
    c, s = np.cos(dpose[:, 2]), np.sin(dpose[:, 2])
    e0 = poses_apply(dpose, j.edge_point)
    ex = c * j.edge_dir[0] - s * j.edge_dir[1]
    ey = s * j.edge_dir[0] + c * j.edge_dir[1]
    a = fpose[:, 2] + da
    ca, sa = np.cos(a), np.sin(a)
    n = np.column_stack([-ca * ey, ca * ex, sa * ex])  # (0, -sin a, cos a) x (ex, ey, 0)
    d = np.column_stack([e0[:, 0] - j.pin_x, e0[:, 1] - fpose[:, 0], np.full_like(a, j.plane_z) - fpose[:, 1]])
    return (d * n).sum(1) / np.linalg.norm(n, axis=1)


def _skew_terms(
    mech: Any, j: SkewContact, gravity: tuple[float, float], density: float, samples: int, drive: StageDrive | None
) -> tuple[Array, Array, Array, Array]:
    """Over one cycle at 1 cycle/s (``samples`` per cycle): ``(t, I_p phi'', M_g, push)`` of :func:`skew_hold`."""
    from planar.analysis.dynamics import mass_properties

    fol = mech.part(j.b)
    m, cog, ic = mass_properties(fol, density)
    ip = ic + m * float(cog[0] ** 2 + cog[1] ** 2)  # the follower's frame origin is on its pivot axis
    one = _law(mech, drive, 1.0)
    t1 = one.times(samples, 1.0)
    h = 1e-4
    ang = [_poses(mech, one.value(t1 + k * h), drive)[j.b][:, 2] for k in (-1, 0, 1)]
    alpha1 = (ang[2] - 2 * ang[1] + ang[0]) / h**2  # rad/s^2 at 1 cycle/s
    now = _poses(mech, one.value(t1), drive)
    fp, dp = now[j.b], now[j.a]
    r = poses_apply(fp, cog) - fp[:, :2]  # pivot to centre of gravity (y, z)
    mg = m * (r[:, 0] * gravity[1] - r[:, 1] * gravity[0])
    s0 = _skew_gap_a(j, fp, dp)
    ds = (_skew_gap_a(j, fp, dp, 1e-7) - _skew_gap_a(j, fp, dp, -1e-7)) / 2e-7
    return t1, ip * alpha1, mg, np.sign(np.sign(s0) * ds)


def skew_hold(
    mech: Any,
    gravity: tuple[float, float],
    speed: float,
    density: float = 1.0,
    samples_per_cycle: int = 72,
    drive: StageDrive | None = None,
    fine: int = 1440,
) -> SkewHold:
    """Inverse dynamics of a #6/#9 follower: can the driver's edge, which only pushes, keep it on its path?

    ``gravity``: in the follower's plane (y, z) (:func:`planar.analysis.dynamics.plane_gravity` ``"yz"``); ``speed``:
    cycles/s, the moments are sampled ``samples_per_cycle`` times over its cycle.  About the pivot the
    contact must exert ``M = I_p phi'' - M_g`` (``I_p`` the follower's moment about the pivot, ``M_g``
    gravity's moment).  The contact keeps the edge at the pin's radius from its axis (``sigma s >= r``,
    ``s`` the skew lines' signed distance, ``sigma`` its sign in contact), so its moment is
    ``lambda sigma ds/dphi`` with ``lambda >= 0``: where ``M`` has the other sign it would have to pull, and
    the pin leaves the edge.  ``phi''`` scales with the speed squared (the driver law's shape is fixed), so
    the critical speed is ``sqrt(min over samples of push M_g / (-push I_p phi''_1))`` where the two oppose
    (``fine`` samples per cycle).
    """
    j = next(j for j in mech.joints if isinstance(j, SkewContact))
    _, ia, mg, push = _skew_terms(mech, j, gravity, density, fine, drive)
    hold = push * (-mg)  # what the contact must give at rest, signed so that >= 0 is a push
    grow = push * ia  # its growth per (cycle/s)^2
    tol = 1e-9 * max(float(np.abs(mg).max()), float(np.abs(ia).max()), 1e-300)
    if (hold < -tol).any():
        crit = 0.0
    else:
        crit = float(np.sqrt(np.where(grow < -tol, np.maximum(hold, 0.0) / np.maximum(-grow, 1e-300), np.inf).min()))
    t1, ia, mg, push = _skew_terms(mech, j, gravity, density, samples_per_cycle, drive)
    moment = speed**2 * ia - mg
    tol = 1e-9 * max(float(np.abs(mg).max()), float(np.abs(ia).max()) * speed**2, 1e-300)
    bad = np.flatnonzero(push * moment < -tol)
    return SkewHold(
        speed, t1 / speed, moment, push, int(bad[0]) if bad.size else None, crit, (float(gravity[0]), float(gravity[1]))
    )


# ---------------------------------------------------------------------------- the whole toy


@dataclass
class StageReport:
    stage: str
    pattern: str
    simulated: bool
    detail: str


@dataclass
class ToyPhysics:
    """What :func:`simulate_toy` found: the motor torque of the toy's plane and every stage's fate."""

    torque: dict[str, Any]
    stages: list[StageReport] = field(default_factory=list)
    liftoff: dict[str, Any] = field(default_factory=dict)
    skew: dict[str, Any] = field(default_factory=dict)  # #6/#9: does the edge hold the pin (skew_hold, pymunk)

    @property
    def not_simulated(self) -> list[StageReport]:
        return [s for s in self.stages if not s.simulated]


def simulate_toy(
    toy: Any, t: Array, effects: Any = None, settings: Any = None, speeds: Any = None, densities: dict[str, float] | None = None
) -> ToyPhysics:
    """The toy's coupled motor run with its torque against inverse dynamics, and every stage's own physics.

    ``t``: output times (s) at the toy's speed.  The coupled run holds the xy
    pieces and, when the scene names gravity, the xz pieces of #8 stages (tied
    to their body's xy piece by :class:`SharedX`; one 2D space, the toy's
    gravity ``(gx, gy, 0)`` acting on them as ``(gx, 0)`` along (x, z):
    :func:`planar.analysis.dynamics.plane_gravity`) and the yz followers of #6/#9 (co-simulated in their plane,
    gravity ``(gy, 0)``, their load on their driver: :func:`_skew_load`), so
    the motor torque and the inverse dynamics it is compared with both carry
    every stage.  ``densities``: per piece (assembly part name), overriding the
    scene's density in the coupled run and its inverse dynamics (e.g. a
    heavier follower).  Each #8 stage also runs alone, one-sided, scanned over
    ``speeds`` (cycles/s) for lift-off; #6/#9 are also rebuilt alone in their
    follower's plane.  A stage that cannot be simulated is reported with the
    reason.
    """
    from planar.analysis.dynamics import gravity_and_damping, plane_gravity
    from planar.physics.simulate import SimSettings, torque_comparison

    asm = toy_assembly(toy)
    gx, gy = (float(v) for v in gravity_and_damping(effects)[0])
    g3 = (gx, gy)  # the toy's gravity (gx, gy, 0), zero when the scene names none
    gxz = plane_gravity("xz", g3)
    g = (float(gxz[0]), float(gxz[1]))  # what an #8 stage's pieces (xz) feel of the toy's gravity (gx, gy, 0)
    has_xz = any(p.plane == "xz" and not p.ground for p in asm.parts)
    # the motor turns the xy pieces and, through the bodies they share, the xz stages (whose contact needs what
    # holds it: without gravity or a spring they are left out of the coupled run)
    flat = coupled_mechanism(asm, xz=has_xz and g != (0.0, 0.0))
    # 128 substeps, 80 iterations: measured, the motor torque's start transient at 32 substeps is 4 % of the peak
    # for the Bunny (its #8 tab coupled), 0.7 % at 64 and 1e-6 at 128 (Horse 2.6e-3, 2.6e-4, 2.9e-5)
    tq = torque_comparison(
        flat, np.asarray(t, float), effects, settings or SimSettings(substeps=128, iterations=80), densities=densities
    )
    tq["pieces"] = [p.name for p in flat.parts]
    speed = toy.driver.rate / (2 * math.pi)
    out = ToyPhysics(tq)
    for p in asm.placed:
        st = p.stage
        label, pat, num = st.label, st.realisation.pattern, st.realisation.number

        def stage_u(q: Array, _i: int = st.index) -> Array:
            toy.world_motion(q)
            return np.asarray(toy._last_bases[_i][0], float)

        drive: StageDrive = (toy.driver, stage_u)  # the stage as the toy drives it
        if num == 8:
            if g == (0.0, 0.0):
                out.stages.append(
                    StageReport(
                        label,
                        pat,
                        False,
                        (
                            "#8: its contact is held by gravity or a spring in its plane (xz); "
                            + (
                                "the scene names none"
                                if g3 == (0.0, 0.0)
                                else f"the scene's gravity ({g3[0]:g}, {g3[1]:g}) has no x component, and its y is normal to "
                                "the xz plane"
                            )
                        ),
                    )
                )
                continue
            crit = hold_margin(st.mech, g, getattr(effects, "density", 1.0), drive=drive)
            sc = list(speeds) if speeds is not None else [speed * f for f in (1.0, 2.0, 4.0, 8.0)]
            lift, runs = liftoff_speed(st.mech, g, sc, drive=drive)
            r0 = runs[0]
            out.liftoff[label] = {
                "predicted_speed": crit,
                "scanned": sc,
                "liftoff_speed": lift,
                "resolution": None if lift is None else liftoff_resolution(sc, lift),
                "sample": runs[-1].liftoff,
                "pose_error": r0.pose_error,
            }
            held = r0.liftoff is None
            agrees = r0.pose_error <= 1e-3
            out.stages.append(
                StageReport(
                    label,
                    pat,
                    agrees,
                    (
                        (
                            ""
                            if agrees
                            else f"#8: the one-sided run strays {r0.pose_error:.2g} of the size from the analytic "
                            "motion (not accepted); "
                        )
                        + f"#8 one-sided contact: {'holds' if held else 'lets go'} at {speed:g} cycles/s "
                        f"(pose error {r0.pose_error:.2g} of the size); lift-off "
                        + (
                            f"at {format_speed(lift, res)} cycles/s (measured to {res:.2g}), sample {runs[-1].liftoff}"
                            if lift is not None and (res := liftoff_resolution(sc, lift)) > 0
                            else "not seen in the scan"
                        )
                        + f"; inverse dynamics predicts {crit:.3g} cycles/s"
                    ),
                )
            )
        elif st.mech.spatial:
            out.stages.append(_skew_report(st, toy, drive, effects, g3, speed, np.asarray(t, float), out))
        else:
            out.stages.append(StageReport(label, pat, True, "in the motor's plane (coupled)"))
    return out


def _skew_report(
    st: Any, toy: Any, drive: StageDrive, effects: Any, g3: tuple[float, float], speed: float, t: Array, out: ToyPhysics
) -> StageReport:
    """#6/#9 in :func:`simulate_toy`: the rebuild alone (pymunk, with gravity) and whether the edge holds the pin."""
    from planar.analysis.dynamics import plane_gravity

    label, pat, mech = st.label, st.realisation.pattern, st.mech
    j = next(j for j in mech.joints if isinstance(j, SkewContact))
    sprung = [f"{s.a}-{s.b}" for s in getattr(effects, "springs", ()) or () if mech.part(j.b).name in (s.a, s.b)]
    if sprung:
        return StageReport(
            label,
            pat,
            False,
            f"#{st.realisation.number}: a spring on the yz follower ({sprung[0]}) is not modelled in its hold check",
        )
    gp = plane_gravity("yz", g3)
    g = (float(gp[0]), float(gp[1]))
    per = max(int(round(1.0 / (speed * float(t[1] - t[0])))), 4) if t.size > 1 else 72
    dens = float(getattr(effects, "density", 1.0) or 1.0)
    hold = skew_hold(mech, g, speed, dens, per, drive)
    rec: list[tuple[float, float]] = []
    err, why = skew_stage(mech, speed, drive=drive, gravity=g, record=rec, density=dens)
    tr, mr = np.array(rec, float).T if rec else (np.zeros(0), np.zeros(0))
    keep = tr > tr[0] + 1.0 / (72 * speed) if tr.size else tr > 0  # its first sample interval: a start transient
    tr, mr = tr[keep], mr[keep]
    # pymunk's contact moment against the side the edge can push (the push sign at the nearest sample)
    pk = hold.push[np.clip(np.rint(tr * speed * per).astype(int), 0, per - 1)] if tr.size else np.zeros(0)
    pulls = np.flatnonzero(pk * mr < -1e-6 * max(float(np.abs(mr).max(initial=0.0)), 1e-300))
    sim_t = float(tr[pulls[0]]) if pulls.size else None
    held = hold.letgo is None
    out.skew[label] = {
        "holds": held,
        "sample": hold.letgo,
        "time": None if held else float(hold.t[hold.letgo]),
        "critical_speed": hold.critical_speed,
        "gravity_yz": list(g),
        "moment_range": [float(hold.moment.min()), float(hold.moment.max())],
        "push_sign": float(hold.push[0]) if np.all(hold.push == hold.push[0]) else 0.0,
        "pymunk_pull_time": sim_t,
    }
    crit = hold.critical_speed
    hold_txt = (
        f"#{st.realisation.number} edge on the pin (it can only push): {'holds' if held else 'lets go'} at "
        f"{speed:g} cycles/s"
        + ("" if held else f" (first at sample {hold.letgo}, t = {hold.t[hold.letgo]:.4g} s)")
        + "; inverse dynamics: lets go "
        + ("at any speed" if crit == 0.0 else "never" if math.isinf(crit) else f"above {crit:.3g} cycles/s")
        + f" (gravity in its plane ({g[0]:g}, {g[1]:g}))"
        + ("; the rebuild (pymunk, two-sided) pulls first at " + (f"t = {sim_t:.4g} s" if sim_t is not None else "no step"))
    )
    if why is not None:
        return StageReport(label, pat, False, why + "; " + hold_txt)
    return StageReport(
        label,
        pat,
        True,
        (
            f"in the motor run, co-simulated in its plane (yz); alone, rebuilt in the follower's plane: "
            f"{err:.2g} of the size; " + hold_txt
        ),
    )


# ---------------------------------------------------------------------------- #6, #9 in the motor run


def _skew_gap(j: SkewContact, pivot: tuple[float, float], a: float, q: tuple[float, float, float]) -> float:
    """Signed distance (model units) between the driver's edge (driver origin pose ``q`` in xy) and the pin's
    axis (through ``(pin_x, pivot)``, tilted ``a`` in yz): the skew lines' common normal, as
    :meth:`SkewContact.residual` measures it, with its sign kept (it stays +-``radius`` in contact)."""
    c, s = math.cos(q[2]), math.sin(q[2])
    e0x = q[0] + c * j.edge_point[0] - s * j.edge_point[1]
    e0y = q[1] + s * j.edge_point[0] + c * j.edge_point[1]
    ex = c * j.edge_dir[0] - s * j.edge_dir[1]
    ey = s * j.edge_dir[0] + c * j.edge_dir[1]
    ca, sa = math.cos(a), math.sin(a)
    n = (-ca * ey, ca * ex, sa * ex)  # (0, -sin a, cos a) x (ex, ey, 0)
    d = (e0x - j.pin_x, e0y - pivot[0], j.plane_z - pivot[1])
    return (d[0] * n[0] + d[1] * n[1] + d[2] * n[2]) / math.sqrt(n[0] ** 2 + n[1] ** 2 + n[2] ** 2)


def _skew_load(rb: Any, j: SkewContact, effects: Any) -> list[Any]:
    """#6/#9 in the motor run: the yz follower co-simulated in a 2D space of its own, in lockstep.

    The follower's body (made by the rebuild, mass from its outline) moves to a
    space of its own (the follower's plane: gravity
    :func:`~planar.analysis.dynamics.plane_gravity` ``"yz"``, the run's damping and step
    scaling) on its pivot.  Each step of the motor's space, before it solves (a
    ``pre_solve`` on a constraint that applies nothing), that space steps once:

    * **the contact's kinematics**: the tilt ``a`` at which the pin touches the
      driver's edge is solved (Newton) from the skew lines' exact distance
      (:func:`_skew_gap`: the pin's tilt-dependent reach in the plane is in
      it), for the driver as pymunk has it now (the follower is put there) and
      moved on by its velocity (a motor on the follower turns it there within
      the step: one velocity row, which pymunk solves exactly; a
      ``GrooveJoint`` holding the edge's trace point, as :func:`skew_stage`
      has it, was measured turning the Bunny's ear 19 % too fast, its pin kept
      in the groove only by the position correction);
    * **the load**: the contact's moment ``M`` on the follower about its pivot
      over the step is read from pymunk (the change of its angular momentum
      about the pivot, less gravity's and the damping's share), and the driver
      gets the contact's generalized force ``Q = -M da/dq`` (virtual work of a
      frictionless contact: ``Q dq + M da = 0``; ``da/dq`` from the skew
      distance by central differences at the current poses), a force at its
      origin and a torque, within the step, so the motor holds it;
    * **stability**: that force follows the driver's velocity of the step
      before; alone, it set the motor's solver oscillating once the
      follower's reflected inertia ``I_p (da/dq)^2`` neared the driver's (the
      Bunny's ear at 10x its density).  The driver therefore carries that
      inertia as added mass and moment (its own, scaled to match along its
      motion), and gets back what
      they resist for the velocity change the follower was moved with (and
      what gravity and damping do to them): the inertial load acts on the
      velocity the solver finds, and nothing is counted twice.
    """
    import pymunk

    from planar.analysis.dynamics import gravity_and_damping, plane_gravity
    from planar.physics.simulate import SimulationError

    drv, fol = rb.bodies[j.a], rb.bodies[j.b]
    if fol.body_type != pymunk.Body.DYNAMIC or drv.space is None:
        raise SimulationError(
            f"joint {j.name!r}: the follower {j.b!r} must move under the solver, driven by {j.a!r} in the motor's space"
        )
    main = drv.space
    main.remove(fol)
    dt = rb.dt
    yz = pymunk.Space()
    yz.iterations = main.iterations
    g, _ = gravity_and_damping(effects)
    gp = plane_gravity("yz", g)
    yz.gravity = (float(gp[0]) * dt * dt, float(gp[1]) * dt * dt)
    yz.damping = main.damping
    fcog, dcog = rb.cog[j.b], rb.cog[j.a]
    here = fol.local_to_world((-fcog[0], -fcog[1]))
    pivot = (float(here[0]), float(here[1]))  # the follower frame's origin: on its pivot axis

    def driver_pose() -> tuple[float, float, float]:
        a = drv.angle
        c, s = math.cos(a), math.sin(a)
        return (drv.position.x - (c * dcog[0] - s * dcog[1]), drv.position.y - (s * dcog[0] + c * dcog[1]), a)

    gap0 = _skew_gap(j, pivot, fol.angle, driver_pose())  # +-radius: the side the edge touches
    turn = pymunk.SimpleMotor(yz.static_body, fol, 0.0)  # Chipmunk drives w_fol - w_static = -rate
    hold = pymunk.PivotJoint(yz.static_body, fol, pivot, (-fcog[0], -fcog[1]))
    hold.error_bias = 1.0 - rb.correction
    yz.add(fol, turn, hold)
    m, ic = fol.mass, fol.moment
    ip = ic + m * float(fcog[0] ** 2 + fcog[1] ** 2)  # the follower's moment about its pivot
    m0, i0 = drv.mass, drv.moment
    hq = 1e-6 * max(rb.mech.size, 1e-12)
    prev: list[tuple[float, float, float]] = []
    scale = [0.0]
    failed: list[str] = []

    def touching(q: tuple[float, float, float], a: float) -> float:
        """The tilt near ``a`` at which the pin touches the edge of a driver at pose ``q`` (Newton)."""
        for _ in range(8):
            f = _skew_gap(j, pivot, a, q) - gap0
            d = (_skew_gap(j, pivot, a + 1e-7, q) - _skew_gap(j, pivot, a - 1e-7, q)) / 2e-7
            step_ = f / d
            a -= step_
            if abs(step_) < 1e-14:
                break
        return a

    def jacobian(a: float, q: tuple[float, float, float]) -> list[float]:
        """``da/dq`` for the driver origin's ``(x, y, angle)``: the contact keeps the skew gap constant."""
        ga = (_skew_gap(j, pivot, a + 1e-6, q) - _skew_gap(j, pivot, a - 1e-6, q)) / 2e-6
        out = []
        for k, h in ((0, hq), (1, hq), (2, 1e-6)):
            qp, qm = list(q), list(q)
            qp[k] += h
            qm[k] -= h
            gq = _skew_gap(j, pivot, a, (qp[0], qp[1], qp[2])) - _skew_gap(j, pivot, a, (qm[0], qm[1], qm[2]))
            out.append(-gq / (2 * h) / ga)
        return out

    def step(_c: Any, _space: Any) -> None:
        q = driver_pose()
        w = drv.angular_velocity
        c, s = math.cos(q[2]), math.sin(q[2])
        rx, ry = -(c * dcog[0] - s * dcog[1]), -(s * dcog[0] + c * dcog[1])  # origin - centre of gravity
        vc = (drv.velocity.x, drv.velocity.y, w)  # centre of gravity's velocity (per step), angular velocity
        vp = (vc[0] - w * ry, vc[1] + w * rx, w)  # the driver origin's velocity: taken as the step's
        # the follower touching the driver as it is now (pymunk moves positions first: it is put where its
        # velocity takes it there), and turned to where it touches the driver moved on by its velocity
        af = touching(q, fol.angle + fol.angular_velocity)
        ca, sa = math.cos(af), math.sin(af)
        fol.angle = af - fol.angular_velocity
        fol.position = (
            pivot[0] + ca * fcog[0] - sa * fcog[1] - fol.velocity.x,
            pivot[1] + sa * fcog[0] + ca * fcog[1] - fol.velocity.y,
        )
        a1 = touching((q[0] + vp[0], q[1] + vp[1], q[2] + vp[2]), af + fol.angular_velocity)
        turn.rate = -(a1 - af)
        v0, w0 = fol.velocity, fol.angular_velocity
        yz.step(1.0)
        # the contact's moment on the follower about its pivot over the step (angular momentum change)
        gx, gy = fol.position.x - pivot[0], fol.position.y - pivot[1]
        v1, w1 = fol.velocity, fol.angular_velocity

        def mom(v: Any, w_: float) -> float:
            return ic * w_ + m * (gx * v[1] - gy * v[0])

        mc = mom(v1, w1) - yz.damping * mom(v0, w0) - m * (gx * yz.gravity[1] - gy * yz.gravity[0])
        jq = jacobian(fol.angle, q)
        if drv.body_type != pymunk.Body.DYNAMIC:
            return  # an imposed driver (kinematic mode): nothing to load
        # the contact's generalized force on the driver: Q = -M da/dq (a force at its origin and a torque)
        drv.apply_force_at_world_point((-mc * jq[0], -mc * jq[1]), (q[0], q[1]))
        # Alone, that force, one step behind the driver's motion, sets the motor's solver oscillating once
        # the follower's reflected inertia I_p (da/dq)^2 is near the driver's (the Bunny's ear at 10x its
        # density).  So the driver carries that inertia as added mass and moment, and gets
        # back what the added inertia resists for the velocity change this step's follower was moved with
        # (vc - the previous step's), and what gravity and damping would do to it: the follower's inertial
        # load then acts on the velocity the solver finds (implicit), and nothing is counted twice.
        # the added inertia: the driver's own, scaled so that along its motion it is the reflected one
        # (I_p (da/dq . qdot)^2 = s (m |v_G|^2 + I w^2)); kept while the driver stands still
        own = m0 * (vc[0] ** 2 + vc[1] ** 2) + i0 * w * w
        if own > 0.0:
            scale[0] = ip * (jq[0] * vp[0] + jq[1] * vp[1] + jq[2] * vp[2]) ** 2 / own
        ma, ia = scale[0] * m0, scale[0] * i0
        drv.mass, drv.moment = m0 + ma, i0 + ia
        pv = prev[0] if prev else vc
        prev[:] = [vc]
        d = main.damping
        drv.force = drv.force + (
            ma * (vc[0] - pv[0] + (1.0 - d) * vc[0] - main.gravity[0]),
            ma * (vc[1] - pv[1] + (1.0 - d) * vc[1] - main.gravity[1]),
        )
        drv.torque = drv.torque - mc * jq[2] + ia * (vc[2] - pv[2] + (1.0 - d) * vc[2])

    def guarded(c_: Any, space_: Any) -> None:
        # pymunk prints and drops an exception raised in a callback: warn once and make the run fail instead
        # (a NaN velocity: the pose check stops the run there and reports it)
        try:
            step(c_, space_)
        except Exception as exc:
            if not failed:
                warnings.warn(f"{j.name}: the co-simulated follower {j.b!r} failed: {exc}", stacklevel=1)
            failed.append(str(exc))
            drv.velocity = (math.nan, math.nan)

    hook = pymunk.SimpleMotor(main.static_body, drv, 0.0)
    hook.max_force = 0.0  # applies nothing: its pre_solve steps the follower's space
    hook.pre_solve = guarded
    return [hook]


_register()
