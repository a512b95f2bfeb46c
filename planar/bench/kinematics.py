"""``planar bench kinematics``: planar's public ``solve`` against pylinkage's fastest path.

A four-bar and Jansen's leg are solved by both on the same linkages (pylinkage's
numba ``step_fast``), interleaved repeats reported as median and spread,
checking that both give the same joint positions.
"""

from __future__ import annotations

import math
import os
import time
from typing import TYPE_CHECKING, Any

import numpy as np

from planar.errors import PlanarError

if TYPE_CHECKING:
    from numpy.typing import NDArray

    Array = NDArray[np.float64]


#: the linkages the kinematics benchmark solves (catalog names)
KINEMATICS_CASES = ("fourbar-crank-rocker", "jansen")
#: largest joint difference from pylinkage (model units) for the two to agree
AGREEMENT = 1e-9


def _pylinkage_of(lk: Any, step: float) -> Any:
    """The same linkage in pylinkage, started on the same assembly branch.

    Each planar node becomes its pylinkage counterpart (``Fixed`` ->
    ``Ground``, ``Crank`` -> ``Crank`` turning ``step`` rad per step,
    ``RRR`` -> ``RRRDyad``, ``Rigid`` -> ``FixedDyad`` in polar form); a
    dyad starts at planar's position for driver value 0, so pylinkage's
    nearest-root rule follows the same branch.
    """
    try:
        import pylinkage as pl
        from pylinkage.simulation import Linkage as PlLinkage
    except ImportError as e:  # pragma: no cover - depends on the environment
        raise PlanarError("planar bench kinematics needs the peer library pylinkage: pip install 'planar[bench]'") from e
    from planar.linkages.dyads import RRR, Crank, Fixed, Rigid

    start = lk.node_positions(np.array([0.0]))
    comps: dict[str, Any] = {}

    def anchor(name: str) -> Any:
        c = comps[name]
        return c.output if isinstance(c, pl.Crank) else c

    for nd in lk.nodes:
        c: Any
        if isinstance(nd, Fixed):
            c = pl.Ground(float(nd.xy[0]), float(nd.xy[1]), name=nd.name)
        elif isinstance(nd, Crank):
            c = pl.Crank(anchor=comps[nd.centre], radius=nd.radius, angular_velocity=step, initial_angle=nd.phase, name=nd.name)
        elif isinstance(nd, RRR):
            x, y = start[nd.name][0]
            c = pl.RRRDyad(anchor(nd.a), anchor(nd.b), nd.ra, nd.rb, x=float(x), y=float(y), name=nd.name)
        elif isinstance(nd, Rigid):
            u, v = nd.local
            c = pl.FixedDyad(anchor(nd.a), anchor(nd.b), math.hypot(u, v), math.atan2(v, u), name=nd.name)
        else:  # pragma: no cover - the benchmarked linkages use the four kinds above
            raise PlanarError(f"no pylinkage counterpart for node kind {type(nd).kind!r}")
        comps[nd.name] = c
    return PlLinkage(list(comps.values()))


def _spread(rates: list[float]) -> dict[str, float]:
    return {"median": float(np.median(rates)), "min": float(min(rates)), "max": float(max(rates))}


def _kinematics_case(name: str, n: int, repeats: int) -> dict[str, Any]:
    """One linkage: planar's public ``solve`` vs pylinkage ``step_fast``, interleaved repeats."""
    from planar.linkages.chunked import solver_for, threads_default
    from planar.scene.catalog import get

    mech: Any = get(name)
    step = 2 * math.pi / 3600
    q = step * np.arange(1, n + 1)
    crank = next(nd for nd in mech.nodes if nd.is_input)

    # agreement: pylinkage re-reads its crank angle from the crank's position every step
    # (it drifts by rounding over many steps), so planar solves at the angles pylinkage reached
    m = min(n, 20_000)
    traj = _pylinkage_of(mech, step).step_fast(iterations=m)
    names = [nd.name for nd in mech.nodes]
    ca = traj[:, names.index(crank.name)] - traj[:, names.index(crank.centre)]
    q_peer = np.arctan2(ca[:, 1], ca[:, 0]) - crank.phase
    ours = mech.node_positions(q_peer)
    diff = max(float(np.max(np.abs(ours[nd] - traj[:, i]))) for i, nd in enumerate(names))
    t0 = time.perf_counter()
    motion = mech.solve(q_peer)  # the first call: numba import and kernel load (or compile) included
    first_call = time.perf_counter() - t0
    diff_points = max(float(np.max(np.abs(motion.points[p] - traj[:, names.index(nd)]))) for p, nd in mech.point_nodes.items())

    # warm-up, outside the timing: pylinkage's numba compile (cached) and one call of the full size each (planar's
    # first call of a size takes new memory, which its later calls recycle: the "new memory per call" rate below
    # times that cost on every call)
    _pylinkage_of(mech, step).step_fast(iterations=n)
    mech.solve(q)
    planar_rates: list[float] = []
    fresh_rates: list[float] = []
    peer_rates: list[float] = []
    planar_cpu: list[float] = []
    peer_cpu: list[float] = []
    valid = True
    for r in range(repeats):
        peer = _pylinkage_of(mech, step)

        def run_planar() -> None:
            nonlocal valid
            c0, t0 = time.process_time(), time.perf_counter()
            mo = mech.solve(q)
            planar_rates.append(n / (time.perf_counter() - t0))
            planar_cpu.append(time.process_time() - c0)
            valid = valid and bool(mo.valid.all())

        def run_fresh() -> None:
            # the same call with output recycling off (planar.core.buffers): every block is new memory
            old = os.environ.get("PLANAR_RECYCLE")
            os.environ["PLANAR_RECYCLE"] = "0"
            try:
                t0 = time.perf_counter()
                mech.solve(q)
                fresh_rates.append(n / (time.perf_counter() - t0))
            finally:
                if old is None:
                    del os.environ["PLANAR_RECYCLE"]
                else:
                    os.environ["PLANAR_RECYCLE"] = old

        def run_peer(peer: Any = peer) -> None:
            c0, t0 = time.process_time(), time.perf_counter()
            peer.step_fast(iterations=n)
            peer_rates.append(n / (time.perf_counter() - t0))
            peer_cpu.append(time.process_time() - c0)

        for fn in (run_planar, run_peer, run_fresh) if r % 2 == 0 else (run_fresh, run_peer, run_planar):
            fn()
    ratios = [a / b for a, b in zip(planar_rates, peer_rates)]
    return {
        "linkage": name,
        "nodes": len(names),
        "parts": len(mech.parts),
        "planar_samples_per_s": _spread(planar_rates),
        "peer_samples_per_s": _spread(peer_rates),
        "ratio": float(np.median(planar_rates) / np.median(peer_rates)),
        "ratio_per_repeat": _spread(ratios),
        # the same solve writing into new memory every call (PLANAR_RECYCLE=0), what a single call costs
        "planar_new_memory_samples_per_s": _spread(fresh_rates),
        "ratio_new_memory": float(np.median(fresh_rates) / np.median(peer_rates)),
        # processor time (all threads of the process): the work each does, less sensitive to other load
        "planar_cpu_s": _spread(planar_cpu),
        "peer_cpu_s": _spread(peer_cpu),
        "cpu_ratio": float(np.median(peer_cpu) / np.median(planar_cpu)) if np.median(planar_cpu) > 0 else math.inf,
        "max_abs_diff_vs_peer": diff,
        "max_abs_diff_points_vs_peer": diff_points,
        "size": float(mech.size),
        "all_valid": valid,
        "agrees": diff <= AGREEMENT and diff_points <= AGREEMENT and valid,
        "threads": threads_default(),
        "kernels": solver_for(mech, n),
        "first_call_s": first_call,
    }


def bench_kinematics(n: int = 1_000_000, repeats: int = 7) -> dict[str, Any]:
    """Throughput of the public ``Mechanism.solve`` vs pylinkage's ``step_fast`` (numba) on the same linkages.

    For the four-bar (ground 4, crank 1, coupler 4, rocker 3, coupler point
    (2, 1)) and Jansen's leg, planar's ``solve`` (the path users call: poses of
    every part, validity, failure codes, named points) and pylinkage's fastest
    path (``step_fast``: every joint's position) each solve ``n`` crank angles
    ``k * 2 pi / 3600``, ``k = 1..n``.  The two alternate, ``repeats`` times
    each (order swapped every repeat); samples/s are reported as median, min
    and max, and ``ratio`` is the ratio of the medians.  Agreement: planar
    solves at the crank angles pylinkage reached and every joint is compared
    (``max_abs_diff_vs_peer``, model units); ``ok`` is false (and the
    command's exit status 1) unless every joint agrees within
    :data:`AGREEMENT` and every sample is valid.  The top-level ``ratio`` is
    the smaller of the two linkages' ratios.  Per case, ``kernels`` names the
    kernels ``solve`` took for ``n`` samples (``"compiled"``: numba,
    ``"numpy"``) and ``first_call_s`` the first solve's time in the process (the agreement check's, up to
    20,000 samples, not a full-size call)
    (importing numba and loading, or compiling, the kernels), which the timed
    repeats do not include; ``planar_cpu_s``/``peer_cpu_s`` the processor time
    of each call (all of planar's threads together) and ``cpu_ratio`` the
    ratio of their medians, the work each does, which other load on the machine
    disturbs less than the wall-clock ``ratio``.  ``solve`` writes into the
    output blocks of results the caller has dropped
    (:mod:`planar.core.buffers`), as each timed call drops the last;
    ``planar_new_memory_samples_per_s`` and ``ratio_new_memory`` time the
    same call with that off (``PLANAR_RECYCLE=0``, new pages every call),
    interleaved with the others.
    """
    if n < 1 or repeats < 1:
        raise PlanarError("planar bench kinematics needs n >= 1 and repeats >= 1")
    cases = [_kinematics_case(name, n, repeats) for name in KINEMATICS_CASES]
    return {
        "benchmark": "kinematics",
        "n": n,
        "repeats": repeats,
        "peer": "pylinkage step_fast (numba)",
        "cores": os.cpu_count(),
        "cases": cases,
        "ratio": min(c["ratio"] for c in cases),
        "ok": all(c["agrees"] for c in cases),
    }


def format_kinematics(r: dict[str, Any]) -> str:
    """Human-readable table of :func:`bench_kinematics` results."""
    lines = [
        (
            f"public solve vs {r['peer']}, {r['n']:,} crank angles, median (min-max) of {r['repeats']} "
            f"interleaved repeats, {r['cores']} cores"
        )
    ]
    for c in r["cases"]:
        p, q, k = c["planar_samples_per_s"], c["peer_samples_per_s"], c["ratio_per_repeat"]
        lines += [
            f"  {c['linkage']} ({c['nodes']} nodes, {c['parts']} parts)",
            (
                f"    planar solve ({c['threads']} threads) {p['median'] / 1e6:8.2f} M samples/s "
                f"({p['min'] / 1e6:.2f}-{p['max'] / 1e6:.2f}), {c['kernels']} kernels "
                f"(the process's first solve, up to 20,000 samples, numba import and kernel load included: "
                f"{c['first_call_s']:.2f} s)"
            ),
            (f"    pylinkage step_fast        {q['median'] / 1e6:8.2f} M samples/s ({q['min'] / 1e6:.2f}-{q['max'] / 1e6:.2f})"),
            f"    ratio                      {c['ratio']:8.2f}  (per repeat {k['min']:.2f}-{k['max']:.2f})",
            (
                f"    planar, new memory per call {c['planar_new_memory_samples_per_s']['median'] / 1e6:7.2f} M samples/s "
                f"(PLANAR_RECYCLE=0): ratio {c['ratio_new_memory']:.2f}"
            ),
            (
                f"    processor time             {c['planar_cpu_s']['median'] * 1e3:8.1f} ms vs "
                f"{c['peer_cpu_s']['median'] * 1e3:.1f} ms: ratio {c['cpu_ratio']:.2f}"
            ),
            f"    max |planar - peer|        {c['max_abs_diff_vs_peer']:8.1e}  (size {c['size']:.3g})"
            + ("" if c["agrees"] else f"  DISAGREES (more than {AGREEMENT:g}, or invalid samples)"),
        ]
    return "\n".join(lines)
