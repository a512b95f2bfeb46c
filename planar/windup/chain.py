"""Chains and trees of elemental mechanisms on one motor: composition, cost, ranking.

A :class:`ToyMechanism` is a motion transfer tree per motor cam (``"left"``
and ``"right"``, the right cam ``phase`` radians ahead).  Chains sharing their
first mechanisms are merged, so every distinct prefix is one *stage*, built
once.  A stage's driver and its parent stage's follower are one physical part
(``merged`` lists the groups); its input is the parent's output carried
through the two realisations' rotations, so the end effector's motion is the
exact composition of the closed forms.  A failure anywhere marks the sample
invalid, naming the stage and its joint; every later stage inherits it.

Drawing layout: each stage is drawn in its own mechanism's view (xy, or xz
for #8), laid out left to right by depth and top to bottom by branch (an
exploded view); ``world_motion`` gives every stage's output in world axes.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from planar.core.model import CamOnLine, Driver, Mechanism, Part, PinInArcSlot, PinInSlot, Pivot, Slide, check_finite
from planar.core.rates import PartRates, RatesResult
from planar.core.registry import Registry
from planar.errors import InputError
from planar.windup.mechanisms import ELEMENTAL, ElementalMechanism, SkewContact
from planar.windup.rates import stage_part_rates
from planar.windup.table import MOTION_TYPES, Realisation, enumerate_chains, realise

__all__ = ["Chain", "ToyMechanism", "bunny", "chain_mechanism", "horse", "rank_trees", "tree_cost"]

Array = NDArray[np.float64]
Chain = tuple[str, ...]


def _check_chain(chain: Sequence[str], where: str = "chain") -> Chain:
    if isinstance(chain, str) or not hasattr(chain, "__iter__"):
        raise InputError(where, chain, "a list of patterns, e.g. ['Rz->Tx', 'Tx->Ox']")
    chain = tuple(chain)
    if not chain:
        raise InputError(where, chain, "at least one pattern")
    prev = "Rz"
    for i, p in enumerate(chain):
        if not isinstance(p, str):
            raise InputError(f"{where}[{i}]", p, "a pattern 'A->B', e.g. 'Rz->Tx'")
        try:
            r = realise(p)  # validates the pattern's form
        except InputError as e:
            raise InputError(f"{where}[{i}]", p, e.expected) from None
        a, b = p.split("->")
        if a != prev:
            raise InputError(f"{where}[{i}]", p, f"a pattern driven by {prev} (the previous stage's output)")
        prev = b
        del r
    return chain


def _to_world(r: Realisation, out: Array) -> Array:
    """A stage's follower motion in world axes."""
    if out.ndim == 2:  # OzT: (dx, dy, alpha)
        R = r.matrix
        d = out[:, :2] @ R[:2, :2].T
        return np.column_stack([d, out[:, 2] * R[2, 2]])
    return r.sign_out * out


def _to_base(r: Realisation, world: Array) -> Array:
    """World driver motion into the stage mechanism's own axes."""
    if world.ndim == 2:
        R = r.matrix
        d = world[:, :2] @ R[:2, :2]
        return np.column_stack([d, world[:, 2] * R[2, 2]])
    return r.sign_in * world


@dataclass
class _Stage:
    key: Chain  # the prefix this stage ends
    realisation: Realisation
    mech: ElementalMechanism
    parent: int | None
    cam: str
    offset: tuple[float, float] = (0.0, 0.0)

    @property
    def label(self) -> str:
        return f"s{self.index}"

    index: int = 0


class ToyMechanism(Mechanism):
    """Motion transfer trees on one motor (one per cam), composed into one mechanism.

    ``cams`` maps ``"left"``/``"right"`` to the chains hanging on that cam;
    ``phase`` (rad) is the right cam's lead.  ``overrides`` maps a pattern
    prefix (a chain tuple), or ``(cam, prefix)`` for one cam's stage only, to
    parameter overrides of that stage's mechanism.  ``names`` maps
    ``(cam, prefix)`` to a name for that stage's end effector: a named point at
    its follower's origin (trails, motion tables).
    """

    def __init__(
        self,
        cams: Mapping[str, Sequence[Sequence[str]]],
        phase: float = math.pi,
        name: str = "toy",
        rate: float = 2 * math.pi,
        overrides: Mapping[Any, Mapping[str, Any]] | None = None,
        samples: int = 721,
        names: Mapping[tuple[str, Chain], str] | None = None,
    ) -> None:
        if not cams:
            raise InputError(f"{name}.cams", cams, "at least one cam with a chain")
        for cam in cams:
            if cam not in ("left", "right"):
                raise InputError(f"{name}.cams", cam, "'left' or 'right'")
        self.cams = {cam: [_check_chain(c, f"{cam}[{i}]") for i, c in enumerate(chains)] for cam, chains in cams.items()}
        self.phase = float(check_finite(f"{name}.phase", phase))
        from planar.core.limits import check_angle

        check_angle(f"{name}.phase", self.phase)
        self.cam_phase = {"left": 0.0, "right": self.phase}
        overrides = dict(overrides or {})
        #: the parameter overrides given, by ``(cam, prefix)`` (what a scene file's ``stages`` record)
        self.stage_overrides: dict[tuple[str, Chain], dict[str, Any]] = {}
        self.stages: list[_Stage] = []
        index: dict[tuple[str, Chain], int] = {}
        q = np.linspace(0.0, 2 * math.pi, samples)
        world_out: dict[int, Array] = {}
        for cam, chains in self.cams.items():
            for chain in chains:
                for depth in range(1, len(chain) + 1):
                    key = chain[:depth]
                    if (cam, key) in index:
                        continue
                    parent = index.get((cam, key[:-1])) if depth > 1 else None
                    r = realise(key[-1])
                    u = _to_base(r, q + self.cam_phase[cam]) if parent is None else _to_base(r, world_out[parent])
                    kw = dict(overrides.get((cam, key)) or overrides.get(key) or {})
                    if kw:
                        self.stage_overrides[(cam, key)] = dict(kw)
                    mech = self._build_stage(r, u, kw, name, key)
                    st = mech.forward(u)
                    world_out[len(self.stages)] = _to_world(r, st.out)
                    stage = _Stage(key, r, mech, parent, cam, index=len(self.stages))
                    index[(cam, key)] = len(self.stages)
                    self.stages.append(stage)
        self._layout()
        parts, joints, merged = self._assemble()
        self.merged = merged
        first = self.stages[0]
        driver = Driver(f"{first.label}.driver", "rotation", origin=first.offset, rate=rate)
        points = {}
        for cam, chains in self.cams.items():
            for chain in chains:
                leaf = self.stages[index[(cam, chain)]]
                points[f"{cam}:{chain[-1].split('->')[1]}@{leaf.label}"] = (f"{leaf.label}.follower", (0.0, 0.0))
        self.names = {(cam, tuple(c)): str(n) for (cam, c), n in (names or {}).items()}
        for (cam, c), n in self.names.items():
            if (cam, c) not in index:
                raise InputError(f"{name}.names", n, f"a stage of the toy ({cam} {' '.join(c)} is none)")
            points[n] = (f"{self.stages[index[(cam, c)]].label}.follower", (0.0, 0.0))
        self.end_effectors = {cam: [index[(cam, c)] for c in chains] for cam, chains in self.cams.items()}
        super().__init__(name, parts, joints, driver, points)

    # -- construction --------------------------------------------------------
    @staticmethod
    def _build_stage(r: Realisation, u: Array, kw: dict, name: str, key: Chain) -> ElementalMechanism:
        k = r.number
        try:
            if u.ndim == 2:
                return ElementalMechanism(k, sizing_input=u, **kw)
            if ELEMENTAL[k].motions[0] == "Rz":  # turning drivers: full turns
                return ElementalMechanism(k, **kw)
            amp = float(np.max(np.abs(u)))
            if amp > 0 and "amplitude" not in kw:
                kw["amplitude"] = amp
            return ElementalMechanism(k, **kw)
        except InputError as e:
            raise InputError(f"{name}.stage {' '.join(key)}", kw, f"a stage that can be built ({e})") from None

    def _layout(self) -> None:
        """Exploded layout: x by depth, y by branch (each stage in its own panel)."""
        widths: dict[int, float] = {}
        heights: dict[int, float] = {}
        for st in self.stages:
            ext = np.array([(x, y) for p in st.mech.parts for x, y, _ in p.hull])
            widths[st.index] = float(np.ptp(ext[:, 0])) + 0.4
            heights[st.index] = float(np.ptp(ext[:, 1])) + 0.4
        col_x: dict[int, float] = {}
        depth_w: dict[int, float] = {}
        for st in self.stages:
            d = len(st.key)
            depth_w[d] = max(depth_w.get(d, 0.0), widths[st.index])
        x = 0.0
        for d in sorted(depth_w):
            col_x[d] = x
            x += depth_w[d]
        row_y = 0.0
        for cam in self.cams:
            leaves = [st for st in self.stages if st.cam == cam]
            # one row per distinct chain position at each depth
            rows: dict[int, int] = {}
            for st in leaves:
                d = len(st.key)
                rows[d] = rows.get(d, 0)
                st.offset = (col_x[d], row_y - rows[d] * max(heights.values()))
                rows[d] += 1
            row_y -= max(rows.values()) * max(heights.values())

    def _assemble(self) -> tuple[list[Part], list, list[tuple[str, ...]]]:
        parts: list[Part] = []
        joints: list = []
        children: dict[int, list[int]] = {}
        for st in self.stages:
            ox, _oy = st.offset
            for p in st.mech.parts:
                name = f"{st.label}.{p.name}"
                off = p.offset + ox if p.plane == "yz" else p.offset
                parts.append(replace(p, name=name, offset=off))
            for j in st.mech.joints:
                joints.append(_rename_joint(j, st.label, ox))
            if st.parent is not None:
                children.setdefault(st.parent, []).append(st.index)
        merged = []
        for parent, kids in children.items():
            merged.append((f"s{parent}.follower", *[f"s{k}.driver" for k in kids]))
        return parts, joints, merged

    # -- kinematics -------------------------------------------------------------
    def world_motion(self, q: Array) -> tuple[dict[int, Array], list[tuple[NDArray[np.bool_], str, str]]]:
        """Every stage's follower motion in world axes, and per-stage validity checks."""
        q = np.asarray(q, float)
        outs: dict[int, Array] = {}
        bases: dict[int, tuple[Array, Any]] = {}
        checks = []
        valid_in: dict[int, NDArray[np.bool_]] = {}
        for st in self.stages:
            r = st.realisation
            if st.parent is None:
                u = _to_base(r, q + self.cam_phase[st.cam])
                ok_in = np.ones(q.shape, bool)
            else:
                u = _to_base(r, outs[st.parent])
                ok_in = valid_in[st.parent]
            res = st.mech.forward(u)
            outs[st.index] = _to_world(r, res.out)
            valid_in[st.index] = ok_in & res.valid
            bases[st.index] = (u, res)
            checks.append(
                (
                    res.valid,
                    f"{st.label}.{ELEMENTAL[r.number].contact_joint}",
                    f"stage {st.label} ({r.pattern}, mechanism #{r.number}): {res.why}",
                )
            )
        self._last_bases = bases
        return outs, checks

    def _solve_poses(self, q: Array):
        _, checks = self.world_motion(q)
        poses: dict[str, Array] = {}
        for st in self.stages:
            u, res = self._last_bases[st.index]
            ox, oy = st.offset
            dp = st.mech._driver_pose(u)
            fp = st.mech._follower_pose(res.out)
            gp = np.zeros((q.size, 3))
            for pname, pose, part in (
                ("ground", gp, st.mech.part("ground")),
                ("driver", dp, st.mech.part("driver")),
                ("follower", fp, st.mech.part("follower")),
            ):
                pose = pose.copy()
                if part.plane == "yz":
                    pose[:, 0] += oy
                else:
                    pose[:, 0] += ox
                    pose[:, 1] += oy
                poses[f"{st.label}.{pname}"] = pose
        return poses, checks

    def part_rates(self, q: Array, qd: Array, qdd: Array) -> RatesResult:
        """Rates of every stage's parts (see :meth:`Mechanism.part_rates`): each stage's input is its parent's
        output (or the motor's at its cam's phase) through the same linear axis maps as the motions."""
        from planar.core.fields import check_driver_rates

        q, qd, qdd = check_driver_rates(f"{self.name}.part_rates", q, qd, qdd, names=("qd", "qdd"))
        outs: dict[int, tuple[Array, Array, Array]] = {}
        valid = np.ones(q.shape, bool)
        parts: dict[str, PartRates] = {}
        for st in self.stages:
            r = st.realisation
            if st.parent is None:
                u = (_to_base(r, q + self.cam_phase[st.cam]), _to_base(r, qd), _to_base(r, qdd))
            else:
                pw = outs[st.parent]
                u = (_to_base(r, pw[0]), _to_base(r, pw[1]), _to_base(r, pw[2]))
            res = st.mech.forward(u[0])
            o1, o2, ok = st.mech.record.rates(st.mech.params, u[0], u[1], u[2])
            valid &= ok & res.valid
            outs[st.index] = (_to_world(r, res.out), _to_world(r, o1), _to_world(r, o2))
            for name, rates in stage_part_rates(st.mech.motion_in, st.mech.record.follower_motion, u, o1, o2).items():
                parts[f"{st.label}.{name}"] = rates
        return parts, valid, "wind-up closed forms differentiated analytically, composed through the toy's stages"

    @property
    def mechanism_count(self) -> int:
        """Number of elemental mechanisms (distinct stages)."""
        return len(self.stages)

    @property
    def cost(self) -> float:
        """The paper's cost: mechanisms + 2 x mean chain length."""
        return tree_cost(self.cams)


#: how chain composition places a stage's joint in the toy: (joint, stage label, stage x offset) -> joint
COMPOSERS: Registry[Callable[[Any, str, float], Any]] = Registry("chain composition")


@COMPOSERS.register(Pivot, PinInSlot, PinInArcSlot, Slide, CamOnLine)
def _renamed(j: Any, label: str, ox: float) -> Any:
    """A planar joint: its parts and name take the stage's label (part frames move with the parts)."""
    return replace(j, name=f"{label}.{j.name}", a=f"{label}.{j.a}", b=f"{label}.{j.b}")


@COMPOSERS.register(SkewContact)
def _renamed_skew(j: SkewContact, label: str, ox: float) -> SkewContact:
    """The spatial contact also carries the pin's world x, which the stage's offset moves."""
    return replace(_renamed(j, label, ox), pin_x=j.pin_x + ox)


def _rename_joint(j: Any, label: str, ox: float) -> Any:
    return COMPOSERS.get(j, f"joint {j.name!r}")(j, label, ox)


def chain_mechanism(chain: Sequence[str], **kw: Any) -> ToyMechanism:
    """One chain on the left cam, composed into a mechanism."""
    chain = _check_chain(chain)  # errors name chain[i]
    return ToyMechanism({"left": [chain]}, name=kw.pop("name", " ".join(chain)), **kw)


def tree_cost(cams: Mapping[str, Iterable[Sequence[str]]]) -> float:
    """``N + 2 * mean(chain length)``: N distinct mechanisms after merging shared prefixes per cam."""
    nodes = set()
    lengths = []
    for cam, chains in cams.items():
        for c in chains:
            c = tuple(c)
            lengths.append(len(c))
            for d in range(1, len(c) + 1):
                nodes.add((cam, c[:d]))
    if not lengths:
        raise InputError("cams", dict(cams), "at least one chain")
    return len(nodes) + 2.0 * float(np.mean(lengths))


def rank_trees(
    targets: Sequence[str],
    max_length: int = 3,
    top: int = 10,
    optional: bool = False,
    cams: Sequence[str] = ("left", "right"),
    limit: int = 2_000_000,
) -> list[tuple[float, dict[str, list[Chain]]]]:
    """Candidate trees for the requested end-effector motions, cheapest first.

    Each target takes one chain (up to ``max_length``) on one cam; ties keep
    enumeration order.  Returns ``(cost, {cam: [chains]})`` pairs.
    """
    if not targets:
        raise InputError("targets", list(targets), "at least one end-effector motion")
    options = []
    for t in targets:
        if t not in MOTION_TYPES:
            raise InputError("targets", t, f"one of {', '.join(MOTION_TYPES)}")
        options.append(enumerate_chains(t, max_length, optional)[t])
    n = math.prod(len(o) for o in options) * len(cams) ** len(targets)
    if n > limit:
        raise InputError("targets", list(targets), f"fewer combinations than {limit:,} (this request has {n:,})")
    scored = []
    for combo in itertools.product(*options):
        for sides in itertools.product(cams, repeat=len(targets)):
            tree: dict[str, list[Chain]] = {}
            for c, s in zip(combo, sides):
                tree.setdefault(s, []).append(c)
            scored.append((tree_cost(tree), tree))
    scored.sort(key=lambda x: x[0])
    # drop mirror images (left/right swapped) with equal cost
    out, seen = [], set()
    for cost, tree in scored:
        sig = frozenset(tuple(sorted(v)) for v in tree.values())
        if sig in seen:
            continue
        seen.add(sig)
        out.append((cost, tree))
        if len(out) == top:
            break
    return out


def horse(**kw: Any) -> ToyMechanism:
    """The paper's Horse: Rz->OzT->Oz on one cam, Rz->OzT->{Ty, Oz} (legs) on the other, half a turn apart."""
    return ToyMechanism(
        {
            "left": [("Rz->OzT", "OzT->Oz")],
            "right": [("Rz->OzT", "OzT->Ty"), ("Rz->OzT", "OzT->Oz")],
        },
        phase=kw.pop("phase", math.pi),
        name=kw.pop("name", "horse"),
        **kw,
    )


def bunny(**kw: Any) -> ToyMechanism:
    """The paper's Bunny: Rz->Tx->{Ox, Oy} (ears on one slider)."""
    return ToyMechanism({"left": [("Rz->Tx", "Tx->Ox"), ("Rz->Tx", "Tx->Oy")]}, name=kw.pop("name", "bunny"), **kw)
