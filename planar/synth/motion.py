"""Motion generation by Burmester theory: a four-bar whose coupler takes 3, 4 or 5 given poses.

A pose is ``(x, y, angle)`` of the guided body (radians): a body point ``z``
(body frame) is at ``W_j(z) = d_j + R_j z`` in pose ``j``.  A dyad (moving
pivot ``z``, fixed pivot ``c``) keeps ``|W_j(z) - c|`` equal for every pose;
subtracting pose 1's equation removes ``|z|^2`` and leaves, for ``j >= 2``,
the bilinear ``row_j(z) . (c, 1) = 0`` with
``row_j(z) = (-2 (d_j - d_1 + (R_j - R_1) z), |d_j|^2 - |d_1|^2 + 2 (R_j^T d_j - R_1^T d_1) . z)``.

* 3 poses: any moving pivot; its fixed pivot is the centre of its three
  positions (a grid of moving pivots is tried).
* 4 poses: ``det [row_2; row_3; row_4](z) = 0``, a cubic in ``z``: the
  circle-point curve, sampled along rays (each ray's cubic interpolated at
  4 nodes and its roots taken as eigenvalues of companion matrices, all rays
  at once); each circle point's fixed pivot (least squares of the 3 rows)
  traces the centre-point curve.
* 5 poses: the Burmester points, where the circle-point curves of poses
  1-4 and 1, 2, 3, 5 meet (0, 2 or 4 real points), by root finding started
  at the grid minima of both determinants; the grid widens (4, 16, 64 times
  the poses' extent) while fewer than 2 or an odd number are found.

Two dyads make a four-bar: the first is the crank.  Pairs are chosen with the
body at one circuit in every pose (no branch defect), the poses met in the
given order by the crank moving one way (no order defect, see
:func:`crank_order`: exact assembly arcs of the crank, so no dead zone between
poses), the crank turning fully if any pair allows it, link ratio within
``max_ratio``, then the smallest ratio; :class:`NoMotionDesign` when no pair
qualifies.  The result is checked by solving the four-bar with planar's solver
at each pose's crank angle and comparing the coupler poses, and at 4096 crank
angles over the swept range (all must assemble).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from planar.errors import InputError, PlanarError
from planar.synth.designs import TOGGLE_FLOOR_DEG, Checked, PlacedFourBar

__all__ = ["MotionDesign", "burmester", "burmester_points", "circle_point_curve", "dyad_rows"]

Array = NDArray[np.float64]


def _rot(a: Array) -> Array:
    c, s = np.cos(a), np.sin(a)
    return np.stack([np.stack([c, -s], -1), np.stack([s, c], -1)], -2)  # (..., 2, 2)


def dyad_rows(poses: Array, z: Array) -> Array:
    """``row_j(z)`` for ``j = 2..n``: ``(K, n-1, 3)`` for body points ``z`` ``(K, 2)``."""
    d = poses[:, :2]
    R = _rot(poses[:, 2])
    dz = d[1:] - d[0]  # (n-1, 2)
    dR = R[1:] - R[0]  # (n-1, 2, 2)
    g = np.einsum("jki,jk->ji", R[1:], d[1:]) - R[0].T @ d[0]  # R_j^T d_j - R_1^T d_1
    const = (d[1:] ** 2).sum(1) - (d[0] ** 2).sum()
    lin = -2.0 * (dz[None] + np.einsum("jab,kb->kja", dR, z))  # (K, n-1, 2)
    last = const[None] + 2.0 * np.einsum("ja,ka->kj", g, z)
    return np.concatenate([lin, last[..., None]], -1)


def fixed_pivots(poses: Array, z: Array) -> tuple[Array, Array]:
    """Least-squares fixed pivot ``c`` for each moving pivot ``z`` and the largest radius mismatch."""
    rows = dyad_rows(poses, z)
    A, b = rows[..., :2], -rows[..., 2]
    AtA = np.einsum("kja,kjb->kab", A, A)
    Atb = np.einsum("kja,kj->ka", A, b)
    det = AtA[:, 0, 0] * AtA[:, 1, 1] - AtA[:, 0, 1] * AtA[:, 1, 0]
    det = np.where(np.abs(det) < 1e-300, np.nan, det)
    cx = (Atb[:, 0] * AtA[:, 1, 1] - Atb[:, 1] * AtA[:, 0, 1]) / det
    cy = (AtA[:, 0, 0] * Atb[:, 1] - AtA[:, 1, 0] * Atb[:, 0]) / det
    c = np.column_stack([cx, cy])
    W = poses[None, :, :2] + np.einsum("jab,kb->kja", _rot(poses[:, 2]), z)
    r = np.hypot(*(W - c[:, None, :]).transpose(2, 0, 1))
    return c, np.ptp(r, axis=1)


def _scale(poses: Array) -> float:
    return float(max(np.hypot(*np.ptp(poses[:, :2], axis=0)), 1e-3))


def _det3(rows: Array) -> Array:
    return np.linalg.det(rows)


def circle_point_curve(poses: Array, rays: int = 720, reach: float = 4.0) -> tuple[Array, Array]:
    """Points ``(K, 2)`` of the circle-point curve (body frame) of 4 poses and their centre points ``(K, 2)``.

    Rays from the centroid of the body's positions (in the body frame at pose
    1) at ``rays`` angles; each ray's determinant is a cubic in the distance
    ``t`` along it, interpolated exactly at 4 nodes; real roots with ``|t| <=
    reach L`` (``L`` the extent of the poses) are kept.
    """
    if len(poses) != 4:
        raise InputError("poses", len(poses), "4 poses for a circle-point curve")
    L = _scale(poses)
    z0 = np.zeros(2)
    psi = np.linspace(0.0, np.pi, rays, endpoint=False)
    u = np.column_stack([np.cos(psi), np.sin(psi)])
    nodes = np.array([-1.5, -0.5, 0.5, 1.5]) * L
    vals = np.stack([_det3(dyad_rows(poses, z0 + t * u)) for t in nodes], 1)  # (rays, 4)
    V = np.vander(nodes, 4)  # t^3 t^2 t 1
    coef = np.linalg.solve(V, vals.T).T  # (rays, 4), highest first
    lead = coef[:, 0]
    scale = np.abs(coef).max(1)
    pts: list[Array] = []
    cubic = np.abs(lead) > 1e-12 * scale
    if cubic.any():
        cc = coef[cubic] / lead[cubic, None]
        comp = np.zeros((cc.shape[0], 3, 3))
        comp[:, 0, :] = -cc[:, 1:]
        comp[:, 1, 0] = 1.0
        comp[:, 2, 1] = 1.0
        roots = np.linalg.eigvals(comp)
        real = np.abs(roots.imag) <= 1e-9 * np.maximum(1.0, np.abs(roots.real))
        uu = u[cubic]
        for k in range(3):
            keep = real[:, k] & (np.abs(roots[:, k].real) <= reach * L)
            pts.append(z0 + roots[keep, k].real[:, None] * uu[keep])
    z = np.concatenate(pts) if pts else np.zeros((0, 2))
    c, _ = fixed_pivots(poses, z)
    good = np.isfinite(c).all(1) & (np.hypot(*(c - poses[:, :2].mean(0)).T) <= 4 * reach * L)
    return z[good], c[good]


def burmester_points(poses: Array, grid: int = 60, reach: float = 4.0) -> tuple[Array, Array]:
    """Burmester points of 5 poses: moving pivots ``(K, 2)`` and fixed pivots ``(K, 2)``, ``K`` in 0..4."""
    from scipy.optimize import root

    if len(poses) != 5:
        raise InputError("poses", len(poses), "5 poses for Burmester points")
    L = _scale(poses)
    p4, p5 = poses[[0, 1, 2, 3]], poses[[0, 1, 2, 4]]
    g = np.linspace(-reach * L, reach * L, grid)
    Z = np.stack(np.meshgrid(g, g), -1).reshape(-1, 2)
    f4, f5 = _det3(dyad_rows(p4, Z)), _det3(dyad_rows(p5, Z))
    s4, s5 = np.abs(f4).max() + 1e-300, np.abs(f5).max() + 1e-300
    f = (f4 / s4) ** 2 + (f5 / s5) ** 2
    starts = Z[np.argsort(f)[:40]]

    def eqs(z: Array) -> Array:
        zz = z[None, :]
        return np.array([_det3(dyad_rows(p4, zz))[0] / s4, _det3(dyad_rows(p5, zz))[0] / s5])

    found: list[Array] = []
    for z0 in starts:
        r = root(eqs, z0, method="hybr")
        if not r.success or np.abs(eqs(r.x)).max() > 1e-10:
            continue
        if np.hypot(*r.x) > 2 * reach * L:
            continue
        if all(np.hypot(*(r.x - q)) > 1e-6 * L for q in found):
            found.append(r.x)
    z = np.array(found).reshape(-1, 2)
    c, mismatch = fixed_pivots(poses, z)
    ok = np.isfinite(c).all(1) & (mismatch <= 1e-6 * L)
    return z[ok], c[ok]


@dataclass
class MotionDesign(Checked, PlacedFourBar):
    ground: float
    crank: float
    coupler: float
    rocker: float
    coupler_point: tuple[float, float]
    angle_offset: float  # body angle - coupler angle
    circuit: str
    placement: tuple[float, float, float]
    theta: Array  # crank angle at each pose
    poses: Array
    dyads: Array  # (2, 4): moving pivot (body frame), fixed pivot (world)
    grashof: str
    candidates: int
    crank_range: tuple[float, float] | None = None  # swept crank angles (rad, unwrapped) of a rocking crank
    in_order: bool = True  # the crank meets the poses in the given order
    checks: dict[str, Any] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        return {
            **self.fourbar_dict(),
            "grashof": self.grashof,
            "dyads": self.dyads.tolist(),
            "candidate_dyads": self.candidates,
            "crank_range": None if self.crank_range is None else list(self.crank_range),
            "ok": self.ok,
            "checks": self.checks,
        }


class NoMotionDesign(PlanarError):
    """No candidate four-bar meets the constraints exactly (the CLI exits 3).

    ``nearest``: for 4 or 5 poses, the four-bar nearest to meeting them in order on one circuit
    (:func:`nearest_motion`; its checks fail and give its errors), or None (the CLI then writes nothing)."""

    nearest: MotionDesign | None = None


def crank_order(
    theta: Array, d: Array, a: Array, b: Array, r: Array
) -> tuple[NDArray[np.bool_], NDArray[np.bool_], Array, Array]:
    """Whether the crank reaches the poses in order, and the crank's swept range.

    ``theta`` ``(P, n)``: crank angle (rad, from the ground line O2-O4) at each
    pose; ``d, a, b, r`` ``(P,)``: ground, crank, coupler, rocker.  The crank
    assembles where ``|b - r| <= |B - O4| <= b + r``, i.e. ``cmin <= cos theta
    <= cmax`` (exact): the whole turn, or one or two arcs symmetric about the
    ground line.  A crank that turns fully must meet the poses in their order
    within one turn, forward or backward (cyclically); a crank confined to an
    arc rocks, so all poses must lie on the same arc, in monotonic order along
    it, and it sweeps only that arc (no toggle or dead zone between poses).
    Returns ``(in_order, full, lo, hi)``: ``lo, hi`` the swept crank range
    (unwrapped, rad; ``lo = hi = nan`` for a full turn).
    """
    two = 2.0 * np.pi
    with np.errstate(divide="ignore", invalid="ignore"):
        cmin = (a**2 + d**2 - (b + r) ** 2) / (2 * a * d)
        cmax = (a**2 + d**2 - (b - r) ** 2) / (2 * a * d)
    full = (cmin <= -1.0) & (cmax >= 1.0)
    fwd = np.mod(np.diff(theta, axis=1), two)
    bwd = np.mod(-np.diff(theta, axis=1), two)
    turn_ok = ((fwd > 0).all(1) & (fwd.sum(1) < two)) | ((bwd > 0).all(1) & (bwd.sum(1) < two))
    around_pi = (cmin <= -1.0) & ~full  # one arc centred on theta = pi
    u = np.where(around_pi[:, None], np.mod(theta, two), (theta + np.pi) % two - np.pi)
    # two arcs (neither limit outside [-1, 1]): the poses must share the sign of theta
    two_arcs = (cmin > -1.0) & (cmax < 1.0)
    same = (np.sign(u) == np.sign(u[:, :1])).all(1) | ~two_arcs
    du = np.diff(u, axis=1)
    mono = (du > 0).all(1) | (du < 0).all(1)
    arc_ok = same & mono & ~full
    lo = np.where(full, np.nan, u.min(1))
    hi = np.where(full, np.nan, u.max(1))
    return np.where(full, turn_ok, arc_ok), full, lo, hi


#: the selection prefers a transmission angle farther from a toggle up to this, then the smaller link ratio
GOOD_TRANSMISSION_DEG = 30.0


def _contains(x: float, lo: Array, hi: Array) -> NDArray[np.bool_]:
    """Whether angle ``x`` (mod 2 pi) lies in each unwrapped range ``[lo, hi]`` (narrower than a turn)."""
    return np.mod(x - lo, 2 * np.pi) <= hi - lo


def transmission_margins(d: Array, a: Array, b: Array, r: Array, full: NDArray[np.bool_], lo: Array, hi: Array) -> Array:
    """Smallest distance (radians) of the transmission angle from a toggle (0 or pi) over each crank's sweep.

    ``d, a, b, r`` ``(P,)``: ground, crank, coupler, rocker; ``full``: the crank turns fully, else it sweeps
    ``[lo, hi]`` (radians from the ground line, unwrapped, as :func:`crank_order` gives).  The transmission
    angle ``mu`` depends on the crank angle ``theta`` only through the diagonal ``|B - O4|^2 = a^2 + d^2 -
    2 a d cos theta`` and is monotonic in it, so its extremes over the sweep are at the extremes of ``cos
    theta`` there (exact, no sampling)."""
    with np.errstate(invalid="ignore"):
        ends = np.stack([np.cos(np.nan_to_num(lo)), np.cos(np.nan_to_num(hi))])
        cmax = np.where(full | _contains(0.0, lo, hi), 1.0, ends.max(0))
        cmin = np.where(full | _contains(np.pi, lo, hi), -1.0, ends.min(0))
    out = np.full(len(d), np.pi / 2)
    for cth in (cmin, cmax):
        diag2 = a * a + d * d - 2 * a * d * cth
        mu = np.arccos(np.clip((b * b + r * r - diag2) / np.maximum(2 * b * r, 1e-300), -1.0, 1.0))
        out = np.minimum(out, np.minimum(mu, np.pi - mu))
    return out


def _pair_table(poses: Array, z: Array, c: Array, max_ratio: float) -> dict[str, Any]:
    """Every ordered pair (crank dyad ``I``, rocker dyad ``J``) of candidate dyads as four-bars through the poses:
    ``usable`` (one circuit at every pose, links within ``max_ratio``), ``in_order``, ``full`` (the crank turns
    fully), the swept crank range ``clo, chi``, the links ``d, a, b, r`` and their ``ratio``."""
    K = len(z)
    I, J = np.meshgrid(np.arange(K), np.arange(K), indexing="ij")
    I, J = I[I != J], J[I != J]
    R = _rot(poses[:, 2])
    W = poses[None, :, :2] + np.einsum("jab,kb->kja", R, z)  # (K, n, 2)
    B, C = W[I], W[J]  # (P, n, 2)
    O2, O4 = c[I][:, None, :], c[J][:, None, :]
    a = np.hypot(*(B[:, 0] - O2[:, 0]).T)
    r = np.hypot(*(C[:, 0] - O4[:, 0]).T)
    b = np.hypot(*(z[I] - z[J]).T)
    d = np.hypot(*(O4[:, 0] - O2[:, 0]).T)
    Lk = np.stack([d, a, b, r], 1)
    lo, hi = Lk.min(1), Lk.max(1)
    L = _scale(poses)
    e1, e2 = O4 - B, C - B
    side = np.sign(e1[..., 0] * e2[..., 1] - e1[..., 1] * e2[..., 0])  # (P, n)
    one_circuit = (np.abs(side.sum(1)) == side.shape[1]) & (side[:, 0] != 0)
    g = O4[:, 0] - O2[:, 0]
    theta = (
        np.arctan2(B[..., 1] - O2[..., 1], B[..., 0] - O2[..., 0]) - np.arctan2(g[:, 1], g[:, 0])[:, None]
    )  # crank angle from the ground line
    in_order, full, clo, chi = crank_order(theta, d, a, b, r)
    ratio = hi / np.maximum(lo, 1e-300)
    usable = one_circuit & (lo > 1e-3 * L) & (ratio <= max_ratio)
    return {
        "I": I, "J": J, "usable": usable, "in_order": in_order, "full": full, "clo": clo, "chi": chi,
        "d": d, "a": a, "b": b, "r": r, "ratio": ratio,
    }  # fmt: skip


def _choose(poses: Array, z: Array, c: Array, max_ratio: float, min_transmission: float = 0.0) -> tuple[int, int, bool]:
    """The best ordered pair (crank dyad, rocker dyad) among candidate dyads (see the module)."""
    K = len(z)
    if K < 2:
        raise NoMotionDesign(f"only {K} dyad found for these {len(poses)} poses: a four-bar needs two")
    t = _pair_table(poses, z, c, max_ratio)
    I, J, usable, full, ratio = t["I"], t["J"], t["usable"], t["full"], t["ratio"]
    if not usable.any():
        raise NoMotionDesign(
            f"none of the {len(I)} pairs of the {K} dyads found takes the body through all "
            f"{len(poses)} poses on one circuit with links within the ratio {max_ratio:g} "
            "(a larger --max-ratio, or other poses)"
        )
    if not (usable & t["in_order"]).any():
        raise NoMotionDesign(
            f"order defect: each of the {int(usable.sum())} four-bars that reach all {len(poses)} "
            "poses on one circuit meets them out of the given order (or with a dead zone "
            "between them) as the crank moves in one direction (other poses, or their order)"
        )
    usable = usable & t["in_order"]
    margin = transmission_margins(t["d"], t["a"], t["b"], t["r"], full, t["clo"], t["chi"])
    keeps = usable & (margin >= max(min_transmission, np.radians(TOGGLE_FLOOR_DEG)) - 1e-9)
    if not keeps.any():  # none keeps the transmission limit: the nearest, written and failing its check
        k = int(np.flatnonzero(usable)[np.argmax(margin[usable])])
        return int(I[k]), int(J[k]), bool(full[k])
    pick = keeps & full if (keeps & full).any() else keeps
    idx = np.flatnonzero(pick)
    good = np.minimum(margin[idx], np.radians(GOOD_TRANSMISSION_DEG))
    k = int(idx[np.lexsort((ratio[idx], -good))[0]])  # farthest from a toggle up to the good angle, then the ratio
    return int(I[k]), int(J[k]), bool(full[k])


def _burmester(poses: Array, max_ratio: float, grid: int, min_transmission: float) -> MotionDesign:
    """:func:`burmester` without the nearest design (the arguments checked)."""
    L = _scale(poses)
    if len(poses) == 3:
        g = np.linspace(-2 * L, 2 * L, grid)
        # moving pivots on a grid in the body frame, centred on the body's positions seen from pose 1
        z = np.stack(np.meshgrid(g, g), -1).reshape(-1, 2)
        centre = _rot(-poses[0, 2]) @ (poses[:, :2].mean(0) - poses[0, :2])
        z = z + centre
        c, _ = fixed_pivots(poses, z)
    elif len(poses) == 4:
        z, c = circle_point_curve(poses)
        if len(z) > 240:
            idx = np.linspace(0, len(z) - 1, 240).round().astype(int)
            z, c = z[idx], c[idx]
    else:
        # real Burmester points come in pairs: widen the search while fewer than 2 or an odd number are found
        for reach, grid in ((4.0, 60), (16.0, 120), (64.0, 160)):
            z, c = burmester_points(poses, grid=grid, reach=reach)
            if len(z) >= 2 and len(z) % 2 == 0:
                break
        if len(z) < 2:
            raise NoMotionDesign(
                f"these 5 poses have {len(z)} Burmester points within 64 times their extent (2 or "
                "4 are needed): no four-bar takes the body through all five (drop a pose, or move "
                "one)"
            )
    ok = np.isfinite(c).all(1)
    z, c = z[ok], c[ok]
    i, j, _ = _choose(poses, z, c, max_ratio, min_transmission)
    return _design(poses, z[i], c[i], z[j], c[j], len(z), min_transmission)


def burmester(poses: Array, max_ratio: float = 10.0, grid: int = 24, min_transmission: float = 0.0) -> MotionDesign:
    """A four-bar guiding a body through 3, 4 or 5 ``poses`` ``(n, 3)`` (see the module).

    ``min_transmission`` (radians, default 0) is the least distance of the transmission
    angle from 0 and pi (a toggle) over the crank's sweep that the design's check
    ``ok_transmission`` accepts (:func:`check_motion`).  Raises :class:`NoMotionDesign` when no four-bar
    meets the poses exactly in order on one circuit; for 4 or 5 poses its ``nearest`` is the four-bar nearest
    to it (:func:`nearest_motion`).
    """
    from planar.core.fields import check_finite, check_number

    poses = check_finite("poses", poses)
    if poses.ndim != 2 or poses.shape[1] != 3 or not 3 <= len(poses) <= 5:
        raise InputError("poses", poses.shape, "3, 4 or 5 poses (x, y, angle)")
    from planar.synth.targets import normalisation

    normalisation(poses[:, :2], "poses")  # positions within what the solvers square and multiply (SIZE_RANGE)
    if not 1.0 <= check_number("max_ratio", max_ratio) <= 1e6:
        raise InputError("max_ratio", max_ratio, "a longest-to-shortest link ratio from 1 to 1e6")
    if not 2 <= check_number("grid", grid, integer=True) <= 4096:
        raise InputError("grid", grid, "a whole number of grid points a side, 2 to 4096")
    if not 0.0 <= check_number("min_transmission", min_transmission) < np.pi / 2:
        raise InputError("min_transmission", min_transmission, "an angle from 0 to below pi/2 rad")
    try:
        return _burmester(poses, max_ratio, grid, min_transmission)
    except NoMotionDesign as e:
        p = poses
        if len(p) >= 4:
            e.nearest = nearest_motion(p, max_ratio, min_transmission)
        if e.nearest is not None and e.nearest.checks["ok_reaches_every_pose"]:
            # the fit found an exact four-bar the Burmester points missed (on 50 held-out 5-pose problems the
            # root finding found 1 of a pair twice; the fit reached the poses to 4e-16 both times)
            return e.nearest
        raise


def _design(
    poses: Array, zi: Array, ci: Array, zj: Array, cj: Array, candidates: int, min_transmission: float = 0.0
) -> MotionDesign:
    from planar.linkages import grashof_class

    R = _rot(poses[:, 2])
    B = poses[:, :2] + R @ zi
    C = poses[:, :2] + R @ zj
    g = cj - ci
    phi = float(np.arctan2(g[1], g[0]))
    d = float(np.hypot(*g))
    a = float(np.hypot(*(B[0] - ci)))
    b = float(np.hypot(*(zi - zj)))
    r = float(np.hypot(*(C[0] - cj)))
    e = (C[0] - B[0]) / b
    q = poses[0, :2] - B[0]
    local = (float(q @ e), float(-q[0] * e[1] + q[1] * e[0]))
    off = float(poses[0, 2] - np.arctan2(e[1], e[0]))
    e1, e2 = cj - B[0], C[0] - B[0]
    circuit = "open" if e1[0] * e2[1] - e1[1] * e2[0] > 0 else "crossed"
    theta = np.arctan2(B[:, 1] - ci[1], B[:, 0] - ci[0]) - phi
    ordered, full, lo, hi = crank_order(theta[None], *(np.array([v]) for v in (d, a, b, r)))
    if not full[0]:  # a rocking crank: its angles as crank_order unwraps them
        cmin = (a * a + d * d - (b + r) ** 2) / (2 * a * d)
        theta = theta % (2 * np.pi) if cmin <= -1.0 else (theta + np.pi) % (2 * np.pi) - np.pi
    md = MotionDesign(
        d,
        a,
        b,
        r,
        local,
        off,
        circuit,
        (float(ci[0]), float(ci[1]), phi),
        theta,
        poses,
        np.array([[*zi, *ci], [*zj, *cj]]),
        grashof_class(a, b, r, d),
        candidates,
        None if full[0] else (float(lo[0]), float(hi[0])),
        bool(ordered[0]),
    )
    check_motion(md, min_transmission=min_transmission)
    return md


def _between(theta: Array, x: float, full: bool) -> str:
    """Where crank angle ``x`` lies among the poses' crank angles ``theta`` (1-based pose numbers)."""
    two_pi = 2 * np.pi
    t = theta % two_pi if full else theta
    x = x % two_pi if full else x
    order = np.argsort(t)
    k = int(np.searchsorted(t[order], x))
    if k == 0 or k == len(t):
        if full:  # past the last pose the crank comes round to the first
            return f"between poses {int(order[-1]) + 1} and {int(order[0]) + 1}"
        return f"beyond pose {int(order[0 if k == 0 else -1]) + 1}"
    i, j = sorted((int(order[k - 1]) + 1, int(order[k]) + 1))
    return f"between poses {i} and {j}"


def check_motion(md: MotionDesign, samples: int = 4096, min_transmission: float = 0.0) -> None:
    """Solve the four-bar at each pose's crank angle with planar's solver; compare the coupler poses.

    Between poses the four-bar is solved again at ``samples`` crank angles
    over the swept range (the whole turn, or the rocking arc): every one must
    assemble on the design's circuit (no dead zone or toggle between poses),
    and the transmission angle stays at least ``min_transmission`` (radians)
    from 0 and pi there (``ok_transmission``; ``min_transmission_deg`` and
    ``min_transmission_at`` say how close it comes and where).
    """
    fb = md.fourbar()
    m = fb.solve(md.theta)
    pos = m.points["coupler_point"]
    ang = m.poses["coupler"][:, 2] + md.angle_offset
    L = _scale(md.poses)
    dp = np.hypot(*(pos - md.poses[:, :2]).T)
    da = np.abs((ang - md.poses[:, 2] + np.pi) % (2 * np.pi) - np.pi)
    lo, hi = md.crank_range if md.crank_range is not None else (0.0, 2 * np.pi)
    crank = np.linspace(lo, hi, samples)
    sweep = fb.solve(crank)
    mu = fb.transmission_angle(crank)
    margin = np.minimum(mu, np.pi - mu)
    worst = int(np.argmin(margin))
    md.checks = {
        "max_position_error": float(dp.max()) if m.valid.all() else float("inf"),
        "max_angle_error_rad": float(da.max()) if m.valid.all() else float("inf"),
        "ok_reaches_every_pose": bool(m.valid.all() and dp.max() <= 1e-6 * L and da.max() <= 1e-6),
        "ok_poses_in_order": md.in_order,
        "ok_assembles_between_poses": bool(sweep.valid.all()),
        "ok_transmission": bool(margin[worst] >= max(min_transmission, np.radians(TOGGLE_FLOOR_DEG)) - 1e-9),
        "transmission_limit_deg": float(np.degrees(max(min_transmission, np.radians(TOGGLE_FLOOR_DEG)))),
        "min_transmission_deg": float(np.degrees(margin[worst])),
        "min_transmission_at": (
            f"crank angle {np.degrees(crank[worst]):.4g} deg, {_between(md.theta, float(crank[worst]), md.crank_range is None)}"
        ),
        "sweep_samples": samples,
        "crank_turns_fully": md.crank_range is None,
    }


# --- the nearest four-bar when none meets the poses exactly ---


def coupler_poses(p: Array, circuit: float, offset: float, theta: Array) -> tuple[Array, NDArray[np.bool_]]:
    """Body poses ``(n, 3)`` (x, y, angle in rad) of the four-bar ``p`` (the kernel's 9 parameters:
    ground, crank, coupler, rocker, coupler point ``u, v``, placement ``x0, y0, phi``) at crank angles
    ``theta`` (rad from the ground line) on ``circuit`` (+1 open, -1 crossed); the body's angle is the
    coupler's (crank pin to rocker pin) plus ``offset``.  Also where the four-bar closes."""
    from planar.synth.kernel import coupler_points

    q = np.vstack([p, p, p]).astype(float)
    q[1, 4], q[1, 5] = p[2], 0.0  # the rocker pin
    q[2, 4], q[2, 5] = 0.0, 0.0  # the crank pin
    th = np.vstack([theta, theta, theta])
    x, y, ok = coupler_points(q, th, np.full(3, float(circuit)))
    ang = np.arctan2(y[1] - y[2], x[1] - x[2]) + offset
    return np.column_stack([x[0], y[0], ang]), ok[0]


def _ordered_angles(W: Array, sign: float) -> Array:
    """Crank angles ``(K, n)`` from rows ``W`` ``(K, n)`` = (the first angle, log of each step): every step of one
    sign (``sign``)."""
    return W[:, :1] + sign * np.concatenate([np.zeros((len(W), 1)), np.cumsum(np.exp(np.minimum(W[:, 1:], 3.0)), axis=1)], axis=1)


def _pose_residuals(Z: Array, poses: Array, circuit: float, L: float, sign: float, max_ratio: float) -> Array:
    """Residuals ``(K, 3 n + n + 1)`` of rows ``Z`` ``(K, 10 + n)`` (9 parameters, the body's angle offset, the
    first crank angle and the log of each step between poses; ``sign``: the crank's direction), in one kernel
    call: position errors over ``L`` and angle errors (rad) at every pose, then penalties
    (:data:`SWEEP_WEIGHT` per radian) for a step into a dead zone, steps over a turn, and the log of the link
    ratio over ``max_ratio``."""
    from planar.synth.kernel import coupler_points

    K, n = len(Z), len(poses)
    th = _ordered_angles(Z[:, 10:], sign)
    q = np.repeat(Z[:, :9], 3, axis=0)
    q[1::3, 4], q[1::3, 5] = Z[:, 2], 0.0  # the rocker pin
    q[2::3, 4], q[2::3, 5] = 0.0, 0.0  # the crank pin
    x, y, ok = coupler_points(q, np.repeat(th, 3, axis=0), np.full(3 * K, float(circuit)))
    ang = np.arctan2(y[1::3] - y[2::3], x[1::3] - x[2::3]) + Z[:, 9:10]
    good = ok[0::3]
    dx, dy = (x[0::3] - poses[:, 0]) / L, (y[0::3] - poses[:, 1]) / L
    da = (ang - poses[:, 2] + np.pi) % (2 * np.pi) - np.pi
    r = np.stack([dx, dy, da], axis=2)  # (K, n, 3)
    r[~good] = 1.0
    # the crank must assemble all the way between poses (no dead zone): cmin <= cos t <= cmax (crank_order)
    d, a, b, c4 = (np.abs(Z[:, i]) + 1e-300 for i in range(4))
    cmin = ((a * a + d * d - (b + c4) ** 2) / (2 * a * d))[:, None]
    cmax = ((a * a + d * d - (b - c4) ** 2) / (2 * a * d))[:, None]
    t0, t1 = np.minimum(th[:, :-1], th[:, 1:]), np.maximum(th[:, :-1], th[:, 1:])
    zone0 = np.where(cmax < 1.0, np.arccos(np.clip(cmax, -1.0, 1.0)) + SWEEP_MARGIN, 0.0)
    zone_pi = np.where(cmin > -1.0, np.pi - np.arccos(np.clip(cmin, -1.0, 1.0)) + SWEEP_MARGIN, 0.0)
    # how deep (rad) each step between poses goes into a dead zone: about 0 where cos t > cmax, about pi where
    # cos t < cmin (exact: the step's nearest angle to the zone's centre)
    dead = np.maximum(0.0, zone0 - _arc_distance(t0, t1, 0.0)) + np.maximum(0.0, zone_pi - _arc_distance(t0, t1, np.pi))
    over = np.maximum(0.0, th.max(1) - th.min(1) - (2 * np.pi - SWEEP_MARGIN)) if n > 1 else np.zeros(K)
    Ls = np.column_stack([d, a, b, c4])
    ratio = np.maximum(0.0, np.log(Ls.max(1) / Ls.min(1)) - np.log(max_ratio) + SWEEP_MARGIN)
    return np.concatenate([r.reshape(K, 3 * n), SWEEP_WEIGHT * dead, SWEEP_WEIGHT * np.column_stack([over, ratio])], 1)


#: the weight of a step between poses into a dead zone (per radian), and the margin (rad) kept from the zone's edge
SWEEP_WEIGHT, SWEEP_MARGIN = 10.0, 1e-4


def _arc_distance(t0: Array, t1: Array, c: float) -> Array:
    """Smallest angular distance (rad) from ``c`` to the arcs ``[t0, t1]`` (unwrapped, ``t0 <= t1``): 0 when an arc
    holds ``c`` (mod 2 pi)."""
    two = 2 * np.pi
    holds = np.floor((t1 - c) / two) >= np.ceil((t0 - c) / two)
    ends = np.minimum(np.abs((t0 - c + np.pi) % two - np.pi), np.abs((t1 - c + np.pi) % two - np.pi))
    return np.where(holds, 0.0, ends)


#: evaluations of the least squares that fits a four-bar to poses it cannot meet exactly
NEAREST_NFEV = 400


def fit_poses(poses: Array, z0: Array, circuit: float, nfev: int = NEAREST_NFEV, max_ratio: float = 10.0) -> tuple[Array, float]:
    """Least squares of the pose errors from ``z0`` (9 parameters, the body's angle offset, a crank angle per pose
    in the poses' order one way round): the crank angles stay in that order (each step between poses is kept of
    one sign), so the fit cannot slide to a four-bar that meets the poses out of order.  Returns the fitted
    vector (9 parameters, offset, crank angles) and its largest error (position over the poses' extent, or angle
    in rad, whichever is larger)."""
    from scipy.optimize import least_squares

    L = _scale(poses)
    th = np.asarray(z0[10:], float)
    fwd = np.mod(np.diff(th), 2 * np.pi)
    sign = 1.0 if fwd.sum() < 2 * np.pi * (len(th) - 1) / 2 else -1.0
    steps = fwd if sign > 0 else np.mod(-np.diff(th), 2 * np.pi)
    w0 = np.concatenate([z0[:10], [th[0]], np.log(np.maximum(steps, 1e-6))])
    args = (poses, circuit, L, sign, max_ratio)

    def fun(w: Array) -> Array:
        return _pose_residuals(w[None, :], *args)[0]

    def jac(w: Array) -> Array:
        """Forward differences, every perturbed row in one kernel call."""
        h = 1e-7 * np.maximum(1.0, np.abs(w))
        R = _pose_residuals(np.vstack([w, w + np.diag(h)]), *args)
        D = R[1:] - R[0]
        k = 3 * len(poses)
        D[:, 2:k:3] = (D[:, 2:k:3] + np.pi) % (2 * np.pi) - np.pi  # angle errors: no jump of a turn
        return (D / h[:, None]).T

    r = least_squares(fun, w0, jac=jac, method="lm", max_nfev=nfev)
    res = fun(r.x)[: 3 * len(poses)].reshape(-1, 3)
    out = np.concatenate([r.x[:10], _ordered_angles(r.x[None, 10:], sign)[0]])
    return out, float(np.max(np.maximum(np.hypot(res[:, 0], res[:, 1]), np.abs(res[:, 2]))))


def _pair_start(poses: Array, zi: Array, ci: Array, zj: Array, cj: Array) -> tuple[Array, float]:
    """The four-bar of a dyad pair at pose 1 (as :func:`_design` builds it) as a start for :func:`fit_poses`:
    9 parameters, the body's angle offset and the crank angle at each pose; and the circuit's sign."""
    R = _rot(poses[:, 2])
    B = poses[:, :2] + R @ zi
    C = poses[:, :2] + R @ zj
    g = cj - ci
    phi = float(np.arctan2(g[1], g[0]))
    b = float(np.hypot(*(zi - zj)))
    e = (C[0] - B[0]) / b
    q = poses[0, :2] - B[0]
    u, v = float(q @ e), float(-q[0] * e[1] + q[1] * e[0])
    off = float(poses[0, 2] - np.arctan2(e[1], e[0]))
    e1 = cj - B[0]
    circ = 1.0 if e1[0] * e[1] - e1[1] * e[0] > 0 else -1.0
    theta = np.arctan2(B[:, 1] - ci[1], B[:, 0] - ci[0]) - phi
    p = [float(np.hypot(*g)), float(np.hypot(*(B[0] - ci))), b, float(np.hypot(*(C[0] - cj))), u, v, *ci, phi]
    return np.array([*p, off, *theta]), circ


def _near_dyads(poses: Array) -> tuple[Array, Array, Array]:
    """Moving pivots (body frame) of dyads near meeting every pose, their least-squares fixed pivots and radius
    mismatch over all the poses (model units): the circle-point curves of every 4 of the poses, and a grid."""
    from itertools import combinations

    L = _scale(poses)
    zs = []
    for keep in combinations(range(len(poses)), 4):
        z, _ = circle_point_curve(poses[list(keep)])
        zs.append(z[np.linspace(0, len(z) - 1, min(len(z), 240)).round().astype(int)] if len(z) else z)
    g = np.linspace(-2 * L, 2 * L, 16)
    centre = _rot(-poses[0, 2]) @ (poses[:, :2].mean(0) - poses[0, :2])
    zs.append(np.stack(np.meshgrid(g, g), -1).reshape(-1, 2) + centre)
    z = np.concatenate(zs)
    c, mismatch = fixed_pivots(poses, z)
    ok = np.isfinite(c).all(1) & np.isfinite(mismatch)
    return z[ok], c[ok], mismatch[ok]


#: dyads (least radius mismatch) paired, and pairs fitted, by :func:`nearest_motion`
NEAREST_DYADS, NEAREST_STARTS = 60, 12


def nearest_motion(poses: Array, max_ratio: float = 10.0, min_transmission: float = 0.0) -> MotionDesign | None:
    """The four-bar nearest to meeting ``poses`` (4 or 5; none meets them all exactly) in order on one circuit.

    Dyads near meeting every pose (:func:`_near_dyads`: the :data:`NEAREST_DYADS` with the least radius
    mismatch) are paired; :data:`NEAREST_STARTS` pairs (those that take the body through the poses on one
    circuit in order with links within ``max_ratio`` first, least mismatch first) are fitted to the poses by least
    squares (:func:`fit_poses`), and the one with the smallest largest error still in order is kept, checked
    (``ok_reaches_every_pose`` fails; its errors are in its checks).  None when no pair qualifies."""
    z, c, mismatch = _near_dyads(poses)
    top = np.argsort(mismatch, kind="stable")[:NEAREST_DYADS]
    z, c, mismatch = z[top], c[top], mismatch[top]
    if len(z) < 2:
        return None
    t = _pair_table(poses, z, c, max_ratio)
    # pairs meeting the poses in order on one circuit first, then those on one circuit, then the rest (the fit
    # keeps the crank angles in the poses' order whatever the start's), each least mismatch first
    rank = np.lexsort((mismatch[t["I"]] + mismatch[t["J"]], ~t["usable"], ~(t["usable"] & t["in_order"])))
    good = rank[:NEAREST_STARTS]
    best: tuple[float, Array, float] | None = None
    for k in good:
        i, j = int(t["I"][k]), int(t["J"][k])
        z0, circ = _pair_start(poses, z[i], c[i], z[j], c[j])
        zf, err = fit_poses(poses, z0, circ, max_ratio=max_ratio)
        L4 = np.abs(zf[:4])
        ordered, *_ = crank_order(zf[None, 10:], *(np.array([v]) for v in L4))
        keep = ordered[0] and L4.min() > 0 and L4.max() <= max_ratio * L4.min() and np.isfinite(err)
        if keep and (best is None or err < best[0]):
            best = (err, zf, circ)
    if best is None:
        return None
    return _fitted_design(poses, best[1], best[2], min_transmission)


def _fitted_design(poses: Array, z: Array, circ: float, min_transmission: float) -> MotionDesign:
    """A MotionDesign from a fitted vector (see :func:`fit_poses`), checked by :func:`check_motion`."""
    from planar.linkages import grashof_class

    d, a, b, r = (float(abs(v)) for v in z[:4])
    u, v, x0, y0, phi, off = (float(w) for w in z[4:10])
    theta = np.asarray(z[10:], float)
    ordered, full, lo, hi = crank_order(theta[None], *(np.array([w]) for w in (d, a, b, r)))
    if not full[0]:
        cmin = (a * a + d * d - (b + r) ** 2) / (2 * a * d)
        theta = theta % (2 * np.pi) if cmin <= -1.0 else (theta + np.pi) % (2 * np.pi) - np.pi
    got, _ = coupler_poses(np.array([d, a, b, r, u, v, x0, y0, phi]), circ, off, theta[:1])
    pins, _ = coupler_points_world(np.array([d, a, b, r, u, v, x0, y0, phi]), circ, theta[:1])
    ca, sa = np.cos(got[0, 2]), np.sin(got[0, 2])
    to_body = np.array([[ca, sa], [-sa, ca]])
    O2 = np.array([x0, y0])
    O4 = O2 + d * np.array([np.cos(phi), np.sin(phi)])
    dyads = np.array([[*(to_body @ (pins[0] - got[0, :2])), *O2], [*(to_body @ (pins[1] - got[0, :2])), *O4]])
    md = MotionDesign(
        d,
        a,
        b,
        r,
        (u, v),
        off,
        "open" if circ > 0 else "crossed",
        (x0, y0, phi),
        theta,
        poses,
        dyads,
        grashof_class(a, b, r, d),
        0,
        None if full[0] else (float(lo[0]), float(hi[0])),
        bool(ordered[0]),
    )
    check_motion(md, min_transmission=min_transmission)
    return md


def coupler_points_world(p: Array, circuit: float, theta: Array) -> tuple[Array, NDArray[np.bool_]]:
    """The crank pin and the rocker pin ``(2, 2)`` (world) of the four-bar ``p`` at one crank angle ``theta[0]``."""
    from planar.synth.kernel import coupler_points

    q = np.vstack([p, p]).astype(float)
    q[0, 4], q[0, 5] = 0.0, 0.0
    q[1, 4], q[1, 5] = p[2], 0.0
    x, y, ok = coupler_points(q, np.asarray(theta[:1], float), np.full(2, float(circuit)))
    return np.column_stack([x[:, 0], y[:, 0]]), ok[:, 0]


def nearest_motion_error(poses: Array, p: Array, circuit: float, offset: float, theta: Array) -> float:
    """Largest error (as :func:`fit_poses`) of least squares started at the four-bar ``p`` with body angle
    ``offset`` and crank angles ``theta``: a reference for the nearest design (used by the benchmark)."""
    return fit_poses(poses, np.concatenate([p[:9], [offset], theta]), circuit)[1]
