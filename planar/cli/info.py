"""``planar info SCENE [--json]``: the homework figures of a scene's mechanism (see :mod:`planar.analysis.info`)."""

from __future__ import annotations

import argparse
import json
from typing import Any

__all__ = ["add_parser"]


def _cmd_info(args: argparse.Namespace) -> int:
    from planar.analysis.info import format_info, info
    from planar.scene.load import load_scene

    scene = load_scene(args.scene)
    r = info(scene.mechanism)
    print(json.dumps(r.as_dict(), indent=2) if args.json else format_info(r))
    return 0


def add_parser(sub: Any) -> None:
    """Add ``planar info`` to the subcommands ``sub``."""

    r = sub.add_parser(
        "info",
        help="degrees of freedom, Grashof class, toggle angles, transmission angles, strokes and time ratio of a scene",
    )
    r.add_argument("scene", help="scene file (TOML)")
    r.add_argument("--json", action="store_true", help="print a JSON object instead of text")
    r.set_defaults(func=_cmd_info)
