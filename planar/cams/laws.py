"""Follower motion laws and the rise-dwell-return-dwell program of a disc cam.

A law maps the normalised segment position ``u`` in ``[0, 1]`` to the
normalised displacement ``y(u)`` from 0 to 1, with its derivatives
``y'(u)`` and ``y''(u)`` (closed forms, vectorised over arrays):

* ``cycloidal``: ``u - sin(2 pi u) / (2 pi)``; velocity and acceleration zero at both ends;
* ``harmonic`` (simple harmonic): ``(1 - cos(pi u)) / 2``; acceleration jumps at the ends;
* ``polynomial-345``: ``10 u^3 - 15 u^4 + 6 u^5``; velocity and acceleration zero at both ends;
* ``dwell``: ``y = 0`` (the follower rests; a dwell's ``lift`` must be 0).

A :class:`Program` is a list of :class:`Segment` s covering one turn of the
cam: each lasts ``angle`` radians of cam rotation and changes the follower's
displacement by ``lift`` (positive: away from the cam's centre, a rise;
negative: a return).  The lifts sum to zero and the displacement never goes
below its start (the base circle).  ``Program.evaluate(theta)`` gives the
displacement ``s`` and its derivatives ``ds/dtheta``, ``d2s/dtheta2`` with
respect to the cam angle ``theta`` (radians, any real value: the program
repeats every turn).  Units of ``s``: model units for a translating follower,
radians for an oscillating one.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from planar.core.fields import check_fields, check_finite, check_number
from planar.errors import InputError

__all__ = ["LAWS", "Law", "Program", "Segment"]

Array = NDArray[np.float64]
TWO_PI = 2.0 * math.pi


@dataclass(frozen=True)
class Law:
    """A normalised rise law ``y(u)`` on ``[0, 1]`` with ``y(0) = 0``, ``y(1) = 1`` (a dwell: ``y = 0``)."""

    name: str
    y: Callable[[Array], Array]
    dy: Callable[[Array], Array]
    d2y: Callable[[Array], Array]


def _zero(u: Array) -> Array:
    return np.zeros_like(u)


#: every motion law, by the name a scene uses
LAWS: dict[str, Law] = {
    "cycloidal": Law(
        "cycloidal",
        lambda u: u - np.sin(TWO_PI * u) / TWO_PI,
        lambda u: 1.0 - np.cos(TWO_PI * u),
        lambda u: TWO_PI * np.sin(TWO_PI * u),
    ),
    "harmonic": Law(
        "harmonic",
        lambda u: 0.5 * (1.0 - np.cos(math.pi * u)),
        lambda u: 0.5 * math.pi * np.sin(math.pi * u),
        lambda u: 0.5 * math.pi**2 * np.cos(math.pi * u),
    ),
    "polynomial-345": Law(
        "polynomial-345",
        lambda u: u**3 * (10.0 - 15.0 * u + 6.0 * u**2),
        lambda u: 30.0 * u**2 * (1.0 - u) ** 2,
        lambda u: 60.0 * u * (1.0 - 3.0 * u + 2.0 * u**2),
    ),
    "dwell": Law("dwell", _zero, _zero, _zero),
}


@dataclass(frozen=True)
class Segment:
    """One part of the program: ``law`` over ``angle`` rad of cam turn, changing the displacement by ``lift``."""

    law: str
    angle: float
    lift: float = 0.0

    def __post_init__(self) -> None:
        if not isinstance(self.law, str) or self.law not in LAWS:
            raise InputError("Segment.law", self.law, f"one of {sorted(LAWS)}")
        check_fields(self, "Segment")
        if not self.angle > 0:
            raise InputError("Segment.angle", self.angle, "a positive angle of cam turn (rad)")

    def describe(self, start: float, unit: str = "deg") -> str:
        """``"cycloidal rise of 0.5 over 0-120 deg"``: what a message names (``start`` in rad)."""
        check_number("Segment.describe(start)", start)
        _check_unit(unit)
        what = "dwell" if self.law == "dwell" else f"{self.law} {'rise' if self.lift > 0 else 'return'}"
        if unit == "deg":
            span = f"{math.degrees(start):.4g}-{math.degrees(start + self.angle):.4g} deg"
        else:
            span = f"{start:.4g}-{start + self.angle:.4g} rad"
        return f"{what} over {span}"


def _check_unit(unit: object) -> None:
    if not isinstance(unit, str) or unit not in ("deg", "rad"):
        raise InputError("unit", unit, "'deg' or 'rad'")


class Program:
    """Segments covering one turn of the cam (angles in rad summing to 2 pi, lifts summing to 0).

    ``where`` names the scene field in error messages (``"mechanism.segments"``).
    """

    def __init__(self, segments: list[Segment] | tuple[Segment, ...], where: str = "segments", lift_unit: str = "") -> None:
        if isinstance(segments, (str, bytes)) or not isinstance(segments, (list, tuple)):
            raise InputError(where, segments, "a list of Segment")
        if not all(isinstance(sg, Segment) for sg in segments):
            raise InputError(where, segments, "a list of Segment (cam.Segment(law, angle, lift))")
        if not isinstance(where, str) or not isinstance(lift_unit, str) or lift_unit not in ("", "deg", "rad"):
            raise InputError("Program(where, lift_unit)", (where, lift_unit), "a string and '', 'deg' or 'rad'")
        self.segments = tuple(segments)
        self.where = where
        #: how a lift is shown in a message: ``"deg"`` for an oscillating follower's lift given in degrees
        self.lift_unit = lift_unit
        if not self.segments:
            raise InputError(where, [], "at least one segment")
        for i, sg in enumerate(self.segments):
            w = f"{where}[{i}]"
            if sg.law not in LAWS:
                raise InputError(f"{w}.law", sg.law, f"one of {sorted(LAWS)}")
            if not (math.isfinite(sg.angle) and sg.angle > 0):
                raise InputError(f"{w}.angle", sg.angle, "a positive angle")
            if not math.isfinite(sg.lift):
                raise InputError(f"{w}.lift", sg.lift, "a finite number")
            if sg.law == "dwell" and sg.lift != 0.0:
                raise InputError(f"{w}.lift", sg.lift, "0 for a dwell (the follower rests)")
            if sg.law != "dwell" and sg.lift == 0.0:
                raise InputError(f"{w}.lift", sg.lift, f"a non-zero lift for a {sg.law} segment (or law = 'dwell')")
        total = sum(sg.angle for sg in self.segments)
        if abs(total - TWO_PI) > 1e-9 * TWO_PI:
            raise InputError(
                f"{where}", f"angles summing to {math.degrees(total):.6g} deg", "segment angles summing to one turn (360 deg)"
            )
        self.starts = np.concatenate([[0.0], np.cumsum([sg.angle for sg in self.segments])[:-1]])
        levels = np.concatenate([[0.0], np.cumsum([sg.lift for sg in self.segments])])
        scale = max(abs(sg.lift) for sg in self.segments) if any(sg.lift for sg in self.segments) else 1.0
        if abs(levels[-1]) > 1e-9 * scale:
            raise InputError(
                f"{where}",
                f"lifts summing to {self._shown(levels[-1])}",
                "lifts summing to 0 (the follower returns to where it started)",
            )
        if not any(sg.lift for sg in self.segments):
            raise InputError(f"{where}", "only dwells", "at least one rise and one return")
        for i in range(len(self.segments)):
            if levels[i + 1] < -1e-9 * scale:
                raise InputError(
                    f"{where}[{i}].lift",
                    float(f"{self._shown(self.segments[i].lift, unit=False)}"),
                    f"a lift that keeps the follower at or above its start (it would go to "
                    f"{self._shown(levels[i + 1])}, inside the base circle)",
                )
        self.levels = levels[:-1]
        self.max_lift = float(levels.max())

    def _shown(self, lift: float, unit: bool = True) -> str:
        """A lift as the user wrote it (degrees for a lift in degrees)."""
        if self.lift_unit == "deg":
            return f"{math.degrees(lift):.6g}" + (" deg" if unit else "")
        return f"{lift:.6g}"

    @staticmethod
    def _wrap(theta: ArrayLike) -> Array:
        """Cam angles in ``[0, 2 pi)`` (``np.mod`` of a tiny negative angle rounds to ``2 pi`` itself)."""
        t = np.mod(check_finite("theta", theta), TWO_PI)
        return np.where(t >= TWO_PI, 0.0, t)

    def segment_of(self, theta: ArrayLike) -> NDArray[np.intp]:
        """Index of the segment each cam angle (rad, any real value) falls in."""
        t = self._wrap(theta)
        return np.clip(np.searchsorted(self.starts, t, side="right") - 1, 0, len(self.segments) - 1)

    def evaluate(self, theta: ArrayLike) -> tuple[Array, Array, Array]:
        """``s, ds/dtheta, d2s/dtheta2`` at cam angles ``theta`` (rad); arrays of ``theta``'s shape."""
        t = self._wrap(theta)
        k = self.segment_of(t)
        s = np.empty_like(t)
        v = np.empty_like(t)
        a = np.empty_like(t)
        for i, sg in enumerate(self.segments):  # one array expression per segment, not per sample
            m = k == i
            if not m.any():
                continue
            law = LAWS[sg.law]
            u = np.clip((t[m] - self.starts[i]) / sg.angle, 0.0, 1.0)
            s[m] = self.levels[i] + sg.lift * law.y(u)
            v[m] = sg.lift / sg.angle * law.dy(u)
            a[m] = sg.lift / sg.angle**2 * law.d2y(u)
        return s, v, a

    def describe(self, i: int, unit: str = "deg") -> str:
        """``"mechanism.segments[1] (cycloidal rise over 120-240 deg)"``."""
        if not -len(self.segments) <= check_number("Program.describe(i)", i, integer=True) < len(self.segments):
            raise InputError("Program.describe(i)", i, f"a segment's index, 0 to {len(self.segments) - 1}")
        return f"{self.where}[{i}] ({self.segments[i].describe(float(self.starts[i]), unit)})"
