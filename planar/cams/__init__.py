"""Profile cams: motion laws, exact outlines for cutting, and the follower as a linkage's input.

:mod:`planar.cams.laws` (laws and segment programs), :mod:`planar.cams.profile`
(pitch curve, outline, envelope, curvature, pressure angle, checks),
:mod:`planar.cams.joint` (the ``cam-profile`` joint kind) and
:mod:`planar.cams.mechanism` (:class:`CamMechanism`).
"""

from planar.cams.joint import CamContact
from planar.cams.laws import LAWS, Program, Segment
from planar.cams.mechanism import CamMechanism
from planar.cams.profile import CamError, CamProfile, CamReport, FollowerGeometry

__all__ = ["LAWS", "CamContact", "CamError", "CamMechanism", "CamProfile", "CamReport", "FollowerGeometry", "Program", "Segment"]
