"""Part of a closed curve: an atlas of the open windows of full-turn four-bars' coupler curves.

Targets on part of a crank-rocker's or drag-link's coupler curve (an arc of the
crank's turn, an open target set) are described badly as a closed curve: the
periodic spline through them (:func:`planar.synth.atlas.smooth_closed`) closes
the gap with a curve the four-bar does not trace, and the closed-curve atlas's
neighbours of that description are far from the true four-bar.  This atlas
describes such targets as what they are, an open arc.

Each entry is one four-bar whose crank turns fully (sampled as the closed-curve
atlas's, :func:`planar.synth.atlas._sample_linkages`: crank or ground shortest,
Grashof, longest / shortest at most 10, the coupler point within about two
coupler lengths, either circuit) and one *window* of its crank's turn: a span
of :data:`SPANS_DEG` starting at a random crank angle.  The coupler point is
solved at :data:`~planar.synth.arcs.ARC_SAMPLES` crank angles over the window
and described as the rocking arcs are (:func:`planar.synth.arcs.describe_open`:
resampled by arc length, normalised for position, scale and the chord's
direction), so the rocking-arc storage, lookup and placement serve it
(:class:`planar.synth.arcs.Arcs`; ``window`` holds the crank angles the arc runs
between).  :func:`window_candidates` gives rows for the closed-curve search's
refinement (:func:`planar.synth.search.search_atlas`), as
:func:`planar.synth.atlas.candidates` does.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from planar.errors import InputError
from planar.synth.arcs import ARC_POINTS, Arcs, built, cached, described_windows

__all__ = [
    "DEFAULT_FOURBARS",
    "QUICK_FOURBARS",
    "SPANS_DEG",
    "build_windows",
    "load_windows",
    "window_candidates",
    "windows_path",
]

Array = NDArray[np.float64]

#: format version of the files on disk (a change rebuilds them)
VERSION = 1
#: the spans (degrees of the crank's turn) of the windows stored per four-bar, each from its own random start
SPANS_DEG = (75.0, 130.0, 190.0, 260.0)
#: the kind stored in the files (:class:`planar.synth.arcs.Arcs`), so neither atlas is read as the other
KIND = "windows"
#: four-bars of the default window atlas (each gives ``len(SPANS_DEG)`` entries) and of the quick budget's
DEFAULT_FOURBARS = 250_000
QUICK_FOURBARS = 5_000


def _chunk(seed: int, index: int, n: int) -> tuple[Array, Array, Array, Array]:
    """One chunk of the build: params, windows, frames and descriptors of its good entries."""
    from planar.synth.atlas import _sample_linkages

    rng = np.random.default_rng([seed, 11, index])
    p = _sample_linkages(rng, n)
    start = rng.uniform(0.0, 2 * np.pi, (n, len(SPANS_DEG)))
    spans = np.radians(SPANS_DEG)
    return described_windows(p, [(start[:, j], start[:, j] + span) for j, span in enumerate(spans)])


def build_windows(fourbars: int = DEFAULT_FOURBARS, seed: int = 0, progress: bool = False) -> Arcs:
    """The windows of ``fourbars`` full-turn four-bars, one per span of :data:`SPANS_DEG` (deterministic for both
    arguments; a window of too short a chord is left out, so the entries are a little fewer than
    ``fourbars * len(SPANS_DEG)``).  Builds in about 13 s of CPU for the default size."""
    if fourbars < 100:
        raise InputError("window atlas size", fourbars, "at least 100 four-bars")
    return built(_chunk, fourbars, seed, "curve windows", progress, KIND, len(SPANS_DEG))


def windows_path(fourbars: int = DEFAULT_FOURBARS, seed: int = 0) -> Path:
    """The cache file of the windows of ``fourbars`` four-bars and ``seed`` (beside the closed-curve atlas)."""
    from planar.synth.atlas import cache_dir

    return cache_dir() / f"windows-v{VERSION}-{ARC_POINTS}-{fourbars}-{seed}.npz"


def load_windows(fourbars: int = DEFAULT_FOURBARS, seed: int = 0, progress: bool = False) -> Arcs:
    """The cached window atlas of ``fourbars`` four-bars, built and cached first if missing (one line on standard
    error says so when ``progress``; kept in memory only when the cache folder cannot be written)."""
    path = windows_path(fourbars, seed)
    return cached(path, "curve-window atlas", fourbars, KIND, len(SPANS_DEG), progress, build_windows, seed)


def load_budget_windows(budget: str, progress: bool = True) -> Arcs:
    """:func:`load_windows` of a search ``budget``'s size (a budget its caller has checked:
    :func:`planar.synth.path.check_path_args`): :data:`QUICK_FOURBARS` for ``"quick"``, else
    :data:`DEFAULT_FOURBARS`."""
    return load_windows(QUICK_FOURBARS if budget == "quick" else DEFAULT_FOURBARS, progress=progress)


def window_candidates(windows: Arcs, targets: Array, k: int = 64) -> Array:
    """Full-turn four-bars a window of whose curve is near the targets ``(N, 2)`` (in order along part of the
    curve), placed onto them: ``4 k`` rows of the kernel's 9 parameters and the circuit (as
    :func:`planar.synth.atlas.candidates`; the targets' description both ways along and mirrored), nearest first
    within each query."""
    from planar.synth.arcs import arc_candidates

    return arc_candidates(windows, targets, k)
