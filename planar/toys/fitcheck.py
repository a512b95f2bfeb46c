"""Motions too small for the cut parts to make: a toy's cam throws and effector strokes against the fit's play.

A laser-cut toy's holes are cut ``clearance_mm`` larger than their pins and
its cuts are off by up to the kerf (``kerf_mm``) where the kerf is not
calibrated: a motion of a few tenths of a millimetre is lost in that play.
:func:`small_motions` lists every cam throw (a #1-#3 stage's follower travel,
twice its eccentricity) and every named effector's stroke (the largest travel
of its piece, or of its named point, over one cycle) smaller than
:data:`FIT_MARGIN` times the larger of the two, all in mm.
"""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["CAM_STAGES", "FIT_MARGIN", "fit_play", "small_motion_text", "small_motions"]

#: a motion must be at least this many times the fit's play (mm) to survive the cut parts
FIT_MARGIN = 3.0
#: the cam-in-window stages, whose throw is twice their eccentricity ``D_jc``
CAM_STAGES = (1, 2, 3)


def fit_play(settings: Any) -> float:
    """The fit's play (mm): the larger of the pin clearance and the kerf of the fabrication settings."""
    _check_settings("fit_play(settings)", settings)
    return float(max(settings.clearance, settings.kerf))


def _travel(track: np.ndarray) -> float:
    """Largest peak-to-peak travel of points over a cycle: ``track`` is (samples, points, 2)."""
    return float(np.max(np.hypot(np.ptp(track[..., 0], axis=0), np.ptp(track[..., 1], axis=0))))


def small_motions(toy: Any, settings: Any, samples: int = 73) -> list[dict[str, Any]]:
    """The items of :func:`motion_sizes` under ``FIT_MARGIN`` x :func:`fit_play` (mm)."""
    from planar.core.fields import check_kind, check_number
    from planar.errors import InputError
    from planar.windup.chain import ToyMechanism

    check_kind("small_motions(toy)", toy, ToyMechanism, "a ToyMechanism (planar.windup.chain)")
    _check_settings("small_motions(settings)", settings)
    if not 3 <= check_number("small_motions(samples)", samples, integer=True) <= 100_000:
        raise InputError("small_motions(samples)", samples, "a whole number of samples, 3 to 100 000")
    return [m for m in motion_sizes(toy, settings, samples) if m["mm"] < m["limit_mm"]]


def motion_sizes(toy: Any, settings: Any, samples: int = 73) -> list[dict[str, Any]]:
    """Every cam throw and named effector stroke of ``toy`` (a ToyMechanism), mm.

    Each item: ``kind`` ("cam throw" or "effector stroke"), ``what`` (the stage or effector), ``mm`` (the
    motion, mm at the settings' ``unit_mm``), ``limit_mm`` (``FIT_MARGIN`` x :func:`fit_play`).  The strokes
    are read from the assembled toy's piece poses (:func:`planar.toys.assembly.toy_assembly`), the throws
    from the stages' parameters.
    """
    from planar.toys.assembly import toy_assembly

    unit = float(settings.unit_mm)
    limit = FIT_MARGIN * fit_play(settings)
    out: list[dict[str, Any]] = []
    for st in toy.stages:
        if st.realisation.number not in CAM_STAGES:
            continue
        P = st.mech.params
        out.append(
            {
                "kind": "cam throw",
                "what": f"stage {st.label} {st.realisation.pattern}",
                "mm": 2.0 * float(np.hypot(P.D_jc[0], P.D_jc[1])) * unit,
                "limit_mm": limit,
            }
        )
    if not toy.names:
        return out
    asm = toy_assembly(toy)
    m = asm.run(samples_per_cycle=samples)
    parts = {p.name: p for p in asm.parts}
    for _key, name in sorted(toy.names.items(), key=lambda kv: kv[1]):
        if name in parts:
            piece, pts = name, np.array([(x, y) for x, y, _r in parts[name].hull] or [(0.0, 0.0)])
        else:
            piece, at = asm.points[name]
            pts = np.array([at], dtype=float)
        pose = np.asarray(m.poses[piece])[np.asarray(m.valid, dtype=bool)]
        c, s = np.cos(pose[:, 2])[:, None], np.sin(pose[:, 2])[:, None]
        track = np.stack([pose[:, :1] + c * pts[:, 0] - s * pts[:, 1], pose[:, 1:2] + s * pts[:, 0] + c * pts[:, 1]], axis=-1)
        out.append({"kind": "effector stroke", "what": f"effector {name!r}", "mm": _travel(track) * unit, "limit_mm": limit})
    return out


def small_motion_text(item: dict[str, Any], settings: Any) -> str:
    """One line for an item of :func:`small_motions`."""
    return (
        f"{item['what']}: {item['kind']} {item['mm']:.3g} mm is under {FIT_MARGIN:g} x the fit's play "
        f"({fit_play(settings):g} mm, the larger of clearance_mm {settings.clearance:g} and kerf_mm "
        f"{settings.kerf:g}): the cut parts will not make this motion (ask for a larger range)"
    )


def _check_settings(field: str, settings: Any) -> None:
    """Fabrication settings (:class:`planar.fabrication.FabSettings`: its ``unit_mm``, ``clearance`` and ``kerf``)."""
    from planar.errors import InputError

    if not all(isinstance(getattr(settings, f, None), float | int) for f in ("unit_mm", "clearance", "kerf")):
        raise InputError(field, settings, "fabrication settings (planar.fabrication.FabSettings)")
