"""A mechanism seen with other parts and joints: what fabrication cuts differs from what moves.

:class:`PartsView` holds its own ``parts`` and ``joints`` and hands everything else (driver, notes, keyed cams,
``run``) to the wrapped mechanism; a view adds what its parts' poses need in ``run``
(:class:`~planar.fabrication.tabs.FabView`, :class:`~planar.fabrication.riders.RiderView`).
"""

from __future__ import annotations

from typing import Any

from planar.core.model import Part

__all__ = ["PartsView"]


class PartsView:
    """``mech`` with ``parts`` and ``joints`` of its own; every other attribute is ``mech``'s."""

    def __init__(self, mech: Any, parts: list[Part], joints: list[Any]) -> None:
        self._mech = mech
        self.parts = tuple(parts)
        self.joints = tuple(joints)

    def __getattr__(self, name: str) -> Any:
        return getattr(self._mech, name)

    def part(self, name: str) -> Part:
        """The view's part ``name``, else the wrapped mechanism's."""
        for p in self.parts:
            if p.name == name:
                return p
        return self._mech.part(name)
