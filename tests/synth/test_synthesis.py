"""Synthesis (issue 15): path, function and motion generation checked against independent linkages."""

from __future__ import annotations

import json
import tomllib

import numpy as np
import pytest

from planar.cli.main import main
from planar.linkages import FourBar
from planar.scene.load import load_scene
from planar.synth.function import freudenstein_fit
from planar.synth.kernel import coupler_points
from planar.synth.motion import burmester, circle_point_curve
from planar.synth.path import synthesise_path

KNOWN = FourBar(4.0, 1.0, 3.5, 3.0, coupler_point=(1.2, 0.9), placement=(0.4, -0.3, 0.5))


def _poses(fb: FourBar, theta: np.ndarray) -> np.ndarray:
    m = fb.solve(theta)
    return np.column_stack([m.points["coupler_point"], m.poses["coupler"][:, 2]])


@pytest.mark.parametrize("circuit", ["open", "crossed"])
def test_kernel_matches_fourbar_solve(circuit):
    fb = FourBar(4, 1, 4, 3, coupler_point=(1.5, -2.0), circuit=circuit, placement=(0.3, -0.2, 0.7))
    th = np.linspace(0, 2 * np.pi, 64, endpoint=False)
    x, y, ok = coupler_points(
        np.array([[4, 1, 4, 3, 1.5, -2.0, 0.3, -0.2, 0.7]], float), th, np.array([1.0 if circuit == "open" else -1.0])
    )
    ref = fb.solve(th).points["coupler_point"]
    assert ok.all()
    assert np.abs(np.column_stack([x[0], y[0]]) - ref).max() < 1e-12


@pytest.mark.slow
def test_path_timed_recovers_known_coupler_curve():
    th = np.linspace(0.2, 2.6, 5)
    pts = KNOWN.solve(th).points["coupler_point"]
    d = synthesise_path(pts, th, budget="quick")
    assert d.ok, d.checks
    assert d.sse < 1e-8 * np.ptp(pts, axis=0).max() ** 2
    # planar's own solve of the result passes through the targets at the prescribed angles
    got = d.fourbar().solve(th).points["coupler_point"]
    assert np.hypot(*(got - pts).T).max() < 1e-4


@pytest.mark.slow
def test_path_untimed_passes_through_points_of_known_curve():
    pts = KNOWN.solve(np.linspace(0.0, 2 * np.pi, 6, endpoint=False)).points["coupler_point"]
    d = synthesise_path(pts, None, budget="quick", seed=1)
    assert d.ok, d.checks
    assert d.checks["grashof"] in ("crank-rocker", "double-crank")
    # independent measure: distance from each target to a dense coupler curve of the result
    curve = d.fourbar().solve(np.linspace(0, 2 * np.pi, 20000, endpoint=False)).points["coupler_point"]
    dist = np.hypot(curve[None, :, 0] - pts[:, None, 0], curve[None, :, 1] - pts[:, None, 1]).min(1)
    assert dist.max() < 2e-3 * np.ptp(pts, axis=0).max()


def test_function_exact_for_three_pairs():
    fb = FourBar(5.0, 1.5, 4.0, 3.5)
    phi = np.array([0.3, 1.1, 2.0])
    _, psi, ok = fb.angles(phi)
    assert ok.all()
    d = freudenstein_fit(phi, psi, ground=5.0)
    assert abs(d.crank - 1.5) < 1e-9 and abs(d.coupler - 4.0) < 1e-9 and abs(d.rocker - 3.5) < 1e-9
    # the synthesised four-bar, solved by planar, gives the requested output angles
    _, out, ok = d.fourbar().angles(phi)
    assert ok.all()
    assert np.abs((out - psi + np.pi) % (2 * np.pi) - np.pi).max() < 1e-9


def test_burmester_four_poses_on_circle_point_curve_and_reached():
    P = _poses(KNOWN, np.linspace(0.3, 2.2, 4))
    z, c = circle_point_curve(P)
    assert len(z) > 100
    # independent of the determinant: each circle point, carried through the 4 poses, stays at one distance
    # from its centre point
    ca, sa = np.cos(P[:, 2]), np.sin(P[:, 2])
    wx = P[:, 0][None] + ca[None] * z[:, :1] - sa[None] * z[:, 1:]
    wy = P[:, 1][None] + sa[None] * z[:, :1] + ca[None] * z[:, 1:]
    r = np.hypot(wx - c[:, :1], wy - c[:, 1:])
    assert (np.ptp(r, axis=1) <= 1e-7 * r.max(axis=1)).all()
    d = burmester(P)
    assert d.ok, d.checks
    m = d.fourbar().solve(d.theta)
    assert np.abs(m.points["coupler_point"] - P[:, :2]).max() < 1e-9


@pytest.mark.parametrize("n", [3, 5])
def test_burmester_three_and_five_poses_reached(n):
    P = _poses(KNOWN, np.linspace(0.3, 2.2, n))
    d = burmester(P)
    assert d.ok, d.checks
    m = d.fourbar().solve(d.theta)
    ang = m.poses["coupler"][:, 2] + d.angle_offset
    assert np.abs(m.points["coupler_point"] - P[:, :2]).max() < 1e-8
    assert np.abs((ang - P[:, 2] + np.pi) % (2 * np.pi) - np.pi).max() < 1e-8


def test_cli_path_writes_scene_that_loads_and_solves(tmp_path, capsys):
    th = np.linspace(0.2, 2.6, 5)
    pts = KNOWN.solve(th).points["coupler_point"]
    csv = tmp_path / "t.csv"
    csv.write_text("x,y,theta\n" + "".join(f"{float(x)!r},{float(y)!r},{float(t)!r}\n" for (x, y), t in zip(pts, th)))
    out = tmp_path / "s.toml"
    assert main(["synth", "path", str(csv), "-o", str(out), "--json", "--budget", "quick"]) == 0
    rep = json.loads(capsys.readouterr().out)
    assert rep["sse"] < 1e-6 and rep["time_s"] > 0
    scene = load_scene(out)
    m = scene.mechanism.solve(th)
    assert np.hypot(*(m.points["coupler_point"] - pts).T).max() < 1e-3
    assert scene.motion().valid.all()
    assert tomllib.loads(out.read_text())["mechanism"]["type"] == "fourbar"


def test_cli_function_and_motion_scenes(tmp_path, capsys):
    fb = FourBar(5.0, 1.5, 4.0, 3.5)
    phi = np.array([0.3, 1.1, 2.0])
    _, psi, _ = fb.angles(phi)
    pairs = tmp_path / "p.csv"
    pairs.write_text("input,output\n" + "".join(f"{float(a)!r},{float(b)!r}\n" for a, b in zip(phi, psi)))
    assert main(["synth", "function", str(pairs), "-o", str(tmp_path / "f.toml"), "--ground", "5"]) == 0
    assert load_scene(tmp_path / "f.toml").motion().valid.all()
    P = _poses(KNOWN, np.linspace(0.3, 2.2, 4))
    poses = tmp_path / "m.csv"
    poses.write_text("x,y,angle\n" + "".join(f"{float(x)!r},{float(y)!r},{float(a)!r}\n" for x, y, a in P))
    assert main(["synth", "motion", str(poses), "-o", str(tmp_path / "m.toml")]) == 0
    assert load_scene(tmp_path / "m.toml").motion().valid.all()
    capsys.readouterr()


def test_cli_bad_input_one_line_nothing_written(tmp_path, capsys):
    bad = tmp_path / "bad.csv"
    bad.write_text("x,y\n1,2\n3,oops\n4,5\n")
    out = tmp_path / "s.toml"
    assert main(["synth", "path", str(bad), "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert "row 3: y" in err and "oops" in err and err.count("\n") == 1
    assert not out.exists()
    assert main(["synth", "path", str(bad), "-o", str(out), "--type", "sixbar"]) == 2
    assert "row 3: y" in capsys.readouterr().err and not out.exists()


def test_svg_target_read_by_svgelements(tmp_path):
    from planar.synth.targets import read_path_targets

    svg = tmp_path / "t.svg"
    svg.write_text('<svg xmlns="http://www.w3.org/2000/svg" width="100" height="100"><path d="M 10 10 L 50 10 L 50 50 Z"/></svg>')
    pts, theta = read_path_targets(svg, 8)
    assert theta is None and pts.shape == (8, 2)
    assert np.allclose(pts[0], (10, -10))  # y up
    x, y = pts.T  # every point on the triangle (10,10)-(50,10)-(50,50), y negated
    on = (np.abs(y + 10) < 1e-9) | (np.abs(x - 50) < 1e-9) | (np.abs(x + y) < 1e-9)
    assert on.all()
    step = np.hypot(*np.diff(np.vstack([pts, pts[:1]]), axis=0).T)
    assert step.max() < 136.57 / 8 + 1e-6  # evenly spaced by arc length (chords no longer than the arcs)


@pytest.mark.slow
def test_bench_synthesis_quick_timed_problem():
    from planar.bench.synthesis import bench_synthesis

    r = bench_synthesis(quick=True, n=20_000, problems=("cabrera-2002-case-2",), reachable=0, heldout=0)
    c = r["cases"][0]
    assert c["planar"]["ok"] and c["planar"]["sse_min"] < 1e-3
    assert "pylinkage" in c["pylinkage"]["call"] and c["published_best_error"]
    assert r["kernel_candidates_per_s"]["median"] > 0
    o = c["pylinkage_optimisers"]  # timed: pylinkage's own sse and planar's, at the same crank angles
    # (pylinkage's swarm is unseeded: whether its best also passes planar's design checks, e.g. the link-ratio
    # bound, varies from run to run; the two scorings of the same linkage must agree every time)
    assert np.isfinite(o["sse_min"]) and o["sse_min"] == pytest.approx(o["pylinkage_sse_of_best"], rel=1e-9)
    assert c["pylinkage_four_targets"]["solutions"] > 0


@pytest.mark.parametrize("topology", ["stephenson", "watt"])
def test_sixbar_kernel_matches_linkage_solve_and_scene(topology, tmp_path):
    from planar.synth.scene_out import linkage_scene_text, write_scene
    from planar.synth.search import Constraints
    from planar.synth.sixbar import SixBarDesign, check_sixbar, sixbar_points

    row = np.array([4.0, 1.0, 3.5, 3.0, 1.2, 0.9, 0.4, -0.3, 0.5, -2.0, 4.0, 4.0, 5.0, 1.5, -0.5, 1.0, 1.0])
    th = np.linspace(0.0, 2 * np.pi, 90, endpoint=False)
    x, y, m = sixbar_points(row[None], th, topology)
    assert (m > 0).all()
    d = SixBarDesign(topology, row, th[:5], np.column_stack([x[0, :5], y[0, :5]]), True, 0.0, 0.0)
    lk = d.linkage()
    got = lk.solve(th)
    assert got.valid.all()
    assert np.abs(got.points["tracer"] - np.column_stack([x[0], y[0]])).max() < 1e-9
    check_sixbar(d, Constraints(max_ratio=100.0), 1.0)
    assert d.ok and d.sse < 1e-20, d.checks
    scene = write_scene(tmp_path / "s.toml", linkage_scene_text("s", d.nodes(), d.links(), {"tracer": "T"}))
    assert np.abs(scene.mechanism.solve(th).points["tracer"] - got.points["tracer"]).max() < 1e-9


def test_function_rocker_pivot_on_negative_axis():
    # pairs measured from the world x axis of a four-bar whose rocker pivot is at (-ground, 0)
    fb = FourBar(5.0, 1.5, 4.0, 3.5)
    theta = np.array([0.3, 1.1, 2.0, 2.6])
    _, out, _ = fb.angles(theta)
    d = freudenstein_fit(theta + np.pi, out + np.pi, ground=5.0)
    assert d.ground_angle == pytest.approx(np.pi)
    assert d.max_error < 1e-9 and abs(d.crank - 1.5) < 1e-9


@pytest.mark.slow
def test_failed_checks_are_loud(tmp_path, capsys):
    from planar.synth.path import FourBarDesign, check_design

    # a double-rocker's crank cannot turn: the design's own check fails
    d = FourBarDesign(
        4, 3, 1.5, 3.5, (0.5, 0.2), "open", (0, 0, 0), np.array([0.5, 1.0, 1.5]), float("nan"), np.zeros((3, 2)), True, 0.0
    )
    check_design(d)
    assert not d.ok and not d.checks["ok_crank_turns_fully"]
    # four pairs no four-bar follows within 0.01 rad: written, reported, exit 3
    pairs = tmp_path / "p.csv"
    pairs.write_text("input,output\n10,60\n40,75\n70,95\n100,110\n")
    assert main(["synth", "function", str(pairs), "-o", str(tmp_path / "f.toml"), "--deg"]) == 3
    assert "check failed: output angle error" in capsys.readouterr().out


@pytest.mark.slow
def test_sixbar_search_recovers_known_watt_tracer_points():
    from planar.synth.sixbar import sixbar_points, synthesise_sixbar

    row = np.array([4.0, 1.0, 3.5, 3.0, 1.2, 0.9, 0.4, -0.3, 0.5, -2.0, 4.0, 4.0, 5.0, 1.5, -0.5, 1.0, 1.0])
    th = np.linspace(0.2, 2.6, 5)
    x, y, _ = sixbar_points(row[None], th, "watt")
    pts = np.column_stack([x[0], y[0]])
    d = synthesise_sixbar(pts, th, "watt", budget=(3000, 20, 6, 2))
    assert d.ok, d.checks
    # planar's general linkage solver, not the search kernel, puts the tracer on the targets (this small
    # budget reaches 1e-5 of the targets' size since every ternary link's sides count in the link ratio)
    got = d.linkage().solve(th).points["tracer"]
    assert np.hypot(*(got - pts).T).max() < 1e-4 * np.ptp(pts, axis=0).max()
