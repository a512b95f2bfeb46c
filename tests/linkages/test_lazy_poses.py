"""Poses computed on first access (planar.core.model.LazyPoses) from the compiled solve's node positions."""

from __future__ import annotations

import copy
import pickle

import numpy as np
import pytest

pytest.importorskip("numba")

from planar.linkages import FourBar
from planar.linkages.chunked import fast_solve
from planar.scene.catalog import get


def _random_fourbars(count: int, seed: int) -> list[FourBar]:
    rng = np.random.default_rng(seed)
    out = []
    while len(out) < count:
        d = rng.uniform(0.05, 20.0, 4)
        if d.max() >= d.sum() - d.max():
            continue
        placed = tuple(rng.normal(scale=5.0, size=3)) if len(out) % 2 else (0.0, 0.0, 0.0)
        circuit = "open" if len(out) % 3 else "crossed"
        out.append(FourBar(*d, coupler_point=tuple(rng.normal(size=2)), placement=placed, circuit=circuit))
    return out


@pytest.mark.parametrize("n", [50, 3_000])
def test_lazy_poses_are_the_eager_solves_bits(n: int) -> None:
    """Poses read after the solve equal the poses the same kernels compute at once (fast_solve's default),
    on random four-bars (placed or not, either circuit, samples that fail) and Jansen's leg."""
    # a path, and values in no order (no branch carried: samples that fail stay on the compiled path)
    qs = (np.linspace(-7.0, 7.0, n), np.random.default_rng(n).uniform(-7.0, 7.0, n))
    fast = failing = 0
    for lk, q in [(lk, q) for lk in [*_random_fourbars(12, 5), get("jansen")] for q in qs]:
        m = lk.solve(q)
        eager = fast_solve(lk, q, jit=True)
        if eager is None:  # a branch may switch: the reference solve (no lazy poses)
            continue
        fast += 1
        failing += not m.valid.all()
        poses, _, points = eager
        assert sorted(m.poses) == sorted(poses)
        for k, v in poses.items():
            assert m.poses[k].tobytes() == np.ascontiguousarray(v).tobytes(), k
        for k, v in points.items():
            assert m.points[k].tobytes() == np.ascontiguousarray(v).tobytes(), k
    assert fast >= 8 and failing >= 2, (fast, failing)


def test_poses_are_computed_once_on_first_read_and_survive_copies() -> None:
    leg = get("jansen")
    q = np.linspace(0.0, 2 * np.pi, 200)
    m = leg.solve(q)
    assert "poses" not in vars(m)  # not computed by the solve
    assert "8 parts" in repr(m) and "poses" not in vars(m)  # the repr does not compute them
    first = m.poses
    assert m.poses is first  # computed once, then an ordinary attribute
    assert len(first) == len(leg.parts)
    m2 = leg.solve(q)
    for other in (pickle.loads(pickle.dumps(m2)), copy.deepcopy(leg.solve(q)), leg.solve(q).take(np.arange(5))):
        for k, v in first.items():
            np.testing.assert_array_equal(other.poses[k], v[: len(other)])
    # the crank's angle is the driver (closed form, not from our kernels)
    np.testing.assert_allclose(np.unwrap(first["crank"][:, 2]), q, atol=1e-12)
    # a coupler angle from the points: atan2 of the joint positions (numpy's)
    b, c = leg.node_positions(q)["A"], leg.node_positions(q)["B"]
    np.testing.assert_allclose(first["j"][:, 2], np.arctan2(c[:, 1] - b[:, 1], c[:, 0] - b[:, 0]), atol=1e-14)


def test_a_result_beyond_the_screen_is_screened_at_once() -> None:
    """Coordinates beyond the finite screen (1e300): the poses are computed and checked during the solve, so
    a sample whose pose overflows is invalid, as before."""
    big = FourBar(4e300, 1e300, 4e300, 3e300)
    m = big.solve(np.linspace(0.0, 6.0, 64))
    assert "poses" in vars(m)
    for v in m.poses.values():
        assert np.isfinite(v).all()
