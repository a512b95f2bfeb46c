"""The curve-window atlas: parts of full-turn four-bars' coupler curves, looked up for targets on part of a curve."""

from __future__ import annotations

import json

import numpy as np
import pytest

from planar.cli.main import main
from planar.errors import InputError
from planar.synth import windows as win
from planar.synth.arcs import build_arcs, read_arcs
from planar.synth.atlas import build_atlas
from planar.synth.kernel import coupler_points
from planar.synth.path import synthesise_path
from planar.synth.search import Constraints, PathObjective, _nearest_theta, max_distance, search_atlas


def _on_curve(row: np.ndarray, circ: float, th: np.ndarray) -> np.ndarray:
    x, y, ok = coupler_points(row[None, :], th[None, :], np.array([circ]))
    assert ok.all()
    return np.column_stack([x[0], y[0]])


def _kernel_row(p: np.ndarray) -> np.ndarray:
    """A stored entry (crank, coupler, rocker, u, v; ground 1 along +x from the origin) as the kernel's 9 numbers."""
    return np.array([1.0, *p[:5], 0.0, 0.0, 0.0])


def test_windows_are_deterministic_full_turn_arcs_of_the_stated_spans():
    a = win.build_windows(300, seed=3)
    b = win.build_windows(300, seed=3)
    assert a.kind == "windows" and a.per == len(win.SPANS_DEG)
    assert np.array_equal(a.desc, b.desc) and np.array_equal(a.params, b.params)
    assert not np.array_equal(a.desc, win.build_windows(300, seed=4).desc)
    spans = np.degrees(a.window[:, 1].astype(float) - a.window[:, 0].astype(float))
    assert np.allclose(np.unique(np.round(spans, 2)), win.SPANS_DEG, atol=0.01)
    # every stored four-bar's crank turns fully (Grashof, crank or ground shortest): it assembles all round
    th = np.linspace(0.0, 2 * np.pi, 97)
    for p in a.params[:40].astype(float):
        L = sorted([1.0, *p[:3]])
        assert L[0] + L[3] < L[1] + L[2]
        _, _, ok = coupler_points(_kernel_row(p)[None, :], th[None, :], np.array([p[5]]))
        assert ok.all()


def test_an_entrys_own_arc_finds_it_placed_on_the_targets():
    # targets on one stored window's arc, moved, turned and scaled: the lookup's first candidate is that entry (its
    # shape: the links over the ground), placed near the targets (the spline through 12 of them is not the arc
    # itself, so the placement is a start, not a fit: within 2 % of the size)
    w = win.build_windows(2_000, seed=0)
    rng = np.random.default_rng(20261216)
    for j in rng.choice(len(w), 5, replace=False):
        p = w.params[j].astype(float)
        a0, a1 = (float(v) for v in w.window[j])
        th = np.linspace(a0, a1, 12)
        pts = _on_curve(_kernel_row(p), float(p[5]), th)
        z = (pts[:, 0] + 1j * pts[:, 1]) * 2.5 * np.exp(0.7j) + (0.3 - 1.1j)
        t = np.column_stack([z.real, z.imag])
        c = win.window_candidates(w, t, k=4)
        obj = PathObjective(t, None, Constraints(), 720)
        size = float(np.sqrt(np.mean(np.sum((t - t.mean(0)) ** 2, 1))))
        assert np.allclose(c[0, 1:6] / c[0, 0], p[:5], rtol=1e-5), (c[0], p)
        assert max_distance(obj, c[0], _nearest_theta(obj, c[0])) / size < 0.02


def test_a_window_atlas_is_not_read_as_rocking_arcs_nor_the_other_way(tmp_path):
    w = win.build_windows(200, seed=0)
    w.save(tmp_path / "w.npz")
    build_arcs(200, seed=0).save(tmp_path / "r.npz")
    with pytest.raises(InputError, match="windows atlas format"):
        read_arcs(tmp_path / "w.npz")
    with pytest.raises(InputError, match="rocking atlas format"):
        read_arcs(tmp_path / "r.npz", win.KIND, len(win.SPANS_DEG))
    assert read_arcs(tmp_path / "w.npz", win.KIND, len(win.SPANS_DEG)).kind == "windows"
    with pytest.raises(InputError, match="windows"):
        synthesise_path(np.random.default_rng(0).random((8, 2)), windows=build_arcs(200, seed=0))


def _part_curve(rng: np.random.Generator, n: int) -> tuple[np.ndarray, np.ndarray, float]:
    """``n`` targets on a random 90 to 200 degree arc of a random crank-rocker's curve (lengths uniform, not the
    atlas's log-uniform), their crank angles and the circuit."""
    while True:
        a, c, r = rng.uniform(0.4, 2.5, 3)
        k = rng.uniform(0.15, 0.8) * min(a, c, r)
        L = sorted((a, k, c, r))
        if L[0] == k and L[0] + L[3] < 0.95 * (L[1] + L[2]):
            break
    row = np.array([a, k, c, r, c * rng.uniform(-1, 2), c * rng.uniform(-1, 1), *rng.uniform(-1, 1, 2), rng.uniform(-3, 3)])
    circ = float(rng.choice([-1.0, 1.0]))
    th = rng.uniform(-np.pi, np.pi) + np.sort(rng.uniform(0.0, np.radians(rng.uniform(90, 200)), n))
    return _on_curve(row, circ, th), th, circ


@pytest.mark.slow
def test_part_curves_recovered_through_their_windows():
    # random crank-rockers never used to build or tune anything, 8 targets on an arc of 90 to 200 degrees: with
    # the windows the search passes every target (largest distance over the size) in order; the windows' stage ran
    # whenever the closed-curve starts failed, and it is what recovers more of them than the search without it
    atlas = build_atlas(200_000, seed=0)
    windows = win.build_windows(60_000, seed=0)
    rng = np.random.default_rng(20261217)
    with_w, without = [], []
    for _ in range(10):
        t, _, _ = _part_curve(rng, 8)
        c = t.mean(0)
        s = float(np.sqrt(np.mean(np.sum((t - c) ** 2, 1))))
        tn = (t - c) / s
        r = search_atlas(tn, atlas, ordered=True, windows=lambda q, k: win.window_candidates(windows, q, k))
        obj = PathObjective(tn, None, Constraints(), 128)
        with_w.append(max_distance(obj, np.append(r.params, r.circuit), r.theta))
        r0 = search_atlas(tn, atlas, ordered=True)
        without.append(max_distance(obj, np.append(r0.params, r0.circuit), r0.theta))
    ok_w = sum(e <= 1e-6 for e in with_w)
    assert ok_w >= 8, with_w
    assert ok_w >= sum(e <= 1e-6 for e in without), (with_w, without)


def test_synth_path_builds_the_windows_on_first_need_and_atlas_windows_builds_them(tmp_path, capsys):
    # quick budget, 8 targets on part of a curve: the window atlas of the budget is built in the cache folder the
    # first time the closed-curve starts fail (one line says so), and synth atlas --windows reports it exists
    rng = np.random.default_rng(20261239)  # one whose closed-curve starts fail on the quick atlas
    t, _, _ = _part_curve(rng, 8)
    f = tmp_path / "arc.csv"
    f.write_text("x,y\n" + "\n".join(f"{a!r},{b!r}" for a, b in t.tolist()) + "\n")
    out = tmp_path / "o.toml"
    main(["synth", "path", str(f), "-o", str(out), "--budget", "quick", "--ordered", "--json", "--full-turn"])
    cap = capsys.readouterr()
    rep = json.loads(cap.out)
    stages = rep["checks"]["stages_s"]
    assert "windows_s" in stages and "windows_load_s" in stages, stages  # built and looked up
    assert "building the curve-window atlas once (5,000 four-bars" in cap.err
    assert win.windows_path(win.QUICK_FOURBARS).exists() and rep["checks"]["max_error"] <= 1e-6
    assert main(["synth", "atlas", "--windows", "--size", str(win.QUICK_FOURBARS)]) == 0
    assert "curve-window atlas of" in capsys.readouterr().out  # exists: not rebuilt
    assert main(["synth", "atlas", "--windows", "--rocking"]) == 2
    assert main(["synth", "atlas", "--windows", "--size", "50", "-o", str(tmp_path / "w.npz")]) == 2
    assert "--size" in capsys.readouterr().err and not (tmp_path / "w.npz").exists()
