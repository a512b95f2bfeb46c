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
    from planar.linkages.nodes import RRR, Crank, Fixed, Rigid

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


#: the sizes of the default size curve (crank angles per solve): a scene's few dozen samples to a million
SIZES = (50, 72, 1_000, 10_000, 100_000, 1_000_000)
#: processor time a timed measurement lasts at least (small sizes repeat the call within it)
MIN_MEASURE_S = 0.02


def _spread(values: list[float]) -> dict[str, float]:
    return {"median": float(np.median(values)), "min": float(min(values)), "max": float(max(values))}


def _calls_for(fn: Any) -> int:
    """How many calls of ``fn`` make one measurement of at least :data:`MIN_MEASURE_S` of processor time."""
    fn()  # a first call may load a kernel (the poses' on their first read)
    c0 = time.process_time()
    fn()
    once = max(time.process_time() - c0, 1e-7)
    return max(1, min(100_000, math.ceil(MIN_MEASURE_S / once)))


def _measure(fn: Any, calls: int) -> tuple[float, float]:
    """Processor and wall time of one call of ``fn`` (mean over ``calls`` calls), in seconds."""
    c0, t0 = time.process_time(), time.perf_counter()
    for _ in range(calls):
        fn()
    return (time.process_time() - c0) / calls, (time.perf_counter() - t0) / calls


def _agreement(mech: Any, step: float, n: int) -> dict[str, Any]:
    """Planar's joints against pylinkage's at the crank angles pylinkage reached (up to 20,000 samples).

    pylinkage re-reads its crank angle from the crank's position every step
    (it drifts by rounding over many steps), so planar solves at those angles.
    """
    crank = next(nd for nd in mech.nodes if nd.is_input)
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
    return {"max_abs_diff_vs_peer": diff, "max_abs_diff_points_vs_peer": diff_points, "first_call_s": first_call}


def _size_row(mech: Any, step: float, n: int, repeats: int) -> dict[str, Any]:
    """One linkage at one size: planar's public ``solve`` and pylinkage's ``step_fast``, interleaved repeats."""
    from planar.linkages.chunked import solver_for

    q = step * np.arange(1, n + 1)
    valid = True

    def planar_call() -> None:
        nonlocal valid
        valid = bool(mech.solve(q).valid.all()) and valid

    def poses_call() -> None:
        motion = mech.solve(q)
        _ = motion.poses  # every part's pose (computed on first access)

    peer = _pylinkage_of(mech, step)

    def peer_call() -> None:
        peer.step_fast(iterations=n)

    fns = {"planar": planar_call, "peer": peer_call, "poses": poses_call}
    # warm-up outside the timing (pylinkage's numba compile, cached; planar's first call of a size takes new
    # memory, which its later calls recycle), and the number of calls that make one measurement
    calls = {who: _calls_for(fn) for who, fn in fns.items()}
    cpu: dict[str, list[float]] = {who: [] for who in fns}
    wall: dict[str, list[float]] = {who: [] for who in fns}
    order = ("planar", "peer", "poses")
    for r in range(repeats):
        for who in order[r % 3 :] + order[: r % 3]:  # each first in turn
            c, w = _measure(fns[who], calls[who])
            cpu[who].append(c)
            wall[who].append(w)
    cpu_ratios = [b / a for a, b in zip(cpu["planar"], cpu["peer"])]
    wall_ratios = [b / a for a, b in zip(wall["planar"], wall["peer"])]
    return {
        "n": n,
        "calls_per_measure": calls,
        "planar_cpu_s": _spread(cpu["planar"]),
        "peer_cpu_s": _spread(cpu["peer"]),
        "planar_wall_s": _spread(wall["planar"]),
        "peer_wall_s": _spread(wall["peer"]),
        "poses_cpu_s": _spread(cpu["poses"]),
        "poses_wall_s": _spread(wall["poses"]),
        # peer time / planar time: above 1 planar is the faster
        "cpu_ratio": float(np.median(cpu["peer"]) / np.median(cpu["planar"])),
        "wall_ratio": float(np.median(wall["peer"]) / np.median(wall["planar"])),
        "poses_cpu_ratio": float(np.median(cpu["peer"]) / np.median(cpu["poses"])),
        "cpu_ratio_per_repeat": _spread(cpu_ratios),
        "wall_ratio_per_repeat": _spread(wall_ratios),
        "planar_samples_per_s": n / float(np.median(wall["planar"])),
        "peer_samples_per_s": n / float(np.median(wall["peer"])),
        "kernels": solver_for(mech, n),
        "all_valid": valid,
    }


def _kinematics_case(name: str, sizes: tuple[int, ...], repeats: int) -> dict[str, Any]:
    """One linkage over the size curve, with the agreement check."""
    from planar.linkages.chunked import threads_default
    from planar.scene.catalog import get

    mech: Any = get(name)
    step = 2 * math.pi / 3600
    agree = _agreement(mech, step, max(sizes))
    rows = [_size_row(mech, step, n, repeats) for n in sizes]
    valid = all(r["all_valid"] for r in rows)
    return {
        "linkage": name,
        "nodes": len(mech.nodes),
        "parts": len(mech.parts),
        "size": float(mech.size),
        "threads": threads_default(),
        **agree,
        "curve": rows,
        "cpu_ratio": min(r["cpu_ratio"] for r in rows),
        "ratio": min(r["wall_ratio"] for r in rows),
        "all_valid": valid,
        "agrees": agree["max_abs_diff_vs_peer"] <= AGREEMENT and agree["max_abs_diff_points_vs_peer"] <= AGREEMENT and valid,
    }


def bench_kinematics(n: int | None = None, repeats: int = 7, sizes: tuple[int, ...] | None = None) -> dict[str, Any]:
    """The public ``Mechanism.solve`` against pylinkage's ``step_fast`` (numba) over a curve of sizes.

    For the four-bar (ground 4, crank 1, coupler 4, rocker 3, coupler point
    (2, 1)) and Jansen's leg, planar's ``solve`` (the path users call: poses of
    every part, validity, failure codes, named points) and pylinkage's fastest
    path (``step_fast``: every joint's position) each solve ``n`` crank angles
    ``k * 2 pi / 3600``, ``k = 1..n``, for every ``n`` of ``sizes`` (default
    :data:`SIZES`; ``n`` alone: that one size).  The two alternate,
    ``repeats`` times each (order swapped every repeat); a measurement repeats
    the call until it lasts :data:`MIN_MEASURE_S` of processor time and gives
    the time of one call.  ``solve`` returns the joints' positions (named
    points), validity and failure codes, as the peer returns its joints; the
    parts' poses (an ``atan2`` per part and sample) are computed when the
    motion's ``poses`` are first read: a third measurement, interleaved with
    the two, times ``solve`` and that read (``poses_cpu_s``,
    ``poses_cpu_ratio``: peer over planar with every pose).  Per size: processor time (all of a process's
    threads: the work each does, which other load on the machine disturbs
    less) and wall time, median with min and max, and the ratios of the
    medians, peer over planar (``cpu_ratio``, ``wall_ratio``: above 1 planar
    is the faster).  Per linkage and at the top, ``cpu_ratio`` and ``ratio``
    are the smallest over the sizes (the top: over both linkages).

    Agreement: planar solves at the crank angles pylinkage reached (up to
    20,000) and every joint is compared (``max_abs_diff_vs_peer``, model
    units); ``ok`` is false (and the command's exit status 1) unless every
    joint agrees within :data:`AGREEMENT` and every sample is valid.
    ``first_call_s``: the process's first solve (numba import and kernel
    load included), which the timed repeats leave out.  ``solve`` writes into
    the output blocks of results the caller has dropped
    (:mod:`planar.core.buffers`), as each timed call drops the last.
    """
    curve = tuple(sizes) if sizes is not None else ((n,) if n is not None else SIZES)
    if not curve or min(curve) < 1 or repeats < 1:
        raise PlanarError("planar bench kinematics needs sizes n >= 1 and repeats >= 1")
    cases = [_kinematics_case(name, curve, repeats) for name in KINEMATICS_CASES]
    return {
        "benchmark": "kinematics",
        "sizes": list(curve),
        "repeats": repeats,
        "peer": "pylinkage step_fast (numba)",
        "cores": os.cpu_count(),
        "cases": cases,
        "ratio": min(c["ratio"] for c in cases),
        "cpu_ratio": min(c["cpu_ratio"] for c in cases),
        "ok": all(c["agrees"] for c in cases),
    }


def _t(s: float) -> str:
    """A time in the unit that suits it."""
    return f"{s * 1e6:.1f} us" if s < 1e-3 else (f"{s * 1e3:.2f} ms" if s < 1.0 else f"{s:.2f} s")


def format_kinematics(r: dict[str, Any]) -> str:
    """Human-readable table of :func:`bench_kinematics` results."""
    lines = [
        (
            f"public solve vs {r['peer']}: time per call, median of {r['repeats']} interleaved repeats "
            f"(ratio: peer / planar, the repeats' range in brackets), {r['cores']} cores; "
            "+poses: solve and every part's pose read (computed on first access)"
        )
    ]
    head = (
        f"    {'N':>9}  {'planar cpu':>10}  {'peer cpu':>10}  {'cpu ratio':>20}  "
        f"{'planar wall':>11}  {'peer wall':>10}  {'wall ratio':>20}  {'+poses cpu':>10}  {'ratio':>6}"
    )
    for c in r["cases"]:
        lines += [
            f"  {c['linkage']} ({c['nodes']} nodes, {c['parts']} parts, {c['threads']} threads; first solve in the "
            f"process, numba import and kernel load included: {c['first_call_s']:.2f} s)",
            head,
        ]
        for row in c["curve"]:
            cr, wr = row["cpu_ratio_per_repeat"], row["wall_ratio_per_repeat"]
            lines.append(
                f"    {row['n']:>9,}  {_t(row['planar_cpu_s']['median']):>10}  {_t(row['peer_cpu_s']['median']):>10}  "
                f"{row['cpu_ratio']:6.2f} ({cr['min']:5.2f}-{cr['max']:5.2f})  "
                f"{_t(row['planar_wall_s']['median']):>11}  {_t(row['peer_wall_s']['median']):>10}  "
                f"{row['wall_ratio']:6.2f} ({wr['min']:5.2f}-{wr['max']:5.2f})  "
                f"{_t(row['poses_cpu_s']['median']):>10}  {row['poses_cpu_ratio']:6.2f}"
                + ("" if row["all_valid"] else "  INVALID SAMPLES")
            )
        lines.append(
            f"    max |planar - peer|  {c['max_abs_diff_vs_peer']:.1e} joints, {c['max_abs_diff_points_vs_peer']:.1e} "
            f"points (size {c['size']:.3g})"
            + ("" if c["agrees"] else f"  DISAGREES (more than {AGREEMENT:g}, or invalid samples)")
        )
    lines.append(f"  smallest ratio over every size: processor time {r['cpu_ratio']:.2f}, wall time {r['ratio']:.2f}")
    return "\n".join(lines)
