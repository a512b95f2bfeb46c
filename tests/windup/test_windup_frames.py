"""Parameters in the supplement's frames: moving ``D_o`` moves the whole mechanism.

The supplement (Part 2, note to #1): ``F_o`` is relative to the driver's frame,
every other follower position to the follower's own frame; the driver's own
positions (``D_jc``) to the driver's frame.  So shifting ``D_o`` by a vector
must shift every part's pose by that vector (in the part's plane) and leave
the follower's motion unchanged; the joints must still close.
"""

import numpy as np
import pytest

from planar.windup import elemental
from planar.windup.mechanisms import ELEMENTAL

SHIFT = np.array([0.13, -0.07, 0.05])
AXES = {"x": 0, "y": 1, "z": 2}


def _cycle(mech, n=181):
    return mech.driver.value(np.linspace(0.0, mech.driver.period, n))


def _shifted(k):
    base = elemental(k)
    o = np.asarray(base.params.D_o, float)
    moved = elemental(k, D_o=tuple(float(x) for x in o + SHIFT[: o.size]))
    return base, moved, SHIFT[: o.size]


def _plane_shift(part, v):
    i, j = AXES[part.plane[0]], AXES[part.plane[1]]
    return np.array([v[i] if i < v.size else 0.0, v[j] if j < v.size else 0.0])


@pytest.mark.parametrize("k", sorted(ELEMENTAL))
def test_moving_D_o_keeps_the_follower_motion(k):
    base, moved, _ = _shifted(k)
    q = _cycle(base)
    a, b = base.stage(q), moved.stage(q)
    assert a.valid.all() and b.valid.all()
    np.testing.assert_allclose(b.out, a.out, rtol=0, atol=1e-12)


@pytest.mark.parametrize("k", sorted(ELEMENTAL))
def test_moving_D_o_moves_every_part(k):
    base, moved, v = _shifted(k)
    q = _cycle(base)
    ma, mb = base.solve(q), moved.solve(q)
    assert ma.valid.all() and mb.valid.all()
    for part in base.parts:
        d = _plane_shift(part, v) if not part.ground else np.zeros(2)
        pa, pb = ma.poses[part.name], mb.poses[part.name]
        np.testing.assert_allclose(
            pb[:, :2] - pa[:, :2], np.broadcast_to(d, pa[:, :2].shape), rtol=0, atol=1e-12, err_msg=f"#{k} {part.name}"
        )
        np.testing.assert_allclose(pb[:, 2], pa[:, 2], rtol=0, atol=1e-12, err_msg=f"#{k} {part.name} angle")
        other = moved.part(part.name)
        if part.ground:  # the ground's features are in world: they move with D_o
            h0, h1 = np.array(part.hull), np.array(other.hull)
            np.testing.assert_allclose(h1[:, :2] - h0[:, :2], np.broadcast_to(_plane_shift(part, v), h0[:, :2].shape), atol=1e-12)
        else:  # moving parts are drawn in their own frames: identical outlines
            assert abs(other.outline.symmetric_difference(part.outline).area) < 1e-12
        # a part moving in "yz" (#6, #9 follower) sits at x = offset: it moves by the shift's x
        axis = ({"x", "y", "z"} - set(part.plane)).pop()
        assert other.offset - part.offset == pytest.approx(
            v[AXES[axis]] if AXES[axis] < v.size and part.offset else 0.0, abs=1e-12
        )
    # every joint of the moved mechanism still closes (its own residual, in world)
    for j in moved.joints:
        assert float(np.max(j.residual(mb.poses))) < 1e-9 * moved.size, f"#{k} {j.name}"


def test_issue_example_stroke_of_1_is_unchanged():
    # the issue's example: elemental(1, D_o=(0.1, 0.05)) changed the stroke from 0.12 to 0.201
    q = np.linspace(0.0, 2 * np.pi, 721)
    base, moved = elemental(1), elemental(1, D_o=(0.1, 0.05))
    assert np.ptp(moved.stage(q).out) == pytest.approx(np.ptp(base.stage(q).out), abs=1e-12)
    assert np.ptp(base.stage(q).out) == pytest.approx(0.12, abs=1e-6)
    f0 = base.solve(np.zeros(1)).poses["follower"][0]
    f1 = moved.solve(np.zeros(1)).poses["follower"][0]
    np.testing.assert_allclose(f1[:2] - f0[:2], [0.1, 0.05], atol=1e-12)
