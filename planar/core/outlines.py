"""Part outlines as shapely geometry, built from a part's exact primitives.

The outer profile is the convex hull of the part's ``hull`` circles (the
wind-up paper's recipe: convex hull around the joints, rounded); holes are
circles, straight slots are stadiums (a segment buffered by half the width) and
arc slots are an arc buffered by half the width.  Curves are approximated with
``quad_segs`` segments per quarter circle; fabrication exporters use the exact
primitives instead.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Protocol

import numpy as np
import shapely
from shapely.geometry import LineString, Point, Polygon

from planar.core.features import ArcSlot, Hole, Slot


class Outlined(Protocol):
    """What an outline is built from (a :class:`~planar.core.model.Part` has it)."""

    @property
    def polygon(self) -> Sequence[tuple[float, float]] | None: ...

    @property
    def hull(self) -> Sequence[tuple[float, float, float]]: ...

    @property
    def features(self) -> Sequence[Hole | Slot | ArcSlot]: ...


__all__ = ["QUAD_SEGS", "feature_shape", "part_outline"]

#: segments per quarter circle for shapely approximations
QUAD_SEGS = 16


def feature_shape(f: Hole | Slot | ArcSlot, grow: float = 0.0) -> shapely.Geometry:
    """The region a feature removes from its part, widened by ``grow`` per side."""
    if isinstance(f, Hole):
        return Point(f.centre).buffer(f.diameter / 2 + grow, quad_segs=QUAD_SEGS)
    if isinstance(f, Slot):
        if np.allclose(f.start, f.end):
            return Point(f.start).buffer(f.width / 2 + grow, quad_segs=QUAD_SEGS)
        return LineString([f.start, f.end]).buffer(f.width / 2 + grow, quad_segs=QUAD_SEGS)
    if isinstance(f, ArcSlot):
        n = max(8, int(abs(f.angle1 - f.angle0) / (np.pi / 2) * QUAD_SEGS) + 2)
        a = np.linspace(f.angle0, f.angle1, n)
        pts = np.c_[f.centre[0] + f.radius * np.cos(a), f.centre[1] + f.radius * np.sin(a)]
        return LineString(pts).buffer(f.width / 2 + grow, quad_segs=QUAD_SEGS)
    raise TypeError(f"unknown feature {f!r}")


def part_outline(part: Outlined) -> Polygon:
    """The part's outline in its own frame, with holes and slots cut out."""
    if part.polygon is not None:
        outer = Polygon(part.polygon)
    else:
        discs = [Point(x, y).buffer(r, quad_segs=QUAD_SEGS) for x, y, r in part.hull]
        outer = shapely.union_all(discs).convex_hull
    for f in part.features:
        outer = outer.difference(feature_shape(f))
    if not isinstance(outer, Polygon):  # a feature split the part: keep the largest piece
        outer = max(getattr(outer, "geoms", [outer]), key=lambda g: g.area)
    return outer
