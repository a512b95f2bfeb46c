"""The compiled (numba) kernels behind ``Linkage.solve`` against the numpy kernels, the reference
solve (``solve_nodes`` + ``carry_branch``) and scipy's root finder."""

import glob
import math
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("numba")

from scipy.optimize import root

from planar.core.geometry import poses_apply
from planar.core.model import merge_failures
from planar.errors import PlanarError
from planar.linkages import RRP, RRR, Actuator, Crank, Fixed, FourBar, Link, Linkage, Rigid, chunked
from planar.linkages.chunked import fast_solve
from planar.scene.catalog import CATALOG, get
from planar.scene.load import load_scene

GALLERY = Path(__file__).resolve().parents[2] / "gallery"


def _actuated() -> Linkage:
    """A linear actuator pushing a rod against a rocker (translation driver, invalid past its reach)."""
    nodes = [
        Fixed("O", (0.0, 0.0)),
        Fixed("O2", (1.0, 0.2)),
        Fixed("R", (3.0, 2.0)),
        Actuator("S", "O", (1.0, 0.2), 0.5),
        RRR("C", "S", 2.0, "R", 1.8, 1),
        Rigid("P", "S", "C", (1.0, 0.4)),
    ]
    links = [Link("block", ("S",), guide=("O", "O2")), Link("rod", ("S", "C", "P")), Link("rocker", ("R", "C"))]
    return Linkage("actuated", nodes, links, points={"tip": "P"}, amplitude=1.0)


def _slotted() -> Linkage:
    """Crank and slotted lever, with a second pin (an ``rrp`` node) running in the moving lever's slot."""
    nodes = [
        Fixed("O", (0.0, 0.0)),
        Fixed("Q", (0.0, -2.0)),
        Fixed("F", (0.5, -0.5)),
        Crank("A", "O", 1.0),
        Rigid("L", "Q", "A", (4.0, 0.0)),
        RRP("X", "F", 2.0, "Q", "L", 1, 0.1),
    ]
    links = [
        Link("crank", ("O", "A")),
        Link("block", ("A",), guide=("Q", "L")),
        Link("lever", ("Q", "L")),
        Link("rod", ("F", "X")),
    ]
    return Linkage("slotted", nodes, links, points={"pin": "X", "tip": "L"}, placement=(0.3, -0.2, 0.4))


def _random_fourbars(k: int) -> dict[str, FourBar]:
    """Four-bars of random proportions, many of them unable to turn fully (invalid samples)."""
    rng = np.random.default_rng(11)
    out: dict[str, FourBar] = {}
    while len(out) < k:
        g, a, b, c = rng.uniform(0.5, 4.0, 4)
        try:
            fb = FourBar(
                g,
                a,
                b,
                c,
                coupler_point=tuple(rng.uniform(-1, 1, 2)),
                circuit=("open", "crossed")[len(out) % 2],
                placement=(0.0, 0.0, 0.0) if len(out) % 3 else (0.5, -1.0, 2.0),
            )
        except PlanarError:
            continue
        out[f"random-{len(out)}"] = fb
    return out


def _linkages() -> dict[str, Linkage]:
    out = {k: m for k in CATALOG if not k.startswith(("windup", "horse", "bunny")) for m in [get(k)] if isinstance(m, Linkage)}
    for f in sorted(glob.glob(str(GALLERY / "*.toml"))):
        m = load_scene(f).mechanism
        if isinstance(m, Linkage):
            out["gallery-" + Path(f).stem] = m
    out["parallelogram"] = FourBar(2.0, 1.0, 2.0, 1.0)
    out["kite"] = FourBar(1.0, 1.0, 2.0, 2.0)
    out["toggle"] = FourBar(4.0, 2.5, 2.0, 3.0, coupler_point=(1.0, -0.5))
    out["actuated"] = _actuated()
    out["slotted"] = _slotted()
    out.update(_random_fourbars(8))
    return out


LINKAGES = _linkages()
QS = {
    "path": np.linspace(0.0, 4 * np.pi, 3001),
    "backward": np.linspace(3.0, -3.0, 2001),
    "scattered": np.random.default_rng(5).uniform(-10, 10, 2000),
    "one": np.array([0.3]),
    "zigzag": np.resize([0.0, 2.0, -1.0, 3.0, 0.5, -2.5], 4000) + np.repeat([0.0, 1e-3], 2000),
    # beyond the polynomial sine's range: the C library's, chunk by chunk
    "huge": np.concatenate([np.linspace(1e6, 1e6 + 6.0, 500), np.linspace(2.0, 8.0, 500)]),
}


def _motion(lk, q, monkeypatch, jit: bool):
    monkeypatch.setattr(chunked, "JIT_MIN", 0 if jit else 10**12)
    return lk.solve(q)


def _reference(lk, q):
    poses, checks = lk._solve_poses(q)
    valid, code, table = merge_failures(q.shape[0], checks)
    pts = {n: poses_apply(poses[part], xy) for n, (part, xy) in lk.points.items()}
    return poses, valid, code, table, pts


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(LINKAGES))
def test_compiled_solve_matches_numpy_kernels_and_reference(name, monkeypatch):
    lk = LINKAGES[name]
    tol = 1e-9 * lk.size
    for qname, q in QS.items():
        a = fast_solve(lk, q, jit=True)
        b = fast_solve(lk, q, jit=False)
        assert (a is None) == (b is None), (name, qname)  # the same branch screen decides
        if a is not None and b is not None:
            assert (a[1] is None) == (b[1] is None)
            if a[1] is not None and b[1] is not None:
                for (ma, na, wa), (mb, nb, wb) in zip(a[1], b[1]):
                    assert np.array_equal(ma, mb) and na == nb and wa == wb
            for part in b[0]:
                assert np.abs(a[0][part][:, :2] - b[0][part][:, :2]).max() <= tol
                assert np.abs(a[0][part][:, 2] - b[0][part][:, 2]).max() <= 1e-9
            for p in b[2]:
                assert np.abs(a[2][p] - b[2][p]).max() <= tol
        # the public solve with the compiled kernels against the reference solve
        m = _motion(lk, q, monkeypatch, jit=True)
        poses, valid, code, table, pts = _reference(lk, q)
        assert np.array_equal(m.valid, valid) and np.array_equal(m.fail_code, code) and m.fail_table == table
        for part, p in poses.items():
            assert np.abs(m.poses[part][:, :2] - p[:, :2]).max() <= tol, (name, qname, part)
            assert np.abs(m.poses[part][:, 2] - p[:, 2]).max() <= 1e-9, (name, qname, part)
        for n, p in pts.items():
            assert np.abs(m.points[n] - p).max() <= tol


def test_the_test_linkages_reach_every_kernel_and_invalid_samples():
    kinds = {type(nd).kind for lk in LINKAGES.values() for nd in lk.nodes}
    # every kind with a chunk kernel is exercised; the gallery's gear, driven-input and triad nodes have none
    # (their linkages take the reference path, tested in test_gears_triads)
    assert kinds >= {"fixed", "crank", "actuator", "rrr", "rrp", "rigid"}
    assert {k for k in kinds if k not in chunked.KERNELS} <= {"geared", "driven", "triad"}
    invalid = [n for n, lk in LINKAGES.items() if n.startswith("random") and not lk.solve(QS["path"]).valid.all()]
    assert len(invalid) >= 3
    assert not LINKAGES["actuated"].solve(np.linspace(-3, 3, 500)).valid.all()


def test_public_solve_takes_the_compiled_kernels_at_every_size(monkeypatch):
    lk = get("jansen")
    q = 2 * np.pi / 3600 * np.arange(1, 30_001)
    calls = []
    real = chunked._solve_compiled
    monkeypatch.setattr(chunked, "_solve_compiled", lambda *a: calls.append(a[3].shape[0]) or real(*a))
    for n in (30_000, 1000, 72, 4, 1):
        lk.solve(q[:n])
    assert calls == [30_000, 1000, 72, 4, 1]
    monkeypatch.setenv("PLANAR_JIT", "0")
    lk.solve(q)
    assert len(calls) == 5


@pytest.mark.parametrize("name", ["jansen", "fourbar-crank-rocker", "fourbar-placed", "slider-crank-offset", "kangaroo"])
def test_warm_path_gives_the_general_solve(name, monkeypatch):
    """The warm path of ``Linkage.solve`` (plain float arrays) against ``Mechanism.solve`` with the same kernels."""
    from planar.core.model import Mechanism

    lk = get(name)
    rng = np.random.default_rng(3)
    for q in (np.linspace(-7.0, 7.0, 50), rng.uniform(-10, 10, 300), np.linspace(0.0, 2 * np.pi, 5000)):
        a = lk.solve(q)
        b = Mechanism.solve(lk, q.tolist())  # a list: the general path
        assert np.array_equal(a.driver, b.driver) and a.driver is not q
        assert np.array_equal(a.valid, b.valid) and np.array_equal(a.fail_code, b.fail_code)
        assert a.fail_table == b.fail_table and list(a.poses) == list(b.poses) and list(a.points) == list(b.points)
        for k in b.poses:
            assert np.array_equal(a.poses[k], b.poses[k])
        for k in b.points:
            assert np.array_equal(a.points[k], b.points[k])
    with pytest.raises(PlanarError):
        lk.solve(np.array([0.0, np.nan]))
    monkeypatch.setenv("PLANAR_MAX_SAMPLES", "10")
    with pytest.raises(PlanarError):
        lk.solve(np.zeros(11))


def test_node_kind_without_encoder_uses_the_numpy_kernels(monkeypatch):
    from planar.linkages import compiled

    lk = get("fourbar-crank-rocker")
    q = np.linspace(0.0, 2 * np.pi, 5000)
    ref = fast_solve(lk, q, jit=False)
    monkeypatch.delitem(compiled.ENCODERS, "rigid")
    fresh = get("fourbar-crank-rocker")
    got = fast_solve(fresh, q, jit=True)
    assert fresh._fast_plan().program is None
    assert ref is not None and got is not None
    for part in ref[0]:
        assert np.array_equal(ref[0][part], got[0][part])


def test_compiled_results_do_not_depend_on_threads_or_chunk_size():
    cases = [
        (get("jansen"), 2 * np.pi / 3600 * np.arange(1, 9001)),
        # steps alternating in sign (no path), with invalid samples
        (LINKAGES["actuated"], np.where(np.arange(9000) % 2, 1.0, -1.0) * np.random.default_rng(1).uniform(0, 4, 9000)),
    ]
    for lk, q in cases:
        a = fast_solve(lk, q, threads=1, chunk=2048, jit=True)
        b = fast_solve(lk, q, threads=2, chunk=300, jit=True)
        c = fast_solve(lk, q, threads=3, chunk=777, jit=True)
        assert a is not None and b is not None and c is not None
        for other in (b, c):
            for part in a[0]:
                assert np.array_equal(a[0][part], other[0][part])
            for n in a[2]:
                assert np.array_equal(a[2][n], other[2][n])
            assert (a[1] is None) == (other[1] is None)
            for x, y in zip(a[1] or [], other[1] or []):
                assert np.array_equal(x[0], y[0])
    assert a[1] is not None and not np.logical_and.reduce([m for m, _, _ in a[1]]).all()


def test_compiled_branch_screen_sends_singular_paths_to_the_reference():
    q = np.linspace(0.0, 2 * np.pi, 721)
    assert fast_solve(LINKAGES["parallelogram"], q, jit=True) is None
    assert fast_solve(LINKAGES["kite"], q, jit=True) is None
    assert fast_solve(get("jansen"), q, jit=True) is not None


def test_angles_and_crank_agree_with_the_c_library():
    """Every direction of a crank (the atan2 and sincos kernels) against math.atan2 / cos / sin."""
    lk = Linkage(
        "crank",
        [Fixed("O", (0.0, 0.0)), Crank("B", "O", 1.0), Rigid("P", "O", "B", (0.5, 0.3))],
        [Link("crank", ("O", "B", "P"))],
        points={"B": "B"},
    )
    special = [0.0, np.pi / 2, np.pi, 3 * np.pi / 2, 2 * np.pi, -np.pi, -np.pi / 2, 1e5, -823549.0]
    picks = np.random.default_rng(3).uniform(-7.0, 7.0, 300).tolist()
    # the polynomial sine and cosine (|angle| <= 2**19 pi / 2), and the C library's beyond
    for q in (np.array(special + picks), np.array([823551.0, -3e7, 1e12])):
        solved = fast_solve(lk, q, jit=True, threads=1)
        assert solved is not None
        ang = solved[0]["crank"][:, 2]
        for i in range(q.size):
            assert abs(ang[i] - math.atan2(math.sin(q[i]), math.cos(q[i]))) <= 4e-15, q[i]
        B = solved[2]["B"]
        assert np.abs(B[:, 0] - np.cos(q)).max() <= 1e-15 and np.abs(B[:, 1] - np.sin(q)).max() <= 1e-15


def test_against_scipy_root_finding():
    """Each moving node solved again by scipy (hybrid Powell) from the pose 12 degrees earlier;
    where a random four-bar cannot close, its crank pin is out of the rocker's reach."""
    fourbars = [lk for n, lk in LINKAGES.items() if n.startswith("random")]
    rng = np.random.default_rng(4)
    full = None
    while full is None or full.grashof not in ("crank-rocker", "double-crank"):
        g, a, b, c = rng.uniform(0.5, 4.0, 4)
        if max(g, a, b, c) < (g + a + b + c) / 2:
            full = FourBar(g, a, b, c, coupler_point=tuple(rng.uniform(-1, 1, 2)))
    for lk in (get("jansen"), LINKAGES["slotted"], full):
        q = np.linspace(0.2, 0.2 + 2 * np.pi, 30001)
        m = fast_solve(lk, q, jit=True)
        assert m is not None and m[1] is None
        for k in range(1000, q.size, 3001):
            pos: dict[str, np.ndarray] = {}
            for nd in lk.nodes:
                got = _node_xy(lk, m, nd.name, k)
                if isinstance(nd, Fixed):
                    pos[nd.name] = np.asarray(nd.xy, float)
                elif isinstance(nd, Crank):
                    pos[nd.name] = pos[nd.centre] + nd.radius * np.array([math.cos(q[k]), math.sin(q[k])])
                else:
                    pos[nd.name] = root(_residual(nd, pos), _node_xy(lk, m, nd.name, k - 1000), tol=1e-14).x
                assert np.abs(pos[nd.name] - got).max() <= 1e-9 * lk.size, (lk.name, nd.name, k)
    for lk in fourbars:
        # values alternating in sign: steps alternate in sign, no path (the compiled kernels throughout)
        q = np.where(np.arange(3000) % 2, 1.0, -1.0) * np.random.default_rng(7).uniform(0.05, 4.0, 3000)
        m = fast_solve(lk, q, jit=True)
        assert m is not None
        g = lk.dims
        reach = np.hypot(g.a * np.cos(q) - g.d, g.a * np.sin(q))  # |B - O4|
        closes = (reach <= g.b + g.c) & (reach >= abs(g.b - g.c))
        valid = np.ones(q.size, bool) if m[1] is None else np.logical_and.reduce([c[0] for c in m[1]])
        assert np.array_equal(valid, closes)
        for k in np.flatnonzero(valid)[:: max(1, int(valid.sum()) // 5)]:
            pos = {"O2": np.zeros(2), "O4": np.array([g.d, 0.0]), "B": g.a * np.array([math.cos(q[k]), math.sin(q[k])])}
            C = _node_xy(lk, m, "C", k)
            C2 = root(_residual(lk.nodes[3], pos), C + 0.02 * lk.size, tol=1e-14).x
            assert np.abs(C2 - C).max() <= 1e-9 * lk.size


def _node_xy(lk, solved, node, k):
    """A node's position (linkage frame) from the solved poses: through a link that carries it."""
    for link in lk.links:
        if node in link.nodes and link.name != lk.ground_name:
            pose = solved[0][link.name][k]
            local = lk._anchors[link.name][node]
            place = np.asarray(lk.placement)
            world = poses_apply(pose, local)
            c, s = math.cos(place[2]), math.sin(place[2])
            d = world - place[:2]
            return np.array([c * d[0] + s * d[1], -s * d[0] + c * d[1]])
    return np.asarray(next(nd.xy for nd in lk.nodes if nd.name == node), float)


def _residual(nd, pos):
    if isinstance(nd, RRR):
        return lambda p: [np.hypot(*(p - pos[nd.a])) - nd.ra, np.hypot(*(p - pos[nd.b])) - nd.rb]
    if isinstance(nd, Rigid):
        e = (pos[nd.b] - pos[nd.a]) / np.hypot(*(pos[nd.b] - pos[nd.a]))
        u, v = nd.local
        return lambda p: [np.dot(p - pos[nd.a], e) - u, _cross(e, p - pos[nd.a]) - v]
    if isinstance(nd, RRP):
        w = pos[nd.q] - pos[nd.p]
        w = w / np.hypot(*w)
        return lambda p: [np.hypot(*(p - pos[nd.a])) - nd.ra, _cross(w, p - pos[nd.p]) - nd.offset]
    raise AssertionError(type(nd).kind)


def _cross(a, b):
    return a[0] * b[1] - a[1] * b[0]


@pytest.mark.slow
def test_compiled_kernels_are_cached_across_processes(tmp_path):
    """A second process loads the kernels from numba's cache (no compilation), from a writable place."""
    import json
    import os
    import subprocess
    import sys

    code = (
        "import json, os, numpy as np\n"
        "from planar.scene.catalog import get\n"
        "get('jansen').solve(np.linspace(0.0, 6.0, 72))\n"
        "from planar.linkages.compiled import solve_range\n"
        "st = solve_range.stats\n"
        "print(json.dumps({'hits': sum(st.cache_hits.values()), 'misses': sum(st.cache_misses.values()),"
        " 'path': st.cache_path, 'writable': os.access(st.cache_path, os.W_OK)}))\n"
    )
    root = Path(__file__).resolve().parents[2]
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path)}  # an empty cache: the first process compiles
    runs = []
    for _ in range(2):
        r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=root, env=env, timeout=600)
        assert r.returncode == 0, r.stderr
        runs.append(json.loads(r.stdout.strip().splitlines()[-1]))
    first, second = runs
    assert first["writable"] and second["writable"]
    assert second["misses"] == 0 and second["hits"] >= 1, runs
    assert any(tmp_path.iterdir())  # the machine code landed in the cache
