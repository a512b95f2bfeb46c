"""``planar synth``, third new-user trial (a bean, a figure eight and poses drawn by hand): the fixes."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from planar.cli.main import main
from planar.synth.search import Constraints

DATA = Path(__file__).parent / "data"
ROW6 = np.array([4.0, 1.0, 3.5, 3.0, 1.2, 0.9, 0.4, -0.3, 0.5, -2.0, 4.0, 4.0, 5.0, 1.5, -0.5, 1.0, 1.0])


def _csv(path: Path, pts: np.ndarray) -> str:
    path.write_text("x,y\n" + "\n".join(f"{float(x)!r},{float(y)!r}" for x, y in pts) + "\n")
    return str(path)


def test_far_off_sixbar_is_named_with_its_worst_target_not_an_internal_error():
    """The six-bar's far-off message read ``worst_target``, which only the four-bar's checks had (exit 1)."""
    from planar.cli.synth import _path_failing
    from planar.synth.sixbar import SixBarDesign, check_sixbar, sixbar_points

    th = np.linspace(0.2, 2.6, 5)
    x, y, _ = sixbar_points(ROW6[None], th, "stephenson")
    t = np.column_stack([x[0], y[0]])
    t[3] += (0.7, -0.4)  # one target far off the tracer's path
    d = SixBarDesign("stephenson", ROW6, th, t, True, 0.0, 0.0)
    check_sixbar(d, Constraints(max_ratio=100.0), 1.0, tolerance=1e-3)
    assert d.checks["worst_target"] == 4
    lines = _path_failing(d, "stephenson six-bar")
    assert any(ln.startswith("no stephenson six-bar found traces this curve") and "at target 4" in ln for ln in lines)
    assert not any("--type sixbar" in ln for ln in lines)


def test_sixbar_reports_whether_it_passes_the_targets_in_one_sweep():
    from planar.synth.sixbar import SixBarDesign, check_sixbar, sixbar_points

    th = np.array([0.2, 0.9, 1.7, 2.6, 3.1])
    x, y, _ = sixbar_points(ROW6[None], th, "stephenson")
    t = np.column_stack([x[0], y[0]])
    for order, expect in ((np.arange(5), True), (np.array([0, 2, 1, 3, 4]), False)):
        d = SixBarDesign("stephenson", ROW6, th[order], t[order], False, 0.0, 0.0)
        check_sixbar(d, Constraints(max_ratio=100.0), 1.0, ordered=True)
        assert d.checks["in_order"] is expect and d.checks["ok_order"] is expect and d.ok is expect


@pytest.mark.slow
def test_sixbar_no_worse_than_the_fourbar_on_curves_no_fourbar_traces(tmp_path):
    """The Stephenson search starts from the four-bar's own curve: its largest distance is never larger."""
    from planar.synth.path import synthesise_path
    from planar.synth.sixbar import synthesise_sixbar
    from planar.synth.targets import read_path_targets

    bean, _ = read_path_targets(str(DATA / "bean.svg"), 25)
    rng = np.random.default_rng(7)
    s = np.linspace(0, 2 * np.pi, 14, endpoint=False)
    wobbly = np.column_stack([3 * np.cos(s) + 0.4 * np.cos(3 * s), np.sin(s) + 0.3 * np.sin(4 * s)])
    wobbly += 0.05 * rng.standard_normal(wobbly.shape)
    # a trial's drawn paw (an open S with a hook): plain synth path finds a rocking four-bar for it, whose curve
    # does not close over a turn, and the six-bar lost its seed (0.239 of the size off against 0.0418)
    paw_svg = tmp_path / "paw.svg"
    paw_svg.write_text('<svg xmlns="http://www.w3.org/2000/svg"><path d="M 5,50 C 15,20 30,45 38,28 C 46,10 58,8 62,18"/></svg>')
    paw, _ = read_path_targets(str(paw_svg), 12)
    for t in (bean, wobbly, paw):
        four = synthesise_path(t, budget="quick", seed=0, full_turn=True)  # the six-bar's crank turns fully
        six = synthesise_sixbar(t, budget="quick", seed=0)
        assert four.checks["max_error"] > 1e-2  # a curve no four-bar traces
        assert six.checks["ok_valid_over_turn"] and six.checks["ok_constraints"], six.checks
        assert six.checks["max_error"] <= four.checks["max_error"] * (1 + 1e-9), (six.checks, four.checks)


def test_the_sixbar_seed_asks_for_a_four_bar_whose_input_turns_fully(monkeypatch):
    # plain synth path may return a rocking four-bar (its input swings): its curve does not close over the six-bar's
    # turn, so it seeds nothing; a trial's paw drawing lost the seed so (0.239 of the size off, the full-turn
    # four-bar 0.0418).  The seed's search is asked for an input that turns fully
    import planar.synth.path as path_mod
    from planar.synth.sixbar import synthesise_sixbar

    asked: list[bool] = []

    class Seeded(Exception):
        pass

    def recorded(*a, **k):  # what the seed's search is asked, then no further (the search itself is tested above)
        asked.append(bool(k.get("full_turn")))
        raise Seeded

    monkeypatch.setattr(path_mod, "best_fourbar", recorded)
    s = np.linspace(0, 2 * np.pi, 10, endpoint=False)
    t = np.column_stack([3 * np.cos(s) + 0.4 * np.cos(3 * s), np.sin(s) + 0.3 * np.sin(4 * s)])
    with pytest.raises(Seeded):
        synthesise_sixbar(t, budget=(500, 3, 5, 1), seed=0)
    assert asked == [True]


@pytest.mark.slow
def test_sixbar_ordered_passes_the_targets_in_one_sweep(tmp_path, capsys):
    from planar.linkages import FourBar

    th = np.linspace(0, 2 * np.pi, 12, endpoint=False)
    pts = FourBar(4.0, 1.0, 3.5, 3.0, coupler_point=(1.5, 1.0)).solve(th).points["coupler_point"]
    src = _csv(tmp_path / "k.csv", pts[[0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11]])
    out = tmp_path / "k.toml"
    rc = main(["synth", "path", src, "-o", str(out), "--type", "sixbar", "--ordered", "--budget", "quick", "--json"])
    rep = json.loads(capsys.readouterr().out)
    assert rc == 0 and rep["checks"]["ok_order"] and rep["checks"]["max_error"] < 1e-6, rep
    # the crank angles at the targets, read back from the scene's own solve, run one way round within a turn
    d = np.diff(np.unwrap(np.asarray(rep["theta"])))
    assert (d > 0).all() or (d < 0).all()


@pytest.mark.slow
def test_pivots_box_named_as_the_likely_reason(tmp_path, capsys):
    from planar.linkages import FourBar

    th = np.linspace(0, 2 * np.pi, 12, endpoint=False)
    pts = FourBar(4.0, 1.0, 3.5, 3.0, coupler_point=(1.5, 1.0)).solve(th).points["coupler_point"]
    src = _csv(tmp_path / "k.csv", pts)
    rc = main(["synth", "path", src, "-o", str(tmp_path / "k.toml"), "--pivots=-1,-1,0,0", "--budget", "quick"])
    out = capsys.readouterr().out
    assert rc == 3 and "the box is why" in out and "not one a four-bar" not in out, out
    assert "--type sixbar" not in out


# four poses of a crank-rocker with a 54 deg transmission angle, as the trial drew them (degrees)
POSES4 = """x,y,angle
1.071099384,2.258457531,47.417659970
0.791725912,2.803593038,32.570891914
-0.217176457,2.308036240,31.598680691
-0.562182730,1.153200943,48.935284610
"""


def _transmission_own(md) -> float:
    """Smallest distance (deg) of the transmission angle from a toggle, by the law of cosines over a dense sweep."""
    lo, hi = md.crank_range if md.crank_range is not None else (0.0, 2 * np.pi)
    th = np.linspace(lo, hi, 100_001)
    diag2 = md.crank**2 + md.ground**2 - 2 * md.crank * md.ground * np.cos(th)
    mu = np.degrees(np.arccos((md.coupler**2 + md.rocker**2 - diag2) / (2 * md.coupler * md.rocker)))
    return float(np.minimum(mu, 180 - mu).min())


@pytest.mark.slow
@pytest.mark.parametrize("limit", [0.0, 20.0, 45.0])
def test_motion_min_transmission_selects_a_design_that_keeps_it(tmp_path, capsys, limit):
    """The trial's poses came from a 54 deg four-bar: no near-toggle design, whatever --min-transmission asks."""
    src = tmp_path / "p.csv"
    src.write_text(POSES4)
    out = tmp_path / "m.toml"
    rc = main(["synth", "motion", str(src), "--deg", "-o", str(out), "--min-transmission", str(limit), "--json"])
    rep = json.loads(capsys.readouterr().out)
    assert rc == 0 and rep["ok"], rep
    from planar.synth.motion import burmester

    t = np.loadtxt(src, delimiter=",", skiprows=1)
    t[:, 2] = np.radians(t[:, 2])
    md = burmester(t, min_transmission=np.radians(limit))
    own = _transmission_own(md)
    assert own >= max(limit, 20.0) and abs(own - rep["checks"]["min_transmission_deg"]) < 0.01


@pytest.mark.slow
def test_motion_transmission_beyond_every_design_fails_with_a_reason(tmp_path, capsys):
    src = tmp_path / "p.csv"
    src.write_text(POSES4)
    rc = main(["synth", "motion", str(src), "--deg", "-o", str(tmp_path / "m.toml"), "--min-transmission", "89", "--json"])
    rep = json.loads(capsys.readouterr().out)
    assert rc == 3 and rep["ok"] is False and "transmission angle" in rep["reason"]


def test_transmission_margins_exact_against_a_dense_sweep():
    from planar.synth.motion import crank_order, transmission_margins

    rng = np.random.default_rng(3)
    for _ in range(40):
        d, a, b, r = rng.uniform(0.2, 3.0, 4)
        th = np.sort(rng.uniform(-np.pi, np.pi, 3))[None]
        _, full, lo, hi = crank_order(th, *(np.array([v]) for v in (d, a, b, r)))
        got = transmission_margins(*(np.array([v]) for v in (d, a, b, r)), full, lo, hi)[0]
        lo0, hi0 = (0.0, 2 * np.pi) if full[0] else (lo[0], hi[0])
        s = np.linspace(lo0, hi0, 100_001)
        c = np.clip((b * b + r * r - (a * a + d * d - 2 * a * d * np.cos(s))) / (2 * b * r), -1, 1)
        mu = np.arccos(c)
        assert got == pytest.approx(np.minimum(mu, np.pi - mu).min(), abs=1e-3)


def test_transmission_constraint_of_the_search_against_a_dense_sweep():
    """The search's penalty is zero exactly when the transmission angle keeps the limit over the whole turn."""
    from planar.synth.search import violation

    rng = np.random.default_rng(11)
    X = np.column_stack([rng.uniform(0.3, 3.0, (400, 4)), np.zeros((400, 5))])
    th = np.linspace(0, 2 * np.pi, 4001)
    lim = np.radians(25.0)
    cons = Constraints(full_turn=False, max_ratio=np.inf, min_transmission=lim)
    v = violation(X, cons, 1.0, 0.0)
    d, a, b, r = (X[:, k : k + 1] for k in range(4))
    c = (b * b + r * r - (a * a + d * d - 2 * a * d * np.cos(th))) / (2 * b * r)
    closes = (np.abs(c) <= 1).all(1)  # the crank turns fully
    mu = np.arccos(np.clip(c, -1, 1))
    keeps = np.minimum(mu, np.pi - mu).min(1) >= lim
    assert closes.sum() > 20 and keeps[closes].any() and (~keeps[closes]).any()
    assert ((v == 0) == keeps)[closes].all()


def test_transmission_failure_worded_by_what_it_is():
    from planar.cli.synth import _transmission_word

    soft = _transmission_word(10.4, "at crank angle 3.1 rad from the ground line", 30.0)
    assert "falls to 10.4 deg" in soft and "drives it poorly" in soft and "jumps" not in soft and "flip" not in soft
    assert "limit 30 deg, --min-transmission" in soft
    hard = _transmission_word(0.42, "over the input's arc", 0.0)
    assert "fold nearly flat" in hard and "lock or flip" in hard and "the floor, 1 deg" in hard


@pytest.mark.slow
def test_path_min_transmission_selects_a_design_that_keeps_it(tmp_path, capsys):
    """--min-transmission 30 on the bean: the design keeps 30 deg (it returned a 10.4 deg design before)."""
    out = tmp_path / "b.toml"
    argv = ["synth", "path", str(DATA / "bean.svg"), "--points", "25", "-o", str(out), "--budget", "quick", "--json"]
    main([*argv, "--min-transmission", "30"])
    rep = json.loads(capsys.readouterr().out)
    assert rep["checks"]["ok_transmission"] and rep["checks"]["min_transmission_deg"] >= 30.0, rep["checks"]
    # the bean is closed: the drawing against the path both ways, said in a caution when beyond the tolerance
    c = rep["checks"]
    assert np.isfinite(c["drawing_max_distance"]) and np.isfinite(c["path_max_distance"])
    said = any("between the targets the drawing lies up to" in x for x in c["cautions"])
    assert said == (c["drawing_max_distance"] > c["tolerance"])
    # by the law of cosines over a dense turn, from the written lengths
    g, a, b, r = (rep[k] for k in ("ground", "crank", "coupler", "rocker"))
    th = np.linspace(0, 2 * np.pi, 100_001)
    mu = np.degrees(np.arccos((b * b + r * r - (a * a + g * g - 2 * a * g * np.cos(th))) / (2 * b * r)))
    assert np.minimum(mu, 180 - mu).min() >= 30.0 - 1e-6


def test_svg_targets_at_equal_arc_lengths_y_turned_up():
    """Gaps along the bean measured on a dense polyline of each Bezier segment (svgelements' segment
    evaluation, not the path's parameter mapping): equal; svgelements' ``point(k/n)`` varied 1.75 times."""
    import svgelements as se

    from planar.synth.targets import read_svg_points

    pts = read_svg_points(DATA / "bean.svg", 25)
    el = next(e for e in se.SVG.parse(str(DATA / "bean.svg")).elements() if isinstance(e, se.Shape))
    dense = np.vstack([np.asarray(seg.npoint(np.linspace(0, 1, 10_001))) for seg in se.Path(el) if not isinstance(seg, se.Move)])
    dense[:, 1] = -dense[:, 1]
    cum = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(dense, axis=0).T))])
    at = cum[[int(np.argmin(np.hypot(*(dense - p).T))) for p in pts]]
    gaps = np.diff(np.append(at, cum[-1]))
    assert np.abs(gaps - cum[-1] / 25).max() < 1e-4 * cum[-1], gaps
    assert np.hypot(*(pts[0] - dense[0])) < 1e-9  # from the path's start


def test_svg_open_line_sampled_end_to_end_with_y_negated(tmp_path):
    from planar.synth.targets import read_svg_points

    f = tmp_path / "l.svg"
    f.write_text('<svg xmlns="http://www.w3.org/2000/svg"><path d="M 0 0 Q 30 0 30 30"/></svg>')
    pts = read_svg_points(f, 5)
    # the quadratic Bezier's arc length by scipy's quadrature: the points at 0, 1/4 ... 1 of it
    from scipy.integrate import quad

    def speed(t: float) -> float:
        return float(np.hypot(2 * (1 - t) * 30 + 2 * t * 0, 2 * t * 30))

    total = quad(speed, 0, 1)[0]
    for k, p in enumerate(pts):
        t = np.linspace(0, 1, 20_001)
        xy = np.column_stack([2 * (1 - t) * t * 30 + t * t * 30, -(t * t * 30)])
        i = int(np.argmin(np.hypot(*(xy - p).T)))
        assert quad(speed, 0, t[i])[0] == pytest.approx(k / 4 * total, abs=2e-3 * total)
    assert pts[-1] == pytest.approx([30.0, -30.0])


def _pink(img) -> np.ndarray:
    a = np.asarray(img.convert("RGB"), int)
    return (np.abs(a - np.array([0xE3, 0x77, 0xC2])).sum(-1) < 40).nonzero()


@pytest.mark.slow
def test_render_draws_the_targets_the_synthesis_wrote(tmp_path):
    """The scene synth writes carries its targets; planar render draws them (pink), framed even far off."""
    from PIL import Image

    from planar.synth.scene_out import fourbar_scene_text

    far = [[9.0, 7.0], [9.5, 7.0], [9.0, 7.5]]  # far from the linkage: the frame must take them in
    text = fourbar_scene_text("t", 4.0, 1.0, 3.5, 3.0, (1.5, 1.0), "open", (0.0, 0.0, 0.0), targets=far)
    for name, t in (("with", text), ("without", text.replace("targets = ", "# targets = "))):
        (tmp_path / f"{name}.toml").write_text(t)
        assert main(["render", str(tmp_path / f"{name}.toml"), "-o", str(tmp_path / f"{name}.gif")]) == 0
    with Image.open(tmp_path / "with.gif") as im:
        ys, xs = _pink(im)
        w, h = im.size
    assert len(xs) > 20 and xs.max() > 0.7 * w and ys.min() < 0.3 * h  # up and right, where the targets are
    with Image.open(tmp_path / "without.gif") as im:
        assert len(_pink(im)[0]) == 0
