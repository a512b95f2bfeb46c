"""SVG in millimetres with the same geometry as the DXF, for cutters whose software takes no DXF.

One ``<g>`` per layer (``CUT_INNER`` blue, ``CUT_OUTER`` red, ``ENGRAVE``
green, ``SHEET`` grey), strokes only.  Arcs are SVG elliptical-arc commands
(circles), holes are ``<circle>``.  The drawing's y axis points up like the
DXF's; SVG's points down, so y is flipped once here.  Reproducible: no ids
or timestamps, fixed number formatting.
"""

from __future__ import annotations

import math
import os
from xml.sax.saxutils import escape

from planar.fabrication import SHEET_GAP, Circle, Contour, Layout
from planar.fileio import atomic_write

__all__ = ["write_svg", "svg_text"]

COLOURS = {"CUT_INNER": "#0000ff", "CUT_OUTER": "#ff0000", "ENGRAVE": "#00a000", "SHEET": "#999999"}


def _f(v: float) -> str:
    s = f"{v:.6f}".rstrip("0").rstrip(".")
    return "0" if s in ("-0", "") else s


def svg_text(layout: Layout) -> str:
    W, H = layout.sheet_size
    total_w = layout.sheets * W + (layout.sheets - 1) * SHEET_GAP

    def y(v: float) -> float:
        return H - v

    def path(c: Contour) -> str:
        v = c.vertices
        parts = [f"M {_f(v[0][0])} {_f(y(v[0][1]))}"]
        for k in range(len(v)):
            x0, y0, b = v[k]
            x1, y1, _ = v[(k + 1) % len(v)]
            if abs(b) < 1e-15:
                parts.append(f"L {_f(x1)} {_f(y(y1))}")
            else:
                theta = 4 * math.atan(b)
                chord = math.hypot(x1 - x0, y1 - y0)
                r = chord / (2 * math.sin(abs(theta) / 2))
                large = 1 if abs(theta) > math.pi else 0
                # counter-clockwise with y up (b > 0) is counter-clockwise on screen too, which in SVG's
                # y-down frame is the negative-angle direction: sweep-flag 0
                sweep = 0 if b > 0 else 1
                parts.append(f"A {_f(r)} {_f(r)} 0 {large} {sweep} {_f(x1)} {_f(y(y1))}")
        parts.append("Z")
        return " ".join(parts)

    def element(c) -> str:
        if isinstance(c, Circle):
            return f'<circle cx="{_f(c.centre[0])}" cy="{_f(y(c.centre[1]))}" r="{_f(c.radius)}"/>'
        return f'<path d="{path(c)}"/>'

    layers: dict[str, list[str]] = {k: [] for k in COLOURS}
    for k in range(layout.sheets):
        x0, y0 = layout.sheet_origin(k)
        layers["SHEET"].append(f'<rect x="{_f(x0)}" y="{_f(y(y0 + H))}" width="{_f(W)}" height="{_f(H)}"/>')
    for p in layout.parts:
        for c in p.inner:
            layers["CUT_INNER"].append(element(c))
        layers["CUT_OUTER"].append(element(p.outer))
        lx, ly = p.label_at
        layers["ENGRAVE"].append(
            f'<text x="{_f(lx)}" y="{_f(y(ly))}" font-size="{_f(p.label_height)}" text-anchor="middle" '
            f'dominant-baseline="middle" stroke="none" fill="{COLOURS["ENGRAVE"]}">{escape(p.name)}</text>')
    out = ['<?xml version="1.0" encoding="UTF-8"?>',
           f'<svg xmlns="http://www.w3.org/2000/svg" width="{_f(total_w)}mm" height="{_f(H)}mm" '
           f'viewBox="0 0 {_f(total_w)} {_f(H)}">']
    for name in ("SHEET", "CUT_INNER", "CUT_OUTER", "ENGRAVE"):
        out.append(f'<g id="{name}" fill="none" stroke="{COLOURS[name]}" stroke-width="0.1">')
        out.extend("  " + e for e in layers[name])
        out.append("</g>")
    out.append("</svg>")
    return "\n".join(out) + "\n"


def write_svg(path: str | os.PathLike, layout: Layout) -> None:
    """Write the layout as SVG (atomically)."""
    text = svg_text(layout)
    with atomic_write(path, "w") as fh:
        fh.write(text)
