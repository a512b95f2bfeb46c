"""Linkages: four-bar, slider-crank, and general pivot/slot linkages from dyads."""

from .dyads import NODE_KINDS, RRP, RRR, Actuator, Crank, Fixed, Link, Linkage, NodeKind, Rigid, node_kind
from .gears import Driven, Geared, GearMesh
from .triads import Triad
from .fourbar import FourBar, freudenstein_angles, grashof_class
from .slidercrank import SliderCrank

__all__ = [
    "NODE_KINDS", "NodeKind", "node_kind", "Actuator", "Crank", "Fixed", "Link", "Linkage", "RRP", "RRR", "Rigid",
    "Geared", "Driven", "GearMesh", "Triad",
    "FourBar", "SliderCrank", "freudenstein_angles", "grashof_class",
]
