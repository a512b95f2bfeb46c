"""The assembled view of a wind-up toy (and of the elemental #6, #8, #9): what the renderer draws.

:func:`assembled` turns a mechanism and its motion into the mechanism and
motion to draw, plus per-frame :class:`Marks`:

* a toy (:class:`~planar.windup.chain.ToyMechanism`) is drawn as its
  assembly (:mod:`planar.toys.assembly`): every piece in place in the
  toy's front view (xy), in layer order (the fabrication's layers: bottom
  first, so upper layers cover lower ones);
* pieces that move in another plane (#8 in xz, the #6/#9 followers in yz) are
  drawn in their own plane's projection, in a panel beside the front view
  (never collapsed to a line);
* #8: its window's taper (``D_w1`` at the bottom to ``D_w2`` at the top, the
  contact edge straight) drawn on the window plate; the tab stands in it;
* #6 and #9: in the front view, the pin's section in the driver's plane (an
  oval, semi-axes ``r`` and ``r / cos(tilt)``) and the contact point where the
  driver's edge touches it.

Anything else is returned unchanged with no marks.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from planar.core.geometry import poses_apply
from planar.core.model import CamOnLine, Mechanism, Motion, Part

__all__ = ["Marks", "assembled", "layer_order"]

Array = NDArray[np.float64]


@dataclass
class Marks:
    """Per-frame drawings in view coordinates: filled rings ``(N, M, 2)``, open lines ``(N, M, 2)``, dots ``(N, 2)``;
    each with a style colour name (``"pin"``, ``"outline"``, ``"invalid"``, ``"trail"``)."""

    rings: list[tuple[Array, str]] = field(default_factory=list)
    lines: list[tuple[Array, str]] = field(default_factory=list)
    dots: list[tuple[Array, str]] = field(default_factory=list)

    def __bool__(self) -> bool:
        return bool(self.rings or self.lines or self.dots)


class _ViewMechanism(Mechanism):
    """Parts already placed for drawing (every plane flattened to the page); poses come with the motion."""

    def _solve_poses(self, q: Array):  # pragma: no cover - a view is never solved, only drawn
        raise NotImplementedError("a view mechanism carries its motion")


def layer_order(mech: Mechanism, unit_mm: float = 100.0, samples: int = 24) -> dict[str, int]:
    """Each part's layer (0 = bottom) as fabrication stacks them (:func:`planar.fabrication.layers.plan_assembly`)."""
    from shapely import affinity

    from planar.fabrication.joints import joint_pins
    from planar.fabrication.layers import plan_assembly

    pins, contacts = joint_pins(mech)
    material = {p.name: affinity.scale(p.outline, unit_mm, unit_mm, origin=(0, 0)) for p in mech.parts}
    asm = plan_assembly(mech, material, pins, contacts, unit_mm, 3.0, 3.0, 1.5, None, samples=samples)
    return {k: (v if v is not None else 0) for k, v in asm.layers.items()}


def _extent(parts: list[Part], poses: dict[str, Array], valid: NDArray[np.bool_], chunk: int = 256) -> tuple[Array, Array]:
    """Lowest and highest point of ``parts``' outlines over the ``valid`` samples, gathered ``chunk`` samples at a
    time (the renderer's memory stays bounded by a chunk of frames; the extent is the same, exactly)."""
    lo, hi = np.full(2, np.inf), np.full(2, -np.inf)
    found = False
    for p in parts:
        ring = np.asarray(p.outline.exterior.coords)
        track = poses[p.name][valid]
        for start in range(0, len(track), chunk):
            pts = poses_apply(track[start : start + chunk], ring).reshape(-1, 2)
            lo, hi = np.minimum(lo, pts.min(0)), np.maximum(hi, pts.max(0))
            found = True
    if not found:
        return np.zeros(2), np.zeros(2)
    return lo, hi


def _taper(mech_parts: dict[str, Part], j: CamOnLine, P: Any, pose: Array) -> Array:
    """The #8 window's opening in view coordinates, per frame: the contact edge straight at the edge point,
    the far side from ``D_w1`` (bottom) to ``D_w2`` (top)."""
    ax, az = j.centre
    h = 0.08
    ring = np.array([(ax, az - h), (ax, az + h), (ax - P.D_w2, az + h), (ax - P.D_w1, az - h), (ax, az - h)])
    return poses_apply(pose, ring)


def _oval(j: Any, drv_pose: Array, fol_pose: Array, n: int = 48) -> tuple[Array, Array]:
    """#6/#9: the pin's section in the driver's plane (front view) and the contact point, per frame.

    The pin's axis passes through ``(pin_x, y, z)`` (the follower's pose in yz) along
    ``(0, -sin a, cos a)``; it meets ``z = plane_z`` at ``(pin_x, y - (plane_z - z) tan a)``, where the pin's
    round section shows as an ellipse with semi-axes ``r`` (x) and ``r / cos a`` (y).  The contact point is
    the ellipse's support point towards the driver's edge.
    """
    a = fol_pose[:, 2]
    ca = np.cos(a)
    cy = fol_pose[:, 0] - (j.plane_z - fol_pose[:, 1]) * np.tan(a)
    cx = np.full_like(cy, j.pin_x)
    rx, ry = j.radius, j.radius / np.abs(ca)
    th = np.linspace(0.0, 2 * math.pi, n, endpoint=False)
    ring = np.stack([cx[:, None] + rx * np.cos(th)[None, :], cy[:, None] + ry[:, None] * np.sin(th)[None, :]], -1)
    # the edge, world: a point and a direction; the normal from the oval's centre towards it
    e0 = poses_apply(drv_pose, j.edge_point)
    ang = drv_pose[:, 2] + math.atan2(j.edge_dir[1], j.edge_dir[0])
    ex, ey = np.cos(ang), np.sin(ang)
    nx, ny = -ey, ex
    side = np.sign((e0[:, 0] - cx) * nx + (e0[:, 1] - cy) * ny)
    nx, ny = nx * side, ny * side
    k = np.sqrt((rx * nx) ** 2 + (ry * ny) ** 2)
    contact = np.column_stack([cx + rx * rx * nx / k, cy + ry * ry * ny / k])
    return ring, contact


def _panel(parts: list[Part], poses: dict[str, Array], shift: Array) -> tuple[list[Part], dict[str, Array]]:
    out_parts, out_poses = [], {}
    for p in parts:
        out_parts.append(replace(p, plane="xy", offset=0.0))
        out_poses[p.name] = poses[p.name] + np.array([shift[0], shift[1], 0.0])
    return out_parts, out_poses


def assembled(mech: Mechanism, motion: Motion) -> tuple[Mechanism, Motion, Marks]:
    """What to draw for ``mech``'s ``motion``: the assembled view with its marks (see the module docstring)."""
    from planar.toys.assembly import ToyAssembly, toy_assembly
    from planar.windup.chain import ToyMechanism
    from planar.windup.mechanisms import ElementalMechanism, SkewContact

    if isinstance(mech, ToyMechanism):
        asm: Mechanism = toy_assembly(mech)
        m = asm.solve(motion.driver, t=motion.t)
        m.valid, m.fail_code, m.fail_table = motion.valid, motion.fail_code, motion.fail_table
        front_plane = "xy"
    elif isinstance(mech, ElementalMechanism) and (mech.spatial or mech.view != "xy"):  # #6, #9; #8
        asm, m, front_plane = mech, motion, mech.view
    else:
        return mech, motion, Marks()
    valid = np.asarray(m.valid, bool)
    valid = valid if valid.any() else np.ones_like(valid)
    front = [p for p in asm.parts if p.plane == front_plane]
    if isinstance(asm, ToyAssembly):
        flat = _FrontOnly(asm, front)
        layers = layer_order(flat)
        front.sort(key=lambda p: (layers.get(p.name, 0), not p.ground))
    lo, hi = _extent(front, m.poses, valid)
    size = float(max(hi - lo)) or 1.0
    parts, poses = _panel(front, m.poses, np.zeros(2))
    x_right = hi[0]
    shifts: dict[str, Array] = {}
    for plane in ("xz", "yz", "xy"):
        side = [p for p in asm.parts if p.plane == plane and p.plane != front_plane]
        if not side:
            continue
        slo, shi = _extent(side, m.poses, valid)
        shift = np.array([x_right + 0.15 * size - slo[0], 0.5 * (lo[1] + hi[1]) - 0.5 * (slo[1] + shi[1])])
        shifts[plane] = shift
        sp, spo = _panel(side, m.poses, shift)
        parts += sp
        poses.update(spo)
        x_right = shi[0] + shift[0]
    marks = Marks()
    by_name = {p.name: p for p in asm.parts}
    for j in asm.joints:
        if isinstance(j, CamOnLine) and by_name[j.b].plane == "xz":
            P = _stage_params(mech, j.name)
            if P is not None and hasattr(P, "D_w1"):
                marks.lines.append((_taper(by_name, j, P, poses[j.b]), "outline"))
        if isinstance(j, SkewContact) and by_name[j.a].plane == front_plane == "xy":
            ring, contact = _oval(j, m.poses[j.a], m.poses[j.b])
            marks.rings.append((ring, "pin"))
            marks.dots.append((contact, "invalid"))
    joints = [j for j in asm.joints if j.a in poses and j.b in poses]
    points = {k: v for k, v in asm.points.items() if v[0] in poses}
    view = _ViewMechanism(f"{asm.name}", parts, joints, asm.driver, points)
    view.view = "xy"
    pts = {k: poses_apply(poses[part], xy) for k, (part, xy) in points.items()}
    vm = Motion(driver=m.driver, poses=poses, valid=m.valid, fail_code=m.fail_code, fail_table=m.fail_table, points=pts, t=m.t)
    return view, vm, marks


class _FrontOnly(Mechanism):
    """The assembly's front-view pieces and their joints (for the layer order)."""

    def __init__(self, asm: Any, parts: list[Part]) -> None:
        self.asm = asm
        names = {p.name for p in parts}
        joints = [j for j in asm.joints if j.a in names and j.b in names]
        super().__init__(asm.name, parts, joints, asm.driver)
        self.parts = tuple(parts)

    def _solve_poses(self, q: Array):
        poses, checks = self.asm._solve_poses(q)
        return {p.name: poses[p.name] for p in self.parts}, checks


def _stage_params(mech: Mechanism, joint: str) -> Any:
    """The parameters (world frame) of the elemental mechanism a joint belongs to."""
    from planar.windup.chain import ToyMechanism

    if isinstance(mech, ToyMechanism):
        label = joint.split(".", 1)[0]
        for st in mech.stages:
            if st.label == label:
                return st.mech.world
        return None
    return getattr(mech, "world", None)
