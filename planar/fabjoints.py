"""What the joints mean for cutting and assembly: pins, contacts, which holes a pin goes through.

A *pin* is a round pin through a hole of one part and a hole or slot of
another (a pivot with holes on both sides, a pin in a straight or arc slot,
each of a slide's two pins).  A *contact* joins two parts without a pin (a
round cam in a hole, a cam on a flat face, a tilting pin on an edge): those
parts must lie in one plane layer to touch.  Positions are in each part's own
frame, model units.  A joint kind with no rule here is an error naming it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from .errors import PlanarError
from .model import ArcSlot, Hole, Mechanism, Part, Slot

__all__ = ["Contact", "FabricationError", "PinSpec", "joint_pins", "pin_features"]

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


@dataclass(frozen=True)
class Contact:
    joint: str
    parts: tuple[str, str]
    coplanar: bool


def _joint_parts(j: Any) -> tuple[str, str]:
    """The two part names a joint connects (``j.parts`` when the joint has it, else the old field names)."""
    if hasattr(j, "parts"):
        a, b = j.parts
        return str(a), str(b)
    for fa, fb in (("a", "b"), ("pin_part", "slot_part"), ("part", "guide"), ("cam_part", "face_part"),
                   ("driver", "follower")):
        if hasattr(j, fa) and hasattr(j, fb):
            return str(getattr(j, fa)), str(getattr(j, fb))
    raise FabricationError(f"joint {getattr(j, 'name', j)!r}: kind {type(j).__name__} names no parts")


def _hole_at(part: Part, p: tuple[float, float]) -> Hole | None:
    for f in part.features:
        if isinstance(f, Hole) and math.dist(f.centre, p) < TOL * max(1.0, abs(p[0]) + abs(p[1])):
            return f
    return None


def _close(a, b) -> bool:
    return math.dist(a, b) < TOL * max(1.0, abs(a[0]) + abs(a[1]))


def joint_pins(mech: Mechanism) -> tuple[list[PinSpec], list[Contact]]:
    """Pins and contacts of every joint, in joint order."""
    pins: list[PinSpec] = []
    contacts: list[Contact] = []
    for j in mech.joints:
        kind = type(j).__name__
        a, b = _joint_parts(j)
        if kind == "Pivot":
            pa, pb = mech.part(a), mech.part(b)
            if _hole_at(pa, j.anchor_a) and _hole_at(pb, j.anchor_b):
                pins.append(PinSpec(j.name, (a, b), (tuple(j.anchor_a), tuple(j.anchor_b)), ("hole", "hole")))
            else:  # a round cam running in a hole: the disc is the pin
                contacts.append(Contact(j.name, (a, b), True))
        elif kind in ("PinInSlot", "PinInArcSlot"):
            pins.append(PinSpec(j.name, (a, b), (tuple(j.pin), _slot_point(j)), ("hole", "slot")))
        elif kind == "Slide":
            for k, p in enumerate((j.anchor, (j.anchor[0] + j.axis[0], j.anchor[1] + j.axis[1]))):
                pins.append(PinSpec(f"{j.name}#{k + 1}", (a, b), (tuple(p), tuple(j.start)), ("hole", "slot")))
        elif kind == "CamOnLine":
            contacts.append(Contact(j.name, (a, b), True))
        elif kind == "SkewContact":
            contacts.append(Contact(j.name, (a, b), False))
        else:
            raise FabricationError(f"joint {j.name!r}: no fabrication rule for joint kind {kind}")
    return pins, contacts


def _slot_point(j: Any) -> tuple[float, float]:
    if hasattr(j, "start"):
        return (float(j.start[0]), float(j.start[1]))
    return (float(j.centre[0] + j.radius), float(j.centre[1]))


def pin_features(mech: Mechanism) -> set[tuple[str, int]]:
    """``(part, feature index)`` of every hole or slot a pin goes through (cut at the scene's pin size)."""
    out: set[tuple[str, int]] = set()
    by_name = {p.name: p for p in mech.parts}
    for j in mech.joints:
        kind = type(j).__name__
        a, b = _joint_parts(j) if kind in ("Pivot", "PinInSlot", "PinInArcSlot", "Slide") else ("", "")
        if kind == "Pivot":
            pa, pb = by_name[a], by_name[b]
            ha, hb = _hole_at(pa, j.anchor_a), _hole_at(pb, j.anchor_b)
            if ha and hb:
                out.add((a, pa.features.index(ha)))
                out.add((b, pb.features.index(hb)))
        elif kind in ("PinInSlot", "PinInArcSlot", "Slide"):
            pin_part, slot_part = by_name[a], by_name[b]
            anchors = [j.pin] if kind != "Slide" else [j.anchor, (j.anchor[0] + j.axis[0], j.anchor[1] + j.axis[1])]
            for p in anchors:
                h = _hole_at(pin_part, p)
                if h is not None:
                    out.add((a, pin_part.features.index(h)))
            for i, f in enumerate(slot_part.features):
                if kind == "PinInArcSlot" and isinstance(f, ArcSlot) and _close(f.centre, j.centre) \
                        and abs(f.radius - j.radius) < TOL * max(1.0, j.radius) or kind != "PinInArcSlot" and isinstance(f, Slot) and _close(f.start, j.start) and _close(f.end, j.end):
                    out.add((b, i))
    return out
