"""``planar plot SCENE -o fig.png|svg [--what curve,follower,pressure,transmission,angle,velocity,speed,acceleration,torque]``."""

from __future__ import annotations

import argparse
from typing import Any

__all__ = ["add_parser"]


def _cmd_plot(args: argparse.Namespace) -> int:
    from planar.draw.charts import write_plot
    from planar.errors import InputError
    from planar.scene.load import load_scene

    what = [w.strip() for w in args.what.split(",")] if args.what is not None else None
    if what is not None and not all(what):
        raise InputError("--what", args.what, "comma-separated chart names, e.g. curve,torque (no empty item)")
    from planar.app.pipeline import numeric_guard
    from planar.cli.common import outputs

    outputs(args, (args.scene,), ("-o/--output", "output", (".png", ".svg")))
    scene = load_scene(args.scene)
    with numeric_guard(scene, "the charts"):
        charts = write_plot(scene, args.output, what, args.samples, option="--what", samples_option="--samples")
    print(f"wrote {args.output}: {', '.join(charts)}")
    return 0


def add_parser(sub: Any) -> None:
    """Register ``planar plot`` on the subcommand parsers ``sub``."""
    p = sub.add_parser(
        "plot",
        help="charts of a scene: point paths, transmission angle, speeds, torque",
        description="Draw the charts a designer looks at (matplotlib) from the scene's exact "
        "motion and rates: curve (paths of the named points), follower and "
        "pressure (a cam's follower motion and pressure angle), transmission "
        "(angle at each RRR dyad, linkages only), angle (every moving part's, "
        "from +x: a rocker's output against the crank), velocity and acceleration "
        "(angular, every moving part), torque (motor torque under [effects], "
        "and the loads alone). Horizontal axis: crank (cam) angle for a turning "
        "input, else time.",
    )
    p.add_argument("scene", help="scene file (TOML)")
    p.add_argument("-o", "--output", required=True, help="figure to write: .png or .svg")
    p.add_argument(
        "--what",
        default=None,
        help="comma-separated charts: curve,follower,pressure,transmission,angle,velocity,speed,"
        "acceleration,torque "
        "(default: every chart that applies)",
    )
    p.add_argument(
        "--samples",
        type=int,
        default=None,
        help="samples per cycle for the charts (default: the scene's [driver] samples_per_cycle)",
    )
    p.set_defaults(func=_cmd_plot)
