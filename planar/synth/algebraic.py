"""Four-bars from the coupler curve's algebraic equation: starts for untimed path synthesis that need no atlas.

The coupler curve of a four-bar is a tricircular sextic.  In isotropic coordinates ``z = x + i y``,
``w = x - i y`` its equation is ``sum c[j, k] z**j w**k = 0`` over ``0 <= j, k <= 3`` with ``c[k, j]`` the
conjugate of ``c[j, k]``: 16 real coefficients, 15 up to scale, and no crank angle in it.  Through 15 or more
targets on one four-bar's curve (any part of it, in any order) the coefficients are the null vector of a
linear system (:func:`fit_sextic`).

The curve's three *singular foci* (where a tangent at one circular point meets one at the other) are the
roots of ``sum_j c[j, 3] z**j`` (:func:`singular_foci`): the ground pivots of the four-bar and of its two
Roberts cognates, whose triangle is similar to the coupler triangle (Roberts-Chebyshev).  With two foci as
ground pivots ``a1, a2`` and the third ``f`` fixing the coupler's shape, what is left is linear
(:func:`dyads_from_foci`): with ``p`` a target, ``n_i = |p - a_i|**2``, the coupler's vectors from the
coupler point to its pins ``l1 = rho s`` and ``l2 = s`` (``rho = (a1 - f) / (a2 - f)``, ``s > 0``) and
``k_i = |l_i|**2 - (link i)**2``, the two loop closures are quadratics in the coupler's rotation ``e**(i t)``
with a common root, and their resultant is

    ``s**2 |D|**2 = |e0 + e1 k1 + e2 k2|**2``,

``D = rho (p* - a1*) (p - a2) - rho* (p* - a2*) (p - a1)``, ``e0 = rho (p* - a1*) n2 - (p* - a2*) n1``,
``e1 = -(p* - a2*)``, ``e2 = rho (p* - a1*)``: one real equation per target, linear in
``(s**2, k1, k2, k1**2, k1 k2, k2**2)``.

On exact targets the four-bar comes out exact (to the conditioning of the fit); on noisy or sparse targets (fewer
than 15, where the fit leaves a family of sextics) the four-bars are starts, refined like the atlas's.
Reference: Wampler, "Isotropic coordinates, circularity and Bezout numbers: planar kinematics from a new
perspective" (ASME DETC 1996) for the isotropic loop equations; Blechschmidt and Uicker, "Linkage synthesis
using algebraic curves" (J. Mech. Trans. Autom. Des. 108, 1986) for synthesis through the curve's equation.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import NDArray

__all__ = ["MIN_TARGETS", "algebraic_starts", "dyads_from_foci", "fit_sextic", "rank_starts", "search_algebraic", "singular_foci"]

Array = NDArray[np.float64]
Complex = NDArray[np.complex128]

#: the fewest targets that fix a tricircular sextic (15 coefficients up to scale)
MIN_TARGETS = 15

#: the monomials ``z**j w**k`` with ``j <= k`` (the others are their conjugates)
_PAIRS = [(j, k) for j in range(4) for k in range(j, 4)]


def _design(t: Array) -> Array:
    """The linear system of :func:`fit_sextic`: one row per target, 16 real columns (the real ``c[j, j]``,
    then the real and imaginary parts of each ``c[j, k]``, ``j < k``)."""
    z = t[:, 0] + 1j * t[:, 1]
    cols = []
    for j, k in _PAIRS:
        m = z**j * np.conj(z) ** k
        cols.extend([m.real] if j == k else [2 * m.real, -2 * m.imag])
    return np.column_stack(cols)


def _coefficients(x: Array) -> Complex:
    """The ``(4, 4)`` Hermitian coefficients ``c[j, k]`` of a solution ``x`` of :func:`_design`."""
    c = np.zeros((4, 4), complex)
    i = 0
    for j, k in _PAIRS:
        if j == k:
            c[j, k] = x[i]
            i += 1
        else:
            c[j, k] = x[i] + 1j * x[i + 1]
            c[k, j] = np.conj(c[j, k])
            i += 2
    return c


def fit_sextic(targets: Array, count: int = 1) -> tuple[list[Complex], Array]:
    """The tricircular sextics through ``targets`` ``(N, 2)`` (normalised: centroid 0, size about 1).

    Returns the ``count`` coefficient arrays ``(4, 4)`` (Hermitian, unit norm) of the smallest singular values,
    smallest first, and the singular values over the largest (16 values, descending; fewer than 16 targets
    leave ``16 - N`` zeros at the end).  With 15 or more targets on one four-bar's curve the first is its curve and
    the second singular value is well above the last."""
    A = _design(np.asarray(targets, float))
    scale = np.linalg.norm(A, axis=0)
    scale[scale == 0] = 1.0
    _, sv, vt = np.linalg.svd(A / scale, full_matrices=True)
    sv = np.concatenate([sv, np.zeros(16 - len(sv))]) / max(sv[0], 1e-300)
    out = []
    for row in vt[::-1][:count]:
        x = row / scale
        out.append(_coefficients(x / np.linalg.norm(x)))
    return out, sv


def singular_foci(c: Complex) -> Complex:
    """The three singular foci of the sextic ``c`` (:func:`fit_sextic`) as complex points ``x + i y``: the roots
    of ``sum_j c[j, 3] z**j`` (fewer when the cubic degenerates)."""
    poly = c[::-1, 3]  # highest power first
    nz = np.flatnonzero(np.abs(poly) > 1e-12 * np.abs(poly).max())
    if len(nz) == 0:
        return np.zeros(0, complex)
    return np.roots(poly[nz[0] :]).astype(complex)


def dyads_from_foci(targets: Array, a1: complex, a2: complex, f: complex) -> Array | None:
    """The four-bar with ground pivots ``a1`` (its input) and ``a2`` whose coupler triangle is similar to the
    foci's triangle ``(a1, a2, f)``, fitted to ``targets`` ``(N >= 6, 2)`` by the linear resultant equation (module
    docstring): the kernel's 9 parameters (:data:`planar.synth.kernel.PARAM_NAMES`), or None when it has no
    real links."""
    p = targets[:, 0] + 1j * targets[:, 1]
    q1, q2 = np.conj(p) - np.conj(a1), np.conj(p) - np.conj(a2)
    if abs(a2 - f) < 1e-12 or abs(a2 - a1) < 1e-12:
        return None
    rho = (a1 - f) / (a2 - f)
    n1, n2 = np.abs(p - a1) ** 2, np.abs(p - a2) ** 2
    D = rho * q1 * (p - a2) - np.conj(rho) * q2 * (p - a1)
    e0, e1, e2 = rho * q1 * n2 - q2 * n1, -q2, rho * q1
    M = np.column_stack(
        [
            np.abs(D) ** 2,
            -2 * (e0 * np.conj(e1)).real,
            -2 * (e0 * np.conj(e2)).real,
            -(np.abs(e1) ** 2),
            -2 * (e1 * np.conj(e2)).real,
            -(np.abs(e2) ** 2),
        ]
    )
    scale = np.linalg.norm(M, axis=0)
    if not np.all(np.isfinite(scale)) or np.any(scale == 0):
        return None
    sol = np.linalg.lstsq(M / scale, np.abs(e0) ** 2, rcond=None)[0] / scale
    s2, k1, k2 = sol[:3]
    if not s2 > 0:
        return None
    s = float(np.sqrt(s2))
    l1, l2 = rho * s, complex(s)
    crank2, rocker2 = abs(l1) ** 2 - k1, abs(l2) ** 2 - k2
    if not (crank2 > 0 and rocker2 > 0) or abs(l2 - l1) < 1e-12:
        return None
    uv = -l1 * np.conj(l2 - l1) / abs(l2 - l1)  # the coupler point from the crank pin, x toward the rocker pin
    g = a2 - a1
    return np.array([abs(g), np.sqrt(crank2), abs(l2 - l1), np.sqrt(rocker2), uv.real, uv.imag, a1.real, a1.imag, np.angle(g)])


def algebraic_starts(targets: Array, sextics: int = 2) -> Array:
    """Four-bars through untimed ``targets`` ``(N, 2)`` (normalised) from their sextic's foci: rows ``(K, 10)``
    (the kernel's 9 parameters and the circuit, both circuits), none when fewer than :data:`MIN_TARGETS` targets.

    Each of the ``sextics`` best-fitting sextics (the second helps when a short arc leaves two nearly equal
    singular values) gives 3 foci, so 6 ordered ground pivot pairs (either pivot the input), each one four-bar
    (:func:`dyads_from_foci`); the curve is traced by it on one of its circuits, which is left to the caller's
    scoring.  Roberts cognates come out together: the same curve from the three pairs of foci."""
    t = np.asarray(targets, float)
    if len(t) < MIN_TARGETS or not np.all(np.isfinite(t)):
        return np.zeros((0, 10))
    rows = []
    for c in fit_sextic(t, sextics)[0]:
        foci = singular_foci(c)
        if len(foci) != 3 or not np.all(np.isfinite(foci)):
            continue
        for i, j in itertools.permutations(range(3), 2):
            row = dyads_from_foci(t, complex(foci[i]), complex(foci[j]), complex(foci[3 - i - j]))
            if row is not None and np.all(np.isfinite(row)):
                rows.extend([np.append(row, 1.0), np.append(row, -1.0)])
    return np.array(rows) if rows else np.zeros((0, 10))


#: how many of the sextic's four-bars (best first, :func:`rank_starts`) :func:`search_algebraic` refines, and the
#: least-squares evaluations each
SEARCH_REFINE, SEARCH_NFEV = 6, 200
#: crank angles per turn at which :func:`rank_starts` looks for each target's nearest coupler point
RANK_SAMPLES = 4096
#: the refinement's box around the targets (lengths and pivots, in multiples of the targets' extent): wide, since a
#: four-bar tracing a short arc can have links far longer than the arc
WIDE_BOX = 1000.0


def rank_starts(targets: Array, rows: Array, samples: int = RANK_SAMPLES) -> tuple[NDArray[np.intp], Array, Array]:
    """Rows ``(K, 10)`` ranked by the largest distance from a target to the nearest of ``samples`` points of the
    row's coupler curve over a turn: the order (best first), each row's crank angle nearest each target ``(K, N)``
    (rad) and that distance ``(K,)`` (inf when the curve has no point)."""
    from planar.synth.kernel import coupler_points

    t = np.asarray(targets, float)
    th = np.linspace(0.0, 2 * np.pi, samples, endpoint=False)
    x, y, ok = coupler_points(rows[:, :9], th, np.where(rows[:, 9] >= 0, 1.0, -1.0))
    theta = np.zeros((len(rows), len(t)))
    far = np.full(len(rows), np.inf)
    for k in range(len(rows)):  # one (N, samples) block per row: memory bounded by the row, not by K
        if not ok[k].any():
            continue
        d2 = (x[k][None, :] - t[:, 0:1]) ** 2 + (y[k][None, :] - t[:, 1:2]) ** 2
        d2[:, ~ok[k]] = np.inf
        j = np.argmin(d2, axis=1)
        theta[k] = th[j]
        far[k] = float(np.sqrt(d2[np.arange(len(t)), j].max()))
    return np.argsort(far, kind="stable"), theta, far


def _wide_bounds(t: Array) -> list[tuple[float, float]]:
    """:data:`WIDE_BOX` bounds for the refinement (the circuit column last, as :func:`default_bounds`)."""
    L = float(max(np.hypot(*np.ptp(t, axis=0)), 1e-9))
    c = t.mean(0)
    b = [(L / WIDE_BOX, WIDE_BOX * L)] * 4 + [(-WIDE_BOX * L, WIDE_BOX * L)] * 2
    b += [(c[0] - WIDE_BOX * L, c[0] + WIDE_BOX * L), (c[1] - WIDE_BOX * L, c[1] + WIDE_BOX * L)]
    return b + [(-3 * np.pi, 3 * np.pi), (-1.0, 1.0)]


#: a caller's preference of a refined exact result (kernel row with circuit, crank angles at the targets): ``None``
#: when it is not usable, else ``(rank, extra)``, rank 0 the best (the search stops at the first of rank 0)
Choice = Callable[[Array, Array], "tuple[int, Any] | None"]


def search_algebraic(targets: Array, cons: Any, choose: Choice, stop: float = 1e-9) -> tuple[Any, Any]:
    """Untimed ``targets`` (normalised: centroid 0, size 1) from their sextic alone (no atlas): the refinements
    (crank angles free, from each target's nearest point) of the best :data:`SEARCH_REFINE` of the
    :func:`algebraic_starts` (:func:`rank_starts`) that are within ``stop`` (largest distance), the one ``choose``
    ranks best.

    ``cons`` (a :class:`planar.synth.search.Constraints`) is kept by the refinement except its full turn (a rocking
    input may be the answer: ``choose`` judges that, the order and anything else).  Returns the result (a
    :class:`planar.synth.search.SearchResult`, its ``stages`` holding ``algebraic_s``) and ``choose``'s extra, or
    ``(None, None)`` when none is usable (fewer than :data:`MIN_TARGETS` targets, targets on no one four-bar's
    curve or too short an arc of it to fix the sextic, or no four-bar ``choose`` accepts)."""
    import dataclasses
    import time

    from planar.synth.search import PathObjective, SearchResult, _refine, max_distance, reassigned_refine

    t0 = time.perf_counter()
    t = np.asarray(targets, float)
    rows = algebraic_starts(t)
    if len(rows) == 0:
        return None, None
    free = dataclasses.replace(cons, full_turn=False)
    obj = PathObjective(t, None, free, 256)
    b = _wide_bounds(t)
    order, theta, _ = rank_starts(t, rows)
    best: tuple[int, Array, Array, Any] | None = None
    for k in order[:SEARCH_REFINE]:
        r, tt, _ = _refine(obj, rows[k], b, max_nfev=SEARCH_NFEV, method="lm", theta0=theta[k])
        if not max_distance(obj, r, tt) <= stop:
            r, tt, _ = reassigned_refine(obj, rows[k], b, SEARCH_NFEV, stop)
            if not max_distance(obj, r, tt) <= stop:
                continue
        choice = choose(r, tt)
        if choice is not None and (best is None or choice[0] < best[0]):
            best = (choice[0], r, tt, choice[1])
            if choice[0] == 0:
                break
    if best is None:
        return None, None
    _, r, tt, extra = best
    sse = float(np.sum(np.square(obj.targets - _points(r, tt))))
    return SearchResult(r[:9], 1 if r[9] >= 0 else -1, tt, sse, True, 1, {"algebraic_s": time.perf_counter() - t0}), extra


def _points(row: Array, theta: Array) -> Array:
    """The coupler points ``(N, 2)`` of row ``row`` (9 parameters and the circuit) at crank angles ``theta``."""
    from planar.synth.kernel import coupler_points

    x, y, _ = coupler_points(row[None, :9], np.asarray(theta, float)[None, :], np.array([1.0 if row[9] >= 0 else -1.0]))
    return np.column_stack([x[0], y[0]])
