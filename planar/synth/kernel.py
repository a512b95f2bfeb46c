"""The vectorised four-bar kernel: coupler points of a whole population of candidates at once.

A candidate is one row of a parameter array ``X`` ``(P, 9)``: ``ground, crank,
coupler, rocker`` (lengths, model units), ``u, v`` (the coupler point in the
coupler's frame: origin at the crank pin ``B``, x axis toward the rocker pin
``C``, as :class:`planar.linkages.FourBar`), and the placement ``x0, y0, phi``
(the crank pivot in the world and the angle of the ground line, radians,
counter-clockwise).  The crank angle ``theta`` is measured from the ground
line, so world crank angle = ``phi + theta``.  ``circuit`` is ``+1`` for
FourBar's ``"open"`` (``C`` to the left of the directed diagonal
``B -> O4``) and ``-1`` for ``"crossed"``.

The closed form avoids every trigonometric call per sample: with
``d = O4 - B``, ``L2 = |d|^2``, ``A = (coupler^2 - rocker^2 + L2) / 2``,
``C - B = (A d + s sqrt(coupler^2 L2 - A^2) perp(d)) / L2``; the coupler
point is ``B + (alpha d + beta perp(d))`` with ``alpha, beta`` from ``u, v``.
Candidates are processed in blocks that fit the cache, every operation an
array expression over ``(block, samples)``.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from planar.linkages.chunked import threads_default

__all__ = ["GRASHOF_MARGIN", "N_PARAMS", "PARAM_NAMES", "coupler_points", "row_points"]

Array = NDArray[np.float64]
Mask = NDArray[np.bool_]

#: the columns of a candidate row
PARAM_NAMES = ("ground", "crank", "coupler", "rocker", "u", "v", "x0", "y0", "phi")
N_PARAMS = len(PARAM_NAMES)

#: relative margin kept from a change-point (s + l = p + q) and from equal shortest links
GRASHOF_MARGIN = 1e-3

#: candidates per block (512 x 64 doubles: 256 kB per array, within the cache)
BLOCK = 512


def _block(X: Array, ct: Array, st: Array, circuit: Array) -> tuple[Array, Array, Mask]:
    """One block: ``ct, st`` are ``(S,)`` (shared crank angles) or ``(P, S)`` (per candidate).

    Worked in the world frame: the crank pin ``B = O2 + crank (cos(phi + theta), sin(phi + theta))``,
    ``d = O4 - B``; ``alpha`` and ``beta`` do not depend on the frame.  In-place operations keep
    the number of temporaries small.
    """
    r1, r2, r3, r4 = X[:, 0:1], X[:, 1:2], X[:, 2:3], X[:, 3:4]
    u, v = X[:, 4:5], X[:, 5:6]
    x0, y0, phi = X[:, 6:7], X[:, 7:8], X[:, 8:9]
    cp, sp = np.cos(phi), np.sin(phi)
    bx = (r2 * cp) * ct
    bx -= (r2 * sp) * st  # B - O2, world
    by = (r2 * sp) * ct
    by += (r2 * cp) * st
    dx = r1 * cp - bx  # O4 - B
    dy = r1 * sp - by
    L2 = r1 * r2 * ct
    L2 *= -2.0
    L2 += r1 * r1 + r2 * r2  # |O4 - B|^2 (law of cosines)
    A = 0.5 * L2
    A += 0.5 * (r3 * r3 - r4 * r4)
    h2 = (r3 * r3) * L2
    h2 -= A * A
    ok = h2 >= 0.0
    np.maximum(h2, 0.0, out=h2)
    w = np.sqrt(h2, out=h2)
    w *= circuit[:, None]
    np.maximum(L2, 1e-12 * (r1 * r1 + r2 * r2), out=L2)  # B on O4: invalid (h2 < 0), kept finite
    inv = np.reciprocal(L2, out=L2)
    inv *= 1.0 / r3
    # alpha = (u A - v w) / (r3 L2), beta = (u w + v A) / (r3 L2)
    alpha = u * A
    alpha -= v * w
    alpha *= inv
    beta = u * w
    beta += v * A
    beta *= inv
    px = alpha * dx
    px -= beta * dy
    px += bx
    px += x0
    py = alpha * dy
    py += beta * dx
    py += by
    py += y0
    return px, py, ok


def coupler_points(
    X: Array, theta: Array, circuit: Array | None = None, threads: int | None = None, dtype: type = np.float64
) -> tuple[Array, Array, Mask]:
    """World coupler points ``(x, y)`` each ``(P, S)`` and validity ``(P, S)``.

    ``theta`` is ``(S,)`` crank angles shared by every candidate or ``(P, S)``
    per candidate (radians from the ground line).  ``circuit`` ``(P,)`` of
    ``+1``/``-1`` (default all ``+1``, FourBar's open circuit).  An invalid
    sample (the dyad cannot close) has finite but meaningless coordinates.
    """
    X = np.asarray(X, dtype)
    P = X.shape[0]
    th: Array = np.asarray(theta, dtype)
    circ: Array = np.ones(P, dtype) if circuit is None else np.asarray(circuit, dtype)
    S = th.shape[-1]
    xs: Array = np.empty((P, S), dtype)
    ys: Array = np.empty((P, S), dtype)
    ok = np.empty((P, S), dtype=bool)
    shared = th.ndim == 1
    if shared:
        ct_all, st_all = np.cos(th), np.sin(th)

    def run(i: int) -> None:
        j = min(P, i + BLOCK)
        if shared:
            ct, st = ct_all, st_all
        else:
            ct, st = np.cos(th[i:j]), np.sin(th[i:j])
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):  # degenerate rows are marked invalid
            xs[i:j], ys[i:j], ok[i:j] = _block(X[i:j], ct, st, circ[i:j])

    starts = range(0, P, BLOCK)
    workers = min(threads_default(), len(starts)) if threads is None else max(1, threads)
    if workers <= 1 or P * S < 1 << 16:
        for i in starts:
            run(i)
    else:
        from concurrent.futures import ThreadPoolExecutor

        with ThreadPoolExecutor(workers) as pool:  # numpy releases the GIL inside each operation
            list(pool.map(run, starts))
    return xs, ys, ok


def row_points(row: Array, theta: Array) -> Array:
    """The coupler points ``(N, 2)`` (world units) of one candidate ``row`` (the 9 parameters and a tenth column whose
    sign is the circuit) at its own crank angles ``theta`` ``(N,)`` (radians from the ground line)."""
    x, y, _ = coupler_points(
        np.asarray(row, float)[None, :N_PARAMS], np.asarray(theta, float)[None, :], np.array([1.0 if row[9] >= 0 else -1.0])
    )
    return np.column_stack([x[0], y[0]])
