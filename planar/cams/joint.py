"""The contact between a profile cam and its follower, as a joint kind every consumer can ask."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numpy.typing import NDArray

from planar.cams.profile import CamProfile
from planar.core.fields import check_kind
from planar.core.geometry import poses_apply
from planar.core.model import Feature, _check_joint, joint_kind

__all__ = ["CamContact"]

Array = NDArray[np.float64]
Vec = tuple[float, float]


@joint_kind
@dataclass(frozen=True, eq=False)
class CamContact:
    """Part ``b`` (a roller, a knife-edge or flat-faced follower) rides on the profile of cam ``a``.

    ``point`` (in ``b``'s frame) is the roller's centre or the knife's tip;
    for a flat face it is a point of the face and ``normal`` (``b``'s frame)
    the face's normal pointing away from the cam.  The residual is exact,
    found on the analytic curve by Newton's method from the cam's angle: the
    distance of ``point`` from the pitch curve (roller, knife), or the gap
    between the face and the outline's support line in the face's direction
    (flat).  ``profile`` is the cam's :class:`~planar.cams.profile.CamProfile`
    in ``a``'s frame.
    """

    kind: ClassVar[str] = "cam-profile"
    point_fields: ClassVar[tuple[str, ...]] = ("point",)
    name: str
    a: str
    b: str
    profile: CamProfile
    point: Vec
    normal: Vec = (0.0, 1.0)

    def __post_init__(self) -> None:
        _check_joint(self, ("point", "normal"), None)
        check_kind(f"CamContact {self.name!r}.profile", self.profile, CamProfile)

    def residual(self, poses: Mapping[str, Array]) -> Array:
        cam = np.atleast_2d(poses[self.a])
        fol = np.atleast_2d(poses[self.b])
        theta = cam[:, 2]
        p = poses_apply(fol, self.point) - cam[:, :2]
        c, s = np.cos(-theta), np.sin(-theta)
        q = np.stack([c * p[:, 0] - s * p[:, 1], s * p[:, 0] + c * p[:, 1]], -1)
        if self.profile.follower.kind != "flat":
            return self.profile.pitch_distance(q, theta)
        ang = fol[:, 2] + np.arctan2(self.normal[1], self.normal[0]) - theta  # the face normal in the cam's frame
        sup = self.profile.support(ang, theta)
        return np.abs(sup - (q * np.stack([np.cos(ang), np.sin(ang)], -1)).sum(-1))

    def features(self) -> tuple[tuple[str, Feature], ...]:
        return ()

    def pins(self) -> tuple[tuple[str, Vec], ...]:
        return ((self.b, self.point),)
