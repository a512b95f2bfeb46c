"""Linkages: four-bar, slider-crank, and general pivot/slot linkages from dyads."""

from .dyads import RRP, RRR, Actuator, Crank, Fixed, Link, Linkage, Rigid
from .fourbar import FourBar, coupler_points_fast, freudenstein_angles, grashof_class
from .slidercrank import SliderCrank

__all__ = [
    "Actuator", "Crank", "Fixed", "Link", "Linkage", "RRP", "RRR", "Rigid",
    "FourBar", "SliderCrank", "coupler_points_fast", "freudenstein_angles", "grashof_class",
]
