"""Checking a run's poses in blocks as it goes (:class:`_PoseCheck`) and naming a failure: a blow-up, or the
mechanism taking another assembly branch at a change point (:func:`change_point`)."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
from numpy.typing import NDArray

from planar.core.geometry import poses_apply
from planar.core.model import Mechanism
from planar.physics.rebuild import _Rebuild
from planar.physics.result import SimFailure
from planar.physics.settings import (
    SimSettings,
    _driven_parts,
)

Array = NDArray[np.float64]


def _hull_points(mech: Mechanism, part: str) -> Array:
    """Points that stand for a part: its hull circle centres (so rotation errors count too)."""
    p = mech.part(part)
    return np.array([(x, y) for x, y, _ in p.hull] or [(0.0, 0.0)], float)


class _PoseCheck:
    """Deviation of simulated poses from the analytic ones, a block of samples at a time."""

    def __init__(self, mech: Mechanism, analytic: dict[str, Array], names: list[str], cogs: Array, settings: SimSettings) -> None:
        self.mech = mech
        self.names = names
        self.cogs = cogs  # (B, 2) body frame origin in the part frame
        self.pts = {n: _hull_points(mech, n) for n in names}
        self.ref = {n: poses_apply(analytic[n], self.pts[n]) for n in names}  # (N, M, 2)
        self.size = mech.size
        self.tol = settings.tolerance * self.size
        self.worst = dict.fromkeys(names, 0.0)

    def part_poses(self, raw: Array) -> Array:
        """``(N, B, 3)`` body states (centre of gravity, angle) -> part frame poses."""
        a = raw[..., 2]
        c, s = np.cos(a), np.sin(a)
        cx, cy = self.cogs[:, 0], self.cogs[:, 1]
        out = np.empty_like(raw)
        out[..., 0] = raw[..., 0] - (c * cx - s * cy)
        out[..., 1] = raw[..., 1] - (s * cx + c * cy)
        out[..., 2] = a
        return out

    def block(self, poses: Array, i0: int) -> tuple[int, str, float] | None:
        """First sample of the block (absolute index) where a part is off, that part and its error."""
        n = poses.shape[0]
        dev = np.empty((n, len(self.names)))
        for k, name in enumerate(self.names):
            pts = poses_apply(poses[:, k], self.pts[name])
            d = np.hypot(*(pts - self.ref[name][i0 : i0 + n]).transpose(2, 0, 1)).max(axis=1)
            dev[:, k] = np.where(np.isfinite(d), d, np.inf)
        bad = (dev > self.tol).any(axis=1)
        if not bad.any():
            for k, name in enumerate(self.names):
                self.worst[name] = max(self.worst[name], float(dev[:, k].max()))
            return None
        i = int(np.flatnonzero(bad)[0])
        for k, name in enumerate(self.names):
            self.worst[name] = max(self.worst[name], float(dev[: i + 1, k].max()))
        k = int(np.argmax(dev[i]))
        return i0 + i, self.names[k], float(dev[i, k])


def _classify(
    mech: Mechanism, poses: dict[str, Array], i: int, part: str, err: float, t: float, settings: SimSettings
) -> SimFailure:
    size = mech.size
    one = {k: v[i : i + 1] for k, v in poses.items()}
    finite = all(np.isfinite(v).all() for v in one.values())
    res = {j.name: float(np.max(j.residual(one))) for j in mech.joints} if finite else {}
    worst_joint = max(res, key=lambda k: res[k]) if res else None
    worst = res[worst_joint] if worst_joint is not None else math.inf
    where = f"at sample {i} (t = {t:.6g} s) part {part!r}"
    if not finite or not math.isfinite(err):
        return SimFailure(i, t, part, "blow-up", math.inf, f"blew up {where}: non-finite body state")
    rel = err / size
    if worst > settings.blowup_tol * size:
        return SimFailure(
            i,
            t,
            part,
            "blow-up",
            rel,
            f"blew up {where}: joint {worst_joint!r} residual {worst / size:.3g} of the size "
            f"(part off its analytic pose by {rel:.3g} of the size)",
        )
    if worst < 0.1 * err and rel > 10.0 * settings.tolerance:
        # every joint holds and the part is far off: another assembly branch (an offset of a few tolerances
        # with the joints holding is drift amplified by a long lever, reported below)
        return SimFailure(
            i,
            t,
            part,
            "branch",
            rel,
            f"switched assembly branch {where}: the part is {rel:.3g} of the size from its "
            f"analytic pose while every joint holds (worst residual {worst / size:.2g} of the size)",
        )
    return SimFailure(
        i,
        t,
        part,
        "drift",
        rel,
        f"left the analytic motion {where}: {rel:.3g} of the size off (tolerance "
        f"{settings.tolerance:g}); joint {worst_joint!r} residual {worst / size:.3g} of the size",
    )


def _failure_at(
    mech: Mechanism,
    rb: _Rebuild,
    check: _PoseCheck,
    raw: Array,
    hit: tuple[int, str, float],
    t: Array,
    settings: SimSettings,
    analytic: dict[str, Array],
) -> SimFailure:
    done = hit[0]
    poses_all = check.part_poses(raw[: done + 1])
    pp = {nm: poses_all[:, kk] for kk, nm in enumerate(check.names)}
    for p in mech.parts:
        if p.name not in pp:
            pp[p.name] = np.repeat(rb.static_pose[p.name][None, :], done + 1, axis=0)
    f = _classify(mech, pp, done, hit[1], hit[2], float(t[done]), settings)
    if f.kind in ("branch", "drift"):
        cp = change_point(mech, analytic, max(0, done - 3), done + 1)
        if cp is not None:
            k, parts = cp
            f = replace(
                f,
                kind="change-point",
                message=f"{f.message}; the analytic motion passes a change point or toggle at sample {k} (with the "
                f"input held, {' and '.join(repr(p) for p in parts)} can still move), where the mechanism may go on "
                "in either assembly",
            )
    return f


def _closure_error(mech: Mechanism, poses: dict[str, Array]) -> Array:
    """Sum of the squared joint residuals per sample (zero on the analytic motion)."""
    return sum((np.asarray(j.residual(poses), float) ** 2 for j in mech.joints), np.zeros(len(next(iter(poses.values())))))


def _mobility(mech: Mechanism, poses: dict[str, Array], free: list[str]) -> tuple[Array, Array]:
    """Per sample: the smallest over the largest eigenvalue of ``J^T J`` with the imposed parts held, and
    the eigenvector of the smallest (the free parts' way to move).

    ``J`` is the joints' constraint Jacobian in the free parts' poses (x, y
    and angle x size), found as the Hessian of the summed squared residuals
    by finite differences.  It is singular, the ratio near zero, where the
    mechanism can move with its input held: a change point or a toggle.
    """
    size = mech.size
    m = 3 * len(free)
    h = 1e-4 * size
    n = len(next(iter(poses.values())))

    def shifted(steps: list[int]) -> dict[str, Array]:
        out = dict(poses)
        for k in steps:
            part, c = free[k // 3], k % 3
            arr = out[part].copy() if out[part] is poses[part] else out[part]
            arr[:, c] += h if c < 2 else h / size
            out[part] = arr
        return out

    f0 = _closure_error(mech, poses)
    f1 = [_closure_error(mech, shifted([i])) for i in range(m)]
    H = np.empty((n, m, m))
    for i in range(m):
        for j in range(i, m):
            fij = _closure_error(mech, shifted([i, j]))
            H[:, i, j] = H[:, j, i] = (fij - f1[i] - f1[j] + f0) / (h * h)
    w, v = np.linalg.eigh(H)
    top = np.maximum(w[:, -1], 1e-300)
    return np.maximum(w[:, 0], 0.0) / top, v[:, :, 0]


def change_point(mech: Mechanism, poses: dict[str, Array], i0: int, i1: int) -> tuple[int, list[str]] | None:
    """A sample of ``i0:i1`` where the mechanism could move with its input held: a change point or toggle.

    There the constraints lose a rank (:func:`_mobility`) and the motion may
    go on in either assembly.  A sample counts when its ratio is below a
    hundredth of the median over 16 samples spread along the run.  Returns
    ``(sample, the parts that move most in the free motion)`` or ``None``.
    """
    imposed = set(_driven_parts(mech)) | {p.name for p in mech.parts if p.ground}
    free = [p.name for p in mech.parts if p.name not in imposed]
    if not free:
        return None
    n = len(next(iter(poses.values())))
    ref = np.unique(np.linspace(0, n - 1, 16).astype(int))
    idx = np.concatenate([np.arange(i0, i1), ref])
    ratio, vec = _mobility(mech, {k: v[idx] for k, v in poses.items()}, free)
    w = ratio[: i1 - i0]
    k = int(np.argmin(w))
    if not w[k] < 1e-2 * float(np.median(ratio[i1 - i0 :])):
        return None
    amount = np.abs(vec[k]).reshape(-1, 3).max(axis=1)
    parts = [free[q] for q in np.argsort(-amount)[:2]]
    return i0 + k, parts
