"""Generic check: the analytic poses of every mechanism satisfy its own joints."""

import numpy as np
import pytest

from planar.catalog import CATALOG
from planar.model import joint_residuals


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
        holes = [f for f in part.features]
        # each hole or slot is cut inside the outline
        assert len(poly.interiors) == len(holes), f"{name}.{part.name}: {len(poly.interiors)} vs {len(holes)}"


def test_residual_detects_a_broken_joint():
    # a ternary link whose triangle is not rigid must show a residual
    from planar.linkages import RRR, Crank, Fixed, Link, Linkage

    nodes = [Fixed("O", (0, 0)), Fixed("Z", (-38, -7.8)), Crank("A", "O", 15),
             RRR("B", "A", 50, "Z", 41.5, -1), RRR("D", "A", 55.8, "Z", 40.1, -1)]
    # D hangs from the crank pin, yet the link "upper" claims Z, B, D are one rigid body
    links = [Link("crank", ("O", "A")), Link("j", ("A", "B")), Link("upper", ("Z", "B", "D")),
             Link("e", ("A", "D"))]
    lk = Linkage("bad", nodes, links)
    m = lk.run(360)
    worst = max(r.max() for r in joint_residuals(lk, m).values())
    assert worst > 1e-3
