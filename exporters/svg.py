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
    return _page(fab, _placed_shapes(fab), fab.assembly.pins, legend, marks, fixings=_fixings(fab, list(fab.grounds)))


def assembly_steps_svg(fab: Any) -> list[str]:
    """The assembly steps: one SVG page per layer from the bottom, the parts laid so far grey, this step's parts
    coloured, and what to do as numbered physical actions in their order: the motor screwed under the ground plate
    and the standoffs under it (step 1), then per part of the layer each pin that starts there (its lower end
    fitted, pushed up through the part's hole from below), the part laid over the pins below it, spacer rings slid
    on, the pins that end there closed; the last step stands it on a base board."""
    asm = fab.assembly
    shapes = _placed_shapes(fab)
    flat = [pp for pp in asm.pins if pp.layers is not None]
    top = max((layer for layer, _, _ in shapes), default=0)
    pages = []
    for k in range(top + 1):
        here = [n for layer, n, _ in shapes if layer == k]
        acts = _layer_actions(fab, flat, here, k)
        if k == top:
            acts += _base_actions(fab)
        lines = [f"{fab.name}: step {k + 1} of {top + 1}, layer {k + 1} ({fab.settings.thickness_mm:g} mm)"]
        lines += [f"{i}. {a}" for i, a in enumerate(acts, start=1)]
        drawn = [(layer if layer == k else -1, n, g) for layer, n, g in shapes if layer <= k]
        pins = [pp for pp in flat if (pp.layers or (0, 0))[0] <= k]
        marks = _fixings(fab, here) if k == 0 or any(n in fab.mounts for n in here) else []
        pages.append(_page(fab, drawn, pins, lines, [], extent=shapes, fixings=marks))
    return pages


def _pin_name(fab: Any, pp: Any) -> str:
    """A pin as the steps call it: its body and letter with its size (``rod B (3 mm x 12.5 mm)``)."""
    from planar.fabrication.hardware import hardware_of, pin_items

    body = pin_items(fab.settings, pp)[0]
    return f"{hardware_of(fab.settings).body} {pp.letter} ({body.size})"


def _layer_actions(fab: Any, flat: list[Any], here: list[str], k: int) -> list[str]:
    """One layer's actions in order: (step 1: motor and standoffs), then per part the pins starting in it, the part
    laid over the pins from below, spacer rings, the pins closed on top."""
    from planar.fabrication.hardware import hardware_of

    asm = fab.assembly
    hw = hardware_of(fab.settings)
    acts: list[str] = []
    for name in here:
        fixed = _motor_actions(fab, flat, name) + _standoff_actions(fab, name)  # the plate stands on its standoffs
        acts += fixed
        started = [pp for pp in flat if not pp.shaft and (pp.layers or (0, 0))[0] == k and name in pp.parts]
        for pp in started:
            acts.append(
                f"{hw.fit_lower.format(pin=_pin_name(fab, pp))}; push it up through {name}'s hole {pp.letter} from "
                f"{name}'s underside"
            )
        if not fixed:
            acts.append(_lay_action(fab, flat, name, k, started))
    if not here:
        acts.append(f"nothing to lay on layer {k + 1} (an empty layer: room for the pins' ends; spacers fill it)")
    for pp in flat:
        lo, hi = pp.layers or (0, 0)
        if lo < k <= hi and not any(asm.layers.get(p) == k for p in pp.parts):
            acts.append(f"slide a spacer ring (spacer {pp.letter}) down pin {pp.letter}")
    for pp in flat:
        if (pp.layers or (0, 0))[1] == k and not pp.shaft:
            acts.append(f"close pin {pp.letter} on top: " + hw.fit_upper.format(pin=f"{hw.body} {pp.letter}"))
    return acts


def _lay_action(fab: Any, flat: list[Any], name: str, k: int, started: list[Any]) -> str:
    """Lay part ``name`` on layer ``k`` (the rods started in it standing in it) over the pins from below (each up
    through its hole), onto the motor shaft's flat if it is the driven part."""
    from planar.fabrication.hardware import driven_part, shaft_retention

    below = [pp for pp in flat if (pp.layers or (0, 0))[0] < k and name in pp.parts]
    through = [pp.letter for pp in below if not pp.shaft]
    shaft = [pp for pp in below if pp.shaft]
    what = f"lay {name} on layer {k + 1}" if k else f"lay {name} flat"
    if started:
        what += f" (pin(s) {', '.join(pp.letter for pp in started)} standing in it)"
    if through:
        what += f" over pin(s) {', '.join(through)}, each up through its hole of that letter"
    if shaft:
        what += f", its D hole down onto the motor shaft {shaft[0].letter}: {shaft_retention(driven_part(shaft[0], fab.grounds))}"
    glued = _glued_on(fab, name, [pp for pp in flat if name in pp.parts])
    if glued:
        what += (
            f"; glue it on {', '.join(glued)} (a drop of cyanoacrylate or epoxy in the hole) at the angle the "
            "assembly drawing shows, before the glue sets: it turns with the rod"
        )
    return what


def _glued_on(fab: Any, name: str, pins: list[Any]) -> list[str]:
    """The pins (``rod B``) that part ``name`` is glued on: the mechanism as cut names its glued joints (a walker's
    crank webs on the short shafts through the frame plates)."""
    mech = fab.mechanism
    glued = set(getattr(mech, "glued", ()))
    if not glued:
        return []
    parts = {jt.name: (jt.a, jt.b) for jt in mech.joints if jt.name in glued}
    return [f"pin {pp.letter}" for pp in pins if not pp.shaft and any(name in parts[j] for j in glued & set(pp.joints))]


def _motor_actions(fab: Any, flat: list[Any], name: str) -> list[str]:
    """The motor screwed under the ground plate ``name`` (if the shaft stands in it), its BOM names and sizes."""
    from planar.fabrication.hardware import motor_items

    s = fab.settings
    shaft = [pp for pp in flat if pp.shaft and name in pp.parts and name in fab.grounds]
    if not shaft:
        return []
    motor, screw = motor_items(s)
    a = shaft[0].letter
    return [
        f"hold the motor ({motor.item}) under {name}, its shaft up through {name}'s hole {a} (the shaft is pin {a})",
        f"countersink the {s.motor_screw_mm:g} mm holes either side of {a} from {name}'s top face (a 90 degree "
        "countersink bit, to 3.2 mm across) so the screws' heads sit flush: the part above turns over them",
        f"screw it on: {screw.qty} motor screws ({screw.item} {screw.size}) down through those holes into the "
        f"motor's face (heads flush in {name})",
    ]


def _standoff_actions(fab: Any, name: str) -> list[str]:
    """The standoffs screwed under the ground plate ``name`` (if it has mounting holes)."""
    from planar.fabrication.hardware import mounting_items

    if name not in fab.mounts:
        return []
    *stack, screw, washer = mounting_items(fab.settings, fab.below_mm)
    acts = []
    if len(stack) > 1:
        acts.append(
            f"screw the {stack[1].qty} standoffs ({stack[1].item} {stack[1].size}) onto the tops of the "
            f"{stack[0].qty} ({stack[0].item} {stack[0].size}), one column under each mounting hole"
        )
    return [
        *acts,
        f"screw {stack[0].qty} standoff columns ({', '.join(f'{i.item} {i.size}' for i in stack)}) under {name}: "
        f"a mounting screw ({screw.item} {screw.size}) with a washer ({washer.item} {washer.size}) down through each "
        "mounting hole (marked S) into a column's top",
        f"stand {name} on its standoffs (what hangs under it, {round(fab.below_mm, 1):g} mm, stays clear of the table)",
    ]


def _base_actions(fab: Any) -> list[str]:
    """The last action: the standoffs fixed to a base board (optional)."""
    from planar.fabrication.hardware import mounting_items

    if not fab.mounts:
        return []
    *_, screw, _ = mounting_items(fab.settings, fab.below_mm)
    n = 2 * len(fab.mounts)
    return [
        f"fix it to a base board ({fab.settings.thickness_mm:g} mm; optional): {n} mounting screws ({screw.item} "
        f"{screw.size}) with washers up through the board into the standoffs' bottoms"
    ]


def _fixings(fab: Any, here: list[str]) -> list[tuple[float, float, float, str]]:
    """Where step 1's fixings go (world mm at the drawn pose): standoffs ``S`` at the mounting holes and the motor
    screws ``m`` either side of the shaft: ``(x, y, radius, label)``."""
    asm, s = fab.assembly, fab.settings
    out = []

    def world(part: str, p: tuple[float, float]) -> tuple[float, float]:
        x, y, a = asm.pose[part]
        return (x + math.cos(a) * p[0] - math.sin(a) * p[1], y + math.sin(a) * p[0] + math.cos(a) * p[1])

    for name in here:
        for c in fab.mounts.get(name, []):
            out.append((*world(name, c), 3.0, "S"))
        for pp in asm.pins:
            if pp.shaft and name in pp.spec.parts and name in fab.grounds:
                cx, cy = pp.spec.at[pp.spec.parts.index(name)]
                for sx in (-1, 1):
                    at = (cx * s.unit_mm + sx * s.motor_screw_spacing_mm / 2, cy * s.unit_mm)
                    out.append((*world(name, at), s.motor_screw_mm / 2, "m"))
    return out


def _page(
    fab: Any,
    shapes: list[tuple[int, str, Any]],
    pins: list[Any],
    legend: list[str],
    marks: list[tuple[float, float]],
    extent: list[tuple[int, str, Any]] | None = None,
    fixings: list[tuple[float, float, float, str]] | None = None,
) -> str:
    """One drawing: parts filled by layer (-1: grey, laid before), pins lettered, red rings at ``marks``, a legend;
    ``fixings`` ``(x, y, r, label)``: standoffs and motor screws drawn as dark rings with a small label."""
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
    for fx, fy, fr, label in fixings or []:
        out.append(
            f'<circle cx="{_f(X(fx))}" cy="{_f(Y(fy))}" r="{_f(max(fr, fs * 0.3))}" fill="none" stroke="#202020" '
            f'stroke-width="{_f(fs * 0.12)}"><title>{escape(label)}</title></circle>'
        )
        out.append(
            f'<text x="{_f(X(fx) + max(fr, fs * 0.3) + fs * 0.2)}" y="{_f(Y(fy) - fs * 0.2)}" font-size="{_f(fs * 0.7)}">'
            f"{escape(label)}</text>"
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


def _fixing_legend(fab: Any) -> list[str]:
    """The legend's lines for the motor with its screws and the ground plates' standoffs and mounting screws."""
    from planar.fabrication.hardware import motor_items, mounting_items

    s = fab.settings
    out = []
    for pp in fab.assembly.pins:
        if pp.shaft:
            motor, screw = motor_items(s)
            out.append(
                f"motor: {motor.item} under layer 1, its shaft is {pp.letter}; {screw.qty} motor screws "
                f"({screw.item} {screw.size}) down through the plate into its face"
            )
    if fab.mounts:
        *stack, screw, _ = mounting_items(s, fab.below_mm)
        out.append(
            f"S: standoffs ({', '.join(f'{i.qty} {i.item} {i.size}' for i in stack)}) under each ground plate, "
            f"mounting screws ({screw.item} {screw.size}) down through its mounting holes into them "
            f"({round(fab.below_mm, 1):g} mm hangs below layer 1)"
        )
    return out


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
    lines += _fixing_legend(fab)
    for jn in getattr(fab, "joins", []):  # tab-and-slot joints (planar.fabrication.tabs)
        lines.append(
            f"{jn.letter}: the {len(jn.spans)} tabs of {jn.piece} ({jn.plane}) into the slots {jn.letter} of "
            f"{jn.base} (layer {(asm.layers.get(jn.base) or 0) + 1}), standing {'below' if jn.side < 0 else 'above'}"
            " it; glue"
        )
    return lines
