"""Views of a toy assembly as mechanisms (one plane, or coupled across planes) and how a stage is driven."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from planar.core.geometry import poses_apply
from planar.core.model import Driver, Mechanism, joint_kind
from planar.toys.assembly import ToyAssembly

__all__ = ["SharedX", "StageDrive", "coupled_mechanism", "plane_mechanism"]

Array = NDArray[np.float64]


class _PlaneView(Mechanism):
    """The pieces of an assembly that move in one plane, and the joints among them."""

    def __init__(self, asm: ToyAssembly, plane: str = "xy") -> None:
        self.asm = asm
        parts = [p for p in asm.parts if p.plane == plane]
        names = {p.name for p in parts}
        joints = [j for j in asm.joints if j.a in names and j.b in names]
        super().__init__(asm.name, parts, joints, asm.driver, {k: v for k, v in asm.points.items() if v[0] in names})
        self.parts = tuple(parts)  # the assembly's parts already carry their joints' features

    def _solve_poses(self, q: Array):
        poses, checks = self.asm._solve_poses(q)
        return {p.name: poses[p.name] for p in self.parts}, checks


def plane_mechanism(asm: ToyAssembly, plane: str = "xy") -> Mechanism:
    """The assembly's pieces in ``plane`` as a mechanism of their own (the motor's plane: ``"xy"``)."""
    return _PlaneView(asm, plane)


@joint_kind
@dataclass(frozen=True)
class SharedX:
    """Two pieces of one rigid body in different planes (xy and xz): they share their x.

    Residual: ``|x of a's origin - x of b's anchor|`` (world x, model units).  In
    one 2D space (pymunk) it is a groove along the second axis on ``a`` through
    its origin, holding ``b``'s anchor: the planes' second axes (y, z) stay
    independent, as they are.
    """

    kind: ClassVar[str] = "shared-x"
    name: str
    a: str  # the piece moving in xz (its x is the body's)
    b: str  # the piece moving in xy
    anchor: tuple[float, float]  # on b, own frame
    reach: float = 10.0

    def residual(self, poses: Any) -> Array:
        return np.abs(poses[self.a][:, 0] - poses_apply(poses[self.b], self.anchor)[:, 0])

    def features(self) -> tuple:
        return ()

    def pins(self) -> tuple:
        return ()


class _CoupledView(Mechanism):
    """The assembly's pieces in one motor run: xy, the yz followers of #6/#9 and (``xz``) the #8 pieces.

    Each xz piece is tied to its body's xy piece by x (:class:`SharedX`); each
    yz follower keeps its stage's :class:`~planar.windup.mechanisms.SkewContact`
    with the driver's edge (rebuilt by co-simulation, see :func:`_skew_load`).
    """

    def __init__(self, asm: ToyAssembly, xz: bool = True) -> None:
        self.asm = asm
        planes = ("xy", "yz", "xz") if xz else ("xy", "yz")
        parts = [p for p in asm.parts if p.plane in planes]
        names = {p.name for p in parts}
        joints: list[Any] = [j for j in asm.joints if j.a in names and j.b in names]
        plane = {p.name: p.plane for p in parts}
        poses0 = asm.solve([0.0]).poses
        for pieces in asm.bodies.values():
            xy = [n for n in pieces if plane.get(n) == "xy"]
            for n in pieces:
                if plane.get(n) == "xz" and xy and not asm.part(n).ground:
                    # b's point with a's x at rest (b's own frame)
                    pb = poses0[xy[0]][0]
                    c, s_ = math.cos(pb[2]), math.sin(pb[2])
                    dx = poses0[n][0, 0] - pb[0]
                    joints.append(SharedX(f"{n}.x", n, xy[0], (c * dx, -s_ * dx), 10.0 * asm.size))
        super().__init__(asm.name, parts, joints, asm.driver, {k: v for k, v in asm.points.items() if v[0] in names})
        self.parts = tuple(parts)
        self.left_out = sorted({p.name for p in asm.parts} - names)

    def _solve_poses(self, q: Array):
        poses, checks = self.asm._solve_poses(q)
        return {p.name: poses[p.name] for p in self.parts}, checks


def coupled_mechanism(asm: ToyAssembly, xz: bool = True) -> Mechanism:
    """The assembly's xy pieces, the yz followers of #6/#9 and (``xz``) the #8 pieces as one mechanism: the
    motor's load includes every stage; pieces left out are named in ``left_out``."""
    return _CoupledView(asm, xz)


# ---------------------------------------------------------------------------- driving one stage

#: how a stage is driven inside a toy: the toy's driver law and a map from its values to the stage's motion
StageDrive = tuple[Driver, Callable[[Array], Array]]


def _law(mech: Any, drive: StageDrive | None, speed: float) -> Driver:
    """The driver law at ``speed`` cycles/s: the toy's (``drive``) or the stage's standalone one."""
    from dataclasses import replace

    return replace(drive[0] if drive is not None else mech.driver, rate=2 * math.pi * speed)


def _poses(mech: Any, q: Array, drive: StageDrive | None) -> dict[str, Array]:
    """The stage's part poses (its own frames) for driver values ``q``."""
    if drive is None:
        return mech.solve(q).poses
    u = drive[1](np.asarray(q, float))
    return {"ground": np.zeros((len(u), 3)), "driver": mech._driver_pose(u), "follower": mech._follower_pose(mech.forward(u).out)}
