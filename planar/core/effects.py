"""Physical effects a simulation may include: plain records of the model.

Only what a scene names is built in the physics rebuild (``planar.physics.simulate``);
an :class:`Effects` with its defaults names nothing.  Units are model units:
lengths in model units, forces in model force units, gravity in model units
per s^2 (world frame, y up).
"""

from __future__ import annotations

from dataclasses import dataclass

from planar.core.fields import _check_name, check_fields, check_positive
from planar.errors import InputError

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

    def __post_init__(self) -> None:
        _check_name("Spring.a", self.a)
        _check_name("Spring.b", self.b)
        check_fields(self, "Spring")
        check_positive("Spring.stiffness", self.stiffness, "stiffness")
        if self.rest_length is not None and self.rest_length < 0:
            raise InputError("Spring.rest_length", self.rest_length, "a length >= 0 (or None: the first sample's)")
        if self.damping < 0:
            raise InputError("Spring.damping", self.damping, "a damping >= 0")


@dataclass(frozen=True)
class Load:
    """A force (world frame) the mechanism exerts at its named point ``point``."""

    point: str
    force: Vec

    def __post_init__(self) -> None:
        _check_name("Load.point", self.point)
        check_fields(self, "Load")


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

    def __post_init__(self) -> None:
        check_fields(self, "effects")
        if self.damping is not None and not 0.0 < self.damping <= 1.0:
            raise InputError("effects.damping", self.damping, "a fraction of velocity kept per second, in (0, 1]")
        check_positive("effects.density", self.density, "density")
        if self.motor_force_limit is not None:
            check_positive("effects.motor_force_limit", self.motor_force_limit, "torque")
        for f, kind in (("springs", Spring), ("loads", Load)):
            items = getattr(self, f)
            if isinstance(items, (str, bytes)) or not isinstance(items, (tuple, list)):
                raise InputError(f"effects.{f}", items, f"a tuple of {kind.__name__}")
            for item in items:
                if not isinstance(item, kind):
                    raise InputError(f"effects.{f}", item, f"a {kind.__name__}")

    @property
    def wants_motor(self) -> bool:
        """Whether the scene names a motor (``motor = true`` or a ``motor_force_limit``)."""
        return self.motor or self.motor_force_limit is not None


NO_EFFECTS = Effects()
