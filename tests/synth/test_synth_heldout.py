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
