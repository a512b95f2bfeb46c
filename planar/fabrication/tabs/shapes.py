"""The planar geometry the tab planner works with: poses applied and undone, a line's intervals inside a
region, tabs placed along them, a moving piece's footprint in a layer, a track that must stand still."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from planar.fabrication.joints import FabricationError


def _world(poly: Any, pose: tuple[float, float, float]) -> Any:
    from shapely import affinity

    x, y, a = pose
    c, s = math.cos(a), math.sin(a)
    return affinity.affine_transform(poly, [c, -s, s, c, x, y])


def _local(poly: Any, pose: tuple[float, float, float]) -> Any:
    from shapely import affinity

    x, y, a = pose
    c, s = math.cos(a), math.sin(a)
    # inverse of p -> R p + t: R^T (p - t)
    return affinity.affine_transform(poly, [c, s, -s, c, -(c * x + s * y), -(-s * x + c * y)])


def _intervals(geom: Any) -> list[tuple[float, float]]:
    """The x-extents of the pieces of a line's intersection (sorted)."""
    if geom.is_empty:
        return []
    parts = getattr(geom, "geoms", [geom])
    out = []
    for g in parts:
        if g.geom_type == "LineString" and g.length > 0:
            xs = np.asarray(g.coords)[:, 0]
            out.append((float(xs.min()), float(xs.max())))
    return sorted(out)


def _and(a: list[tuple[float, float]], b: list[tuple[float, float]]) -> list[tuple[float, float]]:
    out = []
    for a0, a1 in a:
        for b0, b1 in b:
            lo, hi = max(a0, b0), min(a1, b1)
            if hi > lo:
                out.append((lo, hi))
    return sorted(out)


def _along(region: Any, level: float, half: float, lo: float, hi: float) -> list[tuple[float, float]]:
    """Where a strip ``level +- half`` (in the second coordinate) lies inside ``region``, as x intervals."""
    from shapely.geometry import LineString

    got: list[tuple[float, float]] | None = None
    for dy in (-half, -half / 2, 0.0, half / 2, half):
        iv = _intervals(region.intersection(LineString([(lo, level + dy), (hi, level + dy)])))
        got = iv if got is None else _and(got, iv)
    return got or []


def _place(intervals: list[tuple[float, float]], w: float, g: float) -> list[float]:
    """Tab centres: as many ``w`` wide, ``g`` apart as fit in each interval, centred in it."""
    out: list[float] = []
    for lo, hi in intervals:
        n = int(math.floor((hi - lo + g) / (w + g) + 1e-9))
        if n <= 0:
            continue
        span = n * w + (n - 1) * g
        x0 = (lo + hi - span) / 2 + w / 2
        out += [x0 + k * (w + g) for k in range(n)]
    return out


def _layer_footprint(mat: Any, plane: str, at: float, track_n: np.ndarray, track_r: np.ndarray, band: Any, t: float) -> Any:
    """Where a perpendicular piece (its cut outline ``mat``, its ``plane`` at ``at``, mm) passes through the layer
    ``band`` (world, mm) over its pose ``track_n``: strips of thickness ``t``, in the frame of the xy piece whose
    track is ``track_r``."""
    import shapely
    from shapely.geometry import Polygon, box

    mat = mat.simplify(0.05)
    strips = []
    for k in range(len(track_n)):
        got = _world(mat, tuple(track_n[k])).intersection(band)
        if got.area <= 1e-6:
            continue
        a, _, b, _ = got.bounds
        strip = box(a, at - t / 2, b, at + t / 2) if plane == "xz" else box(at - t / 2, a, at + t / 2, b)
        strips.append(_local(strip, tuple(track_r[k])))
    return shapely.union_all(strips) if strips else Polygon()


def _static_pose(track: np.ndarray, what: str, keep: tuple[int, ...]) -> None:
    """Refuse a track whose coordinates ``keep`` (indices into x, y, angle) change over the cycle."""
    spread = np.ptp(track[:, list(keep)], axis=0)
    if float(spread.max()) > 1e-6:
        raise FabricationError(
            f"{what}: it moves across the line where it meets the xy stack (by up to "
            f"{float(spread.max()):.3g}) over the cycle; it cannot be tab-joined"
        )
