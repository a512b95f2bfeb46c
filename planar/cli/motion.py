"""``planar motion SCENE -o OUT.csv`` and ``planar catalog NAME -o OUT.csv``: motion tables."""

from __future__ import annotations

import argparse
from typing import Any

from planar.cli.common import outputs, positive

__all__ = ["add_parser"]


def _cmd_motion(args: argparse.Namespace) -> int:
    from planar.app.pipeline import write_scene_motion
    from planar.scene.load import load_scene

    outputs(args, (args.scene,), ("-o/--output", "output", (".csv",)))
    scene = load_scene(args.scene)
    notes: list[str] = []
    motion = write_scene_motion(scene, args.output, derivatives=args.derivatives, notes=notes)
    print(f"wrote {args.output}: {len(motion)} samples, {int(motion.valid.sum())} valid")
    for note in notes:
        print(f"note: {note}")
    if args.derivatives:
        from planar.analysis.rates import rates_method
        from planar.app.pipeline import table_motion

        print(f"rates: {rates_method(table_motion(scene.mechanism, motion)[0])}")
    return 0


def _cmd_motion_catalog(args: argparse.Namespace) -> int:
    from planar.app.pipeline import write_catalog_motion
    from planar.core.limits import MIN_SAMPLES_PER_CYCLE, check_count
    from planar.errors import InputError

    outputs(args, (), ("-o/--output", "output", (".csv",)))
    positive("--samples", args.samples, integer=True)
    if args.samples < MIN_SAMPLES_PER_CYCLE:
        raise InputError("--samples", args.samples, f"at least {MIN_SAMPLES_PER_CYCLE} samples (a whole number)")
    check_count("samples", "--samples", args.samples, "samples")
    motion = write_catalog_motion(args.mechanism, args.output, args.samples)
    print(f"wrote {args.output}: {len(motion)} samples, {int(motion.valid.sum())} valid")
    return 0


def add_parser(sub: Any) -> None:
    """Add ``planar motion`` to the subcommands ``sub``."""

    mo = sub.add_parser("motion", help="write a scene's motion table (CSV)")
    mo.add_argument("scene", help="scene file (TOML)")
    mo.add_argument("-o", "--output", required=True, help="CSV file to write")
    mo.add_argument(
        "--derivatives",
        action="store_true",
        help="add <point>.vx/.vy/.ax/.ay, <part>.omega/.alpha, transmission angles and motor torque",
    )
    mo.set_defaults(func=_cmd_motion)

    c = sub.add_parser("catalog", help="write the motion table of a built-in mechanism")
    c.add_argument("mechanism", help="catalog name, e.g. jansen, kangaroo, slider-crank")
    c.add_argument("-o", "--output", required=True, help="CSV file to write")
    c.add_argument("--samples", type=int, default=360)
    c.set_defaults(func=_cmd_motion_catalog)
