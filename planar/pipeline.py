"""What the CLI, the benchmarks and the tests run: a scene in, files and records out.

Each function takes a built :class:`planar.scene.Scene` (or a folder given
explicitly) and returns what it made; printing is the caller's business.
Heavy libraries (imageio, pymunk, ezdxf, shapely) are imported inside the
functions that need them, so ``import planar.pipeline`` stays light.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import TYPE_CHECKING

from .errors import InputError

if TYPE_CHECKING:
    from .compare import Comparison
    from .fabexport import Fabrication
    from .model import Motion
    from .render import Style
    from .scene import Scene
    from .simulate import SimResult, SimSettings

__all__ = [
    "DEMO_EXTRAS", "DEMO_SCENES", "build_gallery", "compare_scene", "export_scene",
    "gallery_scenes", "overlay_motion", "render_scene", "run_demo", "scene_style", "write_catalog_motion",
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
MAX_SHEET_MM = 100_000.0


def scene_style(scene: Scene) -> Style:
    """The renderer's :class:`~planar.render.Style` from a scene's ``[render]`` table."""
    from .render import Style

    r = scene.spec.render
    return Style(width=r.width, height=r.height, supersample=r.supersample, background=r.background,
                 trails=r.trails, show_pins=r.show_pins)


def overlay_motion(scene: Scene) -> Motion:
    """The pymunk rebuild's motion of ``scene``, for drawing over the analytic one.

    Raises :class:`~planar.simulate.SimulationError` if the simulation blew up.
    """
    from .simulate import SimulationError, simulate_scene

    sim = simulate_scene(scene)
    if sim.blowup is not None:
        raise SimulationError(f"{scene.path}: the simulation {sim.motion.reason(sim.blowup[0])}; "
                              "no animation written (try more substeps: planar compare --substeps)")
    return sim.motion


def render_scene(scene: Scene, out: str | Path, overlay: Motion | None = None, progress: bool = True) -> int:
    """Render a scene's analytic motion (and optionally an overlay motion) to a GIF; returns frames."""
    from exporters.gif import frame_delay_ms, indexer, write_gif

    from .limits import check_count
    from .render import Renderer, palette_colors

    field_name = "driver.duration" if scene.spec.driver.duration is not None else "driver.cycles"
    check_count("frames", f"{scene.path}: {field_name}", scene.sample_count(), "frames (one per sample)",
                shown=getattr(scene.spec.driver, field_name.split(".")[1]))
    spc = scene.spec.driver.samples_per_cycle
    if 1000.0 * scene.mechanism.driver.period / spc > GIF_MAX_DELAY_MS:
        raise InputError(f"{scene.path}: driver.speed", scene.spec.driver.speed,
                         f"a speed of at least {1000.0 / (GIF_MAX_DELAY_MS * spc):.3g} cycles per second at "
                         f"{spc} samples per cycle (a GIF frame lasts at most {GIF_MAX_DELAY_MS / 1000:g} s)")
    motion = scene.motion()
    polys = {n: scene.polygons[n] for n in scene.spec.render.sweep}
    from shapely.errors import GEOSException

    try:
        r = Renderer(scene.mechanism, motion, scene_style(scene), overlay=overlay, polygons=polys)
        pal = palette_colors(r.style, len(scene.mechanism.parts))
        delay = frame_delay_ms(scene.mechanism.driver.period, scene.spec.driver.samples_per_cycle)
        return write_gif(out, r.frames(progress=progress, post=indexer(pal)), delay, pal)
    except GEOSException as e:  # part outlines of extreme sizes (a coupler point at 1e305) defeat GEOS
        raise InputError(f"{scene.path}: mechanism", f"parts up to {scene.mechanism.size:.4g} units across",
                         f"part sizes the outline geometry can draw (shapely: {' '.join(str(e).split())})") from None


def build_gallery(source: str | Path, output: str | Path | None = None,
                  progress: bool = False) -> Iterator[tuple[Path, Path, int]]:
    """Render every scene of the folder ``source`` to ``output`` (default: beside the scenes).

    Yields ``(scene file, GIF written, frames)`` as each GIF is finished.
    """
    from .scene import load_scene

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


def write_scene_motion(scene: Scene, out: str | Path) -> Motion:
    """Write the scene's analytic motion table (CSV) to ``out``; returns the motion."""
    from .fileio import write_motion_csv

    motion = scene.motion()
    write_motion_csv(out, scene.mechanism, motion)
    return motion


def write_catalog_motion(name: str, out: str | Path, samples: int = 360) -> Motion:
    """Write one cycle (``samples`` samples) of the built-in mechanism ``name`` to ``out`` (CSV)."""
    from .catalog import get
    from .fileio import write_motion_csv

    mech = get(name)
    motion = mech.run(samples_per_cycle=samples)
    write_motion_csv(out, mech, motion)
    return motion


# --------------------------------------------------------------------------- fabrication


def export_scene(scene: Scene, dxf: str | Path | None = None, svg: str | Path | None = None,
                 kerf: float | None = None, sheet: tuple[float, float] | None = None,
                 preview: str | Path | None = None, bom: str | Path | None = None,
                 assembly: str | Path | None = None, kerf_test: str | Path | None = None) -> "Fabrication":
    """Check, layer and nest a scene's parts and write the requested files (see :mod:`planar.fabexport`).

    ``kerf`` (mm) and ``sheet`` (width, height in mm) default to the scene's
    ``[fabrication]`` table.  Every file is written to a temporary and
    renamed only when all succeeded.
    """
    from .fabexport import build, write_outputs
    from .fabparts import FabSettings

    spec = scene.spec.fabrication
    w, h = sheet if sheet is not None else spec.sheet_mm
    where = "--sheet" if sheet is not None else f"{scene.path}: fabrication.sheet_mm"
    if not all(math.isfinite(v) and 0 < v <= MAX_SHEET_MM for v in (w, h)):
        raise InputError(where, f"{w:g} x {h:g}", f"a sheet of finite, positive sides up to {MAX_SHEET_MM:g} mm")
    across = scene.mechanism.size * spec.unit_mm  # the largest part's diameter, mm
    if not across <= math.hypot(w, h):
        raise InputError(f"{scene.path}: fabrication.unit_mm", spec.unit_mm,
                         f"parts that fit the {w:g} x {h:g} mm sheet (the largest part is {across:.4g} mm across; "
                         "a smaller unit_mm or a larger sheet)")
    fab = build(scene, FabSettings.from_spec(spec, kerf, sheet))
    fab.written = write_outputs(fab, dxf, svg, preview, bom, assembly, kerf_test)
    return fab


# --------------------------------------------------------------------------- physics comparison


def compare_scene(scene: Scene, settings: SimSettings | None = None, threshold: float = 1e-3,
                  torque_threshold: float = 0.01, with_series: bool = False) -> tuple[Comparison, SimResult]:
    """Simulate ``scene`` in pymunk and compare it with its analytic motion (and the motor torque).

    See :func:`planar.compare.compare_scene`; ``result.passed`` is false when
    a check fails (the CLI then exits with :data:`planar.compare.EXIT_MISMATCH`).
    """
    from .compare import compare_scene as _compare_scene

    return _compare_scene(scene, settings, threshold, torque_threshold, with_series=with_series)


# --------------------------------------------------------------------------- the demo


#: the embedded default: a wind-up toy and a four-bar walking leg
DEMO_SCENES: dict[str, dict] = {
    "horse": {
        "name": "horse", "angle_unit": "deg",
        "mechanism": {"type": "toy", "left": [["Rz->OzT", "OzT->Oz"]],
                      "right": [["Rz->OzT", "OzT->Ty"], ["Rz->OzT", "OzT->Oz"]], "phase": 180},
        "driver": {"speed": 0.5, "samples_per_cycle": 48},
        "render": {"width": 480, "height": 360},
        "fabrication": {"unit_mm": 100.0},
    },
    "kangaroo-leg": {
        "name": "kangaroo-leg",
        "mechanism": {"type": "fourbar", "ground": 4.0, "crank": 1.0, "coupler": 4.0, "rocker": 3.0,
                      "coupler_point": [5.5, -2.0],
                      "polygons": [{"name": "foot", "part": "coupler",
                                    "points": [[5.1, -2.25], [6.6, -2.25], [6.6, -1.95], [5.1, -1.95]]}]},
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

    from . import analysis
    from .linkages import Linkage
    from .scene import build_scene, parse_scene

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
        line += f"; {len(fab.layout.parts)} parts -> {', '.join(map(str, fab.written))}"
        yield line
        for extra in DEMO_EXTRAS:
            extra(scene, out)
