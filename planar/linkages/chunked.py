"""The fast path behind :meth:`Linkage.solve`: chunked, threaded, branch screen.

The reference solve (:meth:`Linkage.solve_nodes`) places each node for all
samples at once and carries every two-root node's branch by continuity
(:func:`~planar.linkages.nodes.carry_branch`).  This module gives the same
motion faster:

* samples are processed in chunks of :data:`CHUNK` (cache-sized) with
  preallocated per-thread buffers and ufunc ``out=`` arguments; coordinates
  are kept as separate x and y arrays (a fixed node stays a float);
* chunks run on a thread pool (numpy releases the GIL inside its ufuncs);
  every sample's arithmetic is independent of the chunking, so the result does
  not depend on the number of threads;
* the branch continuity check runs only where it can matter.  The motion
  switches to the other root at sample ``k`` only if the quadratic
  extrapolation of the node's previous three samples misses the declared root
  by more than 0.8 of the distance ``sep`` between the roots; that miss (the
  third difference) is at most 4 times the node's largest step in the chunk,
  and a step is at most ``sqrt(2) m`` with ``m`` the largest coordinate
  change.  A chunk where ``128 m^2 + tol^2 < min sep^2`` (``tol`` = 1e-9 of a
  bound on the node's coordinates, above any rounding) and every sample closes
  needs no check; otherwise the third differences are tested sample by
  sample, and a sample that may switch (or follows an invalid one on a path)
  sends the whole batch to the reference solve, which then decides exactly as
  before;
* link angles are one ``arctan2`` per moving link; named points are the nodes'
  positions (no pose round trip; at a failing sample, where a part's frame may
  degenerate, through the part's pose as the reference); validity is merged
  only when a sample fails.

Node kinds without a chunk kernel here (a kind registered elsewhere) make
:func:`fast_solve` return ``None``: the caller uses the reference path.
"""

from __future__ import annotations

import functools
import math
import os
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from itertools import count, pairwise
from threading import Lock
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from planar.core.buffers import MIN_BYTES as _BLOCK_MIN
from planar.core.buffers import block as _pool_block
from planar.core.geometry import CONCENTRIC, TANGENCY_RTOL, line_circle, poses_apply
from planar.core.model import FinitePoses, LazyPoses
from planar.linkages.plan import Linkage, NodeKind, _Plan

if TYPE_CHECKING:
    from planar.linkages.compiled import Program

__all__ = [
    "CHUNK",
    "JIT_CHUNK",
    "JIT_MIN",
    "JIT_THREADS_MIN",
    "KERNELS",
    "Solved",
    "compiled_ready",
    "fast_solve",
    "jit_available",
    "plan_for",
    "solve_compiled",
    "solver_for",
    "threads_default",
]

Array = NDArray[np.float64]
Mask = NDArray[np.bool_]
Coord = Array | float
#: a kernel's result: x, y, validity (None: no check, True: all close) and,
#: for a two-root node, the squared distance between its roots
Placed = tuple[Coord, Coord, "Mask | bool | None", "Array | None"]

#: what a solve returns: poses, validity checks (None: every sample closes), named points
Solved = tuple[dict[str, Array], "list[tuple[Mask, str, str]] | None", "dict[str, Array] | None"]

#: samples per chunk: the working set of a chunk stays in the L2 cache
CHUNK = 8192
#: a plan's program not built yet
_NO_PROGRAM: object = object()
#: samples at the start of a chunk recomputed from the previous chunk (branch screen history)
_OVERLAP = 3


class Scratch:
    """Per-thread scratch buffers of one chunk's length, handed out in turn."""

    def __init__(self, size: int) -> None:
        self.size = size
        self.bufs: list[Array] = []
        self.i = 0
        self.n = size
        self.pair: Array | None = None

    def reset(self, n: int) -> None:
        self.i = 0
        self.n = n

    def get(self) -> Array:
        if self.i == len(self.bufs):
            self.bufs.append(np.empty(self.size))
        b = self.bufs[self.i]
        self.i += 1
        return b[: self.n]

    def get2(self) -> Array:
        """A ``(2, n)`` buffer (kept apart from :meth:`get`'s)."""
        if self.pair is None:
            self.pair = np.empty((2, self.size))
        return self.pair[:, : self.n]


Kernel = Callable[["NodeKind", dict[str, tuple[Coord, Coord]], Array, Scratch, Array, Array], Placed]
#: chunk kernels by node kind name: ``kernel(node, pos, q, scratch, out_x, out_y)``
KERNELS: dict[str, Kernel] = {}


def _kernel(kind: str) -> Callable[[Kernel], Kernel]:
    def reg(fn: Kernel) -> Kernel:
        KERNELS[kind] = fn
        return fn

    return reg


@_kernel("fixed")
def _fixed(node: Any, pos: dict[str, tuple[Coord, Coord]], q: Array, w: Scratch, ox: Array, oy: Array) -> Placed:
    return float(node.xy[0]), float(node.xy[1]), None, None


@_kernel("crank")
def _crank(node: Any, pos: dict[str, tuple[Coord, Coord]], q: Array, w: Scratch, ox: Array, oy: Array) -> Placed:
    # cos and sin by the tangent half-angle: t = tan(a/2), cos = (1 - t^2)/(1 + t^2),
    # sin = 2t/(1 + t^2); tan of a double stays finite (at most ~1e16 near pi/2)
    cx, cy = pos[node.centre]
    r = node.radius
    t, t2 = w.get(), w.get()
    if node.phase:
        np.add(q, node.phase, out=t)
        t *= 0.5
    else:
        np.multiply(q, 0.5, out=t)
    np.tan(t, out=t)
    np.multiply(t, t, out=t2)
    np.subtract(1.0, t2, out=ox)
    t2 += 1.0
    np.reciprocal(t2, out=t2)
    ox *= t2
    ox *= r
    np.multiply(t, t2, out=oy)
    oy *= 2.0 * r
    if not (isinstance(cx, float) and cx == 0.0):
        ox += cx
    if not (isinstance(cy, float) and cy == 0.0):
        oy += cy
    return ox, oy, None, None


@_kernel("actuator")
def _actuator(node: Any, pos: dict[str, tuple[Coord, Coord]], q: Array, w: Scratch, ox: Array, oy: Array) -> Placed:
    ux, uy = (float(v) for v in node.unit_axis)
    sx, sy = pos[node.origin]
    s = w.get()
    np.add(q, node.offset, out=s)
    np.multiply(s, ux, out=ox)
    ox += sx
    np.multiply(s, uy, out=oy)
    oy += sy
    return ox, oy, None, None


@_kernel("rrr")
def _rrr(node: Any, pos: dict[str, tuple[Coord, Coord]], q: Array, w: Scratch, ox: Array, oy: Array) -> Placed:
    """Circle-circle as :func:`planar.core.geometry.circle_circle` (same validity, bit for bit)."""
    ax, ay = pos[node.a]
    bx, by = pos[node.b]
    # scale-free: outside 1e-60..1e60, where fourth powers of lengths leave float64, lengths are taken
    # times k, a power of two near 1 / (ra + rb): exact, so the same bits as unscaled where nothing overflows
    span = node.ra + node.rb
    k = 1.0 if 1e-60 < span < 1e60 else math.ldexp(1.0, -math.frexp(span)[1])
    ra, rb = node.ra * k, node.rb * k
    s, f = ra + rb, ra - rb
    s2, f2 = s * s, f * f
    dx, dy, d2, t, prod = w.get(), w.get(), w.get(), w.get(), w.get()
    np.subtract(bx, ax, out=dx)
    np.subtract(by, ay, out=dy)
    if k != 1.0:
        dx *= k
        dy *= k
    np.multiply(dx, dx, out=d2)
    np.multiply(dy, dy, out=t)
    d2 += t
    np.subtract(s2, d2, out=prod)
    np.subtract(d2, f2, out=t)
    prod *= t  # 4 d^2 h^2
    ok: Mask | bool = True
    # every sample closes when the product clears -rtol s2^2 (the threshold -rtol max(s2, d2)^2
    # is lower) and d > 0; at d = 0 the product is -s2 f2, below that unless the radii are equal
    tiny = CONCENTRIC * s2
    if d2.size and (float(prod.min()) < -TANGENCY_RTOL * s2 * s2 or float(d2.min()) <= tiny):
        scale = np.maximum(s2, d2)
        ok = (prod >= -TANGENCY_RTOL * scale * scale) & (d2 > tiny)
        d2[d2 <= tiny] = 1.0  # concentric: invalid, kept finite as the reference does
    np.maximum(prod, 0.0, out=prod)
    np.reciprocal(d2, out=d2)  # 1 / d^2
    np.sqrt(prod, out=t)
    t *= d2
    t *= 0.5 * node.branch  # branch * h / d
    prod *= d2  # sep^2 = 4 h^2 = prod / d^2
    d2 *= 0.5 * (f * s)  # (ra^2 - rb^2) without cancellation (see geometry.circle_circle)
    d2 += 0.5  # fraction along a -> b
    if k != 1.0:
        dx /= k  # back to model units (exact)
        dy /= k
        prod /= k * k
    m = w.get()
    np.multiply(d2, dx, out=ox)
    ox += ax
    np.multiply(t, dy, out=m)
    ox -= m
    np.multiply(d2, dy, out=oy)
    oy += ay
    np.multiply(t, dx, out=m)
    oy += m
    return ox, oy, ok, prod


def _column(v: Coord, n: int) -> Array:
    return np.broadcast_to(np.asarray(v, float), (n,))


@_kernel("rrp")
def _rrp(node: Any, pos: dict[str, tuple[Coord, Coord]], q: Array, w: Scratch, ox: Array, oy: Array) -> Placed:
    """Line-circle through the reference functions (not on the benchmarked paths)."""
    n = q.shape[0]
    st = {k: np.column_stack([_column(pos[k][0], n), _column(pos[k][1], n)]) for k in (node.a, node.p, node.q)}
    p0, p1 = st[node.p], st[node.q]
    u = p1 - p0
    un = np.hypot(u[:, 0], u[:, 1])[:, None]
    base = p0 + node.offset * np.stack([-u[:, 1], u[:, 0]], -1) / np.where(un > 0, un, 1.0)
    keep, ok, _ = line_circle(base, u, st[node.a], node.ra, node.branch)
    other, _, _ = line_circle(base, u, st[node.a], node.ra, -node.branch)
    ox[:] = keep[:, 0]
    oy[:] = keep[:, 1]
    sep2 = ((keep - other) ** 2).sum(-1)
    return ox, oy, (True if ok.all() else ok), sep2


@_kernel("rigid")
def _rigid(node: Any, pos: dict[str, tuple[Coord, Coord]], q: Array, w: Scratch, ox: Array, oy: Array) -> Placed:
    ax, ay = pos[node.a]
    bx, by = pos[node.b]
    ex, ey, en, m = w.get(), w.get(), w.get(), w.get()
    np.subtract(bx, ax, out=ex)
    np.subtract(by, ay, out=ey)
    np.multiply(ex, ex, out=en)
    np.multiply(ey, ey, out=m)
    en += m
    np.sqrt(en, out=en)
    ok: Mask | bool = True
    if en.size and (float(en.min()) <= 0.0 or float(en.max()) == math.inf):  # coincident, under- or overflow
        h = np.hypot(ex, ey)
        ok = h > 0
        en[:] = np.where(ok, h, 1.0)
    np.reciprocal(en, out=en)
    ex *= en
    ey *= en
    u, v = (float(c) for c in node.local)
    np.multiply(ex, u, out=ox)
    np.multiply(ey, u, out=oy)
    if v:
        np.multiply(ey, v, out=m)
        ox -= m
        np.multiply(ex, v, out=m)
        oy += m
    ox += ax
    oy += ay
    return ox, oy, ok, None


# ------------------------------------------------------------------ the plan


#: per node kind: (node, bound from its refs, grows from its refs, bounds, grows, index) -> (bound, grows),
#: a bound on the node's ``|coordinate|`` at ``q = 0`` and whether it moves with ``|q|`` (downstream of an actuator)
BOUNDS: dict[str, Callable[..., tuple[float, bool]]] = {
    "fixed": lambda nd, b, g, bound, grows, index: (float(np.hypot(*nd.xy)), g),
    "crank": lambda nd, b, g, bound, grows, index: (b + nd.radius, g),
    "actuator": lambda nd, b, g, bound, grows, index: (b + abs(nd.offset), True),
    "rrr": lambda nd, b, g, bound, grows, index: (bound[index[nd.a]] + nd.ra, grows[index[nd.a]]),
    "rrp": lambda nd, b, g, bound, grows, index: (bound[index[nd.a]] + nd.ra, grows[index[nd.a]]),
    "rigid": lambda nd, b, g, bound, grows, index: (b + float(np.hypot(*nd.local)), g),
}


def plan_for(lk: Linkage) -> _Plan | None:
    """The fast-solve plan of ``lk``, or ``None`` when a node kind has no chunk kernel or bound."""
    kernels = []
    for nd in lk.nodes:
        k = KERNELS.get(type(nd).kind)
        if k is None or type(nd).kind not in BOUNDS:
            return None
        kernels.append(k)
    index = {nd.name: i for i, nd in enumerate(lk.nodes)}
    _, ref_checks = lk.solve_nodes(np.zeros(1))
    checks = [(index[node], node, why) for _, node, why in ref_checks]
    links: list[tuple[str, int, int, int]] = []
    for link in lk.links:
        if link.name == lk.ground_name:
            links.append((link.name, -1, -1, -1))
            continue
        d = link.guide if link.guide is not None else (link.nodes[0], link.nodes[1])
        links.append((link.name, index[link.nodes[0]], index[d[0]], index[d[1]]))
    bound: list[float] = []
    grows: list[bool] = []
    for nd in lk.nodes:
        refs = [index[r] for r in nd.refs()]
        b = max((bound[i] for i in refs), default=0.0)
        g = any(grows[i] for i in refs)
        b, g = BOUNDS[type(nd).kind](nd, b, g, bound, grows, index)
        bound.append(b)
        grows.append(g)
    return _Plan(
        list(lk.nodes),
        kernels,
        checks,
        links,
        [(p, index[n]) for p, n in lk.point_nodes.items()],
        (lk.placement[0], lk.placement[1], lk.placement[2]),
        bound,
        grows,
        _NO_PROGRAM,
    )


# ------------------------------------------------------------------ solving


_POOL: ThreadPoolExecutor | None = None


def _forget_pool() -> None:
    """In a forked child the parent's pool threads do not exist: make a new pool on next use."""
    global _POOL
    _POOL = None


if hasattr(os, "register_at_fork"):
    os.register_at_fork(after_in_child=_forget_pool)


def _pool() -> ThreadPoolExecutor:
    global _POOL
    if _POOL is None:
        _POOL = ThreadPoolExecutor(max_workers=_cores(), thread_name_prefix="planar-solve")
    return _POOL


@functools.cache
def _cores() -> int:
    """The machine's cores, asked once (``os.cpu_count`` reads the system's files: tens of microseconds)."""
    return os.cpu_count() or 1


def threads_default() -> int:
    """Threads the fast solve uses: ``PLANAR_THREADS`` if set, else the number of cores."""
    env = os.environ.get("PLANAR_THREADS", "").strip()
    if not env:
        return _cores()
    try:
        n = int(env)
    except ValueError:
        n = 0
    if n < 1:
        from planar.errors import InputError

        raise InputError("PLANAR_THREADS", env, "a positive whole number of threads (unset: every core)")
    return n


def _path_ok(q: Array, k: NDArray[np.intp]) -> Mask:
    """``path_mask(q)[k]`` for the samples ``k`` (>= 3) only."""
    a, b, c = q[k - 2] - q[k - 3], q[k - 1] - q[k - 2], q[k] - q[k - 1]
    same = ((a > 0) & (b > 0) & (c > 0)) | ((a < 0) & (b < 0) & (c < 0))
    mag = np.abs(np.stack([a, b, c]))
    return same & (mag.max(0) <= 1.5 * mag.min(0))


def _may_switch(xy: Array, ok: Mask | bool, sep2: Array, tol: float, q: Array, first: int, w: Scratch) -> bool:
    """Whether a two-root node may leave its declared root at a window sample ``k >= first``.

    ``xy`` ``(2, n)`` holds the node's declared-root positions over the window,
    ``q`` the driver values (same window), ``first`` >= 3 the first sample to
    test.  Conservative: ``False`` guarantees that :func:`carry_branch` flips
    nothing there.
    """
    n = xy.shape[1]
    if n <= first:
        return False
    x, y = xy
    if ok is True:
        d = w.get2()[:, : n - 1]
        np.subtract(xy[:, 1:], xy[:, :-1], out=d)
        step = max(float(d.max()), -float(d.min()))  # |step| <= sqrt(2) * step
        if 128.0 * step * step + tol * tol < float(sep2[first:].min()):
            return False
        valid = np.ones(n, bool)
    else:
        valid = np.asarray(ok)
    k = np.arange(first, n)
    ex = x[k] - 3.0 * x[k - 1] + 3.0 * x[k - 2] - x[k - 3]
    ey = y[k] - 3.0 * y[k - 1] + 3.0 * y[k - 2] - y[k - 3]
    hist = valid[k - 1] & valid[k - 2] & valid[k - 3]
    cand = valid[k] & (~hist | (4.0 * (ex * ex + ey * ey) + tol * tol >= sep2[k]))
    ks = k[cand]
    return bool(ks.size and _path_ok(q, ks).any())


@dataclass
class _ChunkOut:
    masks: list[Mask | None]  # per check, None: all samples close
    switch: bool  # a branch may switch: use the reference solve


def _solve_range(
    plan: _Plan, q: Array, lo: int, hi: int, chunk: int, poses: dict[str, Array], points: dict[str, Array], tols: list[float]
) -> list[_ChunkOut]:
    """Solve samples ``lo:hi`` chunk by chunk into ``poses`` and ``points``."""
    size = min(chunk, hi - lo) + _OVERLAP
    w = Scratch(size)
    nxy = [np.empty((2, size)) for _ in plan.nodes]  # x and y rows of each node
    px, py, pa = plan.placement
    placed = bool(px or py or pa)
    c, s = float(np.cos(pa)), float(np.sin(pa))
    out: list[_ChunkOut] = []
    for i in range(lo, hi, chunk):
        j = min(i + chunk, hi)
        start = max(0, i - _OVERLAP)
        off = i - start
        L = j - start
        qw = q[start:j]
        pos: dict[str, tuple[Coord, Coord]] = {}
        oks: dict[int, Mask | bool] = {}
        switch = False
        for idx, (nd, kern) in enumerate(zip(plan.nodes, plan.kernels)):
            w.reset(L)
            x, y, ok, sep2 = kern(nd, pos, qw, w, nxy[idx][0, :L], nxy[idx][1, :L])
            pos[nd.name] = (x, y)
            if ok is not None:
                oks[idx] = ok
            if sep2 is not None and not switch:
                assert isinstance(x, np.ndarray) and isinstance(y, np.ndarray) and ok is not None
                w.reset(L)
                switch = _may_switch(nxy[idx][:, :L], ok, sep2, tols[idx], qw, max(_OVERLAP, off), w)
        masks: list[Mask | None] = []
        for idx, _, _ in plan.checks:
            ok = oks[idx]
            masks.append(None if isinstance(ok, bool) or bool(np.all(ok[off:])) else np.array(ok[off:]))
        out.append(_ChunkOut(masks, switch))
        if switch:
            break
        # link poses and named points (placement applied)
        w.reset(L - off)
        for name, o, a, b in plan.links:
            if o < 0:
                continue
            P = poses[name]
            ax_, ay_ = pos[plan.nodes[a].name]
            bx_, by_ = pos[plan.nodes[b].name]
            dx, dy = w.get(), w.get()
            np.subtract(_tail(bx_, off), _tail(ax_, off), out=dx)
            np.subtract(_tail(by_, off), _tail(ay_, off), out=dy)
            ang = P[i:j, 2]
            np.arctan2(dy, dx, out=ang)
            ox_, oy_ = pos[plan.nodes[o].name]
            _place(_tail(ox_, off), _tail(oy_, off), P[i:j, 0], P[i:j, 1], placed, px, py, c, s, w)
            if pa:
                ang += pa
            w.reset(L - off)
        for name, nidx in plan.points:
            x, y = pos[plan.nodes[nidx].name]
            pt = points[name]
            _place(_tail(x, off), _tail(y, off), pt[i:j, 0], pt[i:j, 1], placed, px, py, c, s, w)
            w.reset(L - off)
    return out


def _tail(v: Coord, off: int) -> Coord:
    return v[off:] if isinstance(v, np.ndarray) else v


def _place(x: Coord, y: Coord, ox: Array, oy: Array, placed: bool, px: float, py: float, c: float, s: float, w: Scratch) -> None:
    """``(ox, oy) = placement applied to (x, y)``, as :func:`planar.core.geometry.poses_compose`."""
    if not placed:
        ox[...] = x
        oy[...] = y
        return
    m = w.get()
    np.multiply(x, c, out=m)
    np.add(px, m, out=ox)
    np.multiply(y, s, out=m)
    ox -= m
    np.multiply(x, s, out=m)
    np.add(py, m, out=oy)
    np.multiply(y, c, out=m)
    oy += m


def fast_solve(
    lk: Linkage,
    q: Array,
    threads: int | None = None,
    chunk: int | None = None,
    jit: bool | None = None,
    program: Program | None = None,
    lazy: bool = False,
) -> Solved | None:
    """``(poses, checks, points)`` for driver values ``q`` by the chunked path, or ``None``.

    ``None``: a node kind has no kernel, or a branch may switch by continuity
    somewhere (the caller then solves by the reference path).  ``checks`` is
    ``None`` when every sample closes, else the reference's
    ``[(mask, node, why)]``.  ``jit``: ``True`` the compiled kernels
    (:mod:`planar.linkages.compiled`, needs numba), ``False`` the numpy
    kernels, ``None`` the compiled ones for at least :data:`JIT_MIN` samples
    when numba is installed and ``PLANAR_JIT`` is not ``0``.  ``chunk``:
    samples per chunk (default :data:`CHUNK`, compiled :data:`JIT_CHUNK`).
    ``program``: the plan's compiled program when the caller has it already
    (:func:`compiled_ready`): the compiled kernels are taken without asking again.  ``lazy``: the
    compiled kernels may hand over the poses as :class:`~planar.core.model.LazyPoses` (see
    :func:`solve_compiled`).
    """
    plan = lk._fast_plan()
    if plan is None:
        return None
    n = q.shape[0]
    prog = program if program is not None else (_program(plan) if _use_jit(jit, n) else None)
    if prog is not None:
        return solve_compiled(lk, plan, prog, q, threads, chunk, lazy)
    tols = _tols(plan, q)
    nthreads = threads if threads is not None else threads_default()
    chunk = chunk or CHUNK
    poses: dict[str, Array] = {}
    _px, _py, _pa = plan.placement
    for name, o, _, _ in plan.links:
        if o < 0:
            poses[name] = _ground_pose(n, plan.placement)
        else:
            poses[name] = np.empty((n, 3))
    points = {name: np.empty((n, 2)) for name, _ in plan.points}
    nchunks = -(-n // chunk) if n else 0
    if nthreads > 1 and nchunks >= 2:
        futs = [_pool().submit(_solve_range, plan, q, a, b, chunk, poses, points, tols) for a, b in _cuts(n, chunk, nthreads)]
        results = [r for f in futs for r in f.result()]
    else:
        results = _solve_range(plan, q, 0, n, chunk, poses, points, tols)
    if any(r.switch for r in results):
        return None
    checks: list[tuple[Mask, str, str]] | None = None
    if any(m is not None for r in results for m in r.masks):
        checks = []
        for c_i, (_, node, why) in enumerate(plan.checks):
            full = np.ones(n, bool)
            for r, (a, b) in zip(results, _chunk_bounds(n, chunk)):
                m = r.masks[c_i]
                if m is not None:
                    full[a:b] = m
            checks.append((full, node, why))
    return _finish(lk, poses, checks, points)


def _tols(plan: _Plan, q: Array) -> list[float]:
    """Each node's branch-screen tolerance: 1e-9 of a bound on its coordinates over ``q``."""
    qmax = float(np.abs(q).max()) if q.shape[0] and any(plan.grows) else 0.0
    return [1e-9 * (1.0 + b + (qmax if g else 0.0)) for b, g in zip(plan.bound, plan.grows)]


def _ground_pose(n: int, placement: tuple[float, float, float]) -> Array:
    """The ground never moves: one row seen ``n`` times (read-only), as :meth:`Mechanism.solve` returns it."""
    return np.broadcast_to(np.array(placement, dtype=float), (n, 3))


def _cuts(n: int, chunk: int, nthreads: int) -> list[tuple[int, int]]:
    """``nthreads`` (at most one per chunk) ranges of whole chunks covering ``0:n``."""
    nchunks = -(-n // chunk)
    nthreads = min(nthreads, nchunks)
    cuts = [chunk * (nchunks * t // nthreads) for t in range(nthreads)] + [n]
    return list(pairwise(cuts))


def _finish(lk: Linkage, poses: dict[str, Array], checks: list[tuple[Mask, str, str]] | None, points: dict[str, Array]) -> Solved:
    """Where a sample fails a frame may degenerate (two nodes meet): there the named points
    are taken through the part's pose, as the reference does."""
    if checks is not None:
        bad = ~np.logical_and.reduce([m for m, _, _ in checks])
        if bad.any():
            for name, (part, xy) in lk.points.items():
                points[name][bad] = poses_apply(poses[part][bad], xy)
    return poses, checks, points


# ------------------------------------------------------------------ the compiled path

#: smallest batch the compiled kernels take by default (below it the numpy path is as quick
#: as importing numba and loading the kernels once)
JIT_MIN = 0
#: samples per chunk of the compiled kernels (measured on one thread, Jansen's leg: 1e6 samples 17.5 ms
#: in chunks of 8,192 against 20.1 ms in chunks of 2,048, 1e5 samples 1.98 against 2.14 ms; the
#: four-bar the same within the noise; the result does not depend on it)
JIT_CHUNK = 8192
#: smallest batch the compiled path splits over threads by default: below it a solve takes a few
#: milliseconds, and waking the pool's threads costs more processor time than a second core saves
#: (measured on 2 shared cores: the four-bar at 1e5 samples 15.5 ns a sample on one thread, 19.7 on two)
JIT_THREADS_MIN = 1 << 18
#: ranges of chunks per thread the compiled path hands out (balancing threads slowed by other load)
JIT_RANGES_PER_THREAD = 4


def jit_available() -> bool:
    """Whether the compiled kernels can be used (numba installed and ``PLANAR_JIT`` is not ``0``)."""
    if os.environ.get("PLANAR_JIT", "1") == "0":
        return False
    if _NUMBA[0] is None:
        try:
            import numba  # noqa: F401
        except ImportError:
            _NUMBA[0] = False
        else:
            _NUMBA[0] = True
    return bool(_NUMBA[0])


#: whether numba imports (None: not tried yet)
_NUMBA: list[bool | None] = [None]


def solver_for(lk: Linkage, n: int) -> str:
    """Which kernels :meth:`Linkage.solve` takes for ``n`` samples where no branch may switch:
    ``"compiled"``, ``"numpy"`` or ``"reference"`` (a node kind without a chunk kernel)."""
    plan = lk._fast_plan()
    if plan is None:
        return "reference"
    return "compiled" if compiled_ready(plan, n) is not None else "numpy"


def compiled_ready(plan: _Plan, n: int) -> Program | None:
    """The compiled program :func:`fast_solve` runs for ``n`` samples of ``plan``, or ``None`` (numba off or
    missing, or a node kind without an encoder); the first call imports numba and loads the kernels."""
    return _program(plan) if _use_jit(None, n) else None


def _use_jit(jit: bool | None, n: int) -> bool:
    if jit is None:
        return n >= JIT_MIN and jit_available()
    return jit


def _program(plan: _Plan) -> Program | None:
    """The plan's compiled program (built once), or ``None`` when a node kind has no encoder."""
    if plan.program is _NO_PROGRAM:
        from planar.linkages.compiled import program_for

        plan.program = program_for(plan)
    return plan.program


def solve_compiled(
    lk: Linkage,
    plan: _Plan,
    prog: Program,
    q: Array,
    threads: int | None = None,
    chunk: int | None = None,
    lazy: bool = False,
) -> Solved | None:
    """:func:`fast_solve` by the compiled kernels, for a caller that has the plan and its program
    (:func:`compiled_ready`): the tolerances are the plan's own unless a node moves with ``|q|``, and a
    batch of one chunk takes one thread.  ``lazy``: the poses as :class:`~planar.core.model.LazyPoses`
    (computed from the nodes' positions on first access) wherever the finite screen allows it."""
    chunk = chunk or JIT_CHUNK
    tols = _tols(plan, q) if prog.grows else None
    n = q.shape[0]
    if threads is not None:
        nthreads = 1 if n <= chunk else threads
    elif n < JIT_THREADS_MIN:
        nthreads = 1
    else:  # PLANAR_THREADS is read (and checked) on every call where threads may run
        nthreads = threads_default()
    return _solve_compiled(lk, plan, prog, q, tols, nthreads, chunk, lazy)


def _solve_compiled(
    lk: Linkage, plan: _Plan, prog: Program, q: Array, tols: list[float] | None, nthreads: int, chunk: int, lazy: bool
) -> Solved | None:
    """The compiled solve: one call of :func:`~planar.linkages.compiled.solve_range` per range of chunks.

    The kernels write every node's position (and, for a placed linkage, the
    named points); the poses come from the nodes afterwards
    (:func:`_poses_from_nodes`), at once or, ``lazy``, on first access.  The
    warm path of a small batch (one range) is a handful of array
    allocations and one compiled call; the plan's constant arrays are built
    once (:func:`~planar.linkages.compiled.program_for`).
    """
    n = q.shape[0]
    if q.dtype != np.float64 or not q.flags.c_contiguous:
        q = np.ascontiguousarray(q, dtype=float)
    nbytes = n * 8 * (2 * prog.n_store + 2 * prog.n_pts)
    new_block = np.empty if nbytes < _BLOCK_MIN else _pool_block
    nodes = new_block((prog.n_store, n, 2))
    pblock = new_block((prog.n_pts, n, 2)) if prog.n_pts else prog.no_points
    oks = new_block((prog.n_checks, n), bool)
    tol = prog.tol if tols is None else np.asarray(tols, dtype=float)
    nchunks = -(-n // chunk)
    bad_chunks = np.zeros(nchunks, dtype=bool)
    if nthreads <= 1 or nchunks <= 1:
        fails = np.zeros(prog.n_checks, dtype=np.int64)
        found = prog.solve_range(q, 0, n, chunk, prog.kinds, prog.refs, prog.par, tol, prog.check_row, prog.store,
                                 prog.pts, prog.pl, nodes, pblock, oks, fails, bad_chunks)  # fmt: skip
    else:
        fails, founds = _solve_threaded(prog, q, tol, nthreads, chunk, nodes, pblock, oks, bad_chunks)
        found = -1 if min(founds) < 0 else sum(founds)
    if found < 0:
        return None
    if prog.unplaced:
        points = {name: nodes[r] for name, r in zip(prog.pt_names, prog.pt_rows)}
    else:
        points = {name: pblock[i] for i, name in enumerate(prog.pt_names)}
    closes = not any(fails.ravel().tolist())  # fails: per range and check, or per check
    poses: dict[str, Array]
    if lazy and closes and prog.screened and not found:
        poses = LazyPoses(functools.partial(_poses_from_nodes, prog, nodes, nthreads), len(prog.parts))
    else:
        poses = _poses_from_nodes(prog, nodes, nthreads)
        if found and not (isinstance(poses, FinitePoses) and all(np.isfinite(v).all() for v in points.values())):
            poses = dict(poses)  # non-finite numbers: Mechanism.solve looks at every one
    if closes:  # every sample closes
        return poses, None, points
    oks[:, ~np.repeat(bad_chunks, chunk)[:n]] = True  # chunks where every sample closes
    checks = [(oks[row], node, why) for row, (_, node, why) in enumerate(plan.checks)]
    return _finish(lk, poses, checks, {k: v.copy() for k, v in points.items()})


#: samples per chunk of the poses computed from the nodes (measured: Jansen's leg, 1e5 samples, 2.2 ms
#: against 2.6 ms in chunks of 2,048; the result does not depend on it)
POSES_CHUNK = 8192


def _poses_from_nodes(prog: Program, nodes: Array, nthreads: int, chunk: int = POSES_CHUNK) -> dict[str, Array]:
    """Every part's poses from the nodes' positions (:func:`~planar.linkages.compiled.poses_range`):
    a :class:`FinitePoses` when every number is finite."""
    poses_range = _compiled().poses_range
    n = nodes.shape[1]
    new_block = np.empty if n * 24 * prog.n_links < _BLOCK_MIN else _pool_block
    block = new_block((prog.n_links, n, 3))
    ranges = _cuts(n, chunk, nthreads * JIT_RANGES_PER_THREAD) if nthreads > 1 and n > chunk else [(0, n)]

    def run(r: tuple[int, int]) -> int:
        return int(poses_range(nodes, prog.fixed, prog.store, prog.links, prog.pl, block, r[0], r[1], chunk))

    bad = sum(_pool().map(run, ranges)) if len(ranges) > 1 else run(ranges[0])
    ground = prog.ground_pose(n)
    poses: dict[str, Array] = FinitePoses() if not bad else {}
    for name, row in prog.parts:
        poses[name] = ground if row < 0 else block[row]
    return poses


def _compiled() -> Any:
    """The compiled kernels' module (imported on first use: it imports numba)."""
    mod = _COMPILED[0]
    if mod is None:
        from planar.linkages import compiled as mod

        _COMPILED[0] = mod
    return mod


#: :mod:`planar.linkages.compiled` once imported
_COMPILED: list[Any] = [None]


def _solve_threaded(
    prog: Program, q: Array, tol: Array, nthreads: int, chunk: int, nodes: Array, pblock: Array, oks: Mask, bad_chunks: Mask
) -> tuple[NDArray[np.int64], list[int]]:
    """:func:`_solve_compiled` over ranges of chunks taken in turn by ``nthreads`` threads of the pool.

    Returns the failure counts per range and check, and per range -1 where a branch may
    switch, else its count of non-finite pose and point rows.
    """
    from planar.linkages.compiled import solve_range

    n = q.shape[0]
    # more ranges than threads, taken in turn by each thread: a thread slowed by other work on
    # the machine leaves its share to the others (the result does not depend on the ranges)
    ranges = _cuts(n, chunk, nthreads * JIT_RANGES_PER_THREAD)
    fails = np.zeros((len(ranges), prog.n_checks), dtype=np.int64)
    found = [0] * len(ranges)
    taken, lock = count(), Lock()

    def work() -> None:
        while True:
            with lock:
                t = next(taken)
            if t >= len(ranges) or min(found) < 0:
                return
            a, b = ranges[t]
            found[t] = int(
                solve_range(
                    q,
                    a,
                    b,
                    chunk,
                    prog.kinds,
                    prog.refs,
                    prog.par,
                    tol,
                    prog.check_row,
                    prog.store,
                    prog.pts,
                    prog.pl,
                    nodes,
                    pblock,
                    oks,
                    fails[t],
                    bad_chunks,
                )
            )

    workers = min(nthreads, len(ranges))
    if workers > 1:
        for f in [_pool().submit(work) for _ in range(workers)]:
            f.result()
    else:
        work()
    return fails, found


def _chunk_bounds(n: int, chunk: int) -> list[tuple[int, int]]:
    return [(i, min(i + chunk, n)) for i in range(0, n, chunk)]
