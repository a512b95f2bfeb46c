"""Linkages: four-bar, slider-crank, and general pivot/slot linkages from dyads."""

from planar.linkages.fourbar import FourBar, freudenstein_angles, grashof_class
from planar.linkages.gears import Driven, Geared, GearMesh
from planar.linkages.linkage import Link, Linkage
from planar.linkages.nodes import NODE_KINDS, RRP, RRR, Actuator, Crank, Fixed, NodeKind, Rigid, node_kind
from planar.linkages.slidercrank import SliderCrank
from planar.linkages.triads import Triad

__all__ = [
    "NODE_KINDS",
    "RRP",
    "RRR",
    "Actuator",
    "Crank",
    "Driven",
    "Fixed",
    "FourBar",
    "GearMesh",
    "Geared",
    "Link",
    "Linkage",
    "NodeKind",
    "Rigid",
    "SliderCrank",
    "Triad",
    "freudenstein_angles",
    "grashof_class",
    "node_kind",
]
