"""``planar schema``: the JSON schema of scene files."""

from __future__ import annotations

import argparse
import json
import sys
from typing import Any

from planar.cli.common import outputs
from planar.errors import InputError

__all__ = ["add_parser"]


def _cmd_schema(args: argparse.Namespace) -> int:
    from planar.fileio import atomic_write
    from planar.scene.load import scene_schema

    text = json.dumps(scene_schema(), indent=2, sort_keys=True) + "\n"
    outputs(args, (), ("-o/--output", "output", (".json",)))
    if args.output is not None:
        with atomic_write(args.output, "w") as fh:
            fh.write(text)
        print(f"wrote {args.output}")
    else:
        if sys.stdout is None:  # standard output closed (planar schema >&-)
            raise InputError("standard output", "closed", "an open standard output, or -o FILE")
        sys.stdout.write(text)
    return 0


def add_parser(sub: Any) -> None:
    """Add ``planar schema`` to the subcommands ``sub``."""

    sc = sub.add_parser("schema", help="print (or write) the JSON schema of scene files")
    sc.add_argument("-o", "--output", default=None, help="file to write (default: standard output)")
    sc.set_defaults(func=_cmd_schema)
