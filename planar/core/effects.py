"""Physical effects a simulation may include: plain records of the model.

Only what a scene names is built in the physics rebuild (``planar.physics.simulate``);
an :class:`Effects` with its defaults names nothing.  Units are model units:
lengths in model units, forces in model force units, gravity in model units
per s^2 (world frame, y up).
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["NO_EFFECTS", "Effects", "Load", "Spring"]

Vec = tuple[float, float]


@dataclass(frozen=True)
class Spring:
    """A damped spring from ``anchor_a`` on part ``a`` to ``anchor_b`` on part ``b`` (part frames).

    ``rest_length`` ``None``: the anchors' distance in the first sample.
    """

    a: str
    b: str
    stiffness: float
    anchor_a: Vec = (0.0, 0.0)
    anchor_b: Vec = (0.0, 0.0)
    rest_length: float | None = None
    damping: float = 0.0


@dataclass(frozen=True)
class Load:
    """A force (world frame) the mechanism exerts at its named point ``point``."""

    point: str
    force: Vec


@dataclass(frozen=True)
class Effects:
    """What the physics rebuild may include; the defaults include nothing.

    ``damping``: pymunk's space damping (fraction of velocity kept per
    second, in (0, 1]); ``density``: mass per unit area of every part;
    ``motor``: the scene asks for the motor-driven torque check (implied by
    ``motor_force_limit``); ``motor_force_limit``: the largest torque the motor may apply.
    """

    gravity: Vec | None = None
    damping: float | None = None
    density: float = 1.0
    springs: tuple[Spring, ...] = ()
    loads: tuple[Load, ...] = ()
    motor_force_limit: float | None = None
    motor: bool = False

    @property
    def wants_motor(self) -> bool:
        """Whether the scene names a motor (``motor = true`` or a ``motor_force_limit``)."""
        return self.motor or self.motor_force_limit is not None


NO_EFFECTS = Effects()
