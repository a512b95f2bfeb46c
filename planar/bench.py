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
from typing import Any, Callable

import numpy as np

from .errors import PlanarError

__all__ = ["bench_kinematics", "BENCHMARKS"]

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
        raise PlanarError(
            "planar bench kinematics needs the peer library pylinkage: pip install 'planar[bench]'"
        ) from e
    from .linkages.dyads import RRR, Crank, Fixed, Rigid

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
            c = pl.Crank(anchor=comps[nd.centre], radius=nd.radius, angular_velocity=step,
                         initial_angle=nd.phase, name=nd.name)
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
    from .catalog import get
    from .linkages.chunked import threads_default

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
    motion = mech.solve(q_peer)
    diff_points = max(float(np.max(np.abs(motion.points[p] - traj[:, names.index(nd)])))
                      for p, nd in mech.point_nodes.items())

    _pylinkage_of(mech, step).step_fast(iterations=16)  # numba compile (cached) outside the timing
    mech.solve(q[:m])
    planar_rates: list[float] = []
    peer_rates: list[float] = []
    valid = True
    for r in range(repeats):
        peer = _pylinkage_of(mech, step)

        def run_planar() -> None:
            nonlocal valid
            t0 = time.perf_counter()
            mo = mech.solve(q)
            planar_rates.append(n / (time.perf_counter() - t0))
            valid = valid and bool(mo.valid.all())

        def run_peer(peer: Any = peer) -> None:
            t0 = time.perf_counter()
            peer.step_fast(iterations=n)
            peer_rates.append(n / (time.perf_counter() - t0))

        for fn in ((run_planar, run_peer) if r % 2 == 0 else (run_peer, run_planar)):
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
        "max_abs_diff_vs_peer": diff,
        "max_abs_diff_points_vs_peer": diff_points,
        "size": float(mech.size),
        "all_valid": valid,
        "agrees": diff <= AGREEMENT and diff_points <= AGREEMENT and valid,
        "threads": threads_default(),
    }


def bench_kinematics(n: int = 1_000_000, repeats: int = 5) -> dict[str, Any]:
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
    the smaller of the two linkages' ratios.
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
    lines = [(f"public solve vs {r['peer']}, {r['n']:,} crank angles, median (min-max) of {r['repeats']} "
              f"interleaved repeats, {r['cores']} cores")]
    for c in r["cases"]:
        p, q, k = c["planar_samples_per_s"], c["peer_samples_per_s"], c["ratio_per_repeat"]
        lines += [
            f"  {c['linkage']} ({c['nodes']} nodes, {c['parts']} parts)",
            (f"    planar solve ({c['threads']} threads) {p['median'] / 1e6:8.2f} M samples/s "
             f"({p['min'] / 1e6:.2f}-{p['max'] / 1e6:.2f})"),
            (f"    pylinkage step_fast        {q['median'] / 1e6:8.2f} M samples/s "
             f"({q['min'] / 1e6:.2f}-{q['max'] / 1e6:.2f})"),
            f"    ratio                      {c['ratio']:8.2f}  (per repeat {k['min']:.2f}-{k['max']:.2f})",
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

    from .geometry import poses_apply
    from .render import PART_COLORS, _rings

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
            patch.set_xy(rings[n][i])
        return list(patches.values())

    anim = FuncAnimation(fig, update, frames=len(motion), blit=False)
    anim.save(path, writer=PillowWriter(fps=1000.0 / delay_ms))
    plt.close(fig)


def bench_render(n: int = 120, repeats: int = 5, width: int = 480, height: int = 360) -> dict[str, Any]:
    """Frames per second and GIF size: planar's renderer vs matplotlib's animation writer.

    Both draw the same four-bar (parts as filled outlines, coupler trail) at
    the same size and frame count into a GIF; the best of ``repeats`` runs
    each, end to end (drawing, palette, encoding, file).
    """
    import tempfile

    from exporters.gif import frame_delay_ms, indexer, write_gif

    from .catalog import get
    from .render import Renderer, Style, palette_colors

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
    return "\n".join([
        f"four-bar GIF, {r['frames']} frames at {r['size_px'][0]}x{r['size_px'][1]}",
        f"  planar        {r['planar_fps']:8.1f} frames/s   {r['planar_gif_bytes']:>9,} bytes",
        f"  matplotlib    {r['peer_fps']:8.1f} frames/s   {r['peer_gif_bytes']:>9,} bytes",
        f"  ratio planar/matplotlib  {r['ratio']:.2f} (frames/s), size {r['size_ratio']:.2f}",
    ])


BENCHMARKS["render"] = (bench_render, format_render)


# --------------------------------------------------------------------------- accuracy

ACCURACY_GRID = {
    "substeps": (4, 8, 16, 32, 48, 64, 96),
    "iterations": (5, 10, 20, 40),
    "error_bias": (1e-3, 1e-6, 1e-9),
}


def _pareto(points: list[tuple[float, float]]) -> list[bool]:
    """Which (time, error) points no other point beats in both (ties count as not beaten)."""
    out = []
    for i, (t, e) in enumerate(points):
        beaten = any((t2 <= t and e2 <= e and (t2 < t or e2 < e)) for j, (t2, e2) in enumerate(points) if j != i)
        out.append(not beaten)
    return out


def bench_accuracy(out_dir: str = "planar-bench-accuracy", quick: bool = False, repeats: int = 2,
                   progress: bool = True) -> dict[str, Any]:
    """Simulation error against the analytic motion vs wall time, over the settings that trade them.

    For every gallery scene pymunk can rebuild, every combination of
    substeps per frame (i.e. the time step), solver iterations and error bias
    runs one full cycle; the error is the largest distance between simulated
    and analytic part points over the cycle, as a fraction of the mechanism's
    size; the cost is wall seconds per simulated second (best of
    ``repeats``).  Settings are ranked on the aggregate (worst error over the
    mechanisms, total time); the Pareto frontier is marked.  Writes
    ``accuracy.csv`` and ``accuracy.png`` in ``out_dir``.
    """
    import csv
    import sys
    from pathlib import Path

    from .cli import gallery_scenes
    from .compare import compare
    from .scene import load_scene
    from .simulate import DEFAULT_SETTINGS, SimSettings, SimulationError, simulate

    grid = ACCURACY_GRID
    if quick:
        grid = {"substeps": (8, 48), "iterations": (10, 20), "error_bias": (1e-6, 1e-9)}
    settings = [SimSettings(substeps=s, iterations=i, error_bias=b)
                for s in grid["substeps"] for i in grid["iterations"] for b in grid["error_bias"]]
    d = DEFAULT_SETTINGS
    if all((x.substeps, x.iterations, x.error_bias) != (d.substeps, d.iterations, d.error_bias) for x in settings):
        settings.append(d)
    scenes = []
    skipped = {}
    for path in gallery_scenes():
        sc = load_scene(path)
        try:
            simulate(sc.mechanism, sc.motion().t[:3], sc.spec.effects, SimSettings(substeps=1))
        except SimulationError as e:
            skipped[sc.name] = str(e)
            continue
        scenes.append(sc)
    if quick:
        scenes = scenes[:3]
    rows = []
    total = len(scenes) * len(settings)
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=total, desc="accuracy", unit="run", disable=not sys.stderr.isatty(), leave=False)
    for sc in scenes:
        ref = sc.motion()
        sim_seconds = float(ref.t[-1] - ref.t[0])
        for st in settings:
            best = math.inf
            err = math.nan
            for _ in range(repeats):
                r = simulate(sc.mechanism, ref.t, sc.spec.effects, st)
                best = min(best, r.wall_time)
                err = compare(sc.mechanism, ref, r.motion).max_rel_error if r.blowup is None else math.inf
            rows.append({"mechanism": sc.name, "substeps": st.substeps, "iterations": st.iterations,
                         "error_bias": st.error_bias, "dt_s": sim_seconds / (len(ref) - 1) / st.substeps,
                         "error": err, "seconds_per_sim_second": best / sim_seconds})
            if bar is not None:
                bar.update()
    if bar is not None:
        bar.close()
    # aggregate per setting
    agg = []
    for st in settings:
        rs = [r for r in rows if (r["substeps"], r["iterations"], r["error_bias"]) ==
              (st.substeps, st.iterations, st.error_bias)]
        agg.append({"substeps": st.substeps, "iterations": st.iterations, "error_bias": st.error_bias,
                    "max_error": max(r["error"] for r in rs),
                    "seconds_per_sim_second": sum(r["seconds_per_sim_second"] for r in rs)})
    front = _pareto([(a["seconds_per_sim_second"], a["max_error"]) for a in agg])
    for a, f in zip(agg, front):
        a["frontier"] = f
        a["default"] = (a["substeps"], a["iterations"], a["error_bias"]) == (d.substeps, d.iterations, d.error_bias)
    for sc_name in {r["mechanism"] for r in rows}:
        rs = [r for r in rows if r["mechanism"] == sc_name]
        for r, f in zip(rs, _pareto([(r["seconds_per_sim_second"], r["error"]) for r in rs])):
            r["frontier"] = f
    default = next(a for a in agg if a["default"])
    effects_cost = _effects_cost(repeats=max(3, repeats))
    per_mech_default = {r["mechanism"]: r["error"] for r in rows
                        if (r["substeps"], r["iterations"], r["error_bias"]) == (d.substeps, d.iterations, d.error_bias)}
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    from .fileio import atomic_write

    with atomic_write(out / "accuracy.csv", "w") as fh:
        w = csv.DictWriter(fh, fieldnames=["mechanism", "substeps", "iterations", "error_bias", "dt_s", "error",
                                           "seconds_per_sim_second", "frontier"])
        w.writeheader()
        for r in rows:
            w.writerow(r)
        for a in agg:
            w.writerow({"mechanism": "ALL (worst error, total time)", "substeps": a["substeps"],
                        "iterations": a["iterations"], "error_bias": a["error_bias"], "dt_s": "",
                        "error": a["max_error"], "seconds_per_sim_second": a["seconds_per_sim_second"],
                        "frontier": a["frontier"]})
    _accuracy_chart(out / "accuracy.png", agg)
    return {
        "benchmark": "accuracy",
        "mechanisms": [s.name for s in scenes],
        "skipped": skipped,
        "settings": len(settings),
        "default": default,
        "default_on_frontier": bool(default["frontier"]),
        "default_errors": per_mech_default,
        "frontier": [a for a in agg if a["frontier"]],
        "csv": str(out / "accuracy.csv"),
        "chart": str(out / "accuracy.png"),
        "effects_cost": effects_cost,
        # planar's analytic solve is the reference: the ratio is the rebuild's worst error at the defaults
        "ratio": default["max_error"],
    }


def _effects_cost(repeats: int = 3) -> dict[str, float]:
    """Seconds per simulated second of one four-bar leg with different effects named.

    ``none``: no [effects]; ``unused``: an [effects] table naming every effect
    switched off (the same space is built, so it costs the same); then gravity,
    and contact shapes with friction, which do cost.
    """
    from .scene import build_scene, parse_scene
    from .simulate import simulate

    base = {"mechanism": {"type": "fourbar", "ground": 4.0, "crank": 1.0, "coupler": 4.0, "rocker": 3.0,
                          "coupler_point": [2.0, 1.0]}, "driver": {"samples_per_cycle": 36}}
    variants = {
        "none": None,
        "unused": {"contact": False, "springs": [], "loads": []},
        "gravity": {"gravity": [0.0, -9.81]},
        "contact+friction": {"contact": True, "friction": 0.6},
    }
    out = {}
    for name, eff in variants.items():
        data = dict(base)
        if eff is not None:
            data["effects"] = eff
        sc = build_scene(parse_scene(data))
        ref = sc.motion()
        span = float(ref.t[-1] - ref.t[0])
        best = min(simulate(sc.mechanism, ref.t, sc.spec.effects).wall_time for _ in range(repeats))
        out[name] = best / span
    return out


def _accuracy_chart(path, agg: list[dict[str, Any]]) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from .fileio import atomic_write

    fig, ax = plt.subplots(figsize=(6.4, 4.4), dpi=100)
    t = np.array([a["seconds_per_sim_second"] for a in agg])
    e = np.array([a["max_error"] for a in agg])
    f = np.array([a["frontier"] for a in agg])
    ax.scatter(t[~f], e[~f], s=14, c="#9a9a9a", label="setting")
    order = np.argsort(t[f])
    ax.plot(t[f][order], e[f][order], "-o", c="#4e79a7", ms=4, label="Pareto frontier")
    dflt = [i for i, a in enumerate(agg) if a["default"]]
    if dflt:
        i = dflt[0]
        ax.scatter([t[i]], [e[i]], s=80, facecolors="none", edgecolors="#e15759", linewidths=2, label="default")
    ax.axhline(1e-3, ls=":", c="#e15759", lw=1)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("wall seconds per simulated second (all gallery mechanisms)")
    ax.set_ylabel("worst position error / mechanism size")
    ax.set_title("pymunk rebuild vs analytic motion")
    ax.legend(loc="upper right", fontsize=8)
    fig.tight_layout()
    with atomic_write(path, "wb") as fh:
        fig.savefig(fh, format="png", metadata={"Software": None})
    plt.close(fig)


def format_accuracy(r: dict[str, Any]) -> str:
    lines = [f"pymunk rebuild vs analytic, {len(r['mechanisms'])} mechanisms x {r['settings']} settings",
             f"  {'substeps':>8}{'iters':>7}{'err bias':>10}{'worst err':>12}{'s/sim s':>10}"]
    for a in sorted(r["frontier"], key=lambda a: a["seconds_per_sim_second"]):
        mark = "  <- default" if a["default"] else ""
        lines.append(f"  {a['substeps']:>8}{a['iterations']:>7}{a['error_bias']:>10.0e}{a['max_error']:>12.2e}"
                     f"{a['seconds_per_sim_second']:>10.3f}{mark}")
    d = r["default"]
    lines.append(f"  default ({d['substeps']} substeps, {d['iterations']} iterations, error bias {d['error_bias']:g}): "
                 f"worst error {d['max_error']:.2e}, {d['seconds_per_sim_second']:.3f} s per simulated second, "
                 f"{'on' if r['default_on_frontier'] else 'NOT on'} the frontier")
    for k, v in sorted(r["default_errors"].items()):
        lines.append(f"    {k:<22} {v:.2e}")
    for k, v in r["skipped"].items():
        lines.append(f"  skipped {k}: {v}")
    ec = r["effects_cost"]
    lines.append("  effects cost (four-bar leg, s per simulated second): " +
                 ", ".join(f"{k} {v:.4f}" for k, v in ec.items()) +
                 f"; unused/none = {ec['unused'] / ec['none']:.2f}")
    lines.append(f"  wrote {r['csv']} and {r['chart']}")
    return "\n".join(lines)


BENCHMARKS["accuracy"] = (bench_accuracy, format_accuracy)
