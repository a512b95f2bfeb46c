"""Parts laid flat for cutting: exact contours in millimetres, kerf, sheets.

Every contour is exact geometry: straight segments and circular arcs, stored
the way DXF's LWPOLYLINE stores them, as vertices ``(x, y, bulge)`` where
``bulge = tan(sweep / 4)`` of the arc from that vertex to the next (0 for a
straight segment, positive counter-clockwise).  Round holes are circles.

* Outer profile: the convex hull of the part's hull circles (the paper's
  "convex hull around the joints, rounded"): arcs on the circles joined by
  their outer common tangents, computed exactly.
* Holes: pivot holes are the scene's pin diameter plus a running clearance;
  holes the mechanism sizes itself (axles, cams in round holes) keep their
  size, plus the clearance.  Slots are stadiums (straight) or arc slots of the
  pin's width plus clearance.
* Kerf: the beam removes ``kerf / 2`` on each side of its path, so outer
  contours are offset outward by ``kerf / 2`` (hull circles grow: the offset
  of a hull of circles is exact) and holes and slots inward by ``kerf / 2``;
  the cut parts come out at nominal size.
* Layout: parts are placed apart on sheets of the given size by shelf
  packing (each turned by 0 or 90 degrees, whichever is lower), several sheets
  when needed; a part larger than a sheet is an error naming it.

Coordinates: millimetres, x right, y up, sheet ``k`` offset along x by
``k * (sheet width + SHEET_GAP)``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Sequence

import numpy as np

from .errors import InputError
from .model import ArcSlot, Hole, Mechanism, Part, Slot

__all__ = ["Contour", "Circle", "PartCut", "Layout", "hull_of_circles", "part_cuts", "layout_parts",
           "SHEET_GAP", "bulge_points"]

SHEET_GAP = 20.0  # mm between sheets in one drawing
MARGIN = 5.0  # mm from the sheet's edge
SPACING = 4.0  # mm between parts
EPS = 1e-9


@dataclass
class Contour:
    """A closed contour of lines and arcs: vertices ``(x, y, bulge)`` in mm."""

    vertices: list[tuple[float, float, float]]

    def transformed(self, angle: float, dx: float, dy: float) -> "Contour":
        c, s = math.cos(angle), math.sin(angle)
        return Contour([(c * x - s * y + dx, s * x + c * y + dy, b) for x, y, b in self.vertices])


@dataclass
class Circle:
    centre: tuple[float, float]
    radius: float

    def transformed(self, angle: float, dx: float, dy: float) -> "Circle":
        c, s = math.cos(angle), math.sin(angle)
        x, y = self.centre
        return Circle((c * x - s * y + dx, s * x + c * y + dy), self.radius)


Cut = Contour | Circle


@dataclass
class PartCut:
    """One part ready to cut: outer profile, inner cuts, label; in its own frame until laid out."""

    name: str
    outer: Cut
    inner: list[Cut]
    label_at: tuple[float, float]
    label_height: float
    sheet: int = 0
    #: nominal (zero-kerf) hole centres and radii, and which feature each inner cut comes from
    nominal_holes: list[tuple[tuple[float, float], float]] = field(default_factory=list)

    def transformed(self, angle: float, dx: float, dy: float) -> "PartCut":
        c, s = math.cos(angle), math.sin(angle)
        lx, ly = self.label_at
        return PartCut(self.name, self.outer.transformed(angle, dx, dy),
                       [k.transformed(angle, dx, dy) for k in self.inner],
                       (c * lx - s * ly + dx, s * lx + c * ly + dy), self.label_height, self.sheet,
                       [((c * x - s * y + dx, s * x + c * y + dy), r) for (x, y), r in self.nominal_holes])


@dataclass
class Layout:
    parts: list[PartCut]
    sheets: int
    sheet_size: tuple[float, float]
    kerf: float
    unit_mm: float

    def sheet_origin(self, k: int) -> tuple[float, float]:
        return (k * (self.sheet_size[0] + SHEET_GAP), 0.0)


# --------------------------------------------------------------------------- geometry


def _outer_tangent(c1, r1, c2, r2) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """Outer common tangent leaving circle 1 toward circle 2 with both circles on its left.

    Returns the unit outward normal ``n`` and the touching points; None if
    one circle contains the other.
    """
    d = np.asarray(c2, float) - np.asarray(c1, float)
    L = float(np.hypot(*d))
    if L <= abs(r1 - r2) + EPS:
        return None
    u = d / L
    cphi = (r1 - r2) / L
    sphi = math.sqrt(max(0.0, 1.0 - cphi * cphi))
    right = np.array([u[1], -u[0]])
    n = cphi * u + sphi * right
    return n, np.asarray(c1, float) + r1 * n, np.asarray(c2, float) + r2 * n


def hull_of_circles(circles: Sequence[tuple[float, float, float]]) -> Cut:
    """Exact convex hull of circles ``(x, y, r)`` as a counter-clockwise contour (or one circle)."""
    cs = [(float(x), float(y), float(r)) for x, y, r in circles]
    # drop circles inside others (and duplicates)
    keep = []
    for i, (x, y, r) in enumerate(cs):
        inside = False
        for j, (x2, y2, r2) in enumerate(cs):
            if i == j:
                continue
            dist = math.hypot(x - x2, y - y2)
            if dist + r <= r2 + EPS and (dist + r < r2 - EPS or j < i or r < r2):
                inside = True
                break
        if not inside:
            keep.append((x, y, r))
    if len(keep) == 1:
        x, y, r = keep[0]
        return Circle((x, y), r)
    n = len(keep)
    scale = max(max(abs(x) + r, abs(y) + r) for x, y, r in keep)
    tol = 1e-9 * max(scale, 1.0)
    # every hull edge: an outer tangent with all circles on its left
    out_edges: dict[int, list[tuple[float, int, np.ndarray, np.ndarray, np.ndarray]]] = {i: [] for i in range(n)}
    for i in range(n):
        for j in range(n):
            if i == j:
                continue
            t = _outer_tangent(keep[i][:2], keep[i][2], keep[j][:2], keep[j][2])
            if t is None:
                continue
            nrm, p1, p2 = t
            if all((np.array(keep[k][:2]) - p1) @ nrm + keep[k][2] <= tol for k in range(n) if k not in (i, j)):
                out_edges[i].append((math.atan2(nrm[1], nrm[0]), j, nrm, p1, p2))
    # gift wrapping: start at the lowest point (outward normal straight down) and turn counter-clockwise;
    # a large circle can appear more than once on the hull, so the walk follows angles, not circles
    def next_edge(k: int, a: float):
        # the least counter-clockwise turn; tangents along one line (collinear circles) tie within
        # round-off, and then the farthest circle is the hull's next
        sweeps = [((e[0] - a) % (2 * math.pi), e) for e in out_edges[k]]
        sweeps = [((sw if sw < 2 * math.pi - 1e-9 else 0.0), e) for sw, e in sweeps]
        low = min(sw for sw, _ in sweeps)
        ties = [e for sw, e in sweeps if sw <= low + 1e-9]
        return max(ties, key=lambda e: float(np.hypot(*(e[4] - e[3]))))

    i0 = min(range(n), key=lambda k: keep[k][1] - keep[k][2])
    edge = next_edge(i0, -math.pi / 2)
    src = i0
    # walk edge to edge until an edge repeats; the hull is the cycle from its first occurrence
    keys: list[tuple[int, int, float]] = []
    walk: list[tuple[tuple[float, float, float], tuple[float, float, float] | None]] = []
    for _ in range(4 * n * n + 8):
        beta, j, _, p1, p2 = edge
        key = (src, j, beta)
        hit = next((k for k, kk in enumerate(keys) if kk[:2] == key[:2]
                    and abs(math.remainder(kk[2] - beta, 2 * math.pi)) < 1e-9), None)
        if hit is not None:
            walk = walk[hit:]
            break
        keys.append(key)
        nxt = next_edge(j, beta)
        sweep = (nxt[0] - beta) % (2 * math.pi)
        arc = (float(p2[0]), float(p2[1]), math.tan(sweep / 4)) if sweep > 1e-12 else None
        walk.append(((float(p1[0]), float(p1[1]), 0.0), arc))  # tangent segment, then the arc on circle j
        src, edge = j, nxt
    verts: list[tuple[float, float, float]] = []
    for seg, arc in walk:
        verts.append(seg)
        if arc is not None:
            verts.append(arc)
    # drop zero-length steps (a departure exactly at the start point)
    clean: list[tuple[float, float, float]] = []
    for v in verts:
        if clean and math.hypot(v[0] - clean[-1][0], v[1] - clean[-1][1]) <= tol:
            clean[-1] = (clean[-1][0], clean[-1][1], v[2] if v[2] else clean[-1][2])
            continue
        clean.append(v)
    if len(clean) > 1 and math.hypot(clean[0][0] - clean[-1][0], clean[0][1] - clean[-1][1]) <= tol:
        clean.pop()
    return Contour(clean)


def bulge_points(contour: Contour, seg_angle: float = math.radians(2.0)) -> np.ndarray:
    """The contour as a polygon (arcs sampled every ``seg_angle``), for checks and previews."""
    out = []
    v = contour.vertices
    for k in range(len(v)):
        x0, y0, b = v[k]
        x1, y1, _ = v[(k + 1) % len(v)]
        out.append((x0, y0))
        if abs(b) > 1e-15:
            theta = 4 * math.atan(b)
            chord = math.hypot(x1 - x0, y1 - y0)
            r = chord / (2 * math.sin(abs(theta) / 2))
            mx, my = (x0 + x1) / 2, (y0 + y1) / 2
            # centre: from the chord midpoint along the chord's left normal by r cos(theta/2) (signed)
            ux, uy = (x1 - x0) / chord, (y1 - y0) / chord
            h = r * math.cos(theta / 2) * (1 if theta > 0 else -1)
            cx, cy = mx - uy * h, my + ux * h
            a0 = math.atan2(y0 - cy, x0 - cx)
            steps = max(2, int(abs(theta) / seg_angle))
            for s in range(1, steps):
                a = a0 + theta * s / steps
                out.append((cx + r * math.cos(a), cy + r * math.sin(a)))
    return np.asarray(out)


def _stadium(p0, p1, h: float) -> Cut:
    p0, p1 = np.asarray(p0, float), np.asarray(p1, float)
    d = p1 - p0
    L = float(np.hypot(*d))
    if L <= EPS:
        return Circle((float(p0[0]), float(p0[1])), h)
    e = d / L
    nrm = np.array([-e[1], e[0]])
    a, b = p0 - h * nrm, p1 - h * nrm
    c, dd = p1 + h * nrm, p0 + h * nrm
    return Contour([(a[0], a[1], 0.0), (b[0], b[1], 1.0), (c[0], c[1], 0.0), (dd[0], dd[1], 1.0)])


def _arc_slot(centre, R: float, a0: float, a1: float, h: float) -> Cut:
    cx, cy = centre
    sweep = a1 - a0
    bo = math.tan(sweep / 4)

    def pt(r, a):
        return (cx + r * math.cos(a), cy + r * math.sin(a))

    o0, o1 = pt(R + h, a0), pt(R + h, a1)
    i1, i0 = pt(R - h, a1), pt(R - h, a0)
    return Contour([(o0[0], o0[1], bo), (o1[0], o1[1], 1.0), (i1[0], i1[1], -bo), (i0[0], i0[1], 1.0)])


def _label_point(part: Part, u: float) -> tuple[tuple[float, float], float]:
    from shapely.geometry import Point
    from shapely.ops import polylabel

    poly = part.outline
    p = polylabel(poly, tolerance=1e-3 * max(poly.length, 1e-9))
    if not poly.contains(p):
        p = poly.representative_point()
    room = poly.exterior.distance(Point(p))
    for hole in poly.interiors:
        room = min(room, hole.distance(Point(p)))
    # the name must fit across the room too: a character is about 0.6 of the height wide
    n = max(1, len(part.name))
    height = float(min(5.0, 0.8 * room * u, 2 * 0.8 * room * u / (0.6 * n)))
    return (float(p.x * u), float(p.y * u)), max(height, 0.5)


def part_cuts(part: Part, unit_mm: float, kerf: float, pin_mm: float, clearance: float) -> PartCut:
    """A part's cuts in millimetres in its own frame (kerf applied)."""
    u = unit_mm
    k2 = kerf / 2.0
    if part.polygon is not None:
        from shapely.geometry import Polygon

        grown = Polygon([(x * u, y * u) for x, y in part.polygon]).buffer(k2, join_style="mitre")
        outer: Cut = Contour([(float(x), float(y), 0.0) for x, y in list(grown.exterior.coords)[:-1]])
    else:
        outer = hull_of_circles([(x * u, y * u, r * u + k2) for x, y, r in part.hull])
    inner: list[Cut] = []
    nominal = []
    for f in part.features:
        if isinstance(f, Hole):
            d = (pin_mm if f.role == "pin" else f.diameter * u) + clearance
            r = d / 2 - k2
            if r <= 0:
                raise InputError(f"{part.name}.hole", d, f"a hole larger than the kerf {kerf:g} mm")
            c = (f.centre[0] * u, f.centre[1] * u)
            inner.append(Circle(c, r))
            nominal.append((c, d / 2))
        elif isinstance(f, Slot):
            w = (pin_mm if f.role == "pin" else f.width * u) + clearance
            h = w / 2 - k2
            if h <= 0:
                raise InputError(f"{part.name}.slot", w, f"a slot wider than the kerf {kerf:g} mm")
            inner.append(_stadium((f.start[0] * u, f.start[1] * u), (f.end[0] * u, f.end[1] * u), h))
        elif isinstance(f, ArcSlot):
            w = (pin_mm if f.role == "pin" else f.width * u) + clearance
            h = w / 2 - k2
            inner.append(_arc_slot((f.centre[0] * u, f.centre[1] * u), f.radius * u, f.angle0, f.angle1, h))
    at, height = _label_point(part, u)
    return PartCut(part.name, outer, inner, at, height, nominal_holes=nominal)


def _bbox(pc: PartCut) -> tuple[float, float, float, float]:
    pts = bulge_points(pc.outer) if isinstance(pc.outer, Contour) else None
    if pts is None:
        (x, y), r = pc.outer.centre, pc.outer.radius
        return x - r, y - r, x + r, y + r
    return float(pts[:, 0].min()), float(pts[:, 1].min()), float(pts[:, 0].max()), float(pts[:, 1].max())


def layout_parts(mech: Mechanism, unit_mm: float = 10.0, kerf: float = 0.0, pin_mm: float = 3.0,
                 clearance: float = 0.1, sheet: tuple[float, float] = (300.0, 200.0)) -> Layout:
    """Every part of ``mech``, cut-ready, placed apart on as many sheets as needed."""
    W, H = sheet
    if not (W > 2 * MARGIN and H > 2 * MARGIN):
        raise InputError("sheet", sheet, f"a sheet larger than {2 * MARGIN:g} x {2 * MARGIN:g} mm")
    if kerf < 0:
        raise InputError("kerf", kerf, "a kerf >= 0 mm")
    cuts = []
    for p in mech.parts:
        pc = part_cuts(p, unit_mm, kerf, pin_mm, clearance)
        x0, y0, x1, y1 = _bbox(pc)
        w, h = x1 - x0, y1 - y0
        # lie flat: turn a quarter when that makes the part lower (shelves are filled left to right)
        if h > w and h > H - 2 * MARGIN or (w > W - 2 * MARGIN and h <= W - 2 * MARGIN):
            pc = pc.transformed(math.pi / 2, 0.0, 0.0)
            x0, y0, x1, y1 = _bbox(pc)
            w, h = x1 - x0, y1 - y0
        if w > W - 2 * MARGIN or h > H - 2 * MARGIN:
            raise InputError(f"part {p.name!r}", f"{w:.1f} x {h:.1f} mm",
                             f"a part that fits the {W:g} x {H:g} mm sheet inside {MARGIN:g} mm margins "
                             "(use a larger --sheet or a smaller unit_mm)")
        cuts.append((pc, (x0, y0, w, h)))
    # shelf packing, tallest first (stable: ties keep the mechanism's order)
    order = sorted(range(len(cuts)), key=lambda i: -cuts[i][1][3])
    placed: list[PartCut] = []
    sheet_k, x, y, shelf_h = 0, MARGIN, MARGIN, 0.0
    for i in order:
        pc, (x0, y0, w, h) = cuts[i]
        if x + w > W - MARGIN:  # next shelf
            x, y, shelf_h = MARGIN, y + shelf_h + SPACING, 0.0
        if y + h > H - MARGIN:  # next sheet
            sheet_k, x, y, shelf_h = sheet_k + 1, MARGIN, MARGIN, 0.0
        ox = sheet_k * (W + SHEET_GAP)
        moved = pc.transformed(0.0, ox + x - x0, y - y0)
        moved.sheet = sheet_k
        placed.append(moved)
        x += w + SPACING
        shelf_h = max(shelf_h, h)
    placed.sort(key=lambda p: [q.name for q in mech.parts].index(p.name))
    return Layout(placed, sheet_k + 1, (W, H), kerf, unit_mm)
