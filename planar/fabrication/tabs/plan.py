"""The tab planner (:func:`plan_tabs`): the stack along z, each perpendicular plane's position, and the
tabs and slots of every joint (see :mod:`planar.fabrication.tabs`)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from planar.core.model import Mechanism, Part
from planar.fabrication.joints import FabricationError
from planar.fabrication.tabs.model import MIN_TABS, PLANES, TabJoin, TabPlan, _bodies, _joined
from planar.fabrication.tabs.shapes import _along, _and, _layer_footprint, _local, _place, _static_pose, _world


@dataclass
class _Stack:
    """What every step of :func:`plan_tabs` shares: the pieces, their tracks and poses (mm, mm, rad), the
    sizes (mm), each joined piece's side and face, the stack's lower face ``z_stack`` (mm), each piece's shape
    as cut so far and every perpendicular plane fixed so far."""

    parts: dict[str, Part]
    layers: dict[str, int | None]
    material: dict[str, Any]
    s: Any
    joined: dict[str, str]
    track: dict[str, np.ndarray]
    pose: dict[str, tuple[float, float, float]]
    samples: int
    touching: set[frozenset[str]]
    world: dict[str, Any] = field(default_factory=dict)
    sides: dict[str, int] = field(default_factory=dict)
    face: dict[str, float] = field(default_factory=dict)
    z_stack: float = 0.0
    shape: dict[str, Any] = field(default_factory=dict)
    fixed_at: dict[str, float] = field(default_factory=dict)

    @property
    def t(self) -> float:
        return float(self.s.thickness_mm)

    @property
    def w(self) -> float:
        return 2 * self.s.thickness_mm

    @property
    def hw(self) -> float:
        return (self.s.thickness_mm + self.s.clearance) / 2

    @property
    def wall(self) -> float:
        return float(self.s.min_wall)

    @property
    def perp(self) -> list[str]:
        return [n for n, p in self.parts.items() if p.plane in PLANES]

    @property
    def xy(self) -> list[str]:
        return [n for n, p in self.parts.items() if p.plane == "xy"]

    def layer(self, n: str) -> int:
        return self.layers.get(n) or 0

    def band(self, r: str) -> Any:
        """Piece ``r``'s layer along z as a strip (mm), a hundredth of a millimetre inside its faces."""
        from shapely.geometry import box

        lz = self.layer(r) * self.s.thickness_mm + self.z_stack
        return box(-1e5, lz + 0.01, 1e5, lz + self.s.thickness_mm - 0.01)

    def footprint(self, n: str, at: float, r: str) -> Any:
        """Where piece ``n`` (its plane at ``at``, mm) passes through ``r``'s layer over the cycle, ``r``'s frame."""
        return _layer_footprint(
            self.shape[n], self.parts[n].plane, at, self.track[n], self.track[r], self.band(r), self.s.thickness_mm
        )


def plan_tabs(mech: Mechanism, layers: dict[str, int | None], material: dict[str, Any], s: Any, samples: int = 48) -> TabPlan:
    """Tab joints of every perpendicular piece that is rigid with an xy piece, and travel slots for every
    perpendicular piece passing through another xy layer (see the module docstring).

    ``layers``: each piece's layer in its plane; ``material``: each piece's nominal material (mm, own frame).
    """
    parts = {p.name: p for p in mech.parts}
    if not any(p.plane in PLANES for p in parts.values()) or not any(p.plane == "xy" for p in parts.values()):
        return TabPlan()
    bodies = _bodies(mech)
    joined = _joined(mech, bodies)
    if not joined:
        return TabPlan()
    u = s.unit_mm
    motion = mech.run(samples_per_cycle=samples)
    ok = np.flatnonzero(motion.valid)
    ok = ok if ok.size else np.arange(len(motion))
    track = {n: np.asarray(motion.poses[n], float)[ok] * [u, u, 1.0] for n in parts}
    pose: dict[str, tuple[float, float, float]] = {
        n: (float(track[n][0, 0]), float(track[n][0, 1]), float(track[n][0, 2])) for n in parts
    }
    _check_rigid(parts, joined, track)
    c = _Stack(parts, layers, material, s, joined, track, pose, len(ok), {frozenset((j.a, j.b)) for j in mech.joints})
    _place_stack(c, mech)
    c.shape = dict(material)  # each piece as cut (a tab-joined one: cut flat along its edge, tabs added)
    # pieces whose plane is fixed already (a yz piece at its x) keep their way through the layers clear
    c.fixed_at = {n: parts[n].offset * u for n in c.perp if parts[n].plane == "yz" and n not in joined}
    out: list[TabJoin] = []
    for pl in PLANES:
        mine = [n for n in joined if parts[n].plane == pl]
        if mine:
            _plan_plane(c, pl, mine, out)
    return TabPlan(out, {}, [], c.z_stack, c.fixed_at, track, c.shape)


def _check_rigid(parts: dict[str, Part], joined: dict[str, str], track: dict[str, np.ndarray]) -> None:
    """Refuse a joined piece that moves across its xy piece or slides along the line where they meet."""
    for n, q in joined.items():
        pl = parts[n].plane
        k = 1 if pl == "xz" else 0  # the xy coordinate across the perpendicular plane (y for xz, x for yz)
        _static_pose(track[n], f"part {n!r} ({pl})", (1, 2))
        _static_pose(track[q], f"part {q!r}, the xy piece {n!r} stands on", (k, 2))
        shift = track[n][:, 0] - track[q][:, 1 - k]
        if float(np.ptp(shift)) > 1e-6:
            raise FabricationError(
                f"part {n!r} ({pl}) does not move with {q!r} along the line where they meet; it cannot be tab-joined"
            )


def _place_stack(c: _Stack, mech: Mechanism) -> None:
    """Each joined piece's side and face, and the stack's lower face ``c.z_stack`` along the model's z (mm).

    The stack along z: layer k of the xy plane between z0 + k t and z0 + (k + 1) t (mm).  The model's xy
    plane (z = 0: where the #8 driver slides and the #6/#9 pin meets its driver's edge) is the mid-plane of
    the layer the perpendicular stages ride on, as near as the pieces' cuts allow: a piece below the stack
    (the model's -z side, where the #8 plates and the #6/#9 axles hang) stands on its xy piece's lower face,
    one above on its upper face, and keeps min_wall between its edge and its own cuts.
    """
    from shapely.geometry import Polygon

    t, wall, joined, perp, xy = c.s.thickness_mm, c.s.min_wall, c.joined, c.perp, c.xy
    c.world = {n: _world(c.material[n], c.pose[n]) for n in perp}
    c.sides = {n: 1 if c.world[n].centroid.y > 0 else -1 for n in joined}
    c.face = {n: ((c.layers.get(joined[n]) or 0) + (1 if c.sides[n] > 0 else 0)) * t for n in joined}
    lo_b, hi_b = [-math.inf], [math.inf]
    for n in joined:
        cuts = [Polygon(r) for r in c.world[n].interiors]
        if cuts and c.sides[n] < 0:
            lo_b.append(max(q.bounds[3] for q in cuts) + wall - c.face[n])
        elif cuts:
            hi_b.append(min(q.bounds[1] for q in cuts) - wall - c.face[n])
    if max(lo_b) > min(hi_b):
        raise FabricationError(
            "the pieces standing perpendicular to the xy stack need it both higher and lower "
            "for their cuts' walls; they cannot be tab-joined"
        )
    riders = {joined[n] for n in joined if not c.parts[n].ground}
    riders |= {j.a for j in mech.joints if getattr(j, "b", None) in perp and getattr(j, "a", None) in xy}
    ride = [c.layers.get(n) or 0 for n in sorted(riders)] or [0]
    target = -(float(np.mean(ride)) + 0.5) * t
    c.z_stack = min(max(target, max(lo_b)), min(hi_b))


def _plan_plane(c: _Stack, pl: str, mine: list[str], out: list[TabJoin]) -> None:
    """Tab joints of plane ``pl``'s joined pieces ``mine``, appended to ``out``; their shapes and planes fixed."""
    import shapely

    edges = _edges(c, pl, mine)
    keepout = {
        q: shapely.union_all([c.footprint(m, a, q) for m, a in c.fixed_at.items()]).buffer(c.s.clearance)
        for q in set(c.joined.values())
    }
    regions = _regions(c, mine, keepout)
    turned_of: dict[str, Any] = {}
    candidates = _candidates(c, pl, mine)
    # an xz plane's way through the other layers (each piece's body, cut flat, within each xy layer's band
    # at each sample): where it must cut a travel slot, the slot must keep its walls too
    ways = _ways(c, edges) if pl == "xz" else {}
    ats, plan = _choose(c, pl, mine, edges, candidates, regions, turned_of, ways)
    if pl == "xz":  # every xz piece's plane, joined or not, in the layer order
        t = c.s.thickness_mm
        y0 = next(ats[n] - ((c.layers.get(n) or 0) + 0.5) * t for n in mine)
        c.fixed_at.update(
            {n: y0 + ((c.layers.get(n) or 0) + 0.5) * t for n in c.perp if c.parts[n].plane == "xz" and n not in c.joined}
        )
    for n in mine:
        c.fixed_at[n] = ats[n]
        jn = _tab_join(c, pl, n, edges[n], ats[n], plan[n], f"T{len(out) + 1}")
        out.append(jn)
        c.shape[n] = shapely.union_all([c.material[n].intersection(jn.keep)] + jn.tabs)


def _edges(c: _Stack, pl: str, mine: list[str]) -> dict[str, tuple[int, float, list[tuple[float, float]], Any]]:
    """Each piece's edge: its side, the world z of its xy piece's layer face (mm), the intervals along the
    line where the tab's root has a wall's depth of material behind the edge, and the half-plane it keeps."""
    from shapely.geometry import box

    wall = c.s.min_wall
    edges: dict[str, tuple[int, float, list[tuple[float, float]], Any]] = {}
    for n in mine:
        mat = c.world[n]
        side = c.sides[n]
        x0, z0, x1, z1 = mat.bounds
        ze = c.z_stack + c.face[n]
        if (side > 0 and z0 > ze + 1e-6) or (side < 0 and z1 < ze - 1e-6):
            raise FabricationError(
                f"part {n!r} ({pl}): it does not reach the face of {c.joined[n]!r} (z = "
                f"{ze:.3g} mm), where it would stand on it; it cannot be tab-joined"
            )
        keep = box(x0 - 1, ze, x1 + 1, z1 + 1) if side > 0 else box(x0 - 1, z0 - 1, x1 + 1, ze)
        root = mat.intersection(keep)
        # the tab's root: solid material for a wall's depth behind the edge
        iv = _along(root, ze + side * wall / 2, wall / 2 - 1e-3, x0 - 1, x1 + 1)
        edges[n] = (side, ze, iv, keep)
    return edges


def _regions(c: _Stack, mine: list[str], keepout: dict[str, Any]) -> dict[str, Any]:
    """Where each xy piece has room for a slot on a line (its frame: through its pose)."""
    import shapely
    from shapely.geometry import Polygon, box

    t, wall = c.s.thickness_mm, c.s.min_wall
    regions: dict[str, Any] = {}
    for q in {c.joined[n] for n in mine}:
        qm = c.material[q]
        holes = (
            [Polygon(r) for r in qm.interiors]
            if qm.geom_type == "Polygon"
            else [Polygon(r) for g_ in qm.geoms for r in g_.interiors]
        )
        if not keepout[q].is_empty:
            holes.append(keepout[q])
        if c.parts[q].polygon is None and c.s.widen:  # a hull grows to hold its slots: only its cuts matter
            region = box(*qm.buffer(10 * (t + wall) + 50).bounds)
        else:
            region = qm.buffer(-wall)
            region = Polygon(region.exterior) if region.geom_type == "Polygon" else region
        regions[q] = region.difference(shapely.union_all([h.buffer(wall) for h in holes])) if holes else region
    return regions


def _room(c: _Stack, pl: str, regions: dict[str, Any], turned_of: dict[str, Any], n: str, at: float) -> list[tuple[float, float]]:
    """The intervals (world coordinate along the line, mm) where piece ``n``'s xy piece has room for a slot
    on the line where the planes meet, the plane at ``at`` (mm)."""
    from shapely import affinity
    from shapely.geometry import LineString

    q = c.joined[n]
    # the line where the planes meet, in the xy piece's frame, as a strip of half-width hw
    lo, hi = -1e4, 1e4
    line = LineString([(lo, at), (hi, at)]) if pl == "xz" else LineString([(at, lo), (at, hi)])
    local = _local(line, c.pose[q])
    (a0, b0), (a1, b1) = np.asarray(local.coords)
    ang = math.atan2(b1 - b0, a1 - a0)
    # turn the xy piece's frame so the line runs along x at height `level`
    if q not in turned_of:
        turned_of[q] = affinity.rotate(regions[q], -ang, origin=(0, 0), use_radians=True)
    turned = turned_of[q]
    p0 = affinity.rotate(local, -ang, origin=(0, 0), use_radians=True)
    level = float(np.asarray(p0.coords)[0, 1])
    iv = _along(turned, level, c.hw, -1e4, 1e4)
    # back to the world coordinate along the line (the line runs lo -> hi)
    offset = lo - float(np.asarray(p0.coords)[0, 0])
    return [(a + offset, b + offset) for a, b in iv]


def _candidates(c: _Stack, pl: str, mine: list[str]) -> list[dict[str, float]]:
    """The plane positions to try, nearest first (mm: y for xz, x for yz)."""
    t, u = c.s.thickness_mm, c.s.unit_mm
    if pl == "yz":  # the yz pieces stay at their x: each bracket stands beside its piece
        ats = {}
        for n in mine:
            ref = n[len("frame.yz.") :] if n.startswith("frame.yz.") and n[len("frame.yz.") :] in c.parts else n
            ats[n] = c.parts[ref].offset * u + ((c.layers.get(n) or 0) - (c.layers.get(ref) or 0)) * t
        return [ats]
    steps = [0.0] + [sgn * 0.5 * k for k in range(1, 121) for sgn in (1, -1)]  # up to 60 mm either way
    return [{n: y0 + ((c.layers.get(n) or 0) + 0.5) * t for n in mine} for y0 in steps]


def _ways(c: _Stack, edges: dict[str, Any]) -> dict[tuple[str, str], list[tuple[int, float, float]]]:
    """Each xz piece's way through each other xy layer: (sample, lowest x, highest x) wherever it has area."""
    ways: dict[tuple[str, str], list[tuple[int, float, float]]] = {}
    for n in (m for m in c.perp if c.parts[m].plane == "xz"):
        body = c.material[n].intersection(_local(edges[n][3], c.pose[n])) if n in edges else c.material[n]
        body = body.simplify(0.05)
        for r in c.xy:
            if r == c.joined.get(n) or frozenset((n, r)) in c.touching:
                continue
            bd = c.band(r)
            got = [(k, _world(body, tuple(c.track[n][k])).intersection(bd)) for k in range(c.samples)]
            hits = [(k, g_.bounds[0], g_.bounds[2]) for k, g_ in got if g_.area > 1e-6]
            if hits:
                ways[(n, r)] = hits
    return ways


def _choose(
    c: _Stack,
    pl: str,
    mine: list[str],
    edges: dict[str, Any],
    candidates: list[dict[str, float]],
    regions: dict[str, Any],
    turned_of: dict[str, Any],
    ways: dict[tuple[str, str], list[tuple[int, float, float]]],
) -> tuple[dict[str, float], dict[str, list[float]]]:
    """The first candidate plane position where every piece has room for its tabs and every travel slot keeps
    its walls, and the tabs' centres there (mm along the line); refused with the constraint that blocks."""
    from shapely.geometry import Polygon

    t, w, wall = c.s.thickness_mm, c.w, c.s.min_wall
    xy, material = c.xy, c.material
    walls_of = {r: [Polygon(h) for h in material[r].interiors] for r in xy if material[r].geom_type == "Polygon"}
    failed: str | None = None
    blocked = False
    for ats in candidates:
        plan = {}
        for n in mine:
            centres = _place(_and(edges[n][2], _room(c, pl, regions, turned_of, n, ats[n])), w, w)
            if len(centres) < MIN_TABS:
                failed = failed or n  # the first piece that failed at the model's own position
                break
            plan[n] = centres
        else:
            if pl == "xz" and ways:
                y0 = next(ats[n] - ((c.layers.get(n) or 0) + 0.5) * t for n in mine)
                y_of = {m: y0 + ((c.layers.get(m) or 0) + 0.5) * t for m in c.perp if c.parts[m].plane == "xz"}
                if not _clear_way(c, y_of, plan, ways, walls_of):
                    blocked = True
                    continue
            return ats, plan
    if blocked:
        raise FabricationError(
            f"parts {', '.join(repr(n) for n in mine)} ({pl}): wherever their tabs have room, "
            "the travel slots the pieces of this plane need through the other layers would run "
            f"into other cuts (less than {wall:g} mm between); they cannot be tab-joined "
            "(a larger unit_mm or a thinner sheet)"
        )
    n = failed or mine[0]
    raise FabricationError(
        f"part {n!r} ({pl}): no line where it meets {c.joined[n]!r} has room for "
        f"{MIN_TABS} tabs {w:g} mm wide with {wall:g} mm of material round their slots; "
        "it cannot be tab-joined (a larger unit_mm or a thinner sheet)"
    )


def _clear_way(
    c: _Stack,
    y_of: dict[str, float],
    plan: dict[str, list[float]],
    ways: dict[tuple[str, str], list[tuple[int, float, float]]],
    walls_of: dict[str, list[Any]],
) -> bool:
    """Whether every travel slot the xz pieces (planes at ``y_of``, mm) need keeps ``min_wall`` from the other
    cuts, the tab slots of ``plan`` included."""
    from shapely.geometry import box

    w, hw = c.w, c.hw
    slots_of: dict[str, list[Any]] = {}
    for m, cs in plan.items():
        slots_of.setdefault(c.joined[m], []).extend(
            _local(box(x - w / 2, y_of[m] - hw, x + w / 2, y_of[m] + hw), c.pose[c.joined[m]]) for x in cs
        )
    rects = _way_rects(c, y_of, ways, slots_of)
    return all(_rects_clear(c, r, rs, walls_of, slots_of) for r, rs in rects.items())


def _way_rects(
    c: _Stack,
    y_of: dict[str, float],
    ways: dict[tuple[str, str], list[tuple[int, float, float]]],
    slots_of: dict[str, list[Any]],
) -> dict[str, list[Any]]:
    """The travel slots (xy piece -> rectangles, its frame, mm) of the ways that cross its material."""
    import shapely
    from shapely.geometry import box

    t, wall, material = c.s.thickness_mm, c.s.min_wall, c.material
    rects: dict[str, list[Any]] = {}
    for (n, r), hits in ways.items():
        at = y_of[n]
        foot = shapely.union_all([_local(box(a, at - t / 2, b, at + t / 2), tuple(c.track[r][k])) for k, a, b in hits])
        # a hull piece grows round its slots: its material is then at least their hull's
        hull = c.parts[r].polygon is None and c.s.widen
        where = (
            shapely.union_all([material[r]] + [q.buffer(wall) for q in slots_of.get(r, [])]).convex_hull if hull else material[r]
        )
        if foot.intersection(where).area <= 0.5:
            continue
        rects.setdefault(r, []).append(foot.buffer(c.s.clearance, join_style="mitre").minimum_rotated_rectangle)
    return rects


def _rects_clear(c: _Stack, r: str, rs: list[Any], walls_of: dict[str, list[Any]], slots_of: dict[str, list[Any]]) -> bool:
    """Whether piece ``r``'s travel slots ``rs`` (side by side, two ways are one slot: merge_travel) keep
    ``min_wall`` from its cuts and tab slots, and lie inside an explicit outline."""
    import shapely

    wall, material = c.s.min_wall, c.material
    merged = shapely.union_all([q.buffer(wall / 2) for q in rs])
    for g_ in getattr(merged, "geoms", [merged]):
        rect = g_.minimum_rotated_rectangle
        if any(rect.distance(h) < wall for h in walls_of.get(r, [])):
            return False
        if c.parts[r].polygon is not None and not material[r].buffer(-wall).convex_hull.contains(rect):
            return False
        if any(q.distance(rect) < wall for q in slots_of.get(r, [])):
            return False
    return True


def _tab_join(
    c: _Stack,
    pl: str,
    n: str,
    edge: tuple[int, float, list[tuple[float, float]], Any],
    at: float,
    centres: list[float],
    letter: str,
) -> TabJoin:
    """Piece ``n``'s tab joint: its tabs (own frame) at ``centres`` along the line (mm), the plane at ``at``
    (mm), and the slots in its xy piece (that piece's frame)."""
    from shapely.geometry import box

    t, w = c.s.thickness_mm, c.w
    side, ze, _, keep = edge
    q = c.joined[n]
    spans = [(x - w / 2, x + w / 2) for x in centres]
    tabs = [box(a, ze - t, b, ze + 0.01) if side > 0 else box(a, ze - 0.01, b, ze + t) for a, b in spans]
    slots = []
    for x in centres:
        wc = (x, at) if pl == "xz" else (at, x)
        qx, qy, qa = c.pose[q]
        cs, sn = math.cos(qa), math.sin(qa)
        dx, dy = wc[0] - qx, wc[1] - qy
        centre = (cs * dx + sn * dy, -sn * dx + cs * dy)
        along = (0.0 if pl == "xz" else math.pi / 2) - qa
        slots.append((centre, along))
    return TabJoin(
        letter,
        n,
        q,
        pl,
        float(at),
        side,
        ze,
        spans,
        w,
        (w + c.s.clearance, t + c.s.clearance),
        slots,
        _local(keep, c.pose[n]),
        [_local(tb, c.pose[n]) for tb in tabs],
    )
