"""Verdicts on scenes a new user wrote: the torque scale, the search's verdicts and messages, the hints."""

from pathlib import Path

import numpy as np
import pytest

from planar.physics.run import torque_scale
from planar.physics.simulate import torque_comparison
from planar.scene.load import load_scene

SCENES = Path(__file__).resolve().parent / "scenes"


def test_torque_scale_ignores_the_change_points():
    # at a parallelogram's change points the differenced rates are singular: they must not set the scale,
    # so that a torque off by more than its peak is reported as such
    scene = load_scene(SCENES / "parallelogram-motor.toml")
    mech = scene.mechanism
    t = scene.motion().t
    tc = torque_comparison(mech, t, scene.effects)
    assert np.isfinite(tc["scale"]) and tc["scale"] >= tc["peak"] > 0
    # the inertial and gravity terms, each alone, ask a few times the net peak, not thousands
    assert tc["scale"] < 10 * tc["peak"], (tc["scale"], tc["peak"])
    assert tc["max_rel_diff"] == pytest.approx(tc["max_abs_diff"] / tc["scale"])
    # it is the scale measured between the change points
    assert torque_scale(mech, t[5:26], scene.effects) == pytest.approx(tc["scale"], rel=1e-6)
