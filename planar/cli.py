"""The ``planar`` command.

Every subcommand exits 0 on success and 2 on a user error, printing one line
``planar: error: ...`` (no traceback).  Output files are written atomically.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Callable, Sequence

from .errors import PlanarError

__all__ = ["main"]


def _cmd_demo(args: argparse.Namespace) -> int:
    """The embedded default: the kangaroo-style walking leg, its motion and torque."""
    import numpy as np

    from . import analysis
    from .catalog import kangaroo_leg
    from .fileio import write_motion_csv

    out = Path(args.output)
    out.mkdir(parents=True, exist_ok=True)
    leg = kangaroo_leg()
    motion = leg.run(samples_per_cycle=args.samples)
    csv = out / "kangaroo-leg.csv"
    write_motion_csv(csv, leg, motion)
    tau, _ = analysis.motor_torque(leg, motion.driver, {"coupler_point": np.array([0.0, 1.0])})
    foot = motion.points["coupler_point"]
    print(f"{leg.name}: four-bar {leg.grashof}, {len(motion)} samples, all valid: {bool(motion.valid.all())}")
    print(f"  foot stride {np.ptp(foot[:, 0]):.3f} x {np.ptp(foot[:, 1]):.3f} units; "
          f"peak torque for a unit upward foot force {np.abs(tau).max():.3f}")
    print(f"  wrote {csv}")
    for extra in _DEMO_EXTRAS:
        extra(out)
    return 0


#: later features append writers here (GIF, DXF) so the demo grows with the package
_DEMO_EXTRAS: list[Callable[[Path], None]] = []


def _cmd_bench(args: argparse.Namespace) -> int:
    from .bench import BENCHMARKS

    fn, fmt = BENCHMARKS[args.name]
    kwargs = {}
    if args.n is not None:
        kwargs["n"] = args.n
    if args.repeats is not None:
        kwargs["repeats"] = args.repeats
    result = fn(**kwargs)
    print(json.dumps(result, indent=2) if args.json else fmt(result))
    return 0


def _cmd_motion_catalog(args: argparse.Namespace) -> int:
    from .catalog import get
    from .fileio import write_motion_csv

    mech = get(args.mechanism)
    motion = mech.run(samples_per_cycle=args.samples)
    write_motion_csv(args.output, mech, motion)
    print(f"wrote {args.output}: {len(motion)} samples, {int(motion.valid.sum())} valid")
    return 0


def _cmd_chains(args: argparse.Namespace) -> int:
    from .windup.table import enumerate_chains

    chains = enumerate_chains(args.target, args.max_length, args.optional)
    if args.json:
        print(json.dumps({k: [list(c) for c in v] for k, v in chains.items()}))
        return 0
    for motion, cs in chains.items():
        print(f"{motion}: {len(cs)} chains")
        for c in cs:
            print("   " + " -> ".join([c[0].split("->")[0]] + [p.split("->")[1] for p in c]))
    return 0


def build_parser() -> argparse.ArgumentParser:
    from .bench import BENCHMARKS

    p = argparse.ArgumentParser(prog="planar", description="2D rigid-body mechanisms: exact kinematics and more.")
    sub = p.add_subparsers(dest="command", required=True, metavar="COMMAND")

    d = sub.add_parser("demo", help="run the embedded default and write its outputs")
    d.add_argument("-o", "--output", default="planar-demo", help="output directory (default: planar-demo)")
    d.add_argument("--samples", type=int, default=120, help="samples per cycle (default 120)")
    d.set_defaults(func=_cmd_demo)

    b = sub.add_parser("bench", help="benchmarks against a peer, measured in the same run")
    b.add_argument("name", choices=sorted(BENCHMARKS))
    b.add_argument("--json", action="store_true", help="print a JSON object (with a 'ratio' key)")
    b.add_argument("-n", type=int, default=None, help="problem size (samples)")
    b.add_argument("--repeats", type=int, default=None, help="timing repeats (best is kept)")
    b.set_defaults(func=_cmd_bench)

    ch = sub.add_parser("chains", help="motion transfer chains from the motor (Rz) to an end effector")
    ch.add_argument("target", nargs="?", default=None, help="end-effector motion (Ox, Oy, Oz, Tx, Ty, Tz, OzT)")
    ch.add_argument("--max-length", type=int, default=3, help="longest chain (default 3)")
    ch.add_argument("--optional", action="store_true", help="include the Oy->Oy pattern the printed table lacks")
    ch.add_argument("--json", action="store_true", help='print {"Ox": [["Rz->Tx", "Tx->Ox"], ...], ...}')
    ch.set_defaults(func=_cmd_chains)

    c = sub.add_parser("catalog", help="write the motion table of a built-in mechanism")
    c.add_argument("mechanism", help="catalog name, e.g. jansen, kangaroo, slider-crank")
    c.add_argument("-o", "--output", required=True, help="CSV file to write")
    c.add_argument("--samples", type=int, default=360)
    c.set_defaults(func=_cmd_motion_catalog)
    return p


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point: parse, run, turn user errors into exit status 2."""
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args.func(args) or 0)
    except PlanarError as e:
        print(f"planar: error: {e}", file=sys.stderr)
        return 2
    except (FileNotFoundError, IsADirectoryError, PermissionError) as e:
        print(f"planar: error: {e.filename}: {e.strerror}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:  # pragma: no cover
        return 130


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
