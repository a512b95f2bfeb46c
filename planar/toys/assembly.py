"""A wind-up toy as one physical assembly: merged parts, one frame, cams keyed to one shaft.

:func:`toy_assembly` turns a :class:`~planar.windup.chain.ToyMechanism` into a
:class:`ToyAssembly`, an ordinary :class:`~planar.core.model.Mechanism` whose parts
are the toy's rigid pieces:

* **placement**: every stage is put where it physically sits.  A root stage's
  driver turns on the motor axis (the world origin); a child stage is turned
  by its realisation's rotation and moved so that its driver's frame origin
  is its parent's follower's frame origin (same point, same motion: the two
  are one rigid body);
* **merged parts**: a stage's follower and its children's drivers are one part
  (``s0.follower+s1.driver``), in the follower's frame: the outline is the
  shapely union of the members' rounded hulls, and every member's holes and
  slots are kept (holes at one place are one hole, the first member's);
* **one frame**: every stage's ground, moved to its place, is one part
  (``frame``) holding every fixed pivot, slot and the motor shaft;
* **cams keyed to the shaft**: each root stage's driver is a cam
  (``cam.left``, ``cam.right``) on the motor axis; the first is the driven
  part, every other is joined to it by a :class:`KeyedShaft` at its phase
  (fabrication cuts each cam's shaft hole as a D turned by its phase, with an
  engraved phase mark).

Stages that move in another plane (#8 in xz) keep their own plane: their
pieces are separate parts of that plane (``frame.xz``, ``s2.driver``), moved
along x with their parent; #6/#9 followers (yz) move with their stage's
offset.  A rigid body spanning two planes is therefore cut as one piece per
plane (:attr:`ToyAssembly.bodies` names them).  Poses come from the toy's
exact composition; :func:`assembly_residual` checks every joint on them.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, replace
from typing import Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from planar.core.geometry import poses_apply, poses_compose, poses_invert, wrap_angle
from planar.core.model import (
    ArcSlot,
    CamOnLine,
    Driver,
    Feature,
    Hole,
    Mechanism,
    Part,
    PinInArcSlot,
    PinInSlot,
    Pivot,
    Slide,
    Slot,
    joint_kind,
)
from planar.core.rates import PartRates, RatesResult
from planar.core.registry import Registry
from planar.errors import InputError
from planar.toys.redundant import _without_cuts_of, _without_redundant_slides
from planar.windup.chain import ToyMechanism
from planar.windup.mechanisms import SkewContact

__all__ = ["PLACERS", "KeyedShaft", "ToyAssembly", "assembly_residual", "toy_assembly"]

Array = NDArray[np.float64]
Vec = tuple[float, float]
XForm = tuple[float, float, float]  # (tx, ty, angle): a point p maps to R(angle) p + t


@joint_kind
@dataclass(frozen=True)
class KeyedShaft:
    """Part ``b`` keyed to part ``a`` on one shaft: ``anchor_a`` and ``anchor_b`` coincide and
    ``b`` turns with ``a``, ``phase`` radians ahead (the cams of one motor).

    Residual: the anchors' distance plus ``size`` x the angle error (rad), model units.
    """

    kind: ClassVar[str] = "keyed-shaft"
    point_fields: ClassVar[tuple[str, ...]] = ("anchor_a", "anchor_b")
    name: str
    a: str
    b: str
    anchor_a: Vec
    anchor_b: Vec
    phase: float
    size: float = 1.0

    def __post_init__(self) -> None:
        """Refused where it is built: finite anchors and phase, a positive size (NaN would be stored silently)."""
        from planar.core.fields import check_fields

        check_fields(self, f"KeyedShaft {self.name!r}")
        if not self.size > 0:
            raise InputError(f"KeyedShaft {self.name!r}.size", self.size, "a positive, finite size (model units)")

    def residual(self, poses: Mapping[str, Array]) -> Array:
        pa = poses_apply(poses[self.a], self.anchor_a)
        pb = poses_apply(poses[self.b], self.anchor_b)
        da = wrap_angle(poses[self.b][:, 2] - poses[self.a][:, 2] - self.phase)
        return np.hypot(*(pa - pb).T) + self.size * np.abs(da)

    def features(self) -> tuple[tuple[str, Feature], ...]:
        return ()

    def pins(self) -> tuple[tuple[str, Vec], ...]:
        return ((self.a, self.anchor_a),)


# ---------------------------------------------------------------------------- transforms


def _xf_point(m: XForm, p: Any) -> Vec:
    c, s = math.cos(m[2]), math.sin(m[2])
    return (float(m[0] + c * p[0] - s * p[1]), float(m[1] + s * p[0] + c * p[1]))


def _xf_vec(m: XForm, v: Any) -> Vec:
    c, s = math.cos(m[2]), math.sin(m[2])
    return (float(c * v[0] - s * v[1]), float(s * v[0] + c * v[1]))


def _xf_feature(m: XForm, f: Feature) -> Feature:
    if isinstance(f, Hole):
        return replace(f, centre=_xf_point(m, f.centre))
    if isinstance(f, Slot):
        return replace(f, start=_xf_point(m, f.start), end=_xf_point(m, f.end))
    if isinstance(f, ArcSlot):
        return replace(f, centre=_xf_point(m, f.centre), angle0=f.angle0 + m[2], angle1=f.angle1 + m[2])
    raise InputError("feature", type(f).__name__, "a Hole, Slot or ArcSlot (no rule to move it into a merged part)")


#: how a stage's joint moves into the assembly: (joint, xform of a, xform of b, stage) -> the joint's fields
#: that move with its parts (its geometry); the assembly renames it and its parts (:func:`_placed`)
PLACERS: Registry[Callable[..., dict[str, Any]]] = Registry("toy assembly")


@PLACERS.register(Pivot)
def _place_pivot(j: Pivot, ma: XForm, mb: XForm, st: Any) -> dict[str, Any]:
    return {"anchor_a": _xf_point(ma, j.anchor_a), "anchor_b": _xf_point(mb, j.anchor_b)}


@PLACERS.register(PinInSlot)
def _place_pin_slot(j: PinInSlot, ma: XForm, mb: XForm, st: Any) -> dict[str, Any]:
    return {"start": _xf_point(ma, j.start), "end": _xf_point(ma, j.end), "pin": _xf_point(mb, j.pin)}


@PLACERS.register(PinInArcSlot)
def _place_pin_arc(j: PinInArcSlot, ma: XForm, mb: XForm, st: Any) -> dict[str, Any]:
    return {"centre": _xf_point(ma, j.centre), "pin": _xf_point(mb, j.pin)}


@PLACERS.register(Slide)
def _place_slide(j: Slide, ma: XForm, mb: XForm, st: Any) -> dict[str, Any]:
    return {
        "start": _xf_point(ma, j.start),
        "end": _xf_point(ma, j.end),
        "anchor": _xf_point(mb, j.anchor),
        "axis": _xf_vec(mb, j.axis),
    }


@PLACERS.register(CamOnLine)
def _place_cam_line(j: CamOnLine, ma: XForm, mb: XForm, st: Any) -> dict[str, Any]:
    return {"start": _xf_point(ma, j.start), "end": _xf_point(ma, j.end), "centre": _xf_point(mb, j.centre)}


@PLACERS.register(SkewContact)
def _place_skew(j: SkewContact, ma: XForm, mb: XForm, st: Any) -> dict[str, Any]:
    # the driver (xy) moves with ma; the follower (yz) keeps its frame and its axis moves to x + tx
    return {"edge_point": _xf_point(ma, j.edge_point), "edge_dir": _xf_vec(ma, j.edge_dir), "pin_x": j.pin_x + st.place[0]}


def _placed(j: Any, name: str, a: str, b: str, ma: XForm, mb: XForm, st: Any, where: str) -> Any:
    """Joint ``j`` of a stage placed in the assembly: renamed ``name`` between pieces ``a`` and ``b``, its
    geometry moved with its parts (``ma``, ``mb``) by its kind's :data:`PLACERS` entry."""
    moved = PLACERS.get(j, where)(j, ma, mb, st)
    return replace(j, name=name, a=a, b=b, **moved)


# ---------------------------------------------------------------------------- the assembly


@dataclass
class _Placed:
    """A stage's placement: ``place`` maps its own xy frame to the world (``(tx, ty, angle)``)."""

    stage: Any
    place: XForm

    @property
    def label(self) -> str:
        return str(self.stage.label)


def _rest_pose(st: Any, which: str) -> Array:
    """The stage's driver or follower pose at motion zero, its own frame (xy, or its plane)."""
    m = st.mech
    if which == "driver":
        u = np.zeros((1, 3)) if m.motion_in == "OzT" else np.zeros(1)
        return np.asarray(m._driver_pose(u)[0], float)
    out = np.zeros((1, 3)) if m.motion_out == "OzT" else np.zeros(1)
    return np.asarray(m._follower_pose(out)[0], float)


def _track_turns(toy: Any) -> list[float]:
    """Each stage's turn about the motor axis (rad) that keeps merged grounds' tracks apart.

    Two root stages of one pattern on different cams have one ground: merged into one frame, their slots
    would be one track with both pins riding it.  The later such root, and every stage above it, is turned
    half a turn about the motor axis (its cam keyed half a turn further, so it moves as before, turned):
    its track lies across the shaft from the first.  A tree with a stage moving out of the xy plane is not
    turned (no part records a turned xz or yz plane).
    """
    turns = [0.0] * len(toy.stages)
    first: dict[str, str] = {}  # each root pattern's first cam
    for i, st in enumerate(toy.stages):
        if st.parent is not None:
            turns[i] = turns[st.parent]
            continue
        cam = first.setdefault(st.key[0], st.cam)
        tree = [s for s in toy.stages if s.cam == st.cam and s.key[:1] == st.key[:1]]
        if cam != st.cam and all(p.plane == "xy" for s in tree for p in s.mech.parts):
            turns[i] = math.pi
    return turns


def _placements(toy: Any) -> list[_Placed]:
    out: list[_Placed] = []
    turns = _track_turns(toy)
    for st, turn in zip(toy.stages, turns, strict=True):
        R = st.realisation.matrix
        ang = math.atan2(R[1, 0], R[0, 0])
        proper = abs(R[2, 2] - 1.0) < 1e-12 and abs(np.linalg.det(R[:2, :2]) - 1.0) < 1e-12
        if not proper:
            raise InputError(
                f"{toy.name}.stage {' '.join(st.key)}",
                f"realised as #{st.realisation.number} mirrored or turned out of the xy plane",
                "a stage turned about z only (a mirrored stage is not assembled)",
            )
        plane = st.mech.part("driver").plane
        other = sorted({p.plane for p in st.mech.parts} - {"xy"})
        if other and abs(ang) > 1e-12:
            raise InputError(
                f"{toy.name}.stage {' '.join(st.key)}",
                f"realised as #{st.realisation.number} turned {math.degrees(ang):g} deg about z",
                f"a stage with parts moving in {', '.join(other)} that is not turned (a turned "
                f"#{st.realisation.number} would move in another plane, which no part records)",
            )
        d0 = _rest_pose(st, "driver")
        if st.parent is None:
            anchor = (0.0, 0.0)  # the motor axis
        else:
            par = out[st.parent]
            f0 = _rest_pose(par.stage, "follower")
            if par.stage.mech.part("follower").plane != "xy":
                raise InputError(
                    f"{toy.name}.stage {' '.join(st.key)}",
                    par.stage.realisation.pattern,
                    "a parent whose follower moves in xy (its follower carries the child's driver)",
                )
            anchor = _xf_point(par.place, f0[:2])
        if plane == "xy":
            ang += turn
            c, s = math.cos(ang), math.sin(ang)
            t = (anchor[0] - (c * d0[0] - s * d0[1]), anchor[1] - (s * d0[0] + c * d0[1]))
            out.append(_Placed(st, (t[0], t[1], ang)))
        else:  # xz: the slider's x is shared; the plane's own second axis (z) is kept
            out.append(_Placed(st, (anchor[0] - d0[0], 0.0, 0.0)))
    return out


def _world_track(p: _Placed, part: Part, pose: Array) -> Array:
    """A stage part's pose track moved to its place (xy: composed; xz: along x; yz: along y)."""
    tx, ty, a = p.place
    if part.plane == "xy":
        return poses_compose(np.array([tx, ty, a]), pose)
    if part.plane == "xz":
        return pose + np.array([tx, 0.0, 0.0])
    return pose + np.array([ty, 0.0, 0.0])  # yz: (y, z, angle); its x offset moves with the part


def _hull_poly(part: Part) -> Any:
    """The part's outer profile without its holes (shapely)."""
    return Part(part.name, part.hull, (), polygon=part.polygon).outline


def _merge(name: str, members: list[tuple[Part, XForm]], plane: str, ground: bool) -> tuple[Part, list[str]]:
    """One part from ``members`` (each with its transform into the merged frame): union of the hulls, every feature."""
    import shapely
    from shapely import affinity

    notes: list[str] = []
    hull: list[tuple[float, float, float]] = []
    feats: list[Feature] = []
    polys = []
    for part, m in members:
        hull += [(*_xf_point(m, (x, y)), r) for x, y, r in part.hull]
        for f in part.features:
            g = _xf_feature(m, f)
            # two stages' holes at one place of one rigid piece are one cut, the first member's: a follower's
            # pivot hole and its child driver's axle hole are one axle (both pivots are one pin); a second,
            # larger hole there would be pinned to nothing and swallow the pin's hole (#3 -> #1: 6.1 mm for a
            # 3 mm pin on the frame)
            if g not in feats and not (
                isinstance(g, Hole)
                and any(
                    isinstance(h, Hole) and math.dist(h.centre, g.centre) <= 1e-9 * max(1.0, math.hypot(*g.centre)) for h in feats
                )
            ):
                feats.append(g)
        c, s = math.cos(m[2]), math.sin(m[2])
        polys.append(affinity.affine_transform(_hull_poly(part), [c, -s, s, c, m[0], m[1]]))
    offset = members[0][0].offset
    if len(members) == 1:
        p0, m0 = members[0]
        return replace(
            p0,
            name=name,
            hull=tuple(hull),
            features=tuple(feats),
            ground=ground,
            polygon=None if p0.polygon is None else tuple(_xf_point(m0, q) for q in p0.polygon),
        ), notes
    # every cut keeps material round it (fabrication adds slot end margins and walls): each feature's
    # shape grown by three quarters of its width joins the outline
    from planar.core.outlines import feature_shape

    for f in feats:
        w = f.diameter if isinstance(f, Hole) else f.width
        polys.append(feature_shape(f, 0.75 * w))
    union = shapely.union_all(polys)
    if ground:  # the frame is one plate: the rounded hull of every ground (room for the motor and mounting ears)
        return Part(name, tuple(hull), tuple(feats), ground=True, plane=plane, offset=offset), notes
    if union.geom_type != "Polygon":
        notes.append(f"{name}: its members' outlines do not touch; the outline is their rounded convex hull")
        return Part(name, tuple(hull), tuple(feats), ground=ground, plane=plane, offset=offset), notes
    # a closing (grow, then shrink by as much) fills the narrow notches where two members meet at an acute angle
    lo_x, lo_y, hi_x, hi_y = union.bounds
    d = 0.03 * math.hypot(hi_x - lo_x, hi_y - lo_y)
    union = union.buffer(d, quad_segs=16).buffer(-d, quad_segs=16).union(union).simplify(1e-6)
    ring = [(float(x), float(y)) for x, y in np.asarray(union.exterior.coords)[:-1]]
    return Part(name, tuple(hull), tuple(feats), ground=ground, plane=plane, offset=offset, polygon=tuple(ring)), notes


class ToyAssembly(Mechanism):
    """A toy's rigid pieces, one frame, cams keyed to the motor shaft (see the module docstring).

    ``bodies`` maps each rigid body to its pieces (one per plane it spans);
    ``members`` maps each piece to its stage parts with their transforms into
    the piece's frame; ``keyed`` maps each cam to its phase (rad).
    """

    def __init__(self, toy: ToyMechanism) -> None:
        from planar.core.fields import check_kind

        check_kind("ToyAssembly(toy)", toy, ToyMechanism, "a ToyMechanism (planar.windup.chain)")
        self.toy = toy
        self.placed = _placements(toy)
        self.notes: list[str] = []
        cam_name = self._cam_names()
        # rest poses (world, per plane) of every stage part, from the toy's own solve at q = 0
        poses0 = self._stage_poses(np.zeros(1))[0]
        piece_of, body_of, rename = self._pieces_and_bodies(cam_name)
        members, frames = self._piece_frames(piece_of, poses0)
        self.members = members
        self.piece_of = piece_of
        self.bodies: dict[str, list[str]] = {}
        for full, body in body_of.items():
            lst = self.bodies.setdefault(body, [])
            if piece_of[full] not in lst:
                lst.append(piece_of[full])
        self._frames = frames
        parts = self._merged_parts()
        # joints
        xf = {full: m for mem in members.values() for full, m in mem}
        main_cam = cam_name[min(cam_name)]
        self.keyed: dict[str, float] = {main_cam: 0.0}
        #: each keyed cam's own part of its key angle (rad): its root stage's turn relative to the first cam's
        #: (``keyed`` = cam phase difference + this; a Ty cam is #1 turned a quarter)
        self.key_turn: dict[str, float] = {main_cam: 0.0}
        joints, dropped = _without_redundant_slides(self._placed_joints(cam_name, main_cam, xf))
        #: slides dropped as repeats of another (same pieces, same line) and the cuts they took with them
        self.redundant: list[Any] = dropped
        self.removed_features: list[tuple[str, Any]] = []
        if dropped:  # the dropped slides' own cuts go too: their slot on the guide, their pin holes on the body
            parts, self.removed_features = _without_cuts_of(parts, dropped, joints)
        joints += self._keyed_shafts(cam_name, main_cam)
        self.main_cam = main_cam
        d = toy.driver
        driver = Driver(main_cam, "rotation", origin=(0.0, 0.0), rate=d.rate, phase=d.phase)
        named = set(rename.values()) & set(piece_of.values())  # effector pieces carry the name themselves
        points = {k: (piece_of[v[0]], _xf_point(xf[v[0]], v[1])) for k, v in toy.points.items() if k not in named}
        super().__init__(f"{toy.name} (assembled)", parts, joints, driver, points)

    # -- construction, one seam each -------------------------------------------------------------
    def _cam_names(self) -> dict[int, str]:
        """Each root stage's cam piece name (``cam.left``, ``cam.right``, numbered when a side has several)."""
        cams: dict[str, list[int]] = {}
        for p in self.placed:
            if p.stage.parent is None:
                cams.setdefault(p.stage.cam, []).append(p.stage.index)
        cam_name: dict[int, str] = {}
        for side, idx in cams.items():
            for k, i in enumerate(idx):
                cam_name[i] = f"cam.{side}" + (f"{k + 1}" if len(idx) > 1 else "")
        return cam_name

    def _pieces_and_bodies(self, cam_name: dict[int, str]) -> tuple[dict[str, str], dict[str, str], dict[str, str]]:
        """Which piece and which rigid body each stage part belongs to, and the named effectors' renames."""
        toy = self.toy
        merged_of: dict[str, str] = {}
        for group in toy.merged:
            for n in group:
                merged_of[n] = group[0]
        piece_of: dict[str, str] = {}
        body_of: dict[str, str] = {}
        for p in self.placed:
            for part in p.stage.mech.parts:
                full = f"{p.label}.{part.name}"
                if part.ground:
                    piece = "frame" if part.plane == "xy" else f"frame.{part.plane}"
                    body = "frame"
                elif part.name == "driver" and p.stage.parent is None:
                    piece = body = cam_name[p.stage.index]
                else:
                    root = merged_of.get(full, full)
                    group = next((g for g in toy.merged if g[0] == root), (full,))
                    same = [n for n in group if self._stage_part(n).plane == part.plane]
                    piece = "+".join(same)
                    body = "+".join(group)
                piece_of[full] = piece
                body_of[full] = body
        # a named end effector's follower that is a piece of its own takes the effector's name
        label_of = {(st.cam, st.key): st.label for st in toy.stages}
        rename = {f"{label_of[k]}.follower": n for k, n in toy.names.items()}
        for full, n in rename.items():
            if piece_of.get(full) == full:
                piece_of[full] = n
                if body_of.get(full) == full:
                    body_of[full] = n
        return piece_of, body_of, rename

    def _piece_frames(
        self, piece_of: dict[str, str], poses0: dict[str, Array]
    ) -> tuple[dict[str, list[tuple[str, XForm]]], dict[str, Array]]:
        """Each piece's members with their transforms into its frame (world for frames, else its first
        member's frame at rest), and the frames."""
        members: dict[str, list[tuple[str, XForm]]] = {}
        for full, piece in piece_of.items():
            members.setdefault(piece, []).append((full, (0.0, 0.0, 0.0)))
        frames: dict[str, Array] = {}
        for piece, mem in members.items():
            first = mem[0][0]
            frames[piece] = np.zeros(3) if self._stage_part(first).ground else poses0[first][0]
            if self._stage_part(first).plane == "yz":
                frames[piece] = poses0[first][0]
            xs = []
            for full, _ in mem:
                rel = poses_compose(poses_invert(frames[piece]), poses0[full][0])
                xs.append((full, (float(rel[0]), float(rel[1]), float(rel[2]))))
            members[piece] = xs
        return members, frames

    def _merged_parts(self) -> list[Part]:
        """One part per piece: its members' outlines merged (:func:`_merge`); its notes go to :attr:`notes`."""
        parts: list[Part] = []
        for piece, mem in self.members.items():
            p0 = self._stage_part(mem[0][0])
            part, notes = _merge(piece, [(self._stage_part(f), m) for f, m in mem], p0.plane, p0.ground)
            if p0.plane == "yz":  # its x offset moves with its stage
                st = self.placed[int(mem[0][0].split(".")[0][1:])]
                part = replace(part, offset=p0.offset + st.place[0])
            self.notes += notes
            parts.append(part)
        return parts

    def _placed_joints(self, cam_name: dict[int, str], main_cam: str, xf: dict[str, XForm]) -> list[Any]:
        """Every stage joint placed between pieces (:data:`PLACERS`), but the axles of the second cams."""
        joints: list[Any] = []
        for p in self.placed:
            for j in p.stage.mech.joints:
                a, b = f"{p.label}.{j.a}", f"{p.label}.{j.b}"
                if (
                    p.stage.parent is None
                    and isinstance(j, Pivot)
                    and {j.a, j.b} == {"ground", "driver"}
                    and cam_name[p.stage.index] != main_cam
                ):
                    continue  # the axle of a second cam: it is keyed to the first instead (below)
                where = f"joint {j.name!r} of stage {p.label}"
                joints.append(_placed(j, f"{p.label}.{j.name}", self.piece_of[a], self.piece_of[b], xf[a], xf[b], p, where))
        return joints

    def _keyed_shafts(self, cam_name: dict[int, str], main_cam: str) -> list[Any]:
        """Every cam but the first keyed to it at its phase (fills :attr:`keyed` and :attr:`key_turn`)."""
        toy = self.toy
        out: list[Any] = []
        size = 1.0
        first = self.placed[min(cam_name)]
        for i, name in sorted(cam_name.items()):
            if name == main_cam:
                continue
            ph = toy.cam_phase[self.placed[i].stage.cam] - toy.cam_phase[first.stage.cam]
            # a root stage turned by its realisation (Rz->Ty is #1 turned a quarter) turns its cam as much
            turn = self.placed[i].place[2] - first.place[2]
            self.key_turn[name] = float(wrap_angle(np.array([turn]))[0])
            ph = float(wrap_angle(np.array([ph + turn]))[0])
            self.keyed[name] = float(ph)
            out.append(KeyedShaft(f"{name}.key", main_cam, name, (0.0, 0.0), (0.0, 0.0), float(ph), size))
        return out

    def _stage_part(self, full: str) -> Part:
        label, name = full.split(".", 1)
        return self.placed[int(label[1:])].stage.mech.part(name)

    def _stage_poses(self, q: Array) -> tuple[dict[str, Array], list]:
        """Every stage part's pose track at its place (world; xz/yz parts in their plane's coordinates)."""
        toy = self.toy
        _, checks = toy.world_motion(q)
        out: dict[str, Array] = {}
        for p in self.placed:
            st = p.stage
            u, res = toy._last_bases[st.index]
            tracks = {
                "ground": np.zeros((q.size, 3)),
                "driver": st.mech._driver_pose(u),
                "follower": st.mech._follower_pose(res.out),
            }
            for name, pose in tracks.items():
                out[f"{p.label}.{name}"] = _world_track(p, st.mech.part(name), np.asarray(pose, float))
        return out, checks

    def _solve_poses(self, q: Array):
        stage_poses, checks = self._stage_poses(q)
        return self.piece_poses(stage_poses), checks

    def piece_poses(self, stage_poses: Mapping[str, Array]) -> dict[str, Array]:
        """Every piece's pose track from its first member's (a stage part's) track at its place."""
        poses: dict[str, Array] = {}
        for piece, mem in self.members.items():
            full, m = mem[0]
            poses[piece] = poses_compose(stage_poses[full], poses_invert(np.array(m)))
        return poses

    def stage_poses(self, q: Array) -> dict[str, Array]:
        """Every stage part's own pose track at its place (for drawing a stage's parts one by one)."""
        return self._stage_poses(np.asarray(q, float))[0]

    def part_rates(self, q: Array, qd: Array, qdd: Array) -> RatesResult:
        """Rates of every piece (see :meth:`Mechanism.part_rates`), from the rates of the toy's stages.

        Each piece is a stage part (its first member) at the stage's place, then offset on its body.  The
        place is a turn by ``a`` about z and a shift for an xy stage, a shift for xz and yz
        (:func:`_world_track`): the stage part's velocity and acceleration turn by ``a``, its angular rates
        do not change; the piece's origin is a point of that body (``v + omega x r``,
        ``a + alpha x r - omega^2 r``, ``r`` from the stage part's origin to the piece's).
        """
        from planar.core.fields import check_driver_rates

        q, qd, qdd = check_driver_rates(f"{self.name}.part_rates", q, qd, qdd, names=("qd", "qdd"))
        raw, ok, _ = self.toy.part_rates(q, qd, qdd)
        stage_poses = self.stage_poses(q)
        pieces = self.piece_poses(stage_poses)
        out: dict[str, PartRates] = {}
        for piece, members in self.members.items():
            full = members[0][0]
            r0 = raw[full]
            v, a = np.asarray(r0.v, float), np.asarray(r0.a, float)
            if self._stage_part(full).plane == "xy":
                ang = self.placed[int(full.split(".")[0][1:])].place[2]
                c, s_ = np.cos(ang), np.sin(ang)
                v = np.column_stack([c * v[:, 0] - s_ * v[:, 1], s_ * v[:, 0] + c * v[:, 1]])
                a = np.column_stack([c * a[:, 0] - s_ * a[:, 1], s_ * a[:, 0] + c * a[:, 1]])
            r = pieces[piece][:, :2] - stage_poses[full][:, :2]
            om = np.broadcast_to(np.asarray(r0.omega, float), q.shape)
            al = np.broadcast_to(np.asarray(r0.alpha, float), q.shape)
            pv = np.column_stack([v[:, 0] - om * r[:, 1], v[:, 1] + om * r[:, 0]])
            pa = np.column_stack([a[:, 0] - al * r[:, 1] - om * om * r[:, 0], a[:, 1] + al * r[:, 0] - om * om * r[:, 1]])
            out[piece] = PartRates(pv, pa, om, al)
        method = (
            "wind-up closed forms differentiated analytically, composed through the toy's stages, turned to each piece's place"
        )
        return out, ok, method

    def piece_count(self) -> dict[str, int]:
        """Cut pieces per plane."""
        out: dict[str, int] = {}
        for p in self.parts:
            out[p.plane] = out.get(p.plane, 0) + 1
        return out


def toy_assembly(toy: Any) -> ToyAssembly:
    """The assembly of a :class:`~planar.windup.chain.ToyMechanism` (cached on the toy)."""
    from planar.core.fields import check_kind

    check_kind("toy_assembly(toy)", toy, ToyMechanism, "a ToyMechanism (planar.windup.chain)")
    got = getattr(toy, "_assembly", None)
    if got is None:
        got = ToyAssembly(toy)
        toy._assembly = got
    return got


def assembly_refusal(chain: Any) -> str | None:
    """Why a chain (a sequence of patterns) cannot be built as one toy, or ``None`` when it can."""
    from planar.errors import PlanarError
    from planar.windup.chain import chain_mechanism

    try:
        toy_assembly(chain_mechanism(tuple(chain)))
    except InputError as e:
        stage = e.field.split(".stage ", 1)[-1].split()[-1]
        return f"its stage {stage} is {e.value}; needed: {e.expected}"
    except PlanarError as e:
        return str(e)
    return None


def assembly_residual(asm: ToyAssembly, samples: int = 73) -> dict[str, float]:
    """Largest residual of every joint of ``asm`` over one cycle (valid samples), model units."""
    m = asm.run(samples_per_cycle=samples)
    ok = m.valid
    return {j.name: float(np.max(np.asarray(j.residual(m.poses))[ok], initial=0.0)) for j in asm.joints}
