"""Benchmarks a user can run (``planar bench NAME``), each against a peer measured in the same run.

Results are ratios measured on the machine at hand, never hard-coded targets.
Each benchmark is one module here with a ``bench_NAME`` function (keyword
options, a dict of results) and a ``format_NAME`` function (the dict as text);
:data:`BENCHMARKS` names them, and :func:`benchmark` imports one on use, so
``planar --help`` loads none of them.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from typing import Any

__all__ = ["BENCHMARKS", "benchmark"]

#: benchmark name -> its module (``bench_<name>`` and ``format_<name>`` live there)
BENCHMARKS: dict[str, str] = {
    "kinematics": "planar.bench.kinematics",
    "render": "planar.bench.render",
    "accuracy": "planar.bench.accuracy",
    "sim": "planar.bench.sim",
    "synthesis": "planar.bench.synthesis",
}


def benchmark(name: str) -> tuple[Callable[..., dict[str, Any]], Callable[[dict[str, Any]], str]]:
    """The ``(run, format)`` functions of benchmark ``name``, imported now."""
    if not isinstance(name, str) or name not in BENCHMARKS:
        from planar.errors import InputError

        raise InputError("benchmark", name, "one of " + ", ".join(BENCHMARKS))
    mod = importlib.import_module(BENCHMARKS[name])
    return getattr(mod, f"bench_{name}"), getattr(mod, f"format_{name}")
