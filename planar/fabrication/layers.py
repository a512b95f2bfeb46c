"""How the cut parts go together: layers, pins, spacers, hole letters.

* Swept areas: each part's material (outline minus cuts, nominal, mm) moved
  through the mechanism's cycle (``mech.run()``, valid samples) and united.
* Layers: parts whose swept areas overlap (more than ``OVERLAP_MM2``) must lie
  on different layers; parts touching through a contact (a cam in a hole, a cam
  on a face) on the same one when their material overlaps at no instant (else
  the contact reaches across layers, like a tab through a window).  The fewest layers are found by exhaustive
  search over layer assignments (graph colouring, exact for these small
  graphs), and among those the assignment whose pins cross no part on a layer
  between their ends, then with the fewest spacers, is kept; when every
  fewest-layer assignment has such a clash, up to two more layers are tried.  Parts moving in
  another plane (``Part.plane``) are layered among themselves.
* Pins: a pin spans the layers from one part to the other; every layer in
  between that it does not join gets a spacer ring (cut from the sheet) of one
  sheet thickness.  Pin length = thickness x layers spanned + two heads.
* Pins sharing a hole (two joints at one point of one part) are one pin
  through all their parts.  Letters: pins are lettered A, B, ... in joint
  order; the same letter is engraved beside the pin's holes and printed on the
  assembly drawing.
"""

from __future__ import annotations

import functools
import itertools
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from planar.core.model import Mechanism
from planar.errors import InputError
from planar.fabrication.joints import Contact, PinSpec

__all__ = ["Assembly", "PinPlan", "letter", "plan_assembly"]

OVERLAP_MM2 = 0.5
MAX_ASSIGNMENTS = 200_000


def letter(i: int) -> str:
    """A, B, ..., Z, AA, AB, ..."""
    s = ""
    i += 1
    while i:
        i, r = divmod(i - 1, 26)
        s = chr(65 + r) + s
    return s


def pin_stacks(pins: list[PinSpec]) -> list[list[int]]:
    """Pins sharing a hole (same part, same anchor) are one physical pin through all their parts."""
    root = list(range(len(pins)))

    def find(i: int) -> int:
        while root[i] != i:
            i = root[i]
        return i

    seen: dict[tuple[str, float, float], int] = {}
    for i, p in enumerate(pins):
        for side in (0, 1):
            if p.kinds[side] != "hole":
                continue
            key = (p.parts[side], round(p.at[side][0], 9), round(p.at[side][1], 9))
            if key in seen:
                a, b = find(seen[key]), find(i)
                root[max(a, b)] = min(a, b)
            else:
                seen[key] = i
    groups: dict[int, list[int]] = {}
    for i in range(len(pins)):
        groups.setdefault(find(i), []).append(i)
    return sorted(groups.values())


@dataclass
class PinPlan:
    letter: str
    spec: PinSpec
    layers: tuple[int, int] | None
    spacers: int
    length_mm: float
    diameter_mm: float
    shaft: bool = False
    #: every part on this pin (a pin shared by several joints at one hole joins them all)
    parts: tuple[str, ...] = ()
    joints: tuple[str, ...] = ()
    #: parts on layers between the pin's ends that its path crosses (a clash)
    clashes: list[str] = field(default_factory=list)


@dataclass
class Assembly:
    layers: dict[str, int | None]
    n_layers: dict[str, int]
    pins: list[PinPlan]
    contacts: list[Contact]
    #: world transform (mm) of each part at the drawn pose: (x, y, angle)
    pose: dict[str, tuple[float, float, float]]
    notes: list[str] = field(default_factory=list)
    plane: dict[str, str] = field(default_factory=dict)
    unit_mm: float = 1.0


def _placed(poly, pose: np.ndarray, u: float):
    from shapely import affinity

    x, y, a = pose
    c, s = math.cos(a), math.sin(a)
    return affinity.affine_transform(poly, [c, -s, s, c, x * u, y * u])


def _swept(poly, poses: np.ndarray, u: float):
    import shapely

    poly = poly.simplify(0.05)
    return shapely.union_all([_placed(poly, p, u) for p in poses]).buffer(0)


def _check_mech(mech: Any, material: Any, shaft_pin: Any) -> None:
    """:func:`plan_assembly`'s mechanism (a Mechanism, or a view of one: what runs and has parts), its parts'
    material polygons and the motor's pin (a joint's name or None)."""
    if not callable(getattr(mech, "run", None)) or not hasattr(mech, "parts"):
        raise InputError("mech", mech, "a Mechanism (a linkage, a cam or a toy)")
    missing = [p.name for p in mech.parts if not isinstance(material, dict) or p.name not in material]
    if missing:
        raise InputError("material", material, f"a dict of every part's material polygon (mm), {missing[0]!r} too")
    if shaft_pin is not None and not isinstance(shaft_pin, str):
        raise InputError("shaft_pin", shaft_pin, "the name of the joint the motor drives (or None)")


def _check_sizes(unit_mm: Any, thickness: Any, pin_mm: Any, pin_head: Any, ring_mm: Any, samples: Any) -> None:
    """:func:`plan_assembly`'s sizes (mm) and sample count, each named when wrong."""
    from planar.core.fields import check_number
    from planar.errors import InputError

    for name, value in (("unit_mm", unit_mm), ("thickness", thickness), ("pin_mm", pin_mm), ("pin_head", pin_head)):
        if not check_number(name, value) > 0:
            raise InputError(name, value, "a positive size in mm")
    if ring_mm is not None and not check_number("ring_mm", ring_mm) > 0:
        raise InputError("ring_mm", ring_mm, "a positive diameter in mm (or None)")
    if not 2 <= check_number("samples", samples, integer=True) <= 100_000:
        raise InputError("samples", samples, "a whole number of samples, 2 to 100 000")


def plan_assembly(
    mech: Mechanism,
    material: dict[str, Any],
    pins: list[PinSpec],
    contacts: list[Contact],
    unit_mm: float,
    thickness: float,
    pin_mm: float,
    pin_head: float,
    shaft_pin: str | None = None,
    samples: int = 48,
    ring_mm: float | None = None,
) -> Assembly:
    """Layers, pins and spacers for ``mech`` whose parts' material polygons (mm, own frame) are given.

    ``ring_mm``: the outer diameter of a spacer ring (default ``pin_mm``): a part between a pin's ends must clear
    the ring on the pin, not only the pin.
    """
    _check_mech(mech, material, shaft_pin)
    _check_sizes(unit_mm, thickness, pin_mm, pin_head, ring_mm, samples)
    from shapely.geometry import LineString, Point

    u = unit_mm
    motion = mech.run(samples_per_cycle=samples)
    ok = np.flatnonzero(motion.valid)
    if ok.size == 0:
        ok = np.arange(len(motion))
    poses = {n: np.asarray(motion.poses[n])[ok] for n in material}
    names = [p.name for p in mech.parts]
    plane = {p.name: p.plane for p in mech.parts}
    swept = {n: _swept(material[n], poses[n], u) for n in names}
    # pin paths (mm) and which other parts they pass through
    paths = []
    for pin in pins:
        a = pin.parts[0]
        loc = np.asarray(pin.at[0], float)
        pa = poses[a]
        c, s = np.cos(pa[:, 2]), np.sin(pa[:, 2])
        xy = np.c_[pa[:, 0] + c * loc[0] - s * loc[1], pa[:, 1] + s * loc[0] + c * loc[1]] * u
        geom = (
            LineString(xy).buffer((ring_mm or pin_mm) / 2)
            if len(xy) > 1 and np.ptp(xy, axis=0).max() > 1e-9
            else Point(xy[0]).buffer((ring_mm or pin_mm) / 2)
        )
        paths.append(geom)
    stacks = pin_stacks(pins)
    stack_parts = [tuple(dict.fromkeys(p for i in st for p in pins[i].parts)) for st in stacks]
    crossing = [
        sorted(
            {
                q
                for i in st
                for q in names
                if q not in sp and plane[q] == plane[sp[0]] and swept[q].intersection(paths[i]).area > OVERLAP_MM2 / 5
            },
            key=names.index,
        )
        for st, sp in zip(stacks, stack_parts)
    ]
    # contacts merge parts into one node
    root = {n: n for n in names}

    def find(n: str) -> str:
        while root[n] != n:
            n = root[n]
        return n

    notes: list[str] = []

    def worst_overlap(x: str, y: str) -> float:
        return max(
            _placed(material[x], poses[x][i], u).intersection(_placed(material[y], poses[y][i], u)).area
            for i in range(len(poses[x]))
        )

    for ct in contacts:
        x, y = ct.parts
        # a cam running in a hole or on an edge of the same sheet shares its layer; one whose material
        # overlaps the other's (a tab reaching through a window) touches it from another layer
        if ct.coplanar and plane[x] == plane[y]:
            worst = worst_overlap(x, y)
            if worst > OVERLAP_MM2 and ct.through:
                continue  # a tab reaching through a window: it touches from another layer
            if worst > OVERLAP_MM2:
                # a flat part drives only what lies in its own layer: a cam (or roller, or gear) whose material
                # overlaps its follower's cannot share the follower's layer, and on another it drives nothing
                from planar.fabrication.joints import FabricationError

                raise FabricationError(
                    f"joint {ct.joint!r}: {x} must touch {y} in one layer, but their material overlaps by "
                    f"{worst:.1f} mm^2 over the cycle (a larger window or slot, or a smaller cam, clears it)"
                )
            ra, rb = find(x), find(y)
            if ra != rb:
                root[max(ra, rb, key=names.index)] = min(ra, rb, key=names.index)
    layers: dict[str, int | None] = {}
    n_layers: dict[str, int] = {}
    stack = getattr(mech, "layer_stack", None)  # a walker's slabs: one leg's layers planned once, repeated
    for pl in sorted(set(plane.values()), key=lambda v: (v != "xy", v)):
        members = [n for n in names if plane[n] == pl]
        if pl == "xy" and stack is not None:
            layers.update(_stacked_layers(stack, swept, stack_parts, crossing, notes))
            n_layers[pl] = 1 + max(v for n, v in layers.items() if n in members and v is not None)
            continue
        nodes = sorted({find(n) for n in members}, key=names.index)
        group = {r: [n for n in members if find(n) == r] for r in nodes}
        for g in group.values():  # parts in contact share a layer: they must not overlap at any instant
            for x, y in itertools.combinations(g, 2):
                worst = worst_overlap(x, y)
                if worst > OVERLAP_MM2:
                    notes.append(f"{x} and {y} touch (a contact) on one layer but overlap by {worst:.1f} mm^2")
        adj: dict[str, set[str]] = {r: set() for r in nodes}
        for x, y in itertools.combinations(nodes, 2):
            if any(swept[p].intersection(swept[q]).area > OVERLAP_MM2 for p in group[x] for q in group[y]):
                adj[x].add(y)
                adj[y].add(x)
        node_pins = [(i, [find(p) for p in sp]) for i, sp in enumerate(stack_parts) if plane[sp[0]] == pl]
        grounds = [r for r in nodes if any(p.ground for p in mech.parts if p.name in group[r])]
        assign, _ = _best_layers(nodes, adj, node_pins, crossing, group, find, grounds[0] if grounds else None)
        used = sorted(set(assign.values()))
        assign = {r: used.index(v) for r, v in assign.items()}
        n_layers[pl] = len(used)
        for r in nodes:
            for n in group[r]:
                layers[n] = assign[r]
    plans = _pin_plans(pins, stacks, stack_parts, crossing, layers, (thickness, pin_mm, pin_head), shaft_pin, notes)
    notes += _glue_notes(set(getattr(mech, "glued", ())), pins, plans)
    first = int(ok[0])
    pose = {
        n: (float(motion.poses[n][first, 0] * u), float(motion.poses[n][first, 1] * u), float(motion.poses[n][first, 2]))
        for n in names
    }
    return Assembly(layers, n_layers, plans, contacts, pose, notes, plane, u)


def _glue_notes(glued: set[str], pins: list[PinSpec], plans: list[PinPlan]) -> list[str]:
    """One note per pin carrying a glued joint (``glued``: joint names; a walker's crank webs on the short shaft
    through a plate): which parts to glue on it."""
    out = []
    for pp in plans:
        for j in sorted(glued & set(pp.joints)):
            webs = " and ".join(str(p.parts[side]) for p in pins if p.joint == j for side in (0, 1))
            out.append(
                f"pin {pp.letter}: glue {webs} on it at their angles (a drop of cyanoacrylate or epoxy in each hole): "
                "they turn together with the rod, which runs in the plate between them"
            )
    return out


def _stacked_layers(
    stack: tuple[tuple[str, ...], tuple[Any, ...]],
    swept: dict[str, Any],
    stack_parts: list[tuple[str, ...]],
    crossing: list[list[str]],
    notes: list[str],
) -> dict[str, int]:
    """Layers of a walker's slabs (:class:`planar.linkages.legs.Slab`): the first slab planned (its plate at 0,
    the near web on 1, the leg's links above, the far web on top; fewest layers with no pin clash, as
    :func:`_best_layers`), every other slab the same stack, turned over when it hangs below its plate; the
    plates between slabs.  Where no order clears every pin, ``notes`` says so."""
    plates, slabs = stack
    first = slabs[0]
    roles = {first.plate: "plate", first.near: "near", first.far: "far", **{v: k for k, v in first.links.items()}}
    nodes = list(roles)
    links = list(first.links.values())
    adj: dict[str, set[str]] = {r: set() for r in nodes}
    for x, y in itertools.combinations(nodes, 2):
        if x not in links or y not in links or swept[x].intersection(swept[y]).area > OVERLAP_MM2:
            adj[x].add(y)
            adj[y].add(x)
    # every slab's pins, carried onto the first slab's parts by role: the legs are one leg at other phases, so a
    # graze one leg's samples catch holds for them all
    by_role = {v: k for k, v in roles.items()}
    pins_q = []
    for sl in slabs:
        mine = {sl.plate: "plate", sl.near: "near", sl.far: "far", **{v: k for k, v in sl.links.items()}}
        for i, sp in enumerate(stack_parts):
            ends = sorted({by_role[mine[p]] for p in sp if p in mine}, key=nodes.index)
            if len(ends) >= 2:
                crossed = sorted({by_role[mine[q]] for q in crossing[i] if q in mine} - set(ends), key=nodes.index)
                pins_q.append((i, ends, crossed))
    order = sorted(nodes, key=lambda r: (-len(adj[r]), nodes.index(r)))
    chosen: tuple[tuple[int, int, int], dict[str, int]] | None = None
    for k in range(3, len(nodes) + 3):
        fixed = {first.plate: 0, first.near: 1, first.far: k - 1}
        best = _search(order, adj, k, functools.partial(_score, pins_q), fixed)
        if best is not None and (chosen is None or best[0][0] < chosen[0][0]):
            chosen = best
        if chosen is not None and chosen[0][0] == 0:
            break
    assert chosen is not None  # k = len(nodes) + 2 layers hold every part on a layer of its own
    if chosen[0][0]:
        notes.append(
            f"walker slab: no order of one leg's {len(links)} links on up to {len(nodes) + 2} layers (the search "
            f"stops at {MAX_ASSIGNMENTS:,} assignments a layer count) keeps every pin clear of the parts between its ends"
        )
    rel = {roles[n]: v for n, v in chosen[1].items()}
    size = max(rel.values()) + 1
    out = {pl: k * size for k, pl in enumerate(plates)}
    for i, sl in enumerate(slabs):
        mine = {sl.plate: "plate", sl.near: "near", sl.far: "far", **{v: k for k, v in sl.links.items()}}
        for part, role in mine.items():
            if role != "plate":
                out[part] = (i + 1) * size - rel[role] if sl.reversed else i * size + rel[role]
    return out


def _pin_plans(
    pins: list[PinSpec],
    stacks: list[list[int]],
    stack_parts: list[tuple[str, ...]],
    crossing: list[list[str]],
    layers: dict[str, int | None],
    sizes: tuple[float, float, float],
    shaft_pin: str | None,
    notes: list[str],
) -> list[PinPlan]:
    """One :class:`PinPlan` per pin stack: its layers, spacers, length (``sizes``: thickness, pin diameter, head
    allowance, mm) and the parts it crosses between its ends (each noted in ``notes``)."""
    thickness, pin_mm, pin_head = sizes
    plans = []
    for i, (st, sp) in enumerate(zip(stacks, stack_parts)):
        ls = sorted({lp for p in sp if (lp := layers[p]) is not None})
        lo, hi = (ls[0], ls[-1]) if ls else (0, 0)
        clashes = [q for q in crossing[i] if (lq := layers[q]) is not None and lo < lq < hi]
        joints = tuple(pins[j].joint for j in st)
        shaft = any(pins[j].joint == shaft_pin for j in st)
        length = thickness * (hi - lo + 1) + 2 * pin_head
        plans.append(
            PinPlan(letter(i), pins[st[0]], (lo, hi), (hi - lo + 1) - len(ls), length, pin_mm, shaft, sp, joints, clashes)
        )
        if clashes:
            notes.append(f"pin {letter(i)} ({', '.join(joints)}) passes through {', '.join(clashes)} between its layers")
    return plans


def _score(pins_q: list, a: dict[str, int]) -> tuple[int, int, int]:
    """(pin clashes, spacers, spread) of a partial layer assignment ``a`` (only placed pins count)."""
    clash = spacers = spread = 0
    for _, ns, qs in pins_q:
        if any(n not in a for n in ns):
            continue
        ls = {a[n] for n in ns}
        lo, hi = min(ls), max(ls)
        spacers += hi - lo + 1 - len(ls)
        spread += hi - lo
        clash += sum(1 for q in qs if q in a and lo < a[q] < hi)
    return clash, spacers, spread


def _search(
    order: list[str],
    adj: dict,
    k: int,
    score: Callable[[dict[str, int]], tuple[int, int, int]],
    fixed: dict[str, int] | None = None,
) -> tuple[tuple[int, int, int], dict[str, int]] | None:
    """Best assignment of ``k`` layers to ``order`` (neighbours in ``adj`` apart), depth first with bounds;
    ``fixed`` nodes take only their given layer."""
    best: list = [None]
    count = [0]
    assign: dict[str, int] = {}

    def dfs(idx: int) -> None:
        if count[0] >= MAX_ASSIGNMENTS:
            return
        count[0] += 1
        sc = score(assign)
        if best[0] is not None and sc >= best[0][0]:
            return
        if idx == len(order):
            best[0] = (sc, dict(assign))
            return
        r = order[idx]
        used = {assign[n] for n in adj[r] if n in assign}
        for c in [fixed[r]] if fixed and r in fixed else range(k):
            if c not in used:
                assign[r] = c
                dfs(idx + 1)
                del assign[r]

    dfs(0)
    return best[0]


def _best_layers(nodes, adj, node_pins, crossing, group, find, bottom: str | None = None) -> tuple[dict[str, int], int]:
    """Fewest layers (exact), then no pin clashes, then fewest spacers; first found wins ties.

    ``bottom``: a node held at layer 0 (the ground plate: the motor sits under it, so nothing may be below).

    Depth-first over layer assignments with branch and bound: the score of a
    partial assignment (pins whose ends and crossed parts are all placed) only
    grows, so a branch already no better than the best is cut.
    """
    order = sorted(nodes, key=lambda r: (-len(adj[r]), nodes.index(r)))
    pins_q = [(i, nodes_i, [find(q) for q in crossing[i]]) for i, nodes_i in node_pins]
    chromatic = 0
    chosen: tuple[tuple[int, int, int], dict[str, int], int] | None = None
    for k in range(1, len(nodes) + 1):
        if chromatic and k > chromatic + 2:  # two more layers did not clear the clashes
            break
        best = _search(order, adj, k, functools.partial(_score, pins_q), None if bottom is None else {bottom: 0})
        if best is None:
            continue
        chromatic = chromatic or k
        if chosen is None or best[0][0] < chosen[0][0]:
            chosen = (best[0], best[1], k)
        if best[0][0] == 0:
            break
    if chosen is None:
        first = sorted(nodes, key=lambda r: r != bottom)
        return {r: i for i, r in enumerate(first)}, len(nodes)
    return chosen[1], chosen[2]
