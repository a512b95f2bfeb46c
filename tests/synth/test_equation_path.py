"""Path synthesis through the targets' own curve equation, as a user meets it: what the output says, the order
check, rocking inputs (``--input-rocks``) and when the equation gives nothing."""

from __future__ import annotations

import json

import numpy as np
import pytest

from planar.cli.main import main


def _csv(path, pts: np.ndarray) -> str:
    path.write_text("x,y\n" + "\n".join(f"{a!r},{b!r}" for a, b in pts.tolist()) + "\n")
    return str(path)


def _loop(o2: complex, ground: float, phi: float, crank: float, coupler: float, rocker: float, uv: complex, th, circuit=1.0):
    """Coupler points (complex) at crank angles ``th`` (rad from the ground line at angle ``phi``) by this module's own
    loop closure: the rocker pin where the circles about the crank pin and the rocker's pivot meet, left of crank
    pin -> pivot for circuit +1; ``uv`` the coupler point from the crank pin, x toward the rocker pin."""
    b = o2 + crank * np.exp(1j * (phi + np.asarray(th)))
    d = o2 + ground * np.exp(1j * phi) - b
    L = np.abs(d)
    a = (coupler**2 - rocker**2 + L**2) / (2 * L)
    c = b + d / L * (a + 1j * circuit * np.sqrt(coupler**2 - a**2))
    return b + (c - b) / coupler * uv


def _crank_rocker_points(n: int, seed: int) -> np.ndarray:
    """``n`` points, at sorted random crank angles, of a crank-rocker (ground 3.9, crank 1.2, coupler 3.5, rocker 3)
    by :func:`_loop`."""
    th = np.sort(np.random.default_rng(seed).uniform(0, 2 * np.pi, n))
    p = _loop(0j, 3.9, 0.0, 1.2, 3.5, 3.0, 1.5 + 1.0j, th)
    return np.column_stack([p.real, p.imag])


@pytest.mark.slow
def test_shuffled_targets_with_ordered_say_the_order_is_why(tmp_path, capsys):
    """Exact targets listed out of order: exit 3 at once from the equation (no atlas read), the message saying a
    four-bar passes through every target in another order; without --ordered the same targets pass."""
    pts = _crank_rocker_points(20, 1)[np.random.default_rng(2).permutation(20)]
    f = _csv(tmp_path / "shuffled.csv", pts)
    out = tmp_path / "o.toml"
    rc = main(["synth", "path", f, "-o", str(out), "--ordered", "--json"])
    rep = json.loads(capsys.readouterr().out)
    assert rc == 3 and not rep["checks"]["ok_order"] and rep["checks"]["max_error"] < 1e-9
    assert "another order than listed" in rep["checks"]["found_by"], rep["checks"]["found_by"]
    assert set(rep["checks"]["stages_s"]) == {"algebraic_s"}  # no atlas loaded, no search
    assert main(["synth", "path", f, "-o", str(out), "--json"]) == 0
    rep = json.loads(capsys.readouterr().out)
    assert "curve equation" in rep["checks"]["found_by"] and rep["checks"]["max_error"] < 1e-9


@pytest.mark.slow
def test_when_the_equation_gives_nothing_the_output_says_it_was_tried(tmp_path, capsys):
    """Noisy targets: the equation runs (its seconds reported), the sentence says it gave no four-bar, and the failed
    check names noise as a likely reason."""
    pts = _crank_rocker_points(20, 3)
    pts = pts + 0.003 * np.random.default_rng(4).standard_normal(pts.shape)
    f = _csv(tmp_path / "noisy.csv", pts)
    assert main(["synth", "path", f, "-o", str(tmp_path / "o.toml"), "--json", "--budget", "quick"]) == 3
    rep = json.loads(capsys.readouterr().out)
    c = rep["checks"]
    assert "algebraic_s" in c["stages_s"] and "atlas_s" in c["stages_s"]
    assert "curve equation gave no four-bar" in c["found_by"], c["found_by"]
    # noise is named among the likely reasons, with the RMS to set the tolerance by
    assert "points measured with noise, or a shape drawn by hand" in rep["reason"]
    assert f"{c['rms_error']:.2g} of the size" in rep["reason"]


def test_input_rocks_needs_rocking(tmp_path, capsys):
    f = _csv(tmp_path / "t.csv", _crank_rocker_points(8, 5))
    out = tmp_path / "o.toml"
    assert main(["synth", "path", f, "-o", str(out), "--input-rocks"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--input-rocks" in err[0] and "--rocking" in err[0] and not out.exists()


@pytest.mark.slow
def test_rocking_prefers_an_input_that_rocks_and_input_rocks_insists():
    """25 targets on random double-rockers' arcs: --rocking's result's input link rocks whenever one of the curve's
    cognates does (here: the double-rocker itself), said by the equation, not by the atlas; input_rocks gives the
    same or fails, never a crank."""
    from planar.bench.synthesis_rocking import rocking_problem
    from planar.synth.arcs import QUICK_FOURBARS, build_arcs, rocking_range
    from planar.synth.path import synthesise_rocking_path

    arcs = build_arcs(QUICK_FOURBARS)  # in memory: the cache folder's atlas is another test's business
    rng = np.random.default_rng(4242)
    rocks = 0
    for _ in range(8):
        t = rocking_problem(rng, "double", 25)["targets"]
        for strict in (False, True):
            d = synthesise_rocking_path(t, ordered=True, arcs=arcs, budget="quick", input_rocks=strict)
            if "error" in d.checks:
                assert strict
                continue
            row = np.array([d.ground, d.crank, d.coupler, d.rocker])
            link_rocks = rocking_range(np.concatenate([row, [0, 0, 0, 0, 0]]), d.theta) is not None
            assert d.checks["input_link"] == ("rocks" if link_rocks else "could turn fully")
            assert link_rocks or not strict
            rocks += link_rocks and not strict
            if "algebraic_s" in d.checks["stages_s"] and "arcs_s" not in d.checks["stages_s"]:
                assert "curve equation" in d.checks["found_by"] and "rocking-arc atlas" not in d.checks["found_by"]
    assert rocks >= 6, rocks


@pytest.mark.slow
def test_slightly_noisy_targets_within_the_tolerance_need_no_atlas():
    """Digitised points (noise 1e-5 of the size) with --tolerance 1e-4: the equation's four-bar, refined, is within
    it, and no atlas is loaded; its distances are the noise's size, checked by this module's own loop closure."""
    from planar.synth.path import synthesise_path

    p = _crank_rocker_points(30, 11)
    size = float(np.sqrt(np.mean(np.sum((p - p.mean(0)) ** 2, 1))))
    q = p + 1e-5 * size * np.random.default_rng(1).standard_normal(p.shape)
    d = synthesise_path(q, None, tolerance=1e-4)
    assert d.ok and "curve equation" in d.checks["found_by"] and set(d.checks["stages_s"]) == {"algebraic_s"}
    assert 1e-6 < d.checks["max_error"] <= 1e-4
    # the found four-bar's distance from the noise-free curve: within the tolerance too
    x0, y0, phi = d.placement
    circuit = 1.0 if d.circuit == "open" else -1.0
    th = np.linspace(0, 2 * np.pi, 200_001)
    curve = _loop(complex(x0, y0), d.ground, phi, d.crank, d.coupler, d.rocker, complex(*d.coupler_point), th, circuit)
    truth = p[:, 0] + 1j * p[:, 1]
    assert np.max(np.min(np.abs(truth[:, None] - curve[None, :]), axis=1)) < 1e-4 * size
