"""What a simulated run returns: the simulated motion, its settings and figures (:class:`SimResult`), and where
and why it stopped (:class:`SimFailure`)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from planar.core.model import Motion
from planar.physics.settings import (
    SimSettings,
)

Array = NDArray[np.float64]


@dataclass(frozen=True)
class SimFailure:
    """Where and how a simulation left its analytic motion.

    ``kind``: ``"blow-up"`` (non-finite state or a joint came apart),
    ``"change-point"`` (a branch switch or drift within three samples after the
    analytic motion passes a change point or toggle, see :func:`change_point`),
    ``"branch"`` (every joint holds but a part is more than ten tolerances
    elsewhere: another assembly branch) or ``"drift"`` (the part is off by
    more than ``tolerance``, the joints by less than ``blowup_tol``).  ``error``: the part's distance from its
    analytic pose as a fraction of the size.
    """

    sample: int
    time: float
    part: str
    kind: str
    error: float
    message: str


@dataclass
class SimResult:
    """A simulated motion and what it took."""

    motion: Motion
    settings: SimSettings
    mode: str
    built: dict[str, Any]
    wall_time: float
    steps: int
    torque: Array | None = None
    failure: SimFailure | None = None
    #: the rebuild's pin bodies: (part, point in its frame, mass)
    pins: list[tuple[str, tuple[float, float], float]] = field(default_factory=list)
    residuals: dict[str, Array] = field(default_factory=dict)
    #: samples whose interval had a step with the motor at its force limit (motor mode)
    saturated: NDArray[np.intp] = field(default_factory=lambda: np.zeros(0, dtype=np.intp))
    #: largest deviation of every part from its analytic pose over the simulated samples, / size
    pose_error: dict[str, float] = field(default_factory=dict)

    @property
    def blowup(self) -> tuple[int, str] | None:
        """``(sample, message)`` of the failure, if any (any kind, not only blow-ups)."""
        return None if self.failure is None else (self.failure.sample, self.failure.message)
