"""Parts laid flat for cutting: exact contours in millimetres, kerf, sheets.

Every contour is exact geometry: straight segments and circular arcs, stored
the way DXF's LWPOLYLINE stores them, as vertices ``(x, y, bulge)`` where
``bulge = tan(sweep / 4)`` of the arc from that vertex to the next (0 for a
straight segment, positive counter-clockwise).  Round holes are circles.

* Outer profile: the convex hull of the part's hull circles (the paper's
  "convex hull around the joints, rounded"): arcs on the circles joined by
  their outer common tangents, computed exactly.
* Inner cuts: holes, straight slots (stadiums), arc slots and D-shaped
  shaft holes; which size each gets, and the checks, are in
  :mod:`planar.fabrication.parts`.
* Kerf: the beam removes ``kerf / 2`` on each side of its path, so outer
  contours are offset outward by ``kerf / 2`` (hull circles grow: the offset
  of a hull of circles is exact) and holes and slots inward by ``kerf / 2``;
  the cut parts come out at nominal size.
* Nesting: :mod:`planar.fabrication.nesting`; assembly: :mod:`planar.fabrication.layers`.

Coordinates: millimetres, x right, y up.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field, replace

import numpy as np

__all__ = [
    "Circle",
    "Contour",
    "Layout",
    "PartCut",
    "arc_slot",
    "bulge_points",
    "cut_polygon",
    "d_hole",
    "hull_of_circles",
    "rectangle",
    "stadium",
]

EPS = 1e-9


@dataclass
class Contour:
    """A closed contour of lines and arcs: vertices ``(x, y, bulge)`` in mm."""

    vertices: list[tuple[float, float, float]]

    def transformed(self, angle: float, dx: float, dy: float) -> Contour:
        c, s = math.cos(angle), math.sin(angle)
        return Contour([(c * x - s * y + dx, s * x + c * y + dy, b) for x, y, b in self.vertices])


@dataclass
class Circle:
    centre: tuple[float, float]
    radius: float

    def transformed(self, angle: float, dx: float, dy: float) -> Circle:
        c, s = math.cos(angle), math.sin(angle)
        x, y = self.centre
        return Circle((c * x - s * y + dx, s * x + c * y + dy), self.radius)


Cut = Contour | Circle


@dataclass
class PartCut:
    """One part ready to cut: outer profile, inner cuts, engraving; in its own frame until laid out.

    ``engrave`` holds open polylines ``(n, 2)`` (mm): the label and hole
    letters in a single-line stroke font.  ``sheet`` is the sheet index after
    nesting; coordinates are then relative to that sheet's lower-left corner.
    """

    name: str
    outer: Cut
    inner: list[Cut]
    engrave: list[np.ndarray] = field(default_factory=list)
    label: str = ""
    label_height: float = 0.0
    sheet: int = 0
    #: nominal (zero-kerf) hole centres and radii
    nominal_holes: list[tuple[tuple[float, float], float]] = field(default_factory=list)
    #: what the checks changed or found (widened, label shortened, ...), one line each
    notes: list[str] = field(default_factory=list)
    #: whether the outline was widened so every cut keeps the least wall (one of ``notes`` says from what)
    widened: bool = False
    #: assembly layer (0 = bottom) or None for a part standing in another plane
    layer: int | None = None
    #: where the part lies from its own frame: ``(angle, dx, dy)``, a point p goes to R(angle) p + (dx, dy)
    placed: tuple[float, float, float] = (0.0, 0.0, 0.0)
    #: a ground plate's mounting hole centres (mm) in the part's own frame (they stay there when it is laid out)
    mounting_at: list[tuple[float, float]] = field(default_factory=list)

    def transformed(self, angle: float, dx: float, dy: float) -> PartCut:
        c, s = math.cos(angle), math.sin(angle)
        rot = np.array([[c, -s], [s, c]])
        a0, x0, y0 = self.placed
        return replace(
            self,
            outer=self.outer.transformed(angle, dx, dy),
            placed=(a0 + angle, c * x0 - s * y0 + dx, s * x0 + c * y0 + dy),
            inner=[k.transformed(angle, dx, dy) for k in self.inner],
            engrave=[np.asarray(e) @ rot.T + (dx, dy) for e in self.engrave],
            nominal_holes=[((c * x - s * y + dx, s * x + c * y + dy), r) for (x, y), r in self.nominal_holes],
            notes=list(self.notes),
        )


@dataclass
class Layout:
    """Parts nested on ``sheets`` sheets of ``sheet_size`` mm; each part's coordinates are on its own sheet."""

    parts: list[PartCut]
    sheets: int
    sheet_size: tuple[float, float]
    kerf: float
    unit_mm: float
    #: fraction of each sheet's area covered by parts (outer contours)
    utilisation: list[float] = field(default_factory=list)

    def sheet_origin(self, k: int) -> tuple[float, float]:
        """Every sheet is written in its own file with its corner at the origin."""
        return (0.0, 0.0)

    def on_sheet(self, k: int) -> list[PartCut]:
        return [p for p in self.parts if p.sheet == k]


def cut_polygon(cut: Cut, seg_angle: float = math.radians(1.0)):
    """A cut as a shapely polygon (arcs sampled every ``seg_angle``)."""
    from shapely.geometry import Point, Polygon

    if isinstance(cut, Circle):
        return Point(cut.centre).buffer(cut.radius, quad_segs=max(8, int(round(math.pi / 2 / seg_angle))))
    return Polygon(bulge_points(cut, seg_angle))


# --------------------------------------------------------------------------- geometry


def _outer_tangent(c1, r1, c2, r2) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """Outer common tangent leaving circle 1 toward circle 2 with both circles on its left.

    Returns the unit outward normal ``n`` and the touching points; None if
    one circle contains the other.
    """
    d = np.asarray(c2, float) - np.asarray(c1, float)
    L = float(np.hypot(*d))
    if abs(r1 - r2) + EPS >= L:
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
        hit = next(
            (k for k, kk in enumerate(keys) if kk[:2] == key[:2] and abs(math.remainder(kk[2] - beta, 2 * math.pi)) < 1e-9), None
        )
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


def stadium(p0, p1, h: float) -> Cut:
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


def rectangle(centre, half_length: float, half_width: float, angle: float) -> Contour:
    """A rectangle (a tab's through-slot) about ``centre``, its long axis along ``angle`` (rad), counter-clockwise."""
    c, s = math.cos(angle), math.sin(angle)
    cx, cy = centre
    pts = [(-half_length, -half_width), (half_length, -half_width), (half_length, half_width), (-half_length, half_width)]
    return Contour([(cx + c * x - s * y, cy + s * x + c * y, 0.0) for x, y in pts])


def arc_slot(centre, R: float, a0: float, a1: float, h: float) -> Cut:
    cx, cy = centre
    sweep = a1 - a0
    bo = math.tan(sweep / 4)

    def pt(r, a):
        return (cx + r * math.cos(a), cy + r * math.sin(a))

    o0, o1 = pt(R + h, a0), pt(R + h, a1)
    i1, i0 = pt(R - h, a1), pt(R - h, a0)
    return Contour([(o0[0], o0[1], bo), (o1[0], o1[1], 1.0), (i1[0], i1[1], -bo), (i0[0], i0[1], 1.0)])


def d_hole(centre, r: float, flat: float, angle: float) -> Contour:
    """A D-shaped hole: the disc of radius ``r`` cut by the line ``flat`` from the centre along ``angle``.

    Counter-clockwise: the long arc from one end of the flat to the other, then the flat.
    """
    if not 0 < flat < r:
        raise ValueError("flat must lie inside the circle")
    cx, cy = centre
    alpha = math.acos(flat / r)
    p1 = (cx + r * math.cos(angle + alpha), cy + r * math.sin(angle + alpha))
    p2 = (cx + r * math.cos(angle - alpha), cy + r * math.sin(angle - alpha))
    sweep = 2 * math.pi - 2 * alpha
    return Contour([(p1[0], p1[1], math.tan(sweep / 4)), (p2[0], p2[1], 0.0)])
