"""Generic check: the analytic poses of every mechanism satisfy its own joints."""

import numpy as np
import pytest

from planar.core.model import joint_residuals
from planar.scene.catalog import CATALOG


@pytest.mark.parametrize("name", sorted(CATALOG))
def test_joints_close_to_round_off(name):
    mech = CATALOG[name]()
    motion = mech.run(samples_per_cycle=720)
    assert motion.valid.any(), f"{name}: no valid sample"
    res = joint_residuals(mech, motion)
    assert res, f"{name} has no joints"
    for joint, r in res.items():
        assert r.shape == motion.valid.shape
        worst = float(np.max(r[motion.valid]))
        assert worst <= 1e-9 * mech.size, f"{name}: joint {joint} residual {worst:.3g}"
    for part, pose in motion.poses.items():
        assert np.all(np.isfinite(pose)), f"{name}: non-finite pose of {part}"


@pytest.mark.parametrize("name", sorted(CATALOG))
def test_every_part_has_a_real_outline(name):
    mech = CATALOG[name]()
    for part in mech.parts:
        poly = part.outline
        assert poly.is_valid and poly.area > 0, f"{name}.{part.name}"
        holes = list(part.features)
        # each hole or slot is cut inside the outline
        assert len(poly.interiors) == len(holes), f"{name}.{part.name}: {len(poly.interiors)} vs {len(holes)}"


def test_a_link_whose_nodes_move_apart_is_refused_naming_link_nodes_and_change():
    # a ternary link whose triangle is not rigid: D hangs from the crank pin, yet the link
    # "upper" claims Z, B, D are one rigid body
    from planar.errors import InputError
    from planar.linkages import RRR, Crank, Fixed, Link, Linkage

    nodes = [
        Fixed("O", (0, 0)),
        Fixed("Z", (-38, -7.8)),
        Crank("A", "O", 15),
        RRR("B", "A", 50, "Z", 41.5, -1),
        RRR("D", "A", 55.8, "Z", 40.1, -1),
    ]
    links = [Link("crank", ("O", "A")), Link("j", ("A", "B")), Link("upper", ("Z", "B", "D")), Link("e", ("A", "D"))]
    with pytest.raises(InputError) as e:
        Linkage("bad", nodes, links)
    msg = str(e.value)
    assert "bad.links.upper" in msg and "'B' and 'D'" in msg and "changes by" in msg
    # the change it names is the true one (independent: the distance B-D over the cycle)
    ok = Linkage("ok", nodes, links[:2] + [Link("upper", ("Z", "B")), Link("e", ("A", "D")), Link("zd", ("Z", "D"))])
    pos = ok.node_positions(np.linspace(0, 2 * np.pi, 721))
    d = np.hypot(*(pos["B"] - pos["D"]).T)
    assert f"{np.ptp(d):.4g}" in msg


def test_residual_detects_a_broken_joint():
    # a motion in which one part is moved off its pose shows a residual at its joints
    from planar.scene.catalog import jansen_leg

    lk = jansen_leg()
    m = lk.run(90)
    m.poses["upper"] = m.poses["upper"] + np.array([0.0, 0.0, 0.01])
    res = joint_residuals(lk, m)
    worst = max(r.max() for r in res.values())
    assert worst > 0.1  # 0.01 rad at about 40 units
    assert max(res["B"].max(), res["D"].max()) == worst
