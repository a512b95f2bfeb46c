"""Joints a toy's assembly drops as repeats of another, and the cuts they took with them.

Two stages may guide one merged body along one line (the Bunny's s0 follower and s1 driver): the
second slide would cut a second slot inside the first, two more pin holes beside the first two,
and over-constrain the physics rebuild.  :class:`~planar.toys.assembly.ToyAssembly` keeps the
longest slide and takes the others' own cuts away.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

import numpy as np

from planar.core.model import Part

__all__: list[str] = []


def _without_cuts_of(
    parts: list[Part], dropped: list[Any], kept: list[Any], tol: float = 1e-9
) -> tuple[list[Part], list[tuple[str, Any]]]:
    """``parts`` without the slots and pin holes of the ``dropped`` slides (features at their slot ends or at
    their pin points), except that where a ``kept`` joint has a pin at the same place (piece frames) one hole
    stays (the first there, the one the kept pin goes through); and the ``(piece, feature)`` pairs removed."""
    from planar.core.features import Hole, Slot

    keep_pins: dict[str, list[tuple[float, float]]] = {}
    for j in kept:
        for pname, xy in j.pins():
            keep_pins.setdefault(pname, []).append((float(xy[0]), float(xy[1])))
    drop_pins: dict[str, list[tuple[float, float]]] = {}
    drop_slots: dict[str, list[tuple[Any, Any]]] = {}
    for j in dropped:
        for xy in j.pin_points():
            drop_pins.setdefault(j.b, []).append((float(xy[0]), float(xy[1])))
        drop_slots.setdefault(j.a, []).append((j.start, j.end))

    def near(p: Any, q: Any) -> bool:
        return float(np.hypot(p[0] - q[0], p[1] - q[1])) <= tol

    out = []
    removed: list[tuple[str, Any]] = []
    for part in parts:
        feats = []
        kept_at: list[tuple[float, float]] = []  # kept pins' places that already have their one hole
        for f in part.features:
            if isinstance(f, Hole) and any(near(f.centre, q) for q in drop_pins.get(part.name, ())):
                # a kept pin at the same place keeps ONE hole there (the first, the one fabjoints finds); any
                # other hole there is the dropped slide's own (e.g. the Bunny's s1.driver 6 mm pin hole under
                # s0's pin B): cut, it would be pinned to nothing and swallow the pin hole at its own size
                at_kept = next((q for q in keep_pins.get(part.name, ()) if near(f.centre, q)), None)
                if at_kept is None or any(near(at_kept, q) for q in kept_at):
                    removed.append((part.name, f))
                    continue
                kept_at.append(at_kept)
            if isinstance(f, Slot) and any(
                (near(f.start, a) and near(f.end, b)) or (near(f.start, b) and near(f.end, a))
                for a, b in drop_slots.get(part.name, ())
            ):
                removed.append((part.name, f))
                continue
            feats.append(f)
        out.append(replace(part, features=tuple(feats)))
    return out, removed


def _without_redundant_slides(joints: list[Any]) -> tuple[list[Any], list[Any]]:
    """``joints`` without a slide that repeats another: the same two pieces, the same line (a merged body
    guided by two stages' slots on one line, e.g. the Bunny's s0 follower and s1 driver).  The longest
    slot is kept; a second slide would cut a second slot inside the first and two more pin holes beside the
    first two (they overlapped), and over-constrain the physics rebuild."""
    from planar.core.model import Slide

    out: list[Any] = []
    dropped: list[Any] = []
    for j in joints:
        if isinstance(j, Slide):
            s0, s1 = np.asarray(j.start, float), np.asarray(j.end, float)
            length = float(np.hypot(*(s1 - s0)))
            e = (s1 - s0) / length
            same = None
            for k, o in enumerate(out):
                if not isinstance(o, Slide) or {o.a, o.b} != {j.a, j.b}:
                    continue
                o0, o1 = np.asarray(o.start, float), np.asarray(o.end, float)
                d = (o1 - o0) / np.hypot(*(o1 - o0))
                off = abs(float(e[0] * (o0 - s0)[1] - e[1] * (o0 - s0)[0]))
                if abs(float(e[0] * d[1] - e[1] * d[0])) < 1e-9 and off < 1e-9 * max(1.0, length):
                    same = k
                    break
            if same is not None:
                o = out[same]
                if length > float(np.hypot(*(np.asarray(o.end) - np.asarray(o.start)))):
                    out[same] = j
                    dropped.append(o)
                else:
                    dropped.append(j)
                continue
        out.append(j)
    return out, dropped
