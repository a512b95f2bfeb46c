"""The chunked, threaded ``Linkage.solve`` against the reference solve (``solve_nodes`` + ``carry_branch``)."""

import numpy as np
import pytest

from planar.core.geometry import poses_apply
from planar.core.model import merge_failures
from planar.linkages import RRR, Crank, Fixed, FourBar, Link, Linkage
from planar.linkages.chunked import fast_solve
from planar.scene.catalog import CATALOG, get


def _linkages():
    out = {k: get(k) for k in CATALOG if not k.startswith(("windup", "horse", "bunny"))}
    out = {k: m for k, m in out.items() if isinstance(m, Linkage)}
    out["parallelogram"] = FourBar(2.0, 1.0, 2.0, 1.0)
    out["kite"] = FourBar(1.0, 1.0, 2.0, 2.0)
    out["toggle"] = FourBar(4.0, 2.5, 2.0, 3.0, coupler_point=(1.0, -0.5))
    # near a change point: the two roots come close but the motion need not switch
    out["near-parallelogram"] = FourBar(2.0, 1.0, 2.0, 1.001)
    out["near-parallelogram-fine"] = FourBar(2.0, 1.0, 2.0, 1.02)
    return out


LINKAGES = _linkages()
QS = {
    "path": np.linspace(0.0, 4 * np.pi, 3001),
    "backward": np.linspace(3.0, -3.0, 2001),
    "scattered": np.random.default_rng(5).uniform(-10, 10, 2000),
    "one": np.array([0.3]),
    # steps alternate in sign (no path: the chunked path throughout); 0 puts the kite's crank pin
    # on its rocker pivot (concentric circles, invalid)
    "zigzag": np.resize([0.0, 2.0, -1.0, 3.0, 0.5, -2.5], 4000) + np.repeat([0.0, 1e-3], 2000),
}


def _reference(lk, q):
    poses, checks = lk._solve_poses(q)
    valid, code, table = merge_failures(q.shape[0], checks)
    pts = {n: poses_apply(poses[part], xy) for n, (part, xy) in lk.points.items()}
    return poses, valid, code, table, pts


@pytest.mark.parametrize("name", sorted(LINKAGES))
def test_solve_matches_the_reference_solve(name):
    lk = LINKAGES[name]
    for q in QS.values():
        m = lk.solve(q)
        poses, valid, code, table, pts = _reference(lk, q)
        assert np.array_equal(m.valid, valid) and np.array_equal(m.fail_code, code) and m.fail_table == table
        tol = 1e-9 * lk.size
        for part, p in poses.items():
            assert np.abs(m.poses[part][:, :2] - p[:, :2]).max() <= tol
            assert np.abs(m.poses[part][:, 2] - p[:, 2]).max() <= 1e-9  # same arctan2: no 2 pi jumps
        for n, p in pts.items():
            assert np.abs(m.points[n] - p).max() <= tol


def test_results_do_not_depend_on_threads_or_chunk_size():
    lk = get("jansen")
    q = 2 * np.pi / 3600 * np.arange(1, 5001)
    a = fast_solve(lk, q, threads=1, chunk=8192)
    b = fast_solve(lk, q, threads=2, chunk=300)
    c = fast_solve(lk, q, threads=3, chunk=777)
    assert a is not None and b is not None and c is not None
    for other in (b, c):
        for part in a[0]:
            assert np.array_equal(a[0][part], other[0][part])
        for n in a[2]:
            assert np.array_equal(a[2][n], other[2][n])


def test_branch_screen_sends_singular_paths_to_the_reference():
    q = np.linspace(0.0, 2 * np.pi, 721)
    # a change-point four-bar passes through its flat positions: continuity may switch roots
    assert fast_solve(LINKAGES["parallelogram"], q) is None
    assert fast_solve(LINKAGES["kite"], q) is None
    # a Grashof crank-rocker never nears a singular position: solved by the chunked path
    assert fast_solve(get("fourbar-crank-rocker"), q) is not None
    assert fast_solve(get("jansen"), q) is not None
    # driver steps that alternate in sign are no path: continuity never applies, no fallback needed
    zigzag = np.where(np.arange(2000) % 2 == 0, 1.0, -1.0) * np.random.default_rng(2).uniform(0.1, 3.0, 2000)
    assert fast_solve(LINKAGES["parallelogram"], zigzag) is not None


def test_invalid_samples_are_named_as_by_the_reference():
    lk = LINKAGES["toggle"]
    m = lk.solve(QS["path"])
    assert not m.valid.all() and m.failed_joints == {"C"}
    # a node kind without a chunk kernel: the reference path, same answers
    from dataclasses import dataclass
    from typing import ClassVar

    from planar.linkages import node_kind

    @node_kind
    @dataclass(frozen=True)
    class Mirror(Fixed):
        kind: ClassVar[str] = "test-mirror-fixed"

    nodes = [Fixed("O2", (0.0, 0.0)), Mirror("O4", (4.0, 0.0)), Crank("B", "O2", 1.0), RRR("C", "B", 4.0, "O4", 3.0)]
    links = [Link("crank", ("O2", "B")), Link("coupler", ("B", "C")), Link("rocker", ("O4", "C"))]
    odd = Linkage("odd", nodes, links, points={"c": "C"})
    assert fast_solve(odd, QS["path"]) is None
    ref = get("fourbar-crank-rocker").solve(QS["path"])
    assert np.abs(odd.solve(QS["path"]).poses["rocker"] - ref.poses["rocker"]).max() < 1e-12
