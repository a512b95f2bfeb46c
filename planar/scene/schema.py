"""Scene files as data: the pydantic models of every table and key (strict types, one-line errors).

Angles are radians unless the scene says ``angle_unit = "deg"``; lengths are
model units (``[fabrication] unit_mm`` says what one unit is in millimetres).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Annotated, Any, Literal

from pydantic import (
    AfterValidator,
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Field,
    Strict,
    StrictBool,
    ValidationError,
    model_validator,
)

from planar.core.limits import MAX_HARDWARE_MM, MAX_KERF_MM, MAX_MOTOR_BODY_MM, MAX_MOTOR_MM, SIZE_RANGE
from planar.errors import InputError
from planar.scene.messages import MISSING, NAME_PATTERN, first_problem

Vec2 = tuple[float, float]
# strict types: a number is a TOML number (true is not 1.0, "4" is not 4.0), a flag is true or false
Pos = Annotated[float, Strict(), Field(gt=0, allow_inf_nan=False)]
Real = Annotated[float, Strict(), Field(allow_inf_nan=False)]
#: a name written into CSV headers, DXF groups and SVG text: no control character, comma or double quote
_NAME = NAME_PATTERN
Name = Annotated[str, Strict(), Field(min_length=1, max_length=80, pattern=_NAME)]
Title = Annotated[str, Strict(), Field(max_length=80, pattern=_NAME)]

#: the largest length or coordinate a linkage node takes (model units): the bound of a mechanism's size, checked
#: here too so that the schema refuses ``ra = 1e300`` naming the key before a solver squares it
MAX_LENGTH = SIZE_RANGE[1]


def _length(v: float) -> float:
    if not SIZE_RANGE[0] <= v <= SIZE_RANGE[1]:
        raise ValueError(
            f"a length from {SIZE_RANGE[0]:g} to {SIZE_RANGE[1]:g} model units (beyond, the squares and products of "
            "lengths the solvers form leave float64; choose another model unit)"
        )
    return v


def _coordinates(v: tuple[float, ...]) -> tuple[float, ...]:
    if not all(abs(x) <= MAX_LENGTH for x in v):
        raise ValueError(f"coordinates of at most {MAX_LENGTH:g} model units (beyond, their squares leave float64)")
    return v


def _some_points(v: list[Any]) -> list[Any]:
    if not v:
        raise ValueError("at least one point [x, y]; leave the key out to have two chosen (clear of every leg)")
    for i, p in enumerate(v):
        if p in v[:i]:  # one rod, not two: the plates would be held at one point fewer than written
            raise ValueError(f"distinct points (item {i} repeats item {v.index(p)}, {list(p)})")
    return v


#: the slowest and fastest ``[driver] speed`` (cycles per second): a calendar wheel's turn a year is 3e-8, a
#: 60 000 rpm spindle 1e3; far beyond (1e300) the accelerations, speed squared, overflow float64
SPEED_RANGE = (1e-9, 1e6)


def _speed(v: float) -> float:
    if not SPEED_RANGE[0] <= v <= SPEED_RANGE[1]:
        raise ValueError(f"a speed from {SPEED_RANGE[0]:g} to {SPEED_RANGE[1]:g} cycles per second")
    return v


#: the strongest gravity a scene takes, in standard gravities (9.80665 m/s^2, converted with ``unit_mm``)
MAX_G = 1000.0
#: the largest force component a load exerts (model force units): :data:`MAX_LENGTH`'s bound, so that a torque
#: (a force times a length of at most 1e60) and its square stay within float64
MAX_FORCE = 1e60


def _force(v: tuple[float, ...]) -> tuple[float, ...]:
    if not all(abs(x) <= MAX_FORCE for x in v):
        raise ValueError(f"a force whose components are at most {MAX_FORCE:g} (model force units) in size")
    return v


def _mm_up_to(most: float, what: str) -> Any:
    """A check of a positive length in millimetres: at most ``most`` (``what`` it is, for the message)."""

    def check(v: float) -> float:
        if not v <= most:
            raise ValueError(f"{what} greater than 0 and at most {most:g} mm")
        return v

    return check


#: a small gearmotor's dimensions (mm): an N20's, or a 37 mm gearmotor's with an encoder, are well within
MotorMm = Annotated[
    float, Strict(), Field(gt=0, allow_inf_nan=False), AfterValidator(_mm_up_to(MAX_MOTOR_MM, "a motor dimension"))
]
#: a pin, sheet thickness, wall, part or label size (mm)
HardwareMm = Annotated[float, Strict(), Field(gt=0, allow_inf_nan=False), AfterValidator(_mm_up_to(MAX_HARDWARE_MM, "a size"))]
MotorBodyMm = Annotated[
    float, Strict(), Field(gt=0, allow_inf_nan=False), AfterValidator(_mm_up_to(MAX_MOTOR_BODY_MM, "a motor body length"))
]


#: a node's link length or radius (model units): positive, finite, within what float64 squares
Length = Annotated[float, Strict(), Field(gt=0, allow_inf_nan=False), AfterValidator(_length)]
#: a node's point ``[x, y]`` (model units)
Point = Annotated[tuple[Real, Real], AfterValidator(_coordinates)]


def _whole(v: Any) -> Any:
    if isinstance(v, bool) or not isinstance(v, int):
        raise ValueError("expected 1 or -1 (a whole number)")
    return v


Branch = Annotated[Literal[1, -1], BeforeValidator(_whole)]


if TYPE_CHECKING:  # pydantic's model metaclass, named for the type checker only
    from pydantic._internal._model_construction import ModelMetaclass as _ModelMeta
else:  # at run time reached through a public object, not pydantic's private module
    _ModelMeta = type(BaseModel)


class _RefusesInPlanarWords(_ModelMeta):
    """Built from Python (``SceneSpec(mechanism=...)``), a value that does not validate is an
    :class:`~planar.errors.InputError` naming the field as a scene file writes it and the value, as
    :func:`planar.scene.parse_scene` names it, not pydantic's ``ValidationError``.  Only the direct call is
    wrapped: validating a document (``model_validate``, the nested tables) raises pydantic's error, which the
    loader turns into a :class:`~planar.errors.SceneError` naming the file."""

    def __call__(cls, *args: Any, **data: Any) -> Any:
        try:
            return super().__call__(*args, **data)
        except ValidationError as e:
            errors = e.errors(include_url=False)
            field, value, expected = first_problem(errors, data)
            if errors[0]["type"] == "missing" and not (errors[0]["loc"] and isinstance(errors[0]["loc"][-1], int)):
                value = MISSING
            if len(errors) > 1:
                expected += f" (and {len(errors) - 1} more problem{'s' if len(errors) > 2 else ''})"
            raise InputError(f"{cls.__name__}.{field}", value, expected) from None


class _Strict(BaseModel, metaclass=_RefusesInPlanarWords):
    # a docstring under a field is its description in the JSON schema (``planar schema``)
    model_config = ConfigDict(extra="forbid", allow_inf_nan=False, use_attribute_docstrings=True)


class PolygonSpec(_Strict):
    """A polygon fixed to a part (a foot), in that part's frame; drawn swept with it.

    Example: ``[[mechanism.polygons]]`` ``name = "foot"``, ``part = "coupler"``,
    ``points = [[5.1, -2.25], [6.6, -2.25], [6.6, -1.95], [5.1, -1.95]]``.
    """

    name: Name
    """The polygon's name (``[render] sweep`` refers to it), e.g. ``"foot"``."""
    part: Name
    """The part it is fixed to, e.g. ``"coupler"`` (a four-bar's parts: crank, coupler, rocker)."""
    points: Annotated[list[tuple[Real, Real]], Field(min_length=3)]
    """At least three ``[x, y]`` vertices in the part's frame (model units), e.g. ``[[0, 0], [1, 0], [1, 0.2]]``."""
    cut: StrictBool | Literal["part"] = False
    """``true``: ``planar export`` cuts the polygon as part of its part, merged into the part's outline (joined to
    it by their convex hull where they do not touch); ``"part"``: cut as a part of its own (named as the polygon)
    on a layer of its own, fixed to its part by two pins where both have room; ``false`` (default): drawn only."""


class FourBarSpec(_Strict):
    """A four-bar linkage driven at its crank (parts ``crank``, ``coupler``, ``rocker``; point ``coupler_point``).

    Example: ``type = "fourbar"``, ``ground = 4.0``, ``crank = 1.0``,
    ``coupler = 4.0``, ``rocker = 3.0``, ``coupler_point = [5.5, -2.0]``.
    """

    type: Literal["fourbar"]
    """``"fourbar"``: ground pivots at (0, 0) and (ground, 0) before placement."""
    ground: Pos
    """Distance between the ground pivots O2 and O4 (model units), e.g. ``4.0``."""
    crank: Pos
    """Crank length O2-B (the driven link), e.g. ``1.0``."""
    coupler: Pos
    """Coupler length B-C, e.g. ``4.0``."""
    rocker: Pos
    """Rocker length O4-C, e.g. ``3.0``."""
    coupler_point: tuple[Real, Real] = (0.5, 0.0)
    """The named point ``coupler_point`` in the coupler's frame: origin at the crank pin B, x toward the
    rocker pin C, e.g. ``[5.5, -2.0]``."""
    circuit: Literal["open", "crossed"] = "open"
    """Assembly: ``"open"`` (C left of the directed diagonal B -> O4 at every crank angle) or ``"crossed"`` (C to
    its right); a change-point four-bar, whose two circuits meet, is declared with the crank at 90 degrees and
    carried on by continuity."""
    placement: tuple[Real, Real, Real] = (0.0, 0.0, 0.0)
    """``[x, y, angle]`` of the whole linkage in the world (angle in the scene's angle unit), e.g.
    ``[0.0, 0.0, 0.0]``."""
    polygons: list[PolygonSpec] = []
    """Polygons fixed to parts (feet), swept in drawings: ``[[mechanism.polygons]]`` tables."""


class SliderCrankSpec(_Strict):
    """An offset slider-crank: crank about (0, 0), slider on the line ``y = offset`` (parts ``crank``, ``rod``,
    ``slider``; point ``slider_pin``).

    Example: ``type = "slidercrank"``, ``crank = 1.0``, ``rod = 3.0``, ``offset = 0.2``.
    """

    type: Literal["slidercrank"]
    """``"slidercrank"``."""
    crank: Pos
    """Crank radius (model units), e.g. ``1.0``."""
    rod: Pos
    """Connecting-rod length from crank pin to wrist pin, e.g. ``3.0``."""
    offset: Real = 0.0
    """The slider's line ``y = offset`` (model units), e.g. ``0.2``; ``|offset| < crank + rod``."""
    branch: Branch = 1
    """``1``: the slider on the +x side of the crank; ``-1``: the -x side."""
    placement: tuple[Real, Real, Real] = (0.0, 0.0, 0.0)
    """``[x, y, angle]`` of the whole mechanism in the world (angle in the scene's angle unit)."""
    polygons: list[PolygonSpec] = []
    """Polygons fixed to parts, swept in drawings."""


class NodeSpec(_Strict):
    """A joint centre of a general linkage, placed in closed form from nodes declared before it.

    Which keys a node needs depends on its ``kind`` (one ``[[mechanism.nodes]]`` table each):

    * ``fixed`` — a ground point: ``{ name = "O", kind = "fixed", at = [0.0, 0.0] }``;
    * ``crank`` — the input, turning about a node: ``{ name = "A", kind = "crank", centre = "O",
      radius = 15.0, phase = 0.0 }`` (angle = driver + phase, counter-clockwise);
    * ``actuator`` — the input, translating: ``{ name = "P", kind = "actuator", origin = "O",
      axis = [1.0, 0.0], offset = 0.0 }`` (origin + (driver + offset) along the unit axis);
    * ``rrr`` — a dyad, at ``ra`` from ``a`` and ``rb`` from ``b`` (circle-circle):
      ``{ name = "B", kind = "rrr", a = "A", ra = 50.0, b = "Z", rb = 41.5, branch = -1 }``
      (``branch = 1``: left of a -> b at the first sample, then by continuity);
    * ``rrp`` — a pin in a straight slot, at ``ra`` from ``a`` on the line ``p -> q`` shifted left by
      ``offset``: ``{ name = "S", kind = "rrp", a = "A", ra = 3.0, p = "G1", q = "G2", branch = 1 }``
      (``branch = 1``: the root further along p -> q);
    * ``rigid`` — fixed in the frame of ``a`` (origin) and ``b`` (x axis): coupler points, ternary
      links: ``{ name = "T", kind = "rigid", a = "Q", b = "A", local = [4.0, 0.0] }``;
    * ``geared`` — a crank geared to another: ``{ name = "B", kind = "geared", centre = "O2", radius = 1.2,
      mesh = "A", ratio = -1.0, phase = 90.0 }`` (angle = ratio * angle(mesh) + phase; both centres fixed);
    * ``driven`` — an input with its own law of the ``[driver]`` clock theta: ``{ name = "B", kind = "driven",
      centre = "O2", radius = 1.5, cycles = 2.0, phase = 90.0, mean = 110.0, amplitude = 30.0 }``;
    * ``triad`` — one of three nodes on a ternary link, each ``ra`` from its node ``a``, solved together:
      ``{ name = "T1", kind = "triad", members = ["T2", "T3"], a = "C", ra = 3.27, local = [0.0, 0.0],
      at = [2.0, 3.0] }`` (``at``: roughly where it is with the driver at 0; the members give ``a``, ``ra``,
      ``local``, ``at``).
    """

    name: Name
    """The node's name (links, points and later nodes refer to it), e.g. ``"B"``."""
    kind: Literal["fixed", "crank", "actuator", "rrr", "rrp", "rigid", "geared", "driven", "triad"]
    """One of ``fixed``, ``crank``, ``actuator``, ``rrr``, ``rrp``, ``rigid``, ``geared``, ``driven``, ``triad``
    (see the node's description)."""
    at: Point | None = None
    """``fixed``: the ground point ``[x, y]`` (model units), e.g. ``[-38.0, -7.8]``; ``triad``: roughly where the
    node is with the driver at 0 (picks the assembly)."""
    centre: Name | None = None
    """``crank``, ``geared``, ``driven``: the node it turns about, e.g. ``"O"``."""
    radius: Length | None = None
    """``crank``, ``geared``, ``driven``: its radius (model units), e.g. ``15.0``."""
    phase: Real = 0.0
    """``crank``: added to the driver angle; ``geared``: added to ratio * angle(mesh); ``driven``: in its law
    (scene's angle unit), e.g. ``90``."""
    origin: Name | None = None
    """``actuator``: the node it translates from, e.g. ``"O"``."""
    axis: tuple[Real, Real] = (1.0, 0.0)
    """``actuator``: the direction it translates along (normalised), e.g. ``[0.0, 1.0]``."""
    a: Name | None = None
    """``rrr``, ``rrp``, ``triad``: the node at distance ``ra``; ``rigid``: the frame's origin node. E.g. ``"A"``."""
    ra: Length | None = None
    """``rrr``, ``rrp``, ``triad``: the link length from ``a`` (model units), e.g. ``50.0``."""
    b: Name | None = None
    """``rrr``: the node at distance ``rb``; ``rigid``: the node the frame's x axis points to. E.g. ``"Z"``."""
    rb: Length | None = None
    """``rrr``: the link length from ``b`` (model units), e.g. ``41.5``."""
    p: Name | None = None
    """``rrp``: the slot line's first node (the line runs p -> q), e.g. ``"G1"``."""
    q: Name | None = None
    """``rrp``: the slot line's second node, e.g. ``"G2"``."""
    branch: Branch = 1
    """``rrr``: ``1`` left of a -> b, ``-1`` right; ``rrp``: ``1`` further along p -> q. Holds at the first
    sample and is carried by continuity."""
    offset: Real = 0.0
    """``rrp``: the slot line shifted left of p -> q by this (model units); ``actuator``: added to the
    driver value."""
    local: Point | None = None
    """``rigid``: ``[u, v]`` in the frame of ``a`` (origin) and ``b`` (x axis), model units, e.g. ``[4.0, 0.0]``;
    ``triad``: the node's place on the ternary link (any frame), e.g. ``[3.0, 0.0]``."""
    mesh: Name | None = None
    """``geared``: the crank node it meshes with (``crank``, ``geared`` or ``driven``), e.g. ``"A"``."""
    ratio: Real | None = None
    """``geared``: angular velocity ratio, negative (external spur gears): angle = ratio * angle(mesh) + phase,
    e.g. ``-1.0``."""
    cycles: Pos = 1.0
    """``driven``: turns (or rocking cycles) per cycle of the ``[driver]`` clock, e.g. ``2.0``."""
    amplitude: Pos | None = None
    """``driven``: a rocking input: angle = mean + amplitude sin(cycles theta + phase) (scene's angle unit),
    e.g. ``30.0``; without it the node turns: angle = phase + cycles theta."""
    mean: Real = 0.0
    """``driven``: the middle of a rocking input's swing (scene's angle unit), e.g. ``110.0``."""
    members: tuple[Name, Name] | None = None
    """``triad``: on the triad's first node only, the two other nodes (declared after it), e.g.
    ``["T2", "T3"]``."""

    @model_validator(mode="after")
    def _needs(self) -> NodeSpec:
        from planar.linkages import NODE_KINDS

        # the kind's own scene keys; those with a default here (phase, axis, branch, offset) are never None
        kind = NODE_KINDS[self.kind]
        missing = [f for f in getattr(kind, "required_fields", kind.scene_fields) if getattr(self, f) is None]
        if missing:
            keys = ", ".join(f for f in getattr(kind, "required_fields", kind.scene_fields))
            raise ValueError(f"the keys a {self.kind!r} node needs ({keys}): {', '.join(missing)} missing")
        for key, needs in getattr(kind, "paired_fields", ()):
            if key in self.model_fields_set and getattr(self, needs) is None:
                raise ValueError(f"{key} only with {needs} (a {self.kind!r} node without {needs} turns fully): give both")
        return self


class LinkSpec(_Strict):
    """A rigid part carrying nodes: ``{ name = "upper", nodes = ["Z", "B", "D"] }``; a block sliding along a
    line of another link: ``{ name = "block", nodes = ["A"], guide = ["Q", "T"] }``."""

    name: Name
    """The part's name (the ground is ``ground``, made of the fixed nodes unless declared), e.g. ``"lever"``."""
    nodes: Annotated[list[Name], Field(min_length=1)]
    """The nodes it carries; its frame has its origin at the first and x toward the second, e.g.
    ``["Q", "T"]``. A node shared by two links is a pivot."""
    guide: tuple[Name, Name] | None = None
    """With one node: a block on that node sliding along the line ``[p, q]`` of the link carrying both,
    e.g. ``["Q", "T"]``."""


class LinkageSpec(_Strict):
    """A general pivot/slot linkage of nodes and links (see ``gallery/jansen-leg.toml``,
    ``gallery/quick-return.toml``)."""

    type: Literal["linkage"]
    """``"linkage"``."""
    nodes: Annotated[list[NodeSpec], Field(min_length=2)]
    """``[[mechanism.nodes]]`` tables, each placed from nodes declared before it; exactly the first
    ``crank`` or ``actuator`` is the input."""
    links: Annotated[list[LinkSpec], Field(min_length=1)]
    """``[[mechanism.links]]`` tables: the parts."""
    points: dict[Name, Name] = {}
    """Named points: name -> node, e.g. ``{ foot = "F" }`` (columns of the motion table, trails, loads)."""
    placement: tuple[Real, Real, Real] = (0.0, 0.0, 0.0)
    """``[x, y, angle]`` of the whole linkage in the world (angle in the scene's angle unit)."""
    polygons: list[PolygonSpec] = []
    """Polygons fixed to parts, swept in drawings."""


class LegsSpec(_Strict):
    """A walker: ``count`` identical legs phased on one crankshaft (see ``gallery/jansen-walker-4.toml`` and the
    how-to "Describe a walker").  The leg is written as a ``linkage`` scene's nodes and links: a ``fixed`` crank
    centre, exactly one ``crank`` node turning about it on a link of those two nodes, the leg's fixed pivots and
    its dyads.  Leg ``i``'s nodes, links and points are named with the suffix ``_i`` (``F_1``, ``upper_2``,
    ``foot_3``); the crankshaft is the link ``crankshaft``."""

    type: Literal["legs"]
    """``"legs"``."""
    nodes: Annotated[list[NodeSpec], Field(min_length=3)]
    """One leg's ``[[mechanism.nodes]]`` tables, as in a ``linkage`` scene."""
    links: Annotated[list[LinkSpec], Field(min_length=2)]
    """One leg's ``[[mechanism.links]]`` tables, the crank link among them."""
    points: dict[Name, Name] = {}
    """The leg's named points, e.g. ``{ foot = "F" }``: ``foot_1`` ... ``foot_N`` on the walker."""
    count: Annotated[int, Strict(), Field(ge=1, le=16)]
    """How many legs, e.g. ``4`` (even with ``mirror``)."""
    phases: list[Real] | None = None
    """Each leg's crank angle ahead of the shaft (scene's angle unit), e.g. ``[0, 180, 90, 270]``; default
    evenly spread over a turn (with ``mirror``: over the pairs, both legs of a pair on one angle)."""
    mirror: StrictBool = False
    """Every second leg is the one before it mirrored about the vertical through the crank centre (a
    Strandbeest's pairs)."""
    standoffs: Annotated[list[tuple[Real, Real]], AfterValidator(_some_points)] | None = None
    """Where rods hold the built frame plates apart: points ``[x, y]`` (model units) clear of every leg's
    swept area, e.g. ``[[0.0, -30.0]]``; leave the key out to have two chosen (an empty list is refused: a
    walker's plates need rods between them)."""


class ElementalSpec(_Strict):
    """One of the 11 elemental wind-up mechanisms: ``type = "elemental"``, ``number = 2``,
    ``params = { D_jc = [0.0, 0.08] }``."""

    type: Literal["elemental"]
    """``"elemental"``."""
    number: Annotated[int, Strict(), Field(ge=1, le=11)]
    """Which mechanism, 1-11 (the supplement's numbering; README's table of parameters), e.g. ``5``."""
    params: dict[Name, Real | list[Real]] = {}
    """Parameters overriding the supplement's defaults, by name (README: "Elemental parameters"), e.g.
    ``{ F_jc = [-0.5, 0.0], amplitude = 20 }``; angles (``phi``, ``D_theta``, an Oz ``amplitude``) in the
    scene's angle unit."""


class ChainSpec(_Strict):
    """A motion transfer chain from the motor: ``type = "chain"``, ``chain = ["Rz->Tx", "Tx->Oz"]``."""

    type: Literal["chain"]
    """``"chain"``."""
    chain: Annotated[list[Name], Field(min_length=1)]
    """Patterns ``"In->Out"``, the first driven by the motor (``Rz``), each by the previous one's output
    (``planar chains`` lists them), e.g. ``["Rz->OzT", "OzT->Oz"]``."""


class ToyStageSpec(_Strict):
    """One stage of a toy given its own parameters or a name: ``[[mechanism.stages]]`` with ``cam``,
    ``chain`` (the stage's prefix) and ``params`` (as an elemental's), e.g. what ``planar design`` writes."""

    cam: Literal["left", "right"]
    """The cam whose tree holds the stage, ``"left"`` or ``"right"``."""
    chain: Annotated[list[str], Field(min_length=1)]
    """The patterns from the motor to this stage (a prefix of one of the cam's chains), e.g. ``["Rz->Tx"]``."""
    params: dict[str, Real | list[Real]] = {}
    """The stage mechanism's parameters overriding its defaults (angles in the scene's angle unit)."""
    name: str | None = None
    """A name for the stage's end effector: a point at its follower's origin (trails, motion tables)."""


class ToySpec(_Strict):
    """A wind-up toy: chains on the motor's left and right cams (see ``gallery/horse.toml``)."""

    type: Literal["toy"]
    """``"toy"``."""
    left: list[Annotated[list[Name], Field(min_length=1)]] = []
    """Chains on the left cam, e.g. ``[["Rz->OzT", "OzT->Oz"]]``; chains sharing a prefix share its stages."""
    right: list[Annotated[list[Name], Field(min_length=1)]] = []
    """Chains on the right cam, e.g. ``[["Rz->OzT", "OzT->Ty"], ["Rz->OzT", "OzT->Oz"]]``."""
    phase: Real = math.pi
    """The right cam's lead over the left (scene's angle unit), e.g. ``180`` with ``angle_unit = "deg"``."""
    stages: list[ToyStageSpec] = []
    """Stages with their own parameters or end-effector names (``[[mechanism.stages]]``)."""

    @model_validator(mode="after")
    def _some(self) -> ToySpec:
        if not self.left and not self.right:
            raise ValueError("a toy needs at least one chain on the left or right cam")
        return self


class CatalogSpec(_Strict):
    """A built-in mechanism by name: ``type = "catalog"``, ``name = "jansen"``."""

    type: Literal["catalog"]
    """``"catalog"``."""
    name: Name
    """A name of ``planar.scene.catalog.CATALOG``, e.g. ``"jansen"``, ``"kangaroo"``, ``"windup-5"``, ``"horse"``."""


class CamSegmentSpec(_Strict):
    """One segment of a cam's program: ``law`` over ``angle`` of cam turn (angle unit), changing the
    follower's displacement by ``lift`` (model units; an oscillating follower's in the angle unit)."""

    law: Literal["cycloidal", "harmonic", "polynomial-345", "dwell"]
    """The motion law of the segment, e.g. ``"cycloidal"``: cycloidal, simple harmonic, 3-4-5 polynomial or dwell."""
    angle: Pos
    """Cam turn over which the segment runs (angle unit), e.g. ``90.0``; the segments' angles sum to one turn."""
    lift: Real = 0.0
    """Change of the follower's displacement over the segment, e.g. ``16.0`` (model units; an oscillating
    follower's in the angle unit; negative for a return, 0 for a dwell); the lifts sum to 0."""


class CamFollowerSpec(_Strict):
    """A cam's follower: what touches the cam (``kind``) and how it moves (``motion``); see planar.cams."""

    kind: Literal["knife", "roller", "flat"]
    """What touches the cam, e.g. ``"roller"``: a knife edge, a roller or a flat face."""
    motion: Literal["translating", "oscillating"] = "translating"
    """How the follower moves, e.g. ``"oscillating"``: along ``axis`` or about ``pivot``."""
    roller_radius: Pos | None = None
    """Radius of the roller (roller followers only), e.g. ``0.45``."""
    axis: tuple[Real, Real] = (0.0, 1.0)
    """Direction of lift of a translating follower, e.g. ``[0.0, 1.0]``."""
    offset: Real = 0.0
    """Distance of a translating follower's axis to the left of the cam's centre, e.g. ``0.2``."""
    pivot: tuple[Real, Real] | None = None
    """Ground pivot of an oscillating follower's arm, e.g. ``[3.4, 2.0]``."""
    arm: Pos | None = None
    """Pivot to the roller's centre (knife: its tip) of an oscillating follower, e.g. ``3.2``."""
    face_offset: Real = 0.0
    """A flat face's distance from the pivot's line, toward the cam, e.g. ``0.3``."""
    branch: Branch = 1
    """Which of the two arm positions touching the base circle (oscillating), ``1`` or ``-1``."""

    @model_validator(mode="after")
    def _needs(self) -> CamFollowerSpec:
        if (self.kind == "roller") != (self.roller_radius is not None):
            raise ValueError("roller_radius is given for a roller follower, and only for one")
        if self.motion == "oscillating" and (self.pivot is None or self.arm is None):
            raise ValueError("an oscillating follower needs pivot and arm")
        if self.motion == "translating" and (self.pivot is not None or self.arm is not None):
            raise ValueError("pivot and arm are for an oscillating follower (a translating one has axis, offset)")
        return self


class CamSpec(_Strict):
    """A disc cam turning about (0, 0), its follower, and the linkage the follower drives (planar.cams)."""

    type: Literal["cam"]
    """``"cam"``."""
    base_radius: Pos
    """The cam outline's least radius (model units), e.g. ``1.5``."""
    follower: CamFollowerSpec
    """The follower: ``[mechanism.follower]`` with ``kind``, ``motion`` and its geometry."""
    segments: Annotated[list[CamSegmentSpec], Field(min_length=2)]
    """The program, one ``[[mechanism.segments]]`` table per segment (at least two), in cam-angle order."""
    max_pressure_angle: Pos | None = None
    """Largest pressure angle allowed (angle unit), e.g. ``30.0``; default 30 deg translating, 45 oscillating."""
    link_width: Pos | None = None
    """Width of the follower and the linked parts, e.g. ``0.5``; default 8 % of their span."""
    nodes: list[NodeSpec] = []
    """Linkage nodes the follower drives, as in a ``linkage`` scene; the follower's are ``tip`` and ``pivot``."""
    links: list[LinkSpec] = []
    """Links of the driven linkage, as in a ``linkage`` scene (``follower`` may list extra nodes)."""
    points: dict[Name, Name] = {}
    """Named points: name to node, e.g. ``{ beak = "H" }``; default the follower's ``tip``."""
    polygons: list[PolygonSpec] = []
    """Polygons fixed to parts (drawn swept with them), as in other scenes."""


MechanismSpec = Annotated[
    FourBarSpec | SliderCrankSpec | LinkageSpec | LegsSpec | ElementalSpec | ChainSpec | ToySpec | CatalogSpec | CamSpec,
    Field(discriminator="type"),
]


class DriverSpec(_Strict):
    """The input's law: ``speed`` cycles per second, for ``cycles`` or ``duration`` seconds.

    Without ``amplitude`` the input turns fully: ``phase + 2 pi speed t``.
    With ``amplitude`` it rocks: ``centre + amplitude sin(2 pi speed t + phase)``,
    for a limited input (double-rockers, straight-line linkages).  For a
    rotary input (a four-bar's or slider-crank's crank, a linkage's crank node)
    ``amplitude``, ``centre`` and ``phase`` are in the scene's angle unit, the
    input angle counter-clockwise from the linkage's own x axis (a four-bar's
    ground line, before ``placement``; a crank node adds its own ``phase``);
    for a linkage driven by an actuator node, ``amplitude`` and ``centre`` are
    model units along its axis.
    """

    speed: Annotated[Pos, AfterValidator(_speed)] = 1.0
    """Cycles per second of the input (a turn, or a rocking period), 1e-9 to 1e6, e.g. ``0.5``."""
    cycles: Pos | None = None
    """How many cycles to solve (default 1), e.g. ``2``; or give ``duration``."""
    duration: Pos | None = None
    """Seconds to solve instead of ``cycles``, e.g. ``3.0``."""
    samples_per_cycle: Annotated[int, Strict(), Field(ge=4)] = 72
    """Samples (and animation frames) per cycle, at least 4, e.g. ``36``; samples x cycles at most
    ``PLANAR_MAX_SAMPLES`` (:mod:`planar.core.limits`)."""
    phase: Real = 0.0
    """Input at t = 0 for a turning input, or the sine's phase for a rocking one (scene's angle unit)."""
    amplitude: Pos | None = None
    """Rock instead of turning: ``centre + amplitude sin(2 pi speed t + phase)`` (angle unit, or model units
    for an actuator), e.g. ``25``; fourbar, slidercrank and linkage only."""
    centre: Real = 0.0
    """Middle of a rocking input (needs ``amplitude``), e.g. ``60``."""

    @model_validator(mode="after")
    def _one(self) -> DriverSpec:
        if self.cycles is not None and self.duration is not None:
            raise ValueError("give cycles or duration, not both")
        if self.amplitude is None and "centre" in self.model_fields_set:
            raise ValueError("centre is the middle of a rocking input: give amplitude too")
        return self


class LoadSpec(_Strict):
    """A force (model force units, world frame) the mechanism exerts at a named point."""

    point: Name
    """The named point it acts at, e.g. ``"coupler_point"``, ``"foot"``."""
    force: Annotated[tuple[Real, Real], AfterValidator(_force)]
    """``[fx, fy]`` the mechanism exerts there (model force units, world frame; each at most 1e60 in size), e.g.
    ``[0.0, 10.0]``."""


class SpringSpec(_Strict):
    """A damped spring between two parts (anchors in each part's frame)."""

    a: Name
    """The first part, e.g. ``"crank"``."""
    anchor_a: tuple[Real, Real] = (0.0, 0.0)
    """Its anchor in part ``a``'s frame (model units), e.g. ``[0.5, 0.0]``."""
    b: Name
    """The second part, e.g. ``"rocker"``."""
    anchor_b: tuple[Real, Real] = (0.0, 0.0)
    """Its anchor in part ``b``'s frame."""
    rest_length: Annotated[float, Strict(), Field(ge=0)] | None = None
    """Unstretched length (model units); default: the anchors' distance at the first sample."""
    stiffness: Pos
    """Force per unit of stretch, e.g. ``10.0``."""
    damping: Annotated[float, Strict(), Field(ge=0)] = 0.0
    """Force per unit of stretching speed, e.g. ``0.1``."""


class EffectsSpec(_Strict):
    """Physical effects for the physics rebuild and the motor torque; none unless named."""

    gravity: tuple[Real, Real] | None = None
    """``[gx, gy]`` in model units per s^2, e.g. ``[0.0, -9.81]``; none unless given."""
    damping: Annotated[float, Strict(), Field(gt=0, le=1)] | None = None
    """Space damping: fraction of every body's velocity kept per second, in (0, 1], e.g. ``0.99``."""
    density: Pos = 1.0
    """Mass per unit area of every part (inertia in ``compare`` and the motor torque), e.g. ``0.01``."""
    springs: list[SpringSpec] = []
    """Damped springs between parts: ``[{ a = "crank", b = "rocker", stiffness = 10.0 }]``."""
    loads: list[LoadSpec] = []
    """Forces at named points: ``[{ point = "coupler_point", force = [0.0, 10.0] }]``."""
    motor: StrictBool = False
    """``compare`` also drives the mechanism with a motor and checks its torque against inverse dynamics,
    e.g. ``true``; implied by ``motor_force_limit``.  Without it only the motion is compared."""
    motor_force_limit: Pos | None = None
    """``compare`` drives with a motor of this largest torque instead of an exact input, e.g. ``50.0``."""

    @model_validator(mode="before")
    @classmethod
    def _no_contact(cls, data: Any) -> Any:
        for key in ("contact", "friction"):
            if isinstance(data, dict) and key in data:
                raise ValueError(
                    f"'{key}' was removed: the parts of a mechanism sit on layers and never touch, "
                    "so collisions (and their friction) are not simulated; delete the key"
                )
        return data


class RenderSpec(_Strict):
    """How ``planar render`` draws the animation."""

    width: Annotated[int, Strict(), Field(ge=16, le=4096)] = 480
    """Frame width in pixels (16-4096), e.g. ``480``."""
    height: Annotated[int, Strict(), Field(ge=16, le=4096)] = 360
    """Frame height in pixels (16-4096), e.g. ``360``."""
    supersample: Annotated[int, Strict(), Field(ge=1, le=4)] = 2
    """Antialiasing factor 1-4 (drawn this much larger, then reduced)."""
    trails: list[Name] | None = None
    """Named points whose paths are drawn, e.g. ``["coupler_point"]``; default every named point."""
    sweep: list[Name] = []
    """Polygons drawn swept along the motion, e.g. ``["foot"]``."""
    targets: list[tuple[Real, Real]] = []
    """Fixed points drawn as pink dots in every frame, world ``[x, y]`` (model units), e.g. the targets ``planar
    synth path`` aimed at (it writes them here): ``[[1.0, 2.0], [1.5, 2.2]]``."""
    background: Annotated[Name, Field(pattern=r"^#[0-9a-fA-F]{6}$")] = "#ffffff"
    """Background colour ``#rrggbb``, e.g. ``"#ffffff"``."""
    show_pins: StrictBool = True
    """Draw the pins of the joints."""
    fps: Annotated[float, Strict(), Field(gt=0, le=240)] | None = None
    """Frames per second of the animation, e.g. ``25.0``; default 25, or 50 when a cycle would get fewer than 12
    frames; a GIF plays at most 50. A cycle plays for ``1/speed`` seconds within one frame delay."""
    opacity: Annotated[float, Strict(), Field(ge=0, le=1)] = 1.0
    """Fill opacity of moving parts, 0-1, e.g. ``0.6``: below 1 what lies under a part shows through."""
    exploded: StrictBool = False
    """Draw a wind-up toy as its exploded stage panels instead of assembled (default: assembled), e.g. ``true``."""


class FabricationSpec(_Strict):
    """How ``planar export`` cuts the parts (millimetres)."""

    unit_mm: Pos = 10.0
    """What one model unit is in millimetres, e.g. ``15.0``."""
    thickness_mm: HardwareMm = 3.0
    """Sheet thickness (pin lengths, spacers), e.g. ``3.0``."""
    kerf_mm: Annotated[float, Strict(), Field(ge=0, le=MAX_KERF_MM)] = 0.15
    """Beam width 0-2 mm: outlines grow and holes shrink by half of it."""
    pin_diameter_mm: HardwareMm = 3.0
    """Diameter of every pin (holes and slots are cut at this plus ``clearance_mm``)."""
    clearance_mm: Annotated[float, Strict(), Field(ge=0, le=MAX_KERF_MM)] = 0.1
    """Running clearance added to pivot holes and slots, 0-2 mm."""
    sheet_mm: tuple[Pos, Pos] = (300.0, 200.0)
    """Sheet ``[width, height]``; parts that do not fit go on more sheets."""
    # manufacturability (planar.fabrication.parts): thinnest material between a cut and the outline, smallest part,
    # smallest engraved text, clearance past each end of a pin's travel in its slot; narrow parts are
    # widened (widen = true) or refused
    min_wall_mm: HardwareMm = 1.5
    """Thinnest material between a cut and the outline (narrow parts widened or refused)."""
    min_part_mm: HardwareMm = 5.0
    """Smallest part accepted (its smaller side)."""
    min_label_mm: HardwareMm = 1.5
    """Smallest engraved label height; below it the part's number is engraved."""
    slot_end_margin_mm: Annotated[float, Strict(), Field(ge=0, le=50)] = 1.0
    """Slot length past each end of the pin's travel."""
    widen: StrictBool = True
    """Widen a rounded part too narrow for its holes (``false``: refuse it)."""
    # assembly: pin head allowance per end; drive: D-shaft (diameter, distance across the flat), motor
    # screws either side of the shaft, ground-plate mounting holes
    pin_head_mm: Annotated[float, Strict(), Field(ge=0, le=50)] = 1.5
    """Pin head allowance per end (pin length = thickness x layers + two heads)."""
    shaft_diameter_mm: MotorMm = 3.0
    """Motor shaft diameter (the driven part's D hole)."""
    shaft_flat_mm: MotorMm = 2.5
    """Distance across the shaft's flat (the D)."""
    motor_screw_mm: MotorMm = 1.8
    """Motor screw hole diameter as cut (a clearance hole: the screws thread into the motor's face); 1.8 is
    ISO 273's medium clearance hole for the N20's M1.6 screws."""
    motor_screw_spacing_mm: MotorMm = 9.0
    """Distance between the two motor screws, across the shaft (N20: 9)."""
    motor_shaft_mm: MotorMm = 9.0
    """Length of the motor's shaft above its face, up to 100 (an N20 micro gearmotor's D shaft: 9); a plan whose shaft must
    reach higher fails the build check (exit 3)."""
    motor_body_mm: MotorBodyMm = 26.0
    """Length of the motor's body below its face (an N20: 9 gearbox + 15 motor + its end cap and terminals, about
    26; more with an encoder): the mounting standoffs clear it."""
    mounting_hole_mm: MotorMm = 3.2
    """Diameter of the ground plates' mounting holes (on ears), as cut: M3 screws into the standoffs."""
    link_width_mm: HardwareMm | None = None
    """Width of every link of a ``linkage`` scene (mm, the cut and the drawings), at least ``pin_diameter_mm +
    clearance_mm + 2 min_wall_mm``; default 8 % of the linkage's span (the larger side of the box its joints stay
    in over a cycle) times ``unit_mm``."""
    # nesting and file conventions
    spacing_mm: Annotated[float, Strict(), Field(ge=0, le=100)] = 3.0
    """Gap between nested parts."""
    margin_mm: Annotated[float, Strict(), Field(ge=0, le=100)] = 5.0
    """Margin from the sheet's edge."""
    svg_stroke_mm: Pos = 0.025
    """SVG stroke width (hairline for laser software)."""
    cut_colour: Annotated[Name, Field(pattern=r"^#[0-9a-fA-F]{6}$")] = "#ff0000"
    """Colour of cut lines ``#rrggbb``."""
    engrave_colour: Annotated[Name, Field(pattern=r"^#[0-9a-fA-F]{6}$")] = "#0000ff"
    """Colour of engraved lines (labels, letters) ``#rrggbb``."""
    colours: Literal["planar", "boxes"] = "planar"
    """Colour preset of the cut files: ``"planar"`` (``cut_colour`` for every cut, ``engrave_colour``) or
    ``"boxes"`` (Boxes.py's: outer cut black, inner cut blue, engraving green)."""
    reference_square_mm: Annotated[float, Strict(), Field(ge=0, le=100)] = 0.0
    """Side of a reference square cut beside the parts (measure it to check the scale), 0 for none, e.g. ``10``."""
    hardware: Literal["rod-eclip", "screw"] = "rod-eclip"
    """What every pin is: ``"rod-eclip"`` (steel rod, DIN 125 washers and DIN 6799 e-clips) or ``"screw"``
    (ISO 7380 button-head screw, DIN 125 washers, DIN 985 nylon lock nut), sized by ``pin_diameter_mm``."""


#: millimetres per model unit of a wind-up scene that does not say (the paper's toys are about 0.9 units across)
WINDUP_UNIT_MM = 100.0


class SceneSpec(_Strict):
    """A whole scene file."""

    name: Title = ""
    """The scene's name (titles, the mechanism's name); default the file's stem, e.g. ``"kangaroo-leg"``."""
    angle_unit: Literal["rad", "deg"] = "rad"
    """Unit of every angle in the file: ``"rad"`` or ``"deg"``."""
    mechanism: MechanismSpec
    """The mechanism, by ``type``: fourbar, slidercrank, linkage, legs, elemental, chain, toy, catalog."""
    driver: DriverSpec = DriverSpec()
    """The input's law over time."""
    effects: EffectsSpec = EffectsSpec()
    """Physical effects (physics rebuild, motor torque); nothing unless named."""
    render: RenderSpec = RenderSpec()
    """Drawing options."""
    fabrication: FabricationSpec = FabricationSpec()
    """Laser-cutting options (mm); a wind-up scene (elemental, chain, toy) cuts at 100 mm per unit unless its
    ``unit_mm`` says otherwise (the supplement's units: a toy about 9 cm across)."""

    @model_validator(mode="after")
    def _windup_unit(self) -> SceneSpec:
        if self.mechanism.type in ("elemental", "chain", "toy") and "unit_mm" not in self.fabrication.model_fields_set:
            self.fabrication = self.fabrication.model_copy(update={"unit_mm": WINDUP_UNIT_MM})
        return self


def scene_schema() -> dict[str, Any]:
    """JSON schema of a scene file."""
    return SceneSpec.model_json_schema()
