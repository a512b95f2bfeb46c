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

__all__ = ["N_PARAMS", "coupler_points", "PARAM_NAMES"]

Array = NDArray[np.float64]
Mask = NDArray[np.bool_]

#: the columns of a candidate row
PARAM_NAMES = ("ground", "crank", "coupler", "rocker", "u", "v", "x0", "y0", "phi")
N_PARAMS = len(PARAM_NAMES)

#: candidates per block (block x samples doubles stay within a few hundred kB)
BLOCK = 2048


def _block(X: Array, ct: Array, st: Array, circuit: Array) -> tuple[Array, Array, Mask]:
    """One block: ``ct, st`` are ``(S,)`` (shared crank angles) or ``(P, S)`` (per candidate)."""
    r1, r2, r3, r4 = X[:, 0:1], X[:, 1:2], X[:, 2:3], X[:, 3:4]
    u, v = X[:, 4:5], X[:, 5:6]
    x0, y0, phi = X[:, 6:7], X[:, 7:8], X[:, 8:9]
    bx = r2 * ct
    by = r2 * st
    dx = r1 - bx
    dy = -by
    L2 = r1 * r1 + r2 * r2 - 2.0 * r1 * bx
    A = 0.5 * (r3 * r3 - r4 * r4) + 0.5 * L2
    h2 = r3 * r3 * L2 - A * A
    ok = h2 >= 0.0
    w = np.sqrt(np.maximum(h2, 0.0))
    w *= circuit[:, None]
    inv = 1.0 / (r3 * np.maximum(L2, 1e-300))
    # alpha = (u A - v w) / (r3 L2), beta = (u w + v A) / (r3 L2)
    alpha = (u * A - v * w) * inv
    beta = (u * w + v * A) * inv
    px = bx + alpha * dx - beta * dy
    py = by + alpha * dy + beta * dx
    c, s = np.cos(phi), np.sin(phi)
    return x0 + c * px - s * py, y0 + s * px + c * py, ok


def coupler_points(X: Array, theta: Array, circuit: Array | None = None) -> tuple[Array, Array, Mask]:
    """World coupler points ``(x, y)`` each ``(P, S)`` and validity ``(P, S)``.

    ``theta`` is ``(S,)`` crank angles shared by every candidate or ``(P, S)``
    per candidate (radians from the ground line).  ``circuit`` ``(P,)`` of
    ``+1``/``-1`` (default all ``+1``, FourBar's open circuit).  An invalid
    sample (the dyad cannot close) has finite but meaningless coordinates.
    """
    X = np.asarray(X, float)
    P = X.shape[0]
    th = np.asarray(theta, float)
    circ = np.ones(P) if circuit is None else np.asarray(circuit, float)
    S = th.shape[-1]
    xs = np.empty((P, S))
    ys = np.empty((P, S))
    ok = np.empty((P, S), dtype=bool)
    shared = th.ndim == 1
    if shared:
        ct_all, st_all = np.cos(th), np.sin(th)
    for i in range(0, P, BLOCK):
        j = min(P, i + BLOCK)
        if shared:
            ct, st = ct_all, st_all
        else:
            ct, st = np.cos(th[i:j]), np.sin(th[i:j])
        xs[i:j], ys[i:j], ok[i:j] = _block(X[i:j], ct, st, circ[i:j])
    return xs, ys, ok
