"""Scene files: one TOML file describes a mechanism, its driver, effects, drawing and fabrication.

Validated with pydantic: unknown keys are errors, and every error names the
file, the field path, the bad value and what was expected, on one line
(:class:`planar.SceneError`).  ``planar schema`` prints the JSON schema
(committed as ``gallery/scene.schema.json``).

Angles are radians unless the scene says ``angle_unit = "deg"``; lengths are
model units (``[fabrication] unit_mm`` says what one unit is in millimetres).
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Annotated, Any, Literal, Union

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, ValidationError, model_validator

from .effects import Effects, Load, Spring
from .errors import InputError, PlanarError, SceneError
from .model import Mechanism, Motion

__all__ = ["SceneSpec", "Scene", "load_scene", "parse_scene", "scene_schema"]

Vec2 = tuple[float, float]
Pos = Annotated[float, Field(gt=0, allow_inf_nan=False)]
Real = Annotated[float, Field(allow_inf_nan=False)]


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)


class PolygonSpec(_Strict):
    """A polygon fixed to a part (a foot), in that part's frame; drawn swept with it."""

    name: str
    part: str
    points: Annotated[list[tuple[Real, Real]], Field(min_length=3)]


class FourBarSpec(_Strict):
    type: Literal["fourbar"]
    ground: Pos
    crank: Pos
    coupler: Pos
    rocker: Pos
    coupler_point: tuple[Real, Real] = (0.5, 0.0)
    circuit: Literal["open", "crossed"] = "open"
    placement: tuple[Real, Real, Real] = (0.0, 0.0, 0.0)
    polygons: list[PolygonSpec] = []


class SliderCrankSpec(_Strict):
    type: Literal["slidercrank"]
    crank: Pos
    rod: Pos
    offset: Real = 0.0
    branch: Literal[1, -1] = 1
    placement: tuple[Real, Real, Real] = (0.0, 0.0, 0.0)
    polygons: list[PolygonSpec] = []


class NodeSpec(_Strict):
    """A joint centre of a general linkage; which fields it needs depends on ``kind``."""

    name: str
    kind: Literal["fixed", "crank", "actuator", "rrr", "rrp", "rigid"]
    at: tuple[Real, Real] | None = None
    centre: str | None = None
    radius: Pos | None = None
    phase: Real = 0.0
    origin: str | None = None
    axis: tuple[Real, Real] = (1.0, 0.0)
    a: str | None = None
    ra: Pos | None = None
    b: str | None = None
    rb: Pos | None = None
    p: str | None = None
    q: str | None = None
    branch: Literal[1, -1] = 1
    offset: Real = 0.0
    local: tuple[Real, Real] | None = None

    @model_validator(mode="after")
    def _needs(self) -> "NodeSpec":
        from .linkages import NODE_KINDS

        # the kind's own scene keys; those with a default here (phase, axis, branch, offset) are never None
        missing = [f for f in NODE_KINDS[self.kind].scene_fields if getattr(self, f) is None]
        if missing:
            raise ValueError(f"a {self.kind!r} node needs {', '.join(missing)}")
        return self


class LinkSpec(_Strict):
    name: str
    nodes: Annotated[list[str], Field(min_length=1)]
    guide: tuple[str, str] | None = None


class LinkageSpec(_Strict):
    type: Literal["linkage"]
    nodes: Annotated[list[NodeSpec], Field(min_length=2)]
    links: Annotated[list[LinkSpec], Field(min_length=1)]
    points: dict[str, str] = {}
    placement: tuple[Real, Real, Real] = (0.0, 0.0, 0.0)
    polygons: list[PolygonSpec] = []


class ElementalSpec(_Strict):
    type: Literal["elemental"]
    number: Annotated[int, Field(ge=1, le=11)]
    params: dict[str, Union[Real, list[Real]]] = {}


class ChainSpec(_Strict):
    type: Literal["chain"]
    chain: Annotated[list[str], Field(min_length=1)]


class ToySpec(_Strict):
    type: Literal["toy"]
    left: list[Annotated[list[str], Field(min_length=1)]] = []
    right: list[Annotated[list[str], Field(min_length=1)]] = []
    phase: Real = math.pi

    @model_validator(mode="after")
    def _some(self) -> "ToySpec":
        if not self.left and not self.right:
            raise ValueError("a toy needs at least one chain on the left or right cam")
        return self


class CatalogSpec(_Strict):
    type: Literal["catalog"]
    name: str


MechanismSpec = Annotated[
    Union[FourBarSpec, SliderCrankSpec, LinkageSpec, ElementalSpec, ChainSpec, ToySpec, CatalogSpec],
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

    speed: Pos = 1.0
    cycles: Pos | None = None
    duration: Pos | None = None
    samples_per_cycle: Annotated[int, Field(ge=4, le=100_000)] = 72
    phase: Real = 0.0
    amplitude: Pos | None = None
    centre: Real = 0.0

    @model_validator(mode="after")
    def _one(self) -> "DriverSpec":
        if self.cycles is not None and self.duration is not None:
            raise ValueError("give cycles or duration, not both")
        if self.amplitude is None and "centre" in self.model_fields_set:
            raise ValueError("centre is the middle of a rocking input: give amplitude too")
        return self


class LoadSpec(_Strict):
    """A force (model force units, world frame) the mechanism exerts at a named point."""

    point: str
    force: tuple[Real, Real]


class SpringSpec(_Strict):
    """A damped spring between two parts (anchors in each part's frame)."""

    a: str
    anchor_a: tuple[Real, Real] = (0.0, 0.0)
    b: str
    anchor_b: tuple[Real, Real] = (0.0, 0.0)
    rest_length: Annotated[float, Field(ge=0)] | None = None
    stiffness: Pos
    damping: Annotated[float, Field(ge=0)] = 0.0


class EffectsSpec(_Strict):
    """Physical effects for the physics rebuild; none unless named."""

    gravity: tuple[Real, Real] | None = None
    contact: bool = False
    friction: Annotated[float, Field(ge=0)] | None = None
    damping: Annotated[float, Field(gt=0, le=1)] | None = None
    density: Pos = 1.0
    springs: list[SpringSpec] = []
    loads: list[LoadSpec] = []
    motor_force_limit: Pos | None = None


class RenderSpec(_Strict):
    width: Annotated[int, Field(ge=16, le=4096)] = 480
    height: Annotated[int, Field(ge=16, le=4096)] = 360
    supersample: Annotated[int, Field(ge=1, le=4)] = 2
    trails: list[str] | None = None
    sweep: list[str] = []
    background: Annotated[str, Field(pattern=r"^#[0-9a-fA-F]{6}$")] = "#ffffff"
    show_pins: bool = True


class FabricationSpec(_Strict):
    unit_mm: Pos = 10.0
    thickness_mm: Pos = 3.0
    kerf_mm: Annotated[float, Field(ge=0, le=2)] = 0.15
    pin_diameter_mm: Pos = 3.0
    clearance_mm: Annotated[float, Field(ge=0, le=2)] = 0.1
    sheet_mm: tuple[Pos, Pos] = (300.0, 200.0)
    # manufacturability (planar.fabparts): thinnest material between a cut and the outline, smallest part,
    # smallest engraved text, clearance past each end of a pin's travel in its slot; narrow parts are
    # widened (widen = true) or refused
    min_wall_mm: Pos = 1.5
    min_part_mm: Pos = 5.0
    min_label_mm: Pos = 1.5
    slot_end_margin_mm: Annotated[float, Field(ge=0, le=50)] = 1.0
    widen: bool = True
    # assembly: pin head allowance per end; drive: D-shaft (diameter, distance across the flat), motor
    # screws either side of the shaft, ground-plate mounting holes
    pin_head_mm: Annotated[float, Field(ge=0, le=50)] = 1.5
    shaft_diameter_mm: Pos = 3.0
    shaft_flat_mm: Pos = 2.5
    motor_screw_mm: Pos = 1.7
    motor_screw_spacing_mm: Pos = 9.0
    mounting_hole_mm: Pos = 3.2
    # nesting and file conventions
    spacing_mm: Annotated[float, Field(ge=0, le=100)] = 3.0
    margin_mm: Annotated[float, Field(ge=0, le=100)] = 5.0
    svg_stroke_mm: Pos = 0.025
    cut_colour: Annotated[str, Field(pattern=r"^#[0-9a-fA-F]{6}$")] = "#ff0000"
    engrave_colour: Annotated[str, Field(pattern=r"^#[0-9a-fA-F]{6}$")] = "#0000ff"


class SceneSpec(_Strict):
    """A whole scene file."""

    name: str = ""
    angle_unit: Literal["rad", "deg"] = "rad"
    mechanism: MechanismSpec
    driver: DriverSpec = DriverSpec()
    effects: EffectsSpec = EffectsSpec()
    render: RenderSpec = RenderSpec()
    fabrication: FabricationSpec = FabricationSpec()


def scene_schema() -> dict[str, Any]:
    """JSON schema of a scene file."""
    return SceneSpec.model_json_schema()


# --------------------------------------------------------------------------- loading


def _loc(loc: tuple) -> str:
    out = ""
    for part in loc:
        if isinstance(part, int):
            out += f"[{part}]"
        elif part in ("fourbar", "slidercrank", "linkage", "elemental", "chain", "toy", "catalog") and out == "mechanism":
            continue  # the discriminated union's tag
        else:
            out += ("." if out else "") + str(part)
    return out


def _format_validation(path: str, e: ValidationError) -> str:
    errs = e.errors(include_url=False)
    first = errs[0]
    where = _loc(tuple(first["loc"]))
    msg = first["msg"]
    got = first.get("input")
    text = f"{path}: {where or 'scene'}: {msg}"
    if first["type"] not in ("missing",) and not isinstance(got, dict):
        text += f" (got {got!r})"
    if len(errs) > 1:
        text += f" (and {len(errs) - 1} more problem{'s' if len(errs) > 2 else ''})"
    return text


def parse_scene(data: dict[str, Any], path: str = "<scene>") -> SceneSpec:
    """Validate a scene given as a dict (a parsed TOML document)."""
    try:
        return SceneSpec.model_validate(data)
    except ValidationError as e:
        raise SceneError(_format_validation(path, e)) from None


@dataclass
class Scene:
    """A validated scene and the mechanism it describes."""

    spec: SceneSpec
    mechanism: Mechanism
    path: str = "<scene>"
    polygons: dict[str, tuple[str, np.ndarray]] = field(default_factory=dict)

    def motion(self) -> Motion:
        """The analytic motion over the scene's cycles (or duration)."""
        d = self.spec.driver
        drv = self.mechanism.driver
        period = drv.period
        if d.duration is not None:
            cycles = d.duration / period
        else:
            cycles = d.cycles if d.cycles is not None else 1.0
        n = max(2, int(round(d.samples_per_cycle * cycles)))
        t = np.arange(n) * (period / d.samples_per_cycle)
        return self.mechanism.solve(drv.value(t), t=t)

    @property
    def name(self) -> str:
        return self.spec.name or Path(self.path).stem

    @property
    def effects(self) -> Effects:
        """The scene's ``[effects]`` as the model's plain record (what ``simulate`` takes)."""
        e = self.spec.effects
        return Effects(
            gravity=None if e.gravity is None else (float(e.gravity[0]), float(e.gravity[1])),
            contact=e.contact, friction=e.friction, damping=e.damping, density=e.density,
            springs=tuple(Spring(s.a, s.b, s.stiffness, (float(s.anchor_a[0]), float(s.anchor_a[1])),
                                 (float(s.anchor_b[0]), float(s.anchor_b[1])), s.rest_length, s.damping)
                          for s in e.springs),
            loads=tuple(Load(ld.point, (float(ld.force[0]), float(ld.force[1]))) for ld in e.loads),
            motor_force_limit=e.motor_force_limit,
        )


def load_scene(path: str | Path) -> Scene:
    """Read, validate and build the scene in ``path``."""
    p = str(path)
    try:
        with open(path, "rb") as fh:
            data = tomllib.load(fh)
    except FileNotFoundError:
        raise SceneError(f"{p}: no such file") from None
    except IsADirectoryError:
        raise SceneError(f"{p}: is a directory, not a scene file") from None
    except tomllib.TOMLDecodeError as e:
        raise SceneError(f"{p}: not valid TOML: {e}") from None
    return build_scene(parse_scene(data, p), p)


def _angle(spec: SceneSpec, v: float) -> float:
    return math.radians(v) if spec.angle_unit == "deg" else float(v)


def build_scene(spec: SceneSpec, path: str = "<scene>") -> Scene:
    """Build the mechanism a validated scene describes."""
    m = spec.mechanism
    rate = 2 * math.pi * spec.driver.speed
    phase = _angle(spec, spec.driver.phase)
    try:
        rock = _rocking(spec, m)
    except InputError as e:
        raise SceneError(f"{path}: {e}") from None
    try:
        mech = _build(spec, m, rate, phase, rock)
    except PlanarError as e:
        raise SceneError(f"{path}: mechanism: {e}") from None
    polygons: dict[str, tuple[str, np.ndarray]] = {}
    names = {p.name for p in mech.parts}
    for i, poly in enumerate(getattr(m, "polygons", [])):
        if poly.part not in names:
            raise SceneError(f"{path}: mechanism.polygons[{i}].part: no part {poly.part!r} "
                             f"(got {poly.part!r}; parts are {sorted(names)})")
        polygons[poly.name] = (poly.part, np.asarray(poly.points, float))
    for i, n in enumerate(spec.render.sweep):
        if n not in polygons:
            raise SceneError(f"{path}: render.sweep[{i}]: no polygon {n!r} (got {n!r}; polygons are {sorted(polygons)})")
    if spec.render.trails is not None:
        for i, n in enumerate(spec.render.trails):
            if n not in mech.points:
                raise SceneError(f"{path}: render.trails[{i}]: no named point {n!r} "
                                 f"(got {n!r}; points are {sorted(mech.points)})")
    for i, load in enumerate(spec.effects.loads):
        if load.point not in mech.points:
            raise SceneError(f"{path}: effects.loads[{i}].point: no named point {load.point!r} "
                             f"(got {load.point!r}; points are {sorted(mech.points)})")
    for i, s in enumerate(spec.effects.springs):
        for side in ("a", "b"):
            if getattr(s, side) not in names:
                raise SceneError(f"{path}: effects.springs[{i}].{side}: no part {getattr(s, side)!r} "
                                 f"(got {getattr(s, side)!r}; parts are {sorted(names)})")
    return Scene(spec, mech, path, polygons)


#: mechanism types whose driver can rock (``[driver] amplitude``)
_ROCKING = ("fourbar", "slidercrank", "linkage")


def _rocking(spec: SceneSpec, m: Any) -> dict[str, Any]:
    """Keyword arguments ``amplitude``/``centre`` for a rocking input (radians or model units), or none."""
    d = spec.driver
    if d.amplitude is None:
        return {}
    if m.type not in _ROCKING:
        raise InputError("driver.amplitude", d.amplitude,
                         f"no amplitude for a {m.type!r} mechanism (a rocking input is for {', '.join(_ROCKING)})")
    if isinstance(m, LinkageSpec):
        from .linkages import NODE_KINDS

        first = next((n for n in m.nodes if NODE_KINDS[n.kind].is_input), None)
        if first is not None and first.kind == "actuator":  # a translating input: model units
            return {"amplitude": float(d.amplitude), "centre": float(d.centre)}
    return {"amplitude": _angle(spec, d.amplitude), "centre": _angle(spec, d.centre)}


def _build(spec: SceneSpec, m: Any, rate: float, phase: float, rock: dict[str, Any]) -> Mechanism:
    from .catalog import get

    placement: tuple[float, float, float] = (0.0, 0.0, 0.0)
    if hasattr(m, "placement"):
        placement = (m.placement[0], m.placement[1], _angle(spec, m.placement[2]))
    if isinstance(m, FourBarSpec):
        from .linkages import FourBar

        return FourBar(m.ground, m.crank, m.coupler, m.rocker, coupler_point=m.coupler_point,
                       circuit=m.circuit, placement=placement, rate=rate, phase=phase,
                       name=spec.name or "fourbar", **rock)
    if isinstance(m, SliderCrankSpec):
        from .linkages import SliderCrank

        return SliderCrank(m.crank, m.rod, offset=m.offset, branch=m.branch, placement=placement,
                           rate=rate, phase=phase, name=spec.name or "slidercrank", **rock)
    if isinstance(m, LinkageSpec):
        from .linkages import NODE_KINDS, Link, Linkage

        nodes = []
        for n in m.nodes:
            cls = NODE_KINDS[n.kind]  # each node kind declares the scene keys it is built from
            args = [_angle(spec, getattr(n, f)) if f in cls.angle_fields else getattr(n, f)
                    for f in cls.scene_fields]
            nodes.append(cls(n.name, *args))  # type: ignore[call-arg]  # each kind's dataclass fields
        links = [Link(lk.name, tuple(lk.nodes), lk.guide) for lk in m.links]
        return Linkage(spec.name or "linkage", nodes, links, points=m.points, placement=placement,
                       rate=rate, phase=phase, **rock)
    if isinstance(m, ElementalSpec):
        from .windup import ELEMENTAL, ElementalMechanism, params_for

        base = params_for(m.number)
        angle_params = ELEMENTAL[m.number].angle_params
        kw: dict[str, Any] = {}
        for k, v in m.params.items():
            val = tuple(v) if isinstance(v, list) else v
            if k in angle_params:
                val = tuple(_angle(spec, x) for x in val) if isinstance(val, tuple) else _angle(spec, val)
            kw[k] = val
        return ElementalMechanism(m.number, base.replace(**kw), rate=rate, phase=phase)
    if isinstance(m, ChainSpec):
        from .windup.chain import chain_mechanism

        return chain_mechanism(m.chain, rate=rate, name=spec.name or " ".join(m.chain))
    if isinstance(m, ToySpec):
        from .windup.chain import ToyMechanism

        cams = {}
        if m.left:
            cams["left"] = [tuple(c) for c in m.left]
        if m.right:
            cams["right"] = [tuple(c) for c in m.right]
        return ToyMechanism(cams, phase=_angle(spec, m.phase), rate=rate, name=spec.name or "toy")
    mech = get(m.name)
    if rate != 2 * math.pi or phase:
        from dataclasses import replace

        mech.driver = replace(mech.driver, rate=rate, phase=phase)
    return mech
