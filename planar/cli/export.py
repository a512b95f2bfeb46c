"""``planar export SCENE``: every part laid flat for a laser cutter."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from planar.cli.common import outputs, sheet
from planar.errors import InputError

__all__ = ["add_parser"]


#: export's outputs: (option, attribute, suffixes)
_EXPORT_OUTPUTS = (
    ("-o/--output", "output", (".dxf",)),
    ("--svg", "svg", (".svg",)),
    ("--preview", "preview", (".png",)),
    ("--bom", "bom", (".csv",)),
    ("--assembly", "assembly", (".svg",)),
    ("--kerf-test", "kerf_test", (".dxf", ".svg")),
    ("--plan", "plan", (".json",)),
    ("--motion", "motion", (".csv",)),
    ("--steps", "steps", (".svg",)),
)


def _cmd_export(args: argparse.Namespace) -> int:
    from planar.app.pipeline import export_scene
    from planar.fabrication.build import size_note, summary
    from planar.scene.load import load_scene

    if all(getattr(args, attr) is None for _, attr, _ in _EXPORT_OUTPUTS):
        raise InputError(
            "export",
            args.scene,
            "an output: -o parts.dxf, --svg, --preview, --bom, --assembly, --plan, --motion, --steps or --kerf-test "
            "(nothing would be written)",
        )
    outputs(args, (args.scene,), *_EXPORT_OUTPUTS)
    from planar.fabrication.build import KERF_RANGE, kerf_ok

    if args.kerf is not None and not kerf_ok(args.kerf):
        raise InputError("--kerf", args.kerf, KERF_RANGE)
    from planar.app.export import check_lines, scene_with_unit

    size = sheet(args.sheet) if args.sheet else None
    scene = scene_with_unit(load_scene(args.scene), args.unit_mm, "--unit-mm", size)
    fab = export_scene(
        scene,
        args.output,
        args.svg,
        args.kerf,
        size,
        args.preview,
        args.bom,
        args.assembly,
        args.kerf_test,
        plan=args.plan,
        motion=args.motion,
        steps=args.steps,
    )
    for note in fab.notes:
        print(f"note: {note}")
    small = size_note(fab)
    if small:
        print(f"size: {small}")
    for w in fab.warnings:  # a toy's motion the cut parts will not make (the design exits 3 for it; cut anyway)
        print(f"warning: {w}")
    kerf_file = [p for p in fab.written if args.kerf_test is not None and p == Path(args.kerf_test)]
    rest = [p for p in fab.written if p not in kerf_file]
    print(f"{summary(fab)} -> {', '.join(map(str, rest)) or 'no part file written'}")
    for p in kerf_file:  # the calibration piece alone, none of the parts
        print(f"kerf test piece (a 20 mm square with a 10 mm hole, kerf {fab.settings.kerf:g} mm) -> {p}")
    lines = check_lines(scene, fab)  # the files are written (to look at), the exit status says it fails
    for line in lines[: len(fab.violations)]:
        print(f"build check: {line}")
    for line in lines[len(fab.violations) :]:  # what would make it build
        print(f"scale: {line}")
    if fab.violations:
        where = (
            f"; the assembly drawing {args.assembly} rings them red"
            if args.assembly
            else " (--assembly FILE.svg draws them, ringed red)"
        )
        print(f"build check failed: {len(fab.violations)} problem(s){where}")
        return 3
    print("build check: every part, pin, spacer and the motor shaft clear through the cycle")
    return 0


def add_parser(sub: Any) -> None:
    """Add ``planar export`` to the subcommands ``sub``."""

    ex = sub.add_parser("export", help="every part laid flat for a laser cutter (DXF, SVG)")
    ex.add_argument("scene", help="scene file (TOML)")
    ex.add_argument("-o", "--output", default=None, help="DXF file to write")
    ex.add_argument("--svg", default=None, help="SVG file to write")
    ex.add_argument("--kerf", type=float, default=None, help="beam width in mm (default: the scene's kerf_mm)")
    ex.add_argument("--sheet", default=None, help="sheet size WIDTHxHEIGHT in mm (default: the scene's)")
    ex.add_argument(
        "--unit-mm",
        type=float,
        default=None,
        help="millimetres per model unit (default: the scene's [fabrication] unit_mm, 10 if it has none)",
    )
    ex.add_argument("--preview", default=None, help="PNG preview of each sheet (photo-like)")
    ex.add_argument("--bom", default=None, help="bill of materials (CSV): parts, layers, pins, spacers, tab joints")
    ex.add_argument("--assembly", default=None, help="assembly drawing (SVG): parts in place, layers, letters")
    ex.add_argument("--kerf-test", default=None, help="a kerf calibration piece (.dxf or .svg)")
    ex.add_argument(
        "--plan", default=None, help="the assembly as data (JSON): parts' layers and placements, pins, spacers, motor shaft"
    )
    ex.add_argument("--motion", default=None, help="the motion table (CSV) of the parts as cut, one cycle of 240 samples")
    ex.add_argument(
        "--steps", default=None, help="assembly steps (SVG pages steps-1.svg, ...): layer by layer, which pin goes where"
    )
    ex.set_defaults(func=_cmd_export)
