"""Linkage node kinds: joint centres each placed in closed form from nodes declared before it.

Every node kind is one class that declares itself (the :class:`NodeKind`
contract, like pylinkage's ``Component``): the nodes it references, how its
position, velocity and acceleration follow from theirs, its name in scene
files, and what analysis asks of it (its transmission angle and how far it
stands from a toggle).  ``NODE_KINDS`` maps the scene name to the class.

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

**Branches.**  The samples are taken as a path, in their order: the declared
branch holds at the first sample, and is carried by continuity of the motion
through singular samples (two roots meeting, as a change-point four-bar's at
its flat positions, or a dyad's two centres passing through each other, as a
kite's): at each sample the root taken is the one that continues the
quadratic extrapolation of the node's three previous valid samples, where
that prediction prefers the other root by a factor of 4
(:func:`carry_branch`).  Continuity is only applied where the driver steps of
those samples have one sign and agree within a factor of 1.5
(:func:`path_mask`: a path, not a scattered batch), so a batch of unrelated
driver values gets the declared branch throughout.  Where a dyad cannot close
the sample is invalid with the node named.

The linkage that holds the nodes is :class:`planar.linkages.linkage.Linkage`.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from planar.core.geometry import circle_circle, line_circle
from planar.core.limits import check_resolution, resolution_terms
from planar.core.model import _check_name, check_fields, check_finite, check_point, check_positive
from planar.errors import InputError

__all__ = [
    "NODE_KINDS",
    "RRP",
    "RRR",
    "Actuator",
    "Check",
    "Crank",
    "Fixed",
    "Mask",
    "NodeKind",
    "Rigid",
    "Vec",
    "carry_branch",
    "frame_rates",
    "node_kind",
    "path_mask",
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


def _unit(v: Array) -> Array:
    """Rows of ``v`` ``(N, 2)`` scaled to unit length (a zero row stays zero)."""
    n = np.hypot(v[:, 0], v[:, 1])
    return v / np.where(n > 0, n, 1.0)[:, None]


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
    #: the node joins two links at an angle that transmits the motion (:meth:`transmission`)
    transmits: ClassVar[bool] = False
    scene_fields: ClassVar[tuple[str, ...]] = ()
    angle_fields: ClassVar[tuple[str, ...]] = ()
    #: its lengths (model units, > 0: a radius, a link length) and its points or signed offsets (model units),
    #: for the resolution check (:func:`planar.core.limits.check_resolution`)
    length_fields: ClassVar[tuple[str, ...]] = ()
    point_fields: ClassVar[tuple[str, ...]] = ()
    is_input: ClassVar[bool] = False
    name: str

    def refs(self) -> tuple[str, ...]:
        """The nodes this one is placed from (declared before it)."""
        return ()

    def __post_init__(self) -> None:
        """Refused where it is built, not first at the linkage: its name and its kind's own checks."""
        _check_name(f"{type(self).__name__}.name", self.name)
        check_fields(self, f"nodes.{self.name}")
        for ref in self.refs():
            _check_name(f"nodes.{self.name}: a node it is placed from", ref)
        self.validate(f"nodes.{self.name}")
        # its own numbers float64 resolves together (RRR(ra=1e300, rb=1) is refused here; the whole linkage
        # is checked where it is assembled)
        check_resolution(resolution_terms(self, f"nodes.{self.name}"), f"{self.kind} node")

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

    def transmission(self, pos: Mapping[str, Array]) -> Array | None:
        """Transmission angle (rad, in ``[0, pi]``) at this node for positions ``pos``, or ``None`` for a
        kind that joins no two driven links (see :attr:`transmits`)."""
        return None

    def toggle_margin(self, pos: Mapping[str, Array]) -> Array | None:
        """How far the node stands from a toggle, as the sine of an angle (scale-free, 0 at the toggle),
        per sample of ``pos``; ``None`` for a kind without a toggle."""
        return None

    def extra_joints(self, lk: Any, hulls: dict[str, list[tuple[float, float, float]]]) -> list:
        """Joints this node adds beyond those its links imply (a gear mesh); may add hull circles."""
        return []


@node_kind
@dataclass(frozen=True)
class Fixed(NodeKind):
    """A point ``xy`` on the ground."""

    kind: ClassVar[str] = "fixed"
    point_fields: ClassVar[tuple[str, ...]] = ("xy",)
    scene_fields: ClassVar[tuple[str, ...]] = ("at",)
    name: str
    xy: Vec

    def validate(self, where: str) -> None:
        check_point(f"{where}.xy", self.xy)

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
    length_fields: ClassVar[tuple[str, ...]] = ("radius",)
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
        from planar.core.limits import check_angle  # an angle float64 resolves: not phase = 1e300

        check_angle(f"{where}.phase", self.phase)

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
    point_fields: ClassVar[tuple[str, ...]] = ("offset",)
    scene_fields: ClassVar[tuple[str, ...]] = ("origin", "axis", "offset")
    is_input: ClassVar[bool] = True
    name: str
    origin: str
    axis: Vec = (1.0, 0.0)
    offset: float = 0.0

    def refs(self) -> tuple[str, ...]:
        return (self.origin,)

    def validate(self, where: str) -> None:
        ax = check_point(f"{where}.axis", self.axis, "a direction (x, y): two finite numbers")
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
    if isinstance(branch, (bool, np.bool_)) or branch not in (1, -1):
        raise InputError(f"{where}.branch", branch, "+1 or -1")


@node_kind
@dataclass(frozen=True)
class RRR(NodeKind):
    """At ``ra`` from node ``a`` and ``rb`` from node ``b`` (circle-circle); ``branch`` +1: left of ``a -> b``."""

    kind: ClassVar[str] = "rrr"
    transmits: ClassVar[bool] = True
    length_fields: ClassVar[tuple[str, ...]] = ("ra", "rb")
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
        return p, (ok, self._why(pos, ok))

    def _why(self, pos: Mapping[str, Array], ok: Mask) -> str:
        """Why the dyad cannot close where ``ok`` is false: its two pivots coincide (the joint could be anywhere
        on a circle), or its links cannot span their distance."""
        d = np.hypot(*(pos[self.b] - pos[self.a]).T)
        coincide = d <= 1e-9 * (self.ra + self.rb)
        if (~ok).any() and coincide[~ok].all():
            return (
                f"its pivots {self.a!r} and {self.b!r} coincide, so links of length {self.ra:g} and {self.rb:g} "
                "leave the joint anywhere on a circle (the position is undetermined)"
            )
        return (
            f"links of length {self.ra:g} (from {self.a!r}) and {self.rb:g} (from {self.b!r}) "
            "cannot span the distance between them"
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

    def toggle_margin(self, pos: Mapping[str, Array]) -> Array:
        """``|sin|`` of the angle between the links to ``a`` and to ``b``: 0 where they fall into line."""
        u, w = _unit(pos[self.name] - pos[self.a]), _unit(pos[self.name] - pos[self.b])
        return np.abs(_cross(u, w))


@node_kind
@dataclass(frozen=True)
class RRP(NodeKind):
    """At ``ra`` from node ``a`` on the line ``p -> q`` shifted left by ``offset``; ``branch`` +1: further along."""

    kind: ClassVar[str] = "rrp"
    length_fields: ClassVar[tuple[str, ...]] = ("ra",)
    point_fields: ClassVar[tuple[str, ...]] = ("offset",)
    scene_fields: ClassVar[tuple[str, ...]] = ("a", "ra", "p", "q", "branch", "offset")
    name: str
    a: str
    ra: float
    p: str
    q: str
    branch: int = 1
    offset: float = 0.0
    #: what the line is, for messages (e.g. "the slider's guide"); empty: named by its nodes p-q
    line: str = ""

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
        line = self.line or f"the line {self.p!r}-{self.q!r}"
        return p, (ok, f"a link of length {self.ra:g} from {self.a!r} cannot reach {line}")

    def toggle_margin(self, pos: Mapping[str, Array]) -> Array:
        """``|cos|`` of the angle between the rod ``a -> node`` and the slide line ``p -> q``: 0 where the
        rod stands square to the line."""
        u, w = _unit(pos[self.name] - pos[self.a]), _unit(pos[self.q] - pos[self.p])
        return np.abs((u * w).sum(-1))

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
    point_fields: ClassVar[tuple[str, ...]] = ("local",)
    scene_fields: ClassVar[tuple[str, ...]] = ("a", "b", "local")
    name: str
    a: str
    b: str
    local: Vec

    def refs(self) -> tuple[str, ...]:
        return (self.a, self.b)

    def validate(self, where: str) -> None:
        check_point(f"{where}.local", self.local)

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
