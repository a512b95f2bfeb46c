"""A mechanism built in Python as a scene: its ``[mechanism]`` table, the whole scene, and TOML out.

:func:`mechanism_table` turns a :class:`~planar.linkages.FourBar`,
:class:`~planar.linkages.SliderCrank`, :class:`~planar.linkages.Linkage`,
:class:`~planar.windup.ElementalMechanism` or
:class:`~planar.windup.chain.ToyMechanism` into the scene keys that rebuild it;
:func:`scene_data` the whole scene's keys, which
:func:`planar.scene.load.scene_from_mechanism` validates and builds into a
:class:`~planar.scene.load.Scene` (the mechanism rebuilt from those keys, so what is
saved is what runs);
:func:`write_scene` writes a scene's keys as TOML (``Scene.save``).  Angles
are written in radians.  What a scene file cannot say is refused with a
one-line :class:`~planar.errors.InputError`, never dropped: a linkage with a custom part width or pin
diameter, a node kind without scene keys.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Mapping
from dataclasses import fields
from typing import TYPE_CHECKING, Any

import numpy as np

from planar.errors import InputError

if TYPE_CHECKING:
    from planar.core.model import Mechanism
    from planar.linkages import Linkage
    from planar.scene.schema import SceneSpec

__all__ = ["driver_table", "mechanism_table", "scene_data", "scene_toml", "write_scene"]


def _f(v: Any) -> Any:
    if isinstance(v, (tuple, list, np.ndarray)):
        return [_f(x) for x in v]
    if isinstance(v, (bool, np.bool_)):
        return bool(v)
    if isinstance(v, (int, np.integer)):
        return int(v)
    if isinstance(v, (float, np.floating)):
        return float(v)
    return v


def _placement(mech: Linkage) -> list[float]:
    return [float(x) for x in mech.placement]


def mechanism_table(mech: Mechanism) -> dict[str, Any]:
    """The ``[mechanism]`` table that rebuilds ``mech`` (angles in radians)."""
    from planar.linkages import RRP, FourBar, Linkage, SliderCrank
    from planar.windup import ElementalMechanism, params_for
    from planar.windup.chain import ToyMechanism

    if isinstance(mech, FourBar):
        g = mech.dims
        return {
            "type": "fourbar",
            "ground": g.d,
            "crank": g.a,
            "coupler": g.b,
            "rocker": g.c,
            "coupler_point": list(mech.coupler_point),
            "circuit": mech.circuit,
            "placement": _placement(mech),
        }
    if isinstance(mech, SliderCrank):
        branch = next(int(n.branch) for n in mech.nodes if isinstance(n, RRP))
        return {
            "type": "slidercrank",
            "crank": mech.r,
            "rod": mech.l,
            "offset": mech.e,
            "branch": branch,
            "placement": _placement(mech),
        }
    if isinstance(mech, Linkage):
        span = mech._span()
        if not (math.isclose(mech.width, 0.08 * span) and math.isclose(mech.pin_diameter, 0.03 * span)):
            raise InputError(
                f"{mech.name}.width",
                (mech.width, mech.pin_diameter),
                "the default part width and pin diameter (a scene file cannot set them)",
            )
        nodes = []
        for n in mech.nodes:
            row: dict[str, Any] = {"name": n.name, "kind": n.kind}
            for key, fld in zip(n.scene_fields, [f.name for f in fields(n)][1:]):  # type: ignore[arg-type]
                row[key] = _f(getattr(n, fld))
            nodes.append(row)
        links = []
        for lk in mech.links:
            if lk.name == mech.ground_name and lk.nodes == tuple(n.name for n in mech.nodes if n.kind == "fixed"):
                continue  # the default ground
            row = {"name": lk.name, "nodes": list(lk.nodes)}
            if lk.guide is not None:
                row["guide"] = list(lk.guide)
            links.append(row)
        return {
            "type": "linkage",
            "nodes": nodes,
            "links": links,
            "points": dict(mech.point_nodes),
            "placement": _placement(mech),
        }
    if isinstance(mech, ElementalMechanism):
        base = params_for(mech.number)
        changed = {
            f.name: _f(getattr(mech.params, f.name))
            for f in fields(mech.params)
            if getattr(mech.params, f.name) != getattr(base, f.name)
        }
        return {"type": "elemental", "number": mech.number, "params": changed}
    if isinstance(mech, ToyMechanism):
        table: dict[str, Any] = {"type": "toy", "phase": mech.phase}
        for cam, chains in mech.cams.items():
            table[cam] = [list(c) for c in chains]
        given = getattr(mech, "stage_overrides", {})
        rebuilt = ToyMechanism(mech.cams, phase=mech.phase, rate=mech.driver.rate, name=mech.name, overrides=given)
        for a, b in zip(mech.stages, rebuilt.stages):
            if a.mech.params != b.mech.params:
                raise InputError(
                    f"{mech.name}.stage {' '.join(a.key)}",
                    a.mech.params,
                    "a stage whose parameters the toy recorded (ToyMechanism overrides)",
                )
        stages: dict[tuple[str, tuple[str, ...]], dict[str, Any]] = {}
        for (cam, key), kw in given.items():
            stages[(cam, key)] = {"cam": cam, "chain": list(key), "params": {k: _f(v) for k, v in kw.items()}}
        for (cam, key), n in getattr(mech, "names", {}).items():
            stages.setdefault((cam, key), {"cam": cam, "chain": list(key)})["name"] = n
        if stages:
            table["stages"] = list(stages.values())
        return table
    raise InputError(
        "mechanism",
        type(mech).__name__,
        "a FourBar, SliderCrank, Linkage, ElementalMechanism or ToyMechanism (those a scene describes)",
    )


def driver_table(mech: Mechanism) -> dict[str, Any]:
    """The ``[driver]`` keys of ``mech``'s driver law (``speed``, ``phase``, a rocking input's ``amplitude`` and
    ``centre``), radians."""
    from planar.linkages import Linkage
    from planar.windup.chain import ToyMechanism

    d = mech.driver
    out: dict[str, Any] = {"speed": d.rate / (2 * math.pi)}
    if isinstance(mech, Linkage):
        out["phase"] = d.phase
        if d.amplitude is not None:
            out["amplitude"], out["centre"] = d.amplitude, d.centre
    elif not isinstance(mech, ToyMechanism):  # elemental: the phase; its rocking amplitude is a parameter
        out["phase"] = d.phase
    return out


def scene_data(
    mech: Mechanism,
    name: str | None = None,
    driver: Mapping[str, Any] | None = None,
    effects: Mapping[str, Any] | None = None,
    render: Mapping[str, Any] | None = None,
    fabrication: Mapping[str, Any] | None = None,
    polygons: Mapping[str, tuple[str, Any]] | None = None,
) -> dict[str, Any]:
    """The scene keys (a dict, as parsed TOML) of a mechanism built in Python, with optional ``[driver]``
    (e.g. ``samples_per_cycle``, ``cycles``), ``[effects]``, ``[render]`` and ``[fabrication]`` keys and
    swept ``polygons`` (name -> (part, points)).
    """
    table = mechanism_table(mech)
    if polygons:
        if table["type"] not in ("fourbar", "slidercrank", "linkage"):
            raise InputError("polygons", list(polygons), f"no polygons on a {table['type']!r} mechanism")
        table["polygons"] = [{"name": k, "part": p, "points": _f(np.asarray(pts, float))} for k, (p, pts) in polygons.items()]
    data: dict[str, Any] = {
        "name": name or mech.name,
        "angle_unit": "rad",
        "mechanism": table,
        "driver": {**driver_table(mech), **dict(driver or {})},
    }
    for key, extra in (("effects", effects), ("render", render), ("fabrication", fabrication)):
        if extra:
            data[key] = _f(dict(extra))
    return data


# --------------------------------------------------------------------------- TOML out


def _value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if not math.isfinite(v):
            raise InputError("scene value", v, "a finite number")
        return repr(v)
    if isinstance(v, str):
        return json.dumps(v, ensure_ascii=False)
    if isinstance(v, list):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{ " + ", ".join(f"{_key(k)} = {_value(x)}" for k, x in v.items()) + " }" if v else "{}"
    raise InputError("scene value", v, "a number, string, boolean, list or table")


def _key(k: str) -> str:
    return k if k.replace("_", "").replace("-", "").isalnum() and k.isascii() else json.dumps(k)


def _table(path: str, d: Mapping[str, Any], lines: list[str]) -> None:
    subs: list[tuple[str, Any, bool]] = []
    for k, v in d.items():
        if isinstance(v, dict) and v:
            subs.append((k, v, False))
        elif isinstance(v, list) and v and all(isinstance(x, dict) for x in v) and path == "mechanism":
            subs.append((k, v, True))
        else:
            lines.append(f"{_key(k)} = {_value(v)}")
    for k, v, many in subs:
        sub = f"{path}.{_key(k)}" if path else _key(k)
        if many:
            for row in v:
                lines.append("")
                lines.append(f"[[{sub}]]")
                _table(sub, row, lines)
        else:
            lines.append("")
            lines.append(f"[{sub}]")
            _table(sub, v, lines)


def scene_toml(spec: SceneSpec) -> str:
    """A scene's keys as TOML text: the keys it was given (defaults left out), tables in schema order."""
    from planar.scene.schema import SceneSpec

    if not isinstance(spec, SceneSpec):
        raise InputError("spec", spec, "a SceneSpec (Scene.spec, or planar.scene.parse_scene of a table)")
    data = spec.model_dump(mode="json", exclude_unset=True, exclude_none=True)
    data.setdefault("mechanism", {})["type"] = spec.mechanism.type
    top = {k: v for k, v in data.items() if not isinstance(v, dict)}
    lines: list[str] = []
    _table("", top, lines)
    for k in ("mechanism", "driver", "effects", "render", "fabrication"):
        if k in data and (data[k] or k == "mechanism"):
            lines.append("")
            lines.append(f"[{k}]")
            _table(k, data[k], lines)
    return "\n".join(lines).lstrip("\n") + "\n"


def write_scene(spec: SceneSpec, path: str | os.PathLike[str]) -> None:
    """Write ``spec`` to ``path`` as a scene file (atomically; ``planar.scene.load.load_scene`` reads it back)."""
    from planar.fileio import atomic_write, check_output

    if path is None:
        raise InputError("path", None, "a file name ending in .toml")
    check_output("path", path, (".toml",))  # TOML never goes into s.csv
    text = scene_toml(spec)
    with atomic_write(path, "w") as fh:
        fh.write(text)
