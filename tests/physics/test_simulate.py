"""Physics rebuild: what is built, accuracy at the defaults, torque, refusals, hard cases."""

import json
import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from planar.linkages import FourBar
from planar.physics.compare import compare
from planar.physics.simulate import SimSettings, SimulationError, mass_properties, simulate, simulate_scene, torque_comparison
from planar.scene.load import build_scene, load_scene, parse_scene
from planar.windup import elemental

GALLERY = Path(__file__).resolve().parents[2] / "gallery"
SIMULATED = ["horse", "jansen-leg", "kangaroo-leg", "paddle-boat", "slider-crank"] + [
    f"windup-{k:02d}" for k in (1, 2, 3, 4, 5, 7, 8, 10, 11)
]


def scene_of(data):
    return build_scene(parse_scene(data))


LEG = {
    "mechanism": {"type": "fourbar", "ground": 4.0, "crank": 1.0, "coupler": 4.0, "rocker": 3.0, "coupler_point": [2.0, 1.0]},
    "driver": {"samples_per_cycle": 36},
}


def test_mass_properties_match_shapely_and_integration():
    import shapely

    fb = FourBar(4.0, 1.0, 4.0, 3.0, coupler_point=(2.0, 1.0))
    for part in fb.parts:
        m, cog, I = mass_properties(part, 2.0)
        poly = part.outline
        assert m == pytest.approx(2.0 * poly.area, rel=1e-12)
        assert cog == pytest.approx((poly.centroid.x, poly.centroid.y), abs=1e-12)
        # polar moment about the centroid by sampling the area on a fine grid
        x0, y0, x1, y1 = poly.bounds
        n = 400
        xs, ys = np.meshgrid(np.linspace(x0, x1, n), np.linspace(y0, y1, n))
        inside = shapely.contains_xy(poly, xs, ys)
        cell = (x1 - x0) / (n - 1) * (y1 - y0) / (n - 1)
        r2 = (xs - cog[0]) ** 2 + (ys - cog[1]) ** 2
        assert pytest.approx(2.0 * (r2[inside] * cell).sum(), rel=2e-2) == I


@pytest.mark.parametrize("name", SIMULATED)
def test_gallery_mechanism_within_1e3_of_size_at_defaults(name):
    scene = load_scene(GALLERY / f"{name}.toml")
    sim = simulate_scene(scene)
    assert sim.blowup is None
    c = compare(scene.mechanism, scene.motion(), sim.motion)
    assert c.max_rel_error < 1e-3, (name, c.max_rel_error)


def test_only_the_named_effects_are_built():
    bare = simulate_scene(scene_of(LEG))
    assert bare.built["gravity"] is None and bare.built["springs"] == 0
    assert bare.built["damping"] is None and bare.built["loads"] == 0
    explicit_none = simulate_scene(scene_of(dict(LEG, effects={"springs": [], "loads": []})))
    assert dict(explicit_none.built.items()) == dict(bare.built.items())
    # what is built does not depend on how long it runs: a tenth of a cycle
    full = simulate_scene(
        scene_of(
            dict(
                LEG,
                driver={"samples_per_cycle": 36, "duration": 0.1},
                effects={
                    "gravity": [0.0, -9.81],
                    "damping": 0.9,
                    "springs": [{"a": "crank", "b": "rocker", "stiffness": 10.0}],
                    "loads": [{"point": "coupler_point", "force": [0.0, 1.0]}],
                },
            )
        )
    )
    b = full.built
    assert b["gravity"] == (0.0, -9.81) and b["springs"] == 1
    assert b["damping"] == 0.9 and b["loads"] == 1


def test_purely_kinematic_render_builds_no_space(monkeypatch, tmp_path):
    import planar.physics.simulate as sim_mod
    from planar.app.pipeline import render_scene

    def boom(*a, **k):
        raise AssertionError("a space was built")

    monkeypatch.setattr(sim_mod, "_Rebuild", boom)
    assert render_scene(scene_of(LEG), tmp_path / "k.gif", progress=False) == 25  # 1 cycle/s at 25 frames/s


@pytest.mark.slow
def test_spatial_mechanisms_are_refused_with_a_clear_message():
    for k in (6, 9):
        m = elemental(k)
        with pytest.raises(SimulationError, match="spatial"):
            simulate(m, m.driver.times(12))
    r = subprocess.run(
        [sys.executable, "-m", "planar", "compare", str(GALLERY / "windup-06.toml")], capture_output=True, text=True
    )
    assert r.returncode == 2 and "spatial" in r.stderr and "Traceback" not in r.stderr


def test_contact_held_by_gravity_needs_the_effect():
    m = elemental(8)
    with pytest.raises(SimulationError, match="gravity or a spring"):
        simulate(m, m.driver.times(12), None)


@pytest.mark.slow
def test_compare_json_has_max_rel_error_per_part():
    r = subprocess.run(
        [sys.executable, "-m", "planar", "compare", str(GALLERY / "kangaroo-leg.toml"), "--json", "--motor"],
        capture_output=True,
        text=True,
    )
    assert r.returncode == 0, r.stderr
    d = json.loads(r.stdout)
    assert set(d["parts"]) == {"ground", "crank", "coupler", "rocker"}
    for p in d["parts"].values():
        assert 0 <= p["max_rel_error"] < 1e-3
    assert d["torque"]["max_rel_diff"] < 0.02


@pytest.mark.parametrize("name", ["kangaroo-leg", "slider-crank", "windup-02"])
def test_motor_torque_from_impulses_matches_inverse_dynamics(name):
    scene = load_scene(GALLERY / f"{name}.toml")
    data = {"gravity": [0.0, -9.81]} if not scene.spec.effects.loads else {}
    mech = scene.mechanism
    eff = scene.spec.effects.model_copy(update={"gravity": (0.0, -9.81)}) if data else scene.spec.effects
    t = mech.driver.times(36)
    tc = torque_comparison(mech, t, eff)
    assert tc["max_rel_diff"] < 0.02, tc["max_rel_diff"]
    # and the quasi-static part is the analysis module's virtual work torque: with negligible mass,
    # the simulated torque approaches it
    from planar.analysis import statics as analysis

    if scene.spec.effects.loads:
        light = eff.model_copy(update={"density": 1e-4})
        tq = torque_comparison(mech, t, light)
        loads = {l.point: np.asarray(l.force) for l in light.loads}
        K = tq["substeps"]
        tf = t[0] + (np.arange(t.size * K) + 0.5) * ((t[1] - t[0]) / K)
        vw, _ = analysis.motor_torque(mech, mech.driver.value(tf), loads)
        vw = np.roll(vw.reshape(t.size, K).mean(1), 1)
        sim = np.array(tq["simulated"][1:], float)
        assert np.abs(sim - vw[1:]).max() < 0.02 * np.abs(vw).max()


def test_blowup_is_detected_and_reported():
    # one substep, one iteration and no error correction on a fast Jansen leg: the joints fly apart
    scene = load_scene(GALLERY / "jansen-leg.toml")
    mech = scene.mechanism
    t = mech.driver.times(6, 3)
    sim = simulate(mech, t, None, SimSettings(substeps=1, iterations=1, error_bias=0.999, blowup_tol=0.01))
    assert sim.blowup is not None
    i = sim.blowup[0]
    assert not sim.motion.valid[i:].any() and sim.motion.valid[:i].all()
    assert "blew up" in sim.motion.reason(i)
    assert all(np.isfinite(p).all() for p in sim.motion.poses.values())


# ---------------------------------------------------------------- hard cases


def _assembly_error(fb: FourBar, motion) -> np.ndarray:
    """Per sample: how far (fraction of size) ``motion`` is from the nearer of the four-bar's two assemblies.

    Every pivot's centre, as carried by each of the two parts it joins, against
    the closed-form joint centres of the open and of the crossed circuit at the
    same crank angle; invalid samples count as infinitely far.
    """
    from planar.core.geometry import poses_apply
    from planar.core.model import Pivot

    g = fb.dims
    q = motion.driver
    worst = {}
    for circuit in ("open", "crossed"):
        nodes, _ = FourBar(g.d, g.a, g.b, g.c, circuit=circuit).solve_nodes(q)
        err = np.zeros(q.size)
        for j in fb.joints:
            assert isinstance(j, Pivot)
            for part, anchor in ((j.a, j.anchor_a), (j.b, j.anchor_b)):
                xy = poses_apply(motion.poses[part], np.asarray(anchor, float))
                err = np.maximum(err, np.hypot(*(xy - nodes[j.name]).T))
        worst[circuit] = err
    e = np.minimum(worst["open"], worst["crossed"]) / fb.size
    return np.where(motion.valid, e, np.inf)


def test_change_point_fourbar_analytic_and_simulated():
    # parallelogram: flat (change point) at crank angles 0 and pi; start between them, cross four
    fb = FourBar(4.0, 2.0, 4.0, 2.0, phase=0.3)
    t = fb.driver.times(72, 2)
    analytic = fb.solve(fb.driver.value(t), t=t)
    assert analytic.valid.all() and all(np.isfinite(p).all() for p in analytic.poses.values())
    assert np.floor(analytic.driver.max() / np.pi) - np.floor(analytic.driver.min() / np.pi) == 4
    sim = simulate(fb, t)
    assert sim.blowup is None and sim.motion.valid.all()
    # at a change point pymunk may go on in either assembly; at every sample it is on one of them
    e = _assembly_error(fb, sim.motion)
    assert e.max() < 1e-3, (int(e.argmax()), e.max())
    # and it keeps the parallelogram its start gave it (coupler parallel to the ground) through all four
    ang = sim.motion.poses["coupler"][:, 2] - sim.motion.poses["coupler"][0, 2]
    assert np.abs(np.angle(np.exp(1j * ang))).max() < 1e-3
    # the analytic motion is on an assembly too (the check's own sanity)
    assert _assembly_error(fb, analytic).max() < 1e-12


def test_assembly_check_fails_a_garbage_motion():
    # the old check (error < 1e-3 or compare() names a first sample over) passed any motion at all
    fb = FourBar(4.0, 2.0, 4.0, 2.0, phase=0.3)
    t = fb.driver.times(72, 1)
    good = fb.solve(fb.driver.value(t), t=t)
    rng = np.random.default_rng(1)
    garbage = {k: v + rng.normal(0.0, 0.5, v.shape) * (k != "ground") for k, v in good.poses.items()}
    bad = replace(good, poses=garbage)
    c = compare(fb, good, bad)
    assert c.max_rel_error < 1e-3 or c.first_over is not None  # the old assertion: true for garbage
    assert _assembly_error(fb, bad).max() > 1e-3  # the new one is not
    one_off = {k: v.copy() for k, v in good.poses.items()}
    one_off["rocker"][17, 2] += 0.01  # one sample, one part, a hundredth of a radian
    assert _assembly_error(fb, replace(good, poses=one_off)).max() > 1e-3
    hidden = replace(good, poses=garbage, valid=np.zeros(len(good), bool))  # garbage marked invalid
    assert not np.isfinite(_assembly_error(fb, hidden)).any()


def test_rocker_driven_to_its_toggles():
    fb0 = FourBar(4.5, 3.0, 3.0, 3.0)
    ((lo, hi),) = fb0.input_range()
    mid, amp = 0.5 * (lo + hi), 0.5 * (hi - lo)
    fb = FourBar(4.5, 3.0, 3.0, 3.0, amplitude=amp, centre=mid)
    t = fb.driver.times(144)
    analytic = fb.solve(fb.driver.value(t), t=t)
    assert analytic.valid.all()  # exactly at the toggles the solution is valid and finite
    assert all(np.isfinite(p).all() for p in analytic.poses.values())
    sim = simulate(fb, t)
    assert all(np.isfinite(p).all() for p in sim.motion.poses.values())
    # at a toggle the assembly branch is undecided: pymunk may go on in the other one, and only there; the
    # joints still hold (a branch switch, not a blow-up) and up to the toggle the motion is the analytic one
    toggles = np.flatnonzero(np.abs(np.abs(fb.driver.value(t) - mid) - amp) < 1e-9 * amp)
    assert toggles.size >= 1
    f = sim.failure
    if f is not None:
        assert f.kind == "change-point" and "change point or toggle" in f.message, f.message
        assert 0 <= f.sample - toggles[0] <= 2, (f.sample, toggles)
    c = compare(fb, analytic, sim.motion)
    assert c.first_over is None or c.first_over > toggles[0], (c.first_over, toggles)


def test_elemental_near_its_failure_boundary():
    # #3 with the track placed so that the circles are tangent within round-off at one sample
    from scipy.optimize import brentq

    def margin(sx):
        m = elemental(3, S_c=(sx, 0.0, 0.1))
        th = np.linspace(0, 2 * np.pi, 2001)
        P = m.params
        from planar.windup.kinematics import cam_centre

        p0 = np.array(P.F_o)
        s = p0 + np.array(P.S_c[:2])
        R, r = np.hypot(*(p0 - np.array(P.D_jc))), np.hypot(*(p0 - s))
        return (R + r) - np.hypot(*(cam_centre(P.D_o, P.D_jc, th) - s).T).max()

    sx = brentq(margin, 0.05, 0.3, xtol=1e-15)
    m = elemental(3, S_c=(sx, 0.0, 0.1))
    motion = m.run(720)
    assert all(np.isfinite(p).all() for p in motion.poses.values())
    steps = np.abs(np.diff(motion.poses["follower"][:, :2], axis=0)).max()
    assert steps < 0.05 * m.size  # continuous through the near-tangent sample
    if motion.valid.all():
        sim = simulate(m, motion.t[::10])
        assert all(np.isfinite(p).all() for p in sim.motion.poses.values())


def test_ten_thousand_revolutions_analytic_has_no_drift():
    fb = FourBar(4.0, 1.0, 4.0, 3.0, coupler_point=(2.0, 1.0))
    base = np.linspace(0, 2 * np.pi, 37)
    first = fb.solve(base).points["coupler_point"]
    last = fb.solve(base + 2 * np.pi * 9_999).points["coupler_point"]
    assert np.abs(first - last).max() < 1e-9


def test_long_run_simulated_has_no_drift_growth():
    # 1,000 revolutions at 8 samples each: the error of the last 100 revolutions is no larger than
    # that of the first 100 (it is periodic: the same to 1e-11 here, so 10,000 revolutions add nothing)
    fb = FourBar(4.0, 1.0, 4.0, 3.0, coupler_point=(2.0, 1.0), rate=2 * np.pi * 10)
    t = fb.driver.times(8, 1_000)
    sim = simulate(fb, t, settings=SimSettings(substeps=4, iterations=10, error_bias=1e-9, tolerance=0.05))
    assert sim.blowup is None
    analytic = fb.solve(fb.driver.value(t), t=t)
    err = np.hypot(*(sim.motion.poses["rocker"][:, :2] - analytic.poses["rocker"][:, :2]).T)
    early, late = err[: 8 * 100].max(), err[-8 * 100 :].max()
    assert np.isfinite(err).all()
    assert late < 2.0 * early + 1e-12  # no drift growth
    assert err.max() < 1e-2 * fb.size
    # and no trend after the start-up (the first few revolutions settle): the per-revolution worst
    # error of revolutions 100-999 changes by less than 1e-3 of itself over those 900 revolutions
    per_rev = err.reshape(1_000, 8).max(axis=1)[100:]
    slope = np.polyfit(np.arange(per_rev.size), per_rev, 1)[0]
    assert abs(slope) * per_rev.size < 1e-3 * early


def test_mass_ratio_one_to_a_thousand():
    scene = scene_of(LEG)
    mech = scene.mechanism
    t = scene.motion().t
    sim = simulate(mech, t, densities={"coupler": 1000.0, "rocker": 1.0})
    assert sim.blowup is None
    c = compare(mech, scene.motion(), sim.motion)
    assert c.max_rel_error < 1e-3, c.max_rel_error


@pytest.mark.parametrize("scale", [1e-3, 1.0, 1e3])
def test_scaled_mechanisms_keep_their_relative_accuracy(scale):
    fb = FourBar(4.0 * scale, 1.0 * scale, 4.0 * scale, 3.0 * scale, coupler_point=(2.0 * scale, 1.0 * scale))
    t = fb.driver.times(36)
    analytic = fb.solve(fb.driver.value(t), t=t)
    from planar.core.model import joint_residuals

    assert max(r.max() for r in joint_residuals(fb, analytic).values()) < 1e-9 * fb.size
    sim = simulate(fb, t)
    c = compare(fb, analytic, sim.motion)
    assert c.max_rel_error < 1e-3, (scale, c.max_rel_error)


@pytest.mark.slow
def test_accuracy_benchmark_quick_run(tmp_path, monkeypatch):
    pytest.importorskip("matplotlib")
    from planar.bench.accuracy import bench_accuracy

    # run away from the repository: the scenes folder is the one given, never looked up beside the code
    monkeypatch.chdir(tmp_path)
    r = bench_accuracy(GALLERY, out_dir="out", quick=True, repeats=1, progress=False, effects_fraction=0.1)
    out = tmp_path / "out"
    assert (out / "accuracy.csv").exists() and (out / "accuracy.png").stat().st_size > 1000
    from planar.bench.accuracy import ACCURACY_QUICK_GRID
    from planar.physics.simulate import DEFAULT_SETTINGS as D

    g = ACCURACY_QUICK_GRID
    n_grid = len(g["substeps"]) * len(g["iterations"]) * len(g["correction"])
    # the grid has fixed substeps; the defaults (adaptive substeps) are measured beside it
    assert D.step_drift is not None
    assert len(r["mechanisms"]) == 3 and r["settings"] == n_grid + 1
    # whether the defaults sit on the time/error frontier depends on timings (a benchmark's finding, noisy on a
    # shared machine; README reports it): here only that it is reported
    assert isinstance(r["default_on_frontier"], bool)
    # motor mode and torque are measured: the Jansen leg turns at a constant rate
    dj = r["default_errors"]["jansen-leg"]
    assert 0 < dj["motor"] < 1e-4 and 0 < dj["torque"] < 1e-2 and dj["substeps"] > D.substeps
    assert r["default"]["max_error"] < 1e-3
    assert r["frontier"] and all(a["frontier"] for a in r["frontier"])
    # timings are reported, not asserted (a loaded 2-core machine swings them 1.5x); that unused effects
    # build nothing is tested in test_only_the_named_effects_are_built
    assert r["effects_cost"]["unused"] > 0 and r["effects_cost"]["none"] > 0
    import csv

    with open(out / "accuracy.csv") as fh:
        rows = list(csv.DictReader(fh))
    assert {
        "mechanism",
        "substeps",
        "iterations",
        "correction",
        "error",
        "motor_error",
        "torque_error",
        "step_drift",
        "seconds_per_sim_second",
    } <= set(rows[0])


@pytest.mark.slow
@pytest.mark.parametrize("args", [[], ["--scenes", "no-such-folder"]])
def test_accuracy_benchmark_needs_a_scenes_folder(tmp_path, args):
    # from a folder without gallery/: one line naming the folder, exit 2, no traceback, nothing written
    root = str(Path(__file__).resolve().parents[2])
    r = subprocess.run(
        [sys.executable, "-m", "planar", "bench", "accuracy", "--quick", "-o", "out", *args],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        env={"PYTHONPATH": root, "PATH": ""},
    )
    assert r.returncode == 2, r.stderr
    assert "Traceback" not in r.stderr and len(r.stderr.strip().splitlines()) == 1
    assert "folder of scene files" in r.stderr and (args[-1] if args else "gallery") in r.stderr
    assert list(tmp_path.iterdir()) == []


def test_pareto_frontier():
    from planar.bench.accuracy import _pareto

    pts = [(1.0, 1.0), (2.0, 0.5), (3.0, 0.6), (0.5, 2.0), (2.0, 0.5)]
    assert _pareto(pts) == [True, True, False, True, True]


def test_overlay_render(tmp_path):
    from planar.cli.main import main

    out = tmp_path / "o.gif"
    assert main(["render", str(GALLERY / "slider-crank.toml"), "--overlay", "-o", str(out)]) == 0
    assert out.stat().st_size > 1000


@pytest.mark.slow
def test_overlay_draws_up_to_where_the_simulation_stops_holding(tmp_path, capsys):
    from PIL import Image

    from planar.cli.main import main

    out = tmp_path / "o.gif"
    # no error correction: the Jansen leg's simulation leaves its assembly at sample 20; the render still happens
    args = ["render", str(GALLERY / "jansen-leg.toml"), "--overlay", "-o", str(out)]
    assert main([*args, "--error-bias", "0", "--substeps", "64", "--iterations", "40"]) == 0
    text = capsys.readouterr().out
    assert "holds up to sample 20" in text and "drawn frozen from there" in text
    frames = Image.open(out).n_frames
    assert frames == 25
    # the solver options are checked as compare checks them
    assert main([*args, "--substeps", "0"]) == 2
    assert "--substeps" in capsys.readouterr().err
