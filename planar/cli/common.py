"""What the commands share: output checks before any work, positive numbers, sheet sizes."""

from __future__ import annotations

import argparse
import math
from collections.abc import Sequence

from planar.errors import InputError

__all__ = ["outputs", "positive", "sheet"]


def outputs(args: argparse.Namespace, inputs: Sequence[str], *specs: tuple[str, str, tuple[str, ...]]) -> None:
    """Check each output ``(option, attribute, suffixes)`` of ``args`` before any work; refuse two alike."""
    from planar.fileio import check_outputs

    check_outputs(((option, getattr(args, attr), suffixes) for option, attr, suffixes in specs), inputs)


def positive(option: str, value: float | None, integer: bool = False) -> None:
    if value is not None and not (math.isfinite(value) and value > 0):
        raise InputError(option, value, "a positive whole number" if integer else "a positive, finite number")


def sheet(text: str) -> tuple[float, float]:
    try:
        w, h = (float(v) for v in text.lower().split("x"))
    except ValueError:
        raise InputError("--sheet", text, "WIDTHxHEIGHT in millimetres, e.g. 300x200") from None
    if not (math.isfinite(w) and math.isfinite(h) and w > 0 and h > 0):
        raise InputError("--sheet", text, "a positive, finite width and height in millimetres")
    return w, h
