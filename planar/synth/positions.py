"""Refinement of a four-bar on untimed targets in its joints' positions: a better-conditioned parametrisation than
the kernel's lengths and angles where the targets lie on a short, smooth arc.

The variables (:func:`joint_positions`) are the pivots and moving joints at the first target's pose and the input's
turn from there to each later target; the coupler's and rocker's lengths are the loop-closure equations inside
:func:`positions_points`, written with arithmetic, ``cos``, ``sin`` and ``sqrt`` only so that a complex step gives
the exact Jacobian.  :func:`polish_positions` runs Levenberg-Marquardt with geodesic acceleration
(:func:`geodesic_lm`) on them; :func:`planar.synth.search.refined_start` runs it on every closed-curve atlas start
after a few evaluations in the kernel's lengths, :func:`planar.synth.arcs.arc_start` on every rocking start from its
first step.  With a ``floor``, a penalty on :func:`positions_sin2` (the transmission angle's
squared sine at each target) keeps the refinement off the toggles.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import NDArray

from planar.synth.kernel import GRASHOF_MARGIN

__all__ = [
    "geodesic_lm",
    "joint_positions",
    "polish_positions",
    "positions_points",
    "positions_sin2",
    "row_from_positions",
]

Array = NDArray[np.float64]

#: the default iterations of :func:`polish_positions`
POLISH_ITERS = 600
#: the weight of a target's transmission angle below the floor (:func:`_positions_problem`): at a toggle (squared
#: sine 0), with the floor at 1.2 deg, the penalty is 10 sin^2(1.2 deg) = 0.0044, as much as a target 0.0044 of the
#: size off
TOGGLE_WEIGHT = 10.0


def joint_positions(row: Array, theta: Array) -> tuple[Array, Array]:
    """A kernel row (9 parameters and the circuit) and its input angles at the targets ``theta`` ``(N,)`` as the
    joints' positions at the first target's pose, ``O2, B, C, O4, P`` (x, y each: 10 numbers), and the input's
    turn from there to each later target ``(N - 1,)`` (rad): the variables of :func:`polish_positions`."""
    r1, r2, r3, r4, u, v, x0, y0, phi = (float(x) for x in row[:9])
    s = 1.0 if row[9] >= 0 else -1.0
    o2 = complex(x0, y0)
    o4 = o2 + r1 * np.exp(1j * phi)
    b = o2 + r2 * np.exp(1j * (phi + float(theta[0])))
    d = o4 - b
    L2 = abs(d) ** 2
    A = 0.5 * (L2 + r3 * r3 - r4 * r4)
    e = (A + 1j * s * math.sqrt(max(r3 * r3 * L2 - A * A, 0.0))) * d / L2  # C - B
    c = b + e
    p = b + (u + 1j * v) * e / r3
    q = np.array([o2.real, o2.imag, b.real, b.imag, c.real, c.imag, o4.real, o4.imag, p.real, p.imag])
    return q, np.asarray(theta[1:], float) - float(theta[0])


def positions_points(q: Any, turn: Any, circuit: float) -> tuple[Any, Any]:
    """Coupler points ``(x, y)`` at the first pose of :func:`joint_positions` and after each ``turn``: written with
    arithmetic, ``cos``, ``sin`` and ``sqrt`` only, so it runs on complex numbers for the complex-step derivative."""
    x, y, _ = _poses(q, turn, circuit)
    return x, y


def positions_sin2(q: Any, turn: Any) -> Any:
    """The squared sine of the transmission angle (between coupler and rocker, at C) at the first pose of
    :func:`joint_positions` and after each ``turn``: 0 at a toggle.  By the law of sines in the triangle B, C, O4 it
    is ``(b^2 L^2 - A^2) / (b^2 c^2)``, ``b`` the coupler, ``c`` the rocker, ``L`` the diagonal B-O4 and
    ``A = (L^2 + b^2 - c^2) / 2``; arithmetic only, so it runs on complex numbers too."""
    return _poses(q, turn, 1.0)[2]


def _poses(q: Any, turn: Any, circuit: float) -> tuple[Any, Any, Any]:
    """:func:`positions_points`'s coupler points and :func:`positions_sin2`'s squared sines, from one evaluation."""
    o2x, o2y, bx0, by0, cx0, cy0, o4x, o4y, px0, py0 = q
    turn = np.asarray(turn)
    al = np.concatenate([np.zeros(turn.shape[:-1] + (1,), dtype=np.result_type(turn, float)), turn], axis=-1)
    ca, sa = np.cos(al), np.sin(al)
    rx, ry = bx0 - o2x, by0 - o2y
    bx, by = o2x + ca * rx - sa * ry, o2y + sa * rx + ca * ry
    ex0, ey0 = cx0 - bx0, cy0 - by0
    b2 = ex0 * ex0 + ey0 * ey0  # coupler length squared, rocker's below: the loop-closure lengths
    c2 = (cx0 - o4x) ** 2 + (cy0 - o4y) ** 2
    fx, fy = px0 - bx0, py0 - by0
    a1, a2 = (fx * ex0 + fy * ey0) / b2, (ex0 * fy - ey0 * fx) / b2
    dx, dy = o4x - bx, o4y - by
    L2 = dx * dx + dy * dy
    A = 0.5 * (L2 + b2 - c2)
    w2 = b2 * L2 - A * A
    w = circuit * np.sqrt(w2)
    ex, ey = (A * dx - w * dy) / L2, (A * dy + w * dx) / L2
    return bx + a1 * ex - a2 * ey, by + a1 * ey + a2 * ex, w2 / (b2 * c2)


def row_from_positions(q: Array, turn: Array, circuit: float) -> tuple[Array, Array]:
    """The kernel row (9 parameters and ``circuit``) and the input angles at the targets of :func:`joint_positions`'s
    variables."""
    o2, b, c, o4, p = (complex(q[i], q[i + 1]) for i in range(0, 10, 2))
    g, e = o4 - o2, c - b
    phi = math.atan2(g.imag, g.real)
    w = (p - b) / e * abs(e)  # the coupler point in the coupler's frame (x along B -> C)
    row = np.array([abs(g), abs(b - o2), abs(e), abs(c - o4), w.real, w.imag, o2.real, o2.imag, phi, circuit])
    th0 = math.atan2((b - o2).imag, (b - o2).real) - phi
    return row, th0 + np.concatenate([[0.0], np.asarray(turn, float)])


def _ratio_excess(q: Any, max_ratio: float) -> Any:
    """How far the longest of the four links (from the joints' positions ``q``) is over ``max_ratio`` (less a
    margin) times the shortest, 0 when it is not: piecewise analytic, so it runs on complex numbers too."""
    o2x, o2y, bx, by, cx, cy, o4x, o4y = q[:8]
    sides = ((o4x - o2x, o4y - o2y), (bx - o2x, by - o2y), (cx - bx, cy - by), (cx - o4x, cy - o4y))
    L = [np.sqrt(dx * dx + dy * dy) for dx, dy in sides]
    re = [float(np.real(v)) for v in L]
    x = L[int(np.argmax(re))] - max_ratio * (1.0 - 2 * GRASHOF_MARGIN) * L[int(np.argmin(re))]
    return x if float(np.real(x)) > 0 else 0.0 * x


def _positions_problem(t: Array, circuit: float, max_ratio: float, floor: float = 0.0) -> tuple[Any, Any]:
    """Residuals (coupler point minus target, x then y; then the link ratio's excess, weighted as the search weighs a
    broken constraint; then, when ``floor`` (rad) is above 0, one per target: how far the squared sine of the
    transmission angle there is below ``sin(floor)^2``, weighted by :data:`TOGGLE_WEIGHT`) of
    :func:`polish_positions`'s variables and their Jacobian by complex step (exact to rounding: 11 evaluations, the
    later targets' turns perturbed at once as each moves its own target only)."""
    n = len(t)
    w = 10.0 * math.sqrt(n) if math.isfinite(max_ratio) else 0.0
    s2 = math.sin(floor) ** 2
    m = 2 * n + 1 + (n if floor > 0 else 0)

    def barrier(sin2: Any) -> Any:  # below the floor only: piecewise analytic, complex steps pass
        x = s2 - sin2
        return TOGGLE_WEIGHT * np.where(np.real(x) > 0, x, 0.0 * x)

    def resid(z: Array) -> Array:
        with np.errstate(invalid="ignore", divide="ignore"):
            x, y, sin2 = _poses(z[:10], z[10:], circuit)
            parts = [x - t[:, 0], y - t[:, 1], [w * _ratio_excess(z, max_ratio) if w else 0.0]]
            if floor > 0:
                parts.append(barrier(sin2))
            r = np.concatenate(parts)
        return r if np.isfinite(r).all() else np.full(m, 10.0)  # the loop does not close: far

    def jac(z: Array) -> Array:
        h = 1e-30
        Z = np.repeat(z[None, :].astype(complex), 11, axis=0)
        Z[np.arange(10), np.arange(10)] += 1j * h
        Z[10, 10:] += 1j * h
        J = np.zeros((m, len(z)))
        i = np.arange(1, n)
        with np.errstate(invalid="ignore", divide="ignore"):  # the 11 perturbed evaluations as one batch
            x, y, sin2 = _poses(tuple(Z[:, j : j + 1] for j in range(10)), Z[:, 10:], circuit)
            cols = np.concatenate([x.imag, y.imag], axis=1) / h  # (11, 2 n)
            if floor > 0:
                g = barrier(sin2).imag / h
                J[2 * n + 1 :, :10] = g[:10].T
                J[2 * n + 1 + i, 9 + i] = g[10, 1:]
        J[: 2 * n, :10] = cols[:10].T
        J[i, 9 + i], J[n + i, 9 + i] = cols[10, 1:n], cols[10, n + 1 :]
        if w and float(np.real(_ratio_excess(z, max_ratio))) > 0:  # else its derivative is 0
            J[2 * n, :10] = [w * np.imag(_ratio_excess(Z[k], max_ratio)) / h for k in range(10)]
        return np.nan_to_num(J, nan=0.0, posinf=0.0, neginf=0.0)

    return resid, jac


#: geodesic acceleration: the finite-difference step along the velocity, and the largest ratio of the
#: acceleration's to the velocity's size accepted (Transtrum and Sethna's recommended 0.1 and 0.75)
GEODESIC_H, GEODESIC_ALPHA = 0.1, 0.75


def geodesic_lm(resid: Any, jac: Any, z: Array, iters: int, patience: int | None = None) -> tuple[Array, Array]:
    """Levenberg-Marquardt with geodesic acceleration (Transtrum and Sethna, 2011): each damped Gauss-Newton step
    (Marquardt's scaling, the largest diagonal of ``J^T J`` seen) gets a second-order correction along the curved
    valley, from one more residual evaluation; the step is taken only when that correction is small beside it.
    Returns the variables and residuals it ends at after at most ``iters`` accepted or refused steps, or, with
    ``patience``, once that many steps in a row were refused (the damping grown ``2^patience`` times or more: at a
    minimum whose residual is not 0, which targets no four-bar meets end at, every later step is refused until the
    damping passes 1e20, 80 steps or more)."""
    r = resid(z)
    f = float(r @ r)
    J = jac(z)
    lam = 1e-3
    D = np.zeros(len(z))
    refused = 0
    for _ in range(iters):
        if f <= 1e-30 or lam > 1e20 or (patience is not None and refused >= patience):
            break
        refused += 1  # until this step is taken
        A, g = J.T @ J, J.T @ r
        D = np.maximum(D, np.diag(A))
        M = A + lam * np.diag(np.maximum(D, 1e-300))
        try:
            v = -np.linalg.solve(M, g)
            rh = resid(z + GEODESIC_H * v)
            acc = -0.5 * np.linalg.solve(M, J.T @ ((2.0 / GEODESIC_H) * ((rh - r) / GEODESIC_H - J @ v)))
        except np.linalg.LinAlgError:
            lam *= 10.0
            continue
        if 2.0 * math.sqrt(acc @ (D * acc)) > GEODESIC_ALPHA * math.sqrt(v @ (D * v)):
            lam *= 2.0
            continue
        rn = resid(z + v + acc)
        fn = float(rn @ rn)
        if fn < f:
            z, r, f = z + v + acc, rn, fn
            lam = max(lam / 3.0, 1e-12)
            J = jac(z)
            refused = 0
        else:
            lam *= 2.0
    return z, r


def polish_positions(
    t: Array,
    row: Array,
    theta: Array,
    iters: int = POLISH_ITERS,
    max_ratio: float = 10.0,
    floor: float = 0.0,
    patience: int | None = None,
) -> tuple[Array, Array]:
    """A refined kernel row and its input angles at the targets ``t`` (normalised), polished in the joints'
    positions (:func:`joint_positions`: the pivots and moving joints at the first target's pose, the input's turn
    to each later target; the coupler's and rocker's lengths are the loop-closure equations inside
    :func:`positions_points`) by :func:`geodesic_lm` with an exact Jacobian.

    A rocking four-bar's arc is short and smooth: in the kernel's lengths and angles the four-bars within 1e-5 of
    it lie along a long, curved, narrow valley (condition numbers 1e6 to 1e9), where Levenberg-Marquardt with a
    difference Jacobian crawls.  ``floor`` (rad, 0 for none): the transmission angle at the targets is kept this far
    from a toggle by a penalty (the rocking search's: its refinements otherwise end at a toggle, where the arc
    turns back and fits the targets loosely).  ``patience``: :func:`geodesic_lm`'s (None: only ``iters`` ends it).
    Returns the row and angles (the input as given when nothing better is found)."""
    circuit = 1.0 if row[9] >= 0 else -1.0
    q, turn = joint_positions(row, theta)
    resid, jac = _positions_problem(np.asarray(t, float), circuit, max_ratio, floor)
    z0 = np.concatenate([q, turn])
    r0 = resid(z0)
    z, r = geodesic_lm(resid, jac, z0, iters, patience)
    if not float(r @ r) < float(r0 @ r0):
        return row, theta
    return row_from_positions(z[:10], z[10:], circuit)
