"""Everything cut for a scene, decided: parts checked, lettered, layered, tabbed and nested (no file written).

:func:`build` turns a scene into a :class:`Fabrication`; :mod:`planar.app.export` writes it.
"""

from __future__ import annotations

import copy
import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from planar.core.model import Mechanism
from planar.errors import InputError
from planar.fabrication.check import spacer_radius
from planar.fabrication.hardware import below_mm, shaft_check
from planar.fabrication.joints import FabricationError, joint_pins, pin_features
from planar.fabrication.layers import Assembly, letter, pin_stacks, plan_assembly
from planar.fabrication.nesting import nest
from planar.fabrication.parts import FabSettings, nominal_material, part_cuts
from planar.fabrication.sheet import Circle, Layout, PartCut

__all__ = ["Fabrication", "build", "kerf_test_layout", "sheet_paths", "summary"]


@dataclass
class Fabrication:
    name: str
    settings: FabSettings
    layout: Layout
    assembly: Assembly
    notes: list[str] = field(default_factory=list)
    #: the pin that is the motor shaft (joint name), if any
    shaft: str | None = None
    #: each part's material (outline minus cuts, mm) in its own frame
    own: dict[str, Any] = field(default_factory=dict)
    #: the ground plates (with mounting holes)
    grounds: list[str] = field(default_factory=list)
    #: files written by :func:`write_outputs`
    written: list[Path] = field(default_factory=list)
    #: tab-and-slot joints of pieces standing perpendicular to the xy stack (:mod:`planar.fabrication.tabs`)
    joins: list[Any] = field(default_factory=list)
    #: where the xy stack's lower face lies along the model's z (mm), for the pieces standing perpendicular
    stack_z: float = 0.0
    #: each perpendicular piece's plane position (mm: world y for xz, x for yz)
    planes: dict[str, float] = field(default_factory=dict)
    #: motions the cut parts will not make (a toy's cam throw or effector stroke under a few times the fit's
    #: play: :func:`planar.toys.fitcheck.small_motions`), one line each
    warnings: list[str] = field(default_factory=list)
    #: the mechanism as cut (a toy's assembly, perpendicular pieces bracketed): its motion is what the build check moves
    mechanism: Any = None
    #: what the build check found (:func:`planar.fabrication.check.build_check`); empty: it goes together and moves
    violations: list[Any] = field(default_factory=list)
    #: each ground plate's mounting hole centres (mm, the part's own frame)
    mounts: dict[str, list[tuple[float, float]]] = field(default_factory=dict)
    #: how far the motor and the pins' lower ends hang below the bottom layer (mm): the standoffs clear it
    below_mm: float = 0.0
    #: when the build check failed: the smallest ``unit_mm`` found at which the same scene builds
    #: (a :class:`planar.fabrication.scale.ScaleHint`; ``unit_mm`` None: none up to the sheet's size), filled by
    #: ``planar export`` and :func:`planar.export`
    unit_hint: Any = None


def _shaft_pin(mech: Mechanism, pins) -> Any:
    drv = mech.driver
    if drv.kind != "rotation":
        return None
    ground = {p.name for p in mech.parts if p.ground}
    for pin in pins:
        if drv.part in pin.parts and (set(pin.parts) - {drv.part}) <= ground and pin.kinds == ("hole", "hole"):
            return pin
    return None


def _with_riders(scene: Any, mech: Any, s: FabSettings) -> Any:
    """``mech`` with the scene's ``cut = "part"`` polygons as parts pinned to their hosts
    (:mod:`planar.fabrication.riders`); the pins' room is the host's material as cut without them."""
    from planar.fabrication.riders import rider_polygons, with_riders

    if not rider_polygons(scene, mech):
        return mech
    keyed: dict[str, float] = dict(getattr(mech, "keyed", {}))
    pins, _ = joint_pins(mech)
    pinned = pin_features(mech)
    shaft = _shaft_pin(mech, pins)

    def material(name: str) -> Any:
        part = mech.part(name)
        drive_at, motor_at, flat = _shaft_holes(name, shaft, mech.driver.part, keyed)
        pc = part_cuts(
            part,
            s,
            1,
            {i for (pn, i) in pinned if pn == name},
            drive_at,
            motor_at,
            mounting=_mounted(mech, part, shaft),
            drive_flat=flat,
        )
        return nominal_material(pc.outer, pc.inner)

    return with_riders(scene, mech, material, s)


def _fab_mechanism(mech: Mechanism) -> Any:
    """The mechanism whose parts are cut: a wind-up toy is cut as its assembly (merged parts, one frame,
    cams keyed to the shaft; :mod:`planar.toys.assembly`), anything else as it is; pieces standing
    perpendicular to the xy stack get brackets and lose repeated guides (:func:`planar.fabrication.tabs.fab_view`)."""
    from planar.fabrication.tabs import fab_view
    from planar.windup.chain import ToyMechanism

    if isinstance(mech, ToyMechanism):
        from planar.toys.assembly import toy_assembly

        return fab_view(toy_assembly(mech))
    built = getattr(mech, "as_built", None)  # a kind built from other parts than it moves as (a walker's webs)
    return fab_view(built() if built is not None else mech)


def _phase_mark(pc: PartCut, at: tuple[float, float], flat: float, phase: float, turn: float = 0.0) -> None:
    """Engrave a keyed cam's key angle: a tick from its shaft hole along the D's flat and the angle in degrees
    (``phase``, rad: the cam's phase plus ``turn``, its root stage's own turn; the note names both)."""
    import numpy as np

    from planar.fabrication.strokefont import text_strokes

    c, s = math.cos(flat), math.sin(flat)
    pc.engrave.append(np.array([(at[0] + 2.5 * c, at[1] + 2.5 * s), (at[0] + 5.0 * c, at[1] + 5.0 * s)]))
    deg = f"{math.degrees(phase) % 360:.0f}"
    pc.engrave.extend(text_strokes(deg, 1.5, (at[0] - 3.5 * c, at[1] - 3.5 * s), flat - math.pi / 2))
    own = f"{math.degrees(turn) % 360:.0f}"
    cam = f"{math.degrees(phase - turn) % 360:.0f}"
    why = f" = cam phase {cam} + the stage's own turn {own}" if own != "0" else ""
    pc.notes.append(f"{pc.name}: keyed to the motor shaft at {deg} degrees{why} (engraved tick along the D's flat)")


def _mounted(mech: Any, part: Any, shaft: Any) -> bool:
    """Whether ground plate ``part`` gets mounting holes (it stands on the standoffs): every ground plate cut flat,
    but where one of them holds the motor only that one (a walker's other frame plates sit higher in the stack,
    held by its standoff rods)."""
    if not (part.ground and part.plane == "xy"):
        return False
    if shaft is None or part.name in shaft.parts:
        return True
    return not any(mech.part(p).ground for p in shaft.parts)


def _shaft_holes(
    name: str, shaft: Any, driven: str, keyed: dict[str, float]
) -> tuple[tuple[float, float] | None, tuple[float, float] | None, float]:
    """Where part ``name`` takes the motor shaft: ``(D hole, motor hole, the D's flat direction rad)``, own frame.

    The driven part has the D hole, the ground the motor's hole; a toy's cam keyed to the shaft has a D at its
    origin turned by its phase.
    """
    drive_at = motor_at = None
    if shaft is not None and name in shaft.parts:
        k = shaft.parts.index(name)
        if name == driven:
            drive_at = shaft.at[k]
        else:
            motor_at = shaft.at[k]
    flat = math.pi / 2
    if shaft is not None and name in keyed:  # a toy's cam: a D on the shaft, turned by its phase
        drive_at, flat = (0.0, 0.0), math.pi / 2 - keyed[name]
    return drive_at, motor_at, flat


def _cut_polygons(scene: Any, mech: Mechanism, s: FabSettings) -> dict[str, list[Any]]:
    """The scene's polygons marked ``cut = true``, by part: shapely polygons in mm, the part's own frame."""
    from shapely.geometry import Polygon

    names = {p.name for p in mech.parts}
    out: dict[str, list[Any]] = {}
    for i, poly in enumerate(getattr(getattr(scene.spec, "mechanism", None), "polygons", []) or []):
        if getattr(poly, "cut", False) is not True:
            continue  # drawn only, or cut as a part of its own (planar.fabrication.riders)
        if poly.part not in names:
            raise InputError(f"mechanism.polygons[{i}].part", poly.part, "a part that is cut (" + ", ".join(sorted(names)) + ")")
        out.setdefault(poly.part, []).append(Polygon([(x * s.unit_mm, y * s.unit_mm) for x, y in poly.points]).buffer(0))
    return out


def _merged_outline(outer: Any, polys: list[Any], s: FabSettings) -> Any:
    """The part's outline with its cut polygons merged in (grown by the kerf like the outline; a polygon apart
    from the part is joined to it by their convex hull), as a contour of straight segments (mm)."""
    import shapely

    from planar.fabrication.sheet import Contour, cut_polygon

    shape = cut_polygon(outer, math.radians(2.0))
    for p in polys:
        grown = p.buffer(s.kerf / 2, join_style="mitre")
        joined = shape.union(grown)
        shape = joined if joined.geom_type == "Polygon" else shapely.convex_hull(shape.union(grown))
    ring = shapely.geometry.polygon.orient(shape, 1.0).exterior.coords[:-1]
    return Contour([(float(x), float(y), 0.0) for x, y in ring])


def _drive_notes(mech: Mechanism, shaft: Any) -> list[str]:
    """Why there is no motor shaft hole, when there is none."""
    if mech.driver.kind != "rotation":
        return [f"driver {mech.driver.part!r} is a {mech.driver.kind} drive: no motor shaft hole"]
    if shaft is None:
        return [f"driver {mech.driver.part!r}: no pin to the ground on its axis, no motor shaft hole"]
    return []


def _unplannable_tabs(layers: dict[str, int | None], used: dict[str, int | None]) -> None:
    """Raise the error of tab joints whose rounds did not settle: a part whose layer keeps changing, or
    perpendicular pieces still in other layers' way."""
    from planar.fabrication.joints import FabricationError

    moved = [n for n in layers if layers[n] != used.get(n)]
    raise FabricationError(
        f"part {moved[0]!r}: its layer keeps changing as the tab joints are cut; they cannot be planned"
        if moved
        else "the pieces standing perpendicular are still in the way of other layers after 4 "
        "rounds of travel slots; they cannot be tab-joined"
    )


def _hole_letters(
    mech: Mechanism, pins: list[Any], shaft: Any, keyed: dict[str, float] | None = None
) -> dict[str, list[tuple[tuple[float, float], str]]]:
    """Each part's hole letters: ``(hole centre, letter)``, a pin's letter once beside each hole it goes through.

    The motor shaft's holes (the driven part's D, the plate's clearance hole) carry the shaft's letter too, as
    does every cam keyed to the shaft (``keyed``: a toy's cams, their D at their origin), so a maker finds where
    the shaft goes; the BOM's and plan's motor shaft row has the same letter.
    """
    letters: dict[str, list[tuple[tuple[float, float], str]]] = {p.name: [] for p in mech.parts}
    for k, stack in enumerate(pin_stacks(pins)):
        marked: set[tuple[str, tuple[float, float]]] = set()
        for i in stack:
            pin = pins[i]
            for side in (0, 1):
                key = (pin.parts[side], pin.at[side])
                if pin.kinds[side] == "hole" and key not in marked:
                    marked.add(key)
                    letters[pin.parts[side]].append((pin.at[side], letter(k)))
            if pin is shaft:
                for name in keyed or {}:
                    if name in letters and (name, (0.0, 0.0)) not in marked and name not in pin.parts:
                        marked.add((name, (0.0, 0.0)))
                        letters[name].append(((0.0, 0.0), letter(k)))
    return letters


def _spacer_cuts(asm: Assembly, s: FabSettings) -> list[PartCut]:
    """The spacer rings of every pin, cut from the same sheet (``spacer B1``, ``spacer B2``, ...)."""
    from planar.fabrication.check import spacer_radius

    k2 = s.kerf / 2
    ri = (s.pin_mm + s.clearance) / 2
    ro = spacer_radius(s)
    return [
        PartCut(
            f"spacer {pp.letter}{j + 1}",
            Circle((0.0, 0.0), ro + k2),
            [Circle((0.0, 0.0), ri - k2)],
            nominal_holes=[((0.0, 0.0), ri)],
        )
        for pp in asm.pins
        for j in range(pp.spacers)
    ]


def _tab_notes(cuts: list[PartCut], joins: list[Any], s: FabSettings) -> list[str]:
    """Each tabbed piece's and each slotted base's note (added to its part's notes too)."""
    out: list[str] = []
    tabs = {jn.piece: jn for jn in joins}
    for pc in cuts:
        if pc.name in tabs:
            jn = tabs[pc.name]
            pc.notes.append(
                f"{pc.name}: {len(jn.spans)} tab(s) {jn.letter}, {jn.tab_width:g} x "
                f"{s.thickness_mm:g} mm, into the slots {jn.letter} of {jn.base}"
            )
            out.append(pc.notes[-1])
        for jn in joins:
            if jn.base == pc.name:
                pc.notes.append(
                    f"{pc.name}: {len(jn.slots)} slot(s) {jn.letter} "
                    f"{jn.slot_size[0]:g} x {jn.slot_size[1]:g} mm for the tabs of {jn.piece}"
                )
                out.append(pc.notes[-1])
    return out


def build(scene: Any, settings: FabSettings, samples: tuple[int, int] = (120, 240)) -> Fabrication:
    """Cut-ready, checked, layered and nested parts of ``scene`` (raises FabricationError/InputError).

    An error in a ``[fabrication]`` value or a ``mechanism.`` key read from a scene file starts with the file's
    path as given (``toys/bird.toml: fabrication.pin_diameter_mm = 3.5: ...``), as every scene error does.
    ``samples``: samples per cycle of the planner's build checks and of the final one (the verdict in
    ``violations``; :func:`planar.fabrication.plan.settle`).
    """
    where = getattr(scene, "path", None)
    in_file = bool(where) and Path(str(where)).is_file()
    try:
        return _build(scene, settings, samples)
    except InputError as e:
        if not (e.field.startswith("fabrication.") and in_file):
            raise
        raise InputError(f"{where}: {e.field}", e.value, e.expected) from e  # the path as the user gave it
    except FabricationError as e:
        if not (str(e).startswith("mechanism.") and in_file):
            raise
        raise FabricationError(f"{where}: {e}") from e


#: the kerfs a cut accepts, in words (see :func:`kerf_ok`)
KERF_RANGE = "a kerf of 0, or from 0.001 to 2 mm"


def kerf_ok(kerf: float) -> bool:
    """Whether ``kerf`` (mm) can be cut: 0 (no compensation) or 0.001 to 2 mm (an offset below a micrometre
    collapses the outlines' offset geometry, and no laser cuts that fine)."""
    return kerf == 0 or 1e-3 <= kerf <= 2


def _build(scene: Any, settings: FabSettings, samples: tuple[int, int] = (120, 240)) -> Fabrication:
    """:func:`build` without the file name on its errors."""
    s = settings
    if not kerf_ok(s.kerf):
        raise InputError("kerf", s.kerf, KERF_RANGE)
    from planar.fabrication.tabs import merge_travel, plan_tabs, slot_features, travel_slots

    mech = _with_riders(scene, _fab_mechanism(scene.mechanism), s)
    keyed: dict[str, float] = dict(getattr(mech, "keyed", {}))
    pins, contacts = joint_pins(mech)
    pinned = pin_features(mech)
    shaft = _shaft_pin(mech, pins)
    notes: list[str] = list(getattr(mech, "design_notes", ()))  # what a mechanism reports of its own design
    notes += list(mech.notes)
    notes += _drive_notes(mech, shaft)
    letters = _hole_letters(mech, pins, shaft, keyed)
    merged = _cut_polygons(scene, mech, s)

    cut_cache: dict[Any, PartCut] = {}

    def cut_all(joins: list[Any], travel: dict[str, list[Any]]) -> tuple[list[PartCut], list[str]]:
        slots = slot_features(joins)
        for k_, v_ in travel.items():
            slots[k_] = slots.get(k_, []) + v_
        tab_of = {jn.piece: jn for jn in joins}
        cuts: list[PartCut] = []
        part_notes: list[str] = []
        for n, part in enumerate(mech.parts, start=1):
            drive_at, motor_at, flat = _shaft_holes(part.name, shaft, mech.driver.part, keyed)
            extra = tuple(slots.get(part.name, ()))
            tab = tab_of.get(part.name)
            key = (part.name, extra, None if tab is None else (tab.letter, tab.edge, tuple(tab.spans)))
            if key not in cut_cache:  # a part that no tab, slot or travel slot changed is cut once
                cut_cache[key] = part_cuts(
                    part,
                    s,
                    n,
                    {i for (pn, i) in pinned if pn == part.name},
                    drive_at,
                    motor_at,
                    mounting=_mounted(mech, part, shaft),
                    letters=letters[part.name],
                    drive_flat=flat,
                    extra=extra,
                    tabs=tab,
                )
            pc = copy.deepcopy(cut_cache[key])
            if part.name in merged:
                pc.outer = _merged_outline(pc.outer, merged[part.name], s)
            if drive_at is not None and part.name in keyed:
                _phase_mark(
                    pc,
                    (drive_at[0] * s.unit_mm, drive_at[1] * s.unit_mm),
                    flat,
                    keyed[part.name],
                    dict(getattr(mech, "key_turn", {})).get(part.name, 0.0),
                )
            part_notes.extend(pc.notes)
            cuts.append(pc)
        return cuts, part_notes

    def plan(cuts: list[PartCut]) -> tuple[dict[str, Any], Assembly]:
        material = {pc.name: nominal_material(pc.outer, pc.inner, s.kerf / 2) for pc in cuts}
        return material, plan_assembly(
            mech,
            material,
            pins,
            contacts,
            s.unit_mm,
            s.thickness_mm,
            s.pin_mm,
            s.pin_head,
            shaft.joint if shaft is not None else None,
            ring_mm=2 * spacer_radius(s),
        )

    cuts, part_notes = cut_all([], {})
    material0, asm = plan(cuts)
    material = material0
    tab_plan = plan_tabs(mech, asm.layers, material0, s)
    joins = tab_plan.joins
    more_notes: list[str] = []
    if joins or tab_plan.planes:
        # cut again with the tabs and slots, then with travel slots until none is missing; the tabs' faces
        # follow the layers, so a plan whose cuts move a layer is planned again for the new layers
        layers_used = asm.layers
        done = False
        for _ in range(3):
            travel: dict[str, list[Any]] = {}
            travel_notes: list[str] = []
            for _ in range(4):
                cuts, part_notes = cut_all(joins, travel)
                material, asm2 = plan(cuts)
                if asm2.layers != layers_used:
                    break
                more, more_notes = travel_slots(mech, asm2.layers, material, s, tab_plan)
                if not more:
                    done = True
                    break
                for k_, v_ in more.items():
                    travel[k_] = merge_travel(travel.get(k_, []) + v_, s.min_wall)
                travel_notes.extend(more_notes)
            if done or asm2.layers == layers_used:
                break
            layers_used = asm2.layers
            tab_plan = plan_tabs(mech, layers_used, material0, s)
            joins = tab_plan.joins
        if not done:
            _unplannable_tabs(asm2.layers, layers_used)
        notes.extend(travel_notes)
        asm = asm2
        part_notes += _tab_notes(cuts, joins, s)
        _engrave_joins(cuts, joins, s)
    notes.extend(part_notes)
    notes.extend(asm.notes)
    from types import SimpleNamespace

    from planar.fabrication.plan import blocking, settle

    violations = settle(SimpleNamespace(mechanism=mech, assembly=asm, own=material, settings=s), *samples)
    notes.extend(blocking(asm, violations))
    violations = violations + shaft_check(s, asm.pins, _shaft_xy(asm))
    for pc in cuts:
        pc.layer = asm.layers.get(pc.name)
    cuts += _spacer_cuts(asm, s)
    if s.reference_square_mm > 0:
        cuts.append(_reference_square(s))
    layout = nest(cuts, s.sheet, s.spacing, s.margin, s.kerf, s.unit_mm)
    warnings: list[str] = []
    from planar.windup.chain import ToyMechanism

    if isinstance(scene.mechanism, ToyMechanism):  # a toy: its motions against the fit's play
        from planar.toys.fitcheck import small_motion_text, small_motions

        warnings = [small_motion_text(m, s) for m in small_motions(scene.mechanism, s)]
    return Fabrication(
        scene.name,
        s,
        layout,
        asm,
        notes,
        shaft.joint if shaft is not None else None,
        material,
        [p.name for p in mech.parts if p.ground and p.plane == "xy"],
        joins=joins,
        stack_z=tab_plan.z_stack,
        planes=dict(tab_plan.planes),
        warnings=warnings,
        mechanism=mech,
        violations=violations,
        mounts={pc.name: list(pc.mounting_at) for pc in cuts if pc.mounting_at},
        below_mm=below_mm(s, asm.pins, _hang(tab_plan)),
    )


def _hang(tab_plan: Any) -> float:
    """How far the pieces standing perpendicular reach below the xy stack's lower face over the cycle (mm, >= 0)."""
    import numpy as np
    import shapely

    from planar.fabrication.check import placed_array

    lows = [
        float(shapely.bounds(placed_array(tab_plan.shape[n], np.asarray(tab_plan.track[n]), 1.0))[:, 1].min())
        for n in tab_plan.planes
        if n in tab_plan.track and n in tab_plan.shape
    ]
    return max(0.0, tab_plan.z_stack - min(lows)) if lows else 0.0


def _shaft_xy(asm: Assembly) -> tuple[float, float]:
    """Where the motor shaft stands in the drawn pose (mm, world), or the origin without one."""
    for pp in asm.pins:
        if pp.shaft:
            x, y, a = asm.pose[pp.spec.parts[0]]
            lx, ly = pp.spec.at[0][0] * asm.unit_mm, pp.spec.at[0][1] * asm.unit_mm
            return (x + math.cos(a) * lx - math.sin(a) * ly, y + math.sin(a) * lx + math.cos(a) * ly)
    return (0.0, 0.0)


def _engrave_joins(cuts: list[PartCut], joins: list[Any], s: FabSettings) -> None:
    """Engrave each joint's letter beside its slots (where it fits) and once on the tabbed piece by its edge."""
    from planar.fabrication.parts import letter_marks

    by_name = {pc.name: pc for pc in cuts}
    for jn in joins:
        base = by_name[jn.base]
        mat = nominal_material(base.outer, base.inner, s.kerf / 2)
        for e in base.engrave:
            from shapely.geometry import LineString

            mat = mat.difference(LineString(e).buffer(0.5))
        base.engrave.extend(letter_marks(mat, [(c, jn.slot_size[0] / 2, jn.letter) for c, _ in jn.slots], max(s.min_label, 1.5)))
        piece = by_name[jn.piece]
        mat = nominal_material(piece.outer, piece.inner, s.kerf / 2)
        for e in piece.engrave:
            from shapely.geometry import LineString

            mat = mat.difference(LineString(e).buffer(0.5))
        mid = jn.tabs[0].centroid
        piece.engrave.extend(
            letter_marks(mat, [((float(mid.x), float(mid.y)), s.thickness_mm, jn.letter)], max(s.min_label, 1.5))
        )


def _reference_square(s: FabSettings) -> PartCut:
    """A square of ``reference_square_mm`` (kerf-compensated like every outline) with its size engraved: measure
    it after cutting to check the scale (a part is never scaled by the laser software's import)."""
    from planar.fabrication.sheet import Contour
    from planar.fabrication.strokefont import text_strokes

    a = s.reference_square_mm / 2 + s.kerf / 2
    outer = Contour([(-a, -a, 0.0), (a, -a, 0.0), (a, a, 0.0), (-a, a, 0.0)])
    h = min(2.0, s.reference_square_mm / 6)
    text = f"{s.reference_square_mm:g}"
    return PartCut("reference square", outer, [], text_strokes(text, h, (0.0, 0.0), 0.0), text, h)


def sheet_paths(path: str | os.PathLike, sheets: int) -> list[Path]:
    """``parts.dxf`` for one sheet; ``parts-1.dxf``, ``parts-2.dxf``, ... for several."""
    p = Path(path)
    if sheets == 1:
        return [p]
    return [p.with_name(f"{p.stem}-{k + 1}{p.suffix}") for k in range(sheets)]


def kerf_test_layout(settings: FabSettings) -> Layout:
    """A kerf calibration piece: a 20 mm square with a 10 mm hole, both kerf-compensated, the kerf engraved.

    Measure the square and the hole after cutting: too small a square (or too large a hole) means the
    real kerf is wider than ``kerf_mm`` by the difference.
    """
    from planar.fabrication.sheet import Contour
    from planar.fabrication.strokefont import text_strokes

    k2 = settings.kerf / 2
    a = 10.0 + k2
    outer = Contour([(-a, -a, 0.0), (a, -a, 0.0), (a, a, 0.0), (-a, a, 0.0)])
    inner = [Circle((0.0, 3.0), 5.0 - k2)]
    engrave = text_strokes(f"K {settings.kerf:.2f}", 2.0, (0.0, -5.5), 0.0)
    engrave += text_strokes("20 / 10", 1.6, (0.0, -8.3), 0.0)
    pc = PartCut("kerf test", outer, list(inner), engrave, f"K {settings.kerf:.2f}", 2.0, nominal_holes=[((0.0, 3.0), 5.0)])
    return nest([pc], settings.sheet, settings.spacing, settings.margin, settings.kerf, settings.unit_mm)


def size_note(fab: Fabrication) -> str:
    """When parts were widened to the least wall: how long the longest part is at the scene's ``unit_mm`` and how
    to cut it larger, in words (empty otherwise).  A scene from a CSV of targets in arbitrary units keeps the
    default 10 mm per unit, which can leave the parts a few millimetres wide."""
    import numpy as np

    from planar.fabrication.sheet import Contour

    widened = sum(p.widened for p in fab.layout.parts)
    if not widened:
        return ""
    outlines = [np.array(p.outer.vertices)[:, :2] for p in fab.layout.parts if isinstance(p.outer, Contour)]
    longest = max((float(np.ptp(xy, axis=0).max()) for xy in outlines if len(xy)), default=0.0)
    u = fab.layout.unit_mm
    return (
        f"{widened} part(s) were widened to the least wall; at unit_mm {u:g} (millimetres per model unit, the scene's "
        f"[fabrication] unit_mm) the longest part is {longest:.1f} mm: export --unit-mm N cuts the mechanism N/{u:g} "
        "times as large"
    )


def summary(fab: Fabrication) -> str:
    """One line: parts (and the spacer rings cut beside them), sheets, utilisation, layers, pins."""
    lay, asm = fab.layout, fab.assembly
    util = ", ".join(f"{u:.0%}" for u in lay.utilisation)
    layers = max(asm.n_layers.values()) if asm.n_layers else 0
    spacers = sum(p.spacers for p in asm.pins)
    rings = f" + {spacers} spacer ring(s)" if spacers else ""
    extras = [p.name for p in lay.parts if p.name == "reference square"]  # cut, but no part of the assembly
    rings += "".join(f" + a {n}" for n in extras)
    return (
        f"{len(lay.parts) - spacers - len(extras)} parts{rings} on {lay.sheets} sheet(s) of {lay.sheet_size[0]:g} x "
        f"{lay.sheet_size[1]:g} mm (utilisation {util}), kerf {lay.kerf:g} mm, {layers} layer(s) of "
        f"{fab.settings.thickness_mm:g} mm, {len(asm.pins)} pin(s)"
    )
