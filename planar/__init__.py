"""planar: 2D rigid-body mechanisms with exact (closed-form) kinematics.

The working set a user needs is here, under one name each::

    import planar

    leg = planar.FourBar(ground=4, crank=1, coupler=4, rocker=3, coupler_point=(5.5, -2.0))
    motion = leg.solve([0.0, 0.5, 1.0])      # a planar.Motion
    planar.render(leg, "leg.gif")            # a mechanism or a planar.Scene
    scene = planar.load_scene("gallery/kangaroo-leg.toml")
    planar.export(scene, dxf="leg.dxf")

``import planar`` is light: the errors only.  Every other name is loaded on
first use (module ``__getattr__``), so numpy comes in when a model name is
first read, and shapely, pymunk, ezdxf and imageio only with the modules that
use them.  So the ``planar`` command holds nothing heavy until its interrupt
handling is in place (a Ctrl-C while numpy loads is one line, not a traceback).
"""

from __future__ import annotations

import importlib
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

from planar.errors import AssemblyError, CheckError, InputError, LimitError, PlanarError, SceneError

if TYPE_CHECKING:  # pragma: no cover
    from planar.core.model import Driver, Mechanism, Motion, Part, PinInSlot, Pivot, Slide, joint_residuals
    from planar.fabrication.build import Fabrication
    from planar.linkages import RRP, RRR, Actuator, Crank, Fixed, FourBar, Link, Linkage, Rigid, SliderCrank, Triad
    from planar.physics.compare import Comparison
    from planar.physics.simulate import SimResult, SimSettings, simulate
    from planar.scene.load import Scene, load_scene, scene_from_mechanism

__all__ = [
    "RRP",
    "RRR",
    "Actuator",
    "AssemblyError",
    "CheckError",
    "Crank",
    "Driver",
    "Fixed",
    "FourBar",
    "InputError",
    "LimitError",
    "Link",
    "Linkage",
    "Mechanism",
    "Motion",
    "Part",
    "PinInSlot",
    "Pivot",
    "PlanarError",
    "Rigid",
    "Scene",
    "SceneError",
    "SimSettings",
    "Slide",
    "SliderCrank",
    "Triad",
    "compare",
    "export",
    "joint_residuals",
    "load_scene",
    "render",
    "scene_from_mechanism",
    "simulate",
]
__version__ = "0.1.0"

#: name -> the module that defines it, imported on first use
_LAZY: dict[str, str] = {
    **dict.fromkeys(
        ("Driver", "Mechanism", "Motion", "Part", "PinInSlot", "Pivot", "Slide", "joint_residuals"),
        "planar.core.model",
    ),
    **dict.fromkeys(
        ("FourBar", "SliderCrank", "Linkage", "Link", "Fixed", "Crank", "Actuator", "RRR", "RRP", "Rigid", "Triad"),
        "planar.linkages",
    ),
    **dict.fromkeys(("Scene", "load_scene", "scene_from_mechanism"), "planar.scene.load"),
    **dict.fromkeys(("SimSettings", "simulate"), "planar.physics.simulate"),
}


def _load_display() -> None:
    """Import the drawing side, which registers the renderers of :mod:`planar.core.display`."""
    importlib.import_module("planar.draw.notebook")


if "IPython" in sys.modules:  # a notebook: mechanisms and motions display as tables and players
    import planar.draw.notebook  # (light: registers renderers (planar.core.display); numpy loads on first display)
else:  # plain Python: core loads the drawing side the first time it needs a renderer (animate, _repr_html_)
    import planar.core.display

    planar.core.display.set_loader(_load_display)


def __getattr__(name: str) -> Any:
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module 'planar' has no attribute {name!r}")
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value  # later reads skip this function
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))


def _scene(obj: Scene | Mechanism, tables: dict[str, Any]) -> Scene:
    """``obj`` as a scene: a :class:`Scene` as it is, a :class:`Mechanism` through :func:`scene_from_mechanism`."""
    from planar.core.model import Mechanism
    from planar.scene.load import Scene, scene_from_mechanism

    if not isinstance(obj, (Scene, Mechanism)):
        raise InputError("obj", obj, "a Scene (planar.load_scene) or a Mechanism")
    if isinstance(obj, Scene):
        if tables:
            raise InputError(", ".join(sorted(tables)), "given with a Scene", "scene tables only with a Mechanism")
        return obj
    return scene_from_mechanism(obj, **tables)


def render(obj: Scene | Mechanism, out: str | Path, *, progress: bool = False, fps: float | None = None, **tables: Any) -> int:
    """Render a scene or a mechanism to an animation file, as ``planar render`` does; returns the frame count.

    Parameters
    ----------
    obj : Scene or Mechanism
        A loaded scene (:func:`load_scene`) or a mechanism built in Python.
    out : str or Path
        ``.gif`` (reproducible bytes), or ``.mp4``/``.webm`` with the ``video`` extra.
    progress : bool
        Show a progress bar on a terminal.
    fps : float, optional
        Frames per second (default: the scene's ``[render] fps``).
    **tables
        For a mechanism only: scene tables as dicts (``driver``, ``render``,
        ``effects``, ``fabrication``, ``name``), e.g. ``render={"width": 320}``.

    Returns
    -------
    int
        The number of frames written.
    """
    from planar.app.pipeline import render_scene

    if not isinstance(out, (str, Path)):
        raise InputError("out", out, "a file name (str or Path) ending in .gif, .mp4 or .webm")
    if fps is not None and (isinstance(fps, bool) or not isinstance(fps, (int, float))):
        raise InputError("fps", fps, "a number of frames per second")
    try:
        return render_scene(_scene(obj, tables), out, progress=progress, fps=fps)
    except InputError as e:  # the Python argument's name, not the command-line option's
        python_name = {"-o": "out", "--fps": "fps"}.get(e.field)
        if python_name is None or type(e) is not InputError:
            raise
        raise InputError(python_name, e.value, e.expected) from None


def export(
    obj: Scene | Mechanism,
    dxf: str | Path | None = None,
    svg: str | Path | None = None,
    *,
    fabrication: dict[str, Any] | None = None,
    unit_mm: float | None = None,
    check: bool = True,
    **files: Any,
) -> Fabrication:
    """Lay a scene's or a mechanism's parts out for cutting and write the files, as ``planar export`` does.

    Parameters
    ----------
    obj : Scene or Mechanism
        A loaded scene or a mechanism built in Python.
    dxf, svg : str or Path, optional
        The cut sheet as DXF (layers CUT, ENGRAVE, ...) and as SVG, in millimetres.
    fabrication : dict, optional
        For a mechanism only: ``[fabrication]`` keys (``unit_mm``, ``kerf_mm``,
        ``sheet_mm``, ...); a scene carries its own.
    unit_mm : float, optional
        Millimetres per model unit, overriding the scene's ``[fabrication] unit_mm`` (and a ``fabrication``
        dict's), as ``planar export --unit-mm``: positive, the largest part at least ``min_part_mm`` across and
        fitting the sheet's diagonal.
    check : bool
        True (default): when the build check fails (``violations`` not empty), raise
        :class:`planar.errors.CheckError` after the files are written, as ``planar export`` writes them and
        exits 3; its ``result`` is the :class:`Fabrication`, its message names the problems and the smallest
        ``unit_mm`` found at which the same scene builds.  False: return the :class:`Fabrication` whatever
        the check found (read its ``violations``).
    **files
        ``preview`` (.png), ``bom`` (.csv), ``assembly`` (.svg), ``kerf_test``
        (.dxf or .svg), ``plan`` (.json), ``motion`` (.csv), ``steps`` (.svg)
        (paths) and the ``kerf`` (mm) and ``sheet`` ((width, height) mm)
        overrides.  ``steps`` names the assembly steps' pages, one per layer:
        ``steps="st.svg"`` writes ``st-1.svg``, ``st-2.svg``, ... beside it and
        no ``st.svg``.  Each path must end in its format's suffix, and at least
        one output must be given (as ``planar export`` refuses none): for the
        layout alone, use :func:`planar.fabrication.build.build`.

    Returns
    -------
    Fabrication
        The parts, their placement on the sheet and the files written (``written``); every
        file goes to a temporary and is renamed only when all succeeded.  ``violations``: what the
        build check found (empty: every part, pin, spacer and the motor shaft clear through the cycle).

    Raises
    ------
    planar.errors.CheckError
        The build check failed (and ``check`` is true); the files are written.
    """
    from planar.app.export import check_lines, scene_with_unit
    from planar.app.pipeline import EXPORT_FILES, check_export_outputs, export_scene
    from planar.errors import CheckError

    unknown = sorted(set(files) - set(EXPORT_FILES) - {"kerf", "sheet"})
    if unknown:
        raise InputError(", ".join(unknown), files[unknown[0]], f"one of the outputs {', '.join(EXPORT_FILES)}, kerf or sheet")
    if not isinstance(check, bool):
        raise InputError("check", check, "True or False")
    check_export_outputs(dxf, svg, files)  # before the scene is built
    scene = _scene(obj, {} if fabrication is None else {"fabrication": fabrication})
    sheet = files.get("sheet")
    if sheet is not None:  # checked by the export, naming it; the unit's bounds use it when it is two numbers
        try:
            sheet = (float(sheet[0]), float(sheet[1]))
        except (TypeError, ValueError, IndexError, KeyError):
            sheet = None
    scene = scene_with_unit(scene, unit_mm, "unit_mm", sheet)
    fab = export_scene(scene, dxf, svg, **files)
    if check and fab.violations:
        lines = check_lines(scene, fab, option="unit_mm=")
        raise CheckError(
            f"build check failed: {len(fab.violations)} problem(s), the files are written: " + "; ".join(lines),
            fab,
            tuple(lines),
        )
    return fab


def compare(
    obj: Scene | Mechanism,
    *,
    settings: SimSettings | None = None,
    threshold: float = 1e-3,
    torque_threshold: float = 0.01,
    motor: bool | None = None,
    **tables: Any,
) -> tuple[Comparison, SimResult]:
    """Rebuild a scene or a mechanism in pymunk, run it, and compare it with the analytic motion.

    As ``planar compare`` does: per-part pose errors and per-joint drift as a
    fraction of :attr:`Mechanism.size`, and, when the scene names a motor
    (``[effects] motor = true`` or ``motor_force_limit``) or ``motor`` is true,
    the motor torque against inverse dynamics.

    Parameters
    ----------
    obj : Scene or Mechanism
        A loaded scene or a mechanism built in Python.
    settings : SimSettings, optional
        Time step, substeps and solver iterations (default: planar's defaults).
    threshold : float
        Largest pose error accepted, as a fraction of the size (the simulation
        stops at the first part further off).
    torque_threshold : float
        Largest motor-torque difference accepted, relative to the peak.
    motor : bool, optional
        True: also drive with a motor and check its torque (as ``--motor``); False: never;
        None (default): when the scene's ``[effects]`` names a motor.
    **tables
        For a mechanism only: scene tables as dicts (``driver``, ``effects``...).

    Returns
    -------
    (Comparison, SimResult)
        ``comparison.passed`` is false when a check failed (the CLI exits 3).
    """
    import math

    from planar.physics.compare import compare_scene
    from planar.physics.settings import SimSettings

    if settings is not None and not isinstance(settings, SimSettings):
        raise InputError("settings", settings, "a planar.SimSettings (or None for the defaults)")
    for arg, v in (("threshold", threshold), ("torque_threshold", torque_threshold)):
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not (math.isfinite(v) and v > 0):
            raise InputError(arg, v, "a positive, finite fraction")
    return compare_scene(_scene(obj, tables), settings, threshold, torque_threshold, motor=motor)
