"""What would make a scene build: the smallest ``unit_mm`` at which its parts go together and move.

The hardware has fixed sizes in millimetres (a 3 mm pin, a 7 mm washer, a spacer ring), the design's lengths
scale with ``unit_mm``: a four-bar synthesised from a drawing in millimetres (links of about 35 mm at
``unit_mm = 1``) has no room between its moving links and its pivots for the washers and spacers.  When the
build check fails, :func:`smallest_unit` searches the scale: it rebuilds the same scene at larger units
(:func:`scene_at_unit`), plans and checks it on a coarse cycle (:data:`COARSE_SAMPLES` samples) from the
scene's unit upwards by doubling, then bisects between the last unit that failed and the first that built to
within :data:`TOLERANCE`, rounds that up to two significant digits and runs the full build check there (the
export's: 240 samples).  The figure it reports is one at which the export passes; nothing is said of the units
between it and the scene's own (the check is not proved monotonic in the scale, only searched).
:func:`unit_hint` skips the search where no unit helps (:data:`UNSCALED`) or a build takes long
(more than :data:`MAX_PARTS` parts), and says so.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

__all__ = [
    "COARSE_SAMPLES",
    "MAX_BUILDS",
    "MAX_PARTS",
    "TOLERANCE",
    "UNSCALED",
    "ScaleHint",
    "scene_at_unit",
    "smallest_unit",
    "unit_hint",
]

#: samples per cycle of the search's build checks (the pins' paths between samples are swept, so a coarse
#: cycle still sees most collisions; the unit reported is checked again at the export's full 240)
COARSE_SAMPLES = 36
#: the search stops when the unit that builds is within this ratio of the one that does not
TOLERANCE = 1.03
#: builds the search may run in all (the doubling, the bisection and the final checks)
MAX_BUILDS = 14
#: the most parts (as cut) of a mechanism the search runs for: a synthesised four-bar has 4, a six-bar 6; a
#: 5-leg walker (30 parts) took 20 s of CPU a build, so the search's 14 builds would take minutes
MAX_PARTS = 8
#: problems no unit fixes: the motor shaft's length is set by the layers' count and the sheet's thickness
UNSCALED = frozenset({"motor shaft too short"})


@dataclass(frozen=True)
class ScaleHint:
    """What :func:`smallest_unit` found.

    ``unit_mm``: the unit at which the scene builds (the full build check passes), ``None`` when no unit up to
    ``top_mm`` did; ``across_mm``: the largest part's size at that unit (or at ``top_mm``), mm; ``top_mm``: the
    largest unit searched (the largest part then fills the sheet's diagonal); ``builds``: how many builds it ran.
    """

    unit_mm: float | None
    across_mm: float
    top_mm: float
    builds: int
    #: why the search did not run (``""``: it ran)
    skipped: str = ""

    def text(self, option: str = "--unit-mm ") -> str:
        """One line for a maker; ``option`` names how to export at the unit found (``"unit_mm="`` from Python)."""
        if self.skipped:
            return f"no unit_mm searched: {self.skipped}"
        if self.unit_mm is not None:
            return (
                f"the same scene builds at unit_mm = {self.unit_mm:g} (the largest part {self.across_mm:.0f} mm "
                f"across; export with {option}{self.unit_mm:g})"
            )
        return (
            f"no unit_mm up to {self.top_mm:.3g} (where the largest part, {self.across_mm:.0f} mm across, fills the "
            "sheet's diagonal) builds: the design itself must change, or the sheet grow"
        )


def scene_at_unit(scene: Any, unit_mm: float) -> Any:
    """The same scene with ``[fabrication] unit_mm = unit_mm`` (mm per model unit), rebuilt from its spec (a
    linkage's ``link_width_mm`` and the gravity are converted with the unit)."""
    from planar.scene.build import build_scene

    fab = scene.spec.fabrication.model_copy(update={"unit_mm": float(unit_mm)})
    return build_scene(scene.spec.model_copy(update={"fabrication": fab}), scene.path)


def unit_hint(scene: Any, fab: Any) -> ScaleHint:
    """What would make ``scene`` build, its :class:`~planar.fabrication.build.Fabrication` ``fab`` having failed
    the check: :func:`smallest_unit`, unless a problem no unit fixes is among its violations (:data:`UNSCALED`)
    or the mechanism as cut has more than :data:`MAX_PARTS` parts (then the hint says so, with ``builds = 0``)."""
    size = float(scene.mechanism.size)
    top = math.hypot(*fab.settings.sheet) / size
    fixed = sorted({v.what for v in fab.violations} & UNSCALED)
    if fixed:
        return ScaleHint(None, top * size, top, 0, f"{fixed[0]} does not change with the unit (see its line)")
    parts = len(fab.mechanism.parts) if fab.mechanism is not None else len(scene.mechanism.parts)
    if parts > MAX_PARTS:
        return ScaleHint(
            None,
            top * size,
            top,
            0,
            f"{parts} parts (the search runs for at most {MAX_PARTS}: each build of this many takes long); "
            "a larger unit_mm moves pins apart",
        )
    return smallest_unit(scene, fab.settings)


def _nice_up(u: float) -> float:
    """``u`` rounded up to two significant digits (1.837 -> 1.9, 23.2 -> 24)."""
    step = 10.0 ** (math.floor(math.log10(u)) - 1)
    return round(math.ceil(u / step - 1e-9) * step, 12)


def smallest_unit(scene: Any, settings: Any, max_builds: int = MAX_BUILDS) -> ScaleHint:
    """The smallest ``unit_mm`` above ``settings.unit_mm`` at which ``scene`` builds (see the module).

    Parameters
    ----------
    scene : Scene
        The scene whose build check failed at ``settings.unit_mm``.
    settings : FabSettings
        The settings it was built with (sheet, kerf, hardware...); only the unit changes.
    max_builds : int
        Builds the search may run in all.

    Returns
    -------
    ScaleHint
        The unit found (verified by the full build check) or ``None`` with the largest unit searched.
    """
    import dataclasses

    from planar.errors import PlanarError
    from planar.fabrication.build import build

    size = float(scene.mechanism.size)  # the largest part's diameter, model units
    top = math.hypot(*settings.sheet) / size  # export refuses a larger unit: the part would not fit the sheet
    runs = 0

    def builds(u: float, samples: tuple[int, int]) -> bool | None:
        """True: no violation; False: violations; None: refused (a part too large for the sheet...)."""
        nonlocal runs
        runs += 1
        try:
            fab = build(scene_at_unit(scene, u), dataclasses.replace(settings, unit_mm=u), samples=samples)
        except PlanarError:
            return None
        return not fab.violations

    coarse = (COARSE_SAMPLES, COARSE_SAMPLES)
    lo, hi, cap = settings.unit_mm, None, top
    u = lo
    while hi is None and u < cap and runs < max_builds // 2:
        u = min(2.0 * u, cap)
        ok = builds(u, coarse)
        if ok:
            hi = u
        elif ok is None:
            cap = u  # refused (a part too large for the sheet inside its margins): look below it
        else:
            lo = u
    while hi is None and cap / lo > TOLERANCE and runs < max_builds - 3:
        mid = math.sqrt(lo * cap)
        ok = builds(mid, coarse)
        if ok:
            hi = mid
        elif ok is None:
            cap = mid
        else:
            lo = mid
    if hi is None:
        return ScaleHint(None, top * size, top, runs)
    while hi / lo > TOLERANCE and runs < max_builds - 3:
        mid = math.sqrt(lo * hi)
        if builds(mid, coarse):
            hi = mid
        else:
            lo = mid
    u = _nice_up(hi)
    while runs < max_builds and u <= top:
        if builds(u, (120, 240)):
            return ScaleHint(u, u * size, top, runs)
        u = _nice_up(u * 1.05)
    return ScaleHint(None, top * size, top, runs)
