"""The drawing against the coupler path (:mod:`planar.synth.drawing`): both ways, from an SVG written here, the
distances checked by brute force on the same points."""

from types import SimpleNamespace

import numpy as np

from planar.linkages import FourBar
from planar.synth.drawing import drawing_cautions, drawing_gaps
from planar.synth.targets import read_svg_points


def _design(fb, size, swing=None):
    checks = {"size": size}
    if swing is not None:
        checks["input_swing_rad"] = list(swing)
    return SimpleNamespace(checks=checks, fourbar=lambda: fb)


def _svg(path, pts, closed):
    tag = "polygon" if closed else "polyline"
    xy = " ".join(f"{x:.9f},{-y:.9f}" for x, y in pts)  # SVG's y down: read back as (x, -y)
    path.write_text(f'<svg xmlns="http://www.w3.org/2000/svg"><{tag} points="{xy}" fill="none"/></svg>')


def test_a_drawing_of_the_curve_itself_is_on_the_path_and_a_bump_is_measured(tmp_path):
    fb = FourBar(4.0, 1.0, 3.5, 3.0, coupler_point=(2.0, 1.5))
    th = np.linspace(0.0, 2 * np.pi, 720, endpoint=False)
    curve = fb.solve(th).points["coupler_point"]
    size = 2.0
    f = tmp_path / "c.svg"
    _svg(f, curve, True)
    gaps = drawing_gaps(_design(fb, size), f)
    assert gaps["drawing_max_distance"] < 1e-3 and gaps["path_max_distance"] < 1e-3
    assert drawing_cautions(gaps, 1e-2, rocks=False) == []
    # one vertex pushed out along the curve's normal by h: the drawing's farthest point is that vertex
    h = 0.2
    bumped = curve.copy()
    k = 100
    tangent = curve[k + 1] - curve[k - 1]
    normal = np.array([-tangent[1], tangent[0]]) / np.hypot(*tangent)
    bumped[k] += h * normal
    _svg(f, bumped, True)
    gaps = drawing_gaps(_design(fb, size), f)
    # brute force: the drawing's own samples against the path at 40,000 angles
    drawn = read_svg_points(f, 1000)
    dense = fb.solve(np.linspace(0.0, 2 * np.pi, 40000, endpoint=False)).points["coupler_point"]
    brute = max(float(np.min(np.hypot(*(dense - p).T))) for p in drawn)
    assert abs(gaps["drawing_max_distance"] - brute / size) < 1e-4
    assert 0.8 * h / size < gaps["drawing_max_distance"] <= h / size + 1e-4
    (line,) = drawing_cautions(gaps, 1e-2, rocks=False)
    assert "between the targets the drawing lies up to" in line


def test_a_closed_drawing_traced_only_as_an_arc_and_an_open_one_is_not_asked_the_way_back(tmp_path):
    fb = FourBar(4.0, 1.0, 3.5, 3.0, coupler_point=(2.0, 1.5))
    curve = fb.solve(np.linspace(0.0, 2 * np.pi, 720, endpoint=False)).points["coupler_point"]
    f = tmp_path / "c.svg"
    _svg(f, curve, True)
    # the same crank swung over half its turn: the other half of the closed drawing is far from that path
    half = drawing_gaps(_design(fb, 2.0, (0.0, np.pi)), f)
    assert half["drawing_max_distance"] > 0.1 and half["path_max_distance"] < 1e-3
    lines = drawing_cautions(half, 1e-2, rocks=True)
    assert len(lines) == 2 and "the drawing is closed and the input rocks" in lines[0]
    # the half as an open drawing: on the swing's path both ways; the crank's whole turn comes back another way
    _svg(f, curve[:361], False)
    open_half = drawing_gaps(_design(fb, 2.0, (0.0, np.pi)), f)
    assert open_half["drawing_max_distance"] < 1e-3 and open_half["path_max_distance"] < 1e-3
    assert drawing_cautions(open_half, 1e-2, rocks=True) == []
    whole = drawing_gaps(_design(fb, 2.0), f)
    assert whole["drawing_max_distance"] < 1e-3 and whole["path_max_distance"] > 0.1
    (back,) = drawing_cautions(whole, 1e-2, rocks=False)
    assert "comes back another way" in back


def test_a_swinging_input_whose_path_leaves_an_open_drawing_is_cautioned(tmp_path):
    # a trial's drawn corner came back (--input-rocks) exact at its targets with a loop 4.6 of the size off the
    # drawing between two of them, and said nothing: the path's distance from an open drawing, for an input that
    # swings over the targets' span, now gets its own line.  Here the drawing is the straight chord of the crank's
    # half-turn arc, so the path's farthest point from it is the arc's sagitta, checked by brute force
    fb = FourBar(4.0, 1.0, 3.5, 3.0, coupler_point=(2.0, 1.5))
    arc = fb.solve(np.linspace(0.0, np.pi, 4000)).points["coupler_point"]
    f = tmp_path / "chord.svg"
    _svg(f, np.array([arc[0], arc[-1]]), False)
    size = 2.0
    gaps = drawing_gaps(_design(fb, size, (0.0, np.pi)), f)
    a, b = arc[0], arc[-1]
    u = (b - a) / np.hypot(*(b - a))
    rel = arc - a
    along = np.clip(rel @ u, 0.0, np.hypot(*(b - a)))
    brute = float(np.max(np.hypot(*(rel - along[:, None] * u).T))) / size
    assert brute > 0.05 and abs(gaps["path_max_distance"] - brute) < 1e-3 * brute
    lines = drawing_cautions(gaps, 1e-3, rocks=True)
    assert any("the coupler path leaves the drawing by up to" in line for line in lines)
    (leaves,) = [line for line in lines if "leaves the drawing" in line]
    assert f"{gaps['path_max_distance']:.3g}" in leaves
    # within the tolerance: no such line
    assert not any("leaves the drawing" in line for line in drawing_cautions(gaps, 2 * brute, rocks=True))
