"""A mechanism as fabrication cuts it (:func:`fab_view`): repeated perpendicular guides dropped, brackets
added for perpendicular pieces that no pin holds."""

from __future__ import annotations

from typing import Any

import numpy as np

from planar.core.model import Hole, Mechanism, Part, Pivot, Slide
from planar.fabrication.joints import FabricationError
from planar.fabrication.tabs.model import PLANES, _bodies, _joined
from planar.fabrication.views import PartsView


class FabView(PartsView):
    """A mechanism as fabrication cuts it: repeated perpendicular guides dropped, brackets added.

    Everything else (driver, notes, keyed cams, poses) is the wrapped mechanism's; a bracket stands still.
    """

    def __init__(self, mech: Mechanism, parts: list[Part], joints: list[Any], extra: list[str], notes: list[str]) -> None:
        super().__init__(mech, parts, joints)
        self.extra = extra
        self.notes = list(mech.notes) + notes
        self.bodies: dict[str, list[str]] = {k: list(v) for k, v in mech.bodies.items()}

    def run(self, *args: Any, **kw: Any) -> Any:
        m = self._mech.run(*args, **kw)
        for n in self.extra:
            m.poses[n] = np.zeros((len(m), 3))
        return m


def fab_view(mech: Any, samples: int = 48) -> Any:
    """``mech`` as it is cut (see the module docstring); ``mech`` itself when nothing stands perpendicular."""
    from planar.toys.assembly import _without_cuts_of

    parts = list(mech.parts)
    if not any(p.plane in PLANES for p in parts) or not any(p.plane == "xy" for p in parts):
        return mech
    bodies = _bodies(mech)
    joined = _joined(mech, bodies)
    body_of = {n: b for b, ps in bodies.items() for n in ps}
    plane = {p.name: p.plane for p in parts}
    # repeated guides: a perpendicular slide between two joined pieces repeats their bodies' xy slide
    joints, dropped = [], []
    for j in mech.joints:
        if isinstance(j, Slide) and plane.get(j.a) in PLANES and j.a in joined and j.b in joined:
            dropped.append(j)
        else:
            joints.append(j)
    notes: list[str] = []
    if dropped:
        parts, _removed = _without_cuts_of(parts, dropped, joints)
        for j in dropped:
            notes.append(
                f"{j.b}: its slide {j.name!r} in {j.a} is not cut: both pieces stand on the xy stack, "
                f"whose own slide guides them ({body_of.get(j.b, j.b)} on {body_of.get(j.a, j.a)})"
            )
    # brackets for perpendicular pieces that no pin holds
    held = set(joined)
    for j in joints:
        if isinstance(j, Pivot) and plane.get(j.a) == plane.get(j.b) and plane.get(j.a) in PLANES:
            held |= {j.a, j.b}
    loose = [p for p in parts if p.plane in PLANES and p.name not in held]
    extra: list[str] = []
    if loose:
        motion = mech.run(samples_per_cycle=samples)
        ok = np.flatnonzero(motion.valid)
        ok = ok if ok.size else np.arange(len(motion))
        for p in loose:
            bracket, pivot = _bracket(p, np.asarray(motion.poses[p.name], float)[ok])
            parts.append(bracket)
            joints.append(pivot)
            extra.append(bracket.name)
            notes.append(
                f"{bracket.name}: a bracket on the frame holding the axle of {p.name} (pin joint "
                f"{pivot.name!r}); nothing in the model holds it"
            )
    view = FabView(mech, parts, joints, extra, notes)
    frame = next((b for b, ps in bodies.items() if any(n in ps for n in (q.name for q in mech.parts if q.ground))), "frame")
    view.bodies = {**bodies, frame: bodies.get(frame, []) + extra}
    return view


def _bracket(p: Part, poses: np.ndarray) -> tuple[Part, Pivot]:
    """A frame piece in ``p``'s plane holding ``p``'s stationary hole (its axle), its base on ``z = 0``."""
    best = None
    for f in p.features:
        if not isinstance(f, Hole):
            continue
        c, s = np.cos(poses[:, 2]), np.sin(poses[:, 2])
        w = np.c_[poses[:, 0] + c * f.centre[0] - s * f.centre[1], poses[:, 1] + s * f.centre[0] + c * f.centre[1]]
        if float(np.ptp(w, axis=0).max()) < 1e-9 * max(1.0, float(np.abs(w).max())):
            best = (f, (float(w[0, 0]), float(w[0, 1])))
            break
    if best is None:
        raise FabricationError(
            f"part {p.name!r} ({p.plane}): no pin holds it and it turns about no fixed hole; "
            "no bracket can hold it, it cannot be tab-joined"
        )
    f, (u, z) = best
    if abs(z) < 2 * f.diameter:
        raise FabricationError(
            f"part {p.name!r} ({p.plane}): its axle lies on the xy plane (z = {z:.3g}); "
            "no room for a bracket standing on the frame, it cannot be tab-joined"
        )
    boss = 1.5 * f.diameter
    # the base reaches past the piece's own way through the stack on both sides, room for a tab beyond it
    c, s = np.cos(poses[:, 2]), np.sin(poses[:, 2])
    reach = max(float(np.abs(poses[:, 0] + c * x - s * y - u).max()) + r for x, y, r in p.hull)
    base = max(boss, 0.5 * abs(z), reach + 2 * boss)
    name = f"frame.{p.plane}.{p.name}"
    part = Part(
        name,
        ((u, z, boss), (u - base, 0.0, boss), (u + base, 0.0, boss)),
        (Hole((u, z), f.diameter),),
        ground=True,
        plane=p.plane,
        offset=p.offset,
    )
    return part, Pivot(f"{name}.axle", name, p.name, anchor_a=(u, z), anchor_b=(float(f.centre[0]), float(f.centre[1])))
