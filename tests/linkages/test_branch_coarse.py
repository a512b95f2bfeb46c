"""A four-bar with no singular position keeps its declared circuit at every sample, however coarse the sampling.

Found by a new user: a crossed crank-rocker (from `planar synth path`) sampled 4 or 7 times a turn was carried
onto the open circuit by the continuity rule's extrapolation, with every sample marked valid.
"""

import numpy as np
import pytest

from planar.linkages import FourBar


def _one_by_one(fb, q):
    return np.array([fb.solve(q[i : i + 1]).points["coupler_point"][0] for i in range(q.shape[0])])


@pytest.mark.parametrize("n", [4, 7])
def test_the_reported_crossed_crank_rocker(n):
    fb = FourBar(
        5.555758555658564,
        1.5003548841540635,
        5.156900654685513,
        1.9274335137160765,
        coupler_point=(3.0140839693395267, 0.5662632134012724),
        circuit="crossed",
    )
    q = np.arange(n) * 2 * np.pi / n
    np.testing.assert_allclose(fb.solve(q).points["coupler_point"], _one_by_one(fb, q), atol=1e-12)


@pytest.mark.slow
def test_random_grashof_cranks_at_any_sampling():
    rng = np.random.default_rng(7)
    done = 0
    while done < 120:
        lengths = rng.uniform(0.3, 5.0, 4)
        try:
            fb = FourBar(*lengths, coupler_point=tuple(rng.uniform(-2, 2, 2)), circuit=str(rng.choice(["open", "crossed"])))
        except ValueError:
            continue
        if fb.grashof not in ("crank-rocker", "double-crank"):
            continue
        done += 1
        n = int(rng.integers(3, 41))
        q = np.arange(n) * 2 * np.pi / n + rng.uniform(0, 2 * np.pi)
        m = fb.solve(q)
        assert m.valid.all()
        # each sample alone is solved on the declared circuit (no path, nothing carried): the batch must agree
        np.testing.assert_allclose(m.points["coupler_point"], _one_by_one(fb, q), atol=1e-9)


def test_a_parallelogram_is_still_carried_through_its_change_points():
    fb = FourBar(2.0, 1.0, 2.0, 1.0, circuit="open")
    assert fb.grashof == "change-point"
    q = np.linspace(0, 2 * np.pi, 361)
    m = fb.solve(q)
    # a parallelogram: the coupler stays parallel to the ground through the whole turn
    ang = np.angle(np.exp(1j * m.poses["coupler"][:, 2]))
    assert np.abs(np.sin(ang[m.valid])).max() < 1e-6
