"""A toy's gravity is the 3D vector (gx, gy, 0): xz pieces (#8) feel only gx, yz pieces (#6/#9) only gy."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from planar.analysis.dynamics import plane_gravity
from planar.cli.main import main
from planar.physics.toy import simulate_toy
from planar.scene.load import load_scene

BUNNY = Path(__file__).resolve().parents[2] / "gallery" / "bunny.toml"


def _bunny(tmp_path: Path, gravity: str) -> Path:
    text = BUNNY.read_text()
    out = tmp_path / "bunny.toml"
    out.write_text(re.sub(r"^gravity = \[.*\]$", f"gravity = {gravity}", text, count=1, flags=re.M))
    return out


def test_plane_gravity_takes_each_planes_components() -> None:
    g = (3.0, -5.0)
    np.testing.assert_array_equal(plane_gravity("xy", g), [3.0, -5.0])
    np.testing.assert_array_equal(plane_gravity("xz", g), [3.0, 0.0])
    np.testing.assert_array_equal(plane_gravity("yz", g), [-5.0, 0.0])


@pytest.mark.slow
def test_gravity_along_y_does_not_hold_or_move_an_xz_tab(tmp_path: Path) -> None:
    """gy is normal to the #8 stage's plane: its hold and lift-off are those of gx alone, while the motor
    torque (xy pieces) changes with gy and pymunk still agrees with inverse dynamics."""
    runs = {}
    for g in ("[9.81, 0.0]", "[9.81, -9.81]"):
        sc = load_scene(_bunny(tmp_path, g))
        t = sc.mechanism.driver.times(12, 1.0)
        runs[g] = simulate_toy(sc.mechanism, t, sc.effects, speeds=[0.5, 4.0])
    a, b = runs["[9.81, 0.0]"], runs["[9.81, -9.81]"]
    for r in (a, b):
        assert r.torque["failure"] is None and r.torque["max_rel_diff"] < 0.01
        assert "s2.follower" in r.torque["pieces"]
    (label,) = a.liftoff
    assert a.liftoff[label]["predicted_speed"] == b.liftoff[label]["predicted_speed"]
    assert a.liftoff[label]["liftoff_speed"] == b.liftoff[label]["liftoff_speed"]
    assert a.liftoff[label]["pose_error"] == b.liftoff[label]["pose_error"]
    # the xy pieces do feel gy: the motor torque differs by far more than the comparison's tolerance
    ta, tb = np.array(a.torque["analytic"], float), np.array(b.torque["analytic"], float)
    assert np.max(np.abs(ta - tb)) > 0.02 * a.torque["peak"]


@pytest.mark.slow
def test_a_toy_lying_with_gravity_along_y_cannot_hold_its_tab_and_says_so(tmp_path: Path, capsys) -> None:
    code = main(["toy", str(_bunny(tmp_path, "[0.0, -9.81]"))])
    out = capsys.readouterr().out
    assert code == 3
    assert "s2 Tx->Oy: NOT simulated" in out and "normal to the xz plane" in out
    assert "not frame.xz, s2.driver, s2.follower" in out  # left out of the motor run, and the line says so
