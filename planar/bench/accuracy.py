"""``planar bench accuracy``: simulation accuracy against cost over a grid of solver settings, on the scenes of a folder."""

from __future__ import annotations

import math
import os
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from planar.bench.timing import _machine
from planar.errors import PlanarError

if TYPE_CHECKING:
    from numpy.typing import NDArray

    from planar.core.model import Motion
    from planar.scene.load import Scene

    Array = NDArray[np.float64]


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
        from planar.core.progress import progress_bar

        bar = progress_bar(total, "accuracy", "run")
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
        (ax2, tq, "worst motor torque error / torque scale", 1e-2),
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
