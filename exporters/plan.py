"""``plan.json``: the assembly as data, for a tool that checks or assembles it without planar.

Everything in millimetres and degrees, layers and sheets counting from 1.  Each part's ``placement``
``[x_mm, y_mm, angle_deg]`` maps the part's own frame (the frame of the motion table's ``<part>.x``,
``<part>.y``, ``<part>.angle``, lengths times ``unit_mm``) onto its sheet: a point ``p`` of the part lies on
the sheet at ``R(angle) p + (x, y)``.  Each pin names its parts, the layers it spans, its bought length, its
diameter, its ends (height and diameter beyond its outer layers) and where it is: ``anchor`` (a part and the
point in that part's own frame, mm). ``motor``: its body's length below its face (the face against the bottom
layer), its shaft's length above it and its screws; ``mounting``: how far things hang below the bottom layer
(``below_mm``), the standoffs' length and where they go on each ground plate (own frame, mm). The schema is
``docs/reference/plan.schema.json``. Fixed key order and number formatting: the same input gives the same bytes.
"""

from __future__ import annotations

import json
import math
from typing import Any

__all__ = ["SCHEMA_VERSION", "plan_dict", "plan_json"]

SCHEMA_VERSION = 1


def _r(v: float) -> float:
    return round(float(v), 6) + 0.0


def _parts(fab: Any) -> list[dict[str, Any]]:
    asm = fab.assembly
    out = []
    for p in fab.layout.parts:
        if p.name.startswith("spacer ") or p.name not in asm.layers:
            continue  # spacers are listed on their own; the reference square is no part of the assembly
        layer = asm.layers.get(p.name)
        a, dx, dy = p.placed
        out.append(
            {
                "name": p.name,
                "layer": None if layer is None else layer + 1,
                "plane": asm.plane.get(p.name, "xy"),
                "sheet": p.sheet + 1,
                "placement": [_r(dx), _r(dy), _r(math.degrees(a))],
            }
        )
    return out


def _pin(fab: Any, pp: Any) -> dict[str, Any]:
    from planar.fabrication.hardware import (
        driven_part,
        end_height,
        pin_ends,
        pin_items,
        shaft_items,
        shaft_length,
        shaft_retention,
    )

    s = fab.settings
    lo, hi = pp.layers or (0, 0)
    lower, upper = pin_ends(s, pp)
    d = {
        "name": pp.letter,
        "joints": list(pp.joints),
        "parts": list(pp.parts),
        "plane": fab.assembly.plane.get(pp.parts[0], "xy"),
        "layers": [lo + 1, hi + 1],
        "length_mm": _r(shaft_length(s, pp) if pp.shaft else pp.length_mm),
        "diameter_mm": _r(s.shaft_mm if pp.shaft else pp.diameter_mm),
        "head_mm": _r(max(end_height(lower), end_height(upper))),
        "ends": {"lower": _end(lower), "upper": _end(upper)},
        "anchor": {"part": pp.spec.parts[0], "at_mm": [_r(pp.spec.at[0][0] * s.unit_mm), _r(pp.spec.at[0][1] * s.unit_mm)]},
    }
    if pp.shaft:
        d["flat_mm"] = _r(s.shaft_flat_mm)
        d["retention"] = shaft_retention(driven_part(pp, fab.grounds))
    items = shaft_items(s, pp) if pp.shaft else pin_items(s, pp)
    d["hardware"] = [{"item": i.item, "size": i.size, "qty": i.qty} for i in items]
    return d


def _end(end: Any) -> dict[str, Any]:
    """One end of a pin: how far it stands beyond the stack, its widest diameter, and its tiers (from the face
    outwards, each a round body out to its height: a washer and nut or clip, then the thread or rod)."""
    from planar.fabrication.hardware import end_height

    return {
        "height_mm": _r(end_height(end)),
        "diameter_mm": _r(max((tr.diameter for tr in end), default=0.0)),
        "tiers": [{"height_mm": _r(tr.height), "diameter_mm": _r(tr.diameter)} for tr in end],
    }


def _spacers(fab: Any) -> list[dict[str, Any]]:
    from planar.fabrication.check import spacer_radius

    s, asm = fab.settings, fab.assembly
    cut = {p.name: p for p in fab.layout.parts}
    out = []
    for pp in asm.pins:
        lo, hi = pp.layers or (0, 0)
        own = {asm.layers.get(p) for p in pp.parts}
        free = [k for k in range(lo, hi + 1) if k not in own]
        for j, layer in enumerate(free):
            pc = cut.get(f"spacer {pp.letter}{j + 1}")
            a, dx, dy = pc.placed if pc is not None else (0.0, 0.0, 0.0)
            out.append(
                {
                    "name": f"spacer {pp.letter}{j + 1}",
                    "pin": pp.letter,
                    "layer": layer + 1,
                    "sheet": None if pc is None else pc.sheet + 1,
                    "placement": [_r(dx), _r(dy), _r(math.degrees(a))],
                    "inner_mm": _r(s.pin_mm + s.clearance),
                    "outer_mm": _r(2 * spacer_radius(s)),
                }
            )
    return out


def _motor(fab: Any) -> dict[str, Any] | None:
    """The motor (under the bottom layer, its face against it): its body's length below the face, its shaft's
    length above it, and its two face screws."""
    from planar.fabrication.hardware import motor_items

    s = fab.settings
    if not any(p.shaft for p in fab.assembly.pins):
        return None
    motor, screw = motor_items(s)
    return {
        "item": motor.item,
        "body_mm": _r(s.motor_body_mm),
        "shaft_mm": _r(s.motor_shaft_mm),
        "screws": {
            "item": screw.item,
            "size": screw.size,
            "qty": screw.qty,
            "hole_mm": _r(s.motor_screw_mm),
            "spacing_mm": _r(s.motor_screw_spacing_mm),
        },
    }


def _mounting(fab: Any) -> dict[str, Any] | None:
    """The ground plates' standoffs: what hangs below the bottom layer, the standoff length, where they go."""
    from planar.fabrication.hardware import mounting_items, standoff_length, standoffs

    s = fab.settings
    plates = [n for n in fab.grounds if n in fab.mounts and fab.assembly.layers.get(n) is not None]
    if not plates:
        return None
    return {
        "below_mm": _r(fab.below_mm),
        "standoff_mm": _r(standoff_length(s, fab.below_mm)),
        "stacked": standoffs(s, fab.below_mm)[0],
        "hole_mm": _r(s.mounting_hole_mm),
        "plates": [{"part": n, "at_mm": [[_r(x), _r(y)] for x, y in fab.mounts[n]]} for n in plates],
        "hardware": [{"item": i.item, "size": i.size, "qty": i.qty * len(plates)} for i in mounting_items(s, fab.below_mm)],
    }


def plan_dict(fab: Any) -> dict[str, Any]:
    """The plan of a :class:`~planar.fabrication.build.Fabrication` as plain data (see the module docstring)."""
    s = fab.settings
    pins = [p for p in fab.assembly.pins if not p.shaft]
    shafts = [p for p in fab.assembly.pins if p.shaft]
    return {
        "schema": SCHEMA_VERSION,
        "name": fab.name,
        "unit_mm": _r(s.unit_mm),
        "thickness_mm": _r(s.thickness_mm),
        "kerf_mm": _r(s.kerf),
        "pin_diameter_mm": _r(s.pin_mm),
        "clearance_mm": _r(s.clearance),
        "hardware": s.hardware,
        "sheets": fab.layout.sheets,
        "sheet_mm": [_r(fab.layout.sheet_size[0]), _r(fab.layout.sheet_size[1])],
        "layers": max(fab.assembly.n_layers.values(), default=0),
        "parts": _parts(fab),
        "pins": [_pin(fab, p) for p in pins],
        "spacers": _spacers(fab),
        "extras": [
            {"name": p.name, "sheet": p.sheet + 1, "placement": [_r(p.placed[1]), _r(p.placed[2]), _r(math.degrees(p.placed[0]))]}
            for p in fab.layout.parts
            if p.name == "reference square"
        ],
        "motor_shaft": _pin(fab, shafts[0]) if shafts else None,
        "motor": _motor(fab),
        "mounting": _mounting(fab),
        "contacts": [{"joint": c.joint, "parts": list(c.parts)} for c in fab.assembly.contacts],
        "violations": [
            {"what": v.what, "a": v.a, "b": v.b, "layer": v.layer, "sample": v.sample, "samples": v.count} for v in fab.violations
        ],
    }


def plan_json(fab: Any) -> str:
    """``plan.json``'s text (two-space indent, a newline at the end)."""
    return json.dumps(plan_dict(fab), indent=2) + "\n"
