"""The rocking-arc atlas: open-curve descriptions, input ranges, and double-rockers recovered from their arcs."""

from __future__ import annotations

import numpy as np
import pytest

from planar.cli.main import main
from planar.synth.arcs import build_arcs, describe_open, input_range, rocking_range, synthesise_rocking_path
from planar.synth.kernel import coupler_points


def test_open_description_ignores_position_rotation_and_scale():
    rng = np.random.default_rng(3)
    t = np.linspace(0.0, 1.0, 50)
    z = t + 1j * (0.3 * np.sin(3 * t) + 0.1 * t**2)
    for _ in range(5):
        k, a, o = rng.uniform(0.1, 10), rng.uniform(-np.pi, np.pi), complex(*rng.uniform(-5, 5, 2))
        d0, _ = describe_open(z[None, :])
        d1, f1 = describe_open((k * np.exp(1j * a) * z + o)[None, :])
        assert np.allclose(d0, d1, atol=1e-9)
        assert np.isclose(f1[0, 2] / describe_open(z[None, :])[1][0, 2], k)
    # another curve is described differently
    assert np.abs(describe_open((t + 0.3j * t**3)[None, :])[0] - d0).max() > 0.05


def test_input_range_is_where_the_dyad_closes():
    # checked against the kernel's own assembly test on a dense turn: inside the range every angle closes,
    # just outside none does (the range's ends are the input's limits)
    rng = np.random.default_rng(11)
    seen = 0
    while seen < 30:
        a, b, c = np.exp(rng.uniform(np.log(0.2), np.log(3.0), 3))
        lo, hi, rocks = input_range(np.array([a]), np.array([b]), np.array([c]))
        if not rocks[0]:
            continue
        seen += 1
        X = np.array([[1.0, a, b, c, 0.0, 0.0, 0.0, 0.0, 0.0]])
        inside = np.linspace(lo[0] + 1e-6, hi[0] - 1e-6, 400)
        assert coupler_points(X, inside[None, :])[2].all()
        outside = np.array([lo[0] - 1e-3, hi[0] + 1e-3])
        assert not coupler_points(X, outside[None, :])[2].any()
        assert rocking_range(X[0], inside[[5, 200, 390]]) is not None


def _double_rocker(rng: np.random.Generator) -> tuple[np.ndarray, float, float]:
    """A random Grashof double-rocker (the coupler shortest, 2 % from a change point), ground 1, and its input's range."""
    while True:
        L = np.exp(rng.uniform(np.log(0.2), np.log(2.0), 3))  # input, coupler, rocker
        s = sorted([1.0, *L])
        if L[1] == s[0] and s[0] + s[3] < 0.98 * (s[1] + s[2]):
            lo, hi, rocks = input_range(L[:1], L[1:2], L[2:3])
            if rocks[0] and hi[0] - lo[0] > np.radians(20):
                return L, float(lo[0]), float(hi[0])


@pytest.mark.slow
def test_double_rockers_recovered_from_targets_on_their_arc():
    # random Grashof double-rockers never used to build or tune anything, 20 targets on a random part (at least
    # 40 %) of their input's swing: the design passes every target (largest distance over the targets' size) on
    # one swing, in order, and planar's solver assembles the whole swing on one circuit
    arcs = build_arcs(20_000, seed=0)
    rng = np.random.default_rng(20261126)
    errors = []
    for _ in range(6):
        L, lo, hi = _double_rocker(rng)
        span = hi - lo
        a0, a1 = lo + span * rng.uniform(0.02, 0.3), hi - span * rng.uniform(0.02, 0.3)
        p = np.array([1.0, *L, L[1] * rng.uniform(-1, 2), L[1] * rng.uniform(-1.5, 1.5), *rng.uniform(-1, 1, 2), 0.3])
        th = np.sort(rng.uniform(a0, a1, 20))
        circ = float(rng.choice([1.0, -1.0]))
        x, y, ok = coupler_points(p[None], th[None], np.array([circ]))
        assert ok.all()
        d = synthesise_rocking_path(np.column_stack([x[0], y[0]]) * 7.0, tolerance=1e-3, ordered=True, arcs=arcs)
        assert d.checks["ok_swing_assembles"] and d.checks["ok_on_one_swing"]
        errors.append(d.checks["max_error"])
        if d.checks["max_error"] <= 1e-3:
            assert d.ok and d.checks["ok_order"]
            a, b = d.checks["input_swing_rad"]
            assert b - a < 2 * np.pi and d.checks["grashof"] not in ("crank-rocker", "double-crank")
    assert sum(e <= 1e-3 for e in errors) >= 5, errors


def test_rocking_refuses_timed_targets(tmp_path, capsys):
    f = tmp_path / "t.csv"
    f.write_text("x,y,theta\n0,0,0\n1,0.2,0.1\n2,0.1,0.2\n")
    out = tmp_path / "o.toml"
    assert main(["synth", "path", str(f), "--rocking", "-o", str(out)]) == 2
    assert "--rocking" in capsys.readouterr().err and not out.exists()
