"""A walker: N identical legs phased on one crankshaft (:class:`Legs`), and the same walker as it is built
(:class:`LegsAssembly`: crank webs, frame plates and standoffs).

One leg is written as a linkage (a ``fixed`` crank centre, one ``crank`` node, the leg's fixed pivots and its
dyads).  :class:`Legs` repeats it ``count`` times: leg ``i`` turns on the same crankshaft ``phases[i]`` radians
ahead of the shaft angle; with ``mirror`` every second leg is the first mirrored about the vertical line through
the crank centre (its fixed pivots mirrored, every ``branch`` flipped), as a Strandbeest pairs its legs.  The
crankshaft is one rigid link carrying every leg's crank pin; every leg's nodes and links are named with the
suffix ``_i`` (``B_1``, ``upper_2``), mirrored fixed pivots with ``_m`` (``Z_m``).

Built, each leg lies in its own slab of layers between two frame plates (``frame_0`` ... ``frame_N``):

* the crankshaft is built up, as a Strandbeest's is: each slab has two crank webs (``crank_ia`` next to the
  plate the leg hangs on, ``crank_ib`` at the slab's other side) joined by the crank pin through the leg's
  links; between slabs a short shaft joins the webs on either side of a plate (glued into both webs at their
  angle) and turns in the plate's bearing hole.  The motor drives the first slab's web from under ``frame_0``.
  No shaft passes through a slab, so no link sweeps across it (a Jansen leg's links pass over the crank axis).
* the leg's fixed pivots are rods in the plate it hangs on: the plate below its slab, or for the first leg of a
  mirrored pair the plate above (the pair's slabs are mirror images about their shared plate);
* ``standoffs`` (model units, the ground frame) are rods through every plate, with spacer rings between them:
  they hold the plates at their distance.  They must lie clear of every leg's swept area; without any given,
  two are chosen (:func:`auto_standoffs`: the points nearest the crank axis clear of every sweep by a link's
  width, on opposite sides of it).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, fields, replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from planar.core.model import LazyPoses, Mechanism, Part, Pivot
from planar.core.registry import Registry
from planar.errors import InputError
from planar.linkages.linkage import Link, Linkage
from planar.linkages.nodes import RRP, RRR, Crank, Fixed, NodeKind, Rigid

__all__ = ["MIRRORS", "STANDOFF_REACH", "Legs", "LegsAssembly", "Slab", "auto_standoffs"]

#: how far from the crank axis a standoff may stand, in spans of the walker's joints (the frame plates reach it)
STANDOFF_REACH = 3.0

Array = NDArray[np.float64]

#: how each node kind is mirrored about the vertical line ``x = axis`` (a leg's mirror image)
MIRRORS: Registry[Callable[[Any, float], NodeKind]] = Registry("legs mirror", "node kind")


@MIRRORS.register(Fixed)
def _mirror_fixed(n: Fixed, axis: float) -> Fixed:
    return replace(n, xy=(2 * axis - n.xy[0], n.xy[1]))


@MIRRORS.register(Crank)
def _mirror_crank(n: Crank, axis: float) -> NodeKind:
    return n  # on the one crankshaft: the same sense of turning and the same phase


@MIRRORS.register(RRR)
def _mirror_rrr(n: RRR, axis: float) -> NodeKind:
    return replace(n, branch=-n.branch)


@MIRRORS.register(RRP)
def _mirror_rrp(n: RRP, axis: float) -> NodeKind:
    return replace(n, offset=-n.offset)


@MIRRORS.register(Rigid)
def _mirror_rigid(n: Rigid, axis: float) -> NodeKind:
    return replace(n, local=(n.local[0], -n.local[1]))


def _renamed(n: NodeKind, names: Mapping[str, str]) -> NodeKind:
    """``n`` with its name and every node it refers to renamed by ``names``."""
    kw = {f.name: names[v] for f in fields(n) if isinstance(v := getattr(n, f.name), str) and v in names}  # type: ignore[arg-type]
    return replace(n, **kw)  # type: ignore[type-var]


@dataclass(frozen=True)
class Slab:
    """One leg's slab of layers in the built walker: the plate it hangs on, its two crank webs (``near`` the
    plate, ``far`` from it), its links by the leg's link names, and whether it lies above its plate
    (``reversed`` false) or below it (true: the slab's layer order is turned over)."""

    plate: str
    near: str
    far: str
    links: dict[str, str]
    reversed: bool


class Legs(Linkage):
    """``count`` copies of one leg on one crankshaft, leg ``i`` ``phases[i]`` rad ahead (see the module docstring).

    Parameters
    ----------
    name : str
        The walker's name.
    nodes, links : sequence of NodeKind, sequence of Link
        One leg: a ``fixed`` crank centre, exactly one ``crank`` node turning about it (carried by a link of
        those two nodes only), the leg's fixed pivots and the rest of its nodes; its links.
    count : int
        Number of legs, 1 to 16.
    phases : sequence of float, optional
        Each leg's crank angle ahead of the shaft (rad, counter-clockwise); default evenly spread over a
        turn (with ``mirror``: over the pairs, both legs of a pair on one angle).
    mirror : bool
        Every second leg is the previous one mirrored about the vertical through the crank centre.
    points : mapping, optional
        The leg's named points (``{"foot": "F"}``), named ``foot_1`` ... ``foot_N`` on the walker.
    standoffs : sequence of (x, y)
        Where rods hold the built frame plates apart (model units, ground frame).
    rate, phase, width, pin_diameter
        As :class:`~planar.linkages.linkage.Linkage` (``width`` and ``pin_diameter`` default to one leg's).
    """

    def __init__(
        self,
        name: str,
        nodes: Sequence[NodeKind],
        links: Sequence[Link],
        count: int,
        phases: Sequence[float] | None = None,
        mirror: bool = False,
        points: Mapping[str, str] | None = None,
        standoffs: Sequence[Sequence[float]] = (),
        rate: float = 2.0 * np.pi,
        phase: float = 0.0,
        width: float | None = None,
        pin_diameter: float | None = None,
    ) -> None:
        if isinstance(count, bool) or not isinstance(count, (int, np.integer)) or not 1 <= count <= 16:
            raise InputError(f"{name}.count", count, "a whole number of legs from 1 to 16")
        if mirror and count % 2:
            raise InputError(f"{name}.count", count, "an even number of legs with mirror = true (mirrored pairs)")
        self.leg = Linkage(name, nodes, links, points=points, width=width, pin_diameter=pin_diameter)
        crank, centre, crank_link = self._crank_of(name, list(nodes), list(links))
        self.count = int(count)
        self.phases = self._phases(name, phases, count, mirror)
        self.mirrored = tuple(bool(mirror and i % 2 == 1) for i in range(count))
        self.crank_centre = centre.name
        self.crank_nodes = tuple(f"{crank.name}_{i + 1}" for i in range(count))
        so = np.asarray(standoffs, float).reshape(-1, 2) if len(standoffs) else np.zeros((0, 2))
        if not np.isfinite(so).all():
            raise InputError(f"{name}.standoffs", standoffs, "points [x, y] of finite numbers")
        self.standoffs = tuple((float(x), float(y)) for x, y in so)
        self.standoffs_given = bool(len(self.standoffs))
        all_nodes, all_links, all_points, self.legs_links, self.hangs = self._expand(
            list(nodes), list(links), crank, centre, crank_link, dict(points or {})
        )
        super().__init__(
            name,
            all_nodes,
            all_links,
            points=all_points,
            rate=rate,
            phase=phase,
            width=self.leg.width,
            pin_diameter=self.leg.pin_diameter,
        )
        self._check_standoffs_near(name)

    def _check_standoffs_near(self, name: str) -> None:
        """Refuse a standoff farther from the crank axis than :data:`STANDOFF_REACH` times the walker's span: the
        frame plates would stretch to it (a standoff at 1e7 made a plate 10 km long, refused only as a part too
        big for the sheet, naming neither the field nor the value)."""
        cx, cy = self._ref_nodes[self.crank_centre]
        reach = STANDOFF_REACH * self._span()
        for i, (x, y) in enumerate(self.standoffs):
            if math.hypot(x - cx, y - cy) > reach:
                raise InputError(
                    f"{name}.standoffs[{i}]",
                    [x, y],
                    f"a point within {reach:.4g} model units of the crank axis ({STANDOFF_REACH:g} times the walker's "
                    "span): the frame plates reach every standoff",
                )

    @staticmethod
    def _crank_of(name: str, nodes: list[NodeKind], links: list[Link]) -> tuple[Crank, Fixed, Link]:
        inputs = [n for n in nodes if n.is_input]
        if len(inputs) == 1 and not isinstance(inputs[0], Crank):
            raise InputError(
                f"{name}.leg.nodes.{inputs[0].name}.kind",
                inputs[0].kind,
                "'crank': a walker's legs turn on one crankshaft, driven by its crank node",
            )
        if len(inputs) != 1 or not isinstance(inputs[0], Crank):
            raise InputError(f"{name}.leg.nodes", [n.name for n in inputs], "exactly one input node, a crank")
        crank = inputs[0]
        centre = next(n for n in nodes if n.name == crank.centre)
        if not isinstance(centre, Fixed):
            raise InputError(f"{name}.leg.nodes.{crank.name}.centre", crank.centre, "a fixed node (the crankshaft's axis)")
        owner = [lk for lk in links if crank.name in lk.nodes]
        if len(owner) < 1 or set(owner[0].nodes) != {crank.name, centre.name}:
            raise InputError(
                f"{name}.leg.links", [lk.name for lk in owner], f"a crank link carrying only {centre.name!r} and {crank.name!r}"
            )
        if any(lk.name == "ground" for lk in links):
            raise InputError(f"{name}.leg.links", "ground", "no link named 'ground' (the frame is made of the fixed nodes)")
        return crank, centre, owner[0]

    @staticmethod
    def _phases(name: str, phases: Sequence[float] | None, count: int, mirror: bool) -> tuple[float, ...]:
        if phases is None:
            groups = count // 2 if mirror else count
            return tuple(2 * math.pi * (i // 2 if mirror else i) / groups for i in range(count))
        ph = np.asarray(phases, float).ravel()
        if ph.shape != (count,) or not np.isfinite(ph).all():
            raise InputError(f"{name}.phases", phases, f"{count} finite angles, one per leg")
        return tuple(float(v) for v in ph)

    def _expand(
        self,
        nodes: list[NodeKind],
        links: list[Link],
        crank: Crank,
        centre: Fixed,
        crank_link: Link,
        points: dict[str, str],
    ) -> tuple[list[NodeKind], list[Link], dict[str, str], list[dict[str, str]], list[dict[str, str]]]:
        """Every leg's nodes, links and points, renamed (``_i``, mirrored fixed pivots ``_m``); per leg its
        links (leg link name -> walker link name) and fixed pivots (leg node -> walker node)."""
        axis = centre.xy[0]
        fixed = [n for n in nodes if isinstance(n, Fixed)]
        out_nodes: dict[str, NodeKind] = {}
        for n in fixed:
            out_nodes[n.name] = n
        if any(self.mirrored):
            for n in fixed:
                if n.name != centre.name:
                    out_nodes[f"{n.name}_m"] = replace(_mirror_fixed(n, axis), name=f"{n.name}_m")  # type: ignore[type-var]
        out_links = [Link("crankshaft", (centre.name, *self.crank_nodes))]
        legs_links: list[dict[str, str]] = []
        hangs: list[dict[str, str]] = []
        out_points: dict[str, str] = {}
        for i in range(self.count):
            names = {n.name: f"{n.name}_{i + 1}" for n in nodes if not isinstance(n, Fixed)}
            hang = {n.name: (f"{n.name}_m" if self.mirrored[i] else n.name) for n in fixed if n.name != centre.name}
            names.update(hang)
            for nd in nodes:
                if isinstance(nd, Fixed):
                    continue
                m: Any = _renamed(nd, names)
                if nd is crank:
                    m = replace(m, phase=crank.phase + self.phases[i])
                if self.mirrored[i]:
                    m = MIRRORS.get(m, f"node {nd.name!r} of a mirrored leg")(m, axis)
                out_nodes[m.name] = m
            mine = {}
            for lk in links:
                if lk is crank_link:
                    continue
                mine[lk.name] = f"{lk.name}_{i + 1}"
                guide = None if lk.guide is None else (names.get(lk.guide[0], lk.guide[0]), names.get(lk.guide[1], lk.guide[1]))
                out_links.append(Link(mine[lk.name], tuple(names.get(v, v) for v in lk.nodes), guide))
            legs_links.append(mine)
            hangs.append(hang)
            for p, pn in points.items():
                out_points[f"{p}_{i + 1}"] = names.get(pn, pn)
        return list(out_nodes.values()), out_links, out_points, legs_links, hangs

    def as_built(self) -> LegsAssembly:
        """The walker as it is cut and assembled: crank webs in slabs between frame plates (module docstring)."""
        return LegsAssembly(self)


class LegsAssembly(Mechanism):
    """A :class:`Legs` walker as built: the crankshaft split into two webs per slab (each moving as the
    crankshaft does), ``count + 1`` frame plates (standing as the ground), shafts between slabs, standoffs.

    Poses are the walker's; :attr:`layer_stack` tells the assembly planner each leg's slab.
    """

    def __init__(self, legs: Legs) -> None:
        self.legs = legs
        n = legs.count
        reversed_ = [bool(legs.mirrored[i + 1]) if i + 1 < n and not legs.mirrored[i] else False for i in range(n)]
        plates = [f"frame_{k}" for k in range(n + 1)]
        anchors = legs._anchors
        o = legs.crank_centre
        r = legs.width / 2
        slabs = []
        for i in range(n):
            plate = plates[i + 1] if reversed_[i] else plates[i]
            slabs.append(Slab(plate, f"crank_{i + 1}a", f"crank_{i + 1}b", dict(legs.legs_links[i]), reversed_[i]))
        self.layer_stack: tuple[tuple[str, ...], tuple[Slab, ...]] = (tuple(plates), tuple(slabs))
        # which webs sit under and over each plate: the bottom web of slab i is its near web unless reversed
        bottom = [s.far if s.reversed else s.near for s in slabs]
        top = [s.near if s.reversed else s.far for s in slabs]
        pin = legs.pin_diameter
        cs = anchors["crankshaft"]
        ground = anchors[legs.ground_name]
        joints: list[Any] = [Pivot(f"{o}:motor", plates[0], bottom[0], ground[o], cs[o], pin)]
        glued: list[str] = []
        for k in range(1, n + 1):
            joints.append(Pivot(f"{o}:{plates[k]}", plates[k], top[k - 1], ground[o], cs[o], pin))
            if k < n:
                joints.append(Pivot(f"{o}:{top[k - 1]}-{bottom[k]}", top[k - 1], bottom[k], cs[o], cs[o], pin))
                glued.append(joints[-1].name)
        standoffs = legs.standoffs if legs.standoffs_given else auto_standoffs(legs)
        for j, xy in enumerate(standoffs):
            for k in range(n):
                joints.append(Pivot(f"standoff{j + 1}:{k}", plates[k], plates[k + 1], xy, xy, pin))
        for i, s in enumerate(slabs):
            a = legs.crank_nodes[i]
            joints.append(Pivot(f"{a}:{s.near}-{s.far}", s.near, s.far, cs[a], cs[a], pin))
        for jt in legs.joints:
            if (moved := self._rejoined(jt, legs, slabs)) is not None:
                joints.append(moved)
        parts: list[Part] = []
        for pl in plates:
            hung = [nd for i, s in enumerate(slabs) if s.plate == pl for nd in legs.hangs[i].values()]
            hull = [(*ground[o], r)] + [(*ground[nd], r) for nd in dict.fromkeys(hung)] + [(x, y, r) for x, y in standoffs]
            parts.append(Part(pl, tuple(hull), (), ground=True))
        for i, s in enumerate(slabs):
            a = legs.crank_nodes[i]
            for w in (s.near, s.far):
                parts.append(Part(w, ((*cs[o], r), (*cs[a], r))))
        parts += [p for p in legs.parts if p.name not in ("crankshaft", legs.ground_name)]
        from dataclasses import replace as _replace

        driver = _replace(legs.driver, part=bottom[0])
        points = dict(legs.points)
        super().__init__(legs.name, parts, joints, driver, points)
        self.webs = {w: "crankshaft" for s in slabs for w in (s.near, s.far)}
        #: joints whose two parts are glued on the rod through them (the webs on either side of a plate turn as one)
        self.glued = tuple(glued)
        self.standoffs = standoffs
        self.design_notes = [
            f"{legs.name}: {n} leg(s) in slabs between {n + 1} frame plates; the crank webs on either side of a "
            "plate are glued on the short shaft through it at their angle (the crank pins set each web's angle)"
        ]

    @staticmethod
    def _rejoined(jt: Any, legs: Legs, slabs: list[Slab]) -> Any:
        """A walker joint moved onto the built parts: the crankshaft's onto the leg's near web, the ground's onto
        the plate the leg hangs on; ``None`` for the crankshaft's bearing (the built shafts replace it)."""
        g = legs.ground_name
        sides = {jt.a, jt.b}
        if sides == {"crankshaft", g}:
            return None
        if not sides & {"crankshaft", g}:
            return jt
        other = jt.b if jt.a in ("crankshaft", g) else jt.a
        slab = next(s for s in slabs if other in s.links.values())
        new = slab.near if "crankshaft" in sides else slab.plate
        return replace(jt, a=new if jt.a in ("crankshaft", g) else jt.a, b=new if jt.b in ("crankshaft", g) else jt.b)

    def _solve_points(self, q: Array) -> tuple[dict[str, Array], Any, Any]:
        """The walker's solve with its poses renamed onto the built parts; lazy poses stay lazy (renamed when
        first read), so a solve that reads only the points never holds every part's pose track."""
        poses, checks, pts = self.legs._solve_points(q)
        if isinstance(poses, LazyPoses):
            return LazyPoses(functools.partial(self._renamed_poses, poses.make), len(self.parts)), checks, pts
        return self._renamed_poses(lambda: poses), checks, pts

    def _renamed_poses(self, make: Callable[[], Mapping[str, Array]]) -> dict[str, Array]:
        """The walker's poses (``make()``) as the built parts': each web moves as the crankshaft, each plate
        stands as the ground (the same arrays, not copies)."""
        out = dict(make())
        shaft = out.pop("crankshaft")
        g = out.pop(self.legs.ground_name)
        for w in self.webs:
            out[w] = shaft
        for pl in self.layer_stack[0]:
            out[pl] = g
        return out


def auto_standoffs(legs: Legs, samples: int = 72) -> tuple[tuple[float, float], ...]:
    """Two standoff points for a walker's frame plates (model units, ground frame), or none where none fits.

    Every moving part (the crankshaft's hull standing for its webs) swept over the cycle and grown by one link
    width is kept out of; of the points left on a grid of half a link width, the one nearest the crank axis is
    the first standoff and the nearest one at least 120 degrees round the axis from it the second.
    """
    import shapely
    from shapely import affinity

    motion = legs.run(samples_per_cycle=samples)
    ok = np.flatnonzero(motion.valid)
    moving = [p for p in legs.parts if not p.ground]
    swept = []
    for p in moving:
        shape = p.outline.simplify(0.01 * legs.width)
        for x, y, a in np.asarray(motion.poses[p.name])[ok]:
            c, s = math.cos(a), math.sin(a)
            swept.append(affinity.affine_transform(shape, [c, -s, s, c, x, y]))
    keep_out = shapely.union_all(swept).buffer(legs.width)
    o = np.asarray(legs._anchors[legs.ground_name][legs.crank_centre])
    x0, y0, x1, y1 = keep_out.bounds
    h = legs.width / 2
    gx, gy = np.meshgrid(np.arange(x0 - h, x1 + 2 * h, h), np.arange(y0 - h, y1 + 2 * h, h))
    pts = np.c_[gx.ravel(), gy.ravel()]
    free = pts[~shapely.contains_xy(keep_out, pts[:, 0], pts[:, 1])]
    if len(free) == 0:
        return ()
    d = np.hypot(*(free - o).T)
    first = free[np.argmin(d)]
    ang = np.arctan2(*(free - o).T[::-1]) - math.atan2(first[1] - o[1], first[0] - o[0])
    apart = np.abs((ang + math.pi) % (2 * math.pi) - math.pi) >= 2 * math.pi / 3
    if not apart.any():
        return ((float(first[0]), float(first[1])),)
    second = free[apart][np.argmin(d[apart])]
    return ((float(first[0]), float(first[1])), (float(second[0]), float(second[1])))
