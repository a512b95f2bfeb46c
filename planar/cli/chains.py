"""``planar chains``: motion transfer chains from the motor to an end effector."""

from __future__ import annotations

import argparse
import json
from typing import Any

from planar.cli.common import positive

__all__ = ["add_parser"]


def _cmd_chains(args: argparse.Namespace) -> int:
    from planar.core.limits import check_count
    from planar.windup.table import enumerate_chains

    positive("--max-length", args.max_length, integer=True)
    check_count("chain", "--max-length", args.max_length, "patterns in a chain")
    chains = enumerate_chains(args.target, args.max_length, args.optional)
    if args.json:
        print(json.dumps({k: [list(c) for c in v] for k, v in chains.items()}))
        return 0
    from planar.toys.assembly import assembly_refusal

    for motion, cs in chains.items():
        why = {c: assembly_refusal(c) for c in cs}
        print(f"{motion}: {len(cs)} chains, {sum(w is None for w in why.values())} assemble")
        for c in cs:
            path = " -> ".join([c[0].split("->")[0]] + [p.split("->")[1] for p in c])
            # the second column pastes into a scene; the third says whether render, export and toy can build it
            print(
                f"   {path:<28} chain = {json.dumps(list(c)):<40} "
                + ("assembles" if why[c] is None else f"motion only: {why[c]}")
            )
    return 0


def add_parser(sub: Any) -> None:
    """Add ``planar chains`` to the subcommands ``sub``."""

    ch = sub.add_parser("chains", help="motion transfer chains from the motor (Rz) to an end effector")
    ch.add_argument("target", nargs="?", default=None, help="end-effector motion (Ox, Oy, Oz, Tx, Ty, Tz, OzT)")
    ch.add_argument("--max-length", type=int, default=3, help="longest chain (default 3)")
    ch.add_argument("--optional", action="store_true", help="include the Oy->Oy pattern the printed table lacks")
    ch.add_argument("--json", action="store_true", help='print {"Ox": [["Rz->Tx", "Tx->Ox"], ...], ...}')
    ch.set_defaults(func=_cmd_chains)
