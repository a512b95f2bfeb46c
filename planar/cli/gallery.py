"""``planar gallery``: every scene of a folder rendered to a GIF."""

from __future__ import annotations

import argparse
from typing import Any

__all__ = ["add_parser"]


def _cmd_gallery(args: argparse.Namespace) -> int:
    from planar.app.pipeline import build_gallery
    from planar.fileio import check_output, output_transaction

    check_output("-o/--output", args.output, (), directory=True)
    with output_transaction():  # all GIFs or none: a bad scene leaves no half gallery
        done = list(build_gallery(args.source, args.output))
    for path, target, n in done:
        print(f"{path.name}: {n} frames -> {target}")
    return 0


def add_parser(sub: Any) -> None:
    """Add ``planar gallery`` to the subcommands ``sub``."""

    g = sub.add_parser("gallery", help="render every scene of a folder to a GIF")
    g.add_argument("-o", "--output", default=None, help="output directory (default: beside the scenes)")
    g.add_argument("--source", default="gallery", help="folder of scenes (default: ./gallery, the repository's)")
    g.set_defaults(func=_cmd_gallery)
