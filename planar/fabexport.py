"""``planar export``: parts checked, lettered, layered, nested, then every file written at once.

:func:`build` turns a scene into a :class:`Fabrication` (layout, assembly,
notes); :func:`write_outputs` renders every requested file in memory and only
then writes them (each to a temporary beside its target, all renamed at the
end), so bad input or a failed check leaves no file written or clobbered.
With several sheets, ``parts.dxf`` becomes ``parts-1.dxf``, ``parts-2.dxf``
(same for SVG and the preview PNG).
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from .assembly import Assembly, letter, pin_stacks, plan_assembly
from .errors import InputError
from .fabjoints import joint_pins, pin_features
from .fabparts import FabSettings, nominal_material, part_cuts
from .fabrication import Circle, Layout, PartCut
from .nesting import nest

__all__ = ["Fabrication", "build", "kerf_test_layout", "sheet_paths", "write_outputs"]


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
    #: motions the cut parts will not make (a toy's cam throw or effector stroke under a few times the fit's
    #: play: :func:`planar.windup.fitcheck.small_motions`), one line each
    warnings: list[str] = field(default_factory=list)


def _shaft_pin(mech: Any, pins) -> Any:
    drv = mech.driver
    if drv.kind != "rotation":
        return None
    ground = {p.name for p in mech.parts if p.ground}
    for pin in pins:
        if drv.part in pin.parts and (set(pin.parts) - {drv.part}) <= ground and pin.kinds == ("hole", "hole"):
            return pin
    return None


def _fab_mechanism(mech: Any) -> Any:
    """The mechanism whose parts are cut: a wind-up toy is cut as its assembly (merged parts, one frame,
    cams keyed to the shaft; :mod:`planar.windup.assembly`), anything else as it is."""
    from .windup.chain import ToyMechanism

    if isinstance(mech, ToyMechanism):
        from .windup.assembly import toy_assembly

        return toy_assembly(mech)
    return mech


def _phase_mark(pc: PartCut, at: tuple[float, float], flat: float, phase: float, turn: float = 0.0) -> None:
    """Engrave a keyed cam's key angle: a tick from its shaft hole along the D's flat and the angle in degrees
    (``phase``, rad: the cam's phase plus ``turn``, its root stage's own turn; the note names both)."""
    import numpy as np

    from .strokefont import text_strokes

    c, s = math.cos(flat), math.sin(flat)
    pc.engrave.append(np.array([(at[0] + 2.5 * c, at[1] + 2.5 * s), (at[0] + 5.0 * c, at[1] + 5.0 * s)]))
    deg = f"{math.degrees(phase) % 360:.0f}"
    pc.engrave.extend(text_strokes(deg, 1.5, (at[0] - 3.5 * c, at[1] - 3.5 * s), flat - math.pi / 2))
    own = f"{math.degrees(turn) % 360:.0f}"
    cam = f"{math.degrees(phase - turn) % 360:.0f}"
    why = f" = cam phase {cam} + the stage's own turn {own}" if own != "0" else ""
    pc.notes.append(f"{pc.name}: keyed to the motor shaft at {deg} degrees{why} (engraved tick along the D's flat)")


def build(scene: Any, settings: FabSettings) -> Fabrication:
    """Cut-ready, checked, layered and nested parts of ``scene`` (raises FabricationError/InputError)."""
    s = settings
    if not (0 <= s.kerf <= 2):
        raise InputError("kerf", s.kerf, "a kerf between 0 and 2 mm")
    mech = _fab_mechanism(scene.mechanism)
    keyed: dict[str, float] = dict(getattr(mech, "keyed", {}))
    pins, contacts = joint_pins(mech)
    pinned = pin_features(mech)
    shaft = _shaft_pin(mech, pins)
    notes: list[str] = list(getattr(mech, "design_notes", ()))  # what a mechanism reports of its own design
    notes += list(getattr(mech, "notes", []))
    if mech.driver.kind != "rotation":
        notes.append(f"driver {mech.driver.part!r} is a {mech.driver.kind} drive: no motor shaft hole")
    elif shaft is None:
        notes.append(f"driver {mech.driver.part!r}: no pin to the ground on its axis, no motor shaft hole")
    letters: dict[str, list[tuple[tuple[float, float], str]]] = {p.name: [] for p in mech.parts}
    for k, stack in enumerate(pin_stacks(pins)):
        marked: set[tuple[str, tuple[float, float]]] = set()
        for i in stack:
            pin = pins[i]
            for side in (0, 1):
                key = (pin.parts[side], pin.at[side])
                if pin.kinds[side] == "hole" and pin is not shaft and key not in marked:
                    marked.add(key)
                    letters[pin.parts[side]].append((pin.at[side], letter(k)))
    cuts: list[PartCut] = []
    for n, part in enumerate(mech.parts, start=1):
        drive_at = motor_at = None
        if shaft is not None and part.name in shaft.parts:
            k = shaft.parts.index(part.name)
            if part.name == mech.driver.part:
                drive_at = shaft.at[k]
            else:
                motor_at = shaft.at[k]
        flat = math.pi / 2
        if shaft is not None and part.name in keyed:  # a toy's cam: a D on the shaft, turned by its phase
            drive_at, flat = (0.0, 0.0), math.pi / 2 - keyed[part.name]
        pc = part_cuts(part, s, n, {i for (pn, i) in pinned if pn == part.name}, drive_at, motor_at,
                       mounting=part.ground and part.plane == "xy", letters=letters[part.name], drive_flat=flat)
        if drive_at is not None and part.name in keyed:
            _phase_mark(pc, (drive_at[0] * s.unit_mm, drive_at[1] * s.unit_mm), flat, keyed[part.name],
                        dict(getattr(mech, "key_turn", {})).get(part.name, 0.0))
        notes.extend(pc.notes)
        cuts.append(pc)
    material = {pc.name: nominal_material(pc.outer, pc.inner, s.kerf / 2) for pc in cuts}
    asm = plan_assembly(mech, material, pins, contacts, s.unit_mm, s.thickness_mm, s.pin_mm, s.pin_head,
                        shaft.joint if shaft is not None else None)
    notes.extend(asm.notes)
    for pc in cuts:
        pc.layer = asm.layers.get(pc.name)
    # spacer rings, cut from the same sheet
    k2 = s.kerf / 2
    ri = (s.pin_mm + s.clearance) / 2
    ro = max(ri + s.min_wall, s.min_part / 2)
    for pp in asm.pins:
        for j in range(pp.spacers):
            cuts.append(PartCut(f"spacer {pp.letter}{j + 1}", Circle((0.0, 0.0), ro + k2), [Circle((0.0, 0.0), ri - k2)],
                                nominal_holes=[((0.0, 0.0), ri)]))
    layout = nest(cuts, s.sheet, s.spacing, s.margin, s.kerf, s.unit_mm)
    warnings: list[str] = []
    if mech is not scene.mechanism:  # a toy: its motions against the fit's play
        from .windup.fitcheck import small_motion_text, small_motions

        warnings = [small_motion_text(m, s) for m in small_motions(scene.mechanism, s)]
    return Fabrication(scene.name, s, layout, asm, notes, shaft.joint if shaft is not None else None, material,
                       [p.name for p in mech.parts if p.ground and p.plane == "xy"], warnings=warnings)


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
    from .fabrication import Contour
    from .strokefont import text_strokes

    k2 = settings.kerf / 2
    a = 10.0 + k2
    outer = Contour([(-a, -a, 0.0), (a, -a, 0.0), (a, a, 0.0), (-a, a, 0.0)])
    inner = [Circle((0.0, 3.0), 5.0 - k2)]
    engrave = text_strokes(f"K {settings.kerf:.2f}", 2.0, (0.0, -5.5), 0.0)
    engrave += text_strokes("20 / 10", 1.6, (0.0, -8.3), 0.0)
    pc = PartCut("kerf test", outer, list(inner), engrave, f"K {settings.kerf:.2f}", 2.0, nominal_holes=[((0.0, 3.0), 5.0)])
    return nest([pc], settings.sheet, settings.spacing, settings.margin, settings.kerf, settings.unit_mm)


def _commit(files: dict[Path, bytes]) -> None:
    """Write every file to a temporary beside it, then rename them all; on any failure remove the temporaries.

    Inside a command's :func:`planar.fileio.output_transaction` the renames wait for the whole command.
    """
    from .fileio import atomic_write, output_transaction

    for target in files:
        parent = target.parent if str(target.parent) else Path(".")
        if not parent.is_dir():
            raise InputError("output", str(target), f"a path in an existing directory ({parent} does not exist)")
    with output_transaction():
        for target, data in files.items():
            with atomic_write(target, "wb") as fh:
                fh.write(data)


def write_outputs(fab: Fabrication | None, dxf=None, svg=None, preview=None, bom=None, assembly=None,
                  kerf_test=None, settings: FabSettings | None = None) -> list[Path]:
    """Render every requested output in memory, then write them all (see the module docstring)."""
    from exporters.dxf import dxf_bytes
    from exporters.svg import svg_text

    files: dict[Path, bytes] = {}
    if fab is not None:
        lay, s = fab.layout, fab.settings
        meta = f"{fab.name}: {s.thickness_mm:g} mm sheet, kerf {s.kerf:g} mm"
        if dxf is not None:
            for k, p in enumerate(sheet_paths(dxf, lay.sheets)):
                files[p] = dxf_bytes(lay, k, s, f"{meta}, sheet {k + 1} of {lay.sheets}")
        if svg is not None:
            for k, p in enumerate(sheet_paths(svg, lay.sheets)):
                files[p] = svg_text(lay, k, s).encode()
        if preview is not None:
            from exporters.preview import sheet_png

            for k, p in enumerate(sheet_paths(preview, lay.sheets)):
                files[p] = sheet_png(lay, k, s)
        if bom is not None:
            from exporters.bom import bom_text

            files[Path(bom)] = bom_text(fab).encode()
        if assembly is not None:
            from exporters.svg import assembly_svg_text

            files[Path(assembly)] = assembly_svg_text(fab).encode()
    if kerf_test is not None:
        s = settings or (fab.settings if fab is not None else FabSettings())
        lay = kerf_test_layout(s)
        p = Path(kerf_test)
        if p.suffix.lower() == ".svg":
            files[p] = svg_text(lay, 0, s).encode()
        elif p.suffix.lower() == ".dxf":
            files[p] = dxf_bytes(lay, 0, s, f"kerf test, kerf {s.kerf:g} mm")
        else:
            raise InputError("--kerf-test", str(p), "a .dxf or .svg file name")
    if len({str(p.resolve()) for p in files}) != len(files):
        raise InputError("output", ", ".join(map(str, files)), "distinct output files")
    _commit(files)
    return list(files)


def summary(fab: Fabrication) -> str:
    """One line: parts (and the spacer rings cut beside them), sheets, utilisation, layers, pins."""
    lay, asm = fab.layout, fab.assembly
    util = ", ".join(f"{u:.0%}" for u in lay.utilisation)
    layers = max(asm.n_layers.values()) if asm.n_layers else 0
    spacers = sum(p.spacers for p in asm.pins)
    rings = f" + {spacers} spacer ring(s)" if spacers else ""
    return (f"{len(lay.parts) - spacers} parts{rings} on {lay.sheets} sheet(s) of {lay.sheet_size[0]:g} x "
            f"{lay.sheet_size[1]:g} mm (utilisation {util}), kerf {lay.kerf:g} mm, {layers} layer(s) of "
            f"{fab.settings.thickness_mm:g} mm, {len(asm.pins)} pin(s)")

