"""Default geometric parameters of the 11 elemental mechanisms (supplement, Part 2).

Frames (supplement, note to #1: "Coordinate of F_o is relative to the
driver's local coordinate; coordinates of follower's all other positional
parameters are relative to the follower's local coordinate"; the same rule
read for the driver's own parameters):

* ``D_o`` — world (the toy's motor frame): the driver's origin, its rotation
  centre (#1-#6), its rest position (#7-#9) or its arc slot's centre ``m0``
  (#10, #11);
* ``D_jc`` — the driver's frame (origin ``D_o``, axes parallel to world at
  rest): the cam centre (#1-#3) or the driver's pin (#7);
* ``F_o`` — the driver's frame: the follower's origin (its support or pivot);
* ``F_jc``, ``S_c``, ``F_jcx``, ``F_jh`` — the follower's frame (origin
  ``F_o``, axes parallel to world at rest);
* radii, widths, ``phi``, ``D_theta``, ``amplitude``, ``path`` — sizes,
  angles and motions, frame-free.

So moving ``D_o`` moves the whole mechanism and leaves its motion unchanged.
:func:`in_world` resolves a parameter record to world positions (what the
kinematics and the builders compute with).  Units are the supplement's (the
toys were about 9 cm across; read one unit as 100 mm).

Where the supplement leaves a quantity implicit, the choice is stated on the
field (``# planar:``).  Every field can be overridden:
``ElementalMechanism.build(5, F_jc=(-0.5, 0.0))``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace
from typing import Any, TypeVar

from planar.errors import InputError

__all__ = ["P1", "P2", "P3", "P4", "P5", "P6", "P7", "P8", "P9", "P10", "P11", "Params", "check_shapes", "coerce", "in_world"]

V2 = tuple[float, float]
V3 = tuple[float, float, float]


@dataclass(frozen=True)
class Params:
    """Base class: parameters of one elemental mechanism."""

    def replace(self, **kw: Any) -> Params:
        """A copy with ``kw`` replaced; each value checked against the field's shape (see :func:`coerce`)."""
        names = {f.name for f in fields(self)}
        for k in kw:
            if k not in names:
                raise InputError(f"{type(self).__name__}.{k}", kw[k], f"one of the parameters {sorted(names)}")
        return replace(self, **{k: coerce(f"{type(self).__name__}.{k}", getattr(self, k), v) for k, v in kw.items()})


def coerce(field: str, default: Any, value: Any) -> Any:
    """``value`` in the form of ``default``: a finite float, or a tuple of as many finite floats.

    Raises :class:`InputError` naming ``field`` for a vector of the wrong length, a number where a
    vector is expected (or the reverse), a bool, a string or a non-finite number.
    """
    if isinstance(default, tuple):
        n = len(default)
        if isinstance(value, (str, bytes)) or not hasattr(value, "__len__") or len(value) != n:
            raise InputError(field, value, f"a vector of {n} numbers")
        return tuple(_real(f"{field}[{i}]", v) for i, v in enumerate(value))
    if hasattr(value, "__len__"):
        raise InputError(field, value, "a single number")
    return _real(field, value)


def _real(field: str, v: Any) -> float:
    if isinstance(v, bool) or (not isinstance(v, (int, float)) and not hasattr(v, "__float__")):
        raise InputError(field, v, "a number")
    try:
        x = float(v)
    except (TypeError, ValueError, OverflowError):
        raise InputError(field, v, "a number") from None
    if not math.isfinite(x):
        raise InputError(field, v, "a finite number")
    return x


def check_shapes(number: int, P: Params) -> None:
    """:class:`InputError` unless every field of ``P`` has its default's shape (a number or a vector of k)."""
    defaults = type(P)()
    for f in fields(P):
        coerce(f"#{number}.{f.name}", getattr(defaults, f.name), getattr(P, f.name))


_P = TypeVar("_P", bound="Params")


def in_world(P: _P) -> _P:
    """``P`` with ``D_jc`` and ``F_o`` resolved from the driver's frame to world (``D_o +``).

    The other positional parameters stay relative to ``F_o`` (the follower's
    frame), which the code adds where it uses them.  Apply once: the result
    is for computing, not for passing back to :func:`in_world`.
    """
    o = tuple(float(x) for x in P.D_o)  # type: ignore[attr-defined]
    kw: dict[str, Any] = {}
    for name in ("D_jc", "F_o"):
        v = getattr(P, name, None)
        if v is not None:
            kw[name] = tuple(float(o[i]) + float(v[i]) if i < len(o) else float(v[i]) for i in range(len(v)))
    return replace(P, **kw)


@dataclass(frozen=True)
class P1(Params):  # Rz -> Tx
    D_o: V2 = (0.0, 0.0)
    D_ar: float = 0.03
    D_jc: V2 = (0.0, 0.06)
    D_jr: float = 0.12
    F_o: V2 = (0.30, 0.0)
    F_sr: float = 0.035


@dataclass(frozen=True)
class P2(Params):  # Rz -> Oz
    D_o: V2 = (0.0, 0.0)
    D_ar: float = 0.03
    D_jc: V2 = (0.0, 0.06)
    D_jr: float = 0.12
    F_o: V2 = (-0.40, 0.10)
    F_sr: float = 0.03


@dataclass(frozen=True)
class P3(Params):  # Rz -> OzT
    D_o: V3 = (0.0, 0.0, 0.0)
    D_ar: float = 0.03
    D_jc: V2 = (0.0, 0.04)
    D_jr: float = 0.12
    F_o: V2 = (0.60, -0.30)  # planar: the track pin p0 sits at F_o
    F_jr: float = 0.075
    S_c: V3 = (-0.10, -0.20, 0.10)  # track centre s = F_o + S_c (xy)


@dataclass(frozen=True)
class P4(Params):  # Oz -> Ty
    D_o: V3 = (0.0, 0.0, 0.0)
    D_ar: float = 0.03
    F_o: V3 = (0.80, 0.60, -0.40)
    F_jc: V2 = (-0.2, -0.3)  # follower pin p0 = F_o + F_jc; the driver slot is the line through p0 parallel to x at rest
    F_jr: float = 0.07
    F_sr: float = 0.035
    amplitude: float = math.pi / 9  # planar: standalone driver oscillation (the supplement's D_theta of #10/#11)


@dataclass(frozen=True)
class P5(Params):  # Oz -> Oz
    D_o: V3 = (0.0, 0.0, 0.0)
    D_ar: float = 0.03
    F_o: V3 = (1.30, 0.20, -0.30)
    F_ar: float = 0.03
    F_jc: V2 = (-0.60, 0.0)  # follower pin p0 = F_o + F_jc; the driver slot passes through p0, parallel to x at rest
    F_jr: float = 0.06
    amplitude: float = math.pi / 9


@dataclass(frozen=True)
class P6(Params):  # Oz -> Ox (spatial)
    D_o: V3 = (0.0, 0.0, 0.0)
    D_ar: float = 0.03
    F_o: V3 = (0.70, 0.0, -0.80)  # follower pivot axis: parallel to x through (y, z) = (F_o.y, F_o.z)
    F_ar: float = 0.03
    F_jr: float = 0.06  # radius r of the follower's pin, upright at (F_o.x, F_o.y) at rest
    F_h: float = 0.05  # planar: thickness of the follower's arm (drawing only)
    amplitude: float = math.pi / 9


@dataclass(frozen=True)
class P7(Params):  # Tx -> Oz
    D_o: V3 = (0.0, 0.0, 0.0)
    D_jc: V2 = (0.50, 0.25)  # driver pin
    D_jr: float = 0.04
    D_sr: float = 0.035
    F_o: V3 = (0.70, 0.55, 0.30)  # follower pivot; its slot runs from the pivot through the pin at rest
    F_ar: float = 0.035
    amplitude: float = 0.15  # planar: standalone driver stroke (half), model units


@dataclass(frozen=True)
class P8(Params):  # Tx -> Oy (moves in the xz plane)
    D_o: V3 = (0.0, 0.0, 0.0)
    D_ar: float = 0.03
    D_w1: float = 0.20  # tapered window widths (drawing)
    D_w2: float = 0.30
    F_o: V3 = (0.55, 0.30, -0.60)  # pivot B on a vertical (y) axis at (x, z) = (F_o.x, F_o.z)
    F_ar: float = 0.035
    F_jcx: float = 0.05  # planar: the tab's contact face runs parallel to the tab, F_jcx from the pivot axis
    F_jr: float = 0.06
    F_jh: float = 0.40  # tab length: the contact point A0 = B + (F_jcx, F_jh) in (x, z)
    amplitude: float = 0.15


@dataclass(frozen=True)
class P9(Params):  # Tx -> Ox (spatial)
    D_o: V3 = (0.0, 0.0, 0.0)
    D_ar: float = 0.03
    phi: float = math.pi / 3  # slant of the driver's slot
    F_o: V3 = (0.70, 0.55, -0.30)  # pivot axis parallel to x through (y, z) = (F_o.y, F_o.z); pin upright at (F_o.x, F_o.y)
    F_ar: float = 0.035
    F_jr: float = 0.04
    F_h: float = 0.40
    amplitude: float = 0.15


@dataclass(frozen=True)
class P10(Params):  # OzT -> Tx
    D_o: V3 = (0.0, 0.0, 0.0)  # m0: centre of the driver's arc slot
    D_theta: V2 = (-math.pi / 9, math.pi / 9)
    F_o: V3 = (1.20, -0.20, -0.30)
    F_jc: V2 = (-0.40, 0.30)  # follower pin p0 = F_o + F_jc, running in the driver's arc slot
    F_jr: float = 0.075
    F_sr: float = 0.035
    path: V2 = (0.10, 0.05)  # planar: standalone OzT driver translation (ellipse half-axes)


@dataclass(frozen=True)
class P11(Params):  # OzT -> Oz
    D_o: V3 = (0.0, 0.0, 0.0)
    D_theta: V2 = (-math.pi / 9, math.pi / 9)
    F_o: V3 = (0.90, 0.30, -0.30)  # follower pivot s
    F_jc: V2 = (-0.40, -0.30)  # follower pin p0 = F_o + F_jc, in the driver's arc slot about m0
    F_jr: float = 0.075
    F_ar: float = 0.03
    path: V2 = (0.04, 0.03)  # planar: smaller than #10's: at (0.10, 0.05) the arc slot leaves the pin's circle
