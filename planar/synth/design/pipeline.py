"""The pipeline of :func:`design_toy` (see :mod:`planar.synth.design`)."""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from planar.errors import InputError
from planar.synth.design.checks import design_scene, effector_ranges, layer_collisions, physics_check, physics_failures
from planar.synth.design.placement import _variants, place_stages
from planar.synth.design.request import CAMS, SAMPLES, Design, Effector, Placement
from planar.synth.design.sizing import (
    _candidates,
    _no_tree,
    _Scan,
    _scan,
    _scan_key,
    _size_tree,
    _sized_depth,
    _span_fn,
    _toy_phase,
)
from planar.windup.chain import Chain, ToyMechanism
from planar.windup.mechanisms import params_for
from planar.windup.sizing import DESIGN_PARAMETER
from planar.windup.table import enumerate_chains, realise

Array = NDArray[np.float64]

# ----------------------------------------------------------------------------- the pipeline


class _Reach:
    """What each chain reaches alone (its sized stage's parameter scanned, every other at its default) and
    whether the toy assembly can build it alone; both cached."""

    def __init__(self, q: Array, cache: dict[Any, _Scan]) -> None:
        self.q = q
        self.cache = cache
        self.built: dict[Chain, str | None] = {}

    def reach(self, c: Chain) -> tuple[float, float] | None:
        f, _, _, bracket, _ = _span_fn(c, _sized_depth(c), 0.0, {}, self.q)
        return _scan(f, bracket, self.cache, _scan_key(c, _sized_depth(c), {})).reachable()

    def refused(self, c: Chain) -> str | None:
        """Why the assembly cannot build the chain alone (a stage turned out of its plane), or None."""
        if c not in self.built:
            from planar.toys.assembly import toy_assembly

            try:
                toy_assembly(ToyMechanism({"left": [c]}, name="chain"))
                self.built[c] = None
            except InputError as err:
                self.built[c] = str(err)
        return self.built[c]

    def reaches(self, e: Effector, c: Chain) -> bool:
        r = self.reach(c)
        return r is not None and r[0] * (1 - 1e-6) <= e.target <= r[1] * (1 + 0.02)  # scan maxima run low

    def can(self, e: Effector, c: Chain) -> bool:
        return self.reaches(e, c) and self.refused(c) is None


def _chain_options(effectors: list[Effector], max_length: int, at: str) -> list[list[Chain]]:
    """Every chain to each effector's motion, after the phases are checked (at most two, one per cam)."""
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
    return options


def _bad(c: tuple[dict[str, int], list, list]) -> tuple[int, int, int, int]:
    """An export that refuses the pieces (no layers) first, then collisions, pin clashes, layers."""
    return int(not c[0]), len(c[1]), len(c[2]), len(set(c[0].values()))


def _placed(
    toy: ToyMechanism, cams: dict[str, list[Chain]], phase: float, name: str, variant: Any, names: Any, checked: Any
) -> tuple[ToyMechanism, Any, Placement]:
    """The first annealed placement that adds no collision, pin clash or layer (else the toy as it was)."""
    layouts, placement = place_stages(cams, phase, name, variant, names)
    for placed, (f, fp, ov) in layouts:
        moved = ToyMechanism(cams, phase=phase, name=name, overrides=placed, names=names)
        after = layer_collisions(moved)
        placement.checked += 1
        if _bad(after) <= _bad(checked):
            placement.kept = True
            placement.objective = (placement.objective[0], f)
            placement.footprint = (placement.footprint[0], fp)
            placement.overlap = (placement.overlap[0], ov)
            return moved, after, placement
    return toy, checked, placement


def _as_written(effectors: list[Effector], pairs: list[tuple[str, Chain]], sizing: dict, toy: ToyMechanism) -> None:
    """The sized parameter as written (a placement may move it along with another: #4's pin with its origin)."""
    for e, (cam, _chain) in zip(effectors, pairs):
        stage, pname, _ = sizing[e.name]
        key = tuple(stage.split(" "))
        number, comp = realise(key[-1]).number, DESIGN_PARAMETER[realise(key[-1]).number][1]
        val = toy.stage_overrides.get((cam, key), {}).get(pname, getattr(params_for(number), pname))
        sizing[e.name] = (stage, pname, float(val if comp is None else val[comp]))


def _tree_text(pairs: list[tuple[str, Chain]], how: str = "") -> str:
    return "; ".join(f"{cam}: {' '.join(c)}" for cam, c in pairs) + (f" ({how})" if how else "")


@dataclass
class _Run:
    """One call's settings and what it has learnt so far (the trees rejected and why)."""

    effectors: list[Effector]
    name: str
    place: bool
    physics: bool
    t0: float
    t_enum: float
    n_candidates: int
    tried: int = 0
    rejected: list[str] = field(default_factory=list)
    why_not: list[str] = field(default_factory=list)
    first: Design | None = None


def _try_variant(
    run: _Run,
    cost: float,
    pairs: list[tuple[str, Chain]],
    cams: dict[str, list[Chain]],
    phase: float,
    sized: Any,
    how: str,
    variant: Any,
) -> tuple[Design | None, bool]:
    """Build, place and check one variant of a sized tree: the design if it passes every check, else None
    (the reason kept in ``run``); and whether the assembly built it."""
    from planar.toys.assembly import toy_assembly

    _, sizing = sized
    names = {(cam, c): e.name for e, (cam, c) in zip(run.effectors, pairs)}
    try:
        toy = ToyMechanism(dict(cams.items()), phase=phase, name=run.name, overrides=variant, names=names)
        toy_assembly(toy)
    except InputError as err:  # a tree the assembly refuses (a mirrored or turned out-of-plane stage)
        run.why_not.append(_tree_text(pairs, how) + f": the toy assembly cannot build it (it would {_reasons([str(err)])})")
        return None, False
    t_size = time.perf_counter() - run.t0 - run.t_enum
    t1 = time.perf_counter()
    placement = None
    checked = checked_before = layer_collisions(toy)
    layers_before = len(set(checked[0].values()))
    before = {
        "layers": layers_before,
        "collisions": len(checked[1]),
        "pin_clashes": len(checked[2]),
        "export_refused": int(not checked[0]),
    }
    if run.place:
        toy, checked, placement = _placed(toy, cams, phase, run.name, variant, names, checked)
    _as_written(run.effectors, pairs, sizing, toy)
    measured = effector_ranges(toy)
    ranges = {e.name: (math.degrees(measured[e.name][1]) if e.motion[0] == "O" else measured[e.name][1]) for e in run.effectors}
    layers, collisions, clashes = checked
    secs = {"enumerate": run.t_enum, "rank_and_size": t_size, "place_and_check": time.perf_counter() - t1}
    d = Design(
        toy,
        run.effectors,
        pairs,
        cost,
        ranges,
        run.n_candidates,
        run.tried,
        sizing,
        layers,
        collisions,
        secs,
        placement,
        layers_before,
        clashes,
        run.rejected,
        before,
        before_reason=checked_before[2][0] if before["export_refused"] else "",
        variant=how,
    )
    problems = [f"{a}/{b} collide" for a, b, _ in collisions] + clashes
    if not problems and run.physics:
        t2 = time.perf_counter()
        d.physics = physics_check(design_scene(toy, run.name))
        secs["physics"] = time.perf_counter() - t2
        problems = physics_failures(d.physics)
    if not problems:
        return d, True
    # a tree whose pieces collide, whose pins cross pieces or whose physics fails: try the next cheapest
    run.rejected.append(f"cost {cost:g} " + _tree_text(pairs, how) + ": " + ", ".join(problems))
    if run.first is None:
        run.first = d
    return None, True


def _unreachable(effectors: list[Effector], options: list[list[Chain]], rch: _Reach, at: str, max_length: int) -> None:
    """Raise the :class:`InputError` of the first effector whose range no buildable chain reaches (if any)."""
    for e, opts in zip(effectors, options):
        spans = [r for r in (rch.reach(c) for c in opts if rch.refused(c) is None) if r is not None]
        lo = min((r[0] for r in spans), default=math.nan)
        hi = max((r[1] for r in spans), default=math.nan)
        if spans and lo * (1 - 1e-6) <= e.target <= hi:
            continue  # its buildable chains reach the range: the trees failed for another reason
        where = f"reach about {e.unit(lo)} to {e.unit(hi)}" if spans else "reach no range (none can be built)"
        value = f"{e.range:g} {'deg' if e.motion[0] == 'O' else 'units'}"
        turned = [c for c in opts if rch.refused(c) is not None and rch.reaches(e, c)]
        if turned:
            why = _reasons([str(rch.refused(c)) for c in turned])
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


def _check_design_args(
    effectors: Any, name: Any, max_length: Any, max_trees: Any, place: Any, max_fabricated: Any, physics: Any, source: Any
) -> None:
    """:func:`design_toy`'s arguments, each named when wrong (its entrance from Python)."""
    from planar.core.fields import check_number
    from planar.core.limits import check_count
    from planar.synth.design.request import Effector

    if not isinstance(effectors, (list, tuple)) or not effectors or not all(isinstance(e, Effector) for e in effectors):
        raise InputError("effectors", effectors, "a list of one or more Effector (planar.synth.design.Effector)")
    for arg, text in (("name", name), ("source", source)):
        if not isinstance(text, str):
            raise InputError(arg, text, "a string")
    if not 1 <= len(name) <= 80 or any(ord(c) < 32 or ord(c) == 127 or c in ',"' for c in name):  # a scene's name
        raise InputError(
            "name",
            name,
            "a toy name of 1 to 80 characters without control characters (newline, tab, NUL), commas or quotes ('\"')",
        )
    check_count("chain", "max_length", check_number("max_length", max_length, integer=True), "stages in a chain")
    for arg, value in (("max_length", max_length), ("max_trees", max_trees), ("max_fabricated", max_fabricated)):
        if not 1 <= check_number(arg, value, integer=True) <= 1_000_000:
            raise InputError(arg, value, "a whole number from 1 to 1 000 000")
    for arg, flag in (("place", place), ("physics", physics)):
        if not isinstance(flag, bool):
            raise InputError(arg, flag, "True or False")


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
    _check_design_args(effectors, name, max_length, max_trees, place, max_fabricated, physics, source)
    t0 = time.perf_counter()
    q = np.linspace(0.0, 2 * math.pi, SAMPLES)
    cache: dict[Any, _Scan] = {}
    rch = _Reach(q, cache)
    at = f"{source}: " if source else ""
    options = _chain_options(effectors, max_length, at)
    cands = _candidates(effectors, options)
    if not cands:
        where, value, expected = _no_tree(effectors, options)
        raise InputError(at + where, value, expected)
    run = _Run(effectors, name, place, physics, t0, time.perf_counter() - t0, len(cands))
    fabricated = 0
    for cost, _, pairs in cands:
        if run.tried >= max_trees:
            break
        if not all(rch.can(e, c) for e, (_, c) in zip(effectors, pairs)):
            continue
        run.tried += 1
        phase = _toy_phase(effectors, pairs)
        sized = _size_tree(effectors, pairs, phase, q, cache)
        if sized is None:
            run.why_not.append(_tree_text(pairs) + ": no parameter value gives every requested range")
            continue
        cams: dict[str, list[Chain]] = {}
        for cam, c in pairs:
            if c not in cams.setdefault(cam, []):
                cams[cam].append(c)
        names = {(cam, c): e.name for e, (cam, c) in zip(effectors, pairs)}
        made = False
        for how, variant in _variants(cams, phase, name, sized[0], names):
            d, built = _try_variant(run, cost, pairs, cams, phase, sized, how, variant)
            if d is not None:
                return d
            made = made or (place and built)
        fabricated += made
        if fabricated >= max_fabricated:
            break
    if run.first is not None:
        run.first.fallback = True
        return run.first  # every tree tried collides: the cheapest, its failures reported
    _unreachable(effectors, options, rch, at, max_length)
    reason = run.why_not[0] if run.why_not else "none could be sized"
    raise InputError(
        f"{at}request",
        [e.name for e in effectors],
        f"a tree that can be sized and assembled (none of the {run.tried} cheapest that could reach the "
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
        stages = by.setdefault(why, [])  # a reason without a stage is kept too (it was dropped: "it would )")
        if stage and stage not in stages:
            stages.append(stage)
    parts = [why + (f" ({', '.join(stages)})" if stages else "") for why, stages in sorted(by.items())]
    return " or ".join(parts).replace(" or need ", " or ")
