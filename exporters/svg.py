"""SVG in millimetres with the same geometry as the DXF, and the assembly drawing.

Cut files (:func:`svg_text`, one per sheet): the document is the sheet
(``width``/``height`` in mm, no outline drawn), one ``<g>`` per layer —
``CUT_INNER`` and ``CUT_OUTER`` stroked in the cut colour (red by default),
``ENGRAVE`` in the engrave colour (blue), the colours laser software such as
LightBurn, xTool Creative Space or Glowforge maps to operations — strokes only,
hairline width (``svg_stroke_mm``, 0.025 mm = 0.001 in by default).  Arcs are
SVG elliptical-arc commands, holes ``<circle>``; engraving is open paths (a
stroke font, not text).  The drawing's y axis points up like the DXF's; SVG's
points down, so y is flipped once here.  Reproducible: no ids beyond the layer
names, no timestamps, fixed number formatting.

Assembly drawing (:func:`assembly_svg_text`): every part in place at the first
valid pose, filled by layer (bottom first), pins lettered, and a legend of the
layers from the bottom up and of the pins with their lengths and spacers.
"""

from __future__ import annotations

import math
import os
from typing import Any
from xml.sax.saxutils import escape

from planar.fabrication.sheet import Circle, Contour, Layout
from planar.fileio import atomic_write, check_name

__all__ = ["assembly_steps_svg", "assembly_svg_text", "svg_text", "write_svg"]


def _f(v: float) -> str:
    s = f"{v:.6f}".rstrip("0").rstrip(".")
    return "0" if s in ("-0", "") else s


def _path(c: Contour, y) -> str:
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


def _element(c, y) -> str:
    if isinstance(c, Circle):
        return f'<circle cx="{_f(c.centre[0])}" cy="{_f(y(c.centre[1]))}" r="{_f(c.radius)}"/>'
    return f'<path d="{_path(c, y)}"/>'


def svg_text(layout: Layout, sheet: int = 0, settings: Any = None) -> str:
    """One sheet of the layout as an SVG document."""
    W, H = layout.sheet_size
    cut = getattr(settings, "cut_colour", "#ff0000")
    eng = getattr(settings, "engrave_colour", "#0000ff")
    stroke = getattr(settings, "svg_stroke_mm", 0.025)

    def y(v: float) -> float:
        return H - v

    layers: dict[str, list[str]] = {"CUT_INNER": [], "CUT_OUTER": [], "ENGRAVE": []}
    for p in layout.on_sheet(sheet):
        for c in p.inner:
            layers["CUT_INNER"].append(_element(c, y))
        layers["CUT_OUTER"].append(_element(p.outer, y))
        for st in p.engrave:
            d = " ".join(("M" if i == 0 else "L") + f" {_f(float(a))} {_f(y(float(b)))}" for i, (a, b) in enumerate(st))
            layers["ENGRAVE"].append(f'<path d="{d}"/>')
    out = [
        '<?xml version="1.0" encoding="UTF-8"?>',
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{_f(W)}mm" height="{_f(H)}mm" viewBox="0 0 {_f(W)} {_f(H)}">',
    ]
    colour = (
        settings.layer_colours() if hasattr(settings, "layer_colours") else {"CUT_INNER": cut, "CUT_OUTER": cut, "ENGRAVE": eng}
    )
    for name in ("CUT_INNER", "CUT_OUTER", "ENGRAVE"):
        out.append(
            f'<g id="{name}" fill="none" stroke="{colour[name]}" stroke-width="{_f(stroke)}" '
            f'stroke-linecap="round" stroke-linejoin="round">'
        )
        out.extend("  " + e for e in layers[name])
        out.append("</g>")
    out.append("</svg>")
    return "\n".join(out) + "\n"


def write_svg(path: str | os.PathLike, layout: Layout, sheet: int = 0, settings: Any = None) -> None:
    """Write one sheet of the layout as SVG (atomically)."""
    text = svg_text(layout, sheet, settings)
    with atomic_write(path, "w") as fh:
        fh.write(text)


#: fill colours of layers 0, 1, ... (bottom up)
LAYER_FILLS = ("#c8a064", "#6aa0d8", "#e07a5f", "#81b29a", "#f2cc8f", "#9c89b8", "#5fa8d3", "#d4a5a5")


def _placed_shapes(fab: Any) -> list[tuple[int, str, Any]]:
    """Every flat part's material in place at the drawn pose, bottom layer first: ``(layer, name, polygon)``."""
    from shapely import affinity

    asm = fab.assembly
    shapes = []
    for name, layer in asm.layers.items():
        if layer is None or name not in fab.own:
            continue
        x, y, a = asm.pose[name]
        c, s = math.cos(a), math.sin(a)
        shapes.append((layer, name, affinity.affine_transform(fab.own[name], [c, -s, s, c, x, y]).simplify(0.01)))
    shapes.sort(key=lambda t: (t[0], list(asm.layers).index(t[1])))
    return shapes


def assembly_svg_text(fab: Any) -> str:
    """The assembly drawing of a :class:`planar.app.export.Fabrication` (see the module docstring); the build
    check's collisions (:mod:`planar.fabrication.check`) are red rings where they first happen, numbered as in
    the legend."""
    legend = _legend(fab)
    for k, v in enumerate(getattr(fab, "violations", []), start=1):
        legend.append(f"collision {k}: {v.text()}")
    marks = [v.at for v in getattr(fab, "violations", [])]
    return _page(fab, _placed_shapes(fab), fab.assembly.pins, legend, marks)


def assembly_steps_svg(fab: Any) -> list[str]:
    """The assembly steps: one SVG page per layer from the bottom, the parts laid so far grey, this step's parts
    coloured, and what to do: which pins go in from below, which spacers go on, which ends close the pins."""
    from planar.fabrication.hardware import pin_closing, pin_items

    asm, s = fab.assembly, fab.settings
    shapes = _placed_shapes(fab)
    flat = [pp for pp in asm.pins if pp.layers is not None]
    top = max((layer for layer, _, _ in shapes), default=0)
    pages = []
    for k in range(top + 1):
        here = [n for layer, n, _ in shapes if layer == k]
        lines = [f"{fab.name}: step {k + 1} of {top + 1}, layer {k + 1} ({s.thickness_mm:g} mm)"]
        if k == 0:
            shaft = [pp for pp in flat if pp.shaft]
            if shaft:
                lines.append(
                    f"fit the motor under {', '.join(here) or 'the bottom layer'}: its shaft up through {shaft[0].letter}"
                )
        for pp in flat:
            lo, hi = pp.layers or (0, 0)
            if lo == k and not pp.shaft:
                what = ", ".join(f"{i.qty} x {i.item} {i.size}" for i in pin_items(s, pp))
                low = pin_closing(s, pp)[0]
                lines.append(f"pin {pp.letter} up through this layer, its lower end ({low}) fitted first: {what}")
            if lo < k <= hi and not any(asm.layers.get(p) == k for p in pp.parts):
                lines.append(f"slide a spacer ring onto pin {pp.letter}")
        lines.append("lay " + (", ".join(here) if here else "nothing (an empty layer: the spacers fill it)"))
        for pp in flat:
            if (pp.layers or (0, 0))[1] == k:
                lines.append(_close_line(fab, pp))
        drawn = [(layer if layer == k else -1, n, g) for layer, n, g in shapes if layer <= k]
        pins = [pp for pp in flat if (pp.layers or (0, 0))[0] <= k]
        pages.append(_page(fab, drawn, pins, lines, [], extent=shapes))
    return pages


def _close_line(fab: Any, pp: Any) -> str:
    """The step line that closes a pin's upper end with its own hardware (the motor shaft: how it is held)."""
    from planar.fabrication.hardware import driven_part, pin_closing, shaft_retention

    s = fab.settings
    if pp.shaft:
        return f"fix the motor shaft: {shaft_retention(driven_part(pp, fab.grounds))}"
    return f"close pin {pp.letter} on top ({pin_closing(s, pp)[1]})"


def _page(
    fab: Any,
    shapes: list[tuple[int, str, Any]],
    pins: list[Any],
    legend: list[str],
    marks: list[tuple[float, float]],
    extent: list[tuple[int, str, Any]] | None = None,
) -> str:
    """One drawing: parts filled by layer (-1: grey, laid before), pins lettered, red rings at ``marks``, a legend."""
    asm = fab.assembly
    pts = []
    for *_, g in extent if extent is not None else shapes:
        b = g.bounds
        pts += [(b[0], b[1]), (b[2], b[3])]
    for pp in asm.pins:
        pts.append(_pin_xy(asm, pp))
    pts += list(marks)
    if not pts:
        pts = [(0.0, 0.0), (10.0, 10.0)]
    x0 = min(p[0] for p in pts) - 10
    y0 = min(p[1] for p in pts) - 10
    x1 = max(p[0] for p in pts) + 10
    y1 = max(p[1] for p in pts) + 10
    fs = max(2.5, 0.025 * max(x1 - x0, y1 - y0))
    lw = fs * 0.6 * max(len(t) for t in legend) + 10
    W = (x1 - x0) + lw
    H = max(y1 - y0, fs * 1.5 * (len(legend) + 1))

    def X(v: float) -> float:
        return v - x0

    def Y(v: float) -> float:
        return y1 - v

    out = [
        '<?xml version="1.0" encoding="UTF-8"?>',
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{_f(W)}mm" height="{_f(H)}mm" viewBox="0 0 {_f(W)} {_f(H)}" '
        f'font-family="sans-serif">',
        f'<rect x="0" y="0" width="{_f(W)}" height="{_f(H)}" fill="#ffffff"/>',
    ]
    for layer, name, g in shapes:
        check_name("part name", name)
        geoms = getattr(g, "geoms", [g])
        d = []
        for poly in geoms:
            for ring in [poly.exterior, *poly.interiors]:
                xy = list(ring.coords)
                d.append("M " + " L ".join(f"{X(a):.3f} {Y(b):.3f}" for a, b in xy) + " Z")
        fill = "#d0d0d0" if layer < 0 else LAYER_FILLS[layer % len(LAYER_FILLS)]
        title = "laid before" if layer < 0 else f"layer {layer + 1}"
        out.append(
            f'<path d="{" ".join(d)}" fill="{fill}" fill-opacity="0.75" '
            f'fill-rule="evenodd" stroke="#333333" stroke-width="{_f(fs * 0.08)}"><title>{escape(name)} '
            f"({title})</title></path>"
        )
    for pp in pins:
        px, py = _pin_xy(asm, pp)
        out.append(
            f'<circle cx="{_f(X(px))}" cy="{_f(Y(py))}" r="{_f(fs * 0.7)}" fill="#ffffff" stroke="#000000" '
            f'stroke-width="{_f(fs * 0.06)}"/>'
        )
        out.append(
            f'<text x="{_f(X(px))}" y="{_f(Y(py) + fs * 0.35)}" font-size="{_f(fs)}" text-anchor="middle">'
            f"{escape(pp.letter)}</text>"
        )
    for k, (mx, my) in enumerate(marks, start=1):
        out.append(
            f'<circle cx="{_f(X(mx))}" cy="{_f(Y(my))}" r="{_f(fs * 1.2)}" fill="none" stroke="#ff0000" '
            f'stroke-width="{_f(fs * 0.15)}"><title>collision {k}</title></circle>'
        )
    lx = x1 - x0 + 5
    for i, t in enumerate(legend):
        out.append(f'<text x="{_f(lx)}" y="{_f(fs * 1.5 * (i + 1))}" font-size="{_f(fs)}">{escape(t)}</text>')
    out.append("</svg>")
    return "\n".join(out) + "\n"


def _pin_xy(asm, pp) -> tuple[float, float]:
    a = pp.spec.parts[0]
    x, y, ang = asm.pose[a]
    u = asm.unit_mm
    lx, ly = pp.spec.at[0][0] * u, pp.spec.at[0][1] * u
    c, s = math.cos(ang), math.sin(ang)
    return (x + c * lx - s * ly, y + s * lx + c * ly)


def _legend(fab: Any) -> list[str]:
    asm = fab.assembly
    t = fab.settings.thickness_mm
    lines = [f"{fab.name}: layers from the bottom, {t:g} mm each"]
    by_plane: dict[str, list[str]] = {}
    for name, layer in asm.layers.items():
        if layer is not None:
            by_plane.setdefault(asm.plane.get(name, "xy"), []).append(name)
    for pl in sorted(by_plane, key=lambda v: (v != "xy", v)):
        names = by_plane[pl]
        if pl != "xy":
            lines.append(f"standing in the {pl} plane:")
        for k in range(max(asm.layers[n] or 0 for n in names) + 1):
            here = ", ".join(n for n in names if asm.layers[n] == k)
            lines.append(f"  layer {k + 1}: " + (here or "spacers only (room for a pin's end or a part passing)"))
    for pp in asm.pins:
        lo, hi = pp.layers or (0, 0)
        what = "motor shaft" if pp.shaft else f"pin d{pp.diameter_mm:g} x {pp.length_mm:g} mm ({fab.settings.hardware})"
        sp = f", {pp.spacers} spacer(s)" if pp.spacers else ""
        joins = " + ".join(pp.parts)
        lines.append(f"{pp.letter}: {what}, {joins}, layers {lo + 1}-{hi + 1}{sp}")
    for jn in getattr(fab, "joins", []):  # tab-and-slot joints (planar.fabrication.tabs)
        lines.append(
            f"{jn.letter}: the {len(jn.spans)} tabs of {jn.piece} ({jn.plane}) into the slots {jn.letter} of "
            f"{jn.base} (layer {(asm.layers.get(jn.base) or 0) + 1}), standing {'below' if jn.side < 0 else 'above'}"
            " it; glue"
        )
    return lines
