"""Independent readers for the export tests: ezdxf for DXF, svgelements for SVG, shapely to compare.

Nothing here uses planar's own geometry code: contours are flattened by
ezdxf's path module and by svgelements' segment evaluation.
"""

from __future__ import annotations

import numpy as np
from shapely.geometry import Polygon

CUT_LAYERS = ("CUT_INNER", "CUT_OUTER")


def dxf_cut_polygons(path, layers=CUT_LAYERS) -> list[Polygon]:
    """Every closed cut contour of a DXF as a shapely polygon (ezdxf flattening, 1e-4 mm)."""
    import ezdxf

    doc = ezdxf.readfile(path)
    out = []
    for e in doc.modelspace():
        if e.dxf.layer not in layers or e.dxftype() not in ("CIRCLE", "LWPOLYLINE"):
            continue
        out.append(_valid(Polygon(_dxf_points(e))))
    return out


def _dxf_points(e) -> list[tuple[float, float]]:
    """Points on a CIRCLE or closed LWPOLYLINE, exact on its arcs (ezdxf's ARC/CIRCLE flattening, 1e-5 mm).

    (ezdxf's path module would first turn arcs into Bezier curves, a few micrometres off a circle.)
    """
    if e.dxftype() == "CIRCLE":
        return [(v.x, v.y) for v in e.flattening(1e-5)]
    x0, y0, *_ = e.get_points("xy")[0]
    pts: list[tuple[float, float]] = []
    here: tuple[float, float] = (x0, y0)  # where the previous segment ended
    for ve in e.virtual_entities():
        if ve.dxftype() == "LINE":
            seg = [(ve.dxf.start.x, ve.dxf.start.y), (ve.dxf.end.x, ve.dxf.end.y)]
        else:  # ARC, always counter-clockwise in DXF: reverse when the polyline runs clockwise
            seg = [(v.x, v.y) for v in ve.flattening(1e-5)]
        if np.hypot(*np.subtract(seg[-1], here)) < np.hypot(*np.subtract(seg[0], here)):
            seg = seg[::-1]
        pts.extend(seg[:-1])
        here = seg[-1]
    return pts


def svg_closed_polygons(path) -> list[Polygon]:
    """Every closed shape of an SVG (paths ending in Z, circles) in mm with y up, read by svgelements."""
    from svgelements import SVG, Arc, Close, Move, Path, Rect, Shape

    svg = SVG.parse(str(path))
    scale = svg.width / svg.viewbox.width  # svgelements works in px (96 per inch)
    H = svg.viewbox.height
    out = []
    for el in svg.elements():
        if not isinstance(el, Shape) or isinstance(el, Rect):  # a rect is the sheet, not a cut
            continue
        p = Path(el)
        segs = list(p.segments())
        if not any(isinstance(s, Close) for s in segs):
            continue
        pts = []
        for s in segs:
            if isinstance(s, Move):
                continue
            n = 400 if isinstance(s, Arc) else 2
            pts.extend(s.npoint(np.linspace(0.0, 1.0, n))[:-1].tolist())
        xy = np.asarray(pts, float) / scale
        xy[:, 1] = H - xy[:, 1]
        out.append(_valid(Polygon(xy)))
    return out


def _valid(p: Polygon) -> Polygon:
    """Round-off at a tangent join (1e-14 mm) can make GEOS see a self-touch; buffer(0) mends only that."""
    if p.is_valid:
        return p
    q = p.buffer(0)
    assert abs(q.area - p.area) <= 1e-9 * max(p.area, 1.0), "a contour that really crosses itself"
    return q


def match_contours(a: list[Polygon], b: list[Polygon]) -> list[float]:
    """Pair each polygon of ``a`` with the one of ``b`` it overlaps most; relative symmetric differences."""
    assert len(a) == len(b), (len(a), len(b))
    cb = np.array([[q.centroid.x, q.centroid.y] for q in b]) if b else np.zeros((0, 2))
    used: set[int] = set()
    rel = []
    for p in a:
        d = np.hypot(*(cb - [p.centroid.x, p.centroid.y]).T)
        cand = [int(i) for i in np.argsort(d)[:6] if int(i) not in used]
        best = min(cand, key=lambda i: p.symmetric_difference(b[i]).area)
        used.add(best)
        rel.append(p.symmetric_difference(b[best]).area / max(b[best].area, 1e-12))
    return rel
