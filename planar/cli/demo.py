"""``planar demo``: the embedded default (a wind-up toy and a walking leg), animated, cut and tabled."""

from __future__ import annotations

import argparse
from typing import Any

__all__ = ["add_parser"]


def _cmd_demo(args: argparse.Namespace) -> int:
    """The embedded default: a wind-up toy and a four-bar walking leg, animated (and cut)."""
    from planar.app.pipeline import run_demo
    from planar.fileio import check_output

    # each file is written atomically; not one transaction, as DEMO_EXTRAS may read what the demo wrote
    check_output("-o/--output", args.output, (), directory=True)
    for line in run_demo(args.output):
        print(line)
    return 0


def add_parser(sub: Any) -> None:
    """Add ``planar demo`` to the subcommands ``sub``."""

    d = sub.add_parser("demo", help="run the embedded default and write its outputs")
    d.add_argument("-o", "--output", default="planar-demo", help="output directory (default: planar-demo)")
    d.set_defaults(func=_cmd_demo)
