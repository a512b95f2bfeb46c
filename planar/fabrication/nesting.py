"""Nesting: parts turned to their minimum-area rectangle and packed on sheets by rectpack.

Each part is turned so the long side of its minimum-area bounding rectangle
(shapely) lies along x — or kept as it is when its upright bounding box is
smaller — and the rectangles, grown by the spacing, are packed by rectpack
(which may turn each by another quarter).  Several rectpack algorithms are
tried; the fewest sheets win, then the most compact last sheet.  Sizes are
rounded up to 0.01 mm integers for rectpack.  Sheets are filled inside
``margin`` of their edge; a part larger than a sheet is an error naming it.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from planar.errors import InputError
from planar.fabrication.sheet import Layout, PartCut, cut_polygon

__all__ = ["nest"]

_Q = 100  # rectpack works in integers: 0.01 mm


def _bbox(pc: PartCut) -> tuple[float, float, float, float]:
    x0, y0, x1, y1 = cut_polygon(pc.outer, math.radians(0.5)).bounds
    return x0, y0, x1, y1


def _upright(pc: PartCut) -> PartCut:
    """The part turned so its minimum-area rectangle is axis-aligned (long side along x), if that is smaller."""
    poly = cut_polygon(pc.outer, math.radians(0.5))
    rect = np.asarray(poly.minimum_rotated_rectangle.exterior.coords)[:4]
    e1, e2 = rect[1] - rect[0], rect[2] - rect[1]
    long = e1 if np.hypot(*e1) >= np.hypot(*e2) else e2
    angle = -math.atan2(long[1], long[0])
    # the same rectangle either way round: turn by less than a quarter turn, so labels stay readable
    angle = (angle + math.pi / 2) % math.pi - math.pi / 2
    x0, y0, x1, y1 = poly.bounds
    turned = pc.transformed(angle, 0.0, 0.0)
    a0, b0, a1, b1 = _bbox(turned)
    if (a1 - a0) * (b1 - b0) < (x1 - x0) * (y1 - y0) * (1 - 1e-9):
        return turned
    return pc


def nest(
    cuts: Sequence[PartCut], sheet: tuple[float, float], spacing: float, margin: float, kerf: float, unit_mm: float
) -> Layout:
    """Place every part on as few sheets as rectpack finds; coordinates per sheet, mm."""
    import rectpack

    from planar.core.fields import check_number, check_point

    W, H = check_point("sheet", sheet, "a sheet (width, height) in mm: two finite numbers")
    if not isinstance(cuts, (list, tuple)) or not cuts or not all(isinstance(c, PartCut) for c in cuts):
        raise InputError("cuts", cuts, "a list of one or more PartCut (planar.fabrication.part_cuts)")
    for name, value in (("spacing", spacing), ("margin", margin), ("kerf", kerf), ("unit_mm", unit_mm)):
        if check_number(name, value) < 0:
            raise InputError(name, value, "a size >= 0 in mm")
    if not (math.isfinite(W) and math.isfinite(H)) or 2 * margin >= W or 2 * margin >= H:
        raise InputError("sheet", f"{W:g} x {H:g}", f"a finite sheet larger than the {margin:g} mm margins")
    binw, binh = int(math.floor((W - 2 * margin + spacing) * _Q)), int(math.floor((H - 2 * margin + spacing) * _Q))
    parts = [_upright(pc) for pc in cuts]
    rects = []
    for pc in parts:
        x0, y0, x1, y1 = _bbox(pc)
        w, h = int(math.ceil((x1 - x0 + spacing) * _Q)), int(math.ceil((y1 - y0 + spacing) * _Q))
        if not ((w <= binw and h <= binh) or (h <= binw and w <= binh)):
            raise InputError(
                f"part {pc.name!r}",
                f"{x1 - x0:.1f} x {y1 - y0:.1f} mm",
                f"a part that fits the {W:g} x {H:g} mm sheet inside {margin:g} mm margins "
                "(use a larger --sheet or a smaller unit_mm)",
            )
        rects.append((w, h))
    best = None
    for algo in (rectpack.MaxRectsBssf, rectpack.MaxRectsBaf, rectpack.MaxRectsBl, rectpack.GuillotineBssfMaxas):
        for sort in (rectpack.SORT_AREA, rectpack.SORT_LSIDE, rectpack.SORT_PERI):
            packer = rectpack.newPacker(
                mode=rectpack.PackingMode.Offline, bin_algo=rectpack.PackingBin.BFF, pack_algo=algo, sort_algo=sort, rotation=True
            )
            for i, (w, h) in enumerate(rects):
                packer.add_rect(w, h, rid=i)
            packer.add_bin(binw, binh, count=len(rects))
            packer.pack()
            placed = packer.rect_list()
            if len(placed) != len(rects):
                continue
            n = 1 + max(b for b, *_ in placed)
            last = [(x + w, y + h) for b, x, y, w, h, _ in placed if b == n - 1]
            score = (n, max(a for a, _ in last) * max(b for _, b in last))
            if best is None or score < best[0]:
                best = (score, placed)
    if best is None:  # pragma: no cover - every part fits a sheet on its own
        raise InputError("sheet", f"{W:g} x {H:g}", "room for every part")
    out: list[PartCut] = []
    for b, x, y, w, h, i in sorted(best[1], key=lambda r: r[5]):
        pc = parts[i]
        if (w, h) != rects[i]:
            pc = pc.transformed(math.pi / 2, 0.0, 0.0)
        x0, y0, _, _ = _bbox(pc)
        moved = pc.transformed(0.0, margin + x / _Q - x0, margin + y / _Q - y0)
        moved.sheet = b
        out.append(moved)
    n = best[0][0]
    util = []
    for k in range(n):
        area = sum(cut_polygon(p.outer).area for p in out if p.sheet == k)
        util.append(area / (W * H))
    return Layout(out, n, (W, H), kerf, unit_mm, util)
