"""Function generation on one circuit: a search when Freudenstein's closed form is not a usable four-bar.

Normalised to a unit ground link (the design is scaled by ``--ground`` at the
end).  A candidate is ``a, b, c`` (crank, coupler, rocker), the offsets ``A,
B`` (crank angle from the ground line = input + ``A``; rocker angle from the
ground line = output + ``B``; radians, counter-clockwise) and a circuit
(``+1`` open, ``-1`` crossed, as :mod:`.kernel`).  With fixed offsets ``A = B``
is ``0`` or ``-pi`` (the rocker pivot on the positive or negative x axis);
with free offsets both are unknowns, so only the pairs' differences matter.

Valid: the crank moves over the inputs' arc ``[min, max]`` (unwrapped, as
given) without meeting a toggle, so the rocker follows one circuit
continuously (the transmission angle stays inside ``(0, pi)`` over the arc,
computed exactly from the arc's extreme ``cos``); the longest / shortest link
is at most ``max_ratio``; the transmission angle keeps ``min_transmission``
from a toggle; with ``full_turn`` the whole turn assembles too (and keeps the
same margin).  The error is the true output angle on the candidate's circuit
(the :mod:`.kernel`'s rocker pin) minus the request, not Freudenstein's
equation residual.

Free offsets with 5 or more pairs are first solved algebraically: expanded,
Freudenstein's equation is linear and homogeneous in seven products of the
unknowns (:func:`_linear_unknowns`), so its null space (a line from 6 pairs,
a plane and a cubic at 5) gives every four-bar that meets the pairs exactly;
Gauss-Newton on the five unknowns polishes them.  A valid one within
:data:`ALGEBRAIC_EXACT` is the design (the one with the largest transmission
margin when several are); otherwise they join the seeds.

Seeds: Freudenstein's linear least squares at a grid of offsets (free) or at
the given ones (fixed), and a scrambled Sobol sample of the lengths (and
offsets), each on both circuits, evaluated at once; the best valid ones (and
the best few by a penalised cost) are refined by ``scipy.optimize.least_squares``
with the constraints as hinge residuals, and rechecked.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from planar.synth.kernel import coupler_points

__all__ = ["FunctionConstraints", "SearchResult", "arc_margin", "output_errors", "search_function"]

Array = NDArray[np.float64]
TWO_PI = 2 * np.pi
#: transmission margin (rad) below which a sample counts as at a toggle, whatever the request
MARGIN_FLOOR = 1e-4
#: most pairs the seeds are judged at (the refinement and the final check use every pair)
SCREEN = 24
#: weight of a constraint's violation (rad) against output-angle error (rad) in the refinement
WEIGHT = 10.0
#: free offsets: Gauss-Newton steps polishing the algebraic solutions of Freudenstein's equation
NEWTON_STEPS = 12


@dataclass(frozen=True)
class FunctionConstraints:
    """What a valid design must meet (angles in radians)."""

    free_offsets: bool = False
    full_turn: bool = False
    max_ratio: float = 10.0
    min_transmission: float = 0.0

    @property
    def floor(self) -> float:
        return max(self.min_transmission, MARGIN_FLOOR)


@dataclass
class SearchResult:
    """The chosen candidate (normalised, ground 1) or ``None``, and why none was valid."""

    x: Array | None  # a, b, c, A, B
    circuit: int
    max_error: float
    margin: float  # transmission margin over the arc (rad)
    candidates: int
    refined: int
    reason: str = ""
    counts: dict[str, int] = field(default_factory=dict)


def _wrap(a: Array) -> Array:
    return (np.asarray(a) + np.pi) % TWO_PI - np.pi


def _acos_ext(x: Array) -> Array:
    """``arccos`` continued past ``[-1, 1]`` linearly (negative below 0, above pi beyond): a signed margin."""
    return np.where(x > 1, 1.0 - x, np.where(x < -1, np.pi - 1.0 - x, np.arccos(np.clip(x, -1.0, 1.0))))


def arc_margin(a: Array, b: Array, c: Array, t0: Array, t1: Array) -> Array:
    """Smallest transmission-angle distance from a toggle (rad) while the crank sweeps ``[t0, t1]``.

    Unit ground.  ``|B - O4|^2 = a^2 + 1 - 2 a cos t`` is monotonic in ``cos t``,
    so its extremes over the arc are at the arc's extreme ``cos`` (1 when the
    arc holds a multiple of 2 pi, -1 when it holds an odd multiple of pi, else
    an end).  Negative where the dyad cannot close somewhere on the arc.
    """
    t0, t1 = np.asarray(t0, float), np.asarray(t1, float)
    has0 = np.floor(t1 / TWO_PI) >= np.ceil(t0 / TWO_PI)
    haspi = np.floor((t1 - np.pi) / TWO_PI) >= np.ceil((t0 - np.pi) / TWO_PI)
    cmax = np.where(has0, 1.0, np.maximum(np.cos(t0), np.cos(t1)))
    cmin = np.where(haspi, -1.0, np.minimum(np.cos(t0), np.cos(t1)))
    l2min = a * a + 1.0 - 2.0 * a * cmax
    l2max = a * a + 1.0 - 2.0 * a * cmin
    mu_lo = _acos_ext((b * b + c * c - l2min) / (2.0 * b * c))
    mu_hi = _acos_ext((b * b + c * c - l2max) / (2.0 * b * c))
    return np.minimum(mu_lo, np.pi - mu_hi)


def output_errors(X: Array, circuit: Array, phi: Array, psi: Array) -> tuple[Array, NDArray[np.bool_]]:
    """Wrapped output-angle errors ``(P, n)`` (rad) of candidates ``X`` ``(P, 5)`` and where they close.

    The rocker pin ``C`` comes from the vectorised kernel (coupler point at
    ``(coupler, 0)`` in the coupler's frame), the rocker angle is
    ``atan2(C - O4)`` with ``O4 = (1, 0)``.
    """
    _a, _b, _c, A, B = (X[:, i : i + 1] for i in range(5))
    K = np.zeros((len(X), 9))
    K[:, 0], K[:, 1], K[:, 2], K[:, 3], K[:, 4] = 1.0, X[:, 0], X[:, 1], X[:, 2], X[:, 1]
    cx, cy, ok = coupler_points(K, phi[None, :] + A, circuit)
    return _wrap(np.arctan2(cy, cx - 1.0) - psi[None, :] - B), ok


def violations(X: Array, phi: Array, cons: FunctionConstraints, slack: float = 0.0) -> Array:
    """``(P, 3)`` hinge violations (rad, 0 when met): work-arc margin, full-turn margin, log link ratio."""
    a, b, c, A = X[:, 0], X[:, 1], X[:, 2], X[:, 3]
    need = cons.floor + slack
    v = np.zeros((len(X), 3))
    v[:, 0] = np.maximum(0.0, need - arc_margin(a, b, c, phi.min() + A, phi.max() + A))
    if cons.full_turn:
        v[:, 1] = np.maximum(0.0, need - arc_margin(a, b, c, np.zeros_like(a), np.full_like(a, TWO_PI)))
    lengths = np.column_stack([a, b, c, np.ones_like(a)])
    v[:, 2] = np.maximum(0.0, np.log(lengths.max(1) / lengths.min(1)) - np.log(cons.max_ratio) + slack)
    return v


def _closed_form_seeds(phi: Array, psi: Array, A: Array, B: Array) -> Array:
    """Freudenstein's linear least squares at each offset pair ``(A, B)``: rows ``a, b, c, A, B`` (real ones)."""
    th, ps = phi[None, :] + A[:, None], psi[None, :] + B[:, None]
    M = np.stack([np.cos(ps), -np.cos(th), np.ones_like(th)], axis=-1)  # (G, n, 3)
    rhs = np.cos(th - ps)
    MtM = np.einsum("gni,gnj->gij", M, M)
    Mtr = np.einsum("gni,gn->gi", M, rhs)
    good = np.abs(np.linalg.det(MtM)) > 1e-12
    K = np.linalg.solve(MtM[good], Mtr[good][..., None])[..., 0]
    A, B = A[good], B[good]
    same = K[:, 0] * K[:, 1] > 0
    K, A, B = K[same], A[same], B[same]
    turn = np.where(K[:, 0] < 0, np.pi, 0.0)  # negative K1, K2: the frame turned by pi
    a, c = 1.0 / np.abs(K[:, 0]), 1.0 / np.abs(K[:, 1])
    b2 = a * a + c * c + 1.0 - 2.0 * a * c * K[:, 2]
    real = b2 > 0
    return np.column_stack([a, np.sqrt(np.where(real, b2, 1.0)), c, A - turn, B - turn])[real]


def _freudenstein_newton(phi: Array, psi: Array, Z: Array, iterations: int = NEWTON_STEPS) -> tuple[Array, Array]:
    """Gauss-Newton, all starts at once, on Freudenstein's equation with free offsets: rows ``Z = (K1, K2, K3, A,
    B)``, residuals ``K1 cos(psi + B) - K2 cos(phi + A) + K3 - cos(phi + A - psi - B)``, their exact Jacobian, a
    step kept only where it lowers the residual.  Returns the rows and their residuals' norms."""

    def res(Z: Array) -> tuple[Array, Array, Array]:
        th, ps = phi[None, :] + Z[:, 3:4], psi[None, :] + Z[:, 4:5]
        return Z[:, 0:1] * np.cos(ps) - Z[:, 1:2] * np.cos(th) + Z[:, 2:3] - np.cos(th - ps), th, ps

    r, th, ps = res(Z)
    cost = np.einsum("pn,pn->p", r, r)
    for _ in range(iterations):
        s = np.sin(th - ps)
        J = np.stack(
            [np.cos(ps), -np.cos(th), np.ones_like(th), Z[:, 1:2] * np.sin(th) + s, -Z[:, 0:1] * np.sin(ps) - s], axis=-1
        )
        step = np.stack([np.linalg.lstsq(Ji, -ri, rcond=None)[0] for Ji, ri in zip(J, r)]) if len(Z) else Z
        rn, thn, psn = res(Z + step)
        cn = np.einsum("pn,pn->p", rn, rn)
        better = cn < cost
        if not better.any():
            break
        Z = np.where(better[:, None], Z + step, Z)
        r, th, ps = (np.where(better[:, None], new, old) for new, old in ((rn, r), (thn, th), (psn, ps)))
        cost = np.where(better, cn, cost)
    return Z, np.sqrt(cost)


def _linear_unknowns(phi: Array, psi: Array) -> Array:
    """Candidate vectors ``u = (K1 cos B, K1 sin B, K2 cos A, K2 sin A, K3, cos(A - B), sin(A - B))`` (rows).

    Expanded, Freudenstein's equation with free offsets is linear and homogeneous in ``u``:
    ``u1 cos psi - u2 sin psi - u3 cos phi + u4 sin phi + u5 - u6 cos(phi - psi) + u7 sin(phi - psi) = 0``.
    With 6 or more pairs the exact ``u`` spans the null space of that system (its last right singular vector;
    the least-squares one when no four-bar meets the pairs).  With 5 pairs the null space is a plane
    ``alpha v1 + beta v2``; ``u`` must also be consistent (``(u3 + i u4)(u1 - i u2)(u6 - i u7)`` real, since
    ``A - B`` is the angle of ``u6 + i u7``): a homogeneous cubic in ``(alpha, beta)``, up to three roots.
    Fewer pairs: none (the search's grid and random seeds find those)."""
    n = len(phi)
    if n < 5:
        return np.zeros((0, 7))
    d = phi - psi
    M = np.column_stack([np.cos(psi), -np.sin(psi), -np.cos(phi), np.sin(phi), np.ones(n), -np.cos(d), np.sin(d)])
    V = np.linalg.svd(M / np.linalg.norm(M, axis=1, keepdims=True), full_matrices=n < 7)[2]  # 7 x 7 (never n x n)
    if n > 5:
        return V[-1:]
    v1, v2 = V[-2], V[-1]

    def imag(U: Array) -> Array:
        return np.imag((U[:, 2] + 1j * U[:, 3]) * (U[:, 0] - 1j * U[:, 1]) * (U[:, 5] - 1j * U[:, 6]))

    # u = alpha v1 + beta v2: with beta = 1 a cubic in alpha (fitted exactly at 4 points), and beta = 0 checked
    a = np.array([-1.0, -1 / 3, 1 / 3, 1.0])
    roots = np.roots(np.polyfit(a, imag(a[:, None] * v1 + v2), 3))
    alphas = roots[np.abs(roots.imag) <= 1e-8 * np.maximum(1.0, np.abs(roots))].real
    rows = [al * v1 + v2 for al in alphas]
    if abs(imag(v1[None, :])[0]) <= 1e-12:
        rows.append(v1)
    return np.array(rows).reshape(-1, 7)


def _algebraic_seeds(phi: Array, psi: Array) -> Array:
    """Free offsets, 5 or more pairs: the four-bars of :func:`_linear_unknowns`, polished by
    :func:`_freudenstein_newton`, as rows ``a, b, c, A, B`` (real ones, ``K1`` and ``K2`` of one sign).  Where a
    four-bar meets the pairs exactly it is among them, to rounding."""
    U = _linear_unknowns(phi, psi)
    U = np.vstack([U, -U])  # u and -u: one of them has K1 and K2 of one sign
    U = U / np.maximum(np.hypot(U[:, 5], U[:, 6]), 1e-300)[:, None]  # cos^2 + sin^2 = 1
    B, A = np.arctan2(U[:, 1], U[:, 0]), np.arctan2(U[:, 3], U[:, 2])
    K1, K2 = np.hypot(U[:, 0], U[:, 1]), np.hypot(U[:, 2], U[:, 3])
    flip = np.cos(A - B - np.arctan2(U[:, 6], U[:, 5])) < 0  # A - B off by pi: K2 is negative
    K2 = np.where(flip, -K2, K2)
    A = np.where(flip, A + np.pi, A)
    Z, _ = _freudenstein_newton(phi, psi, np.column_stack([K1, K2, U[:, 4], A, B]))
    Z = Z[(Z[:, 0] * Z[:, 1] > 0) & np.isfinite(Z).all(1)]
    turn = np.where(Z[:, 0] < 0, np.pi, 0.0)  # negative K1, K2: the frame turned by pi
    a, c = 1.0 / np.abs(Z[:, 0]), 1.0 / np.abs(Z[:, 1])
    b2 = a * a + c * c + 1.0 - 2.0 * a * c * Z[:, 2]
    real = b2 > 0
    return np.column_stack([a, np.sqrt(np.where(real, b2, 1.0)), c, _wrap(Z[:, 3] - turn), _wrap(Z[:, 4] - turn)])[real]


def _seeds(phi: Array, psi: Array, cons: FunctionConstraints, n_random: int, grid: int, seed: int) -> Array:
    from scipy.stats import qmc

    lr = np.log(cons.max_ratio)
    if cons.free_offsets:
        g = np.linspace(-np.pi, np.pi, grid, endpoint=False)
        GA, GB = np.meshgrid(g, g, indexing="ij")
        cf = _closed_form_seeds(phi, psi, GA.ravel(), GB.ravel())
        s = qmc.Sobol(5, scramble=True, seed=seed).random(n_random)
        rnd = np.column_stack([np.exp(lr * (2 * s[:, :3] - 1)), np.pi * (2 * s[:, 3:] - 1)])
    else:
        cf = _closed_form_seeds(phi, psi, np.array([0.0, -np.pi]), np.array([0.0, -np.pi]))
        cf = cf[np.isclose(cf[:, 3], cf[:, 4])]  # fixed: A = B, 0 or -pi (up to 2 pi)
        s = qmc.Sobol(3, scramble=True, seed=seed).random(n_random)
        L = np.exp(lr * (2 * s - 1))
        off = np.repeat([0.0, -np.pi], n_random)[:, None]
        rnd = np.column_stack([np.tile(L, (2, 1)), off, off])
    return np.vstack([cf, rnd])


def _pick_starts(cost: Array, X: Array, circ: Array, k: int) -> list[int]:
    """Up to ``k`` of the cheapest candidates, no two closer than 0.05 in (log lengths, offsets) on one circuit."""
    order = np.argsort(cost, kind="stable")
    order = order[np.isfinite(cost[order])][: 50 * k]
    Z = np.column_stack([np.log(X[:, :3]), X[:, 3:], circ])
    kept: list[int] = []
    for i in order:
        if len(kept) == k:
            break
        if not kept or np.min(np.abs(Z[kept] - Z[i]).max(1)) > 0.05:
            kept.append(int(i))
    return kept


def _refine(x0: Array, circuit: int, phi: Array, psi: Array, cons: FunctionConstraints, nfev: int = 100) -> Array:
    """Least squares on the output-angle errors and the constraints' hinges (slack 1e-3 rad inside), at most
    ``nfev`` evaluations."""
    from scipy.optimize import least_squares

    lr = np.log(cons.max_ratio)
    free = cons.free_offsets

    def full(Z: Array) -> Array:
        """Rows ``z`` (log lengths, and offsets when free) as candidates ``a, b, c, A, B``."""
        off = Z[:, 3:] if free else np.broadcast_to(x0[3:], (len(Z), 2))
        return np.column_stack([np.exp(Z[:, :3]), off])

    def many(Z: Array) -> Array:
        X = full(Z)
        e, ok = output_errors(X, np.full(len(Z), float(circuit)), phi, psi)
        return np.column_stack([np.where(ok, e, np.pi), WEIGHT * violations(X, phi, cons, slack=1e-3)])

    def fun(z: Array) -> Array:
        return many(z[None, :])[0]

    def jac(z: Array) -> Array:
        """Forward differences, every perturbed candidate in one kernel call."""
        h = 1e-7 * np.maximum(1.0, np.abs(z))
        R = many(np.vstack([z, z + np.diag(h)]))
        D = R[1:] - R[0]
        D[:, : len(phi)] = _wrap(D[:, : len(phi)])
        return (D / h[:, None]).T

    z0 = np.concatenate([np.log(x0[:3]), x0[3:] if free else []])
    lo = np.concatenate([np.full(3, -lr), np.full(len(z0) - 3, -np.inf)])
    hi = -lo
    z0 = np.clip(z0, lo + 1e-9, hi - 1e-9)
    r = least_squares(fun, z0, jac=jac, bounds=(lo, hi), method="trf", xtol=1e-13, ftol=1e-13, gtol=1e-13, max_nfev=nfev)
    return full(r.x[None, :])[0]


def _counts(X: Array, circ: Array, phi: Array, cons: FunctionConstraints) -> dict[str, int]:
    a, b, c, A = X[:, 0], X[:, 1], X[:, 2], X[:, 3]
    m = arc_margin(a, b, c, phi.min() + A, phi.max() + A)
    lengths = np.column_stack([a, b, c, np.ones_like(a)])
    s1 = m >= MARGIN_FLOOR
    s2 = s1 & (lengths.max(1) / lengths.min(1) <= cons.max_ratio)
    s3 = s2 & (m >= cons.floor)
    s4 = s3
    if cons.full_turn:
        s4 = s3 & (arc_margin(a, b, c, np.zeros_like(a), np.full_like(a, TWO_PI)) >= cons.floor)
    return {
        "assemble_over_arc": int(s1.sum()),
        "and_link_ratio": int(s2.sum()),
        "and_transmission": int(s3.sum()),
        "and_full_turn": int(s4.sum()),
    }


def _why(counts: dict[str, int], phi: Array, cons: FunctionConstraints) -> str:
    arc = np.degrees(np.ptp(phi))
    steps = [
        ("assemble_over_arc", f"assembles over the inputs' {arc:.4g} deg arc on one circuit"),
        ("and_link_ratio", f"keeps longest / shortest link <= {cons.max_ratio:g}"),
        ("and_transmission", f"keeps the transmission angle >= {np.degrees(cons.min_transmission):.4g} deg from a toggle"),
        ("and_full_turn", "lets the crank turn fully"),
    ]
    met = [text for key, text in steps if counts[key] > 0]
    first = next(text for key, text in steps if counts[key] == 0)
    return (
        f"no four-bar {first}"
        + (f" while it {', '.join(met)}" if met else "")
        + (" (the pairs at their given angles; --free-offsets lets the offsets vary)" if not cons.free_offsets else "")
    )


def search_function(
    phi: Array, psi: Array, cons: FunctionConstraints, n_random: int = 1 << 14, grid: int = 72, starts: int = 12, seed: int = 0
) -> SearchResult:
    """The valid candidate with the smallest output-angle error (see the module); ties: the larger margin.

    The seeds are judged at up to ``SCREEN`` pairs spread over the inputs (the arc test uses all of
    them); the refinement and the choice at every pair.
    """
    from planar.core.fields import check_kind, check_number, check_samples
    from planar.errors import InputError

    phi, psi = check_samples("phi", phi), check_samples("psi", psi)
    if len(phi) != len(psi) or len(phi) < 3:
        raise InputError("phi, psi", (len(phi), len(psi)), "3 or more input and output angles, as many of each")
    check_kind("cons", cons, FunctionConstraints)
    for name, value, least, most in (("n_random", n_random, 1, 1 << 22), ("grid", grid, 2, 4096), ("starts", starts, 1, 4096)):
        if not least <= check_number(name, value, integer=True) <= most:
            raise InputError(name, value, f"a whole number from {least} to {most}")
    if check_number("seed", seed, integer=True) < 0:
        raise InputError("seed", seed, "a whole number >= 0")
    order = np.argsort(phi, kind="stable")  # seeds judged at most SCREEN pairs, spread over the arc
    sub = order[np.unique(np.round(np.linspace(0, len(phi) - 1, min(len(phi), SCREEN))).astype(int))]
    alg = _algebraic_seeds(phi, psi) if cons.free_offsets else np.zeros((0, 5))
    exact = _exact_choice(alg, phi, psi, cons)
    if exact is not None:
        return exact
    X = np.vstack([alg, _seeds(phi[sub], psi[sub], cons, n_random, grid, seed)])
    X = np.vstack([X, X])
    circ = np.repeat([1.0, -1.0], len(X) // 2)
    e, ok = output_errors(X, circ, phi[sub], psi[sub])
    rms = np.where(ok.all(1), np.sqrt(np.mean(e * e, axis=1)), np.inf)
    v = violations(X, phi, cons).sum(1)
    valid = v == 0
    counts = _counts(X, circ, phi, cons)
    picks = _pick_starts(np.where(valid, rms, np.inf), X, circ, starts)
    picks += [i for i in _pick_starts(rms + WEIGHT * v, X, circ, starts // 3) if i not in picks]
    R = np.array([_refine(X[i], int(circ[i]), phi, psi, cons) for i in picks]) if picks else np.zeros((0, 5))
    C = circ[picks]
    # the refined candidates and their starts, judged alike
    allX, allC = np.vstack([R, X[picks]]), np.concatenate([C, C])
    e, ok = output_errors(allX, allC, phi, psi)
    err = np.where(ok.all(1), np.abs(e).max(1), np.inf)
    good = (violations(allX, phi, cons).sum(1) == 0) & np.isfinite(err)
    if not good.any():
        return SearchResult(None, 0, float("inf"), float("nan"), len(X), len(picks), _why(counts, phi, cons), counts)
    margin = arc_margin(allX[:, 0], allX[:, 1], allX[:, 2], phi.min() + allX[:, 3], phi.max() + allX[:, 3])
    best = err[good].min()
    tie = good & (err <= best * (1 + 1e-3) + 1e-9)
    i = int(np.flatnonzero(tie)[np.argmax(margin[tie])])
    x = allX[i].copy()
    err_i, margin_i = float(err[i]), float(margin[i])
    if err_i > POLISH_ABOVE:
        x, err_i, margin_i = _polish(x, int(allC[i]), phi, psi, cons, err_i, margin_i)
    if cons.free_offsets:
        x[3:] = _wrap(x[3:])
    return SearchResult(x, int(allC[i]), err_i, margin_i, len(X), len(picks), "", counts)


#: an algebraic solution (free offsets, 5 or more pairs) this close (rad) at every pair, and valid, is the design
#: without the search
ALGEBRAIC_EXACT = 1e-9


def _exact_choice(X: Array, phi: Array, psi: Array, cons: FunctionConstraints) -> SearchResult | None:
    """Of the candidates ``X`` (rows ``a, b, c, A, B``) on either circuit, the valid one within
    :data:`ALGEBRAIC_EXACT` at every pair with the largest transmission margin (polished), or None."""
    if not len(X):
        return None
    X2, circ = np.vstack([X, X]), np.repeat([1.0, -1.0], len(X))
    e, ok = output_errors(X2, circ, phi, psi)
    err = np.where(ok.all(1), np.abs(e).max(1), np.inf)
    good = (violations(X2, phi, cons).sum(1) == 0) & (err <= ALGEBRAIC_EXACT)
    if not good.any():
        return None
    margin = arc_margin(X2[:, 0], X2[:, 1], X2[:, 2], phi.min() + X2[:, 3], phi.max() + X2[:, 3])
    i = int(np.flatnonzero(good)[np.argmax(margin[good])])
    x, err_i, margin_i = X2[i].copy(), float(err[i]), float(margin[i])
    if err_i > POLISH_ABOVE:
        x, err_i, margin_i = _polish(x, int(circ[i]), phi, psi, cons, err_i, margin_i)
    x[3:] = _wrap(x[3:])
    return SearchResult(x, int(circ[i]), err_i, margin_i, len(X2), 0, "", _counts(X2, circ, phi, cons))


#: the chosen candidate is refined further (:data:`POLISH_NFEV` evaluations) when its largest error (rad) is above this
POLISH_ABOVE = 1e-12
#: evaluations of that last refinement: on 5 pairs with free offsets (as many unknowns as pairs) the 100 evaluations
#: of the first refinement left 3 of 20 held-out problems at 2e-6 to 4e-5 rad; 300 more took two of them to 1e-14
POLISH_NFEV = 300


def _polish(
    x: Array, circuit: int, phi: Array, psi: Array, cons: FunctionConstraints, err: float, margin: float
) -> tuple[Array, float, float]:
    """``x`` refined :data:`POLISH_NFEV` more evaluations, kept if still valid and more accurate."""
    y = _refine(x, circuit, phi, psi, cons, POLISH_NFEV)
    e, ok = output_errors(y[None, :], np.array([float(circuit)]), phi, psi)
    ey = float(np.abs(e).max()) if ok.all() else np.inf
    if violations(y[None, :], phi, cons).sum() == 0 and ey < err:
        return y, ey, float(arc_margin(y[0], y[1], y[2], phi.min() + y[3], phi.max() + y[3]))
    return x, err, margin
