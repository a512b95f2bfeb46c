"""Scene files: one TOML file describes a mechanism, its driver, effects, drawing and fabrication.

This module reads and validates a file; :mod:`planar.scene.schema` holds the keys and
:mod:`planar.scene.build` the mechanism built from them.

Validated with pydantic: unknown keys are errors, and every error names the
file, the field path, the bad value and what was expected, on one line
(:class:`planar.SceneError`).  ``planar schema`` prints the JSON schema
(committed as ``gallery/scene.schema.json``).

Angles are radians unless the scene says ``angle_unit = "deg"``; lengths are
model units (``[fabrication] unit_mm`` says what one unit is in millimetres).
"""

from __future__ import annotations

import tomllib
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from pydantic import ValidationError

from planar.core.model import Mechanism
from planar.errors import InputError, SceneError
from planar.scene.build import Scene, build_scene
from planar.scene.messages import child_of as _child
from planar.scene.messages import expected_text as _expected
from planar.scene.messages import field_path as _loc
from planar.scene.schema import SceneSpec, scene_schema

__all__ = ["Scene", "SceneSpec", "build_scene", "load_scene", "parse_scene", "scene_from_mechanism", "scene_schema"]


# --------------------------------------------------------------------------- loading


def _format_validation(path: str, e: ValidationError, data: Any = None) -> str:
    errs = e.errors(include_url=False)
    first = errs[0]
    where = _loc(tuple(first["loc"]), data) or "scene"
    got = first.get("input")
    loc = tuple(first["loc"])
    if first["type"] == "missing" and loc and isinstance(loc[-1], int):  # a list of fixed length, too short
        owner = _loc(loc[:-1], data)
        have = data
        for part in loc[:-1]:  # a union member's tag is not in the document: stay where it is
            have = _child(have, part) if _child(have, part) is not None else have
        text = f"{path}: {owner} = {have!r}: expected more items (item {loc[-1]} is missing)"
    elif first["type"] == "missing" or isinstance(got, dict):
        text = f"{path}: {where}: expected {_expected(first)}"
    else:
        text = f"{path}: {where} = {got!r}: expected {_expected(first)}"
    if len(errs) > 1:
        text += f" (and {len(errs) - 1} more problem{'s' if len(errs) > 2 else ''})"
    return text


def parse_scene(data: dict[str, Any], path: str = "<scene>") -> SceneSpec:
    """Validate a scene given as a dict (a parsed TOML document)."""
    try:
        return SceneSpec.model_validate(data)
    except ValidationError as e:
        raise SceneError(_format_validation(path, e, data)) from None


def _read_text(p: str) -> str:
    """The scene file as text: UTF-8 (a UTF-8 byte-order mark is skipped) or UTF-16 with its byte-order mark."""
    try:
        with open(p, "rb") as fh:
            raw = fh.read(64 * 2**20 + 1)
    except FileNotFoundError:
        raise SceneError(f"{p}: no such file") from None
    except IsADirectoryError:
        raise SceneError(f"{p}: is a directory, not a scene file") from None
    except OSError as e:  # a loop of symbolic links, no permission, a device
        raise SceneError(f"{p}: cannot be read ({e.strerror or e})") from None
    if len(raw) > 64 * 2**20:
        raise SceneError(f"{p}: larger than 64 MiB; a scene file is a short TOML text")
    codec = "utf-16" if raw[:2] in (b"\xff\xfe", b"\xfe\xff") else "utf-8-sig"
    try:
        text = raw.decode(codec)
    except UnicodeDecodeError as e:
        raise SceneError(
            f"{p}: not a text file in UTF-8 (or UTF-16 with a byte-order mark): byte {e.start} is {raw[e.start : e.start + 1]!r}"
        ) from None
    text = text.removeprefix("\ufeff")  # a byte-order mark some editors repeat inside the text
    if "\x00" in text:
        raise SceneError(f"{p}: not a text file (it holds NUL bytes); a scene is TOML text")
    return text


def load_scene(path: str | Path) -> Scene:
    """Read, validate and build the scene in ``path`` (UTF-8, or UTF-16 with a byte-order mark)."""
    if not isinstance(path, (str, Path)) and not hasattr(path, "__fspath__"):
        raise InputError("load_scene(path)", path, "a path to a scene file (a string or a pathlib.Path)")
    p = str(path)
    text = _read_text(p)
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise SceneError(f"{p}: not valid TOML: {' '.join(str(e).split())}") from None
    return build_scene(parse_scene(data, p), p)


#: the keyword tables of :func:`scene_from_mechanism` (the arguments of :func:`planar.scene.write.scene_data`)
_TABLES = ("name", "driver", "effects", "render", "fabrication", "polygons")


def scene_from_mechanism(mech: Mechanism, **tables: Any) -> Scene:
    """A :class:`~planar.scene.load.Scene` of a mechanism built in Python, validated like a scene file.

    ``tables`` (see :func:`planar.scene.write.scene_data`): ``name``, ``driver``,
    ``effects``, ``render``, ``fabrication`` (dicts of scene keys) and
    ``polygons``; ``scene.save(path)`` writes it as a scene file.  The
    scene's mechanism is rebuilt from the keys: what is saved is what runs.
    """
    from planar.scene.write import scene_data

    if not isinstance(mech, Mechanism):
        raise InputError("mech", mech, "a Mechanism (FourBar, Linkage, ...)")
    for key, table in tables.items():
        if key not in _TABLES:
            raise InputError(key, table, f"one of the scene tables {', '.join(_TABLES)}")
        if key != "name" and table is not None and not isinstance(table, Mapping):
            raise InputError(key, table, "a dict of the scene table's keys")
    where = f"<{type(mech).__name__} {mech.name!r}>"
    return build_scene(parse_scene(scene_data(mech, **tables), where), where)
