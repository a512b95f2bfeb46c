"""Physics verdicts: the settings search, the torque scale, the motor only when asked, true hints."""

from dataclasses import replace

import numpy as np
import pytest

from planar.core.effects import Effects
from planar.linkages import FourBar
from planar.physics.compare import compare_scene, torque_line
from planar.physics.converge import converge, failure_cause, hint
from planar.physics.run import torque_scale
from planar.physics.settings import DEFAULT_SETTINGS, SimSettings, step_correction
from planar.physics.simulate import simulate, torque_comparison
from planar.scene.load import build_scene, parse_scene

LEG = {
    "mechanism": {"type": "fourbar", "ground": 4.0, "crank": 1.0, "coupler": 4.0, "rocker": 3.0, "coupler_point": [2.0, 1.0]},
    "driver": {"samples_per_cycle": 36},
}


@pytest.mark.slow
def test_motor_check_only_when_the_scene_names_a_motor():
    plain = build_scene(parse_scene(LEG))
    r, _ = compare_scene(plain)
    assert r.torque is None and r.passed
    named = build_scene(parse_scene(dict(LEG, effects={"motor": True})))
    assert named.effects.wants_motor
    r, _ = compare_scene(named)
    assert r.torque is not None and r.torque["samples_compared"] == 35 and r.passed
    r, _ = compare_scene(plain, motor=True)
    assert r.torque is not None
    assert build_scene(parse_scene(dict(LEG, effects={"motor_force_limit": 1e9}))).effects.wants_motor


def test_torque_scale_is_physical_and_bounds_the_peak():
    fb = FourBar(4.0, 1.0, 4.0, 3.0, coupler_point=(2.0, 1.0))
    t = fb.driver.times(36)
    tc = torque_comparison(fb, t, None)
    assert tc["scale"] >= tc["peak"] > 0
    # the scale goes as density (mass) and as the rate squared, as a torque of inertia does
    fast = FourBar(4.0, 1.0, 4.0, 3.0, coupler_point=(2.0, 1.0))
    fast = (
        replace(fast, driver=replace(fast.driver, rate=2 * fast.driver.rate)) if hasattr(fast, "__dataclass_fields__") else None
    )
    s1 = torque_scale(fb, t)
    if fast is not None:
        s2 = torque_scale(fast, fast.driver.times(36))
        assert s2 == pytest.approx(4 * s1, rel=1e-3)
    assert tc["worst_sample"] is not None and 0 < tc["worst_sample"] < 36
    assert tc["max_rel_diff"] == pytest.approx(tc["max_abs_diff"] / tc["scale"])


def test_zero_samples_compared_is_said_so():
    line = torque_line({"samples_compared": 0})
    assert "0 samples compared" in line and "%" not in line


def test_correction_per_second_is_kept_past_2400_steps_per_turn():
    fb = FourBar(4.0, 1.0, 4.0, 3.0)
    P = fb.driver.period
    c = [step_correction(DEFAULT_SETTINGS, fb, P / n, DEFAULT_SETTINGS.iterations) for n in (1200, 2400, 4800, 9600)]
    assert c[0] == c[1] == DEFAULT_SETTINGS.correction
    assert c[2] == pytest.approx(c[1] / 2) and c[3] == pytest.approx(c[1] / 4)


def _fake(results):
    """A run whose outcome per budget is given: (cause, sample, error)."""
    seen = []

    def run(st):
        seen.append(st)
        return results[min(len(seen) - 1, len(results) - 1)]

    def outcome(r):
        return r[0], r[1], r[2], {}

    return run, outcome, seen


def test_search_verdicts():
    run, outcome, seen = _fake([(None, 36, 0.0)])
    _, s = converge(run, outcome, DEFAULT_SETTINGS)
    assert s.verdict == "pass" and len(seen) == 1  # a run that holds costs one run
    run, outcome, seen = _fake([("constraint", 20, 0.01), (None, 36, 0.0)])
    _, s = converge(run, outcome, DEFAULT_SETTINGS)
    assert s.verdict == "pass" and seen[1].iterations == 2 * DEFAULT_SETTINGS.iterations
    run, outcome, seen = _fake([("drift", 20, 0.01), ("drift", 20, 0.012)])
    _, s = converge(run, outcome, DEFAULT_SETTINGS)
    assert s.verdict == "differs" and "differs" in s.line()
    run, outcome, seen = _fake([("drift", 20, 0.01), ("drift", 25, 0.005), ("drift", 30, 0.003)])
    _, s = converge(run, outcome, DEFAULT_SETTINGS, cap_s=0.0)
    assert s.verdict == "unconverged" and "could not converge within 0 s" in s.line()
    # a knob that makes it fail earlier is swapped for the other
    run, outcome, seen = _fake([("drift", 276, 0.01), ("drift", 254, 0.02), ("drift", 240, 0.02), (None, 300, 0)])
    _, s = converge(run, outcome, DEFAULT_SETTINGS)
    assert seen[2].iterations == 2 * DEFAULT_SETTINGS.iterations


def test_causes_and_their_hints():
    assert failure_cause("blow-up", 0.1, 0.2, 1.0) == "constraint"
    assert failure_cause("drift", 2e-3, 1e-3, 1e-5) == "constraint"  # more residual than stepping leaves
    assert failure_cause("drift", 2e-3, 1e-5, 1e-5) == "drift"
    assert failure_cause("change-point", 0.1, 0.0) == "change-point"
    assert "--iterations" in hint("constraint") and "--substeps" in hint("drift")
    assert "motor_force_limit" in hint("saturation")


@pytest.mark.slow
def test_the_constraint_hint_helps():
    # no error correction: the Jansen leg's joints come apart; the hint for that cause (iterations) fixes it
    from planar.scene.catalog import get

    mech = get("jansen")
    t = mech.driver.times(36)
    st = SimSettings(substeps=64, iterations=40, error_bias=0.0, step_drift=None)
    bad = simulate(mech, t, None, st)
    assert bad.failure is not None
    i = bad.failure.sample
    res = max(float(v[i]) for v in bad.residuals.values()) / mech.size
    cause = failure_cause(bad.failure.kind, bad.failure.error, res, bad.built["standing_drift"])
    assert cause == "constraint" and "--iterations" in hint(cause)
    good = simulate(mech, t, None, replace(st, iterations=2 * st.iterations))
    assert good.failure is None or good.failure.sample > i
    assert np.isfinite(good.motion.poses[mech.driver.part]).all()


def test_kite_names_its_coincident_pivots():
    fb = FourBar(1.0, 1.0, 2.0, 2.0)  # ground = crank: at 0 the crank pin sits on the rocker's pivot
    th = np.linspace(0.0, 2 * np.pi, 361)
    m = fb.solve(th)
    bad = np.flatnonzero(~m.valid)
    assert bad.tolist() == [0]
    why = m.reason(0)
    assert "coincide" in why and "cannot span" not in why
    # a four-bar that truly cannot span keeps saying so
    fb2 = FourBar(4.0, 1.5, 2.0, 1.0)
    m2 = fb2.solve(th)
    i = int(np.flatnonzero(~m2.valid)[0])
    assert "cannot span" in m2.reason(i)


def test_liftoff_speed_is_printed_to_its_resolution():
    from planar.physics.toy import format_speed, liftoff_resolution

    res = liftoff_resolution([2.0, 4.0, 8.0], 3.4375)  # bisected five times between 2 and 4
    assert res == pytest.approx(2.0 / 32)
    assert format_speed(3.4375, res) == "3.44"
    assert liftoff_resolution([2.0, 4.0], 2.0) == 2.0  # the first scanned speed let go: no bisection
    assert format_speed(2.0, 2.0) == "2"


def _cause(sim, mech):
    f = sim.failure
    res = max(float(v[f.sample]) for v in sim.residuals.values()) / mech.size
    return failure_cause(f.kind, f.error, res, sim.built["standing_drift"])


@pytest.mark.slow
def test_the_drift_hint_helps_and_the_other_knob_does_not():
    # a four-bar at 12 samples a turn and 8 fixed substeps: the joints drift by what stepping leaves standing
    fb = FourBar(4.0, 1.0, 4.0, 3.0, coupler_point=(2.0, 1.0))
    t = fb.driver.times(12)
    st = SimSettings(substeps=8, iterations=40, step_drift=None)
    bad = simulate(fb, t, None, st)
    assert bad.failure is not None
    cause = _cause(bad, fb)
    assert cause == "drift" and "--substeps" in hint(cause)
    more_steps = simulate(fb, t, None, replace(st, substeps=32))
    assert more_steps.failure is None
    more_iterations = simulate(fb, t, None, replace(st, iterations=80))  # the hint not given: no help
    assert more_iterations.failure is not None


@pytest.mark.slow
def test_the_saturation_hint_helps():
    fb = FourBar(4.0, 1.0, 4.0, 3.0, coupler_point=(2.0, 1.0))
    t = fb.driver.times(36)
    peak = torque_comparison(fb, t, None)["peak"]
    weak = torque_comparison(fb, t, Effects(motor_force_limit=0.3 * peak))
    assert weak["saturated"]
    assert "motor_force_limit" in hint("saturation")
    strong = torque_comparison(fb, t, Effects(motor_force_limit=1.5 * peak))  # the limit above the needed peak
    assert not strong["saturated"] and strong["max_rel_diff"] < 0.01
    lighter = torque_comparison(fb, t, Effects(motor_force_limit=0.3 * peak, density=0.2))  # or lighter parts
    assert not lighter["saturated"]


def test_fixed_substeps_are_never_raised_by_the_search():
    # --step-drift 0 (step_drift None) keeps --substeps fixed: a run that keeps drifting stops the search
    from planar.physics.converge import converge
    from planar.physics.settings import SimSettings

    seen = []

    def run(st):
        seen.append((st.substeps, st.iterations))
        return st

    def outcome(st):  # drifts while its joints hold, failing later with each budget (never "differs")
        return "drift", len(seen) * 10, 1e-2, {"substeps": st.substeps, "iterations": st.iterations, "correction": 0.2}

    _, search = converge(run, outcome, SimSettings(substeps=7, step_drift=None), cap_s=1e9)
    assert {s for s, _ in seen} == {7} and search.verdict == "unconverged" and "fixed" in search.line()
    seen.clear()
    _, search = converge(run, outcome, SimSettings(substeps=7), cap_s=1e9)  # step_drift given: substeps raised
    assert max(s for s, _ in seen) > 7 and "fixed" not in search.line()


@pytest.mark.slow
def test_comparison_to_dict_has_the_settings_like_the_cli():
    import planar
    from planar.linkages.fourbar import FourBar
    from planar.physics.simulate import SimSettings

    comp, sim = planar.compare(
        FourBar(ground=4, crank=1, coupler=3.5, rocker=3), settings=SimSettings(step_drift=None), driver={"samples_per_cycle": 24}
    )
    d = comp.to_dict()
    assert d["settings"]["substeps"] == sim.built["substeps"] == 28 and d["settings"]["step_drift"] is None
    assert d["search"]["verdict"] == comp.search.verdict
