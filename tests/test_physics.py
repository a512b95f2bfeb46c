"""Physics you can trust: failures found by comparing poses, torque with every effect, exit statuses."""

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from planar.compare import EXIT_MISMATCH, compare
from planar.geometry import poses_apply
from planar.linkages import FourBar
from planar.scene import build_scene, load_scene, parse_scene
from planar.simulate import SimSettings, simulate

GALLERY = Path(__file__).resolve().parents[1] / "gallery"


def scene_of(data):
    return build_scene(parse_scene(data))


def run_cli(*args):
    return subprocess.run([sys.executable, "-m", "planar", *args], capture_output=True, text=True)


# ---------------------------------------------------------------- 1. failures by pose


def _hull_distance(mech, part, p, q):
    pts = np.array([(x, y) for x, y, _ in mech.part(part).hull])
    return float(np.hypot(*(poses_apply(p, pts) - poses_apply(q, pts)).T).max())


def test_jansen_without_error_correction_is_a_failure_with_sample_and_part():
    scene = load_scene(GALLERY / "jansen-leg.toml")
    mech, ref = scene.mechanism, scene.motion()
    sim = simulate(mech, ref.t, None, SimSettings(substeps=64, iterations=40, error_bias=0.0))
    f = sim.failure
    assert f is not None and f.part in {p.name for p in mech.parts}
    # the reported part really is off by more than the tolerance at that sample, and nothing before was
    i = f.sample
    d = _hull_distance(mech, f.part, sim.motion.poses[f.part][i], ref.poses[f.part][i])
    assert d > 1e-3 * mech.size and d == pytest.approx(f.error * mech.size, rel=1e-9)
    assert not sim.motion.valid[i:].any() and sim.motion.valid[:i].all()
    for p in mech.parts:
        for k in range(i):
            assert _hull_distance(mech, p.name, sim.motion.poses[p.name][k], ref.poses[p.name][k]) <= 1e-3 * mech.size
    assert f"sample {i}" in f.message and repr(f.part) in f.message
    assert compare(mech, ref, sim.motion).failure == f.message


def test_change_point_fourbar_switching_branch_is_reported_as_such():
    fb = FourBar(4.0, 2.0, 4.0, 2.0)  # parallelogram: flat at crank angle 0, where both circuits meet
    t = fb.driver.times(72, 2)
    sim = simulate(fb, t)
    f = sim.failure
    assert f is not None and f.kind == "branch" and "switched assembly branch" in f.message
    assert f.sample <= 3
    # independent check: let it run on; it settles on the crossed circuit (the anti-parallelogram), not the open one
    free = simulate(fb, t, settings=SimSettings(tolerance=10.0))
    assert free.failure is None
    crossed = FourBar(4.0, 2.0, 4.0, 2.0, circuit="crossed").solve(fb.driver.value(t))
    open_ = fb.solve(fb.driver.value(t))
    for i in range(3, 36):
        for part in ("coupler", "rocker"):
            on_crossed = _hull_distance(fb, part, free.motion.poses[part][i], crossed.poses[part][i])
            on_open = _hull_distance(fb, part, free.motion.poses[part][i], open_.poses[part][i])
            assert on_crossed < 1e-2 * fb.size and on_crossed < 0.1 * on_open


def test_rocker_driven_to_its_toggle_is_caught_there():
    fb0 = FourBar(4.5, 3.0, 3.0, 3.0)
    (lo, hi), = fb0.input_range()
    fb = FourBar(4.5, 3.0, 3.0, 3.0, amplitude=0.5 * (hi - lo), centre=0.5 * (lo + hi))
    t = fb.driver.times(144)
    sim = simulate(fb, t)
    f = sim.failure
    assert f is not None and f.kind == "branch"
    # the toggle is at the top of the swing, a quarter period in (sample 36); the flip shows right after it
    assert 36 <= f.sample <= 40
    # joints still hold where the pose is lost: it is another assembly, not a blow-up
    assert max(float(r[f.sample]) for r in sim.residuals.values()) < 0.1 * f.error * fb.size


def test_compare_exit_status_3_when_the_error_passes_the_threshold():
    path = str(GALLERY / "slider-crank.toml")
    ok = run_cli("compare", path, "--json")
    assert ok.returncode == 0, ok.stdout + ok.stderr
    d = json.loads(ok.stdout)
    assert d["passed"] and d["problems"] == [] and d["max_rel_error"] < 1e-3
    # the same run against a threshold below its own error fails, with status 3 and the reason
    tight = run_cli("compare", path, "--threshold", f"{d['max_rel_error'] / 4:.3e}")
    assert tight.returncode == EXIT_MISMATCH == 3, tight.stdout + tight.stderr
    assert "FAILED" in tight.stdout and "Traceback" not in tight.stderr
    # a user error is still 2
    assert run_cli("compare", str(GALLERY / "nope.toml")).returncode == 2


def test_compare_exit_status_3_on_a_branch_flip():
    r = run_cli("compare", str(GALLERY / "jansen-leg.toml"), "--error-bias", "0", "--iterations", "40",
                "--substeps", "64")
    assert r.returncode == EXIT_MISMATCH, r.stdout + r.stderr
    assert "simulation failed" in r.stdout and "sample" in r.stdout
