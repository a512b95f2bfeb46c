"""The synthesis benchmark's error measure checked against pylinkage's solver, and its published figures."""

from __future__ import annotations

import math

import numpy as np
import pytest

from planar.bench.peers.pylinkage import PylinkageFourBar, place
from planar.bench.synthesis import PROBLEMS, format_synthesis, score_params, subset4

pytest.importorskip("pylinkage")

# a Grashof crank-rocker placed off the origin (planar's 9 parameters), used as input only
FOURBAR = np.array([3.0, 1.0, 3.2, 2.5, 1.1, 0.6, 2.0, 1.5, 0.3])


@pytest.mark.parametrize("circuit", [1.0, -1.0])
def test_timed_sse_matches_pylinkage_simulation(circuit):
    """planar's sse at the prescribed angles equals pylinkage's, simulated by pylinkage from the same joints."""
    prob = PROBLEMS["cabrera-2002-case-2"]
    t, th = np.asarray(prob["targets"], float), np.asarray(prob["theta"], float)
    d = score_params(FOURBAR, circuit, t, th)
    assert d is not None and d.checks["ok_crank_turns_fully"]
    assert d.sse == pytest.approx(PylinkageFourBar(t, th).sse(FOURBAR, circuit), rel=1e-9)


def test_untimed_sse_matches_pylinkage_simulation():
    """Untimed: each target's nearest of 7200 crank angles, in planar and in pylinkage's simulation."""
    t = np.asarray(PROBLEMS["kunjur-1997-line"]["targets"], float) / 10.0
    d = score_params(FOURBAR, 1.0, t, None)
    assert d is not None
    assert d.sse == pytest.approx(PylinkageFourBar(t, None, steps=7200).sse(FOURBAR, 1.0), rel=1e-9)


def test_place_closes_the_loop():
    A, D, B, C, _P = place(FOURBAR, -1.0)
    r1, r2, r3, r4 = FOURBAR[:4]
    assert np.hypot(*(D - A)) == pytest.approx(r1) and np.hypot(*(B - A)) == pytest.approx(r2)
    assert np.hypot(*(C - B)) == pytest.approx(r3) and np.hypot(*(C - D)) == pytest.approx(r4)
    assert place(np.array([10.0, 1.0, 1.0, 1.0, 0, 0, 0, 0, 0]), 1.0) is None


def test_peer_refuses_angles_off_its_steps():
    from planar.errors import PlanarError

    with pytest.raises(PlanarError, match="whole multiples"):
        PylinkageFourBar(np.zeros((3, 2)), np.array([0.0, 0.1, 0.2]))


@pytest.mark.parametrize("name", sorted(PROBLEMS))
def test_published_figures(name):
    """A published error is recomputed from the published linkage; without one the entry says where it was sought."""
    prob = PROBLEMS[name]
    t = np.asarray(prob["targets"], float)
    th = None if prob["theta"] is None else np.asarray(prob["theta"], float)
    if prob["published_params"] is None:
        assert prob["published"] == "not found" and "searched" in prob["searched"]
        return
    p, circuit = prob["published_params"]
    d = score_params(np.asarray(p, float), circuit, t, th)
    assert d is not None and math.isfinite(d.sse)
    assert d.sse == pytest.approx(float(prob["published"]), rel=0.05)


def test_subset4_and_format():
    assert subset4(6) == [0, 2, 3, 5] and subset4(5) == [0, 1, 3, 4] and subset4(4) == [0, 1, 2, 3]
    case = {
        "problem": "p",
        "targets": 6,
        "timed": False,
        "published_best_error": "not found",
        "published_source": "s",
        "planar": {"sse_median": 1.0, "sse_min": 1.0, "sse_max": 1.0, "time_s": {"median": 1.0}, "ok": True},
        "pylinkage": {"sse": None, "solutions": 0, "time_s": {"median": 0.1}},
        "pylinkage_without_grashof": {"sse": None, "solutions": 0, "crank_turns_fully": None, "time_s": 0.1},
        "pylinkage_four_targets": {"sse": 0.2, "solutions": 5, "crank_turns_fully": True, "time_s": 0.1},
        "pylinkage_optimisers": {
            "sse_median": 0.3,
            "sse_min": 0.2,
            "sse_max": 0.4,
            "pylinkage_sse_of_best": 0.2,
            "time_s": {"median": 1.0},
            "evaluations": 9,
        },
    }
    k = {"median": 1.0, "min": 1.0, "max": 1.0, "samples": 64, "threads": 1, "float64": {"median": 1.0, "min": 1.0, "max": 1.0}}
    out = format_synthesis({"repeats": 1, "cores": 2, "kernel_candidates_per_s": k, "cases": [case]})
    assert "pylinkage optimisers" in out and "published_searched" in out


def test_unreachable_problems_are_seeded_and_noisy_by_their_level():
    from planar.bench.synthesis import reachable_problem, unreachable_problem
    from planar.synth.sixbar import sixbar_points

    for kind in (0.005, 0.02, "stephenson", "watt"):
        a = unreachable_problem(np.random.default_rng(5), 12, kind)
        b = unreachable_problem(np.random.default_rng(5), 12, kind)
        assert a.shape == (12, 2) and np.isfinite(a).all() and np.array_equal(a, b)
    # the noise is Gaussian of the level given, a fraction of the targets' size
    rng = np.random.default_rng(9)
    st = rng.bit_generator.state
    noisy = unreachable_problem(rng, 200, 0.02)
    rng2 = np.random.default_rng(9)
    rng2.bit_generator.state = st
    rng2.uniform(0.0, 2 * np.pi, 200)  # the angles unreachable_problem draws first
    clean, _ = reachable_problem(rng2, 200)
    size = np.sqrt(np.mean(np.sum((clean - clean.mean(0)) ** 2, 1)))
    assert np.std(noisy - clean) / size == pytest.approx(0.02, rel=0.15)
    # a six-bar's second dyad closes over the whole turn (checked at 3600 crank angles)
    from planar.bench.synthesis import random_sixbar

    X = random_sixbar(np.random.default_rng(2), "watt")
    _, _, margin = sixbar_points(X[None, :], np.linspace(0, 2 * np.pi, 3600, endpoint=False), "watt")
    assert margin.min() > 0


def test_reachable_kinds_draw_what_they_name():
    """The reachable benchmark's kinds: drag-links are double-cranks with the ground shortest and crank-rockers
    crank-rockers (planar's FourBar says so), both valid over the whole turn on their circuit; a part-curve's crank
    angles are sorted and span at most 300 degrees; same seed, same targets; an unknown kind is refused naming the
    kinds."""
    from planar.bench.synthesis import REACHABLE_KINDS, bench_reachable, random_crank_rocker, random_drag_link
    from planar.errors import PlanarError
    from planar.linkages import FourBar

    rng = np.random.default_rng(41)
    for kind, draw in REACHABLE_KINDS.items():
        for _ in range(20):
            T, th = draw(rng, 9)
            assert T.shape == (9, 2) and np.all(np.diff(th) > 0)
            assert kind != "part-curve" or th[-1] - th[0] <= np.radians(300.0)
        a, b = draw(np.random.default_rng(3), 9), draw(np.random.default_rng(3), 9)
        assert np.array_equal(a[0], b[0]) and np.array_equal(a[1], b[1])
    for draw, grashof in ((random_drag_link, "double-crank"), (random_crank_rocker, "crank-rocker")):
        for _ in range(10):
            row, circ = draw(rng)
            circuit = "open" if circ > 0 else "crossed"
            fb = FourBar(*row[:4], coupler_point=(row[4], row[5]), circuit=circuit, placement=tuple(row[6:9]))
            assert fb.grashof == grashof
            assert (row[0] == row[:4].min()) == (grashof == "double-crank")
            assert fb.solve(np.linspace(0.0, 2 * np.pi, 90, endpoint=False)).valid.all()
    with pytest.raises(PlanarError, match=r"unknown kind 'rocker'.*drag-link"):
        bench_reachable(kinds=("rocker",))


@pytest.mark.slow
def test_bench_reachable_reports_every_kind():
    """One problem of each kind at 8 targets (quick atlas): the summary and the text name each kind with its
    untimed and timed figures; the timed problems are exact (the closed form), the noisy comparison only for the
    crank-rockers."""
    from planar.bench.synthesis import REACHABLE_KINDS, bench_reachable, format_reachable

    r = bench_reachable(sizes=(8,), count=1, quick=True, kind_count=1)
    assert [(s["kind"], s["targets"], s["problems"]) for s in r["summary"].values()] == [(k, 8, 1) for k in REACHABLE_KINDS]
    for s in r["summary"].values():
        assert s["timed_recovered_1e-6"] == 1.0 and s["timed_max_cpu_s"] >= s["timed_median_cpu_s"] > 0
        assert ("noisy_planar_as_good_as_scipy" in s) == (s["kind"] == "crank-rocker")
    text = format_reachable(r, [])
    assert all(f"  {k:<12}        8" in text for k in REACHABLE_KINDS)
