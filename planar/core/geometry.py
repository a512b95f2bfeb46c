"""Homogeneous 2D transforms and robust, vectorised intersections.

Conventions (see ARCHITECTURE.md): right-handed frame, x right, y up, angles in
radians, counter-clockwise positive.  Samples run along axis 0: a point cloud is
``(N, 2)``, a pose track ``(N, 3)`` holding ``x, y, angle``.

Transforms follow section 1 of the course notes (seed 004): a point ``p`` is
augmented to ``[px, py, 1]`` and multiplied by 3x3 matrices; composition reads
right to left.  Batches of transforms are ``(N, 3, 3)`` arrays.

Intersections never divide by a coordinate difference and never return an
unexplained NaN: every function returns the points *and* a boolean ``valid``
mask.  Invalid samples hold the nearest real configuration (the square root of
a negative discriminant is clamped to zero), so downstream arithmetic stays
finite, and callers report the mask.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "CONCENTRIC",
    "TANGENCY_RTOL",
    "apply",
    "circle_circle",
    "compose",
    "invert",
    "line_circle",
    "matrix_to_pose",
    "perp",
    "pose_matrix",
    "poses_apply",
    "poses_compose",
    "poses_invert",
    "rotation",
    "translation",
    "wrap_angle",
]

#: centres closer than sqrt(CONCENTRIC) of the radii's sum are concentric (circle_circle and its fast kernel)
CONCENTRIC = 1e-200

Array = NDArray[np.float64]

#: Relative tolerance under which a negative discriminant counts as tangency
#: (valid, with the double root).  It is relative to the squared size of the
#: problem, so it scales with the mechanism.
TANGENCY_RTOL = 1e-12


# --------------------------------------------------------------------------
# Homogeneous transforms
# --------------------------------------------------------------------------


def translation(x: ArrayLike, y: ArrayLike) -> Array:
    """Translation matrix by ``(x, y)``; ``(3, 3)`` or ``(N, 3, 3)`` for arrays."""
    x, y = np.broadcast_arrays(np.asarray(x, float), np.asarray(y, float))
    m = np.zeros(x.shape + (3, 3))
    m[..., 0, 0] = m[..., 1, 1] = m[..., 2, 2] = 1.0
    m[..., 0, 2] = x
    m[..., 1, 2] = y
    return m


def rotation(theta: ArrayLike) -> Array:
    """Rotation matrix by ``theta`` radians counter-clockwise about the origin."""
    t = np.asarray(theta, float)
    c, s = np.cos(t), np.sin(t)
    m = np.zeros(t.shape + (3, 3))
    m[..., 0, 0] = c
    m[..., 0, 1] = -s
    m[..., 1, 0] = s
    m[..., 1, 1] = c
    m[..., 2, 2] = 1.0
    return m


def pose_matrix(pose: ArrayLike) -> Array:
    """Matrix of a pose ``(x, y, angle)``: rotate by angle, then translate.

    ``pose`` may be ``(3,)`` or ``(N, 3)``; maps a part's own frame to the world.
    """
    p = np.asarray(pose, float)
    return compose(translation(p[..., 0], p[..., 1]), rotation(p[..., 2]))


def compose(*mats: ArrayLike) -> Array:
    """Product ``M1 @ M2 @ ...`` (applied right to left), broadcasting batches."""
    out = np.asarray(mats[0], float)
    for m in mats[1:]:
        out = np.matmul(out, np.asarray(m, float))
    return out


def invert(m: ArrayLike) -> Array:
    """Inverse of rigid transforms (rotation + translation), exactly: ``[R^T, -R^T t]``."""
    m = np.asarray(m, float)
    out = np.zeros_like(m)
    rt = np.swapaxes(m[..., :2, :2], -1, -2)
    out[..., :2, :2] = rt
    out[..., :2, 2] = -np.einsum("...ij,...j->...i", rt, m[..., :2, 2])
    out[..., 2, 2] = 1.0
    return out


def apply(m: ArrayLike, points: ArrayLike) -> Array:
    """Apply transform(s) to points.

    ``m`` ``(3, 3)`` with points ``(..., 2)`` gives ``(..., 2)``.  A batch
    ``(N, 3, 3)`` with points ``(M, 2)`` gives ``(N, M, 2)``; with points
    ``(N, 2)`` paired sample by sample use :func:`poses_apply`.
    """
    m = np.asarray(m, float)
    p = np.asarray(points, float)
    r = m[..., :2, :2]
    t = m[..., :2, 2]
    if m.ndim == 2:
        return p @ r.T + t
    # batch of transforms applied to one shared cloud
    return np.einsum("nij,mj->nmi", r, p) + t[:, None, :]


def matrix_to_pose(m: ArrayLike) -> Array:
    """Pose ``(x, y, angle)`` of a rigid transform matrix (batched)."""
    m = np.asarray(m, float)
    return np.stack([m[..., 0, 2], m[..., 1, 2], np.arctan2(m[..., 1, 0], m[..., 0, 0])], axis=-1)


def poses_compose(a: ArrayLike, b: ArrayLike) -> Array:
    """Pose of ``a ∘ b`` (b expressed in a's frame), without building matrices."""
    a = np.asarray(a, float)
    b = np.asarray(b, float)
    c, s = np.cos(a[..., 2]), np.sin(a[..., 2])
    x = a[..., 0] + c * b[..., 0] - s * b[..., 1]
    y = a[..., 1] + s * b[..., 0] + c * b[..., 1]
    return np.stack(np.broadcast_arrays(x, y, a[..., 2] + b[..., 2]), axis=-1)


def poses_invert(a: ArrayLike) -> Array:
    """Inverse pose: the world frame seen from the part."""
    a = np.asarray(a, float)
    c, s = np.cos(a[..., 2]), np.sin(a[..., 2])
    x = -(c * a[..., 0] + s * a[..., 1])
    y = -(-s * a[..., 0] + c * a[..., 1])
    return np.stack([x, y, -a[..., 2]], axis=-1)


def poses_apply(poses: ArrayLike, points: ArrayLike) -> Array:
    """World coordinates of part-frame points.

    ``poses`` ``(N, 3)`` with ``points`` ``(2,)`` gives ``(N, 2)``; with
    ``(M, 2)`` gives ``(N, M, 2)``; with ``(N, 2)`` pairs sample by sample only
    if you pass ``points[:, None, :]`` and squeeze — use the first two forms.
    """
    q = np.asarray(poses, float)
    p = np.asarray(points, float)
    c, s = np.cos(q[..., 2]), np.sin(q[..., 2])
    if p.ndim == 1:
        return np.stack([q[..., 0] + c * p[0] - s * p[1], q[..., 1] + s * p[0] + c * p[1]], axis=-1)
    c = c[..., None]
    s = s[..., None]
    x = q[..., 0, None] + c * p[:, 0] - s * p[:, 1]
    y = q[..., 1, None] + s * p[:, 0] + c * p[:, 1]
    return np.stack([x, y], axis=-1)


def wrap_angle(a: ArrayLike) -> Array:
    """Wrap angles to ``(-pi, pi]``."""
    a = np.asarray(a, float)
    w = np.remainder(a + np.pi, 2.0 * np.pi) - np.pi
    return np.where(w == -np.pi, np.pi, w)


def perp(v: ArrayLike) -> Array:
    """Vector rotated +90 degrees: ``(x, y) -> (-y, x)``."""
    v = np.asarray(v, float)
    return np.stack([-v[..., 1], v[..., 0]], axis=-1)


# --------------------------------------------------------------------------
# Intersections
# --------------------------------------------------------------------------


def circle_circle(
    c1: ArrayLike,
    r1: ArrayLike,
    c2: ArrayLike,
    r2: ArrayLike,
    branch: ArrayLike = 1.0,
    rtol: float = TANGENCY_RTOL,
) -> tuple[Array, NDArray[np.bool_]]:
    """Intersection of circle ``(c1, r1)`` with circle ``(c2, r2)``.

    Returns ``(points, valid)``.  ``branch = +1`` picks the point to the *left*
    of the directed line ``c1 -> c2`` (counter-clockwise side), ``-1`` the right.

    Numerics: with ``d = |c2 - c1|`` the half-chord satisfies
    ``4 d^2 h^2 = ((r1 + r2)^2 - d^2) (d^2 - (r1 - r2)^2)``, a product of two
    differences each formed without cancellation between large terms; this is
    the stable form of Heron's formula.  Tangency within ``rtol`` of the
    squared scale is valid with the double root.  Concentric centres
    (``d == 0``) are invalid.
    """
    c1 = np.asarray(c1, float)
    c2 = np.asarray(c2, float)
    r1 = np.asarray(r1, float)
    r2 = np.asarray(r2, float)
    dx = c2[..., 0] - c1[..., 0]
    dy = c2[..., 1] - c1[..., 1]
    # scale-free: lengths divided by the power of two nearest r1 + r2, an exact scaling (the same bits
    # as unscaled where nothing overflows), so the squares below hold from 1e-300 to 1e300
    _, e = np.frexp(np.abs(r1) + np.abs(r2))
    k = np.ldexp(1.0, -e)
    ux, uy, q1, q2 = dx * k, dy * k, r1 * k, r2 * k
    d2 = ux * ux + uy * uy
    sum_ = q1 + q2
    dif = q1 - q2
    prod = (sum_ * sum_ - d2) * (d2 - dif * dif)  # = 4 d^2 h^2 (scaled)
    scale = np.maximum(sum_ * sum_, d2)
    # concentric circles (centres within 1e-100 of the radii's sum): no (or infinitely many) intersections;
    # closer than that, a / d^2 overflows and the (invalid) point would not be finite
    ok_d = d2 > CONCENTRIC * sum_ * sum_
    valid = (prod >= -rtol * scale * scale) & ok_d
    safe_d2 = np.where(ok_d, d2, 1.0)
    # fraction of d along c1->c2; r1^2 - r2^2 as (r1 - r2)(r1 + r2): nearly equal radii round to their exact
    # difference (as squares they cancel, and with nearly concentric centres the point was garbage; hypothesis)
    a = 0.5 * (d2 + dif * sum_) / safe_d2
    h = 0.5 * np.sqrt(np.maximum(prod, 0.0)) / safe_d2  # half-chord / d
    hb = h * np.asarray(branch, float)
    x = c1[..., 0] + a * dx - hb * dy
    y = c1[..., 1] + a * dy + hb * dx
    return np.stack([x, y], axis=-1), np.asarray(valid)


def line_circle(
    p: ArrayLike,
    u: ArrayLike,
    c: ArrayLike,
    r: ArrayLike,
    branch: ArrayLike = 1.0,
    rtol: float = TANGENCY_RTOL,
) -> tuple[Array, NDArray[np.bool_], Array]:
    """Intersection of the line ``p + s u`` with the circle ``(c, r)``.

    ``u`` need not be unit length (it is normalised; a zero ``u`` is invalid).
    ``branch = +1`` picks the root with the larger ``s`` (further along ``u``),
    ``-1`` the smaller.  Returns ``(points, valid, s)`` with ``s`` the signed
    distance along the unit direction from ``p``.

    Numerics: with ``e`` the signed distance of ``c`` from the line, the
    half-chord is ``sqrt((r - e)(r + e))``; no quadratic formula with
    cancellation and no division by a coordinate difference.
    """
    p = np.asarray(p, float)
    u = np.asarray(u, float)
    c = np.asarray(c, float)
    r = np.asarray(r, float)
    un = np.hypot(u[..., 0], u[..., 1])
    ok_u = un > 0
    un = np.where(ok_u, un, 1.0)
    ux = u[..., 0] / un
    uy = u[..., 1] / un
    wx = c[..., 0] - p[..., 0]
    wy = c[..., 1] - p[..., 1]
    s0 = wx * ux + wy * uy  # foot of the perpendicular from c
    e = ux * wy - uy * wx  # signed distance of c from the line (left positive)
    # scale-free: r and e times the power of two nearest |r| (exact), so the squares hold from 1e-300 to 1e300
    _, ex = np.frexp(np.abs(r))
    k = np.ldexp(1.0, -ex)
    rk, ek = r * k, e * k
    h2 = (rk - ek) * (rk + ek)
    scale = np.maximum(rk * rk, ek * ek)
    valid = (h2 >= -rtol * np.maximum(scale, np.finfo(float).tiny)) & ok_u
    s = s0 + np.asarray(branch, float) * (np.sqrt(np.maximum(h2, 0.0)) / k)
    pts = np.stack([p[..., 0] + s * ux, p[..., 1] + s * uy], axis=-1)
    return pts, np.asarray(valid), s
