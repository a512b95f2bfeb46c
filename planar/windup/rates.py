"""Rates (velocities, accelerations) of wind-up mechanisms and toys: not derived yet.

:func:`planar.derivatives.mechanism_rates` hands every mechanism that is not a
linkage here.  The wind-up closed forms have no differentiated counterpart
yet, and a difference of samples is not offered in their place: asking for
them raises :class:`~planar.registry.UnsupportedError` naming the mechanism.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from ..registry import UnsupportedError

if TYPE_CHECKING:
    from ..derivatives import PartRates
    from ..model import Mechanism

__all__ = ["windup_rates"]


def windup_rates(mech: "Mechanism", q: NDArray[np.float64], qd: NDArray[np.float64], qdd: NDArray[np.float64]
                 ) -> tuple[dict[str, "PartRates"], NDArray[np.bool_], str]:
    """Part rates of a wind-up mechanism; raises :class:`UnsupportedError` for every kind so far."""
    raise UnsupportedError(
        f"rates (velocities, accelerations, torque): no closed-form derivatives for {type(mech).__name__} "
        f"{mech.name!r} yet; available for linkages (fourbar, slidercrank, linkage)")
