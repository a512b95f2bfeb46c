"""Triads: Assur groups of class III, solved by Newton iteration with continuation.

A triad is a ternary link carrying three nodes ``T1, T2, T3`` (at
``local`` coordinates in its own frame), each joined by a binary link of
length ``ra`` to a node ``a`` placed before the triad (the ground, a crank
pin, a dyad).  Its loop cannot be closed dyad by dyad: the three nodes are
placed together.  The first of them (kind ``"triad"`` with ``members``)
names the other two, which are declared after it with kind ``"triad"`` and no
``members``; every outer node ``a`` must be declared before the first.  A
Stephenson six-bar whose crank drives a binary link of the ternary coupler
is one.

Unknowns are the ternary link's pose ``(x, y, phi)``; the equations
``|T_i - A_i|^2 = ra_i^2`` are solved by Newton's method (analytic 3x3
Jacobian, ``numpy.linalg.solve`` batched over samples).

**Branch.**  ``at`` gives each node's position (roughly) at driver value 0:
the assembly Newton reaches from there is the declared one (a linkage with a
triad declares its branches at driver value 0, so a path starting elsewhere
is led in from 0, as a four-bar's is from its reference).  Along a path (see
:func:`~planar.linkages.nodes.path_mask`) each sample takes the assembly
Newton reaches from the previous valid sample's: sequential continuation,
computed in blocks (the block is solved at once from a tangent prediction,
then every sample is checked to be what Newton from its predecessor gives;
the first that is not is replaced by that, and the next block starts there),
so a smooth path costs a few vectorised passes.  A scattered batch takes the
assembly reached from ``at`` at every sample.

**Failures** are invalid samples with the reason: Newton does not converge
(the loop cannot close), the Jacobian is singular (a dead centre), or the
solution jumps to another branch (a step from the last valid sample, per
sample, more than 10x the steps of the valid samples either side; after a
dead centre the assembly Newton finds may be another branch: that first sample
is flagged, and the path continues from it).  An invalid sample holds the last
valid pose.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from typing import ClassVar, cast

import numpy as np
from numpy.typing import NDArray

from planar.core.model import check_point, check_positive
from planar.errors import InputError
from planar.linkages.nodes import Check, Mask, NodeKind, Vec, node_kind

__all__ = ["Triad", "solve_triad"]

Array = NDArray[np.float64]

#: Newton stops when every link length is met to this fraction of the triad's scale
NEWTON_TOL = 1e-13
#: a sample is valid when its lengths are met to this fraction of the scale
VALID_TOL = 1e-9
#: a step larger than this many times both neighbouring steps is a jump to another branch
JUMP_FACTOR = 10.0


def _frame(S: Array, u: Array) -> tuple[Array, Array]:
    """Node positions ``(N, 3, 2)`` and their derivatives by ``phi`` for poses ``u`` ``(N, 3)``."""
    c, s = np.cos(u[:, 2])[:, None], np.sin(u[:, 2])[:, None]
    rx = c * S[None, :, 0] - s * S[None, :, 1]
    ry = s * S[None, :, 0] + c * S[None, :, 1]
    T = np.stack([u[:, None, 0] + rx, u[:, None, 1] + ry], -1)
    dT = np.stack([-ry, rx], -1)
    return T, dT


def _residual(K: Array, u: Array, L: Array, S: Array) -> tuple[Array, Array]:
    """``F`` ``(N, 3)`` (squared length errors) and the Jacobian ``(N, 3, 3)`` by ``x, y, phi``."""
    T, dT = _frame(S, u)
    D = T - K
    F = (D * D).sum(-1) - L * L
    J = np.empty(F.shape + (3,))
    J[:, :, :2] = 2.0 * D
    J[:, :, 2] = 2.0 * (D * dT).sum(-1)
    return F, J


def _newton(
    K: Array, u0: Array, L: Array, S: Array, scale: float, iters: int = 50
) -> tuple[Array, NDArray[np.bool_], NDArray[np.bool_]]:
    """Newton from ``u0`` for every row at once: ``(u, converged, singular)``."""
    u = np.array(u0, float, copy=True)
    n = u.shape[0]
    active = np.ones(n, bool)
    sing = np.zeros(n, bool)
    tol = NEWTON_TOL * scale
    for _ in range(iters):
        idx = np.flatnonzero(active)
        if idx.size == 0:
            break
        F, J = _residual(K[idx], u[idx], L, S)
        err = (np.abs(F) / (2.0 * L)).max(1)
        done = err <= tol
        det = np.linalg.det(J)
        bad = ~done & ~(np.abs(det) > 1e-12 * scale**4)
        go = ~done & ~bad
        if go.any():
            step = np.linalg.solve(J[go], F[go][:, :, None])[:, :, 0]
            # damped: at most a quarter of the scale and half a radian per iteration
            f = np.minimum(
                1.0,
                np.minimum(
                    0.25 * scale / np.maximum(np.hypot(step[:, 0], step[:, 1]), 1e-300),
                    0.5 / np.maximum(np.abs(step[:, 2]), 1e-300),
                ),
            )
            u[idx[go]] -= f[:, None] * step
        active[idx[done | bad]] = False
        sing[idx[bad]] = True
    F, _ = _residual(K, u, L, S)
    conv = (np.abs(F) / (2.0 * L)).max(1) <= VALID_TOL * scale
    return u, conv & ~sing, sing & ~conv


def _pose_distance(a: Array, b: Array, scale: float) -> Array:
    d = np.remainder(a[:, 2] - b[:, 2] + np.pi, 2 * np.pi) - np.pi
    return np.hypot(np.hypot(a[:, 0] - b[:, 0], a[:, 1] - b[:, 1]), scale * d)


def solve_triad(
    K: Array, L: Array, S: Array, u_ref: Array, cont: NDArray[np.bool_], scale: float
) -> tuple[Array, NDArray[np.bool_], NDArray[np.int8]]:
    """Ternary-link poses ``(N, 3)`` for outer nodes ``K`` ``(N, 3, 2)``, validity, and why (codes).

    ``cont[k]``: sample ``k`` continues sample ``k - 1`` (a path); the other
    samples start from ``u_ref``.  Codes: 0 valid, 1 no convergence, 2
    singular Jacobian, 3 jump to another branch.
    """
    n = K.shape[0]
    # the samples that start from the declared assembly (the first, and every one of a scattered batch)
    first = ~np.asarray(cont, bool).copy()
    first[0] = True
    u = np.broadcast_to(u_ref, (n, 3)).copy()
    ok = np.zeros(n, bool)
    code = np.ones(n, np.int8)
    u[first], ok[first], sing = _newton(K[first], u[first], L, S, scale)
    code[first] = np.where(ok[first], 0, np.where(sing, 2, 1))
    ks = np.flatnonzero(~first)
    block = 8
    i = 0
    while i < ks.size:
        p = int(ks[i])
        # the run of continued samples starting at p
        j = i
        while j + 1 < ks.size and ks[j + 1] == ks[j] + 1 and j + 1 - i < block:
            j += 1
        rows = ks[i : j + 1]
        base = p - 1
        while base >= 0 and not ok[base]:
            base -= 1
        ub = u[base] if base >= 0 else u_ref
        if base != p - 1:
            # after an invalid sample every sample continues the last valid one until one closes: all at once
            z, zok, zsing = _newton(K[rows], np.broadcast_to(ub, (rows.size, 3)), L, S, scale)
            m = int(np.argmax(zok)) if zok.any() else rows.size
            u[rows[:m]] = ub
            ok[rows[:m]] = False
            code[rows[:m]] = np.where(zsing[:m], 2, 1)
            if m < rows.size:
                u[rows[m]], ok[rows[m]], code[rows[m]] = z[m], True, 0
                m += 1
            i += m
            block = min(2 * block, 4096)
            continue
        # tangent prediction from the two previous valid samples, when they are neighbours
        slope = np.zeros(3)
        if base >= 1 and ok[base - 1] and base == p - 1:
            slope = u[base] - u[base - 1]  # one sample's step
            slope[2] = np.remainder(slope[2] + np.pi, 2 * np.pi) - np.pi
        seed = ub[None, :] + np.arange(1, rows.size + 1)[:, None] * slope[None, :]
        w, wok, _wsing = _newton(K[rows], seed, L, S, scale)
        # each sample must be what Newton from its predecessor gives
        prev = np.vstack([ub[None, :], w[:-1]])
        y, yok, ysing = _newton(K[rows], prev, L, S, scale)
        agree = wok & yok & (_pose_distance(w, y, scale) <= 1e-7 * scale)
        m = int(np.argmin(agree)) if not agree.all() else rows.size
        if m:
            u[rows[:m]] = w[:m]
            ok[rows[:m]] = True
            code[rows[:m]] = 0
            i += m
            block = min(2 * block, 4096) if m == rows.size else block
            continue
        # the first sample: sequential continuation exactly
        r = rows[0]
        if yok[0]:
            u[r], ok[r], code[r] = y[0], True, 0
        else:
            u[r], ok[r], code[r] = ub, False, (2 if ysing[0] else 1)
        block = max(8, block // 2)
        i += 1
    # a jump to another branch: a step (per sample, from the last valid one) much larger than the steps of
    # the valid samples either side
    if n >= 3 and ks.size:
        idx = np.arange(n)
        last = np.maximum.accumulate(np.where(ok, idx, -1))
        prev = np.concatenate([[-1], last[:-1]])
        after = np.minimum.accumulate(np.where(ok, idx, n)[::-1])[::-1]
        nxt = np.concatenate([after[1:], [n]])
        kk = np.flatnonzero(ok & (prev >= 0) & cont)
        dist = np.zeros(n)
        rate = np.full(n + 1, np.nan)
        dist[kk] = _pose_distance(u[kk], u[prev[kk]], scale)
        rate[kk] = dist[kk] / (kk - prev[kk])
        before_rate = np.where(prev >= 0, rate[np.maximum(prev, 0)], np.nan)
        after_rate = rate[nxt]
        with np.errstate(invalid="ignore"):
            big = (rate[:n] > JUMP_FACTOR * np.fmax(before_rate, after_rate)) & (dist > 1e-3 * scale)
        big &= np.isfinite(before_rate) | np.isfinite(after_rate)
        ok &= ~big
        code[big] = 3
    return u, ok, code


_WHY = {
    1: "Newton found no assembly (the loop cannot close)",
    2: "its Jacobian is singular (a dead centre)",
    3: "the solution jumped to another branch",
}


@node_kind
@dataclass(frozen=True)
class Triad(NodeKind):
    """One node of a triad: ``ra`` from node ``a``, at ``local`` on the ternary link; ``at``: near it at driver 0."""

    kind: ClassVar[str] = "triad"
    length_fields: ClassVar[tuple[str, ...]] = ("ra",)
    point_fields: ClassVar[tuple[str, ...]] = ("local", "at")
    scene_fields: ClassVar[tuple[str, ...]] = ("a", "ra", "local", "at", "members")
    #: the keys every triad node gives (``members`` only the first of the three)
    required_fields: ClassVar[tuple[str, ...]] = ("a", "ra", "local", "at")
    #: declares its branch at driver value 0 (the linkage leads a path in from there)
    continued: ClassVar[bool] = True
    name: str
    a: str
    ra: float
    local: Vec
    at: Vec
    members: tuple[str, ...] | None = None
    #: on the first node, once bound: the three nodes, itself first
    group: tuple[Triad, ...] = field(default=(), compare=False, repr=False)

    def refs(self) -> tuple[str, ...]:
        return (self.a,)

    def validate(self, where: str) -> None:
        check_positive(f"{where}.ra", self.ra)
        check_point(f"{where}.local", self.local)
        check_point(f"{where}.at", self.at)
        if not isinstance(self.group, tuple) or not all(isinstance(g, Triad) for g in self.group):
            raise InputError(f"{where}.group", self.group, "a tuple of Triad (the triad's other members, or ())")
        if self.members is not None:
            if not isinstance(self.members, (tuple, list)) or not all(isinstance(m, str) for m in self.members):
                raise InputError(f"{where}.members", self.members, "the two other nodes of the triad (a list of two names)")
            ms = tuple(self.members)
            if len(ms) != 2 or len(set(ms)) != 2 or self.name in ms:
                raise InputError(f"{where}.members", list(ms), "the two other nodes of the triad")

    def held_by(self) -> tuple[tuple[str, ...], ...]:
        if self.members:
            return ((self.name, self.a), (self.name,) + tuple(self.members))
        return ((self.name, self.a),)

    def bind(self, where: str, nodes: Mapping[str, NodeKind]) -> NodeKind:
        order = {k: i for i, k in enumerate(nodes)}
        if not self.members:
            leaders = [n for n in nodes.values() if isinstance(n, Triad) and n.members and self.name in n.members]
            if len(leaders) != 1:
                raise InputError(
                    where,
                    self.name,
                    f"a triad node named in the members of exactly one triad node declared before it (found {len(leaders)})",
                )
            return self
        group = [self]
        for m in self.members:
            node = nodes.get(m)
            if not isinstance(node, Triad) or node.members:
                raise InputError(f"{where}.members", m, "a node of kind 'triad' without members, declared after it")
            if order[m] < order[self.name]:
                raise InputError(f"{where}.members", m, f"a node declared after {self.name!r} (the triad's first)")
            if order[node.a] > order[self.name]:
                raise InputError(
                    f"{where}.members",
                    m,
                    f"a member whose node {node.a!r} is declared before {self.name!r} (the triad is placed there)",
                )
            group.append(node)
        S = np.array([g.local for g in group], float)
        area = (S[1, 0] - S[0, 0]) * (S[2, 1] - S[0, 1]) - (S[1, 1] - S[0, 1]) * (S[2, 0] - S[0, 0])
        size = max(float(np.ptp(S, axis=0).max()), 1e-300)
        if abs(area) <= 1e-9 * size * size:
            raise InputError(
                f"{where}.local", [list(g.local) for g in group], "three local points of the ternary link not on one line"
            )
        return replace(self, group=tuple(group))

    # -- solving ------------------------------------------------------------
    def _data(self) -> tuple[Array, Array, Array, float]:
        S = np.array([g.local for g in self.group], float)
        L = np.array([g.ra for g in self.group], float)
        AT = np.array([g.at for g in self.group], float)
        # the pose that best maps the local points onto ``at`` (least squares)
        sc, ac = S - S.mean(0), AT - AT.mean(0)
        phi = float(np.arctan2((sc[:, 0] * ac[:, 1] - sc[:, 1] * ac[:, 0]).sum(), (sc * ac).sum()))
        c, s = np.cos(phi), np.sin(phi)
        x = AT.mean(0) - np.array([c * S[:, 0].mean() - s * S[:, 1].mean(), s * S[:, 0].mean() + c * S[:, 1].mean()])
        scale = float(L.max() + np.hypot(S[:, 0], S[:, 1]).max())
        return S, L, np.array([x[0], x[1], phi]), scale

    def position(self, pos: Mapping[str, Array], q: Array, path: Mask) -> tuple[Array, Check | None]:
        if not self.members:
            if self.name not in pos:
                raise RuntimeError(f"triad node {self.name!r} solved before its group's first node")
            return pos[self.name], None
        from planar.linkages.nodes import path_mask

        S, L, u_ref, scale = self._data()
        K = np.stack([np.broadcast_to(pos[g.a], (q.shape[0], 2)) for g in self.group], 1)
        n = q.shape[0]
        cont = np.zeros(n, bool)
        if n >= 4:
            pm = path_mask(q)
            cont[1:] = pm[1:]
            cont[1:4] = pm[3]
        u, ok, code = solve_triad(K, L, S, u_ref, cont, scale)
        T, _ = _frame(S, u)
        out = cast(dict, pos)  # the first node places its members too
        for k, g in enumerate(self.group[1:], 1):
            out[g.name] = T[:, k]
        kinds = [v for c, v in _WHY.items() if (code == c).any()]
        names = ", ".join(repr(g.name) for g in self.group)
        why = f"the triad {names}: " + ("; ".join(kinds) if kinds else "cannot close")
        return T[:, 0], (ok, why)

    _PAIRS: ClassVar[tuple[tuple[int, int], ...]] = ((0, 1), (1, 2), (0, 2))

    def _rates(self, pos: Mapping[str, Array], b: Array, out: Mapping[str, Array]) -> tuple[Array, Mask]:
        """Solve the differentiated closure ``M x = b`` (six equations, see :meth:`velocity`) into ``out``."""
        T = [pos[g.name] for g in self.group]
        n = T[0].shape[0]
        M = np.zeros((n, 6, 6))
        for i, g in enumerate(self.group):
            M[:, i, 2 * i : 2 * i + 2] = T[i] - pos[g.a]
        for r, (i, j) in enumerate(self._PAIRS, 3):
            d = T[i] - T[j]
            M[:, r, 2 * i : 2 * i + 2] = d
            M[:, r, 2 * j : 2 * j + 2] = -d
        scale = self._data()[3]
        ok: Mask = np.abs(np.linalg.det(M)) > 1e-12 * scale**6
        M[~ok] = np.eye(6)
        x = np.asarray(np.linalg.solve(M, b[:, :, None])[:, :, 0], dtype=np.float64)
        dest = cast(dict, out)  # the first node places its members' rates too
        for k, g in enumerate(self.group[1:], 1):
            dest[g.name] = x[:, 2 * k : 2 * k + 2]
        return x[:, :2], ok

    def velocity(self, pos: Mapping[str, Array], vel: Mapping[str, Array], qd: Array) -> tuple[Array, Mask | None]:
        if not self.members:
            return vel[self.name], None
        # (T_i - A_i) . (v_i - vA_i) = 0 and (T_i - T_j) . (v_i - v_j) = 0: six equations in v_1..v_3
        n = pos[self.name].shape[0]
        b = np.zeros((n, 6))
        for i, g in enumerate(self.group):
            b[:, i] = ((pos[g.name] - pos[g.a]) * vel[g.a]).sum(-1)
        return self._rates(pos, b, vel)

    def acceleration(
        self, pos: Mapping[str, Array], vel: Mapping[str, Array], acc: Mapping[str, Array], qd: Array, qdd: Array
    ) -> tuple[Array, Mask | None]:
        if not self.members:
            return acc[self.name], None
        # differentiated again: (T_i - A_i) . (a_i - aA_i) + |v_i - vA_i|^2 = 0,
        # (T_i - T_j) . (a_i - a_j) + |v_i - v_j|^2 = 0
        n = pos[self.name].shape[0]
        b = np.zeros((n, 6))
        for i, g in enumerate(self.group):
            dv = vel[g.name] - vel[g.a]
            b[:, i] = ((pos[g.name] - pos[g.a]) * acc[g.a]).sum(-1) - (dv * dv).sum(-1)
        for r, (i, j) in enumerate(self._PAIRS, 3):
            dv = vel[self.group[i].name] - vel[self.group[j].name]
            b[:, r] = -(dv * dv).sum(-1)
        return self._rates(pos, b, acc)
