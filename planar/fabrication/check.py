"""The build check: the cut parts, placed in their layers, moved through the cycle (a swept 2.5-D collision check).

Every part is its cut material (outline minus holes and slots, kerf removed: the
nominal shape, mm, own frame) in its layer's z-range ``[layer t, (layer + 1) t]``
(``t`` the sheet thickness).  Every pin is a disc of its diameter in the z-range of
the layers it spans, with an end (a head, a washer and clip, a nut: its height and
diameter from :mod:`planar.fabrication.hardware`) in the range just beyond each side;
a spacer ring is a disc of its outer diameter in its layer; the motor shaft rises
from below the bottom layer to its top end.  At every sample of the motion:

* two parts on one layer that overlap (by more than ``AREA_MM2``) collide;
* a pin (its path between samples swept as a stadium) must overlap no part's
  material on a layer it spans: it passes only through its own parts' holes and
  slots;
* a pin's ends and spacers must overlap no part on the layers they occupy;
* two pins whose z-ranges meet must stay a diameter plus the clearance apart
  (shafts), and their ends their ends' diameter apart.

All of it is shapely 2's vectorised functions over arrays of geometries (one array
per part: its material at every sample), no Python loop over samples.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

__all__ = ["AREA_MM2", "BodyZ", "Violation", "build_check", "check_bodies", "placed_array"]

#: overlaps smaller than this (mm^2) are the polygon approximation of arcs, not a collision
AREA_MM2 = 0.05


@dataclass(frozen=True)
class Violation:
    """Two bodies that collide: ``what`` (``"parts overlap"``, ``"pin through part"``, ...), the pair, the layer
    (1 = bottom) and the first sample where they do (index into the check's samples), and how many samples."""

    what: str
    a: str
    b: str
    layer: int
    sample: int
    count: int
    depth: float
    #: where (world, mm) at the first sample: the overlap's centroid or the midpoint between the pins
    at: tuple[float, float] = (0.0, 0.0)

    def text(self) -> str:
        return (
            f"{self.what}: {self.a} and {self.b} on layer {self.layer}, first at sample {self.sample} "
            f"({self.count} sample(s), up to {self.depth:.2f} mm^2)"
        )


@dataclass
class BodyZ:
    """One body of the check: its footprint at every sample (shapely array, mm, world) and its z-range (mm)."""

    name: str
    shapes: Any
    z0: float
    z1: float
    kind: str  # "part", "pin", "end", "spacer", "shaft"
    #: names of bodies this body may overlap (a pin's own parts: checked at the samples by :func:`_in_own_holes`)
    owner: tuple[str, ...] = ()
    #: a round body's centre at every sample (mm) and its radius (mm): pins, ends, spacers
    track: Any = None
    radius: float = 0.0


def placed_array(poly: Any, poses: np.ndarray, u: float) -> Any:
    """``poly`` (own frame, mm) placed at every pose ``(x, y, angle)`` (model units, rad): an array of polygons.

    One vectorised construction: the rings' coordinates are rotated and moved for all samples at once
    (numpy), and shapely 2 builds the N polygons from the (N, m, 2) arrays.
    """
    import shapely

    polys = shapely.get_parts(poly)
    c, s = np.cos(poses[:, 2])[:, None], np.sin(poses[:, 2])[:, None]
    dx, dy = (poses[:, 0] * u)[:, None], (poses[:, 1] * u)[:, None]

    def move(ring: Any) -> Any:
        xy = shapely.get_coordinates(ring)
        x = c * xy[:, 0] - s * xy[:, 1] + dx
        y = s * xy[:, 0] + c * xy[:, 1] + dy
        return shapely.linearrings(np.stack([x, y], axis=-1))

    out = []
    for p in polys:
        shell = move(shapely.get_exterior_ring(p))
        holes = [move(shapely.get_interior_ring(p, i)) for i in range(shapely.get_num_interior_rings(p))]
        out.append(shapely.polygons(shell, np.stack(holes, axis=1) if holes else None))
    if len(out) == 1:
        return out[0]
    return shapely.multipolygons(np.stack(out, axis=1))


def _overlap(a: BodyZ, b: BodyZ, t: float) -> tuple[np.ndarray, int, np.ndarray] | None:
    """Per-sample overlap area of two bodies whose z-ranges meet (None when they cannot touch)."""
    import shapely

    if min(a.z1, b.z1) - max(a.z0, b.z0) <= 1e-9:
        return None
    ab = shapely.intersects(a.shapes, b.shapes)
    if not ab.any():
        return None
    area = np.zeros(len(ab))
    common = shapely.intersection(a.shapes[ab], b.shapes[ab])
    area[ab] = shapely.area(common)
    layer = int(math.floor(max(a.z0, b.z0) / t + 1e-9)) + 1
    where = np.full((len(ab), 2), np.nan)
    where[ab] = shapely.get_coordinates(shapely.centroid(common))
    return area, layer, where


def _too_close(a: BodyZ, b: BodyZ, clearance: float, t: float) -> Violation | None:
    """Two round bodies (pins, ends, spacers) whose z-ranges meet closer than their radii plus ``clearance``."""
    if min(a.z1, b.z1) - max(a.z0, b.z0) <= 1e-9:
        return None
    gap = np.hypot(*(a.track - b.track).T) - (a.radius + b.radius + clearance)
    bad = np.flatnonzero(gap < -1e-6)
    if not bad.size:
        return None
    layer = int(math.floor(max(a.z0, b.z0) / t + 1e-9)) + 1
    mid = (a.track[bad[0]] + b.track[bad[0]]) / 2
    return Violation(
        "pins collide", a.name, b.name, layer, int(bad[0]), int(bad.size), float(-gap.min()), (float(mid[0]), float(mid[1]))
    )


def check_bodies(
    bodies: list[BodyZ], t: float, skip: set[frozenset[str]] | None = None, clearance: float = 0.0
) -> list[Violation]:
    """Every pair of bodies whose z-ranges meet and whose footprints overlap at some sample (``skip``: pairs
    allowed to: joined parts touching in one layer); two round bodies (pins, their ends and spacers) closer than
    their radii plus ``clearance`` (mm).  ``depth`` is an area (mm^2) for footprints, a distance (mm) for round ones."""
    import shapely

    skip = skip or set()
    out: list[Violation] = []
    boxes = [shapely.total_bounds(b.shapes) for b in bodies]
    for i, a in enumerate(bodies):
        for j in range(i + 1, len(bodies)):
            b = bodies[j]
            if frozenset((a.name, b.name)) in skip or b.name in a.owner or a.name in b.owner:
                continue
            if a.track is not None and b.track is not None:
                v = _too_close(a, b, clearance, t)
                if v is not None:
                    out.append(v)
                continue
            ba, bb = boxes[i], boxes[j]
            if ba[2] < bb[0] or bb[2] < ba[0] or ba[3] < bb[1] or bb[3] < ba[1]:
                continue
            got = _overlap(a, b, t)
            if got is None:
                continue
            area, layer, where = got
            bad = np.flatnonzero(area > AREA_MM2)
            if bad.size:
                what = _what(a.kind, b.kind)
                at = (float(where[bad[0], 0]), float(where[bad[0], 1]))
                out.append(Violation(what, a.name, b.name, layer, int(bad[0]), int(bad.size), float(area.max()), at))
    return out


def _what(ka: str, kb: str) -> str:
    kinds = {ka, kb}
    if kinds == {"part"}:
        return "parts overlap"
    if "part" in kinds:
        other = (kinds - {"part"}).pop()
        return {"pin": "pin through part", "end": "pin end strikes part", "spacer": "spacer strikes part"}.get(
            other, "motor shaft through part"
        )
    return "pins collide"


def _track(poses: np.ndarray, at: tuple[float, float], u: float) -> np.ndarray:
    """World position (mm) of the point ``at`` (own frame, model units) at every pose."""
    c, s = np.cos(poses[:, 2]), np.sin(poses[:, 2])
    return np.c_[poses[:, 0] + c * at[0] - s * at[1], poses[:, 1] + s * at[0] + c * at[1]] * u


def _swept_discs(xy: np.ndarray, r: float) -> Any:
    """The disc of radius ``r`` swept from each sample to the next (a stadium per sample, the last to the first)."""
    import shapely

    nxt = np.roll(xy, -1, axis=0)
    segs = shapely.linestrings(np.stack([xy, nxt], axis=1))
    return shapely.buffer(segs, r, quad_segs=8)


def build_check(fab: Any, samples: int = 240) -> list[Violation]:
    """The build check of a :class:`~planar.fabrication.build.Fabrication` over ``samples`` samples of its cycle.

    Reads the fabrication's own geometry (``fab.own``: each part's nominal material, mm, own frame), its
    assembly plan (layers, pins, spacers, the ends of :mod:`planar.fabrication.hardware`) and the cut mechanism's
    motion.  Returns every colliding pair, in a fixed order (empty: it goes together and moves).  Parts standing
    perpendicular to the xy stack (tabbed pieces) are not in it.
    """
    mech, asm, s = fab.mechanism, fab.assembly, fab.settings
    if mech is None:
        return []
    motion = mech.run(samples_per_cycle=samples)
    ok = np.flatnonzero(motion.valid)
    if ok.size == 0:
        return []
    poses = {n: np.asarray(motion.poses[n], float)[ok] for n in fab.own}
    parts = part_bodies(fab.own, asm.layers, asm.plane, poses, s.unit_mm, s.thickness_mm)
    by_name = {b.name: b for b in parts}
    bodies = list(parts)
    out: list[Violation] = []
    for pp in asm.pins:
        if asm.plane.get(pp.parts[0], "xy") != "xy":
            continue  # a pin between pieces standing perpendicular: not in the xy stack
        own = {asm.layers[p] for p in pp.parts if asm.layers.get(p) is not None}
        bodies += pin_bodies(pp, poses, s, own)
        out += _in_own_holes(pp, poses, s, by_name)
    skip = {frozenset(c.parts) for c in asm.contacts}
    return out + check_bodies(bodies, s.thickness_mm, skip, s.clearance)


def part_bodies(
    own: dict[str, Any],
    layers: dict[str, int | None],
    plane: dict[str, str],
    poses: dict[str, np.ndarray],
    u: float,
    t: float,
) -> list[BodyZ]:
    """Each flat part's material at every sample in its layer's z-range (layers from 0, ``t`` mm each)."""
    out = []
    for name, mat in own.items():
        layer = layers.get(name)
        if layer is None or plane.get(name, "xy") != "xy" or mat.is_empty:
            continue
        out.append(BodyZ(name, placed_array(mat.simplify(0.01), poses[name], u), layer * t, (layer + 1) * t, "part"))
    return out


def _in_own_holes(pp: Any, poses: dict[str, np.ndarray], s: Any, parts: dict[str, BodyZ]) -> list[Violation]:
    """The pin's disc at each sample against its own parts' material: it must lie in their holes and slots."""
    import shapely

    xy = _track(poses[pp.spec.parts[0]], pp.spec.at[0], s.unit_mm)
    # a D shaft fits its D hole exactly: the disc inside its flat (centre to flat: flat_mm - shaft_mm / 2)
    r = min(s.shaft_mm / 2, s.shaft_flat_mm - s.shaft_mm / 2) - 0.01 if pp.shaft else pp.diameter_mm / 2
    disc = shapely.buffer(shapely.points(xy), r, quad_segs=8)
    out = []
    for p in pp.parts:
        body = parts.get(p)
        if body is None:
            continue
        area = shapely.area(shapely.intersection(disc, body.shapes))
        bad = np.flatnonzero(area > AREA_MM2)
        if bad.size:
            layer = int(round(body.z0 / s.thickness_mm)) + 1
            what = "motor shaft outside its hole" if pp.shaft else "pin outside its hole or slot"
            at = (float(xy[bad[0], 0]), float(xy[bad[0], 1]))
            out.append(Violation(what, _pin_name(pp), p, layer, int(bad[0]), int(bad.size), float(area.max()), at))
    return out


def _pin_name(pp: Any) -> str:
    return f"{'motor shaft' if pp.shaft else 'pin'} {pp.letter}"


def pin_bodies(pp: Any, poses: dict[str, np.ndarray], s: Any, own_layers: set[int]) -> list[BodyZ]:
    """A pin's shaft (swept between samples), its two ends and its spacer rings as bodies of the check."""
    from planar.fabrication.hardware import pin_ends

    u, t = s.unit_mm, s.thickness_mm
    lo, hi = pp.layers or (0, 0)
    xy = _track(poses[pp.spec.parts[0]], pp.spec.at[0], u)
    name = _pin_name(pp)
    z0 = -1e3 if pp.shaft else lo * t  # the motor shaft rises from the motor under the bottom layer
    r = (s.shaft_mm if pp.shaft else pp.diameter_mm) / 2
    kind = "shaft" if pp.shaft else "pin"
    out = [BodyZ(name, _swept_discs(xy, r), z0, (hi + 1) * t, kind, tuple(pp.parts), xy, r)]
    lower, upper = pin_ends(s, pp)
    out += _end_bodies(f"{name} lower end", lower, xy, lo * t, -1.0, name)
    out += _end_bodies(f"{name} upper end", upper, xy, (hi + 1) * t, 1.0, name)
    ro = spacer_radius(s)
    for layer in range(lo, hi + 1):
        if layer not in own_layers:
            out.append(
                BodyZ(
                    f"{name} spacer",
                    _swept_discs(xy, ro),
                    layer * t,
                    (layer + 1) * t,
                    "spacer",
                    (name,),
                    xy,
                    ro,
                )
            )
    return out


def _end_bodies(name: str, end: Any, xy: np.ndarray, face: float, side: float, pin: str) -> list[BodyZ]:
    """A pin's end as bodies of the check: each tier (:class:`~planar.fabrication.hardware.Tier`) a disc swept
    between samples, from the tier before it (or the stack's ``face``, mm) out to its height, on ``side`` (-1
    below the stack, +1 above).  Every tier is named as the end, so a strike reads ``pin B upper end``."""
    out = []
    z = 0.0
    for tr in end:
        if tr.height > z + 1e-9:
            a, b = sorted((face + side * z, face + side * tr.height))
            r = tr.diameter / 2
            out.append(BodyZ(name, _swept_discs(xy, r), a, b, "end", (pin,), xy, r))
            z = tr.height
    return out


def spacer_radius(s: Any) -> float:
    """A spacer ring's outer radius (mm): the pin's hole plus a wall, at least half the smallest part."""
    return max((s.pin_mm + s.clearance) / 2 + s.min_wall, s.min_part / 2)
