"""Bill of materials (CSV): parts with layer and sheet, pins with diameter and length, spacers, motor, screws.

Columns: ``item, id, qty, layer, sheet, size_mm, joins, notes``.  Each pin's row names what it is made of (the
``[fabrication] hardware``: a steel rod with washers and e-clips, or a button-head screw with washers and a nylon
lock nut; :mod:`planar.fabrication.hardware`), the motor shaft's row its length above the motor and what holds
its driven part, the ``motor``, ``motor screw``, ``standoff`` and ``mounting screw`` rows their sizes with
lengths (the standoffs tall enough for what hangs under the bottom layer: the motor's body, the pins' lower ends),
a ``sheet`` row first (how many sheets, their size and thickness), and the
``buy`` rows at the end total every item to buy by size.  A ``tabs`` row
per tab-and-slot joint (``planar.fabrication.tabs``): its letter, the number of tabs,
a tab's ``width x length``, ``piece -> xy piece`` and which slots they go into.  Layers and
sheets count from 1; ``size_mm`` is the part's bounding box as laid out, a pin's
``d x length``, a spacer's ``ID x OD x thickness`` (its ``layer`` the layers its rings fill, each ring
named).  Fixed formatting, rows in mechanism order: the same input gives the same bytes.
"""

from __future__ import annotations

import csv
import io
import math
from typing import Any

from planar.fabrication.hardware import (
    driven_part,
    motor_items,
    mounting_items,
    pin_items,
    shaft_items,
    shaft_length,
    shaft_retention,
    standoffs,
)
from planar.fabrication.sheet import cut_polygon

__all__ = ["bom_text"]


def bom_text(fab: Any) -> str:
    s, asm, lay = fab.settings, fab.assembly, fab.layout
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(["item", "id", "qty", "layer", "sheet", "size_mm", "joins", "notes"])
    notes_of: dict[str, list[str]] = {}
    for n in fab.notes:
        notes_of.setdefault(n.split(":", 1)[0], []).append(n.split(":", 1)[-1].strip())
    _sheet_row(w, fab)
    for p in lay.parts:
        if p.name.startswith("spacer ") or p.name not in asm.layers:
            continue  # spacers have their own rows; the reference square is no part
        x0, y0, x1, y1 = cut_polygon(p.outer, math.radians(0.5)).bounds
        layer = asm.layers.get(p.name)
        plane = asm.plane.get(p.name, "xy")
        where = "" if layer is None else (f"{layer + 1}" if plane == "xy" else f"{plane} {layer + 1}")
        extra = [f"engraved {p.label!r}" if p.label and p.label != p.name else ""] + notes_of.get(p.name, [])
        w.writerow(
            [
                "part",
                p.name,
                1,
                where,
                p.sheet + 1,
                f"{x1 - x0:.1f} x {y1 - y0:.1f} x {s.thickness_mm:g}",
                "",
                "; ".join(e for e in extra if e),
            ]
        )
    ri = s.pin_mm + s.clearance
    for pp in asm.pins:
        lo, hi = pp.layers or (0, 0)
        joins = " + ".join(pp.parts)
        if pp.shaft:
            w.writerow(
                [
                    "motor shaft",
                    pp.letter,
                    1,
                    f"{lo + 1}-{hi + 1}",
                    "",
                    f"D {s.shaft_mm:g} ({s.shaft_flat_mm:g} across flat) x {shaft_length(s, pp):g} above the motor",
                    joins,
                    f"joint {', '.join(pp.joints)}; the motor's shaft is {s.motor_shaft_mm:g} mm (motor_shaft_mm)"
                    f"{': too short' if shaft_length(s, pp) > s.motor_shaft_mm + 1e-9 else ''}; "
                    "motor under the ground plate, 2 screws "
                    f"{s.motor_screw_spacing_mm:g} mm apart; {shaft_retention(driven_part(pp, fab.grounds))}: "
                    + " + ".join(f"{i.qty} {i.item} {i.size}" for i in shaft_items(s, pp)),
                ]
            )
        else:
            w.writerow(
                [
                    "pin",
                    pp.letter,
                    1,
                    f"{lo + 1}-{hi + 1}",
                    "",
                    f"{pp.diameter_mm:g} x {pp.length_mm:g}",
                    joins,
                    f"joint {', '.join(pp.joints)}; "
                    + " + ".join(f"{i.qty} {i.item} {i.size}" for i in pin_items(s, pp))
                    + (f"; passes through {', '.join(pp.clashes)}" if pp.clashes else ""),
                ]
            )
        if pp.spacers:
            sp = [
                p
                for p in lay.parts
                if p.name.startswith(f"spacer {pp.letter}") and p.name[len(f"spacer {pp.letter}") :].isdigit()
            ]
            od = 2 * max((c.radius for c in [p.outer for p in sp] if hasattr(c, "radius")), default=0.0) - s.kerf
            own = {asm.layers.get(p) for p in pp.parts}
            free = [k + 1 for k in range(lo, hi + 1) if k not in own]
            w.writerow(
                [
                    "spacer",
                    pp.letter,
                    pp.spacers,
                    ", ".join(str(k) for k in free),
                    "+".join(str(p.sheet + 1) for p in sp),
                    f"{ri:g} x {od:g} x {s.thickness_mm:g}",
                    joins,
                    f"cut from the sheet; on pin {pp.letter} (layers {lo + 1}-{hi + 1}) filling layer"
                    f"{'s' if len(free) > 1 else ''} {_and(free)}: "
                    + ", ".join(f"spacer {pp.letter}{j + 1} on layer {k}" for j, k in enumerate(free)),
                ]
            )
    for jn in getattr(fab, "joins", []):  # tab-and-slot joints of pieces standing perpendicular (planar.fabrication.tabs)
        lo, hi = jn.slot_size
        w.writerow(
            [
                "tabs",
                jn.letter,
                len(jn.spans),
                "",
                "",
                f"{jn.tab_width:g} x {s.thickness_mm:g}",
                f"{jn.piece} -> {jn.base}",
                f"the {len(jn.spans)} tabs {jn.letter} of {jn.piece} ({jn.plane}) into the {len(jn.slots)} slots "
                f"{jn.letter} ({lo:g} x {hi:g} mm) of {jn.base}; glue them",
            ]
        )
    for p in lay.parts:
        if p.name == "reference square":  # cut beside the parts, no part of the assembly
            x0, y0, x1, y1 = cut_polygon(p.outer, math.radians(0.5)).bounds
            w.writerow(
                [
                    "reference square",
                    "",
                    1,
                    "",
                    p.sheet + 1,
                    f"{s.reference_square_mm:g} x {s.reference_square_mm:g}",
                    "",
                    "not a part: measure it after cutting to check the scale",
                ]
            )
    _fixing_rows(w, fab)
    _buy_rows(w, fab)
    return buf.getvalue()


def _sheet_row(w: Any, fab: Any) -> None:
    """The sheet itself: how many, their size and thickness (the material is the maker's choice: plywood or
    acrylic of that thickness)."""
    s, lay = fab.settings, fab.layout
    w.writerow(
        [
            "sheet",
            "",
            lay.sheets,
            "",
            "1" if lay.sheets == 1 else f"1-{lay.sheets}",
            f"{lay.sheet_size[0]:g} x {lay.sheet_size[1]:g} x {s.thickness_mm:g}",
            "",
            f"plywood (birch, laser grade) or cast acrylic, {s.thickness_mm:g} mm; every part and spacer ring is cut "
            f"from it (kerf {lay.kerf:g} mm)",
        ]
    )


def _and(xs: list[int]) -> str:
    """``1``, ``1 and 2``, ``1, 2 and 3``."""
    words = [str(x) for x in xs]
    return words[0] if len(words) == 1 else ", ".join(words[:-1]) + " and " + words[-1]


def _plates(fab: Any) -> list[str]:
    """The ground plates cut flat with two mounting holes each (the plates that stand on the standoffs)."""
    asm = fab.assembly
    return [p.name for p in fab.layout.parts if asm.layers.get(p.name) is not None and p.name in fab.mounts]


def _fixing_rows(w: Any, fab: Any) -> None:
    """The motor with its face screws, and the ground plates' mounting screws, washers and nuts."""
    s = fab.settings
    for pp in fab.assembly.pins:
        if pp.shaft:
            motor, screw = motor_items(s)
            w.writerow(["motor", pp.letter, motor.qty, "", "", motor.size, "", f"{motor.item}; its shaft is pin {pp.letter}"])
            w.writerow(
                [
                    "motor screw",
                    pp.letter,
                    screw.qty,
                    "",
                    "",
                    screw.size,
                    "",
                    f"{screw.item}, down through the ground plate into the motor's face under it, heads countersunk "
                    f"flush with the plate's top face ({s.motor_screw_mm:g} mm clearance holes, "
                    f"{s.motor_screw_spacing_mm:g} mm apart, countersunk from the top to 3.2 mm across)",
                ]
            )
    plates = _plates(fab)
    if plates:
        *stack, screw, washer = mounting_items(s, fab.below_mm)
        k, height = standoffs(s, fab.below_mm)
        for standoff in stack:
            w.writerow(
                [
                    "standoff",
                    "",
                    standoff.qty * len(plates),
                    "",
                    "",
                    standoff.size,
                    "",
                    f"{standoff.item}, under the two mounting holes of each ground plate"
                    + (f" ({k} stacked under each hole: {height:g} mm, the male-female ones on top)" if k > 1 else "")
                    + f": {round(fab.below_mm, 1):g} mm hangs below the bottom layer (the motor's body, the pins' lower"
                    " ends, pieces standing below), the standoffs stand the plate clear of it",
                ]
            )
        w.writerow(
            [
                "mounting screw",
                "",
                screw.qty * len(plates),
                "",
                "",
                screw.size,
                "",
                f"{screw.item} + {washer.item}, four per ground plate: two down through its mounting holes "
                f"({s.mounting_hole_mm:g} mm) into the standoffs' tops, two up through a {s.thickness_mm:g} mm base "
                "board into their bottoms (a thicker base: longer screws)",
            ]
        )


def _buy_rows(w: Any, fab: Any) -> None:
    """One ``buy`` row per item to buy by size (pins' fasteners, the motor, its screws and glue, mounting screws): totals."""
    s, asm = fab.settings, fab.assembly
    total: dict[tuple[str, str], int] = {}
    uses: dict[tuple[str, str], list[str]] = {}

    def add(items: list[Any], use: str) -> None:
        for i in items:
            total[(i.item, i.size)] = total.get((i.item, i.size), 0) + i.qty
            if use not in uses.setdefault((i.item, i.size), []):
                uses[(i.item, i.size)].append(use)

    for pp in asm.pins:
        add(shaft_items(s, pp) + motor_items(s) if pp.shaft else pin_items(s, pp), "motor" if pp.shaft else "pins")
    for _ in _plates(fab):
        add(mounting_items(s, fab.below_mm), "mounting")
    for (item, size), qty in sorted(total.items()):
        w.writerow(["buy", item, qty, "", "", size, "", "total for " + ", ".join(uses[(item, size)])])
