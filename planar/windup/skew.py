"""The joint a spatial #6 or #9 closes: a driver edge in the xy plane touching a follower's tilting pin
(:class:`SkewContact`)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numpy.typing import NDArray

from planar.core.geometry import poses_apply
from planar.core.model import Feature, joint_kind

Array = NDArray[np.float64]


@joint_kind
@dataclass(frozen=True)
class SkewContact:
    """A driver edge (part ``a``, in the xy plane) touching a follower's tilting pin (part ``b``; spatial #6, #9).

    Residual: ``| distance(edge line, pin axis) - r |`` in 3D, from the
    driver's pose (xy) and the follower's pose in its ``"yz"`` plane.
    """

    kind: ClassVar[str] = "skew-contact"
    length_fields: ClassVar[tuple[str, ...]] = ("radius",)
    point_fields: ClassVar[tuple[str, ...]] = ("edge_point", "pin_x", "plane_z")
    name: str
    a: str  # the driver, carrying the edge
    b: str  # the follower, carrying the pin
    edge_point: tuple[float, float]  # on the edge, driver frame
    edge_dir: tuple[float, float]  # driver frame
    pin_x: float  # the pin's x (the follower's offset)
    radius: float
    plane_z: float = 0.0

    def features(self) -> tuple[tuple[str, Feature], ...]:
        return ()

    def pins(self) -> tuple[tuple[str, tuple[float, float]], ...]:
        return ()  # the pin tilts out of the driver's plane; drawn with the follower's outline

    def residual(self, poses) -> Array:
        dp = poses[self.a]
        e0 = poses_apply(dp, self.edge_point)
        c, s = np.cos(dp[:, 2]), np.sin(dp[:, 2])
        ex = c * self.edge_dir[0] - s * self.edge_dir[1]
        ey = s * self.edge_dir[0] + c * self.edge_dir[1]
        fp = poses[self.b]  # (y, z, alpha) of the pivot axis point
        a = fp[:, 2]
        P0 = np.column_stack([np.full_like(a, self.pin_x), fp[:, 0], fp[:, 1]])
        d1 = np.column_stack([np.zeros_like(a), -np.sin(a), np.cos(a)])
        d2 = np.column_stack([ex, ey, np.zeros_like(a)])
        E0 = np.column_stack([e0[:, 0], e0[:, 1], np.full_like(a, self.plane_z)])
        n = np.cross(d1, d2)
        dist = np.abs(((E0 - P0) * n).sum(-1)) / np.linalg.norm(n, axis=1)
        return np.abs(dist - self.radius)
