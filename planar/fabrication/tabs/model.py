"""The tab joints' records (:class:`TabJoin`, :class:`TabPlan`) and which perpendicular piece is
joined to which xy piece (its rigid body's): what the view, the planner and the slots share."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from planar.core.model import Mechanism
from planar.fabrication.joints import FabricationError
from planar.fabrication.parts import Feature

PLANES = ("xz", "yz")
MIN_TABS = 2


@dataclass
class TabJoin:
    """Tabs of ``piece`` (perpendicular) in slots of ``base`` (xy), lettered ``letter`` (``T1``, ...).

    ``at``: the piece's plane (mm; world y for xz, x for yz); ``side``: +1 when the piece lies on the
    model's +z side of the xy plane; ``edge``: the world z (mm) where it stands on the xy piece's face;
    ``spans``: each tab's ends along the line where the planes meet (world
    x for xz, y for yz, mm); ``slots``: each slot's centre (base frame, mm) and the slot's long-axis angle.
    """

    letter: str
    piece: str
    base: str
    plane: str
    at: float
    side: int
    #: the edge the piece stands on: world z (mm) of its plane; its tabs run from there ``thickness`` away from it
    edge: float
    spans: list[tuple[float, float]]
    tab_width: float
    slot_size: tuple[float, float]
    slots: list[tuple[tuple[float, float], float]] = field(default_factory=list)
    #: the piece's own-frame outline change: keep this half-plane polygon, add these tab rectangles (mm)
    keep: Any = None
    tabs: list[Any] = field(default_factory=list)


def _bodies(mech: Mechanism) -> dict[str, list[str]]:
    """Rigid bodies -> pieces (a toy assembly's own; else each part alone, every ground one body)."""
    got = mech.bodies
    if got:
        return {k: list(v) for k, v in got.items()}
    out: dict[str, list[str]] = {}
    for p in mech.parts:
        out.setdefault("frame" if p.ground else p.name, []).append(p.name)
    return out


def _joined(mech: Mechanism, bodies: dict[str, list[str]]) -> dict[str, str]:
    """Perpendicular piece -> the xy piece of its body it is tab-joined to."""
    plane = {p.name: p.plane for p in mech.parts}
    out: dict[str, str] = {}
    for pieces in bodies.values():
        xy = [n for n in pieces if plane.get(n) == "xy"]
        for n in pieces:
            if plane.get(n) in PLANES and xy:
                if len(xy) > 1:
                    raise FabricationError(
                        f"part {n!r}: its body has {len(xy)} xy pieces ({', '.join(xy)}); "
                        "no rule says which one its tabs go into, it cannot be tab-joined"
                    )
                out[n] = xy[0]
    return out


@dataclass
class TabPlan:
    """The tab joints, the travel slots (xy piece -> cuts, mm) letting perpendicular pieces pass through other
    layers, what was done (notes), and the stack's lower face along the model's z (mm)."""

    joins: list[TabJoin] = field(default_factory=list)
    travel: dict[str, list[Feature]] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)
    z_stack: float = 0.0
    #: every perpendicular piece's plane position (mm: y for xz, x for yz)
    planes: dict[str, float] = field(default_factory=dict)
    #: pose tracks over the cycle (mm, mm, rad) and each piece's shape as cut (own frame, mm)
    track: dict[str, Any] = field(default_factory=dict)
    shape: dict[str, Any] = field(default_factory=dict)
