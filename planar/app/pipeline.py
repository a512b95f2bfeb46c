"""What the CLI, the benchmarks and the tests run: a scene in, files and records out.

Each function takes a built :class:`planar.scene.load.Scene` (or a folder given
explicitly) and returns what it made; printing is the caller's business.
Heavy libraries (imageio, pymunk, ezdxf, shapely) are imported inside the
functions that need them, so ``import planar.app.pipeline`` stays light.
"""

from __future__ import annotations

import contextlib
import math
import os
from collections.abc import Callable, Iterator, Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

from planar.core import limits as _limits
from planar.errors import InputError, LimitError


def _check_scene(field: str, scene: object) -> None:
    """:class:`InputError` unless ``scene`` is a :class:`~planar.scene.build.Scene` (``load_scene``'s)."""
    from planar.core.fields import check_kind
    from planar.scene.build import Scene as SceneKind

    check_kind(field, scene, SceneKind, "a Scene (planar.load_scene, or scene_from_mechanism)")


def _check_path(field: str, path: object) -> None:
    if not isinstance(path, (str, os.PathLike)):
        raise InputError(field, path, "a file name (a string or a pathlib.Path)")


def _check_flag(field: str, value: object) -> None:
    if not isinstance(value, bool):
        raise InputError(field, value, "True or False")


if TYPE_CHECKING:
    from planar.core.model import Mechanism, Motion
    from planar.draw.frames import Style
    from planar.draw.timing import FramePlan
    from planar.fabrication.build import Fabrication
    from planar.physics.compare import Comparison
    from planar.physics.simulate import SimResult, SimSettings
    from planar.scene.load import Scene

__all__ = [
    "DEMO_EXTRAS",
    "DEMO_SCENES",
    "build_gallery",
    "compare_scene",
    "export_mechanism",
    "export_scene",
    "gallery_scenes",
    "overlay_motion",
    "plot_mechanism",
    "render_mechanism",
    "render_scene",
    "run_demo",
    "scene_style",
    "write_catalog_motion",
    "write_mechanism_motion",
    "write_scene_motion",
]


# --------------------------------------------------------------------------- scenes of a folder


def gallery_scenes(folder: str | os.PathLike[str]) -> list[Path]:
    """The scene files (``*.toml``) directly in ``folder``, sorted by name.

    The folder is always given by the caller (``planar gallery --source``,
    ``planar bench accuracy --scenes``): nothing is looked up beside the
    code.  Raises :class:`InputError` if ``folder`` is not a directory or holds
    no scene file.
    """
    if not isinstance(folder, (str, os.PathLike)):
        raise InputError("scenes folder", folder, "a folder name (a string or a pathlib.Path)")
    p = Path(folder)
    if not p.is_dir():
        raise InputError("scenes folder", str(p), "an existing folder of .toml scene files")
    scenes = sorted(p.glob("*.toml"))
    if not scenes:
        raise InputError("scenes folder", str(p), "a folder with .toml scene files (it has none)")
    return scenes


# --------------------------------------------------------------------------- render

#: the longest frame delay a GIF can hold (65535 hundredths of a second)
GIF_MAX_DELAY_MS = 655_350.0

#: the largest sheet side (mm) the fabrication geometry is computed for
MAX_SHEET_MM = _limits.MAX_SHEET_MM


def scene_style(scene: Scene) -> Style:
    """The renderer's :class:`~planar.draw.frames.Style` from a scene's ``[render]`` table."""
    from planar.draw.frames import Style

    r = scene.spec.render
    return Style(
        width=r.width,
        height=r.height,
        supersample=r.supersample,
        background=r.background,
        trails=r.trails,
        show_pins=r.show_pins,
        opacity=r.opacity,
        exploded=r.exploded,
    )


def overlay_motion(scene: Scene, settings: SimSettings | None = None, notes: list[str] | None = None) -> Motion:
    """The pymunk rebuild's motion of ``scene``, for drawing over the analytic one.

    Where the simulation stops holding its analytic motion, the overlay stays
    at the last pose it reached (drawn frozen from there on) and a note naming
    that sample, its time and why is added to ``notes``.  ``settings``: the
    solver settings, as ``planar compare`` takes them.
    """
    from planar.physics.simulate import DEFAULT_SETTINGS, simulate_scene

    sim = simulate_scene(scene, settings or DEFAULT_SETTINGS, mode="kinematic")
    if sim.failure is not None and notes is not None:
        f = sim.failure
        notes.append(
            f"the simulation holds up to sample {f.sample} (t = {f.time:.6g} s) and is drawn frozen from there: {f.message}"
        )
    return sim.motion


#: output suffixes ``render_scene`` writes
ANIMATION_SUFFIXES = (".gif", ".mp4", ".webm", ".html")


def animation_plan(scene: Scene, out: str | Path, fps: float | None = None, fps_option: str = "fps") -> FramePlan:
    """The frames ``render_scene`` draws for ``out`` (GIF delays are whole 10 ms ticks; video any rate);
    ``fps_option`` names ``fps`` in messages (``--fps`` for the command line)."""
    from planar.draw.timing import plan_frames, scene_duration

    fps = fps if fps is not None else scene.spec.render.fps
    try:
        return plan_frames(
            scene.mechanism.driver.period,
            scene_duration(scene),
            fps,
            tick_ms=10.0 if Path(out).suffix.lower() == ".gif" else None,
            fps_option=fps_option,
        )
    except InputError as e:  # the planner names "duration_s" or "period_s": say which key of which scene
        d = scene.spec.driver
        if e.field == "duration_s" or isinstance(e, LimitError):  # too many frames: the cycles (or duration) ask them
            key, value = (
                ("driver.duration", d.duration)
                if d.duration is not None
                else ("driver.cycles", d.cycles if d.cycles is not None else 1.0)
            )
            raise type(e)(f"{scene.path}: {key}", value, e.expected) from None
        if e.field == "period_s":
            raise InputError(f"{scene.path}: driver.speed", d.speed, "a finite, positive speed (cycles per second)") from None
        raise


def render_scene(
    scene: Scene,
    out: str | Path,
    overlay: Motion | None = None,
    progress: bool = True,
    fps: float | None = None,
    notes: list[str] | None = None,
    options: tuple[str, str] = ("out", "fps"),
) -> int:
    """Render a scene's analytic motion (and optionally an overlay motion) to ``out``; returns the frame count.

    The format follows the suffix: ``.gif`` (streamed, reproducible), ``.mp4``
    or ``.webm`` (the ``video`` extra).  Frames are resampled so that a cycle
    plays for what the scene's ``speed`` says, within one frame delay
    (:func:`planar.draw.timing.plan_frames`); ``fps`` (or the scene's
    ``[render] fps``) sets the frame rate.  The overlay, a simulated motion
    with sample times, is interpolated to the frame instants.  ``notes``, if
    given, receives what a user should hear: a cycle that plays slower than
    its speed, samples that cannot be assembled (drawn tinted red).  ``options`` names ``out`` and ``fps``
    in messages (``("-o", "--fps")`` for the command line).
    """
    import numpy as np

    from planar.draw.frames import Renderer, palette_colors
    from planar.draw.timing import animation_motion, resample
    from planar.errors import InputError

    if not (isinstance(options, tuple) and len(options) == 2 and all(isinstance(o, str) for o in options)):
        raise InputError("options", options, "two strings naming out and fps in messages, e.g. ('-o', '--fps')")
    _check_scene("scene", scene)
    _check_path(options[0], out)
    _check_flag("progress", progress)
    from planar.core.model import Motion as MotionKind

    if overlay is not None and not isinstance(overlay, MotionKind):
        raise InputError("overlay", overlay, "a Motion with sample times (a simulated run), or None")
    if fps is not None:
        from planar.core.fields import check_number

        check_number(options[1], fps)
    suffix = Path(out).suffix.lower()
    if suffix not in ANIMATION_SUFFIXES:
        raise InputError(options[0], str(out), f"an animation file ending in {', '.join(ANIMATION_SUFFIXES)}")
    if suffix not in (".gif", ".html"):
        from planar.app.formats import writer

        video_available = writer("mp4").video_available

        if not video_available():
            raise InputError(
                options[0],
                str(out),
                f"the video extra for {suffix} output: pip install 'planar[video]' (imageio-ffmpeg), or write a .gif",
            )

    from planar.core.limits import check_count

    # bounds before any frame is planned or drawn: the scene's samples (and memory), then the frames
    scene.sample_count()
    field_name = "driver.duration" if scene.spec.driver.duration is not None else "driver.cycles"
    shown = getattr(scene.spec.driver, field_name.split(".")[1])
    shown = 1.0 if shown is None else shown  # one cycle unless the scene says
    plan = animation_plan(scene, out, fps, options[1])
    check_count("frames", f"{scene.path}: {field_name}", plan.frames, "frames", shown=shown)
    check_count(
        "samples",
        f"{scene.path}: {field_name}",
        plan.frames * max(1, math.ceil(scene.spec.driver.samples_per_cycle / plan.frames_per_cycle)),
        "samples to draw from",
        shown=shown,
    )
    if suffix == ".gif" and plan.delay_ms > GIF_MAX_DELAY_MS:
        raise InputError(
            f"{scene.path}: driver.speed",
            scene.spec.driver.speed,
            f"a frame delay a GIF can hold (at most {GIF_MAX_DELAY_MS / 1000:g} s; this needs "
            f"{plan.delay_ms / 1000:.4g} s): a higher speed or frame rate",
        )
    motion, fine = animation_motion(scene, plan)
    if notes is not None:
        if plan.note():
            notes.append(plan.note())
        bad = ~fine.valid
        if bad.any():
            notes.append(
                f"{int(bad.sum())} of the {len(fine)} samples drawn from cannot be assembled and are drawn "
                f"tinted red; first: {fine.reason(int(bad.argmax()), scene.spec.angle_unit)}"
            )
    if overlay is not None:
        overlay = resample(overlay, plan.times())
    if suffix == ".html":
        from planar.app.formats import writer
        from planar.draw.player import player_html

        with numeric_guard(scene, "the animation"):
            page = player_html(scene.mechanism, motion, fine, scene_style(scene), frame_ms=plan.delay_ms)
        writer("html").write_html(out, page)
        return len(motion)
    polys = {n: scene.polygons[n] for n in scene.spec.render.sweep}
    with numeric_guard(scene, "the animation"):
        targets = np.asarray(scene.spec.render.targets, float).reshape(-1, 2)
        r = Renderer(
            scene.mechanism, motion, scene_style(scene), overlay=overlay, polygons=polys, trail_motion=fine, targets=targets
        )
        if suffix == ".gif":
            from planar.app.formats import writer

            gif = writer("gif")
            indexer, write_gif = gif.indexer, gif.write_gif

            pal = palette_colors(r.style, len(scene.mechanism.parts))
            return write_gif(out, r.frames(progress=progress, post=indexer(pal)), int(plan.delay_ms), pal)
        from planar.app.formats import writer

        write_video = writer("mp4").write_video

        return write_video(out, r.frames(progress=progress), plan.fps)


def build_gallery(
    source: str | Path, output: str | Path | None = None, progress: bool = False
) -> Iterator[tuple[Path, Path, int]]:
    """Render every scene of the folder ``source`` to ``output`` (default: beside the scenes).

    Yields ``(scene file, GIF written, frames)`` as each GIF is finished.
    """
    from planar.scene.load import load_scene

    scenes = gallery_scenes(source)
    out = Path(output) if output is not None else Path(source)
    if out.exists() and not out.is_dir():
        raise InputError("gallery output", str(out), "a folder (it is an existing file)")
    loaded = [load_scene(path) for path in scenes]  # every scene checked before the first GIF is drawn
    out.mkdir(parents=True, exist_ok=True)
    for path, scene in zip(scenes, loaded):
        target = out / (path.stem + ".gif")
        yield path, target, render_scene(scene, target, progress=progress)


# --------------------------------------------------------------------------- motion tables


@contextlib.contextmanager
def numeric_guard(scene: Scene, doing: str) -> Iterator[None]:
    """Turn a numerical library's failure on a scene of extreme sizes (shapely's GEOS, a singular matrix in
    matplotlib, an overflow) into one line naming the scene, its size and what was being done."""
    import numpy as np

    from planar.errors import PlanarError

    try:
        yield
    except PlanarError:
        raise
    except (np.linalg.LinAlgError, OverflowError, FloatingPointError, ValueError) as e:
        if type(e).__module__.startswith("planar"):
            raise
        raise InputError(
            f"{scene.path}: mechanism",
            f"parts up to {scene.mechanism.size:.4g} units across",
            f"numbers (sizes, loads, densities) at which {doing} can be computed ({type(e).__name__}: "
            f"{' '.join(str(e).split())})",
        ) from None
    except Exception as e:
        if type(e).__name__ != "GEOSException":
            raise
        raise InputError(
            f"{scene.path}: mechanism",
            f"parts up to {scene.mechanism.size:.4g} units across",
            f"numbers (sizes, loads, densities) at which {doing} can be computed (shapely: {' '.join(str(e).split())})",
        ) from None


def write_scene_motion(scene: Scene, out: str | Path, derivatives: bool = False, notes: list[str] | None = None) -> Motion:
    """Write the scene's analytic motion table (CSV) to ``out``; returns the motion.

    ``notes``: where to add what the table is, when not the obvious (see :func:`table_motion`).

    ``derivatives``: add the rates of :func:`planar.analysis.rates.derivative_columns`
    (point velocities and accelerations, part omega and alpha, transmission
    angles, motor torque under the scene's ``[effects]``) before ``valid``.
    Nothing is written if they cannot be computed.
    """
    from planar.fileio import write_motion_csv

    _check_scene("scene", scene)
    _check_path("out", out)
    _check_flag("derivatives", derivatives)
    if Path(out).suffix.lower() != ".csv":
        raise InputError("out", str(out), "a .csv file (the motion table is CSV)")
    mech, motion = table_motion(scene.mechanism, scene.motion(), notes=notes)
    if not derivatives:
        write_motion_csv(out, mech, motion)
        return motion
    from planar.analysis.rates import derivative_columns

    with numeric_guard(scene, "the rates and motor torque"):  # rates per sample: streamed a chunk at a time
        write_motion_csv(out, mech, motion, extra=lambda sub: derivative_columns(mech, sub, scene.effects))
    return motion


def write_catalog_motion(name: str, out: str | Path, samples: int = 360) -> Motion:
    """Write one cycle (``samples`` samples) of the built-in mechanism ``name`` to ``out`` (CSV)."""
    from planar.fileio import write_motion_csv
    from planar.scene.catalog import get

    mech, motion = table_motion(get(name), None, samples, notes=[])
    write_motion_csv(out, mech, motion)
    return motion


def table_motion(
    mech: Mechanism, motion: Motion | None, samples: int = 360, notes: list[str] | None = None
) -> tuple[Mechanism, Motion]:
    """The mechanism and motion a motion table reports: ``mech`` and ``motion`` (or one cycle of
    ``samples`` samples), except for a wind-up toy, whose table is its assembly in the toy's frame
    (:class:`planar.toys.assembly.ToyAssembly`: every piece in its own plane, a Ty effector moving
    along y) rather than the stages' panels the toy's own motion lays side by side.  A toy the
    assembly cannot build keeps its stages' panels (each stage in its own frame, side by side), and a
    note saying so and why is added to ``notes``."""
    if motion is None:
        motion = mech.run(samples_per_cycle=samples)
    import sys

    chain = sys.modules.get("planar.windup.chain")  # not imported: ``mech`` is no toy
    if chain is None or not isinstance(mech, chain.ToyMechanism):
        return mech, motion
    from planar.toys.assembly import toy_assembly

    try:
        asm = toy_assembly(mech)
    except InputError as e:
        if notes is not None:
            notes.append(
                f"{mech.name} cannot be assembled ({e}); the table has its stages' panels instead: "
                "each stage in its own frame, side by side, not the toy's frame"
            )
        return mech, motion
    return asm, asm.solve(motion.driver, t=motion.t)


# --------------------------------------------------------------------------- fabrication


#: the files :func:`export_scene` writes besides ``dxf`` and ``svg`` (keyword arguments)
EXPORT_FILES = ("preview", "bom", "assembly", "kerf_test", "plan", "motion", "steps")


def check_export_outputs(dxf: object, svg: object, files: Mapping[str, Any]) -> None:
    """:class:`InputError` unless an export names an output (``dxf``, ``svg`` or one of :data:`EXPORT_FILES` in
    ``files``): with none, the whole export would run and write nothing (``planar export`` refuses it too)."""
    if dxf is None and svg is None and not any(files.get(k) is not None for k in EXPORT_FILES):
        raise InputError(
            "dxf, svg, ...",
            None,
            f"an output: dxf, svg or one of {', '.join(EXPORT_FILES)} (for the layout alone, planar.fabrication.build.build)",
        )


def export_scene(
    scene: Scene,
    dxf: str | Path | None = None,
    svg: str | Path | None = None,
    kerf: float | None = None,
    sheet: tuple[float, float] | None = None,
    preview: str | Path | None = None,
    bom: str | Path | None = None,
    assembly: str | Path | None = None,
    kerf_test: str | Path | None = None,
    plan: str | Path | None = None,
    motion: str | Path | None = None,
    steps: str | Path | None = None,
) -> Fabrication:
    """Check, layer and nest a scene's parts and write the requested files (see :mod:`planar.app.export`).

    ``kerf`` (mm) and ``sheet`` (width, height in mm) default to the scene's
    ``[fabrication]`` table.  ``steps`` names the assembly steps' pages, one
    per layer: ``steps="st.svg"`` writes ``st-1.svg``, ``st-2.svg``, ... and
    no ``st.svg``.  Every file is written to a temporary and renamed only
    when all succeeded.
    """
    from planar.app.export import write_outputs
    from planar.core.fields import check_number, check_point
    from planar.fabrication.build import build
    from planar.fabrication.parts import FabSettings
    from planar.fileio import check_outputs

    _check_scene("scene", scene)
    if kerf is not None:
        check_number("kerf", kerf)
    if sheet is not None:
        sheet = check_point("sheet", sheet, "a sheet (width, height) in mm: two finite numbers")
    outputs = (
        ("dxf", dxf, (".dxf",)),
        ("svg", svg, (".svg",)),
        ("preview", preview, (".png",)),
        ("bom", bom, (".csv",)),
        ("assembly", assembly, (".svg",)),
        ("kerf_test", kerf_test, (".dxf", ".svg")),
        ("plan", plan, (".json",)),
        ("motion", motion, (".csv",)),
        ("steps", steps, (".svg",)),
    )
    check_export_outputs(dxf, svg, {arg: path for arg, path, _ in outputs[2:]})
    # the suffix names the format (DXF bytes never go into x.svg), and two outputs never name one file
    check_outputs(outputs, (scene.path,) if Path(str(scene.path)).is_file() else ())
    spec = scene.spec.fabrication
    w, h = sheet if sheet is not None else spec.sheet_mm
    where = "--sheet" if sheet is not None else f"{scene.path}: fabrication.sheet_mm"
    if not all(math.isfinite(v) and 0 < v <= MAX_SHEET_MM for v in (w, h)):
        raise InputError(where, f"{w:g} x {h:g}", f"a sheet of finite, positive sides up to {MAX_SHEET_MM:g} mm")
    across = scene.mechanism.size * spec.unit_mm  # the largest part's diameter, mm
    if not across <= math.hypot(w, h):
        raise InputError(
            f"{scene.path}: fabrication.unit_mm",
            spec.unit_mm,
            f"parts that fit the {w:g} x {h:g} mm sheet (the largest part is {across:.4g} mm across; "
            "a smaller unit_mm or a larger sheet)",
        )
    if not across >= spec.min_part_mm:  # 1e-300 mm per unit: refused for the unit, not for a pin hole in a speck
        raise InputError(
            f"{scene.path}: fabrication.unit_mm",
            spec.unit_mm,
            f"a unit whose largest part is at least min_part_mm = {spec.min_part_mm:g} mm across (it is "
            f"{across:.4g} mm; a larger unit_mm)",
        )
    fab = build(scene, FabSettings.from_spec(spec, kerf, sheet))
    fab.written = write_outputs(fab, dxf, svg, preview, bom, assembly, kerf_test, plan=plan, motion=motion, steps=steps)
    return fab


# --------------------------------------------------------------------------- physics comparison


def compare_scene(
    scene: Scene,
    settings: SimSettings | None = None,
    threshold: float = 1e-3,
    torque_threshold: float = 0.01,
    with_series: bool = False,
    motor: bool | None = None,
    time_cap: float | None = None,
) -> tuple[Comparison, SimResult]:
    """Simulate ``scene`` in pymunk and compare it with its analytic motion (and the motor torque).

    See :func:`planar.physics.compare.compare_scene`; ``result.passed`` is false when
    a check fails (the CLI then exits with :data:`planar.physics.compare.EXIT_MISMATCH`).
    """
    from planar.physics.compare import compare_scene as _compare_scene

    _check_scene("scene", scene)
    return _compare_scene(scene, settings, threshold, torque_threshold, with_series, motor, time_cap)


# --------------------------------------------------------------------------- mechanisms built in Python


def render_mechanism(mech: Mechanism, out: str | Path, progress: bool = False, **tables: Any) -> int:
    """Render a mechanism built in Python to a GIF, as ``planar render`` would its scene; returns frames.

    ``tables`` as for :func:`scene_from_mechanism`, e.g. ``driver={"samples_per_cycle": 48}``,
    ``render={"width": 320, "trails": ["coupler_point"]}``.
    """
    from planar.scene.load import scene_from_mechanism

    return render_scene(scene_from_mechanism(mech, **tables), out, progress=progress)


def export_mechanism(
    mech: Mechanism,
    dxf: str | Path | None = None,
    svg: str | Path | None = None,
    fabrication: dict[str, Any] | None = None,
    **files: Any,
) -> Fabrication:
    """Lay out a mechanism built in Python for cutting, as ``planar export`` would its scene.

    ``fabrication``: ``[fabrication]`` keys (``unit_mm``, ``kerf_mm``, ...);
    ``files``: the other outputs of :func:`export_scene` (``preview``, ``bom``,
    ``assembly``, ``kerf_test``) and its ``kerf``/``sheet`` overrides.
    """
    from planar.scene.load import scene_from_mechanism

    check_export_outputs(dxf, svg, files)  # before the scene is built
    return export_scene(scene_from_mechanism(mech, fabrication=fabrication), dxf, svg, **files)


def write_mechanism_motion(mech: Mechanism, out: str | Path, derivatives: bool = False, **tables: Any) -> Motion:
    """The motion table (CSV) of a mechanism built in Python, as ``planar motion [--derivatives]`` writes it.

    The mechanism's own name is in no column, so one a scene file could not hold (a comma, a double quote,
    more than 80 characters; ``FourBar(name="a,b")``) is accepted: the scene behind the table gets it
    without them, unless ``tables`` names the scene (``name=...``).  Column names holding a comma are
    quoted (:func:`planar.fileio.write_motion_csv`).
    """
    from planar.core.model import Mechanism
    from planar.scene.load import scene_from_mechanism

    if "name" not in tables and isinstance(mech, Mechanism):
        safe = mech.name.replace(",", " ").replace('"', "'")[:80]
        if safe != mech.name:
            tables = {**tables, "name": safe}
    return write_scene_motion(scene_from_mechanism(mech, **tables), out, derivatives=derivatives)


def plot_mechanism(mech: Mechanism, out: str | Path, what: list[str] | str | None = None, **tables: Any) -> list[str]:
    """The charts of a mechanism built in Python (PNG or SVG), as ``planar plot`` draws them.

    ``what``: a chart name (``"curve"``) or a list of them; all that apply when ``None``.
    """
    from planar.draw.charts import write_plot
    from planar.scene.load import scene_from_mechanism

    return write_plot(scene_from_mechanism(mech, **tables), out, what)


# --------------------------------------------------------------------------- the demo


#: the embedded default: a wind-up toy and a four-bar walking leg
DEMO_SCENES: dict[str, dict] = {
    "horse": {
        "name": "horse",
        "angle_unit": "deg",
        "mechanism": {
            "type": "toy",
            "left": [["Rz->OzT", "OzT->Oz"]],
            "right": [["Rz->OzT", "OzT->Ty"], ["Rz->OzT", "OzT->Oz"]],
            "phase": 180,
        },
        "driver": {"speed": 0.5, "samples_per_cycle": 48},
        "render": {"width": 480, "height": 360},
        "fabrication": {"unit_mm": 100.0, "sheet_mm": [400.0, 300.0]},  # one frame spans every pivot
    },
    "kangaroo-leg": {
        "name": "kangaroo-leg",
        "mechanism": {
            "type": "fourbar",
            "ground": 4.0,
            "crank": 1.0,
            "coupler": 4.0,
            "rocker": 3.0,
            "coupler_point": [5.5, -2.0],
            "polygons": [{"name": "foot", "part": "coupler", "points": [[5.1, -2.25], [6.6, -2.25], [6.6, -1.95], [5.1, -1.95]]}],
        },
        "driver": {"speed": 1.0, "samples_per_cycle": 48},
        "effects": {"loads": [{"point": "coupler_point", "force": [0.0, 10.0]}]},
        "render": {"width": 480, "height": 360, "sweep": ["foot"]},
        "fabrication": {"unit_mm": 15.0},
    },
}

#: later features append writers here ``(scene, output dir)`` so the demo grows with the package
DEMO_EXTRAS: list[Callable[..., None]] = []


def run_demo(output: str | Path) -> Iterator[str]:
    """Animate, tabulate and cut the embedded demo scenes into ``output``; yields one line per scene."""
    import numpy as np

    from planar.analysis import statics as analysis
    from planar.fileio import check_output
    from planar.linkages import Linkage
    from planar.scene.load import build_scene, parse_scene

    _check_path("output", output)
    check_output("output", output, (), directory=True)
    out = Path(output)
    out.mkdir(parents=True, exist_ok=True)
    for name, data in DEMO_SCENES.items():
        scene = build_scene(parse_scene(data, f"<demo {name}>"), f"<demo {name}>")
        gif = out / f"{name}.gif"
        n = render_scene(scene, gif)
        csv = out / f"{name}.csv"
        motion = write_scene_motion(scene, csv)
        line = f"{name}: {n} frames, all valid: {bool(motion.valid.all())} -> {gif}, {csv}"
        if name == "kangaroo-leg" and isinstance(scene.mechanism, Linkage):
            loads = {ld.point: np.array(ld.force) for ld in scene.spec.effects.loads}
            tau, _ = analysis.motor_torque(scene.mechanism, motion.driver, loads)
            line += f"; peak motor torque {np.abs(tau).max():.3f} (force x unit) for a 10 N foot push"
        dxf = out / f"{name}.dxf"
        fab = export_scene(scene, dxf=dxf)
        rings = sum(pp.spacers for pp in fab.assembly.pins)
        line += (
            f"; {len(fab.layout.parts) - rings} parts{f' + {rings} spacer rings' if rings else ''} on "
            f"{fab.layout.sheets} sheet(s) -> {', '.join(map(str, fab.written))}"
        )
        yield line
        for extra in DEMO_EXTRAS:
            extra(scene, out)
