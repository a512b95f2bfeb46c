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


def test_the_curve_chart_is_solved_finer_where_a_point_sweeps_fast() -> None:
    """A trial's nearly folding four-bar (coupler and rocker equal to 1e-7: the coupler point swept a third of its
    figure in 1.5 deg of crank) was drawn from the scene's 72 samples as straight chords cutting across the curve;
    the curve chart re-solves it finer, and its drawn path then stays near the curve solved at 20,000 samples."""
    from planar.draw.timing import CHORD_RATIO

    leg = planar.FourBar(ground=1.6217, crank=1.6399, coupler=2.93428, rocker=2.9342771, coupler_point=(0.702, -1.755))
    scene = planar.scene_from_mechanism(leg)
    n = scene.spec.driver.samples_per_cycle
    (line,) = [ln for ln in scene_figure(scene, "curve").axes[0].get_lines() if ln.get_gid() == "curve:coupler_point"]
    drawn = np.column_stack(line.get_data())
    fine = leg.solve(np.linspace(0.0, 2 * np.pi, 20_000, endpoint=False)).points["coupler_point"]
    coarse = leg.solve(np.linspace(0.0, 2 * np.pi, n, endpoint=False)).points["coupler_point"]

    def off(pts):  # the largest distance from the midpoint of a drawn chord to the fine curve
        from scipy.spatial import cKDTree

        return float(cKDTree(fine).query(0.5 * (pts[1:] + pts[:-1]))[0].max())

    size = np.ptp(fine, axis=0).max()
    assert len(drawn) > CHORD_RATIO * n and off(drawn) < 0.01 * size < off(np.vstack([coarse, coarse[:1]]))
    # a point moving at an even pace keeps the scene's own samples
    even = planar.FourBar(ground=4.0, crank=1.0, coupler=3.5, rocker=3.0, coupler_point=(1.5, 1.0))
    es = planar.scene_from_mechanism(even)
    (line,) = [ln for ln in scene_figure(es, "curve").axes[0].get_lines() if ln.get_gid() == "curve:coupler_point"]
    assert len(line.get_xdata()) == es.spec.driver.samples_per_cycle + 1


def test_an_animation_draws_a_fast_sweep_from_a_finer_grid() -> None:
    """The render's trails come from the fine grid of :func:`animation_motion`; for the nearly folding four-bar it is
    made finer (the frames stay at the same instants) and its chords stay near the curve solved at 20,000 samples,
    where the scene's own 72 cut across it; for an even pace it is not made finer."""
    from planar.draw.timing import CHORD_RATIO, animation_motion, plan_frames, scene_duration

    def grids(leg):
        scene = planar.scene_from_mechanism(leg)
        plan = plan_frames(scene.mechanism.driver.period, scene_duration(scene))
        frames, fine = animation_motion(scene, plan)
        direct = scene.mechanism.solve(scene.mechanism.driver.value(frames.t), t=frames.t)
        assert np.allclose(frames.points["coupler_point"], direct.points["coupler_point"], atol=1e-9)
        return scene.spec.driver.samples_per_cycle, fine.points["coupler_point"][fine.valid]

    leg = planar.FourBar(ground=1.6217, crank=1.6399, coupler=2.93428, rocker=2.9342771, coupler_point=(0.702, -1.755))
    n, trail = grids(leg)
    truth = leg.solve(np.linspace(0.0, 2 * np.pi, 20_000, endpoint=False)).points["coupler_point"]
    coarse = leg.solve(np.linspace(0.0, 2 * np.pi, n, endpoint=False)).points["coupler_point"]

    def off(pts):  # the largest distance from the midpoint of a chord to the fine curve
        from scipy.spatial import cKDTree

        return float(cKDTree(truth).query(0.5 * (pts[1:] + pts[:-1]))[0].max())

    size = np.ptp(truth, axis=0).max()
    assert len(trail) > CHORD_RATIO * n and off(trail) < 0.01 * size < off(coarse)
    n, even = grids(planar.FourBar(ground=4.0, crank=1.0, coupler=3.5, rocker=3.0, coupler_point=(1.5, 1.0)))
    assert len(even) < 2 * n
