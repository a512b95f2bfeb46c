"""Wind-up #6 and #9: the follower in its own plane, whether the edge holds the pin, and its load in the motor run."""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from planar.core.geometry import poses_apply
from planar.physics.toyviews import StageDrive, _law, _poses

__all__ = ["SkewHold", "skew_hold", "skew_stage"]
from planar.windup.mechanisms import ElementalMechanism, SkewContact

Array = NDArray[np.float64]


# ---------------------------------------------------------------------------- #6, #9: in the follower's plane


def skew_stage(
    mech: ElementalMechanism,
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
    mech: ElementalMechanism, j: SkewContact, gravity: tuple[float, float], density: float, samples: int, drive: StageDrive | None
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
    mech: ElementalMechanism,
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
