"""Verdicts on scenes a new user wrote: the torque scale, the search's verdicts and messages, the hints."""

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from planar.physics.compare import compare_scene
from planar.physics.converge import converge
from planar.physics.run import torque_scale
from planar.physics.settings import DEFAULT_SETTINGS
from planar.physics.simulate import torque_comparison
from planar.scene.load import load_scene

SCENES = Path(__file__).resolve().parent / "scenes"


@pytest.mark.slow
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


def _budgets(results):
    """A run whose outcome per budget is given as (cause, sample, error, progress); the last repeats."""
    seen = []

    def run(st):
        seen.append(st)
        return results[min(len(seen) - 1, len(results) - 1)]

    def outcome(r):
        return r[0], r[1], r[2], {"progress": r[3]}

    return run, outcome, seen


def test_differs_needs_the_error_to_stop_shrinking():
    # the parallelogram's motor run near its change point: the torque error wanders while the pose error
    # halves with each budget: the solver limits it, not the mechanism, and a larger budget passes
    errors = [(3.09, 2.6e-4), (1.54, 1.6e-4), (0.389, 9.9e-5), (0.485, 3.7e-5), (0.374, 1.8e-5)]
    run, outcome, seen = _budgets([("constraint", 71, e, p) for e, p in errors] + [(None, 71, 0.0, 0.0)])
    _, s = converge(run, outcome, DEFAULT_SETTINGS)
    assert s.verdict == "pass", s.line()
    # the same errors with nothing shrinking: the mechanism differs, said after three budgets
    run, outcome, seen = _budgets([("constraint", 71, 0.4, 1e-4)])
    _, s = converge(run, outcome, DEFAULT_SETTINGS)
    assert s.verdict == "differs" and len(seen) == 3 and "3 budgets agree" in s.line()


def test_the_search_names_the_limit_that_stopped_it():
    # every budget still improves: the tries run out long before the time cap
    run, outcome, seen = _budgets([("constraint", 71, 2.0**-k, 2.0**-k) for k in range(10)])
    _, s = converge(run, outcome, DEFAULT_SETTINGS, cap_s=1e9)
    line = s.line()
    assert s.verdict == "unconverged" and s.stopped == "tries"
    assert "within" not in line and f"gave up after {len(seen)} tries" in line
    assert f"up to {max(st.iterations for st in seen)} iterations" in line and "s CPU" in line
    assert f"--iterations {2 * seen[-1].iterations}" in line  # the budget it would have tried next
    # the time cap, when it is what stops it, is named as such
    run, outcome, seen = _budgets([("constraint", 71, 2.0**-k, 2.0**-k) for k in range(10)])
    _, s = converge(run, outcome, DEFAULT_SETTINGS, cap_s=0.0)
    assert s.stopped == "time" and "could not converge within 0 s CPU" in s.line()


@pytest.mark.slow
def test_the_parallelogram_motor_run_is_not_called_different():
    scene = load_scene(SCENES / "parallelogram-phase.toml")
    r, _ = compare_scene(scene)
    s = r.torque_search
    assert s.verdict != "differs", s.line()
    if s.verdict == "unconverged":
        # its hint, applied, converges
        assert s.next_settings is not None and f"--iterations {s.next_settings.iterations}" in s.line()
        r2, _ = compare_scene(scene, replace(DEFAULT_SETTINGS, iterations=s.next_settings.iterations))
        assert r2.torque_search.verdict == "pass" and r2.torque["max_rel_diff"] < 0.01, r2.problems()


@pytest.mark.slow
def test_a_saturated_motor_gets_its_own_hint_only():
    from planar.analysis.dynamics import part_mass_table

    scene = load_scene(SCENES / "shaper-saturated.toml")
    r, _ = compare_scene(scene)
    text = "\n".join(r.problems())
    assert r.torque["saturated"] and "motor saturated" in text
    assert "--iterations" not in text and "--substeps" not in text  # no budget helps a motor at its limit
    assert r.torque_search.verdict == "saturated"
    # the part to lighten is the heaviest moving one of this mechanism (it has no coupler)
    ground = {p.name for p in scene.mechanism.parts if p.ground}
    masses = {k: v[0] for k, v in part_mass_table(scene.mechanism, scene.effects).items() if k not in ground}
    assert f"a lighter {max(masses, key=lambda k: masses[k])!r}" in text
    assert "coupler" not in text and "coupler" not in {p.name for p in scene.mechanism.parts}


@pytest.mark.slow
def test_the_imposed_crank_has_no_error_after_a_branch_switch():
    # the kinematic parallelogram takes the other assembly at its change point; the crank is imposed
    from planar.physics.compare import compare
    from planar.physics.simulate import simulate

    scene = load_scene(SCENES / "parallelogram.toml")
    motion = scene.motion()
    sim = simulate(scene.mechanism, motion.t, scene.effects)
    assert sim.failure is not None
    r = compare(scene.mechanism, motion, sim.motion)
    crank = next(p for p in r.parts if p.part == "crank")
    assert crank.max_angle_error < 1e-9 and crank.max_rel_error < 1e-9 and crank.first_over is None
    assert any(f"compared up to sample {sim.failure.sample}" in n for n in r.notes)
    assert not r.passed  # the parts that did switch still fail


@pytest.mark.slow
def test_json_describes_both_runs():
    import json
    import re
    import subprocess
    import sys

    out = subprocess.run(
        [sys.executable, "-m", "planar", "compare", str(SCENES / "parallelogram-motor.toml"), "--json"],
        capture_output=True,
        text=True,
        check=False,
    )
    assert out.returncode in (0, 3), out.stderr
    d = json.loads(out.stdout)
    assert set(d["search"]) == {"kinematic", "motor"}
    for run in ("kinematic", "motor"):
        assert d["search"][run]["verdict"] and d["search"][run]["tried"] and d["search"][run]["line"]
    # the note names the keys it refers to as they are spelled in the same table
    named = re.findall(r"'(\w+)'", d["torque"]["note"])
    assert named and all(k in d["torque"] for k in named), named
    assert "motor" in d["built"]["mode"] and "kinematic" in d["built"]["mode"]
    assert d["built"]["motor"]["iterations"] == d["torque"]["iterations"]


@pytest.mark.slow
def test_a_crank_that_cannot_turn_is_refused_with_what_to_change():
    import re
    import tomllib

    from planar.physics.settings import SimulationError
    from planar.physics.simulate import simulate_scene
    from planar.scene.load import build_scene, parse_scene

    path = SCENES / "nongrashof-deg.toml"
    with pytest.raises(SimulationError) as err:
        simulate_scene(load_scene(path))
    msg = str(err.value)
    assert "deg" in msg and "rad" not in msg  # the scene's unit
    q = load_scene(path).mechanism.driver.value(load_scene(path).motion().t)
    i = int(re.search(r"invalid at sample (\d+)", msg).group(1))
    assert f"driver value {np.degrees(q[i]):.4g} deg" in msg
    assert "other link lengths" in msg
    amp, centre = (float(v) for v in re.search(r"amplitude = ([-\d.]+), centre = ([-\d.]+)", msg).groups())
    # the rocking input it suggests assembles, and simulates
    spec = tomllib.loads(path.read_text())
    spec["driver"].update(amplitude=amp, centre=centre)
    rocking = build_scene(parse_scene(spec))
    assert rocking.motion().valid.all()
    assert simulate_scene(rocking).failure is None


def test_a_genuine_torque_peak_is_not_capped(monkeypatch):
    # a quick return's inertia peak is brief but real: the robust cap must leave it standing
    from planar.physics import torquescale

    scene = load_scene(SCENES / "shaper-saturated.toml")
    mech, t = scene.mechanism, scene.motion().t
    capped = torque_scale(mech, t, scene.effects)
    monkeypatch.setattr(torquescale, "_SCALE_SPREAD", 1e12)
    assert capped == pytest.approx(torque_scale(mech, t, scene.effects), rel=1e-12)
