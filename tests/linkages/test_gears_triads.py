"""Gears between cranks, two-input linkages and triads, checked against scipy's root finders."""

from __future__ import annotations

import copy
import tomllib
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import fsolve, root

from planar.core.model import joint_residuals
from planar.errors import InputError, SceneError
from planar.fileio import motion_columns
from planar.linkages import RRR, Crank, Fixed, Geared, Link, Linkage, Triad
from planar.scene.load import build_scene, load_scene, parse_scene

GALLERY = Path(__file__).resolve().parents[2] / "gallery"


R = 0.9  # crank radius: inside both pitch circles for the ratios tested


def _five_bar(ratio: float = -1.0, phase: float = 0.5, radius: float = R) -> Linkage:
    nodes = [
        Fixed("O1", (0.0, 0.0)),
        Fixed("O2", (4.0, 0.0)),
        Crank("A", "O1", radius),
        Geared("B", "O2", radius, "A", ratio, phase),
        RRR("P", "A", 4.0, "B", 4.0, 1),
    ]
    links = [Link("ga", ("O1", "A")), Link("gb", ("O2", "B")), Link("ca", ("A", "P")), Link("cb", ("B", "P"))]
    return Linkage("five", nodes, links, points={"pen": "P"}, width=0.3)


@pytest.mark.parametrize("ratio", [-1.0, -0.5, -2.0])
def test_gear_ratio_held_exactly(ratio: float) -> None:
    lk = _five_bar(ratio)
    q = np.linspace(0.0, 4 * np.pi, 401)
    pos = lk.node_positions(q)
    a = np.unwrap(np.arctan2(*(pos["A"] - pos["O1"]).T[::-1]))
    b = np.unwrap(np.arctan2(*(pos["B"] - pos["O2"]).T[::-1]))
    # angles measured from the node positions, unwrapped: b = ratio a + phase
    off = b - ratio * a
    assert np.ptp(off) < 1e-12
    assert abs(np.remainder(off[0] - 0.5 + np.pi, 2 * np.pi) - np.pi) < 1e-12
    vals = lk.input_values(q)
    assert np.array_equal(vals["B"], ratio * vals["A"] + 0.5)
    m = lk.solve(q)
    gear = next(j for j in lk.joints if j.kind == "gear")
    assert float(gear.residual(m.poses).max()) < 1e-12
    # pitch circles: radii sum to the centre distance, in the ratio of the speeds
    assert gear.radius_a + gear.radius_b == pytest.approx(4.0)
    assert gear.radius_a / gear.radius_b == pytest.approx(abs(ratio))
    # a wrong ratio shows in the residual
    worse = type(gear)(
        gear.name, gear.a, gear.b, gear.ratio * 1.01, gear.phase, gear.centre_a, gear.centre_b, gear.radius_a, gear.radius_b
    )
    assert float(worse.residual(m.poses).max()) > 1e-3


def test_five_bar_closure_against_scipy() -> None:
    lk = _five_bar()
    rng = np.random.default_rng(3)
    q = np.sort(rng.uniform(0, 2 * np.pi, 12))
    pos = lk.node_positions(q)
    for i in range(q.size):
        A, B = pos["A"][i], pos["B"][i]
        # the crank pins from their own angles, independently of the solver
        assert np.allclose(A, R * np.array([np.cos(q[i]), np.sin(q[i])]), atol=1e-12)
        bb = -q[i] + 0.5
        assert np.allclose(B, [4 + R * np.cos(bb), R * np.sin(bb)], atol=1e-12)

        def f(p: np.ndarray, A: np.ndarray = A, B: np.ndarray = B) -> list[float]:
            return [float(np.hypot(*(p - A)) - 4.0), float(np.hypot(*(p - B)) - 4.0)]

        sol = root(f, pos["P"][i] + [0.3, -0.2], tol=1e-13)
        assert np.max(np.abs(f(sol.x))) < 1e-12
        assert np.allclose(sol.x, pos["P"][i], atol=1e-10)
    m = lk.solve(q)
    assert m.valid.all()
    assert max(float(r.max()) for r in joint_residuals(lk, m).values()) < 1e-9 * lk.size


def test_gear_velocity_matches_differences() -> None:
    lk = _five_bar(-0.5)
    q = np.linspace(0.2, 2.0, 7)
    v, ok = lk.node_velocities(q)
    h = 1e-6
    d = (lk.node_positions(q + h)["P"] - lk.node_positions(q - h)["P"]) / (2 * h)
    assert ok.all() and np.allclose(v["P"], d, atol=1e-7)
    d = (lk.node_positions(q + h)["B"] - lk.node_positions(q - h)["B"]) / (2 * h)
    assert np.allclose(v["B"], d, atol=1e-7)


def test_geared_refusals() -> None:
    with pytest.raises(InputError, match="ratio"):
        _five_bar(ratio=1.0)
    # a crank pin past the small gear's pitch circle (4 / 3 for ratio -0.5): the gears could not share a layer
    with pytest.raises(InputError, match="pitch circle"):
        _five_bar(ratio=-0.5, radius=1.2)
    nodes = [
        Fixed("O1", (0.0, 0.0)),
        Fixed("O2", (4.0, 0.0)),
        Crank("A", "O1", 1.2),
        RRR("M", "A", 3.0, "O2", 3.0),
        Geared("B", "M", 1.0, "A", -1.0),
        RRR("P", "A", 4.0, "B", 4.0),
    ]
    links = [
        Link("ga", ("O1", "A")),
        Link("m", ("A", "M", "O2")),
        Link("gb", ("M", "B")),
        Link("ca", ("A", "P")),
        Link("cb", ("B", "P")),
    ]
    with pytest.raises(InputError, match="fixed nodes"):
        Linkage("bad", nodes, links)


@pytest.mark.slow
def test_geared_five_bar_scene_export_and_compare(tmp_path: Path) -> None:
    from planar.physics.compare import compare_scene

    scene = load_scene(GALLERY / "geared-five-bar.toml")
    m = scene.motion()
    assert m.valid.all()
    names, _table = motion_columns(scene.mechanism, m)
    assert names[:4] == ["t", "driver", "driver.A", "driver.B"]
    result, sim = compare_scene(scene, motor=True)  # the scene names no motor: asked for here
    assert sim.failure is None
    assert result.torque is not None and result.torque["max_rel_diff"] < 0.01  # the GearJoint carries the load
    # cut: both gears as their pitch circles (2 units each, 12 mm a unit, kerf 0.15 mm), read back with ezdxf;
    # the assembly puts them in one layer
    import csv

    import ezdxf

    from planar.app.pipeline import export_scene

    export_scene(scene, dxf=tmp_path / "p.dxf", bom=tmp_path / "bom.csv")
    doc = ezdxf.readfile(tmp_path / "p.dxf")
    outer = sorted(round(e.dxf.radius, 6) for e in doc.modelspace().query("CIRCLE") if e.dxf.layer == "CUT_OUTER")
    assert outer.count(round(2.0 * 12.0 + 0.075, 6)) == 2
    rows = {r["id"]: r for r in csv.DictReader((tmp_path / "bom.csv").open()) if r["item"] == "part"}
    assert rows["gear-left"]["layer"] == rows["gear-right"]["layer"]


def _two_input_scene() -> dict:
    d = tomllib.loads((GALLERY / "geared-five-bar.toml").read_text())
    nodes = d["mechanism"]["nodes"]
    nodes[2] = {"name": "A", "kind": "driven", "centre": "O1", "radius": 1.2, "amplitude": 40.0, "mean": 60.0}
    nodes[3] = {
        "name": "B",
        "kind": "driven",
        "centre": "O2",
        "radius": 1.2,
        "cycles": 2.0,
        "phase": 30.0,
        "amplitude": 30.0,
        "mean": 120.0,
    }
    d["driver"] = {"speed": 0.5, "samples_per_cycle": 48}
    return d


def test_two_drivers_scene_columns_and_laws() -> None:
    scene = build_scene(parse_scene(_two_input_scene()))
    m = scene.motion()
    assert m.valid.all()
    names, table = motion_columns(scene.mechanism, m)
    col = {n: table[:, i] for i, n in enumerate(names)}
    theta = col["driver"]
    assert np.allclose(theta, np.pi * col["t"])  # the clock: 2 pi speed t
    a = np.radians(60) + np.radians(40) * np.sin(theta)
    b = np.radians(120) + np.radians(30) * np.sin(2 * theta + np.radians(30))
    assert np.allclose(col["driver.A"], a, atol=1e-14) and np.allclose(col["driver.B"], b, atol=1e-14)
    pos = scene.mechanism.node_positions(theta)
    assert np.allclose(pos["A"], 1.2 * np.c_[np.cos(a), np.sin(a)], atol=1e-12)
    assert np.allclose(pos["B"], [4, 0] + 1.2 * np.c_[np.cos(b), np.sin(b)], atol=1e-12)
    # velocities of the two-input linkage by its own closure against differences in the clock
    v, ok = scene.mechanism.node_velocities(theta[:8])
    h = 1e-6
    d = (scene.mechanism.node_positions(theta[:8] + h)["P"] - scene.mechanism.node_positions(theta[:8] - h)["P"]) / (2 * h)
    assert ok.all() and np.allclose(v["P"], d, atol=1e-6)


def test_two_drivers_compare_kinematic_and_refusals() -> None:
    from planar.physics.compare import compare_scene

    scene = build_scene(parse_scene(_two_input_scene()))
    result, sim = compare_scene(scene)
    assert sim.failure is None  # both inputs imposed: the simulation follows
    assert result.torque is None  # no steadily turning motor: not compared
    bad = _two_input_scene()
    bad["driver"]["amplitude"] = 10.0
    with pytest.raises(SceneError, match="amplitude"):
        build_scene(parse_scene(bad))


# ---------------------------------------------------------------------------- triads


def _six_bar() -> Linkage:
    return load_scene(GALLERY / "stephenson-six-bar.toml").mechanism  # type: ignore[return-value]


def _loop_equations(lk: Linkage, q: float):
    """The full loop of the triad in node coordinates (six unknowns), independent of the solver's pose form."""
    byname = {n.name: n for n in lk.nodes}
    tri = [byname[k] for k in ("T1", "T2", "T3")]
    S = np.array([t.local for t in tri])
    C = 0.7 * np.array([np.cos(q), np.sin(q)])
    K = [C, np.array(byname["G2"].xy), np.array(byname["G3"].xy)]

    def f(x: np.ndarray) -> list[float]:
        T = x.reshape(3, 2)
        out = [float(np.hypot(*(T[i] - K[i])) - tri[i].ra) for i in range(3)]
        for i, j in ((0, 1), (1, 2), (0, 2)):
            out.append(float(np.hypot(*(T[i] - T[j])) - np.hypot(*(S[i] - S[j]))))
        return out

    return f


def test_triad_against_scipy_continuation() -> None:
    lk = _six_bar()
    q = np.linspace(0.0, 2 * np.pi, 97)
    pos = lk.node_positions(q)
    assert all(np.isfinite(v).all() for v in pos.values())
    m = lk.solve(q)
    assert m.valid.all()
    rng = np.random.default_rng(7)
    for k in rng.choice(np.arange(1, q.size), 10, replace=False):
        prev = np.concatenate([pos[n][k - 1] for n in ("T1", "T2", "T3")])
        x = fsolve(_loop_equations(lk, float(q[k])), prev, xtol=1e-12)
        assert np.max(np.abs(_loop_equations(lk, float(q[k]))(x))) < 1e-10
        ours = np.concatenate([pos[n][k] for n in ("T1", "T2", "T3")])
        assert np.allclose(x, ours, atol=1e-9)
        # our solution satisfies the loop equations
        assert np.max(np.abs(_loop_equations(lk, float(q[k]))(ours))) < 1e-9 * lk.size
    # the ternary link stays rigid and the chirality is kept (no mirror assembly)
    T1, T2, T3 = pos["T1"], pos["T2"], pos["T3"]
    cross = (T2[:, 0] - T1[:, 0]) * (T3[:, 1] - T1[:, 1]) - (T2[:, 1] - T1[:, 1]) * (T3[:, 0] - T1[:, 0])
    assert (cross > 0).all()


def test_triad_same_branch_either_direction_and_from_elsewhere() -> None:
    lk = _six_bar()
    q = np.linspace(0.0, 2 * np.pi, 145)
    fwd = lk.node_positions(q)
    back = lk.node_positions(q[::-1])
    for n in ("T1", "T2", "T3", "E"):
        assert np.allclose(fwd[n], back[n][::-1], atol=1e-9)
    # a path starting elsewhere is led in from driver value 0: the same assembly
    part = lk.node_positions(q[60:100])
    assert np.allclose(part["T3"], fwd["T3"][60:100], atol=1e-9)
    # a scattered batch: every value from the declared assembly; the same here (one circuit)
    idx = np.array([100, 3, 77, 40, 12])
    assert np.allclose(lk.node_positions(q[idx])["T2"], fwd["T2"][idx], atol=1e-9)


def test_triad_velocity_matches_differences() -> None:
    lk = _six_bar()
    q = np.linspace(0.3, 2.5, 6)
    v, ok = lk.node_velocities(q)
    h = 1e-6
    assert ok.all()
    for n in ("T1", "T2", "T3", "E"):
        d = (lk.node_positions(q + h)[n] - lk.node_positions(q - h)[n]) / (2 * h)
        assert np.allclose(v[n], d, atol=1e-6)


def test_triad_failures_are_invalid_samples_with_reason() -> None:
    d = tomllib.loads((GALLERY / "stephenson-six-bar.toml").read_text())
    d["mechanism"]["nodes"][2]["at"] = [2.0, 8.0]
    d["mechanism"]["nodes"][3]["radius"] = 1.0
    d["mechanism"]["nodes"][4]["ra"] = float(np.hypot(1.0, 3.0))
    d["mechanism"]["nodes"][6]["ra"] = float(np.hypot(1.5, 3.5))
    scene = build_scene(parse_scene(d))
    m = scene.motion()
    assert 0 < m.valid.sum() < len(m)
    i = int(np.flatnonzero(~m.valid)[0])
    assert "triad" in m.reason(i) and "'T1'" in m.reason(i)
    # scipy agrees there is no assembly there: least squares keeps a residual
    from scipy.optimize import least_squares

    lk = scene.mechanism
    byname = {n.name: n for n in lk.nodes}
    bad_q = float(m.driver[np.flatnonzero(~m.valid)[len(np.flatnonzero(~m.valid)) // 2]])
    S = np.array([byname[k].local for k in ("T1", "T2", "T3")])
    L = [byname[k].ra for k in ("T1", "T2", "T3")]
    K = [np.array([np.cos(bad_q), np.sin(bad_q)]), np.array([6.0, 0.0]), np.array([2.0, 8.0])]

    def g(u: np.ndarray) -> list[float]:
        c, s = np.cos(u[2]), np.sin(u[2])
        return [
            float(np.hypot(*(u[:2] + [c * S[i, 0] - s * S[i, 1], s * S[i, 0] + c * S[i, 1]] - K[i])) - L[i]) for i in range(3)
        ]

    rng = np.random.default_rng(0)
    best = min(least_squares(g, rng.uniform([-5, -5, -np.pi], [10, 10, np.pi])).cost for _ in range(25))
    assert best > 1e-6


def test_triad_declaration_errors() -> None:
    d = tomllib.loads((GALLERY / "stephenson-six-bar.toml").read_text())
    orphan = copy.deepcopy(d)
    del orphan["mechanism"]["nodes"][4]["members"]
    with pytest.raises(SceneError, match="members"):
        build_scene(parse_scene(orphan))
    before = copy.deepcopy(d)
    nodes = before["mechanism"]["nodes"]
    nodes[4], nodes[5] = nodes[5], nodes[4]  # a member declared before the triad's first node
    with pytest.raises(SceneError, match="triad"):
        build_scene(parse_scene(before))
    line = copy.deepcopy(d)
    line["mechanism"]["nodes"][6]["local"] = [6.0, 0.0]
    with pytest.raises(SceneError, match="one line"):
        build_scene(parse_scene(line))
    with pytest.raises(InputError):
        Triad("T", "A", 1.0, (0.0, 0.0), (0.0, 0.0), ("T", "U")).validate("x")


def _dead_centre_six_bar() -> Linkage:
    """A Stephenson six-bar whose triad reaches a dead centre near crank angle 1.99 rad (found by a search)."""
    G2, G3, r = (6.312451035078426, -0.4134985153095454), (-0.45359010799997446, 5.930763662478237), 0.8286678037109922
    T = np.array(
        [[2.4080079945914776, 3.223385904964576], [5.0476084374687495, 3.3911156677558036], [3.7776357488676, 4.723780354556157]]
    )
    S = T - T[0]
    L = [float(np.hypot(*(T[0] - (r, 0.0)))), float(np.hypot(*(T[1] - G2))), float(np.hypot(*(T[2] - G3)))]
    nodes = [
        Fixed("G1", (0.0, 0.0)),
        Fixed("G2", G2),
        Fixed("G3", G3),
        Crank("C", "G1", r),
        Triad("T1", "C", L[0], (0.0, 0.0), tuple(T[0]), ("T2", "T3")),
        Triad("T2", "G2", L[1], tuple(S[1]), tuple(T[1])),
        Triad("T3", "G3", L[2], tuple(S[2]), tuple(T[2])),
    ]
    links = [
        Link("crank", ("G1", "C")),
        Link("rod", ("C", "T1")),
        Link("ternary", ("T1", "T2", "T3")),
        Link("rocker", ("G2", "T2")),
        Link("hanger", ("G3", "T3")),
    ]
    return Linkage("dead-centre", nodes, links)


def test_triad_dead_centre_jump_is_flagged() -> None:
    lk = _dead_centre_six_bar()
    q = np.linspace(0.0, 2 * np.pi, 720)
    m = lk.solve(q)
    bad = np.flatnonzero(~m.valid)
    assert 1 <= bad.size <= 3
    k = int(bad[-1])
    assert "jumped to another branch" in m.reason(k)
    pos = lk.node_positions(q)
    # the triad moves far in one step there, and little in the steps either side
    step = np.hypot(*(pos["T3"][1:] - pos["T3"][:-1]).T)
    assert step[k - 1] > 10 * max(step[k - 3], step[k + 1])
    # scipy, continued from the last valid sample, finds no assembly near it either: the branch ends
    f = _loop_equations_general(lk, float(q[k]))
    prev = np.concatenate([pos[n][bad[0] - 1] for n in ("T1", "T2", "T3")])
    x, _info, ier, _msg = fsolve(f, prev, full_output=True)
    near = ier == 1 and np.max(np.abs(f(x))) < 1e-9 and np.abs(x - prev).max() < 0.2
    assert not near


def _loop_equations_general(lk: Linkage, q: float):
    byname = {n.name: n for n in lk.nodes}
    tri = [byname[k] for k in ("T1", "T2", "T3")]
    S = np.array([t.local for t in tri])
    crank = byname["C"]
    C = crank.radius * np.array([np.cos(q), np.sin(q)])
    K = [C, np.array(byname["G2"].xy), np.array(byname["G3"].xy)]

    def f(x: np.ndarray) -> list[float]:
        T = x.reshape(3, 2)
        out = [float(np.hypot(*(T[i] - K[i])) - tri[i].ra) for i in range(3)]
        for i, j in ((0, 1), (1, 2), (0, 2)):
            out.append(float(np.hypot(*(T[i] - T[j])) - np.hypot(*(S[i] - S[j]))))
        return out

    return f


def test_blocked_continuation_equals_sample_by_sample() -> None:
    from planar.linkages.triads import _newton, solve_triad

    lk = _six_bar()
    t1 = next(n for n in lk.nodes if isinstance(n, Triad) and n.members)
    S, L, u_ref, scale = t1._data()
    n = 400
    q = np.linspace(0.0, 6 * np.pi, n)
    K = np.stack([0.7 * np.c_[np.cos(q), np.sin(q)], np.broadcast_to([6.0, 0.0], (n, 2)), np.broadcast_to([1.0, 7.5], (n, 2))], 1)
    cont = np.ones(n, bool)
    cont[0] = False
    u, ok, _code = solve_triad(K, L, S, u_ref, cont, scale)
    seq = np.empty((n, 3))
    prev = u_ref
    for k in range(n):  # the definition: Newton from the previous sample's assembly
        w, _, _ = _newton(K[k : k + 1], prev[None], L, S, scale)
        seq[k] = prev = w[0]
    assert ok.all() and np.abs(u - seq).max() < 1e-9


def test_random_triads_never_silently_wrong() -> None:
    """Random six-bars: every sample marked valid closes every loop (distances from node positions)."""
    rng = np.random.default_rng(11)
    checked = 0
    for _ in range(8):
        G2, G3, r = rng.uniform([3, -2], [8, 2]), rng.uniform([-1, 5], [5, 9]), float(rng.uniform(0.3, 1.5))
        T = np.array([[2, 3], [5, 3], [3.5, 4.5]]) + rng.normal(0, 0.3, (3, 2))
        S = T - T[0]
        L = [float(np.hypot(*(T[0] - (r, 0.0)))), float(np.hypot(*(T[1] - G2))), float(np.hypot(*(T[2] - G3)))]
        nodes = [
            Fixed("G1", (0.0, 0.0)),
            Fixed("G2", tuple(G2)),
            Fixed("G3", tuple(G3)),
            Crank("C", "G1", r),
            Triad("T1", "C", L[0], (0.0, 0.0), tuple(T[0]), ("T2", "T3")),
            Triad("T2", "G2", L[1], tuple(S[1]), tuple(T[1])),
            Triad("T3", "G3", L[2], tuple(S[2]), tuple(T[2])),
        ]
        links = [
            Link("crank", ("G1", "C")),
            Link("rod", ("C", "T1")),
            Link("ternary", ("T1", "T2", "T3")),
            Link("rocker", ("G2", "T2")),
            Link("hanger", ("G3", "T3")),
        ]
        lk = Linkage("random", nodes, links)
        q = np.linspace(0.0, 2 * np.pi, 360)
        pos, checks = lk.solve_nodes(q)
        ok = np.logical_and.reduce([c for c, _, _ in checks])
        outer = [pos["C"], pos["G2"], pos["G3"]]
        for i, n in enumerate(("T1", "T2", "T3")):
            assert np.abs(np.hypot(*(pos[n][ok] - outer[i][ok]).T) - L[i]).max() < 1e-9 * lk.size
        for i, j in ((0, 1), (1, 2), (0, 2)):
            a, b = pos[f"T{i + 1}"][ok], pos[f"T{j + 1}"][ok]
            assert np.abs(np.hypot(*(a - b).T) - np.hypot(*(S[i] - S[j]))).max() < 1e-9 * lk.size
        checked += int(ok.sum())
    assert checked > 700


@pytest.mark.parametrize(
    "edit,expect",
    [
        (("ratio = -1.0", "ratio = 0.5"), "nodes.B.ratio"),
        (('mesh = "A"', 'mesh = "O1"'), "nodes.B.mesh"),
    ],
)
def test_bad_gear_scene_is_one_line_exit_2(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], edit: tuple[str, str], expect: str
) -> None:
    from planar.cli.main import main

    text = (GALLERY / "geared-five-bar.toml").read_text()
    assert edit[0] in text
    p = tmp_path / "bad.toml"
    p.write_text(text.replace(edit[0], edit[1]))
    out = tmp_path / "m.csv"
    assert main(["motion", str(p), "-o", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and expect in err[0] and "Traceback" not in err[0]
    assert not out.exists()


def test_accelerations_match_differences_of_velocities() -> None:
    """Gears, a second input and a triad: the closure differentiated twice against central differences."""
    cases = [
        (_five_bar(-0.5), np.linspace(0.2, 2.0, 6), ("B", "P")),
        (_six_bar(), np.linspace(0.3, 2.5, 6), ("T1", "T2", "T3", "E")),
        (build_scene(parse_scene(_two_input_scene())).mechanism, np.linspace(0.2, 3.0, 6), ("A", "B", "P")),
    ]
    h = 1e-5
    for lk, q, names in cases:
        assert isinstance(lk, Linkage)
        qd, qdd = 1.7, -0.4  # a driver speeding down: both terms of the chain rule count
        _pos, _vel, acc, ok = lk.node_accelerations(q, qd, qdd)
        assert ok.all()
        vp, _ = lk.node_velocities(q + h, 1.0)
        vm, _ = lk.node_velocities(q - h, 1.0)
        v1, _ = lk.node_velocities(q, 1.0)
        for n in names:
            d2 = (vp[n] - vm[n]) / (2 * h)  # second coefficient d2X/dq2
            assert np.allclose(acc[n], d2 * qd * qd + v1[n] * qdd, atol=1e-6), (lk.name, n)
