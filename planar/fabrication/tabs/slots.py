"""Cuts in the xy pieces: travel slots where a perpendicular piece passes through a layer, merged where
their walls would be too thin, and the tab joints' slots."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from planar.core.model import Mechanism
from planar.fabrication.parts import Feature
from planar.fabrication.tabs.model import TabJoin, TabPlan
from planar.fabrication.tabs.shapes import _layer_footprint


def travel_slots(
    mech: Mechanism, layers: dict[str, int | None], material: dict[str, Any], s: Any, plan: TabPlan
) -> tuple[dict[str, list[Feature]], list[str]]:
    """Travel slots (xy piece -> cuts, mm) for perpendicular pieces that pass through another xy piece's layer
    where it has material (``material``: as cut so far), and a note for each; pieces joined by a joint
    (the #6/#9 pin on its driver's edge) touch by design and get none."""
    from shapely.geometry import box

    parts = {p.name: p for p in mech.parts}
    t = s.thickness_mm
    joined = {jn.piece: jn.base for jn in plan.joins}
    touching = {frozenset((j.a, j.b)) for j in mech.joints}
    track = plan.track

    def footprint(n: str, at: float, r: str) -> Any:
        lz = (layers.get(r) or 0) * t + plan.z_stack
        return _layer_footprint(
            plan.shape[n], parts[n].plane, at, track[n], track[r], box(-1e5, lz + 0.01, 1e5, lz + t - 0.01), t
        )

    out: dict[str, list[Feature]] = {}
    notes: list[str] = []
    for n, at in plan.planes.items():
        for r in (q for q, p in parts.items() if p.plane == "xy"):
            if r == joined.get(n) or frozenset((n, r)) in touching:
                continue  # its tabs go through their own slots; a contact touches on purpose
            foot = footprint(n, at, r)
            if foot.is_empty or foot.intersection(material[r]).area <= 0.5:
                continue
            rect = foot.buffer(s.clearance, join_style="mitre").minimum_rotated_rectangle
            length, width, ang = _rect_sides(rect)
            c = rect.centroid
            out.setdefault(r, []).append(
                Feature("rect", f"travel slot for {n}", (float(c.x), float(c.y)), width / 2, R=length / 2, t0=ang)
            )
            notes.append(
                f"{r}: a travel slot {length:.1f} x {width:.1f} mm for {n} ({parts[n].plane}), which passes through its layer"
            )
    return out, notes


def merge_travel(feats: list[Feature], wall: float) -> list[Feature]:
    """Travel slots closer than ``wall`` to each other (two perpendicular pieces side by side) as one slot:
    the smallest rectangle round both."""
    from planar.fabrication.sheet import cut_polygon

    out = list(feats)
    merged = True
    while merged:
        merged = False
        for i in range(len(out)):
            for j in range(i + 1, len(out)):
                a, b = cut_polygon(out[i].cut(0.0)), cut_polygon(out[j].cut(0.0))
                if a.distance(b) < wall:
                    rect = a.union(b).minimum_rotated_rectangle
                    length, width, ang = _rect_sides(rect)
                    c = rect.centroid
                    what = out[i].what + " and " + out[j].what.removeprefix("travel slot for ")
                    out[i] = Feature("rect", what, (float(c.x), float(c.y)), width / 2, R=length / 2, t0=ang)
                    del out[j]
                    merged = True
                    break
            if merged:
                break
    return out


def _rect_sides(rect: Any) -> tuple[float, float, float]:
    """A rectangle's long side, short side and the long side's angle (rad)."""
    xy = np.asarray(rect.exterior.coords)[:4]
    e1, e2 = xy[1] - xy[0], xy[2] - xy[1]
    a, b = float(np.hypot(*e1)), float(np.hypot(*e2))
    long = e1 if a >= b else e2
    return max(a, b), min(a, b), math.atan2(long[1], long[0])


def slot_features(joins: list[TabJoin]) -> dict[str, list[Feature]]:
    """The xy pieces' through-slots as fabrication features (mm, own frame)."""
    out: dict[str, list[Feature]] = {}
    for jn in joins:
        L, W = jn.slot_size
        for c, ang in jn.slots:
            out.setdefault(jn.base, []).append(Feature("rect", f"tab slot {jn.letter}", c, W / 2, R=L / 2, t0=ang))
    return out
