"""Toy design from requested motions: the paper's pipeline, end to end (``planar design``).

A request lists end effectors (``[[effector]]``: ``name``, ``motion``,
``range``, optional ``cam`` and ``phase``).  :func:`design_toy`

1. **enumerates** every chain from the motor to each effector's motion (up to
   three stages, :func:`~planar.windup.table.enumerate_chains`);
2. **merges** one chain per effector into trees on the two cams (chains on one
   cam share their common prefix: one stage each), respecting a requested
   ``cam`` and putting effectors with different ``phase`` on different cams;
3. **ranks** the trees by the paper's cost (:func:`~planar.windup.chain.tree_cost`:
   mechanisms + 2 x mean chain length), cheapest first, skipping trees with a
   chain that cannot reach its effector's range (each chain's reachable range
   is scanned once, lazily, its sized stage's parameter varied) or that the toy
   assembly cannot build (a mirrored stage, a stage turned out of its plane);
   an unreachable range is refused naming the reach of the buildable chains;
4. **sizes** the cheapest tree that works: each effector's last stage's design
   parameter (:data:`~planar.windup.sizing.DESIGN_PARAMETER`; its parent's for a
   #10, whose stroke follows its driver's travel) is solved with
   :func:`scipy.optimize.brentq` so that the effector's range, composed
   through the tree (its parent's actual output, not a standalone law), is the
   request; stages are sized parents first;
5. **places** the stages (:func:`place_stages`): a toy's stages sit where the
   assembly puts them (a child's driver on its parent's follower, the roots on
   the motor axis); the free variables are each stage's joint moves that
   change no motion (:func:`placement_variables`: found per stage on its real
   input among :data:`MOVES`, e.g. #1's slider, #4's follower origin about its
   pin, #7's pin and pivot together), annealed toward a small footprint and
   little overlap of unjoined pieces or crowding of cuts; the result is kept
   only if it adds no export refusal, collision, pin clash or layer;
6. **checks** the result independently: each effector's range is measured on
   the assembled toy's piece poses, and the export's own layer plan
   (:func:`planar.app.export.build`) is checked with shapely for pieces of one
   layer overlapping at any of 24 sampled poses and for pins running through
   a piece; then the toy's physics (:func:`physics_check`, as ``planar toy``).
   A tree that fails is tried again with its cranks grown into disc cams
   (:func:`_disc_cams`, same motion), then passed over for the next cheapest
   (up to ``max_fabricated``); if all fail, the cheapest is returned with its
   failures (``planar design`` exits 3).

Units: ranges of O motions (and the rotation of OzT) in degrees, of T
motions in model units (one unit is 100 mm when cut); phases in cycles.
"""

from __future__ import annotations

import itertools
import math
import time
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from planar.errors import InputError, PlanarError
from planar.windup.chain import Chain, ToyMechanism, _to_base, _to_world, tree_cost
from planar.windup.mechanisms import ELEMENTAL, check_params, params_for
from planar.windup.sizing import DESIGN_PARAMETER
from planar.windup.table import MOTION_TYPES, enumerate_chains, realise

__all__ = ["Design", "Effector", "design_toy", "effector_ranges", "layer_collisions", "load_request"]

Array = NDArray[np.float64]
CAMS = ("left", "right")
#: samples of one motor turn used for sizing and for the checks
SAMPLES = 721
#: design-parameter values scanned per sized stage before root finding
SCAN = 97
#: relative range tolerance the check demands (the request says 1 %)
TOLERANCE = 0.01


@dataclass(frozen=True)
class Effector:
    """One requested end effector: ``range`` in degrees (O, OzT's rotation) or model units (T);
    ``phase`` in cycles, ``0 <= phase < 1`` (only differences between cams matter)."""

    name: str
    motion: str
    range: float
    cam: str | None = None
    phase: float = 0.0

    @property
    def target(self) -> float:
        """The range in the kinematics' units (radians or model units)."""
        return math.radians(self.range) if self.motion[0] == "O" else self.range

    def unit(self, value: float) -> str:
        """``value`` (kinematics units) in the request's units, with the unit."""
        return f"{math.degrees(value):.4g} deg" if self.motion[0] == "O" else f"{value:.4g} units"


@dataclass
class Design:
    """A designed toy: the sized mechanism, which tree, its cost and the checks' figures."""

    toy: ToyMechanism
    effectors: list[Effector]
    assignment: list[tuple[str, Chain]]
    cost: float
    ranges: dict[str, float]  # measured in the assembled toy, request units
    candidates: int  # trees considered (after the reachability filter)
    tried: int  # trees sized before one worked
    sizing: dict[str, tuple[str, str, float]]  # effector -> (stage chain, parameter, value)
    layers: dict[str, int] = field(default_factory=dict)
    collisions: list[tuple[str, str, float]] = field(default_factory=list)
    seconds: dict[str, float] = field(default_factory=dict)
    placement: Placement | None = None
    layers_before: int | None = None  # layers of the toy before placement
    clashes: list[str] = field(default_factory=list)  # pins crossing a piece between their layers
    rejected: list[str] = field(default_factory=list)  # cheaper trees whose fabrication collided
    before: dict[str, int] = field(default_factory=dict)  # layers, collisions, pin clashes before placement
    before_reason: str = ""  # why the export refused the pieces before placement, if it did
    physics: dict[str, Any] | None = None  # :func:`physics_check` of the written toy (None: not run)
    variant: str = ""  # how the tree differs from the tree as sized ("its cams grown into discs"), or ""
    fallback: bool = False  # every tree tried failed: this is the cheapest (``rejected[0]``), written with its failures

    @property
    def export_refused(self) -> str:
        """Why the export refuses the toy's pieces ("" when it cuts them; then ``clashes`` are pins only)."""
        return self.clashes[0] if not self.layers and self.clashes else ""

    @property
    def gravity_x(self) -> list[str]:
        """The #8 stages for which the toy is written with gravity along +x (:func:`design_scene`)."""
        return [st.label for st in self.toy.stages if st.realisation.number == 8]

    @property
    def gravity_y(self) -> list[str]:
        """The #6/#9 stages for which the toy is written with gravity along -y (:func:`design_scene`)."""
        return [st.label for st in self.toy.stages if st.realisation.number in (6, 9)]

    def report(self) -> dict[str, Any]:
        return {
            "toy": self.toy.name,
            "cost": self.cost,
            "mechanisms": self.toy.mechanism_count,
            "cams": {cam: [list(c) for c in chains] for cam, chains in self.toy.cams.items()},
            "phase_deg": math.degrees(self.toy.phase),
            "effectors": [
                {
                    "name": e.name,
                    "motion": e.motion,
                    "cam": cam,
                    "chain": list(chain),
                    "requested": e.range,
                    "achieved": self.ranges[e.name],
                    "error": abs(self.ranges[e.name] - e.range) / e.range,
                    "sized": {
                        "stage": self.sizing[e.name][0],
                        "parameter": self.sizing[e.name][1],
                        "value": self.sizing[e.name][2],
                    },
                }
                for e, (cam, chain) in zip(self.effectors, self.assignment)
            ],
            "trees_considered": self.candidates,
            "trees_sized": self.tried,
            "layers": {k: v + 1 for k, v in self.layers.items()},  # numbered from 1, as in the BOM
            "layer_count": len(set(self.layers.values())),
            "before_placement": self.before,
            "placement": None
            if self.placement is None
            else {
                "variables": self.placement.variables,
                "objective": list(self.placement.objective),
                "footprint": list(self.placement.footprint),
                "overlap": list(self.placement.overlap),
                "evaluations": self.placement.evaluations,
                "rejected": self.placement.rejected,
                "kept": self.placement.kept,
                "checked": self.placement.checked,
            },
            "collisions": [{"a": a, "b": b, "overlap": ov} for a, b, ov in self.collisions],
            "pin_clashes": [] if self.export_refused else self.clashes,
            "export_refused": self.export_refused or None,
            "variant": self.variant or None,
            "fallback": self.fallback,
            "gravity": design_gravity(self.toy),
            "rejected_trees": self.rejected,
            "physics": self.physics,
            "seconds": self.seconds,
        }


# ----------------------------------------------------------------------------- the request


def load_request(path: str | Path) -> list[Effector]:
    """Read a request file (TOML ``[[effector]]`` tables); bad input is an :class:`InputError` naming the field."""
    p = str(path)
    from planar.fileio import read_text

    try:
        data = tomllib.loads(read_text(p, "request file (TOML)"))
    except tomllib.TOMLDecodeError as e:
        raise InputError(p, p, f"TOML ({e})") from None
    extra = sorted(set(data) - {"effector", "name"})
    if extra:
        raise InputError(f"{p}: {extra[0]}", data[extra[0]], "only [[effector]] tables and a toy name")
    rows = data.get("effector")
    if not isinstance(rows, list) or not rows or not all(isinstance(r, dict) for r in rows):
        raise InputError(f"{p}: effector", rows, "one or more [[effector]] tables")
    out = []
    for i, r in enumerate(rows):
        where = f"{p}: effector[{i}]"
        bad = sorted(set(r) - {"name", "motion", "range", "cam", "phase"})
        if bad:
            raise InputError(f"{where}.{bad[0]}", r[bad[0]], "one of name, motion, range, cam, phase")
        for req in ("name", "motion", "range"):
            if req not in r:
                raise InputError(f"{where}.{req}", None, f"a {req} (the field is required)")
        name = r.get("name")
        if isinstance(name, str) and name.strip():
            where = f"{p}: effector {name!r}"
        if (
            not isinstance(name, str)
            or not name.strip()
            or any(c in name for c in '.:+,"')
            or name == "frame"
            or any(ord(c) < 32 or ord(c) == 127 for c in name)
        ):
            raise InputError(
                f"{where}.name",
                name,
                "a name without '.', ':', '+', ',', '\"' or control characters, not 'frame' (the effector's piece)",
            )
        motion = r.get("motion")
        if motion not in MOTION_TYPES:
            raise InputError(f"{where}.motion", motion, f"one of {', '.join(MOTION_TYPES)}")
        rng = r.get("range")
        if isinstance(rng, bool) or not isinstance(rng, (int, float)) or not math.isfinite(rng) or rng <= 0:
            raise InputError(f"{where}.range", rng, "a positive number (degrees for O and OzT, model units for T)")
        cam = r.get("cam")
        if cam is not None and cam not in CAMS:
            raise InputError(f"{where}.cam", cam, "'left' or 'right'")
        ph = r.get("phase", 0.0)
        if isinstance(ph, bool) or not isinstance(ph, (int, float)) or not math.isfinite(ph):
            raise InputError(f"{where}.phase", ph, "a number of cycles (0 <= phase < 1)")
        if not 0 <= ph < 1:
            raise InputError(f"{where}.phase", ph, _phase_hint(float(ph)))
        out.append(Effector(name, str(motion), float(rng), cam, float(ph)))
    names = [e.name for e in out]
    dup = next((n for n in names if names.count(n) > 1), None)
    if dup is not None:
        raise InputError(f"{p}: effector.name", dup, "distinct effector names")
    return out


def _phase_hint(ph: float) -> str:
    """What a phase outside [0, 1) should have been: cycles, with a guess at what was meant."""
    text = "a phase in cycles (0 <= phase < 1; a quarter turn is 0.25)"
    if 1 <= ph <= 360 and (ph >= 5 or ph == int(ph)):
        return text + f"; if {ph:g} is degrees, write phase = {ph / 360:.6g} (degrees / 360)"
    if 1 <= ph < 5:
        return text + f"; whole turns make no difference: {ph:g} cycles is phase = {ph % 1:.6g}"
    return text


# ----------------------------------------------------------------------------- composition and sizing


def _stage_params(number: int, kw: dict[str, Any], u: Array) -> Any:
    """The parameters :class:`ToyMechanism` builds a stage with (its oscillating drivers' amplitude from ``u``)."""
    kw = dict(kw)
    if u.ndim == 1 and ELEMENTAL[number].motions[0] != "Rz" and "amplitude" not in kw:
        amp = float(np.max(np.abs(u)))
        if amp > 0:
            kw["amplitude"] = amp
    return params_for(number, **kw)


def _compose(chain: Chain, cam_phase: float, overrides: dict[Chain, dict[str, Any]], q: Array) -> list[Array] | None:
    """Every stage's world output along ``chain`` (by depth) for motor angles ``q`` (rad), as
    :class:`ToyMechanism` composes it; None where a stage's parameters are refused or it fails at a sample."""
    outs = []
    world = q + cam_phase  # the cam's rotation drives the first stage
    for d in range(1, len(chain) + 1):
        r = realise(chain[d - 1])
        u = _to_base(r, world)
        try:
            P = _stage_params(r.number, overrides.get(chain[:d], {}), u)
            check_params(r.number, P)
        except InputError:
            return None
        res = ELEMENTAL[r.number].forward(P, u)
        if not np.all(res.valid):
            return None
        world = _to_world(r, res.out)
        outs.append(world)
    return outs


def _span(out: Array) -> float:
    """Peak-to-peak of an effector motion (the rotation of OzT)."""
    return float(np.ptp(out[:, 2] if out.ndim == 2 else out))


def _sized_depth(chain: Chain) -> int:
    """Which stage (depth, 1-based) sizes the effector: the last, or its parent for a #10 in a chain."""
    if len(chain) > 1 and realise(chain[-1]).number == 10:
        return len(chain) - 1
    return len(chain)


@dataclass
class _Scan:
    values: Array
    spans: Array  # NaN where invalid

    def reachable(self) -> tuple[float, float] | None:
        ok = np.isfinite(self.spans)
        return (float(self.spans[ok].min()), float(self.spans[ok].max())) if ok.any() else None


def _setter(number: int, base_kw: dict[str, Any], name: str, comp: int | None):
    default = getattr(params_for(number), name)

    def kw(v: float) -> dict[str, Any]:
        out = dict(base_kw)
        if comp is None:
            out[name] = float(v)
        else:
            cur = list(out.get(name, default))
            cur[comp] = float(v)
            out[name] = tuple(cur)
        return out

    return kw, float(default if comp is None else default[comp])


def _span_fn(chain: Chain, depth: int, cam_phase: float, overrides: dict[Chain, dict[str, Any]], q: Array):
    number = realise(chain[depth - 1]).number
    name, comp, bracket, _ = DESIGN_PARAMETER[number]
    kw_of, current = _setter(number, overrides.get(chain[:depth], {}), name, comp)

    def f(v: float) -> float:
        ov = dict(overrides)
        ov[chain[:depth]] = kw_of(v)
        outs = _compose(chain, cam_phase, ov, q)
        return float("nan") if outs is None else _span(outs[-1])

    return f, kw_of, name, bracket, current


def _scan(f, bracket: tuple[float, float], cache: dict | None = None, key: Any = None) -> _Scan:
    if cache is not None and key in cache:
        return cache[key]
    v = np.linspace(bracket[0], bracket[1], SCAN)
    sc = _Scan(v, np.array([f(x) for x in v]))
    if cache is not None:
        cache[key] = sc
    return sc


def _scan_key(chain: Chain, depth: int, overrides: dict[Chain, dict[str, Any]]) -> Any:
    """What a scan depends on: the chain, the sized stage and the overrides along the chain (a cam's phase
    only shifts the cycle)."""
    return (
        chain,
        depth,
        tuple(
            (k, tuple(sorted((n, repr(v)) for n, v in overrides[k].items())))
            for k in (chain[:d] for d in range(1, len(chain) + 1))
            if k in overrides
        ),
    )


def _solve(f, sc: _Scan, target: float, current: float) -> float | None:
    """The parameter value nearest ``current`` whose span is ``target`` (brentq between scan neighbours)."""
    from scipy.optimize import brentq

    d = sc.spans - target
    roots = []
    for k in range(sc.values.size - 1):
        a, b = d[k], d[k + 1]
        if not (np.isfinite(a) and np.isfinite(b)):
            continue
        if a == 0:
            roots.append(float(sc.values[k]))
        elif a * b < 0:
            try:
                roots.append(float(brentq(lambda v: f(v) - target, sc.values[k], sc.values[k + 1], xtol=1e-14, rtol=1e-13)))
            except ValueError:  # an invalid sliver between the scan values
                continue
    roots = [r for r in roots if np.isfinite(f(r))]
    return min(roots, key=lambda r: abs(r - current)) if roots else None


# ----------------------------------------------------------------------------- trees


def _candidates(
    effectors: list[Effector], options: list[list[Chain]], limit: int = 500_000
) -> list[tuple[float, int, list[tuple[str, Chain]]]]:
    """Every assignment of one chain and one cam per effector, cheapest first (cost, then enumeration order)."""
    cams = [[e.cam] if e.cam else list(CAMS) for e in effectors]
    if not any(e.cam for e in effectors):
        cams[0] = [CAMS[0]]  # with no cam named, a tree and its mirror image (cams swapped) are one design
    n = math.prod(len(o) for o in options) * math.prod(len(c) for c in cams)
    if n > limit:
        raise InputError(
            "request", [e.name for e in effectors], f"fewer chain and cam combinations than {limit:,} (this request has {n:,})"
        )
    out = []
    k = 0
    for combo in itertools.product(*options):
        for sides in itertools.product(*cams):
            k += 1
            pairs = list(zip(sides, combo))
            if len(set(pairs)) < len(pairs):
                continue  # two effectors cannot be one stage's follower
            ok = True
            for cam in CAMS:  # one cam turns its effectors at one phase
                ph = {round(e.phase % 1.0, 12) for e, s in zip(effectors, sides) if s == cam}
                if len(ph) > 1:
                    ok = False
            if not ok:
                continue
            tree: dict[str, list[Chain]] = {}
            for s, c in pairs:
                tree.setdefault(s, []).append(c)
            out.append((tree_cost(tree), k, pairs))
    out.sort(key=lambda x: (x[0], x[1]))
    return out


def _no_tree(effectors: list[Effector], options: list[list[Chain]]) -> tuple[str, Any, str]:
    """Why no assignment of chains and cams exists (the fields of an :class:`InputError`): two effectors that
    would be one stage's follower (one chain each, one cam), or the cams' phases."""
    cams = [[e.cam] if e.cam else list(CAMS) for e in effectors]
    for i, j in itertools.combinations(range(len(effectors)), 2):
        a, b = effectors[i], effectors[j]
        shared = set(options[i]) & set(options[j])
        if (
            shared
            and set(options[i]) == shared == set(options[j])
            and set(cams[i]) == set(cams[j])
            and len(cams[i]) * len(options[i]) == 1
        ):
            chain = " ".join(next(iter(shared)))
            return (
                f"effectors {a.name!r} and {b.name!r} ({a.motion}, {b.motion})",
                f"{cams[i][0]} cam",
                f"effectors with a follower each: their only chain, {chain}, on one cam is one stage "
                "(put them on different cams, or ask for different motions)",
            )
    return (
        "request",
        [e.name for e in effectors],
        "an assignment of one chain and one cam per effector (two effectors cannot be one stage's follower, "
        "and one cam turns its effectors at one phase)",
    )


def _size_tree(
    effectors: list[Effector], pairs: list[tuple[str, Chain]], phase: float, q: Array, cache: dict
) -> tuple[dict[tuple[str, Chain], dict[str, Any]], dict[str, tuple[str, str, float]]] | None:
    """Sized overrides (by ``(cam, prefix)``) for one tree, or None when some effector cannot be sized in it."""
    cam_phase = {"left": 0.0, "right": phase}
    per_cam: dict[str, dict[Chain, dict[str, Any]]] = {cam: {} for cam in CAMS}
    fixed: set[tuple[str, Chain]] = set()
    sizing: dict[str, tuple[str, str, float]] = {}
    order = sorted(range(len(effectors)), key=lambda i: (_sized_depth(pairs[i][1]), len(pairs[i][1]), i))
    for i in order:
        e, (cam, chain) = effectors[i], pairs[i]
        depth = _sized_depth(chain)
        key = (cam, chain[:depth])
        if key in fixed:
            return None  # another effector already sized this stage
        f, kw_of, name, bracket, current = _span_fn(chain, depth, cam_phase[cam], per_cam[cam], q)
        sc = _scan(f, bracket, cache, _scan_key(chain, depth, per_cam[cam]))
        v = _solve(f, sc, e.target, current)
        if v is None:
            return None
        per_cam[cam][chain[:depth]] = kw_of(v)
        fixed.add(key)
        sizing[e.name] = (" ".join(chain[:depth]), name, v)
    overrides = {(cam, k): kw for cam, d in per_cam.items() for k, kw in d.items()}
    return overrides, sizing


def _toy_phase(effectors: list[Effector], pairs: list[tuple[str, Chain]]) -> float:
    ph = {cam: e.phase for e, (cam, _) in zip(effectors, pairs)}
    if "left" in ph and "right" in ph:
        return float(2 * math.pi * ((ph["right"] - ph["left"]) % 1.0))
    return 0.0 if "left" in ph else float(2 * math.pi * (ph["right"] % 1.0))


# ----------------------------------------------------------------------------- checks


def effector_ranges(toy: ToyMechanism, samples: int = SAMPLES) -> dict[str, tuple[str, float]]:
    """Each named effector's range measured on the assembled toy's piece poses: ``name -> (motion, range)``.

    The range is the peak-to-peak of the piece's pose track (its angle for O
    and OzT, rad; its coordinate along the axis for T, model units) over one
    cycle, read from the assembly's solved motion (not from the sizing).
    """
    from planar.toys.assembly import toy_assembly

    asm = toy_assembly(toy)
    m = asm.run(samples_per_cycle=samples)
    if not np.all(m.valid):
        raise InputError(toy.name, "motion", "a toy valid over its whole cycle")
    out = {}
    for (_cam, chain), name in toy.names.items():
        motion = chain[-1].split("->")[1]
        piece = name if any(p.name == name for p in asm.parts) else asm.points[name][0]
        pose = np.asarray(m.poses[piece])
        plane = next(p.plane for p in asm.parts if p.name == piece)
        if motion[0] == "O":
            val = float(np.ptp(np.unwrap(pose[:, 2])))
        else:
            axis = plane.index(motion[1])  # the piece's plane names its pose's two coordinates
            val = float(np.ptp(pose[:, axis]))
        out[name] = (motion, val)
    return out


def layer_collisions(
    toy: ToyMechanism, samples: int = 24, unit_mm: float = 100.0
) -> tuple[dict[str, int], list[tuple[str, str, float]], list[str]]:
    """The toy's fabrication (what ``planar export`` cuts) checked for collisions over ``samples`` poses.

    Returns ``(layers, collisions, pin clashes)``: the export's layer of every
    piece; every pair of pieces on one layer (same plane) whose cut material
    (outline minus holes and slots, mm) overlaps at some sampled pose by more
    than the fabrication's tolerance (``planar.fabrication.layers.OVERLAP_MM2``, 0.5 mm^2),
    with the worst overlap (mm^2); and the export's pin clashes (a pin whose
    path crosses a piece on a layer between its ends), or the export's refusal
    of the pieces (no layers) as the one clash.
    """
    from shapely import affinity

    from planar.fabrication.build import build
    from planar.fabrication.layers import OVERLAP_MM2
    from planar.fabrication.parts import FabSettings
    from planar.scene.load import scene_from_mechanism
    from planar.toys.assembly import toy_assembly

    scene = scene_from_mechanism(toy, fabrication={"unit_mm": unit_mm})
    try:
        fab = build(scene, FabSettings.from_spec(scene.spec.fabrication, None, None))
    except PlanarError as e:  # the export refuses these pieces (e.g. no material left between two cuts)
        return {}, [], [f"the export refuses it: {e}"]
    plan = fab.assembly
    layers = {k: (v if v is not None else 0) for k, v in plan.layers.items()}
    clashes = [f"pin {pp.letter} ({', '.join(pp.joints)}) through {q}" for pp in plan.pins for q in pp.clashes]
    asm = toy_assembly(toy)
    m = asm.run(samples_per_cycle=samples)
    ok = np.flatnonzero(m.valid)
    plane = {p.name: p.plane for p in asm.parts}

    def placed(name: str, k: int) -> Any:
        x, y, a = m.poses[name][k]
        c, s = math.cos(a), math.sin(a)
        return affinity.affine_transform(fab.own[name], [c, -s, s, c, x * unit_mm, y * unit_mm])

    found = []
    names = [p.name for p in asm.parts]
    for a, b in itertools.combinations(names, 2):
        if plane[a] != plane[b] or layers.get(a) != layers.get(b):
            continue
        worst = max(placed(a, int(k)).intersection(placed(b, int(k))).area for k in ok)
        if worst > OVERLAP_MM2:
            found.append((a, b, float(worst)))
    return layers, found, clashes


#: the written toy's scene tables: half a cycle a second, 36 frames a cycle, a small GIF, 100 mm a unit
SCENE_TABLES: dict[str, Any] = {
    "driver": {"speed": 0.5, "samples_per_cycle": 36},
    "render": {"width": 360, "height": 270},
    "fabrication": {"unit_mm": 100.0},
}
#: Earth's gravity in the written scene's model units per s^2 (9810 mm/s^2 at its ``unit_mm``): physics runs in
#: model units, so a toy cut at 100 mm per unit falls at 98.1 units/s^2
EARTH_GRAVITY = 9810.0 / SCENE_TABLES["fabrication"]["unit_mm"]
#: the motor torque's largest allowed difference from inverse dynamics, fraction of its peak (as ``planar toy``)
TORQUE_TOLERANCE = 0.01


def design_gravity(toy: ToyMechanism) -> list[float] | None:
    """The gravity ``planar design`` writes for ``toy`` (None: none).  A #8 stage's tab is held on its face by
    gravity along +x (its plane xz), a #6/#9 follower's pin on its driver's edge by gravity along -y (its plane
    yz; README, "Wind-up toys"): a toy with them is written standing that way.  The -y side is the one the
    edge holds for the gallery's and the trial's followers; the physics check (:func:`physics_check`) says
    where it is not."""
    nums = {st.realisation.number for st in toy.stages}
    g = [1.0 if 8 in nums else 0.0, -1.0 if nums & {6, 9} else 0.0]
    norm = math.hypot(*g)
    # Earth's gravity (EARTH_GRAVITY model units/s^2), tilted 45 degrees between +x and -y when both are needed
    return [EARTH_GRAVITY * c / norm + 0.0 for c in g] if norm else None


def design_scene(toy: ToyMechanism, name: str) -> Any:
    """The scene ``planar design`` writes for ``toy``, with :func:`design_gravity`."""
    from planar.scene.load import scene_from_mechanism

    g = design_gravity(toy)
    effects = {"gravity": g} if g is not None else {}
    return scene_from_mechanism(toy, name=name, effects=effects, **SCENE_TABLES)


def physics_check(scene: Any) -> dict[str, Any]:
    """Run the scene's toy as ``planar toy`` does and judge it: a dict with ``ok`` and the figures.

    Coupled pymunk physics, the motor the only driver, its torque against
    inverse dynamics at the scene's speed (``torque_rel_diff``, fraction of
    the peak; ``failure``), each #8 tab's lift-off (``lets_go``: stages whose
    tab lets go at that speed) and every stage the physics did not simulate,
    or simulated with a result it does not accept (``not_simulated``: stage
    label, pattern, the effector it ends, the reason).  ``ok`` is false for
    any of them; a physics run that refuses the toy (a :class:`PlanarError`)
    is ``failure``.
    """
    from planar.physics.toy import simulate_toy

    toy = scene.mechanism
    speed = toy.driver.rate / (2 * math.pi)
    effector = {st.label: toy.names.get((st.cam, st.key)) for st in toy.stages}
    try:
        motion = scene.motion()
        phys = simulate_toy(toy, motion.t, scene.effects, speeds=[speed])
    except PlanarError as e:
        return {
            "ok": False,
            "torque_rel_diff": None,
            "failure": f"the physics refuses the toy: {e}",
            "lets_go": [],
            "pin_lets_go": [],
            "not_simulated": [],
            "stages": [],
            "speed": speed,
        }
    tq = phys.torque
    lets_go = sorted(k for k, v in phys.liftoff.items() if v["liftoff_speed"] is not None and v["liftoff_speed"] <= speed)
    pin_lets_go = sorted(k for k, v in phys.skew.items() if not v["holds"])  # #6/#9: the edge would have to pull
    missing = [
        {"stage": s.stage, "pattern": s.pattern, "effector": effector.get(s.stage), "reason": s.detail}
        for s in phys.not_simulated
    ]
    ok = tq["failure"] is None and tq["max_rel_diff"] <= TORQUE_TOLERANCE and not lets_go and not pin_lets_go and not missing
    return {
        "ok": bool(ok),
        "torque_rel_diff": float(tq["max_rel_diff"]),
        "failure": tq["failure"],
        "lets_go": lets_go,
        "pin_lets_go": pin_lets_go,
        "not_simulated": missing,
        "speed": speed,
        "stages": [{"stage": s.stage, "pattern": s.pattern, "simulated": s.simulated, "detail": s.detail} for s in phys.stages],
    }


def physics_failures(phys: dict[str, Any]) -> list[str]:
    """One line per reason the physics check failed (empty when it passed)."""
    out = []
    if phys["failure"]:
        out.append(str(phys["failure"]))
    elif phys["torque_rel_diff"] is not None and phys["torque_rel_diff"] > TORQUE_TOLERANCE:
        out.append(
            f"motor torque strays {phys['torque_rel_diff']:.2g} of its peak from inverse dynamics "
            f"(more than {TORQUE_TOLERANCE:g})"
        )
    for k in phys["lets_go"]:
        out.append(f"stage {k}'s tab lets go at {phys['speed']:g} cycles/s")
    for k in phys.get("pin_lets_go", []):
        out.append(f"stage {k}'s pin leaves its driver's edge at {phys['speed']:g} cycles/s")
    for m in phys["not_simulated"]:
        who = f" (effector {m['effector']!r})" if m["effector"] else ""
        out.append(f"stage {m['stage']} {m['pattern']}{who} not simulated: {m['reason']}")
    return out


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


@dataclass
class Placement:
    """What the annealing did: variables, objective and footprint before and after, evaluations."""

    variables: list[str]
    objective: tuple[float, float]
    footprint: tuple[float, float]
    overlap: tuple[float, float]
    evaluations: int
    rejected: int
    seconds: float
    kept: bool = True  # False when no annealed layout passed the fabrication check (the start is kept)
    checked: int = 0  # annealed layouts checked against the fabrication


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


def _geometry(mech: Any) -> Any:
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
        outs, checks = toy.world_motion(q)
        if not all(np.all(ok) for ok, _, _ in checks) or any(not np.allclose(outs[k], ref[k], rtol=0, atol=1e-9) for k in ref):
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
    got, checks = disc.world_motion(q)
    if not all(np.all(ok) for ok, _, _ in checks) or any(not np.allclose(got[k], ref[k], rtol=0, atol=1e-9) for k in ref):
        return None
    return out


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


# ----------------------------------------------------------------------------- the pipeline


def design_toy(
    effectors: list[Effector],
    name: str = "designed toy",
    max_length: int = 3,
    max_trees: int = 200,
    place: bool = True,
    max_fabricated: int = 4,
    physics: bool = True,
    source: str = "",
) -> Design:
    """Design a toy for ``effectors`` (see the module docstring); an unreachable request is an
    :class:`InputError` naming ``source`` (the request file), the effector, its range and the ranges the
    chains the toy assembly can build reach (chains it refuses, e.g. a stage turned out of its plane, are
    left out of that reach and named when they alone would reach the range).

    ``place``: anneal the placement; ``max_fabricated``: trees checked against the export (and the physics)
    before giving up; ``physics``: run :func:`physics_check` on a tree that passes the export's check and
    pass it over when it fails (``Design.physics`` holds the verdict).  Seconds per step in ``Design.seconds``
    (``rank_and_size`` counts every tree tried before the one returned).
    """
    t0 = time.perf_counter()
    q = np.linspace(0.0, 2 * math.pi, SAMPLES)
    cache: dict[Any, _Scan] = {}

    def reach(c: Chain) -> tuple[float, float] | None:
        """The ranges the chain reaches alone (its sized stage's parameter scanned; every other at its default)."""
        f, _, _, bracket, _ = _span_fn(c, _sized_depth(c), 0.0, {}, q)
        return _scan(f, bracket, cache, _scan_key(c, _sized_depth(c), {})).reachable()

    built: dict[Chain, str | None] = {}

    def refused(c: Chain) -> str | None:
        """Why the assembly cannot build the chain alone (a stage turned out of its plane), or None."""
        if c not in built:
            from planar.toys.assembly import toy_assembly

            try:
                toy_assembly(ToyMechanism({"left": [c]}, name="chain"))
                built[c] = None
            except InputError as err:
                built[c] = str(err)
        return built[c]

    def reaches(e: Effector, c: Chain) -> bool:
        r = reach(c)
        return r is not None and r[0] * (1 - 1e-6) <= e.target <= r[1] * (1 + 0.02)  # scan maxima run low

    def can(e: Effector, c: Chain) -> bool:
        return reaches(e, c) and refused(c) is None

    at = f"{source}: " if source else ""

    phases = sorted({round(e.phase % 1.0, 12) for e in effectors})
    if len(phases) > 2:
        raise InputError(f"{at}effector phases", phases, "at most two distinct phases (one per cam)")
    for cam in CAMS:
        on = sorted({round(e.phase % 1.0, 12) for e in effectors if e.cam == cam})
        if len(on) > 1:
            raise InputError(f"{at}effector phases on the {cam} cam", on, "one phase per cam")
    options = [enumerate_chains(e.motion, max_length)[e.motion] for e in effectors]
    for e, opts in zip(effectors, options):
        if not opts:
            raise InputError(
                f"{at}effector {e.name!r} ({e.motion}) chain length",
                max_length,
                f"enough stages for a chain from the motor to {e.motion} (--max-length)",
            )
    cands = _candidates(effectors, options)
    if not cands:
        where, value, expected = _no_tree(effectors, options)
        raise InputError(at + where, value, expected)
    t_enum = time.perf_counter() - t0
    tried = fabricated = 0
    rejected: list[str] = []
    why_not: list[str] = []  # why each tree that could reach the ranges was not built
    first: Design | None = None
    for cost, _, pairs in cands:
        if tried >= max_trees:
            break
        if not all(can(e, c) for e, (_, c) in zip(effectors, pairs)):
            continue
        tried += 1
        phase = _toy_phase(effectors, pairs)
        sized = _size_tree(effectors, pairs, phase, q, cache)
        if sized is None:
            why_not.append(
                "; ".join(f"{cam}: {' '.join(c)}" for cam, c in pairs) + ": no parameter value gives every requested range"
            )
            continue
        overrides, sizing = sized
        cams: dict[str, list[Chain]] = {}
        for cam, c in pairs:
            if c not in cams.setdefault(cam, []):
                cams[cam].append(c)
        names = {(cam, c): e.name for e, (cam, c) in zip(effectors, pairs)}
        made = False
        for how, variant in _variants(cams, phase, name, overrides, names):
            try:
                toy = ToyMechanism(dict(cams.items()), phase=phase, name=name, overrides=variant, names=names)
                from planar.toys.assembly import toy_assembly

                toy_assembly(toy)
            except InputError as err:  # a tree the assembly refuses (a mirrored or turned out-of-plane stage)
                why_not.append(
                    "; ".join(f"{cam}: {' '.join(c)}" for cam, c in pairs)
                    + (f" ({how})" if how else "")
                    + f": the toy assembly cannot build it (it would "
                    f"{_reasons([str(err)])})"
                )
                continue
            t_size = time.perf_counter() - t0 - t_enum
            t1 = time.perf_counter()
            placement = None
            checked = layer_collisions(toy)
            layers_before = len(set(checked[0].values()))
            checked_before = checked
            before = {
                "layers": layers_before,
                "collisions": len(checked[1]),
                "pin_clashes": len(checked[2]),
                "export_refused": int(not checked[0]),
            }

            def bad(c: tuple[dict[str, int], list, list]) -> tuple[int, int, int, int]:
                """An export that refuses the pieces (no layers) first, then collisions, pin clashes, layers."""
                return int(not c[0]), len(c[1]), len(c[2]), len(set(c[0].values()))

            if place:
                layouts, placement = place_stages(cams, phase, name, variant, names)
                for placed, (f, fp, ov) in layouts:
                    moved = ToyMechanism(cams, phase=phase, name=name, overrides=placed, names=names)
                    after = layer_collisions(moved)
                    placement.checked += 1
                    # keep a placement only where it adds no collision, no pin clash and no layer
                    if bad(after) <= bad(checked):
                        toy, checked = moved, after
                        placement.kept = True
                        placement.objective = (placement.objective[0], f)
                        placement.footprint = (placement.footprint[0], fp)
                        placement.overlap = (placement.overlap[0], ov)
                        break
                made = True
            # the sized parameter as written (a placement may move it along with another: #4's pin with its origin)
            for e, (cam, _chain) in zip(effectors, pairs):
                stage, pname, _ = sizing[e.name]
                key = tuple(stage.split(" "))
                number, comp = realise(key[-1]).number, DESIGN_PARAMETER[realise(key[-1]).number][1]
                val = toy.stage_overrides.get((cam, key), {}).get(pname, getattr(params_for(number), pname))
                sizing[e.name] = (stage, pname, float(val if comp is None else val[comp]))
            measured = effector_ranges(toy)
            ranges = {}
            for e in effectors:
                _, val = measured[e.name]
                ranges[e.name] = math.degrees(val) if e.motion[0] == "O" else val
            layers, collisions, clashes = checked
            secs = {"enumerate": t_enum, "rank_and_size": t_size, "place_and_check": time.perf_counter() - t1}
            d = Design(
                toy,
                effectors,
                pairs,
                cost,
                ranges,
                len(cands),
                tried,
                sizing,
                layers,
                collisions,
                secs,
                placement,
                layers_before,
                clashes,
                rejected,
                before,
                before_reason=checked_before[2][0] if before["export_refused"] else "",
                variant=how,
            )
            problems = [f"{a}/{b} collide" for a, b, _ in collisions] + clashes
            if not problems and physics:
                t2 = time.perf_counter()
                d.physics = physics_check(design_scene(toy, name))
                secs["physics"] = time.perf_counter() - t2
                problems = physics_failures(d.physics)
            if not problems:
                return d
            # a tree whose pieces collide, whose pins cross pieces or whose physics fails: try the next cheapest
            rejected.append(
                f"cost {cost:g} "
                + "; ".join(f"{cam}: {' '.join(c)}" for cam, c in pairs)
                + (f" ({how})" if how else "")
                + ": "
                + ", ".join(problems)
            )
            if first is None:
                first = d
        fabricated += made
        if fabricated >= max_fabricated:
            break
    if first is not None:
        first.fallback = True
        return first  # every tree tried collides: the cheapest, its failures reported
    for e, opts in zip(effectors, options):
        spans = [r for r in (reach(c) for c in opts if refused(c) is None) if r is not None]
        lo = min((r[0] for r in spans), default=math.nan)
        hi = max((r[1] for r in spans), default=math.nan)
        if spans and lo * (1 - 1e-6) <= e.target <= hi:
            continue  # its buildable chains reach the range: the trees failed for another reason
        where = f"reach about {e.unit(lo)} to {e.unit(hi)}" if spans else "reach no range (none can be built)"
        value = f"{e.range:g} {'deg' if e.motion[0] == 'O' else 'units'}"
        turned = [c for c in opts if refused(c) is not None and reaches(e, c)]
        if turned:
            why = _reasons([str(refused(c)) for c in turned])
            listed = ", ".join(" ".join(c) for c in turned[:3]) + (f" and {len(turned) - 3} more" if len(turned) > 3 else "")
            raise InputError(
                f"{at}effector {e.name!r} ({e.motion}) range",
                e.range,
                f"a range the toy assembly can build: the chains that reach {value} ({listed}) "
                f"{why}, which planar's toy assembly cannot build; buildable chains up to "
                f"{max_length} stages {where}",
            )
        raise InputError(
            f"{at}effector {e.name!r} ({e.motion}) range",
            e.range,
            f"a range buildable chains reach (buildable chains up to {max_length} stages {where})",
        )
    reason = why_not[0] if why_not else "none could be sized"
    raise InputError(
        f"{at}request",
        [e.name for e in effectors],
        f"a tree that can be sized and assembled (none of the {tried} cheapest that could reach the "
        f"ranges; the cheapest: {reason})",
    )


def _assembly_reason(err: str) -> tuple[str, str]:
    """Why the toy assembly refuses a chain or tree, in a user's terms, and the stage it names (from its
    :class:`InputError`)."""
    stage = err.split(" = ")[0].split(".stage ", 1)[-1].split(" ")[-1] if ".stage " in err else ""
    if "not turned" in err:
        return "need a stage turned out of its plane", stage
    if "mirrored" in err:
        return "need a mirrored stage", stage
    if "follower moves in xy" in err:
        return "need a stage driven by a follower moving out of the toy's plane", stage
    return f"need what the assembly refuses ({err})", ""


def _reasons(errs: list[str]) -> str:
    """:func:`_assembly_reason` of several refusals, one clause per reason with its stages."""
    by: dict[str, list[str]] = {}
    for e in errs:
        why, stage = _assembly_reason(e)
        if stage and stage not in by.setdefault(why, []):
            by[why].append(stage)
    parts = [why + (f" ({', '.join(stages)})" if stages else "") for why, stages in sorted(by.items())]
    return " or ".join(parts).replace(" or need ", " or ")
