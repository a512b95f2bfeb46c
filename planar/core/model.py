"""The mechanism model every consumer reads: parts, joints, driver, motion.

A :class:`Mechanism` is declared once: rigid :class:`Part` objects (each with
its outline in its own frame), joints between parts, and one :class:`Driver`.
Its :meth:`Mechanism.solve` maps an array of driver values to a
:class:`Motion` holding, for every part, an ``(N, 3)`` pose track
``(x, y, angle)`` that maps the part's own frame to the world, a validity mask
and, for every invalid sample, which joint failed and why.

Units are model units (a scene says what one unit is in millimetres); angles
are radians, counter-clockwise positive.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from functools import cached_property
from types import MappingProxyType
from typing import TYPE_CHECKING, Any, ClassVar, Literal, Protocol, TypeVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

from planar.core.buffers import block as new_block
from planar.core.fields import (
    _check_name,
    check_fields,
    check_finite,
    check_number,
    check_point,
    check_positive,
    check_samples,
)
from planar.core.geometry import poses_apply
from planar.errors import InputError

if TYPE_CHECKING:  # shapely is imported only when an outline is asked for
    import shapely

    from planar.core.rates import RatesResult

__all__ = [
    "JOINT_KINDS",
    "ArcSlot",
    "CamOnLine",
    "Driver",
    "FinitePoses",
    "Hole",
    "Joint",
    "JointProtocol",
    "LazyPoses",
    "Mechanism",
    "Motion",
    "Part",
    "PinInArcSlot",
    "PinInSlot",
    "Pivot",
    "Slide",
    "Slot",
    "check_fields",
    "check_finite",
    "check_point",
    "check_positive",
    "check_samples",
    "joint_kind",
    "joint_residuals",
]

Vec = tuple[float, float]
Array = NDArray[np.float64]


class FinitePoses(dict[str, "NDArray[np.float64]"]):
    """Poses from a solver that screened every number it wrote (poses and named points) and found
    them finite: :meth:`Mechanism.solve` skips its own finite screen for them."""


class LazyPoses(FinitePoses):
    """Poses a solver computes on first access: an empty marker holding the function that computes them.

    A solver that has every node's position can leave the parts' poses (an
    ``atan2`` per part and sample) until someone reads them: :class:`Motion`
    takes this marker as its ``poses`` and calls ``make()`` the first time
    ``motion.poses`` is read, once, keeping the result.  The solver guarantees
    that the poses it will compute are finite (a :class:`FinitePoses`).
    ``parts``: how many parts (for a motion's ``repr`` without computing them).
    """

    def __init__(self, make: Callable[[], dict[str, NDArray[np.float64]]], parts: int) -> None:
        super().__init__()
        self.make = make
        self.parts = parts


def _check_joint(joint: Any, points: tuple[str, ...], size: str | None) -> None:
    """Refuse a joint whose names are not names, whose points are not two finite numbers or whose ``size``
    (a pin diameter or a slot width, when given) is not a positive length; the message names the joint's field."""
    kind = type(joint).__name__
    for f in ("name", "a", "b"):
        _check_name(f"{kind}.{f}", getattr(joint, f))
    for f in points:
        check_point(f"{kind} {joint.name!r}.{f}", getattr(joint, f))
    if size is not None and getattr(joint, size) is not None:
        check_positive(f"{kind} {joint.name!r}.{size}", getattr(joint, size))
    from planar.core.limits import check_resolution, resolution_terms

    check_resolution(resolution_terms(joint, f"{kind} {joint.name!r}"), f"{kind} joint")


def _vec(v: ArrayLike) -> Vec:
    a = np.asarray(v, dtype=float).reshape(2)
    return (float(a[0]), float(a[1]))


# --------------------------------------------------------------------------
# Parts and their features (exact geometry, in the part's own frame)
# --------------------------------------------------------------------------


from planar.core.features import ArcSlot, Hole, Slot  # noqa: E402  (re-exported: defined in planar.core.features)

Feature = Hole | Slot | ArcSlot


@dataclass(frozen=True, eq=False)
class Part:
    """A rigid part.

    ``hull`` lists circles ``(x, y, r)`` whose convex hull is the outer
    profile (the paper's recipe: convex hull around the joints, rounded); it
    is exact geometry (lines tangent to arcs) for fabrication.  ``features``
    are holes and slots cut from it.  ``plane`` names the plane the part moves
    in (``"xy"`` for planar parts; wind-up mechanism #8 moves in ``"xz"``).
    """

    name: str
    hull: tuple[tuple[float, float, float], ...]
    features: tuple[Feature, ...] = ()
    ground: bool = False
    plane: str = "xy"
    #: position along the normal of ``plane`` (e.g. x for a part moving in "yz")
    offset: float = 0.0
    #: an explicit outer polygon (own frame) replacing the rounded hull, if given
    polygon: tuple[Vec, ...] | None = None

    def __post_init__(self) -> None:
        _check_name("Part.name", self.name)
        where = f"Part {self.name!r}"
        if not isinstance(self.hull, (tuple, list, np.ndarray)) or not (len(self.hull) or self.polygon is not None):
            raise InputError(f"{where}.hull", self.hull, "one or more circles (x, y, r) (or a polygon)")
        if not isinstance(self.ground, (bool, np.bool_)):
            raise InputError(f"{where}.ground", self.ground, "True or False")
        h = check_finite(f"{where}.hull", self.hull) if len(self.hull) else np.zeros((0, 3))
        if h.ndim != 2 or h.shape[1] != 3:
            raise InputError(f"{where}.hull", self.hull, "circles (x, y, r): a sequence of three numbers each")
        if (h[:, 2] < 0).any():
            raise InputError(f"{where}.hull", self.hull, "circles with radius r >= 0")
        if self.polygon is not None:
            poly = check_finite(f"{where}.polygon", self.polygon)
            if poly.ndim != 2 or poly.shape[1] != 2 or len(poly) < 3:
                raise InputError(f"{where}.polygon", self.polygon, "three or more points (x, y)")
        if not isinstance(self.plane, str) or self.plane not in ("xy", "xz", "yz"):
            raise InputError(f"{where}.plane", self.plane, "'xy', 'xz' or 'yz'")
        check_number(f"{where}.offset", self.offset)
        if not isinstance(self.features, (tuple, list)) or not all(isinstance(f, (Hole, Slot, ArcSlot)) for f in self.features):
            raise InputError(f"{where}.features", self.features, "a tuple of Hole, Slot or ArcSlot")
        from planar.core.limits import check_resolution

        check_resolution(self._resolution_terms(where), "part")

    def _resolution_terms(self, where: str) -> list[tuple[str, object, float, bool]]:
        """The part's lengths (hull radii > 0, its features' sizes) and coordinates (hull centres, polygon points,
        features, ``offset``), own frame, for :func:`planar.core.limits.check_resolution`; named ``where.FIELD``."""
        from planar.core.limits import resolution_terms

        terms: list[tuple[str, object, float, bool]] = []
        h = np.asarray(self.hull, dtype=float).reshape(-1, 3)
        if len(h):
            far = int(np.abs(h[:, :2]).max(axis=1).argmax())
            terms.append((f"{where}.hull[{far}]", self.hull[far], float(np.abs(h[far, :2]).max()), False))
            r = np.where(h[:, 2] > 0, h[:, 2], np.inf)
            if np.isfinite(r).any():
                k = int(r.argmin())
                terms.append((f"{where}.hull[{k}]", self.hull[k], float(h[k, 2]), True))
        if self.polygon is not None:
            poly = np.abs(np.asarray(self.polygon, dtype=float).reshape(-1, 2)).max(axis=1)
            k = int(poly.argmax())
            terms.append((f"{where}.polygon[{k}]", self.polygon[k], float(poly[k]), False))
        terms.append((f"{where}.offset", self.offset, abs(float(self.offset)), False))
        for i, f in enumerate(self.features):
            terms += resolution_terms(f, f"{where}.features[{i}]")
        return terms

    @cached_property
    def outline(self) -> shapely.Polygon:
        """The outline as a shapely polygon with holes and slots cut out."""
        from planar.core.outlines import part_outline

        return part_outline(self)

    @property
    def area(self) -> float:
        """Area of the outline in model units squared."""
        return float(self.outline.area)


# --------------------------------------------------------------------------
# Joints: every kind joins part ``a`` to part ``b`` and declares itself
# --------------------------------------------------------------------------

#: every joint kind, by name (filled by :func:`joint_kind`)
JOINT_KINDS: dict[str, type] = {}

J = TypeVar("J", bound=type)


def joint_kind(cls: J) -> J:
    """Class decorator: register ``cls`` as a joint kind (ezdxf's ``register_entity`` pattern).

    A joint kind is a frozen dataclass with ``name``, the two parts it joins
    ``a`` and ``b`` (part names; ``a`` carries the track, slot, face or edge,
    ``b`` the pin, block or cam riding on it; for a pivot they are
    symmetric), a class attribute ``kind``, and the methods of
    :class:`JointProtocol`.  Registering a name twice is a :class:`TypeError`.
    """
    name = cls.__dict__.get("kind")
    if not isinstance(name, str):
        raise TypeError(f"joint kind {cls.__name__} needs a class attribute 'kind'")
    if name in JOINT_KINDS:
        raise TypeError(f"double registration for joint kind {name!r}")
    for attr in ("residual", "features", "pins"):
        if not callable(getattr(cls, attr, None)):
            raise TypeError(f"joint kind {name!r} has no method {attr!r}")
    JOINT_KINDS[name] = cls
    return cls


class JointProtocol(Protocol):
    """What every joint kind states, one uniform way (pymunk's ``a`` and ``b``)."""

    kind: ClassVar[str]
    name: str
    a: str
    b: str

    def residual(self, poses: Mapping[str, Array]) -> Array:
        """How far the joint is from closing, per sample (model units, >= 0)."""
        ...

    def features(self) -> tuple[tuple[str, Feature], ...]:
        """``(part, feature)``: the holes and slots this joint cuts into its parts (own frames)."""
        ...

    def pins(self) -> tuple[tuple[str, Vec], ...]:
        """``(part, point)``: where the joint's pins sit (own frames), for drawing."""
        ...


Joint = JointProtocol


def _pose(poses: Mapping[str, Array], part: str) -> Array:
    return poses[part]


def _point_line_distance(p: Array, a: Array, b: Array) -> Array:
    """Signed distance of ``p`` from the line ``a -> b`` (left positive); ``(N,)``."""
    d = b - a
    n = np.hypot(d[..., 0], d[..., 1])
    w = p - a
    return (d[..., 0] * w[..., 1] - d[..., 1] * w[..., 0]) / n


@joint_kind
@dataclass(frozen=True)
class Pivot:
    """Revolute joint: point ``anchor_a`` of part ``a`` coincides with ``anchor_b`` of ``b``.

    ``diameter`` (model units), when given, is the pin: the joint then puts a
    pin hole on both parts; ``None`` leaves the holes to the part's builder.
    """

    kind: ClassVar[str] = "pivot"
    length_fields: ClassVar[tuple[str, ...]] = ("diameter",)
    point_fields: ClassVar[tuple[str, ...]] = ("anchor_a", "anchor_b")
    name: str
    a: str
    b: str
    anchor_a: Vec
    anchor_b: Vec
    diameter: float | None = None

    def __post_init__(self) -> None:
        _check_joint(self, ("anchor_a", "anchor_b"), "diameter")

    def residual(self, poses: Mapping[str, Array]) -> Array:
        """Distance between the two anchor points, per sample."""
        pa = poses_apply(_pose(poses, self.a), self.anchor_a)
        pb = poses_apply(_pose(poses, self.b), self.anchor_b)
        return np.hypot(*(pa - pb).T)

    def features(self) -> tuple[tuple[str, Feature], ...]:
        if self.diameter is None:
            return ()
        return ((self.a, Hole(self.anchor_a, self.diameter, "pin")), (self.b, Hole(self.anchor_b, self.diameter, "pin")))

    def pins(self) -> tuple[tuple[str, Vec], ...]:
        return ((self.a, self.anchor_a),)


@joint_kind
@dataclass(frozen=True)
class PinInSlot:
    """A pin at ``pin`` on part ``b`` runs in a straight slot ``start -> end`` of part ``a``.

    The residual is the pin's distance from the slot's centre line, plus how
    far it has left the slot's length (so a slot that is too short shows).
    ``width``, when given, is the slot's width (the pin's diameter): the joint
    then cuts the slot in ``a`` and the pin hole in ``b``.
    """

    kind: ClassVar[str] = "pin-in-slot"
    length_fields: ClassVar[tuple[str, ...]] = ("width",)
    point_fields: ClassVar[tuple[str, ...]] = ("start", "end", "pin")
    name: str
    a: str
    b: str
    start: Vec
    end: Vec
    pin: Vec
    width: float | None = None

    def __post_init__(self) -> None:
        _check_joint(self, ("start", "end", "pin"), "width")

    def residual(self, poses: Mapping[str, Array]) -> Array:
        p = poses_apply(_pose(poses, self.b), self.pin)
        s0 = poses_apply(_pose(poses, self.a), self.start)
        s1 = poses_apply(_pose(poses, self.a), self.end)
        off = np.abs(_point_line_distance(p, s0, s1))
        d = s1 - s0
        L = np.hypot(d[..., 0], d[..., 1])
        s = ((p - s0) * d).sum(-1) / L
        beyond = np.maximum(0.0, np.maximum(-s, s - L))
        return np.hypot(off, beyond)

    def features(self) -> tuple[tuple[str, Feature], ...]:
        if self.width is None:
            return ()
        return ((self.a, Slot(self.start, self.end, self.width, "pin")), (self.b, Hole(self.pin, self.width, "pin")))

    def pins(self) -> tuple[tuple[str, Vec], ...]:
        return ((self.b, self.pin),)


@joint_kind
@dataclass(frozen=True)
class PinInArcSlot:
    """A pin at ``pin`` on part ``b`` in an arc slot of part ``a`` (``centre``, mid-radius ``radius``).

    Kinematically the same as a pivot on a link of length ``radius`` about
    ``centre`` (reference file); the residual is ``| |pin - centre| - radius |``.
    The arc slot itself is cut by the part's builder (it knows the travel).
    """

    kind: ClassVar[str] = "pin-in-arc-slot"
    length_fields: ClassVar[tuple[str, ...]] = ("radius",)
    point_fields: ClassVar[tuple[str, ...]] = ("centre", "pin")
    name: str
    a: str
    b: str
    centre: Vec
    radius: float
    pin: Vec

    def __post_init__(self) -> None:
        _check_joint(self, ("centre", "pin"), "radius")

    def residual(self, poses: Mapping[str, Array]) -> Array:
        p = poses_apply(_pose(poses, self.b), self.pin)
        c = poses_apply(_pose(poses, self.a), self.centre)
        return np.abs(np.hypot(*(p - c).T) - self.radius)

    def features(self) -> tuple[tuple[str, Feature], ...]:
        return ()

    def pins(self) -> tuple[tuple[str, Vec], ...]:
        return ((self.b, self.pin),)


@joint_kind
@dataclass(frozen=True)
class Slide:
    """Prismatic joint: part ``b`` translates along the line ``start -> end`` of part ``a`` without turning.

    Realised as two pins of ``b`` (``anchor`` and ``anchor + axis``, with
    ``axis`` a vector in ``b``'s frame) sliding in one straight slot
    ``start -> end`` of ``a`` (the paper's support kind (h)).  The residual
    is the larger of the two pins' distances from the slot line.  ``width``,
    when given, is the slot's width: the joint then cuts the slot in ``a`` and
    the two pin holes in ``b``.
    """

    kind: ClassVar[str] = "slide"
    length_fields: ClassVar[tuple[str, ...]] = ("width",)
    point_fields: ClassVar[tuple[str, ...]] = ("start", "end", "anchor", "axis")
    name: str
    a: str
    b: str
    start: Vec
    end: Vec
    anchor: Vec
    axis: Vec
    width: float | None = None

    def __post_init__(self) -> None:
        _check_joint(self, ("start", "end", "anchor", "axis"), "width")
        if self.axis[0] == 0 and self.axis[1] == 0:  # its two pins would be one: nothing stops it turning
            raise InputError(f"Slide {self.name!r}.axis", self.axis, "a non-zero vector (the second pin's offset)")

    def pin_points(self) -> tuple[Vec, Vec]:
        """The two pins of ``b`` in its own frame: ``anchor`` and ``anchor + axis``."""
        return self.anchor, (self.anchor[0] + self.axis[0], self.anchor[1] + self.axis[1])

    def residual(self, poses: Mapping[str, Array]) -> Array:
        q = _pose(poses, self.b)
        p1, p2 = (poses_apply(q, p) for p in self.pin_points())
        s0 = poses_apply(_pose(poses, self.a), self.start)
        s1 = poses_apply(_pose(poses, self.a), self.end)
        return np.maximum(np.abs(_point_line_distance(p1, s0, s1)), np.abs(_point_line_distance(p2, s0, s1)))

    def features(self) -> tuple[tuple[str, Feature], ...]:
        if self.width is None:
            return ()
        p1, p2 = self.pin_points()
        return (
            (self.a, Slot(self.start, self.end, self.width, "pin")),
            (self.b, Hole(p1, self.width, "pin")),
            (self.b, Hole(p2, self.width, "pin")),
        )

    def pins(self) -> tuple[tuple[str, Vec], ...]:
        return tuple((self.b, p) for p in self.pin_points())


@joint_kind
@dataclass(frozen=True)
class CamOnLine:
    """A round cam (``centre``, ``radius`` on part ``b``) touching a flat face of part ``a``.

    The face is the line ``start -> end`` on ``a``; the residual is
    ``| distance(centre, line) - radius |``.
    """

    kind: ClassVar[str] = "cam-on-line"
    length_fields: ClassVar[tuple[str, ...]] = ("radius",)
    point_fields: ClassVar[tuple[str, ...]] = ("start", "end", "centre")
    name: str
    a: str
    b: str
    start: Vec
    end: Vec
    centre: Vec
    radius: float

    def __post_init__(self) -> None:
        _check_joint(self, ("start", "end", "centre"), None)
        if not check_number(f"CamOnLine {self.name!r}.radius", self.radius) >= 0:  # 0: a point touching the face
            raise InputError(f"CamOnLine {self.name!r}.radius", self.radius, "a radius >= 0")

    def residual(self, poses: Mapping[str, Array]) -> Array:
        c = poses_apply(_pose(poses, self.b), self.centre)
        s0 = poses_apply(_pose(poses, self.a), self.start)
        s1 = poses_apply(_pose(poses, self.a), self.end)
        return np.abs(np.abs(_point_line_distance(c, s0, s1)) - self.radius)

    def features(self) -> tuple[tuple[str, Feature], ...]:
        return ()

    def pins(self) -> tuple[tuple[str, Vec], ...]:
        return ((self.b, self.centre),)


# --------------------------------------------------------------------------
# Driver
# --------------------------------------------------------------------------


@dataclass(frozen=True)
class Driver:
    """The single input of a mechanism.

    ``kind`` is ``"rotation"`` (value in radians, counter-clockwise, about
    ``origin`` of the ground) or ``"translation"`` (value in model units along
    the unit ``axis``).  ``rate`` is the angular frequency in rad/s.  Over
    time ``t`` (seconds) the driver value is

    * full rotation (``amplitude is None``): ``phase + rate * t``; for
      ``kind="path"`` this is the phase of a closed driver path (an OzT
      driver's step) that the mechanism maps to a pose;
    * oscillation: ``centre + amplitude * sin(rate * t + phase)``.
    """

    part: str
    kind: Literal["rotation", "translation", "path"] = "rotation"
    origin: Vec = (0.0, 0.0)
    axis: Vec = (1.0, 0.0)
    rate: float = 2.0 * np.pi
    phase: float = 0.0
    amplitude: float | None = None
    centre: float = 0.0

    def __post_init__(self) -> None:
        if not isinstance(self.part, str) or not self.part:
            raise InputError("driver.part", self.part, "the name of the part it drives (a non-empty string)")
        _check_name("driver.part", self.part)
        if not isinstance(self.kind, str) or self.kind not in ("rotation", "translation", "path"):
            raise InputError("driver.kind", self.kind, "'rotation', 'translation' or 'path'")
        check_fields(self, "driver", skip=("part", "origin", "axis"))
        for f in ("origin", "axis"):
            v = check_finite(f"driver.{f}", getattr(self, f))
            if v.shape != (2,):
                raise InputError(f"driver.{f}", getattr(self, f), "a point (x, y)" if f == "origin" else "a direction (x, y)")
        if not float(np.hypot(*np.asarray(self.axis, float))) > 0:
            raise InputError("driver.axis", self.axis, "a direction of non-zero length")
        check_finite("driver.phase", self.phase)
        check_finite("driver.centre", self.centre)
        if self.amplitude is not None:
            amp = check_finite("driver.amplitude", self.amplitude)
            if amp.shape != () or not float(amp) > 0:
                raise InputError("driver.amplitude", self.amplitude, "a positive amplitude (the phase sets the direction)")
        check_positive("driver.rate", self.rate, "rate (rad/s)")
        from planar.core.limits import check_angle  # an angle float64 resolves (not a phase of 1e300 rad)

        check_angle("driver.phase", self.phase)
        if self.kind != "translation":  # a translation's centre and amplitude are lengths
            check_angle("driver.centre", self.centre)
            check_angle("driver.amplitude", self.amplitude or 0.0)
        if self.kind == "translation" and self.amplitude is None:
            raise InputError("driver.amplitude", None, "a stroke amplitude for a translation driver")

    @property
    def period(self) -> float:
        """Seconds per cycle."""
        return 2.0 * np.pi / self.rate

    def value(self, t: ArrayLike) -> Array:
        """Driver value at times ``t`` (s)."""
        t = check_samples("driver.value(t)", t) if np.ndim(t) else check_finite("driver.value(t)", t)
        if self.amplitude is None:
            return self.phase + self.rate * t
        return self.centre + self.amplitude * np.sin(self.rate * t + self.phase)

    def speed(self, t: ArrayLike) -> Array:
        """Time derivative of :meth:`value` (rad/s or units/s)."""
        t = check_samples("driver.speed(t)", t) if np.ndim(t) else check_finite("driver.speed(t)", t)
        if self.amplitude is None:
            return np.full_like(t, self.rate)
        return self.amplitude * self.rate * np.cos(self.rate * t + self.phase)

    def times(self, samples_per_cycle: int = 360, cycles: float = 1.0) -> Array:
        """Sample times covering ``cycles`` periods, end point excluded."""
        from planar.core.limits import sample_count

        n = sample_count(samples_per_cycle, cycles)  # finite, positive and within PLANAR_MAX_SAMPLES
        if n < 1:
            raise InputError("samples_per_cycle", samples_per_cycle, "at least one sample")
        return np.arange(n, dtype=np.float64) * (self.period / samples_per_cycle)


# --------------------------------------------------------------------------
# Motion
# --------------------------------------------------------------------------


@dataclass
class Motion:
    """Poses of every part over a batch of driver values.

    ``poses[part]`` is ``(N, 3)``: ``x, y, angle`` of the part's frame in the
    world.  ``valid`` is ``(N,)``.  ``fail_code[i]`` indexes ``fail_table``
    (``-1`` where valid); each table entry is ``(joint, why)``.  Invalid
    samples hold finite, nearest-real poses (never NaN) so they can be drawn
    and marked.  A solver may hand over the poses as :class:`LazyPoses`
    (a linkage's compiled solve does): they are then computed the first
    time ``poses`` is read, and kept.
    """

    driver: Array
    poses: dict[str, Array]
    valid: NDArray[np.bool_]
    fail_code: NDArray[np.int16]
    fail_table: list[tuple[str, str]] = field(default_factory=list)
    points: dict[str, Array] = field(default_factory=dict)
    t: Array | None = None
    #: the mechanism solved (set by :meth:`Mechanism.solve`; what ``animate`` and the notebook display draw)
    mechanism: Any = field(default=None, repr=False, compare=False)

    def __post_init__(self) -> None:
        self._check()
        if isinstance(self.poses, LazyPoses):  # computed on first access (see __getattr__)
            self.__dict__["_lazy_poses"] = self.__dict__.pop("poses")

    def _check(self) -> None:
        """Refuse what is not a motion: driver values one finite 1-D array; ``valid``, ``fail_code`` (and
        ``t``) one entry per sample; each pose ``(N, 3)`` and each point ``(N, 2)`` (their numbers are the
        solver's to screen)."""
        d = self.driver
        if not (isinstance(d, np.ndarray) and d.dtype == np.float64 and d.ndim == 1 and np.isfinite(d.sum())):
            self.driver = d = check_samples("Motion.driver", d)
        n = d.shape[0]
        for f, kinds in (("valid", "b"), ("fail_code", "iu")):
            v = getattr(self, f)
            if not isinstance(v, np.ndarray) or v.dtype.kind not in kinds or v.shape != (n,):
                what = "truth values" if f == "valid" else "whole numbers"
                raise InputError(f"Motion.{f}", v, f"an array of {what}, one per driver value ({n})")
        if self.t is not None:
            self.t = check_samples("Motion.t", self.t, n) if np.ndim(self.t) else check_samples("Motion.t", [self.t], n)
        for f, width in (("poses", 3), ("points", 2)):
            table = getattr(self, f)
            if not isinstance(table, Mapping):
                raise InputError(f"Motion.{f}", table, f"a mapping of name to an (N, {width}) array")
            for key, arr in table.items():
                if not isinstance(arr, np.ndarray) or arr.shape != (n, width):
                    raise InputError(f"Motion.{f}.{key}", arr, f"an array of shape ({n}, {width})")
        if not isinstance(self.fail_table, list):
            raise InputError("Motion.fail_table", self.fail_table, "a list of (joint, why)")

    if not TYPE_CHECKING:  # (the type checker keeps reporting unknown attributes)

        def __getattr__(self, name: str) -> Any:
            """``poses`` given as :class:`LazyPoses`: computed now, once, and kept (an ordinary attribute then)."""
            if name == "poses":
                lazy = self.__dict__.get("_lazy_poses")
                if lazy is not None:
                    poses = lazy.make()
                    self.__dict__["poses"] = poses
                    self.__dict__.pop("_lazy_poses", None)
                    return poses
            raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")

    def __getstate__(self) -> dict[str, Any]:
        """Pickled (and deep-copied) with its poses computed."""
        _ = self.poses
        return dict(self.__dict__)

    def __len__(self) -> int:
        return int(self.driver.shape[0])

    def __repr__(self) -> str:
        n = len(self)
        bad = n - int(np.count_nonzero(self.valid))
        src = f" of {self.mechanism.name!r}" if self.mechanism is not None else ""
        span = f", driver {float(self.driver[0]):.4g} to {float(self.driver[-1]):.4g}" if n else ""
        lazy = self.__dict__.get("_lazy_poses")
        parts = lazy.parts if lazy is not None else len(self.poses)
        return f"<Motion{src}: {n} samples, {parts} parts, {bad} invalid{span}>"

    def _repr_html_(self) -> str | None:
        from planar.core.display import html

        return html("motion", self)

    def animate(self, **options: Any) -> Any:
        """An animation player of this motion (see :func:`planar.draw.notebook.animate`); needs its mechanism."""
        from planar.core.display import renderer

        if self.mechanism is None:
            raise InputError("motion.mechanism", None, "a motion made by Mechanism.solve or run (it knows its mechanism)")
        player = renderer("animate")
        if player is None:
            raise InputError("animate", self.mechanism.name, "the drawing side (planar.draw.notebook) importable")
        return player(self.mechanism, self, **options)

    def reason(self, i: int, angle_unit: str = "rad") -> str:
        """Why sample ``i`` is invalid (empty string when it is valid).

        ``angle_unit``: ``"deg"`` says a rotation driver's value in degrees (a scene's
        ``angle_unit``); otherwise the driver value is as stored (radians, or a length).
        """
        n = len(self)
        if not isinstance(angle_unit, str) or angle_unit not in ("rad", "deg"):
            raise InputError("Motion.reason(angle_unit)", angle_unit, "'rad' or 'deg'")
        if isinstance(i, (bool, np.bool_)) or not isinstance(i, (int, np.integer)):
            raise InputError("Motion.reason(i)", i, "a sample index (a whole number)")
        if not -n <= i < n:
            raise InputError("Motion.reason(i)", i, f"an index from {-n} to {n - 1} (the motion has {n} samples)")
        code = int(self.fail_code[i])
        if code < 0:
            return ""
        joint, why = self.fail_table[code]
        value, unit = float(self.driver[i]), ""
        driver = getattr(self.mechanism, "driver", None)
        if angle_unit == "deg" and getattr(driver, "kind", None) == "rotation":
            value, unit = float(np.degrees(value)), " deg"
        return f"joint {joint!r} cannot close at driver value {value:.6g}{unit}: {why}"

    def failures(self) -> list[tuple[int, float, str, str]]:
        """``(index, driver value, joint, why)`` for every invalid sample."""
        idx = np.flatnonzero(~self.valid)
        return [(int(i), float(self.driver[i]), *self.fail_table[int(self.fail_code[i])]) for i in idx]

    def take(self, index: ArrayLike) -> Motion:
        """The samples ``index`` (an index array or boolean mask) as a new motion."""
        idx = np.asarray(index)
        n = len(self)
        if idx.ndim > 1:
            raise InputError("Motion.take(index)", f"an array of shape {idx.shape}", "a 1-D index array or mask")
        if idx.dtype == bool:
            if idx.shape != (n,):
                raise InputError("Motion.take(index)", f"a mask of shape {idx.shape}", f"a mask of shape ({n},)")
        elif idx.dtype.kind not in "iu" and not (idx.size == 0 and idx.dtype.kind == "f"):
            raise InputError("Motion.take(index)", index, "sample indices (whole numbers) or a boolean mask")
        elif idx.size and not (-n <= int(idx.min()) and int(idx.max()) < n):
            raise InputError("Motion.take(index)", index, f"indices from {-n} to {n - 1} (the motion has {n} samples)")
        idx = idx.astype(np.intp) if idx.dtype.kind == "f" else idx
        return Motion(
            driver=self.driver[idx],
            poses={k: v[idx] for k, v in self.poses.items()},
            valid=self.valid[idx],
            fail_code=self.fail_code[idx],
            fail_table=list(self.fail_table),
            points={k: v[idx] for k, v in self.points.items()},
            t=None if self.t is None else self.t[idx],
            mechanism=self.mechanism,
        )

    @property
    def failed_joints(self) -> set[str]:
        """Names of the joints that failed anywhere."""
        codes = np.unique(self.fail_code[self.fail_code >= 0])
        return {self.fail_table[int(c)][0] for c in codes}


def merge_failures(
    n: int, checks: Sequence[tuple[NDArray[np.bool_], str, str]]
) -> tuple[NDArray[np.bool_], NDArray[np.int16], list[tuple[str, str]]]:
    """Combine per-joint validity masks into (valid, fail_code, fail_table).

    ``checks`` holds ``(valid_mask, joint, why)`` in solve order; a sample's
    failure is attributed to the *first* joint that could not close.
    """
    valid = np.ones(n, dtype=bool)
    code = np.full(n, -1, dtype=np.int16)
    table: list[tuple[str, str]] = []
    for mask, joint, why in checks:
        bad = ~np.asarray(mask, dtype=bool) & valid
        if bad.any():
            code[bad] = len(table)
            table.append((joint, why))
            valid &= ~bad
    return valid, code, table


# --------------------------------------------------------------------------
# Mechanism
# --------------------------------------------------------------------------


class Mechanism:
    """Base class of every mechanism: parts, joints, a driver, named points.

    Subclasses implement :meth:`_solve_poses`.  ``points`` maps a name (a
    coupler point, a foot) to ``(part, (x, y))`` in that part's frame.
    """

    name: str
    parts: tuple[Part, ...]
    joints: tuple[JointProtocol, ...]
    driver: Driver
    points: dict[str, tuple[str, Vec]]
    #: the elemental stages a composed toy is made of, in order (empty for every other mechanism)
    stages: Sequence[Any] = ()
    #: true when a part turns out of the driver's plane (elemental #6, #9): no 2D physics rebuild
    spatial: bool = False
    #: the plane the poses are given in: ``"xy"``, or ``"xz"`` (elemental #8: ``(x, z)`` coordinates)
    view: str = "xy"
    #: rigid bodies -> the parts they are made of (a toy's pieces); empty: every part is a body of its own
    bodies: Mapping[str, Sequence[str]] = MappingProxyType({})
    #: what building the mechanism noticed and a maker should read (a toy's merged outlines)
    notes: Sequence[str] = ()

    def __init__(
        self,
        name: str,
        parts: Sequence[Part],
        joints: Sequence[Any],
        driver: Driver,
        points: Mapping[str, tuple[str, Vec]] | None = None,
    ) -> None:
        _check_name("Mechanism.name", name)
        if isinstance(parts, (str, bytes)) or not isinstance(parts, Iterable) or not all(isinstance(p, Part) for p in parts):
            raise InputError(f"{name}.parts", parts, "a sequence of Part")
        if (
            isinstance(joints, (str, bytes))
            or not isinstance(joints, Iterable)
            or not all(hasattr(j, "residual") for j in joints)
        ):
            raise InputError(f"{name}.joints", joints, "a sequence of joints (planar.core.model's joint kinds)")
        if not isinstance(driver, Driver):
            raise InputError(f"{name}.driver", driver, "a Driver")
        self.name = name
        self.parts = tuple(parts)
        self.joints = tuple(joints)
        self.driver = driver
        if points is not None and not isinstance(points, Mapping):
            raise InputError(f"{name}.points", points, "a mapping of point name to (part, (x, y))")
        self.points = dict(points or {})
        names = [p.name for p in self.parts]
        if len(set(names)) != len(names):
            raise InputError(f"{name}.parts", names, "unique part names")
        for pname, (part, _) in self.points.items():
            if part not in names:
                raise InputError(f"{name}.points.{pname}", part, f"one of the parts {names}")
            if pname in names:
                raise InputError(f"{name}.points", pname, "a point name that no part has (tables name columns by both)")
        self._check_joints(names)
        if driver.part not in names:
            raise InputError(f"{name}.driver.part", driver.part, f"one of the parts {names}")
        self.parts = _with_joint_features(self.parts, self.joints)
        self._check_resolution()

    def _check_resolution(self) -> None:
        """Refuse a part or joint coordinate float64 resolves coarser than :data:`~planar.core.limits.RESOLUTION` of
        the mechanism's smallest length (a pin hole, a hull radius, a slot): the whole assembly, as a scene is."""
        from planar.core.limits import check_resolution, resolution_terms

        terms = [t for p in self.parts for t in p._resolution_terms(f"{self.name}.parts.{p.name}")]
        terms += [t for j in self.joints for t in resolution_terms(j, f"{self.name}.joints.{j.name}")]
        check_resolution(terms, "mechanism")

    def _check_joints(self, names: list[str]) -> None:
        """Every joint is of a registered kind and joins two existing parts."""
        seen: set[str] = set()
        for j in self.joints:
            cls = type(j)
            kname = cls.__dict__.get("kind")
            if not isinstance(kname, str) or JOINT_KINDS.get(kname) is not cls:
                raise InputError(
                    f"{self.name}.joints.{getattr(j, 'name', '?')}",
                    cls.__name__,
                    f"a registered joint kind, one of {sorted(JOINT_KINDS)}",
                )
            if j.name in seen:
                raise InputError(f"{self.name}.joints", j.name, "unique joint names")
            seen.add(j.name)
            for side in ("a", "b"):
                if getattr(j, side) not in names:
                    raise InputError(f"{self.name}.joints.{j.name}.{side}", getattr(j, side), f"one of the parts {names}")

    # -- to implement ------------------------------------------------------
    def _solve_poses(self, q: Array) -> tuple[dict[str, Array], list[tuple[NDArray[np.bool_], str, str]]]:
        """Poses for driver values ``q`` and the per-joint validity checks."""
        from planar.core.registry import UnsupportedError

        raise UnsupportedError(
            f"{self.name}: a bare Mechanism has no solver; build a kind that solves itself "
            "(Linkage, FourBar, SliderCrank, ...) from its parts and joints"
        )

    def part_rates(self, q: Array, qd: Array, qdd: Array) -> RatesResult:
        """Velocity, acceleration, angular velocity and acceleration of every part, in closed form.

        ``q``, ``qd``, ``qdd``: the driver's values, rates and rates of change,
        one each per sample (1-D arrays of one shape; rad or model units, per s,
        per s^2).  Returns ``(parts, valid, method)``: a
        :class:`~planar.core.rates.PartRates` per part (world frame, see
        :mod:`planar.core.rates`), where they are defined, and how they were
        found.  A kind with closed-form rates overrides this; the base raises
        :class:`~planar.core.registry.UnsupportedError` naming the kind (never a difference).
        """
        from planar.core.registry import UnsupportedError

        raise UnsupportedError(
            f"rates (velocities, accelerations, torque): no closed-form derivatives for {type(self).__name__} {self.name!r}"
        )

    # -- shared ------------------------------------------------------------
    def part(self, name: str) -> Part:
        """The part called ``name``."""
        if not isinstance(name, str):
            raise InputError(f"{self.name}.part", name, f"a part's name, one of {[p.name for p in self.parts]}")
        for p in self.parts:
            if p.name == name:
                return p
        raise InputError(f"{self.name}.part", name, f"one of {[p.name for p in self.parts]}")

    def _check_placement(self) -> None:
        """Once per mechanism: refuse a placement float64 cannot resolve (as a scene's, :func:`check_scale`)."""
        if "_placement_checked" not in self.__dict__:
            from planar.core.limits import check_scale

            check_scale(self.name, self, size_range=False)
            self.__dict__["_placement_checked"] = True

    def _check_rates_scale(self, where: str) -> None:
        """Once per mechanism: refuse rates, transmission angles and dynamics of a mechanism whose size is
        outside :data:`planar.core.limits.SIZE_RANGE` (1e-60 to 1e60 model units).

        Its motion solves at any scale, but rates multiply lengths (a cross product of two positions at 1e300
        overflows float64) and would come back invalid or zero at every sample; ``where`` names the call.
        """
        if "_rates_scale_checked" not in self.__dict__:
            from planar.core.limits import check_scale

            check_scale(where, self)
            self.__dict__["_rates_scale_checked"] = True

    def _check_driver_resolution(self, q: Array) -> None:
        """Refuse driver values so large that float64's spacing there is coarser than the mechanism needs.

        An angle (rad) must be resolved to :data:`planar.core.limits.RESOLUTION` rad (up to about
        8.4e6 rad), a translation (model units) to that fraction of the mechanism's size: at
        ``q = 1e300`` every sample would be computed from noise and marked valid.
        """
        from planar.core.limits import RESOLUTION

        if not q.size:
            return
        qmax = float(np.abs(q).max())
        unit, fine = ("rad", RESOLUTION) if self.driver.kind != "translation" else ("model units", RESOLUTION * self.size)
        if float(np.spacing(qmax)) > fine:
            far = math.ldexp(1.0, math.frexp(fine)[1] + 52)  # the largest power of two float64 resolves that finely
            raise InputError(
                f"{self.name}.solve(q)",
                f"a driver value of {qmax:.6g} {unit}",
                f"driver values within about {far:.3g} {unit} of zero: float64 resolves {float(np.spacing(qmax)):.3g} "
                f"{unit} there, coarser than {fine:.3g} {unit} (take the value modulo a turn, or move it nearer zero)",
            )

    def solve(self, q: ArrayLike, t: ArrayLike | None = None) -> Motion:
        """Solve all samples at once for driver values ``q`` (scalar or array).

        Raises :class:`~planar.errors.InputError` for driver values float64 cannot resolve finely
        enough (beyond about 8.4e6 rad for a turning driver).
        """
        self._check_placement()
        if isinstance(q, np.ma.MaskedArray) or np.asarray(q).dtype == bool:
            raise InputError(
                f"{self.name}.solve(q)",
                f"a {'masked' if isinstance(q, np.ma.MaskedArray) else 'bool'} array",
                "plain driver values (a masked array: pass q[~q.mask] or q.filled(v))",
            )
        from planar.core import limits

        n_q = int(np.size(q))
        limits.check_count(
            "samples", f"{self.name}.solve(q)", float(n_q), "samples of one motion", shown=f"{n_q:,} driver values"
        )
        need, held = None, 0.0
        if n_q > limits.PILOT_ABOVE:  # a large solve: what this kind really allocates (a pilot), and what is held
            qf = np.ravel(check_finite(f"{self.name}.solve(q)", q))
            need, held = limits.pilot_bytes(lambda k: self.solve(qf[:k]), n_q), limits.resident_bytes()
        if need is None:
            need = limits.motion_bytes(len(self.parts), len(self.points), float(n_q))
        fits = f"{limits.units_within(held, need / max(n_q, 1)):,} samples"
        limits.check_memory(f"{self.name}.solve(q)", f"{n_q:,} driver values", need + held, "a motion", fits=fits)
        qin = np.atleast_1d(check_finite(f"{self.name}.solve(q)", q))
        self._check_driver_resolution(qin)
        qa = new_block(qin.shape)  # the motion's own copy (recycled memory for a large batch)
        np.copyto(qa, qin)
        if qa.ndim != 1:  # an OzT driver's path is a function of its 1-D driver value too
            raise InputError(f"{self.name}.solve(q)", f"an array of shape {qa.shape}", "a scalar or a 1-D array of driver values")
        if t is not None:
            t = check_finite(f"{self.name}.solve(t)", t)
        if t is not None and np.shape(t) != qa.shape[:1]:
            raise InputError(
                f"{self.name}.solve(t)", f"an array of shape {np.shape(t)}", f"one time per driver value (shape {qa.shape[:1]})"
            )
        poses, checks, pts = self._solve_points(qa)
        n = qa.shape[0]
        for p in self.parts:  # the ground never moves: its track is one row seen n times (read-only, no memory)
            g = poses.get(p.name)
            if p.ground and g is not None and n and g.ndim == 2 and g.strides[0] != 0:
                poses[p.name] = np.broadcast_to(g[0].copy(), g.shape)
        table: list[tuple[str, str]] = []
        if pts is None:
            pts = {name: poses_apply(poses[part], xy) for name, (part, xy) in self.points.items()}
        # the final finite check: a sample whose numbers overflowed float64 is never valid (and holds 0, not NaN)
        finite = np.ones(n, dtype=bool)
        for arr in () if isinstance(poses, FinitePoses) else (*poses.values(), *pts.values()):
            if arr.ndim == 2 and arr.strides[0] == 0:  # one row seen n times (the ground)
                finite &= bool(np.isfinite(arr[:1]).all())
            elif not np.isfinite(arr.sum()):  # a cheap screen (a sum of finite numbers may overflow: look closer)
                finite &= np.isfinite(arr).reshape(n, -1).all(axis=1)
        if not finite.all():
            checks = list(checks or []) + [(finite, "result", "a number overflowed float64 (non-finite result)")]
            poses = {k: np.nan_to_num(v, nan=0.0, posinf=0.0, neginf=0.0) for k, v in poses.items()}
            pts = {k: np.nan_to_num(v, nan=0.0, posinf=0.0, neginf=0.0) for k, v in pts.items()}
        if checks is None:  # every sample closes
            valid, code = np.ones(n, dtype=bool), np.full(n, -1, dtype=np.int16)
        else:
            valid, code, table = merge_failures(n, checks)
        return Motion(
            driver=qa,
            poses=poses,
            valid=valid,
            fail_code=code,
            fail_table=table,
            points=pts,
            t=None if t is None else np.asarray(t, dtype=float),
            mechanism=self,
        )

    def _solve_points(
        self, q: Array
    ) -> tuple[dict[str, Array], list[tuple[NDArray[np.bool_], str, str]] | None, dict[str, Array] | None]:
        """Poses, validity checks (``None``: every sample closes) and named points (``None``: from the poses).

        A subclass with a faster path than :meth:`_solve_poses` overrides this.
        """
        poses, checks = self._solve_poses(q)
        return poses, checks, None

    def run(self, samples_per_cycle: int = 360, cycles: float = 1.0) -> Motion:
        """Solve over time with the driver's law (``cycles`` periods of ``samples_per_cycle`` samples each,
        a whole number of at least 4, as a scene's ``samples_per_cycle``)."""
        import numbers

        from planar.core.limits import MIN_SAMPLES_PER_CYCLE, sample_count

        sample_count(samples_per_cycle, cycles)  # types, finite, the samples limit: its own words first
        if not (isinstance(samples_per_cycle, numbers.Integral) and samples_per_cycle >= MIN_SAMPLES_PER_CYCLE):
            raise InputError(
                "samples_per_cycle", samples_per_cycle, f"a whole number of at least {MIN_SAMPLES_PER_CYCLE} samples"
            )
        t = self.driver.times(samples_per_cycle, cycles)
        return self.solve(self.driver.value(t), t=t)

    @cached_property
    def size(self) -> float:
        """The mechanism's characteristic length, the denominator of every "error / size" figure.

        Defined once, here: the largest diameter of any part, i.e. the
        largest distance between two points of one part's hull,
        ``max |c_i - c_j| + r_i + r_j`` over the hull circles ``(c, r)`` of
        each part (its own frame, so it does not depend on the pose).  Model
        units; 1.0 for a mechanism with no hulls.
        """
        best = 0.0
        for p in self.parts:
            if p.hull:
                h = np.asarray(p.hull, dtype=float)
                d = np.hypot(h[:, None, 0] - h[None, :, 0], h[:, None, 1] - h[None, :, 1])
                best = max(best, float((d + h[:, None, 2] + h[None, :, 2]).max()))
        return best or 1.0

    def __repr__(self) -> str:
        return f"<{type(self).__name__} {self.name!r}: {len(self.parts)} parts, {len(self.joints)} joints>"

    def _repr_html_(self) -> str | None:
        from planar.core.display import html

        return html("mechanism", self)

    def animate(self, samples_per_cycle: int = 72, **options: Any) -> Any:
        """An animation player of one cycle (``samples_per_cycle`` frames), shown inline in a notebook.

        See :func:`planar.draw.notebook.animate` for the options; ``.save("x.html")`` writes the page.
        The drawing side (:mod:`planar.draw.notebook`) is loaded on first use (``import planar`` is enough).
        """
        from planar.core.display import renderer

        player = renderer("animate")
        if player is None:
            raise InputError("animate", self.name, "the drawing side (planar.draw.notebook) importable")
        return player(self, self.run(samples_per_cycle=samples_per_cycle), **options)


def _with_joint_features(parts: tuple[Part, ...], joints: Sequence[Any]) -> tuple[Part, ...]:
    """``parts`` with every feature their joints declare added (once; a feature already there is kept)."""
    extra: dict[str, list[Feature]] = {}
    for j in joints:
        for part, feat in j.features():
            extra.setdefault(part, []).append(feat)
    if not extra:
        return parts
    out = []
    for p in parts:
        add = [f for f in dict.fromkeys(extra.get(p.name, ())) if f not in p.features]
        out.append(replace(p, features=p.features + tuple(add)) if add else p)
    return tuple(out)


def joint_residuals(mech: Mechanism, motion: Motion) -> dict[str, Array]:
    """Residual (model units) of every joint of ``mech`` on every sample of ``motion``."""
    if not isinstance(mech, Mechanism):
        raise InputError("mech", type(mech).__name__, "a Mechanism")
    if not isinstance(motion, Motion):
        raise InputError("motion", type(motion).__name__, "a Motion (from mech.solve or mech.run)")
    return {j.name: np.asarray(j.residual(motion.poses)) for j in mech.joints}
