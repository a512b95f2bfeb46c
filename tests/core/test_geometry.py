"""Transforms and intersections: properties (hypothesis) and exact cases."""

import numpy as np
from hypothesis import assume, given
from hypothesis import strategies as st

from planar.core import geometry as g

coord = st.floats(-100, 100, allow_nan=False)
angle = st.floats(-10, 10, allow_nan=False)
radius = st.floats(0.01, 100, allow_nan=False)


@given(coord, coord, angle, coord, coord)
def test_rotation_translation_match_notes_matrices(x, y, th, px, py):
    # notes eqs (1)-(2): p' = T R p
    m = g.compose(g.translation(x, y), g.rotation(th))
    expected = np.array([x + np.cos(th) * px - np.sin(th) * py, y + np.sin(th) * px + np.cos(th) * py])
    np.testing.assert_allclose(g.apply(m, [px, py]), expected, atol=1e-9)
    np.testing.assert_allclose(g.poses_apply(np.array([x, y, th]), [px, py]), expected, atol=1e-9)


@given(coord, coord, angle)
def test_inverse_is_inverse(x, y, th):
    m = g.pose_matrix([x, y, th])
    np.testing.assert_allclose(g.compose(m, g.invert(m)), np.eye(3), atol=1e-9)
    np.testing.assert_allclose(g.compose(g.invert(m), m), np.eye(3), atol=1e-9)


@given(st.lists(st.tuples(coord, coord, angle), min_size=1, max_size=5), coord, coord)
def test_batched_poses_agree_with_matrices(poses, px, py):
    P = np.array(poses)
    mats = g.pose_matrix(P)
    via_mat = g.apply(mats, np.array([[px, py]]))[:, 0, :]
    np.testing.assert_allclose(g.poses_apply(P, [px, py]), via_mat, atol=1e-9)
    back = g.matrix_to_pose(mats)
    np.testing.assert_allclose(back[:, :2], P[:, :2], atol=1e-12)
    np.testing.assert_allclose(g.wrap_angle(back[:, 2] - P[:, 2]), 0, atol=1e-12)


@given(st.tuples(coord, coord, angle), st.tuples(coord, coord, angle), coord, coord)
def test_pose_composition_matches_matrix_product(a, b, px, py):
    ab = g.poses_compose(np.array(a), np.array(b))
    m = g.compose(g.pose_matrix(a), g.pose_matrix(b))
    np.testing.assert_allclose(g.poses_apply(ab, [px, py]), g.apply(m, [px, py]), atol=1e-8)
    inv = g.poses_invert(np.array(a))
    ident = g.poses_compose(np.array(a), inv)
    np.testing.assert_allclose(ident[:2], 0, atol=1e-9)


def test_notes_eq3_rotation_about_a_point():
    # T1^-1 R T1 rotates about the point T1 moves to the origin
    c = np.array([2.0, 1.0])
    m = g.compose(g.invert(g.translation(*-c)), g.rotation(np.pi / 2), g.translation(*-c))
    np.testing.assert_allclose(g.apply(m, c), c, atol=1e-15)
    np.testing.assert_allclose(g.apply(m, c + [1, 0]), c + [0, 1], atol=1e-15)


@given(coord, coord, radius, coord, coord, radius, st.sampled_from([1.0, -1.0]))
def test_circle_circle_points_lie_on_both_circles(x1, y1, r1, x2, y2, r2, br):
    p, ok = g.circle_circle([x1, y1], r1, [x2, y2], r2, br)
    d = np.hypot(x2 - x1, y2 - y1)
    if d > 1e-9 * max(r1, r2) and abs(r1 - r2) * (1 + 1e-9) < d < (r1 + r2) * (1 - 1e-9):
        assert ok
    if d > (r1 + r2) * (1 + 1e-6) or d < abs(r1 - r2) * (1 - 1e-6):
        assert not ok
    assert np.all(np.isfinite(p))
    if ok:
        scale = max(r1, r2, d, 1.0)
        tol = 1e-6 * scale  # near-tangent roots lose half the digits: sqrt of round-off
        assert abs(np.hypot(*(p - [x1, y1])) - r1) <= tol
        assert abs(np.hypot(*(p - [x2, y2])) - r2) <= tol
        side = (x2 - x1) * (p[1] - y1) - (y2 - y1) * (p[0] - x1)
        assert side * br >= -1e-6 * scale * scale


def test_circle_circle_is_accurate_away_from_tangency():
    rng = np.random.default_rng(0)
    c1 = rng.uniform(-5, 5, (1000, 2))
    c2 = rng.uniform(-5, 5, (1000, 2))
    d = np.hypot(*(c2 - c1).T)
    r1 = d * rng.uniform(0.3, 0.9, 1000)
    r2 = d * rng.uniform(0.3, 0.9, 1000)
    far = np.abs(r1 + r2 - d) > 0.01 * d
    p, ok = g.circle_circle(c1, r1, c2, r2, -1.0)
    assert np.array_equal(ok[far], (r1 + r2 > d)[far])
    err1 = np.abs(np.hypot(*(p - c1).T) - r1)[ok]
    err2 = np.abs(np.hypot(*(p - c2).T) - r2)[ok]
    assert max(err1.max(), err2.max()) < 1e-12 * 10


def test_circle_circle_tangent_and_concentric():
    p, ok = g.circle_circle([0, 0], 1.0, [2, 0], 1.0)
    assert ok and np.allclose(p, [1, 0])
    # tangent within round-off on the failing side still counts, finite
    p, ok = g.circle_circle([0, 0], 1.0, [2 + 1e-15, 0], 1.0)
    assert ok and np.allclose(p, [1, 0], atol=1e-7)
    p, ok = g.circle_circle([1, 1], 1.0, [1, 1], 1.0)
    assert not ok and np.all(np.isfinite(p))


def test_circle_circle_no_division_by_coordinate_difference():
    # vertical and horizontal centre lines both work (no dx or dy in a denominator)
    p, ok = g.circle_circle([0, 0], 5.0, [0, 6], 5.0, 1.0)
    assert ok and np.allclose(p, [-4, 3])
    p, ok = g.circle_circle([0, 0], 5.0, [6, 0], 5.0, 1.0)
    assert ok and np.allclose(p, [3, 4])


@given(coord, coord, angle, coord, coord, radius, st.sampled_from([1.0, -1.0]))
def test_line_circle(px, py, ang, cx, cy, r, br):
    u = np.array([np.cos(ang), np.sin(ang)])
    p, ok, s = g.line_circle([px, py], 3.0 * u, [cx, cy], r, br)
    e = abs(u[0] * (cy - py) - u[1] * (cx - px))
    assume(abs(e - r) > 1e-6 * max(r, 1))
    assert ok == (e < r)
    assert np.all(np.isfinite(p))
    if ok:
        scale = max(r, np.hypot(cx - px, cy - py), 1.0)
        assert abs(np.hypot(p[0] - cx, p[1] - cy) - r) < 1e-9 * scale
        # on the line
        assert abs(u[0] * (p[1] - py) - u[1] * (p[0] - px)) < 1e-9 * scale
        _other, _, s2 = g.line_circle([px, py], u, [cx, cy], r, -br)
        assert (s - s2) * br >= -1e-12


def test_line_circle_zero_direction_invalid():
    p, ok, _ = g.line_circle([0, 0], [0, 0], [0, 0], 1.0)
    assert not ok and np.all(np.isfinite(p))


def test_wrap_angle_range():
    a = np.linspace(-20, 20, 1001)
    w = g.wrap_angle(a)
    assert np.all(w > -np.pi) and np.all(w <= np.pi)
    np.testing.assert_allclose(np.cos(w), np.cos(a), atol=1e-12)


def test_nearly_concentric_circles_with_nearly_equal_radii_meet_where_both_circles_are() -> None:
    """Centres 5e-17 apart, radii one unit in the last place apart: the circles do meet (a 0.12-high chord
    0.11 off the centres); as squares the radii cancelled and the point was 0.02 off both circles."""
    from planar.core.geometry import circle_circle

    c1 = np.array([0.2, 0.0])
    c2 = np.array([0.2 * np.cos(2 * np.pi), 0.2 * np.sin(2 * np.pi)])  # 4.9e-17 from c1
    r1, r2 = 0.2, 0.20000000000000004
    for branch in (1.0, -1.0):
        p, ok = circle_circle(c1, r1, c2, r2, branch)
        assert bool(ok)
        assert abs(np.hypot(*(p - c1)) - r1) < 1e-12 and abs(np.hypot(*(p - c2)) - r2) < 1e-12
