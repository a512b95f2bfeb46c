"""Default geometric parameters of the 11 elemental mechanisms (supplement, Part 2).

Positions of the follower's origin ``F_o`` are in the driver's frame (whose
origin is the driver's rotation centre ``D_o``); every other follower
parameter is relative to ``F_o`` (supplement note to #1).  Units are the
supplement's (the toys were about 9 cm across; read one unit as 100 mm).

Where the supplement leaves a quantity implicit, the choice is stated on the
field (``# planar:``).  Every field can be overridden:
``ElementalMechanism.build(5, F_jc=(-0.5, 0.0))``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace
from typing import Any

from ..errors import InputError

__all__ = ["Params", "P1", "P2", "P3", "P4", "P5", "P6", "P7", "P8", "P9", "P10", "P11"]

V2 = tuple[float, float]
V3 = tuple[float, float, float]


@dataclass(frozen=True)
class Params:
    """Base class: parameters of one elemental mechanism."""

    def replace(self, **kw: Any) -> "Params":
        names = {f.name for f in fields(self)}
        for k in kw:
            if k not in names:
                raise InputError(f"{type(self).__name__}.{k}", kw[k], f"one of the parameters {sorted(names)}")
        return replace(self, **kw)


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
