"""Offset slider-crank: crank ``r`` about ``O = (0, 0)``, rod ``l``, slider on ``y = offset``.

Closed form (line-circle dyad): the slider's x is
``r cos(theta) + branch * sqrt(l^2 - (r sin(theta) - e)^2)``, computed through
:func:`planar.core.geometry.line_circle` (half-chord ``sqrt((l - h)(l + h))``, no
cancellation).  ``branch=+1`` puts the slider on the +x side.
"""

from __future__ import annotations

import numbers
from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from planar.core.fields import check_number
from planar.core.model import check_finite, check_positive
from planar.errors import InputError
from planar.linkages.linkage import Link, Linkage
from planar.linkages.nodes import RRP, Crank, Fixed

__all__ = ["SliderCrank"]


class SliderCrank(Linkage):
    """Offset slider-crank with parts ``ground``, ``crank``, ``rod``, ``slider``.

    The slider block slides (pure translation) along the ground's guide line
    ``y = offset``; the named point ``slider_pin`` is the wrist pin.
    """

    def __init__(
        self,
        crank: float,
        rod: float,
        offset: float = 0.0,
        branch: int = 1,
        placement: Sequence[float] = (0.0, 0.0, 0.0),
        name: str = "slidercrank",
        **kw: Any,
    ) -> None:
        r = check_positive(f"{name}.crank", crank)
        l = check_positive(f"{name}.rod", rod)
        e = float(check_number(f"{name}.offset", offset))
        if max(r, l) > 1e100 * min(r, l):  # as freudenstein_angles: no mechanism, and its squares overflow
            short, long_ = (("crank", "rod"), ("rod", "crank"))[l < r]
            raise InputError(f"{name}.{long_}", max(r, l), f"a length within 1e100 of the {short}'s ({min(r, l):g})")
        if abs(e) >= r + l:
            raise InputError(
                f"{name}.offset", offset, f"|offset| < crank + rod = {r + l:g} (else the rod never reaches the guide)"
            )
        if isinstance(branch, bool) or not isinstance(branch, numbers.Integral) or branch not in (1, -1):
            raise InputError(f"{name}.branch", branch, "1 (slider on the +x side) or -1")
        self.r: float = r
        self.l: float = l
        self.e: float = e
        self.branch: int = int(branch)
        span = r + l
        nodes = [
            Fixed("O", (0.0, 0.0)),
            Fixed("G1", (-span, e)),
            Fixed("G2", (2 * span, e)),
            Crank("A", "O", r),
            RRP("S", "A", l, "G1", "G2", branch, line="the slider's guide line"),
        ]
        links = [
            Link("crank", ("O", "A")),
            Link("rod", ("A", "S")),
            Link("slider", ("S",), guide=("G1", "G2")),
        ]
        super().__init__(name, nodes, links, points={"slider_pin": "S"}, placement=placement, **kw)

    def slider_position(self, theta: ArrayLike) -> np.ndarray:
        """Slider x (before placement) by the textbook formula, for cross-checks: ``branch`` picks the root.

        ``r cos(theta) + branch sqrt(l^2 - (r sin(theta) - e)^2)``; where the rod cannot reach the
        guide the root is taken at zero (see :meth:`solve` for the validity mask).
        """
        th = check_finite(f"{self.name}.slider_position(theta)", theta)
        h = self.r * np.sin(th) - self.e
        return self.r * np.cos(th) + self.branch * np.sqrt(np.maximum((self.l - h) * (self.l + h), 0.0))
