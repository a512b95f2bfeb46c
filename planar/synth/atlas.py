"""An atlas of normalised four-bar coupler curves, searched by nearest neighbour.

Each entry is one four-bar on one circuit, in a normalised frame: ground
``1`` along +x from the crank pivot at the origin, crank, coupler and rocker
lengths and the coupler point ``(u, v)`` in the coupler's frame (as
:mod:`planar.synth.kernel`).  The atlas covers linkages whose crank turns
fully (Grashof with the crank or the ground shortest: crank-rockers and
drag-links), link ratio at most :data:`MAX_RATIO`, both circuits.

Its coupler curve, solved at :data:`CURVE_SAMPLES` crank angles over the
turn, is resampled to :data:`RESAMPLE` points evenly spaced by arc length
and described by its Fourier coefficients ``c_n`` (``n = +-1 ... +-K``,
:data:`HARMONICS`), normalised for

* position: ``c_0`` (the centroid) is left out;
* scale: divided by the RMS distance from the centroid;
* rotation ``phi`` and starting point ``s``: ``c_n`` is multiplied by
  ``exp(-i (phi + n s))`` with ``phi`` and ``s`` chosen so ``c_1`` and
  ``c_-1`` are real and positive.  That leaves one ambiguity (``phi + pi``,
  ``s + pi`` flips the sign of every even harmonic): the atlas stores one
  choice and a query tries both.

A query (:func:`candidates`) describes the targets the same way (their
polygon, closed, resampled by arc length), also reversed (the crank may turn
either way along them) and mirrored, finds the nearest entries with
:class:`scipy.spatial.cKDTree`, and maps each back onto the targets (scale,
rotation and position from the two descriptions).  The candidates are then
refined by :mod:`planar.synth.search` on the targets themselves.

The build (:func:`build_atlas`) is vectorised over chunks of linkages (no
Python loop per linkage; memory bounded by the chunk), deterministic for a
given size and seed (every chunk has its own seeded generator), and cached
on disk (:func:`load_atlas`).
"""

from __future__ import annotations

import os
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from planar.errors import InputError
from planar.synth.kernel import coupler_points

__all__ = [
    "DEFAULT_SIZE",
    "Atlas",
    "atlas_path",
    "build_atlas",
    "candidates",
    "curve_candidates",
    "describe",
    "load_atlas",
]

Array = NDArray[np.float64]

#: format version of the files on disk (a change rebuilds them)
VERSION = 1
#: harmonics kept on each side (n = +-1 ... +-K): 2 + 4 (K - 1) numbers per curve
HARMONICS = 5
#: crank angles each atlas curve is solved at
CURVE_SAMPLES = 128
#: points per curve after arc-length resampling (the FFT length)
RESAMPLE = 64
#: longest / shortest link of an atlas linkage at most this
MAX_RATIO = 10.0
#: entries of the default atlas (four-bars, each on one circuit)
DEFAULT_SIZE = 1_000_000
#: entries of the atlas the quick budget uses (builds in about a second)
QUICK_SIZE = 20_000
#: linkages per chunk of the build (memory: about 300 MiB of temporaries, :data:`CHUNK_BYTES`)
CHUNK = 20_000


class DescriptorIndex:
    """What a stored set of normalised curves shares: its length and a k-d tree over its descriptors
    (``desc``, one row per curve), built on first use (the atlas of closed curves and the rocking arcs)."""

    params: NDArray[np.float32]
    desc: NDArray[np.float32]
    _tree: Any

    def __len__(self) -> int:
        return len(self.params)

    @property
    def tree(self) -> Any:
        """The :class:`scipy.spatial.cKDTree` over the descriptors (built on first use)."""
        if self._tree is None:
            from scipy.spatial import cKDTree

            self._tree = cKDTree(np.asarray(self.desc, float), balanced_tree=False, compact_nodes=False)
        return self._tree


@dataclass
class Atlas(DescriptorIndex):
    """Normalised four-bars and their curve descriptors (see the module).

    ``params`` ``(M, 6)``: crank, coupler, rocker, u, v, circuit (ground 1);
    ``frame`` ``(M, 4)``: the curve's centroid x, y, its size (RMS distance
    from the centroid) and the rotation ``phi`` (radians) of the stored
    description; ``desc`` ``(M, D)``.
    """

    params: NDArray[np.float32]
    frame: NDArray[np.float32]
    desc: NDArray[np.float32]
    seed: int
    build_seconds: float = 0.0
    _tree: Any = field(default=None, repr=False)

    def save(self, path: str | Path) -> None:
        """Write the atlas as one ``.npz`` file (written to a temporary beside it, then moved into place).

        A failure names ``path`` (never the temporary) and leaves no file behind.
        """
        from planar.fileio import atomic_write

        p = Path(path)
        p.parent.mkdir(parents=True, exist_ok=True)
        meta = np.array([VERSION, HARMONICS, CURVE_SAMPLES, RESAMPLE, self.seed], dtype=np.int64)
        with atomic_write(p) as fh:
            np.savez(fh, params=self.params, frame=self.frame, desc=self.desc, meta=meta, seconds=np.float64(self.build_seconds))


def _descriptor(c: NDArray[np.complex128], pos: NDArray[np.complex128], neg: NDArray[np.complex128]) -> Array:
    """Real descriptor rows from normalised coefficients ``c_1, c_-1`` (real) and ``c_n, c_-n`` (n >= 2)."""
    return np.concatenate([c.real, pos.real, pos.imag, neg.real, neg.imag], axis=1)


def describe(z: NDArray[np.complex128]) -> tuple[Array, Array]:
    """Descriptors of closed curves ``z`` ``(P, S)`` (complex points in order, the last joined to the first).

    Returns ``desc`` ``(P, D)`` and ``frame`` ``(P, 4)`` (centroid x, y, size, rotation; see :class:`Atlas`),
    both after arc-length resampling to :data:`RESAMPLE` points.  A curve of zero length gives NaN.
    """
    P, S = z.shape
    seg = np.abs(np.diff(z, axis=1, append=z[:, :1]))
    cum = np.concatenate([np.zeros((P, 1)), np.cumsum(seg, axis=1)], axis=1)
    total = cum[:, -1:]
    with np.errstate(invalid="ignore", divide="ignore"):
        u = cum / total  # 0 ... 1 per row
    rows = np.arange(P)[:, None]
    flat = (u + 2.0 * rows).ravel()  # increasing over the whole array
    q = (np.arange(RESAMPLE) / RESAMPLE)[None, :] + 2.0 * rows
    k = np.clip(np.searchsorted(flat, q.ravel(), side="right") - 1, 0, None).reshape(P, RESAMPLE)
    k = np.minimum(k - rows * (S + 1), S - 1)
    zz = np.concatenate([z, z[:, :1]], axis=1)
    u0 = np.take_along_axis(u, k, axis=1)
    u1 = np.take_along_axis(u, k + 1, axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        f = np.clip((q - 2.0 * rows - u0) / (u1 - u0), 0.0, 1.0)
    f = np.nan_to_num(f)
    w = np.take_along_axis(zz, k, axis=1) * (1 - f) + np.take_along_axis(zz, k + 1, axis=1) * f
    C = np.fft.fft(w, axis=1) / RESAMPLE
    c0 = C[:, 0]
    size = np.sqrt(np.sum(np.abs(C[:, 1:]) ** 2, axis=1))
    a1, am1 = np.angle(C[:, 1]), np.angle(C[:, -1])
    phi, s = 0.5 * (a1 + am1), 0.5 * (a1 - am1)
    n = np.arange(2, HARMONICS + 1)
    with np.errstate(invalid="ignore", divide="ignore"):
        inv = 1.0 / size
    rot = np.exp(-1j * phi)[:, None]
    pos = C[:, n] * rot * np.exp(-1j * n[None, :] * s[:, None]) * inv[:, None]
    neg = C[:, -n] * rot * np.exp(1j * n[None, :] * s[:, None]) * inv[:, None]
    c1 = np.column_stack([np.abs(C[:, 1]), np.abs(C[:, -1])]) * inv[:, None]
    desc = _descriptor(c1.astype(complex), pos, neg)
    frame = np.column_stack([c0.real, c0.imag, size, phi])
    return desc, frame


def _flip(desc: Array) -> Array:
    """The other normalisation (``phi + pi``, ``s + pi``): every even harmonic changes sign."""
    out = desc.copy()
    K = HARMONICS - 1
    n = np.arange(2, HARMONICS + 1)
    sign = np.where(n % 2 == 0, -1.0, 1.0)
    for j in range(4):  # pos.real, pos.imag, neg.real, neg.imag blocks
        out[:, 2 + j * K : 2 + (j + 1) * K] *= sign
    return out


def _sample_linkages(rng: np.random.Generator, n: int) -> Array:
    """``n`` rows of crank, coupler, rocker, u, v, circuit (ground 1) whose crank turns fully, ratio <= MAX_RATIO."""
    out: list[Array] = []
    have = 0
    while have < n:
        m = 3 * (n - have) + 64
        L = np.exp(rng.uniform(np.log(1 / MAX_RATIO), np.log(MAX_RATIO), (m, 3)))
        allL = np.column_stack([np.ones(m), L])
        lo, hi = allL.min(1), allL.max(1)
        total = allL.sum(1)
        margin = 1e-3 * total
        grashof = lo + hi + margin <= total - lo - hi
        crank_or_ground = np.minimum(allL[:, 0], allL[:, 1]) + margin <= np.minimum(allL[:, 2], allL[:, 3])
        keep = grashof & crank_or_ground & (hi <= MAX_RATIO * lo)
        L = L[keep]
        k = len(L)
        u = L[:, 1] * rng.uniform(-1.5, 2.5, k)
        v = L[:, 1] * rng.uniform(-2.0, 2.0, k)
        circ = np.where(rng.random(k) < 0.5, 1.0, -1.0)
        out.append(np.column_stack([L, u, v, circ]))
        have += k
    return np.concatenate(out)[:n]


def _chunk(seed: int, index: int, n: int) -> tuple[Array, Array, Array]:
    rng = np.random.default_rng([seed, index])
    p = _sample_linkages(rng, n)
    X = np.column_stack([np.ones(n), p[:, :5], np.zeros((n, 3))])
    th = np.linspace(0.0, 2 * np.pi, CURVE_SAMPLES, endpoint=False)
    x, y, ok = coupler_points(X, th, p[:, 5], threads=1)
    desc, frame = describe(x + 1j * y)
    good = ok.all(1) & np.isfinite(desc).all(1) & (frame[:, 2] > 1e-9)
    return p[good], frame[good], desc[good]


#: bytes the build holds per entry beyond the entry itself (measured: see :func:`check_atlas_memory`)
BUILD_EXTRA_BYTES = 0.0
#: bytes of one chunk's temporaries in the build (solved curves, their resampling and FFT; tracemalloc measured
#: 299 MiB for a chunk of :data:`CHUNK` linkages, and 3e6 four-bars peaked at 680 MiB resident: 50 + 320 + 300)
CHUNK_BYTES = 320 * 2**20
#: bytes a search over the atlas holds per entry: the entry, its float64 descriptor and the k-d tree over it
SEARCH_BYTES = 400.0


def check_atlas_memory(where: str, size: int, search: bool = False) -> None:
    """:class:`~planar.errors.LimitError` (naming ``where`` and ``size``) before an atlas of ``size`` entries is
    built (``search=False``) or read and searched (``search=True``) beyond the memory limit (``PLANAR_MAX_MEMORY``).
    What this process already holds counts."""
    from planar.core.limits import check_memory, resident_bytes, units_within

    per = SEARCH_BYTES if search else ENTRY_BYTES + BUILD_EXTRA_BYTES
    fixed = resident_bytes() + (0.0 if search else CHUNK_BYTES)
    what = "an atlas search" if search else "an atlas build"
    check_memory(where, size, fixed + per * size, what, fits=f"{units_within(fixed, per):,} four-bars")


def build_atlas(size: int = DEFAULT_SIZE, seed: int = 0, progress: bool = False) -> Atlas:
    """Build an atlas of ``size`` four-bars (deterministic for ``size`` and ``seed``; see the module).

    ``progress``: show a progress bar (on standard error when it is a terminal).  About 25 s of CPU per
    million entries (:data:`BUILD_S_PER_MILLION`).
    """
    if size < 100:
        raise InputError("atlas size", size, "at least 100 four-bars")
    check_atlas_memory("atlas size", size)
    t0 = time.process_time()
    # the entries go straight into their float32 arrays a chunk at a time: the build holds the atlas once
    # (ENTRY_BYTES an entry) and one chunk's temporaries, not every chunk's float64 rows and their copies
    params = np.empty((size, 6), np.float32)
    frame = np.empty((size, 4), np.float32)
    desc = np.empty((size, 2 + 4 * (HARMONICS - 1)), np.float32)
    have, index = 0, 0
    bar = None
    if progress:
        from planar.core.progress import progress_bar

        bar = progress_bar(size, "atlas", "curve", unit_scale=True)
    while have < size:
        n = min(CHUNK, size - have)
        p, f, d = _chunk(seed, index, n)
        k = min(len(p), size - have)
        params[have : have + k], frame[have : have + k], desc[have : have + k] = p[:k], f[:k], d[:k]
        have += k
        index += 1
        if bar is not None:
            bar.update(k)
    if bar is not None:
        bar.close()
    return Atlas(params, frame, desc, seed, time.process_time() - t0)


def cache_dir() -> Path:
    """Where atlases are cached: ``PLANAR_CACHE_DIR`` if set, else the user's cache folder (platformdirs)."""
    env = os.environ.get("PLANAR_CACHE_DIR", "").strip()
    if env:
        return Path(env)
    import platformdirs

    return Path(platformdirs.user_cache_dir("planar", appauthor=False))


def atlas_path(size: int = DEFAULT_SIZE, seed: int = 0) -> Path:
    """The cache file of the atlas of ``size`` entries and ``seed``."""
    return cache_dir() / f"atlas-v{VERSION}-{size}-{seed}.npz"


#: bytes of one atlas entry on disk (float32: 6 parameters, 4 of frame, 2 + 4 (K - 1) descriptor numbers)
ENTRY_BYTES = 4 * (6 + 4 + 2 + 4 * (HARMONICS - 1))
#: CPU seconds of the build per million entries (measured: about 22 to 25 s)
BUILD_S_PER_MILLION = 25.0


def build_notice(size: int, path: str | Path) -> str:
    """The line printed before a first-use build: what is built, how big, where, and how to choose the place."""
    return (
        f"planar: building the coupler-curve atlas once ({size:,} four-bar curves, about "
        f"{max(1, round(size * BUILD_S_PER_MILLION / 1e6))} s of CPU, {size * ENTRY_BYTES / 1e6:.3g} MB on disk), "
        f"cached at {path}; "
        "later runs read it. Set PLANAR_CACHE_DIR to choose the folder, or build one with "
        "'planar synth atlas -o FILE' and pass --atlas FILE"
    )


_LOADED: dict[str, Atlas] = {}


def _stored_rows(path: str) -> int:
    """Entries of the atlas file ``path``, read from its ``params`` array's header (nothing loaded)."""
    import zipfile

    with zipfile.ZipFile(path) as zf, zf.open("params.npy") as fh:
        version = np.lib.format.read_magic(fh)
        read = np.lib.format.read_array_header_1_0 if version == (1, 0) else np.lib.format.read_array_header_2_0
        shape = read(fh)[0]
    return int(shape[0]) if shape else 0


def unreadable(e: Exception, path: str | None = None) -> str:
    """What was wrong with a file that is not an atlas (of curves or of arcs), in words (not the exception's class
    name); ``path``: the file, to tell one that is no archive at all (numpy's loader then speaks of pickles)."""
    import zipfile

    if isinstance(e, zipfile.BadZipFile) or (path is not None and os.path.isfile(path) and not zipfile.is_zipfile(path)):
        return "not a .npz archive"
    if isinstance(e, KeyError):
        return "an archive without the atlas arrays"
    if isinstance(e, OSError) and e.strerror:
        return e.strerror
    return " ".join(str(e).split())[:120] or "unreadable"


def read_atlas(path: str | Path) -> Atlas:
    """An atlas written by :meth:`Atlas.save`; raises :class:`InputError` naming the file if it is not one."""
    p = str(path)
    if p in _LOADED:
        return _LOADED[p]
    import zipfile

    try:
        rows = _stored_rows(p)
    except FileNotFoundError:
        raise InputError(p, "missing", "an atlas file written by planar synth atlas") from None
    except (KeyError, ValueError, OSError, zipfile.BadZipFile) as e:
        raise InputError(p, unreadable(e), "an atlas file written by planar synth atlas") from None
    check_atlas_memory(p, rows, search=True)  # from the file's header, before its arrays are read
    try:
        with np.load(p) as z:
            meta = z["meta"]
            if meta[:4].tolist() != [VERSION, HARMONICS, CURVE_SAMPLES, RESAMPLE]:
                raise InputError(p, f"atlas format {meta[:4].tolist()}", "an atlas of this planar (rebuild it)")
            a = Atlas(z["params"], z["frame"], z["desc"], int(meta[4]), float(z["seconds"]))
    except FileNotFoundError:
        raise InputError(p, "missing", "an atlas file written by planar synth atlas") from None
    except (KeyError, ValueError, OSError) as e:
        raise InputError(p, unreadable(e), "an atlas file written by planar synth atlas") from None
    _LOADED[p] = a
    return a


def load_atlas(size: int = DEFAULT_SIZE, seed: int = 0, progress: bool = False) -> Atlas:
    """The cached atlas of ``size`` entries, built and cached first if missing (see :func:`atlas_path`).

    When the cache folder cannot be written the atlas is kept in memory only.
    """
    path = atlas_path(size, seed)
    if path.exists():
        return read_atlas(path)
    if progress:
        import sys

        print(build_notice(size, path), file=sys.stderr, flush=True)
    a = build_atlas(size, seed, progress)
    try:
        a.save(path)
        _LOADED[str(path)] = a
    except (OSError, InputError) as e:  # an unwritable cache folder: the atlas is kept in memory only
        if progress:
            import sys

            why = e.strerror if isinstance(e, OSError) and e.strerror else " ".join(str(e).split())
            print(
                f"planar: note: the atlas could not be cached at {path} ({why}); it is kept for this run only "
                "and built again next time (set PLANAR_CACHE_DIR to a folder that can be written)",
                file=sys.stderr,
                flush=True,
            )
    return a


def _mirror(rows: Array) -> Array:
    """Candidate rows (kernel's 9 parameters and the circuit) mirrored across the x axis."""
    out = rows.copy()
    out[:, 5] *= -1.0  # v
    out[:, 7] *= -1.0  # y0
    out[:, 8] *= -1.0  # phi
    out[:, 9] *= -1.0  # circuit
    return out


def _place(atlas: Atlas, idx: NDArray[np.intp], wframe: Array) -> Array:
    """Atlas entries ``idx`` mapped onto a query described by ``wframe`` (centroid x, y, size, rotation)."""
    p = atlas.params[idx].astype(float)
    fr = atlas.frame[idx].astype(float)
    k = wframe[2] / fr[:, 2]
    psi = wframe[3] - fr[:, 3]
    e = np.exp(1j * psi)
    o2 = (wframe[0] + 1j * wframe[1]) - k * e * (fr[:, 0] + 1j * fr[:, 1])
    rows = np.column_stack(
        [k, k * p[:, 0], k * p[:, 1], k * p[:, 2], k * p[:, 3], k * p[:, 4], o2.real, o2.imag, np.angle(e), p[:, 5]]
    )
    return rows


def smooth_closed(z: NDArray[np.complex128], n: int = CURVE_SAMPLES) -> NDArray[np.complex128]:
    """``n`` points on the periodic cubic spline through the closed polygon ``z`` (parametrised by chord length).

    Sparse targets (8 of them) describe their curve better through the spline than through the polygon.
    """
    from scipy.interpolate import CubicSpline

    seg = np.abs(np.diff(z, append=z[:1]))
    if len(z) < 4 or np.any(seg <= 1e-12 * max(float(seg.max()), 1e-300)):
        return z
    s = np.concatenate([[0.0], np.cumsum(seg)])
    zz = np.append(z, z[0])
    cs = CubicSpline(s, np.column_stack([zz.real, zz.imag]), bc_type="periodic")
    q = cs(np.linspace(0.0, s[-1], n, endpoint=False))
    return np.asarray(q[:, 0] + 1j * q[:, 1])


def views(z: NDArray[np.complex128]) -> list[tuple[bool, NDArray[np.complex128]]]:
    """The four ways a query looks up points ``z`` (complex, in order): as given and reversed, plain and mirrored
    (conjugated), as ``(mirrored, points)``; rows found for a mirrored view are mirrored back (:func:`_mirror`)."""
    zc = np.conj(z)
    return [(False, z), (False, z[::-1]), (True, zc), (True, zc[::-1])]


def _both_normalisations(atlas: Atlas, d: Array, fr: Array, k: int) -> list[Array]:
    """The ``k`` nearest entries to a description ``d`` ``(1, D)`` (frame ``fr`` ``(1, 4)``) and to its other
    normalisation (turned half a turn, :func:`_flip`), each placed onto the query."""
    out = []
    for flipped in (False, True):
        q = _flip(d) if flipped else d
        wf = fr[0].copy()
        if flipped:
            wf[3] += np.pi
        _, idx = atlas.tree.query(q[0], k=min(k, len(atlas)))
        out.append(_place(atlas, np.atleast_1d(idx), wf))
    return out


def curve_candidates(atlas: Atlas, z: NDArray[np.complex128], k: int = 32) -> Array:
    """Four-bars whose curves are near the closed curve ``z`` (complex points in the crank's order, e.g. a
    refined four-bar's coupler curve), placed onto it: ``2 k`` rows as :func:`candidates` (both normalisations,
    not reversed or mirrored: an atlas curve runs the way its crank turns, as ``z`` does)."""
    d, fr = describe(np.asarray(z, complex)[None, :])
    if not np.isfinite(d).all():
        return np.empty((0, 10))
    return np.concatenate(_both_normalisations(atlas, d, fr, k))


def candidates(atlas: Atlas, targets: Array, k: int = 32) -> Array:
    """Four-bars near ``targets`` ``(N, 2)`` (ordered), as rows of the kernel's 9 parameters and the circuit.

    The targets are described as a closed curve (:func:`smooth_closed`), in both directions and mirrored, each description
    in both normalisations (see the module): ``8 k`` rows, nearest first within each query.
    """
    t = np.asarray(targets, float)
    out: list[Array] = []
    for mirrored, seq in views(t[:, 0] + 1j * t[:, 1]):
        d, fr = describe(smooth_closed(seq)[None, :])
        if np.isfinite(d).all():
            out.extend(_mirror(rows) if mirrored else rows for rows in _both_normalisations(atlas, d, fr, k))
    if not out:
        return np.empty((0, 10))
    return np.concatenate(out)
