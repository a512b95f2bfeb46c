"""A synthesised four-bar as a scene file (TOML) that renders, exports and compares like any other.

The text is built here (no TOML writer is needed for one flat table), then
parsed and built by :mod:`planar.scene.load` before anything is written: a scene
that would not load is an error, never a file.  Floats are written with
``repr`` (shortest round trip), so the file reproduces the design exactly and
the same design gives the same bytes.
"""

from __future__ import annotations

import tomllib
from collections.abc import Sequence
from pathlib import Path
from typing import Any

__all__ = ["fourbar_scene_text", "linkage_scene_text", "write_scene"]


def _f(v: float) -> str:
    return repr(float(v))


def _vec(v: Sequence[float]) -> str:
    return "[" + ", ".join(_f(x) for x in v) + "]"


def fourbar_scene_text(
    name: str,
    ground: float,
    crank: float,
    coupler: float,
    rocker: float,
    coupler_point: Sequence[float],
    circuit: str,
    placement: Sequence[float],
    comments: Sequence[str] = (),
    amplitude: float | None = None,
    centre: float = 0.0,
    samples_per_cycle: int = 72,
    targets: Sequence[Sequence[float]] = (),
    unit_mm: float | None = None,
    trails: Sequence[str] = ("coupler_point",),
) -> str:
    """The scene text of a four-bar (radians); ``amplitude``/``centre`` give a rocking driver; ``trails``: the named
    points whose paths are drawn (none for a function generator, whose coupler point means nothing); ``targets``
    ``[x, y]`` each: fixed points ``planar render`` and ``planar plot`` draw (``[render] targets``);
    ``unit_mm``: what one unit of the targets is in millimetres, written as ``[fabrication] unit_mm`` (none:
    the scene's default, 10; an SVG's user units are millimetres: :func:`planar.synth.targets.target_unit_mm`)."""
    lines = [f"# {c}" for c in comments]
    lines += [
        f"name = {name!r}".replace("'", '"'),
        'angle_unit = "rad"',
        "",
        "[mechanism]",
        'type = "fourbar"',
        f"ground = {_f(ground)}",
        f"crank = {_f(crank)}",
        f"coupler = {_f(coupler)}",
        f"rocker = {_f(rocker)}",
        f"coupler_point = {_vec(coupler_point)}",
        f'circuit = "{circuit}"',
        f"placement = {_vec(placement)}",
        "",
        "[driver]",
        "speed = 1.0",
        "cycles = 1",
        f"samples_per_cycle = {int(samples_per_cycle)}",
    ]
    if amplitude is not None:
        lines += [f"amplitude = {_f(amplitude)}", f"centre = {_f(centre)}"]
    drawn = ", ".join(f'"{t}"' for t in trails)
    lines += ["", "[render]", f"trails = [{drawn}]", *_targets(targets), *_fabrication(unit_mm), ""]
    return "\n".join(lines)


def _fabrication(unit_mm: float | None) -> list[str]:
    """The ``[fabrication]`` table holding ``unit_mm`` (none for ``None``)."""
    if unit_mm is None:
        return []
    from planar.core.fields import check_number

    if not check_number("unit_mm", unit_mm) > 0:
        from planar.errors import InputError

        raise InputError("unit_mm", unit_mm, "a positive number of millimetres per unit")
    return ["", "[fabrication]", f"unit_mm = {_f(unit_mm)}"]


def _targets(targets: Sequence[Sequence[float]]) -> list[str]:
    """The ``[render] targets`` line (none for no targets)."""
    if not len(targets):
        return []
    return ["targets = [" + ", ".join(_vec(p) for p in targets) + "]"]


def _value(v: Any) -> str:
    if isinstance(v, str):
        return '"' + v + '"'
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, (tuple, list)):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    return _f(v)


def linkage_scene_text(
    name: str,
    nodes: Sequence[dict[str, Any]],
    links: Sequence[tuple[str, Sequence[str]]],
    points: dict[str, str],
    comments: Sequence[str] = (),
    samples_per_cycle: int = 72,
    targets: Sequence[Sequence[float]] = (),
    unit_mm: float | None = None,
) -> str:
    """The scene text of a general linkage (``type = "linkage"``; node tables as the scene schema's; ``targets``
    and ``unit_mm`` as :func:`fourbar_scene_text`'s)."""
    lines = [f"# {c}" for c in comments]
    lines += [
        f'name = "{name}"',
        'angle_unit = "rad"',
        "",
        "[mechanism]",
        'type = "linkage"',
        "points = { " + ", ".join(f'{k} = "{v}"' for k, v in points.items()) + " }",
        "",
    ]
    for n in nodes:
        lines.append("[[mechanism.nodes]]")
        lines += [f"{k} = {_value(v)}" for k, v in n.items()]
        lines.append("")
    for lname, lnodes in links:
        lines += ["[[mechanism.links]]", f'name = "{lname}"', f"nodes = {_value(list(lnodes))}", ""]
    lines += [
        "[driver]",
        "speed = 1.0",
        "cycles = 1",
        f"samples_per_cycle = {int(samples_per_cycle)}",
        "",
        "[render]",
        "trails = [" + ", ".join(f'"{k}"' for k in points) + "]",
        *_targets(targets),
        *_fabrication(unit_mm),
        "",
    ]
    return "\n".join(lines)


def write_scene(path: str | Path, text: str) -> Any:
    """Check that ``text`` loads as a scene and builds, then write it atomically; returns the :class:`Scene`."""
    from planar.fileio import atomic_write
    from planar.scene.load import build_scene, parse_scene

    scene = build_scene(parse_scene(tomllib.loads(text), str(path)), str(path))
    with atomic_write(path, "w") as fh:
        fh.write(text)
    return scene
