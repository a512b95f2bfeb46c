"""A general pivot/slot linkage: node kinds (:mod:`planar.linkages.nodes`) carried by links.

A linkage is a list of *nodes* (joint centres), each placed in closed form from
nodes declared before it, and a list of *links* (rigid parts) naming the nodes
they carry.  A link's frame has its origin at its first node and its x axis
toward its second; a link with one node and a ``guide`` ``(p, q)`` keeps the
guide line's direction (a slider block).  Joints follow from the declaration:
a node shared by links is a pivot; an RRP node is a pin in a straight slot of
the link that carries the line; a guided link is a block sliding along the
line of the link that carries ``p`` and ``q``, which may itself move (the
inverted slider-crank family: a quick return's block in its slotted lever, an
oscillating cylinder's piston).  Each link is checked to be rigid: nodes on
one link that move relative to each other are refused when the linkage is
built.

Every node is solved for all driver values at once (no per-sample loop),
branches carried as :mod:`planar.linkages.nodes` describes.
:meth:`Linkage.solve` takes the compiled (or chunked numpy) path of
:mod:`planar.linkages.chunked`, which gives the same motion and hands a batch
to the reference solve here (:meth:`Linkage.solve_nodes`) wherever a branch
may switch by continuity.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

from planar.core.buffers import MIN_BYTES
from planar.core.buffers import block as new_block
from planar.core.geometry import poses_apply, poses_compose, poses_invert
from planar.core.limits import check_resolution, limit, resolution_terms
from planar.core.model import (
    Driver,
    FinitePoses,
    Mechanism,
    Motion,
    Part,
    PinInSlot,
    Pivot,
    Slide,
    check_finite,
    check_positive,
    check_samples,
    merge_failures,
)
from planar.core.rates import PartRates, RatesResult, rotate_vectors
from planar.errors import AssemblyError, InputError
from planar.linkages.chunked import Solved, _Plan, compiled_ready, fast_solve, plan_for, solve_compiled
from planar.linkages.nodes import NODE_KINDS, RRP, Actuator, Crank, Fixed, Mask, NodeKind, Vec, _cross, frame_rates, path_mask

__all__ = ["LEAD_MAX", "Link", "Linkage"]

Array = NDArray[np.float64]


@dataclass(frozen=True)
class Link:
    """A rigid part carrying ``nodes``; ``guide`` ``(p, q)`` makes it a block sliding along that line."""

    name: str
    nodes: tuple[str, ...]
    guide: tuple[str, str] | None = None

    def __post_init__(self) -> None:
        from planar.core.model import _check_name

        _check_name("Link.name", self.name)
        nodes = self.nodes
        if isinstance(nodes, (str, bytes)) or not isinstance(nodes, (tuple, list)) or not all(isinstance(n, str) for n in nodes):
            raise InputError(f"Link {self.name!r}.nodes", self.nodes, "a sequence of node names (('O', 'A'), not 'OA')")
        if not nodes or len(set(nodes)) != len(nodes):
            raise InputError(f"Link {self.name!r}.nodes", self.nodes, "one or more node names, each once")
        guide = self.guide
        if guide is not None and (
            not isinstance(guide, (tuple, list)) or len(guide) != 2 or not all(isinstance(n, str) for n in guide)
        ):
            raise InputError(f"Link {self.name!r}.guide", guide, "two node names (p, q) the block slides along, or None")


#: most steps of a lead-in (:meth:`Linkage._lead_in`)
LEAD_MAX = 4096


def _lead_steps(h: float, h_max: float, span: float) -> Array:
    """Distances before the path's first sample of a lead-in's samples, farthest first.

    The steps start at ``h`` and grow 1.4x per sample up to ``h_max``; they
    stop once they cover ``span`` (or after :data:`LEAD_MAX` steps).  Array
    operations only, with the same products and sums, in the same order, as
    the sample-by-sample recurrence ``step = min(1.4 step, h_max)``, ``total
    += step`` (a running product and a running sum are sequential in numpy).
    """
    # steps while growing: h 1.4^k < h_max; then h_max until the span is covered
    grow = 1 if h >= h_max else min(LEAD_MAX, 2 + int(math.log(h_max / h) / math.log(1.4)))
    size = min(LEAD_MAX, grow + 1 + int(span / h_max))
    while True:
        factors = np.full(size, 1.4)
        factors[0] = h
        with np.errstate(over="ignore"):  # the running product may pass float64's range: capped at h_max
            steps = np.minimum(np.multiply.accumulate(factors), h_max)
        total = np.add.accumulate(steps)
        if total[-1] >= span or size == LEAD_MAX:
            break
        size = min(LEAD_MAX, 2 * size)  # rounding left the estimate short
    k = int(np.searchsorted(total, span, side="left")) + 1  # the first step that reaches the span, included
    back = total[: min(k, size)]  # distances before q[0], nearest first
    return back[::-1]


class Linkage(Mechanism):
    """A single-input planar linkage of pivots and slots, solved in closed form.

    ``placement`` ``(x, y, angle)`` places the whole linkage in the world
    (the linkage is solved in its own frame, then transformed).  ``width``
    and ``pin_diameter`` size the parts' outlines (default: 8 % and 3 % of
    the linkage's span).  ``points`` maps names to node names.  A driver that
    rocks instead of turning: ``amplitude`` and ``centre`` (rad or units), so
    the input is ``centre + amplitude sin(rate t + phase)``.

    ``ground`` names the ground part (the frame that never moves): a link of that name among ``links``, whose
    nodes must all stay still (a link carrying the crank's moving end is refused), or, when no link has that
    name, the part made of the ``Fixed`` nodes, given that name (so any name is accepted: ``ground="frame"``
    names the frame part ``frame``).  It names a part, not a node.
    """

    def __init__(
        self,
        name: str,
        nodes: Sequence[NodeKind],
        links: Sequence[Link],
        points: Mapping[str, str] | None = None,
        placement: Sequence[float] = (0.0, 0.0, 0.0),
        rate: float = 2.0 * np.pi,
        phase: float = 0.0,
        amplitude: float | None = None,
        centre: float = 0.0,
        width: float | None = None,
        pin_diameter: float | None = None,
        ground: str = "ground",
    ) -> None:
        from planar.core.model import _check_name

        _check_name("Linkage.name", name)
        _check_name(f"{name}.ground", ground)
        for arg, seq, cls in (("nodes", nodes, NodeKind), ("links", links, Link)):
            if isinstance(seq, (str, bytes)) or not hasattr(seq, "__iter__"):
                raise InputError(f"{name}.{arg}", seq, f"a list of {cls.__name__} objects")
            bad = next((x for x in seq if not isinstance(x, cls)), None)
            if bad is not None:
                raise InputError(f"{name}.{arg}", bad, f"a list of {cls.__name__} objects (planar.linkages)")
        if points is not None and not isinstance(points, Mapping):
            raise InputError(f"{name}.points", points, "a dict of point name -> node name (or None)")
        self.name = name
        self.nodes: tuple[NodeKind, ...] = tuple(nodes)
        pl = check_finite(f"{name}.placement", placement)
        if pl.shape != (3,):
            raise InputError(f"{name}.placement", placement, "(x, y, angle): three numbers")
        self.placement = tuple(float(v) for v in pl)
        self._validate_nodes(name)
        self._check_node_resolution(name)
        bound: dict[str, NodeKind] = {n.name: n for n in self.nodes}
        for n in self.nodes:
            bound[n.name] = n.bind(f"{name}.nodes.{n.name}", bound)
        self.nodes = tuple(bound.values())
        if any(getattr(n, "continued", False) for n in self.nodes):
            self.branch_reference = 0.0  # a triad's declared assembly holds at driver value 0
        clocked = [n.name for n in self.nodes if getattr(n, "clocked", False)]
        if clocked and amplitude is not None:
            raise InputError(
                f"{name}.driver.amplitude",
                amplitude,
                f"no amplitude: with driven nodes ({', '.join(clocked)}) the driver is a clock "
                "(phase + rate t); give each driven node its own amplitude",
            )
        self.ground_name = ground
        self.links = self._with_ground(tuple(links), ground)
        self._validate_links(name)
        self._check_held(name)
        inputs = [n for n in self.nodes if n.is_input]
        if not inputs:
            raise InputError(f"{name}.nodes", [n.name for n in self.nodes], "one crank or actuator node as the input")
        self._driver_node = inputs[0]
        driver_link = self._link_of(self._driver_node.name, exclude_ground=True)
        byname = {n.name: n for n in self.nodes}
        make = getattr(self._driver_node, "make_driver", None)
        if make is not None:
            c = byname[self._driver_node.centre]  # type: ignore[attr-defined]
            driver = make(driver_link, c.xy if isinstance(c, Fixed) else (0.0, 0.0), rate, phase)
        elif isinstance(self._driver_node, Crank):
            c = byname[self._driver_node.centre]
            origin = c.xy if isinstance(c, Fixed) else (0.0, 0.0)
            driver = Driver(driver_link, "rotation", origin=origin, rate=rate, phase=phase, amplitude=amplitude, centre=centre)
        else:
            ax = np.asarray(getattr(self._driver_node, "axis", (1.0, 0.0)), float)
            driver = Driver(
                driver_link,
                "translation",
                axis=(float(ax[0] / np.hypot(*ax)), float(ax[1] / np.hypot(*ax))),
                rate=rate,
                phase=phase,
                amplitude=amplitude if amplitude is not None else 1.0,
                centre=centre,
            )
        self.driver = driver
        # one sweep of the driver's cycle: the reference configuration, rigidity, slot travel
        self._sweep_q = self._cycle_inputs(driver)
        self._sweep_pos, sweep_ok = self._solve_valid(self._sweep_q)
        if not sweep_ok.any():
            _, checks = self.solve_nodes(self._sweep_q)
            joint, why = next(((j, w) for m, j, w in checks if not m.any()), (checks[0][1], checks[0][2]))
            raise AssemblyError(f"{name}: cannot be assembled at any driver value: joint {joint!r}: {why}")
        self._sweep_ok = sweep_ok
        k_ref = int(np.argmax(sweep_ok))
        self._ref_nodes = {k: v[k_ref] for k, v in self._sweep_pos.items()}
        self._check_rigid(name)
        self._check_ground_still(name)
        span = self._span()
        self.width = check_positive(f"{name}.width", width) if width is not None else 0.08 * span
        self.pin_diameter = check_positive(f"{name}.pin_diameter", pin_diameter) if pin_diameter is not None else 0.03 * span
        self._anchors = self._local_anchors()
        parts, joints = self._build_parts_and_joints()
        pts = {}
        #: named point -> the node that defines it
        self.point_nodes: dict[str, str] = dict(points or {})
        for pname, node in self.point_nodes.items():
            if node not in byname:
                raise InputError(f"{name}.points.{pname}", node, f"a node name, one of {list(byname)}")
            link = self._link_of(node, exclude_ground=False)
            pts[pname] = (link, self._anchors[link][node])
        super().__init__(name, parts, joints, driver, pts)

    # -- validation ---------------------------------------------------------
    def _validate_nodes(self, name: str) -> None:
        seen: set[str] = set()
        for n in self.nodes:
            where = f"{name}.nodes.{getattr(n, 'name', '?')}"
            cls = type(n)
            kname = cls.__dict__.get("kind")
            if not isinstance(kname, str) or NODE_KINDS.get(kname) is not cls:
                raise InputError(where, cls.__name__, f"a registered node kind, one of {sorted(NODE_KINDS)}")
            if n.name in seen:
                raise InputError(where, n.name, "a node name used once")
            for r in n.refs():
                if r == n.name:
                    n.validate(where)  # its own words first (a gear meshing with itself says so)
                    raise InputError(where, r, "another node (a node cannot refer to itself)")
                if r not in seen:
                    raise InputError(where, r, "a node declared before it")
            n.validate(where)
            seen.add(n.name)

    def _check_node_resolution(self, name: str) -> None:
        """Refuse a node's length or coordinate (or the placement) that float64 resolves coarser than
        :data:`~planar.core.limits.RESOLUTION` of the linkage's smallest length, before it is solved: a far
        ``Fixed`` node or an ``RRR`` link of 1e300 beside 1-unit links would otherwise be solved into noise
        (or refused for a reason it does not have)."""
        terms = [t for n in self.nodes for t in resolution_terms(n, f"{name}.nodes.{n.name}")]
        x, y, _ = self.placement
        terms.append((f"{name}.placement", self.placement, max(abs(x), abs(y)), False))
        check_resolution(terms, "linkage")

    def _with_ground(self, links: tuple[Link, ...], ground: str) -> tuple[Link, ...]:
        if any(lk.name == ground for lk in links):
            return links
        fixed = tuple(n.name for n in self.nodes if isinstance(n, Fixed))
        return (Link(ground, fixed),) + links

    def _validate_links(self, name: str) -> None:
        names = {n.name for n in self.nodes}
        seen: set[str] = set()
        for lk in self.links:
            where = f"{name}.links.{lk.name}"
            if lk.name in seen:
                raise InputError(where, lk.name, "a link name used once")
            seen.add(lk.name)
            for n in lk.nodes:
                if n not in names:
                    raise InputError(f"{where}.nodes", n, f"a node name, one of {sorted(names)}")
            if len(set(lk.nodes)) != len(lk.nodes):
                raise InputError(f"{where}.nodes", lk.nodes, "each node once")
            if lk.name != self.ground_name and len(lk.nodes) < 2 and lk.guide is None:
                raise InputError(f"{where}.nodes", lk.nodes, "two or more nodes (or one node and a guide)")
            if lk.guide is not None:
                for g in lk.guide:
                    if g not in names:
                        raise InputError(f"{where}.guide", g, f"a node name, one of {sorted(names)}")
                if lk.guide[0] == lk.guide[1]:
                    raise InputError(f"{where}.guide", lk.guide, "two different nodes")
                self._guide_owner(lk)  # raises if no other link carries the guide line

    def _check_held(self, name: str) -> None:
        """Every node's constraint is held by a part: the nodes it is placed from share a link with it."""
        for n in self.nodes:
            for group in n.held_by():
                if not any(all(g in lk.nodes for g in group) for lk in self.links):
                    others = ", ".join(repr(g) for g in group if g != n.name)
                    raise InputError(
                        f"{name}.nodes.{n.name}",
                        n.name,
                        f"a link carrying {n.name!r} with {others} (the {n.kind} node is placed "
                        "from them; without that link no part holds it there)",
                    )

    def _guide_owner(self, lk: Link) -> str:
        """The link (not ``lk``) that carries both nodes of ``lk``'s guide line."""
        assert lk.guide is not None
        p, q = lk.guide
        for other in self.links:
            if other.name != lk.name and p in other.nodes and q in other.nodes:
                return other.name
        raise InputError(
            f"{self.name}.links.{lk.name}.guide",
            list(lk.guide),
            "two nodes carried by one other link (the link the block slides along)",
        )

    def _link_of(self, node: str, exclude_ground: bool) -> str:
        for lk in self.links:
            if exclude_ground and lk.name == self.ground_name:
                continue
            if node in lk.nodes:
                return lk.name
        raise InputError(f"{self.name}.links", node, "a link that carries this node")

    def _cycle_inputs(self, driver: Driver, n: int = 721) -> Array:
        """Driver values over one cycle of its law (a full turn for a turning crank)."""
        if driver.amplitude is None:
            return driver.phase + np.linspace(0.0, 2 * np.pi, n)
        return driver.value(np.linspace(0.0, driver.period, n))

    def _solve_valid(self, q: Array) -> tuple[dict[str, Array], Mask]:
        pos, checks = self.solve_nodes(q)
        ok = np.ones(q.shape, bool)
        for m, _, _ in checks:
            ok &= m
        return pos, ok

    def _check_rigid(self, name: str) -> None:
        """Refuse a link whose nodes move relative to each other over the driver's cycle."""
        ok = self._sweep_ok
        P = {k: v[ok] for k, v in self._sweep_pos.items()}
        tol = 1e-9 * self._span()
        for lk in self.links:
            nodes = list(lk.nodes)
            for i, a in enumerate(nodes):
                for b in nodes[i + 1 :]:
                    d = np.hypot(*(P[a] - P[b]).T)
                    change = float(d.max() - d.min())
                    if change > tol:
                        raise InputError(
                            f"{name}.links.{lk.name}",
                            nodes,
                            f"a rigid link: nodes {a!r} and {b!r} move relative to each other "
                            f"(their distance changes by {change:.4g}, from {d.min():.6g} to {d.max():.6g})",
                        )
            if lk.guide is not None and len(nodes) >= 2:
                g = P[lk.guide[1]] - P[lk.guide[0]]
                e = P[nodes[1]] - P[nodes[0]]
                turn = np.arctan2(_cross(g, e), (g * e).sum(-1))
                dev = float(np.ptp(np.unwrap(turn)))
                if dev > 1e-9:
                    raise InputError(
                        f"{name}.links.{lk.name}",
                        nodes,
                        f"a block that keeps its guide's direction: nodes {nodes[0]!r}-{nodes[1]!r} turn by "
                        f"{dev:.4g} rad against the guide {lk.guide[0]!r}-{lk.guide[1]!r}",
                    )

    def _check_ground_still(self, name: str) -> None:
        """Refuse a ``ground`` naming a link that carries a moving node: the ground part never moves, so the
        motion would hold that node still while the solver moves it (every sample marked valid, the joint open)."""
        ok = self._sweep_ok
        tol = 1e-9 * self._span()
        for lk in self.links:
            if lk.name != self.ground_name:
                continue
            for node in lk.nodes:
                moved = float(np.ptp(self._sweep_pos[node][ok], axis=0).max(initial=0.0))
                if moved > tol:
                    raise InputError(
                        f"{name}.ground",
                        self.ground_name,
                        f"a link whose nodes stay still, or a new name for the part the fixed nodes make: link "
                        f"{lk.name!r} carries node {node!r}, which moves by {moved:.4g} over the driver's cycle",
                    )

    # -- solving ------------------------------------------------------------
    #: driver value at which the declared branches hold (``None``: at the first sample); see
    #: :meth:`_lead_in` (a :class:`FourBar` declares its circuit with the crank at pi/2)
    branch_reference: float | None = None

    def _lead_in(self, q: Array) -> Array:
        """Driver values leading from :attr:`branch_reference` into the path ``q`` (empty if none applies).

        The lead-in runs toward ``q[0]`` in the path's direction (for a
        turning crank from the reference a whole number of turns away, less
        than one turn before ``q[0]``), with steps that shrink by at most 1.4x
        per sample down to the path's first step, so continuity carries the
        declared branch from the reference through every sample, ``q[0]``
        included even where it is singular.
        """
        ref = self.branch_reference
        if ref is None or q.shape[0] < 4 or not self._carries_branches() or not self._path(q[:4])[3]:
            return q[:0]
        q0, h = float(q[0]), float(q[1] - q[0])
        direction = 1.0 if h > 0 else -1.0
        if self.driver.kind == "rotation":
            turns = np.floor((q0 - ref) / (2 * np.pi)) if direction > 0 else np.ceil((q0 - ref) / (2 * np.pi))
            ref = ref + 2 * np.pi * turns
        span = (q0 - ref) * direction
        if span <= 0:
            return q[:0]
        return q0 - direction * _lead_steps(
            abs(h), max(abs(h), 2 * np.pi / 360 if self.driver.kind == "rotation" else abs(h)), span
        )

    def solve_nodes(self, q: Array, lead: Array | None = None) -> tuple[dict[str, Array], list[tuple[Mask, str, str]]]:
        """World positions ``(N, 2)`` of every node (before placement) and validity checks.

        The samples are a path in their order (see the module's note on branches).
        ``lead``: :meth:`_lead_in` of ``q`` when the caller has it already.
        """
        q = np.asarray(q, dtype=float)
        if lead is None:
            lead = self._lead_in(q)
        if lead.size == 0:
            return self._solve_nodes(q, self.nodes)
        k = lead.shape[0]
        pos, checks = self._solve_nodes(np.concatenate([lead, q]), self.nodes)
        return {n: v[k:] for n, v in pos.items()}, [(m[k:], j, w) for m, j, w in checks]

    def _carries_branches(self) -> bool:
        """Whether the motion may carry a branch by continuity at all (see :meth:`_path`)."""
        return True

    def _path(self, q: Array) -> Mask:
        """Where the samples are a path along which a branch may be carried (:func:`path_mask`); a subclass
        that knows its motion has no singular position returns no path (its declared branches hold)."""
        return path_mask(q)

    def _solve_nodes(self, q: Array, nodes: Sequence[NodeKind]) -> tuple[dict[str, Array], list[tuple[Mask, str, str]]]:
        path = self._path(q)
        pos: dict[str, Array] = {}
        checks: list[tuple[Mask, str, str]] = []
        for node in nodes:
            p, check = node.position(pos, q, path)
            pos[node.name] = p
            if check is not None:
                checks.append((check[0], node.name, check[1]))
        return pos, checks

    def _link_poses(self, pos: Mapping[str, Array], n: int) -> dict[str, Array]:
        poses: dict[str, Array] = {}
        for lk in self.links:
            if lk.name == self.ground_name:
                poses[lk.name] = np.zeros((n, 3))
                continue
            o = pos[lk.nodes[0]]
            d = pos[lk.guide[1]] - pos[lk.guide[0]] if lk.guide is not None else pos[lk.nodes[1]] - o
            poses[lk.name] = np.column_stack([o[:, 0], o[:, 1], np.arctan2(d[:, 1], d[:, 0])])
        return poses

    def _fast_plan(self) -> _Plan | None:
        """The chunked solver's plan (built on first use; ``None`` if a node kind has no chunk kernel)."""
        if "_plan" not in self.__dict__:
            self.__dict__["_plan"] = plan_for(self)
        plan: _Plan | None = self.__dict__["_plan"]
        return plan

    def _declared_branches_hold(self, q: Array, lead: Array) -> bool:
        """Whether the branch carried from :attr:`branch_reference` along ``lead`` is the declared one at ``q[0]``.

        The chunked path starts every dyad on its declared branch; where the
        lead-in from the reference arrives on the other one (a change-point
        four-bar starting past a flat position), the reference path is used.
        """
        if lead.size == 0:
            return True
        k = lead.shape[0]
        pos, checks = self._solve_nodes(np.concatenate([lead, q[:1]]), self.nodes)
        if not all(bool(m[k]) for m, _, _ in checks):
            return False
        for node in self.nodes:
            b = node.branch_of(pos)
            if b is not None and b != getattr(node, "branch", b):
                return False
        return True

    def solve(self, q: ArrayLike, t: ArrayLike | None = None) -> Motion:
        """Solve all samples at once for driver values ``q`` (scalar or array); see :meth:`Mechanism.solve`.

        A plain 1-D float64 array on the compiled path takes a warm path with the
        same result: the same checks (a limit, finite values) made cheaply, and
        the motion built straight from the compiled kernels' output (their
        poses and points screened finite as they are written).  Anything else,
        and any batch the warm path cannot finish (a branch that may switch,
        a non-finite number), goes through :meth:`Mechanism.solve`.
        """
        self._check_placement()
        if t is None and type(q) is np.ndarray and q.dtype == np.float64 and q.ndim == 1:
            warm = self._solve_warm(q)
            if warm is not None:
                return warm
        return super().solve(q, t)

    def _solve_warm(self, q: Array) -> Motion | None:
        n = q.shape[0]
        if n > limit("samples"):
            return None  # Mechanism.solve raises the error
        plan = self.__dict__.get("_plan") or self._fast_plan()
        prog = None if plan is None else compiled_ready(plan, n)
        if plan is None or prog is None:
            return None
        if n * 8 < MIN_BYTES:
            qa = q.copy()  # the motion's own copy
        else:
            qa = new_block((n,))
            qa[...] = q
        lead = self._lead_in(qa)
        if lead.size and not self._declared_branches_hold(qa, lead):
            return None
        solved = solve_compiled(self, plan, prog, qa, lazy=True)  # None for a driver value not finite
        if solved is None or not isinstance(solved[0], FinitePoses):
            return None
        poses, checks, pts = solved
        if checks is None:  # every sample closes
            table: list[tuple[str, str]] = []
            big = 2 * n >= MIN_BYTES  # recycled memory: new pages would cost a fault each
            valid = new_block((n,), bool) if big else np.empty(n, dtype=bool)
            code = new_block((n,), np.int16) if big else np.empty(n, dtype=np.int16)
            valid.fill(True)
            code.fill(-1)
        else:
            valid, code, table = merge_failures(n, checks)
        return Motion(driver=qa, poses=poses, valid=valid, fail_code=code, fail_table=table, points=pts or {}, mechanism=self)

    def _solve_points(self, q: Array) -> Solved:
        """The chunked, threaded path (:mod:`planar.linkages.chunked`), else the reference path.

        Kinds without a chunk kernel (gears, driven inputs, triads) have no plan and go straight to the
        reference path. The lead-in is built once and, on falling back, handed to the reference solve.
        """
        lead = self._lead_in(q) if q.ndim == 1 else None
        if lead is not None and self._fast_plan() is not None and self._declared_branches_hold(q, lead):
            fast = fast_solve(self, q, lazy=True)
            if fast is not None:
                return fast
        poses, checks = self._solve_poses(q, lead)
        return poses, checks, None

    def _solve_poses(self, q: Array, lead: Array | None = None) -> tuple[dict[str, Array], list[tuple[Mask, str, str]]]:
        pos, checks = self.solve_nodes(q, lead)
        poses = self._link_poses(pos, q.shape[0])
        if any(self.placement):
            pl = np.asarray(self.placement)
            poses = {k: poses_compose(pl, v) for k, v in poses.items()}
        return poses, checks

    def node_velocities(self, q: ArrayLike, qdot: ArrayLike = 1.0) -> tuple[dict[str, Array], Mask]:
        """Velocity ``(N, 2)`` of every node (own frame, before placement) and where it is defined.

        Each node kind differentiates its own closure (:meth:`NodeKind.velocity`);
        ``qdot = 1`` gives velocity coefficients ``dX/dq``.
        """
        self._check_rates_scale(f"{self.name}.node_velocities")
        qa = check_samples(f"{self.name}.node_velocities(q)", q)
        qd = np.broadcast_to(check_samples(f"{self.name}.node_velocities(qdot)", qdot, qa.shape[0]), qa.shape)
        pos, checks = self.solve_nodes(qa)
        valid = np.ones(qa.shape, bool)
        for m, _, _ in checks:
            valid &= m
        vel: dict[str, Array] = {}
        for node in self.nodes:
            v, ok = node.velocity_at(pos, vel, qa, qd)
            vel[node.name] = v
            if ok is not None:
                valid &= ok
        return vel, valid

    def node_accelerations(
        self,
        q: ArrayLike,
        qdot: ArrayLike = 1.0,
        qddot: ArrayLike = 0.0,
        solved: tuple[dict[str, Array], list[tuple[Mask, str, str]]] | None = None,
    ) -> tuple[dict[str, Array], dict[str, Array], dict[str, Array], Mask]:
        """Position, velocity and acceleration ``(N, 2)`` of every node (own frame, before placement).

        Each node kind differentiates its closure twice
        (:meth:`NodeKind.acceleration`), no differencing: ``qdot`` is the
        driver's rate (rad/s or units/s) and ``qddot`` its rate of change per
        sample; with ``qdot = 1, qddot = 0`` the accelerations are the second
        coefficients ``d2X/dq2``.  ``valid`` is false where the position does
        not close or a differentiated closure is singular (a toggle).
        ``solved``: :meth:`solve_nodes` of ``q`` if the caller has it already.
        """
        where = f"{self.name}.node_accelerations"
        self._check_rates_scale(where)
        qa = check_samples(f"{where}(q)", q)
        qd = np.broadcast_to(check_samples(f"{where}(qdot)", qdot, qa.shape[0]), qa.shape)
        qdd = np.broadcast_to(check_samples(f"{where}(qddot)", qddot, qa.shape[0]), qa.shape)
        if solved is not None and not (isinstance(solved, tuple) and len(solved) == 2 and isinstance(solved[0], dict)):
            raise InputError(f"{where}(solved)", solved, "solve_nodes(q) of the same q (or None)")
        pos, checks = solved if solved is not None else self.solve_nodes(qa)
        valid = np.ones(qa.shape, bool)
        for m, _, _ in checks:
            valid &= m
        vel: dict[str, Array] = {}
        acc: dict[str, Array] = {}
        for node in self.nodes:
            v, ok = node.velocity_at(pos, vel, qa, qd)
            vel[node.name] = v
            a, ok2 = node.acceleration_at(pos, vel, acc, qa, qd, qdd)
            acc[node.name] = a
            for mask in (ok, ok2):
                if mask is not None:
                    valid &= mask
            valid &= np.isfinite(v).all(-1) & np.isfinite(a).all(-1)  # a rate beyond float64 is no rate
        return pos, vel, acc, valid

    def link_rates(
        self, pos: Mapping[str, Array], vel: Mapping[str, Array], acc: Mapping[str, Array]
    ) -> dict[str, tuple[Array, Array, Array, Array]]:
        """Per link: ``(origin velocity, origin acceleration, omega, alpha)`` in the linkage's own frame.

        The link's frame is its pose's (origin at its first node, x toward its
        second, or along its guide), so these are the time derivatives of the
        poses :meth:`solve` returns (placement rotates the vectors, not the rates).
        """
        out: dict[str, tuple[Array, Array, Array, Array]] = {}
        n = next(iter(pos.values())).shape[0] if pos else 0
        for lk in self.links:
            if lk.name == self.ground_name:
                z = np.zeros((n, 2))
                out[lk.name] = (z, z, np.zeros(n), np.zeros(n))
                continue
            a, b = lk.guide if lk.guide is not None else (lk.nodes[0], lk.nodes[1])
            omega, alpha = frame_rates(pos[b] - pos[a], vel[b] - vel[a], acc[b] - acc[a])
            o = lk.nodes[0]
            out[lk.name] = (vel[o], acc[o], omega, alpha)
        return out

    # -- parts and joints -----------------------------------------------------
    def _span(self) -> float:
        """The larger side of the box every node stays in over the driver's cycle (independent of the phase)."""
        ok = self._sweep_ok
        pts = np.concatenate([v[ok] for v in self._sweep_pos.values()])
        ext = float(np.max(np.ptp(pts, axis=0))) if len(pts) > 1 else 1.0
        return ext if ext > 0 else 1.0

    def _local_anchors(self) -> dict[str, dict[str, Vec]]:
        ref = {k: v[None, :] for k, v in self._ref_nodes.items()}
        poses = self._link_poses(ref, 1)
        out: dict[str, dict[str, Vec]] = {}
        for lk in self.links:
            inv = poses_invert(poses[lk.name][0])
            names = list(lk.nodes) + [g for g in (lk.guide or ()) if g not in lk.nodes and lk.name != self.ground_name]
            out[lk.name] = {}
            for nd in names:
                x, y = poses_apply(inv, self._ref_nodes[nd])
                out[lk.name][nd] = (float(x), float(y))
        return out

    def _travel(self, node: str, p: str, q: str) -> tuple[float, float]:
        """Range of ``node``'s position along the line ``p -> q`` over the driver's cycle."""
        ok = self._sweep_ok
        P = self._sweep_pos
        a, b = P[p][ok], P[q][ok]
        d = b - a
        u = d / np.hypot(d[:, 0], d[:, 1])[:, None]  # unit first: a product of two 1e300 lengths overflows
        s = ((P[node][ok] - a) * u).sum(-1)
        return float(s.min()), float(s.max())

    def _build_parts_and_joints(self) -> tuple[list[Part], list[Pivot | PinInSlot | Slide]]:
        """Parts (hulls) and the joints the declaration implies; the joints cut the holes and slots."""
        r = self.width / 2
        hulls: dict[str, list[tuple[float, float, float]]] = {lk.name: [] for lk in self.links}
        joints: list[Pivot | PinInSlot | Slide] = []
        owners: dict[str, list[str]] = {}
        for lk in self.links:
            for nd in lk.nodes:
                owners.setdefault(nd, []).append(lk.name)
                x, y = self._anchors[lk.name][nd]
                hulls[lk.name].append((x, y, r))
        for nd, links in owners.items():
            first = links[0]
            for other in links[1:]:
                jname = nd if len(links) == 2 else f"{nd}:{other}"
                joints.append(
                    Pivot(jname, first, other, self._anchors[first][nd], self._anchors[other][nd], diameter=self.pin_diameter)
                )
        guided = {(lk.guide, nd): lk for lk in self.links if lk.guide is not None for nd in lk.nodes[:1]}
        for node in self.nodes:
            if isinstance(node, RRP) and ((node.p, node.q), node.name) not in guided:
                self._pin_slot(node, owners.get(node.name, []), hulls, joints)
        for (guide, nd), lk in guided.items():
            assert guide is not None
            self._block_slide(lk, nd, guide, hulls, joints)
        for node in self.nodes:
            joints.extend(node.extra_joints(self, hulls))
        parts = []
        for lk in self.links:
            hull = hulls[lk.name] or [(0.0, 0.0, r)]
            parts.append(Part(lk.name, tuple(hull), (), ground=lk.name == self.ground_name))
        return parts, joints

    def _slot_on(
        self, owner: str, node: str, p: str, q: str, offset: float, pad: float, hulls: dict[str, list[tuple[float, float, float]]]
    ) -> tuple[Vec, Vec]:
        """Ends of a slot on ``owner`` along ``p -> q`` covering ``node``'s travel plus ``pad``; widens the hull."""
        ap = np.asarray(self._anchors[owner][p])
        aq = np.asarray(self._anchors[owner][q])
        e = (aq - ap) / np.hypot(*(aq - ap))
        base = ap + offset * np.array([-e[1], e[0]])
        s0, s1 = self._travel(node, p, q)
        start = base + (s0 - pad) * e
        end = base + (s1 + pad) * e
        start_t, end_t = (float(start[0]), float(start[1])), (float(end[0]), float(end[1]))
        hulls[owner].extend([(start_t[0], start_t[1], self.width / 2), (end_t[0], end_t[1], self.width / 2)])
        return start_t, end_t

    def _pin_slot(
        self,
        node: RRP,
        links: list[str],
        hulls: dict[str, list[tuple[float, float, float]]],
        joints: list[Pivot | PinInSlot | Slide],
    ) -> None:
        owner = next((lk.name for lk in self.links if node.p in lk.nodes and node.q in lk.nodes), None)
        if owner is None:
            raise InputError(
                f"{self.name}.nodes.{node.name}", (node.p, node.q), "line nodes carried by one link (the slot's part)"
            )
        start, end = self._slot_on(owner, node.name, node.p, node.q, node.offset, 0.0, hulls)
        riders = [lk for lk in links if lk != owner]
        if not riders:
            raise InputError(f"{self.name}.nodes.{node.name}", node.name, "a link that carries the pin running in the slot")
        pin_link = riders[0]
        joints.append(
            PinInSlot(
                f"{node.name}-slot", owner, pin_link, start, end, self._anchors[pin_link][node.name], width=self.pin_diameter
            )
        )

    def _block_slide(
        self,
        lk: Link,
        node: str,
        guide: tuple[str, str],
        hulls: dict[str, list[tuple[float, float, float]]],
        joints: list[Pivot | PinInSlot | Slide],
    ) -> None:
        """A block ``lk`` on ``node`` sliding along the line ``guide`` of the link that carries it."""
        owner = self._guide_owner(lk)
        p, q = guide
        # the block's node lies on the guide line (an RRP node's offset, or measured here)
        ap, aq = np.asarray(self._ref_nodes[p]), np.asarray(self._ref_nodes[q])
        e = (aq - ap) / np.hypot(*(aq - ap))
        offset = float(_cross(e[None], (np.asarray(self._ref_nodes[node]) - ap)[None])[0])
        start, end = self._slot_on(owner, node, p, q, offset, self.width, hulls)
        anchor = self._anchors[lk.name][node]
        pins = [(anchor[0] - self.width, anchor[1]), (anchor[0] + self.width, anchor[1])]
        for px, py in pins:
            hulls[lk.name].append((px, py, self.width / 2))
        joints.append(
            Slide(f"{lk.name}-slide", owner, lk.name, start, end, pins[0], (2 * self.width, 0.0), width=self.pin_diameter)
        )

    @property
    def extra_driven_parts(self) -> list[str]:
        """Links of the inputs beyond the first that no gear ties to it (a simulation imposes their motion)."""
        return [
            self._link_of(n.name, exclude_ground=True)
            for n in self.nodes
            if getattr(n, "clocked", False) and n is not self._driver_node
        ]

    def input_values(self, q: ArrayLike) -> dict[str, Array]:
        """Each input node's value (crank angle, rad, unwrapped) at driver values ``q`` when there are several.

        Empty for a single-input linkage (its value is the driver value).
        """
        qa = check_samples(f"{self.name}.input_values(q)", q)  # checked for a single input too
        inputs = [n for n in self.nodes if n.is_input]
        if len(inputs) < 2:
            return {}
        out: dict[str, Array] = {}
        for n in inputs:
            own = getattr(n, "input_angle", None)  # a geared or driven node's law
            if own is not None:
                out[n.name] = own(qa)
            elif isinstance(n, Crank):
                out[n.name] = qa + n.phase
            elif isinstance(n, Actuator):
                out[n.name] = qa + n.offset
        return out

    def node_positions(self, q: ArrayLike) -> dict[str, Array]:
        """World positions ``(N, 2)`` of every node, placement applied."""
        pos, _ = self.solve_nodes(check_samples(f"{self.name}.node_positions(q)", q))
        if any(self.placement):
            pl = np.asarray(self.placement)
            return {k: poses_apply(pl, v) for k, v in pos.items()}
        return pos

    # -- rates: the kind's own answer to Mechanism.part_rates ---------------------------------------
    #: the last node solve of any linkage, ``(linkage, digest of q, solve_nodes result)``: a motion table
    #: asks for rates at two driver speeds and the transmission angles of the same samples
    _last_node_solve: ClassVar[list[tuple[Linkage, bytes, Any]]] = []

    def cached_solve_nodes(self, q: Array) -> tuple[dict[str, Array], list[tuple[Mask, str, str]]]:
        """:meth:`solve_nodes` of ``q``, remembered for the last ``q`` asked (one entry for all linkages)."""
        import hashlib

        key = hashlib.blake2b(np.ascontiguousarray(q).tobytes(), digest_size=16).digest() + str(q.shape).encode()
        last = Linkage._last_node_solve
        if last and last[0][0] is self and last[0][1] == key:
            return last[0][2]
        solved = self.solve_nodes(q)
        last[:] = [(self, key, solved)]
        return solved

    def part_rates(self, q: Array, qd: Array, qdd: Array) -> RatesResult:
        """Rates of every link (see :meth:`Mechanism.part_rates`): every node kind's closure differentiated
        twice (:meth:`node_accelerations`), the link frames' rates (:meth:`link_rates`) turned by the placement."""
        from planar.core.fields import check_driver_rates

        q, qd, qdd = check_driver_rates(f"{self.name}.part_rates", q, qd, qdd, names=("qd", "qdd"))
        pos, vel, acc, valid = self.node_accelerations(q, qd, qdd, solved=self.cached_solve_nodes(q))
        ang = self.placement[2]
        out = {
            name: PartRates(rotate_vectors(v, ang), rotate_vectors(a, ang), om, al)
            for name, (v, a, om, al) in self.link_rates(pos, vel, acc).items()
        }
        return out, valid, "linkage closure equations differentiated twice (node kinds)"
