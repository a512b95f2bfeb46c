"""The charts a designer looks at, drawn with matplotlib: path, transmission, speeds, accelerations, torque.

:func:`scene_figure` returns a :class:`matplotlib.figure.Figure` (built
without pyplot, on the Agg canvas, so nothing global changes and no display
is needed); :func:`write_plot` writes it as PNG or SVG with reproducible
bytes (no date, a fixed SVG id salt).  Every curve is the analytic motion of
:meth:`planar.scene.load.Scene.motion` and its exact rates
(:mod:`planar.analysis.rates`); nothing is differenced.

Charts (``what``):

* ``curve`` — the path of every named point (a coupler curve, a foot's
  stride), equal axes, the first sample marked;
* ``transmission`` — transmission angle of every RRR dyad (degrees) with the
  40-140 degree band designers aim for; only for linkages with dyads;
* ``velocity`` — angular velocity of every moving part (rad/s);
* ``speed`` — speed ``|v|`` of every named point (model units/s; a foot's);
* ``acceleration`` — angular acceleration of every moving part (rad/s^2);
* ``torque`` — the motor torque under the scene's ``[effects]`` (inverse
  dynamics) and the loads' share alone;
* ``follower`` — a cam's follower: displacement, velocity and acceleration
  against cam angle (the motion law's closed forms), one panel each;
* ``pressure`` — a cam's pressure angle, with its allowed maximum.

The horizontal axis is the crank angle (a cam's: cam angle) in degrees for a
turning input, else time in seconds.  Invalid samples (and toggles, where rates are undefined)
are gaps.
"""

from __future__ import annotations

import io
import math
import os
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from planar.errors import InputError

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from planar.core.model import Mechanism, Motion
    from planar.scene.load import Scene

__all__ = ["CHARTS", "available_charts", "scene_figure", "write_plot"]

#: every chart :func:`scene_figure` can draw, in drawing order
CHARTS = ("curve", "follower", "pressure", "transmission", "angle", "velocity", "speed", "acceleration", "torque")
#: the transmission angles designers keep to (degrees)
GOOD_TRANSMISSION = (40.0, 140.0)


def available_charts(scene: Scene) -> list[str]:
    """The charts that apply to ``scene`` (``transmission`` only where the mechanism has dyads)."""
    from planar.analysis.rates import transmission_angles
    from planar.core.fields import check_kind
    from planar.scene.build import Scene as SceneKind

    check_kind("available_charts(scene)", scene, SceneKind)

    out = ["curve"] if scene.mechanism.points else []
    if _is_cam(scene.mechanism):
        out += ["follower", "pressure"]
    if transmission_angles(scene.mechanism, scene.mechanism.driver.value(np.zeros(1))):
        out.append("transmission")
    out += ["angle", "velocity"]
    if scene.mechanism.points:
        out.append("speed")
    return out + ["acceleration", "torque"]


def _is_cam(mech: Mechanism) -> bool:
    from planar.cams.mechanism import CamMechanism

    return isinstance(mech, CamMechanism)


def _parse_what(scene: Scene, what: Sequence[str] | str | None, option: str = "what") -> list[str]:
    """The charts asked for (a name or a list of names; all that apply when ``None``); ``option`` names the
    argument in messages (``what`` from Python, ``--what`` on the command line)."""
    avail = available_charts(scene)
    if what is None:
        return avail
    if isinstance(what, str):  # one chart's name, not its letters
        what = [what]
    try:
        items = list(what)
    except TypeError:
        raise InputError(option, what, f"a chart name or a list of them, of {', '.join(avail)}") from None
    chosen = []
    for w in items:
        if not isinstance(w, str) or w not in CHARTS:
            raise InputError(option, w, f"one of {', '.join(CHARTS)}")
        if w not in avail:
            why = (
                "it has no named points"
                if w in ("curve", "speed")
                else "it is not a cam"
                if w in ("follower", "pressure")
                else "it has no RRR dyad"
            )
            raise InputError(option, w, f"a chart that applies to {scene.name!r} ({why}); it has {', '.join(avail)}")
        if w not in chosen:
            chosen.append(w)
    if not chosen:
        raise InputError(option, ",".join(items), f"at least one chart, of {', '.join(avail)}")
    return chosen


#: bytes a chart figure adds beyond its samples: matplotlib's import, the figure and its rendering (measured, see
#: :func:`_motion`)
FIGURE_BYTES = 128 * 2**20


def _motion(scene: Scene, samples_per_cycle: int | None, name: str = "samples_per_cycle") -> Motion:
    """The scene's motion, over its own cycles or duration, at ``samples_per_cycle`` (default: the scene's);
    ``name`` names it in messages (``--samples`` for the command line)."""
    if samples_per_cycle is not None and (
        isinstance(samples_per_cycle, bool) or not isinstance(samples_per_cycle, int) or samples_per_cycle < 4
    ):
        raise InputError(name, samples_per_cycle, "at least 4 samples per cycle")
    d = scene.spec.driver
    drv = scene.mechanism.driver
    if samples_per_cycle is None:
        n = scene.sample_count()  # the scene's own count, checked as its motion is
        spc: float = d.samples_per_cycle
        where, shown = f"{scene.path}: driver.samples_per_cycle", d.samples_per_cycle
    else:
        cycles = d.duration / drv.period if d.duration is not None else (d.cycles if d.cycles is not None else 1.0)
        from planar.core.limits import check_count

        total = samples_per_cycle * cycles  # bounded before anything is allocated (planar.core.limits)
        n = max(
            2,
            check_count(
                "samples",
                name,
                round(total) if math.isfinite(total) else total,
                f"samples in all ({name} x the scene's cycles)",
                shown=samples_per_cycle,
            ),
        )
        spc, where, shown = samples_per_cycle, name, samples_per_cycle
    from planar.core.limits import check_memory, resident_bytes, units_within

    # the motion and, over all of it at once, its rates, torque and lines: measured 1.5 kB a sample for the
    # Jansen leg (2 958 MiB at 2e6 samples), about twice what the motion alone is estimated at; what this
    # process holds already, and the figure's own drawing (matplotlib's import and Agg rendering: a Jansen plot of
    # 96,132 samples peaked at 342 MiB resident with 80 MiB held and 176 MiB estimated for its samples)
    per = 2 * 8.0 * 4 * (3 * len(scene.mechanism.parts) + 2 * len(scene.mechanism.points) + 4)
    held = resident_bytes() + FIGURE_BYTES
    check_memory(where, shown, held + per * n, "the charts' motion and rates", fits=f"{units_within(held, per):,} samples")
    if samples_per_cycle is None:
        return scene.motion()
    t = np.arange(n) * (drv.period / spc)
    return scene.mechanism.solve(drv.value(t), t=t)


def scene_figure(
    scene: Scene,
    what: Sequence[str] | str | None = None,
    width_in: float = 6.4,
    samples_per_cycle: int | None = None,
    samples_option: str = "samples_per_cycle",
) -> Figure:
    """The charts ``what`` (default: every chart that applies) of ``scene``, stacked in one figure.

    ``samples_per_cycle``: sample the motion this finely instead of the
    scene's ``[driver] samples_per_cycle`` (smoother curves); ``samples_option`` names it in messages.

    Each axes carries a ``gid`` naming its chart (``"chart-curve"``, ...), and
    each line a ``gid`` naming what it plots (``"curve:coupler_point"``,
    ``"omega:rocker"``, ``"torque"``), so tests and callers can find them.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from planar.analysis.rates import derivative_columns

    charts = _parse_what(scene, what)
    mech = scene.mechanism
    motion = _motion(scene, samples_per_cycle, samples_option)
    names, cols = derivative_columns(mech, motion, scene.effects)
    ok = cols[names.index("rates_valid")] == 1.0
    col = {n: c if n == "rates_valid" else np.where(ok, c, np.nan) for n, c in zip(names, cols)}  # gaps, not 0
    drv = mech.driver
    cam = _is_cam(mech)
    if drv.kind == "rotation" and drv.amplitude is None:
        x, xlabel, xunit = np.degrees(motion.driver), f"{'cam' if cam else 'crank'} angle (deg)", "°"
    else:
        assert motion.t is not None
        x, xlabel, xunit = motion.t, "time (s)", " s"
    good = col["rates_valid"] == 1.0
    moving = [p.name for p in mech.parts if not p.ground]

    panels = [(c, k) for c in charts for k in ((0, 1, 2) if c == "follower" else (0,))]
    fig = Figure(figsize=(width_in, 2.6 * len(panels) + 0.6), dpi=100, layout="constrained")
    FigureCanvasAgg(fig)
    title = scene.name
    fig.suptitle(f"{title}: {drv.rate / (2 * np.pi):g} cycles/s", fontsize=11)
    axes = fig.subplots(len(panels), 1, squeeze=False)[:, 0]
    for ax, (chart, k) in zip(axes, panels):
        if chart == "follower":
            _follower_panel(ax, mech, motion, x, k)
            ax.set_xlabel(xlabel)
            continue
        ax.set_gid(f"chart-{chart}")
        ax.grid(True, lw=0.4, alpha=0.5)
        if chart == "curve":
            _curve_panel(ax, scene, _curve_motion(scene, motion, samples_per_cycle))
        elif chart == "pressure":
            cm: Any = mech  # a CamMechanism (available_charts offers "pressure" only for one)
            prof = cm.profile
            deg = np.degrees(prof.pressure_angle(np.mod(motion.driver, 2 * np.pi)))
            (ln,) = ax.plot(x, deg, lw=1.4, label="pressure angle")
            ln.set_gid("pressure")
            limit = float(np.degrees(cm.max_pressure_angle))
            ax.axhline(limit, color="#d62728", lw=0.8, ls="--")
            ax.axhline(-limit, color="#d62728", lw=0.8, ls="--")
            k2 = int(np.nanargmax(np.abs(deg)))
            ax.set_title(f"pressure angle: largest {abs(deg[k2]):.1f}° at {x[k2]:.4g}{xunit} (allowed {limit:.0f}°)", fontsize=9)
            ax.set_ylabel("pressure angle (deg)")
        elif chart == "transmission":
            lo, hi = GOOD_TRANSMISSION
            ax.axhspan(lo, hi, color="#2ca02c", alpha=0.08, lw=0)
            for nm in [n for n in names if n.endswith(".transmission")]:
                deg = np.degrees(col[nm])
                (ln,) = ax.plot(x, deg, lw=1.4, label=nm.split(".")[0])
                ln.set_gid(f"transmission:{nm.split('.')[0]}")
                if np.isfinite(deg).any():  # mark the worst sample: the furthest from 90 degrees
                    k = int(np.nanargmax(np.abs(deg - 90.0)))
                    ax.annotate(f"{deg[k]:.0f}°", (x[k], deg[k]), fontsize=8, xytext=(3, 3), textcoords="offset points")
            ax.set_ylim(0, 180)
            ax.set_ylabel("transmission angle (deg)")
            ax.set_title(f"transmission angle at each dyad (band: {lo:g}-{hi:g}°)", fontsize=9)
        elif chart == "angle":
            _angle_panel(ax, motion, moving, x)
        elif chart == "speed":
            for pname in motion.points:
                sp = np.hypot(col[f"{pname}.vx"], col[f"{pname}.vy"])
                (ln,) = ax.plot(x, sp, lw=1.2, label=pname)
                ln.set_gid(f"speed:{pname}")
            ax.set_ylabel("speed (model units/s)")
            ax.set_ylim(bottom=0)
        elif chart in ("velocity", "acceleration"):
            key, unit = ("omega", "rad/s") if chart == "velocity" else ("alpha", "rad/s²")
            for p in moving:
                (ln,) = ax.plot(x, col[f"{p}.{key}"], lw=1.2, label=p)
                ln.set_gid(f"{key}:{p}")
            ax.set_ylabel(f"{'angular velocity' if key == 'omega' else 'angular acceleration'} ({unit})")
        else:
            (ln,) = ax.plot(x, col["torque"], lw=1.6, label="motor torque (all effects)")
            ln.set_gid("torque")
            (ln2,) = ax.plot(x, col["torque.loads"], lw=1.0, ls="--", label="loads alone")
            ln2.set_gid("torque.loads")
            ax.axhline(0.0, color="k", lw=0.5)
            ax.set_ylabel("torque (model force x length units)")
            if good.any():
                k = int(np.nanargmax(np.abs(col["torque"])))
                ax.set_title(f"motor torque: peak {abs(col['torque'][k]):.4g} at {x[k]:.4g}{xunit}", fontsize=9)
        if chart != "curve":
            ax.set_xlabel(xlabel)
        if len(ax.get_lines()) > 1 or chart == "curve":
            ax.legend(fontsize=7, loc="best", ncols=2 if len(ax.get_lines()) > 6 else 1)
    return fig


def _angle_panel(ax: Any, motion: Motion, moving: list[str], x: np.ndarray) -> None:
    """Every moving part's angle (degrees, counter-clockwise from the world's +x axis, unwrapped along the
    motion: a rocker's output against the crank's input, what a function generator is asked for)."""
    for p in moving:
        a = np.degrees(np.unwrap(np.asarray(motion.poses[p])[:, 2]))
        (ln,) = ax.plot(x, np.where(motion.valid, a, np.nan), lw=1.2, label=p)
        ln.set_gid(f"angle:{p}")
    ax.set_ylabel("angle from +x (deg)")
    ax.set_title("each moving part's angle (counter-clockwise from +x)", fontsize=9)


#: the colour of the targets on the coupler-curve chart (the animation's target dots are pink too)
TARGET_COLOUR = "#e75480"


def _curve_motion(scene: Scene, motion: Motion, samples_per_cycle: int | None) -> Motion:
    """The motion the curve chart draws: ``motion`` itself, or, when no ``samples_per_cycle`` was asked and a named
    point sweeps fast (:func:`planar.draw.timing.chord_ratio` over :data:`planar.draw.timing.CHORD_RATIO`), the
    motion re-solved with that many times the samples (at most
    :data:`planar.draw.timing.MAX_SAMPLES_PER_CYCLE` a cycle)."""
    from planar.draw.timing import CHORD_RATIO, MAX_SAMPLES_PER_CYCLE, chord_ratio

    if samples_per_cycle is not None:
        return motion
    ratio = chord_ratio(motion)
    spc = scene.spec.driver.samples_per_cycle
    if ratio <= CHORD_RATIO or spc >= MAX_SAMPLES_PER_CYCLE:
        return motion
    return _motion(scene, int(min(MAX_SAMPLES_PER_CYCLE, spc * np.ceil(ratio))))


def _curve_panel(ax: Any, scene: Scene, motion: Motion) -> None:
    """The path of every named point (world, model units), its first sample dotted, and the scene's
    ``[render] targets`` (the points a synthesis aimed at) as pink dots, numbered in their order."""
    closed_loop = scene.mechanism.driver.amplitude is None
    for pname, xy in motion.points.items():
        pts = np.where(motion.valid[:, None], xy, np.nan)
        closed = np.vstack([pts, pts[:1]]) if closed_loop else pts
        (ln,) = ax.plot(closed[:, 0], closed[:, 1], lw=1.4, label=pname)
        ln.set_gid(f"curve:{pname}")
        ax.plot(xy[:1, 0], xy[:1, 1], "o", ms=4, color=ln.get_color())
    targets = np.asarray(scene.spec.render.targets, float).reshape(-1, 2)
    what = "dot: first sample"
    if len(targets):
        (tl,) = ax.plot(
            targets[:, 0], targets[:, 1], "o", ms=4.5, mfc="none", mec=TARGET_COLOUR, mew=1.4, label=f"targets ({len(targets)})"
        )
        tl.set_gid("targets")
        if len(targets) <= 30:  # their order (a timed or ordered synthesis passes them in it)
            for k, (tx, ty) in enumerate(targets, start=1):
                ax.annotate(str(k), (tx, ty), fontsize=6, color=TARGET_COLOUR, xytext=(3, 3), textcoords="offset points")
        what += "; rings: the targets"
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x (model units)")
    ax.set_ylabel("y")
    ax.set_title(f"path of the named points ({what})", fontsize=9)


def _follower_panel(ax: Any, mech: Any, motion: Motion, x: np.ndarray, k: int) -> None:
    """Panel ``k`` (0 displacement, 1 velocity, 2 acceleration) of a cam's follower, from the motion law."""
    ax.set_gid(f"chart-follower-{('displacement', 'velocity', 'acceleration')[k]}")
    ax.grid(True, lw=0.4, alpha=0.5)
    fm = mech.follower_motion(motion.driver)
    osc = mech.profile.follower.motion == "oscillating"
    y = (fm["q"], fm["dq_dt"], fm["d2q_dt2"])[k]
    if osc:
        y = np.degrees(y)
    unit = ("deg", "deg/s", "deg/s²")[k] if osc else ("model units", "units/s", "units/s²")[k]
    name = ("displacement", "velocity", "acceleration")[k]
    (ln,) = ax.plot(x, y, lw=1.4, color=("#1f77b4", "#ff7f0e", "#2ca02c")[k], label=f"follower {name}")
    ln.set_gid(f"follower:{name}")
    ax.set_ylabel(f"{'arm angle' if osc and k == 0 else name} ({unit})")
    if k == 0:
        ax.set_title(f"follower ({'oscillating arm' if osc else 'translating'}): the cam's motion law", fontsize=9)


def _render(fig: Any, fmt: str) -> bytes:
    import matplotlib

    buf = io.BytesIO()
    meta: dict[str, Any] = {"Date": None} if fmt == "svg" else {"Software": None}
    with matplotlib.rc_context({"svg.hashsalt": "planar", "svg.fonttype": "none"}):
        fig.savefig(buf, format=fmt, metadata=meta)
    return buf.getvalue()


def write_plot(
    scene: Scene,
    out: str | os.PathLike[str],
    what: Sequence[str] | str | None = None,
    samples_per_cycle: int | None = None,
    option: str = "what",
    samples_option: str = "samples_per_cycle",
) -> list[str]:
    """Write the charts of ``scene`` to ``out`` (``.png`` or ``.svg``, reproducible bytes); returns the charts.

    ``what`` (a chart name or a list of them) and ``samples_per_cycle`` as for :func:`scene_figure`;
    ``option`` names ``what`` in messages (``--what`` for the command line), ``samples_option``
    ``samples_per_cycle`` (``--samples``).
    """
    from planar.fileio import atomic_write

    ext = os.path.splitext(str(out))[1].lower().lstrip(".")
    if ext not in ("png", "svg"):
        raise InputError("out", str(out), "a .png or .svg file name")
    charts = _parse_what(scene, what, option)
    fig = scene_figure(scene, charts, samples_per_cycle=samples_per_cycle, samples_option=samples_option)
    data = _render(fig, ext)
    with atomic_write(out, "wb") as fh:
        fh.write(data)
    return charts
