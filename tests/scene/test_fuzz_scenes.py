"""Issue 13: a fuzzer mutating the gallery's scenes accepts no exception but planar's own.

Each example takes a gallery scene, changes one thing (a value's type, a
number to an extreme, a vector's length, a key removed or an unknown key
added) and runs it through validation, building and the motion.  The only
acceptable failure is a :class:`planar.errors.PlanarError` whose message is
one line; anything else (TypeError, IndexError, OverflowError, ...) fails.
A motion that comes back has finite numbers wherever it says ``valid``.
Bounded: a fixed number of examples, samples capped by ``PLANAR_MAX_SAMPLES``.
"""

from __future__ import annotations

import copy
import math
import tomllib
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from planar.errors import PlanarError
from planar.scene.load import build_scene, parse_scene

GALLERY = Path(__file__).resolve().parents[2] / "gallery"
SCENES = {p.stem: tomllib.loads(p.read_text()) for p in sorted(GALLERY.glob("*.toml"))}


def _leaves(d: Any, path: tuple = ()) -> list[tuple]:
    """Paths to every value (dict keys and list indices), containers included."""
    out = [path] if path else []
    if isinstance(d, dict):
        for k, v in d.items():
            out += _leaves(v, path + (k,))
    elif isinstance(d, list):
        for i, v in enumerate(d):
            out += _leaves(v, path + (i,))
    return out


def _get(d: Any, path: tuple) -> Any:
    for p in path:
        d = d[p]
    return d


numbers = st.one_of(
    st.integers(-(10**20), 10**20),
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from([0.0, -0.0, 1e-320, 1e308, -1e308, 1e154, 1e-170, 2.0**53]),
)
values = st.one_of(
    numbers,
    st.booleans(),
    st.text(max_size=6),
    st.none(),
    st.lists(numbers, max_size=4),
    st.dictionaries(st.text(max_size=3), numbers, max_size=2),
)


@st.composite
def mutated(draw: st.DrawFn) -> tuple[str, dict]:
    name = draw(st.sampled_from(sorted(SCENES)))
    data = copy.deepcopy(SCENES[name])
    paths = _leaves(data)
    path = draw(st.sampled_from(paths))
    parent = _get(data, path[:-1])
    old = parent[path[-1]]
    kind = draw(st.sampled_from(["value", "value", "number", "vector", "delete", "unknown"]))
    if kind == "delete":
        del parent[path[-1]]
    elif kind == "unknown":
        target = parent if isinstance(parent, dict) else data
        target[draw(st.text(min_size=1, max_size=5))] = draw(values)
    elif kind == "vector" and isinstance(old, list):
        n = draw(st.integers(0, len(old) + 2))
        parent[path[-1]] = (old * 3)[:n]
    elif kind == "number":
        parent[path[-1]] = draw(numbers)
    else:
        parent[path[-1]] = draw(values)
    return name, data


def _none_to_missing(d: Any) -> Any:
    """TOML has no null: a None becomes a missing key (in a list, the string "null")."""
    if isinstance(d, dict):
        return {k: _none_to_missing(v) for k, v in d.items() if v is not None}
    if isinstance(d, list):
        return [("null" if v is None else _none_to_missing(v)) for v in d]
    return d


@settings(
    max_examples=250,
    deadline=None,
    derandomize=True,
    database=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much],
)
@given(mutated())
def test_mutated_gallery_scenes_fail_only_with_planar_errors(case: tuple[str, dict]) -> None:
    name, data = case
    data = _none_to_missing(data)
    mp = pytest.MonkeyPatch()
    mp.setenv("PLANAR_MAX_SAMPLES", "4000")
    try:
        with warnings.catch_warnings(), np.errstate(all="ignore"):
            warnings.simplefilter("ignore")
            scene = build_scene(parse_scene(data, f"{name}.toml"), f"{name}.toml")
            motion = scene.motion()
    except PlanarError as e:
        assert "\n" not in str(e).strip(), str(e)
        return
    finally:
        mp.undo()
    ok = motion.valid
    for arr in (*motion.poses.values(), *motion.points.values()):
        assert np.isfinite(arr[ok]).all()
        assert np.isfinite(arr).all()  # invalid samples hold finite numbers too, never NaN


def test_fuzzer_mutations_reach_every_scene() -> None:
    assert len(SCENES) >= 10 and all(_leaves(d) for d in SCENES.values())
    assert math.isfinite(float(len(SCENES)))
