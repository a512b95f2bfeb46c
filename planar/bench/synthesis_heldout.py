"""Function and motion synthesis on held-out problems made from known random four-bars (part of ``planar bench synthesis``).

Function generation: a random four-bar (unit ground along +x, crank, coupler
and rocker log-uniform with longest / shortest at most 8, either circuit),
an input arc on which its crank moves on one circuit without meeting a toggle
(the whole assembly range for a rocking crank, shrunk by 10 % at each end;
an arc of 60 to 300 degrees for a crank that turns fully), ``n`` crank angles
drawn in it and sorted, and the rocker's angles there: ``n`` (input, output)
pairs a four-bar meets exactly, in order, on one circuit.  Two ways:

* ``fixed``: the angles from the ground line (as ``planar synth function``
  reads them without ``--free-offsets``);
* ``free``: both shifted by random offsets (``--free-offsets``: only the pairs'
  differences matter).

Motion generation: a random Grashof crank-rocker (the same lengths with the
crank shortest), a random coupler point, a body angle offset and a placement,
``n`` (3, 4 or 5) crank angles drawn in one turn and sorted: the coupler's
poses ``(x, y, angle)`` there.

Unreachable problems: the same, perturbed (the output angles by Gaussian noise
of :data:`FUNCTION_NOISE` rad at 6 and 10 pairs with fixed offsets, where the
four-bar's three unknowns are over-determined; the poses by noise of
:data:`MOTION_NOISE` of their extent in position and the same in radians, at 5
poses, kept only when planar's Burmester synthesis finds no exact four-bar for
them).  Measured there: planar's nearest design's error, against the error of
least squares started at the known four-bar (a reference no search of planar
produced), and whether the design fails its check (the CLI's exit 3).

The peer: pylinkage 1.3's ``synthesis.function_generation(angle_pairs)`` and
``synthesis.motion_generation(poses)`` on the same problems, their solutions
scored by planar's measure (a pylinkage call that raises or returns no
solution counts as a miss, and the exception's text is kept); and its
``path_generation`` / ``path_generation_with_timing`` on the reachable-curve
benchmark's own problems (:func:`bench_reachable_pylinkage`).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import NDArray

__all__ = [
    "bench_function_heldout",
    "bench_motion_heldout",
    "bench_reachable_pylinkage",
    "format_heldout",
    "format_reachable_pylinkage",
    "function_problem",
    "motion_problem",
    "reachable_problems",
]

Array = NDArray[np.float64]

#: the seed of the held-out problems, never used to tune anything (90817 measured the search before the algebraic
#: solve of free offsets; this one, after it)
SEED = 20261130
#: pairs per function problem and poses per motion problem
FUNCTION_SIZES = (3, 4, 5, 7, 10)
MOTION_SIZES = (3, 4, 5)
#: noise of the unreachable function problems' output angles (rad) and the motion problems' poses (fraction of
#: their extent; the same number in radians for the angles)
FUNCTION_NOISE = 0.02
MOTION_NOISE = 0.02
#: recovered: the largest error within this (output angle in rad; pose position over the poses' extent and angle in rad)
EXACT = 1e-6


def _lengths(rng: np.random.Generator, ratio: float = 8.0) -> Array:
    """Crank, coupler, rocker (unit ground) log-uniform, longest / shortest of the four at most ``ratio``."""
    while True:
        L = np.exp(rng.uniform(-np.log(ratio) / 2, np.log(ratio) / 2, 3))
        allL = np.append(L, 1.0)
        if allL.max() <= ratio * allL.min():
            return L


def crank_arc(a: float, b: float, c: float) -> tuple[float, float] | None:
    """The crank angles (rad, from the ground line; unit ground) where the dyad closes, as one arc ``(lo, hi)``
    (unwrapped, ``hi - lo <= 2 pi``), or None when it closes nowhere; a full turn is ``(0, 2 pi)``.

    ``|B - O4|^2 = a^2 + 1 - 2 a cos t`` between ``(b - c)^2`` and ``(b + c)^2``.  Of two symmetric arcs
    (about 0 and pi) the one about 0 is given when both exist."""
    cmin = (a * a + 1.0 - (b + c) ** 2) / (2.0 * a)
    cmax = (a * a + 1.0 - (b - c) ** 2) / (2.0 * a)
    if cmin > 1.0 or cmax < -1.0:
        return None
    if cmin <= -1.0 and cmax >= 1.0:
        return 0.0, 2 * np.pi
    if cmin <= -1.0:  # about pi: cos t <= cmax
        t = math.acos(cmax)
        return t, 2 * np.pi - t
    if cmax >= 1.0:  # about 0: cos t >= cmin
        t = math.acos(cmin)
        return -t, t
    return math.acos(cmax), math.acos(cmin)  # two arcs: the upper one


def _rocker(a: float, b: float, c: float, circuit: float, theta: Array) -> tuple[Array, NDArray[np.bool_]]:
    """The rocker's angle (rad, from the ground line) at crank angles ``theta``, and where it closes (kernel)."""
    from planar.synth.kernel import coupler_points

    K = np.array([[1.0, a, b, c, b, 0.0, 0.0, 0.0, 0.0]])
    cx, cy, ok = coupler_points(K, theta[None, :], np.array([circuit]))
    return np.arctan2(cy[0], cx[0] - 1.0), ok[0]


def function_problem(rng: np.random.Generator, n: int, free: bool) -> dict[str, Any]:
    """``n`` (input, output) pairs of a random four-bar (see the module): ``phi``, ``psi`` (rad) and the four-bar."""
    while True:
        a, b, c = _lengths(rng)
        arc = crank_arc(a, b, c)
        if arc is None:
            continue
        lo, hi = arc
        if hi - lo >= 2 * np.pi - 1e-12:
            span = rng.uniform(np.radians(60), np.radians(300))
            lo = rng.uniform(0, 2 * np.pi)
            hi = lo + span
        else:
            pad = 0.1 * (hi - lo)
            lo, hi = lo + pad, hi - pad
        if hi - lo < np.radians(20):
            continue
        circuit = float(rng.choice([1.0, -1.0]))
        phi = np.sort(rng.uniform(lo, hi, n))
        if np.min(np.diff(phi), initial=1.0) < 1e-3:
            continue
        psi, ok = _rocker(a, b, c, circuit, phi)
        from planar.synth.function_search import arc_margin

        if not ok.all() or arc_margin(a, b, c, phi.min(), phi.max()) < 1e-3:
            continue
        dense = np.linspace(phi.min(), phi.max(), 721)
        track, _ = _rocker(a, b, c, circuit, np.unique(np.concatenate([dense, phi])))
        track = np.unwrap(track)
        psi = track[np.searchsorted(np.unique(np.concatenate([dense, phi])), phi)]
        if np.max(np.abs(np.diff(psi)), initial=0.0) >= 0.9 * np.pi:
            continue  # a step of half a turn or more between pairs: ambiguous as pairs (read with steps < pi)
        A = B = 0.0
        if free:
            A, B = rng.uniform(-np.pi, np.pi, 2)
        return {"phi": phi - A, "psi": psi - B, "fourbar": [1.0, a, b, c], "circuit": circuit, "offsets": [A, B]}


def _pose_rows(p: Array, circuit: float, offset: float, theta: Array) -> Array:
    """Poses ``(n, 3)`` of the coupler of kernel row ``p`` (9 parameters) at crank angles ``theta``: the coupler
    point and the coupler's angle (C - B) plus ``offset``."""
    from planar.synth.kernel import coupler_points

    q = np.vstack([p, p])
    q[1, 4], q[1, 5] = p[2], 0.0  # the rocker pin C
    x, y, ok = coupler_points(q, np.vstack([theta, theta]), np.array([circuit, circuit]))
    q0 = p.copy()
    q0[4], q0[5] = 0.0, 0.0  # the crank pin B
    bx, by, _ = coupler_points(q0[None, :], theta[None, :], np.array([circuit]))
    ang = np.arctan2(y[1] - by[0], x[1] - bx[0]) + offset
    if not ok.all():
        return np.full((len(theta), 3), np.nan)
    return np.column_stack([x[0], y[0], ang])


def motion_problem(rng: np.random.Generator, n: int) -> dict[str, Any]:
    """``n`` coupler poses of a random Grashof crank-rocker (see the module) in the crank's order."""
    while True:
        a, b, c = _lengths(rng)
        L = sorted((1.0, a, b, c))
        if not (a == L[0] and L[0] + L[3] < 0.98 * (L[1] + L[2])):
            continue
        u, v = b * rng.uniform(-1.0, 2.0), b * rng.uniform(-1.5, 1.5)
        circuit = float(rng.choice([1.0, -1.0]))
        p = np.array([1.0, a, b, c, u, v, *rng.uniform(-1, 1, 2), rng.uniform(-np.pi, np.pi)])
        theta = np.sort(rng.uniform(0, 2 * np.pi, n))
        gaps = np.diff(np.append(theta, theta[0] + 2 * np.pi))
        if gaps.min() < np.radians(10):
            continue
        offset = rng.uniform(-np.pi, np.pi)
        poses = _pose_rows(p, circuit, offset, theta)
        ext = float(np.hypot(*np.ptp(poses[:, :2], axis=0)))
        if not np.isfinite(poses).all() or ext < 0.05 or np.ptp(np.unwrap(poses[:, 2])) < np.radians(5):
            continue
        return {"poses": poses, "fourbar": p.tolist(), "circuit": circuit, "offset": offset, "theta": theta}


def motion_error(poses: Array, got: Array) -> float:
    """Largest pose error: position over the poses' extent, or angle (rad), whichever is larger."""
    ext = max(float(np.hypot(*np.ptp(poses[:, :2], axis=0))), 1e-300)
    dp = np.hypot(*(got[:, :2] - poses[:, :2]).T) / ext
    da = np.abs((got[:, 2] - poses[:, 2] + np.pi) % (2 * np.pi) - np.pi)
    return float(np.max(np.maximum(dp, da)))


def _median(v: list[float]) -> float:
    return float(np.median(v)) if v else float("nan")


# --- function generation ---


def _planar_function(phi: Array, psi: Array, free: bool, tolerance: float) -> tuple[float, bool, bool, float]:
    """planar's design: (largest output error, ok, crank turns the pairs in order on one circuit, CPU s)."""
    from planar.synth.function import synthesise_function
    from planar.synth.function_search import FunctionConstraints

    c0 = time.process_time()
    d, _ = synthesise_function(phi, psi, 1.0, FunctionConstraints(free_offsets=free), tolerance)
    cpu = time.process_time() - c0
    if d is None:
        return math.inf, False, False, cpu
    return d.max_error, d.ok, bool(d.checks["ok_assembles_over_arc"]), cpu


def _pylinkage_function(phi: Array, psi: Array) -> tuple[float, str]:
    """pylinkage's ``function_generation`` on the pairs (angles from its ground line, as given): the best
    solution's largest output error by planar's kernel on the solution's circuit nearest the pairs, or inf and
    what the call returned."""
    try:
        from pylinkage.synthesis import function_generation
    except ImportError as exc:  # pragma: no cover - the peer is optional
        return math.inf, f"import failed: {exc}"
    try:
        res = function_generation([(float(a), float(b)) for a, b in zip(phi, psi)], require_grashof=False)
    except Exception as exc:  # any failure of the peer is recorded, not raised
        return math.inf, f"function_generation raised {type(exc).__name__}: {exc}"
    sols = list(getattr(res, "raw_solutions", []) or [])
    if not sols:
        return math.inf, "function_generation returned no solution" + (
            f" ({res.warnings[0]})" if getattr(res, "warnings", None) else ""
        )
    best = math.inf
    for s in sols:
        d = float(np.hypot(*np.subtract(s.ground_pivot_d, s.ground_pivot_a)))
        if d <= 0:
            continue
        a, b, c = s.crank_length / d, s.coupler_length / d, s.rocker_length / d
        g = np.subtract(s.ground_pivot_d, s.ground_pivot_a)
        turn = math.atan2(g[1], g[0])
        for circ in (1.0, -1.0):
            r, ok = _rocker(a, b, c, circ, phi - turn)
            if ok.all():
                e = (r + turn) - psi
                e = (e + np.pi) % (2 * np.pi) - np.pi
                best = min(best, float(np.max(np.abs(e))))
    return best, f"{len(sols)} solution(s)"


def _function_reference(phi: Array, psi: Array, p: dict[str, Any]) -> float:
    """Largest output error of least squares (scipy) started at the known four-bar: what the nearest is at most."""
    from scipy.optimize import least_squares

    circ = p["circuit"]

    def res(z: Array) -> Array:
        a, b, c = np.exp(z)
        r, ok = _rocker(float(a), float(b), float(c), circ, phi)
        return np.where(ok, (r - psi + np.pi) % (2 * np.pi) - np.pi, np.pi)

    r = least_squares(res, np.log(p["fourbar"][1:]), method="lm", max_nfev=400)
    return float(np.max(np.abs(res(r.x))))


def bench_function_heldout(count: int = 50, seed: int = SEED, sizes: tuple[int, ...] = FUNCTION_SIZES) -> dict[str, Any]:
    """Function generation on ``count`` held-out problems per number of pairs and way (see the module)."""
    rng = np.random.default_rng([seed, 1])
    rows: list[dict[str, Any]] = []
    for free in (False, True):
        for n in sizes:
            for _ in range(count):
                p = function_problem(rng, n, free)
                e, ok, one, cpu = _planar_function(p["phi"], p["psi"], free, EXACT)
                rec = {"pairs": n, "offsets": "free" if free else "fixed", "max_error": e, "ok": ok, "one_circuit": one}
                rec["cpu_s"] = cpu
                if not free:
                    rec["pylinkage_error"], rec["pylinkage_note"] = _pylinkage_function(p["phi"], p["psi"])
                rows.append(rec)
    unreach: list[dict[str, Any]] = []
    for n in (6, 10):
        for _ in range(count):
            p = function_problem(rng, n, False)
            noisy = p["psi"] + FUNCTION_NOISE * rng.standard_normal(n)
            e, ok, one, cpu = _planar_function(p["phi"], noisy, False, EXACT)
            unreach.append(
                {"pairs": n, "max_error": e, "ok": ok, "cpu_s": cpu, "reference_error": _function_reference(p["phi"], noisy, p)}
            )
    return {"seed": seed, "count": count, "rows": rows, "unreachable": unreach, "summary": _function_summary(rows, unreach)}


def _function_summary(rows: list[dict[str, Any]], unreach: list[dict[str, Any]]) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for way in ("fixed", "free"):
        for n in sorted({r["pairs"] for r in rows}):
            rs = [r for r in rows if r["pairs"] == n and r["offsets"] == way]
            if not rs:
                continue
            out[f"{way} {n}"] = _solved_summary(rs, [r["one_circuit"] for r in rs], peer=way == "fixed")
    for n in sorted({r["pairs"] for r in unreach}):
        out[f"unreachable {n}"] = _unreachable_summary([r for r in unreach if r["pairs"] == n])
    return out


def _solved_summary(rs: list[dict[str, Any]], kept: list[bool], peer: bool = True) -> dict[str, Any]:
    """Reachable problems' rows ``rs``: how many, the share recovered (largest error <= :data:`EXACT` and ``kept``:
    on one circuit, in order), the median error and CPU; with ``peer``, pylinkage's share and median error."""
    e = np.array([r["max_error"] for r in rs])
    rec = {
        "problems": len(rs),
        "recovered": float(np.mean((e <= EXACT) & np.array(kept))),
        "median_error": _median(list(e)),
        "median_cpu_s": _median([r["cpu_s"] for r in rs]),
    }
    if peer:
        pe = np.array([r["pylinkage_error"] for r in rs])
        rec["pylinkage_recovered"] = float(np.mean(pe <= EXACT))
        rec["pylinkage_median_error"] = _median(list(pe))
    return rec


def _unreachable_summary(rs: list[dict[str, Any]], nearest: bool = False) -> dict[str, Any]:
    """Unreachable problems' rows ``rs``: how many, the share that exit 3 (with ``nearest``: the share where a
    nearest design is given), the share whose error is within 1e-6 of the least-squares reference's, the
    medians of both errors and of the CPU."""
    e = np.array([r["max_error"] for r in rs])
    ref = np.array([r["reference_error"] for r in rs])
    return {
        "problems": len(rs),
        "exit_3": float(np.mean([not r["ok"] for r in rs])),
        **({"nearest_given": float(np.mean(np.isfinite(e)))} if nearest else {}),
        "as_good_as_reference": float(np.mean(e <= ref * (1 + 1e-6) + 1e-9)),
        "median_error": _median(list(e)),
        "median_reference_error": _median(list(ref)),
        "median_cpu_s": _median([r["cpu_s"] for r in rs]),
    }


# --- motion generation ---


def _planar_motion(poses: Array) -> tuple[float, bool, bool, float, str]:
    """planar's design: (largest pose error, ok, in order, CPU s, why none when none)."""
    from planar.synth.motion import NoMotionDesign, burmester

    c0 = time.process_time()
    try:
        d = burmester(poses)
    except NoMotionDesign as e:
        nearest = getattr(e, "nearest", None)
        cpu = time.process_time() - c0
        if nearest is None:
            return math.inf, False, False, cpu, str(e)
        return _motion_design_error(nearest), False, bool(nearest.in_order), cpu, str(e)
    cpu = time.process_time() - c0
    return _motion_design_error(d), d.ok, bool(d.checks["ok_poses_in_order"]), cpu, ""


def _motion_design_error(d: Any) -> float:
    """Largest pose error of a MotionDesign, as :func:`motion_error` (position over the extent, angle in rad)."""
    L = max(float(np.hypot(*np.ptp(d.poses[:, :2], axis=0))), 1e-300)
    return max(d.checks["max_position_error"] / L, d.checks["max_angle_error_rad"])


def _pylinkage_motion(poses: Array) -> tuple[float, str]:
    """pylinkage's ``motion_generation`` on the poses: the best solution's largest pose error by planar's measure
    (the coupler point and angle fitted to pose 1 as pylinkage's body frame is), or inf and what the call returned."""
    try:
        from pylinkage.synthesis import Pose, motion_generation
    except ImportError as exc:  # pragma: no cover
        return math.inf, f"import failed: {exc}"
    try:
        res = motion_generation([Pose(float(x), float(y), float(a)) for x, y, a in poses], require_grashof=False)
    except Exception as exc:  # any failure of the peer is recorded, not raised
        return math.inf, f"motion_generation raised {type(exc).__name__}: {exc}"
    sols = list(getattr(res, "raw_solutions", []) or [])
    if not sols:
        return math.inf, "motion_generation returned no solution" + (
            f" ({res.warnings[0]})" if getattr(res, "warnings", None) else ""
        )
    best = min(_pylinkage_motion_error(s, poses) for s in sols)
    return best, f"{len(sols)} solution(s)"


def _pylinkage_motion_error(s: Any, poses: Array) -> float:
    """One pylinkage FourBarSolution's largest pose error on one circuit, inf unless the crank meets the poses in
    order: the body attached to its coupler at pose 1 (where pylinkage gives its joints), the crank angle at
    each pose the one that puts the crank pin where the body's moving pivot is there (exact), planar's kernel
    solving the coupler's pose at it on each circuit."""
    from planar.synth.motion import crank_order

    A, D = np.asarray(s.ground_pivot_a, float), np.asarray(s.ground_pivot_d, float)
    B, C = np.asarray(s.crank_pivot_b, float), np.asarray(s.coupler_pivot_c, float)
    g = D - A
    d, b = float(np.hypot(*g)), float(np.hypot(*(C - B)))
    if d <= 0 or b <= 0:
        return math.inf
    e = (C - B) / b
    q = poses[0, :2] - B
    u, v = float(q @ e), float(e[0] * q[1] - e[1] * q[0])
    off = float(poses[0, 2] - math.atan2(e[1], e[0]))
    phi = math.atan2(g[1], g[0])
    p = np.array([d, s.crank_length, s.coupler_length, s.rocker_length, u, v, A[0], A[1], phi])
    c0, s0 = math.cos(poses[0, 2]), math.sin(poses[0, 2])
    zb = np.array([[c0, s0], [-s0, c0]]) @ (B - poses[0, :2])  # the crank pin in the body's frame
    cj, sj = np.cos(poses[:, 2]), np.sin(poses[:, 2])
    Bj = poses[:, :2] + np.column_stack([cj * zb[0] - sj * zb[1], sj * zb[0] + cj * zb[1]])
    th = np.arctan2(Bj[:, 1] - A[1], Bj[:, 0] - A[0]) - phi
    ordered, *_ = crank_order(th[None, :], *(np.array([x]) for x in p[:4]))
    if not ordered[0]:
        return math.inf
    best = math.inf
    for circ in (1.0, -1.0):
        got = _pose_rows_any(p, circ, off, th)
        if got is not None and np.isfinite(got).all():
            best = min(best, motion_error(poses, got))
    return best


def _pose_rows_any(p: Array, circ: float, off: float, th: Array) -> Array | None:
    """Poses at crank angles ``th`` where the four-bar closes (NaN where it does not), or None if nowhere."""
    from planar.synth.kernel import coupler_points

    q = np.vstack([p, p, p])
    q[1, 4], q[1, 5] = p[2], 0.0
    q[2, 4], q[2, 5] = 0.0, 0.0
    x, y, ok = coupler_points(q, np.vstack([th, th, th]), np.full(3, circ))
    good = ok[0]
    if not good.any():
        return None
    ang = np.arctan2(y[1] - y[2], x[1] - x[2]) + off
    out = np.column_stack([x[0], y[0], ang])
    out[~good] = np.nan
    return out


def _motion_reference(poses: Array, p: dict[str, Any]) -> float:
    """Largest pose error of least squares (scipy) started at the known four-bar (the crank angles free)."""
    from planar.synth.motion import nearest_motion_error

    return nearest_motion_error(poses, np.asarray(p["fourbar"], float), p["circuit"], p["offset"], np.asarray(p["theta"]))


def bench_motion_heldout(count: int = 50, seed: int = SEED, sizes: tuple[int, ...] = MOTION_SIZES) -> dict[str, Any]:
    """Motion generation on ``count`` held-out problems per number of poses, and unreachable 5-pose problems."""
    rng = np.random.default_rng([seed, 2])
    rows: list[dict[str, Any]] = []
    for n in sizes:
        for _ in range(count):
            p = motion_problem(rng, n)
            e, ok, order, cpu, why = _planar_motion(p["poses"])
            pe, note = _pylinkage_motion(p["poses"])
            rows.append(
                {"poses": n, "max_error": e, "ok": ok, "in_order": order, "cpu_s": cpu, "why": why}
                | {"pylinkage_error": pe, "pylinkage_note": note}
            )
    unreach: list[dict[str, Any]] = []
    tries = 0
    while len(unreach) < count and tries < 40 * count:
        tries += 1
        p = motion_problem(rng, 5)
        poses = p["poses"].copy()
        ext = float(np.hypot(*np.ptp(poses[:, :2], axis=0)))
        poses[:, :2] += MOTION_NOISE * ext * rng.standard_normal((5, 2))
        poses[:, 2] += MOTION_NOISE * rng.standard_normal(5)
        e, ok, order, cpu, why = _planar_motion(poses)
        if not why:  # an exact four-bar exists for the perturbed poses: not an unreachable problem
            continue
        unreach.append({"poses": 5, "max_error": e, "ok": ok, "cpu_s": cpu, "why": why, "in_order": order})
        unreach[-1]["reference_error"] = _motion_reference(poses, p)
    return {
        "seed": seed,
        "count": count,
        "rows": rows,
        "unreachable": unreach,
        "unreachable_tried": tries,
        "summary": _motion_summary(rows, unreach),
    }


def _motion_summary(rows: list[dict[str, Any]], unreach: list[dict[str, Any]]) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for n in sorted({r["poses"] for r in rows}):
        rs = [r for r in rows if r["poses"] == n]
        out[str(n)] = _solved_summary(rs, [r["in_order"] and r["ok"] for r in rs])
    if unreach:
        out["unreachable 5"] = _unreachable_summary(unreach, nearest=True)
    return out


def format_heldout(fn: dict[str, Any], mo: dict[str, Any]) -> str:
    """The two held-out benchmarks as text."""
    lines = [
        f"function and motion synthesis on held-out four-bars (seed {fn['seed']}, {fn['count']} problems a size; "
        f"recovered: largest error <= {EXACT:g}, in order on one circuit; CPU per problem)"
    ]
    for key, s in fn["summary"].items():
        if key.startswith("unreachable"):
            lines.append(
                f"  function, {key.split()[1]} noisy pairs (no four-bar): exit 3 in {s['exit_3']:.0%}, nearest's error "
                f"median {s['median_error']:.3g} rad (least squares from the true four-bar {s['median_reference_error']:.3g}), "
                f"as good in {s['as_good_as_reference']:.0%}, CPU {s['median_cpu_s']:.2f} s"
            )
            continue
        way, n = key.split()
        peer = (
            f"; pylinkage {s['pylinkage_recovered']:.0%} (median {s['pylinkage_median_error']:.3g})"
            if "pylinkage_recovered" in s
            else ""
        )
        lines.append(
            f"  function, {n} pairs, {way} offsets: recovered {s['recovered']:.0%} of {s['problems']}, median error "
            f"{s['median_error']:.3g} rad, CPU {s['median_cpu_s']:.2f} s{peer}"
        )
    for key, s in mo["summary"].items():
        if key.startswith("unreachable"):
            lines.append(
                f"  motion, 5 noisy poses (no four-bar; {s['problems']} of {mo['unreachable_tried']} tried): exit 3 in "
                f"{s['exit_3']:.0%}, nearest given in {s['nearest_given']:.0%}, its error median {s['median_error']:.3g} "
                f"(least squares from the true four-bar {s['median_reference_error']:.3g}), as good in "
                f"{s['as_good_as_reference']:.0%}, CPU {s['median_cpu_s']:.2f} s"
            )
            continue
        lines.append(
            f"  motion, {key} poses: recovered {s['recovered']:.0%} of {s['problems']}, median error {s['median_error']:.3g}, "
            f"CPU {s['median_cpu_s']:.2f} s; pylinkage {s['pylinkage_recovered']:.0%} (median {s['pylinkage_median_error']:.3g})"
        )
    return "\n".join(lines)


# --- pylinkage's path synthesis on the reachable-curve benchmark's problems ---


def reachable_problems(
    reachable_problem: Callable[[np.random.Generator, int], tuple[Array, Array]],
    sizes: tuple[int, ...] = (8, 12, 25, 50),
    count: int = 25,
    seed: int = 2026,
) -> list[dict[str, Any]]:
    """The problems of :func:`planar.bench.synthesis.bench_reachable` with the same arguments, drawn in its order
    by its ``reachable_problem`` (each problem's targets and crank angles, then the noise it adds, so the next
    problem is the same)."""
    rng = np.random.default_rng(seed)
    out = []
    for n in sizes:
        for _ in range(count):
            T, th = reachable_problem(rng, n)
            rng.standard_normal(T.shape)  # bench_reachable's noisy copy
            out.append({"targets": T, "theta": th, "n": n})
    return out


def _pylinkage_path(T: Array, theta: Array | None, score: Callable[..., Any]) -> tuple[float, float, str]:
    """pylinkage's ``path_generation`` (untimed) or ``path_generation_with_timing`` on all the targets: the best
    solution's largest distance over the targets' size (planar's measure: ``score(solution, targets, theta)``,
    :func:`planar.bench.synthesis._from_pylinkage`, a design or None), its CPU seconds, and what it returned."""
    import warnings

    pts = [(float(x), float(y)) for x, y in T]
    size = float(np.sqrt(np.mean(np.sum((T - T.mean(0)) ** 2, axis=1))))
    c0 = time.process_time()
    try:
        from pylinkage.synthesis import path_generation, path_generation_with_timing

        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            if theta is None:
                res = path_generation(pts, require_grashof=False)
            else:
                res = path_generation_with_timing(pts, [float(t) for t in theta], require_grashof=False)
    except Exception as exc:  # any failure of the peer is recorded, not raised
        return math.inf, time.process_time() - c0, f"raised {type(exc).__name__}: {exc}"
    cpu = time.process_time() - c0
    designs = [d for d in (score(s, T, theta) for s in res.raw_solutions) if d is not None]
    if not designs:
        first = res.warnings[0].splitlines()[0] if res.warnings else ""
        return math.inf, cpu, f"no solution ({len(res.raw_solutions)} returned){': ' + first if first else ''}"
    best = min(d.checks["max_target_distance"] for d in designs)
    return best / size, cpu, f"{len(designs)} solution(s)"


#: reachable problems per number of targets pylinkage is run on where a user runs the benchmark (each of its
#: calls takes about 12 s of CPU to completion, timed and untimed: 25 per size for 4 sizes were 20 minutes)
PEER_PER_SIZE = 5


def bench_reachable_pylinkage(
    problems: list[dict[str, Any]], score: Callable[..., Any], seed: int = 2026, per_size: int | None = None
) -> dict[str, Any]:
    """pylinkage 1.3's path synthesis on ``problems`` (:func:`reachable_problems`: the reachable-curve benchmark's
    own, drawn with ``seed``), untimed and timed, ``require_grashof=False``, each solution scored by ``score``
    (see :func:`_pylinkage_path`): success (largest distance <= 1e-6 and <= 1e-3 of the targets' size) and CPU
    per call.  Its calls take no budget (they run to completion): their CPU is reported.  ``per_size``: the
    first ``per_size`` problems of each number of targets only (None: every one; see :data:`PEER_PER_SIZE`)."""
    if per_size is not None:
        taken: dict[int, int] = {}
        kept = []
        for p in problems:
            if taken.get(p["n"], 0) < per_size:
                kept.append(p)
                taken[p["n"]] = taken.get(p["n"], 0) + 1
        problems = kept
    rows = []
    sizes = tuple(sorted({p["n"] for p in problems}))
    count = max((sum(p["n"] == n for p in problems) for n in sizes), default=0)
    for p in problems:
        rec: dict[str, Any] = {"targets": p["n"]}
        for mode, th in (("untimed", None), ("timed", p["theta"])):
            e, cpu, note = _pylinkage_path(p["targets"], th, score)
            rec[mode] = {"max_error": e, "cpu_s": cpu, "note": note}
        rows.append(rec)
    summary: dict[str, Any] = {}
    for n in sizes:
        rs = [r for r in rows if r["targets"] == n]
        summary[str(n)] = {
            mode: {
                "problems": len(rs),
                "within_1e-6": float(np.mean([r[mode]["max_error"] <= 1e-6 for r in rs])),
                "within_1e-3": float(np.mean([r[mode]["max_error"] <= 1e-3 for r in rs])),
                "median_error": _median([r[mode]["max_error"] for r in rs]),
                "median_cpu_s": _median([r[mode]["cpu_s"] for r in rs]),
                "notes": sorted({r[mode]["note"] for r in rs})[:3],
            }
            for mode in ("untimed", "timed")
        }
    return {"seed": seed, "count": count, "rows": rows, "summary": summary}


def format_reachable_pylinkage(r: dict[str, Any]) -> str:
    """pylinkage on the reachable curves, as text."""
    lines = [f"pylinkage 1.3 synthesis on the reachable curves (seed {r['seed']}, {r['count']} per size; no budget)"]
    for n, s in r["summary"].items():
        for mode, m in s.items():
            lines.append(
                f"  {n} targets, {mode}: within 1e-6 {m['within_1e-6']:.0%}, within 1e-3 {m['within_1e-3']:.0%}, "
                f"median error {m['median_error']:.3g}, CPU {m['median_cpu_s']:.2f} s; returned: {'; '.join(m['notes'])}"
            )
    return "\n".join(lines)
