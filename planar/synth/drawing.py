"""How far a four-bar's coupler path lies from the drawing its targets were sampled from.

A path synthesis from an SVG meets a few points sampled along the drawing (``--points``); between them the
coupler path may leave the drawing, and a closed drawing may be traced only in part (an input that rocks goes out
and back along an arc) or with a loop the drawing does not have.  The check at the targets sees none of this.
:func:`drawing_gaps` measures it both ways with shapely's distances: every point of the drawing (sampled densely
by arc length) to the coupler path (the crank's whole turn, or a rocking input's swing, solved by planar's
solver), and, for a closed drawing, every point of the path to the drawing.  :func:`drawing_cautions` says in
words what exceeds the tolerance.

Targets from a table have no drawing; :func:`between_targets` measures the coupler path between each target and the
next (the way the design passes them) against the smooth curve through the targets (a natural cubic spline, as
the arc lookup describes them), and :func:`between_caution` says when it strays beyond :data:`DETOUR`: a dip, loop
or overshoot the targets do not ask for.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

__all__ = [
    "BETWEEN_CAUTION",
    "DETOUR",
    "DRAWING_SAMPLES",
    "PATH_SAMPLES",
    "between_caution",
    "between_targets",
    "drawing_cautions",
    "drawing_gaps",
    "drawing_stray",
]

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
            f"the coupler path leaves the closed drawing by up to {off:.3g} of the targets' size ({off / tolerance:.3g} "
            "times the tolerance; planar render shows where)"
        )
    elif off > tolerance and not rocks:
        out.append(
            f"the crank turns fully, so after the drawn arc the coupler point comes back another way, up to {off:.3g} of "
            "the targets' size from the drawing (planar render shows it; --rocking asks for an input that swings along "
            "the arc only)"
        )
    elif off > tolerance:  # an input that swings over the targets' span: the path should follow the open drawing
        out.append(
            f"between the targets the coupler path leaves the drawing by up to {off:.3g} of their size ({off / tolerance:.3g} "
            "times the tolerance; planar render shows where, and more --points hold the search to more of the drawing)"
        )
    return out


def drawing_stray(gaps: dict[str, float], rocks: bool) -> float | None:
    """How far (over the targets' size) a design's coupler path and the drawing it was asked to trace stray from each
    other where the path should follow the drawing all along, from :func:`drawing_gaps`'s figures (``rocks``: the
    design's input swings rather than turns); None where it need not: a closed drawing traced by an input that
    rocks (along part of it and back) is measured by neither figure, an open drawing traced by a crank that turns
    fully (which comes back another way) only by the drawing's distance from the path.  Beyond :data:`DETOUR` the
    design does not trace the drawing: ``synth path`` fails it (``checks.ok_follows_drawing``, exit 3), as a check
    at the targets cannot see (a trial's nodding-beak arc came back within the tolerance at every target, its
    path 0.496 of the size off the drawing between two of them)."""
    closed = bool(gaps.get("drawing_closed", 0.0))
    if closed and rocks:
        return None
    far = float(gaps.get("drawing_max_distance", 0.0))
    return far if not closed and not rocks else max(far, float(gaps.get("path_max_distance", 0.0)))


#: a stretch of coupler path between two targets straying farther than ``DETOUR`` (over the targets' size) from the
#: smooth curve through the targets and longer than ``DETOUR_LENGTH`` times that curve's stretch is worth a caution:
#: a dip, loop or overshoot.  A smooth curve through sparse targets already differs from the true curve across wide
#: gaps (on 45 random four-bars' own curves at 8 targets, development seed 55, the four-bar recovered exactly:
#: distances up to 1.22 of the size, length ratios up to 10.7, and 2 of the 45 beyond both limits: the true curve
#: itself runs that far from the smooth one there, which the line then says rightly); a trial's hand-drawn hook
#: came back with 0.80 and 4.4 times (an input turning fully) and 0.29 and 2.7 times (one that rocks)
DETOUR, DETOUR_LENGTH = 0.25, 2.0
#: how :func:`between_caution`'s line begins (a drawing's own check replaces it: :func:`drawing_cautions`)
BETWEEN_CAUTION = "between targets "
#: input angles solved (and points of the smooth curve taken) between each target and the next
BETWEEN_SAMPLES = 64


def _steps(design: Any) -> Array | None:
    """The signed input-angle steps (rad) from each target to the next the way ``design`` passes them: one way round
    within one turn for a crank that turns fully, along the swing for an input that rocks; None when the targets
    are not passed in their order (the path between them then is not one stretch of the motion)."""
    from planar.synth.arcs import on_swing
    from planar.synth.search import turn_steps

    th = np.asarray(design.theta, float)
    swing = design.checks.get("input_swing_rad")
    if swing is None:
        return turn_steps(th)
    d = np.diff(on_swing(th, (float(swing[0]), float(swing[1]))))
    return d if (np.all(d > 0) or np.all(d < 0)) else None


def _lengths(p: Array) -> Array:
    """Lengths of polylines ``p`` ``(K, S, 2)``."""
    return np.asarray(np.sum(np.linalg.norm(np.diff(p, axis=1), axis=2), axis=1))


def between_targets(design: Any) -> dict[str, Any]:
    """How ``design``'s coupler path runs, between each target and the next (the way the design passes them), against
    the smooth curve through the targets (a natural cubic spline by chord length, as
    :func:`planar.synth.arcs.smooth_open`), by planar's solver at :data:`BETWEEN_SAMPLES` input angles a stretch.

    Returns ``between_max_distance`` (the farthest point of the path from the smooth curve, over the targets' size
    ``design.checks["size"]``), ``between_length_ratio`` (the largest ratio of a stretch of path's length to the
    smooth curve's between the same targets) and ``between_detour``: the farthest stretch beyond both :data:`DETOUR`
    and :data:`DETOUR_LENGTH` (``targets``, the 1-based numbers of the two around it, its ``distance`` and
    ``length_ratio``), or None; an empty dict when the design does not pass the targets in their order or does not
    assemble between them."""
    import shapely
    from scipy.interpolate import CubicSpline

    t = np.asarray(design.targets, float)
    seg = np.linalg.norm(np.diff(t, axis=0), axis=1)
    steps = _steps(design) if len(t) >= 3 and np.all(seg > 0) else None
    if steps is None:
        return {}
    f = np.linspace(0.0, 1.0, BETWEEN_SAMPLES)
    th = np.asarray(design.theta, float)[:-1, None] + steps[:, None] * f[None, :]
    motion = design.fourbar().solve(th.ravel())
    if not np.all(motion.valid):
        return {}
    path = np.asarray(motion.points["coupler_point"], float).reshape(*th.shape, 2)
    s = np.concatenate([[0.0], np.cumsum(seg)])
    smooth = CubicSpline(s, t, bc_type="natural")(s[:-1, None] + seg[:, None] * f[None, :])  # (N - 1, S, 2)
    curve = shapely.LineString(smooth.reshape(-1, 2))
    far = shapely.distance(shapely.points(path.reshape(-1, 2)), curve).reshape(th.shape).max(axis=1)
    far = far / float(design.checks["size"])
    ratio = _lengths(path) / _lengths(smooth)
    detour = np.where((far > DETOUR) & (ratio > DETOUR_LENGTH), far, -1.0)
    i = int(np.argmax(detour))
    worst = {"targets": [i + 1, i + 2], "distance": float(far[i]), "length_ratio": float(ratio[i])}
    return {
        "between_max_distance": float(far.max()),
        "between_length_ratio": float(ratio.max()),
        "between_detour": worst if detour[i] > 0 else None,
    }


def between_caution(figures: dict[str, Any]) -> list[str]:
    """A ``caution:`` line when :func:`between_targets` found a detour (empty otherwise)."""
    if not figures.get("between_detour"):
        return []
    a, b = figures["between_detour"]["targets"]
    far, ratio = figures["between_detour"]["distance"], figures["between_detour"]["length_ratio"]
    return [
        f"{BETWEEN_CAUTION}{a} and {b} the coupler path strays up to {far:.3g} of the targets' size from a smooth curve "
        f"through them, over {ratio:.3g} times its length (a dip, loop or overshoot; the check at the targets does not "
        "see between them): add targets there if the path matters, and see it with planar render"
    ]
