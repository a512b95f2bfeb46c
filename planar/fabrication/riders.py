"""Polygons cut as parts of their own (``cut = "part"``): a foot, a wing, a bird's head on its own layer.

A scene's ``[[mechanism.polygons]]`` entry with ``cut = "part"`` becomes a *rider*: a part named after the
polygon, its outline the polygon (the host part's own frame, so it moves exactly as its host), fixed to its host
by two pins.  The pins stand where both pieces have room for a pin hole with ``min_wall_mm`` all round (the
polygon and the host's cut material, each shrunk by a hole's radius plus the wall), as far apart as that room
allows, so the two pins hold the rider against turning; they keep an end's width (washer and clip, or nut) from
each other and from the host's own pins under the rider, so their ends clear.  A rounded host (a hull of
circles) too narrow for them grows round them, as it grows round any hole (the part's note says so).  A host's
pin under the rider goes on through it (one pin through host, rider and the host's other part), so no layer
order puts the rider between that pin's ends without a hole.  Each pin is a :class:`~planar.core.model.Pivot` between
host and rider with a pin hole in both: the layer planner puts the rider on a layer of its own (its area overlaps
its host's), the BOM, ``plan.json`` and the assembly steps list its pins like any other, and the build check
moves it with its host and checks it against every part on its layer.

``cut = true`` (merged into the host's outline) is :func:`planar.fabrication.build._merged_outline`'s.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from planar.core.model import Hole, Part, Pivot
from planar.errors import InputError
from planar.fabrication.views import PartsView

__all__ = ["ROOM_MARGIN", "RiderView", "pin_sites", "rider_polygons", "with_riders"]

#: more room than the wall (mm) round a rider's pin hole: the buffered outlines' chords lie inside their arcs
ROOM_MARGIN = 0.05


def rider_polygons(scene: Any, mech: Any) -> list[tuple[int, Any]]:
    """``(index, polygon spec)`` of the scene's polygons with ``cut = "part"``, their host checked."""
    names = {p.name for p in mech.parts}
    out = []
    for i, poly in enumerate(getattr(getattr(scene.spec, "mechanism", None), "polygons", []) or []):
        if getattr(poly, "cut", False) != "part":
            continue
        if poly.part not in names:
            raise InputError(f"mechanism.polygons[{i}].part", poly.part, "a part that is cut (" + ", ".join(sorted(names)) + ")")
        if poly.name in names:
            raise InputError(
                f"mechanism.polygons[{i}].name", poly.name, "a name no part has (the polygon is cut as a part of that name)"
            )
        out.append((i, poly))
    return out


def pin_sites(
    rider_mm: Any,
    host_mm: Any,
    r_hole: float,
    wall: float,
    grows: bool = False,
    others: Any = None,
    apart: float = 0.0,
) -> tuple[tuple[float, float], tuple[float, float]] | None:
    """Two pin centres (mm, the host's own frame) with a hole of radius ``r_hole`` and ``wall`` of material round
    it in both the rider's outline and the host's material (outline minus its cuts), as far apart as possible and
    at least two holes plus a wall apart; ``None`` when there is no such room.

    ``grows``: the host is a rounded hull that widens round a new hole (:func:`planar.fabrication.parts.part_cuts`),
    so a pin may stand anywhere on its outline or, failing that, anywhere in the rider, clear of the host's cuts.
    ``others``: centres (mm) of the host's pins that the rider takes too; the two pins stand ``apart`` mm from them
    and from each other (their ends' width plus the clearance), as far as the pin holes' walls ask at least.
    """
    import shapely

    near = r_hole + wall + ROOM_MARGIN
    rider_room = rider_mm.buffer(-near, quad_segs=32)
    if others is not None and len(others):
        rider_room = rider_room.difference(shapely.union_all(shapely.buffer(shapely.points(others), apart, quad_segs=32)))
    if grows:
        cuts = shapely.Polygon(host_mm.exterior).difference(host_mm).buffer(near, quad_segs=32)
        tries = [shapely.Polygon(host_mm.exterior).difference(cuts), None]
    else:
        tries = [host_mm.buffer(-near, quad_segs=32)]
    for host_room in tries:
        room = rider_room if host_room is None else rider_room.intersection(host_room)
        if host_room is None:
            room = room.difference(cuts)
        got = _farthest(room, max(2 * r_hole + wall, apart))
        if got is not None:
            return got
    return None


def _farthest(room: Any, least: float) -> tuple[tuple[float, float], tuple[float, float]] | None:
    """The two points of ``room`` farthest apart (mm), when at least ``least`` apart."""
    import shapely

    if room.is_empty:
        return None
    pts = shapely.get_coordinates(shapely.segmentize(shapely.boundary(room), 0.25))
    if len(pts) < 2:
        return None
    pts = np.unique(np.round(pts, 6), axis=0)
    if len(pts) > 600:  # a bounded pairwise search: every k-th point
        pts = pts[np.linspace(0, len(pts) - 1, 600).astype(int)]
    d = np.hypot(*(pts[:, None, :] - pts[None, :, :]).transpose(2, 0, 1))
    i, j = np.unravel_index(int(np.argmax(d)), d.shape)
    if d[i, j] < least - 1e-9:
        return None
    a, b = sorted([(float(pts[i, 0]), float(pts[i, 1])), (float(pts[j, 0]), float(pts[j, 1]))])
    return a, b


class RiderView(PartsView):
    """A mechanism with its riders: each host part with two more pin holes, each rider a part with two pin holes,
    two pivots between them; the rider's pose is its host's at every sample.  Everything else is the wrapped
    mechanism's."""

    def __init__(self, mech: Any, parts: list[Part], joints: list[Any], hosts: dict[str, str]) -> None:
        super().__init__(mech, parts, joints)
        self.hosts = dict(hosts)

    def run(self, *args: Any, **kw: Any) -> Any:
        m = self._mech.run(*args, **kw)
        for rider, host in self.hosts.items():
            m.poses[rider] = np.array(m.poses[host], float, copy=True)
        return m


def with_riders(scene: Any, mech: Any, host_material: Any, s: Any) -> Any:
    """``mech`` with the scene's ``cut = "part"`` polygons as riders (``mech`` itself when there are none).

    ``host_material(name)``: the host part's cut material (mm, own frame) before its rider's pins; ``s``: the
    :class:`~planar.fabrication.parts.FabSettings`.  A polygon with no room for two pins on its host is an error
    naming it and the room it needs.
    """
    from shapely.geometry import Polygon

    from planar.fabrication.hardware import hardware_of
    from planar.fabrication.joints import FabricationError

    riders = rider_polygons(scene, mech)
    if not riders:
        return mech
    u = s.unit_mm
    parts = {p.name: p for p in mech.parts}
    order = [p.name for p in mech.parts]
    joints = list(mech.joints)
    hosts: dict[str, str] = {}
    r_hole = (s.pin_mm + s.clearance) / 2
    ends = hardware_of(s).ends(s.pin_mm, s.thickness_mm)
    apart = max(t.diameter for end in ends for t in end) + s.clearance + ROOM_MARGIN
    d = s.pin_mm / u
    for i, poly in riders:
        shape = Polygon([(x * u, y * u) for x, y in poly.points]).buffer(0)
        host = parts[poly.part]
        through = _pins_inside(host, shape, u, r_hole + s.min_wall)
        grows = host.polygon is None and s.widen
        sites = pin_sites(
            shape, host_material(poly.part), r_hole, s.min_wall, grows, np.array(through, float).reshape(-1, 2) * u, apart
        )
        if sites is None:
            raise FabricationError(
                f"mechanism.polygons[{i}] {poly.name!r}: no room for two {2 * r_hole:g} mm pin holes with "
                f"{s.min_wall:g} mm of wall in both it and {poly.part!r}; make it overlap its part by more "
                "(or cut = true to merge it into the part's outline)"
            )
        at = [(x / u, y / u) for x, y in sites]
        parts[poly.part] = dataclasses.replace(host, features=tuple(host.features) + tuple(Hole(c, d, "pin") for c in at))
        parts[poly.name] = Part(
            poly.name,
            (),
            tuple(Hole(c, d, "pin") for c in at + through),
            plane=host.plane,
            polygon=tuple((float(x), float(y)) for x, y in poly.points),
        )
        order.append(poly.name)
        joints += [Pivot(f"{poly.name}#{k + 1}", poly.part, poly.name, c, c) for k, c in enumerate(at)]
        # a host's pin under the rider goes on through it (one pin: host, rider and the host's other part)
        joints += [Pivot(f"{poly.name}@{k + 1}", poly.part, poly.name, c, c) for k, c in enumerate(through)]
        hosts[poly.name] = poly.part
    return RiderView(mech, [parts[n] for n in order], joints, hosts)


def _pins_inside(host: Part, rider_mm: Any, u: float, near: float) -> list[tuple[float, float]]:
    """The host's pin holes (model units, own frame) that lie in the rider with room for their hole and wall."""
    from shapely.geometry import Point

    room = rider_mm.buffer(-near, quad_segs=32)
    return [
        (float(f.centre[0]), float(f.centre[1]))
        for f in host.features
        if isinstance(f, Hole) and f.role == "pin" and room.contains(Point(f.centre[0] * u, f.centre[1] * u))
    ]
