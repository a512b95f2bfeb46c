"""Features cut from a part (holes and slots), as exact geometry in the part's own frame.

Lengths are model units; angles radians, counter-clockwise.  This module
imports nothing from planar but its checks (:mod:`planar.core.fields`, :mod:`planar.core.limits`), so
:mod:`planar.core.model` (which re-exports these classes) and :mod:`planar.core.outlines` (which turns them into shapely geometry)
can both use it without importing each other.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from planar.core.fields import check_fields, check_positive
from planar.core.limits import check_resolution, resolution_terms

__all__ = ["ArcSlot", "Hole", "Slot"]

Vec = tuple[float, float]


@dataclass(frozen=True)
class Hole:
    """A round hole centred at ``centre``; ``diameter`` nominal.

    ``role="pin"``: a pivot hole whose size fabrication takes from the pin
    (the scene's pin diameter); ``"sized"``: the mechanism's own size (an
    axle, a cam's round hole).
    """

    length_fields: ClassVar[tuple[str, ...]] = ("diameter",)
    point_fields: ClassVar[tuple[str, ...]] = ("centre",)
    centre: Vec
    diameter: float
    role: str = "sized"

    def __post_init__(self) -> None:
        check_fields(self, "Hole")
        check_positive("Hole.diameter", self.diameter)
        check_resolution(resolution_terms(self, "Hole"), "hole")


@dataclass(frozen=True)
class Slot:
    """A straight slot (stadium): the pin's centre travels from ``start`` to ``end``."""

    length_fields: ClassVar[tuple[str, ...]] = ("width",)
    point_fields: ClassVar[tuple[str, ...]] = ("start", "end")
    start: Vec
    end: Vec
    width: float
    role: str = "sized"

    def __post_init__(self) -> None:
        check_fields(self, "Slot")
        check_positive("Slot.width", self.width)
        check_resolution(resolution_terms(self, "Slot"), "slot")


@dataclass(frozen=True)
class ArcSlot:
    """An arc slot about ``centre`` of mid-radius ``radius`` from ``angle0`` to ``angle1`` (CCW)."""

    length_fields: ClassVar[tuple[str, ...]] = ("radius", "width")
    point_fields: ClassVar[tuple[str, ...]] = ("centre",)
    centre: Vec
    radius: float
    angle0: float
    angle1: float
    width: float
    role: str = "sized"

    def __post_init__(self) -> None:
        check_fields(self, "ArcSlot")
        check_positive("ArcSlot.radius", self.radius)
        check_positive("ArcSlot.width", self.width)
        check_resolution(resolution_terms(self, "ArcSlot"), "arc slot")
