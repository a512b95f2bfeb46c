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

The foci can also be unknowns (:func:`refine_foci`): the resultant at each target, divided by its gradient with
respect to the target (:func:`foci_residuals`, Sampson's first-order distance to the curve), depends on the three
foci and ``(s**2, k1, k2)`` only (nine reals, a four-bar's nine dimensions, no crank angle).  For given foci the
dyads are fitted by a few Gauss-Newton steps from the linear solution (:func:`fitted_dyads`), leaving a least-squares
problem in the six coordinates of the foci (variable projection, Kaufman's Jacobian).  From a nearby four-bar
(:func:`foci_of_row` gives its foci) it reaches the targets' curve more often than the four-bar refined with its
crank angles: :func:`search_algebraic` uses it when a short arc leaves the sextic nearly undetermined.  From an
atlas's starts below 15 targets it recovered more than the same starts refined directly (12 targets, 30 problems
per kind: double-rockers 10 -> 63 %, part-curves 23 -> 60 %), but no more than the atlas search's later stages
already do, at more CPU, so the atlas search does not use it (see docs/explanation/curve-equation.md).
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

from planar.synth.kernel import coupler_points, row_points

__all__ = [
    "MIN_TARGETS",
    "algebraic_starts",
    "dyads_from_foci",
    "fit_sextic",
    "fitted_dyads",
    "foci_of_row",
    "foci_residuals",
    "rank_starts",
    "refine_foci",
    "row_of_foci",
    "search_algebraic",
    "singular_foci",
]

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


def _linear_system(targets: Array, a1: complex, a2: complex, f: complex) -> tuple[Array, Complex, Complex, Complex, Complex]:
    """The resultant equation (module docstring) at ``targets`` ``(N, 2)`` for the foci ``a1, a2, f``: its matrix
    ``(N, 6)`` on ``(s**2, k1, k2, k1**2, k1 k2, k2**2)`` (right side ``|e0|**2``), and ``D, e0, e1, e2`` ``(N,)``."""
    p = targets[:, 0] + 1j * targets[:, 1]
    q1, q2 = np.conj(p) - np.conj(a1), np.conj(p) - np.conj(a2)
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
    return M, D, e0, e1, e2


def _linear_dyads(targets: Array, a1: complex, a2: complex, f: complex) -> Array | None:
    """``(s**2, k1, k2)`` fitted to ``targets`` for the foci ``a1, a2, f`` by the linear least squares on the six
    products (:func:`_linear_system`), or None when the system is degenerate."""
    if abs(a2 - f) < 1e-12 or abs(a2 - a1) < 1e-12:
        return None
    M, _, e0, _, _ = _linear_system(targets, a1, a2, f)
    scale = np.linalg.norm(M, axis=0)
    if not np.all(np.isfinite(scale)) or np.any(scale == 0):
        return None
    sol = np.linalg.lstsq(M / scale, np.abs(e0) ** 2, rcond=None)[0] / scale
    return np.asarray(sol[:3], float)


def dyads_from_foci(targets: Array, a1: complex, a2: complex, f: complex) -> Array | None:
    """The four-bar with ground pivots ``a1`` (its input) and ``a2`` whose coupler triangle is similar to the
    foci's triangle ``(a1, a2, f)``, fitted to ``targets`` ``(N >= 6, 2)`` by the linear resultant equation (module
    docstring): the kernel's 9 parameters (:data:`planar.synth.kernel.PARAM_NAMES`), or None when it has no
    real links."""
    sol = _linear_dyads(targets, a1, a2, f)
    if sol is None or not sol[0] > 0:
        return None
    return row_of_foci(a1, a2, f, float(np.sqrt(sol[0])), float(sol[1]), float(sol[2]))


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
    """:data:`WIDE_BOX` bounds for the refinement (:func:`planar.synth.search.default_bounds`, no region)."""
    from planar.synth.search import Constraints, default_bounds

    return default_bounds(t, Constraints(), False, reach=WIDE_BOX, shortest=WIDE_BOX, turn=3 * np.pi)


#: a caller's preference of a refined exact result (kernel row with circuit, crank angles at the targets): ``None``
#: when it is not usable, else ``(rank, extra)``, rank 0 the best (the search stops at the first of rank 0)
Choice = Callable[[Array, Array], "tuple[int, Any] | None"]

#: the sextic's starts whose foci :func:`search_algebraic` refines (:func:`refine_foci`) when none of its four-bars
#: refines to an exact usable one; the largest foci residual (targets' size 1) under which the refined foci's
#: four-bars are refined on the targets, and how many of them (best first, :func:`rank_starts`)
FOCI_STARTS, FOCI_FAR, FOCI_REFINE = 4, 1e-4, 2


def search_algebraic(
    targets: Array, cons: Any, choose: Choice, stop: float = 1e-9, accept: float | None = None
) -> tuple[Any, Any]:
    """Untimed ``targets`` (normalised: centroid 0, size 1) from their sextic alone (no atlas): the refinements
    (crank angles free, from each target's nearest point) of the best :data:`SEARCH_REFINE` of the
    :func:`algebraic_starts` (:func:`rank_starts`) that are within ``stop`` (largest distance), the one ``choose``
    ranks best (lower rank, then smaller distance); with ``accept`` (a largest distance above ``stop``: noisy or
    measured targets) the best within it when none is within ``stop``.  When none is usable (a short arc leaves the
    sextic nearly undetermined, so its foci are off), the
    foci of the :data:`FOCI_STARTS` best starts are refined on the targets (:func:`refine_foci`) and their four-bars
    refined the same way.

    ``cons`` (a :class:`planar.synth.search.Constraints`) is kept by the refinement except its full turn (a rocking
    input may be the answer: ``choose`` judges that, the order and anything else).  Returns the result (a
    :class:`planar.synth.search.SearchResult`, its ``stages`` holding ``algebraic_s``) and ``choose``'s extra, or
    ``(None, None)`` when none is usable (fewer than :data:`MIN_TARGETS` targets, targets on no one four-bar's
    curve or too short an arc of it to fix the sextic, or no four-bar ``choose`` accepts)."""
    import dataclasses
    import time

    from planar.synth.search import PathObjective, SearchResult

    t0 = time.perf_counter()
    t = np.asarray(targets, float)
    rows = algebraic_starts(t)
    if len(rows) == 0:
        return None, None
    obj = PathObjective(t, None, dataclasses.replace(cons, full_turn=False), 256)
    order, theta, _ = rank_starts(t, rows)
    best: Best | None = None
    for k in order[:SEARCH_REFINE]:
        best = _better(best, finish_start(obj, rows[k], theta[k], stop, accept), choose)
        if best is not None and best[0] == 0 and best[1] <= stop:
            break
    for k in order[:FOCI_STARTS] if best is None or best[1] > stop else []:
        best = _kept(best, finish_foci(obj, rows[k], stop, choose, accept))
        if best is not None and best[1] <= stop:
            break
    if best is None:
        return None, None
    _, _, r, tt, extra = best
    sse = float(np.sum(np.square(obj.targets - row_points(r, tt))))
    return SearchResult(r[:9], 1 if r[9] >= 0 else -1, tt, sse, True, 1, {"algebraic_s": time.perf_counter() - t0}), extra


#: a refined four-bar as the searches here keep it: ``choose``'s rank, its largest distance, row, crank angles, extra
Best = tuple[int, float, Array, Array, Any]


def _kept(best: Best | None, other: Best | None) -> Best | None:
    """The better of two kept results (lower rank, then smaller distance; either may be None)."""
    if best is None or (other is not None and other[:2] < best[:2]):
        return other
    return best


def _better(best: Best | None, found: tuple[Array, Array, float] | None, choose: Choice) -> Best | None:
    """``best`` or the refined ``found`` (row, crank angles, largest distance) when ``choose`` ranks it better (a
    lower rank, then a smaller distance)."""
    choice = None if found is None else choose(found[0], found[1])
    if found is None or choice is None:
        return best
    return _kept(best, (choice[0], found[2], found[0], found[1], choice[1]))


def finish_foci(obj: Any, start: Array, stop: float, choose: Choice, accept: float | None = None) -> Best | None:
    """A start (kernel row and circuit) near the untimed targets of ``obj`` (a
    :class:`planar.synth.search.PathObjective`, normalised targets), its foci refined (:func:`refine_foci`) and,
    when their largest residual is at most :data:`FOCI_FAR`, the :data:`FOCI_REFINE` best of their four-bars
    finished by :func:`finish_start` (within ``accept``, default ``stop``): the best ``choose`` accepts, or None."""
    rows, far = refine_foci(obj.targets, start)
    if not far <= FOCI_FAR or len(rows) == 0:
        return None
    order, theta, dist = rank_starts(obj.targets, rows)
    best = None
    for k in order[:FOCI_REFINE]:
        if not np.isfinite(dist[k]):
            break
        best = _better(best, finish_start(obj, rows[k], theta[k], stop, accept), choose)
        if best is not None and best[0] == 0 and best[1] <= stop:
            break
    return best


def finish_start(
    obj: Any, row: Array, theta: Array, stop: float, accept: float | None = None
) -> tuple[Array, Array, float] | None:
    """One start (kernel row and circuit; crank angles ``theta`` at the targets of ``obj``, rad) refined on the
    targets (crank angles free, :data:`WIDE_BOX`) by Levenberg-Marquardt, then with its angles re-assigned
    (:func:`planar.synth.search.reassigned_refine`) if not within ``stop``: the refined row, crank angles and largest
    distance when within ``accept`` (default ``stop``), else None."""
    from planar.synth.search import _refine, max_distance, reassigned_refine

    b = _wide_bounds(obj.targets)
    r, tt, _ = _refine(obj, row, b, max_nfev=SEARCH_NFEV, method="lm", theta0=theta)
    e = max_distance(obj, r, tt)
    if not e <= stop:
        r2, tt2, _ = reassigned_refine(obj, row, b, SEARCH_NFEV, stop)
        e2 = max_distance(obj, r2, tt2)
        if e2 < e or not np.isfinite(e):
            r, tt, e = r2, tt2, e2
    return (r, tt, e) if e <= max(stop, accept if accept is not None else stop) else None


def foci_of_row(row: Array) -> tuple[complex, complex, complex, float, float, float]:
    """A four-bar (kernel row: :data:`planar.synth.kernel.PARAM_NAMES`, a circuit column ignored) as its curve's
    singular foci and dyads (module docstring): ``(a1, a2, f, s, k1, k2)`` with ``a1, a2`` the input's and the
    rocker's ground pivots and ``f`` the third focus (complex points, model units), ``s = |l2|`` (model units) and
    ``k_i = |l_i|**2 - (link i)**2`` (squared model units); the inverse of :func:`row_of_foci`."""
    g, crank, coupler, rocker, u, v, x0, y0, phi = (float(x) for x in row[:9])
    a1 = complex(x0, y0)
    a2 = a1 + g * np.exp(1j * phi)
    uv = complex(u, v)
    l1, l2 = -uv, coupler - uv  # the coupler point to the crank pin and to the rocker pin, in the coupler's frame
    rho = l1 / l2
    f = (rho * a2 - a1) / (rho - 1) if abs(rho - 1) > 1e-300 else complex(np.inf)
    return a1, a2, complex(f), abs(l2), abs(l1) ** 2 - crank**2, abs(l2) ** 2 - rocker**2


def row_of_foci(a1: complex, a2: complex, f: complex, s: float, k1: float, k2: float) -> Array | None:
    """The kernel's 9 parameters of the four-bar with foci ``a1, a2, f`` and dyads ``s, k1, k2``
    (:func:`foci_of_row`), or None when it has no real links (``s <= 0``, a squared link length not positive, or
    coincident pins or foci)."""
    if not (s > 0 and np.isfinite(s)) or abs(a2 - f) < 1e-12 or abs(a2 - a1) < 1e-12:
        return None
    rho = (a1 - f) / (a2 - f)
    l1, l2 = rho * s, complex(s)
    crank2, rocker2 = abs(l1) ** 2 - k1, abs(l2) ** 2 - k2
    if not (crank2 > 0 and rocker2 > 0) or abs(l2 - l1) < 1e-12:
        return None
    uv = -l1 * np.conj(l2 - l1) / abs(l2 - l1)  # the coupler point from the crank pin, x toward the rocker pin
    g = a2 - a1
    out = np.array([abs(g), np.sqrt(crank2), abs(l2 - l1), np.sqrt(rocker2), uv.real, uv.imag, a1.real, a1.imag, np.angle(g)])
    return out if np.all(np.isfinite(out)) else None


def foci_residuals(targets: Array, x: Array) -> Array:
    """The resultant equation (module docstring) at each target ``(N, 2)`` for the unknowns ``x`` =
    ``(a1.real, a1.imag, a2.real, a2.imag, f.real, f.imag, s**2, k1, k2)``, over its gradient with respect to the
    target (Sampson's first-order distance from the target to the curve, model units)."""
    p = targets[:, 0] + 1j * targets[:, 1]
    a1, a2, f = complex(x[0], x[1]), complex(x[2], x[3]), complex(x[4], x[5])
    s2, k1, k2 = x[6], x[7], x[8]
    den = a2 - f
    rho = (a1 - f) / den if den != 0 else complex(np.inf)
    q1, q2 = np.conj(p - a1), np.conj(p - a2)
    P1, P2 = p - a1, p - a2
    m1, m2 = q1 * P1 + k1, q2 * P2 + k2  # n_i + k_i
    D = rho * q1 * P2 - np.conj(rho) * q2 * P1
    E = rho * q1 * m2 - q2 * m1
    # Wirtinger derivatives with respect to conj(p): the real r has gradient norm 2 |dr / d conj(p)|
    dD = np.conj(D) * (rho * P2 - np.conj(rho) * P1) + D * np.conj(rho * q1 - np.conj(rho) * q2)
    dE = np.conj(E) * (rho * m2 + rho * q1 * P2 - m1 - q2 * P1) + E * np.conj((rho - 1) * q1 * q2)
    r = s2 * np.abs(D) ** 2 - np.abs(E) ** 2
    g = 2 * np.abs(s2 * dD - dE)
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        out = r / np.maximum(g, 1e-300)
    return np.where(np.isfinite(out), out, 1e6)


#: least-squares evaluations of :func:`refine_foci` (each solving the dyads, :func:`fitted_dyads`), and the
#: Gauss-Newton iterations of :func:`fitted_dyads`
FOCI_NFEV, DYAD_ITERS = 100, 6


def _foci_vector(row: Array) -> Array:
    """:func:`foci_of_row` as the unknowns of :func:`foci_residuals`."""
    a1, a2, f, s, k1, k2 = foci_of_row(row)
    return np.array([a1.real, a1.imag, a2.real, a2.imag, f.real, f.imag, s * s, k1, k2])


def _dyad_jacobian(t: Array, x: Array, r: Array, columns: range) -> Array:
    """Forward differences of :func:`foci_residuals` (``r`` at ``x``) with respect to the unknowns ``columns``."""
    J = np.empty((len(t), len(columns)))
    for c, i in enumerate(columns):
        h = 1e-7 * (1.0 + abs(x[i]))
        xh = x.copy()
        xh[i] += h
        J[:, c] = (foci_residuals(t, xh) - r) / h
    return J


def fitted_dyads(targets: Array, foci: Array, iters: int = DYAD_ITERS) -> Array:
    """The unknowns of :func:`foci_residuals` for the foci ``foci`` (``a1.real, a1.imag, a2.real, a2.imag, f.real,
    f.imag``) with the dyads ``(s**2, k1, k2)`` fitted to ``targets`` ``(N, 2)``: the linear least squares on the six
    products (:func:`dyads_from_foci`), then ``iters`` Gauss-Newton steps on the three, each target's residual
    weighted as :func:`foci_residuals` (the weights held over a step: the derivatives of the resultant alone, which
    is linear in ``s**2`` and quadratic in ``k1, k2``).  The residual is linear in ``s**2`` and
    quadratic in ``k1, k2``, so these converge in a few steps.  NaN dyads when the foci are degenerate."""
    t = np.asarray(targets, float)
    a1, a2, f = complex(foci[0], foci[1]), complex(foci[2], foci[3]), complex(foci[4], foci[5])
    x = np.concatenate([np.asarray(foci[:6], float), np.full(3, np.nan)])
    sol = _linear_dyads(t, a1, a2, f)
    if sol is None or not np.all(np.isfinite(sol)):
        return x
    x[6:] = sol
    _, D, e0, e1, e2 = _linear_system(t, a1, a2, f)
    with np.errstate(all="ignore"):
        for _ in range(iters):
            r = foci_residuals(t, x)
            E = e0 + e1 * x[7] + e2 * x[8]
            raw = x[6] * np.abs(D) ** 2 - np.abs(E) ** 2
            w = np.where(raw != 0, r / np.where(raw != 0, raw, 1.0), 0.0)  # the residual's weight
            J = np.column_stack([np.abs(D) ** 2, -2 * (np.conj(E) * e1).real, -2 * (np.conj(E) * e2).real]) * w[:, None]
            if not np.all(np.isfinite(J)):
                break
            step = np.linalg.lstsq(J, -r, rcond=None)[0]
            x[6:] += step
            if np.linalg.norm(step) <= 1e-15 * (1.0 + np.linalg.norm(x[6:])):
                break
    return x


def _projected(t: Array) -> tuple[Any, Any]:
    """The residuals of :func:`refine_foci` as functions of the foci (6 reals) and their Jacobian by variable
    projection (Kaufman's: the derivatives with the dyads held, by forward differences on :func:`foci_residuals`,
    minus their part along the dyads' derivatives), the dyads fitted once per point (:func:`fitted_dyads`)."""
    memo: dict[bytes, Array] = {}

    def dyads(v: Array) -> Array:
        key = np.asarray(v, float).tobytes()
        if key not in memo:
            memo.clear()  # Levenberg-Marquardt asks for the Jacobian at the last point it evaluated
            memo[key] = fitted_dyads(t, v)
        return memo[key]

    def resid(v: Array) -> Array:
        return foci_residuals(t, dyads(v))

    def jac(v: Array) -> Array:
        x = dyads(v)
        J = _dyad_jacobian(t, x, foci_residuals(t, x), range(9))
        if not np.all(np.isfinite(J)):
            return np.nan_to_num(J[:, :6])
        q = np.linalg.qr(J[:, 6:])[0]
        return J[:, :6] - q @ (q.T @ J[:, :6])

    return resid, jac


def refine_foci(targets: Array, start: Array, nfev: int = FOCI_NFEV) -> tuple[Array, float]:
    """Four-bars through untimed ``targets`` ``(N >= 6, 2)`` from a nearby one ``start`` (kernel row, 9 parameters
    and optionally a circuit): the foci as unknowns (variable projection).  Levenberg-Marquardt
    (:func:`scipy.optimize.least_squares`) on the start's three foci (6 reals, model units), the dyads fitted to
    them at every evaluation (:func:`fitted_dyads`), each target's residual the distance-like
    :func:`foci_residuals` (no crank angle anywhere); then the four-bars of the refined foci: the refined one
    itself and, from each ordered pair of foci as ground pivots, the dyads fitted by :func:`dyads_from_foci` (the
    Roberts cognates), each on both circuits.  Returns rows ``(K, 10)`` (none when the start has no finite foci or
    fewer than 6 targets) and the refined foci's largest residual (:func:`foci_residuals`, model units; inf when
    none): near rounding when the targets lie on the refined foci's curve."""
    from scipy.optimize import least_squares

    t = np.asarray(targets, float)
    v0 = _foci_vector(np.asarray(start, float))[:6]
    if len(t) < 6 or not np.all(np.isfinite(v0)):
        return np.zeros((0, 10)), np.inf

    resid, jac = _projected(t)
    with np.errstate(all="ignore"):
        v = least_squares(resid, v0, jac=jac, method="lm", x_scale="jac", max_nfev=nfev).x
    x = fitted_dyads(t, v)
    far = float(np.max(np.abs(foci_residuals(t, x)))) if np.all(np.isfinite(x)) else np.inf
    foci = [complex(x[0], x[1]), complex(x[2], x[3]), complex(x[4], x[5])]
    s = float(np.sqrt(x[6])) if x[6] > 0 else 0.0
    found = [row_of_foci(foci[0], foci[1], foci[2], s, float(x[7]), float(x[8]))]
    found += [dyads_from_foci(t, foci[i], foci[j], foci[3 - i - j]) for i, j in itertools.permutations(range(3), 2)]
    rows = [np.append(r, c) for r in found if r is not None for c in (1.0, -1.0)]
    return (np.array(rows), far) if rows else (np.zeros((0, 10)), np.inf)
