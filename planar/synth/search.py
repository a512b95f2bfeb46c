"""Global search over four-bar candidates, then local refinement.

The objective is evaluated for a whole population at once with
:func:`planar.synth.kernel.coupler_points`: every candidate's coupler point
at the prescribed crank angles (timed targets), or at ``samples`` crank angles
over the turn, each target scored by its nearest sample (untimed).  Design
constraints are penalties added to the error of a candidate that breaks them,
in proportion to how far it does:

* the crank turns fully: Grashof (``s + l <= p + q``) with the crank or the
  ground the shortest link (crank-rocker or double-crank), by a margin;
* link ratio: longest / shortest link at most ``max_ratio``;
* ground pivots inside ``region`` ``(xmin, ymin, xmax, ymax)``;
* the transmission angle at least ``min_transmission`` (radians) from a toggle (0 or pi) over the turn,
  when asked (its extremes over a full turn are at crank angles 0 and pi, exact).

The search: ``n_sample`` random candidates (uniform in the bounds; the
"atlas" stage, cheap because it is one kernel call), the best of them seed
:func:`scipy.optimize.differential_evolution` (``vectorized=True``, the
population evaluated by one kernel call per generation), and
:func:`scipy.optimize.least_squares` refines distinct candidates, half from
DE's final population and half from the sample's best, the crank angles at
the targets becoming variables for untimed targets (its Jacobian by forward
differences, all perturbed candidates in one kernel call).  Candidates are
screened in float32, refined and checked in float64.  Same inputs and
``seed``, same result.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from planar.synth.kernel import GRASHOF_MARGIN, N_PARAMS, coupler_points
from planar.synth.positions import polish_positions

__all__ = [
    "REL_TOL",
    "Constraints",
    "PathObjective",
    "SearchResult",
    "constraint_failures",
    "region_failures",
    "search_fourbar",
    "violation",
]

Array = NDArray[np.float64]

#: relative tolerance of the final constraint check (rounding-level overshoots pass)
REL_TOL = 1e-9

#: evaluations of one least-squares refinement (bounded, so its cost grows with the targets only through
#: each evaluation's size)
REFINE_NFEV = 200

#: the largest absolute cosine of a transmission angle the penalty counts (a candidate beyond it cannot assemble anyway)
CMU_CAP = 1e6


@dataclass(frozen=True)
class Constraints:
    """What a designer asks of the linkage besides the path (see the module)."""

    full_turn: bool = True
    max_ratio: float = 10.0
    region: tuple[float, float, float, float] | None = None
    #: radians; 0 (the default) asks nothing
    min_transmission: float = 0.0


def violation(X: Array, cons: Constraints, scale: float, margin: float = GRASHOF_MARGIN) -> Array:
    """How far each candidate ``(P, 9)`` breaks the constraints, in units of ``scale`` (0 when it keeps them).

    ``margin`` (a fraction of the links' total length) is kept from a
    change-point; the search uses :data:`GRASHOF_MARGIN`, the refinement
    twice that (so it stays inside), the final check none.
    """
    L = X[:, :4]
    r1, r2 = X[:, 0], X[:, 1]
    lo, hi = L.min(1), L.max(1)
    v = np.zeros(X.shape[0])
    if cons.full_turn:
        total = L.sum(1)
        pq = total - lo - hi
        v += np.maximum(0.0, lo + hi - pq + margin * total)
        v += np.maximum(0.0, np.minimum(r1, r2) - np.minimum(X[:, 2], X[:, 3]) + margin * total)
    v += np.maximum(0.0, hi - cons.max_ratio * (1.0 - margin) * lo)
    if cons.region is not None:
        x0, y0, x1, y1 = cons.region
        ox, oy = X[:, 6], X[:, 7]
        o4x, o4y = ox + r1 * np.cos(X[:, 8]), oy + r1 * np.sin(X[:, 8])
        for px, py in ((ox, oy), (o4x, o4y)):
            v += np.maximum(0.0, x0 - px) + np.maximum(0.0, px - x1) + np.maximum(0.0, y0 - py) + np.maximum(0.0, py - y1)
    if cons.min_transmission > 0:
        # cos of the transmission angle at the shortest and longest diagonal B-O4 (crank angles 0 and pi)
        cos_lim = np.cos(cons.min_transmission)
        r3, r4 = X[:, 2], X[:, 3]
        for diag in (np.abs(r1 - r2), r1 + r2):
            with np.errstate(over="ignore", invalid="ignore"):
                cmu = (r3 * r3 + r4 * r4 - diag * diag) / np.maximum(2 * r3 * r4, 1e-300)
            # a runaway candidate (a link near 0 or huge) gets a large finite penalty, not an overflow
            v += np.maximum(0.0, np.minimum(np.abs(np.nan_to_num(cmu, nan=CMU_CAP)), CMU_CAP) - cos_lim) * scale
    return v / scale


def region_failures(pivots: dict[str, tuple[float, float]], cons: Constraints) -> list[str]:
    """One line per ground pivot outside ``cons.region`` (to :data:`REL_TOL` of the box's size), naming it."""
    if cons.region is None:
        return []
    x0, y0, x1, y1 = cons.region
    tol = REL_TOL * max(x1 - x0, y1 - y0, abs(x0), abs(x1), abs(y0), abs(y1))
    out = []
    for name, (px, py) in pivots.items():
        if not (x0 - tol <= px <= x1 + tol and y0 - tol <= py <= y1 + tol):
            out.append(f"pivot {name} at ({px:.6g}, {py:.6g}) is outside the --pivots box x {x0:g}..{x1:g}, y {y0:g}..{y1:g}")
    return out


def ratio_failures(links: dict[str, float], max_ratio: float) -> list[str]:
    """The link ratio (longest / shortest of ``links``, names to lengths) over ``max_ratio`` (relative
    tolerance :data:`REL_TOL`), as one line naming both links, or nothing."""
    if not np.isfinite(max_ratio):
        return []
    lo = min(links, key=lambda k: links[k])
    hi = max(links, key=lambda k: links[k])
    if links[hi] <= max_ratio * links[lo] * (1.0 + REL_TOL):
        return []
    return [
        f"link ratio {links[hi] / links[lo]:.10g} (longest {hi} {links[hi]:.6g} / shortest {lo} "
        f"{links[lo]:.6g}) is over --max-ratio {max_ratio:g}"
    ]


def constraint_failures(p: Array, cons: Constraints) -> list[str]:
    """The constraints a four-bar (kernel row ``p``, world units) breaks, each named with its value and
    limit (relative tolerance :data:`REL_TOL`); empty when it keeps them all."""
    r1, r2, r3, r4 = (float(v) for v in p[:4])
    out: list[str] = []
    if cons.full_turn:
        L = sorted((r1, r2, r3, r4))
        tol = REL_TOL * sum(L)
        if L[0] + L[3] > L[1] + L[2] + tol:
            out.append(
                f"the crank turns fully: shortest + longest link {L[0] + L[3]:.10g} > the other two "
                f"{L[1] + L[2]:.10g} (not Grashof)"
            )
        elif min(r1, r2) > min(r3, r4) + tol:
            out.append(
                f"the crank turns fully: neither crank {r2:.6g} nor ground {r1:.6g} is the shortest link "
                f"(coupler {r3:.6g}, rocker {r4:.6g})"
            )
    out += ratio_failures({"ground": r1, "crank": r2, "coupler": r3, "rocker": r4}, cons.max_ratio)
    x0, y0, phi = (float(v) for v in p[6:9])
    out += region_failures({"O2": (x0, y0), "O4": (x0 + r1 * np.cos(phi), y0 + r1 * np.sin(phi))}, cons)
    return out


@dataclass
class PathObjective:
    """Sum of squared distances to the targets for a population of candidates.

    ``targets`` ``(N, 2)``; ``theta`` ``(N,)`` prescribed crank angles or
    ``None``; a candidate row is the kernel's 9 parameters and a tenth column
    whose sign is the circuit.  ``samples`` crank angles per candidate over a
    turn when untimed.
    """

    targets: Array
    theta: Array | None
    cons: Constraints
    samples: int = 64
    scale: float = field(init=False)
    penalty: float = field(init=False)

    def __post_init__(self) -> None:
        t = self.targets
        self.scale = float(max(np.hypot(*np.ptp(t, axis=0)), 1e-9))
        # any feasible candidate beats every infeasible one that is not absurdly far
        self.penalty = 100.0 * self.scale**2 * len(t)

    def __call__(self, x: Array) -> Array:
        """``x`` ``(10, P)`` as scipy's vectorised DE passes it; returns ``(P,)``."""
        return self.population(np.asarray(x, float).T)

    def population(self, X: Array, dtype: type = np.float32) -> Array:
        """Objective of candidates ``X`` ``(P, 10)`` (screened in ``dtype``; float64 sums)."""
        X = np.atleast_2d(X)
        circ = np.where(X[:, 9] >= 0, 1.0, -1.0)
        P9 = X[:, :N_PARAMS]
        tx, ty = self.targets[:, 0], self.targets[:, 1]
        if self.theta is not None:
            x, y, ok = coupler_points(P9, self.theta, circ, dtype=dtype)
            tx, ty = tx.astype(dtype), ty.astype(dtype)
            d2 = (x - tx) ** 2 + (y - ty) ** 2
            d2 = np.where(ok, d2, 4.0 * self.scale**2)
            err = d2.sum(1, dtype=float)
        else:
            th = np.linspace(0.0, 2 * np.pi, self.samples, endpoint=False)
            x, y, ok = coupler_points(P9, th, circ, dtype=dtype)
            far = 1e6 * self.scale**2
            err = np.zeros(X.shape[0])
            tx, ty = tx.astype(dtype), ty.astype(dtype)
            for k in range(len(tx)):
                d2 = (x - tx[k]) ** 2
                d2 += (y - ty[k]) ** 2
                d2[~ok] = far
                err += d2.min(1)
        v = violation(P9, self.cons, self.scale)
        return err + np.where(v > 0, self.penalty * (1.0 + v), 0.0)


@dataclass
class SearchResult:
    """The best candidate: parameters (9), circuit (+1/-1), crank angles at the targets, error."""

    params: Array
    circuit: int
    theta: Array
    sse: float
    feasible: bool
    evaluations: int
    stages: dict[str, float]
    #: which lookup the result's start came from, when a search tells (``"windows"``: the curve-window atlas)
    source: str = ""


def default_bounds(
    targets: Array,
    cons: Constraints,
    theta_given: bool,
    reach: float = 4.0,
    shortest: float = 50.0,
    turn: float = np.pi,
) -> list[tuple[float, float]]:
    """Search bounds from the targets' extent ``L`` and centre: lengths ``[L / shortest, reach L]``, coupler point
    ``+-reach L``, crank pivot within ``reach L`` of the centre (or in ``cons.region``), ground angle within
    ``+-turn`` (radians), then the circuit column.  The defaults bound the global search; the refinement of a
    start (a four-bar tracing a short arc can have links far longer than the arc) uses wider ones."""
    t = np.asarray(targets, float)
    L = float(max(np.hypot(*np.ptp(t, axis=0)), 1e-9))
    c = t.mean(0)
    b = [(L / shortest, reach * L)] * 4 + [(-reach * L, reach * L)] * 2
    if cons.region is not None:
        x0, y0, x1, y1 = cons.region
        b += [(x0, x1), (y0, y1)]
    else:
        b += [(c[0] - reach * L, c[0] + reach * L), (c[1] - reach * L, c[1] + reach * L)]
    b += [(-turn, turn), (-1.0, 1.0)]
    return b


def _nearest_theta(obj: PathObjective, row: Array, n: int = 720) -> Array:
    th = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    circ = np.array([1.0 if row[9] >= 0 else -1.0])
    x, y, ok = coupler_points(row[None, :N_PARAMS], th, circ)
    d2 = (x[0][None, :] - obj.targets[:, 0:1]) ** 2 + (y[0][None, :] - obj.targets[:, 1:2]) ** 2
    d2[:, ~ok[0]] = np.inf
    return th[np.argmin(d2, axis=1)]


def _curve_d2(obj: PathObjective, row: Array, n: int) -> tuple[Array, Array]:
    """Crank angles ``(n,)`` over a turn and the squared distance ``(N, n)`` from each target to the coupler
    point there (inf where the dyad cannot close)."""
    th = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    circ = np.array([1.0 if row[9] >= 0 else -1.0])
    x, y, ok = coupler_points(row[None, :N_PARAMS], th, circ)
    d2 = (x[0][None, :] - obj.targets[:, 0:1]) ** 2 + (y[0][None, :] - obj.targets[:, 1:2]) ** 2
    d2[:, ~ok[0]] = np.inf
    return th, d2


def ordered_theta(d2: Array, th: Array, starts: int = 4) -> tuple[Array, float]:
    """Crank angles at the targets that run one way round within one turn, in the targets' order, nearest in
    total: ``d2`` ``(N, n)`` squared distances from each target to the curve at the crank angles ``th``
    ``(n,)``.  Dynamic programming over the samples (a running minimum per target), from the ``starts`` best
    local minima of the first target's distance, both ways round.  Returns the angles (radians, in ``th``)
    and the total squared distance.

    Where the coupler curve crosses itself or passes near itself, the nearest point of the curve to a target
    can lie on the wrong part of it; Levenberg-Marquardt started there stalls (in our runs a 1 % change of
    the true four-bar's dimensions, with the angles re-assigned by nearest point, stalled at 0.1 of the size;
    from the ordered angles it converged)."""
    N, n = d2.shape
    d0 = d2[0]
    loc = np.flatnonzero((d0 <= np.roll(d0, 1)) & (d0 <= np.roll(d0, -1)) & np.isfinite(d0))
    if len(loc) == 0:
        return th[np.argmin(d2, axis=1)], float("inf")
    loc = loc[np.argsort(d0[loc], kind="stable")[:starts]]
    k = np.arange(n)
    # every start both ways round at once (rows: one way from each start, then the other way)
    idx = (np.concatenate([loc, loc])[:, None] + np.repeat([1, -1], len(loc))[:, None] * k[None, :]) % n
    D = d2[:, idx]  # (N, V, n): each variant's turn unrolled from its start
    V = len(idx)
    cost = np.full((V, n), np.inf)
    cost[:, 0] = D[0, :, 0]
    arg = np.zeros((N, V, n), dtype=np.intp)
    for i in range(1, N):
        run = np.minimum.accumulate(cost, axis=1)
        arg[i] = np.maximum.accumulate(np.where(cost <= run, k, 0), axis=1)
        cost = D[i] + run
    ends = np.argmin(cost, axis=1)
    totals = cost[np.arange(V), ends]
    v = int(np.argmin(totals))  # the first of the best, as one variant after another would keep
    if not np.isfinite(totals[v]):
        return th[np.argmin(d2, axis=1)], float("inf")
    path = np.empty(N, dtype=np.intp)
    j = int(ends[v])
    for i in range(N - 1, -1, -1):
        path[i] = j
        j = int(arg[i, v, j])
    return th[idx[v, path]], float(totals[v])


def _residual_functions(obj: PathObjective, circuit: float, hi: Array) -> tuple[Any, Any]:
    """The residuals of the least-squares refinement and their Jacobian, as functions of the variables ``z``
    (the kernel's 9 parameters, then the crank angle at each target when ``obj`` is untimed): ``2 n``
    distances along x and y, then the weighted constraint violation.  ``hi``: the parameters' upper bounds (a
    difference step that would cross one goes the other way)."""
    timed = obj.theta is not None
    n = len(obj.targets)
    th0 = obj.theta
    circ = np.array([circuit])
    w = np.sqrt(obj.penalty)
    hi = hi[:N_PARAMS] if timed else np.concatenate([hi[:N_PARAMS], np.full(n, np.inf)])

    def rows(Z: Array) -> Array:
        """Residuals of many variable vectors ``Z`` ``(K, m)`` in one kernel call: ``(K, 2 n + 1)``."""
        P = Z[:, :N_PARAMS]
        th = np.broadcast_to(th0, (len(Z), n)) if th0 is not None else Z[:, N_PARAMS:]
        x, y, ok = coupler_points(P, np.ascontiguousarray(th), np.full(len(Z), circ[0]))
        r = np.concatenate([x - obj.targets[:, 0], y - obj.targets[:, 1]], axis=1)
        r = np.where(np.concatenate([ok, ok], axis=1), r, obj.scale)
        v = violation(P, obj.cons, obj.scale, 2 * GRASHOF_MARGIN)
        return np.concatenate([r, (w * v)[:, None]], axis=1)

    def resid(z: Array) -> Array:
        return rows(z[None, :])[0]

    def jac(z: Array) -> Array:
        # forward differences exploiting the structure: the residuals at target i depend on the 9 parameters and
        # on theta_i only, so one extra row perturbing every theta at once gives all of d(x_i, y_i)/d(theta_i):
        # 10 or 11 kernel rows per Jacobian whatever the number of targets (all in one call)
        h = 1.49e-8 * np.maximum(1.0, np.abs(z))
        h = np.where(z + h > hi, -h, h)  # stay inside the bounds
        m = len(z)
        Z = np.repeat(z[None, :], N_PARAMS + 2 if not timed else N_PARAMS + 1, axis=0)
        Z[1 : N_PARAMS + 1, :N_PARAMS] += np.diag(h[:N_PARAMS])
        if not timed:
            Z[-1, N_PARAMS:] += h[N_PARAMS:]
        R = rows(Z)
        J = np.zeros((R.shape[1], m))
        J[:, :N_PARAMS] = ((R[1 : N_PARAMS + 1] - R[0]) / h[:N_PARAMS, None]).T
        if not timed:
            d = (R[-1] - R[0])[: 2 * n]
            i = np.arange(n)
            J[i, N_PARAMS + i] = d[:n] / h[N_PARAMS:]
            J[n + i, N_PARAMS + i] = d[n:] / h[N_PARAMS:]
        return J

    return resid, jac


def _refine(
    obj: PathObjective,
    row: Array,
    bounds: list[tuple[float, float]],
    max_nfev: int,
    method: str = "trf",
    theta0: Array | None = None,
    polish: bool = True,
) -> tuple[Array, Array, float]:
    """least_squares from ``row``: returns (row, theta at the targets, sse with penalties).

    ``method="lm"`` (Levenberg-Marquardt, no bounds: the constraints stay penalties) converges in far fewer
    evaluations on reachable targets; it needs at least as many residuals as variables (else trf is used).
    """
    from scipy.optimize import least_squares

    circ = np.array([1.0 if row[9] >= 0 else -1.0])
    lo = np.array([b[0] for b in bounds[:N_PARAMS]])
    hi = np.array([b[1] for b in bounds[:N_PARAMS]])
    timed = obj.theta is not None
    n = len(obj.targets)
    th0: Array = obj.theta if obj.theta is not None else (_nearest_theta(obj, row) if theta0 is None else theta0)
    resid, jac = _residual_functions(obj, float(circ[0]), hi)

    def split(z: Array) -> tuple[Array, Array]:
        return z[:N_PARAMS], (obj.theta if timed else z[N_PARAMS:])  # type: ignore[return-value]

    z0 = np.clip(row[:N_PARAMS], lo, hi)
    if not timed:
        z0 = np.concatenate([z0, th0])
        lo = np.concatenate([lo, np.full(n, -np.inf)])
        hi = np.concatenate([hi, np.full(n, np.inf)])
    # keep strictly inside the bounds (least_squares requires it)
    fin = np.isfinite(lo) & np.isfinite(hi)
    span = np.where(fin, hi - lo, 0.0)
    z0 = np.where(fin, np.clip(z0, np.where(fin, lo, 0.0) + 1e-9 * span, np.where(fin, hi, 0.0) - 1e-9 * span), z0)
    tight = {"xtol": 1e-14, "ftol": 1e-14, "gtol": 1e-14}
    if method == "lm" and 2 * n + 1 >= len(z0):
        res = least_squares(resid, z0, jac=jac, method="lm", x_scale="jac", max_nfev=max_nfev, **tight)
    else:
        res = least_squares(resid, z0, jac=jac, bounds=(lo, hi), method="trf", x_scale="jac", max_nfev=max_nfev, **tight)
    z, fun = res.x, res.fun
    if polish and np.sqrt(np.sum(fun**2)) <= NEWTON_FROM * obj.scale:
        z, fun = min_norm_newton(resid, jac, z, fun)
    p, th = split(z)
    out = np.append(p, row[9])
    return (
        out,
        np.asarray(th, float).copy(),
        float(obj.population(out[None, :], np.float64)[0])
        if timed
        else float(np.sum(fun[: 2 * n] ** 2) + (obj.penalty if violation(p[None, :], obj.cons, obj.scale)[0] > 0 else 0.0)),
    )


#: the residual norm (a fraction of the targets' size) under which a least-squares result is finished by
#: :func:`min_norm_newton`, and that finish's most iterations
NEWTON_FROM, NEWTON_ITERS = 0.05, 30


def min_norm_newton(resid: Any, jac: Any, z: Array, r: Array, iters: int = NEWTON_ITERS) -> tuple[Array, Array]:
    """Gauss-Newton from ``z`` (residuals ``r``) with minimum-norm steps (:func:`numpy.linalg.lstsq`), halving a
    step that does not lower the residual norm: the variables and residuals it ends at.

    On targets a four-bar passes through (a zero-residual problem) this converges quadratically onto the
    solutions; with fewer equations than unknowns (8 targets: 16 equations, 17 unknowns) the solutions form
    a curve and Levenberg-Marquardt crawls along its valley, while the minimum-norm step goes straight to
    the nearest solution.  Stops when the norm no longer falls or is at rounding level."""
    f = float(np.sum(r**2))
    for _ in range(iters):
        if f <= 1e-28:
            break
        dz = np.linalg.lstsq(jac(z), -r, rcond=None)[0]
        step = 1.0
        for _ in range(6):
            zn = z + step * dz
            with np.errstate(over="ignore", invalid="ignore"):  # a step too far overflows: inf, then halved
                rn = resid(zn)
                fn = float(np.sum(rn**2))
            fn = fn if np.isfinite(fn) else np.inf
            if fn < f:
                break
            step *= 0.5
        else:
            break
        gain = f - fn
        z, r, f = zn, rn, fn
        if gain <= 1e-6 * f and f > 0:
            break
    return z, r


def search_fourbar(
    targets: Array,
    theta: Array | None = None,
    cons: Constraints | None = None,
    bounds: list[tuple[float, float]] | None = None,
    n_sample: int = 100_000,
    maxiter: int = 200,
    popsize: int = 30,
    refine: int = 4,
    seed: int = 0,
    samples: int = 64,
) -> SearchResult:
    """Random sample, differential evolution, least-squares refinement (see the module)."""
    cons = cons if cons is not None else Constraints()
    import time

    targets = np.asarray(targets, float)
    th = None if theta is None else np.asarray(theta, float)
    obj = PathObjective(targets, th, cons, samples)
    b = bounds if bounds is not None else default_bounds(targets, cons, th is not None)
    lo = np.array([v[0] for v in b])
    hi = np.array([v[1] for v in b])
    stages: dict[str, float] = {}
    X, order, de = sampled_evolution(obj, obj.population, b, n_sample, popsize, maxiter, seed, stages)
    evals = n_sample + (int(de.nit) + 1) * min(n_sample, popsize * len(b))  # scipy counts calls, not candidates
    # refine the DE best and the best distinct candidates of the sample and the final population
    # half the starts from DE's final population (its basin), half from the sample's best (other basins)
    starts: list[Array] = []
    for pool, k in (
        (np.vstack([de.x[None, :], de.population[np.argsort(de.population_energies)]]), (refine + 1) // 2),
        (X[order[: 50 * refine]], refine),
    ):
        for row in pool:
            if len(starts) >= k:
                break
            if all(np.linalg.norm((row - s) / (hi - lo)) > 0.05 for s in starts):
                starts.append(row)
    t2 = time.perf_counter()
    best: tuple[float, Array, Array] | None = None
    for row in starts:
        r, tt, e = _refine(obj, row, b, max_nfev=REFINE_NFEV)
        if best is None or e < best[0]:
            best = (e, r, tt)
    stages["refine_s"] = time.perf_counter() - t2
    assert best is not None
    e, r, tt = best
    feasible = not constraint_failures(r[:N_PARAMS], cons)
    return SearchResult(r[:N_PARAMS], 1 if r[9] >= 0 else -1, tt, float(e), feasible, evals, stages)


def sampled_evolution(
    objective: Any,
    sample_cost: Any,
    b: list[tuple[float, float]],
    n_sample: int,
    popsize: int,
    maxiter: int,
    seed: int,
    stages: dict[str, float] | None = None,
) -> tuple[Array, NDArray[np.intp], Any]:
    """The global search's first two steps: ``n_sample`` uniform random rows within the bounds ``b`` (seeded
    ``seed``), their costs (``sample_cost`` of the rows ``(n_sample, len(b))``), then
    :func:`scipy.optimize.differential_evolution` of the vectorised ``objective`` (columns are candidates) started
    from the ``popsize * len(b)`` cheapest, ``maxiter`` generations, no polish.  Returns the sample, its order
    (cheapest first) and scipy's result; ``stages`` gains ``sample_s`` and ``de_s`` (seconds)."""
    import time

    from scipy.optimize import differential_evolution

    lo = np.array([v[0] for v in b])
    hi = np.array([v[1] for v in b])
    t0 = time.perf_counter()
    X = lo + (hi - lo) * np.random.default_rng(seed).random((n_sample, len(b)))
    order = np.argsort(sample_cost(X), kind="stable")
    t1 = time.perf_counter()
    de = differential_evolution(
        objective,
        b,
        init=X[order[: popsize * len(b)]],
        maxiter=maxiter,
        tol=0.0,
        atol=0.0,
        seed=seed,
        vectorized=True,
        updating="deferred",
        polish=False,
        mutation=(0.5, 1.0),
        recombination=0.9,
    )
    if stages is not None:
        stages["sample_s"], stages["de_s"] = t1 - t0, time.perf_counter() - t1
    return X, order, de


def max_distance(obj: PathObjective, row: Array, theta: Array) -> float:
    """Largest distance from a target to the coupler point of ``row`` at ``theta`` (inf if it cannot close)."""
    x, y, ok = coupler_points(row[None, :N_PARAMS], theta[None, :], np.array([1.0 if row[9] >= 0 else -1.0]))
    if not ok.all():
        return float("inf")
    return float(np.max(np.hypot(x[0] - obj.targets[:, 0], y[0] - obj.targets[:, 1])))


def turn_steps(theta: Array) -> Array | None:
    """The signed steps (radians) of crank angles ``theta`` (one per target, in the targets' order) when they run one
    way round within one turn: each in ``[0, 2 pi)`` counter-clockwise, else each in ``(-2 pi, 0]`` clockwise;
    None when they run neither way (the branch does not pass the targets in their order)."""
    d = np.diff(np.asarray(theta, float))
    span = 2 * np.pi * (1 - 1e-9)
    fwd = np.mod(d, 2 * np.pi)
    if fwd.sum() < span:
        return fwd
    back = -np.mod(-d, 2 * np.pi)
    return back if -back.sum() < span else None


def in_order(theta: Array) -> bool:
    """Whether crank angles ``theta`` (radians, one per target in the targets' order) run one way round
    within one turn: the branch passes the targets in their order (:func:`turn_steps`)."""
    return turn_steps(theta) is not None


#: a refined start this near (largest distance over the targets' size), in order when asked and keeping the
#: constraints, ends the trying of further starts when the search's stop is below it: it goes on in the joints'
#: positions instead (:func:`planar.synth.positions.polish_positions`), as the rocking search's ``BASIN`` does.
#: On development part-curves (seed 778, 40 at 8 and 40 at 12 targets) the same were recovered within 1e-6 (38 and
#: 37), and 11 that had gone through the later stages for 4 to 6 s of CPU ended in 0.9 to 2.0 s, 1e-14 to 2e-7 of
#: the size off where the later stages had reached 2e-15 to 2e-7
BASIN = 1e-6


def basin_for(tolerance: float, basin: float = BASIN) -> float:
    """The basin a search answering to ``tolerance`` (a largest distance over the targets' size) uses: ``basin``
    (:data:`BASIN`, or the rocking search's :data:`planar.synth.arcs.BASIN`), or a tenth of the tolerance when that is
    smaller, so a near result ends the search well within the tolerance."""
    return min(basin, tolerance / 10)


def search_atlas(
    targets: Array,
    atlas: Any,
    cons: Constraints | None = None,
    neighbours: int = 64,
    refine: int = 16,
    stop: float | Any = 1e-9,
    samples: int = 128,
    ordered: bool = False,
    windows: Callable[[Array, int], Array] | None = None,
    basin: float = BASIN,
) -> SearchResult:
    """Untimed targets (normalised: centroid 0, size 1) from an atlas (:mod:`planar.synth.atlas`), refined.

    The atlas gives ``8 neighbours`` candidates (:func:`planar.synth.atlas.candidates`); they are scored
    by the untimed objective at ``samples`` crank angles, and the ``refine`` best distinct ones are refined
    by least squares (crank angles at the targets free), best first, stopping early once the largest
    distance to a target is at most ``stop`` (model units of the normalised targets; or, a function of a row and
    its crank angles at the targets, once it returns True).  ``ordered``: a result whose branch passes the targets
    out of order (:func:`in_order`) is kept only if no other is found.  ``windows``: None, or a function of the
    targets and a number of neighbours giving candidate rows from the curve-window atlas
    (:func:`planar.synth.windows.window_candidates` on an atlas, loaded when first called).  ``basin``: after the
    windows' starts, the first look-up of refined curves and the wide lookup's serial starts, a best result within it
    (largest distance, with ``stop`` below it) is finished in the joints' positions and ends the search
    (:data:`BASIN`).

    When the first starts fail, the targets are looked up as part of a closed curve too: the ``refine`` best of
    their ``4 neighbours`` nearest windows (:func:`planar.synth.windows.window_candidates`) are refined.  The
    spline through targets on an arc of the crank's turn closes the gap with a curve no four-bar traces, and
    their closed-curve neighbours miss (development part-curves, seed 777, 20 each: 8 targets 18 -> 20 of 20
    within 1e-6, median CPU 2.56 -> 0.74 s; 12 targets 18 -> 19, 1.94 -> 0.73 s).

    When none reaches ``stop`` (nor the windows' starts), the later stages run in turn until one does: one round of
    looking up the best refined curves (:func:`_requery`), the wide lookup (:func:`_wide_candidates`), the batch of starts
    (:func:`_batch_starts`), :data:`REQUERY_ROUNDS` more rounds of looking up, and the two best refined for longer.
    The first round of looking up came before the wide lookup after measuring (seed 20261204, never used to tune:
    drag-links' whole curves at 8 targets 56 -> 58 of 60 within 1e-6, median CPU 1.58 -> 0.93 s; crank-rockers and
    12 targets the same or faster; docs/explanation/coupler-curve-atlas.md).
    """
    import time

    from planar.synth.atlas import candidates

    cons = cons if cons is not None else Constraints()
    t = np.asarray(targets, float)
    obj = PathObjective(t, None, cons, samples)
    b = default_bounds(t, cons, False, turn=3 * np.pi)  # the ground line's angle: no wall at +-pi near a candidate
    stages: dict[str, float] = {}
    t0 = time.perf_counter()
    every = candidates(atlas, t, neighbours)
    stages["atlas_s"] = time.perf_counter() - t0
    t1 = time.perf_counter()
    done: list[tuple[float, Array, Array]] = []
    tried: list[Array] = []
    wide: list[Array] = []
    found = _refine_starts(obj, cons, b, every, refine, ordered, stop, done, tried)
    if not found and windows is not None:  # part of a closed curve: its windows' neighbours (the spline closed it)
        t2 = time.perf_counter()
        found = _refine_starts(obj, cons, b, windows(t, neighbours), refine, ordered, stop, done, tried)
        stages["windows_s"] = time.perf_counter() - t2
    # none reached ``stop``: the curves of the best refined four-bars looked up (they pass near every target, so
    # they describe the targets' curve better than the targets' own spline, rough across the gaps between sparse
    # targets): one round before the wide lookup, more after the batch stage
    found = found or _basin(obj, cons, ordered, stop, done, basin)
    found = found or _requery(obj, atlas, cons, b, ordered, stop, done, tried)
    found = found or _basin(obj, cons, ordered, stop, done, basin)
    if not found:
        wide.append(_wide_candidates(atlas, obj, BATCH_STARTS))
        found = _refine_starts(obj, cons, b, wide[0][:WIDE_KEEP], WIDE_REFINE, ordered, stop, done, tried)
    found = found or _basin(obj, cons, ordered, stop, done, basin)
    if not found and not _batch_starts(obj, cons, b, wide[0], ordered, stop, done, tried):
        for _ in range(REQUERY_ROUNDS):
            if _requery(obj, atlas, cons, b, ordered, stop, done, tried):
                break
        else:
            _longer(obj, cons, b, ordered, stop, done)
    stages["refine_s"] = time.perf_counter() - t1 - stages.get("windows_s", 0.0)  # each second in one stage
    best = min(done, key=lambda d: d[0])
    e, r, tt = best
    feasible = not constraint_failures(r[:N_PARAMS], cons)
    return SearchResult(r[:N_PARAMS], 1 if r[9] >= 0 else -1, tt, float(e), feasible, len(tried), stages)


def _basin(
    obj: PathObjective,
    cons: Constraints,
    ordered: bool,
    stop: float | Any,
    done: list[tuple[float, Array, Array]],
    basin: float,
) -> bool:
    """Whether the best refined so far (of the three best by their sums of squares) is within ``basin`` (largest
    distance; a float ``stop`` below it): then it goes on in the joints' positions (appended to ``done``) and the
    search ends with it."""
    if callable(stop) or stop >= basin or not done:
        return False
    for _, r, tt in sorted(done, key=lambda d: d[0])[:3]:
        if ordered and not in_order(tt):
            continue
        if violation(r[None, :N_PARAMS], cons, obj.scale, 0.0)[0] > 0 or max_distance(obj, r, tt) > basin:
            continue
        r2, tt2 = polish_positions(obj.targets, r, tt, max_ratio=cons.max_ratio)
        _record(obj, cons, r2, tt2, _sse(obj, r2, tt2), ordered, stop, done)
        return True
    return False


def _longer(
    obj: PathObjective,
    cons: Constraints,
    b: list[tuple[float, float]],
    ordered: bool,
    stop: float | Any,
    done: list[tuple[float, Array, Array]],
) -> None:
    """The last stage of :func:`search_atlas`: the two best refined go on (Levenberg-Marquardt can crawl along a
    valley; on 8 targets, underdetermined, it sometimes needs a thousand evaluations), each then in the joints'
    positions (:func:`planar.synth.positions.polish_positions`) when still short of ``stop``; appended to ``done``."""
    for _, r, tt in sorted(done, key=lambda d: d[0])[:2]:
        if _refined(obj, cons, b, r, tt, 10 * REFINE_NFEV, ordered, stop, done):
            return
        _, r2, tt2 = done[-1]
        r3, tt3 = polish_positions(obj.targets, r2, tt2, max_ratio=cons.max_ratio)
        if _record(obj, cons, r3, tt3, _sse(obj, r3, tt3), ordered, stop, done):
            return


#: the wide lookup, when the targets' nearest entries fail: neighbours per query (8 queries), the best kept by a
#: cheap similarity fit on a coarse curve (samples) and how many of them are refined
WIDE_K, WIDE_KEEP, WIDE_SAMPLES, WIDE_REFINE = 4000, 256, 32, 16


def _wide_candidates(atlas: Any, obj: PathObjective, keep: int = WIDE_KEEP) -> Array:
    """Many more of the targets' atlas neighbours (:data:`WIDE_K` per query), ranked by the distance from each
    target to the nearest point of the candidate's coupler curve after a similarity fit on a coarse curve
    (:func:`align_candidates` at :data:`WIDE_SAMPLES` crank angles): the ``keep`` best, best first.

    Across the gaps between sparse targets their spline differs from the true curve, so the true curve's own
    neighbours can rank thousands deep among the spline's; the fit to the targets themselves ranks them again."""
    from planar.synth.atlas import candidates

    C = candidates(atlas, obj.targets, WIDE_K)
    A, score = align_candidates(obj, C, samples=WIDE_SAMPLES)
    return A[np.argsort(score, kind="stable")[:keep]]


#: the batch stage, when the wide lookup's serial refinements fail: how many of the wide candidates are refined at
#: once (:func:`batch_lm`), its iterations (the crank angles assigned afresh every :data:`REASSIGN_NFEV`), and how
#: many of its best results are finished one by one
BATCH_STARTS, BATCH_ITERS, BATCH_FINISH = 512, 60, 16


def _batch_starts(
    obj: PathObjective,
    cons: Constraints,
    b: list[tuple[float, float]],
    wide: Array,
    ordered: bool,
    stop: float | Any,
    done: list[tuple[float, Array, Array]],
    tried: list[Array],
) -> bool:
    """Levenberg-Marquardt on the :data:`BATCH_STARTS` best wide candidates at once (:func:`batch_lm`, a few
    hundred starts for the price of a few serial ones), then the :data:`BATCH_FINISH` best of its results finished
    by :func:`_refined` with their crank angles (appended to ``done``); whether one reached ``stop``.

    Eight targets leave a one-parameter family of four-bars through them and many curves that pass near all
    eight: the serial refinements of the best-fitting wide candidates stop at local minima 1e-5 to 1e-3 of the
    size off, while somewhere among the next few hundred a start lies in the basin of an exact four-bar."""
    if len(wide) == 0:
        return False
    C, _ = align_candidates(obj, wide[:BATCH_STARTS])
    Z, f = batch_lm(obj, C, BATCH_ITERS)
    lo = np.array([v[0] for v in b])
    hi = np.array([v[1] for v in b])
    n0 = len(tried)
    for j in np.argsort(f, kind="stable"):
        if len(tried) - n0 >= BATCH_FINISH or not np.isfinite(f[j]):
            break
        row = np.append(Z[j, :N_PARAMS], C[j, 9])
        if all(np.linalg.norm((row - s) / (hi - lo)) > 1e-6 for s in tried[n0:]):
            tried.append(row)
            if _refined(obj, cons, b, row, Z[j, N_PARAMS:], REFINE_NFEV, ordered, stop, done):
                return True
    return False


def _batch_residuals(obj: PathObjective, Z: Array, circ: Array) -> Array:
    """The refinement's residuals (:func:`_residual_functions`) of many variable vectors ``Z`` ``(K, 9 + N)`` with
    circuits ``circ`` ``(K,)``: ``(K, 2 N + 1)``."""
    P = Z[:, :N_PARAMS]
    x, y, ok = coupler_points(P, np.ascontiguousarray(Z[:, N_PARAMS:]), circ)
    r = np.concatenate([x - obj.targets[:, 0], y - obj.targets[:, 1]], axis=1)
    r = np.where(np.concatenate([ok, ok], axis=1), r, obj.scale)
    v = violation(P, obj.cons, obj.scale, 2 * GRASHOF_MARGIN)
    return np.concatenate([r, (np.sqrt(obj.penalty) * v)[:, None]], axis=1)


def _batch_jacobian(obj: PathObjective, Z: Array, circ: Array, R0: Array) -> Array:
    """Forward-difference Jacobians ``(K, 2 N + 1, 9 + N)`` of :func:`_batch_residuals` at ``Z`` (residuals ``R0``),
    structured as in :func:`_residual_functions` (10 kernel rows per start, all starts in one call)."""
    K, m = Z.shape
    n = m - N_PARAMS
    h = 1.49e-8 * np.maximum(1.0, np.abs(Z))
    E = np.repeat(Z[:, None, :], N_PARAMS + 1, axis=1)
    i9 = np.arange(N_PARAMS)
    E[:, i9, i9] += h[:, :N_PARAMS]
    E[:, -1, N_PARAMS:] += h[:, N_PARAMS:]
    R = _batch_residuals(obj, E.reshape(-1, m), np.repeat(circ, N_PARAMS + 1)).reshape(K, N_PARAMS + 1, -1)
    J = np.zeros((K, R.shape[2], m))
    J[:, :, :N_PARAMS] = np.transpose((R[:, :N_PARAMS] - R0[:, None, :]) / h[:, :N_PARAMS, None], (0, 2, 1))
    d = (R[:, -1] - R0)[:, : 2 * n]
    i = np.arange(n)
    J[:, i, N_PARAMS + i] = d[:, :n] / h[:, N_PARAMS:]
    J[:, n + i, N_PARAMS + i] = d[:, n:] / h[:, N_PARAMS:]
    return J


def _structured_normal(J: Array, R: Array) -> tuple[Array, ...]:
    """The normal equations of Jacobians ``J`` ``(K, 2 N + 1, 9 + N)`` (:func:`_batch_jacobian`) and residuals ``R``,
    in the blocks their structure leaves: ``A_pp`` ``(K, 9, 9)`` (the parameters), ``A_tp`` ``(K, N, 9)``,
    the diagonal ``a_tt`` ``(K, N)`` (crank angle ``i`` moves only target ``i``'s residuals), and the gradient's
    parts ``g_p`` ``(K, 9)``, ``g_t`` ``(K, N)``."""
    n = J.shape[2] - N_PARAMS
    i = np.arange(n)
    Jp = J[:, :, :N_PARAMS]
    jx, jy = J[:, i, N_PARAMS + i], J[:, n + i, N_PARAMS + i]
    App = np.matmul(Jp.transpose(0, 2, 1), Jp)
    Atp = Jp[:, :n, :] * jx[:, :, None] + Jp[:, n : 2 * n, :] * jy[:, :, None]
    att = jx * jx + jy * jy
    gp = np.matmul(Jp.transpose(0, 2, 1), R[:, :, None])[:, :, 0]
    gt = jx * R[:, :n] + jy * R[:, n : 2 * n]
    return App, Atp, att, gp, gt


def _damped_step(normal: tuple[Array, ...], lam: Array) -> Array:
    """Levenberg-Marquardt steps ``(K, 9 + N)`` of the structured normal equations (:func:`_structured_normal`)
    damped by ``lam`` ``(K,)`` times their diagonal (Marquardt's scaling): the crank angles eliminated (their block
    is diagonal), a 9 x 9 Schur complement solved per start, the angles' steps back-substituted.  The same steps as
    solving the whole ``(9 + N)`` system, at a cost linear in ``N``."""
    App, Atp, att, gp, gt = normal
    dp = np.einsum("kjj->kj", App) + 1e-12
    T = att + lam[:, None] * (att + 1e-12)
    W = Atp / T[:, :, None]
    S = App + (lam[:, None] * dp)[:, :, None] * np.eye(N_PARAMS) - np.matmul(W.transpose(0, 2, 1), Atp)
    rhs = -gp + np.matmul(W.transpose(0, 2, 1), gt[:, :, None])[:, :, 0]
    sp = np.linalg.solve(S, rhs[:, :, None])[:, :, 0]
    st = (-gt - np.matmul(Atp, sp[:, :, None])[:, :, 0]) / T
    return np.concatenate([sp, st], axis=1)


def batch_lm(obj: PathObjective, C: Array, iters: int, reassign: int = 10) -> tuple[Array, Array]:
    """Levenberg-Marquardt from many starts at once: candidate rows ``C`` ``(K, 10)`` on untimed targets, the
    crank angles at the targets assigned on each start's curve (:func:`assign_theta`) and again every
    ``reassign`` iterations; ``iters`` iterations, each one kernel call for every start's Jacobian and a batched
    solve of the damped normal equations (Marquardt's diagonal scaling, the damping per start divided by 3 after
    a step that lowers its sum of squares, multiplied by 4 after one that does not, up to 4 tries).  Returns the
    variables ``(K, 9 + N)`` (parameters, then the crank angles) and their sums of squares with penalties ``(K,)``.

    Cheaper per start than :func:`scipy.optimize.least_squares`, since the small algebra of all starts runs in a
    few numpy calls; it is a screening step: the best results are finished by :func:`_refine`."""
    K = len(C)
    circ = np.where(C[:, 9] >= 0, 1.0, -1.0)
    m = N_PARAMS + len(obj.targets)
    Z = np.empty((K, m))
    Z[:, :N_PARAMS] = C[:, :N_PARAMS]
    lam = np.full(K, 1e-3)
    f = np.full(K, np.inf)
    R = np.zeros((K, 2 * len(obj.targets) + 1))
    # a step too far overflows: its sum of squares is inf and the step is not taken (pending, lam raised)
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        for it in range(iters):
            if it % reassign == 0:
                Z[:, N_PARAMS:] = assign_theta_batch(obj, np.column_stack([Z[:, :N_PARAMS], circ]))
                R = _batch_residuals(obj, Z, circ)
                f = np.sum(R**2, axis=1)
            normal = _structured_normal(_batch_jacobian(obj, Z, circ, R), R)
            pending = np.isfinite(f)
            for _ in range(4):
                step = _damped_step(normal, lam)
                Rn = _batch_residuals(obj, Z + step, circ)
                fn = np.sum(Rn**2, axis=1)
                better = pending & np.isfinite(fn) & (fn < f)
                Z[better] += step[better]
                R[better], f[better] = Rn[better], fn[better]
                lam = np.where(better, lam / 3, np.where(pending, lam * 4, lam))
                pending &= ~better
                if not pending.any():
                    break
    return Z, f


#: after the batch stage: rounds of looking up the best refined curves (:func:`_requery`; one round also runs before
#: the wide lookup), from how many of them, the neighbours of each (in both normalisations) and how many of those are
#: refined per round
REQUERY_ROUNDS, REQUERY_FROM, REQUERY_K, REQUERY_REFINE = 4, 3, 16, 8


def _requery(
    obj: PathObjective,
    atlas: Any,
    cons: Constraints,
    b: list[tuple[float, float]],
    ordered: bool,
    stop: float | Any,
    done: list[tuple[float, Array, Array]],
    tried: list[Array],
) -> bool:
    """One round of looking up the curves of the :data:`REQUERY_FROM` best refined four-bars in ``done``
    (:func:`planar.synth.atlas.curve_candidates`, :data:`REQUERY_K` neighbours each) and refining the
    :data:`REQUERY_REFINE` best of those not ``tried`` (:func:`_refine_starts`); whether one reached ``stop``."""
    from planar.synth.atlas import curve_candidates

    top = sorted(done, key=lambda d: d[0])[:REQUERY_FROM]
    near = [curve_candidates(atlas, _curve(r), REQUERY_K) for _, r, _ in top]
    return bool(near) and _refine_starts(obj, cons, b, np.concatenate(near), REQUERY_REFINE, ordered, stop, done, tried)


def _curve(row: Array, n: int = 128) -> NDArray[np.complex128]:
    """The coupler curve of ``row`` at ``n`` crank angles over the turn, as complex points."""
    th = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    x, y, _ = coupler_points(row[None, :N_PARAMS], th, np.array([1.0 if row[9] >= 0 else -1.0]))
    return x[0] + 1j * y[0]


#: similarity fits (nearest points, then scale, rotation and position by least squares) per candidate before ranking
ALIGN_ROUNDS = 3


def align_candidates(obj: PathObjective, C: Array, samples: int = 64, block: int = 256) -> tuple[Array, Array]:
    """Candidate rows ``C`` ``(R, 10)`` moved by the similarity (scale, rotation, position) that best maps
    their coupler curves onto the targets, and their untimed objective after it ``(R,)``.

    An atlas entry is placed by the descriptors of its curve and of the targets' spline; across the gaps
    between sparse targets that spline differs from the true curve, and so does the placement.  Here each
    candidate's curve (``samples`` crank angles) is matched to the targets by nearest points and the
    similarity solved in closed form (complex least squares), :data:`ALIGN_ROUNDS` times, all candidates of a
    ``block`` at once."""
    t = obj.targets[:, 0] + 1j * obj.targets[:, 1]
    th = np.linspace(0.0, 2 * np.pi, samples, endpoint=False)
    out = C.copy()
    score = np.full(len(C), np.inf)
    for i in range(0, len(C), block):
        R = C[i : i + block]
        x, y, ok = coupler_points(R[:, :N_PARAMS], th, np.where(R[:, 9] >= 0, 1.0, -1.0))
        z = x + 1j * y
        good = ok.all(1)
        a = np.ones(len(R), complex)
        b0 = np.zeros(len(R), complex)
        for _ in range(ALIGN_ROUNDS):
            w = a[:, None] * z + b0[:, None]
            d2 = np.abs(w[:, None, :] - t[None, :, None]) ** 2  # (R, N, S)
            j = np.argmin(d2, axis=2)
            m = np.take_along_axis(z, j, axis=1)  # the matched curve points, before the similarity
            mc = m - m.mean(1, keepdims=True)
            tc = t[None, :] - t.mean()
            den = np.sum(np.abs(mc) ** 2, axis=1)
            a = np.where(den > 0, np.sum(np.conj(mc) * tc, axis=1) / np.where(den > 0, den, 1.0), 1.0)
            b0 = t.mean() - a * m.mean(1)
        w = a[:, None] * z + b0[:, None]
        sc = np.sum(np.min(np.abs(w[:, None, :] - t[None, :, None]) ** 2, axis=2), axis=1)
        moved = _moved(R, a, b0)
        use = good & np.isfinite(sc) & (np.abs(a) > 0)
        out[i : i + block][use] = moved[use]
        score[i : i + block][use] = sc[use]
    return out, score


def _moved(R: Array, a: NDArray[np.complex128], b0: NDArray[np.complex128]) -> Array:
    """Candidate rows ``R`` ``(K, 10)`` moved by the similarities ``w = a z + b0`` (complex, one per row): lengths
    and coupler point scaled by ``|a|``, the crank pivot mapped, the ground line turned by ``arg a``."""
    k = np.abs(a)
    o = a * (R[:, 6] + 1j * R[:, 7]) + b0
    moved = R.copy()
    moved[:, :6] *= k[:, None]
    moved[:, 6], moved[:, 7] = o.real, o.imag
    moved[:, 8] = np.mod(R[:, 8] + np.angle(a) + np.pi, 2 * np.pi) - np.pi
    return moved


def timed_starts(atlas: Any, obj: PathObjective, k: int = 64) -> Array:
    """Starts for timed targets (``obj.theta`` given): the targets' atlas neighbours (:func:`planar.synth.atlas.candidates`,
    ``k`` per query), each moved by the similarity that best maps its coupler points at the prescribed crank angles
    onto the targets (the correspondence is known: closed-form complex least squares), best first by what remains.

    The crank angle is measured from the ground line, which the similarity turns with the linkage, so an atlas
    neighbour of the four-bar itself lands near it; a cognate or a mirror image (same curve, other timing) does
    not, and ranks low."""
    from planar.synth.atlas import candidates

    C = candidates(atlas, obj.targets, k)
    if len(C) == 0:
        return C
    th = np.broadcast_to(np.asarray(obj.theta, float), (len(C), len(obj.targets)))
    x, y, ok = coupler_points(C[:, :N_PARAMS], np.ascontiguousarray(th), np.where(C[:, 9] >= 0, 1.0, -1.0))
    z = x + 1j * y
    t = obj.targets[:, 0] + 1j * obj.targets[:, 1]
    zc = z - z.mean(1, keepdims=True)
    den = np.sum(np.abs(zc) ** 2, axis=1)
    a = np.where(den > 0, np.sum(np.conj(zc) * (t - t.mean())[None, :], axis=1) / np.where(den > 0, den, 1.0), 0.0)
    b0 = t.mean() - a * z.mean(1)
    score = np.sum(np.abs(a[:, None] * z + b0[:, None] - t[None, :]) ** 2, axis=1)
    score = np.where(ok.all(1) & (np.abs(a) > 0) & np.isfinite(score), score, np.inf)
    order = np.argsort(score, kind="stable")
    return _moved(C, a, b0)[order[np.isfinite(score[order])]]


def _refine_starts(
    obj: PathObjective,
    cons: Constraints,
    b: list[tuple[float, float]],
    every: Array,
    refine: int,
    ordered: bool,
    stop: float | Any,
    done: list[tuple[float, Array, Array]],
    tried: list[Array],
) -> bool:
    """Score candidate rows ``every`` by the untimed objective and refine the ``refine`` best that differ from
    each other and from those ``tried`` before (appended to it), best first; whether one reached ``stop``."""
    lo = np.array([v[0] for v in b])
    hi = np.array([v[1] for v in b])
    if len(every) == 0:
        return False
    every, _ = align_candidates(obj, every)
    inside = np.all((every - lo >= 0) & (hi - every >= 0), axis=1)
    C = every[inside] if inside.any() else np.clip(every, lo, hi)
    f = obj.population(C, np.float64)
    n0 = len(tried)
    for row in C[np.argsort(f, kind="stable")]:
        if len(tried) - n0 >= refine:
            break
        if all(np.linalg.norm((row - s) / (hi - lo)) > 1e-3 for s in tried):
            tried.append(row)
            if _refined(obj, cons, b, row, None, REFINE_NFEV, ordered, stop, done):
                return True
    return False


#: re-assignments of the crank angles at the targets in :func:`reassigned_refine`, and the evaluations between them
REASSIGN_ROUNDS, REASSIGN_NFEV = 8, 10


def assign_theta(obj: PathObjective, row: Array, n: int = 256) -> Array:
    """Crank angles at the targets on the curve of ``row``: in the targets' order (:func:`ordered_theta`) when
    that costs at most 10 times the nearest points' squared distance (the targets then run along the curve),
    else each target's nearest point."""
    th, d2 = _curve_d2(obj, row, n)
    return _assigned(d2, th)


def _assigned(d2: Array, th: Array) -> Array:
    """:func:`assign_theta` from the squared distances ``d2`` ``(N, n)`` of the targets to a curve at ``th``."""
    near = th[np.argmin(d2, axis=1)]
    cost_near = float(np.sum(np.min(d2, axis=1)))
    if not np.isfinite(cost_near):
        return near
    ordered, cost = ordered_theta(d2, th)
    return ordered if cost <= 10.0 * cost_near + 1e-30 else near


def assign_theta_batch(obj: PathObjective, rows: Array, n: int = 256) -> Array:
    """:func:`assign_theta` for candidate rows ``rows`` ``(K, 10)`` (the same angles ``(K, N)``), their curves solved
    by one kernel call."""
    th = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    x, y, ok = coupler_points(rows[:, :N_PARAMS], th, np.where(rows[:, 9] >= 0, 1.0, -1.0))
    out = np.empty((len(rows), len(obj.targets)))
    for k in range(len(rows)):
        d2 = (x[k][None, :] - obj.targets[:, 0:1]) ** 2 + (y[k][None, :] - obj.targets[:, 1:2]) ** 2
        d2[:, ~ok[k]] = np.inf
        out[k] = _assigned(d2, th)
    return out


def reassigned_refine(
    obj: PathObjective, row: Array, b: list[tuple[float, float]], nfev: int, stop: float | Any
) -> tuple[Array, Array, float]:
    """Levenberg-Marquardt on the targets with the crank angles free, in short runs of :data:`REASSIGN_NFEV`
    evaluations between which the angles are assigned afresh on the current curve (:func:`assign_theta`), then
    one run of the remaining evaluations; stops early once the largest distance is at most ``stop``.

    The joint problem (nine dimensions and one angle per target) has local minima where a target is matched
    to the wrong part of the curve; re-assigning lets it leave them.  From the true four-bar with its nine
    dimensions changed by 5 % (12 targets, 100 random crank-rockers), one run from the nearest points
    converged in 67 %, from the ordered points 81 %, with these re-assignments 92 %."""
    r = row
    spent = 0
    for _ in range(REASSIGN_ROUNDS):
        if spent + REASSIGN_NFEV >= nfev:
            break
        r, tt, e = _refine(obj, r, b, max_nfev=REASSIGN_NFEV, method="lm", theta0=assign_theta(obj, r))
        spent += REASSIGN_NFEV
        if _reached(obj, r, tt, stop):
            return r, tt, e
    return _refine(obj, r, b, max_nfev=max(nfev - spent, REASSIGN_NFEV), method="lm", theta0=assign_theta(obj, r))


def _refined(
    obj: PathObjective,
    cons: Constraints,
    b: list[tuple[float, float]],
    row: Array,
    theta0: Array | None,
    nfev: int,
    ordered: bool,
    stop: float | Any,
    done: list[tuple[float, Array, Array]],
) -> bool:
    """Refine one start (appended to ``done``); whether it reached ``stop`` keeping the constraints (and order).
    Without ``theta0`` the start is an atlas entry placed on the targets (:func:`planar.synth.positions.refined_start`:
    ``nfev`` is not used); with it, ``nfev`` evaluations of Levenberg-Marquardt from those angles."""
    if theta0 is None:
        r, tt = refined_start(obj, row, b, stop, cons.max_ratio)
        e = _sse(obj, r, tt)
    else:
        r, tt, e = _refine(obj, row, b, max_nfev=nfev, method="lm", theta0=theta0)
    return _record(obj, cons, r, tt, e, ordered, stop, done)


def _record(
    obj: PathObjective,
    cons: Constraints,
    r: Array,
    tt: Array,
    e: float,
    ordered: bool,
    stop: float | Any,
    done: list[tuple[float, Array, Array]],
) -> bool:
    """Append a refined row ``r`` (crank angles ``tt``, sum of squares with penalties ``e``) to ``done``, ranked
    for :func:`search_atlas`'s pick: one out of order after any in order; one that ends the search (within ``stop``,
    in order when asked, keeping the constraints as the design's check does) by its bare sum of squares, since
    the penalty keeps a wider margin from a change point than the check and would rank it behind a worse result
    the search then returns.  Returns whether it ends the search."""
    ok_order = in_order(tt) or not ordered
    ends = ok_order and _reached(obj, r, tt, stop) and not violation(r[None, :N_PARAMS], cons, obj.scale, 0.0)[0] > 0
    if ends:
        e = _sse(obj, r, tt, penalise=False)
    done.append((e if ok_order else e + obj.penalty, r, tt))  # out of order: worse than any in-order result
    return bool(ends)


#: one start of an atlas search (:func:`refined_start`): Levenberg-Marquardt evaluations in the kernel's lengths and
#: angles from angles assigned on the start's curve, then iterations in the joints' positions
START_NFEV, START_ITERS = 10, 120


def refined_start(
    obj: PathObjective, row: Array, b: list[tuple[float, float]], stop: float | Any, max_ratio: float, floor: float = 0.0
) -> tuple[Array, Array]:
    """One atlas start ``row`` (9 parameters and the circuit) refined on the untimed targets of ``obj``:
    :data:`START_NFEV` evaluations of Levenberg-Marquardt in the kernel's lengths and angles from angles assigned on
    its curve (:func:`reassigned_refine`: they carry an atlas entry's placement onto the targets), then, unless that
    reaches ``stop`` (a largest distance, or a function of the row and its angles as :func:`search_atlas` takes),
    :data:`START_ITERS` iterations in the joints' positions (:func:`planar.synth.positions.polish_positions`, keeping
    the transmission angle at the targets ``floor`` rad from a toggle when above 0), kept when nearer.  Returns the
    row and its input angles at the targets.

    Measured on development problems (seeds 777 to 779, 1 BLAS thread, CPU medians), against 200 evaluations in
    the lengths and angles per start: double- and triple-rockers at 8 and 12 targets (with 32 starts instead of
    16) 63 -> 73 of 80 within 1e-6 at medians 0.51-1.49 -> 0.48-1.18 s; drag-links' whole curves at 8 targets
    46 -> 47 of 50, 12 targets 20 -> 20 of 20, medians 0.22-0.76 -> 0.16-0.22 s; part-curves at 8 targets 17 -> 18
    of 20, median 3.64 -> 0.51 s; crank-rockers at 8 targets 58 -> 57 of 60, medians 0.19-0.26 -> 0.11-0.13 s
    (docs/explanation/coupler-curve-atlas.md).  The rocking search's starts have since gone to the joints' positions
    from the first step (:func:`planar.synth.arcs.arc_start`)."""
    r, tt, _ = reassigned_refine(obj, row, b, START_NFEV, stop)
    if _reached(obj, r, tt, stop):
        return r, tt
    r2, tt2 = polish_positions(obj.targets, r, tt, START_ITERS, max_ratio, floor)
    return (r2, tt2) if max_distance(obj, r2, tt2) < max_distance(obj, r, tt) else (r, tt)


def _sse(obj: PathObjective, row: Array, theta: Array, penalise: bool = True) -> float:
    """The refinement's sum of squares of an untimed ``row`` at crank angles ``theta``, with the constraint penalty
    when it breaks one (as :func:`_refine` returns; without it when not ``penalise``)."""
    x, y, ok = coupler_points(row[None, :N_PARAMS], theta[None, :], np.array([1.0 if row[9] >= 0 else -1.0]))
    if not ok.all():
        return float(np.inf)
    sse = float(np.sum((x[0] - obj.targets[:, 0]) ** 2 + (y[0] - obj.targets[:, 1]) ** 2))
    broken = penalise and violation(row[None, :N_PARAMS], obj.cons, obj.scale)[0] > 0
    return sse + (obj.penalty if broken else 0.0)


def _reached(obj: PathObjective, row: Array, theta: Array, stop: float | Any) -> bool:
    """Whether a refined ``row`` (crank angles ``theta`` at the targets) ends the search: its largest distance is
    at most ``stop``, or ``stop`` (a function of the row and the angles) says so."""
    return bool(stop(row, theta)) if callable(stop) else max_distance(obj, row, theta) <= stop


#: timed targets: the untimed largest distance (the targets' size 1) from which a refined curve is refined with the
#: crank angles fixed, and the timed largest distance that ends the search
TIMED_FROM, TIMED_STOP = 1e-6, 1e-9

#: timed targets: how many direct starts (:func:`timed_starts`) are refined before the untimed search
TIMED_DIRECT = 4


def _dyad_line(A: Array, rhs: Array) -> tuple[Array, Array] | None:
    """The solutions of ``A x = rhs`` (``A`` of rank 6 in 7 unknowns): a point and the null direction, by SVD; None
    when a second singular value is also at rounding level (the targets do not fix the line)."""
    U, S, Vt = np.linalg.svd(A, full_matrices=False)
    if S[-2] <= DYAD_RCOND * S[0]:
        return None
    return Vt[:-1].T @ ((U[:, :-1].T @ rhs) / S[:-1]), Vt[-1]


def _dyad_roots(x0: Array, n: Array) -> list[float]:
    """Where on the line ``x0 + t n`` of unknowns ``[K, a, b, q]`` (``a, b, q`` complex, as pairs) the product ``q``
    equals ``a conj(b)``: the real parts of the two roots of that complex quadratic in ``t``."""
    a0, a1 = complex(x0[1], x0[2]), complex(n[1], n[2])
    b0, b1 = complex(x0[3], x0[4]), complex(n[3], n[4])
    q0, q1 = complex(x0[5], x0[6]), complex(n[5], n[6])
    lead = -a1 * np.conj(b1)
    if abs(lead) == 0.0:
        return []
    return [float(r.real) for r in np.roots([lead, q1 - a1 * np.conj(b0) - a0 * np.conj(b1), q0 - a0 * np.conj(b0)])]


#: singular values (relative to the largest) under which the closed-form timed solution is not attempted
DYAD_RCOND = 1e-10


def timed_closed_form(targets: Array, theta: Array) -> Array:
    """Four-bars whose coupler point passes through ``targets`` ``(N, 2)`` at the crank angles ``theta`` ``(N,)``
    (radians from the ground line), in closed form from the targets alone (no search): rows of the kernel's 9
    parameters and the circuit ``(k, 10)``, usually two (a four-bar and another with the same timing), none for
    fewer than 7 targets or when the targets do not fix them.  Exact for targets a four-bar passes through (to
    rounding); for others a start for least squares.

    The crank pin is ``B_i = O2 + w e^(i theta_i)`` (complex; ``w`` the crank, turned by the ground line's
    angle) and the coupler point stays at a distance ``d`` from it: ``|P_i - O2 - w e^(i theta_i)|^2 = d^2``.
    Expanded, that is linear in ``K = |O2|^2 + |w|^2 - d^2``, ``O2``, ``w`` and ``q = O2 conj(w)`` (7 real
    unknowns, one equation per target).  Two dyads turning at the crank's rate reach the coupler point (the
    crank and one of a cognate's), so the system has rank 6; the line of its solutions meets ``q = O2 conj(w)``
    at both (a quadratic).  With the crank known, the coupler's pose at each target is known (``B_i`` and the
    direction to ``P_i``), and the rocker pin ``C_i = B_i + c u_i`` (``u_i`` the unit vector from ``B_i`` to
    ``P_i``, ``c`` complex in the coupler's frame) on a circle about ``O4`` is the same problem again, linear in
    ``c``, ``O4``, ``|c|^2 + |O4|^2 - r4^2`` and ``c conj(O4)``; its two solutions are the rocker pin and the crank
    pin itself (``c = 0``, discarded)."""
    P = np.asarray(targets, float) @ np.array([1.0, 1j])
    th = np.asarray(theta, float)
    N = len(P)
    out: list[list[float]] = []
    if N < 7:
        return np.empty((0, N_PARAMS + 1))
    e = np.exp(-1j * th)
    Pe = P * e
    A = np.column_stack([np.ones(N), -2 * P.real, -2 * P.imag, -2 * Pe.real, -2 * Pe.imag, 2 * e.real, -2 * e.imag])
    line = _dyad_line(A, -(np.abs(P) ** 2))
    for t in _dyad_roots(*line) if line is not None else []:
        x = line[0] + t * line[1]  # type: ignore[index]
        O2, w = complex(x[1], x[2]), complex(x[3], x[4])
        d2 = abs(O2) ** 2 + abs(w) ** 2 - x[0]
        if d2 <= 0 or w == 0:
            continue
        B = O2 + w * np.exp(1j * th)
        u = (P - B) / np.maximum(np.abs(P - B), 1e-300)
        Bu = B * np.conj(u)
        A2 = np.column_stack([np.ones(N), 2 * Bu.real, 2 * Bu.imag, -2 * B.real, -2 * B.imag, -2 * u.real, 2 * u.imag])
        line2 = _dyad_line(A2, -(np.abs(B) ** 2))
        for s in _dyad_roots(*line2) if line2 is not None else []:
            y = line2[0] + s * line2[1]  # type: ignore[index]
            c, O4 = complex(y[1], y[2]), complex(y[3], y[4])
            if abs(c) <= 1e-9 * np.sqrt(d2) or O4 == O2:
                continue
            C = B + c * u
            uv = np.sqrt(d2) * np.conj(c) / abs(c)  # the coupler point in the coupler's frame (x toward C)
            circ = 1.0 if np.mean((np.conj(O4 - B) * (C - B)).imag) >= 0 else -1.0
            r4 = float(np.mean(np.abs(C - O4)))
            out.append([abs(O4 - O2), abs(w), abs(c), r4, uv.real, uv.imag, O2.real, O2.imag, float(np.angle(O4 - O2)), circ])
    rows = np.array(out, float).reshape(-1, N_PARAMS + 1)
    return rows[np.isfinite(rows).all(1) & (rows[:, :4] > 0).all(1)]


def timed_from_atlas(
    targets: Array, theta: Array, atlas: Any, cons: Constraints | None = None, starts: int = 3, closed_form: bool = True
) -> SearchResult | None:
    """Timed targets (normalised) from the atlas: first the closed form (:func:`timed_closed_form`, exact on targets
    a four-bar passes through, from 7 targets; refined with the crank angles fixed at ``theta`` when not exact), then
    the :data:`TIMED_DIRECT` best direct starts (:func:`timed_starts`) refined likewise; when none is exact, the untimed
    curve (:func:`search_atlas`, each refined start within :data:`TIMED_FROM` refined again with the angles
    fixed, until one is exact), then least squares with the angles fixed from its best (None when no start
    closes at every crank angle).  ``atlas``: an atlas, or a function of no arguments returning one (called only
    when the closed form gives nothing exact, so a loader need not run).  ``closed_form=False`` leaves the closed
    form out (the atlas's starts alone).  The result's ``stages``: ``closed_form_s`` alone when the closed form gave
    it, else ``timed_s`` (and the untimed search's when it ran)."""
    import time

    cons = cons if cons is not None else Constraints()
    t0 = time.perf_counter()
    obj = PathObjective(np.asarray(targets, float), np.asarray(theta, float), cons)
    free = PathObjective(obj.targets, None, cons)
    b = default_bounds(obj.targets, cons, True, turn=3 * np.pi)
    timed: list[tuple[float, Array, Array]] = []

    def exact_timed(row: Array, th: Array) -> bool:
        # a curve through the targets is this four-bar or a cognate (the same curve at other crank angles): only
        # the angles fixed at ``theta`` tell; a cognate's timed refinement fails and the untimed search goes on
        if max_distance(free, row, th) > TIMED_FROM:
            return False
        r, tt, e = _refine(obj, row, b, max_nfev=REFINE_NFEV, method="lm")
        timed.append((e, r, tt))
        return max_distance(obj, r, obj.theta) <= TIMED_STOP and not constraint_failures(r[:N_PARAMS], cons)  # type: ignore[arg-type]

    # first the closed form (exact on targets a four-bar passes through), then the direct starts: the neighbours
    # placed by the prescribed timing, each refined with the angles fixed
    exact = timed_closed_form(obj.targets, obj.theta) if closed_form else np.empty((0, N_PARAMS + 1))  # type: ignore[arg-type]

    def direct() -> Any:
        yield from exact
        yield from timed_starts(the_atlas(), obj)[:TIMED_DIRECT]  # the atlas's lookup only when the closed form fails

    def the_atlas() -> Any:
        return atlas() if callable(atlas) else atlas

    for k, row in enumerate(direct()):
        r, tt = row, np.asarray(obj.theta, float)
        if max_distance(obj, row, tt) > TIMED_STOP:
            r, tt, _ = _refine(obj, row, b, max_nfev=REFINE_NFEV, method="lm")
        e = float(obj.population(r[None, :], np.float64)[0])
        if not np.isfinite(e):  # a degenerate start (from an ill-conditioned closed form): nothing to keep
            continue
        if max_distance(obj, r, obj.theta) <= TIMED_STOP and not constraint_failures(r[:N_PARAMS], cons):  # type: ignore[arg-type]
            stages = {"closed_form_s" if k < len(exact) else "timed_s": time.perf_counter() - t0}
            return SearchResult(r[:N_PARAMS], 1 if r[9] >= 0 else -1, tt, float(e), True, 0, stages)
        timed.append((e, r, tt))
    u = search_atlas(targets, the_atlas(), cons, stop=exact_timed)
    r0, tt0, e0 = _refine(obj, np.append(u.params, u.circuit), b, max_nfev=REFINE_NFEV, method="lm")
    timed.append((e0, r0, tt0))
    e, r, tt = min(timed, key=lambda d: d[0])
    if not np.isfinite(e):
        return None
    stages = {**u.stages, "timed_s": time.perf_counter() - t0}
    feasible = not constraint_failures(r[:N_PARAMS], cons)
    return SearchResult(r[:N_PARAMS], 1 if r[9] >= 0 else -1, tt, float(e), feasible, u.evaluations, stages)
