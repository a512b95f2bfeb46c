"""General pivot/slot linkages built from dyads (Assur groups of class II).

A linkage is a list of *nodes* (joint centres), each placed in closed form from
nodes declared before it, and a list of *links* (rigid parts) naming the nodes
they carry.  Every node kind is one class that declares itself (the
:class:`NodeKind` contract, like pylinkage's ``Component``): the nodes it
references, how its position and its velocity follow from theirs, and its
name in scene files.  ``NODE_KINDS`` maps that name to the class.

* :class:`Fixed` (``"fixed"``) — a point on the ground.
* :class:`Crank` (``"crank"``) — rotates about a node:
  ``centre + r (cos(q + phase), sin(q + phase))`` with ``q`` the driver angle.
* :class:`Actuator` (``"actuator"``) — translates with the driver:
  ``origin + (q + offset) * axis``.
* :class:`RRR` (``"rrr"``) — distance ``ra`` from node ``a`` and ``rb`` from
  node ``b`` (circle-circle).  ``branch=+1`` starts it to the left of ``a -> b``.
* :class:`RRP` (``"rrp"``) — distance ``ra`` from ``a`` and on the line
  through ``p -> q`` (shifted left by ``offset``), line-circle.
  ``branch=+1`` starts it at the root further along ``p -> q``.
* :class:`Rigid` (``"rigid"``) — fixed in the frame of nodes ``a, b``:
  ``a + u e + v e_perp`` with ``e`` the unit vector ``a -> b`` (coupler
  points, ternary links, a lever's far end).

A link's frame has its origin at its first node and its x axis toward its
second; a link with one node and a ``guide`` ``(p, q)`` keeps the guide
line's direction (a slider block).  Joints follow from the declaration: a
node shared by links is a pivot; an RRP node is a pin in a straight slot of
the link that carries the line; a guided link is a block sliding along the
line of the link that carries ``p`` and ``q``, which may itself move (the
inverted slider-crank family: a quick return's block in its slotted lever, an
oscillating cylinder's piston).  Each link is checked to be rigid: nodes on
one link that move relative to each other are refused when the linkage is
built.

Every node is solved for all driver values at once (numpy, no per-sample
loop).  **Branches.**  The samples are taken as a path, in their order: the
declared branch holds at the first sample, and is carried by continuity of
the motion through singular samples (two roots meeting, as a change-point
four-bar's at its flat positions, or a dyad's two centres passing through
each other, as a kite's): at each sample the root taken is the one that
continues the quadratic extrapolation of the node's three previous valid
samples, where that prediction prefers the other root by a factor of 4.
Continuity is only applied where the driver steps of those samples have one
sign and agree within a factor of 1.5 (a path, not a scattered batch), so a
batch of unrelated driver values gets the declared branch throughout.
Where a dyad cannot close the sample is invalid with the node named.

:meth:`Linkage.solve` takes the chunked, threaded path of
:mod:`planar.linkages.chunked`, which gives the same motion and hands a batch
to the reference solve here (:meth:`Linkage.solve_nodes`) wherever a branch
may switch by continuity.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

from planar.core.geometry import circle_circle, line_circle, poses_apply, poses_compose, poses_invert
from planar.core.model import Driver, Mechanism, Part, PinInSlot, Pivot, Slide, check_finite, check_positive
from planar.errors import AssemblyError, InputError
from planar.linkages.chunked import Solved, _Plan, fast_solve, plan_for

__all__ = [
    "NODE_KINDS",
    "RRP",
    "RRR",
    "Actuator",
    "Crank",
    "Fixed",
    "Link",
    "Linkage",
    "Node",
    "NodeKind",
    "Rigid",
    "carry_branch",
    "frame_rates",
    "node_kind",
]

Vec = tuple[float, float]
Array = NDArray[np.float64]
Mask = NDArray[np.bool_]
Check = tuple[Mask, str]

#: every node kind, by its scene name (filled by :func:`node_kind`)
NODE_KINDS: dict[str, type[NodeKind]] = {}


def node_kind(cls: type[NodeKind]) -> type[NodeKind]:
    """Class decorator: register a node kind under its ``kind`` name (a double is a :class:`TypeError`)."""
    name = cls.__dict__.get("kind")
    if not isinstance(name, str):
        raise TypeError(f"node kind {cls.__name__} needs a class attribute 'kind'")
    if name in NODE_KINDS:
        raise TypeError(f"double registration for node kind {name!r}")
    NODE_KINDS[name] = cls
    return cls


def _perp(v: Array) -> Array:
    return np.stack([-v[:, 1], v[:, 0]], -1)


def _cross(a: Array, b: Array) -> Array:
    return a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]


def _dot(a: Array, b: Array) -> Array:
    """Row-wise dot product of ``(N, 2)`` arrays (faster than ``(a * b).sum(-1)``)."""
    return a[:, 0] * b[:, 0] + a[:, 1] * b[:, 1]


def _solve2(r1: Array, b1: Array, r2: Array, b2: Array) -> tuple[Array, Mask]:
    """Solve ``r1 . v = b1, r2 . v = b2`` per sample (Cramer); ``ok`` false where singular."""
    det = r1[:, 0] * r2[:, 1] - r1[:, 1] * r2[:, 0]
    scale = np.hypot(r1[:, 0], r1[:, 1]) * np.hypot(r2[:, 0], r2[:, 1])
    sing = np.abs(det) <= 1e-12 * scale
    det = np.where(sing, 1.0, det)
    vx = (b1 * r2[:, 1] - b2 * r1[:, 1]) / det
    vy = (r1[:, 0] * b2 - r2[:, 0] * b1) / det
    return np.stack([vx, vy], -1), ~sing


def frame_rates(d: Array, vd: Array, ad: Array) -> tuple[Array, Array]:
    """Angular velocity and acceleration of the direction ``d`` ``(N, 2)`` (rad/s, rad/s^2, CCW positive).

    ``phi = atan2(d)``: ``omega = cross(d, d') / |d|^2`` and
    ``alpha = cross(d, d'') / |d|^2 - 2 omega (d . d') / |d|^2``.
    """
    n2 = _dot(d, d)
    n2 = np.where(n2 > 0, n2, 1.0)
    omega = _cross(d, vd) / n2
    return omega, _cross(d, ad) / n2 - 2.0 * omega * _dot(d, vd) / n2


def carry_branch(keep: Array, other: Array, valid: Mask, path: Mask) -> NDArray[np.bool_]:
    """Where the motion continues on the ``other`` root rather than the declared one.

    ``keep`` and ``other`` are the two roots ``(N, 2)`` of a dyad, ``valid``
    where it closes, ``path[k]`` where samples ``k-3 .. k`` are a path (see the
    module's note on branches).  Returns ``flip`` ``(N,)``: the samples where
    the other root is taken.  Each switch is found with array operations over
    the remaining samples; the loop runs once per switch plus once.
    """
    n = keep.shape[0]
    flip = np.zeros(n, dtype=bool)
    if n < 4:
        return flip
    idx = np.arange(n)
    last = np.maximum.accumulate(np.where(valid, idx, -1))
    prev = np.concatenate([[-1], last[:-1]])  # prev[k]: the last valid sample before k

    def back(i: NDArray[np.int_]) -> NDArray[np.int_]:
        return np.where(i >= 0, prev[np.maximum(i, 0)], -1)

    p1 = prev
    p2 = back(p1)
    p3 = back(p2)
    p4 = back(p3)
    ok = valid & (p4 >= 0) & (idx - p4 <= 10) & path
    ks = np.flatnonzero(ok)
    if ks.size == 0:
        return flip
    i1, i2, i3, i4 = p1[ks], p2[ks], p3[ks], p4[ks]

    def lagrange(t: Array, t1: Array, t2: Array, t3: Array) -> tuple[Array, Array, Array]:
        return (
            (t - t2) * (t - t3) / ((t1 - t2) * (t1 - t3)),
            (t - t1) * (t - t3) / ((t2 - t1) * (t2 - t3)),
            (t - t1) * (t - t2) / ((t3 - t1) * (t3 - t2)),
        )

    # quadratic (Lagrange) extrapolation in the sample index to k, and (the check of its credibility) to the
    # previous sample from the three before it
    f = [a.astype(float) for a in (ks, i1, i2, i3, i4)]
    w1, w2, w3 = lagrange(f[0], f[1], f[2], f[3])
    v1, v2, v3 = lagrange(f[1], f[2], f[3], f[4])
    cur = keep.copy()
    alt = other.copy()
    start = 0
    while True:
        sel = slice(start, None)
        k, a1, a2, a3, a4 = ks[sel], i1[sel], i2[sel], i3[sel], i4[sel]
        pred = w1[sel, None] * cur[a1] + w2[sel, None] * cur[a2] + w3[sel, None] * cur[a3]
        dk = np.hypot(*(cur[k] - pred).T)
        da = np.hypot(*(alt[k] - pred).T)
        # the extrapolation's own miss one sample back: a flip needs the jump to stand out from it (coarse
        # samples, a few per turn, extrapolate badly and must not trade the declared branch for the other one)
        miss = np.hypot(*(cur[a1] - (v1[sel, None] * cur[a2] + v2[sel, None] * cur[a3] + v3[sel, None] * cur[a4])).T)
        hit = np.flatnonzero((4.0 * da < dk) & (4.0 * miss < dk))
        if hit.size == 0:
            return flip
        j = int(k[hit[0]])
        flip[j:] ^= True
        cur[j:], alt[j:] = alt[j:].copy(), cur[j:].copy()
        start += int(hit[0]) + 1


class NodeKind:
    """What a node kind declares (subclasses are frozen dataclasses with a ``name``).

    ``kind`` is its name in scene files, ``scene_fields`` the scene keys
    passed to its constructor after ``name`` (``angle_fields`` among them are
    angles, converted from the scene's angle unit).  ``is_input``: the node
    moves with the driver value.
    """

    kind: ClassVar[str]
    scene_fields: ClassVar[tuple[str, ...]] = ()
    angle_fields: ClassVar[tuple[str, ...]] = ()
    is_input: ClassVar[bool] = False
    name: str

    def refs(self) -> tuple[str, ...]:
        """The nodes this one is placed from (declared before it)."""
        return ()

    def validate(self, where: str) -> None:
        """Raise :class:`InputError` (naming ``where``) for unusable values."""

    def position(self, pos: Mapping[str, Array], q: Array, path: Mask) -> tuple[Array, Check | None]:
        """World position ``(N, 2)`` and, for a node that can fail to close, ``(valid, why)``."""
        raise NotImplementedError

    def velocity(self, pos: Mapping[str, Array], vel: Mapping[str, Array], qd: Array) -> tuple[Array, Mask | None]:
        """Velocity ``(N, 2)`` from the positions and the velocities of the nodes before it.

        ``qd`` is the driver's rate (rad/s or units/s) per sample; ``ok``
        false where the differentiated closure is singular (a toggle).
        """
        raise NotImplementedError

    def acceleration(
        self, pos: Mapping[str, Array], vel: Mapping[str, Array], acc: Mapping[str, Array], qd: Array, qdd: Array
    ) -> tuple[Array, Mask | None]:
        """Acceleration ``(N, 2)`` from the closure differentiated twice (no differencing).

        ``pos``, ``vel`` hold every node's position and velocity (this one's
        included), ``acc`` the accelerations of the nodes before it; ``qd`` and
        ``qdd`` the driver's rate and its rate of change per sample.  ``ok``
        false where the closure is singular (a toggle), as for :meth:`velocity`.
        A kind without one refuses rates (velocities, accelerations, torque) by name.
        """
        from planar.core.registry import UnsupportedError

        raise UnsupportedError(
            f"rates (accelerations): node kind {self.kind!r} ({type(self).__name__}) has no acceleration method"
        )

    def held_by(self) -> tuple[tuple[str, ...], ...]:
        """Groups of nodes (this one included) that one link must carry to hold this node's constraint."""
        return ()

    def branch_of(self, pos: Mapping[str, Array]) -> int | None:
        """Which branch (+1 or -1) the node's last position in ``pos`` is on; ``None`` for kinds without one."""
        return None

    def bind(self, where: str, nodes: Mapping[str, NodeKind]) -> NodeKind:
        """This node, given every node of its linkage (those before it bound): a kind that needs another node's
        declaration (a gear's partner, a triad's members) returns a copy holding it, or raises :class:`InputError`."""
        return self

    def velocity_at(self, pos: Mapping[str, Array], vel: Mapping[str, Array], q: Array, qd: Array) -> tuple[Array, Mask | None]:
        """:meth:`velocity` for kinds that also need the driver values ``q``."""
        return self.velocity(pos, vel, qd)

    def acceleration_at(
        self, pos: Mapping[str, Array], vel: Mapping[str, Array], acc: Mapping[str, Array], q: Array, qd: Array, qdd: Array
    ) -> tuple[Array, Mask | None]:
        """:meth:`acceleration` for kinds that also need the driver values ``q``."""
        return self.acceleration(pos, vel, acc, qd, qdd)

    def extra_joints(self, lk: Linkage, hulls: dict[str, list[tuple[float, float, float]]]) -> list:
        """Joints this node adds beyond those its links imply (a gear mesh); may add hull circles."""
        return []


@node_kind
@dataclass(frozen=True)
class Fixed(NodeKind):
    """A point ``xy`` on the ground."""

    kind: ClassVar[str] = "fixed"
    scene_fields: ClassVar[tuple[str, ...]] = ("at",)
    name: str
    xy: Vec

    def validate(self, where: str) -> None:
        check_finite(f"{where}.xy", self.xy)

    def position(self, pos: Mapping[str, Array], q: Array, path: Mask) -> tuple[Array, Check | None]:
        return np.broadcast_to(np.asarray(self.xy, float), (q.shape[0], 2)), None

    def velocity(self, pos: Mapping[str, Array], vel: Mapping[str, Array], qd: Array) -> tuple[Array, Mask | None]:
        return np.zeros((qd.shape[0], 2)), None

    def acceleration(
        self, pos: Mapping[str, Array], vel: Mapping[str, Array], acc: Mapping[str, Array], qd: Array, qdd: Array
    ) -> tuple[Array, Mask | None]:
        return np.zeros((qd.shape[0], 2)), None


@node_kind
@dataclass(frozen=True)
class Crank(NodeKind):
    """Turns about node ``centre`` at ``radius``: angle ``q + phase`` (rad, counter-clockwise)."""

    kind: ClassVar[str] = "crank"
    scene_fields: ClassVar[tuple[str, ...]] = ("centre", "radius", "phase")
    angle_fields: ClassVar[tuple[str, ...]] = ("phase",)
    is_input: ClassVar[bool] = True
    name: str
    centre: str
    radius: float
    phase: float = 0.0

    def refs(self) -> tuple[str, ...]:
        return (self.centre,)

    def held_by(self) -> tuple[tuple[str, ...], ...]:
        return ((self.name, self.centre),)

    def validate(self, where: str) -> None:
        check_positive(f"{where}.radius", self.radius)
        check_finite(f"{where}.phase", self.phase)

    def position(self, pos: Mapping[str, Array], q: Array, path: Mask) -> tuple[Array, Check | None]:
        a = q + self.phase
        return pos[self.centre] + self.radius * np.stack([np.cos(a), np.sin(a)], -1), None

    def velocity(self, pos: Mapping[str, Array], vel: Mapping[str, Array], qd: Array) -> tuple[Array, Mask | None]:
        return vel[self.centre] + qd[:, None] * _perp(pos[self.name] - pos[self.centre]), None

    def acceleration(
        self, pos: Mapping[str, Array], vel: Mapping[str, Array], acc: Mapping[str, Array], qd: Array, qdd: Array
    ) -> tuple[Array, Mask | None]:
        # P = C + r (cos, sin)(q + phase): aP = aC + qdd perp(P - C) - qd^2 (P - C)
        r = pos[self.name] - pos[self.centre]
        return acc[self.centre] + qdd[:, None] * _perp(r) - (qd * qd)[:, None] * r, None


@node_kind
@dataclass(frozen=True)
class Actuator(NodeKind):
    """Translates with the driver: ``origin + (q + offset) * axis / |axis|`` (model units)."""

    kind: ClassVar[str] = "actuator"
    scene_fields: ClassVar[tuple[str, ...]] = ("origin", "axis", "offset")
    is_input: ClassVar[bool] = True
    name: str
    origin: str
    axis: Vec = (1.0, 0.0)
    offset: float = 0.0

    def refs(self) -> tuple[str, ...]:
        return (self.origin,)

    def validate(self, where: str) -> None:
        ax = check_finite(f"{where}.axis", self.axis)
        if np.hypot(*ax) == 0:
            raise InputError(f"{where}.axis", self.axis, "a non-zero direction")
        check_finite(f"{where}.offset", self.offset)

    @property
    def unit_axis(self) -> Array:
        ax = np.asarray(self.axis, float)
        return ax / np.hypot(*ax)

    def position(self, pos: Mapping[str, Array], q: Array, path: Mask) -> tuple[Array, Check | None]:
        return pos[self.origin] + (q + self.offset)[:, None] * self.unit_axis, None

    def velocity(self, pos: Mapping[str, Array], vel: Mapping[str, Array], qd: Array) -> tuple[Array, Mask | None]:
        return vel[self.origin] + qd[:, None] * self.unit_axis, None

    def acceleration(
        self, pos: Mapping[str, Array], vel: Mapping[str, Array], acc: Mapping[str, Array], qd: Array, qdd: Array
    ) -> tuple[Array, Mask | None]:
        return acc[self.origin] + qdd[:, None] * self.unit_axis, None


def _check_branch(where: str, branch: int) -> None:
    if branch not in (1, -1):
        raise InputError(f"{where}.branch", branch, "+1 or -1")


@node_kind
@dataclass(frozen=True)
class RRR(NodeKind):
    """At ``ra`` from node ``a`` and ``rb`` from node ``b`` (circle-circle); ``branch`` +1: left of ``a -> b``."""

    kind: ClassVar[str] = "rrr"
    scene_fields: ClassVar[tuple[str, ...]] = ("a", "ra", "b", "rb", "branch")
    name: str
    a: str
    ra: float
    b: str
    rb: float
    branch: int = 1

    def refs(self) -> tuple[str, ...]:
        return (self.a, self.b)

    def validate(self, where: str) -> None:
        check_positive(f"{where}.ra", self.ra)
        check_positive(f"{where}.rb", self.rb)
        _check_branch(where, self.branch)

    def position(self, pos: Mapping[str, Array], q: Array, path: Mask) -> tuple[Array, Check | None]:
        keep, ok = circle_circle(pos[self.a], self.ra, pos[self.b], self.rb, self.branch)
        other, _ = circle_circle(pos[self.a], self.ra, pos[self.b], self.rb, -self.branch)
        flip = carry_branch(keep, other, ok, path)
        p = np.where(flip[:, None], other, keep) if flip.any() else keep
        return p, (
            ok,
            f"links of length {self.ra:g} (from {self.a!r}) and {self.rb:g} (from {self.b!r}) "
            "cannot span the distance between them",
        )

    def held_by(self) -> tuple[tuple[str, ...], ...]:
        return ((self.name, self.a), (self.name, self.b))

    def branch_of(self, pos: Mapping[str, Array]) -> int | None:
        a, b, p = pos[self.a][-1], pos[self.b][-1], pos[self.name][-1]
        return 1 if (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0]) >= 0 else -1

    def velocity(self, pos: Mapping[str, Array], vel: Mapping[str, Array], qd: Array) -> tuple[Array, Mask | None]:
        # (P - A) . (vP - vA) = 0 and (P - B) . (vP - vB) = 0
        P = pos[self.name]
        r1, r2 = P - pos[self.a], P - pos[self.b]
        return _solve2(r1, (r1 * vel[self.a]).sum(-1), r2, (r2 * vel[self.b]).sum(-1))

    def acceleration(
        self, pos: Mapping[str, Array], vel: Mapping[str, Array], acc: Mapping[str, Array], qd: Array, qdd: Array
    ) -> tuple[Array, Mask | None]:
        # (P - A) . (vP - vA) = 0 differentiated: (P - A) . aP = (P - A) . aA - |vP - vA|^2 (and for B)
        P, vP = pos[self.name], vel[self.name]
        r1, r2 = P - pos[self.a], P - pos[self.b]
        w1, w2 = vP - vel[self.a], vP - vel[self.b]
        return _solve2(r1, _dot(r1, acc[self.a]) - _dot(w1, w1), r2, _dot(r2, acc[self.b]) - _dot(w2, w2))

    def transmission(self, pos: Mapping[str, Array]) -> Array:
        """Transmission angle (rad, in ``[0, pi]``) at this node: between the links to ``a`` and to ``b``."""
        r1, r2 = pos[self.a] - pos[self.name], pos[self.b] - pos[self.name]
        return np.arctan2(np.abs(_cross(r1, r2)), _dot(r1, r2))


@node_kind
@dataclass(frozen=True)
class RRP(NodeKind):
    """At ``ra`` from node ``a`` on the line ``p -> q`` shifted left by ``offset``; ``branch`` +1: further along."""

    kind: ClassVar[str] = "rrp"
    scene_fields: ClassVar[tuple[str, ...]] = ("a", "ra", "p", "q", "branch", "offset")
    name: str
    a: str
    ra: float
    p: str
    q: str
    branch: int = 1
    offset: float = 0.0

    def refs(self) -> tuple[str, ...]:
        return (self.a, self.p, self.q)

    def validate(self, where: str) -> None:
        check_positive(f"{where}.ra", self.ra)
        check_finite(f"{where}.offset", self.offset)
        _check_branch(where, self.branch)

    def position(self, pos: Mapping[str, Array], q: Array, path: Mask) -> tuple[Array, Check | None]:
        p0, p1 = pos[self.p], pos[self.q]
        u = p1 - p0
        un = np.hypot(u[:, 0], u[:, 1])[:, None]
        base = p0 + self.offset * _perp(u) / np.where(un > 0, un, 1.0)
        keep, ok, _ = line_circle(base, u, pos[self.a], self.ra, self.branch)
        other, _, _ = line_circle(base, u, pos[self.a], self.ra, -self.branch)
        flip = carry_branch(keep, other, ok, path)
        p = np.where(flip[:, None], other, keep) if flip.any() else keep
        return p, (ok, f"a link of length {self.ra:g} from {self.a!r} cannot reach the line {self.p!r}-{self.q!r}")

    def held_by(self) -> tuple[tuple[str, ...], ...]:
        return ((self.name, self.a),)

    def branch_of(self, pos: Mapping[str, Array]) -> int | None:
        u = pos[self.q][-1] - pos[self.p][-1]
        # further along p -> q than the foot of the perpendicular from a: +1
        return 1 if float(np.dot(pos[self.name][-1] - pos[self.a][-1], u)) >= 0 else -1

    def velocity(self, pos: Mapping[str, Array], vel: Mapping[str, Array], qd: Array) -> tuple[Array, Mask | None]:
        # |P - A| = ra and cross(w, P - p) = e |w|, differentiated:
        # cross(w, vP) = e (w . vw)/|w| - cross(vw, P - p) + cross(w, vp)
        P = pos[self.name]
        r1 = P - pos[self.a]
        p0, vp0 = pos[self.p], vel[self.p]
        w = pos[self.q] - p0
        vw = vel[self.q] - vp0
        wn = np.hypot(w[:, 0], w[:, 1])
        b2 = self.offset * (w * vw).sum(-1) / wn - _cross(vw, P - p0) + _cross(w, vp0)
        return _solve2(r1, (r1 * vel[self.a]).sum(-1), _perp(w), b2)

    def acceleration(
        self, pos: Mapping[str, Array], vel: Mapping[str, Array], acc: Mapping[str, Array], qd: Array, qdd: Array
    ) -> tuple[Array, Mask | None]:
        # the velocity's two conditions differentiated once more:
        # (P - A) . aP = (P - A) . aA - |vP - vA|^2
        # cross(w, aP) = cross(w, ap) - cross(aw, P - p) - 2 cross(vw, vP - vp)
        #                + e ((|vw|^2 + w . aw) / |w| - (w . vw)^2 / |w|^3)
        P, vP = pos[self.name], vel[self.name]
        r1, v1 = P - pos[self.a], vP - vel[self.a]
        p0, vp0, ap0 = pos[self.p], vel[self.p], acc[self.p]
        w, vw, aw = pos[self.q] - p0, vel[self.q] - vp0, acc[self.q] - ap0
        wn = np.hypot(w[:, 0], w[:, 1])
        wv = _dot(w, vw)
        b2 = (
            _cross(w, ap0)
            - _cross(aw, P - p0)
            - 2.0 * _cross(vw, vP - vp0)
            + self.offset * ((_dot(vw, vw) + _dot(w, aw)) / wn - wv * wv / wn**3)
        )
        return _solve2(r1, _dot(r1, acc[self.a]) - _dot(v1, v1), _perp(w), b2)


@node_kind
@dataclass(frozen=True)
class Rigid(NodeKind):
    """Fixed in the frame of nodes ``a, b``: ``a + u e + v e_perp``, ``e`` the unit vector ``a -> b``."""

    kind: ClassVar[str] = "rigid"
    scene_fields: ClassVar[tuple[str, ...]] = ("a", "b", "local")
    name: str
    a: str
    b: str
    local: Vec

    def refs(self) -> tuple[str, ...]:
        return (self.a, self.b)

    def validate(self, where: str) -> None:
        check_finite(f"{where}.local", self.local)

    def held_by(self) -> tuple[tuple[str, ...], ...]:
        # its distance from ``a``; the direction ``a -> b`` may be held by a guide (a cylinder along its rod)
        return ((self.name, self.a),)

    def position(self, pos: Mapping[str, Array], q: Array, path: Mask) -> tuple[Array, Check | None]:
        a, b = pos[self.a], pos[self.b]
        e = b - a
        en = np.hypot(e[:, 0], e[:, 1])
        ok = en > 0
        e = e / np.where(ok, en, 1.0)[:, None]
        u, v = self.local
        return a + u * e + v * _perp(e), (ok, f"nodes {self.a!r} and {self.b!r} coincide")

    def velocity(self, pos: Mapping[str, Array], vel: Mapping[str, Array], qd: Array) -> tuple[Array, Mask | None]:
        a = pos[self.a]
        d = pos[self.b] - a
        omega = _cross(d, vel[self.b] - vel[self.a]) / (d * d).sum(-1)
        return vel[self.a] + omega[:, None] * _perp(pos[self.name] - a), None

    def acceleration(
        self, pos: Mapping[str, Array], vel: Mapping[str, Array], acc: Mapping[str, Array], qd: Array, qdd: Array
    ) -> tuple[Array, Mask | None]:
        # aP = aA + alpha perp(P - A) - omega^2 (P - A), omega and alpha of the frame a -> b
        omega, alpha = frame_rates(pos[self.b] - pos[self.a], vel[self.b] - vel[self.a], acc[self.b] - acc[self.a])
        r = pos[self.name] - pos[self.a]
        return acc[self.a] + alpha[:, None] * _perp(r) - (omega * omega)[:, None] * r, None


Node = Fixed | Crank | Actuator | RRR | RRP | Rigid


@dataclass(frozen=True)
class Link:
    """A rigid part carrying ``nodes``; ``guide`` ``(p, q)`` makes it a block sliding along that line."""

    name: str
    nodes: tuple[str, ...]
    guide: tuple[str, str] | None = None


def path_mask(q: Array) -> Mask:
    """``path[k]``: the driver steps into samples ``k-3 .. k`` share one sign and agree within 1.5x."""
    n = q.shape[0]
    out = np.zeros(n, dtype=bool)
    if n < 4:
        return out
    dq = np.diff(q)
    a, b, c = dq[:-2], dq[1:-1], dq[2:]
    same = ((a > 0) & (b > 0) & (c > 0)) | ((a < 0) & (b < 0) & (c < 0))
    mag = np.abs(np.stack([a, b, c]))
    out[3:] = same & (mag.max(0) <= 1.5 * mag.min(0))
    return out


class Linkage(Mechanism):
    """A single-input planar linkage of pivots and slots, solved in closed form.

    ``placement`` ``(x, y, angle)`` places the whole linkage in the world
    (the linkage is solved in its own frame, then transformed).  ``width``
    and ``pin_diameter`` size the parts' outlines (default: 8 % and 3 % of
    the linkage's span).  ``points`` maps names to node names.  A driver that
    rocks instead of turning: ``amplitude`` and ``centre`` (rad or units), so
    the input is ``centre + amplitude sin(rate t + phase)``.
    """

    def __init__(
        self,
        name: str,
        nodes: Sequence[NodeKind],
        links: Sequence[Link],
        points: Mapping[str, str] | None = None,
        placement: Sequence[float] = (0.0, 0.0, 0.0),
        rate: float = 2.0 * np.pi,
        phase: float = 0.0,
        amplitude: float | None = None,
        centre: float = 0.0,
        width: float | None = None,
        pin_diameter: float | None = None,
        ground: str = "ground",
    ) -> None:
        self.name = name
        self.nodes: tuple[NodeKind, ...] = tuple(nodes)
        pl = check_finite(f"{name}.placement", placement)
        if pl.shape != (3,):
            raise InputError(f"{name}.placement", placement, "(x, y, angle): three numbers")
        self.placement = tuple(float(v) for v in pl)
        self._validate_nodes(name)
        bound: dict[str, NodeKind] = {n.name: n for n in self.nodes}
        for n in self.nodes:
            bound[n.name] = n.bind(f"{name}.nodes.{n.name}", bound)
        self.nodes = tuple(bound.values())
        if any(getattr(n, "continued", False) for n in self.nodes):
            self.branch_reference = 0.0  # a triad's declared assembly holds at driver value 0
        clocked = [n.name for n in self.nodes if getattr(n, "clocked", False)]
        if clocked and amplitude is not None:
            raise InputError(
                f"{name}.driver.amplitude",
                amplitude,
                f"no amplitude: with driven nodes ({', '.join(clocked)}) the driver is a clock "
                "(phase + rate t); give each driven node its own amplitude",
            )
        self.ground_name = ground
        self.links = self._with_ground(tuple(links), ground)
        self._validate_links(name)
        self._check_held(name)
        inputs = [n for n in self.nodes if n.is_input]
        if not inputs:
            raise InputError(f"{name}.nodes", [n.name for n in self.nodes], "one crank or actuator node as the input")
        self._driver_node = inputs[0]
        driver_link = self._link_of(self._driver_node.name, exclude_ground=True)
        byname = {n.name: n for n in self.nodes}
        make = getattr(self._driver_node, "make_driver", None)
        if make is not None:
            c = byname[self._driver_node.centre]  # type: ignore[attr-defined]
            driver = make(driver_link, c.xy if isinstance(c, Fixed) else (0.0, 0.0), rate, phase)
        elif isinstance(self._driver_node, Crank):
            c = byname[self._driver_node.centre]
            origin = c.xy if isinstance(c, Fixed) else (0.0, 0.0)
            driver = Driver(driver_link, "rotation", origin=origin, rate=rate, phase=phase, amplitude=amplitude, centre=centre)
        else:
            ax = np.asarray(getattr(self._driver_node, "axis", (1.0, 0.0)), float)
            driver = Driver(
                driver_link,
                "translation",
                axis=(float(ax[0] / np.hypot(*ax)), float(ax[1] / np.hypot(*ax))),
                rate=rate,
                phase=phase,
                amplitude=amplitude if amplitude is not None else 1.0,
                centre=centre,
            )
        self.driver = driver
        # one sweep of the driver's cycle: the reference configuration, rigidity, slot travel
        self._sweep_q = self._cycle_inputs(driver)
        self._sweep_pos, sweep_ok = self._solve_valid(self._sweep_q)
        if not sweep_ok.any():
            _, checks = self.solve_nodes(self._sweep_q)
            joint, why = next(((j, w) for m, j, w in checks if not m.any()), (checks[0][1], checks[0][2]))
            raise AssemblyError(f"{name}: cannot be assembled at any driver value: joint {joint!r}: {why}")
        self._sweep_ok = sweep_ok
        k_ref = int(np.argmax(sweep_ok))
        self._ref_nodes = {k: v[k_ref] for k, v in self._sweep_pos.items()}
        self._check_rigid(name)
        span = self._span()
        self.width = check_positive(f"{name}.width", width) if width is not None else 0.08 * span
        self.pin_diameter = check_positive(f"{name}.pin_diameter", pin_diameter) if pin_diameter is not None else 0.03 * span
        self._anchors = self._local_anchors()
        parts, joints = self._build_parts_and_joints()
        pts = {}
        #: named point -> the node that defines it
        self.point_nodes: dict[str, str] = dict(points or {})
        for pname, node in self.point_nodes.items():
            if node not in byname:
                raise InputError(f"{name}.points.{pname}", node, f"a node name, one of {list(byname)}")
            link = self._link_of(node, exclude_ground=False)
            pts[pname] = (link, self._anchors[link][node])
        super().__init__(name, parts, joints, driver, pts)

    # -- validation ---------------------------------------------------------
    def _validate_nodes(self, name: str) -> None:
        seen: set[str] = set()
        for n in self.nodes:
            where = f"{name}.nodes.{getattr(n, 'name', '?')}"
            cls = type(n)
            kname = cls.__dict__.get("kind")
            if not isinstance(kname, str) or NODE_KINDS.get(kname) is not cls:
                raise InputError(where, cls.__name__, f"a registered node kind, one of {sorted(NODE_KINDS)}")
            if n.name in seen:
                raise InputError(where, n.name, "a node name used once")
            for r in n.refs():
                if r == n.name:
                    n.validate(where)  # its own words first (a gear meshing with itself says so)
                    raise InputError(where, r, "another node (a node cannot refer to itself)")
                if r not in seen:
                    raise InputError(where, r, "a node declared before it")
            n.validate(where)
            seen.add(n.name)

    def _with_ground(self, links: tuple[Link, ...], ground: str) -> tuple[Link, ...]:
        if any(lk.name == ground for lk in links):
            return links
        fixed = tuple(n.name for n in self.nodes if isinstance(n, Fixed))
        return (Link(ground, fixed),) + links

    def _validate_links(self, name: str) -> None:
        names = {n.name for n in self.nodes}
        seen: set[str] = set()
        for lk in self.links:
            where = f"{name}.links.{lk.name}"
            if lk.name in seen:
                raise InputError(where, lk.name, "a link name used once")
            seen.add(lk.name)
            for n in lk.nodes:
                if n not in names:
                    raise InputError(f"{where}.nodes", n, f"a node name, one of {sorted(names)}")
            if len(set(lk.nodes)) != len(lk.nodes):
                raise InputError(f"{where}.nodes", lk.nodes, "each node once")
            if lk.name != self.ground_name and len(lk.nodes) < 2 and lk.guide is None:
                raise InputError(f"{where}.nodes", lk.nodes, "two or more nodes (or one node and a guide)")
            if lk.guide is not None:
                for g in lk.guide:
                    if g not in names:
                        raise InputError(f"{where}.guide", g, f"a node name, one of {sorted(names)}")
                if lk.guide[0] == lk.guide[1]:
                    raise InputError(f"{where}.guide", lk.guide, "two different nodes")
                self._guide_owner(lk)  # raises if no other link carries the guide line

    def _check_held(self, name: str) -> None:
        """Every node's constraint is held by a part: the nodes it is placed from share a link with it."""
        for n in self.nodes:
            for group in n.held_by():
                if not any(all(g in lk.nodes for g in group) for lk in self.links):
                    others = ", ".join(repr(g) for g in group if g != n.name)
                    raise InputError(
                        f"{name}.nodes.{n.name}",
                        n.name,
                        f"a link carrying {n.name!r} with {others} (the {n.kind} node is placed "
                        "from them; without that link no part holds it there)",
                    )

    def _guide_owner(self, lk: Link) -> str:
        """The link (not ``lk``) that carries both nodes of ``lk``'s guide line."""
        assert lk.guide is not None
        p, q = lk.guide
        for other in self.links:
            if other.name != lk.name and p in other.nodes and q in other.nodes:
                return other.name
        raise InputError(
            f"{self.name}.links.{lk.name}.guide",
            list(lk.guide),
            "two nodes carried by one other link (the link the block slides along)",
        )

    def _link_of(self, node: str, exclude_ground: bool) -> str:
        for lk in self.links:
            if exclude_ground and lk.name == self.ground_name:
                continue
            if node in lk.nodes:
                return lk.name
        raise InputError(f"{self.name}.links", node, "a link that carries this node")

    def _cycle_inputs(self, driver: Driver, n: int = 721) -> Array:
        """Driver values over one cycle of its law (a full turn for a turning crank)."""
        if driver.amplitude is None:
            return driver.phase + np.linspace(0.0, 2 * np.pi, n)
        return driver.value(np.linspace(0.0, driver.period, n))

    def _solve_valid(self, q: Array) -> tuple[dict[str, Array], Mask]:
        pos, checks = self.solve_nodes(q)
        ok = np.ones(q.shape, bool)
        for m, _, _ in checks:
            ok &= m
        return pos, ok

    def _check_rigid(self, name: str) -> None:
        """Refuse a link whose nodes move relative to each other over the driver's cycle."""
        ok = self._sweep_ok
        P = {k: v[ok] for k, v in self._sweep_pos.items()}
        tol = 1e-9 * self._span()
        for lk in self.links:
            nodes = list(lk.nodes)
            for i, a in enumerate(nodes):
                for b in nodes[i + 1 :]:
                    d = np.hypot(*(P[a] - P[b]).T)
                    change = float(d.max() - d.min())
                    if change > tol:
                        raise InputError(
                            f"{name}.links.{lk.name}",
                            nodes,
                            f"a rigid link: nodes {a!r} and {b!r} move relative to each other "
                            f"(their distance changes by {change:.4g}, from {d.min():.6g} to {d.max():.6g})",
                        )
            if lk.guide is not None and len(nodes) >= 2:
                g = P[lk.guide[1]] - P[lk.guide[0]]
                e = P[nodes[1]] - P[nodes[0]]
                turn = np.arctan2(_cross(g, e), (g * e).sum(-1))
                dev = float(np.ptp(np.unwrap(turn)))
                if dev > 1e-9:
                    raise InputError(
                        f"{name}.links.{lk.name}",
                        nodes,
                        f"a block that keeps its guide's direction: nodes {nodes[0]!r}-{nodes[1]!r} turn by "
                        f"{dev:.4g} rad against the guide {lk.guide[0]!r}-{lk.guide[1]!r}",
                    )

    # -- solving ------------------------------------------------------------
    #: driver value at which the declared branches hold (``None``: at the first sample); see
    #: :meth:`_lead_in` (a :class:`FourBar` declares its circuit with the crank at pi/2)
    branch_reference: float | None = None

    def _lead_in(self, q: Array) -> Array:
        """Driver values leading from :attr:`branch_reference` into the path ``q`` (empty if none applies).

        The lead-in runs toward ``q[0]`` in the path's direction (for a
        turning crank from the reference a whole number of turns away, less
        than one turn before ``q[0]``), with steps that shrink by at most 1.4x
        per sample down to the path's first step, so continuity carries the
        declared branch from the reference through every sample, ``q[0]``
        included even where it is singular.
        """
        ref = self.branch_reference
        if ref is None or q.shape[0] < 4 or not path_mask(q[:4])[3]:
            return q[:0]
        q0, h = float(q[0]), float(q[1] - q[0])
        direction = 1.0 if h > 0 else -1.0
        if self.driver.kind == "rotation":
            turns = np.floor((q0 - ref) / (2 * np.pi)) if direction > 0 else np.ceil((q0 - ref) / (2 * np.pi))
            ref = ref + 2 * np.pi * turns
        span = (q0 - ref) * direction
        if span <= 0:
            return q[:0]
        h_max = max(abs(h), 2 * np.pi / 360 if self.driver.kind == "rotation" else abs(h))
        steps: list[float] = []
        step, total = abs(h), 0.0
        while total < span and len(steps) < 4096:
            step = min(step * 1.4, h_max) if steps else abs(h)
            steps.append(step)
            total += step
        back = np.cumsum(steps)  # distances before q[0], nearest first
        return q0 - direction * back[::-1]

    def solve_nodes(self, q: Array, lead: Array | None = None) -> tuple[dict[str, Array], list[tuple[Mask, str, str]]]:
        """World positions ``(N, 2)`` of every node (before placement) and validity checks.

        The samples are a path in their order (see the module's note on branches).
        ``lead``: :meth:`_lead_in` of ``q`` when the caller has it already.
        """
        q = np.asarray(q, dtype=float)
        if lead is None:
            lead = self._lead_in(q)
        if lead.size == 0:
            return self._solve_nodes(q, self.nodes)
        k = lead.shape[0]
        pos, checks = self._solve_nodes(np.concatenate([lead, q]), self.nodes)
        return {n: v[k:] for n, v in pos.items()}, [(m[k:], j, w) for m, j, w in checks]

    def _path(self, q: Array) -> Mask:
        """Where the samples are a path along which a branch may be carried (:func:`path_mask`); a subclass
        that knows its motion has no singular position returns no path (its declared branches hold)."""
        return path_mask(q)

    def _solve_nodes(self, q: Array, nodes: Sequence[NodeKind]) -> tuple[dict[str, Array], list[tuple[Mask, str, str]]]:
        path = self._path(q)
        pos: dict[str, Array] = {}
        checks: list[tuple[Mask, str, str]] = []
        for node in nodes:
            p, check = node.position(pos, q, path)
            pos[node.name] = p
            if check is not None:
                checks.append((check[0], node.name, check[1]))
        return pos, checks

    def _link_poses(self, pos: Mapping[str, Array], n: int) -> dict[str, Array]:
        poses: dict[str, Array] = {}
        for lk in self.links:
            if lk.name == self.ground_name:
                poses[lk.name] = np.zeros((n, 3))
                continue
            o = pos[lk.nodes[0]]
            d = pos[lk.guide[1]] - pos[lk.guide[0]] if lk.guide is not None else pos[lk.nodes[1]] - o
            poses[lk.name] = np.column_stack([o[:, 0], o[:, 1], np.arctan2(d[:, 1], d[:, 0])])
        return poses

    def _fast_plan(self) -> _Plan | None:
        """The chunked solver's plan (built on first use; ``None`` if a node kind has no chunk kernel)."""
        if "_plan" not in self.__dict__:
            self.__dict__["_plan"] = plan_for(self)
        plan: _Plan | None = self.__dict__["_plan"]
        return plan

    def _declared_branches_hold(self, q: Array, lead: Array) -> bool:
        """Whether the branch carried from :attr:`branch_reference` along ``lead`` is the declared one at ``q[0]``.

        The chunked path starts every dyad on its declared branch; where the
        lead-in from the reference arrives on the other one (a change-point
        four-bar starting past a flat position), the reference path is used.
        """
        if lead.size == 0:
            return True
        k = lead.shape[0]
        pos, checks = self._solve_nodes(np.concatenate([lead, q[:1]]), self.nodes)
        if not all(bool(m[k]) for m, _, _ in checks):
            return False
        for node in self.nodes:
            b = node.branch_of(pos)
            if b is not None and b != getattr(node, "branch", b):
                return False
        return True

    def _solve_points(self, q: Array) -> Solved:
        """The chunked, threaded path (:mod:`planar.linkages.chunked`), else the reference path.

        Kinds without a chunk kernel (gears, driven inputs, triads) have no plan and go straight to the
        reference path. The lead-in is built once and, on falling back, handed to the reference solve.
        """
        lead = self._lead_in(q) if q.ndim == 1 else None
        if lead is not None and self._fast_plan() is not None and self._declared_branches_hold(q, lead):
            fast = fast_solve(self, q)
            if fast is not None:
                return fast
        poses, checks = self._solve_poses(q, lead)
        return poses, checks, None

    def _solve_poses(self, q: Array, lead: Array | None = None):
        pos, checks = self.solve_nodes(q, lead)
        poses = self._link_poses(pos, q.shape[0])
        if any(self.placement):
            pl = np.asarray(self.placement)
            poses = {k: poses_compose(pl, v) for k, v in poses.items()}
        return poses, checks

    def node_velocities(self, q: ArrayLike, qdot: ArrayLike = 1.0) -> tuple[dict[str, Array], Mask]:
        """Velocity ``(N, 2)`` of every node (own frame, before placement) and where it is defined.

        Each node kind differentiates its own closure (:meth:`NodeKind.velocity`);
        ``qdot = 1`` gives velocity coefficients ``dX/dq``.
        """
        qa = np.atleast_1d(np.asarray(q, float))
        qd = np.broadcast_to(np.asarray(qdot, float), qa.shape)
        pos, checks = self.solve_nodes(qa)
        valid = np.ones(qa.shape, bool)
        for m, _, _ in checks:
            valid &= m
        vel: dict[str, Array] = {}
        for node in self.nodes:
            v, ok = node.velocity_at(pos, vel, qa, qd)
            vel[node.name] = v
            if ok is not None:
                valid &= ok
        return vel, valid

    def node_accelerations(
        self,
        q: ArrayLike,
        qdot: ArrayLike = 1.0,
        qddot: ArrayLike = 0.0,
        solved: tuple[dict[str, Array], list[tuple[Mask, str, str]]] | None = None,
    ) -> tuple[dict[str, Array], dict[str, Array], dict[str, Array], Mask]:
        """Position, velocity and acceleration ``(N, 2)`` of every node (own frame, before placement).

        Each node kind differentiates its closure twice
        (:meth:`NodeKind.acceleration`), no differencing: ``qdot`` is the
        driver's rate (rad/s or units/s) and ``qddot`` its rate of change per
        sample; with ``qdot = 1, qddot = 0`` the accelerations are the second
        coefficients ``d2X/dq2``.  ``valid`` is false where the position does
        not close or a differentiated closure is singular (a toggle).
        ``solved``: :meth:`solve_nodes` of ``q`` if the caller has it already.
        """
        qa = np.atleast_1d(np.asarray(q, float))
        qd = np.broadcast_to(np.asarray(qdot, float), qa.shape)
        qdd = np.broadcast_to(np.asarray(qddot, float), qa.shape)
        pos, checks = solved if solved is not None else self.solve_nodes(qa)
        valid = np.ones(qa.shape, bool)
        for m, _, _ in checks:
            valid &= m
        vel: dict[str, Array] = {}
        acc: dict[str, Array] = {}
        for node in self.nodes:
            v, ok = node.velocity_at(pos, vel, qa, qd)
            vel[node.name] = v
            a, ok2 = node.acceleration_at(pos, vel, acc, qa, qd, qdd)
            acc[node.name] = a
            for mask in (ok, ok2):
                if mask is not None:
                    valid &= mask
        return pos, vel, acc, valid

    def link_rates(
        self, pos: Mapping[str, Array], vel: Mapping[str, Array], acc: Mapping[str, Array]
    ) -> dict[str, tuple[Array, Array, Array, Array]]:
        """Per link: ``(origin velocity, origin acceleration, omega, alpha)`` in the linkage's own frame.

        The link's frame is its pose's (origin at its first node, x toward its
        second, or along its guide), so these are the time derivatives of the
        poses :meth:`solve` returns (placement rotates the vectors, not the rates).
        """
        out: dict[str, tuple[Array, Array, Array, Array]] = {}
        n = next(iter(pos.values())).shape[0] if pos else 0
        for lk in self.links:
            if lk.name == self.ground_name:
                z = np.zeros((n, 2))
                out[lk.name] = (z, z, np.zeros(n), np.zeros(n))
                continue
            a, b = lk.guide if lk.guide is not None else (lk.nodes[0], lk.nodes[1])
            omega, alpha = frame_rates(pos[b] - pos[a], vel[b] - vel[a], acc[b] - acc[a])
            o = lk.nodes[0]
            out[lk.name] = (vel[o], acc[o], omega, alpha)
        return out

    # -- parts and joints -----------------------------------------------------
    def _span(self) -> float:
        """The larger side of the box every node stays in over the driver's cycle (independent of the phase)."""
        ok = self._sweep_ok
        pts = np.concatenate([v[ok] for v in self._sweep_pos.values()])
        ext = float(np.max(np.ptp(pts, axis=0))) if len(pts) > 1 else 1.0
        return ext if ext > 0 else 1.0

    def _local_anchors(self) -> dict[str, dict[str, Vec]]:
        ref = {k: v[None, :] for k, v in self._ref_nodes.items()}
        poses = self._link_poses(ref, 1)
        out: dict[str, dict[str, Vec]] = {}
        for lk in self.links:
            inv = poses_invert(poses[lk.name][0])
            names = list(lk.nodes) + [g for g in (lk.guide or ()) if g not in lk.nodes and lk.name != self.ground_name]
            out[lk.name] = {}
            for nd in names:
                x, y = poses_apply(inv, self._ref_nodes[nd])
                out[lk.name][nd] = (float(x), float(y))
        return out

    def _travel(self, node: str, p: str, q: str) -> tuple[float, float]:
        """Range of ``node``'s position along the line ``p -> q`` over the driver's cycle."""
        ok = self._sweep_ok
        P = self._sweep_pos
        a, b = P[p][ok], P[q][ok]
        d = b - a
        s = ((P[node][ok] - a) * d).sum(-1) / np.hypot(d[:, 0], d[:, 1])
        return float(s.min()), float(s.max())

    def _build_parts_and_joints(self) -> tuple[list[Part], list[Pivot | PinInSlot | Slide]]:
        """Parts (hulls) and the joints the declaration implies; the joints cut the holes and slots."""
        r = self.width / 2
        hulls: dict[str, list[tuple[float, float, float]]] = {lk.name: [] for lk in self.links}
        joints: list[Pivot | PinInSlot | Slide] = []
        owners: dict[str, list[str]] = {}
        for lk in self.links:
            for nd in lk.nodes:
                owners.setdefault(nd, []).append(lk.name)
                x, y = self._anchors[lk.name][nd]
                hulls[lk.name].append((x, y, r))
        for nd, links in owners.items():
            first = links[0]
            for other in links[1:]:
                jname = nd if len(links) == 2 else f"{nd}:{other}"
                joints.append(
                    Pivot(jname, first, other, self._anchors[first][nd], self._anchors[other][nd], diameter=self.pin_diameter)
                )
        guided = {(lk.guide, nd): lk for lk in self.links if lk.guide is not None for nd in lk.nodes[:1]}
        for node in self.nodes:
            if isinstance(node, RRP) and ((node.p, node.q), node.name) not in guided:
                self._pin_slot(node, owners.get(node.name, []), hulls, joints)
        for (guide, nd), lk in guided.items():
            assert guide is not None
            self._block_slide(lk, nd, guide, hulls, joints)
        for node in self.nodes:
            joints.extend(node.extra_joints(self, hulls))
        parts = []
        for lk in self.links:
            hull = hulls[lk.name] or [(0.0, 0.0, r)]
            parts.append(Part(lk.name, tuple(hull), (), ground=lk.name == self.ground_name))
        return parts, joints

    def _slot_on(
        self, owner: str, node: str, p: str, q: str, offset: float, pad: float, hulls: dict[str, list[tuple[float, float, float]]]
    ) -> tuple[Vec, Vec]:
        """Ends of a slot on ``owner`` along ``p -> q`` covering ``node``'s travel plus ``pad``; widens the hull."""
        ap = np.asarray(self._anchors[owner][p])
        aq = np.asarray(self._anchors[owner][q])
        e = (aq - ap) / np.hypot(*(aq - ap))
        base = ap + offset * np.array([-e[1], e[0]])
        s0, s1 = self._travel(node, p, q)
        start = base + (s0 - pad) * e
        end = base + (s1 + pad) * e
        start_t, end_t = (float(start[0]), float(start[1])), (float(end[0]), float(end[1]))
        hulls[owner].extend([(start_t[0], start_t[1], self.width / 2), (end_t[0], end_t[1], self.width / 2)])
        return start_t, end_t

    def _pin_slot(
        self,
        node: RRP,
        links: list[str],
        hulls: dict[str, list[tuple[float, float, float]]],
        joints: list[Pivot | PinInSlot | Slide],
    ) -> None:
        owner = next((lk.name for lk in self.links if node.p in lk.nodes and node.q in lk.nodes), None)
        if owner is None:
            raise InputError(
                f"{self.name}.nodes.{node.name}", (node.p, node.q), "line nodes carried by one link (the slot's part)"
            )
        start, end = self._slot_on(owner, node.name, node.p, node.q, node.offset, 0.0, hulls)
        riders = [lk for lk in links if lk != owner]
        if not riders:
            raise InputError(f"{self.name}.nodes.{node.name}", node.name, "a link that carries the pin running in the slot")
        pin_link = riders[0]
        joints.append(
            PinInSlot(
                f"{node.name}-slot", owner, pin_link, start, end, self._anchors[pin_link][node.name], width=self.pin_diameter
            )
        )

    def _block_slide(
        self,
        lk: Link,
        node: str,
        guide: tuple[str, str],
        hulls: dict[str, list[tuple[float, float, float]]],
        joints: list[Pivot | PinInSlot | Slide],
    ) -> None:
        """A block ``lk`` on ``node`` sliding along the line ``guide`` of the link that carries it."""
        owner = self._guide_owner(lk)
        p, q = guide
        # the block's node lies on the guide line (an RRP node's offset, or measured here)
        ap, aq = np.asarray(self._ref_nodes[p]), np.asarray(self._ref_nodes[q])
        e = (aq - ap) / np.hypot(*(aq - ap))
        offset = float(_cross(e[None], (np.asarray(self._ref_nodes[node]) - ap)[None])[0])
        start, end = self._slot_on(owner, node, p, q, offset, self.width, hulls)
        anchor = self._anchors[lk.name][node]
        pins = [(anchor[0] - self.width, anchor[1]), (anchor[0] + self.width, anchor[1])]
        for px, py in pins:
            hulls[lk.name].append((px, py, self.width / 2))
        joints.append(
            Slide(f"{lk.name}-slide", owner, lk.name, start, end, pins[0], (2 * self.width, 0.0), width=self.pin_diameter)
        )

    @property
    def extra_driven_parts(self) -> list[str]:
        """Links of the inputs beyond the first that no gear ties to it (a simulation imposes their motion)."""
        return [
            self._link_of(n.name, exclude_ground=True)
            for n in self.nodes
            if getattr(n, "clocked", False) and n is not self._driver_node
        ]

    def input_values(self, q: ArrayLike) -> dict[str, Array]:
        """Each input node's value (crank angle, rad, unwrapped) at driver values ``q`` when there are several.

        Empty for a single-input linkage (its value is the driver value).
        """
        inputs = [n for n in self.nodes if n.is_input]
        if len(inputs) < 2:
            return {}
        qa = np.atleast_1d(np.asarray(q, float))
        out: dict[str, Array] = {}
        for n in inputs:
            own = getattr(n, "input_angle", None)  # a geared or driven node's law
            if own is not None:
                out[n.name] = own(qa)
            elif isinstance(n, Crank):
                out[n.name] = qa + n.phase
            elif isinstance(n, Actuator):
                out[n.name] = qa + n.offset
        return out

    def node_positions(self, q) -> dict[str, Array]:
        """World positions ``(N, 2)`` of every node, placement applied."""
        pos, _ = self.solve_nodes(np.atleast_1d(np.asarray(q, float)))
        if any(self.placement):
            pl = np.asarray(self.placement)
            return {k: poses_apply(pl, v) for k, v in pos.items()}
        return pos
