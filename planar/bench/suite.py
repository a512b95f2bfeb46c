"""Benchmarks a user can run (``planar bench NAME``), each against a peer in the same run.

Results are ratios measured on the machine at hand, never hard-coded targets.
``kinematics``: planar's public ``solve`` of a four-bar and of Jansen's leg
against pylinkage's fastest path (its numba ``step_fast``) on the same
linkages, interleaved repeats reported as median and spread, checking that
both give the same joint positions.
"""

from __future__ import annotations

import math
import os
import time
from collections.abc import Callable, Mapping, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from planar.errors import PlanarError

if TYPE_CHECKING:
    from numpy.typing import NDArray

    from planar.core.model import Motion
    from planar.scene.load import Scene

    Array = NDArray[np.float64]

__all__ = ["BENCHMARKS", "bench_kinematics"]


def _best_time(fn: Callable[[], Any], repeats: int) -> float:
    best = math.inf
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


# --------------------------------------------------------------------------- kinematics

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


BENCHMARKS: dict[str, tuple[Callable[..., dict[str, Any]], Callable[[dict[str, Any]], str]]] = {
    "kinematics": (bench_kinematics, format_kinematics),
}


# --------------------------------------------------------------------------- render


def _matplotlib_gif(mech, motion, path: str, width: int, height: int, delay_ms: int) -> None:
    """The peer: matplotlib's FuncAnimation + PillowWriter drawing the same parts and trail."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.animation import FuncAnimation, PillowWriter
    from matplotlib.patches import Polygon

    from planar.core.geometry import poses_apply
    from planar.draw.frames import PART_COLORS, _rings

    fig = plt.figure(figsize=(width / 100, height / 100), dpi=100)
    ax = fig.add_axes((0, 0, 1, 1))
    ax.set_aspect("equal")
    ax.axis("off")
    rings = {p.name: poses_apply(motion.poses[p.name], _rings(p)[0]) for p in mech.parts}
    allp = np.concatenate([r.reshape(-1, 2) for r in rings.values()])
    pad = 0.05 * np.ptp(allp, axis=0).max()
    ax.set_xlim(allp[:, 0].min() - pad, allp[:, 0].max() + pad)
    ax.set_ylim(allp[:, 1].min() - pad, allp[:, 1].max() + pad)
    patches = {}
    for i, p in enumerate(mech.parts):
        colour = "#c8c8c8" if p.ground else PART_COLORS[(i - 1) % len(PART_COLORS)]
        patches[p.name] = ax.add_patch(Polygon(rings[p.name][0], closed=True, fc=colour, ec="#303030"))
    for pts in motion.points.values():
        ax.plot(pts[:, 0], pts[:, 1], lw=1, color="#7f3fbf")

    def update(i: int):
        for n, patch in patches.items():
            patch.set_xy(rings[n][i])  # type: ignore[attr-defined]  # Polygon patches
        return list(patches.values())

    anim = FuncAnimation(fig, update, frames=len(motion), blit=False)
    anim.save(path, writer=PillowWriter(fps=int(round(1000.0 / delay_ms))))
    plt.close(fig)


def bench_render(n: int = 120, repeats: int = 5, width: int = 480, height: int = 360) -> dict[str, Any]:
    """Frames per second and GIF size: planar's renderer vs matplotlib's animation writer.

    Both draw the same four-bar (parts as filled outlines, coupler trail) at
    the same size and frame count into a GIF; the best of ``repeats`` runs
    each, end to end (drawing, palette, encoding, file).
    """
    import tempfile

    from planar.app.formats import writer
    from planar.draw.frames import Renderer, Style, palette_colors
    from planar.scene.catalog import get

    gif = writer("gif")
    frame_delay_ms, indexer, write_gif = gif.frame_delay_ms, gif.indexer, gif.write_gif
    mech = get("fourbar-crank-rocker")
    motion = mech.run(samples_per_cycle=n)
    delay = frame_delay_ms(mech.driver.period, n)
    with tempfile.TemporaryDirectory() as tmp:
        ours_path = os.path.join(tmp, "planar.gif")
        peer_path = os.path.join(tmp, "matplotlib.gif")

        def ours() -> None:
            r = Renderer(mech, motion, Style(width=width, height=height))
            pal = palette_colors(r.style, len(mech.parts))
            write_gif(ours_path, r.frames(post=indexer(pal)), delay, pal)

        def peer() -> None:
            _matplotlib_gif(mech, motion, peer_path, width, height, delay)

        ours()
        peer()
        t_ours = _best_time(ours, repeats)
        t_peer = _best_time(peer, repeats)
        size_ours = os.path.getsize(ours_path)
        size_peer = os.path.getsize(peer_path)
    return {
        "benchmark": "render",
        "frames": n,
        "size_px": [width, height],
        "planar_fps": n / t_ours,
        "peer": "matplotlib FuncAnimation + PillowWriter",
        "peer_fps": n / t_peer,
        "ratio": (n / t_ours) / (n / t_peer),
        "planar_gif_bytes": size_ours,
        "peer_gif_bytes": size_peer,
        "size_ratio": size_ours / size_peer,
    }


def format_render(r: dict[str, Any]) -> str:
    return "\n".join(
        [
            f"four-bar GIF, {r['frames']} frames at {r['size_px'][0]}x{r['size_px'][1]}",
            f"  planar        {r['planar_fps']:8.1f} frames/s   {r['planar_gif_bytes']:>9,} bytes",
            f"  matplotlib    {r['peer_fps']:8.1f} frames/s   {r['peer_gif_bytes']:>9,} bytes",
            f"  ratio planar/matplotlib  {r['ratio']:.2f} (frames/s), size {r['size_ratio']:.2f}",
        ]
    )


BENCHMARKS["render"] = (bench_render, format_render)


# --------------------------------------------------------------------------- accuracy


def _times(m: Motion) -> Array:
    """The sample times of a motion solved over time (a scene's motion always has them)."""
    if m.t is None:
        raise PlanarError("benchmark: a motion without sample times")
    return m.t


ACCURACY_GRID = {
    "substeps": (8, 16, 32, 64, 96),
    "iterations": (10, 20, 40, 80),
    "correction": (0.02, 0.05, 0.1, 0.2, 0.4),
}

#: ``planar bench accuracy --quick``
ACCURACY_QUICK_GRID = {"substeps": (8, 32), "iterations": (10, 40), "correction": (0.05, 0.2)}
#: the scenes ``--quick`` measures first, when the folder has them (else its first three that simulate)
ACCURACY_QUICK_SCENES = ("kangaroo-leg", "slider-crank", "jansen-leg")

#: adaptive settings measured beside the fixed grid: (least substeps, step drift), 40 iterations, correction 0.2;
#: each a factor 2 in step from the next (the drift per step goes as the step squared)
ACCURACY_ADAPTIVE = ((16, 1.4e-5), (32, 3.5e-6), (64, 8.75e-7))


def _setting_key(st: Any) -> tuple[Any, ...]:
    return (st.substeps, st.iterations, st.correction, st.error_bias, st.step_drift)


def _setting_label(st: Any) -> str:
    """``32/40/0.2`` for fixed substeps, ``32+/40/0.2 drift 3.5e-06`` for adaptive ones, error bias if given."""
    corr = f"bias {st.error_bias:g}" if st.error_bias is not None else f"{st.correction:g}"
    if st.step_drift is None:
        return f"{st.substeps}/{st.iterations}/{corr}"
    return f"{st.substeps}+/{st.iterations}/{corr} drift {st.step_drift:g}"


def accuracy_settings(quick: bool = False, grid: Mapping[str, Sequence[float]] | None = None) -> list[Any]:
    """The settings ``bench accuracy`` measures: the grid with fixed substeps, adaptive ones, the defaults
    and the defaults before issue 12 (64 substeps, 20 iterations, error bias 1e-9 per second)."""
    from dataclasses import replace

    from planar.physics.simulate import DEFAULT_SETTINGS, SimSettings

    if grid is None:
        grid = ACCURACY_QUICK_GRID if quick else ACCURACY_GRID
    out = [
        SimSettings(substeps=int(s), iterations=int(i), correction=float(b), tolerance=1.0, step_drift=None)
        for s in grid["substeps"]
        for i in grid["iterations"]
        for b in grid["correction"]
    ]
    extra = [replace(DEFAULT_SETTINGS, tolerance=1.0)]
    if not quick:
        extra += [
            SimSettings(substeps=k, iterations=40, correction=0.2, step_drift=d, tolerance=1.0) for k, d in ACCURACY_ADAPTIVE
        ]
        extra.append(_previous_defaults())
    keys = {_setting_key(x) for x in out}
    for x in extra:
        if _setting_key(x) not in keys:
            out.append(x)
            keys.add(_setting_key(x))
    return out


def _machine() -> str:
    """The machine a benchmark ran on: architecture, processor, cores, Python."""
    import platform

    return (
        f"{platform.machine()} {platform.processor() or ''} {os.cpu_count()} cores, Python {platform.python_version()}"
    ).replace("  ", " ")


def _previous_defaults() -> Any:
    from planar.physics.simulate import SimSettings

    return SimSettings(substeps=64, iterations=20, error_bias=1e-9, tolerance=1.0, step_drift=None)


def _pareto(points: list[tuple[float, float]]) -> list[bool]:
    """Which (time, error) points no other point beats in both (ties count as not beaten)."""
    out = []
    for i, (t, e) in enumerate(points):
        beaten = any((t2 <= t and e2 <= e and (t2 < t or e2 < e)) for j, (t2, e2) in enumerate(points) if j != i)
        out.append(not beaten)
    return out


def bench_accuracy(
    scenes: str | os.PathLike,
    out_dir: str = "planar-bench-accuracy",
    quick: bool = False,
    repeats: int = 2,
    progress: bool = True,
    grid: Mapping[str, Sequence[float]] | None = None,
    effects_fraction: float = 1.0,
) -> dict[str, Any]:
    """Simulation error against the analytic motion vs wall time, over the settings that trade them.

    ``scenes`` is the folder of scene files to measure (``planar bench
    accuracy --scenes``; the repository's ``gallery/``); nothing is looked up
    beside the code.  For every scene there that pymunk can rebuild, every combination of
    substeps per frame (i.e. the time step), solver iterations and error bias
    runs one full cycle; the error is the largest distance between simulated
    and analytic part points over the cycle, as a fraction of the mechanism's
    size; the cost is wall seconds per simulated second (best of
    ``repeats``).  Settings are ranked on the aggregate (worst error over the
    mechanisms, total time); the Pareto frontier is marked.  Writes
    ``accuracy.csv`` and ``accuracy.png`` in ``out_dir``.  ``quick``: the
    grid :data:`ACCURACY_QUICK_GRID` on three scenes (:data:`ACCURACY_QUICK_SCENES` first); ``grid``
    replaces the grid (keys as :data:`ACCURACY_GRID`).  The default settings
    are always measured.  The cost of effects (``effects_cost``) is measured
    over the first ``effects_fraction`` of a four-bar's cycle.
    """
    import csv
    import sys
    from dataclasses import replace
    from pathlib import Path

    from planar.app.pipeline import gallery_scenes
    from planar.errors import PlanarError
    from planar.physics.compare import compare
    from planar.physics.simulate import DEFAULT_SETTINGS, SimSettings, SimulationError, simulate, torque_comparison
    from planar.scene.load import load_scene

    scene_files = gallery_scenes(scenes)  # checks the folder before any work
    if quick:  # the quick run's three: a four-bar, a slider-crank and the Jansen leg when the folder has them
        scene_files.sort(
            key=lambda p: (
                ACCURACY_QUICK_SCENES.index(p.stem) if p.stem in ACCURACY_QUICK_SCENES else len(ACCURACY_QUICK_SCENES),
                p.name,
            )
        )
    settings = accuracy_settings(quick, grid)
    d = replace(DEFAULT_SETTINGS, tolerance=1.0)
    prev = _previous_defaults()
    measured: list[Scene] = []
    skipped: dict[str, str] = {}
    for path in scene_files:
        if quick and len(measured) == 3:
            break
        sc = load_scene(path)
        try:
            simulate(sc.mechanism, _times(sc.motion())[:3], sc.effects, SimSettings(substeps=1))
        except SimulationError as e:
            skipped[sc.name] = str(e)
            continue
        measured.append(sc)
    rows: list[dict[str, Any]] = []
    total = len(measured) * len(settings)
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=total, desc="accuracy", unit="run", disable=not sys.stderr.isatty(), leave=False)
    for sc in measured:
        ref = sc.motion()
        t_ref = _times(ref)
        sim_seconds = float(t_ref[-1] - t_ref[0])
        drv = sc.mechanism.driver
        motor_ok = drv.kind == "rotation" and drv.amplitude is None
        for st in settings:
            best = math.inf
            err = math.nan
            for _ in range(repeats):
                sim = simulate(sc.mechanism, t_ref, sc.effects, st)
                best = min(best, sim.wall_time)
                err = compare(sc.mechanism, ref, sim.motion).max_rel_error if sim.failure is None else math.inf
            motor_err = torque_err = math.nan
            if motor_ok:
                try:
                    tc = torque_comparison(sc.mechanism, t_ref, sc.effects, st)
                    motor_err = tc["pose_error"] if tc["failure"] is None else math.inf
                    torque_err = tc["max_rel_diff"] if tc["failure"] is None else math.inf
                except PlanarError:
                    motor_ok = False
            rows.append(
                {
                    "mechanism": sc.name,
                    "setting": _setting_label(st),
                    "substeps": sim.built["substeps"],
                    "iterations": sim.built["iterations"],
                    "correction": st.correction,
                    "step_drift": "" if st.step_drift is None else st.step_drift,
                    "error_bias": "" if st.error_bias is None else st.error_bias,
                    "dt_s": sim_seconds / (len(ref) - 1) / sim.built["substeps"],
                    "error": err,
                    "motor_error": motor_err,
                    "torque_error": torque_err,
                    "seconds_per_sim_second": best / sim_seconds,
                }
            )
            if bar is not None:
                bar.update()
    if bar is not None:
        bar.close()

    # aggregate per setting
    def worst(rs, key):
        v = [r[key] for r in rs if not math.isnan(r[key])]
        return max(v) if v else math.nan

    agg = []
    for st in settings:
        rs = [r for r in rows if r["setting"] == _setting_label(st)]
        agg.append(
            {
                "setting": _setting_label(st),
                "substeps": st.substeps,
                "iterations": st.iterations,
                "correction": st.correction,
                "step_drift": st.step_drift,
                "error_bias": st.error_bias,
                "max_error": max(worst(rs, "error"), worst(rs, "motor_error")),
                "kinematic_error": worst(rs, "error"),
                "motor_error": worst(rs, "motor_error"),
                "torque_error": worst(rs, "torque_error"),
                "seconds_per_sim_second": sum(r["seconds_per_sim_second"] for r in rs),
            }
        )
    front = _pareto([(a["seconds_per_sim_second"], a["max_error"]) for a in agg])
    for a, f in zip(agg, front):
        a["frontier"] = f and math.isfinite(a["max_error"])  # a setting that fails somewhere is no choice
        a["default"] = a["setting"] == _setting_label(d)
        a["previous_default"] = a["setting"] == _setting_label(prev)
    for sc_name in {r["mechanism"] for r in rows}:
        rs = [r for r in rows if r["mechanism"] == sc_name]
        for r, f in zip(rs, _pareto([(r["seconds_per_sim_second"], r["error"]) for r in rs])):
            r["frontier"] = f
    default = next(a for a in agg if a["default"])
    effects_cost = _effects_cost(repeats=max(3, repeats), fraction=effects_fraction)
    per_mech_default = {
        r["mechanism"]: {
            "kinematic": r["error"],
            "motor": r["motor_error"],
            "torque": r["torque_error"],
            "substeps": r["substeps"],
        }
        for r in rows
        if r["setting"] == _setting_label(d)
    }
    previous = next((a for a in agg if a["previous_default"]), None)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    from planar.fileio import atomic_write

    with atomic_write(out / "accuracy.csv", "w") as fh:
        w = csv.DictWriter(
            fh,
            fieldnames=[
                "mechanism",
                "setting",
                "substeps",
                "iterations",
                "correction",
                "step_drift",
                "error_bias",
                "dt_s",
                "error",
                "motor_error",
                "torque_error",
                "seconds_per_sim_second",
                "frontier",
            ],
            lineterminator="\n",
        )
        w.writeheader()
        for r in rows:
            w.writerow(r)
        for a in agg:
            w.writerow(
                {
                    "mechanism": "ALL (worst error, total time)",
                    "setting": a["setting"],
                    "substeps": a["substeps"],
                    "iterations": a["iterations"],
                    "correction": a["correction"],
                    "step_drift": "" if a["step_drift"] is None else a["step_drift"],
                    "error_bias": "" if a["error_bias"] is None else a["error_bias"],
                    "dt_s": "",
                    "error": a["kinematic_error"],
                    "motor_error": a["motor_error"],
                    "torque_error": a["torque_error"],
                    "seconds_per_sim_second": a["seconds_per_sim_second"],
                    "frontier": a["frontier"],
                }
            )
    _accuracy_chart(out / "accuracy.png", agg)
    return {
        "benchmark": "accuracy",
        "mechanisms": [s.name for s in measured],
        "skipped": skipped,
        "settings": len(settings),
        "default": default,
        "default_on_frontier": bool(default["frontier"]),
        "default_errors": per_mech_default,
        "previous_default": previous,
        "machine": _machine(),
        "frontier": [a for a in agg if a["frontier"]],
        "csv": str(out / "accuracy.csv"),
        "chart": str(out / "accuracy.png"),
        "effects_cost": effects_cost,
        # planar's analytic solve is the reference: the ratio is the rebuild's worst error at the defaults
        "ratio": default["max_error"],
    }


#: the least total wall time (s) a timing's repeats fill before their best is taken
MIN_TIMING_S = 0.25


def _effects_cost(repeats: int = 3, fraction: float = 1.0) -> dict[str, float]:
    """Seconds per simulated second of one four-bar leg with different effects named.

    Each variant simulates the first ``fraction`` of one cycle (at least two
    samples), best of ``repeats`` runs or of as many as fill :data:`MIN_TIMING_S`.

    ``none``: no [effects]; ``unused``: an [effects] table naming every effect
    switched off (the same space is built, so it costs the same); then gravity
    and damping.
    """
    from planar.physics.simulate import simulate
    from planar.scene.load import build_scene, parse_scene

    base = {
        "mechanism": {"type": "fourbar", "ground": 4.0, "crank": 1.0, "coupler": 4.0, "rocker": 3.0, "coupler_point": [2.0, 1.0]},
        "driver": {"samples_per_cycle": 360},
    }
    variants: dict[str, dict[str, Any] | None] = {
        "none": None,
        "unused": {"springs": [], "loads": []},
        "gravity": {"gravity": [0.0, -9.81]},
        "damping": {"damping": 0.5},
    }
    out = {}
    for name, eff in variants.items():
        data = dict(base)
        if eff is not None:
            data["effects"] = eff
        sc = build_scene(parse_scene(data))
        t_all = _times(sc.motion())
        t = t_all[: max(2, round(fraction * t_all.size))]
        span = float(t[-1] - t[0])
        # best of ``repeats`` runs, and of more while they total under MIN_TIMING_S (cheap variants
        # take milliseconds: a best of three would be noise)
        times: list[float] = []
        while len(times) < repeats or (sum(times) < MIN_TIMING_S and len(times) < 1000):
            times.append(simulate(sc.mechanism, t, sc.effects).wall_time)
        best = min(times)
        out[name] = best / span
    return out


def _accuracy_chart(path, agg: list[dict[str, Any]]) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from planar.fileio import atomic_write

    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(10.4, 4.4), dpi=100)
    t = np.array([a["seconds_per_sim_second"] for a in agg])
    e = np.array([a["max_error"] for a in agg])
    tq = np.array([a["torque_error"] for a in agg])
    f = np.array([a["frontier"] for a in agg])
    order = np.argsort(t[f])
    dflt = [i for i, a in enumerate(agg) if a["default"]]
    for axis, y, label, line in (
        (ax, e, "worst position error / size (kinematic and motor mode)", 1e-4),
        (ax2, tq, "worst motor torque error / peak", 1e-2),
    ):
        bad = ~np.isfinite(y)
        y = np.where(bad, 1.0, y)
        axis.scatter(t[~f & ~bad], y[~f & ~bad], s=14, c="#9a9a9a", label="setting")
        if bad.any():
            axis.scatter(t[bad], y[bad], s=18, marker="x", c="#9a9a9a", label="failed somewhere (drawn at 1)")
        axis.plot(t[f][order], y[f][order], "-o", c="#4e79a7", ms=4, label="Pareto frontier (positions)")
        adapt = np.array([a.get("step_drift") is not None and not a["default"] for a in agg])
        if adapt.any():
            axis.scatter(t[adapt], y[adapt], s=30, marker="^", c="#59a14f", label="adaptive substeps")
        if dflt:
            i = dflt[0]
            axis.scatter([t[i]], [y[i]], s=80, facecolors="none", edgecolors="#e15759", linewidths=2, label="default")
        prev = [i for i, a in enumerate(agg) if a.get("previous_default")]
        if prev:
            i = prev[0]
            axis.scatter(
                [t[i]],
                [y[i]],
                s=80,
                marker="s",
                facecolors="none",
                edgecolors="#b07aa1",
                linewidths=2,
                label="defaults before issue 12",
            )
        axis.axhline(line, ls=":", c="#e15759", lw=1)
        axis.set_xscale("log")
        axis.set_yscale("log")
        from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

        axis.xaxis.set_major_locator(LogLocator(subs=(1.0, 2.0, 5.0)))
        axis.xaxis.set_minor_formatter(NullFormatter())  # minor labels overlap on less than two decades
        axis.xaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
        axis.set_xlabel("wall seconds per simulated second (all gallery mechanisms)")
        axis.set_ylabel(label)
        axis.legend(loc="upper right", fontsize=8)
    ax.set_title("pymunk rebuild vs analytic motion")
    ax2.set_title("motor torque vs inverse dynamics")
    fig.tight_layout()
    with atomic_write(path, "wb") as fh:
        fig.savefig(fh, format="png", metadata={"Software": None})
    plt.close(fig)


def format_accuracy(r: dict[str, Any]) -> str:
    lines = [
        f"pymunk rebuild vs analytic, {len(r['mechanisms'])} mechanisms x {r['settings']} settings ({r['machine']})",
        "  frontier (substeps/iterations/correction; N+ = at least N, raised for the step drift):",
        f"  {'setting':<28}{'worst err':>10}{'torque':>10}{'s/sim s':>10}",
    ]
    for a in sorted(r["frontier"], key=lambda a: a["seconds_per_sim_second"]):
        mark = "  <- default" if a["default"] else ""
        lines.append(
            f"  {a['setting']:<28}{a['max_error']:>10.2e}{a['torque_error']:>10.2e}{a['seconds_per_sim_second']:>10.3f}{mark}"
        )
    d = r["default"]
    lines.append(
        f"  default ({d['setting']}): worst error {d['max_error']:.2e} (kinematic {d['kinematic_error']:.2e}, "
        f"motor {d['motor_error']:.2e}), torque {d['torque_error']:.2e}, "
        f"{d['seconds_per_sim_second']:.3f} s per simulated second, "
        f"{'on' if r['default_on_frontier'] else 'NOT on'} the frontier"
    )
    p = r.get("previous_default")
    if p is not None:
        lines.append(
            f"  defaults before issue 12 ({p['setting']}): worst error {p['max_error']:.2e}, torque "
            f"{p['torque_error']:.2e}, {p['seconds_per_sim_second']:.3f} s per simulated second "
            f"(defaults / before = {d['seconds_per_sim_second'] / p['seconds_per_sim_second']:.2f})"
        )

    def num(x: float) -> str:
        return "-" if math.isnan(x) else f"{x:.2e}"  # "-": no steady motor (a rocking driver, staged toys)

    for k, v in sorted(r["default_errors"].items()):
        lines.append(
            f"    {k:<22} substeps {v['substeps']:>3}  kinematic {num(v['kinematic']):>8}  "
            f"motor {num(v['motor']):>8}  torque {num(v['torque']):>8}"
        )
    for k, v in r["skipped"].items():
        lines.append(f"  skipped {k}: {v}")
    ec = r["effects_cost"]
    lines.append(
        "  effects cost (four-bar leg, s per simulated second): "
        + ", ".join(f"{k} {v:.4f}" for k, v in ec.items())
        + f"; unused/none = {ec['unused'] / ec['none']:.2f}"
    )
    lines.append(f"  wrote {r['csv']} and {r['chart']}")
    return "\n".join(lines)


BENCHMARKS["accuracy"] = (bench_accuracy, format_accuracy)


# --------------------------------------------------------------------------- sim


def _bare_space(mech, t, settings):
    """The same pymunk space planar builds (bodies, joints, pins), placed at the first sample, and its step count."""
    from planar.physics.simulate import _analytic_pose_velocity, _Rebuild, substeps_for

    poses, vel, analytic = _analytic_pose_velocity(mech, t)
    sub = substeps_for(mech, poses, vel, float(t[1] - t[0]), settings)
    dt = float(t[1] - t[0]) / sub
    rb = _Rebuild(mech, analytic, None, settings, "kinematic", dt)
    comp = rb.compensation()
    if comp:
        rb = _Rebuild(mech, analytic, None, settings, "kinematic", dt, overrides=comp)
    rb.set_state({k: v[0] for k, v in poses.items()}, {k: v[0] for k, v in vel.items()})
    drv = rb.bodies[mech.driver.part]
    drv.angular_velocity = mech.driver.rate * dt  # one time unit per step, as planar runs it
    return rb.space, (t.size - 1) * sub


def bench_sim(n: int = 360, repeats: int = 7) -> dict[str, Any]:
    """Wall time per physics step: planar's ``simulate`` against a bare pymunk loop on the same space.

    For the four-bar leg and the Jansen leg, ``n`` samples of one cycle at
    the default settings: planar's run (driver, pose recording, failure
    checks in blocks) and a bare ``space.step`` loop over the same bodies
    and joints (the driver turned by a constant angular velocity), timed
    alternately ``repeats`` times.  ``ratio`` is the median of the per-repeat
    ratios planar / bare (worst mechanism), with their spread.
    """
    from planar.linkages import FourBar
    from planar.physics.simulate import DEFAULT_SETTINGS, simulate
    from planar.scene.catalog import get

    st = DEFAULT_SETTINGS
    mechs = {"four-bar": FourBar(4.0, 1.0, 4.0, 3.0, coupler_point=(2.0, 1.0)), "jansen": get("jansen")}
    out: dict[str, Any] = {
        "benchmark": "sim",
        "samples": n,
        "substeps": st.substeps,
        "repeats": repeats,
        "machine": _machine(),
        "mechanisms": {},
    }
    for name, mech in mechs.items():
        t = mech.driver.times(n)
        ratios, ours, bare = [], [], []
        for _ in range(repeats):
            r = simulate(mech, t, None, st)
            per_ours = r.wall_time / r.steps
            space, steps = _bare_space(mech, t, st)
            step = space.step
            t0 = time.perf_counter()
            for _ in range(steps):
                step(1.0)
            per_bare = (time.perf_counter() - t0) / steps
            ours.append(per_ours)
            bare.append(per_bare)
            ratios.append(per_ours / per_bare)
        out["mechanisms"][name] = {
            "planar_us_per_step": float(np.median(ours)) * 1e6,
            "bare_pymunk_us_per_step": float(np.median(bare)) * 1e6,
            "ratio": float(np.median(ratios)),
            "ratio_spread": [float(min(ratios)), float(max(ratios))],
            "steps": int(r.steps),
            "substeps": int(r.built["substeps"]),
            "iterations": int(r.built["iterations"]),
        }
    worst = max(out["mechanisms"].values(), key=lambda m: m["ratio"])
    out["ratio"] = worst["ratio"]
    out["ratio_spread"] = worst["ratio_spread"]
    return out


def format_sim(r: dict[str, Any]) -> str:
    head = (
        f"physics step cost, planar vs bare pymunk on the same space ({r['samples']} samples x "
        f"{r['substeps']} substeps, {r['repeats']} interleaved repeats; {r['machine']})"
    )
    lines = [head]
    for name, m in r["mechanisms"].items():
        lines.append(
            f"  {name:<10} planar {m['planar_us_per_step']:8.2f} us/step   bare {m['bare_pymunk_us_per_step']:8.2f}"
            f" us/step   ratio {m['ratio']:.2f} (spread {m['ratio_spread'][0]:.2f}-{m['ratio_spread'][1]:.2f})"
        )
    lines.append(f"  ratio (worst mechanism, median): {r['ratio']:.2f}")
    return "\n".join(lines)


BENCHMARKS["sim"] = (bench_sim, format_sim)


# --------------------------------------------------------------------------- synthesis


def _bench_synthesis(**kw: Any) -> dict[str, Any]:
    from planar.bench.synthesis import bench_synthesis

    return bench_synthesis(**kw)


def _format_synthesis(r: dict[str, Any]) -> str:
    from planar.bench.synthesis import format_synthesis

    return format_synthesis(r)


BENCHMARKS["synthesis"] = (_bench_synthesis, _format_synthesis)
