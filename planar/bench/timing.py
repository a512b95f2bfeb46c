"""Timing helpers the benchmarks share: best-of timing and a one-line description of the machine."""

from __future__ import annotations

import math
import os
import time
from collections.abc import Callable
from typing import Any

__all__ = ["_best_time", "_machine"]


def _best_time(fn: Callable[[], Any], repeats: int) -> float:
    best = math.inf
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def _machine() -> str:
    """The machine a benchmark ran on: architecture, processor, cores, Python."""
    import platform

    return (
        f"{platform.machine()} {platform.processor() or ''} {os.cpu_count()} cores, Python {platform.python_version()}"
    ).replace("  ", " ")
