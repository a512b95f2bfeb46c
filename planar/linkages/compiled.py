"""Compiled (numba) chunk kernels behind :meth:`Linkage.solve` for large batches.

The same solve as :mod:`planar.linkages.chunked` (same chunks with a
three-sample overlap, same branch screen, same validity), with every node
kind's arithmetic fused into one compiled loop over a chunk instead of one
numpy pass per operation, and every part's pose and named point written in
the same pass.  One function (:func:`solve_range`) is compiled once for every
linkage: the linkage is handed to it as a small program (a kind code, up to
three referenced nodes and up to six numbers per node, see :data:`ENCODERS`),
so a new linkage costs no compilation; ``cache=True`` keeps the machine code
between processes.

Arithmetic: circle-circle, line-circle, rigid points and placement are the
numpy path's expressions in the numpy path's order (no fast-math, no fused
multiply-add), so validity is decided by the same comparisons.  Two
functions differ from numpy's by rounding only: the crank's cosine and sine
(fdlibm's polynomial kernels after a three-part Cody-Waite reduction, for
``|angle| <= 2**19 pi / 2``, else the C library's) and ``atan2`` (fdlibm's
``atan`` polynomial after an exact-quadrant reduction); both are within a few
units in the last place, and branch-free, so the compiler vectorises them.

The kernels release the GIL (``nogil``): :func:`planar.linkages.chunked.fast_solve`
runs one range of chunks per thread of its pool, as the numpy path does.
Importing this module needs numba; :mod:`planar.linkages.chunked` imports it
only when a batch is large enough to use it.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np
from numba import njit
from numpy.typing import NDArray

from planar.core.geometry import CONCENTRIC, TANGENCY_RTOL
from planar.linkages.plan import _Plan

__all__ = ["ENCODERS", "SCREEN", "Program", "poses_range", "program_for", "solve_range"]

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]
BoolArray = NDArray[np.bool_]

FIXED, CRANK, ACTUATOR, RRR, RRP, RIGID = range(6)
#: kinds whose node has two roots (the branch screen runs on them)
TWO_ROOT = (RRR, RRP)
#: kinds whose node can fail to close (a validity row each)
CHECKED = (RRR, RRP, RIGID)

_RTOL = TANGENCY_RTOL
_CONCENTRIC = CONCENTRIC
_TINY = float(np.finfo(float).tiny)
#: the finite screen's bound on a node's coordinates (model units): below it every difference of two
#: coordinates, every placed coordinate (placement offsets below it too) and so every atan2 is finite
SCREEN = 1e300

# Cody-Waite pi/2 in three parts of 33 bits (fdlibm's pio2_1, pio2_2, pio2_2t): exact products
# n * part for |n| < 2**20
_INVPIO2 = 6.36619772367581382433e-01
_PIO2_1 = 1.57079632673412561417e00
_PIO2_2 = 6.07710050630396597660e-11
_PIO2_2T = 2.02226624879595063154e-21
#: largest ``|angle|`` the polynomial sine and cosine take (beyond: the C library's)
SINCOS_MAX = 2.0**19 * math.pi / 2
_S1, _S2, _S3 = -1.66666666666666324348e-01, 8.33333333332248946124e-03, -1.98412698298579493134e-04
_S4, _S5, _S6 = 2.75573137070700676789e-06, -2.50507602534068634195e-08, 1.58969099521155010221e-10
_C1, _C2, _C3 = 4.16666666666666019037e-02, -1.38888888888741095749e-03, 2.48015872894767294178e-05
_C4, _C5, _C6 = -2.75573143513906633035e-07, 2.08757232129817482790e-09, -1.13596475577881948265e-11
# fdlibm atan: polynomial for |x| < 7/16, pi/4 split in a high and a low part
_AT = (
    3.33333333333329318027e-01,
    -1.99999999998764832476e-01,
    1.42857142725034663711e-01,
    -1.11111104054623557880e-01,
    9.09088713343650656196e-02,
    -7.69187620504482999495e-02,
    6.66107313738753120669e-02,
    -5.83357013379057348645e-02,
    4.97687799461593236017e-02,
    -3.65315727442169155270e-02,
    1.62858201153657823623e-02,
)
_AT0, _AT1, _AT2, _AT3, _AT4, _AT5, _AT6, _AT7, _AT8, _AT9, _AT10 = _AT
_PIO4_HI, _PIO4_LO = 7.85398163397448278999e-01, 3.06161699786838301793e-17
_PIO2_HI, _PIO2_LO = 1.57079632679489655800e00, 6.12323399573676603587e-17
_PI_HI, _PI_LO = 3.14159265358979311600e00, 1.22464679914735317720e-16
_TAN_PI8 = 0.41421356237309503  # tan(pi/8)

_JIT: dict[str, Any] = {"cache": True, "nogil": True, "error_model": "numpy"}
#: the polynomial kernels may fuse multiply-adds (they differ from the C library by rounding anyway)
_JIT_POLY: dict[str, Any] = {**_JIT, "fastmath": {"contract"}}


@njit(**_JIT_POLY)
def _sincos(a: float) -> tuple[float, float]:
    """``(sin a, cos a)`` for ``|a| <= SINCOS_MAX``, branch-free."""
    n = math.floor(a * _INVPIO2 + 0.5)
    r = ((a - n * _PIO2_1) - n * _PIO2_2) - n * _PIO2_2T
    z = r * r
    s = r + z * r * (_S1 + z * (_S2 + z * (_S3 + z * (_S4 + z * (_S5 + z * _S6)))))
    c = 1.0 - (0.5 * z - z * z * (_C1 + z * (_C2 + z * (_C3 + z * (_C4 + z * (_C5 + z * _C6))))))
    m = n - 4.0 * math.floor(n * 0.25)  # quadrant 0..3
    odd = (m == 1.0) | (m == 3.0)
    sa = c if odd else s
    ca = s if odd else c
    sa = -sa if m >= 2.0 else sa
    ca = -ca if (m == 1.0) | (m == 2.0) else ca
    return sa, ca


@njit(**_JIT_POLY)
def _atan2(y: float, x: float) -> float:
    """``atan2(y, x)`` in ``[-pi, pi]``, signs of zeros as the C library's, branch-free."""
    ax, ay = abs(x), abs(y)
    swap = ay > ax
    num = ax if swap else ay
    den = ay if swap else ax
    big = num > _TAN_PI8 * den
    top = num - den if big else num
    bot = num + den if big else den
    bot = 1.0 if bot == 0.0 else bot  # atan2(0, 0)
    t = top / bot  # |t| <= tan(pi/8) < 7/16
    z = t * t
    w = z * z
    s1 = z * (_AT0 + w * (_AT2 + w * (_AT4 + w * (_AT6 + w * (_AT8 + w * _AT10)))))
    s2 = w * (_AT1 + w * (_AT3 + w * (_AT5 + w * (_AT7 + w * _AT9))))
    r = (_PIO4_HI - ((t * (s1 + s2) - _PIO4_LO) - t)) if big else (t - t * (s1 + s2))
    r = (_PIO2_HI - r) + _PIO2_LO if swap else r
    r = (_PI_HI - r) + _PI_LO if math.copysign(1.0, x) < 0.0 else r
    return math.copysign(r, y)


# ------------------------------------------------------------------ node kinds on one chunk window


@njit(**_JIT)
def _k_fixed(par: FloatArray, L: int, xo: FloatArray, yo: FloatArray) -> None:
    x, y = par[0], par[1]
    for i in range(L):
        xo[i] = x
        yo[i] = y


@njit(**_JIT)
def _k_crank(par: FloatArray, q: FloatArray, L: int, xc: FloatArray, yc: FloatArray, xo: FloatArray, yo: FloatArray) -> None:
    r, phase = par[0], par[1]
    big = 0
    for i in range(L):
        a = q[i] + phase
        big += abs(a) > SINCOS_MAX
        s, c = _sincos(a)  # finite (and unused) beyond SINCOS_MAX
        xo[i] = r * c + xc[i]
        yo[i] = r * s + yc[i]
    if big:
        for i in range(L):
            a = q[i] + phase
            xo[i] = r * math.cos(a) + xc[i]
            yo[i] = r * math.sin(a) + yc[i]


@njit(**_JIT)
def _k_actuator(par: FloatArray, q: FloatArray, L: int, xs: FloatArray, ys: FloatArray, xo: FloatArray, yo: FloatArray) -> None:
    ux, uy, off = par[0], par[1], par[2]
    for i in range(L):
        s = q[i] + off
        xo[i] = s * ux + xs[i]
        yo[i] = s * uy + ys[i]


@njit(**_JIT)
def _rrr_sample(dx: float, dy: float, s2: float, f2: float, tiny: float, hb: float) -> tuple[bool, float, float, float]:
    """One sample of :func:`_k_rrr` from the centres' offset ``(dx, dy)``: whether the circles meet, the
    clamped Heron product ``(s^2 - d^2)(d^2 - f^2)``, ``1 / d^2`` (1 for concentric centres) and the
    half-chord factor ``t`` (signed by the branch)."""
    d2 = dx * dx + dy * dy
    prod = (s2 - d2) * (d2 - f2)
    scale = max(s2, d2)
    good = (prod >= -_RTOL * scale * scale) & (d2 > tiny)
    d2 = 1.0 if d2 <= tiny else d2
    prod = max(prod, 0.0)
    inv = 1.0 / d2
    return good, prod, inv, math.sqrt(prod) * inv * hb


@njit(**_JIT)
def _k_rrr(
    par: FloatArray,
    L: int,
    xa: FloatArray,
    ya: FloatArray,
    xb: FloatArray,
    yb: FloatArray,
    xo: FloatArray,
    yo: FloatArray,
    ok: BoolArray,
    sep: FloatArray,
) -> int:
    """Circle-circle as the numpy path (``chunked._rrr``); returns the number of samples that fail."""
    ra, rb, branch = par[0], par[1], par[2]
    # scale-free as the numpy path: outside 1e-60..1e60 lengths are taken times k, a power of two
    # near 1 / (ra + rb) (exact: the same bits as unscaled where nothing overflows)
    span = ra + rb
    k = 1.0 if 1e-60 < span < 1e60 else math.ldexp(1.0, -math.frexp(span)[1])
    ra, rb = ra * k, rb * k
    s = ra + rb
    f = ra - rb
    s2, f2 = s * s, f * f
    tiny = _CONCENTRIC * s2
    hb = 0.5 * branch
    hr = 0.5 * (f * s)  # (ra^2 - rb^2) without cancellation, as the numpy path
    fails = 0
    if k == 1.0:
        for i in range(L):
            dx = xb[i] - xa[i]
            dy = yb[i] - ya[i]
            good, prod, inv, t = _rrr_sample(dx, dy, s2, f2, tiny, hb)
            ok[i] = good
            fails += not good
            sep[i] = prod * inv
            fr = inv * hr + 0.5
            xo[i] = (fr * dx + xa[i]) - t * dy
            yo[i] = (fr * dy + ya[i]) + t * dx
        return fails
    for i in range(L):
        dx = (xb[i] - xa[i]) * k
        dy = (yb[i] - ya[i]) * k
        good, prod, inv, t = _rrr_sample(dx, dy, s2, f2, tiny, hb)
        ok[i] = good
        fails += not good
        sep[i] = prod * inv / (k * k)
        fr = inv * hr + 0.5
        dx /= k  # back to model units (exact)
        dy /= k
        xo[i] = (fr * dx + xa[i]) - t * dy
        yo[i] = (fr * dy + ya[i]) + t * dx
    return fails


@njit(**_JIT)
def _k_rrp(
    par: FloatArray,
    L: int,
    xa: FloatArray,
    ya: FloatArray,
    xp: FloatArray,
    yp: FloatArray,
    xq: FloatArray,
    yq: FloatArray,
    xo: FloatArray,
    yo: FloatArray,
    ok: BoolArray,
    sep: FloatArray,
) -> int:
    """Line-circle as :func:`planar.core.geometry.line_circle` (the numpy path's ``chunked._rrp``)."""
    ra, branch, off = par[0], par[1], par[2]
    # scale-free as line_circle: ra and e times the power of two nearest 1 / ra (exact: the same bits
    # where nothing overflows), so the squares hold from 1e-300 to 1e300
    k = math.ldexp(1.0, -math.frexp(abs(ra))[1])
    rk = ra * k
    fails = 0
    for i in range(L):
        ux = xq[i] - xp[i]
        uy = yq[i] - yp[i]
        un = math.hypot(ux, uy)
        ok_u = un > 0.0
        un = un if ok_u else 1.0
        bx = xp[i] + off * -uy / un
        by = yp[i] + off * ux / un
        ex = ux / un
        ey = uy / un
        wx = xa[i] - bx
        wy = ya[i] - by
        s0 = wx * ex + wy * ey
        e = (ex * wy - ey * wx) * k
        h2 = (rk - e) * (rk + e)
        scale = max(rk * rk, e * e)
        good = (h2 >= -_RTOL * max(scale, _TINY)) & ok_u
        ok[i] = good
        fails += not good
        h = math.sqrt(max(h2, 0.0)) / k
        sk = s0 + branch * h
        so = s0 + -branch * h
        kx, ky = bx + sk * ex, by + sk * ey
        ox, oy = bx + so * ex, by + so * ey
        xo[i] = kx
        yo[i] = ky
        sep[i] = (kx - ox) ** 2 + (ky - oy) ** 2
    return fails


@njit(**_JIT)
def _k_rigid(
    par: FloatArray,
    L: int,
    xa: FloatArray,
    ya: FloatArray,
    xb: FloatArray,
    yb: FloatArray,
    xo: FloatArray,
    yo: FloatArray,
    ok: BoolArray,
) -> int:
    u, v = par[0], par[1]
    fails = 0
    for i in range(L):
        ex = xb[i] - xa[i]
        ey = yb[i] - ya[i]
        en = math.sqrt(ex * ex + ey * ey)
        fails += (en <= 0.0) | (en == math.inf)  # coincident, under- or overflow: again below
        inv = 1.0 / en
        ex *= inv
        ey *= inv
        ok[i] = True
        xo[i] = (ex * u - ey * v) + xa[i]
        yo[i] = (ey * u + ex * v) + ya[i]
    if fails:  # coincident nodes or an underflow: again, as the reference (hypot)
        fails = 0
        for i in range(L):
            ex = xb[i] - xa[i]
            ey = yb[i] - ya[i]
            en = math.hypot(ex, ey)
            good = en > 0.0
            ok[i] = good
            fails += not good
            inv = 1.0 / (en if good else 1.0)
            ex *= inv
            ey *= inv
            xo[i] = (ex * u - ey * v) + xa[i]
            yo[i] = (ey * u + ex * v) + ya[i]
    return fails


@njit(**_JIT)
def _may_switch(
    x: FloatArray, y: FloatArray, ok: BoolArray, sep: FloatArray, tol: float, q: FloatArray, first: int, L: int
) -> bool:
    """``chunked._may_switch`` on one window: a vectorised count, then the path test where it is not zero.

    (Indices are offsets from slices, never ``k - 1``: a possibly negative index costs numba a
    wraparound test that stops the loop from being vectorised.)
    """
    t2 = tol * tol
    m = L - first
    x0, x1, x2, x3 = x[first:], x[first - 1 :], x[first - 2 :], x[first - 3 :]
    y0, y1, y2, y3 = y[first:], y[first - 1 :], y[first - 2 :], y[first - 3 :]
    o0, o1, o2, o3 = ok[first:], ok[first - 1 :], ok[first - 2 :], ok[first - 3 :]
    s = sep[first:]
    cand = 0
    for k in range(m):
        ex = x0[k] - 3.0 * x1[k] + 3.0 * x2[k] - x3[k]
        ey = y0[k] - 3.0 * y1[k] + 3.0 * y2[k] - y3[k]
        hist = o1[k] & o2[k] & o3[k]
        cand += o0[k] & ((4.0 * (ex * ex + ey * ey) + t2 >= s[k]) | (not hist))
    if cand == 0:
        return False
    q0, q1, q2, q3 = q[first:], q[first - 1 :], q[first - 2 :], q[first - 3 :]
    for k in range(m):
        ex = x0[k] - 3.0 * x1[k] + 3.0 * x2[k] - x3[k]
        ey = y0[k] - 3.0 * y1[k] + 3.0 * y2[k] - y3[k]
        hist = o1[k] & o2[k] & o3[k]
        if o0[k] and ((not hist) or 4.0 * (ex * ex + ey * ey) + t2 >= s[k]):
            # chunked._path_ok: the three driver steps into sample k share a sign, within 1.5x
            a, b, c = q2[k] - q3[k], q1[k] - q2[k], q0[k] - q1[k]
            same = ((a > 0) & (b > 0) & (c > 0)) | ((a < 0) & (b < 0) & (c < 0))
            a, b, c = abs(a), abs(b), abs(c)
            if same and max(a, max(b, c)) <= 1.5 * min(a, min(b, c)):
                return True
    return False


@njit(**_JIT)
def _may_switch_closed(
    x: FloatArray, y: FloatArray, ok: BoolArray, sep: FloatArray, tol: float, q: FloatArray, first: int, L: int
) -> bool:
    """:func:`_may_switch` for a window where every sample closes (no validity to read): the count
    of candidates alone, then :func:`_may_switch` itself where it is not zero."""
    t2 = tol * tol
    m = L - first
    x0, x1, x2, x3 = x[first:], x[first - 1 :], x[first - 2 :], x[first - 3 :]
    y0, y1, y2, y3 = y[first:], y[first - 1 :], y[first - 2 :], y[first - 3 :]
    s = sep[first:]
    cand = 0
    for k in range(m):
        ex = x0[k] - 3.0 * x1[k] + 3.0 * x2[k] - x3[k]
        ey = y0[k] - 3.0 * y1[k] + 3.0 * y2[k] - y3[k]
        cand += 4.0 * (ex * ex + ey * ey) + t2 >= s[k]
    if cand == 0:
        return False
    return _may_switch(x, y, ok, sep, tol, q, first, L)


@njit(**_JIT)
def _k_pose(
    xo: FloatArray,
    yo: FloatArray,
    xa: FloatArray,
    ya: FloatArray,
    xb: FloatArray,
    yb: FloatArray,
    m: int,
    pl: FloatArray,
    P: FloatArray,
) -> int:
    """Pose rows ``P[:m]`` from node windows of length ``m``: origin, ``atan2`` of ``a -> b``, placement.

    Returns how many rows hold a non-finite number (counted as they are written: the
    caller's finite screen needs no second pass over the output)."""
    px, py, pa, c, s = pl[0], pl[1], pl[2], pl[3], pl[4]
    F = P.ravel()
    bad = 0
    if pa == 0.0 and px == 0.0 and py == 0.0:
        for i in range(m):
            u, v = xo[i], yo[i]
            w = _atan2(yb[i] - ya[i], xb[i] - xa[i])
            F[3 * i] = u
            F[3 * i + 1] = v
            F[3 * i + 2] = w
            bad += not math.isfinite(u + v + w)
    else:
        for i in range(m):
            u = (px + xo[i] * c) - yo[i] * s
            v = (py + xo[i] * s) + yo[i] * c
            w = _atan2(yb[i] - ya[i], xb[i] - xa[i]) + pa
            F[3 * i] = u
            F[3 * i + 1] = v
            F[3 * i + 2] = w
            bad += not math.isfinite(u + v + w)
    return bad


@njit(**_JIT)
def _k_point(x: FloatArray, y: FloatArray, m: int, pl: FloatArray, out: FloatArray) -> int:
    """Named point rows ``out[:m]``; returns how many hold a non-finite number."""
    px, py, pa, c, s = pl[0], pl[1], pl[2], pl[3], pl[4]
    F = out.ravel()
    bad = 0
    if pa == 0.0 and px == 0.0 and py == 0.0:
        for i in range(m):
            u, v = x[i], y[i]
            F[2 * i] = u
            F[2 * i + 1] = v
            bad += not math.isfinite(u + v)
    else:
        for i in range(m):
            u = (px + x[i] * c) - y[i] * s
            v = (py + x[i] * s) + y[i] * c
            F[2 * i] = u
            F[2 * i + 1] = v
            bad += not math.isfinite(u + v)
    return bad


@njit(**_JIT)
def _finite(q: FloatArray, lo: int, hi: int) -> bool:
    """Whether every ``q[lo:hi]`` is finite (a vectorised count)."""
    bad = 0
    for i in range(lo, hi):
        bad += not math.isfinite(q[i])
    return bad == 0


@njit(**_JIT)
def _k_store(x: FloatArray, y: FloatArray, m: int, out: FloatArray) -> int:
    """Node rows ``out[:m]`` (x and y side by side); returns how many the finite screen flags (a
    coordinate beyond :data:`SCREEN`, or not a number)."""
    F = out.ravel()
    bad = 0
    for i in range(m):
        u, v = x[i], y[i]
        F[2 * i] = u
        F[2 * i + 1] = v
        bad += not ((abs(u) <= SCREEN) & (abs(v) <= SCREEN))
    return bad


@njit(**_JIT)
def _store_nodes(X: FloatArray, Y: FloatArray, off: int, m: int, store: IntArray, nodes: FloatArray, i: int) -> int:
    """Every written node's window ``X[nd, off:off + m]`` into ``nodes[store[nd], i:i + m]``; the screen's count."""
    bad = 0
    for nd in range(store.shape[0]):
        if store[nd] >= 0:
            bad += _k_store(X[nd, off:], Y[nd, off:], m, nodes[store[nd], i : i + m])
    return bad


@njit(**_JIT)
def poses_range(
    nodes: FloatArray,
    fixed: FloatArray,
    store: IntArray,
    links: IntArray,
    pl: FloatArray,
    poses: FloatArray,
    lo: int,
    hi: int,
    chunk: int,
) -> int:
    """Pose rows ``poses[j, lo:hi]`` of every moving part from the node rows :func:`solve_range` wrote.

    ``store[i]``: node ``i``'s row in ``nodes`` (-1: a fixed node, at
    ``fixed[i]``); ``links`` ``(m, 3)``: origin, direction from, direction to
    of each moving part (node indices).  The arithmetic is :func:`_k_pose`'s on
    the same numbers, so the poses are the same bits as if written while
    solving.  Returns how many rows hold a non-finite number.
    """
    nn = store.shape[0]
    W = max(1, min(chunk, hi - lo))
    X = np.empty((nn, W))
    Y = np.empty((nn, W))
    for nd in range(nn):
        if store[nd] < 0:
            for t in range(W):
                X[nd, t] = fixed[nd, 0]
                Y[nd, t] = fixed[nd, 1]
    bad = 0
    for i in range(lo, hi, chunk):
        j = min(i + chunk, hi)
        m = j - i
        for nd in range(nn):
            r = store[nd]
            if r >= 0:
                F = nodes[r, i:j].ravel()
                xr, yr = X[nd], Y[nd]
                for t in range(m):
                    xr[t] = F[2 * t]
                    yr[t] = F[2 * t + 1]
        for li in range(links.shape[0]):
            o, a, b = links[li, 0], links[li, 1], links[li, 2]
            bad += _k_pose(X[o], Y[o], X[a], Y[a], X[b], Y[b], m, pl, poses[li, i:j])
    return bad


@njit(**_JIT)
def solve_range(
    q: FloatArray,
    lo: int,
    hi: int,
    chunk: int,
    kinds: IntArray,
    refs: IntArray,
    par: FloatArray,
    tols: FloatArray,
    check_row: IntArray,
    store: IntArray,
    pts: IntArray,
    pl: FloatArray,
    nodes: FloatArray,
    points: FloatArray,
    oks: BoolArray,
    fails: IntArray,
    bad_chunks: BoolArray,
) -> int:
    """Solve samples ``lo:hi`` chunk by chunk; returns -1 where a driver value is not finite or a
    branch may switch (then it stops early), else the number of node and point rows the finite
    screen flags.

    ``kinds[i]``, ``refs[i]``, ``par[i]``: node ``i``'s kind code, referenced
    nodes and numbers (:data:`ENCODERS`); ``tols[i]`` its branch-screen
    tolerance; ``check_row[i]`` its row in ``oks`` (-1: it cannot fail).
    ``store[i]``: node ``i``'s row in ``nodes`` ``(s, n, 2)`` (its positions
    in the linkage's frame; -1: not written); ``pts`` the node of each named
    point written to ``points[j]`` ``(n, 2)`` with placement ``pl`` (``x, y,
    angle, cos, sin``).  A node row is flagged where a coordinate is beyond
    :data:`SCREEN` (or not a number): below it every pose and point computed
    from the nodes is finite.  ``fails[row]`` counts the samples of this range
    that fail; ``oks[row]`` is written only for the chunks where a sample fails
    (marked in ``bad_chunks``, indexed by sample // chunk).
    """
    if not _finite(q, lo, hi):
        return -1
    nn = kinds.shape[0]
    W = min(chunk, hi - lo) + 3
    X = np.empty((nn, W))
    Y = np.empty((nn, W))
    OK = np.ones((nn, W), dtype=np.bool_)
    sep = np.empty(W)
    nonfinite = 0
    for i in range(lo, hi, chunk):
        j = min(i + chunk, hi)
        ws = max(0, i - 3)
        off = i - ws
        L = j - ws
        first = max(3, off)
        m = j - i
        qw = q[ws:j]
        bad = 0
        for nd in range(nn):
            k = kinds[nd]
            r = refs[nd]
            p = par[nd]
            xo, yo, ok = X[nd], Y[nd], OK[nd]
            nf = 0
            if k == FIXED:
                if i == lo:  # a fixed node's rows never change
                    _k_fixed(p, W, xo, yo)
            elif k == CRANK:
                _k_crank(p, qw, L, X[r[0]], Y[r[0]], xo, yo)
            elif k == ACTUATOR:
                _k_actuator(p, qw, L, X[r[0]], Y[r[0]], xo, yo)
            elif k == RRR:
                nf = _k_rrr(p, L, X[r[0]], Y[r[0]], X[r[1]], Y[r[1]], xo, yo, ok, sep)
            elif k == RRP:
                nf = _k_rrp(p, L, X[r[0]], Y[r[0]], X[r[1]], Y[r[1]], X[r[2]], Y[r[2]], xo, yo, ok, sep)
            else:
                nf = _k_rigid(p, L, X[r[0]], Y[r[0]], X[r[1]], Y[r[1]], xo, yo, ok)
            if k in (RRR, RRP):
                if nf == 0:
                    switch = _may_switch_closed(xo, yo, ok, sep, tols[nd], qw, first, L)
                else:
                    switch = _may_switch(xo, yo, ok, sep, tols[nd], qw, first, L)
                if switch:
                    return -1
            if nf and check_row[nd] >= 0:
                okw = ok[off:]
                cnt = 0
                for t in range(m):
                    cnt += not okw[t]
                fails[check_row[nd]] += cnt
                bad += cnt
        if bad:  # validity rows only for chunks where a sample fails
            bad_chunks[i // chunk] = True
            for nd in range(nn):
                row = check_row[nd]
                if row >= 0:
                    okw = OK[nd, off:]
                    o = oks[row, i:j]
                    for t in range(m):
                        o[t] = okw[t]
        nonfinite += _store_nodes(X, Y, off, m, store, nodes, i)
        for pi in range(pts.shape[0]):
            nonfinite += _k_point(X[pts[pi], off:], Y[pts[pi], off:], m, pl, points[pi, i:j])
    return nonfinite


# ------------------------------------------------------------------ programs

#: per node kind name: ``encode(node, index) -> (code, refs, numbers)``; a kind without an
#: encoder is solved by the numpy path
ENCODERS: dict[str, Callable[[Any, dict[str, int]], tuple[int, tuple[int, ...], tuple[float, ...]]]] = {
    "fixed": lambda nd, ix: (FIXED, (), (float(nd.xy[0]), float(nd.xy[1]))),
    "crank": lambda nd, ix: (CRANK, (ix[nd.centre],), (float(nd.radius), float(nd.phase))),
    "actuator": lambda nd, ix: (ACTUATOR, (ix[nd.origin],), (float(nd.unit_axis[0]), float(nd.unit_axis[1]), float(nd.offset))),
    "rrr": lambda nd, ix: (RRR, (ix[nd.a], ix[nd.b]), (float(nd.ra), float(nd.rb), float(nd.branch))),
    "rrp": lambda nd, ix: (RRP, (ix[nd.a], ix[nd.p], ix[nd.q]), (float(nd.ra), float(nd.branch), float(nd.offset))),
    "rigid": lambda nd, ix: (RIGID, (ix[nd.a], ix[nd.b]), (float(nd.local[0]), float(nd.local[1]))),
}


class Program:
    """A linkage's plan as arrays for :func:`solve_range`, with what the warm path reuses on every call."""

    def __init__(
        self,
        kinds: IntArray,
        refs: IntArray,
        par: FloatArray,
        check_row: IntArray,
        links: IntArray,
        pts: IntArray,
        pl: FloatArray,
        plan: _Plan,
    ) -> None:
        self.kinds, self.refs, self.par, self.check_row = kinds, refs, par, check_row
        self.links, self.pl = links, pl
        self.n_links, self.n_checks = int(links.shape[0]), len(plan.checks)
        #: each part in the plan's order with its row of the pose block (-1: the ground)
        moving = [name for name, o, _, _ in plan.links if o >= 0]
        self.parts = [(name, moving.index(name) if o >= 0 else -1) for name, o, _, _ in plan.links]
        self.pt_names = [name for name, _ in plan.points]
        # the nodes written while solving: every node a moving part or a named point reads but a fixed
        # one a part reads (the poses take those from ``fixed``)
        used = {int(i) for i in links.ravel()}
        named = {int(i) for i in pts}
        keep = [i for i in range(kinds.shape[0]) if i in named or (i in used and kinds[i] != FIXED)]
        self.store = np.full(kinds.shape[0], -1, np.int64)
        self.store[keep] = np.arange(len(keep))
        self.n_store = len(keep)
        self.fixed = np.ascontiguousarray(par[:, :2])
        #: no placement: a named point is its node's row (no copy); else the kernels write it placed
        self.unplaced = bool(pl[0] == 0.0 and pl[1] == 0.0 and pl[2] == 0.0)
        self.pt_rows = [int(self.store[i]) for i in pts]
        self.pts = np.zeros(0, np.int64) if self.unplaced else pts
        self.n_pts = int(self.pts.shape[0])
        self.no_points = np.empty((0, 1, 2))
        self.solve_range = solve_range
        #: a node moves with ``|q|`` (its tolerance depends on the batch)
        self.grows = any(plan.grows)
        #: the branch-screen tolerances when no node moves with ``|q|`` (as ``chunked._tols``)
        self.tol = np.array([1e-9 * (1.0 + b) for b in plan.bound])
        row = np.array(plan.placement, dtype=float)
        row.flags.writeable = False
        self._ground_row = row
        self._ground_last: FloatArray | None = None
        #: the placement within the finite screen (else the poses are computed and screened at once)
        self.screened = bool(abs(pl[0]) <= SCREEN and abs(pl[1]) <= SCREEN)

    def ground_pose(self, n: int) -> FloatArray:
        """The ground's track: the placement row seen ``n`` times (read-only, no memory; the last one kept)."""
        last = self._ground_last
        if last is None or last.shape[0] != n:
            last = np.ndarray((n, 3), dtype=float, buffer=self._ground_row, strides=(0, 8))
            self._ground_last = last
        return last


def program_for(plan: _Plan) -> Program | None:
    """The program of a plan, or ``None`` when a node kind has no encoder."""
    index = {nd.name: i for i, nd in enumerate(plan.nodes)}
    nn = len(plan.nodes)
    kinds = np.zeros(nn, np.int64)
    refs = np.zeros((nn, 3), np.int64)
    par = np.zeros((nn, 6))
    for i, nd in enumerate(plan.nodes):
        enc = ENCODERS.get(type(nd).kind)
        if enc is None:
            return None
        code, rr, pp = enc(nd, index)
        kinds[i] = code
        refs[i, : len(rr)] = rr
        par[i, : len(pp)] = pp
    check_row = np.full(nn, -1, np.int64)
    for row, (i, _, _) in enumerate(plan.checks):
        check_row[i] = row
    if sorted(i for i, _, _ in plan.checks) != [i for i in range(nn) if kinds[i] in CHECKED]:
        return None  # the reference checks other nodes than the kernels report: keep the numpy path
    links = np.array([(o, a, b) for _, o, a, b in plan.links if o >= 0], np.int64).reshape(-1, 3)
    pts = np.array([i for _, i in plan.points], np.int64)
    px, py, pa = plan.placement
    pl = np.array([px, py, pa, float(np.cos(pa)), float(np.sin(pa))])  # as the numpy path
    return Program(kinds, refs, par, check_row, links, pts, pl, plan)
