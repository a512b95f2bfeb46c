"""Path synthesis of six-bars: a four-bar driving a second dyad whose link carries the tracer.

Two topologies, both with the ground a ternary link (pivots ``O2``, ``O4``, ``O6``):

* ``stephenson``: the dyad ``E - F - O6`` hangs from a point ``E`` of the
  four-bar's coupler (coupler and ground are the ternary links, not joined
  to each other: Stephenson's chain);
* ``watt``: the dyad hangs from a point ``E`` of the four-bar's rocker (rocker
  and ground are the ternary links, joined at ``O4``: Watt's chain; two
  four-bars in series).

The tracer ``T`` is fixed to link ``E - F`` (frame: origin ``E``, x toward
``F``).  A candidate row: the four-bar's 9 kernel parameters with ``E`` in
place of the coupler point (in the coupler's frame, or the rocker's: origin
``O4``, x toward ``C``), then ``O6 (x, y)``, ``l5 = |EF|``, ``l6 = |F O6|``,
``T (u, v)``, and the signs of the two circuits.  Constraints: the crank
turns fully (Grashof crank, as for four-bars), the second dyad closes at
every one of ``samples`` crank angles over the turn by a margin (so it never
changes branch), link ratio, pivot region.  Search and refinement as
:mod:`planar.synth.search`; the result is a general
:class:`planar.linkages.Linkage` checked with planar's solver over the turn.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from planar.errors import InputError
from planar.synth.designs import Checked
from planar.synth.kernel import GRASHOF_MARGIN, coupler_points
from planar.synth.path import DEFAULT_TOLERANCE, normalised
from planar.synth.search import Constraints, in_order, violation
from planar.synth.targets import normalisation

__all__ = ["TOPOLOGIES", "SixBarDesign", "sixbar_points", "synthesise_sixbar"]

Array = NDArray[np.float64]
TOPOLOGIES = ("stephenson", "watt")
N6 = 15  # continuous parameters; columns 15, 16 are the circuit signs
#: the second dyad must close with ``h^2 / (l5^2 |E - O6|^2)`` at least this over the turn
DYAD_MARGIN = 1e-4


def sixbar_points(X: Array, theta: Array, topology: str) -> tuple[Array, Array, Array]:
    """Tracer ``(x, y)`` each ``(P, S)`` and the second dyad's closure margin ``(P, S)`` (negative: open).

    The four-bar's own validity is folded into the margin (-1 where it cannot close).
    """
    X = np.atleast_2d(np.asarray(X, float))
    c1 = np.where(X[:, 15] >= 0, 1.0, -1.0)
    c2 = np.where(X[:, 16] >= 0, 1.0, -1.0)
    th = np.asarray(theta, float)
    if topology == "stephenson":
        ex, ey, ok = coupler_points(X[:, :9], th, c1)
    else:
        P9 = X[:, :9].copy()
        P9[:, 4] = P9[:, 2]  # C is the coupler point (coupler, 0)
        P9[:, 5] = 0.0
        cx, cy, ok = coupler_points(P9, th, c1)
        r1, r4, phi = X[:, 0:1], X[:, 3:4], X[:, 8:9]
        o4x, o4y = X[:, 6:7] + r1 * np.cos(phi), X[:, 7:8] + r1 * np.sin(phi)
        kx, ky = (cx - o4x) / r4, (cy - o4y) / r4
        eu, ev = X[:, 4:5], X[:, 5:6]
        ex = o4x + eu * kx - ev * ky
        ey = o4y + eu * ky + ev * kx
    o6x, o6y, l5, l6 = X[:, 9:10], X[:, 10:11], X[:, 11:12], X[:, 12:13]
    tu, tv = X[:, 13:14], X[:, 14:15]
    dx, dy = o6x - ex, o6y - ey
    L2 = dx * dx + dy * dy
    A = 0.5 * (l5 * l5 - l6 * l6 + L2)
    h2 = l5 * l5 * L2 - A * A
    margin = h2 / np.maximum(l5 * l5 * L2, 1e-300)
    margin = np.where(ok, margin, -1.0)
    w = np.sqrt(np.maximum(h2, 0.0)) * c2[:, None]
    inv = 1.0 / np.maximum(L2, 1e-300)
    fx = ex + (A * dx - w * dy) * inv  # F = E + (A d + w perp(d)) / L2
    fy = ey + (A * dy + w * dx) * inv
    kx, ky = (fx - ex) / l5, (fy - ey) / l5
    return ex + tu * kx - tv * ky, ey + tu * ky + tv * kx, margin


def link_lengths(X: Array, topology: str) -> dict[str, Array]:
    """Every distance between two joints of one link ``(P,)`` each, named: the binary links, the three
    sides of the ground (``O2``, ``O4``, ``O6``) and of the other ternary link (coupler ``B C E`` or rocker
    ``O4 C E``)."""
    r1, r2, r3, r4, eu, ev, x0, y0, phi = (X[:, k] for k in range(9))
    o4x, o4y = x0 + r1 * np.cos(phi), y0 + r1 * np.sin(phi)
    out = {
        "ground O2-O4": r1,
        "crank": r2,
        "coupler B-C": r3,
        "rocker O4-C": r4,
        "ground O2-O6": np.hypot(X[:, 9] - x0, X[:, 10] - y0),
        "ground O4-O6": np.hypot(X[:, 9] - o4x, X[:, 10] - o4y),
        "link5 E-F": X[:, 11],
        "link6 F-O6": X[:, 12],
    }
    if topology == "stephenson":
        out["coupler B-E"] = np.hypot(eu, ev)
        out["coupler C-E"] = np.hypot(eu - r3, ev)
    else:
        out["rocker O4-E"] = np.hypot(eu, ev)
        out["rocker C-E"] = np.hypot(eu - r4, ev)
    return out


def _violation6(X: Array, cons: Constraints, scale: float, margin: float, topology: str) -> Array:
    v = violation(X[:, :9], Constraints(cons.full_turn, np.inf, cons.region), scale, margin)
    L = np.column_stack(list(link_lengths(X, topology).values()))
    v += np.maximum(0.0, L.max(1) - cons.max_ratio * (1.0 - margin) * L.min(1)) / scale
    if cons.region is not None:
        x0, y0, x1, y1 = cons.region
        px, py = X[:, 9], X[:, 10]
        v += (np.maximum(0.0, x0 - px) + np.maximum(0.0, px - x1) + np.maximum(0.0, y0 - py) + np.maximum(0.0, py - y1)) / scale
    return v


def sixbar_constraint_failures(row: Array, cons: Constraints, topology: str) -> list[str]:
    """The constraints a six-bar (``row``, world units) breaks, each named with its value and limit."""
    from planar.synth.search import constraint_failures, ratio_failures, region_failures

    out = list(constraint_failures(row[:9], Constraints(cons.full_turn, np.inf, cons.region)))
    out += ratio_failures({k: float(v[0]) for k, v in link_lengths(row[None, :], topology).items()}, cons.max_ratio)
    out += region_failures({"O6": (float(row[9]), float(row[10]))}, cons)
    return out


@dataclass
class _Objective:
    targets: Array
    theta: Array | None
    cons: Constraints
    topology: str
    samples: int = 64
    scale: float = field(init=False)
    penalty: float = field(init=False)

    def __post_init__(self) -> None:
        self.scale = float(max(np.hypot(*np.ptp(self.targets, axis=0)), 1e-9))
        self.penalty = 100.0 * self.scale**2 * len(self.targets)

    def __call__(self, x: Array) -> Array:
        X = np.asarray(x, float).T
        return np.concatenate([self.population(X[i : i + 4096]) for i in range(0, len(X), 4096)])

    def population(self, X: Array) -> Array:
        turn = np.linspace(0.0, 2 * np.pi, self.samples, endpoint=False)
        th = turn if self.theta is None else np.concatenate([turn, self.theta])
        x, y, m = sixbar_points(X, th, self.topology)
        tx, ty = self.targets[:, 0], self.targets[:, 1]
        S = self.samples
        if self.theta is None:
            err = np.zeros(len(X))
            for k in range(len(tx)):
                err += ((x - tx[k]) ** 2 + (y - ty[k]) ** 2).min(1)
        else:
            err = ((x[:, S:] - tx) ** 2 + (y[:, S:] - ty) ** 2).sum(1)
        closes = np.maximum(0.0, DYAD_MARGIN - m[:, :S]).max(1)
        v = _violation6(X, self.cons, self.scale, GRASHOF_MARGIN, self.topology) + closes
        return err + np.where(v > 0, self.penalty * (1.0 + v), 0.0)


@dataclass
class SixBarDesign(Checked):
    topology: str
    params: Array  # the 17 columns (see the module)
    theta: Array
    targets: Array
    timed: bool
    sse: float
    seconds: float
    checks: dict[str, Any] = field(default_factory=dict)

    def nodes(self) -> list[dict[str, Any]]:
        """The linkage's nodes as scene tables (world coordinates, radians)."""
        p = self.params
        r1, r2, r3, r4, eu, ev, x0, y0, phi = (float(v) for v in p[:9])
        o4 = (x0 + r1 * np.cos(phi), y0 + r1 * np.sin(phi))
        e_from = ("B", "C") if self.topology == "stephenson" else ("O4", "C")
        return [
            {"name": "O2", "kind": "fixed", "at": (x0, y0)},
            {"name": "O4", "kind": "fixed", "at": (float(o4[0]), float(o4[1]))},
            {"name": "O6", "kind": "fixed", "at": (float(p[9]), float(p[10]))},
            {"name": "B", "kind": "crank", "centre": "O2", "radius": r2, "phase": phi},
            {"name": "C", "kind": "rrr", "a": "B", "ra": r3, "b": "O4", "rb": r4, "branch": 1 if p[15] >= 0 else -1},
            {"name": "E", "kind": "rigid", "a": e_from[0], "b": e_from[1], "local": (eu, ev)},
            {
                "name": "F",
                "kind": "rrr",
                "a": "E",
                "ra": float(p[11]),
                "b": "O6",
                "rb": float(p[12]),
                "branch": 1 if p[16] >= 0 else -1,
            },
            {"name": "T", "kind": "rigid", "a": "E", "b": "F", "local": (float(p[13]), float(p[14]))},
        ]

    def links(self) -> list[tuple[str, tuple[str, ...]]]:
        if self.topology == "stephenson":
            return [
                ("crank", ("O2", "B")),
                ("coupler", ("B", "C", "E")),
                ("rocker", ("O4", "C")),
                ("link5", ("E", "F", "T")),
                ("link6", ("O6", "F")),
            ]
        return [
            ("crank", ("O2", "B")),
            ("coupler", ("B", "C")),
            ("rocker", ("O4", "C", "E")),
            ("link5", ("E", "F", "T")),
            ("link6", ("O6", "F")),
        ]

    def linkage(self):
        from planar.linkages import NODE_KINDS, Link, Linkage

        nodes = []
        for n in self.nodes():
            cls = NODE_KINDS[n["kind"]]
            nodes.append(cls(n["name"], *[n[f] for f in cls.scene_fields if f in n]))
        return Linkage(f"sixbar-{self.topology}", nodes, [Link(a, b) for a, b in self.links()], points={"tracer": "T"})

    def to_dict(self) -> dict[str, Any]:
        return {
            "type": f"sixbar-{self.topology}",
            "nodes": self.nodes(),
            "links": self.links(),
            "theta": [float(t) for t in self.theta],
            "sse": self.sse,
            "timed": self.timed,
            "time_s": self.seconds,
            "ok": self.ok,
            "checks": self.checks,
        }


def _refine(
    obj: _Objective, row: Array, lo: Array, hi: Array, max_nfev: int, theta0: Array | None = None
) -> tuple[Array, Array, float]:
    from scipy.optimize import least_squares

    timed = obj.theta is not None
    n = len(obj.targets)
    if timed:
        th0 = np.asarray(obj.theta)
    elif theta0 is not None:
        th0 = np.asarray(theta0, float)
    else:
        turn = np.linspace(0, 2 * np.pi, 720, endpoint=False)
        x, y, _ = sixbar_points(row[None], turn, obj.topology)
        th0 = turn[np.argmin((x[0][None] - obj.targets[:, :1]) ** 2 + (y[0][None] - obj.targets[:, 1:]) ** 2, 1)]
    turn64 = np.linspace(0.0, 2 * np.pi, obj.samples, endpoint=False)
    w = np.sqrt(obj.penalty)
    signs = row[15:17]

    def full(z: Array) -> Array:
        return np.concatenate([z[:N6], signs])

    S = obj.samples

    def rows(Z: Array) -> Array:
        """Residuals of many variable vectors ``Z`` ``(K, m)`` in one kernel call."""
        X = np.concatenate([Z[:, :N6], np.broadcast_to(signs, (len(Z), 2))], axis=1)
        th = np.broadcast_to(th0, (len(Z), n)) if timed else Z[:, N6:]
        allth = np.concatenate([np.broadcast_to(turn64, (len(Z), S)), th], axis=1)
        x, y, m = sixbar_points(X, np.ascontiguousarray(allth), obj.topology)
        r = np.concatenate([x[:, S:] - obj.targets[:, 0], y[:, S:] - obj.targets[:, 1]], axis=1)
        v = _violation6(X, obj.cons, obj.scale, 2 * GRASHOF_MARGIN, obj.topology)
        v = v + np.maximum(0.0, 2 * DYAD_MARGIN - m[:, :S]).max(1)
        return np.concatenate([r, (w * v)[:, None]], axis=1)

    def resid(z: Array) -> Array:
        return rows(z[None, :])[0]

    def jac(z: Array) -> Array:
        h = 1.49e-8 * np.maximum(1.0, np.abs(z))
        h = np.where(z + h > bhi, -h, h)
        R = rows(np.vstack([z[None, :], z[None, :] + np.diag(h)]))
        return ((R[1:] - R[0]) / h[:, None]).T

    span = hi[:N6] - lo[:N6]
    z0 = np.clip(row[:N6], lo[:N6] + 1e-9 * span, hi[:N6] - 1e-9 * span)
    blo, bhi = lo[:N6], hi[:N6]
    if not timed:
        z0 = np.concatenate([z0, th0])
        blo = np.concatenate([blo, np.full(n, -np.inf)])
        bhi = np.concatenate([bhi, np.full(n, np.inf)])
    res = least_squares(resid, z0, jac=jac, bounds=(blo, bhi), x_scale="jac", max_nfev=max_nfev)
    out = full(res.x)
    th = th0 if timed else res.x[N6:]
    e = float(np.sum(res.fun[: 2 * n] ** 2))
    if res.fun[-1] > 0:
        e += obj.penalty
    return out, np.asarray(th, float), e


def _fourbar_seed(
    t: Array,
    th: Array | None,
    cons: Constraints,
    seed: int,
    budget: str,
    atlas: Any,
    ordered: bool,
    tolerance: float,
    lo: Array,
    hi: Array,
) -> tuple[Array, Array] | None:
    """A Stephenson six-bar tracing the best four-bar's coupler curve, and its crank angles at the targets.

    The four-bar is the one ``planar synth path`` finds with an input that turns fully
    (:func:`planar.synth.path.best_fourbar` with ``full_turn``: the atlas and, when that is not within the
    tolerance, the global search; a rocking input's four-bar, which plain ``synth path`` may return, does not
    close over the six-bar's turn, and a trial's drawn paw lost its seed so: 0.239 of the size off where the
    full-turn four-bar was 0.0418); the tracer sits on ``E``, the coupler
    point, so the six-bar's tracer path is the four-bar's.  The second dyad ``E - F - O6`` (``l5 = l6``,
    at least 0.55 of ``O6``'s farthest distance from the curve: it closes over the whole turn with a margin)
    is the one of a grid of ``O6`` in the bounds and lengths that breaks the constraints least.  None when
    the four-bar breaks them or cannot close over the turn."""
    from planar.synth.path import best_fourbar

    r = best_fourbar(t, th, cons, budget, seed, atlas, ordered, tolerance, full_turn=True)
    if not r.feasible:
        return None
    turn = np.linspace(0, 2 * np.pi, 720, endpoint=False)
    x, y, ok = coupler_points(r.params[None], turn, np.array([float(r.circuit)]))
    if not ok.all():
        return None
    L = float(max(np.hypot(*np.ptp(t, axis=0)), 1e-9))
    gx, gy = np.meshgrid(np.linspace(lo[9], hi[9], 17), np.linspace(lo[10], hi[10], 17))
    o6 = np.column_stack([gx.ravel(), gy.ravel()])
    dist = np.hypot(x[0][None, :] - o6[:, :1], y[0][None, :] - o6[:, 1:])
    keep = dist.min(1) > 0.05 * L  # E never passes through O6 (the dyad's direction would be undefined)
    rows = []
    for k in (0.55, 0.75, 1.0, 1.5):
        ln = np.clip(k * dist.max(1)[keep], lo[11], hi[11])
        n = len(ln)
        rows.append(
            np.column_stack(
                [np.broadcast_to(r.params, (n, 9)), o6[keep], ln, ln, np.zeros((n, 2)), np.full(n, float(r.circuit)), np.ones(n)]
            )
        )
    if not rows or not sum(len(v) for v in rows):
        return None
    X = np.vstack(rows)
    _, _, m = sixbar_points(X, turn[::4], "stephenson")
    v = _violation6(X, cons, L, 2 * GRASHOF_MARGIN, "stephenson") + np.maximum(0.0, 2 * DYAD_MARGIN - m).max(1)
    best = int(np.lexsort((X[:, 11], v))[0])  # least violation, then the shortest dyad
    return X[best], np.asarray(r.theta, float)


def synthesise_sixbar(
    targets: Array,
    theta: Array | None = None,
    topology: str = "stephenson",
    cons: Constraints | None = None,
    budget: str | tuple[int, int, int, int] = "normal",
    seed: int = 0,
    tolerance: float = DEFAULT_TOLERANCE,
    atlas: Any = None,
    ordered: bool = False,
) -> SixBarDesign:
    """A six-bar (``topology`` ``"stephenson"`` or ``"watt"``) whose tracer passes through ``targets``.

    ``tolerance``, ``atlas``, ``ordered``: as :func:`planar.synth.path.synthesise_path`'s.  The Stephenson
    search also starts from the four-bar :func:`planar.synth.path.synthesise_path` would find (the tracer
    on its coupler point, a dyad that always closes), kept unrefined among the candidates: the result is
    never further from the targets (largest distance) than that four-bar when the dyad keeps the
    constraints.  Of all candidates the one the check judges best is kept (constraints, order, largest
    distance), not the smallest sum of squares.
    ``budget``: ``"quick"``, ``"normal"``, ``"thorough"`` or ``(random samples, DE generations, DE
    population per variable, refinement starts)``.
    """
    from planar.synth.search import default_bounds, sampled_evolution
    from planar.synth.targets import check_search_args

    t, theta = check_search_args(targets, theta, seed, tolerance, {"ordered": ordered})
    if cons is not None and not isinstance(cons, Constraints):
        raise InputError("cons", cons, "a synth.search.Constraints (or None)")
    cons = cons if cons is not None else Constraints()
    if not isinstance(topology, str) or topology not in TOPOLOGIES:
        raise InputError("topology", topology, f"one of {', '.join(TOPOLOGIES)}")
    kw = {"quick": (20_000, 60, 10, 2), "normal": (100_000, 200, 15, 4), "thorough": (400_000, 600, 25, 8)}
    if isinstance(budget, tuple):
        if len(budget) != 4 or not all(isinstance(v, int) and not isinstance(v, bool) and 0 < v <= 10**7 for v in budget):
            raise InputError("budget", budget, "(samples, iterations, population, refinements): four whole numbers from 1 to 1e7")
        n_sample, maxiter, popsize, refine = budget
    elif isinstance(budget, str) and budget in kw:
        n_sample, maxiter, popsize, refine = kw[budget]
    else:
        raise InputError("budget", budget, f"one of {', '.join(kw)}")
    t0 = time.perf_counter()
    th = None if theta is None else np.asarray(theta, float)
    # searched on the targets moved to their centroid and divided by their size, then mapped back
    tw, cons_w = t, cons
    c0, s0 = normalisation(tw)
    t, cons = (tw - c0) / s0, normalised(cons_w, c0, s0)
    obj = _Objective(t, th, cons, topology)
    fb = default_bounds(t, cons, th is not None)  # 9 four-bar bounds + circuit
    L = obj.scale
    c = t.mean(0)
    if cons.region is not None:
        o6 = [(cons.region[0], cons.region[2]), (cons.region[1], cons.region[3])]
    else:
        o6 = [(c[0] - 4 * L, c[0] + 4 * L), (c[1] - 4 * L, c[1] + 4 * L)]
    b = fb[:9] + o6 + [(L / 50, 4 * L)] * 2 + [(-4 * L, 4 * L)] * 2 + [(-1.0, 1.0)] * 2
    lo = np.array([v[0] for v in b])
    hi = np.array([v[1] for v in b])
    X, order, de = sampled_evolution(obj, lambda rows: obj(rows.T), b, n_sample, popsize, maxiter, seed)
    pool = np.vstack([de.x[None], de.population[np.argsort(de.population_energies)], X[order[: 4 * refine]]])
    pool = np.clip(pool, lo, hi)
    starts: list[tuple[Array, Array | None]] = []
    for row in pool:
        if all(np.linalg.norm((row - s) / (hi - lo)) > 0.05 for s, _ in starts):
            starts.append((row, None))
        if len(starts) >= refine:
            break
    done: list[tuple[Array, Array]] = []
    if topology == "stephenson":
        seeded = _fourbar_seed(t, th, cons, seed, _named(budget), atlas, ordered, tolerance, lo, hi)
        if seeded is not None:
            row, tt = seeded
            row[8] = (row[8] + np.pi) % (2 * np.pi) - np.pi  # the ground line's angle inside the bounds
            lo, hi = np.minimum(lo, row), np.maximum(hi, row)  # the four-bar's lengths kept, even beyond the bounds
            done.append((row, th if th is not None else tt))  # the four-bar's own curve, unrefined
            starts.insert(0, (row, tt))
    for row, t_start in starts:
        r, rt, _ = _refine(obj, row, lo, hi, 40 * (N6 + (0 if th is not None else len(t))), None if th is not None else t_start)
        done.append((r, rt))
    best = _best_of(obj, done, topology, ordered)
    p = best[0].copy()
    p[:6] *= s0
    p[6:8] = p[6:8] * s0 + c0
    p[9:11] = p[9:11] * s0 + c0
    p[11:15] *= s0
    d = SixBarDesign(topology, p, best[1], tw, th is not None, float("nan"), time.perf_counter() - t0)
    check_sixbar(d, cons_w, float(max(np.hypot(*np.ptp(tw, axis=0)), 1e-300)), tolerance, ordered)
    return d


def _named(budget: str | tuple[int, int, int, int]) -> str:
    """The four-bar search's budget for a six-bar ``budget`` (a tuple of effort figures: ``"quick"``)."""
    return budget if isinstance(budget, str) else "quick"


def _best_of(obj: _Objective, done: list[tuple[Array, Array]], topology: str, ordered: bool) -> tuple[Array, Array]:
    """The candidate ``(row, theta)`` the check judges best: keeping the constraints and closing over the turn
    first, then (``ordered``) passing the targets in order, then the smallest largest distance to a target."""

    def key(c: tuple[Array, Array]) -> tuple[bool, bool, float]:
        row, tt = c
        x, y, m = sixbar_points(row[None], tt, topology)
        far = float(np.max(np.hypot(x[0] - obj.targets[:, 0], y[0] - obj.targets[:, 1]))) if (m > 0).all() else np.inf
        bad = _violation6(row[None], obj.cons, obj.scale, 0.0, topology)[0] > 0 or not _closes(row, topology)
        return bool(bad), bool(ordered and not in_order(tt)), far

    return min(done, key=key)


def _closes(row: Array, topology: str, n: int = 720) -> bool:
    """Whether the second dyad closes with a margin at ``n`` crank angles over the turn."""
    _, _, m = sixbar_points(row[None], np.linspace(0, 2 * np.pi, n, endpoint=False), topology)
    return bool((m > 0).all())


def invalid_ranges(bad: NDArray[np.bool_], turn: Array) -> list[tuple[float, float]]:
    """Driver ranges ``(first, last)`` (radians) of the runs of ``bad`` samples over the turn ``turn``."""
    out: list[tuple[float, float]] = []
    idx = np.flatnonzero(bad)
    if len(idx) == 0:
        return out
    breaks = np.flatnonzero(np.diff(idx) > 1)
    starts = np.concatenate([idx[:1], idx[breaks + 1]])
    ends = np.concatenate([idx[breaks], idx[-1:]])
    return [(float(turn[a]), float(turn[b])) for a, b in zip(starts, ends)]


def check_sixbar(
    d: SixBarDesign, cons: Constraints, scale: float, tolerance: float = DEFAULT_TOLERANCE, ordered: bool = False
) -> None:
    """sse and checks from planar's solver: the whole turn valid and on the search's branches.

    ``worst_target`` (1-based) is the target farthest from the tracer; ``in_order`` whether the crank angles
    at the targets run one way round within one turn (the tracer passes them in one sweep), a check
    (``ok_order``) with ``ordered``.

    Where the linkage cannot be assembled is found on 36,000 driver angles (the kernel, as the search's
    dyad margin) and 360 (planar's solver); ``failures`` names the driver ranges.
    """
    from planar.errors import PlanarError

    cf = sixbar_constraint_failures(d.params, cons, d.topology)
    try:
        lk = d.linkage()
    except PlanarError as e:
        d.sse = float("inf")
        d.checks = {"ok_builds": False, "error": str(e), "ok_constraints": not cf, "constraint_failures": cf}
        return
    th = np.mod(d.theta, 2 * np.pi)
    turn = np.linspace(0.0, 2 * np.pi, 360, endpoint=False)
    swept = np.sort(np.concatenate([turn, th]))
    path = lk.solve(swept)  # the turn in steps of at most 1 deg, through every target's crank angle
    full = lk.solve(turn)
    # the targets as the driven linkage meets them: on that path (a solve at the targets' angles alone carried
    # the second dyad onto its other branch across wide gaps between targets, which no driven linkage does)
    at = path.take(np.searchsorted(swept, th))
    pts = at.points["tracer"]
    x, y, _ = sixbar_points(d.params[None], d.theta, d.topology)
    kern = np.column_stack([x[0], y[0]])
    d.sse = float(np.sum((pts - d.targets) ** 2)) if at.valid.all() else float("inf")
    dense = np.linspace(0.0, 2 * np.pi, 36_000, endpoint=False)
    _, _, m = sixbar_points(d.params[None], dense, d.topology)
    ranges = invalid_ranges(m[0] <= 0, dense) or invalid_ranges(~full.valid, turn)
    failures = [
        f"the linkage cannot be assembled for driver angles {a:.4g}..{b:.4g} rad (from the ground line O2-O4)" for a, b in ranges
    ]
    _, size = normalisation(d.targets)
    rms = math.sqrt(d.sse / len(d.targets)) / size if math.isfinite(d.sse) else float("inf")
    d.checks = {
        "ok_builds": True,
        "ok_valid_over_turn": bool(full.valid.all() and path.valid.all()) and not ranges,
        "invalid_driver_ranges": ranges,
        "ok_same_branches_as_search": bool(at.valid.all()) and float(np.max(np.abs(pts - kern))) <= 1e-9 * scale,
        "ok_constraints": not cf,
        "constraint_failures": cf,
        "failures": failures,
        "size": size,
        "rms_error": rms,
        "tolerance": tolerance,
        "max_target_distance": float(np.max(np.hypot(*(pts - d.targets).T))) if at.valid.all() else float("inf"),
    }
    d.checks["worst_target"] = int(np.argmax(np.hypot(*(pts - d.targets).T))) + 1 if at.valid.all() else 0
    d.checks["max_error"] = d.checks["max_target_distance"] / size
    d.checks["ok_accuracy"] = bool(d.checks["max_error"] <= tolerance)
    d.checks["in_order"] = in_order(d.theta)
    if ordered:
        d.checks["ok_order"] = d.checks["in_order"]
