"""Two motions of one mechanism side by side: analytic against simulated.

Per part: the largest and RMS distance between the part's frame origins
(model units, and as a fraction of the mechanism's size) and the largest
angle difference; per joint: the residual of the second motion; and the
first sample where a part's error passes ``threshold`` (fraction of size).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .geometry import poses_apply, wrap_angle
from .model import Mechanism, Motion, joint_residuals

__all__ = ["PartError", "Comparison", "compare", "format_comparison"]


@dataclass
class PartError:
    part: str
    max_error: float
    rms_error: float
    max_rel_error: float
    max_angle_error: float
    first_over: int | None


@dataclass
class Comparison:
    mechanism: str
    size: float
    samples: int
    threshold: float
    parts: list[PartError]
    joints: dict[str, float]
    first_over: int | None
    torque: dict[str, Any] | None = None
    notes: list[str] = field(default_factory=list)

    @property
    def max_rel_error(self) -> float:
        return max((p.max_rel_error for p in self.parts), default=0.0)

    def to_dict(self) -> dict[str, Any]:
        return {
            "mechanism": self.mechanism,
            "size": self.size,
            "samples": self.samples,
            "threshold": self.threshold,
            "max_rel_error": self.max_rel_error,
            "first_over_threshold": self.first_over,
            "parts": {p.part: {"max_error": p.max_error, "rms_error": p.rms_error,
                               "max_rel_error": p.max_rel_error, "max_angle_error": p.max_angle_error,
                               "first_over_threshold": p.first_over} for p in self.parts},
            "joints": {k: {"max_residual": v, "max_rel_residual": v / self.size} for k, v in self.joints.items()},
            "torque": self.torque,
            "notes": self.notes,
        }


def _part_points(mech: Mechanism, part: str) -> NDArray[np.float64]:
    """Points that stand for a part: its hull circle centres (so rotation errors count too)."""
    p = mech.part(part)
    pts = np.array([(x, y) for x, y, _ in p.hull] or [(0.0, 0.0)])
    return pts


def compare(mech: Mechanism, reference: Motion, other: Motion, threshold: float = 1e-3) -> Comparison:
    """Errors of ``other`` against ``reference`` (same samples) for every part and joint."""
    size = mech.size
    ok = reference.valid & other.valid
    parts = []
    first_all: int | None = None
    for p in mech.parts:
        pts = _part_points(mech, p.name)
        a = poses_apply(reference.poses[p.name], pts)  # (N, M, 2)
        b = poses_apply(other.poses[p.name], pts)
        d = np.hypot(*(a - b).transpose(2, 0, 1)).max(axis=1)  # worst point per sample
        d = np.where(ok, d, 0.0)
        ang = np.abs(wrap_angle(reference.poses[p.name][:, 2] - other.poses[p.name][:, 2]))
        ang = np.where(ok, ang, 0.0)
        over = np.flatnonzero(d > threshold * size)
        first = int(over[0]) if over.size else None
        if first is not None and (first_all is None or first < first_all):
            first_all = first
        n = max(int(ok.sum()), 1)
        parts.append(PartError(p.name, float(d.max()), float(np.sqrt((d[ok] ** 2).sum() / n)),
                               float(d.max() / size), float(ang.max()), first))
    res = joint_residuals(mech, other)
    joints = {k: float(np.max(np.where(ok, v, 0.0))) for k, v in res.items()}
    notes = []
    if not other.valid.all():
        i = int(np.flatnonzero(~other.valid)[0])
        notes.append(other.reason(i) or f"sample {i} invalid")
    return Comparison(mech.name, size, len(reference), threshold, parts, joints, first_all, notes=notes)


def format_comparison(c: Comparison) -> str:
    """A table for the terminal."""
    lines = [f"{c.mechanism}: {c.samples} samples, size {c.size:.4g}, threshold {c.threshold:g} of size",
             f"  {'part':<16}{'max err':>11}{'rms err':>11}{'max/size':>11}{'max angle':>11}  first over",
             ]
    for p in c.parts:
        first = "-" if p.first_over is None else str(p.first_over)
        lines.append(f"  {p.part:<16}{p.max_error:11.3e}{p.rms_error:11.3e}{p.max_rel_error:11.3e}"
                     f"{p.max_angle_error:11.3e}  {first}")
    lines.append(f"  {'joint':<16}{'residual':>11}{'/size':>11}")
    for k, v in c.joints.items():
        lines.append(f"  {k:<16}{v:11.3e}{v / c.size:11.3e}")
    if c.torque:
        t = c.torque
        lines.append(f"  motor torque: pymunk vs virtual work: max |diff| {t['max_abs_diff']:.3e} "
                     f"({t['max_rel_diff']:.2%} of peak {t['peak']:.4g})")
    for n in c.notes:
        lines.append(f"  note: {n}")
    return "\n".join(lines)
