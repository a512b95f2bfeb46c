"""One progress bar for every long job: shown on a terminal, silent when standard error is piped.

The contract (docs/explanation/contract.md) says long jobs show a progress bar on a terminal and stay
quiet when piped or captured; every bar in planar (render, the synthesis atlas, bench accuracy) comes
from :func:`progress_bar`, so none can forget the rule.  tqdm is imported only when a bar is asked for.
"""

from __future__ import annotations

import sys
from typing import Any

__all__ = ["progress_bar"]


def progress_bar(total: int, desc: str, unit: str, **kw: Any) -> Any:
    """A tqdm bar over ``total`` steps on standard error, disabled unless standard error is a terminal.

    ``desc`` names the job, ``unit`` one step; other keywords go to tqdm.  The bar is removed when it
    closes (``leave=False``).  Returns the bar (a disabled bar still takes ``update`` and ``close``).
    """
    from tqdm import tqdm

    stream = sys.stderr
    try:
        tty = bool(stream.isatty())
    except (AttributeError, ValueError):  # a closed or replaced stream
        tty = False
    kw.setdefault("leave", False)
    return tqdm(total=total, desc=desc, unit=unit, file=stream, disable=not tty, **kw)
