"""Issue 11 item 3/4: the #6/#9 edge can only push its follower's pin; inverse dynamics says where it lets go."""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest

from planar.analysis.dynamics import plane_gravity
from planar.cli.main import main
from planar.core.geometry import poses_apply
from planar.physics.toy import _poses, skew_hold, skew_stage
from planar.scene.load import load_scene
from planar.toys.assembly import toy_assembly
from planar.windup.mechanisms import SkewContact

ROOT = Path(__file__).resolve().parents[2]

FLAPPER = """name = "flapper"
angle_unit = "deg"

[mechanism]
type = "toy"
left = [["Rz->Ty"]]
right = [["Rz->Oz", "Oz->Ox"]]
phase = 90.0

[driver]
speed = {speed}
samples_per_cycle = 36

[effects]
gravity = {gravity}
"""


def _flapper(tmp_path: Path, speed: float, gravity: str) -> Path:
    p = tmp_path / "flapper.toml"
    p.write_text(FLAPPER.format(speed=speed, gravity=gravity))
    return p


def _skew_stage(path: Path):
    """The toy's #6/#9 stage as the toy drives it, and the toy's gravity in its follower's plane (yz)."""
    sc = load_scene(path)
    toy = sc.mechanism
    (st,) = [p.stage for p in toy_assembly(toy).placed if p.stage.mech.spatial and p.stage.realisation.number != 8]

    def stage_u(q, _i=st.index):
        toy.world_motion(q)
        return np.asarray(toy._last_bases[_i][0], float)

    gp = plane_gravity("yz", sc.effects.gravity)
    return st.mech, (toy.driver, stage_u), (float(gp[0]), float(gp[1])), toy.driver.rate / (2 * math.pi)


def _push_in_plane(mech, drive, samples: int) -> np.ndarray:
    """The push side derived a second way, in the follower's plane: the edge crosses the plane x = pin_x at a
    trace point, on one side of the pin's axis (``side``) at a height ``h`` along it; the edge pushes the pin
    away from it (along the axis's normal), a moment ``side h F`` about the pivot."""
    from dataclasses import replace

    j = next(j for j in mech.joints if isinstance(j, SkewContact))
    law = replace(drive[0], rate=2 * math.pi)
    po = _poses(mech, law.value(law.times(samples, 1.0)), drive)
    dp, fp = po[j.a], po[j.b]
    e0 = poses_apply(dp, j.edge_point)
    ang = dp[:, 2] + math.atan2(j.edge_dir[1], j.edge_dir[0])
    ty = e0[:, 1] + (j.pin_x - e0[:, 0]) * np.tan(ang)
    dy, dz = ty - fp[:, 0], j.plane_z - fp[:, 1]
    a = fp[:, 2]
    side = np.sign(dy * np.cos(a) + dz * np.sin(a))
    h = -dy * np.sin(a) + dz * np.cos(a)
    return side * np.sign(h)


@pytest.mark.slow
def test_flapper_without_gravity_lets_go_and_planar_toy_fails(tmp_path: Path, capsys) -> None:
    """The trial's flapper: no gravity at 5 cycles/s; nothing holds the wing's pin on its driver's edge."""
    path = _flapper(tmp_path, 5.0, "[0.0, 0.0]")
    mech, drive, g, speed = _skew_stage(path)
    h = skew_hold(mech, g, speed, samples_per_cycle=36, drive=drive)
    assert h.critical_speed == 0.0 and h.letgo is not None
    # the moment the edge must give (I_p phi'' alone) takes both signs over the cycle: somewhere it must pull
    assert h.moment.min() < 0 < h.moment.max()
    assert main(["toy", str(path)]) == 3
    out = capsys.readouterr().out
    assert "s2: the edge lets the pin go at the scene's speed (5 cycles/s)" in out and "[FAIL]" in out
    assert f"sample {h.letgo}" in out


def test_gravity_in_the_followers_plane_holds_slow_and_lets_go_fast_as_pymunk_says(tmp_path: Path) -> None:
    """Gravity along -y lies in the wing's plane (yz): it holds the pin on the edge up to a speed; the two-sided
    pymunk rebuild's contact moment (angular momentum change less gravity's moment) first takes the pulling
    sign at that speed (bisection), and matches inverse dynamics' moment along the way."""
    mech, drive, g, speed = _skew_stage(_flapper(tmp_path, 0.5, "[0.0, -9.81]"))
    assert g == (-9.81, 0.0)
    h = skew_hold(mech, g, speed, samples_per_cycle=72, drive=drive)
    crit = h.critical_speed
    assert h.letgo is None and 1.0 < crit < 3.0, crit
    # the push side from the skew distance's gradient agrees with the in-plane picture
    np.testing.assert_array_equal(h.push, _push_in_plane(mech, drive, 72))

    def pulls(sp: float) -> bool:
        rec: list[tuple[float, float]] = []
        _err, why = skew_stage(mech, sp, samples_per_cycle=72, substeps=32, drive=drive, gravity=g, record=rec)
        assert why is None
        _t, m = np.array(rec).T
        m = m[32:]  # the first sample interval: the start transient
        return bool((h.push[0] * m < 0).any())

    # pymunk's moment against inverse dynamics' (the interval's mid-point) at the scene's speed
    rec: list[tuple[float, float]] = []
    skew_stage(mech, speed, samples_per_cycle=72, substeps=32, drive=drive, gravity=g, record=rec)
    m_sim = np.array(rec)[:, 1].reshape(-1, 32).mean(1)[1:]
    m_id = 0.5 * (h.moment[1:] + h.moment[:-1])[1:]
    assert np.abs(m_sim - m_id).max() < 1e-3 * np.abs(m_id).max()
    lo, hi = 0.5, 4.0
    assert not pulls(lo) and pulls(hi)
    for _ in range(7):
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if pulls(mid) else (mid, hi)
    assert abs(0.5 * (lo + hi) - crit) < 0.01 * crit, (lo, hi, crit)
    # above it, inverse dynamics names the first sample where it would pull
    fast = skew_hold(mech, g, 1.2 * crit, samples_per_cycle=72, drive=drive)
    assert fast.letgo is not None and fast.push[fast.letgo] * fast.moment[fast.letgo] < 0
    # gravity the other way pushes the pin off the edge: it cannot hold even at rest
    assert skew_hold(mech, (9.81, 0.0), 0.1, drive=drive).critical_speed == 0.0


@pytest.mark.parametrize("gravity, holds", [("[9.81, 0.0]", False), ("[9.81, -9.81]", True), ("[69.367175, -69.367175]", True)])
def test_bunny_ear_needs_gravity_in_its_plane(tmp_path: Path, gravity: str, holds: bool) -> None:
    """The gallery Bunny's #9 ear turns in yz: gx (the old gallery gravity) is normal to it and holds nothing; the
    gallery's gravity has a -y part that holds the pin on the slider's edge at its speed."""
    text = (ROOT / "gallery" / "bunny.toml").read_text()
    assert "gravity = [69.367175, -69.367175]" in text  # the gallery scene: Earth's, tilted 45 degrees
    p = tmp_path / "bunny.toml"
    p.write_text(re.sub(r"^gravity = \[.*\]$", f"gravity = {gravity}", text, count=1, flags=re.M))
    mech, drive, g, speed = _skew_stage(p)
    h = skew_hold(mech, g, speed, samples_per_cycle=36, drive=drive)
    assert (h.letgo is None) is holds
    if holds:
        assert speed < h.critical_speed < 10 * speed, h.critical_speed
    else:
        assert h.critical_speed == 0.0
