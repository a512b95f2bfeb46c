"""The output formats: a file suffix names the writer module in :mod:`exporters`, imported on first use.

This registry is the one door between planar and its writers (as matplotlib's
backends are named by a string and imported when asked for): nothing else in
planar imports :mod:`exporters`, and a writer's heavy libraries (imageio,
ezdxf, matplotlib) load only when a file of its format is written.

Adding a format is one module in ``exporters/`` plus one entry here.
"""

from __future__ import annotations

import importlib
from types import ModuleType

from planar.errors import InputError

__all__ = ["FORMATS", "suffixes", "writer"]

#: suffix (without the dot) -> (writer module, what it writes)
FORMATS: dict[str, tuple[str, str]] = {
    "gif": ("exporters.gif", "animation, streamed frame by frame"),
    "mp4": ("exporters.video", "animation through ffmpeg (the video extra)"),
    "webm": ("exporters.video", "animation through ffmpeg (the video extra)"),
    "html": ("exporters.html", "animation player: one self-contained page of SVG and JavaScript"),
    "dxf": ("exporters.dxf", "cut sheets for a laser cutter, millimetres"),
    "svg": ("exporters.svg", "cut sheets and the assembly drawing, millimetres"),
    "png": ("exporters.preview", "a photo-like preview of a cut sheet"),
    "bom": ("exporters.bom", "the bill of materials (CSV)"),
    "json": ("exporters.plan", "the assembly plan (plan.json: parts, layers, placements, pins, spacers, motor shaft)"),
}


def suffixes() -> list[str]:
    """The suffixes a writer is registered for, sorted."""
    return sorted(FORMATS)


def writer(suffix: str) -> ModuleType:
    """The writer module for ``suffix`` (``"gif"``, ``".dxf"`` ...), imported now.

    Raises
    ------
    InputError
        For a suffix no writer is registered for, naming it and the known ones.
    """
    key = suffix.lower().lstrip(".") if isinstance(suffix, str) else None
    if key not in FORMATS:
        raise InputError("format", suffix, "one of " + ", ".join(suffixes()))
    return importlib.import_module(FORMATS[key][0])
