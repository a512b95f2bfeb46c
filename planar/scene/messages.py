"""Pydantic's validation errors said in planar's words: the field path as the scene file writes it and what was
expected (``mechanism.nodes.T1.local = [0.0, 0.0, 0.0]: expected at most 2 items (it has 3)``).

Shared by the scene loader (:func:`planar.scene.load.parse_scene`, a :class:`~planar.errors.SceneError` naming the
file) and the specs built directly from Python (``SceneSpec(...)``, an :class:`~planar.errors.InputError` naming
the argument); it imports nothing of the scene room, so :mod:`planar.scene.schema` can use it.
"""

from __future__ import annotations

import re
from typing import Any

__all__ = ["MISSING", "NAME_PATTERN", "child_of", "expected_text", "field_path", "first_problem"]


class _Missing:
    """The value of a field that was not given, shown as ``(missing)`` in a message."""

    def __repr__(self) -> str:
        return "(missing)"


#: the value a message shows for a field that was not given
MISSING = _Missing()

#: a name in a scene (parts, links, nodes, points, polygons): no control characters, commas or double quotes
NAME_PATTERN = r'^[^\x00-\x1f\x7f,"]*$'


def field_path(loc: tuple, data: Any = None) -> str:
    """The field path of a pydantic error location; a list item with a name (a node, a link) is named by it."""
    out = ""
    node = data
    for i, part in enumerate(loc):
        child = child_of(node, part)
        if isinstance(part, int):
            name = child.get("name") if isinstance(child, dict) else None
            named = isinstance(name, str) and re.fullmatch(r"[A-Za-z0-9_\-]+", name) is not None
            out += f".{name}" if named else f"[{part}]"
        elif (
            i == 1
            and loc[0] == "mechanism"
            and part in ("fourbar", "slidercrank", "linkage", "legs", "elemental", "chain", "toy", "catalog", "cam")
        ):
            continue  # the discriminated union's tag
        elif i > 0 and (str(part) in ("float", "int", "str", "bool") or str(part).startswith(("list[", "tuple["))):
            continue  # which member of a union (a number or a list of numbers) pydantic tried
        elif not re.fullmatch(r"[A-Za-z0-9_\-]+", str(part)):
            out += f"[{str(part)!r}]"  # a key with spaces, dots or control characters, shown quoted on one line
        else:
            out += ("." if out else "") + str(part)
        if child is not None:
            node = child
    return out


def child_of(node: Any, part: Any) -> Any:
    """``node[part]`` of the parsed document, or None (a union member's tag is not in the document)."""
    if isinstance(part, int) and isinstance(node, list) and -len(node) <= part < len(node):
        return node[part]
    if isinstance(part, str) and isinstance(node, dict):
        return node.get(part)
    return None


#: pydantic's error types said in planar's words: "FIELD = VALUE: expected ..." (ctx holds the bounds)
_WORDS: dict[str, str] = {
    "missing": "a value here (it is missing)",
    "greater_than": "a number greater than {gt}",
    "greater_than_equal": "a number of at least {ge}",
    "less_than": "a number less than {lt}",
    "less_than_equal": "a number of at most {le}",
    "finite_number": "a finite number",
    "literal_error": "one of {expected}",
    "too_long": "at most {max_length} items (it has {actual_length})",
    "too_short": "at least {min_length} items (it has {actual_length})",
    "float_type": "a number",
    "float_parsing": "a number",
    "int_type": "a whole number (written without a point)",
    "int_parsing": "a whole number (written without a point)",
    "int_from_float": "a whole number (written without a point)",
    "bool_type": "true or false",
    "bool_parsing": "true or false",
    "string_type": "text in double quotes",
    "list_type": "a list [...]",
    "tuple_type": "a list [...]",
    "dict_type": "a table",
    "model_type": "a table",
    "extra_forbidden": "no such key here (a misspelt or misplaced key)",
}


def expected_text(err: Any) -> str:
    """What a pydantic error says was expected, in planar's words."""
    kind = err["type"]
    ctx = err.get("ctx") or {}
    if kind == "string_pattern_mismatch" and ctx.get("pattern") == NAME_PATTERN:
        return "a name without control characters (newline, tab), commas or double quotes"
    if kind in _WORDS:
        try:
            return _WORDS[kind].format(**ctx)
        except (KeyError, IndexError):
            pass
    msg = str(err["msg"]).removeprefix("Value error, ")
    return msg[:1].lower() + msg[1:]


def first_problem(errors: list[Any], data: Any = None) -> tuple[str, Any, str]:
    """``(field, value, expected)`` of the first of pydantic's ``errors`` (``ValidationError.errors()``); ``data``
    is what was validated (a list item with a name is named by it).  The value of a missing item is what holds
    it; of a missing key or a table, the table."""
    first = errors[0]
    loc = tuple(first["loc"])
    where = field_path(loc, data) or "scene"
    got = first.get("input")
    if first["type"] == "missing" and loc and isinstance(loc[-1], int):  # a list of fixed length, too short
        have = data
        for part in loc[:-1]:  # a union member's tag is not in the document: stay where it is
            have = child_of(have, part) if child_of(have, part) is not None else have
        return field_path(loc[:-1], data), have, f"more items (item {loc[-1]} is missing)"
    return where, got, expected_text(first)
