"""The ``planar`` console script: import the command line, run it, exit with its status.

A Ctrl-C while the command line's modules import (before :func:`planar.cli.main.main` can
catch it) exits 130 with one line, as it does once the command runs.
"""

from __future__ import annotations

import sys


def run() -> None:
    """Run ``planar`` with ``sys.argv``; exit 130 quietly on a Ctrl-C during start-up.

    Raises
    ------
    SystemExit
        Always: the command's exit status, or 130 when interrupted while importing.
    """
    try:
        from planar.cli.main import main
    except KeyboardInterrupt:  # Ctrl-C while importing: nothing has been written yet
        print("planar: interrupted (no output written)", file=sys.stderr)
        raise SystemExit(130) from None
    raise SystemExit(main())
