"""Mechanisms written as a user would (tests/physics/scenes), each with its true verdict at the defaults."""

from pathlib import Path

import pytest

from planar.physics.compare import compare_scene
from planar.scene.load import load_scene

SCENES = Path(__file__).resolve().parent / "scenes"


@pytest.mark.slow
@pytest.mark.parametrize("name", ["six-bar-slider", "jansen-walker", "crank-shaper", "constant-speed-slider"])
def test_correct_mechanisms_pass_within_1e_4_of_size(name):
    scene = load_scene(SCENES / f"{name}.toml")
    if name == "jansen-walker":
        assert len(scene.mechanism.parts) >= 20
    r, sim = compare_scene(scene, motor=True)
    assert r.passed, r.problems()
    assert r.max_rel_error < 1e-4, r.max_rel_error
    assert r.search.verdict == "pass" and r.torque_search.verdict == "pass"
    assert r.torque["samples_compared"] == len(sim.motion) - 1
    assert r.torque["max_rel_diff"] < 0.01


@pytest.mark.slow
def test_a_zero_torque_mechanism_is_judged_on_its_own_scale():
    # a block carried round at a constant radius: the true torque is zero, the reference's peak round-off
    r, _ = compare_scene(load_scene(SCENES / "constant-speed-slider.toml"))
    t = r.torque
    assert t is not None  # the scene names a motor
    assert t["peak"] < 1e-6 * t["scale"]  # the 'peak' is round-off ...
    assert t["max_rel_diff"] < 1e-3 and r.passed  # ... and is not what the difference is measured against


@pytest.mark.slow
def test_the_parallelogram_names_its_change_point():
    r, sim = compare_scene(load_scene(SCENES / "parallelogram.toml"))
    assert not r.passed
    assert r.search.verdict == "change-point"
    assert sim.failure is not None and sim.failure.kind == "change-point"
    (line,) = [p for p in r.problems() if "change point" in p]
    assert "at sample 0" in line  # the crank starts along the ground: all four pivots in line
