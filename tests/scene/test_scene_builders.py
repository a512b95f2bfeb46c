"""Every scene mechanism table has its builder in scene.build.BUILDERS; the elemental numbers come from the records."""

from __future__ import annotations

import typing

import pytest

from planar.core.registry import UnsupportedError
from planar.scene import schema
from planar.scene.build import BUILDERS, _build
from planar.windup.mechanisms import ELEMENTAL
from planar.windup.sizing import DESIGN_PARAMETER


def test_every_mechanism_table_type_has_a_builder() -> None:
    union = typing.get_args(typing.get_args(schema.MechanismSpec)[0])
    assert union, "MechanismSpec is no longer a union of table types"
    assert set(union) == set(BUILDERS.kinds())


def test_a_table_type_without_a_builder_is_refused_by_name() -> None:
    class OddSpec:
        type = "odd"

    with pytest.raises(UnsupportedError, match="OddSpec"):
        _build(schema.SceneSpec.model_validate({"mechanism": {"type": "catalog", "name": "jansen"}}), OddSpec(), 1.0, 0.0, {})


def test_elemental_numbers_come_from_the_records() -> None:
    numbers = sorted(ELEMENTAL)
    assert numbers == list(range(1, len(numbers) + 1))
    field = schema.ElementalSpec.model_fields["number"]
    bounds = [(getattr(m, "ge", None), getattr(m, "le", None)) for m in field.metadata]
    assert (1, numbers[-1]) in bounds or ((1, None) in bounds and (None, numbers[-1]) in bounds), bounds
    assert sorted(DESIGN_PARAMETER) == numbers
