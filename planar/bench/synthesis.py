"""``planar bench synthesis``: published path-synthesis problems, planar against pylinkage's synthesis and optimisers, one run.

Problems (targets exactly as published):

* ``cabrera-2002-case-2``: five points at prescribed crank angles pi/6 ...
  pi/2, Grashof crank (Cabrera, Simon, Prado, Mech. Mach. Theory 37 (2002)
  1165-1177, case 2);
* ``kunjur-1997-line``: six points on the line x = 20, y = 20 ... 45, no
  timing (Kunjur & Krishnamurty 1997; Cabrera et al. 2002, case 1).

Their published best errors were not found (:data:`SEARCHED` says where this
session looked); each problem carries ``published_params`` for a published
linkage, None while there is none, and the tests recompute a published error
from its parameters when one is added.

The peer is pylinkage 1.3, in four ways, every result converted to planar's
parameters and scored by the same measure as planar's: ``sse``, the sum of
squared distances from the targets to the coupler point, from planar's
solver, at the prescribed crank angles (timed) or at the crank angles nearest
each target on the curve (untimed, 7200 per turn):

* its synthesis as documented: ``path_generation_with_timing(points,
  crank_angles)`` (timed) and ``path_generation(points)`` (untimed,
  ``orientation_resolution=3`` in ``--quick``);
* the same with ``require_grashof=False``;
* the same on four of the targets (:func:`subset4`; pylinkage documents three
  or four as its practical range), ``require_grashof=False``, every solution
  kept, scored on all the targets;
* its optimisers: particle swarm over the whole four-bar with planar's
  bounds, then Nelder-Mead (:mod:`planar.bench.peers.pylinkage`).

planar, the documented synthesis and the optimisers alternate for
``repeats`` repeats (planar's seed is the repeat number; pylinkage's swarm is
unseeded); times are wall seconds, median (min-max).  With ``--full`` (``quick=False``),
planar's Stephenson and Watt six-bars run once each (seed 0) on the same
targets.
"""

from __future__ import annotations

import math
import os
import time
import warnings
from typing import Any

import numpy as np
from numpy.typing import NDArray

from planar.errors import PlanarError
from planar.synth.path import FourBarDesign, check_design, synthesise_path
from planar.synth.search import Constraints

__all__ = ["PROBLEMS", "bench_synthesis", "format_synthesis", "kernel_rate"]

Array = NDArray[np.float64]

#: what this session's search covered for the published errors (see the README's benchmark section)
SEARCHED = (
    "searched (2026-11-22) with the session's search tool: its web-page corpus holds later papers that "
    "benchmark these cases (Sleesongsom & Bureerat, Comput. Intell. Neurosci. 2018, 5462563; Appl. Sci. 2022, "
    "12(15), 7368; Yao et al., individual repairing method; Winyangkul et al., Biomimetics 2026, 11(3), 160; "
    "Buskiewicz, J. Theor. Appl. Mech. 56(1) (2018) 43-55; Sedano et al., Math. Probl. Eng. 2012, 151590; "
    "Kafash & Nahvi, Mech. Mach. Theory 115 (2017) 18-34) but returns only each page's opening passage, never a "
    "results table, and no page of Acharyya & Mandal 2009, Ebrahimi & Payvandy or Lin 2010; the public-code index "
    "has no file with "
    "the case-2 coordinates (2.759, 3.363, 3.943) or with Kunjur, Krishnamurty or Acharyya in this context; "
    "jmejia8/eca-four-bar-mechanisms (testTrajectories.jl, case 4) holds the six line points, no error"
)

PROBLEMS: dict[str, dict[str, Any]] = {
    "cabrera-2002-case-2": {
        "targets": [(3.0, 3.0), (2.759, 3.363), (2.372, 3.663), (1.890, 3.862), (1.355, 3.943)],
        "theta": [math.pi / 6, math.pi / 4, math.pi / 3, 5 * math.pi / 12, math.pi / 2],
        "published": "not found",
        "published_params": None,
        "source": "Cabrera, Simon, Prado, Mech. Mach. Theory 37 (2002) 1165-1177, case 2",
        "searched": SEARCHED,
    },
    "kunjur-1997-line": {
        "targets": [(20.0, y) for y in (20.0, 25.0, 30.0, 35.0, 40.0, 45.0)],
        "theta": None,
        "published": "not found",
        "published_params": None,
        "source": "Kunjur & Krishnamurty 1997; Cabrera et al. 2002 case 1",
        "searched": SEARCHED,
    },
}


def subset4(n: int) -> list[int]:
    """Four of ``n`` targets for pylinkage's synthesis (its practical range): first, last, two evenly between."""
    return sorted({int(i) for i in np.rint(np.linspace(0, n - 1, 4))})


def _from_pylinkage(sol: Any, targets: Array, theta: Array | None) -> FourBarDesign | None:
    """A pylinkage FourBarSolution as planar's design, scored like planar's (None if it cannot close)."""
    A, D = np.asarray(sol.ground_pivot_a, float), np.asarray(sol.ground_pivot_d, float)
    B, C = np.asarray(sol.crank_pivot_b, float), np.asarray(sol.coupler_pivot_c, float)
    P = np.asarray(sol.coupler_point if sol.coupler_point is not None else B, float)
    g = D - A
    e = (C - B) / max(np.hypot(*(C - B)), 1e-300)
    q = P - B
    u, v = float(q @ e), float(e[0] * q[1] - e[1] * q[0])
    e1 = D - B
    circ = 1.0 if e1[0] * (C - B)[1] - e1[1] * (C - B)[0] > 0 else -1.0
    row = np.array(
        [np.hypot(*g), sol.crank_length, sol.coupler_length, sol.rocker_length, u, v, A[0], A[1], math.atan2(g[1], g[0])]
    )
    return score_params(row, circ, targets, theta)


def score_params(p: Array, circuit: float, targets: Array, theta: Array | None) -> FourBarDesign | None:
    """planar's design of the four-bar ``p`` (planar's 9 parameters, circuit sign), scored by planar's solver.

    Timed: at ``theta``; untimed: at the crank angles nearest each target (7200 per turn).  None if the
    lengths cannot close.
    """
    from planar.synth.kernel import coupler_points
    from planar.synth.search import PathObjective, _nearest_theta

    row = np.append(np.asarray(p, float)[:9], 1.0 if circuit >= 0 else -1.0)
    circ = row[9]
    L = row[:4]
    if L.min() <= 0 or L.max() >= L.sum() - L.max():
        return None
    if theta is None:
        th = _nearest_theta(PathObjective(targets, None, Constraints(full_turn=False, max_ratio=1e12)), row, 7200)
    else:
        th = np.asarray(theta, float)
    d = FourBarDesign(
        float(row[0]),
        float(row[1]),
        float(row[2]),
        float(row[3]),
        (float(row[4]), float(row[5])),
        "open" if circ > 0 else "crossed",
        (float(row[6]), float(row[7]), float(row[8])),
        th,
        float("nan"),
        targets,
        theta is not None,
        0.0,
    )
    try:
        x, y, _ = coupler_points(row[None, :9], th[None, :], np.array([circ]))
        check_design(d, np.column_stack([x[0], y[0]]))
    except PlanarError:
        return None
    return d


def _pylinkage_run(name: str, prob: dict[str, Any], quick: bool, require_grashof: bool, four: bool = False) -> dict[str, Any]:
    """pylinkage's synthesis on the problem's targets (``four``: on :func:`subset4` of them, every
    solution kept, ``require_grashof=False``), each solution scored by planar's measure on all targets."""
    try:
        import pylinkage
        from pylinkage.synthesis import path_generation, path_generation_with_timing
    except ImportError as e:  # pragma: no cover - depends on the environment
        raise PlanarError("planar bench synthesis needs the peer library pylinkage: pip install 'planar[bench]'") from e
    t = np.asarray(prob["targets"], float)
    idx = subset4(len(t)) if four else list(range(len(t)))
    pts = [(float(t[i, 0]), float(t[i, 1])) for i in idx]
    what = f"targets {[i + 1 for i in idx]}" if four else "points"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        t0 = time.perf_counter()
        if prob["theta"] is not None:
            angles = [float(prob["theta"][i]) for i in idx]
            call = f"path_generation_with_timing({what}, their crank angles, require_grashof={require_grashof})"
            res = path_generation_with_timing(pts, angles, require_grashof=require_grashof)
        else:
            kw: dict[str, Any] = {"require_grashof": require_grashof}
            if four:
                kw["max_solutions"] = None
            elif quick:
                kw["orientation_resolution"] = 3
            call = f"path_generation({what}" + "".join(f", {k}={v}" for k, v in kw.items()) + ")"
            res = path_generation(pts, **kw)
        secs = time.perf_counter() - t0
    th = None if prob["theta"] is None else np.asarray(prob["theta"], float)
    designs = [d for d in (_from_pylinkage(s, t, th) for s in res.raw_solutions) if d is not None]
    best = min(designs, key=lambda d: d.sse) if designs else None
    return {
        "call": f"pylinkage {pylinkage.__version__} synthesis.{call}",
        "time_s": secs,
        "solutions": len(res.raw_solutions),
        "sse": None if best is None else best.sse,
        "grashof": None if best is None else best.checks.get("grashof"),
        "crank_turns_fully": None if best is None else bool(best.checks.get("ok_crank_turns_fully")),
        "warnings": [w.splitlines()[0] for w in res.warnings],
    }


def _pylinkage_optimise(prob: dict[str, Any], quick: bool) -> dict[str, Any]:
    """pylinkage's optimisers (:mod:`planar.bench.peers.pylinkage`), the result scored by planar's measure."""
    import pylinkage

    from planar.bench.peers.pylinkage import optimise

    t = np.asarray(prob["targets"], float)
    th = None if prob["theta"] is None else np.asarray(prob["theta"], float)
    r = optimise(t, th, "quick" if quick else "normal")
    d = score_params(r["params"], r["circuit"], t, th)
    return {
        "call": f"pylinkage {pylinkage.__version__} " + r["calls"],
        "time_s": r["time_s"],
        "evaluations": r["evaluations"],
        "pylinkage_sse": r["pylinkage_sse"],
        "sse": None if d is None else d.sse,
        "ok": d is not None and d.ok,
        "best": None if d is None else d.to_dict(),
    }


def kernel_bytes(samples: int = 64) -> float:
    """Bytes one candidate of :func:`kernel_rate` holds at its peak (the float64 pass): its parameters (9
    float64) and its coupler point ``x``, ``y`` (float64) and validity (1 byte) at each of ``samples`` angles,
    plus the parameters again while they are drawn (``column_stack`` of the random columns)."""
    return 2 * 9 * 8.0 + samples * (8 + 8 + 1)


def check_kernel_rate(n: int, samples: int = 64) -> None:
    """:class:`~planar.errors.LimitError` before :func:`kernel_rate` of ``n`` candidates would pass the memory
    limit (``-n`` named, with the count that fits): ``n`` x :func:`kernel_bytes` beside what is held."""
    from planar.core.limits import check_memory, resident_bytes, units_within

    held, per = resident_bytes(), kernel_bytes(samples)
    check_memory(
        "-n", n, held + per * n, "the kernel-rate measurement's candidates", fits=f"{units_within(held, per):,} candidates"
    )


def kernel_rate(n: int = 200_000, samples: int = 64, repeats: int = 5) -> dict[str, Any]:
    """Candidate four-bars evaluated per second by the kernel (coupler point and validity at ``samples`` angles).

    float32 (the search's screening precision) and float64 (refinement), interleaved.  Refused up front
    (:func:`check_kernel_rate`) when ``n`` candidates would pass the memory limit.
    """
    from planar.synth.kernel import coupler_points

    check_kernel_rate(n, samples)

    rng = np.random.default_rng(0)
    X = np.column_stack([rng.uniform(1, 3, (n, 4)), rng.uniform(-2, 2, (n, 2)), rng.uniform(-1, 1, (n, 3))])
    th = np.linspace(0, 2 * np.pi, samples, endpoint=False)
    coupler_points(X[:1000], th)
    rates: dict[type, list[float]] = {np.float32: [], np.float64: []}
    for r in range(repeats):
        for dt in (np.float32, np.float64) if r % 2 == 0 else (np.float64, np.float32):
            t0 = time.perf_counter()
            coupler_points(X, th, dtype=dt)
            rates[dt].append(n / (time.perf_counter() - t0))
    from planar.linkages.chunked import threads_default

    r32, r64 = rates[np.float32], rates[np.float64]
    return {
        "candidates": n,
        "samples": samples,
        "threads": threads_default(),
        "median": float(np.median(r32)),
        "min": float(min(r32)),
        "max": float(max(r32)),
        "float64": {"median": float(np.median(r64)), "min": float(min(r64)), "max": float(max(r64))},
    }


def bench_synthesis(
    repeats: int = 3,
    quick: bool = False,
    n: int | None = None,
    problems: tuple[str, ...] | None = None,
    reachable: int | None = None,
    heldout: int | None = None,
) -> dict[str, Any]:
    """Both problems, planar and pylinkage alternating ``repeats`` times (see the module).

    ``quick``: one repeat, planar's ``quick`` budget, pylinkage's coarser
    orientation grid; ``n`` (``-n``): candidates in the kernel-rate measurement;
    ``problems``: a subset of :data:`PROBLEMS` by name (all by default);
    ``reachable``: random reachable crank-rocker curves per number of targets in :func:`bench_reachable` (25, or 2
    with ``quick``, which also runs one drag-link and one part-curve a size; 0 leaves that benchmark, the targets
    scaling, :func:`bench_unreachable` (7 problems per group, 56 in all, or 1 per group with ``quick``) and
    :func:`planar.bench.synthesis_rocking.bench_rocking` (the rocking inputs' arcs) out);
    ``heldout``: function and motion problems per size in :mod:`planar.bench.synthesis_heldout` (50, or 2 with
    ``quick``; 0 leaves them out).
    """
    if repeats < 1:
        raise PlanarError("planar bench synthesis needs repeats >= 1")
    if quick:
        repeats = 1
    n_rate = n or (50_000 if quick else 250_000)
    check_kernel_rate(n_rate)  # before the minutes of the problems, not after them
    budget = "quick" if quick else "normal"
    cases = []
    names = tuple(PROBLEMS) if problems is None else problems
    for name in names:
        if name not in PROBLEMS:
            raise PlanarError(f"no synthesis problem {name!r} (problems: {', '.join(PROBLEMS)})")
        prob = PROBLEMS[name]
        t = np.asarray(prob["targets"], float)
        th = None if prob["theta"] is None else np.asarray(prob["theta"], float)
        ours: list[FourBarDesign] = []
        peer: list[dict[str, Any]] = []
        opt: list[dict[str, Any]] = []
        for r in range(repeats):
            for side in ("planar", "peer", "opt") if r % 2 == 0 else ("opt", "peer", "planar"):
                if side == "planar":
                    ours.append(synthesise_path(t, th, Constraints(), budget=budget, seed=r))
                elif side == "peer":
                    peer.append(_pylinkage_run(name, prob, quick, require_grashof=True))
                else:
                    opt.append(_pylinkage_optimise(prob, quick))
        loose = _pylinkage_run(name, prob, quick, require_grashof=False)
        four = _pylinkage_run(name, prob, quick, require_grashof=False, four=True)
        six: dict[str, Any] = {}
        if not quick:  # one run per six-bar topology (seed 0): the same targets, what a six-bar adds
            from planar.synth.sixbar import TOPOLOGIES, synthesise_sixbar

            for topo in TOPOLOGIES:
                d6 = synthesise_sixbar(t, th, topo, Constraints(), budget=budget, seed=0)
                six[topo] = {"sse": d6.sse, "time_s": d6.seconds, "ok": d6.ok}
        best = min(ours, key=lambda d: d.sse)
        times = [d.seconds for d in ours]
        ptimes = [p["time_s"] for p in peer]
        sses = [d.sse for d in ours]
        cases.append(
            {
                "problem": name,
                "targets": len(t),
                "timed": th is not None,
                "published_best_error": prob["published"],
                "published_source": prob["source"],
                "published_searched": prob["searched"],
                "planar": {
                    "sse_median": float(np.median(sses)),
                    "sse_min": float(min(sses)),
                    "sse_max": float(max(sses)),
                    "time_s": {"median": float(np.median(times)), "min": float(min(times)), "max": float(max(times))},
                    "budget": budget,
                    "ok": all(d.ok for d in ours),
                    "best": best.to_dict(),
                },
                "pylinkage": {
                    **peer[0],
                    "time_s": {"median": float(np.median(ptimes)), "min": float(min(ptimes)), "max": float(max(ptimes))},
                },
                "pylinkage_without_grashof": loose,
                "pylinkage_four_targets": four,
                "pylinkage_optimisers": _summary(opt),
                "planar_sixbar": six,
            }
        )
    rate = kernel_rate(n_rate, repeats=1 if quick else 5)
    count = (2 if quick else 25) if reachable is None else reachable
    extra: dict[str, Any] = {}
    if count > 0:
        # the other kinds (drag-links, part-curves): one a size in the quick run, as many as the crank-rockers otherwise
        extra["reachable"] = bench_reachable(count=count, quick=quick, kind_count=1 if quick else None)
        extra["targets_scaling"] = bench_targets_scaling(quick=quick)
        extra["unreachable"] = bench_unreachable(count=1 if quick else 7, quick=quick)
        from planar.bench.synthesis_heldout import bench_reachable_pylinkage, reachable_problems

        peer_problems = reachable_problems(reachable_problem, count=count)
        extra["reachable_pylinkage"] = bench_reachable_pylinkage(peer_problems, _from_pylinkage)
        from planar.bench.synthesis_rocking import bench_rocking

        extra["rocking"] = bench_rocking(quick=quick)  # double- and triple-rockers' arcs, untimed and ordered
    per = (2 if quick else 50) if heldout is None else heldout
    if per > 0:
        from planar.bench.synthesis_heldout import bench_function_heldout, bench_motion_heldout

        extra["function_heldout"] = bench_function_heldout(count=per)
        extra["motion_heldout"] = bench_motion_heldout(count=per)
    return {
        **extra,
        "benchmark": "synthesis",
        "repeats": repeats,
        "quick": quick,
        "cores": os.cpu_count(),
        "kernel_candidates_per_s": rate,
        "cases": cases,
        "ok": all(c["planar"]["ok"] for c in cases),
    }


def _summary(runs: list[dict[str, Any]]) -> dict[str, Any]:
    """The optimiser's repeats: planar-scored sse and time, median (min-max), and the best run."""
    sses = [r["sse"] if r["sse"] is not None else math.inf for r in runs]
    times = [r["time_s"] for r in runs]
    best = runs[int(np.argmin(sses))]
    return {
        "call": best["call"],
        "runs": len(runs),
        "sse_median": float(np.median(sses)),
        "sse_min": float(min(sses)),
        "sse_max": float(max(sses)),
        "time_s": {"median": float(np.median(times)), "min": float(min(times)), "max": float(max(times))},
        "evaluations": best["evaluations"],
        "pylinkage_sse_of_best": best["pylinkage_sse"],
        "ok": all(r["ok"] for r in runs),
        "best": best["best"],
    }


def _e(v: Any) -> str:
    return "none" if v is None else (v if isinstance(v, str) else f"{v:.3g}")


def format_synthesis(r: dict[str, Any]) -> str:
    k = r["kernel_candidates_per_s"]
    lines = [
        f"path synthesis, planar vs pylinkage's synthesis and optimisers, {r['repeats']} interleaved repeat(s), "
        f"{r['cores']} cores",
        f"  kernel: {k['median']:,.0f} candidate four-bars/s at {k['samples']} samples, float32 "
        f"({k['min']:,.0f}-{k['max']:,.0f}); float64 {k['float64']['median']:,.0f} "
        f"({k['float64']['min']:,.0f}-{k['float64']['max']:,.0f}); {k['threads']} threads",
    ]
    for c in r["cases"]:
        p, q, q2 = c["planar"], c["pylinkage"], c["pylinkage_without_grashof"]
        q4, o = c["pylinkage_four_targets"], c["pylinkage_optimisers"]
        lines += [
            f"  {c['problem']} ({c['targets']} targets, {'timed' if c['timed'] else 'untimed'}); "
            f"published best error: {c['published_best_error']} ({c['published_source']})",
            f"    planar     sse {_e(p['sse_median'])} ({_e(p['sse_min'])}-{_e(p['sse_max'])})  "
            f"time {p['time_s']['median']:.2f} s  {'ok' if p['ok'] else 'CHECK FAILED'}",
            f"    pylinkage synthesis, as documented: sse {_e(q['sse'])} ({q['solutions']} solutions)  "
            f"time {q['time_s']['median']:.2f} s",
            f"    pylinkage synthesis, require_grashof=False: sse {_e(q2['sse'])} ({q2['solutions']} solutions, "
            f"crank turns fully: {q2['crank_turns_fully']})  time {q2['time_s']:.2f} s",
            f"    pylinkage synthesis on 4 of the targets, scored on all: sse {_e(q4['sse'])} "
            f"({q4['solutions']} solutions, crank turns fully: {q4['crank_turns_fully']})  time {q4['time_s']:.2f} s",
            f"    pylinkage optimisers (particle swarm, Nelder-Mead): sse {_e(o['sse_median'])} "
            f"({_e(o['sse_min'])}-{_e(o['sse_max'])}; pylinkage's own {_e(o['pylinkage_sse_of_best'])})  "
            f"time {o['time_s']['median']:.2f} s  {o['evaluations']} evaluations",
        ]
        for topo, v in c.get("planar_sixbar", {}).items():
            lines.append(
                f"    planar {topo} six-bar (one run): sse {_e(v['sse'])}  time {v['time_s']:.2f} s  "
                f"{'ok' if v['ok'] else 'CHECK FAILED'}"
            )
    if any(c["published_best_error"] == "not found" for c in r["cases"]):
        lines.append("  published errors not found: --json's published_searched (and the README) say where this looked")
    if "reachable" in r:
        lines.append(format_reachable(r["reachable"], r["targets_scaling"]))
    if "unreachable" in r:
        lines.append(format_unreachable(r["unreachable"]))
    if "reachable_pylinkage" in r:
        from planar.bench.synthesis_heldout import format_reachable_pylinkage

        lines.append(format_reachable_pylinkage(r["reachable_pylinkage"]))
    if "rocking" in r:
        from planar.bench.synthesis_rocking import format_rocking

        lines.append(format_rocking(r["rocking"]))
    if "function_heldout" in r:
        from planar.bench.synthesis_heldout import format_heldout

        lines.append(format_heldout(r["function_heldout"], r["motion_heldout"]))
    return "\n".join(lines)


# --- reachable curves: random four-bars the search was not tuned on (issue: synthesis that finds the mechanism) ---


def _random_grashof(rng: np.random.Generator, shortest: str) -> tuple[Array, float]:
    """A random Grashof four-bar whose ``shortest`` link (``"crank"`` or ``"ground"``) is shortest (link ratio <= 10,
    2 % from a change point), a random coupler point and placement: the kernel's 9 parameters and the circuit.
    Three lengths uniform in 0.3 to 3, the shortest 0.1 to 1 times their least; coupler point uniform in a box
    twice the coupler's length, placement anywhere in the unit square, any rotation."""
    while True:
        a, c, r = rng.uniform(0.3, 3.0, 3)
        short = rng.uniform(0.1, 1.0) * min(a, c, r)
        g, k = (a, short) if shortest == "crank" else (short, a)
        L = sorted((g, k, c, r))
        if L[0] == short and L[0] + L[3] < 0.98 * (L[1] + L[2]) and L[3] <= 9.5 * L[0]:
            break
    u, v = c * rng.uniform(-1.0, 2.0), c * rng.uniform(-1.0, 1.0)
    row = np.array([g, k, c, r, u, v, rng.uniform(), rng.uniform(), rng.uniform(-np.pi, np.pi)])
    return row, float(rng.choice([-1.0, 1.0]))


def random_crank_rocker(rng: np.random.Generator) -> tuple[Array, float]:
    """A random Grashof crank-rocker (crank shortest, link ratio <= 10) with a random coupler point and placement:
    the kernel's 9 parameters and the circuit.  Lengths uniform (not the atlas's log-uniform): see
    :func:`_random_grashof`."""
    return _random_grashof(rng, "crank")


def reachable_problem(rng: np.random.Generator, n: int) -> tuple[Array, Array]:
    """``n`` targets on the coupler curve of :func:`random_crank_rocker` at sorted random crank angles, and the angles."""
    row, circ = random_crank_rocker(rng)
    th = np.sort(rng.uniform(0.0, 2 * np.pi, n))
    return _on_curve(row, circ, th), th


def random_drag_link(rng: np.random.Generator) -> tuple[Array, float]:
    """A random Grashof drag-link (double-crank: the ground shortest, link ratio <= 10, 2 % from a change point)
    with a random coupler point and placement, drawn as :func:`random_crank_rocker` with the ground and crank
    exchanged: the kernel's 9 parameters and the circuit."""
    return _random_grashof(rng, "ground")


def _on_curve(row: Array, circ: float, th: Array) -> Array:
    from planar.synth.kernel import coupler_points

    x, y, _ = coupler_points(row[None, :], th, np.array([circ]))
    return np.column_stack([x[0], y[0]])


def _whole_turn(rng: np.random.Generator, n: int, linkage: Any) -> tuple[Array, Array]:
    row, circ = linkage(rng)
    th = np.sort(rng.uniform(0.0, 2 * np.pi, n))
    return _on_curve(row, circ, th), th


def part_curve_problem(rng: np.random.Generator, n: int) -> tuple[Array, Array]:
    """``n`` targets on PART of the coupler curve of a random crank-rocker or drag-link (either, even odds): sorted
    random crank angles within an arc of 90 to 300 degrees starting anywhere (an open target set), and the angles."""
    row, circ = (random_crank_rocker if rng.random() < 0.5 else random_drag_link)(rng)
    span = np.radians(rng.uniform(90.0, 300.0))
    th = rng.uniform(-np.pi, np.pi) + np.sort(rng.uniform(0.0, span, n))
    return _on_curve(row, circ, th), th


#: the reachable problems' kinds (:func:`bench_reachable`): each draws ``n`` targets and their crank angles
REACHABLE_KINDS: dict[str, Any] = {
    "crank-rocker": reachable_problem,
    "drag-link": lambda rng, n: _whole_turn(rng, n, random_drag_link),
    "part-curve": part_curve_problem,
}


def _max_error(targets: Array, row: Array, theta: Array) -> float:
    """Largest distance from a target to the coupler point of ``row`` (9 + circuit) at ``theta``, over the
    targets' size (RMS distance from their centroid)."""
    from planar.synth.search import Constraints, PathObjective, max_distance
    from planar.synth.targets import normalisation

    _, s = normalisation(targets)
    return max_distance(PathObjective(targets, None, Constraints()), row, np.asarray(theta, float)) / s


def scipy_baseline(targets: Array, theta: Array | None, cpu_s: float, seed: int = 0) -> tuple[float, int]:
    """A plain many-start :func:`scipy.optimize.least_squares` (trf, its own finite differences) from random
    starts in planar's bounds, the crank angles at the targets free when untimed (started at the nearest
    point of the start's curve), until ``cpu_s`` of CPU time is spent: (best largest error over the targets'
    size, starts).  Same normalisation as planar (targets moved to centroid 0, size 1)."""
    from scipy.optimize import least_squares

    from planar.synth.kernel import coupler_points
    from planar.synth.search import Constraints, PathObjective, _nearest_theta, default_bounds, violation
    from planar.synth.targets import normalisation

    c, s = normalisation(targets)
    t = (targets - c) / s
    b = default_bounds(t, Constraints(), theta is not None)
    lo, hi = np.array([v[0] for v in b]), np.array([v[1] for v in b])
    rng = np.random.default_rng(seed)
    obj = PathObjective(t, theta, Constraints())
    best, starts, t0 = math.inf, 0, time.process_time()
    while starts == 0 or time.process_time() - t0 < cpu_s:
        row = lo + (hi - lo) * rng.random(len(b))
        circ = 1.0 if row[9] >= 0 else -1.0
        th0 = theta if theta is not None else _nearest_theta(obj, row)

        def resid(z: Array, circ: float = circ) -> Array:
            th = theta if theta is not None else z[9:]
            x, y, ok = coupler_points(z[None, :9], np.asarray(th)[None, :], np.array([circ]))
            r = np.concatenate([x[0] - t[:, 0], y[0] - t[:, 1]])
            return np.append(np.where(np.concatenate([ok[0], ok[0]]), r, 10.0), 10.0 * violation(z[None, :9], obj.cons, 1.0)[0])

        z0 = row[:9] if theta is not None else np.concatenate([row[:9], th0])
        res = least_squares(resid, z0, method="trf", max_nfev=200 * len(z0))
        starts += 1
        th = theta if theta is not None else res.x[9:]
        if violation(res.x[None, :9], Constraints(), 1.0, 0.0)[0] == 0:
            best = min(best, _max_error(t, np.append(res.x[:9], circ), th))
    return best, starts


def loaded_atlases(quick: bool) -> dict[str, Any]:
    """The closed-curve atlas and the curve-window atlas of the budget, loaded (built on first use) and their k-d
    trees built, so no timed problem pays for either: keyword arguments of
    :func:`planar.synth.path.synthesise_path`."""
    from planar.synth import windows
    from planar.synth.atlas import DEFAULT_SIZE, QUICK_SIZE, load_atlas

    atlas = load_atlas(QUICK_SIZE if quick else DEFAULT_SIZE)
    w = windows.load_windows(windows.QUICK_FOURBARS if quick else windows.DEFAULT_FOURBARS)
    atlas.tree  # noqa: B018 (built here, not inside the first timed problem)
    w.tree  # noqa: B018
    return {"atlas": atlas, "windows": w}


def bench_reachable(
    sizes: tuple[int, ...] = (8, 12, 25, 50),
    count: int = 25,
    seed: int = 2026,
    quick: bool = False,
    noise: float = 0.01,
    kinds: tuple[str, ...] = tuple(REACHABLE_KINDS),
    kind_count: int | None = None,
) -> dict[str, Any]:
    """Reachable curves of random four-bars never used to tune anything, per kind of :data:`REACHABLE_KINDS`
    (crank-rockers over the whole turn, drag-links over the whole turn, part-curves: an arc of 90 to 300 degrees of
    a crank-rocker's or drag-link's turn), ``count`` crank-rockers and ``kind_count`` (``count`` when None) of each
    other kind per number of targets in ``sizes``, each kind its own random stream (``seed`` and the kind's place):
    planar untimed (atlas, after it is loaded) and timed, each by CPU time (``time.process_time``) and largest
    error over the targets' size; then the crank-rockers' curves with Gaussian noise (``noise`` of their size;
    unreachable), planar against :func:`scipy_baseline` given the CPU time planar took.  ``quick``: the
    20,000-curve atlas."""
    from threadpoolctl import threadpool_limits

    for k in kinds:
        if k not in REACHABLE_KINDS:
            raise PlanarError(f"bench_reachable: unknown kind {k!r} (one of {', '.join(REACHABLE_KINDS)})")
    t0 = time.process_time()
    atlases = loaded_atlases(quick)
    atlas = atlases["atlas"]
    load_s = time.process_time() - t0
    rows: list[dict[str, Any]] = []
    with threadpool_limits(1):
        for place, kind in enumerate(kinds):
            # the crank-rockers keep the stream they always had (``seed`` alone)
            rng = np.random.default_rng(seed if kind == "crank-rocker" else (seed, place))
            per = count if kind == "crank-rocker" or kind_count is None else kind_count
            for n in sizes:
                for _ in range(per):
                    rows.append(_reachable_row(rng, kind, n, atlases, quick, noise if kind == "crank-rocker" else None))
    return {
        "atlas_size": len(atlas),
        "atlas_load_cpu_s": load_s,
        "atlas_build_cpu_s": atlas.build_seconds,
        "rows": rows,
        "summary": _reachable_summary(rows),
    }


def _reachable_row(
    rng: np.random.Generator, kind: str, n: int, atlases: dict[str, Any], quick: bool, noise: float | None
) -> dict[str, Any]:
    """One problem of :func:`bench_reachable`: untimed and timed, and with ``noise`` (None: not) against scipy."""
    T, th = REACHABLE_KINDS[kind](rng, n)
    budget = "quick" if quick else "normal"
    rec: dict[str, Any] = {"kind": kind, "targets": n}
    for mode, theta in (("untimed", None), ("timed", th)):
        c0 = time.process_time()
        d = synthesise_path(T, theta, budget=budget, **atlases)
        rec[mode] = {"cpu_s": time.process_time() - c0, "max_error": d.checks["max_error"], "ok": d.ok}
    if noise is not None:
        noisy = T + noise * float(np.sqrt(np.mean(np.sum((T - T.mean(0)) ** 2, 1)))) * rng.standard_normal(T.shape)
        c0 = time.process_time()
        d = synthesise_path(noisy, None, budget=budget, **atlases)
        cpu = time.process_time() - c0
        base, starts = scipy_baseline(noisy, None, cpu)
        rec["noisy"] = {"cpu_s": cpu, "planar_max_error": d.checks["max_error"], "scipy_max_error": base, "scipy_starts": starts}
    return rec


def _reachable_summary(rows: list[dict[str, Any]]) -> dict[str, Any]:
    """Per kind and number of targets (keys ``"<kind> <n>"``): success within 1e-6 of the size, median error and
    CPU (median, 90th percentile, largest), untimed and timed; for the crank-rockers the noisy comparison."""
    out: dict[str, Any] = {}
    for kind in dict.fromkeys(r.get("kind", "crank-rocker") for r in rows):
        for n in sorted({r["targets"] for r in rows if r.get("kind", "crank-rocker") == kind}):
            rs = [r for r in rows if r.get("kind", "crank-rocker") == kind and r["targets"] == n]
            s: dict[str, Any] = {"kind": kind, "targets": n, "problems": len(rs)}
            for mode in ("untimed", "timed"):
                e = np.array([r[mode]["max_error"] for r in rs])
                c = np.array([r[mode]["cpu_s"] for r in rs])
                s[f"{mode}_recovered_1e-6"] = float(np.mean(e <= 1e-6))
                s[f"{mode}_median_error"] = float(np.median(e))
                s[f"{mode}_median_cpu_s"] = float(np.median(c))
                s[f"{mode}_p90_cpu_s"] = float(np.percentile(c, 90))
                s[f"{mode}_max_cpu_s"] = float(np.max(c))
            if all("noisy" in r for r in rs):
                s["noisy_planar_as_good_as_scipy"] = float(
                    np.mean([r["noisy"]["planar_max_error"] <= r["noisy"]["scipy_max_error"] * (1 + 1e-9) for r in rs])
                )
                s["noisy_planar_median_error"] = float(np.median([r["noisy"]["planar_max_error"] for r in rs]))
                s["noisy_scipy_median_error"] = float(np.median([r["noisy"]["scipy_max_error"] for r in rs]))
            out[f"{kind} {n}"] = s
    return out


def bench_targets_scaling(
    sizes: tuple[int, ...] = (8, 16, 32, 64, 128), seed: int = 7, quick: bool = False
) -> list[dict[str, Any]]:
    """CPU time of untimed path synthesis against the number of targets (one reachable curve each, atlas loaded)."""
    from planar.synth.path import synthesise_path

    atlases = loaded_atlases(quick)
    rng = np.random.default_rng(seed)
    out = []
    for n in sizes:
        T, _ = reachable_problem(rng, n)
        c0 = time.process_time()
        d = synthesise_path(T, None, budget="quick" if quick else "normal", **atlases)
        out.append({"targets": n, "cpu_s": time.process_time() - c0, "max_error": d.checks["max_error"]})
    return out


def format_reachable(r: dict[str, Any], scaling: list[dict[str, Any]]) -> str:
    lines = [
        f"reachable curves of random four-bars (atlas of {r['atlas_size']:,}: built in {r['atlas_build_cpu_s']:.1f} s CPU, "
        f"loaded in {r['atlas_load_cpu_s']:.1f} s CPU)",
        "  kind          targets  untimed ok(<=1e-6)  median err  CPU median / 90th pct | timed ok  CPU median / max | "
        "noisy: planar >= scipy  median err planar / scipy",
    ]
    for s in r["summary"].values():
        noisy = (
            f"{s['noisy_planar_as_good_as_scipy']:>21.0%}  "
            f"{s['noisy_planar_median_error']:.3g} / {s['noisy_scipy_median_error']:.3g}"
            if "noisy_planar_as_good_as_scipy" in s
            else f"{'-':>21}"
        )
        lines.append(
            f"  {s['kind']:<12}  {s['targets']:>7}  {s['untimed_recovered_1e-6']:>17.0%}  {s['untimed_median_error']:>10.2g}  "
            f"{s['untimed_median_cpu_s']:>11.2f} / {s['untimed_p90_cpu_s']:.2f} s | {s['timed_recovered_1e-6']:>8.0%}  "
            f"{s['timed_median_cpu_s']:>10.2f} / {s['timed_max_cpu_s']:.2f} s | {noisy}"
        )
    lines.append("  untimed CPU against targets: " + ", ".join(f"{x['targets']}: {x['cpu_s']:.2f} s" for x in scaling))
    return "\n".join(lines)


# --- unreachable targets: noisy four-bar curves and six-bar curves, planar against the scipy baseline ---

#: the unreachable groups: (what, targets, noise as a fraction of the size or a six-bar topology)
UNREACHABLE_GROUPS: tuple[tuple[str, int, float | str], ...] = (
    ("noise 0.5 %", 12, 0.005),
    ("noise 0.5 %", 25, 0.005),
    ("noise 2 %", 12, 0.02),
    ("noise 2 %", 25, 0.02),
    ("stephenson six-bar", 12, "stephenson"),
    ("stephenson six-bar", 25, "stephenson"),
    ("watt six-bar", 12, "watt"),
    ("watt six-bar", 25, "watt"),
)


def random_sixbar(rng: np.random.Generator, topology: str, samples: int = 256) -> Array:
    """A random six-bar of planar's ``topology`` (:data:`planar.synth.sixbar.TOPOLOGIES`) whose crank turns
    fully and whose second dyad closes over the whole turn with a margin: its 15 parameters and two circuit
    signs (:func:`planar.synth.sixbar.sixbar_points`).  The four-bar is :func:`random_crank_rocker`; the
    point ``E`` anywhere within a box twice the coupler's (rocker's) length, the fixed pivot ``O6`` within
    two ground lengths of the crank pivot, the dyad's links and the tracer in proportion to them."""
    from planar.synth.sixbar import sixbar_points

    th = np.linspace(0.0, 2 * np.pi, samples, endpoint=False)
    while True:
        row, circ = random_crank_rocker(rng)
        g, side = row[0], row[2] if topology == "stephenson" else row[3]
        e = side * rng.uniform(-1.0, 1.0, 2) + np.array([0.5 * side, 0.0])
        o6 = row[6:8] + 2.0 * g * rng.uniform(-1.0, 1.0, 2)
        l5, l6 = g * np.exp(rng.uniform(np.log(0.3), np.log(3.0), 2))
        tu, tv = l5 * rng.uniform(-1.0, 2.0), l5 * rng.uniform(-1.0, 1.0)
        X = np.concatenate([row[:4], e, row[6:9], o6, [l5, l6, tu, tv, circ, rng.choice([-1.0, 1.0])]])
        _, _, margin = sixbar_points(X[None, :], th, topology)
        if margin.min() > 1e-2:
            return X


def unreachable_problem(rng: np.random.Generator, n: int, kind: float | str) -> Array:
    """``n`` targets no four-bar passes through exactly: a random crank-rocker's curve at sorted random crank
    angles with Gaussian noise of ``kind`` (a float, a fraction of the targets' size) in each coordinate, or a
    random six-bar's tracer curve (``kind`` its topology)."""
    th = np.sort(rng.uniform(0.0, 2 * np.pi, n))
    if isinstance(kind, str):
        from planar.synth.sixbar import sixbar_points

        x, y, _ = sixbar_points(random_sixbar(rng, kind)[None, :], th, kind)
        return np.column_stack([x[0], y[0]])
    T, _ = reachable_problem(rng, n)
    size = float(np.sqrt(np.mean(np.sum((T - T.mean(0)) ** 2, 1))))
    return T + kind * size * rng.standard_normal(T.shape)


def bench_unreachable(count: int = 7, seed: int = 4711, quick: bool = False) -> dict[str, Any]:
    """``count`` problems of every group of :data:`UNREACHABLE_GROUPS` (seeded ``seed``, never used to tune
    anything): planar's untimed path synthesis (``normal`` budget, or ``quick``; CPU time by
    ``time.process_time``), then :func:`scipy_baseline` given the same CPU time; each by the largest distance
    from a target to the coupler point over the targets' size.  ``as_good``: planar's at most the
    baseline's (relative 1e-9)."""
    from threadpoolctl import threadpool_limits

    from planar.synth.path import synthesise_path

    atlases = loaded_atlases(quick)
    rows: list[dict[str, Any]] = []
    with threadpool_limits(1):
        for g, (what, n, kind) in enumerate(UNREACHABLE_GROUPS):
            rng = np.random.default_rng([seed, g])
            for _ in range(count):
                T = unreachable_problem(rng, n, kind)
                c0 = time.process_time()
                d = synthesise_path(T, None, budget="quick" if quick else "normal", **atlases)
                cpu = time.process_time() - c0
                base, starts = scipy_baseline(T, None, cpu)
                e = float(d.checks["max_error"])
                rows.append(
                    {
                        "group": what,
                        "targets": n,
                        "cpu_s": cpu,
                        "planar_max_error": e,
                        "scipy_max_error": base,
                        "scipy_starts": starts,
                        "as_good": bool(e <= base * (1 + 1e-9)),
                    }
                )
    groups: dict[str, Any] = {}
    for what, n, _ in UNREACHABLE_GROUPS:
        rs = [r for r in rows if r["group"] == what and r["targets"] == n]
        groups[f"{what}, {n} targets"] = {
            "problems": len(rs),
            "as_good": float(np.mean([r["as_good"] for r in rs])),
            "planar_median_error": float(np.median([r["planar_max_error"] for r in rs])),
            "scipy_median_error": float(np.median([r["scipy_max_error"] for r in rs])),
            "median_cpu_s": float(np.median([r["cpu_s"] for r in rs])),
        }
    return {"rows": rows, "groups": groups, "as_good": float(np.mean([r["as_good"] for r in rows])), "problems": len(rows)}


def format_unreachable(r: dict[str, Any]) -> str:
    lines = [
        f"unreachable targets ({r['problems']} problems): planar as good as a many-start scipy least_squares given "
        f"the same CPU time in {r['as_good']:.0%}",
        "  group                              as good  median err planar / scipy  median CPU",
    ]
    for k, s in r["groups"].items():
        lines.append(
            f"  {k:<34} {s['as_good']:>7.0%}  {s['planar_median_error']:.3g} / {s['scipy_median_error']:.3g}"
            f"  {s['median_cpu_s']:.2f} s"
        )
    return "\n".join(lines)
