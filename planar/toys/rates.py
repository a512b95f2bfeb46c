"""Rates of every piece of a toy's assembly, from the rates of its stages (:mod:`planar.windup.rates`)."""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from planar.windup.rates import toy_rates

__all__ = ["assembly_rates"]

Array = NDArray[np.float64]
Mask = NDArray[np.bool_]


def assembly_rates(asm: Any, q: Array, qd: Array, qdd: Array) -> tuple[dict[str, tuple[Array, ...]], Mask]:
    """Rates of every piece of a toy's assembly (:class:`~planar.toys.assembly.ToyAssembly`, the toy's
    frame): each piece is a stage part (its first member) at the stage's place, then offset on its body.

    The place is a turn by ``a`` about z and a shift for an xy stage, a shift for xz and yz
    (:func:`planar.toys.assembly._world_track`): the stage part's velocity and acceleration turn by
    ``a``, its angular rates do not change; the piece's origin is a point of that body
    (``v + omega x r``, ``a + alpha x r - omega^2 r``, ``r`` from the stage part's origin to the piece's)."""
    raw, ok = toy_rates(asm.toy, q, qd, qdd)
    stage_poses = asm.stage_poses(q)
    pieces = asm.piece_poses(stage_poses)
    out: dict[str, tuple[Array, ...]] = {}
    for piece, members in asm.members.items():
        full = members[0][0]
        v, a, om, al = (np.asarray(x, float) for x in raw[full])
        if asm._stage_part(full).plane == "xy":
            ang = asm.placed[int(full.split(".")[0][1:])].place[2]
            c, s_ = np.cos(ang), np.sin(ang)
            v = np.column_stack([c * v[:, 0] - s_ * v[:, 1], s_ * v[:, 0] + c * v[:, 1]])
            a = np.column_stack([c * a[:, 0] - s_ * a[:, 1], s_ * a[:, 0] + c * a[:, 1]])
        r = pieces[piece][:, :2] - stage_poses[full][:, :2]
        om, al = np.broadcast_to(om, q.shape), np.broadcast_to(al, q.shape)
        pv = np.column_stack([v[:, 0] - om * r[:, 1], v[:, 1] + om * r[:, 0]])
        pa = np.column_stack([a[:, 0] - al * r[:, 1] - om * om * r[:, 0], a[:, 1] + al * r[:, 0] - om * om * r[:, 1]])
        out[piece] = (pv, pa, om, al)
    return out, ok
