"""Placement: the stages' free joint moves annealed toward a small footprint; disc-cam variants."""

from __future__ import annotations

import itertools
import math
import time
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from planar.errors import InputError
from planar.synth.design.request import Placement
from planar.synth.design.sizing import _stage_params
from planar.windup.chain import Chain, ToyMechanism
from planar.windup.mechanisms import ELEMENTAL, ElementalMechanism, check_params, params_for

Array = NDArray[np.float64]

# ----------------------------------------------------------------------------- placement

#: candidate placement moves of a stage, tried on every stage: a name and the parameters it shifts together
#: (``+1``/``-1``), one component at a time.  A move is a placement variable of a stage only where it leaves
#: the stage's motion on its real input unchanged (to 1e-9, :func:`placement_variables`) and changes its
#: parts: e.g. #1's and #9's follower (``F_o``), #4's and #10's follower origin about its pin (``F_o`` with
#: ``F_jc`` back), #7's driver pin and follower pivot together, #8's pivot with its tab.
MOVES: tuple[tuple[str, dict[str, int]], ...] = (
    ("F_o", {"F_o": 1}),
    ("F_jc", {"F_jc": 1}),
    ("D_jc", {"D_jc": 1}),
    ("S_c", {"S_c": 1}),
    ("F_o-F_jc", {"F_o": 1, "F_jc": -1}),
    ("F_o-S_c", {"F_o": 1, "S_c": -1}),
    ("F_o+D_jc", {"F_o": 1, "D_jc": 1}),
)
#: the shifts (model units) a move is tried at before it is taken as a placement variable
MOVE_PROBES = (-0.2, -0.05, 0.05, 0.2)
#: annealing: iterations, step (model units), box around the default position (model units), overlap weight
ANNEAL_STEPS = 40
ANNEAL_STEP = 0.08
ANNEAL_BOX = 0.4
OVERLAP_WEIGHT = 10.0
#: outline simplification in the placement objective (model units)
SIMPLIFY = 0.003
#: how many of the best annealed layouts are checked against the fabrication
PLACEMENT_OPTIONS = 2
#: a pin's radius in the placement's clash penalty (model units: 1.5 mm)
PIN_RADIUS = 0.015
#: the pieces' crowding in the placement objective (model units at 100 mm a unit, the export's defaults): the
#: least wall between cuts with the clearance (2 mm), the motor's shaft clearance and screws (9 mm apart)
WALL = 0.02
MOTOR_SHAFT_R = 0.023
MOTOR_SCREW_X = 0.045
MOTOR_SCREW_R = 0.012
#: crowding counts this many times its area in the overlap (the export refuses a crowded piece, while
#: overlapping pieces may still go on different layers)
CROWDING_WEIGHT = 1000.0


def _posed(shape: Any, pose: Array) -> Any:
    """``shape`` (own frame) placed at every pose of ``pose`` (k x 3: x, y, angle in rad): k geometries,
    transformed in one array expression (every copy has the same coordinates, in order)."""
    import shapely

    n = int(shapely.get_num_coordinates(shape))
    geoms = np.empty(len(pose), dtype=object)
    geoms[:] = [shape] * len(pose)
    P = np.repeat(pose, n, axis=0)
    c, s = np.cos(P[:, 2]), np.sin(P[:, 2])

    def move(xy: Array) -> Array:
        return np.column_stack([P[:, 0] + c * xy[:, 0] - s * xy[:, 1], P[:, 1] + s * xy[:, 0] + c * xy[:, 1]])

    return shapely.transform(geoms, move)


def _layout_score(toy: ToyMechanism, samples: int = 8) -> tuple[float, float]:
    """``(footprint, overlap)`` of the toy's pieces over one cycle (``samples`` poses), units^2.

    Footprint: the convex hull area of every piece's swept region, summed over
    the planes the pieces move in (xy, and xz/yz for #8, #6, #9).  Overlap:
    the swept overlap of pieces of one plane that no joint connects (pairs
    that must go on different layers), plus the area pins sweep through pieces
    of their plane they do not hold, plus the pieces' crowding (a piece's cuts,
    each grown by half a wall, overlapping one another, or the frame's the
    motor's screws: what the export refuses as too little material),
    ``CROWDING_WEIGHT`` x its area.
    """
    import shapely

    from planar.core.model import Hole
    from planar.core.outlines import feature_shape
    from planar.fabrication.joints import joint_pins
    from planar.fabrication.layers import pin_stacks
    from planar.toys.assembly import ToyAssembly

    asm = ToyAssembly(toy)
    m = asm.run(samples_per_cycle=samples)
    joined = {frozenset((j.a, j.b)) for j in asm.joints}
    plane = {p.name: p.plane for p in asm.parts}
    swept = {}
    for p in asm.parts:
        pose = np.asarray(m.poses[p.name])
        if p.ground:
            pose = pose[:1]  # a frame does not move
        shape = p.outline.simplify(SIMPLIFY)  # 0.3 mm: the objective need not follow every facet of a cam
        swept[p.name] = shapely.union_all(_posed(shape, pose))
    footprint = sum(
        float(shapely.union_all([g for n, g in swept.items() if plane[n] == pl]).convex_hull.area)
        for pl in sorted(set(plane.values()))
    )
    overlap = 0.0
    names = [n for n in swept if not asm.part(n).ground]
    for a, b in itertools.combinations(names, 2):
        if plane[a] == plane[b] and frozenset((a, b)) not in joined:
            overlap += float(swept[a].intersection(swept[b]).area)
    # pins crossing pieces they do not join (the fabrication would need them on layers outside the pin)
    pins, _ = joint_pins(asm)
    for stack in pin_stacks(pins):
        on = {n for i in stack for n in pins[i].parts}
        pin = pins[stack[0]]
        a = pin.parts[0]
        if a not in swept:
            continue
        pose = np.asarray(m.poses[a])
        c, s = np.cos(pose[:, 2]), np.sin(pose[:, 2])
        x, y = pin.at[0]
        path = np.c_[pose[:, 0] + c * x - s * y, pose[:, 1] + s * x + c * y]
        geom = shapely.buffer(
            shapely.points(path[0]) if np.ptp(path, axis=0).max() < 1e-9 else shapely.linestrings(path), PIN_RADIUS
        )
        for n in names:
            if n not in on and plane[n] == plane[a]:
                overlap += float(swept[n].intersection(geom).area)
    # a piece's cuts too close to one another, the frame's to the motor (each piece in its own frame)
    for p in asm.parts:
        cuts = [
            feature_shape(f, WALL / 2)
            for f in p.features
            if not (p.ground and p.plane == "xy" and isinstance(f, Hole) and np.hypot(*f.centre) < 1e-9)
        ]
        if p.ground and p.plane == "xy":
            cuts += [shapely.Point(sx * MOTOR_SCREW_X, 0.0).buffer(MOTOR_SCREW_R + WALL / 2) for sx in (-1, 1)]
            cuts.append(shapely.Point(0.0, 0.0).buffer(MOTOR_SHAFT_R + WALL / 2))
        for g, h in itertools.combinations(cuts, 2):
            if not (g.contains(h) or h.contains(g)):
                overlap += CROWDING_WEIGHT * float(g.intersection(h).area)
    return footprint, overlap


@dataclass(frozen=True)
class PlacementVariable:
    """One placement variable: a stage (``cam``, ``key``), a move of :data:`MOVES` and the component it shifts."""

    cam: str
    key: Chain
    move: str
    shifts: tuple[tuple[str, int], ...]
    comp: int

    @property
    def label(self) -> str:
        return f"{self.cam} {' '.join(self.key)}: {self.move}[{'xyz'[self.comp]}]"


def _shifted(kw: dict[str, Any], number: int, var: PlacementVariable, dx: float) -> dict[str, Any]:
    """``kw`` with ``var``'s move applied by ``dx`` (model units)."""
    out = dict(kw)
    defaults = params_for(number)
    for pname, sign in var.shifts:
        cur = list(out.get(pname, getattr(defaults, pname)))
        cur[var.comp] = float(cur[var.comp]) + sign * dx
        out[pname] = tuple(cur)
    return out


def _geometry(mech: ElementalMechanism) -> Any:
    """What a stage's placement changes: its parts' hulls, cuts and outlines, and its follower's rest pose."""
    out = np.zeros((1, 3)) if mech.motion_out == "OzT" else np.zeros(1)
    return ([(p.hull, p.features, p.polygon) for p in mech.parts], np.round(mech._follower_pose(out), 12).tolist())


def placement_variables(toy: ToyMechanism, samples: int = 181) -> list[PlacementVariable]:
    """Every stage's moves (:data:`MOVES`, one component each) that change its parts but not its motion.

    A move qualifies when, at every shift of :data:`MOVE_PROBES`, the stage's
    parameters are accepted, its follower's motion on the input the toy
    gives it (``samples`` of a cycle) is unchanged to 1e-9 and valid, and its
    parts or its follower's rest pose (where its children sit) change.
    """
    q = np.linspace(0.0, 2 * math.pi, samples)
    toy.world_motion(q)
    bases = toy._last_bases
    found: list[PlacementVariable] = []
    for st in toy.stages:
        number = st.realisation.number
        u, res = bases[st.index]
        kw = dict(toy.stage_overrides.get((st.cam, st.key), {}))
        try:  # the stage rebuilt on the same samples (its slots' lengths follow the input it is built for)
            geo0 = _geometry(ToyMechanism._build_stage(st.realisation, u, dict(kw), toy.name, st.key))
        except InputError:
            continue
        defaults = params_for(number)
        for move, shifts in MOVES:
            if not all(hasattr(defaults, n) for n in shifts):
                continue
            width = min(len(getattr(defaults, n)) for n in shifts)
            for comp in range(width):
                var = PlacementVariable(st.cam, st.key, move, tuple(shifts.items()), comp)
                ok = True
                moved = False
                for dx in MOVE_PROBES:
                    kw2 = _shifted(kw, number, var, dx)
                    try:
                        P = _stage_params(number, kw2, u)
                        check_params(number, P)
                        r2 = ELEMENTAL[number].forward(P, u)
                        mech = ToyMechanism._build_stage(st.realisation, u, dict(kw2), toy.name, st.key)
                    except InputError:
                        ok = False
                        break
                    if not np.all(r2.valid) or not np.allclose(r2.out, res.out, rtol=0, atol=1e-9):
                        ok = False
                        break
                    moved = moved or _geometry(mech) != geo0
                if ok and moved:
                    found.append(var)
    # one move per stage and component where several do the same (F_o alone and F_o with D_jc on a #1):
    # the first in MOVES order is kept
    out: list[PlacementVariable] = []
    for v in found:
        if not any(
            o.cam == v.cam and o.key == v.key and o.comp == v.comp and dict(o.shifts).keys() <= dict(v.shifts).keys() for o in out
        ):
            out.append(v)
    return out


def place_stages(
    cams: dict[str, list[Chain]],
    phase: float,
    name: str,
    overrides: dict[tuple[str, Chain], dict[str, Any]],
    names: dict[tuple[str, Chain], str],
    seed: int = 0,
) -> tuple[list[tuple[dict[tuple[str, Chain], dict[str, Any]], tuple[float, float, float]]], Placement]:
    """Anneal the placement variables (:func:`placement_variables`) to a compact toy whose pieces overlap little.

    Returns the best ``PLACEMENT_OPTIONS`` distinct layouts the annealing
    accepted that improve on the start (overrides and ``(objective,
    footprint, overlap)``, best first) and what it did; the caller checks
    them against the fabrication in turn.

    Objective: footprint + ``OVERLAP_WEIGHT`` x overlap (:func:`_layout_score`).
    A move that changes any stage's motion (compared on 181 samples to 1e-9)
    or that the toy cannot be built with is rejected.  Simulated annealing
    with a fixed seed (same request, same toy), ``ANNEAL_STEPS`` moves, each
    shifting a random subset of the variables.
    """
    t0 = time.perf_counter()
    q = np.linspace(0.0, 2 * math.pi, 181)
    base = ToyMechanism(cams, phase=phase, name=name, overrides=overrides, names=names)
    variables = placement_variables(base)
    number = {(st.cam, st.key): st.realisation.number for st in base.stages}

    def layout(x: Array) -> dict[tuple[str, Chain], dict[str, Any]]:
        ov = {k: dict(v) for k, v in overrides.items()}
        for v, dx in zip(variables, x):
            if dx != 0.0:
                ov[(v.cam, v.key)] = _shifted(ov.get((v.cam, v.key), {}), number[(v.cam, v.key)], v, float(dx))
        return ov

    def build(x: Array) -> ToyMechanism | None:
        try:
            return ToyMechanism(cams, phase=phase, name=name, overrides=layout(x), names=names)
        except InputError:
            return None

    ref, _ = base.world_motion(q)
    ref = {k: v.copy() for k, v in ref.items()}

    def score(x: Array) -> tuple[float, float, float, ToyMechanism | None]:
        toy = build(x)
        if toy is None:
            return math.inf, math.inf, math.inf, None
        if not _moves_as(toy, q, ref):
            return math.inf, math.inf, math.inf, None
        try:
            fp, ovl = _layout_score(toy)
        except InputError:
            return math.inf, math.inf, math.inf, None
        return fp + OVERLAP_WEIGHT * ovl, fp, ovl, toy

    labels = [v.label for v in variables]
    x0 = np.zeros(len(variables))
    f0, fp0, ov0, _ = score(x0)
    if not variables or not math.isfinite(f0):
        return [], Placement(labels, (f0, f0), (fp0, fp0), (ov0, ov0), 1, 0, time.perf_counter() - t0, kept=False)
    rng = np.random.default_rng(seed)
    lo, hi = x0 - ANNEAL_BOX, x0 + ANNEAL_BOX
    x, fx = x0.copy(), f0
    states: list[tuple[float, float, float, Array]] = []  # accepted layouts better than the start
    temp0 = 0.05 * f0
    evals, rejected = 1, 0
    p_move = max(1.0 / len(variables), 0.3)
    for k in range(ANNEAL_STEPS):
        temp = temp0 * (1 - k / ANNEAL_STEPS) + 1e-12
        mask = rng.random(x.size) < p_move
        mask[rng.integers(x.size)] = True
        y = np.clip(x + mask * rng.normal(0.0, ANNEAL_STEP, x.size), lo, hi)
        fy, fpy, ovy, _ = score(y)
        evals += 1
        if not math.isfinite(fy):
            rejected += 1
            continue
        if fy <= fx or rng.random() < math.exp(-(fy - fx) / temp):
            x, fx = y, fy
            if fy < f0 and all(np.abs(y - st[3]).max() > 1e-9 for st in states):
                states.append((fy, fpy, ovy, y.copy()))
    options = [(layout(xs), (f, fp, ov)) for f, fp, ov, xs in sorted(states, key=lambda t: t[0])[:PLACEMENT_OPTIONS]]
    return options, Placement(labels, (f0, f0), (fp0, fp0), (ov0, ov0), evals, rejected, time.perf_counter() - t0, kept=False)


#: cam-in-window stages (#1-#3): their motion follows the eccentricity alone, not the disc's radius
DISC_CAMS = (1, 2, 3)
#: material kept round the axle's boss when a cam is grown into a disc (model units: 1 mm)
DISC_MARGIN = 0.01


def _disc_cams(
    cams: dict[str, list[Chain]],
    phase: float,
    name: str,
    overrides: dict[tuple[str, Chain], dict[str, Any]],
    names: dict[tuple[str, Chain], str],
) -> dict[tuple[str, Chain], dict[str, Any]] | None:
    """``overrides`` with every #1-#3 cam that would be a crank (its axle's boss leaving the disc,
    ``|D_jc| + 2 D_ar > D_jr``) grown into a disc holding the boss, or None when none is; None too when the
    grown toy moves differently (compared on 181 samples to 1e-9) or cannot be built.

    A crank is cut as a pin in a pin-wide slot across layers, so its follower covers the motor shaft and
    must lie outside the cams' layers; a disc runs in its follower's window in one layer."""
    toy = ToyMechanism(cams, phase=phase, name=name, overrides=overrides, names=names)
    out = {k: dict(v) for k, v in overrides.items()}
    grown = False
    for st in toy.stages:
        if st.realisation.number not in DISC_CAMS:
            continue
        P = st.mech.params
        e = float(np.hypot(P.D_jc[0], P.D_jc[1]))
        if e + 2 * P.D_ar > P.D_jr:
            out.setdefault((st.cam, st.key), {})["D_jr"] = e + 2 * P.D_ar + DISC_MARGIN
            grown = True
    if not grown:
        return None
    q = np.linspace(0.0, 2 * math.pi, 181)
    try:
        disc = ToyMechanism(cams, phase=phase, name=name, overrides=out, names=names)
    except InputError:
        return None
    ref, _ = toy.world_motion(q)
    return out if _moves_as(disc, q, ref) else None


def _moves_as(toy: ToyMechanism, q: Array, ref: dict[int, Array]) -> bool:
    """Whether ``toy`` closes at every motor angle ``q`` (rad) and moves every stage's follower as ``ref`` (world
    motions at ``q``, per stage) does, to 1e-9."""
    got, checks = toy.world_motion(q)
    return all(np.all(ok) for ok, _, _ in checks) and all(np.allclose(got[k], ref[k], rtol=0, atol=1e-9) for k in ref)


def _variants(
    cams: dict[str, list[Chain]],
    phase: float,
    name: str,
    overrides: dict[tuple[str, Chain], dict[str, Any]],
    names: dict[tuple[str, Chain], str],
) -> list[tuple[str, dict[tuple[str, Chain], dict[str, Any]]]]:
    """The sized tree as sized, then (when it has cranks) with its cams grown into discs (:func:`_disc_cams`)."""
    out: list[tuple[str, dict[tuple[str, Chain], dict[str, Any]]]] = [("", overrides)]
    try:
        disc = _disc_cams(cams, phase, name, overrides, names)
    except InputError:
        disc = None
    if disc is not None:
        out.append(("its cams grown into discs", disc))
    return out
