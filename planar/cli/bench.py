"""``planar bench NAME``: a benchmark against a peer measured in the same run."""

from __future__ import annotations

import argparse
import json
import os
from typing import Any

from planar.cli.common import positive
from planar.errors import InputError

__all__ = ["add_parser"]

#: exit status of a benchmark whose own check failed (its figures disagree with the peer's), as ``planar compare``
EXIT_CHECK = 3


def _cmd_bench(args: argparse.Namespace) -> int:
    from planar.bench import benchmark

    fn, fmt = benchmark(args.name)
    positive("-n", args.n, integer=True)
    positive("--repeats", args.repeats, integer=True)
    if args.n is not None:
        from planar.core.limits import check_count

        check_count("samples", "-n", args.n, "samples")
    kwargs = {}
    if args.n is not None:
        if args.name == "accuracy":
            raise InputError("-n", args.n, "no problem size for the accuracy benchmark (it runs the scenes of --scenes)")
        kwargs["n"] = args.n
    if args.repeats is not None:
        kwargs["repeats"] = args.repeats
    if args.full and args.name != "synthesis":
        raise InputError("--full", True, "only with 'planar bench synthesis' (whose quick run is the default)")
    if args.full and args.quick:
        raise InputError("--full", True, "no --quick with it (one or the other)")
    if args.name == "synthesis":
        kwargs["quick"] = not args.full  # the whole run takes over an hour of CPU: asked for, not the default
    if args.name == "accuracy":
        from planar.fileio import check_output

        check_output("-o/--output", args.output, (), directory=True)  # before the minutes of work, not after
        parent = os.path.dirname(os.path.abspath(args.output))
        if not os.path.isdir(parent):
            raise InputError("-o/--output", args.output, f"a folder in an existing folder ({parent} does not exist)")
        if not os.path.isdir(args.scenes):
            raise InputError("--scenes", args.scenes, "an existing folder of scene files")
        kwargs["scenes"] = args.scenes
        kwargs["out_dir"] = args.output
        kwargs["quick"] = args.quick
    result = fn(**kwargs)
    print(json.dumps(result, indent=2) if args.json else fmt(result))
    return 0 if result.get("ok", True) else EXIT_CHECK


def add_parser(sub: Any) -> None:
    """Add ``planar bench`` to the subcommands ``sub``."""

    b = sub.add_parser("bench", help="benchmarks against a peer, measured in the same run")
    from planar.bench import BENCHMARKS

    b.add_argument("name", choices=sorted(BENCHMARKS))
    b.add_argument("--json", action="store_true", help="print a JSON object (with a 'ratio' key)")
    b.add_argument("-n", type=int, default=None, help="problem size (samples)")
    b.add_argument(
        "--repeats",
        type=int,
        default=None,
        help="timing repeats (kinematics: 7 by default, interleaved with the peer; median and spread reported)",
    )
    b.add_argument("-o", "--output", default="planar-bench-accuracy", help="accuracy: folder for the CSV and chart")
    b.add_argument(
        "--quick",
        action="store_true",
        help="accuracy: a small grid on three mechanisms; synthesis: the default already (one repeat, small budgets)",
    )
    b.add_argument(
        "--full",
        action="store_true",
        help="synthesis: every problem at the normal budgets, 5 repeats (well over an hour of CPU)",
    )
    b.add_argument(
        "--scenes", default="gallery", help="accuracy: folder of scene files to measure (default: ./gallery, the repository's)"
    )
    b.set_defaults(func=_cmd_bench)
