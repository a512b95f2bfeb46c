"""pylinkage's optimisers on a benchmark's targets: its particle swarm over a whole four-bar, then its Nelder-Mead.

pylinkage 1.3's optimisers (``pylinkage.optimization``) tune a Linkage
through ``eval_func(linkage, dims, joint_positions) -> score``.
``particle_swarm_optimization`` takes ``dimensions``, so its swarm searches
the same ten variables as planar's search (:mod:`planar.synth.search`):
ground, crank, coupler and rocker lengths, the coupler point ``(u, v)`` in
the coupler's frame, the crank pivot ``(x0, y0)``, the ground angle ``phi``
(radians) and the circuit's sign, within planar's default bounds.  Each
candidate is placed at crank angle 0 from the ground line (closed form, the
circuit chosen by the sign), its joints set on one pylinkage Linkage built by
pylinkage's own ``synthesis.conversion.solution_to_linkage``, and pylinkage
simulates a whole crank turn (``step_fast``, :data:`STEPS` steps of 1 degree;
row ``j`` is crank angle ``(j + 1)`` degrees).  A candidate that cannot turn
its crank fully (pylinkage returns NaN) or whose longest link exceeds 10
times its shortest (planar's default ``max_ratio``) scores ``inf``.  The
fitness is the sum of squared distances (model units squared): at the rows of
the prescribed crank angles (timed; they must be whole degrees) or each
target's nearest row (untimed).  ``minimize_linkage`` (Nelder-Mead) then
polishes pylinkage's own constraints of that linkage (crank, coupler, rocker,
coupler point distance and angle) with the pivots fixed, the pattern
pylinkage's ``chain_optimizers`` documents (global search, local polish); for
untimed targets on a finer turn (:data:`POLISH_STEPS`), since the nearest of
360 steps leaves an error of the coupler point's travel in half a degree.

pylinkage's swarm draws from an unseeded ``numpy.random.default_rng()``, so
its result varies from run to run; the benchmark reports the spread.
"""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from planar.errors import PlanarError

__all__ = ["STEPS", "PylinkageFourBar", "optimise"]

Array = NDArray[np.float64]

#: crank steps per turn in pylinkage's simulation (1 degree each)
STEPS = 360

#: crank steps per turn of the polish for untimed targets (the nearest step of 1 degree is too coarse to polish)
POLISH_STEPS = 3600

#: the swarm and polish budgets: pylinkage's defaults (100 particles, 200 iterations) and a quick one
BUDGETS = {
    "quick": {"n_particles": 40, "iterations": 50, "polish": 300},
    "normal": {"n_particles": 100, "iterations": 200, "polish": 1000},
}


def place(p: Array, circuit: float) -> tuple[Array, Array, Array, Array, Array] | None:
    """Joints ``A, D, B, C, P`` of the four-bar ``p`` (planar's 9 parameters) at crank angle 0; None if it cannot close."""
    r1, r2, r3, r4, u, v, x0, y0, phi = (float(x) for x in p[:9])
    A = np.array([x0, y0])
    e1 = np.array([math.cos(phi), math.sin(phi)])
    D, B = A + r1 * e1, A + r2 * e1
    d = D - B
    L2 = float(d @ d)
    a = 0.5 * (r3 * r3 - r4 * r4 + L2)
    h2 = r3 * r3 * L2 - a * a
    if L2 <= 0.0 or h2 < 0.0:
        return None
    w = (1.0 if circuit >= 0 else -1.0) * math.sqrt(h2)
    C = B + (a * d + w * np.array([-d[1], d[0]])) / L2
    e = (C - B) / r3
    P = B + u * e + v * np.array([-e[1], e[0]])
    return A, D, B, C, P


class PylinkageFourBar:
    """One pylinkage Linkage re-dimensioned per candidate, and the sse fitness from pylinkage's simulation."""

    def __init__(self, targets: Array, theta: Array | None, steps: int = STEPS) -> None:
        from pylinkage.synthesis._types import FourBarSolution
        from pylinkage.synthesis.conversion import solution_to_linkage

        self.targets = np.asarray(targets, float)
        self.steps = steps
        self.rows: NDArray[np.int64] | None = None
        if theta is not None:
            k = np.asarray(theta, float) / (2 * np.pi / steps)
            if np.max(np.abs(k - np.rint(k))) > 1e-6:
                raise PlanarError(
                    f"pylinkage peer: prescribed crank angles must be whole multiples of "
                    f"{360 / steps:g} degrees, got {np.degrees(theta).tolist()}"
                )
            self.rows = (np.rint(k).astype(np.int64) - 1) % steps
        joints = place(np.array([3.0, 1.0, 3.0, 2.5, 1.0, 0.5, 0.0, 0.0, 0.0]), 1.0)
        assert joints is not None
        A, D, B, C, P = ((float(j[0]), float(j[1])) for j in joints)
        self.linkage = solution_to_linkage(FourBarSolution(A, D, B, C, 1.0, 3.0, 2.5, 3.0, P), iterations=steps)
        self.evaluations = 0

    def coupler_path(self, p: Array, circuit: float) -> Array | None:
        """pylinkage's coupler point over a turn ``(steps, 2)`` (row ``j``: crank angle ``j + 1`` steps); None if it fails."""
        L = np.asarray(p[:4], float)
        if L.min() <= 0.0 or L.max() > 10.0 * L.min():
            return None
        joints = place(p, circuit)
        if joints is None:
            return None
        A, D, B, C, P = joints
        q, c = P - B, C - B
        dist = float(np.hypot(*q))
        ang = math.atan2(q[1], q[0]) - math.atan2(c[1], c[0])
        lk = self.linkage
        lk.set_coords([(float(j[0]), float(j[1])) for j in (A, D, B, C, P)])
        lk.set_constraints([float(p[1]), float(p[2]), float(p[3]), dist, ang])
        try:
            tr = lk.step_fast(iterations=self.steps)
        except Exception:  # an unbuildable candidate, as pylinkage's own evaluation treats it
            return None
        xy = np.asarray(tr, float)[:, -1, :]
        return xy if np.isfinite(xy).all() else None

    def sse(self, p: Array, circuit: float) -> float:
        """The fitness: sum of squared distances to the targets from pylinkage's simulation (``inf`` if it fails)."""
        self.evaluations += 1
        xy = self.coupler_path(p, circuit)
        if xy is None:
            return math.inf
        t = self.targets
        if self.rows is not None:
            return float(np.sum((xy[self.rows] - t) ** 2))
        d2 = (xy[None, :, 0] - t[:, 0:1]) ** 2 + (xy[None, :, 1] - t[:, 1:2]) ** 2
        return float(d2.min(1).sum())


def optimise(targets: Array, theta: Array | None, budget: str = "normal") -> dict[str, Any]:
    """pylinkage's particle swarm (10 variables, planar's bounds), then its Nelder-Mead polish; see the module.

    Returns the best parameters (planar's 9 and the circuit sign), pylinkage's own sse of the
    swarm's best and of the polished one (both on the polish's turn), the evaluations and the
    wall time (s).
    """
    from pylinkage.optimization import minimize_linkage, particle_swarm_optimization

    from planar.synth.search import Constraints, default_bounds

    if budget not in BUDGETS:
        raise PlanarError(f"pylinkage peer: no budget {budget!r} ({', '.join(BUDGETS)})")
    b = BUDGETS[budget]
    t0 = time.perf_counter()
    peer = PylinkageFourBar(targets, theta)
    bounds = default_bounds(np.asarray(targets, float), Constraints(), theta is not None)
    lo, hi = [x[0] for x in bounds], [x[1] for x in bounds]

    def swarm_fitness(linkage: Any, dims: Sequence[float], pos: Any) -> float:
        x = np.asarray(dims, float)
        return peer.sse(x[:9], x[9])

    ens = particle_swarm_optimization(
        swarm_fitness,
        peer.linkage,
        dimensions=10,
        bounds=(lo, hi),
        n_particles=b["n_particles"],
        iterations=b["iterations"],
        order_relation=min,
        verbose=False,
    )
    x = np.asarray(ens.dimensions[0], float)
    swarm_sse = float(ens.scores["score"][0])
    circ = 1.0 if x[9] >= 0 else -1.0
    fixed = x.copy()
    fine = peer if theta is not None else PylinkageFourBar(targets, None, POLISH_STEPS)

    def polish_fitness(linkage: Any, dims: Sequence[float], pos: Any) -> float:
        r2, r3, r4, dist, ang = (float(v) for v in dims)
        p = fixed[:9].copy()
        p[1:6] = [r2, r3, r4, dist * math.cos(ang), dist * math.sin(ang)]
        return fine.sse(p, circ)

    polished_sse = swarm_sse = fine.sse(x[:9], circ) if fine is not peer else swarm_sse
    if math.isfinite(swarm_sse):
        x0 = [x[1], x[2], x[3], float(np.hypot(x[4], x[5])), math.atan2(x[5], x[4])]
        pol = minimize_linkage(
            polish_fitness, fine.linkage, x0=x0, order_relation=min, method="Nelder-Mead", maxiter=b["polish"], verbose=False
        )
        polished_sse = float(pol.scores["score"][0])
        if polished_sse < swarm_sse:
            r2, r3, r4, dist, ang = (float(v) for v in pol.dimensions[0])
            x[1:6] = [r2, r3, r4, dist * math.cos(ang), dist * math.sin(ang)]
        else:
            polished_sse = swarm_sse
    return {
        "params": x[:9],
        "circuit": circ,
        "swarm_sse": swarm_sse,
        "pylinkage_sse": polished_sse,
        "evaluations": peer.evaluations + (fine.evaluations if fine is not peer else 0),
        "time_s": time.perf_counter() - t0,
        "calls": (
            f"optimization.particle_swarm_optimization(dimensions=10, n_particles={b['n_particles']}, "
            f"iterations={b['iterations']}, order_relation=min), then "
            f"optimization.minimize_linkage(method='Nelder-Mead', maxiter={b['polish']}, order_relation=min)"
        ),
    }
