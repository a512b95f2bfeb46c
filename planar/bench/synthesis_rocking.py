"""Rocking inputs: double- and triple-rockers recovered from targets on their arcs (part of ``planar bench synthesis``).

The problems are made from known random four-bars whose input link cannot turn fully:

* lengths: ground 1, input, coupler and rocker log-uniform in :data:`LENGTHS`;
* kind ``"double"``: a Grashof double-rocker (the coupler the shortest link, the shortest plus the longest at
  most ``1 - CHANGE_MARGIN`` times the other two: :data:`CHANGE_MARGIN` from a change point); kind
  ``"triple"``: a non-Grashof triple-rocker (the shortest plus the longest at least ``1 + CHANGE_MARGIN``
  times the other two);
* the input's range (where the loop closes, the upper of two symmetric arcs when there are two) at least
  :data:`MIN_SWING_DEG` degrees;
* the coupler point ``u`` in ``(-1, 2)`` and ``v`` in ``(-1.5, 1.5)`` coupler lengths (in the coupler's frame:
  origin at the input's pin, x toward the rocker's pin), the input pivot in ``(-1, 1)^2``, the ground line's
  angle uniform, either circuit;
* the sub-range rule: the targets are the coupler points at ``n`` sorted uniform input angles in a random part
  of the range, from a fraction in :data:`SUBRANGE` of it in from its lower end to a fraction in
  :data:`SUBRANGE` in from its upper end (targets usually cover part of a swing, rarely all of it).

Every problem's targets therefore lie, in order, on one swing of a rocking four-bar on one circuit.  Each is
given untimed and ordered to :func:`planar.synth.path.synthesise_rocking_path` (the rocking-arc atlas and the
curve-window atlas loaded once before the first problem: their load is not in the problems' CPU) with a tolerance
of 1e-3 of the targets'
size; measured: the largest distance over the targets' size (planar's solver), whether the result keeps the
targets on one swing of its input, in order, its whole swing assembling on one circuit, and the CPU time of
the call (``time.process_time``, one BLAS thread).
"""

from __future__ import annotations

import math
import time
from typing import Any

import numpy as np
from numpy.typing import NDArray

__all__ = ["KINDS", "bench_rocking", "format_rocking", "rocking_problem"]

Array = NDArray[np.float64]

#: the default seed of the problems (drawn after the search was settled: never used to tune it)
SEED = 20261130
#: the two kinds of rocking four-bar
KINDS = ("double", "triple")
#: the input, coupler and rocker lengths (ground 1) are log-uniform between these
LENGTHS = (0.2, 2.0)
#: the distance from a change point, as a fraction of the sum of the middle two links
CHANGE_MARGIN = 0.02
#: the input's range is at least this (degrees)
MIN_SWING_DEG = 20.0
#: the targets' sub-range starts and ends this fraction of the range in from each end (uniform)
SUBRANGE = (0.02, 0.32)
#: the number of targets per problem, and problems per size of each kind (quick: fewer)
SIZES = (8, 12, 25, 50)
COUNT = {"double": 50, "triple": 20}
QUICK_COUNT = {"double": 2, "triple": 1}
#: recovered: the largest distance over the targets' size at most this
EXACT = 1e-6


def _lengths(rng: np.random.Generator, kind: str) -> tuple[Array, float, float]:
    """Input, coupler and rocker lengths (ground 1) of a rocking four-bar of ``kind``, and its input's range (rad)."""
    from planar.synth.arcs import input_range

    lo_l, hi_l = np.log(LENGTHS[0]), np.log(LENGTHS[1])
    while True:
        L = np.exp(rng.uniform(lo_l, hi_l, 3))
        s = sorted([1.0, *L])
        if kind == "double":
            ok = L[1] == s[0] and s[0] + s[3] < (1.0 - CHANGE_MARGIN) * (s[1] + s[2])
        else:
            ok = s[0] + s[3] > (1.0 + CHANGE_MARGIN) * (s[1] + s[2])
        if not ok:
            continue
        lo, hi, rocks = input_range(L[:1], L[1:2], L[2:3])
        if rocks[0] and hi[0] - lo[0] > math.radians(MIN_SWING_DEG):
            return L, float(lo[0]), float(hi[0])


def rocking_problem(rng: np.random.Generator, kind: str, n: int) -> dict[str, Any]:
    """``n`` targets on the arc of a random rocking four-bar of ``kind`` (``"double"`` or ``"triple"``; see the
    module): ``targets`` ``(n, 2)``, the four-bar as a kernel row ``fourbar`` (ground, input, coupler, rocker,
    u, v, x0, y0, phi), its ``circuit`` (+1 open, -1 crossed), the input angles ``theta`` (rad from the ground
    line, sorted) and its input's whole ``range`` (rad)."""
    from planar.synth.kernel import coupler_points

    if kind not in KINDS:
        from planar.errors import InputError

        raise InputError("kind", kind, "one of " + ", ".join(KINDS))
    L, lo, hi = _lengths(rng, kind)
    span = hi - lo
    a0, a1 = lo + span * rng.uniform(*SUBRANGE), hi - span * rng.uniform(*SUBRANGE)
    u, v = L[1] * rng.uniform(-1.0, 2.0), L[1] * rng.uniform(-1.5, 1.5)
    p = np.array([1.0, *L, u, v, *rng.uniform(-1.0, 1.0, 2), rng.uniform(-np.pi, np.pi)])
    theta = np.sort(rng.uniform(a0, a1, n))
    circuit = float(rng.choice([1.0, -1.0]))
    x, y, ok = coupler_points(p[None], theta[None], np.array([circuit]))
    if not ok.all():  # inside the range the loop always closes: a failure here is a bug, not bad luck
        raise AssertionError("a rocking problem's loop does not close inside its input's range")
    return {
        "targets": np.column_stack([x[0], y[0]]),
        "fourbar": p,
        "circuit": circuit,
        "theta": theta,
        "range": (lo, hi),
    }


def _counts(count: int | dict[str, int] | None, quick: bool) -> dict[str, int]:
    if count is None:
        return dict(QUICK_COUNT if quick else COUNT)
    if isinstance(count, dict):
        return {k: int(count.get(k, 0)) for k in KINDS}
    return {k: int(count) for k in KINDS}


def _one(t: Array, arcs: Any, windows: Any, budget: str) -> dict[str, Any]:
    from planar.synth.path import synthesise_rocking_path

    c0 = time.process_time()
    d = synthesise_rocking_path(t, tolerance=1e-3, ordered=True, arcs=arcs, budget=budget, windows=windows)
    cpu = time.process_time() - c0
    ch = d.checks
    kept = bool(ch.get("ok_on_one_swing") and ch.get("ok_order") and ch.get("ok_swing_assembles"))
    return {"error": float(ch.get("max_error", math.inf)), "cpu_s": cpu, "one_swing": kept}


def bench_rocking(
    sizes: tuple[int, ...] = SIZES,
    count: int | dict[str, int] | None = None,
    seed: int = SEED,
    quick: bool = False,
) -> dict[str, Any]:
    """Random double- and triple-rockers (see the module) recovered from ``sizes`` targets on their arcs.

    ``count``: problems per kind and size (an int for both, or ``{"double": n, "triple": m}``; default
    :data:`COUNT`, :data:`QUICK_COUNT` with ``quick``); ``seed``: the problems' seed (problem ``i`` of a kind and
    size is the same whatever the other counts); ``quick``: the quick arc atlas (``budget="quick"``) and the quick
    counts.  Returns the atlases' load CPU (s), and per kind and size the problems' largest distances over their
    size, CPU times (s), whether each kept its targets on one swing in order, and a summary."""
    from threadpoolctl import threadpool_limits

    from planar.synth.arcs import DEFAULT_FOURBARS, QUICK_FOURBARS, load_arcs
    from planar.synth.windows import load_budget_windows

    counts = _counts(count, quick)
    budget = "quick" if quick else "normal"
    c0 = time.process_time()
    arcs = load_arcs(QUICK_FOURBARS if quick else DEFAULT_FOURBARS, progress=True)
    windows = load_budget_windows(budget)
    arcs.tree  # noqa: B018 - the k-d trees are built on first use: here, not in the first problem
    windows.tree  # noqa: B018
    load = time.process_time() - c0
    groups = []
    with threadpool_limits(1):
        for kind in KINDS:
            for n in sizes:
                rng = np.random.default_rng([seed, n, KINDS.index(kind)])
                rows = [_one(rocking_problem(rng, kind, n)["targets"], arcs, windows, budget) for _ in range(counts[kind])]
                groups.append({"kind": kind, "targets": n, "problems": rows, **_summary(rows)})
    return {"seed": seed, "quick": quick, "atlas_arcs": len(arcs), "atlas_load_cpu_s": load, "groups": groups}


def _summary(rows: list[dict[str, Any]]) -> dict[str, Any]:
    if not rows:
        return {"count": 0}
    e = np.array([r["error"] for r in rows])
    c = np.array([r["cpu_s"] for r in rows])
    return {
        "count": len(rows),
        "within_1e-6": float(np.mean(e <= EXACT)),
        "within_1e-4": float(np.mean(e <= 1e-4)),
        "within_1e-3": float(np.mean(e <= 1e-3)),
        "median_error": float(np.median(e)),
        "cpu_median_s": float(np.median(c)),
        "cpu_p90_s": float(np.percentile(c, 90)),
        "all_on_one_swing": all(r["one_swing"] for r in rows),
    }


def _kept(g: dict[str, Any]) -> str:
    """How many results kept their targets on one swing, in order (those that did not fail their own check)."""
    bad = sum(not q["one_swing"] for q in g["problems"])
    return "all" if not bad else f"{g['count'] - bad} of {g['count']} (the rest fail their check)"


def format_rocking(result: dict[str, Any]) -> str:
    """The result of :func:`bench_rocking` as a table."""
    lines = [
        f"rocking inputs: seed {result['seed']}, arc atlas of {result['atlas_arcs']:,} arcs "
        f"and the curve-window atlas (loaded in {result['atlas_load_cpu_s']:.1f} s CPU); untimed, ordered; largest "
        "distance over the targets' size",
        f"{'four-bars':<15}{'targets':>8}{'problems':>9}{'<=1e-6':>8}{'<=1e-4':>8}{'<=1e-3':>8}"
        f"{'median':>10}{'CPU med':>9}{'CPU p90':>9}  on one swing, in order",
    ]
    for g in result["groups"]:
        if not g["count"]:
            continue
        lines.append(
            f"{g['kind'] + '-rockers':<15}{g['targets']:>8}{g['count']:>9}{g['within_1e-6']:>8.0%}"
            f"{g['within_1e-4']:>8.0%}{g['within_1e-3']:>8.0%}{g['median_error']:>10.1e}"
            f"{g['cpu_median_s']:>8.2f}s{g['cpu_p90_s']:>8.2f}s  {_kept(g)}"
        )
    return "\n".join(lines)
