"""Held-out function and motion problems: made from known four-bars, checked by geometry nobody here wrote."""

from __future__ import annotations

import numpy as np
import pytest

from planar.bench.synthesis_heldout import (
    bench_function_heldout,
    bench_motion_heldout,
    format_heldout,
    function_problem,
    motion_problem,
)


def test_function_pairs_satisfy_freudenstein():
    # Freudenstein's equation (Norton's form) with K from the four-bar's own lengths holds at every pair
    rng = np.random.default_rng(5)
    for free in (False, True):
        for n in (3, 7, 10):
            p = function_problem(rng, n, free)
            d, a, b, c = p["fourbar"]
            A, B = p["offsets"]
            phi, psi = p["phi"] + A, p["psi"] + B
            K1, K2, K3 = d / a, d / c, (a * a - b * b + c * c + d * d) / (2 * a * c)
            assert np.allclose(K1 * np.cos(psi) - K2 * np.cos(phi) + K3, np.cos(phi - psi), atol=1e-10)
            assert np.all(np.diff(p["phi"]) > 0)


def test_motion_poses_keep_both_dyads_rigid():
    # the body's crank pin and rocker pin (fixed in the body) stay at their link lengths from the ground pivots
    rng = np.random.default_rng(6)
    for n in (3, 4, 5):
        p = motion_problem(rng, n)
        poses = p["poses"]
        d, a, b, r, u, v, x0, y0, phi = p["fourbar"]
        O2 = np.array([x0, y0])
        O4 = O2 + d * np.array([np.cos(phi), np.sin(phi)])
        ang = poses[:, 2] - p["offset"]  # the coupler's angle
        e = np.column_stack([np.cos(ang), np.sin(ang)])
        nrm = np.column_stack([-e[:, 1], e[:, 0]])
        B = poses[:, :2] - u * e - v * nrm
        C = B + b * e
        assert np.allclose(np.hypot(*(B - O2).T), a, atol=1e-9)
        assert np.allclose(np.hypot(*(C - O4).T), r, atol=1e-9)


@pytest.mark.slow
def test_heldout_small_run_recovers_and_reports_the_nearest():
    fn = bench_function_heldout(count=3, seed=1, sizes=(3, 6))
    mo = bench_motion_heldout(count=3, seed=1, sizes=(4, 5))
    s = fn["summary"]
    assert s["fixed 3"]["recovered"] == 1.0 and s["fixed 6"]["recovered"] == 1.0
    assert s["unreachable 6"]["exit_3"] == 1.0 and s["unreachable 6"]["median_error"] > 1e-6
    assert mo["summary"]["5"]["recovered"] >= 2 / 3
    text = format_heldout(fn, mo)
    assert "function, 3 pairs, fixed offsets" in text and "motion, 5 poses" in text


def test_pylinkage_on_the_first_problems_of_each_size(monkeypatch):
    """``per_size`` keeps the first problems of each number of targets, in the order drawn (the peer stubbed)."""
    from planar.bench import synthesis_heldout as H

    seen = []
    monkeypatch.setattr(H, "_pylinkage_path", lambda T, th, score: seen.append((len(T), th is None)) or (0.5, 0.0, "stub"))
    rng = np.random.default_rng(9)
    problems = [{"n": n, "targets": rng.random((n, 2)), "theta": rng.random(n)} for n in (8, 12, 8, 25, 12, 8, 25)]
    r = H.bench_reachable_pylinkage(problems, score=None, per_size=2)
    assert [row["targets"] for row in r["rows"]] == [8, 12, 8, 25, 12, 25]
    assert r["count"] == 2 and [s["untimed"]["problems"] for s in r["summary"].values()] == [2, 2, 2]
    assert seen == [(n, untimed) for n in (8, 12, 8, 25, 12, 25) for untimed in (True, False)]
    assert len(H.bench_reachable_pylinkage(problems, score=None)["rows"]) == len(problems)
