"""Function generation on one circuit (issue 15, item 2): search beyond Freudenstein's closed form.

Checked against what the search did not compute: scipy's root finder on the
loop-closure equations, planar's FourBar solve of the written scene, and
four-bars whose pairs were sampled from known linkages.
"""

from __future__ import annotations

import json
from types import SimpleNamespace

import numpy as np
import pytest
from scipy.optimize import fsolve

from planar.cli.main import main
from planar.linkages import FourBar
from planar.scene.load import load_scene
from planar.synth.function import freudenstein_fit, synthesise_function
from planar.synth.function_search import FunctionConstraints, arc_margin


def _wrap(a):
    return (np.asarray(a) + np.pi) % (2 * np.pi) - np.pi


def _loop_closure_outputs(d):
    """World rocker angles at the requested inputs by scipy's root finder on the vector loop
    ``a e^{i th} + b e^{i th3} - c e^{i th4} - d = 0`` in the ground line's frame: started from 8 rocker
    angles round the circle, the roots found are sorted by the side of ``C`` (left of the directed
    diagonal ``B -> O4``: FourBar's open circuit), and the one on the design's circuit is returned."""
    a, b, c, g = d.crank, d.coupler, d.rocker, d.ground
    want = 1 if d.circuit == "open" else -1
    out = []
    for th in d.phi + d.input_offset:
        Bx, By = a * np.cos(th), a * np.sin(th)

        def f(v, th=th):
            t3, t4 = v
            return [a * np.cos(th) + b * np.cos(t3) - c * np.cos(t4) - g, a * np.sin(th) + b * np.sin(t3) - c * np.sin(t4)]

        roots = []
        for t4 in np.linspace(0, 2 * np.pi, 8, endpoint=False):
            Cx, Cy = g + c * np.cos(t4), c * np.sin(t4)
            sol, _, ier, _ = fsolve(f, [np.arctan2(Cy - By, Cx - Bx), t4], full_output=True, xtol=1e-13)
            if ier == 1 and np.abs(f(sol)).max() < 1e-10:
                Cx, Cy = g + c * np.cos(sol[1]), c * np.sin(sol[1])
                if np.sign((g - Bx) * (Cy - By) - (0 - By) * (Cx - Bx)) == want:
                    roots.append(float(sol[1]))
        assert roots, "no root on the design's circuit"
        assert np.ptp(np.unwrap(roots)) < 1e-7  # one root on each circuit
        out.append(roots[0] + d.ground_angle)
    return np.array(out)


def _pairs_csv(path, phi, psi):
    path.write_text("input,output\n" + "".join(f"{float(a)!r},{float(b)!r}\n" for a, b in zip(phi, psi)))
    return path


def test_arc_margin_matches_dense_sampling():
    rng = np.random.default_rng(3)
    a, b, c = np.exp(rng.uniform(-1.5, 1.5, (3, 300)))
    t0 = rng.uniform(-7, 7, 300)
    t1 = t0 + rng.uniform(0.05, 4.0, 300)
    m = arc_margin(a, b, c, t0, t1)
    s = np.linspace(0, 1, 4001)
    T = t0[:, None] + (t1 - t0)[:, None] * s
    L2 = a[:, None] ** 2 + 1 - 2 * a[:, None] * np.cos(T)
    cmu = (b[:, None] ** 2 + c[:, None] ** 2 - L2) / (2 * b[:, None] * c[:, None])
    closes = (np.abs(cmu) <= 1).all(1)
    assert (closes == (m >= 0)).mean() > 0.97  # both sides occur, and agree
    assert 30 < closes.sum() < 270
    both = closes & (m > 1e-3)
    mu = np.arccos(cmu[both])
    dense = np.minimum(mu.min(1), np.pi - mu.max(1))
    assert np.abs(dense - m[both]).max() < 2e-3  # sampled margin (upper bound) close to the exact one


def test_known_fourbar_recovered_fixed_offsets():
    fb = FourBar(5.0, 1.5, 4.0, 3.5)  # crank-rocker
    phi = np.linspace(0.4, 2.4, 7)
    _, psi, ok = fb.angles(phi)
    assert ok.all()
    d, why = synthesise_function(phi, psi, ground=5.0)
    assert d is not None and d.ok, (why, d and d.checks)
    assert d.max_error < 1e-9
    assert abs(d.crank - 1.5) < 1e-6 and abs(d.coupler - 4.0) < 1e-6 and abs(d.rocker - 3.5) < 1e-6


@pytest.mark.slow
def test_known_fourbar_recovered_with_free_offsets_and_root_finder_agrees():
    # a double-rocker's pairs, given with unknown zeros: only the differences are the request
    fb = FourBar(4.0, 3.0, 1.6, 3.5, circuit="crossed")
    lo, hi = fb.input_range()[0]
    phi = np.linspace(lo + 0.1 * (hi - lo), hi - 0.1 * (hi - lo), 8)
    _, psi, ok = fb.angles(phi)
    assert ok.all()
    d, why = synthesise_function(phi + 0.7, psi - 1.1, ground=4.0, cons=FunctionConstraints(free_offsets=True))
    assert d is not None and d.ok, (why, d and d.checks)
    assert d.max_error < 1e-7
    assert np.allclose([d.crank, d.coupler, d.rocker], [3.0, 1.6, 3.5], atol=1e-5)
    assert abs(_wrap(d.input_offset + 0.7)) < 1e-6 and abs(_wrap(d.output_offset - 1.1)) < 1e-6
    # scipy's root finder, on the design's circuit, gives the reported errors
    want = d.psi + d.output_offset + d.ground_angle
    assert np.abs(_wrap(_loop_closure_outputs(d) - want) - d.output_error).max() < 1e-9


def _random_pairs(rng, n):
    """``n`` (input, output) pairs of a random four-bar (FourBar's own solve) on an arc its crank moves over."""
    while True:
        a, b, c = np.exp(rng.uniform(-1.0, 1.0, 3))
        if max(a, b, c, 1.0) >= 0.99 * (a + b + c + 1.0 - max(a, b, c, 1.0)):
            continue  # it cannot close
        fb = FourBar(1.0, a, b, c, circuit=str(rng.choice(["open", "crossed"])))
        rng_ = fb.input_range()
        if not rng_:
            continue
        lo, hi = rng_[0]
        if hi - lo > 6.28:
            lo, hi = lo, lo + rng.uniform(1.0, 5.0)
        pad = 0.1 * (hi - lo)
        phi = np.sort(rng.uniform(lo + pad, hi - pad, n))
        _, psi, ok = fb.angles(phi)
        if ok.all() and np.min(np.diff(phi)) > 1e-3 and np.abs(np.diff(np.unwrap(psi))).max() < 2.8:
            return (a, b, c), phi, psi


@pytest.mark.parametrize("n", [5, 6, 9])
def test_free_offsets_five_or_more_pairs_exact(n):
    """Free offsets from 5 pairs: the algebraic solve meets every pair to rounding, in a few ms; from 6 pairs the
    four-bar is the one the pairs came from (the null space is a line)."""
    import time

    rng = np.random.default_rng(100 + n)
    cpu = []
    for _ in range(8):
        (a, b, c), phi, psi = _random_pairs(rng, n)
        A, B = rng.uniform(-np.pi, np.pi, 2)
        t0 = time.process_time()
        d, why = synthesise_function(phi - A, psi - B, ground=2.0, cons=FunctionConstraints(free_offsets=True, max_ratio=30))
        cpu.append(time.process_time() - t0)
        assert d is not None and d.ok, (why, d and d.checks)
        assert d.max_error < 1e-9
        if n >= 6:
            assert np.allclose([d.crank, d.coupler, d.rocker], [2 * a, 2 * b, 2 * c], rtol=1e-6)
    assert np.median(cpu) < 0.05


def test_linear_unknowns_hold_the_true_four_bar():
    """The null space's candidates include the four-bar the 5 pairs came from (its seven products)."""
    from planar.synth.function_search import _linear_unknowns

    rng = np.random.default_rng(7)
    for _ in range(12):
        (a, b, c), phi, psi = _random_pairs(rng, 5)
        A, B = rng.uniform(-np.pi, np.pi, 2)
        K1, K2, K3 = 1 / a, 1 / c, (a * a - b * b + c * c + 1) / (2 * a * c)
        u = np.array([K1 * np.cos(B), K1 * np.sin(B), K2 * np.cos(A), K2 * np.sin(A), K3, np.cos(A - B), np.sin(A - B)])
        U = _linear_unknowns(phi - A, psi - B)
        U = U / np.hypot(U[:, 5], U[:, 6])[:, None]
        assert 1 <= len(U) <= 3
        assert min(np.abs(U - u).max(1).min(), np.abs(U + u).max(1).min()) < 1e-6


def test_cli_finds_valid_linkage_where_closed_form_is_not_one(tmp_path, capsys):
    # y = tan x on [0, pi/4], 5 Chebyshev points, 120 deg in, 90 deg out, both zeros on the ground line:
    # the closed form's four-bar cannot reach every pair on its circuit (it exited 3 before this change)
    x = np.pi / 8 - np.pi / 8 * np.cos((2 * np.arange(1, 6) - 1) * np.pi / 10)
    phi, psi = 120 * x / (np.pi / 4), 90 * np.tan(x)
    assert not np.isfinite(freudenstein_fit(np.radians(phi), np.radians(psi)).max_error)
    pairs = _pairs_csv(tmp_path / "p.csv", phi, psi)
    out = tmp_path / "f.toml"
    assert main(["synth", "function", str(pairs), "-o", str(out), "--deg", "--json"]) == 0
    r = json.loads(capsys.readouterr().out)
    assert r["ok"] and r["method"] == "search" and r["max_output_error_rad"] <= 0.01
    # the written scene, solved by planar, gives the reported errors at the requested inputs
    scene = load_scene(out)
    assert scene.motion().valid.all()
    m = scene.mechanism.solve(np.radians(phi) + r["input_offset_rad"])
    world = m.poses["rocker"][:, 2]
    want = np.radians(psi) + r["output_offset_rad"] + r["ground_angle"]
    assert np.abs(_wrap(world - want) - r["output_error_rad"]).max() < 1e-9
    # and so does scipy's root finder on the loop-closure equations of the written lengths
    d = SimpleNamespace(
        phi=np.radians(phi),
        input_offset=r["input_offset_rad"],
        **{k: r[k] for k in ("crank", "coupler", "rocker", "ground", "circuit", "ground_angle")},
    )
    assert np.abs(_wrap(_loop_closure_outputs(d) - want) - r["output_error_rad"]).max() < 1e-9


def test_cli_free_offsets_three_pairs_exact_with_good_transmission(tmp_path, capsys):
    pairs = _pairs_csv(tmp_path / "p.csv", [45, 75, 105], [135, 160, 225])
    out = tmp_path / "f.toml"
    assert (
        main(["synth", "function", str(pairs), "-o", str(out), "--deg", "--json", "--free-offsets", "--min-transmission", "30"])
        == 0
    )
    r = json.loads(capsys.readouterr().out)
    assert r["max_output_error_rad"] < 1e-9 and r["checks"]["min_transmission_deg"] >= 30
    fb = load_scene(out).mechanism
    th = np.linspace(np.radians(45), np.radians(105), 50) + r["input_offset_rad"]
    mu = fb.transmission_angle(th)
    assert np.minimum(mu, np.pi - mu).min() >= np.radians(30) - 1e-9


@pytest.mark.slow
def test_cli_full_turn_is_a_grashof_crank(tmp_path, capsys):
    fb = FourBar(5.0, 1.5, 4.0, 3.5)
    phi = np.linspace(0.0, 3.0, 6)
    _, psi, _ = fb.angles(phi)
    pairs = _pairs_csv(tmp_path / "p.csv", phi + 1.0, psi + 2.0)  # other zeros than the linkage's
    out = tmp_path / "f.toml"
    assert (
        main(
            [
                "synth",
                "function",
                str(pairs),
                "-o",
                str(out),
                "--json",
                "--free-offsets",
                "--full-turn",
                "--min-transmission",
                "30",
            ]
        )
        == 0
    )
    r = json.loads(capsys.readouterr().out)
    assert r["grashof"] in ("crank-rocker", "double-crank") and r["checks"]["crank_turns_fully"]
    assert r["max_output_error_rad"] < 1e-6
    scene = load_scene(out)
    assert scene.motion().valid.all()
    # over the whole turn, the angle between coupler and rocker (from the solved part poses) keeps 30 deg
    m = scene.mechanism.solve(np.linspace(0, 2 * np.pi, 720, endpoint=False))
    assert m.valid.all()
    rel = m.poses["coupler"][:, 2] - m.poses["rocker"][:, 2]
    assert np.degrees(np.arccos(np.abs(np.cos(rel)))).min() >= 30 - 1e-6


def test_nothing_valid_exits_3_names_the_constraint_writes_nothing(tmp_path, capsys):
    # within 1 deg of 90 deg transmission over a 60 deg arc: the coupler-rocker angle must barely change,
    # impossible with links within a ratio of 10 (|B - O4|^2 changes by 2 a d (cos t1 - cos t0))
    pairs = _pairs_csv(tmp_path / "p.csv", [60, 90, 120], [100, 120, 130])
    out = tmp_path / "f.toml"
    assert main(["synth", "function", str(pairs), "-o", str(out), "--deg", "--free-offsets", "--min-transmission", "89"]) == 3
    text = capsys.readouterr().out
    assert "no four-bar keeps the transmission angle >= 89 deg" in text and "nothing written" in text
    assert not out.exists()


@pytest.mark.parametrize(
    "argv, field",
    [
        (["--max-ratio", "1"], "--max-ratio"),
        (["--min-transmission", "90"], "--min-transmission"),
        (["--tolerance", "0"], "--tolerance"),
    ],
)
def test_cli_function_bad_options(tmp_path, capsys, argv, field):
    pairs = _pairs_csv(tmp_path / "p.csv", [10, 40, 70], [60, 75, 95])
    out = tmp_path / "f.toml"
    assert main(["synth", "function", str(pairs), "-o", str(out), "--deg", *argv]) == 2
    err = capsys.readouterr().err
    assert field in err and err.count("\n") == 1 and not out.exists()


def test_cli_function_repeated_input_names_file_and_column(tmp_path, capsys):
    pairs = _pairs_csv(tmp_path / "p.csv", [10, 10, 70], [60, 75, 95])
    out = tmp_path / "f.toml"
    assert main(["synth", "function", str(pairs), "-o", str(out), "--deg"]) == 2
    err = capsys.readouterr().err
    assert "p.csv: input = [10.0, 10.0, 70.0]" in err and err.count("\n") == 1 and not out.exists()
