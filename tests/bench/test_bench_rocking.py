"""The rocking benchmark's problems (random double- and triple-rockers) and its quick run."""

from __future__ import annotations

import math

import numpy as np
import pytest

from planar.bench.synthesis_rocking import CHANGE_MARGIN, SUBRANGE, bench_rocking, format_rocking, rocking_problem
from planar.errors import InputError
from planar.linkages import FourBar


def _fourbar(p: dict) -> FourBar:
    g, a, b, c, u, v, x0, y0, phi = (float(x) for x in p["fourbar"])
    return FourBar(g, a, b, c, coupler_point=(u, v), circuit="open" if p["circuit"] > 0 else "crossed", placement=(x0, y0, phi))


@pytest.mark.parametrize("kind", ["double", "triple"])
def test_problems_lie_on_one_swing_of_a_rocking_fourbar(kind):
    # checked with planar's solver (not the kernel that made them): the four-bar is of the kind, its input
    # rocks, the targets are its coupler points at sorted angles inside one interval of its input's range,
    # away from its ends by the sub-range rule, and solving the swing as one path meets them all
    rng = np.random.default_rng(5)
    for n in (8, 25):
        for _ in range(4):
            p = rocking_problem(rng, kind, n)
            fb = _fourbar(p)
            g = sorted(p["fourbar"][:4])
            if kind == "double":
                assert fb.grashof == "double-rocker"
                assert g[0] + g[3] < (1 - CHANGE_MARGIN) * (g[1] + g[2]) + 1e-12
            else:
                assert fb.grashof == "non-Grashof"
                assert g[0] + g[3] > (1 + CHANGE_MARGIN) * (g[1] + g[2]) - 1e-12
            th = p["theta"]
            assert len(th) == n and np.all(np.diff(th) >= 0)
            ranges = fb.input_range()
            assert ranges != [(0.0, 2 * math.pi)]  # the input does not turn fully
            lo, hi = p["range"]
            u = np.mod(th - lo, 2 * math.pi) + lo  # on the range's own turn
            inside = [iv for iv in ranges if np.all(np.mod(u - iv[0], 2 * math.pi) <= iv[1] - iv[0] + 1e-9)]
            assert inside, (ranges, lo, hi)
            span = hi - lo
            assert u.min() - lo >= SUBRANGE[0] * span - 1e-9 and hi - u.max() >= SUBRANGE[0] * span - 1e-9
            sweep = np.unique(np.concatenate([np.linspace(u.min(), u.max(), 400), u]))
            path = fb.solve(sweep)
            assert path.valid.all()
            at = path.points["coupler_point"][np.searchsorted(sweep, u)]
            size = float(np.hypot(*np.ptp(p["targets"], axis=0)))
            assert np.max(np.hypot(*(at - p["targets"]).T)) <= 1e-9 * size
            outside = fb.solve(np.array([lo - 1e-3, hi + 1e-3]))
            assert not outside.valid.any()  # the range's ends are the input's limits


def test_problems_are_reproducible_and_kinds_checked():
    a = rocking_problem(np.random.default_rng([7, 12, 0]), "double", 12)
    b = rocking_problem(np.random.default_rng([7, 12, 0]), "double", 12)
    assert np.array_equal(a["targets"], b["targets"])
    with pytest.raises(InputError):
        rocking_problem(np.random.default_rng(0), "crank-rocker", 12)


@pytest.mark.slow
def test_quick_rocking_bench_runs_and_is_sane():
    r = bench_rocking(sizes=(8, 12), quick=True, seed=4)
    assert [(g["kind"], g["targets"]) for g in r["groups"]] == [("double", 8), ("double", 12), ("triple", 8), ("triple", 12)]
    for g in r["groups"]:
        assert g["count"] == len(g["problems"]) >= 1
        assert 0.0 <= g["within_1e-6"] <= g["within_1e-4"] <= g["within_1e-3"] <= 1.0
        for q in g["problems"]:
            assert q["error"] >= 0 and 0 < q["cpu_s"] < 120
        assert g["all_on_one_swing"] is True
    # the quick atlas still recovers most of these to a maker's tolerance
    within = [g["within_1e-3"] for g in r["groups"]]
    assert np.mean(within) >= 0.5
    text = format_rocking(r)
    assert "double-rockers" in text and "triple-rockers" in text
