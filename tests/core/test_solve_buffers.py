"""Recycled output blocks (planar.core.buffers) and the compiled path's finite screen."""

from __future__ import annotations

import gc

import numpy as np
import pytest

pytest.importorskip("numba")

from planar.core import buffers
from planar.linkages import FourBar
from planar.linkages.chunked import JIT_MIN, JIT_THREADS_MIN, solver_for
from planar.scene.catalog import get

N = max(JIT_MIN, 40_000)  # large enough for the compiled path and for blocks the pool takes
needs_pool = pytest.mark.skipif(buffers._FREE < 0, reason="reference counts do not tell on this interpreter")


def _address(a: np.ndarray) -> int:
    return int(a.__array_interface__["data"][0])


def test_a_held_result_is_never_written_by_a_later_solve() -> None:
    leg = get("jansen")
    assert solver_for(leg, N) == "compiled"
    q1 = np.linspace(0.0, 2 * np.pi, N)
    first = leg.solve(q1)
    keep = first.poses["j"][::7, 1:]  # a view of a view of the output block: all the caller keeps
    kept = keep.copy()
    foot = first.points["foot"].copy()
    del first
    gc.collect()
    for _ in range(3):  # solves of other angles: none may land in the block ``keep`` views
        other = leg.solve(q1 + 1.0)
        del other
    np.testing.assert_array_equal(keep, kept)
    again = leg.solve(q1)  # and the values are the solve's own (not a stale block's)
    np.testing.assert_array_equal(again.points["foot"], foot)


@needs_pool
def test_a_released_block_is_written_again_and_release_returns_it() -> None:
    leg = get("jansen")
    q = np.linspace(0.0, 2 * np.pi, N)
    gc.collect()
    buffers.release()  # blocks other tests released: the next solve takes new memory
    m = leg.solve(q)
    where = _address(m.poses["j"])
    del m
    gc.collect()
    assert buffers.pooled_bytes() >= 7 * N * 3 * 8  # the parts' block, waiting for the next solve
    m = leg.solve(q + 0.5)
    assert _address(m.poses["j"]) == where  # the same memory, no new pages
    ref = leg.solve(q[:100] + 0.5)  # below the pool's size: new arrays, the numpy path
    np.testing.assert_allclose(m.poses["j"][:100], ref.poses["j"], rtol=0, atol=1e-12)
    del m
    gc.collect()
    buffers.release()
    assert buffers.pooled_bytes() == 0


def test_recycling_can_be_turned_off(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("PLANAR_RECYCLE", "0")
    leg = get("jansen")
    q = np.linspace(0.0, 2 * np.pi, N)
    m = leg.solve(q)
    where = _address(m.poses["j"])
    held = buffers.pooled_bytes()
    m2 = leg.solve(q)
    assert _address(m2.poses["j"]) != where
    assert buffers.pooled_bytes() == held


@pytest.mark.filterwarnings("ignore::RuntimeWarning")  # the plan's bounds overflow in passing
def test_compiled_path_marks_overflowing_samples_invalid_as_the_numpy_path(monkeypatch: pytest.MonkeyPatch) -> None:
    """A coupler point near the float64 limit overflows in some poses: those samples are invalid (with the
    reason) and hold 0, the same samples as the numpy kernels find."""
    from planar.core.model import Hole, Mechanism, Part, Pivot
    from planar.linkages.linkage import Linkage

    with monkeypatch.context() as m:  # past what the constructors accept (an infinite hull): the kernels' own guard
        m.setattr(Linkage, "_check_node_resolution", lambda self, name: None)  # a coupler point float64 cannot resolve
        m.setattr(Mechanism, "_check_resolution", lambda self: None)
        m.setattr(Part, "__post_init__", lambda self: None)
        m.setattr(Pivot, "__post_init__", lambda self: None)  # its pins: an infinite diameter
        m.setattr(Hole, "__post_init__", lambda self: None)  # and their holes
        big = FourBar(4.0, 1.0, 4.0, 3.0, coupler_point=(1.3e308, -1.3e308))
    big.__dict__["_placement_checked"] = True  # and past the solve's own placement check, as if it passed
    q = np.linspace(0.0, 2 * np.pi, N)
    assert solver_for(big, N) == "compiled"
    with np.errstate(all="ignore"):
        fast = big.solve(q)
        monkeypatch.setenv("PLANAR_JIT", "0")
        slow = big.solve(q)
    assert 0 < (~fast.valid).sum() < N  # some overflow, some do not
    np.testing.assert_array_equal(fast.valid, slow.valid)
    assert any("non-finite" in why for _, why in fast.fail_table)
    for arr in (*fast.poses.values(), *fast.points.values()):
        assert np.isfinite(arr).all()
    # an independent count: where x cos - y sin (or x sin + y cos) of the coupler point overflows
    a = slow.poses["coupler"][:, 2]
    with np.errstate(all="ignore"):
        cx = np.cos(a) * 1.3e308 + np.sin(a) * 1.3e308 + slow.poses["coupler"][:, 0]
        cy = np.sin(a) * 1.3e308 - np.cos(a) * 1.3e308 + slow.poses["coupler"][:, 1]
    np.testing.assert_array_equal(~fast.valid, ~(np.isfinite(cx) & np.isfinite(cy)))


@pytest.mark.parametrize("n", [50, N])  # the numpy (or reference) path and the compiled one
def test_the_ground_pose_is_one_read_only_row(n: int) -> None:
    """The ground never moves: every path returns its track as one row seen n times, read-only, at the
    linkage's placement."""
    from planar.linkages import Linkage

    for mech in (get("jansen"), FourBar(4.0, 1.0, 4.0, 3.0, coupler_point=(2.0, 1.0))):
        m = mech.solve(np.linspace(0.0, 2 * np.pi, n))
        ground = next(p.name for p in mech.parts if p.ground)
        g = m.poses[ground]
        assert g.shape == (n, 3) and g.strides[0] == 0 and not g.flags.writeable
        expect = np.array(mech.placement, float) if isinstance(mech, Linkage) else np.zeros(3)
        np.testing.assert_array_equal(g, np.broadcast_to(expect, (n, 3)))
        with pytest.raises(ValueError, match="read-only"):
            g[0, 0] = 1.0


@needs_pool
def test_released_blocks_stay_within_the_cap_when_a_solve_starts(monkeypatch: pytest.MonkeyPatch) -> None:
    """Solves of many sizes: the pool never holds more than MAX_BYTES of released blocks when a solve takes a new
    block (a new user's 300 solves of random sizes reached 695 MiB against 512)."""
    monkeypatch.setattr(buffers, "MAX_BYTES", 8 << 20)
    leg = FourBar(4.0, 1.0, 4.0, 3.0, coupler_point=(2.0, 1.0))
    gc.collect()
    buffers.release()
    seen = []
    for n in np.random.default_rng(0).integers(30_000, 100_000, 40):
        m = leg.solve(np.linspace(0.0, 2 * np.pi, int(n)))
        seen.append(buffers.pooled_bytes())  # released blocks, while this result is held
        del m
    assert max(seen) <= 8 << 20, max(seen)
    buffers.release()


def test_bad_settings_and_inputs_are_one_line_errors(monkeypatch: pytest.MonkeyPatch) -> None:
    from planar.errors import InputError, LimitError

    leg = FourBar(4.0, 1.0, 4.0, 3.0)
    q = np.linspace(0.0, 1.0, N)
    # PLANAR_THREADS is read where threads may run: from JIT_THREADS_MIN samples
    threaded = np.linspace(0.0, 1.0, max(N, JIT_THREADS_MIN))
    for var, bad in (("PLANAR_THREADS", "abc"), ("PLANAR_THREADS", "0"), ("PLANAR_RECYCLE", "maybe")):
        monkeypatch.setenv(var, bad)
        with pytest.raises(InputError, match=var):
            leg.solve(threaded if var == "PLANAR_THREADS" else q)
        monkeypatch.delenv(var)
    monkeypatch.setenv("PLANAR_RECYCLE", "off")
    assert leg.solve(q).valid.all()
    monkeypatch.delenv("PLANAR_RECYCLE")
    monkeypatch.setenv("PLANAR_MAX_SAMPLES", "1000")
    with pytest.raises(LimitError, match="PLANAR_MAX_SAMPLES"):
        leg.solve(q)
    monkeypatch.delenv("PLANAR_MAX_SAMPLES")
    with pytest.raises(InputError, match="masked"):
        leg.solve(np.ma.masked_greater(q, 0.5))
    with pytest.raises(InputError, match="bool"):
        leg.solve(q > 0.5)


@needs_pool
def test_released_blocks_follow_what_is_held() -> None:
    """A long-running caller solving many sizes (a render: motion after motion) never calls release(): when a
    solve takes a new block, the released blocks are trimmed to at most the bytes held in results (they were
    allowed up to MAX_BYTES, 512 MiB, whatever was held)."""
    leg = FourBar(4.0, 1.0, 4.0, 3.0, coupler_point=(2.0, 1.0))
    gc.collect()
    buffers.release()
    keep = leg.solve(np.linspace(0.0, 2 * np.pi, 100_000))
    assert len(keep.poses) == 4
    seen = []
    for n in np.geomspace(30_000, 99_000, 14).astype(int):  # growing: no released block serves the next solve
        m = leg.solve(np.linspace(0.0, 2 * np.pi, int(n)))
        assert len(m.poses) == 4
        seen.append((buffers.pooled_bytes(), buffers.held_bytes()))
        del m
    assert all(free <= held for free, held in seen), seen
    assert max(held for _, held in seen) < 64 << 20  # the held result and one solve's blocks
    del keep
    buffers.release()
