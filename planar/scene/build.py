"""A validated scene built into its mechanism: :class:`Scene` and :func:`build_scene`."""

from __future__ import annotations

import math
import re
from collections.abc import Callable
from contextvars import ContextVar
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from planar.core.effects import Effects, Load, Spring
from planar.core.limits import check_coordinates, check_scale
from planar.core.model import Mechanism, Motion
from planar.core.registry import Registry
from planar.errors import InputError, PlanarError, SceneError
from planar.scene.schema import (
    MAX_G,
    CamSpec,
    CatalogSpec,
    ChainSpec,
    ElementalSpec,
    FourBarSpec,
    LegsSpec,
    LinkageSpec,
    SceneSpec,
    SliderCrankSpec,
    ToySpec,
)

__all__ = ["Scene", "build_scene"]


@dataclass
class Scene:
    """A validated scene and the mechanism it describes."""

    spec: SceneSpec
    mechanism: Mechanism
    path: str = "<scene>"
    polygons: dict[str, tuple[str, np.ndarray]] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if not isinstance(self.spec, SceneSpec):
            raise InputError("Scene.spec", self.spec, "a SceneSpec (planar.scene.parse_scene of a table)")
        if not isinstance(self.mechanism, Mechanism):
            raise InputError("Scene.mechanism", self.mechanism, "a Mechanism (build_scene makes one from the spec)")
        if not isinstance(self.path, str):
            raise InputError("Scene.path", self.path, "a string naming the scene in messages")
        if not isinstance(self.polygons, dict) or not all(
            isinstance(v, tuple) and len(v) == 2 and isinstance(v[0], str) for v in self.polygons.values()
        ):
            raise InputError("Scene.polygons", self.polygons, "a dict of name to (part, (M, 2) array)")

    def __repr__(self) -> str:
        return f"<Scene {self.spec.name!r} from {self.path}: {self.mechanism!r}>"

    def _repr_html_(self) -> str | None:
        from planar.core.display import html

        return html("scene", self)

    def sample_count(self) -> int:
        """Samples of :meth:`motion`, checked against :mod:`planar.core.limits` (samples and memory)
        before anything is allocated; :class:`~planar.errors.LimitError` names the scene's field."""
        from planar.core.limits import check_count, check_memory, units_within

        d = self.spec.driver
        period = self.mechanism.driver.period
        value: float | None
        if d.duration is not None:
            field_name, value, cycles = "driver.duration", d.duration, d.duration / period
        else:
            field_name, value = "driver.cycles", d.cycles
            cycles = d.cycles if d.cycles is not None else 1.0
            if d.cycles is None:  # one cycle: the per-cycle count is what asks
                field_name, value = "driver.samples_per_cycle", d.samples_per_cycle
        total = d.samples_per_cycle * cycles
        where = f"{self.path}: {field_name}"
        n = check_count(
            "samples",
            where,
            round(total) if math.isfinite(total) else total,
            "samples in all (samples_per_cycle x cycles)",
            shown=value,
        )
        # poses (x, y, angle) of every part, points (x, y), driver, time and the solver's working copies
        per_sample = 8 * (3 * len(self.mechanism.parts) + 2 * len(self.mechanism.points) + 4) * 4
        check_memory(where, value, float(per_sample) * max(n, 2), "a motion", fits=f"{units_within(0.0, per_sample):,} samples")
        return max(2, n)

    def times(self) -> NDArray[np.float64]:
        """The times (s) of :meth:`motion`'s samples, without solving it (checked as :meth:`sample_count`)."""
        step = self.mechanism.driver.period / self.spec.driver.samples_per_cycle
        return np.arange(self.sample_count(), dtype=np.float64) * step

    def motion(self) -> Motion:
        """The analytic motion over the scene's cycles (or duration)."""
        t = self.times()
        return self.mechanism.solve(self.mechanism.driver.value(t), t=t)

    @property
    def name(self) -> str:
        return self.spec.name or Path(self.path).stem

    def save(self, path: str | Path) -> None:
        """Write this scene as a TOML scene file that :func:`load_scene` reads back to the same motion.

        The keys the scene was given are written (defaults left out), angles
        as given with the scene's ``angle_unit``; atomic.  ``path`` must end in
        ``.toml`` and be in an existing folder.  A mechanism built in
        Python becomes a scene with :func:`planar.scene.load.scene_from_mechanism`.
        """
        from planar.fileio import check_output
        from planar.scene.write import write_scene

        if path is None:
            raise InputError("path", None, "a file name ending in .toml")
        check_output("path", path, (".toml",))  # TOML never goes into s.csv
        write_scene(self.spec, path)

    @property
    def effects(self) -> Effects:
        """The scene's ``[effects]`` as the model's plain record (what ``simulate`` takes)."""
        e = self.spec.effects
        return Effects(
            gravity=None if e.gravity is None else (float(e.gravity[0]), float(e.gravity[1])),
            damping=e.damping,
            density=e.density,
            springs=tuple(
                Spring(
                    s.a,
                    s.b,
                    s.stiffness,
                    (float(s.anchor_a[0]), float(s.anchor_a[1])),
                    (float(s.anchor_b[0]), float(s.anchor_b[1])),
                    s.rest_length,
                    s.damping,
                )
                for s in e.springs
            ),
            loads=tuple(Load(ld.point, (float(ld.force[0]), float(ld.force[1]))) for ld in e.loads),
            motor_force_limit=e.motor_force_limit,
            motor=e.motor,
        )


#: while a scene builds: each angle converted to radians -> the value as the file gives it (for messages)
_SHOWN: ContextVar[dict[float, Any] | None] = ContextVar("planar_scene_angles", default=None)


def _angle(spec: SceneSpec, v: float, field: str = "") -> float:
    """``v`` (the scene's angle unit) in radians; ``field`` named: refused first if float64 cannot resolve it."""
    if field:
        _check_scene_angle(spec, field, v)
    r = math.radians(v) if spec.angle_unit == "deg" else float(v)
    shown = _SHOWN.get()
    if shown is not None and spec.angle_unit == "deg":
        shown[r] = v
    return r


def _check_scene_angle(spec: SceneSpec, field: str, v: float) -> None:
    """:class:`InputError` if the angle ``v`` (the scene's unit) reaches beyond :data:`~planar.core.limits.MAX_ANGLE`
    rad; the value as written and the bound in the scene's unit (a NaN or a non-number is the model's to refuse)."""
    from planar.core.limits import MAX_ANGLE, RESOLUTION

    deg = spec.angle_unit == "deg"
    try:
        x = float(v)
    except (TypeError, ValueError):
        return
    bound = math.degrees(MAX_ANGLE) if deg else MAX_ANGLE
    if math.isfinite(x) and abs(x) > bound:
        fine = math.degrees(RESOLUTION) if deg else RESOLUTION
        raise InputError(
            field,
            v,
            f"an angle of at most {bound:.4g} {spec.angle_unit} (about {MAX_ANGLE / (2 * math.pi):.0f} turns): "
            f"beyond, float64 resolves an angle coarser than {fine:.2g} {spec.angle_unit}",
        )


def _as_written(e: PlanarError) -> PlanarError:
    """``e`` showing an angle it names as the scene file gives it (degrees), not as converted to radians."""
    shown = _SHOWN.get() or {}
    if isinstance(e, InputError) and isinstance(e.value, float) and not isinstance(e.value, bool) and e.value in shown:
        return type(e)(e.field, shown[e.value], e.expected)
    return e


def _build_mechanism(spec: SceneSpec, m: Any, path: str, rate: float) -> Mechanism:
    """The scene's mechanism; an error names the file, and an angle as the file gives it."""
    token = _SHOWN.set({})
    try:
        try:
            phase = _angle(spec, spec.driver.phase, "driver.phase")
            rock = _rocking(spec, m)
            _link_width(spec.fabrication, m.type)
        except InputError as e:
            raise SceneError(f"{path}: {_as_written(e)}") from None
        try:
            with np.errstate(all="ignore"):
                return _build(spec, m, rate, phase, rock)
        except PlanarError as e:
            raise SceneError(f"{path}: mechanism: {_as_written(e)}") from None
        except (ValueError, ArithmeticError) as e:  # numbers past what a builder's arithmetic holds (NaN, overflow)
            raise SceneError(
                f"{path}: mechanism: cannot be built from these numbers "
                f"({type(e).__name__}: {' '.join(str(e).split())}); check for extreme values"
            ) from None
    finally:
        _SHOWN.reset(token)


def build_scene(spec: SceneSpec, path: str = "<scene>") -> Scene:
    """Build the mechanism a validated scene describes."""
    if not isinstance(spec, SceneSpec):
        raise InputError("spec", spec, "a SceneSpec (planar.scene.parse_scene of a table)")
    if not isinstance(path, str):
        raise InputError("path", path, "a string naming the scene in messages")
    m = spec.mechanism
    rate = 2 * math.pi * spec.driver.speed
    if not (math.isfinite(rate) and math.isfinite(2 * math.pi / rate) and rate > 0):
        raise SceneError(
            f"{path}: driver.speed = {spec.driver.speed!r}: expected a speed whose period "
            "(1 / speed seconds) and angular rate are finite numbers"
        )
    _check_gravity(spec, path)
    mech = _build_mechanism(spec, m, path, rate)
    try:
        check_scale(path, mech)  # numbers float64 holds faithfully (not a placement at 1e16 or a size of 1e-200)
        _check_extents(spec, mech, path)
    except InputError as e:
        raise SceneError(str(e)) from None
    polygons: dict[str, tuple[str, np.ndarray]] = {}
    names = {p.name for p in mech.parts}
    for i, poly in enumerate(getattr(m, "polygons", [])):
        if poly.name in polygons:
            raise SceneError(
                f"{path}: mechanism.polygons[{i}].name: a second polygon named {poly.name!r} (polygon names must differ)"
            )
        if poly.part not in names:
            raise SceneError(
                f"{path}: mechanism.polygons[{i}].part: no part {poly.part!r} (got {poly.part!r}; parts are {sorted(names)})"
            )
        polygons[poly.name] = (poly.part, np.asarray(poly.points, float))
    for i, n in enumerate(spec.render.sweep):
        if n not in polygons:
            raise SceneError(f"{path}: render.sweep[{i}]: no polygon {n!r} (got {n!r}; polygons are {sorted(polygons)})")
    if spec.render.trails is not None:
        for i, n in enumerate(spec.render.trails):
            if n not in mech.points:
                raise SceneError(
                    f"{path}: render.trails[{i}]: no named point {n!r} (got {n!r}; points are {sorted(mech.points)})"
                )
    for i, load in enumerate(spec.effects.loads):
        if load.point not in mech.points:
            raise SceneError(
                f"{path}: effects.loads[{i}].point: no named point {load.point!r} "
                f"(got {load.point!r}; points are {sorted(mech.points)})"
            )
    for i, s in enumerate(spec.effects.springs):
        for side in ("a", "b"):
            if getattr(s, side) not in names:
                raise SceneError(
                    f"{path}: effects.springs[{i}].{side}: no part {getattr(s, side)!r} "
                    f"(got {getattr(s, side)!r}; parts are {sorted(names)})"
                )
    return Scene(spec, mech, path, polygons)


#: standard gravity, mm/s^2
STANDARD_GRAVITY_MM = 9806.65


def _check_gravity(spec: SceneSpec, path: str) -> None:
    """:class:`SceneError` if ``[effects] gravity`` is beyond :data:`~planar.scene.schema.MAX_G` standard
    gravities (model units per s^2 converted with ``unit_mm``): ``[1e300, 0]`` is refused, not simulated."""
    g = spec.effects.gravity
    if g is None:
        return
    u = spec.fabrication.unit_mm
    most = MAX_G * STANDARD_GRAVITY_MM / u  # model units / s^2
    if not math.hypot(*g) <= most:
        raise SceneError(
            f"{path}: effects.gravity = {list(g)!r}: expected a gravity of at most {MAX_G:g} g, {most:.4g} model "
            f"units/s^2 at unit_mm = {u:g} (one g is {STANDARD_GRAVITY_MM / u:.4g})"
        )


def _check_extents(spec: SceneSpec, mech: Mechanism, path: str) -> None:
    """:class:`InputError` for a standoff or a polygon vertex float64 cannot place faithfully (the rule
    :func:`~planar.core.limits.check_scale` applies to the placement)."""
    m = spec.mechanism
    for i, xy in enumerate(getattr(m, "standoffs", None) or ()):
        check_coordinates(f"{path}: mechanism.standoffs[{i}]", xy, mech, list(xy))
    for i, poly in enumerate(getattr(m, "polygons", ())):
        which = f".{poly.name}" if re.fullmatch(r"[A-Za-z0-9_\-]+", poly.name) else f"[{i}]"  # as the schema's errors
        check_coordinates(f"{path}: mechanism.polygons{which}.points", poly.points, mech, [list(p) for p in poly.points])


#: mechanism types whose driver can rock (``[driver] amplitude``)
_ROCKING = ("fourbar", "slidercrank", "linkage")


def _rocking(spec: SceneSpec, m: Any) -> dict[str, Any]:
    """Keyword arguments ``amplitude``/``centre`` for a rocking input (radians or model units), or none."""
    d = spec.driver
    if d.amplitude is None:
        return {}
    if m.type not in _ROCKING:
        raise InputError(
            "driver.amplitude",
            d.amplitude,
            f"no amplitude for a {m.type!r} mechanism (a rocking input is for {', '.join(_ROCKING)})",
        )
    if isinstance(m, LinkageSpec):
        from planar.linkages import NODE_KINDS

        first = next((n for n in m.nodes if NODE_KINDS[n.kind].is_input), None)
        if first is not None and first.kind == "actuator":  # a translating input: model units
            return {"amplitude": float(d.amplitude), "centre": float(d.centre)}
    return {"amplitude": _angle(spec, d.amplitude, "driver.amplitude"), "centre": _angle(spec, d.centre, "driver.centre")}


@dataclass(frozen=True)
class _Build:
    """What every mechanism table's builder reads besides its own table: the driver's rate (rad/s) and
    phase (rad), the rocking driver's amplitude and centre (empty for a turning one), the placement."""

    rate: float
    phase: float
    rock: dict[str, Any]
    placement: tuple[float, float, float]


#: the builder of each scene mechanism table, keyed by its spec class (``type = "..."`` in the file)
BUILDERS: Registry[Callable[[SceneSpec, Any, _Build], Mechanism]] = Registry("scene build", "mechanism table")


def _build(spec: SceneSpec, m: Any, rate: float, phase: float, rock: dict[str, Any]) -> Mechanism:
    placement: tuple[float, float, float] = (0.0, 0.0, 0.0)
    if hasattr(m, "placement"):
        placement = (m.placement[0], m.placement[1], _angle(spec, m.placement[2], "placement[2]"))
    return BUILDERS.get(m, f"mechanism type {getattr(m, 'type', '?')!r}")(spec, m, _Build(rate, phase, rock, placement))


@BUILDERS.register(FourBarSpec)
def _build_fourbar(spec: SceneSpec, m: FourBarSpec, b: _Build) -> Mechanism:
    from planar.linkages import FourBar

    return FourBar(
        m.ground,
        m.crank,
        m.coupler,
        m.rocker,
        coupler_point=m.coupler_point,
        circuit=m.circuit,
        placement=b.placement,
        rate=b.rate,
        phase=b.phase,
        name=spec.name or "fourbar",
        **b.rock,
    )


@BUILDERS.register(SliderCrankSpec)
def _build_slidercrank(spec: SceneSpec, m: SliderCrankSpec, b: _Build) -> Mechanism:
    from planar.linkages import SliderCrank

    return SliderCrank(
        m.crank,
        m.rod,
        offset=m.offset,
        branch=m.branch,
        placement=b.placement,
        rate=b.rate,
        phase=b.phase,
        name=spec.name or "slidercrank",
        **b.rock,
    )


def _nodes_and_links(spec: SceneSpec, m: LinkageSpec | LegsSpec) -> tuple[list[Any], list[Any]]:
    """A linkage or leg table's node kinds and links, built from their scene keys (angles in radians, each
    named ``nodes.NAME.FIELD`` where float64 cannot resolve it)."""
    from planar.linkages import NODE_KINDS, Link

    nodes = []
    for n in m.nodes:
        cls = NODE_KINDS[n.kind]  # each node kind declares the scene keys it is built from
        args = [
            _angle(spec, getattr(n, f), f"nodes.{n.name}.{f}")
            if f in cls.angle_fields and getattr(n, f) is not None
            else getattr(n, f)
            for f in cls.scene_fields
        ]
        nodes.append(cls(n.name, *args))  # type: ignore[call-arg]  # each kind's dataclass fields
    return nodes, [Link(lk.name, tuple(lk.nodes), lk.guide) for lk in m.links]


@BUILDERS.register(LinkageSpec)
def _build_linkage(spec: SceneSpec, m: LinkageSpec, b: _Build) -> Mechanism:
    from planar.linkages import Linkage

    nodes, links = _nodes_and_links(spec, m)
    return Linkage(
        spec.name or "linkage",
        nodes,
        links,
        points=m.points,
        placement=b.placement,
        rate=b.rate,
        phase=b.phase,
        width=_link_width(spec.fabrication, m.type),
        **b.rock,
    )


@BUILDERS.register(LegsSpec)
def _build_legs(spec: SceneSpec, m: LegsSpec, b: _Build) -> Mechanism:
    from planar.linkages.legs import Legs

    nodes, links = _nodes_and_links(spec, m)
    phases = None if m.phases is None else [_angle(spec, v, f"phases[{i}]") for i, v in enumerate(m.phases)]
    return Legs(
        spec.name or "legs",
        nodes,
        links,
        m.count,
        phases,
        mirror=m.mirror,
        points=m.points,
        standoffs=[tuple(p) for p in m.standoffs or ()],
        rate=b.rate,
        phase=b.phase,
    )


def _link_width(fab: Any, kind: str) -> float | None:
    """``[fabrication] link_width_mm`` in model units (``None``: the linkage's default, 8 % of its span); a width
    under a pin hole with ``min_wall_mm`` each side, or one given in a scene other than ``linkage``, is an error
    naming the field."""
    w = fab.link_width_mm
    if w is None:
        return None
    if kind != "linkage":
        raise InputError(
            "fabrication.link_width_mm",
            w,
            f"no link_width_mm in a {kind} scene (it sets a linkage scene's links; a cam scene's is [mechanism] link_width)",
        )
    least = fab.pin_diameter_mm + fab.clearance_mm + 2 * fab.min_wall_mm
    if w < least - 1e-9:
        raise InputError(
            "fabrication.link_width_mm",
            w,
            f"at least {least:g} mm: a pin hole of pin_diameter_mm + clearance_mm = "
            f"{fab.pin_diameter_mm + fab.clearance_mm:g} mm with min_wall_mm {fab.min_wall_mm:g} each side",
        )
    return float(w) / fab.unit_mm


def _scene_angles(spec: SceneSpec, kw: dict[str, Any], angle_params: tuple[str, ...], where: str = "params") -> dict[str, Any]:
    """``kw`` with the parameters a scene gives in its angle unit turned to radians (a number or a vector)."""
    out = dict(kw)
    for k in angle_params:
        if k in out:
            val = out[k]
            if isinstance(val, tuple):
                out[k] = tuple(_angle(spec, x, f"{where}.{k}[{j}]") for j, x in enumerate(val))
            else:
                out[k] = _angle(spec, val, f"{where}.{k}")
    return out


@BUILDERS.register(ElementalSpec)
def _build_elemental(spec: SceneSpec, m: ElementalSpec, b: _Build) -> Mechanism:
    from planar.windup import ELEMENTAL, ElementalMechanism, params_for
    from planar.windup.params import coerce

    base = params_for(m.number)
    kw: dict[str, Any] = {}
    known = sorted(f for f in vars(base))
    for k, v in m.params.items():
        if k not in known:
            raise InputError(f"params.{k}", v, f"a parameter of mechanism #{m.number}, one of {known}")
        kw[k] = coerce(f"params.{k}", getattr(base, k), v)  # a vector of the right length, or a number
    kw = _scene_angles(spec, kw, ELEMENTAL[m.number].angle_params)
    try:
        return ElementalMechanism(m.number, base.replace(**kw), rate=b.rate, phase=b.phase)
    except InputError as e:  # check_params names "#5.F_o": the scene's key is params.F_o
        if e.field.startswith(f"#{m.number}.") and e.field[len(f"#{m.number}.") :] != "params":
            raise InputError("params." + e.field[len(f"#{m.number}.") :], e.value, e.expected) from None
        raise


@BUILDERS.register(ChainSpec)
def _build_chain(spec: SceneSpec, m: ChainSpec, b: _Build) -> Mechanism:
    from planar.windup.chain import chain_mechanism

    return chain_mechanism(m.chain, rate=b.rate, name=spec.name or " ".join(m.chain))


@BUILDERS.register(ToySpec)
def _build_toy(spec: SceneSpec, m: ToySpec, b: _Build) -> Mechanism:
    from planar.windup import ELEMENTAL
    from planar.windup.chain import ToyMechanism
    from planar.windup.table import realise

    cams = {}
    if m.left:
        cams["left"] = [tuple(c) for c in m.left]
    if m.right:
        cams["right"] = [tuple(c) for c in m.right]
    overrides: dict[Any, dict[str, Any]] = {}
    names: dict[tuple[str, tuple[str, ...]], str] = {}
    for i, sg in enumerate(m.stages):
        key = (sg.cam, tuple(sg.chain))
        if not any(tuple(c[: len(key[1])]) == key[1] for c in cams.get(sg.cam, [])):
            raise InputError(f"mechanism.stages[{i}].chain", sg.chain, f"a prefix of a chain on the {sg.cam} cam")
        kw = {k: tuple(v) if isinstance(v, list) else v for k, v in sg.params.items()}
        kw = _scene_angles(spec, kw, ELEMENTAL[realise(sg.chain[-1]).number].angle_params, f"stages[{i}].params")
        if kw:
            overrides[key] = kw
        if sg.name is not None:
            names[key] = sg.name
    phase = _angle(spec, m.phase, "phase")
    return ToyMechanism(cams, phase=phase, rate=b.rate, name=spec.name or "toy", overrides=overrides, names=names)


@BUILDERS.register(CamSpec)
def _build_cam_table(spec: SceneSpec, m: CamSpec, b: _Build) -> Mechanism:
    return _build_cam(spec, m, b.rate, b.phase)


@BUILDERS.register(CatalogSpec)
def _build_catalog(spec: SceneSpec, m: CatalogSpec, b: _Build) -> Mechanism:
    from planar.scene.catalog import get

    try:
        mech = get(m.name)
    except InputError as e:
        raise InputError("name", m.name, e.expected) from None
    if b.rate != 2 * math.pi or b.phase:
        from dataclasses import replace

        mech.driver = replace(mech.driver, rate=b.rate, phase=b.phase)
    return mech


def _build_cam(spec: SceneSpec, m: CamSpec, rate: float, phase: float) -> Mechanism:
    """A :class:`planar.cams.CamMechanism` from a ``type = "cam"`` mechanism table."""
    from planar.cams import CamMechanism, CamProfile, FollowerGeometry, Program, Segment
    from planar.linkages import NODE_KINDS, Link

    f = m.follower
    osc = f.motion == "oscillating"
    segments = []
    for i, sg in enumerate(m.segments):
        try:
            segments.append(
                Segment(
                    sg.law,
                    _angle(spec, sg.angle, f"segments[{i}].angle"),
                    _angle(spec, sg.lift, f"segments[{i}].lift") if osc else float(sg.lift),
                )
            )
        except InputError as e:  # the segment's own check, named by its place in the file
            raise InputError(f"mechanism.segments[{i}].{e.field.rpartition('.')[2]}", e.value, e.expected) from None
    program = Program(
        segments,
        "mechanism.segments",
        lift_unit="deg" if osc and spec.angle_unit == "deg" else "",
    )
    geom = FollowerGeometry(
        f.kind,
        f.motion,
        float(f.roller_radius or 0.0),
        (float(f.axis[0]), float(f.axis[1])),
        float(f.offset),
        (0.0, 0.0) if f.pivot is None else (float(f.pivot[0]), float(f.pivot[1])),
        float(f.arm or 0.0),
        float(f.face_offset),
        int(f.branch),
    )
    profile = CamProfile(program, float(m.base_radius), geom, "mechanism")
    limit = (
        math.radians(45.0 if osc else 30.0)
        if m.max_pressure_angle is None
        else _angle(spec, m.max_pressure_angle, "max_pressure_angle")
    )
    nodes = []
    for n in m.nodes:
        cls = NODE_KINDS[n.kind]
        args = [
            _angle(spec, getattr(n, k), f"nodes.{n.name}.{k}") if k in cls.angle_fields else getattr(n, k)
            for k in cls.scene_fields
        ]
        nodes.append(cls(n.name, *args))  # type: ignore[call-arg]  # each kind's dataclass fields
    links = [Link(lk.name, tuple(lk.nodes), lk.guide) for lk in m.links]
    return CamMechanism(
        spec.name or "cam",
        profile,
        nodes,
        links,
        points=m.points or None,
        rate=rate,
        phase=phase,
        max_pressure_angle=limit,
        unit=spec.angle_unit,
        width=m.link_width,
    )
