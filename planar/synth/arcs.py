"""Rocking inputs: an atlas of the open coupler arcs of four-bars whose input link cannot turn fully.

A double-rocker (Grashof, the coupler shortest), a rocker-crank (Grashof, the
rocker shortest) or a triple-rocker (not Grashof) has an input that swings
between two limits (where the coupler and the rocker line up); driven within
them on one circuit, its coupler point traces an *arc*, back and forth.  The
closed-curve atlas (:mod:`planar.synth.atlas`) holds only linkages whose crank
turns fully, so it cannot describe these; this atlas does.

Each entry is one four-bar (unit ground along +x from the input pivot at the
origin; input, coupler and rocker lengths log-uniform with longest / shortest
at most :data:`MAX_RATIO`; the coupler point within about two coupler
lengths; either circuit) and one *window* of its input's range (the range
shrunk by 1 % at each end, then the fractions :data:`WINDOWS` of it: targets
usually cover part of the swing).  The coupler point is solved at
:data:`ARC_SAMPLES` input angles over the window, resampled to
:data:`ARC_POINTS` points evenly spaced by arc length from one end to the
other, and described as those points normalised for position (centroid at
0), scale (RMS distance from it 1) and rotation (the chord, first point to
last, along +x): ``2 ARC_POINTS`` numbers.  A query describes the targets the
same way (a natural cubic spline through them in their order, by chord
length), also reversed and mirrored, finds the nearest entries with
:class:`scipy.spatial.cKDTree`, places each on the targets by the similarity
the two descriptions differ by, and the best are refined in the joints'
positions with the input angle at each target free (:func:`arc_start`).

The interface to the path search is :func:`arc_candidates` (targets in, rows of
the kernel's 9 parameters and the circuit out, as
:func:`planar.synth.atlas.candidates`) and :func:`search_arcs` (lookup and
refinement in one call, for targets already normalised).  :func:`rocking_range`
says whether a refined four-bar passes the targets on one swing of its input
and between which angles.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from planar.errors import InputError
from planar.synth.algebraic import MIN_TARGETS, search_algebraic
from planar.synth.atlas import DescriptorIndex, unreadable
from planar.synth.designs import TOGGLE_FLOOR_DEG
from planar.synth.kernel import coupler_points, row_points
from planar.synth.positions import polish_positions

__all__ = [
    "ARC_POINTS",
    "Arcs",
    "arc_candidates",
    "build_arcs",
    "describe_open",
    "load_arcs",
    "rocking_range",
    "search_arcs",
]

Array = NDArray[np.float64]

#: format version of the files on disk (a change rebuilds them)
VERSION = 1
#: points of an arc after arc-length resampling (the descriptor has twice as many numbers)
ARC_POINTS = 16
#: input angles each window is solved at
ARC_SAMPLES = 96
#: windows of the input's range (fractions of it) stored per four-bar
WINDOWS = ((0.0, 1.0), (0.0, 0.6), (0.4, 1.0), (0.2, 0.8))
#: longest / shortest link at most this
MAX_RATIO = 10.0
#: four-bars of the default arc atlas (each gives len(WINDOWS) entries) and of the quick one
DEFAULT_FOURBARS = 250_000
QUICK_FOURBARS = 5_000
#: four-bars per chunk of the build
CHUNK = 10_000
#: an arc whose chord (first point to last) is shorter than this fraction of its RMS size is not stored (its
#: rotation is ill-defined)
MIN_CHORD = 0.2


@dataclass
class Arcs(DescriptorIndex):
    """Rocking four-bars' arc descriptors (see the module).

    ``params`` ``(M, 6)``: input, coupler, rocker, u, v, circuit (ground 1); ``window`` ``(M, 2)``: the input
    angles (rad from the ground line) the arc runs between; ``frame`` ``(M, 4)``: centroid x, y, size and
    rotation of the stored description; ``desc`` ``(M, 2 ARC_POINTS)``.  ``kind``: ``"rocking"`` (this module's
    arcs) or ``"windows"`` (windows of full-turn four-bars' curves, :mod:`planar.synth.windows`), ``per`` arcs
    stored per four-bar; a file of one kind is not read as the other.
    """

    params: NDArray[np.float32]
    window: NDArray[np.float32]
    frame: NDArray[np.float32]
    desc: NDArray[np.float32]
    seed: int
    build_seconds: float = 0.0
    kind: str = "rocking"
    per: int = len(WINDOWS)
    _tree: Any = field(default=None, repr=False)

    def save(self, path: str | Path) -> None:
        """Write the arcs as one ``.npz`` file (a temporary beside it, then moved into place)."""
        from planar.fileio import atomic_write

        p = Path(path)
        p.parent.mkdir(parents=True, exist_ok=True)
        meta = np.array([VERSION, ARC_POINTS, ARC_SAMPLES, self.per, self.seed], dtype=np.int64)
        with atomic_write(p) as fh:
            np.savez(
                fh,
                params=self.params,
                window=self.window,
                frame=self.frame,
                desc=self.desc,
                meta=meta,
                seconds=np.float64(self.build_seconds),
                kind=np.array(self.kind),
            )


def describe_open(z: NDArray[np.complex128]) -> tuple[Array, Array]:
    """Descriptors ``(P, 2 ARC_POINTS)`` and frames ``(P, 4)`` of open curves ``z`` ``(P, S)`` (points in order).

    Resampled to :data:`ARC_POINTS` points evenly spaced by arc length from the first point to the last, then
    moved to their centroid, turned so the chord lies along +x and divided by their RMS distance from the
    centroid.  NaN for a curve of zero length or chord."""
    P, _S = z.shape
    seg = np.abs(np.diff(z, axis=1))
    cum = np.concatenate([np.zeros((P, 1)), np.cumsum(seg, axis=1)], axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        u = cum / cum[:, -1:]
    q = np.linspace(0.0, 1.0, ARC_POINTS)
    w = np.empty((P, ARC_POINTS), complex)
    for i in range(P):  # np.interp per row: P is a chunk, ARC_POINTS small
        if not np.isfinite(u[i]).all():
            w[i] = np.nan
            continue
        w[i] = np.interp(q, u[i], z[i].real) + 1j * np.interp(q, u[i], z[i].imag)
    c = w.mean(1)
    d = w - c[:, None]
    size = np.sqrt(np.mean(np.abs(d) ** 2, axis=1))
    chord = w[:, -1] - w[:, 0]
    rot = np.angle(chord)
    with np.errstate(invalid="ignore", divide="ignore"):
        n = d * np.exp(-1j * rot)[:, None] / size[:, None]
    bad = ~(np.abs(chord) > 1e-12 * np.maximum(size, 1e-300))
    n[bad] = np.nan
    desc = np.concatenate([n.real, n.imag], axis=1)
    frame = np.column_stack([c.real, c.imag, size, rot])
    return desc, frame


def input_range(a: Array, b: Array, c: Array) -> tuple[Array, Array, NDArray[np.bool_]]:
    """The input angles (rad from the ground line; unit ground) where four-bars of input ``a``, coupler ``b``
    and rocker ``c`` assemble, as one arc ``lo, hi`` each (of two symmetric arcs, the upper one), and whether
    the input rocks (does not turn fully) and assembles somewhere."""
    with np.errstate(invalid="ignore", divide="ignore"):
        cmin = (a * a + 1.0 - (b + c) ** 2) / (2.0 * a)
        cmax = (a * a + 1.0 - (b - c) ** 2) / (2.0 * a)
    full = (cmin <= -1.0) & (cmax >= 1.0)
    none = (cmin > 1.0) | (cmax < -1.0) | (cmin >= cmax)
    ac_max = np.arccos(np.clip(cmax, -1.0, 1.0))
    ac_min = np.arccos(np.clip(cmin, -1.0, 1.0))
    lo = np.where(cmin <= -1.0, ac_max, np.where(cmax >= 1.0, -ac_min, ac_max))
    hi = np.where(cmin <= -1.0, 2 * np.pi - ac_max, ac_min)
    return lo, hi, ~full & ~none & (hi - lo > 1e-3)


def _sample_rocking(rng: np.random.Generator, n: int) -> Array:
    """``n`` rows of input, coupler, rocker, u, v, circuit (ground 1) whose input rocks, ratio <= MAX_RATIO."""
    out: list[Array] = []
    have = 0
    while have < n:
        m = 3 * (n - have) + 64
        L = np.exp(rng.uniform(np.log(1 / MAX_RATIO), np.log(MAX_RATIO), (m, 3)))
        allL = np.column_stack([np.ones(m), L])
        lo, hi, rocks = input_range(L[:, 0], L[:, 1], L[:, 2])
        keep = rocks & (allL.max(1) <= MAX_RATIO * allL.min(1)) & (hi - lo > np.radians(10))
        L = L[keep]
        k = len(L)
        u = L[:, 1] * rng.uniform(-1.5, 2.5, k)
        v = L[:, 1] * rng.uniform(-2.0, 2.0, k)
        circ = np.where(rng.random(k) < 0.5, 1.0, -1.0)
        out.append(np.column_stack([L, u, v, circ]))
        have += k
    return np.concatenate(out)[:n]


def described_windows(p: Array, windows: list[tuple[Array, Array]]) -> tuple[Array, Array, Array, Array]:
    """Four-bars ``p`` ``(n, 6)`` (input, coupler, rocker, u, v, circuit; ground 1) described over each window
    ``(a0, a1)`` of input angles (rad, ``(n,)`` each) at :data:`ARC_SAMPLES` angles (:func:`describe_open`):
    the params, windows, frames and descriptors of the arcs that assemble throughout and have a chord of at least
    :data:`MIN_CHORD` of their size, every window's in turn."""
    n = len(p)
    X = np.column_stack([np.ones(n), p[:, :5], np.zeros((n, 3))])
    f = np.linspace(0.0, 1.0, ARC_SAMPLES)
    P, W, F, D = [], [], [], []
    for a0, a1 in windows:
        th = a0[:, None] + (a1 - a0)[:, None] * f[None, :]
        x, y, ok = coupler_points(X, th, p[:, 5], threads=1)
        desc, frame = describe_open(x + 1j * y)
        chord = np.abs((x[:, -1] - x[:, 0]) + 1j * (y[:, -1] - y[:, 0]))
        good = ok.all(1) & np.isfinite(desc).all(1) & (frame[:, 2] > 1e-9) & (chord > MIN_CHORD * frame[:, 2])
        P.append(p[good])
        W.append(np.column_stack([a0, a1])[good])
        F.append(frame[good])
        D.append(desc[good])
    return np.concatenate(P), np.concatenate(W), np.concatenate(F), np.concatenate(D)


def _chunk(seed: int, index: int, n: int) -> tuple[Array, Array, Array, Array]:
    rng = np.random.default_rng([seed, 7, index])
    p = _sample_rocking(rng, n)
    lo, hi, _ = input_range(p[:, 0], p[:, 1], p[:, 2])
    pad = 0.01 * (hi - lo)
    lo, hi = lo + pad, hi - pad
    return described_windows(p, [(lo + w0 * (hi - lo), lo + w1 * (hi - lo)) for w0, w1 in WINDOWS])


def built(
    chunk: Any, fourbars: int, seed: int, label: str, progress: bool, kind: str = "rocking", per: int = len(WINDOWS)
) -> Arcs:
    """The arcs (of ``kind``, ``per`` a four-bar) of ``fourbars`` four-bars from ``chunk(seed, index, n)`` in chunks
    of :data:`CHUNK`, stored as float32, with the CPU seconds taken; a progress bar named ``label`` when
    ``progress``."""
    t0 = time.process_time()
    parts: list[tuple[Array, ...]] = []
    bar = None
    if progress:
        from planar.core.progress import progress_bar

        bar = progress_bar(fourbars, label, "four-bar", unit_scale=True)
    for index, have in enumerate(range(0, fourbars, CHUNK)):
        n = min(CHUNK, fourbars - have)
        parts.append(tuple(a.astype(np.float32) for a in chunk(seed, index, n)))
        if bar is not None:
            bar.update(n)
    if bar is not None:
        bar.close()
    p, w, f, d = (np.concatenate([q[i] for q in parts]) for i in range(4))
    return Arcs(p, w, f, d, seed, time.process_time() - t0, kind, per)


def build_arcs(fourbars: int = DEFAULT_FOURBARS, seed: int = 0, progress: bool = False) -> Arcs:
    """The arcs of ``fourbars`` rocking four-bars, :data:`WINDOWS` each (deterministic for both arguments; an arc
    too short a chord is left out, so the entries are a little fewer than ``fourbars * len(WINDOWS)``)."""
    if fourbars < 100:
        raise InputError("arc atlas size", fourbars, "at least 100 four-bars")
    return built(_chunk, fourbars, seed, "rocking arcs", progress)


def arcs_path(fourbars: int = DEFAULT_FOURBARS, seed: int = 0) -> Path:
    """The cache file of the arcs of ``fourbars`` four-bars and ``seed`` (beside the closed-curve atlas)."""
    from planar.synth.atlas import cache_dir

    return cache_dir() / f"arcs-v{VERSION}-{fourbars}-{seed}.npz"


_LOADED: dict[str, Arcs] = {}


def read_arcs(path: str | Path, kind: str = "rocking", per: int = len(WINDOWS)) -> Arcs:
    """Arcs of ``kind`` (``per`` of them a four-bar) written by :meth:`Arcs.save`; :class:`InputError` naming the
    file if it is not one (a file without a kind holds rocking arcs)."""
    p = str(path)
    if p in _LOADED:
        return _LOADED[p]
    what = "an arc atlas" if kind == "rocking" else "a curve-window atlas"
    try:
        with np.load(p) as z:
            meta = z["meta"]
            stored = str(z["kind"]) if "kind" in z.files else "rocking"
            if meta[:4].tolist() != [VERSION, ARC_POINTS, ARC_SAMPLES, per] or stored != kind:
                raise InputError(p, f"{stored} atlas format {meta[:4].tolist()}", f"{what} of this planar (rebuild it)")
            a = Arcs(z["params"], z["window"], z["frame"], z["desc"], int(meta[4]), float(z["seconds"]), kind, per)
    except InputError:
        raise
    except FileNotFoundError:
        raise InputError(p, "missing", f"{what} file written by planar") from None
    except (KeyError, ValueError, OSError) as e:
        raise InputError(p, unreadable(e, p), f"{what} file written by planar") from None
    _LOADED[p] = a
    return a


def load_arcs(fourbars: int = DEFAULT_FOURBARS, seed: int = 0, progress: bool = False) -> Arcs:
    """The cached arcs of ``fourbars`` four-bars, built and cached first if missing (kept in memory only when the
    cache folder cannot be written)."""
    return cached(arcs_path(fourbars, seed), "rocking-arc atlas", fourbars, "rocking", len(WINDOWS), progress, build_arcs, seed)


def cached(path: Path, what: str, fourbars: int, kind: str, per: int, progress: bool, build: Any, seed: int) -> Arcs:
    """The arc atlas of ``kind`` (``per`` arcs a four-bar) cached at ``path``, read (:func:`read_arcs`), or built
    first by ``build(fourbars, seed, progress)`` and saved there, one line (:func:`build_line`, naming it ``what``)
    on standard error saying so when ``progress``; kept in memory only when the cache folder cannot be written."""
    if path.exists():
        return read_arcs(path, kind, per)
    if progress:
        import sys

        print(build_line(what, fourbars, per, path), file=sys.stderr, flush=True)
    a: Arcs = build(fourbars, seed, progress)
    try:
        a.save(path)
        _LOADED[str(path)] = a
    except (OSError, InputError):
        pass
    return a


#: CPU seconds a four-bar of an arc atlas's build takes (about 13 to 14 s for 250,000 on the development machine) and
#: bytes an arc takes on disk
BUILD_S_PER_FOURBAR, ARC_BYTES = 5.6e-5, 176


def build_line(what: str, fourbars: int, per: int, path: str | Path) -> str:
    """The line said before an arc atlas (``what``: rocking arcs or curve windows) is built on first use: how many
    four-bars and arcs, about how long and how large, and where it is cached."""
    return (
        f"planar: building the {what} once ({fourbars:,} four-bars, {per} arcs each, about "
        f"{max(1, round(fourbars * BUILD_S_PER_FOURBAR))} s of CPU, {fourbars * per * ARC_BYTES / 1e6:.0f} MB on disk), "
        f"cached at {path}; later runs read it (PLANAR_CACHE_DIR chooses the folder)"
    )


def smooth_open(z: NDArray[np.complex128], n: int = ARC_SAMPLES) -> NDArray[np.complex128]:
    """``n`` points on the natural cubic spline through the points ``z`` in order (parametrised by chord length)."""
    from scipy.interpolate import CubicSpline

    seg = np.abs(np.diff(z))
    if len(z) < 3 or np.any(seg <= 1e-12 * max(float(seg.max()), 1e-300)):
        return z
    s = np.concatenate([[0.0], np.cumsum(seg)])
    cs = CubicSpline(s, np.column_stack([z.real, z.imag]), bc_type="natural")
    q = cs(np.linspace(0.0, s[-1], n))
    return np.asarray(q[:, 0] + 1j * q[:, 1])


def arc_candidates(arcs: Arcs, targets: Array, k: int = 64) -> Array:
    """Rocking four-bars whose arcs are near the targets ``(N, 2)`` (in order along the arc), placed onto them:
    rows of the kernel's 9 parameters and the circuit (as :func:`planar.synth.atlas.candidates`), ``4 k`` of them
    (the targets' description both ways along and mirrored), nearest first within each query."""
    from planar.synth.atlas import _mirror, views

    t = np.asarray(targets, float)
    out: list[Array] = []
    for mirrored, seq in views(t[:, 0] + 1j * t[:, 1]):
        d, fr = describe_open(smooth_open(seq)[None, :])
        if not np.isfinite(d).all():
            continue
        _, idx = arcs.tree.query(d[0], k=min(k, len(arcs)))
        rows = _place(arcs, np.atleast_1d(idx), fr[0])
        out.append(_mirror(rows) if mirrored else rows)
    return np.concatenate(out) if out else np.empty((0, 10))


def _place(arcs: Arcs, idx: NDArray[np.intp], wframe: Array) -> Array:
    """Entries ``idx`` mapped onto a query described by ``wframe`` (centroid x, y, size, rotation)."""
    p = arcs.params[idx].astype(float)
    fr = arcs.frame[idx].astype(float)
    k = wframe[2] / fr[:, 2]
    e = np.exp(1j * (wframe[3] - fr[:, 3]))
    o2 = (wframe[0] + 1j * wframe[1]) - k * e * (fr[:, 0] + 1j * fr[:, 1])
    return np.column_stack(
        [k, k * p[:, 0], k * p[:, 1], k * p[:, 2], k * p[:, 3], k * p[:, 4], o2.real, o2.imag, np.angle(e), p[:, 5]]
    )


def rocking_range(row: Array, theta: Array) -> tuple[float, float] | None:
    """The input angles (rad from the ground line, ``lo <= hi``) a rocking four-bar (kernel row ``row``: 9
    parameters) must swing between to pass crank angles ``theta`` on one swing (all on the same arc of its
    range, none across a dead zone), or None when they are not on one arc (or its input turns fully)."""
    r1, r2, r3, r4 = (abs(float(v)) for v in row[:4])
    lo, hi, rocks = input_range(np.array([r2 / r1]), np.array([r3 / r1]), np.array([r4 / r1]))
    if not rocks[0]:
        return None
    lo0, hi0 = float(lo[0]), float(hi[0])
    th = np.asarray(theta, float)
    for arc_lo, arc_hi in ((lo0, hi0), (-hi0, -lo0)):  # the upper arc and its mirror (two-arc linkages)
        u = arc_lo + np.mod(th - arc_lo, 2 * np.pi)
        if np.all(u <= arc_hi + 1e-12):
            return float(u.min()), float(u.max())
    return None


def input_swing(row: Array, theta: Array) -> tuple[float, float] | None:
    """The input angles (rad from the ground line, ``lo <= hi``) a four-bar (kernel row ``row``) swings between to
    pass crank angles ``theta`` in their order on one swing: :func:`rocking_range` when its input rocks; when it
    turns fully (a crank-rocker tracing part of its closed curve: a cognate of a double-rocker does), the angles'
    own span when they run one way within one turn (such a crank can be driven back and forth over it); else None."""
    swing = rocking_range(row, theta)
    r1, r2, r3, r4 = (abs(float(v)) for v in row[:4])
    if swing is not None or input_range(np.array([r2 / r1]), np.array([r3 / r1]), np.array([r4 / r1]))[2][0]:
        return swing
    step = np.mod(np.diff(np.asarray(theta, float)) + np.pi, 2 * np.pi) - np.pi
    u = float(theta[0]) + np.concatenate([[0.0], np.cumsum(step)])
    if not (np.all(step > 0) or np.all(step < 0)) or np.ptp(u) >= 2 * np.pi:
        return None
    lo, hi = float(u.min()), float(u.max())
    return (lo, hi) if hi > lo else None


#: lookup and refinement effort: neighbours per query, and starts refined (:func:`arc_start`)
SEARCH_K, SEARCH_REFINE = 64, 32
#: a looked-up start's refinement (:func:`arc_start`): at most this many iterations in the joints' positions
ARC_START_ITERS = 300
#: a start's refinement and the final polish (:func:`_polished`) end after this many refused steps in a row
#: (:func:`planar.synth.positions.geodesic_lm`'s ``patience``)
REFINE_PATIENCE = 15
#: the rounds of :func:`search_arcs`: neighbours per query, and how many starts may have been refined by the round's
#: end (its own and the rounds' before); a later round runs only when the best so far is a near miss: beyond
#: :data:`BASIN` but within ``NEAR_MISS`` (the targets' size 1).  Drawn or noisy targets, which no four-bar meets,
#: stop after the first round
ROUNDS = ((SEARCH_K, SEARCH_REFINE), (256, 128))
NEAR_MISS = 1e-3
#: the final polish (:func:`planar.synth.positions.polish_positions`): iterations per start (ended, as a start's, after
#: :data:`REFINE_PATIENCE` refused steps in a row), and how many of the best refined starts (each on one swing) it
#: is tried on, best first, until one is within the search's stop or :data:`BASIN`
POLISH_ITERS, POLISH_STARTS = 600, 8
#: a start this near (largest distance over the targets' size) ends the trying of further starts: only it is
#: polished on, and no later round runs.  On a short arc the last digits come slowly (the nearest four-bars lie in a
#: narrow valley), so a search whose stop is far below this would try every start before polishing the one already
#: found.  The same as the closed-curve search's (:data:`planar.synth.search.BASIN`); a caller passes a smaller one
#: for a tolerance under ten times it
BASIN = 1e-6
#: when the rounds end with nothing usable or nothing within ``GUARD_AFTER`` (the targets' size 1), and most of
#: their starts ended unusable, the ``GUARD_STARTS`` best of the first round's starts are refined again keeping the
#: transmission angle at the targets ``TOGGLE_GUARD_DEG`` beyond the floor a result must keep
#: (:func:`planar.synth.positions.polish_positions`'s ``floor``): on some arcs most starts otherwise end at a toggle,
#: where the arc turns back and fits the targets loosely, and are not usable
GUARD_AFTER, TOGGLE_GUARD_DEG, GUARD_STARTS = 1e-4, 0.2, 8
#: the curve-window round of :func:`search_arcs` (after the first round, when it left nothing within the basin):
#: neighbours per query in the curve-window atlas (:mod:`planar.synth.windows`: parts of the curves of four-bars whose
#: crank turns fully, as one of a double-rocker's two cognates does) and how many of them are refined
WINDOWS_K, WINDOWS_REFINE = 16, 16
#: the requery rounds of :func:`search_arcs` (after the other rounds when the best is a near miss; the second only
#: when the first made it nearer): the best refined four-bar's arc from its first target to its last, at
#: :data:`ARC_SAMPLES` input angles, looked up in the rocking arcs, ``REQUERY_K`` neighbours a view, and up to
#: ``REQUERY_REFINE`` of them refined (all of them: the best 64 by the objective of a wider lookup rescued fewer
#: misses); at most ``REQUERY_ROUNDS`` rounds.  That arc passes within a near miss of every target, so it describes
#: their curve better than the spline through 12 uneven targets does, as the closed-curve search's requery
#: (:func:`planar.synth.search._requery`) does (docs/explanation/coupler-curve-atlas.md)
REQUERY_K, REQUERY_REFINE, REQUERY_ROUNDS = 16, 64, 2


def on_swing(theta: Array, swing: tuple[float, float]) -> Array:
    """Input angles ``theta`` (rad) as angles within ``swing`` ``(lo, hi)`` (``lo`` itself included)."""
    lo = swing[0]
    return lo - 1e-9 + np.mod(np.asarray(theta, float) - lo + 1e-9, 2 * np.pi)


def one_way(theta: Array, swing: tuple[float, float]) -> bool:
    """Whether input angles ``theta`` (rad) placed on the ``swing`` run one way (the targets met in order)."""
    du = np.diff(on_swing(theta, swing))
    return bool(np.all(du > 0) or np.all(du < 0))


def swing_transmission(row: Array, swing: tuple[float, float], n: int = 181) -> float:
    """The smallest distance (rad) of the transmission angle of kernel row ``row`` from a toggle (0 or pi) over
    ``swing`` (input angles, rad from the ground line), on ``n`` angles: law of cosines in the diagonal B-O4."""
    r1, r2, r3, r4 = (abs(float(v)) for v in row[:4])
    th = np.linspace(swing[0], swing[1], n)
    c = (r3 * r3 + r4 * r4 - (r1 * r1 + r2 * r2 - 2 * r1 * r2 * np.cos(th))) / (2 * r3 * r4)
    mu = np.arccos(np.clip(c, -1.0, 1.0))
    return float(np.min(np.minimum(mu, np.pi - mu)))


def usable_swing(
    r: Array, theta: Array, cons: Any, scale: float, ordered: bool, input_rocks: bool = False
) -> tuple[float, float] | None:
    """The swing (:func:`input_swing`) of a refined row ``r`` (9 parameters and the circuit) passing crank angles
    ``theta``, when it is usable as a rocking result: it keeps ``cons`` (the full turn not asked), meets the targets
    one way when ``ordered``, and its transmission angle over the swing keeps ``cons.min_transmission`` and the floor
    :data:`planar.synth.designs.TOGGLE_FLOOR_DEG`; with ``input_rocks``, its input link itself cannot turn fully
    (:func:`rocking_range`: not a cognate whose crank is swung over the targets' span); else None."""
    from planar.synth.search import violation

    swing = rocking_range(r[:9], theta) if input_rocks else input_swing(r[:9], theta)
    if swing is None or violation(r[None, :9], cons, scale, 0.0)[0] > 0 or (ordered and not one_way(theta, swing)):
        return None
    floor = max(float(cons.min_transmission), math.radians(TOGGLE_FLOOR_DEG))
    return swing if swing_transmission(r, swing) >= floor else None


def arc_start(obj: Any, row: Array, max_ratio: float, floor: float = 0.0) -> tuple[Array, Array]:
    """A looked-up start ``row`` (9 parameters and the circuit, placed on the targets of ``obj``) refined: the input
    angles assigned on its curve (:func:`planar.synth.search.assign_theta`), then at most :data:`ARC_START_ITERS`
    iterations in the joints' positions (:func:`planar.synth.positions.polish_positions`, keeping the link ratio
    ``max_ratio`` and the transmission angle at the targets ``floor`` rad from a toggle when above 0), ended after
    :data:`REFINE_PATIENCE` refused steps in a row.  Returns the row and its input angles at the targets (the
    start's own when nothing nearer is found).

    The closed-curve search's start (:func:`planar.synth.search.refined_start`) first takes 10 evaluations of
    least squares in the kernel's lengths and angles.  On a rocking arc those angles come from a curve sampled
    every 1.4 degrees of input over a swing of a few tens of degrees, so the placed start is 0.03 to 0.5 of the
    size off, and the lengths' steps often leave the range where the loop closes.  Measured on the 14 rocking
    problems at 12 targets the search had missed (five seeds), each started from its true four-bar's own arc over
    the targets' window, placed as a lookup places it: the closed-curve search's start came within 1e-6 in 4, this
    one in all 14 (docs/explanation/coupler-curve-atlas.md)."""
    from planar.synth.search import assign_theta

    theta = assign_theta(obj, row)
    return polish_positions(obj.targets, row, theta, ARC_START_ITERS, max_ratio, floor, REFINE_PATIENCE)


#: a rocking start's outcome: largest distance (the targets' size 1), refined row, input angles at the targets, swing
Found = tuple[float, Array, Array, tuple[float, float]]


def _tried_starts(
    obj: Any, every: Array, limit: int, tried: list[Array], refine: Any, usable: Any, stop: float, basin: float = BASIN
) -> list[Found]:
    """The looked-up rows ``every`` refined (``refine(row) -> (row, angles)``) best first by ``obj``'s score at
    sampled angles, skipping rows already in ``tried`` (appended to as they are tried), until ``tried`` holds
    ``limit`` rows or one on a usable swing (``usable(row, angles)``) is within ``stop`` or ``basin``."""
    from planar.synth.search import max_distance

    f = obj.population(every, np.float64) if len(every) else np.zeros(0)
    found: list[Found] = []
    for row in every[np.argsort(f, kind="stable")]:
        if len(tried) >= limit:
            break
        if tried:  # np.allclose(row, s, rtol=1e-6, atol=1e-9) against every row tried, at once
            seen = np.asarray(tried)
            if np.any(np.all(np.abs(row - seen) <= 1e-9 + 1e-6 * np.abs(seen), axis=1)):
                continue
        tried.append(row)
        r, tt = refine(row)
        swing = usable(r, tt)
        if swing is not None:
            found.append((max_distance(obj, r, tt), r, tt, swing))
            if found[-1][0] <= max(stop, basin):
                break
    return found


def _polished(
    obj: Any, found: list[Found], stop: float, usable: Any, max_ratio: float, floor: float, basin: float = BASIN
) -> Found | None:
    """The best of ``found`` after the best few (only the best when it is within ``basin``; none when within
    ``stop``) go on in the joints' positions (:func:`planar.synth.positions.polish_positions`), until one is within
    ``stop`` or ``basin``; None when ``found`` is empty."""
    from planar.synth.search import max_distance

    if not found:
        return None
    found = sorted(found, key=lambda c: c[0])
    best = found[0]
    for _, r0, tt0, _ in found[: 1 if best[0] <= basin else POLISH_STARTS] if best[0] > stop else []:
        r, tt = polish_positions(obj.targets, r0, tt0, POLISH_ITERS, max_ratio, floor, REFINE_PATIENCE)
        swing = usable(r, tt)
        e = max_distance(obj, r, tt) if swing is not None else math.inf
        if swing is not None and e < best[0]:
            best = (e, r, tt, swing)
        if best[0] <= max(stop, basin):
            break
    return best


@dataclass
class _Rounds:
    """The state of :func:`search_arcs`'s rounds: the objective (normalised targets), the search's stop and basin,
    the usable-swing test, the link-ratio limit, the stages' seconds, the starts tried and the best found so far."""

    obj: Any
    stop: float
    basin: float
    usable: Any
    max_ratio: float
    stages: dict[str, float]
    tried: list[Array] = field(default_factory=list)
    best: Found | None = None
    #: the round the best came from: ``"windows"`` for the curve-window round, else empty
    best_from: str = ""

    def short(self) -> bool:
        """Whether nothing found so far is within the stop or the basin."""
        return self.best is None or self.best[0] > max(self.stop, self.basin)

    def near_miss(self) -> bool:
        """Whether the best so far is worth more starts: beyond the stop and the basin, within :data:`NEAR_MISS`
        (drawn or noisy targets, which no four-bar meets, are not)."""
        return self.best is not None and max(self.stop, self.basin) < self.best[0] <= NEAR_MISS

    def run(self, every: Array, limit: int, tried: list[Array], floor: float, stage: str | None = None) -> int:
        """One round on the looked-up rows ``every``: the untried refined best first until ``tried`` holds ``limit``
        (:func:`_tried_starts`), the best few polished (:func:`_polished`), keeping transmission ``floor`` (rad) at
        the targets; its seconds go to ``stage``, or to ``refine_s`` and ``polish_s``.  Returns how many of its
        starts ended on a usable swing."""

        def refine(row: Array) -> tuple[Array, Array]:
            return self.rocking_input(*arc_start(self.obj, row, self.max_ratio, floor))

        t1 = time.perf_counter()
        found = _tried_starts(self.obj, every, limit, tried, refine, self.usable, self.stop, self.basin)
        t2 = time.perf_counter()
        polished = _polished(self.obj, found, self.stop, self.usable, self.max_ratio, floor, self.basin)
        t3 = time.perf_counter()
        for key, sec in ((stage, t3 - t1),) if stage else (("refine_s", t2 - t1), ("polish_s", t3 - t2)):
            self.stages[key] = self.stages.get(key, 0.0) + sec
        if polished is not None and (self.best is None or polished[0] < self.best[0]):
            self.best, self.best_from = polished, "windows" if stage == "windows_s" else ""
        return len(found)

    def rocking_input(self, r: Array, tt: Array) -> tuple[Array, Array]:
        """A refined row ``r`` (input angles ``tt``), or, when its input turns fully, its cognate on the same input
        pivot whose input link turns with ``r``'s coupler (:func:`planar.synth.cognates.input_cognate`: the same
        curve) if that input rocks and the cognate is usable: an input link that rocks is preferred, and with
        ``input_rocks`` no other is usable."""
        from planar.synth.cognates import input_cognate

        if rocking_range(r[:9], tt) is not None:
            return r, tt
        cog = input_cognate(r, tt)
        if cog is None or rocking_range(cog[0][:9], cog[1]) is None or self.usable(*cog) is None:
            return r, tt
        return cog

    def lookup(self, arcs: Arcs, k: int) -> Array:
        """``k`` neighbours a view in the rocking arcs, their seconds in ``arcs_s``."""
        t1 = time.perf_counter()
        every = arc_candidates(arcs, self.obj.targets, k)
        self.stages["arcs_s"] = self.stages.get("arcs_s", 0.0) + time.perf_counter() - t1
        return every

    def requery_round(self, arcs: Arcs) -> int:
        """One requery round (:data:`REQUERY_K`, :data:`REQUERY_REFINE`): the best so far's arc between its first and
        last target's input angles looked up (:func:`arc_candidates`) and refined; its seconds in ``requery_s``."""
        assert self.best is not None
        _, r, tt, swing = self.best
        u = on_swing(tt, swing)
        x, y, _ = coupler_points(r[None, :9], np.linspace(u[0], u[-1], ARC_SAMPLES)[None], np.array([r[9]]))
        t1 = time.perf_counter()
        every = arc_candidates(arcs, np.column_stack([x[0], y[0]]), REQUERY_K)
        self.stages["requery_s"] = self.stages.get("requery_s", 0.0) + time.perf_counter() - t1
        return self.run(every, len(self.tried) + REQUERY_REFINE, self.tried, 0.0, "requery_s")

    def windows_round(self, windows: Any) -> int:
        """The curve-window round (:data:`WINDOWS_K`, :data:`WINDOWS_REFINE`): the atlas (``windows``, or a function
        of no arguments returning it) loaded here, its seconds in ``windows_load_s``, the round's in ``windows_s``
        (its lookup is :func:`arc_candidates`'s, as :func:`planar.synth.windows.window_candidates`)."""
        t1 = time.perf_counter()
        atlas = windows() if callable(windows) else windows
        t2 = time.perf_counter()
        self.stages["windows_load_s"] = t2 - t1
        every = arc_candidates(atlas, self.obj.targets, WINDOWS_K)
        self.stages["windows_s"] = time.perf_counter() - t2
        return self.run(every, len(self.tried) + WINDOWS_REFINE, self.tried, 0.0, "windows_s")


def search_arcs(
    targets: Array,
    arcs: Arcs,
    cons: Any = None,
    stop: float = 1e-9,
    ordered: bool = False,
    input_rocks: bool = False,
    windows: Any = None,
    basin: float = BASIN,
) -> tuple[Any, tuple[float, float] | None]:
    """Untimed targets (normalised: centroid 0, size 1) from the rocking arcs, refined: the best result (as
    :class:`planar.synth.search.SearchResult`) whose targets lie on one swing of its input (``ordered``: met in
    their order as it swings one way), whose transmission angle keeps over that swing ``cons.min_transmission``
    and the floor :data:`planar.synth.designs.TOGGLE_FLOOR_DEG` from a toggle, and that swing's input range
    (:func:`rocking_range`; None when no result does).  ``cons``: the path's
    :class:`~planar.synth.search.Constraints` with the full turn not required (its link ratio is kept).
    ``input_rocks``: only a four-bar whose input link itself cannot turn fully (see :func:`usable_swing`).
    ``windows``: None, or the curve-window atlas (:mod:`planar.synth.windows`) or a function of no arguments
    returning it (called only when its round runs).  ``basin``: a result within it ends the search (see
    :data:`BASIN`).

    Past the targets' own curve equation, the search runs in rounds: each looks up neighbours, refines the starts
    not yet tried best first (:func:`_tried_starts`) and polishes the best few (:func:`_polished`); a later round
    runs only when nothing found so far is within ``basin``.  The first looks up the rocking arcs (``ROUNDS[0]``);
    then, with ``windows``, the curve windows (:data:`WINDOWS_K`, :data:`WINDOWS_REFINE`; their four-bars' cranks
    turn fully, and a refined one's cognate whose input rocks replaces it: :meth:`_Rounds.rocking_input`, as for
    every refined start); then, only after a near miss (beyond ``basin``, within
    :data:`NEAR_MISS`), the rocking arcs again, more of them (``ROUNDS[1]``); then, while the best is a near miss
    (after a requery, only if it came nearer), the best's own arc over the targets looked up (:data:`REQUERY_K`,
    :meth:`_Rounds.requery_round`).  When they end with nothing usable
    or nothing within :data:`GUARD_AFTER`, and most of their starts were unusable, the :data:`GUARD_STARTS` best
    starts are refined once more keeping the transmission angle at the targets :data:`TOGGLE_GUARD_DEG` beyond the
    floor (docs/explanation/coupler-curve-atlas.md)."""
    import dataclasses

    from planar.synth.search import Constraints, PathObjective, SearchResult

    cons = dataclasses.replace(cons if cons is not None else Constraints(), full_turn=False)
    t = np.asarray(targets, float)
    obj = PathObjective(t, None, cons, 256)

    def usable(r: Array, tt: Array) -> tuple[float, float] | None:
        return usable_swing(r, tt, cons, obj.scale, ordered, input_rocks)

    # the four-bar of the targets' own sextic first (exact from 15 targets on a long enough arc): no lookup
    def choose(r: Array, tt: Array) -> tuple[int, Any] | None:  # an input link that rocks first
        swing = usable(r, tt)
        return None if swing is None else (0 if rocking_range(r[:9], tt) is not None else 1, swing)

    t_alg = time.perf_counter()
    alg, swing = search_algebraic(t, cons, choose, stop)
    if alg is not None:
        return alg, swing
    stages = {"algebraic_s": time.perf_counter() - t_alg} if len(t) >= MIN_TARGETS else {}
    rounds = _Rounds(obj, stop, basin, usable, cons.max_ratio, stages)
    usable_starts = rounds.run(rounds.lookup(arcs, ROUNDS[0][0]), ROUNDS[0][1], rounds.tried, 0.0)
    if windows is not None and rounds.short():
        usable_starts += rounds.windows_round(windows)
    for k, limit in ROUNDS[1:]:
        if rounds.near_miss():  # else found, or not near enough for more starts to be worth their time
            usable_starts += rounds.run(rounds.lookup(arcs, k), limit, rounds.tried, 0.0)
    for _ in range(REQUERY_ROUNDS):
        before = rounds.best
        if not rounds.near_miss():
            break
        usable_starts += rounds.requery_round(arcs)
        if rounds.best is before:  # no nearer: looking up the same arc again finds the same neighbours
            break
    best = rounds.best
    if (best is None or best[0] > GUARD_AFTER) and 2 * usable_starts < len(rounds.tried):
        # most starts ended unusable, at a toggle: again, kept off them
        guard = max(float(cons.min_transmission), math.radians(TOGGLE_FLOOR_DEG)) + math.radians(TOGGLE_GUARD_DEG)
        guarded: list[Array] = []
        rounds.run(rounds.lookup(arcs, ROUNDS[0][0]), GUARD_STARTS, guarded, guard)
        rounds.tried += guarded
    if rounds.best is None:
        return None, None
    _, r, tt, swing = rounds.best
    sse = float(np.sum(np.square(row_points(r, tt) - t)))
    result = SearchResult(r[:9], 1 if r[9] >= 0 else -1, tt, sse, True, len(rounds.tried), stages, rounds.best_from)
    return result, swing
