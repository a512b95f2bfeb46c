"""Untimed path synthesis says what few targets, or targets on a short arc, leave open (a new user's trial: a
four-bar exact at 8 targets whose curve was 1.4 % of the size away from theirs between the targets)."""

import numpy as np
import pytest

from planar.synth.kernel import coupler_points
from planar.synth.path import FIXED_FROM, untimed_cautions

ROW = np.array([1.0, 0.3, 1.1, 0.9, 0.5, 0.4, 0.2, 0.1, 0.3])


def _points(row, th):
    x, y, ok = coupler_points(np.asarray(row, float)[None, :], np.asarray(th, float), np.array([1.0]))
    assert ok.all()
    return np.column_stack([x[0], y[0]])


def test_cautions_name_too_few_targets_and_a_short_arc():
    whole = np.linspace(0, 2 * np.pi, 12, endpoint=False)
    assert untimed_cautions(12, whole) == []
    few = untimed_cautions(8, whole[:8] * 1.5)
    assert len(few) == 1 and "8 untimed targets do not fix the curve: through 8 points a one-parameter family" in few[0]
    assert "a finite number" in untimed_cautions(9, whole)[0] and "a 3-parameter family" in untimed_cautions(6, whole)[0]
    arc = untimed_cautions(12, np.linspace(1.0, 1.0 + np.radians(100), 12))
    assert len(arc) == 1 and "on 100 deg of the crank's turn" in arc[0]
    # a rocking input (theta None) takes no crank angles: the caution does not offer them (a re-trial's point)
    rocks = untimed_cautions(8, None)
    assert len(rocks) == 1 and "crank angles" not in rocks[0] and "spread along the arc" in rocks[0]
    assert "crank angles" in few[0] and untimed_cautions(FIXED_FROM, None) == []


def test_eight_targets_are_passed_exactly_by_another_four_bar_with_another_curve():
    """What the caution claims, shown: from the four-bar through 8 targets, a step along the null direction of the
    16 x 17 system (9 dimensions, 8 crank angles) and Gauss-Newton back give a second four-bar through all 8 to
    rounding whose curve leaves the first's between the targets."""
    th = np.sort(np.random.default_rng(4).uniform(0, 2 * np.pi, 8))
    T = _points(ROW, th)

    def resid(z):
        return (_points(z[:9], z[9:]) - T).ravel()

    def jac(z):
        h = 1e-7
        return np.column_stack([(resid(z + h * e) - resid(z - h * e)) / (2 * h) for e in np.eye(len(z))])

    z0 = np.concatenate([ROW, th])
    v = np.linalg.svd(jac(z0))[2][-1]  # the family's tangent
    z = z0 + 0.05 * v / np.linalg.norm(v[:9])
    for _ in range(30):
        z = z - np.linalg.lstsq(jac(z), resid(z), rcond=None)[0]
    assert np.abs(resid(z)).max() < 1e-12
    assert np.abs(z[:9] - ROW).max() > 1e-3  # another four-bar
    dense = np.linspace(0, 2 * np.pi, 2000, endpoint=False)
    mine, other = _points(ROW, dense), _points(z[:9], dense)
    gap = np.sqrt(((other[:, None, :] - mine[None, :, :]) ** 2).sum(-1)).min(1).max()
    size = np.sqrt(np.mean(np.sum((T - T.mean(0)) ** 2, 1)))
    assert gap > 1e-3 * size  # its curve is another between the targets


def test_synthesis_reports_the_cautions(tmp_path):
    from planar.synth.atlas import build_atlas
    from planar.synth.path import synthesise_path

    atlas = build_atlas(5000, seed=0)
    few = synthesise_path(_points(ROW, np.linspace(0, 2 * np.pi, 8, endpoint=False)), atlas=atlas, budget="quick")
    assert any("8 untimed targets do not fix the curve" in c for c in few.checks["cautions"])
    many = synthesise_path(_points(ROW, np.linspace(0, 2 * np.pi, 16, endpoint=False)), atlas=atlas, budget="quick")
    assert many.checks["max_error"] < 1e-6 and many.checks["cautions"] == []
    timed = synthesise_path(_points(ROW, th := np.linspace(0, 6, 8)), th, atlas=atlas, budget="quick")
    assert not any("untimed" in c for c in timed.checks["cautions"])  # crank angles given: the timing fixes it


def test_the_command_line_prints_each_caution(tmp_path, capsys):
    from planar.cli.main import main

    f = tmp_path / "t.csv"
    np.savetxt(f, _points(ROW, np.linspace(0, 2 * np.pi, 8, endpoint=False)), delimiter=",", header="x,y", comments="")
    rc = main(["synth", "path", str(f), "-o", str(tmp_path / "s.toml"), "--budget", "quick", "--ordered"])
    out = capsys.readouterr().out.splitlines()
    cautions = [line for line in out if line.startswith("caution: ")]
    assert rc == 0 and len(cautions) == 1 and "8 untimed targets do not fix the curve" in cautions[0], out
    assert ", synthesised in " in out[0] and " s (wall); found by " in out[0]


def test_unmet_targets_get_a_linkage_that_does_not_nearly_fold(monkeypatch):
    """A trial's hand-drawn figure: the nearest four-bar found had a transmission angle of 0.36 deg (two links
    equal to 1e-8), below the 1 deg floor; the search runs again keeping the floor and that design is kept."""
    import planar.synth.path_search as P
    import planar.synth.search as S
    from planar.synth.path import transmission_margin

    T = _points(ROW, np.linspace(0, 2 * np.pi, 9, endpoint=False))
    folding = np.array([1.0, 0.3, 0.7, 0.6000001, 0.5, 0.4, 0.2, 0.1, 0.3])  # 1 + 0.3 = 0.7 + 0.6: a change point
    calls = []

    def fake(t, atlas, cons=None, **k):
        calls.append(cons.min_transmission)
        row = folding if cons.min_transmission == 0 else ROW * np.array([1, 1, 1, 1, 1.05, 1, 1, 1, 1])
        return S.SearchResult(row, 1, np.linspace(0, 2 * np.pi, 9, endpoint=False), 1.0, True, 1, {"atlas_s": 0.0})

    monkeypatch.setattr(S, "search_atlas", fake)
    monkeypatch.setattr(P.PathSearch, "rocking", lambda self, stages: (None, None, np.inf, ""))
    monkeypatch.setattr(P, "search_fourbar", lambda *a, **k: fake(None, None, S.Constraints()))
    search = P.PathSearch(T, S.Constraints(), "quick", 0, 1e-3, object(), True)
    r, found, swing = search.run(None)
    assert (
        swing is None
        and calls[-1] == np.radians(1.0)
        and "at least 1 deg from a toggle" in found
        and "that first search: " in found
        and "floor_s" in r.stages
    )
    assert np.degrees(transmission_margin(_fb(r.params))[0]) > 1.0 > np.degrees(transmission_margin(_fb(folding))[0])


def _fb(row):
    from planar.linkages import FourBar

    return FourBar(ground=row[0], crank=row[1], coupler=row[2], rocker=row[3])


def test_a_linkage_near_a_toggle_is_cautioned_unless_a_limit_was_asked():
    """A re-trial's hand-drawn Z came back with a transmission angle 2.97 deg from a toggle and nothing said so."""
    from types import SimpleNamespace

    from planar.synth.path import transmission_cautions
    from planar.synth.search import Constraints

    near = SimpleNamespace(checks={"min_transmission_deg": 2.97, "min_transmission_at_rad": 0.0, "ok_transmission": True})
    (said,) = transmission_cautions(near, Constraints())
    assert "within 2.97 deg of a toggle" in said and "--min-transmission" in said
    assert transmission_cautions(near, Constraints(min_transmission=0.5)) == []  # asked: the check judges it
    far = SimpleNamespace(checks={"min_transmission_deg": 35.0, "min_transmission_at_rad": 0.0, "ok_transmission": True})
    assert transmission_cautions(far, Constraints()) == []
    # where: the crank's angle, or a rocking input's (a trial read "crank at" of an input that only swings)
    assert "(crank at 0 deg from the ground line)" in said
    rocks = SimpleNamespace(checks={**near.checks, "input": "rocks"})
    (said,) = transmission_cautions(rocks, Constraints())
    assert "(input at 0 deg from the ground line)" in said and "crank" not in said


def test_a_near_miss_names_the_options_that_keep_four_bars_out():
    # a trial's point: with --min-transmission and --full-turn the near miss came from them, and the line blamed noise
    # alone
    from types import SimpleNamespace

    from planar.cli.synth import _path_failing

    checks = {"ok_accuracy": False, "max_error": 0.0075, "tolerance": 0.005, "size": 2.5, "rms_error": 0.0038}
    d = SimpleNamespace(checks=checks, sse=7.9e-4)
    (plain,) = _path_failing(d)
    assert "may be the noise" in plain and "keep the nearer" not in plain
    (asked,) = _path_failing(d, asked=("--min-transmission", "--full-turn"))
    said = "; or --min-transmission and --full-turn keep the nearer four-bars out: without them it may come closer"
    assert asked.endswith(said)


def test_the_span_is_the_one_the_crank_turns_through_the_targets_in_order():
    # a re-trial's point: crank angles 62, then 196 down to 105 deg are met in order turning clockwise through 318
    # deg, where the smallest arc holding them is 134 deg; the caution gives the turn, and says which way it goes
    from planar.synth.path import crank_span

    theta = np.radians([62.0, 350.0, 300.0, 250.0, 196.0, 160.0, 130.0, 105.0])
    assert crank_span(theta) == pytest.approx((317.0, True))
    assert crank_span(theta[::-1]) == pytest.approx((317.0, False))
    s = np.radians([10.0, 200.0, 50.0, 120.0])  # out of order: the smallest arc holding them
    assert crank_span(s) == pytest.approx((190.0, False))
    said = untimed_cautions(12, theta)
    assert any("clockwise" in c and "last to first" in c for c in said) and not any("deg of the crank" in c for c in said)
    short = untimed_cautions(12, np.radians([100.0, 80.0, 60.0, 40.0, 20.0, 0.0]))
    assert any("on 100 deg of the crank's turn" in c for c in short) and any("clockwise" in c for c in short)


def test_a_four_bar_far_larger_than_its_targets_is_cautioned():
    # a trial's drawn corner (35 by 30 mm) came back with a 5,036 mm ground link and no word; the caution names the
    # longest link and its ratio to the targets' extent (the bounding box's diagonal, by hand here)
    from types import SimpleNamespace

    from planar.synth.path import LARGE_DESIGN, size_cautions

    t = np.array([[5.0, 35.0], [40.0, 35.0], [40.0, 5.0]])
    extent = float(np.hypot(35.0, 30.0))
    big = SimpleNamespace(targets=t, ground=5036.0, crank=515.0, coupler=800.0, rocker=900.0)
    (line,) = size_cautions(big)
    assert "its ground (5036)" in line and f"{5036.0 / extent:.3g} times" in line
    small = SimpleNamespace(targets=t, ground=LARGE_DESIGN * extent * 0.99, crank=10.0, coupler=20.0, rocker=30.0)
    assert size_cautions(small) == []
    assert "its rocker" in size_cautions(SimpleNamespace(targets=t, ground=1.0, crank=1.0, coupler=1.0, rocker=2e4))[0]
