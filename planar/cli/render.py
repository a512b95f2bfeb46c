"""``planar render SCENE -o OUT``: a scene's animation (GIF, MP4, WebM)."""

from __future__ import annotations

import argparse
from typing import Any

from planar.cli.common import outputs
from planar.cli.compare import add_solver_options

__all__ = ["add_parser"]


def _cmd_render(args: argparse.Namespace) -> int:
    from planar.app.pipeline import ANIMATION_SUFFIXES, animation_plan, overlay_motion, render_scene
    from planar.cli.compare import settings_from_args
    from planar.scene.load import load_scene

    outputs(args, (args.scene,), ("-o/--output", "output", ANIMATION_SUFFIXES))
    settings = settings_from_args(args)
    scene = load_scene(args.scene)
    notes: list[str] = []
    overlay = overlay_motion(scene, settings, notes) if args.overlay else None
    n = render_scene(scene, args.output, overlay=overlay, fps=args.fps, notes=notes, options=("-o", "--fps"))
    for note in notes:
        print(f"note: {note}")
    plan = animation_plan(scene, args.output, args.fps, "--fps")  # arithmetic only: what render_scene drew
    print(f"wrote {args.output}: {n} frames, {plan.fps:.3g} frames/s, a cycle plays {plan.cycle_play_s:.3g} s")
    return 0


def add_parser(sub: Any) -> None:
    """Add ``planar render`` to the subcommands ``sub``."""

    r = sub.add_parser("render", help="render a scene's animation to a GIF, an HTML player (or MP4/WebM)")
    r.add_argument("scene", help="scene file (TOML)")
    r.add_argument(
        "-o",
        "--output",
        required=True,
        help="animation to write: .gif, .html (a self-contained player page), or .mp4/.webm with the video "
        "extra (pip install 'planar[video]')",
    )
    r.add_argument(
        "--fps",
        type=float,
        default=None,
        help="frames per second (default: the scene's [render] fps, else 25, or 50 for fast cycles; "
        "a GIF plays at most 50); a cycle plays for 1/speed seconds within one frame",
    )
    r.add_argument("--overlay", action="store_true", help="draw the pymunk simulation over the analytic motion")
    add_solver_options(r)
    r.set_defaults(func=_cmd_render)
