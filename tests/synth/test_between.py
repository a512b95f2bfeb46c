"""The coupler path between untimed targets, against the smooth curve through them (a dip, loop or overshoot)."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
import shapely
from scipy.interpolate import CubicSpline

from planar.linkages import FourBar
from planar.synth.drawing import DETOUR, DETOUR_LENGTH, between_caution, between_targets

# a crank-rocker whose coupler curve crosses itself (a figure eight): found by shapely's is_simple over random
# four-bars, one whose lobe reaches far from the rest
LOOPED = FourBar(3.211, 1.0, 2.66, 2.055, coupler_point=(1.846, -3.143))


def _design(fb: FourBar, theta: np.ndarray) -> SimpleNamespace:
    """What :func:`between_targets` reads of a design: its four-bar, crank angles, targets and their size."""
    t = np.asarray(fb.solve(theta).points["coupler_point"], float)
    size = float(np.sqrt(np.mean(np.sum((t - t.mean(0)) ** 2, 1))))
    return SimpleNamespace(fourbar=lambda: fb, theta=theta, targets=t, checks={"size": size})


def _loop_angles(fb: FourBar, n: int = 2000) -> tuple[float, float]:
    """The crank angles (rad) where the curve's loop starts and ends (its self-crossing), by brute force over
    segment pairs."""
    th = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    p = np.asarray(fb.solve(th).points["coupler_point"], float)
    segs = [shapely.LineString([p[i], p[(i + 1) % n]]) for i in range(n)]
    tree = shapely.STRtree(segs)
    for i, s in enumerate(segs):
        for j in tree.query(s, predicate="intersects"):
            if abs(int(j) - i) > 2 and abs(int(j) - i) < n - 2:
                a, b = sorted((i, int(j)))
                return (th[a], th[b]) if b - a < n / 2 else (th[b], th[a] + 2 * np.pi)
    raise AssertionError("no loop")


def test_a_loop_between_two_targets_is_found_and_measured_as_a_dense_check_does():
    a, b = _loop_angles(LOOPED)
    # one target just before the loop, then 7 from just after it round the rest of the turn, in the crank's order:
    # the loop lies between targets 1 and 2
    others = np.linspace(b + 0.15, a - 0.15 + 2 * np.pi, 8)[:-1]
    theta = np.mod(np.concatenate([[a - 0.15], others]), 2 * np.pi)
    d = _design(LOOPED, theta)
    got = between_targets(d)
    assert got["between_detour"] is not None and got["between_detour"]["targets"] == [1, 2], got
    # the same figures by brute force: the path densely from planar's solver, the smooth curve densely from scipy
    t = d.targets
    seg = np.linalg.norm(np.diff(t, axis=0), axis=1)
    s = np.concatenate([[0.0], np.cumsum(seg)])
    spline = CubicSpline(s, t, bc_type="natural")
    curve = spline(np.linspace(0.0, s[-1], 40_000))
    step = np.mod(theta[1] - theta[0], 2 * np.pi)
    path = np.asarray(LOOPED.solve(theta[0] + step * np.linspace(0, 1, 1500)).points["coupler_point"], float)
    far = np.sqrt(((path[:, None, :] - curve[None, ::8, :]) ** 2).sum(-1)).min(1).max() / d.checks["size"]
    ratio = (
        np.linalg.norm(np.diff(path, axis=0), axis=1).sum()
        / np.linalg.norm(np.diff(spline(np.linspace(s[0], s[1], 3000)), axis=0), axis=1).sum()
    )
    assert abs(got["between_detour"]["distance"] - far) <= 0.03 * far
    assert abs(got["between_detour"]["length_ratio"] - ratio) <= 0.01 * ratio
    assert far > DETOUR and ratio > DETOUR_LENGTH
    (line,) = between_caution(got)
    assert line.startswith("between targets 1 and 2 the coupler path strays up to")


def test_targets_along_a_smooth_curve_raise_no_caution():
    # 20 targets spread over random crank-rockers' curves (lengths uniform, never tuned on): the path between
    # neighbouring targets keeps near the smooth curve through them, and nothing is said
    rng = np.random.default_rng(20261219)
    for _ in range(8):
        while True:
            g, c, r = rng.uniform(1.5, 4.0, 3)
            if 1 + max(g, c, r) < sum((g, c, r)) - max(g, c, r):
                break
        fb = FourBar(g, 1.0, c, r, coupler_point=(c * rng.uniform(-0.5, 1.5), c * rng.uniform(-0.5, 0.5)))
        theta = np.sort(rng.uniform(0, 2 * np.pi, 20))
        got = between_targets(_design(fb, theta))
        assert got["between_detour"] is None and between_caution(got) == [], got


def test_targets_out_of_order_are_not_measured():
    theta = np.array([0.0, 2.0, 1.0, 3.0, 4.0])
    assert between_targets(_design(LOOPED, theta)) == {}


# a shallow S ending in a hook, drawn by eye in a new-user trial (no four-bar passes through it exactly)
HOOK = [(0, 0), (1, 0.6), (2, 0.9), (3, 0.8), (4, 0.4), (5, 0.1), (6, 0.2), (6.8, 0.7), (7.2, 1.5)]


@pytest.mark.slow
def test_synth_path_says_where_the_path_strays_and_a_drawing_says_it_its_own_way(tmp_path, capsys):
    # CSV targets: the caution names the stretch and its figures, as checks.between_detour has them; the same
    # points as an SVG polyline: the drawing's own check speaks instead (no smooth-curve line beside it)
    import json

    from planar.cli.main import main

    csv = tmp_path / "hook.csv"
    csv.write_text("x,y\n" + "\n".join(f"{x},{y}" for x, y in HOOK) + "\n")
    args = ["--budget", "quick", "--ordered", "--full-turn", "--json"]
    main(["synth", "path", str(csv), "-o", str(tmp_path / "a.toml"), *args])
    c = json.loads(capsys.readouterr().out)["checks"]
    worst = c["between_detour"]
    assert worst is not None and worst["distance"] > DETOUR and worst["length_ratio"] > DETOUR_LENGTH, c
    a, b = worst["targets"]
    said = [x for x in c["cautions"] if x.startswith(f"between targets {a} and {b} ")]
    assert len(said) == 1 and f"{worst['distance']:.3g} of the targets' size" in said[0]
    pts = " ".join(f"{x},{-y}" for x, y in HOOK)  # SVG's y points down
    svg = tmp_path / "hook.svg"
    svg.write_text(f'<svg xmlns="http://www.w3.org/2000/svg"><polyline points="{pts}" fill="none"/></svg>')
    main(["synth", "path", str(svg), "--points", "9", "-o", str(tmp_path / "b.toml"), *args])
    c2 = json.loads(capsys.readouterr().out)["checks"]
    assert "drawing_max_distance" in c2 and not any(x.startswith("between targets ") for x in c2["cautions"])
