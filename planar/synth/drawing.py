"""How far a four-bar's coupler path lies from the drawing its targets were sampled from.

A path synthesis from an SVG meets a few points sampled along the drawing (``--points``); between them the
coupler path may leave the drawing, and a closed drawing may be traced only in part (an input that rocks goes out
and back along an arc) or with a loop the drawing does not have.  The check at the targets sees none of this.
:func:`drawing_gaps` measures it both ways with shapely's distances: every point of the drawing (sampled densely
by arc length) to the coupler path (the crank's whole turn, or a rocking input's swing, solved by planar's
solver), and, for a closed drawing, every point of the path to the drawing.  :func:`drawing_cautions` says in
words what exceeds the tolerance.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

__all__ = ["DRAWING_SAMPLES", "PATH_SAMPLES", "drawing_cautions", "drawing_gaps"]

Array = NDArray[np.float64]

#: points sampled along the drawing (evenly by arc length), and input angles solved over the turn or the swing
DRAWING_SAMPLES, PATH_SAMPLES = 1000, 4000


def drawing_gaps(design: Any, svg: str | Path) -> dict[str, float]:
    """The largest distances between the drawing of ``svg`` (its first shape, as
    :func:`planar.synth.targets.read_svg_points` samples it) and ``design``'s coupler path, over the targets'
    size (``design.checks["size"]``).

    Returns ``drawing_max_distance`` (the farthest point of the drawing from the path), ``path_max_distance`` (the
    farthest point of the path from the drawing: a loop or detour a closed drawing lacks, or the way back of a
    crank whose drawing is an open arc) and ``drawing_closed`` (1.0 for a closed drawing, else 0.0); the distances
    are ``inf`` when the path does not assemble.  The path is the crank's whole turn, or the swing
    ``checks["input_swing_rad"]`` of an input that rocks, at :data:`PATH_SAMPLES` angles joined by straight
    segments (on the trial's egg, a crank's and a rocking result, 4,000 angles gave figures within 9e-6 of the size
    of 40,000's)."""
    import shapely

    from planar.synth.targets import read_svg_shape

    drawn, closed = read_svg_shape(svg, DRAWING_SAMPLES)
    swing = design.checks.get("input_swing_rad")
    lo, hi = (float(swing[0]), float(swing[1])) if swing is not None else (0.0, 2 * np.pi)
    th = np.linspace(lo, hi, PATH_SAMPLES, endpoint=swing is not None)
    motion = design.fourbar().solve(th)
    size = float(design.checks["size"])
    out = {"drawing_max_distance": float("inf"), "path_max_distance": float("inf"), "drawing_closed": float(closed)}
    if not motion.valid.all():
        return out
    path = np.asarray(motion.points["coupler_point"], float)
    line = shapely.LinearRing(path) if swing is None else shapely.LineString(path)
    out["drawing_max_distance"] = float(np.max(shapely.distance(shapely.points(drawn), line))) / size
    drawing = shapely.LinearRing(drawn) if closed else shapely.LineString(drawn)
    out["path_max_distance"] = float(np.max(shapely.distance(shapely.points(path), drawing))) / size
    return out


def drawing_cautions(gaps: dict[str, float], tolerance: float, rocks: bool) -> list[str]:
    """``caution:`` lines for the figures of :func:`drawing_gaps` (``rocks``: the design's input swings rather than
    turns) beyond ``tolerance`` (a fraction of the targets' size): the check at the targets does not see between
    them, nor where the path goes that the drawing does not."""
    out = []
    closed = bool(gaps.get("drawing_closed", 0.0))
    if closed and rocks:
        out.append(
            "the drawing is closed and the input rocks: the coupler point runs along part of it and back the same way, "
            "so the rest of the drawing is not traced (plain synth path searches a closed drawing for an input that "
            "turns fully)"
        )
    far = gaps.get("drawing_max_distance", 0.0)
    if far > tolerance:
        out.append(
            f"between the targets the drawing lies up to {far:.3g} of their size from the coupler path ({far / tolerance:.3g} "
            "times the tolerance; the check at the targets does not see between them): more --points hold the search "
            "to more of the drawing, and planar plot --what curve draws the path through the targets"
        )
    off = gaps.get("path_max_distance", 0.0)
    if off > tolerance and closed:
        out.append(
            f"the coupler path leaves the closed drawing by up to {off:.3g} of the targets' size: a loop or detour the "
            "drawing does not have"
        )
    elif off > tolerance and not rocks:
        out.append(
            f"the crank turns fully, so after the drawn arc the coupler point comes back another way, up to {off:.3g} of "
            "the targets' size from the drawing (planar render shows it; --rocking asks for an input that swings along "
            "the arc only)"
        )
    return out
