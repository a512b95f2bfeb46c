"""General pivot/slot linkages built from dyads (Assur groups of class II).

A linkage is a list of *nodes* (joint centres), each placed in closed form from
nodes declared before it, and a list of *links* (rigid parts) naming the nodes
they carry.  Node kinds:

* :class:`Fixed` — a point on the ground.
* :class:`Crank` — rotates about a node: ``centre + r (cos(q + phase), sin(q + phase))``
  where ``q`` is the driver angle.
* :class:`Actuator` — translates with the driver: ``origin + (q + offset) * axis``.
* :class:`RRR` — distance ``ra`` from node ``a`` and ``rb`` from node ``b``
  (circle-circle).  ``branch=+1`` places it to the left of ``a -> b``.
* :class:`RRP` — distance ``ra`` from ``a`` and on the line through ``p -> q``
  (shifted left by ``offset``), line-circle.  ``branch=+1`` takes the root
  further along ``p -> q``.
* :class:`Rigid` — fixed in the frame of nodes ``a, b``: ``a + u e + v e_perp``
  with ``e`` the unit vector ``a -> b`` (coupler points, ternary links).

A link's frame has its origin at its first node and its x axis toward its
second; a link with one node and a ``guide`` keeps the guide line's direction
(a slider block).  Joints follow from the declaration: a node shared by links
is a pivot; an RRP node is a pin in a straight slot of the link that carries
the line, or a slide when the carrying link is guided by that line.

Every node is solved for all driver values at once (numpy, no per-sample
loop).  A branch is a fixed side of a fixed directed line, so it is continuous
through a full input sweep wherever the dyad can close; where it cannot, the
sample is invalid with the node named.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping, Sequence

import numpy as np
from numpy.typing import NDArray

from ..errors import AssemblyError, InputError
from ..geometry import circle_circle, line_circle, poses_apply, poses_compose, poses_invert
from ..model import (
    Driver,
    Hole,
    Mechanism,
    Part,
    PinInSlot,
    Pivot,
    Slide,
    Slot,
    check_finite,
    check_positive,
)

__all__ = ["Fixed", "Crank", "Actuator", "RRR", "RRP", "Rigid", "Link", "Linkage", "Node"]

Vec = tuple[float, float]
Array = NDArray[np.float64]


@dataclass(frozen=True)
class Fixed:
    name: str
    xy: Vec


@dataclass(frozen=True)
class Crank:
    name: str
    centre: str
    radius: float
    phase: float = 0.0


@dataclass(frozen=True)
class Actuator:
    name: str
    origin: str
    axis: Vec = (1.0, 0.0)
    offset: float = 0.0


@dataclass(frozen=True)
class RRR:
    name: str
    a: str
    ra: float
    b: str
    rb: float
    branch: int = 1


@dataclass(frozen=True)
class RRP:
    name: str
    a: str
    ra: float
    p: str
    q: str
    branch: int = 1
    offset: float = 0.0


@dataclass(frozen=True)
class Rigid:
    name: str
    a: str
    b: str
    local: Vec


Node = Fixed | Crank | Actuator | RRR | RRP | Rigid


@dataclass(frozen=True)
class Link:
    """A rigid part carrying ``nodes``; ``guide`` makes a one-node slider block."""

    name: str
    nodes: tuple[str, ...]
    guide: tuple[str, str] | None = None


def _refs(n: Node) -> tuple[str, ...]:
    if isinstance(n, Fixed):
        return ()
    if isinstance(n, Crank):
        return (n.centre,)
    if isinstance(n, Actuator):
        return (n.origin,)
    if isinstance(n, RRR):
        return (n.a, n.b)
    if isinstance(n, RRP):
        return (n.a, n.p, n.q)
    return (n.a, n.b)


class Linkage(Mechanism):
    """A single-input planar linkage of pivots and slots, solved in closed form.

    ``placement`` ``(x, y, angle)`` places the whole linkage in the world
    (the linkage is solved in its own frame, then transformed).  ``width``
    and ``pin_diameter`` size the parts' outlines (default: 8 % and 3 % of
    the linkage's span).  ``points`` maps names to node names.
    """

    def __init__(
        self,
        name: str,
        nodes: Sequence[Node],
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
        self.nodes: tuple[Node, ...] = tuple(nodes)
        self.placement = tuple(float(v) for v in check_finite(f"{name}.placement", placement))
        self._validate_nodes(name)
        self.links = self._with_ground(tuple(links), ground)
        self.ground_name = ground
        self._validate_links(name)
        drivers = [n for n in self.nodes if isinstance(n, (Crank, Actuator))]
        if not drivers:
            raise InputError(f"{name}.nodes", [n.name for n in self.nodes], "one Crank or Actuator node as the input")
        self._driver_node = drivers[0]
        driver_link = self._link_of(self._driver_node.name, exclude_ground=True)
        byname = {n.name: n for n in self.nodes}
        if isinstance(self._driver_node, Crank):
            c = byname[self._driver_node.centre]
            origin = c.xy if isinstance(c, Fixed) else (0.0, 0.0)
            driver = Driver(driver_link, "rotation", origin=origin, rate=rate, phase=phase,
                            amplitude=amplitude, centre=centre)
        else:
            ax = np.asarray(self._driver_node.axis, float)
            driver = Driver(driver_link, "translation", axis=tuple(ax / np.hypot(*ax)), rate=rate,
                            phase=phase, amplitude=amplitude if amplitude is not None else 1.0, centre=centre)
        # reference configuration: the first assemblable sample of a sweep
        q_ref = self._reference_input(name, driver)
        ref = self.solve_nodes(np.array([q_ref]))[0]
        self._ref_nodes = {k: v[0] for k, v in ref.items()}
        span = self._span()
        self.width = check_positive(f"{name}.width", width) if width is not None else 0.08 * span
        self.pin_diameter = (
            check_positive(f"{name}.pin_diameter", pin_diameter) if pin_diameter is not None else 0.03 * span
        )
        self._anchors = self._local_anchors()
        parts, joints = self._build_parts_and_joints(driver)
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
            where = f"{name}.nodes.{n.name}"
            if n.name in seen:
                raise InputError(where, n.name, "a node name used once")
            for r in _refs(n):
                if r not in seen:
                    raise InputError(where, r, "a node declared before it")
            if isinstance(n, Fixed):
                check_finite(f"{where}.xy", n.xy)
            elif isinstance(n, Crank):
                check_positive(f"{where}.radius", n.radius)
                check_finite(f"{where}.phase", n.phase)
            elif isinstance(n, Actuator):
                ax = check_finite(f"{where}.axis", n.axis)
                if np.hypot(*ax) == 0:
                    raise InputError(f"{where}.axis", n.axis, "a non-zero direction")
            elif isinstance(n, RRR):
                check_positive(f"{where}.ra", n.ra)
                check_positive(f"{where}.rb", n.rb)
                if n.branch not in (1, -1):
                    raise InputError(f"{where}.branch", n.branch, "+1 or -1")
            elif isinstance(n, RRP):
                check_positive(f"{where}.ra", n.ra)
                check_finite(f"{where}.offset", n.offset)
                if n.branch not in (1, -1):
                    raise InputError(f"{where}.branch", n.branch, "+1 or -1")
            elif isinstance(n, Rigid):
                check_finite(f"{where}.local", n.local)
            seen.add(n.name)

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
            if lk.name != self.ground_name and len(lk.nodes) < 2 and lk.guide is None:
                raise InputError(f"{where}.nodes", lk.nodes, "two or more nodes (or one node and a guide)")

    def _link_of(self, node: str, exclude_ground: bool) -> str:
        for lk in self.links:
            if exclude_ground and lk.name == self.ground_name:
                continue
            if node in lk.nodes:
                return lk.name
        raise InputError(f"{self.name if hasattr(self, 'name') else 'linkage'}.links", node,
                         "a link that carries this node")

    def _reference_input(self, name: str, driver: Driver) -> float:
        if driver.amplitude is None:
            q = driver.phase + np.linspace(0.0, 2 * np.pi, 721)
        else:
            q = driver.value(np.linspace(0.0, driver.period, 721))
        nodes, checks = self.solve_nodes(q)
        ok = np.ones(q.shape, bool)
        for m, _, _ in checks:
            ok &= m
        if not ok.any():
            joint, why = checks[0][1], checks[0][2]
            for m, j, w in checks:
                if not m.any():
                    joint, why = j, w
                    break
            raise AssemblyError(f"{name}: cannot be assembled at any driver value: joint {joint!r}: {why}")
        return float(q[np.argmax(ok)])

    # -- solving ------------------------------------------------------------
    def solve_nodes(self, q: Array) -> tuple[dict[str, Array], list[tuple[NDArray[np.bool_], str, str]]]:
        """World positions ``(N, 2)`` of every node (before placement) and validity checks."""
        n = q.shape[0]
        pos: dict[str, Array] = {}
        checks: list[tuple[NDArray[np.bool_], str, str]] = []
        for node in self.nodes:
            if isinstance(node, Fixed):
                pos[node.name] = np.broadcast_to(np.asarray(node.xy, float), (n, 2))
            elif isinstance(node, Crank):
                a = q + node.phase
                pos[node.name] = pos[node.centre] + node.radius * np.stack([np.cos(a), np.sin(a)], -1)
            elif isinstance(node, Actuator):
                ax = np.asarray(node.axis, float)
                ax = ax / np.hypot(*ax)
                pos[node.name] = pos[node.origin] + (q + node.offset)[:, None] * ax
            elif isinstance(node, RRR):
                p, ok = circle_circle(pos[node.a], node.ra, pos[node.b], node.rb, node.branch)
                pos[node.name] = p
                checks.append((ok, node.name, f"links of length {node.ra:g} (from {node.a!r}) and "
                               f"{node.rb:g} (from {node.b!r}) cannot span the distance between them"))
            elif isinstance(node, RRP):
                p0, p1 = pos[node.p], pos[node.q]
                u = p1 - p0
                un = np.hypot(u[:, 0], u[:, 1])[:, None]
                base = p0 + node.offset * np.stack([-u[:, 1], u[:, 0]], -1) / un
                p, ok, _ = line_circle(base, u, pos[node.a], node.ra, node.branch)
                pos[node.name] = p
                checks.append((ok, node.name, f"a link of length {node.ra:g} from {node.a!r} cannot "
                               f"reach the line {node.p!r}-{node.q!r}"))
            else:  # Rigid
                a, b = pos[node.a], pos[node.b]
                e = b - a
                en = np.hypot(e[:, 0], e[:, 1])
                ok = en > 0
                e = e / np.where(ok, en, 1.0)[:, None]
                u, v = node.local
                pos[node.name] = a + u * e + v * np.stack([-e[:, 1], e[:, 0]], -1)
                checks.append((ok, node.name, f"nodes {node.a!r} and {node.b!r} coincide"))
        return pos, checks

    def _link_poses(self, pos: Mapping[str, Array], n: int) -> dict[str, Array]:
        poses: dict[str, Array] = {}
        for lk in self.links:
            if lk.name == self.ground_name:
                poses[lk.name] = np.zeros((n, 3))
                continue
            o = pos[lk.nodes[0]]
            if lk.guide is not None:
                d = pos[lk.guide[1]] - pos[lk.guide[0]]
            else:
                d = pos[lk.nodes[1]] - o
            poses[lk.name] = np.column_stack([o[:, 0], o[:, 1], np.arctan2(d[:, 1], d[:, 0])])
        return poses

    def _solve_poses(self, q: Array):  # type: ignore[override]
        pos, checks = self.solve_nodes(q)
        poses = self._link_poses(pos, q.shape[0])
        if any(self.placement):
            pl = np.asarray(self.placement)
            poses = {k: poses_compose(pl, v) for k, v in poses.items()}
        return poses, checks

    # -- parts and joints -----------------------------------------------------
    def _span(self) -> float:
        pts = np.array(list(self._ref_nodes.values()))
        ext = float(np.max(np.ptp(pts, axis=0))) if len(pts) > 1 else 1.0
        return ext if ext > 0 else 1.0

    def _local_anchors(self) -> dict[str, dict[str, Vec]]:
        ref = {k: v[None, :] for k, v in self._ref_nodes.items()}
        poses = self._link_poses(ref, 1)
        out: dict[str, dict[str, Vec]] = {}
        for lk in self.links:
            inv = poses_invert(poses[lk.name][0])
            names = list(lk.nodes) + [g for g in (lk.guide or ()) if g not in lk.nodes and lk.name != self.ground_name]
            out[lk.name] = {
                nd: tuple(float(c) for c in poses_apply(inv, self._ref_nodes[nd])) for nd in names  # type: ignore[misc]
            }
        return out

    def _travel(self, node: str, p: str, q: str) -> tuple[float, float]:
        """Range of ``node``'s position along the line ``p -> q`` over a full sweep."""
        drv = self.driver if hasattr(self, "driver") else None
        qs = np.linspace(0, 2 * np.pi, 721) if drv is None or drv.amplitude is None else \
            drv.value(np.linspace(0, drv.period, 721))
        pos, checks = self.solve_nodes(qs)
        ok = np.ones(qs.shape, bool)
        for m, _, _ in checks:
            ok &= m
        a, b = pos[p][ok], pos[q][ok]
        d = b - a
        s = ((pos[node][ok] - a) * d).sum(-1) / np.hypot(d[:, 0], d[:, 1])
        return float(s.min()), float(s.max())

    def _build_parts_and_joints(self, driver: Driver) -> tuple[list[Part], list]:
        self.driver = driver  # needed by _travel
        r = self.width / 2
        hulls: dict[str, list[tuple[float, float, float]]] = {lk.name: [] for lk in self.links}
        feats: dict[str, list] = {lk.name: [] for lk in self.links}
        joints: list = []
        byname = {n.name: n for n in self.nodes}
        owners: dict[str, list[str]] = {}
        for lk in self.links:
            for nd in lk.nodes:
                owners.setdefault(nd, []).append(lk.name)
        for lk in self.links:
            for nd in lk.nodes:
                x, y = self._anchors[lk.name][nd]
                hulls[lk.name].append((x, y, r))
                # a hole only where a pin goes: a shared node or a pin running in a slot
                if len(owners[nd]) > 1 or isinstance(byname[nd], RRP):
                    feats[lk.name].append(Hole((x, y), self.pin_diameter, role="pin"))
        for nd, links in owners.items():
            node = byname[nd]
            first = links[0]
            for other in links[1:]:
                jname = nd if len(links) == 2 else f"{nd}:{other}"
                joints.append(Pivot(jname, first, other, anchor_a=self._anchors[first][nd], anchor_b=self._anchors[other][nd]))
            if isinstance(node, RRP):
                self._slot_joint(node, links, hulls, feats, joints)
        parts = []
        for lk in self.links:
            is_ground = lk.name == self.ground_name
            hull = hulls[lk.name] or [(0.0, 0.0, r)]
            parts.append(Part(lk.name, tuple(hull), tuple(feats[lk.name]), ground=is_ground))
        return parts, joints

    def _slot_joint(self, node: RRP, links: list[str], hulls, feats, joints) -> None:
        owner = None
        for lk in self.links:
            if node.p in lk.nodes and node.q in lk.nodes:
                owner = lk.name
                break
        if owner is None:
            raise InputError(f"{self.name}.nodes.{node.name}", (node.p, node.q),
                             "line nodes carried by one link (the slot's part)")
        ap = np.asarray(self._anchors[owner][node.p])
        aq = np.asarray(self._anchors[owner][node.q])
        e = (aq - ap) / np.hypot(*(aq - ap))
        base = ap + node.offset * np.array([-e[1], e[0]])
        s0, s1 = self._travel(node.name, node.p, node.q)
        guided = [lk for lk in self.links if lk.guide == (node.p, node.q) and node.name in lk.nodes]
        pad = self.width if guided else 0.0
        start = base + (s0 - pad) * e
        end = base + (s1 + pad) * e
        start_t, end_t = tuple(map(float, start)), tuple(map(float, end))
        feats[owner].append(Slot(start_t, end_t, self.pin_diameter, role="pin"))
        hulls[owner].extend([(start_t[0], start_t[1], self.width / 2), (end_t[0], end_t[1], self.width / 2)])
        for lk in links:
            if lk == owner or (guided and not any(g.name == lk for g in guided)):
                continue  # links pinned to a slider block ride on it, not in the slot
            if any(g.name == lk for g in guided):
                # slider block: two guide pins a width apart along the slot
                anchor = self._anchors[lk][node.name]
                pins = [(anchor[0] - self.width, anchor[1]), (anchor[0] + self.width, anchor[1])]
                for px, py in pins:
                    hulls[lk].append((px, py, self.width / 2))
                    feats[lk].append(Hole((px, py), self.pin_diameter, role="pin"))
                joints.append(Slide(f"{lk}-slide", owner, lk, start=start_t, end=end_t, anchor=pins[0], axis=(2 * self.width, 0.0)))
            else:
                joints.append(PinInSlot(f"{node.name}-slot", owner, lk, start=start_t, end=end_t, pin=self._anchors[lk][node.name]))

    def node_positions(self, q) -> dict[str, Array]:
        """World positions ``(N, 2)`` of every node, placement applied."""
        pos, _ = self.solve_nodes(np.atleast_1d(np.asarray(q, float)))
        if any(self.placement):
            pl = np.asarray(self.placement)
            return {k: poses_apply(pl, v) for k, v in pos.items()}
        return pos
