"""The live editor (planar[notebook]): its Python side recomputes the curve from the sliders' state, no browser."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from planar.draw.widget import Editor
from planar.linkages.fourbar import FourBar
from planar.scene.load import load_scene, scene_from_mechanism

GALLERY = Path(__file__).resolve().parents[2] / "gallery"


def _scene(**dims):
    base = {"ground": 4.0, "crank": 1.0, "coupler": 3.5, "rocker": 3.0}
    return scene_from_mechanism(FourBar(**{**base, **dims}, coupler_point=(1.5, 1.0)))


def _coupler_point(a, b, c, d, theta, cp):
    """Coupler point by hand: B on the crank circle, C from circle-circle intersection (open circuit: C left of B->O4)."""
    B = np.array([a * math.cos(theta), a * math.sin(theta)])
    O4 = np.array([d, 0.0])
    e = O4 - B
    L = float(np.hypot(*e))
    x = (b * b - c * c + L * L) / (2 * L)
    h = math.sqrt(max(b * b - x * x, 0.0))
    u = e / L
    C = B + x * u + h * np.array([-u[1], u[0]])
    ux = (C - B) / b
    return B + cp[0] * ux + cp[1] * np.array([-ux[1], ux[0]])


def test_dragging_a_slider_recomputes_the_curve():
    ed = Editor(_scene(), samples=36)
    assert set(ed.dims) >= {"ground", "crank", "coupler", "rocker"}
    before = np.array(ed.curve)
    ed.set(crank=1.3)
    after = np.array(ed.curve)
    assert not np.allclose(before, after)
    for k in (0, 9, 20):
        theta = 2 * math.pi * k / 36
        assert after[k] == pytest.approx(_coupler_point(1.3, 3.5, 3.0, 4.0, theta, (1.5, 1.0)), abs=1e-8)
    assert all(ed.valid) and ed.toggles == []


def test_dead_zones_and_toggles_shown():
    ed = Editor(_scene(), samples=72)
    ed.set(crank=2.8)  # s + l = 6.8 > p + q = 6.5: a triple rocker, the crank cannot turn
    assert not all(ed.valid) and any(ed.valid)
    assert len(ed.toggles) == 2  # the two toggle positions, as points on the curve


def test_impossible_values_keep_the_last_curve(tmp_path):
    ed = Editor(_scene(), samples=24)
    good = list(ed.curve)
    ed.set(crank=20.0)  # the longest link longer than the others together
    assert ed.error and ed.curve == good


def test_saved_scene_loads_with_the_edit(tmp_path):
    ed = Editor(_scene(), samples=24)
    ed.set(rocker=3.2)
    ed.save(tmp_path / "edited.toml")
    again = load_scene(tmp_path / "edited.toml")
    assert again.mechanism.dims.c == pytest.approx(3.2)


def test_linkage_node_dimensions():
    ed = Editor(load_scene(GALLERY / "jansen-leg.toml"), samples=24)
    assert "A.radius" in ed.dims and "B.ra" in ed.dims
    before = np.array(ed.curve)
    ed.set(**{"A.radius": 14.0})
    assert not np.allclose(before, np.array(ed.curve)) and not ed.error


def test_widget_traits_drive_the_editor():
    pytest.importorskip("anywidget", reason="the notebook extra (anywidget)")
    from planar.draw.widget import editor

    w = editor(_scene(), samples=24)
    first = list(w.curve)
    w.dims = {**w.dims, "coupler": 3.8}
    assert w.curve != first and w.editor.dims["coupler"] == 3.8
