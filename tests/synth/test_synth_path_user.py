"""A new user's trial of ``synth path`` on drawn curves: crank angles, stages, messages, transmission."""

import json
import math

import numpy as np
import pytest

from planar.cli.main import main
from planar.synth.kernel import coupler_points
from planar.synth.path import wrapped


def _curve(row, circ, th):
    x, y, _ = coupler_points(np.asarray(row, float)[None, :], np.asarray(th, float)[None, :], np.array([circ]))
    return np.column_stack([x[0], y[0]])


def _csv(path, T, theta=None):
    head = "x,y" + (",theta" if theta is not None else "")
    ts = [float(t) for t in theta] if theta is not None else [None] * len(T)
    rows = [f"{x!r},{y!r}" + (f",{t!r}" if t is not None else "") for (x, y), t in zip(T.tolist(), ts)]
    path.write_text(head + "\n" + "\n".join(rows) + "\n")
    return path


def test_wrapped_is_in_one_turn():
    t = wrapped(np.array([-1e-20, -0.000291448, 6.2619, 7.0, -7.0, 0.0]))
    assert np.all((t >= 0) & (t < 2 * np.pi))
    assert np.allclose(np.exp(1j * t), np.exp(1j * np.array([-1e-20, -0.000291448, 6.2619, 7.0, -7.0, 0.0])))


@pytest.mark.slow
def test_scene_comment_and_json_give_the_same_wrapped_crank_angles(tmp_path, capsys):
    """Timed targets with negative crank angles: the comment and the JSON both give them in [0, 2 pi)."""
    th = np.linspace(-np.pi, np.pi, 10, endpoint=False)
    T = _curve([1.0, 0.3, 1.1, 0.9, 0.5, 0.4, 0.0, 0.0, 0.0], 1.0, th)
    src = _csv(tmp_path / "t.csv", T, th)
    out = tmp_path / "s.toml"
    main(["synth", "path", str(src), "-o", str(out), "--budget", "quick", "--json"])
    rep = json.loads(capsys.readouterr().out)
    line = next(s for s in out.read_text().splitlines() if s.startswith("# crank angle"))
    comment = np.array([float(v) for v in line.split(":", 1)[1].split(",")])
    js = np.array(rep["theta"])
    assert np.all((js >= 0) & (js < 2 * math.pi)) and np.all((comment >= 0) & (comment < 2 * math.pi))
    assert np.allclose(comment, js, atol=1e-5)


def test_first_build_says_what_it_builds_and_where(tmp_path, monkeypatch, capsys):
    from planar.synth.atlas import ENTRY_BYTES, atlas_path, load_atlas

    monkeypatch.setenv("PLANAR_CACHE_DIR", str(tmp_path / "cache"))
    load_atlas(500, seed=3, progress=True)
    err = capsys.readouterr().err
    line = err.splitlines()[0]
    assert "once" in line and "500 four-bar curves" in line and str(atlas_path(500, 3)) in line
    assert "PLANAR_CACHE_DIR" in line and "--atlas" in line
    assert atlas_path(500, 3).exists()
    # the stated size is the file's (within the npz container's few kB)
    assert abs(atlas_path(500, 3).stat().st_size - 500 * ENTRY_BYTES) < 5000
    load_atlas(500, seed=3, progress=True)
    assert "building" not in capsys.readouterr().err  # read, not built


def test_a_cache_folder_that_is_a_file_is_said_not_claimed(tmp_path, monkeypatch, capsys):
    """PLANAR_CACHE_DIR naming a regular file: the atlas is built for this run, and the notice says it could
    not be cached there (it said 'cached at FILE/atlas-...; later runs read it')."""
    from planar.synth.atlas import load_atlas

    afile = tmp_path / "afile"
    afile.write_text("x")
    monkeypatch.setenv("PLANAR_CACHE_DIR", str(afile))
    a = load_atlas(300, seed=5, progress=True)
    assert len(a.params) == 300
    err = capsys.readouterr().err
    assert "could not be cached" in err and str(afile) in err and "for this run only" in err, err
    assert afile.read_text() == "x"


def test_a_request_without_effectors_says_missing_not_none(tmp_path, capsys):
    """A design request with no [[effector]] tables: the value is 'missing' (it printed Python's None)."""
    r = tmp_path / "r.toml"
    r.write_text('name = "x"\n')
    assert main(["design", str(r), "-o", str(tmp_path / "d.toml")]) == 2
    err = capsys.readouterr().err
    assert "effector = 'missing'" in err and "None" not in err, err
    assert not (tmp_path / "d.toml").exists()


def test_a_file_that_is_not_an_atlas_is_named_in_words(tmp_path):
    """--atlas of a CSV: the message says what is wrong, not an exception class name ('BadZipFile')."""
    from planar.errors import InputError
    from planar.synth.atlas import read_atlas

    f = tmp_path / "c.csv"
    f.write_text("x,y\n0,0\n")
    with pytest.raises(InputError) as e:
        read_atlas(f)
    assert "not a .npz archive" in str(e.value) and "BadZip" not in str(e.value)


def test_transmission_margin_against_the_solved_joints():
    """The smallest transmission-angle margin, against the angle at C measured from the solver's joint positions."""
    from planar.linkages import FourBar
    from planar.synth.path import transmission_margin

    rng = np.random.default_rng(7)
    # the user's ordered square design (0.396 deg) and random Grashof four-bars (crank or ground shortest)
    cases = [(26.955905620174722, 27.19792239465485, 35.035022287527305, 35.03502226747112)]
    while len(cases) < 12:
        g, a, b, c = np.exp(rng.uniform(-1, 1, 4))
        s = sorted((g, a, b, c))
        if s[0] + s[3] <= s[1] + s[2] and min(g, a) == s[0]:
            cases.append((g, a, b, c))
    for g, a, b, c in cases:
        fb = FourBar(ground=g, crank=a, coupler=b, rocker=c, coupler_point=(0.5 * b, 0.0))
        th = np.linspace(0, 2 * np.pi, 20001)
        t3, _, ok = fb.angles(th)  # the joints from the coupler's angle (tangent half-angle), not the law of cosines
        assert ok.all()
        B = a * np.column_stack([np.cos(th), np.sin(th)])
        C = B + b * np.column_stack([np.cos(t3), np.sin(t3)])
        cb, co = B - C, np.array([g, 0.0]) - C
        mu = np.arccos(np.clip(np.sum(cb * co, 1) / np.hypot(*cb.T) / np.hypot(*co.T), -1, 1))
        want = np.minimum(mu, np.pi - mu).min()
        got, at = transmission_margin(fb)
        assert got == pytest.approx(want, abs=1e-6)
        assert got <= want + 1e-12 and 0 <= at < 2 * np.pi
    got, _ = transmission_margin(FourBar(ground=cases[0][0], crank=cases[0][1], coupler=cases[0][2], rocker=cases[0][3]))
    assert np.degrees(got) == pytest.approx(0.396, abs=1e-3)


def _fake(max_error, tol=1e-3):
    from types import SimpleNamespace

    sq = np.array([[0, 0], [1, 0], [2, 0], [3, 0], [3, 1], [3, 2], [3, 3], [2, 3], [1, 3], [0, 3], [0, 2], [0, 1]], float)
    checks = {
        "ok_accuracy": False,
        "max_error": max_error,
        "tolerance": tol,
        "size": 1.0,
        "rms_error": max_error / 2,
        "worst_target": 3,
    }
    return SimpleNamespace(checks=checks, sse=1.0, targets=sq)


def test_far_off_says_plainly_no_four_bar_and_why_near_miss_does_not():
    from planar.cli.synth import _path_failing

    near = _path_failing(_fake(0.0011))
    assert len(near) == 1 and "no four-bar" not in near[0] and "points measured with noise, or a shape drawn by hand" in near[0]
    far = _path_failing(_fake(0.2))
    assert len(far) == 2 and far[1].startswith("no four-bar found traces this curve within --tolerance 0.001")
    assert "0.2 of the targets' size off at target 3" in far[1] and "90 deg at target" in far[1] and "corner" in far[1]


def test_sharpest_turn_smooth_and_cornered():
    from planar.cli.synth import _sharpest_turn

    t = np.linspace(0, 2 * np.pi, 16, endpoint=False)
    ell = np.column_stack([3 * np.cos(t), np.sin(t)])
    assert _sharpest_turn(ell)[0] < 60
    sq = np.array([[0, 0], [1, 0], [2, 0], [3, 0], [3, 1], [3, 2], [3, 3], [2, 3], [1, 3], [0, 3], [0, 2], [0, 1]], float)
    deg, at = _sharpest_turn(sq)
    assert deg == pytest.approx(90) and at in (1, 4, 7, 10)


@pytest.mark.slow
def test_unreachable_square_stages_and_found_by(tmp_path, capsys):
    """A square: the atlas misses, the global search runs; every stage is reported, the text names the one."""
    from planar.synth.atlas import build_atlas

    f = tmp_path / "a.npz"
    build_atlas(2000, seed=0).save(f)
    side = np.linspace(0, 1, 4, endpoint=False)
    sq = np.vstack(
        [np.column_stack([side, 0 * side]), np.column_stack([1 + 0 * side, side])]
        + [np.column_stack([1 - side, 1 + 0 * side]), np.column_stack([0 * side, 1 - side])]
    )
    src = _csv(tmp_path / "sq.csv", 60 * sq)
    rc = main(["synth", "path", str(src), "-o", str(tmp_path / "s.toml"), "--atlas", str(f), "--budget", "quick"])
    out = capsys.readouterr().out
    assert rc == 3 and "no four-bar found traces this curve" in out and "corner" in out and "found by" in out
    main(["synth", "path", str(src), "-o", str(tmp_path / "s.toml"), "--atlas", str(f), "--budget", "quick", "--json"])
    rep = json.loads(capsys.readouterr().out)
    st = rep["checks"]["stages_s"]
    assert {"atlas_load_s", "atlas_s", "refine_s", "global_sample_s", "global_de_s", "global_refine_s"} <= set(st)
    assert "global search" in rep["checks"]["found_by"]
    # a reachable curve: found by the atlas, the global search never ran
    th = np.linspace(0, 2 * np.pi, 12, endpoint=False)
    T = _curve([1.0, 0.3, 1.1, 0.9, 0.5, 0.4, 0.0, 0.0, 0.0], 1.0, th)
    src = _csv(tmp_path / "r.csv", T)
    rc = main(["synth", "path", str(src), "-o", str(tmp_path / "r.toml"), "--atlas", str(f), "--budget", "quick", "--json"])
    rep = json.loads(capsys.readouterr().out)
    if rep["checks"]["ok_accuracy"]:
        assert not any(k.startswith("global_") for k in rep["checks"]["stages_s"])
        assert rep["checks"]["found_by"].startswith("the atlas")


@pytest.mark.slow
def test_min_transmission_fails_the_check_naming_the_angle(tmp_path, capsys):
    th = np.linspace(0, 2 * np.pi, 12, endpoint=False)
    T = _curve([1.0, 0.3, 1.1, 0.9, 0.5, 0.4, 0.0, 0.0, 0.0], 1.0, th)
    src = _csv(tmp_path / "r.csv", T)
    assert main(["synth", "path", str(src), "-o", str(tmp_path / "x.toml"), "--min-transmission", "90"]) == 2
    rc = main(["synth", "path", str(src), "-o", str(tmp_path / "r.toml"), "--budget", "quick", "--min-transmission", "89"])
    out = capsys.readouterr().out
    assert rc == 3 and "the transmission angle falls to" in out and "limit 89 deg" in out
    rc = main(["synth", "path", str(src), "-o", str(tmp_path / "r.toml"), "--budget", "quick", "--json"])
    rep = json.loads(capsys.readouterr().out)
    assert rep["checks"]["ok_transmission"] == (rep["checks"]["min_transmission_deg"] >= 1.0)


def test_atlas_and_global_results_compared_by_largest_distance(monkeypatch):
    """The global search's result with the smaller sum of squares but the larger largest distance loses."""
    import planar.synth.path_search as P
    import planar.synth.search as S
    from planar.synth.path_search import PathSearch

    row = np.array([1.0, 0.3, 1.1, 0.9, 0.5, 0.4, 0.0, 0.0, 0.0])
    th = np.linspace(0, 2 * np.pi, 12, endpoint=False)
    T = _curve(row, 1.0, th)
    near, far = row.copy(), row.copy()
    near[4] += 1e-3
    far[5] += 1e-1
    good = S.SearchResult(near, 1, th, 1.0, True, 1, {"atlas_s": 0.0})  # sse values swapped on purpose
    bad = S.SearchResult(far, 1, th, 1e-9, True, 1, {"sample_s": 0.0})
    monkeypatch.setattr(S, "search_atlas", lambda *a, **k: good)
    monkeypatch.setattr(P, "search_fourbar", lambda *a, **k: bad)
    r, found, swing = PathSearch(T, S.Constraints(), "quick", 0, 1e-9, object(), False).run(None)
    assert r is good and found.startswith("the atlas") and "global_sample_s" in r.stages and swing is None


def test_a_file_that_is_not_an_arc_atlas_is_named_in_words(tmp_path):
    """The rocking arcs' reader shares the atlas's words (it printed the exception's class, or numpy's pickle text)."""
    from planar.errors import InputError
    from planar.synth.arcs import read_arcs

    f = tmp_path / "c.csv"
    f.write_text("x,y\n0,0\n")
    with pytest.raises(InputError) as e:
        read_arcs(f)
    assert "not a .npz archive" in str(e.value) and "pickle" not in str(e.value)
