"""Issue 11 item 3: the yz followers of #6/#9 in a toy's coupled motor run, their load in the motor torque
and in the inverse dynamics it is compared with."""

from __future__ import annotations

import math

import numpy as np
import pytest

from planar.analysis.dynamics import inverse_dynamics_torque, mass_properties
from planar.physics.simulate import SimSettings, torque_comparison
from planar.physics.toy import coupled_mechanism, plane_mechanism, simulate_toy
from planar.scene.load import load_scene
from planar.toys.assembly import toy_assembly

TOY = SimSettings(substeps=128, iterations=80)  # simulate_toy's settings


def _interval_mean(mech, t, effects, densities):
    """Inverse dynamics averaged over each sample's interval, as torque_comparison does."""
    dt = float(t[1] - t[0])
    K = TOY.substeps
    fine = t[0] - dt + (np.arange(t.size * K) + 1.0) * (dt / K)
    return inverse_dynamics_torque(mech, fine, effects, densities, t_rest=float(t[0] - dt)).reshape(t.size, K).mean(1)


def test_a_heavier_bunny_ear_loads_the_motor_and_inverse_dynamics_alike():
    from dataclasses import replace

    sc = load_scene("gallery/bunny.toml")
    toy = sc.mechanism
    # a tenth of the gallery's Earth gravity: the slider's weight would otherwise dwarf the ear's inertia
    eff = replace(sc.effects, gravity=(9.81, 0.0))
    mech = coupled_mechanism(toy_assembly(toy))
    assert "s1.follower" in [p.name for p in mech.parts]
    t = toy.driver.times(12, 1.0)
    heavy = {"s1.follower": 100.0}  # the ear 100x as dense as the rest
    r = torque_comparison(mech, t, eff, TOY, densities=heavy)
    # pymunk (the ear co-simulated in its plane, its load on the slider) agrees with inverse dynamics
    assert r["failure"] is None and r["max_rel_diff"] < 0.01, r["max_rel_diff"]
    assert r["pose_error"] < 1e-3
    sim = np.array(r["simulated"][1:], float)
    ana = np.array(r["analytic"][1:])
    # ... and both carry the ear: without it (a massless ear) they would be far more than the tolerance apart
    bare = _interval_mean(mech, t, eff, {"s1.follower": 1e-12})[1:]
    peak = r["peak"]
    assert np.abs(sim - bare).max() > 10 * 0.01 * peak, np.abs(sim - bare).max() / peak
    assert np.abs(ana - bare).max() > 10 * 0.01 * peak
    # the motor's run at the scene's density moves by the ear's share too: pymunk's change matches inverse dynamics'
    r1 = torque_comparison(mech, t, eff, TOY)
    d_sim = sim - np.array(r1["simulated"][1:], float)
    d_ana = ana - np.array(r1["analytic"][1:])
    assert np.abs(d_sim - d_ana).max() < 1e-3 * np.abs(d_ana).max(), np.abs(d_sim - d_ana).max()


@pytest.mark.parametrize("gravity", [(9.81, 0.0), (0.0, -9.81)])
def test_the_ears_share_of_inverse_dynamics_is_its_power_balance(gravity):
    # derived independently: a follower turning phi about a fixed pivot takes power I_p phi' phi'' - m g_yz . v_G;
    # the scene's gravity (gx, gy) acts in the yz plane as (gy, 0) (gx runs along the plane's normal)
    from planar.core.effects import Effects

    sc = load_scene("gallery/bunny.toml")
    toy = sc.mechanism
    mech = coupled_mechanism(toy_assembly(toy))
    eff = Effects(gravity=gravity)
    w = toy.driver.rate
    t = np.linspace(0.0, toy.driver.period, 2001)
    share = inverse_dynamics_torque(mech, t, eff, {"s1.follower": 3.0}) - inverse_dynamics_torque(
        mech, t, eff, {"s1.follower": 1e-12}
    )
    part = mech.part("s1.follower")
    m, cog, ic = mass_properties(part, 3.0)
    pose = mech.solve(toy.driver.value(t)).poses["s1.follower"]
    phi = np.unwrap(pose[:, 2])
    d1 = np.gradient(phi, t)
    d2 = np.gradient(d1, t)
    ip = ic + m * (cog[0] ** 2 + cog[1] ** 2)
    c, s = np.cos(phi), np.sin(phi)
    vy = np.gradient(pose[:, 0] + c * cog[0] - s * cog[1], t)  # the centre of gravity's y rate
    power = ip * d1 * d2 - m * gravity[1] * vy
    inner = slice(5, -5)  # np.gradient is one-sided at the ends
    err = np.abs(share - power / w)[inner].max()
    assert err < 1e-3 * np.abs(share[inner]).max(), (err, np.abs(share).max())
    assert np.abs(share).max() > 1e-3  # not a vanishing share


def test_a_six_on_a_turning_driver_with_gravity_in_the_followers_plane():
    # #6 (Oz->Ox): the edge on a turning piece; gravity along -y acts in the follower's plane
    from planar.scene.load import build_scene, parse_scene

    data = {
        "name": "six",
        "mechanism": {"type": "toy", "left": [["Rz->Oz", "Oz->Ox"]]},
        "driver": {"speed": 0.5},
        "effects": {"gravity": [0.0, -9.81]},
    }
    sc = build_scene(parse_scene(data, "six.toml"), "six.toml")
    toy = sc.mechanism
    mech = coupled_mechanism(toy_assembly(toy))
    t = toy.driver.times(12, 1.0)
    heavy = {"s1.follower": 30.0}
    r = torque_comparison(mech, t, sc.effects, TOY, densities=heavy)
    assert r["failure"] is None and r["max_rel_diff"] < 0.01, r["max_rel_diff"]
    bare = _interval_mean(mech, t, sc.effects, {"s1.follower": 1e-12})[1:]
    sim = np.array(r["simulated"][1:], float)
    assert np.abs(sim - bare).max() > 10 * 0.01 * r["peak"]


def test_the_horse_is_unchanged():
    # no stage out of the motor's plane: the coupled run is the xy pieces' run, to the bit
    sc = load_scene("gallery/horse.toml")
    toy = sc.mechanism
    t = toy.driver.times(12, 1.0)
    tp = simulate_toy(toy, t, sc.effects)
    asm = toy_assembly(toy)
    r = torque_comparison(plane_mechanism(asm, "xy"), t, sc.effects, TOY)
    assert tp.torque["simulated"] == r["simulated"] and tp.torque["analytic"] == r["analytic"]
    assert tp.torque["failure"] is None and tp.torque["max_rel_diff"] < 0.01
    assert sorted(tp.torque["pieces"]) == sorted(p.name for p in asm.parts)
    assert all(s.simulated for s in tp.stages)
    assert math.isfinite(tp.torque["peak"])
