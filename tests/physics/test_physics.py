"""Physics you can trust: failures found by comparing poses, torque with every effect, exit statuses."""

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from planar.core.geometry import poses_apply
from planar.linkages import FourBar
from planar.physics.compare import EXIT_MISMATCH, compare
from planar.physics.simulate import SimSettings, simulate
from planar.scene.load import build_scene, load_scene, parse_scene

GALLERY = Path(__file__).resolve().parents[2] / "gallery"


def scene_of(data):
    return build_scene(parse_scene(data))


def run_cli(*args):
    return subprocess.run([sys.executable, "-m", "planar", *args], capture_output=True, text=True, check=False)


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
    assert f is not None and f.kind == "change-point" and "switched assembly branch" in f.message and "change point" in f.message
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
    ((lo, hi),) = fb0.input_range()
    fb = FourBar(4.5, 3.0, 3.0, 3.0, amplitude=0.5 * (hi - lo), centre=0.5 * (lo + hi))
    t = fb.driver.times(144)
    sim = simulate(fb, t)
    f = sim.failure
    assert f is not None and f.kind == "change-point"
    # the toggle is at the top of the swing, a quarter period in (sample 36); the flip shows right after it
    assert 36 <= f.sample <= 40
    # joints still hold where the pose is lost: it is another assembly, not a blow-up
    assert max(float(r[f.sample]) for r in sim.residuals.values()) < 0.1 * f.error * fb.size


@pytest.mark.slow
def test_compare_exit_status_3_when_the_error_passes_the_threshold():
    path = str(GALLERY / "slider-crank.toml")
    ok = run_cli("compare", path, "--json")
    assert ok.returncode == 0, ok.stdout + ok.stderr
    d = json.loads(ok.stdout)
    assert d["passed"] and d["problems"] == [] and d["max_rel_error"] < 1e-3
    # the same run against a threshold below its own error fails, with status 3 and the reason
    tight = run_cli("compare", path, "--threshold", f"{d['max_rel_error'] / 4:.3e}", "--time-cap", "1e-9")
    assert tight.returncode == EXIT_MISMATCH == 3, tight.stdout + tight.stderr
    assert "FAILED" in tight.stdout and "Traceback" not in tight.stderr
    # given time, the settings search finds a budget that meets the tighter threshold, and says which
    found = run_cli("compare", path, "--threshold", f"{d['max_rel_error'] / 4:.3e}")
    assert found.returncode == 0, found.stdout + found.stderr
    assert "converged at" in found.stdout
    # a user error is still 2
    assert run_cli("compare", str(GALLERY / "nope.toml")).returncode == 2


@pytest.mark.slow
def test_compare_exit_status_3_on_a_branch_flip():
    args = ("compare", str(GALLERY / "jansen-leg.toml"), "--error-bias", "0", "--iterations", "40", "--substeps", "64")
    # no time for the settings search: the flip at the given budget is the verdict, as its own kind
    r = run_cli(*args, "--time-cap", "1e-9")
    assert r.returncode == EXIT_MISMATCH, r.stdout + r.stderr
    assert "could not converge within 1e-09 s" in r.stdout and "sample" in r.stdout
    assert "change point" not in r.stdout  # a flip of the solver, not of the mechanism
    # with the search, the hint it follows (more iterations for a constraint error) makes it hold
    r = run_cli(*args)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "converged at substeps 64, iterations 80" in r.stdout


# ---------------------------------------------------------------- 2. torque with every effect

LEG = {
    "mechanism": {"type": "fourbar", "ground": 4.0, "crank": 1.0, "coupler": 4.0, "rocker": 3.0, "coupler_point": [2.0, 1.0]},
    "driver": {"samples_per_cycle": 36},
}


@pytest.mark.parametrize(
    "effects",
    [
        {"springs": [{"a": "crank", "b": "rocker", "stiffness": 20.0, "anchor_b": [3.0, 0.0]}]},
        {
            "springs": [
                {
                    "a": "ground",
                    "b": "coupler",
                    "stiffness": 5.0,
                    "damping": 2.0,
                    "anchor_b": [2.0, 1.0],
                    "anchor_a": [0.0, 3.0],
                    "rest_length": 2.0,
                }
            ]
        },
        {"damping": 0.5},
        {"gravity": [0.0, -9.81], "loads": [{"point": "coupler_point", "force": [0.0, 3.0]}]},
    ],
)
def test_torque_with_springs_damping_gravity_loads_within_one_percent(effects):
    from planar.physics.simulate import torque_comparison

    sc = scene_of(dict(LEG, effects=effects))
    tc = torque_comparison(sc.mechanism, sc.motion().t, sc.effects)
    assert tc["failure"] is None and tc["saturated"] == []
    assert tc["max_rel_diff"] < 0.01, tc["max_rel_diff"]


def test_inverse_dynamics_matches_an_independent_newton_euler_solve():
    """Joint forces of every link from F = m a, M = I alpha (a linear system), motor torque from the crank."""
    from planar.analysis.dynamics import inverse_dynamics_torque, mass_properties

    sc = scene_of(dict(LEG, effects={"gravity": [0.0, -9.81], "loads": [{"point": "coupler_point", "force": [1.0, 2.0]}]}))
    mech, e = sc.mechanism, sc.effects
    t = np.linspace(0.0, mech.driver.period, 9)[:-1]
    ours = inverse_dynamics_torque(mech, t, e)
    w = mech.driver.rate
    g = np.array(e.gravity)
    load = np.array(e.loads[0].force)
    h = 1e-5
    for k, tk in enumerate(t):
        m = [mech.solve(mech.driver.value([tk + d * h])) for d in (-1, 0, 1)]
        joints = {j.name: j for j in mech.joints}
        # unknowns: pin forces at O2, B, C, O4 (each on the second-named body from the first), motor torque
        bodies = ["crank", "coupler", "rocker"]
        # joint points in world at this instant (from the model's own joint anchors)
        pin_world = {}
        for name, j in joints.items():
            pin_world[name] = poses_apply(m[1].poses[j.b][0], np.asarray(j.anchor_b))
        names = list(joints)
        A = np.zeros((9, 2 * len(names) + 1))
        b = np.zeros(9)
        for bi, body in enumerate(bodies):
            mass, cog, inertia = mass_properties(mech.part(body), e.density)
            G = [poses_apply(mm.poses[body][0], np.asarray(cog)) for mm in m]
            acc = (G[2] - 2 * G[1] + G[0]) / h**2
            ang = np.unwrap([mm.poses[body][0, 2] for mm in m])
            alpha = (ang[2] - 2 * ang[1] + ang[0]) / h**2
            ext = mass * g.copy()
            mom = 0.0
            if body == "coupler":
                P = m[1].points["coupler_point"][0]
                ext = ext - load  # the load pushes back on the mechanism
                d = P - G[1]
                mom += d[0] * -load[1] - d[1] * -load[0]
            for ji, name in enumerate(names):
                j = joints[name]
                sign = 1.0 if j.b == body else (-1.0 if j.a == body else 0.0)
                if sign == 0.0:
                    continue
                r = pin_world[name] - G[1]
                A[3 * bi, 2 * ji] += sign
                A[3 * bi + 1, 2 * ji + 1] += sign
                A[3 * bi + 2, 2 * ji] += sign * -r[1]
                A[3 * bi + 2, 2 * ji + 1] += sign * r[0]
            if body == "crank":
                A[3 * bi + 2, -1] = 1.0
            b[3 * bi : 3 * bi + 2] = mass * acc - ext
            b[3 * bi + 2] = inertia * alpha - mom
        sol, *_ = np.linalg.lstsq(A, b, rcond=None)
        assert sol[-1] == pytest.approx(ours[k], rel=1e-5, abs=1e-6 * np.abs(ours).max()), (k, sol[-1], ours[k])
    assert w > 0


@pytest.mark.slow
def test_motor_saturation_is_reported_with_its_samples_and_fails_compare(tmp_path):
    from planar.physics.simulate import torque_comparison

    sc = load_scene(GALLERY / "kangaroo-leg.toml")
    need = torque_comparison(sc.mechanism, sc.motion().t, sc.effects)["peak"]
    text = (GALLERY / "kangaroo-leg.toml").read_text()
    limit = 0.4 * need
    path = tmp_path / "weak.toml"
    path.write_text(
        text.replace("[effects]", f"[effects]\nmotor_force_limit = {limit:.6g}")
        if "[effects]" in text
        else text + f"\n[effects]\nmotor_force_limit = {limit:.6g}\n"
    )
    weak = load_scene(path)
    tc = torque_comparison(weak.mechanism, weak.motion().t, weak.effects)
    assert tc["saturated"], tc
    an = np.abs(np.array(tc["analytic"]))
    assert an[tc["saturated"][0]] > 0.9 * limit  # it saturates where the need reaches the limit
    r = run_cli("compare", str(path))
    assert r.returncode == EXIT_MISMATCH and "motor saturated" in r.stdout, r.stdout


@pytest.mark.slow
@pytest.mark.parametrize("key", ["contact = true", "contact = false", "friction = 0.3"])
def test_contact_and_friction_keys_are_refused_in_one_line(tmp_path, key):
    # collisions were removed (parts sit on layers and never touch): the scene is refused when read, exit 2,
    # one line naming the key, nothing written
    p = tmp_path / "c.toml"
    p.write_text(
        f'name = "c"\n[mechanism]\ntype = "fourbar"\nground = 4.0\ncrank = 1.0\ncoupler = 4.0\nrocker = 3.0\n[effects]\n{key}\n'
    )
    for cmd in (["compare", str(p)], ["render", str(p), "-o", str(tmp_path / "c.gif")]):
        r = run_cli(*cmd)
        assert r.returncode == 2 and "Traceback" not in r.stderr
        line = r.stderr.strip()
        assert len(line.splitlines()) == 1 and str(p) in line and key.split()[0] in line and "removed" in line
    assert sorted(x.name for x in tmp_path.iterdir()) == ["c.toml"]


@pytest.mark.slow
def test_bench_sim_json_has_both_timings_and_ratio():
    r = run_cli("bench", "sim", "--json", "-n", "24", "--repeats", "3")
    assert r.returncode == 0, r.stderr
    d = json.loads(r.stdout)
    assert set(d["mechanisms"]) == {"four-bar", "jansen"} and d["ratio"] > 0
    for m in d["mechanisms"].values():
        assert m["planar_us_per_step"] > 0 and m["bare_pymunk_us_per_step"] > 0
        assert m["ratio_spread"][0] <= m["ratio"] <= m["ratio_spread"][1]
