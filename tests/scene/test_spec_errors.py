"""Issue 26: a scene spec built directly from Python (``SceneSpec(...)``) refuses a bad value with an
:class:`~planar.errors.InputError` naming the field as a scene file writes it and the value (before, pydantic's
``ValidationError`` escaped); validating a document still gives the loader's :class:`~planar.errors.SceneError`
naming the file, with the same words."""

from __future__ import annotations

import math
from typing import Any

import pytest

from planar.errors import InputError, SceneError
from planar.scene import SceneSpec, parse_scene

FOURBAR = {"type": "fourbar", "ground": 4.0, "crank": 1.0, "coupler": 4.0, "rocker": 3.0}


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({}, r"^SceneSpec\.mechanism = \(missing\): expected a value here"),
        ({"mechanism": "x"}, r"^SceneSpec\.mechanism = 'x': expected"),
        ({"mechanism": {**FOURBAR, "ground": -1.0}}, r"^SceneSpec\.mechanism\.ground = -1\.0: expected a number greater than 0"),
        ({"mechanism": FOURBAR, "name": None}, r"^SceneSpec\.name = None: expected text"),
        ({"mechanism": FOURBAR, "angle_unit": "grad"}, r"^SceneSpec\.angle_unit = 'grad': expected one of 'rad' or 'deg'"),
        ({"mechanism": FOURBAR, "driver": math.nan}, r"^SceneSpec\.driver = nan: expected a table"),
        ({"mechanism": FOURBAR, "driver": {"speed": math.inf}}, r"^SceneSpec\.driver\.speed = inf: expected"),
        ({"mechanism": FOURBAR, "render": {"width": "480"}}, r"^SceneSpec\.render\.width = '480': expected a whole number"),
        ({"mechanism": FOURBAR, "fabrication": [1]}, r"^SceneSpec\.fabrication = \[1\]: expected a table"),
        ({"mechanism": FOURBAR, "effects": {"gravity": [0, "x"]}}, r"^SceneSpec\.effects\.gravity"),
        ({"mechanism": FOURBAR, "colour": 1}, r"^SceneSpec\.colour = 1: expected no such key here"),
    ],
)
def test_a_spec_built_from_python_names_the_field_and_value(kwargs: dict[str, Any], message: str) -> None:
    with pytest.raises(InputError, match=message):
        SceneSpec(**kwargs)


def test_a_valid_spec_builds_and_the_loader_keeps_its_words() -> None:
    assert SceneSpec(mechanism=FOURBAR).mechanism.type == "fourbar"
    with pytest.raises(SceneError, match=r"^s\.toml: mechanism\.ground = -1\.0: expected a number greater than 0"):
        parse_scene({"mechanism": {**FOURBAR, "ground": -1.0}}, "s.toml")
    with pytest.raises(SceneError, match=r"^s\.toml: mechanism: expected a value here"):
        parse_scene({}, "s.toml")
