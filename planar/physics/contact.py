"""Wind-up #8: a contact that can let go, held by gravity; its lift-off speed."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from planar.core.geometry import poses_apply
from planar.core.model import CamOnLine
from planar.physics.toyviews import StageDrive, _law, _poses

__all__ = ["ContactRun", "contact_hold", "format_speed", "hold_margin", "liftoff_resolution", "liftoff_speed"]

Array = NDArray[np.float64]


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
