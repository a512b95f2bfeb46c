"""Gears between cranks, and inputs with their own driving law.

* :class:`Geared` (``"geared"``) — a crank turning about ``centre`` at
  ``radius`` whose angle is a fixed multiple of the input angle of the crank
  it meshes with (``mesh``): ``angle = ratio * angle(mesh) + phase`` (rad,
  counter-clockwise).  ``ratio`` is the angular velocity ratio and must be
  negative: two external spur gears turn opposite ways (``-1`` for equal
  gears; ``-0.5`` for a gear twice the size of its partner).  Both centres
  must be fixed nodes.  The two crank links become gear blanks: each gets a
  disc of its *pitch circle* (radii ``R_mesh + R = d`` and
  ``R_mesh / R = |ratio|`` for centres ``d`` apart), and a
  :class:`GearMesh` joint holds the ratio.  Drawings and cut files show and
  cut the pitch circles (no teeth); the assembly puts the two gears in one
  layer, so a gear part that reaches past its pitch circle (a crank pin
  further out) is refused.
* :class:`Driven` (``"driven"``) — a crank with a driving law of its own,
  for two-input mechanisms (a five-bar or pantograph guided by two inputs).
  With driven nodes the scene's ``[driver]`` is a clock: its value is
  ``theta = phase + 2 pi speed t`` (rad), and a driven node's angle is
  ``phase_n + cycles theta`` (a full turn, ``cycles`` turns per clock cycle),
  or ``mean + amplitude sin(cycles theta + phase_n)`` (a rocking input).
  A plain ``crank`` in the same linkage turns with the clock.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from fractions import Fraction
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from planar.core.model import Driver, check_finite, check_positive, joint_kind
from planar.errors import InputError
from planar.linkages.nodes import Check, Crank, Fixed, Mask, NodeKind, _perp, frame_rates, node_kind

if TYPE_CHECKING:
    from planar.linkages.linkage import Linkage

__all__ = ["Driven", "GearMesh", "Geared", "input_angle"]

Array = NDArray[np.float64]


def input_angle(node: NodeKind, q: Array) -> Array:
    """The unwrapped angle (rad) of an input crank node at driver values ``q``."""
    if isinstance(node, Crank):
        return q + node.phase
    if isinstance(node, (Geared, Driven)):
        return node.input_angle(q)
    raise TypeError(f"node {node.name!r} ({type(node).kind}) has no input angle")


def _omega(pos: Mapping[str, Array], vel: Mapping[str, Array], node: str, centre: str) -> Array:
    """Angular velocity (rad/s) of the line ``centre -> node`` from positions and velocities."""
    r = pos[node] - pos[centre]
    v = vel[node] - vel[centre]
    return (r[:, 0] * v[:, 1] - r[:, 1] * v[:, 0]) / (r * r).sum(-1)


#: the gear ratios (their size, ``|ratio|``) a pair of pitch circles can have in a drawing and a cut file
RATIO_RANGE = (1e-6, 1e6)


@node_kind
@dataclass(frozen=True)
class Geared(NodeKind):
    """Turns about ``centre`` at ``radius``: ``angle = ratio * angle(mesh) + phase`` (rad); ``ratio < 0``."""

    kind: ClassVar[str] = "geared"
    length_fields: ClassVar[tuple[str, ...]] = ("radius",)
    scene_fields: ClassVar[tuple[str, ...]] = ("centre", "radius", "mesh", "ratio", "phase")
    angle_fields: ClassVar[tuple[str, ...]] = ("phase",)
    is_input: ClassVar[bool] = True
    name: str
    centre: str
    radius: float
    mesh: str
    ratio: float
    phase: float = 0.0
    #: the node it meshes with (set when the linkage is built, :meth:`bind`)
    base: NodeKind | None = field(default=None, compare=False, repr=False)

    def refs(self) -> tuple[str, ...]:
        return (self.centre, self.mesh)

    def held_by(self) -> tuple[tuple[str, ...], ...]:
        return ((self.name, self.centre),)

    def validate(self, where: str) -> None:
        if self.base is not None and not isinstance(self.base, NodeKind):
            raise InputError(f"{where}.base", self.base, "the node kind the gear rides on (or None)")
        if self.mesh == self.name:
            raise InputError(f"{where}.mesh", self.mesh, "another gear's node (a gear cannot mesh with itself)")
        if self.mesh == self.centre:
            raise InputError(f"{where}.mesh", self.mesh, "the gear it meshes with, not its own centre")
        check_positive(f"{where}.radius", self.radius)
        check_finite(f"{where}.phase", self.phase)
        from planar.core.limits import check_angle  # an angle float64 resolves: not phase = 1e300

        check_angle(f"{where}.phase", self.phase)
        if isinstance(self.ratio, (str, bytes, bool)):
            raise InputError(f"{where}.ratio", self.ratio, "a negative number")
        r = float(check_finite(f"{where}.ratio", self.ratio))
        if r < 0 and not RATIO_RANGE[0] <= -r <= RATIO_RANGE[1]:
            raise InputError(
                f"{where}.ratio",
                self.ratio,
                f"a ratio from -{RATIO_RANGE[1]:g} to -{RATIO_RANGE[0]:g} (beyond, one gear's pitch circle is less "
                f"than {RATIO_RANGE[0]:g} of the distance between the centres)",
            )
        if not r < 0:
            raise InputError(
                f"{where}.ratio",
                self.ratio,
                "a negative ratio (external spur gears turn opposite ways; a positive ratio needs an "
                "idler or a belt, which planar does not build)",
            )

    def bind(self, where: str, nodes: Mapping[str, NodeKind]) -> NodeKind:
        m = nodes[self.mesh]
        if not isinstance(m, (Crank, Geared, Driven)):
            raise InputError(f"{where}.mesh", self.mesh, "a crank, geared or driven node (the gear it meshes with)")
        for c in (self.centre, m.centre):
            if not isinstance(nodes[c], Fixed):
                raise InputError(
                    f"{where}.centre" if c == self.centre else f"{where}.mesh",
                    c,
                    "gear centres on fixed nodes (both gears turn about the ground)",
                )
        return replace(self, base=m)

    def input_angle(self, q: Array) -> Array:
        assert self.base is not None, "a geared node is bound when its linkage is built"
        return self.ratio * input_angle(self.base, q) + self.phase

    def position(self, pos: Mapping[str, Array], q: Array, path: Mask) -> tuple[Array, Check | None]:
        a = self.input_angle(q)
        return pos[self.centre] + self.radius * np.stack([np.cos(a), np.sin(a)], -1), None

    def velocity(self, pos: Mapping[str, Array], vel: Mapping[str, Array], qd: Array) -> tuple[Array, Mask | None]:
        assert isinstance(self.base, (Crank, Geared, Driven))
        w = self.ratio * _omega(pos, vel, self.base.name, self.base.centre)
        return vel[self.centre] + w[:, None] * _perp(pos[self.name] - pos[self.centre]), None

    def acceleration(
        self, pos: Mapping[str, Array], vel: Mapping[str, Array], acc: Mapping[str, Array], qd: Array, qdd: Array
    ) -> tuple[Array, Mask | None]:
        assert isinstance(self.base, (Crank, Geared, Driven))
        m, c = self.base.name, self.base.centre
        w, al = frame_rates(pos[m] - pos[c], vel[m] - vel[c], acc[m] - acc[c])
        return _turning(pos, vel, acc, self.name, self.centre, self.ratio * w, self.ratio * al), None

    def extra_joints(self, lk: Linkage, hulls: dict[str, list[tuple[float, float, float]]]) -> list[Any]:
        """The gear pair: pitch-circle discs on both crank links and the :class:`GearMesh` joint."""
        assert self.base is not None
        mesh_centre = self.base.centre  # type: ignore[attr-defined]
        la = _crank_link(lk, self.base.name, mesh_centre)
        lb = _crank_link(lk, self.name, self.centre)
        ca, cb = np.asarray(lk._ref_nodes[mesh_centre]), np.asarray(lk._ref_nodes[self.centre])
        d = float(np.hypot(*(cb - ca)))
        if d <= 0:
            raise InputError(
                f"{lk.name}.nodes.{self.name}.centre", self.centre, f"a gear centre apart from its partner's {mesh_centre!r}"
            )
        k = abs(self.ratio)
        ra, rb = d * k / (1 + k), d / (1 + k)
        xa, ya = lk._anchors[la][mesh_centre]
        xb, yb = lk._anchors[lb][self.centre]
        # the two gears share a layer: nothing on either gear part may reach past its pitch circle
        for link, (cx, cy), radius in ((la, (xa, ya), ra), (lb, (xb, yb), rb)):
            reach = max(float(np.hypot(x - cx, y - cy)) + r for x, y, r in hulls[link])
            if reach > radius * (1 + 1e-9):
                raise InputError(
                    f"{lk.name}.links.{link}",
                    list(next(k.nodes for k in lk.links if k.name == link)),
                    f"a gear part within its pitch circle (radius {radius:.4g}): it reaches "
                    f"{reach:.4g} from its centre (part width {lk.width:.4g}), so the two gears "
                    "could not turn in one layer; shorten the crank or move the centres apart",
                )
        hulls[la].append((xa, ya, ra))
        hulls[lb].append((xb, yb, rb))
        ref = lk._link_poses({n: v[None, :] for n, v in lk._ref_nodes.items()}, 1)
        phase = float(ref[lb][0, 2] - self.ratio * ref[la][0, 2])
        return [GearMesh(f"{self.name}-gear", la, lb, float(self.ratio), phase, (xa, ya), (xb, yb), ra, rb)]


def _turning(
    pos: Mapping[str, Array], vel: Mapping[str, Array], acc: Mapping[str, Array], node: str, centre: str, w: Array, al: Array
) -> Array:
    """Acceleration of ``node`` turning about ``centre`` at ``w`` (rad/s), ``al`` (rad/s^2)."""
    r = pos[node] - pos[centre]
    return acc[centre] + al[:, None] * _perp(r) - (w * w)[:, None] * r


def _crank_link(lk: Linkage, node: str, centre: str) -> str:
    for link in lk.links:
        if link.name != lk.ground_name and node in link.nodes and centre in link.nodes:
            return link.name
    raise InputError(f"{lk.name}.links", [node, centre], "a link carrying the gear's crank node and its centre")


@node_kind
@dataclass(frozen=True)
class Driven(NodeKind):
    """A crank about ``centre`` at ``radius`` with its own law of the clock ``theta`` (see the module note)."""

    kind: ClassVar[str] = "driven"
    length_fields: ClassVar[tuple[str, ...]] = ("radius",)
    scene_fields: ClassVar[tuple[str, ...]] = ("centre", "radius", "cycles", "phase", "amplitude", "mean")
    #: without ``amplitude`` the node turns fully (``phase + cycles theta``)
    required_fields: ClassVar[tuple[str, ...]] = ("centre", "radius")
    #: scene keys that mean something only beside another: ``mean`` is a rocking node's (with ``amplitude``)
    paired_fields: ClassVar[tuple[tuple[str, str], ...]] = (("mean", "amplitude"),)
    angle_fields: ClassVar[tuple[str, ...]] = ("phase", "amplitude", "mean")
    is_input: ClassVar[bool] = True
    #: its value follows the clock through a law of its own
    clocked: ClassVar[bool] = True
    name: str
    centre: str
    radius: float
    cycles: float = 1.0
    phase: float = 0.0
    amplitude: float | None = None
    mean: float = 0.0

    def refs(self) -> tuple[str, ...]:
        return (self.centre,)

    def held_by(self) -> tuple[tuple[str, ...], ...]:
        return ((self.name, self.centre),)

    def validate(self, where: str) -> None:
        check_positive(f"{where}.radius", self.radius)
        check_positive(f"{where}.cycles", self.cycles)
        check_finite(f"{where}.phase", self.phase)
        check_finite(f"{where}.mean", self.mean)
        if self.amplitude is not None:
            check_positive(f"{where}.amplitude", self.amplitude)
        from planar.core.limits import check_angle  # numbers float64 resolves: not cycles = 1e300

        check_angle(f"{where}.cycles", self.cycles, 2 * np.pi)
        for f in ("phase", "mean", "amplitude"):
            check_angle(f"{where}.{f}", getattr(self, f) or 0.0)

    def input_angle(self, q: Array) -> Array:
        """The crank angle (rad) at clock values ``q``."""
        if self.amplitude is None:
            return self.phase + self.cycles * q
        return self.mean + self.amplitude * np.sin(self.cycles * q + self.phase)

    def input_rate(self, q: Array) -> Array:
        """``d angle / d theta``."""
        if self.amplitude is None:
            return np.full_like(q, self.cycles)
        return self.amplitude * self.cycles * np.cos(self.cycles * q + self.phase)

    def input_accel(self, q: Array) -> Array:
        """``d2 angle / d theta2``."""
        if self.amplitude is None:
            return np.zeros_like(q)
        return -self.amplitude * self.cycles**2 * np.sin(self.cycles * q + self.phase)

    def make_driver(self, link: str, origin: tuple[float, float], rate: float, phase: float) -> Driver:
        """The linkage's driver when this node is its first input: the clock (kind ``"path"``)."""
        return Driver(link, "path", origin=origin, rate=rate, phase=phase)

    def position(self, pos: Mapping[str, Array], q: Array, path: Mask) -> tuple[Array, Check | None]:
        a = self.input_angle(q)
        return pos[self.centre] + self.radius * np.stack([np.cos(a), np.sin(a)], -1), None

    def velocity(self, pos: Mapping[str, Array], vel: Mapping[str, Array], qd: Array) -> tuple[Array, Mask | None]:
        raise NotImplementedError("a driven node's velocity needs the clock value: call velocity_at")

    def velocity_at(self, pos: Mapping[str, Array], vel: Mapping[str, Array], q: Array, qd: Array) -> tuple[Array, Mask | None]:
        w = self.input_rate(q) * qd
        return vel[self.centre] + w[:, None] * _perp(pos[self.name] - pos[self.centre]), None

    def acceleration(
        self, pos: Mapping[str, Array], vel: Mapping[str, Array], acc: Mapping[str, Array], qd: Array, qdd: Array
    ) -> tuple[Array, Mask | None]:
        raise NotImplementedError("a driven node's acceleration needs the clock value: call acceleration_at")

    def acceleration_at(
        self, pos: Mapping[str, Array], vel: Mapping[str, Array], acc: Mapping[str, Array], q: Array, qd: Array, qdd: Array
    ) -> tuple[Array, Mask | None]:
        w = self.input_rate(q) * qd
        al = self.input_accel(q) * qd * qd + self.input_rate(q) * qdd
        return _turning(pos, vel, acc, self.name, self.centre, w, al), None


def _ratio_period(ratio: float) -> float:
    """The angle (rad) modulo which ``angle_b - ratio * angle_a`` is defined when both are known modulo 2 pi."""
    den = Fraction(abs(ratio)).limit_denominator(1000).denominator
    return 2 * np.pi / den


@joint_kind
@dataclass(frozen=True)
class GearMesh:
    """Two gears in mesh: ``angle_b = ratio * angle_a + phase`` (part angles, rad).

    ``centre_a``/``centre_b`` are the gear centres in each part's frame,
    ``radius_a``/``radius_b`` the pitch radii.  The residual is the pitch
    arc (model units) by which part ``b`` is off the ratio; angles known
    modulo 2 pi make it defined modulo ``2 pi / q`` for ``|ratio| = p / q``.
    No holes, no pins: the gear blanks' outlines are their parts'.
    """

    kind: ClassVar[str] = "gear"
    length_fields: ClassVar[tuple[str, ...]] = ("radius_a", "radius_b")
    point_fields: ClassVar[tuple[str, ...]] = ("centre_a", "centre_b")
    name: str
    a: str
    b: str
    ratio: float
    phase: float
    centre_a: tuple[float, float]
    centre_b: tuple[float, float]
    radius_a: float
    radius_b: float

    def __post_init__(self) -> None:
        """Refused where it is built: finite numbers, a nonzero ratio (negative: external gears turning opposite
        ways), positive pitch radii."""
        from planar.core.fields import check_fields

        where = f"GearMesh {self.name!r}"
        check_fields(self, where)
        if self.ratio == 0:
            raise InputError(f"{where}.ratio", self.ratio, "a nonzero ratio (negative for external gears)")
        check_positive(f"{where}.radius_a", self.radius_a, "pitch radius")
        check_positive(f"{where}.radius_b", self.radius_b, "pitch radius")

    def residual(self, poses: Mapping[str, Array]) -> Array:
        pa = np.asarray(poses[self.a]).reshape(-1, 3)
        pb = np.asarray(poses[self.b]).reshape(-1, 3)
        period = _ratio_period(self.ratio)
        off = pb[:, 2] - self.ratio * pa[:, 2] - self.phase
        off = np.remainder(off + period / 2, period) - period / 2
        return self.radius_b * np.abs(off)

    def features(self) -> tuple[tuple[str, Any], ...]:
        return ()

    def pins(self) -> tuple[tuple[str, tuple[float, float]], ...]:
        return ()
