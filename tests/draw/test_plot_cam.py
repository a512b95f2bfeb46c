"""A cam's charts: the follower's motion law and the pressure angle, checked against the solved motion."""

import numpy as np
import pytest

from planar.draw.charts import available_charts, scene_figure
from planar.scene.load import load_scene


def _line(fig, gid):
    for ax in fig.axes:
        for ln in ax.get_lines():
            if ln.get_gid() == gid:
                return np.asarray(ln.get_xdata(), float), np.asarray(ln.get_ydata(), float), ax
    raise AssertionError(gid)


def test_cam_follower_and_pressure_charts():
    scene = load_scene("gallery/cam-automaton.toml")
    assert {"follower", "pressure"} <= set(available_charts(scene))
    fig = scene_figure(scene, ["follower", "pressure"], samples_per_cycle=720)
    _x, s, ax = _line(fig, "follower:displacement")
    assert ax.get_xlabel() == "cam angle (deg)"
    # independent of the motion law's code: the follower arm's angle in the solved poses (degrees, mod 360)
    mech = scene.mechanism
    t = mech.driver.times(720)
    arm = np.degrees(mech.solve(mech.driver.value(t), t=t).poses["follower"][:, 2])
    assert np.abs(np.angle(np.exp(1j * np.radians(s - arm)))).max() < 1e-9
    # velocity: central differences of that angle in time (deg/s), away from the segment joins
    _, v, _ = _line(fig, "follower:velocity")
    dt = t[1] - t[0]
    fd = np.degrees(np.angle(np.exp(1j * np.radians(np.roll(arm, -1) - np.roll(arm, 1))))) / (2 * dt)
    assert np.median(np.abs(fd - v)) < 1e-3 * np.abs(v).max()
    _, p, pax = _line(fig, "pressure")
    assert np.abs(p).max() == pytest.approx(np.degrees(mech.report.max_pressure_angle), abs=0.2)
    assert "allowed 45" in pax.get_title()


def test_cam_charts_refused_for_a_linkage():
    from planar.errors import InputError

    with pytest.raises(InputError, match="not a cam"):
        scene_figure(load_scene("gallery/kangaroo-leg.toml"), ["follower"])
