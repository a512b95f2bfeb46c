"""What the joints mean for cutting and assembly: pins, contacts, which holes a pin goes through.

A *pin* is a round pin through a hole of one part and a hole or slot of
another (a pivot with holes on both sides, a pin in a straight or arc slot,
each of a slide's two pins).  A *contact* joins two parts without a pin (a
round cam in a hole, a cam on a flat face, a tilting pin on an edge): those
parts must lie in one plane layer to touch.  Positions are in each part's own
frame, model units.  Rules are found per joint kind in ``PIN_RULES``; a kind with
no rule is an error naming it.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from planar.cams.joint import CamContact
from planar.core.model import ArcSlot, CamOnLine, Hole, Mechanism, Part, PinInArcSlot, PinInSlot, Pivot, Slide, Slot
from planar.core.registry import Registry
from planar.errors import PlanarError
from planar.linkages.gears import GearMesh
from planar.toys.assembly import KeyedShaft
from planar.windup.mechanisms import SkewContact

__all__ = ["PIN_RULES", "Contact", "FabricationError", "PinSpec", "joint_pins", "pin_features", "register_contact"]

TOL = 1e-7


class FabricationError(PlanarError):
    """A mechanism that cannot be made as asked (message: one line naming the part or joint)."""


@dataclass(frozen=True)
class PinSpec:
    """A pin joining ``parts[0]`` (at ``at[0]``, own frame) and ``parts[1]`` (at ``at[1]``)."""

    joint: str
    parts: tuple[str, str]
    at: tuple[tuple[float, float], tuple[float, float]]
    #: "hole" or "slot" on each side
    kinds: tuple[str, str]
    #: ``(part, feature index)`` of each hole or slot this pin goes through (cut at the scene's pin size)
    features: tuple[tuple[str, int], ...] = ()


@dataclass(frozen=True)
class Contact:
    """Two parts joined by touching: ``coplanar`` ones share a layer; ``through``: one may instead reach
    through the other from another layer (#8's tab standing in its window)."""

    joint: str
    parts: tuple[str, str]
    coplanar: bool
    through: bool = False


def _hole_at(part: Part, p: tuple[float, float]) -> Hole | None:
    for f in part.features:
        if isinstance(f, Hole) and math.dist(f.centre, p) < TOL * max(1.0, abs(p[0]) + abs(p[1])):
            return f
    return None


def _index(mech: Mechanism, part: str, feature: Any) -> tuple[tuple[str, int], ...]:
    """``((part, index),)`` of ``feature`` on ``part``, or ``()`` when there is none."""
    if feature is None:
        return ()
    return ((part, mech.part(part).features.index(feature)),)


def _slot_on(part: Part, j: PinInSlot | Slide) -> Slot | None:
    for f in part.features:
        if isinstance(f, Slot) and _close(f.start, j.start) and _close(f.end, j.end):
            return f
    return None


def _v(p: Any) -> tuple[float, float]:
    return (float(p[0]), float(p[1]))


def _close(a: Any, b: Any) -> bool:
    return math.dist(a, b) < TOL * max(1.0, abs(a[0]) + abs(a[1]))


#: pins and contacts of one joint, per joint kind: (mechanism, joint) -> (pins, contacts)
PIN_RULES: Registry[Callable[[Mechanism, Any], tuple[list[PinSpec], list[Contact]]]] = Registry("fabrication")


@PIN_RULES.register(Pivot)
def _pivot(mech: Mechanism, j: Pivot) -> tuple[list[PinSpec], list[Contact]]:
    ha, hb = _hole_at(mech.part(j.a), j.anchor_a), _hole_at(mech.part(j.b), j.anchor_b)
    if ha and hb:
        feats = _index(mech, j.a, ha) + _index(mech, j.b, hb)
        return [PinSpec(j.name, (j.a, j.b), (_v(j.anchor_a), _v(j.anchor_b)), ("hole", "hole"), feats)], []
    return [], [Contact(j.name, (j.a, j.b), True)]  # a round cam running in a hole: the disc is the pin


@PIN_RULES.register(PinInSlot)
def _pin_in_slot(mech: Mechanism, j: PinInSlot) -> tuple[list[PinSpec], list[Contact]]:
    hole = _hole_at(mech.part(j.b), j.pin)
    if hole is None:
        # no hole at the "pin": the part's own round body runs in the slot (a wind-up eccentric cam in its
        # follower's window), so nothing is pinned and the window keeps its own width
        return [], [Contact(j.name, (j.a, j.b), True)]
    feats = _index(mech, j.b, hole) + _index(mech, j.a, _slot_on(mech.part(j.a), j))
    return [PinSpec(j.name, (j.b, j.a), (_v(j.pin), _v(j.start)), ("hole", "slot"), feats)], []


@PIN_RULES.register(PinInArcSlot)
def _pin_in_arc_slot(mech: Mechanism, j: PinInArcSlot) -> tuple[list[PinSpec], list[Contact]]:
    on_arc = (float(j.centre[0] + j.radius), float(j.centre[1]))
    arc = next(
        (
            f
            for f in mech.part(j.a).features
            if isinstance(f, ArcSlot) and _close(f.centre, j.centre) and abs(f.radius - j.radius) < TOL * max(1.0, j.radius)
        ),
        None,
    )
    feats = _index(mech, j.b, _hole_at(mech.part(j.b), j.pin)) + _index(mech, j.a, arc)
    return [PinSpec(j.name, (j.b, j.a), (_v(j.pin), on_arc), ("hole", "slot"), feats)], []


@PIN_RULES.register(Slide)
def _slide(mech: Mechanism, j: Slide) -> tuple[list[PinSpec], list[Contact]]:
    slot = _index(mech, j.a, _slot_on(mech.part(j.a), j))
    return [
        PinSpec(
            f"{j.name}#{k + 1}",
            (j.b, j.a),
            (_v(p), _v(j.start)),
            ("hole", "slot"),
            _index(mech, j.b, _hole_at(mech.part(j.b), p)) + slot,
        )
        for k, p in enumerate(j.pin_points())
    ], []


@PIN_RULES.register(KeyedShaft)
def _keyed_shaft(mech: Mechanism, j: KeyedShaft) -> tuple[list[PinSpec], list[Contact]]:
    """The motor shaft: one pin through every cam keyed to it."""
    return [PinSpec(j.name, (j.a, j.b), (j.anchor_a, j.anchor_b), ("hole", "hole"))], []


@PIN_RULES.register(CamOnLine)
def _cam_on_line(mech: Mechanism, j: CamOnLine) -> tuple[list[PinSpec], list[Contact]]:
    return [], [Contact(j.name, (j.a, j.b), True, through=True)]


def register_contact(kind: type, coplanar: bool) -> None:
    """A joint kind that joins its parts by touching, without a pin (``coplanar``: in one layer)."""

    def rule(mech: Mechanism, j: Any) -> tuple[list[PinSpec], list[Contact]]:
        return [], [Contact(j.name, (j.a, j.b), coplanar)]

    PIN_RULES.register(kind)(rule)


register_contact(SkewContact, coplanar=False)  # a tilting pin on an edge: across layers
register_contact(GearMesh, coplanar=True)  # two gears in mesh: one layer
register_contact(CamContact, coplanar=True)  # a profile cam and its roller or follower: in one layer


def joint_pins(mech: Mechanism) -> tuple[list[PinSpec], list[Contact]]:
    """Pins and contacts of every joint, in joint order (a kind with no rule is an error naming it)."""
    pins: list[PinSpec] = []
    contacts: list[Contact] = []
    for j in mech.joints:
        p, c = PIN_RULES.get(j, f"joint {j.name!r}")(mech, j)
        pins += p
        contacts += c
    return pins, contacts


def pin_features(mech: Mechanism) -> set[tuple[str, int]]:
    """``(part, feature index)`` of every hole or slot a pin goes through (cut at the scene's pin size): what
    each joint kind's rule in ``PIN_RULES`` says its pins go through."""
    pins, _ = joint_pins(mech)
    return {f for pin in pins for f in pin.features}
