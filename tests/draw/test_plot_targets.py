"""The coupler-curve chart draws a scene's [render] targets (the points a synthesis aimed at), as render does."""

from __future__ import annotations

import numpy as np

import planar
from planar.draw.charts import scene_figure


def test_the_curve_chart_rings_each_target_where_the_scene_puts_it() -> None:
    leg = planar.FourBar(ground=4.0, crank=1.0, coupler=3.5, rocker=3.0, coupler_point=(1.5, 1.0))
    on_curve = leg.solve(np.linspace(0.0, 2 * np.pi, 7, endpoint=False)).points["coupler_point"]
    targets = on_curve + np.random.default_rng(2).normal(0.0, 0.05, on_curve.shape)
    scene = planar.scene_from_mechanism(leg, render={"targets": targets.tolist()})
    fig = scene_figure(scene, "curve")
    (ax,) = fig.axes
    (dots,) = [ln for ln in ax.get_lines() if ln.get_gid() == "targets"]
    assert np.allclose(np.column_stack(dots.get_data()), targets)
    assert [t.get_text() for t in ax.texts] == [str(k) for k in range(1, 8)]
    assert "targets (7)" in [t.get_text() for t in ax.get_legend().get_texts()]
    plain = scene_figure(planar.scene_from_mechanism(leg), "curve")
    assert not [ln for ln in plain.axes[0].get_lines() if ln.get_gid() == "targets"]
