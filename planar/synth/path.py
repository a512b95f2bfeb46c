"""Path synthesis of a four-bar: a coupler curve through target points, timed or not.

:func:`synthesise_path` searches (:mod:`planar.synth.search`), builds the
result as a :class:`planar.linkages.FourBar` and checks it with planar's own
solver, not the search kernel: the coupler point at the crank angles found
(``sse``, sum of squared distances to the targets, model units squared), and
the whole turn solved as a path (360 samples, branch continuity): every
sample valid, and equal (to 1e-9 of the targets' extent) to the same angles
solved as a shuffled batch, which keeps the declared circuit at every sample
as the solve at the targets does: the circuit never switches.  Also checked:
the constraints (:func:`planar.synth.search.constraint_failures`, each
broken one named) and the accuracy, ``rms_error`` = RMS distance to the
targets / their size (RMS distance from their centroid) at most
``tolerance``; ``max_error`` = largest distance to a target / their size
at most ``tolerance`` (``ok_accuracy``; ``rms_error`` is reported beside
it).  With ``ordered``, ``ok_order``: the branch passes the targets in their
order (:func:`planar.synth.search.in_order`).  The search runs on the targets moved to their centroid and
divided by their size (the pivots box with them); the result is mapped back.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from planar.core.fields import check_number
from planar.errors import InputError
from planar.synth.designs import TOGGLE_FLOOR_DEG, Checked, PlacedFourBar
from planar.synth.path_search import BUDGETS, EQUATION_SOURCE, PathSearch
from planar.synth.search import Constraints, PathObjective, basin_for, constraint_failures
from planar.synth.targets import check_search_args, check_theta, normalisation

__all__ = ["FourBarDesign", "check_path_args", "synthesise_path", "synthesise_rocking_path"]

Array = NDArray[np.float64]

#: default largest distance to a target, as a fraction of the targets' size (RMS distance from the centroid)
DEFAULT_TOLERANCE = 1e-3


def wrapped(theta: Array) -> Array:
    """Crank angles ``theta`` (radians) wrapped to ``[0, 2 pi)``, as the scene's comment and the JSON give them."""
    t = np.mod(np.asarray(theta, float), 2 * np.pi)
    t[t >= 2 * np.pi] = 0.0  # a tiny negative angle rounds to 2 pi
    return t


def normalised(cons: Constraints, c: Array, s: float) -> Constraints:
    """``cons`` for targets moved by ``-c`` and divided by ``s`` (the pivots box moves with them)."""
    import dataclasses

    if cons.region is None:
        return cons
    x0, y0, x1, y1 = cons.region
    return dataclasses.replace(cons, region=((x0 - c[0]) / s, (y0 - c[1]) / s, (x1 - c[0]) / s, (y1 - c[1]) / s))


@dataclass
class FourBarDesign(Checked, PlacedFourBar):
    """A synthesised four-bar and how well it does (see the module for the checks)."""

    ground: float
    crank: float
    coupler: float
    rocker: float
    coupler_point: tuple[float, float]
    circuit: str
    placement: tuple[float, float, float]
    theta: Array  # crank angle at each target (radians from the ground line, in [0, 2 pi))
    sse: float  # from planar's solver at ``theta``
    targets: Array
    timed: bool
    seconds: float
    checks: dict[str, Any] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        return {
            **self.fourbar_dict(),
            "sse": self.sse,
            "timed": self.timed,
            "time_s": self.seconds,
            "ok": self.ok,
            "checks": self.checks,
        }


def check_design(d: FourBarDesign, kernel_points: Array | None = None) -> None:
    """Fill ``d.sse`` and ``d.checks`` from planar's solver (see the module)."""
    fb = d.fourbar()
    g = fb.grashof
    th = np.asarray(d.theta, float)
    at = fb.solve(th)  # a scattered batch: the declared circuit at every sample
    pts = at.points["coupler_point"]
    d.sse = float(np.sum((pts - d.targets) ** 2)) if at.valid.all() else float("inf")
    n = 360
    turn = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    path = fb.solve(turn)
    # the turn solved as a path (branch continuity) against the same angles shuffled (a scattered batch keeps
    # the declared circuit at every sample, as at the targets): equal everywhere, the circuit never switches
    perm = np.random.default_rng(0).permutation(n)
    batch = fb.solve(turn[perm])
    scale = float(max(np.hypot(*np.ptp(d.targets, axis=0)), 1e-9))
    d.checks = {
        "grashof": g,
        "ok_crank_turns_fully": g in ("crank-rocker", "double-crank") and bool(path.valid.all()),
        "ok_valid_at_targets": bool(at.valid.all()),
        "ok_same_circuit_over_turn": bool(batch.valid.all() and path.valid.all())
        and bool(np.max(np.abs(batch.points["coupler_point"] - path.points["coupler_point"][perm])) <= 1e-9 * scale),
        "max_target_distance": float(np.max(np.hypot(*(pts - d.targets).T))) if at.valid.all() else float("inf"),
        "worst_target": int(np.argmax(np.hypot(*(pts - d.targets).T))) + 1 if at.valid.all() else 0,
    }
    if kernel_points is not None:
        # the search's own kernel and planar's solver must place the coupler point alike at the targets (a
        # solver carried onto the other circuit once reported an sse of 23 for a design the search scored 3e-3)
        gap = float(np.max(np.abs(kernel_points - pts))) if at.valid.all() else float("inf")
        d.checks["kernel_vs_solve"] = gap
        d.checks["ok_kernel_matches_solve"] = bool(gap <= 1e-6 * scale)


def transmission_margin(fb: Any, theta: Array | None = None) -> tuple[float, float]:
    """``(margin, theta)``: the smallest distance (radians) of the transmission angle from a toggle (0 or pi)
    at the crank angles ``theta`` (radians from the ground line; default: the whole turn), and the angle where
    it is.

    Over a turn the angle depends on the crank only through the diagonal ``B-O4``, longest at ``theta = pi``
    and shortest at ``0``, so its extremes are there; a grid of 721 angles is checked as well."""
    th = np.concatenate([[0.0, np.pi], np.linspace(0.0, 2 * np.pi, 721, endpoint=False)]) if theta is None else theta
    mu = np.asarray(fb.transmission_angle(th), float)
    m = np.minimum(mu, np.pi - mu)
    k = int(np.argmin(m))
    return float(m[k]), float(th[k])


def best_fourbar(
    t: Array,
    theta: Array | None,
    cons: Constraints,
    budget: str = "normal",
    seed: int = 0,
    atlas: Any = None,
    ordered: bool = False,
    tolerance: float = DEFAULT_TOLERANCE,
    full_turn: bool = False,
) -> Any:
    """The search of :func:`synthesise_path` on targets ``t`` already normalised (centroid 0, size 1; ``cons``
    normalised with them): a :class:`planar.synth.search.SearchResult`.  ``full_turn``: only a four-bar whose
    input turns fully (the rocking arcs are not tried)."""
    from threadpoolctl import threadpool_limits

    if not isinstance(budget, str) or budget not in BUDGETS:
        raise InputError("budget", budget, f"one of {', '.join(BUDGETS)}")
    with threadpool_limits(1):
        return PathSearch(t, cons, budget, seed, tolerance, atlas, ordered, full_turn=full_turn).run(theta)[0]


def unboxed_error(targets: Array, cons: Constraints, atlas: Any = None, budget: str = "normal") -> float:
    """Largest distance from a target to the atlas's best four-bar (lookup and refinement, crank angles free),
    as a fraction of the targets' size, with ``cons`` but no pivots box: what a ``--pivots`` box costs.
    ``atlas``: as :func:`synthesise_path`'s (the cached one of ``budget`` when None)."""
    from threadpoolctl import threadpool_limits

    from planar.synth.search import max_distance, search_atlas

    t = np.asarray(targets, float)
    c, s = normalisation(t)
    if atlas is None:
        from planar.synth.atlas import DEFAULT_SIZE, QUICK_SIZE, load_atlas

        atlas = load_atlas(QUICK_SIZE if budget == "quick" else DEFAULT_SIZE, progress=True)
    import dataclasses

    free = dataclasses.replace(cons, region=None)
    tn = (t - c) / s
    with threadpool_limits(1):
        r = search_atlas(tn, atlas, free)
    return max_distance(PathObjective(tn, None, free), np.append(r.params, r.circuit), r.theta)


def synthesise_path(
    targets: Array,
    theta: Array | None = None,
    cons: Constraints | None = None,
    budget: str = "normal",
    seed: int = 0,
    tolerance: float = DEFAULT_TOLERANCE,
    atlas: Any = None,
    ordered: bool = False,
    min_transmission: float = 0.0,
    arcs: Any = None,
    full_turn: bool = False,
    windows: Any = None,
) -> FourBarDesign:
    """A four-bar whose coupler point passes through (or nearest to) ``targets`` ``(N, 2)``.

    ``theta`` ``(N,)``: prescribed crank angles (radians from the ground
    line); ``None`` leaves them free: the targets are looked up in a
    coupler-curve atlas (:mod:`planar.synth.atlas`; ``atlas``, or the cached
    one of the budget: 20,000 curves for ``"quick"``, 1,000,000 otherwise,
    built on first use) and refined, and when its first starts fail, as part
    of a closed curve in the curve-window atlas (:mod:`planar.synth.windows`;
    ``windows``, or the cached one of the budget: 5,000 four-bars for
    ``"quick"``, 250,000 otherwise, built on first need); when that is not within ``tolerance``
    the rocking arcs are tried (:mod:`planar.synth.arcs`: four-bars whose input
    swings between two angles; ``arcs``, or the cached arc atlas of the budget
    when it is on disk; not with a pivots box, ``min_transmission`` or
    ``full_turn``: only an input that turns fully, as for a closed drawn
    shape, which a rocking input traces only as an arc), then the global search.  A rocking result's checks are those of
    :func:`synthesise_rocking_path` and ``checks["input"]`` says ``"rocks"``
    (``"turns fully"`` otherwise).
    ``budget``: ``"quick"`` (for tests), ``"normal"`` or ``"thorough"``.
    ``tolerance``: the largest accepted distance from a target to the
    coupler point, as a fraction of the targets' size (RMS distance from
    their centroid; check ``ok_accuracy``).  ``ordered``: the branch must
    pass the targets in their order (check ``ok_order``).  ``min_transmission``
    (radians): the transmission angle must stay at least this far from a
    toggle (0 or pi) over the turn, and never nearer than
    :data:`TOGGLE_FLOOR_DEG` (check ``ok_transmission``; the angle and the
    crank angle where it is smallest are ``min_transmission_deg`` and
    ``min_transmission_at_rad``).  Raises
    :class:`InputError` for fewer than 3 targets or mismatched lengths.
    ``checks["cautions"]`` says in words what untimed targets met leave open (:func:`untimed_cautions`: fewer
    than 10 targets do not fix the curve; targets on less than 270 degrees of the crank's turn fix it weakly
    beyond them) and when the transmission angle comes within 10 degrees of a toggle with no ``min_transmission``
    asked (:func:`transmission_cautions`); the command line prints each as a ``caution:`` line.

    Small dense algebra (the least-squares steps) runs on one BLAS thread
    (threadpoolctl): on two threads under load each small SVD was 200 times
    slower.
    """
    from threadpoolctl import threadpool_limits

    t, theta, cons = check_path_args(
        targets, theta, cons, budget, seed, tolerance, ordered, min_transmission, {"full_turn": full_turn}
    )
    if atlas is not None:
        from planar.synth.atlas import Atlas

        if not isinstance(atlas, Atlas):
            raise InputError("atlas", atlas, "an Atlas (planar.synth.atlas.load_atlas), or None for the cached one")
    arcs = _check_arcs(arcs)
    windows = _check_arcs(windows, "windows", "windows")
    t0 = time.perf_counter()
    # searched on the targets moved to their centroid and divided by their size, then mapped back
    c, s = normalisation(t)
    with threadpool_limits(1):
        search = PathSearch(
            (t - c) / s,
            normalised(cons, c, s),
            budget,
            seed,
            tolerance,
            atlas,
            ordered,
            arcs,
            full_turn=bool(full_turn),
            windows=windows,
        )
        r, source, swing = search.run(theta)
    d, p = design_from(r, c, s, t, theta is not None, time.perf_counter() - t0)
    if swing is not None:  # the input rocks: checked over its swing
        return _rocking_checked(d, r, p, swing, tolerance, ordered, cons, source, s)
    from planar.synth.kernel import coupler_points
    from planar.synth.search import in_order

    x, y, _ = coupler_points(p[None, :], d.theta[None, :], np.array([float(r.circuit)]))
    check_design(d, np.column_stack([x[0], y[0]]))
    d.checks["constraint_failures"] = constraint_failures(p, cons)
    d.checks["ok_constraints"] = not d.checks["constraint_failures"]
    d.checks["size"] = s
    d.checks["rms_error"] = (math.sqrt(d.sse / len(t)) / s) if math.isfinite(d.sse) else float("inf")
    d.checks["max_error"] = d.checks["max_target_distance"] / s
    d.checks["ok_accuracy"] = bool(d.checks["max_error"] <= tolerance)
    d.checks["tolerance"] = tolerance
    if ordered:
        d.checks["ok_order"] = in_order(d.theta)
    _check_transmission(d, None, cons.min_transmission)
    d.checks["stages_s"] = r.stages
    d.checks["found_by"] = source
    d.checks["input"] = "turns fully"
    d.checks["evaluations"] = r.evaluations
    d.checks["cautions"] = design_cautions(d, cons, theta is None, d.theta)
    return d


def design_cautions(d: Any, cons: Constraints, untimed: bool, theta: Array | None) -> list[str]:
    """``checks["cautions"]`` of a checked design ``d``: what ``untimed`` targets it meets leave open
    (:func:`untimed_cautions`; the crank angles ``theta`` at them, rad, when its crank turns fully, None when its
    input rocks: the swing is the arc, no span to judge; targets not met are said to be so by the accuracy check),
    a coupler path that strays between two untimed targets (:func:`planar.synth.drawing.between_targets`, whose
    figures join ``d.checks``), a linkage that comes near a toggle (:func:`transmission_cautions`) and one far larger
    than its targets (:func:`size_cautions`)."""
    from planar.synth.drawing import between_caution, between_targets

    met = untimed and bool(d.checks.get("ok_accuracy"))
    between = between_targets(d) if untimed else {}
    d.checks.update(between)
    cautions = (untimed_cautions(len(d.targets), theta) if met else []) + between_caution(between)
    return cautions + transmission_cautions(d, cons) + size_cautions(d)


#: a design whose longest link is more than this many times the targets' extent (the diagonal of their bounding box)
#: is cautioned: on random rocking four-bars' own arcs (12 targets) the true four-bar's ratio had a median of 1.5 to
#: 2.5 and a 99th percentile of 12 to 16; a trial's drawn corner came back at 109 (a link ratio at the --max-ratio limit)
LARGE_DESIGN = 30.0


def size_cautions(d: Any) -> list[str]:
    """A caution, in words, when ``d``'s longest link is more than :data:`LARGE_DESIGN` times its targets' extent."""
    extent = float(np.hypot(*np.ptp(np.asarray(d.targets, float), axis=0)))
    links = {"ground": d.ground, "crank": d.crank, "coupler": d.coupler, "rocker": d.rocker}
    name = max(links, key=lambda k: links[k])
    if not extent > 0 or links[name] <= LARGE_DESIGN * extent:
        return []
    return [
        f"the four-bar is large beside its targets: its {name} ({links[name]:.4g}) is {links[name] / extent:.3g} times the "
        f"targets' extent ({extent:.4g}, their bounding box's diagonal), a nearly straight stretch of a large "
        "four-bar's curve; more targets, or a drawing with more curve to it, may give a smaller one"
    ]


#: a design whose transmission angle comes nearer a toggle than this (degrees), with no ``min_transmission`` asked,
#: is cautioned (it passes the 1 degree floor, but such a linkage binds or jerks there; 40 is common advice)
LOW_TRANSMISSION_DEG = 10.0


def transmission_cautions(d: Any, cons: Constraints) -> list[str]:
    """A caution, in words, when ``d``'s transmission angle comes within :data:`LOW_TRANSMISSION_DEG` of a toggle
    and no ``min_transmission`` was asked (empty otherwise, and when the check already failed)."""
    deg = d.checks.get("min_transmission_deg")
    if deg is None or cons.min_transmission > 0 or not d.checks.get("ok_transmission", True) or deg >= LOW_TRANSMISSION_DEG:
        return []
    link = "input" if d.checks.get("input") == "rocks" else "crank"  # a rocking input is no crank (a trial's point)
    return [
        f"the transmission angle comes within {deg:.3g} deg of a toggle ({link} at "
        f"{math.degrees(d.checks['min_transmission_at_rad']):.4g} deg from the ground line): a linkage this near "
        "folding binds or jerks there; --min-transmission N (min_transmission=, radians, from Python) asks the search "
        "to keep N deg (20 to 40 is common advice)"
    ]


#: untimed targets fewer than this do not fix a four-bar's curve (9 dimensions, one condition per target: 8 leave a
#: one-parameter family through them, 9 a finite number of four-bars)
FIXED_FROM = 10
#: crank angles (degrees) the untimed targets of a result whose crank turns fully must span for no caution
SPAN_DEG = 270.0


def untimed_cautions(n: int, theta: Array | None) -> list[str]:
    """What an untimed result through ``n`` targets (at crank angles ``theta``, rad, of a crank that turns fully;
    None for an input that rocks) does not settle, in words: the curve when fewer than :data:`FIXED_FROM` targets,
    the curve beyond the targets when they span less than :data:`SPAN_DEG` of the crank's turn.  Empty when
    neither."""
    out = []
    if n < FIXED_FROM:
        family = "a one-parameter family" if n == 8 else "a finite number" if n == 9 else f"a {9 - n}-parameter family"
        timing = "" if theta is None else ", or their crank angles,"  # a rocking search takes no angles
        out.append(
            f"{n} untimed targets do not fix the curve: through {n} points {family} of four-bars pass, so between and "
            f"beyond the targets this curve is one of several (give {FIXED_FROM} or more targets spread along the "
            f"{'arc' if theta is None else 'curve'}{timing} to pin it down)"
        )
    if theta is None:
        return out
    span, clockwise = crank_span(np.asarray(theta, float))
    if span < SPAN_DEG:
        out.append(
            f"the targets lie on {span:.0f} deg of the crank's turn: beyond them the curve is weakly fixed (four-bars "
            "whose curves differ there pass as close to the targets); add targets there to pin it down"
        )
    if clockwise:
        out.append(
            "the crank meets the targets in their order turning clockwise; the scene's driver turns it "
            "counter-clockwise, so the animation meets them last to first"
        )
    return out


def crank_span(theta: Array) -> tuple[float, bool]:
    """The degrees of the crank's turn the targets at crank angles ``theta`` (rad, in the targets' order) lie on, and
    whether the crank meets them in their order turning clockwise: passed in their order one way round within one
    turn, the angle the crank turns from the first to the last; else the smallest arc holding them all (and False)."""
    from planar.synth.search import turn_steps

    th = np.asarray(theta, float)
    if len(th) < 2:
        return 0.0, False
    steps = turn_steps(th)
    if steps is not None:
        return float(np.degrees(abs(steps.sum()))), bool(steps.sum() < 0)
    s = np.sort(np.mod(th, 2 * np.pi))
    return float(np.degrees(2 * np.pi - np.diff(np.append(s, s[0] + 2 * np.pi)).max())), False


def check_path_args(
    targets: Any,
    theta: Any,
    cons: Any,
    budget: Any,
    seed: Any,
    tolerance: Any,
    ordered: Any,
    min_transmission: Any = 0.0,
    flags: dict[str, Any] | None = None,
) -> tuple[Array, Array | None, Constraints]:
    """The Python entrance of a path synthesis (:func:`synthesise_path`, :func:`synthesise_rocking_path`): the
    targets, crank angles, seed, tolerance, ``ordered`` and the other ``flags`` by name (each True or False:
    :func:`planar.synth.targets.check_search_args`),
    ``cons`` a :class:`~planar.synth.search.Constraints` or None, ``min_transmission`` from 0 to below pi/2 rad,
    targets not all one point, ``budget`` one of :data:`BUDGETS`; :class:`InputError` naming the argument.
    Returns the targets and angles as arrays and the constraints (``min_transmission`` in them when larger)."""
    import dataclasses

    t, theta = check_search_args(targets, theta, seed, tolerance, {"ordered": ordered, **(flags or {})})
    if theta is not None:
        check_theta(theta, None, False)
    if cons is not None and not isinstance(cons, Constraints):
        raise InputError("cons", cons, "a synth.search.Constraints (or None)")
    cons = cons if cons is not None else Constraints()
    if not 0.0 <= check_number("min_transmission", min_transmission) < math.pi / 2:
        raise InputError("min_transmission", min_transmission, "an angle from 0 to below pi/2 rad")
    if np.ptp(t, axis=0).max() <= 0:
        raise InputError("targets", t[0].tolist(), "targets that are not all the same point")
    if not isinstance(budget, str) or budget not in BUDGETS:
        raise InputError("budget", budget, f"one of {', '.join(BUDGETS)}")
    if min_transmission > cons.min_transmission:  # asked for: a constraint of the search, not only a check
        cons = dataclasses.replace(cons, min_transmission=float(min_transmission))
    return t, theta, cons


def _check_arcs(arcs: Any, name: str = "arcs", kind: str = "rocking") -> Any:
    """``arcs`` (the argument ``name``): None or an arc atlas of ``kind`` (:class:`planar.synth.arcs.Arcs`:
    ``"rocking"`` from :func:`planar.synth.arcs.load_arcs`, ``"windows"`` from
    :func:`planar.synth.windows.load_windows`); :class:`InputError` otherwise."""
    if arcs is not None:
        from planar.synth.arcs import Arcs

        loader = "planar.synth.arcs.load_arcs" if kind == "rocking" else "planar.synth.windows.load_windows"
        if not isinstance(arcs, Arcs) or arcs.kind != kind:
            raise InputError(name, arcs, f"an Arcs of kind {kind!r} ({loader}), or None for the cached one")
    return arcs


def design_from(r: Any, c: Array, s: float, t: Array, timed: bool, seconds: float) -> tuple[FourBarDesign, Array]:
    """The design of a search result ``r`` on targets normalised by centroid ``c`` and size ``s``, mapped back onto
    the targets ``t`` (not yet checked: ``sse`` NaN), and its kernel row in the targets' units."""
    p = np.asarray(r.params, float).copy()
    p[:6] *= s
    p[6:8] = p[6:8] * s + c
    d = FourBarDesign(
        float(p[0]),
        float(p[1]),
        float(p[2]),
        float(p[3]),
        (float(p[4]), float(p[5])),
        "open" if r.circuit > 0 else "crossed",
        (float(p[6]), float(p[7]), float(p[8])),
        wrapped(r.theta),
        math.nan,
        t,
        timed,
        seconds,
    )
    return d, p


def _rocking_asked(ordered: bool, min_transmission: float, input_rocks: bool) -> str:
    """What every result of the rocking search must be, in words, for when none is: its input link rocking
    (``input_rocks``), the targets on one swing (in order when ``ordered``), and the transmission angle over that
    swing ``min_transmission`` (rad) or :data:`TOGGLE_FLOOR_DEG` from a toggle, whichever is more; each with the
    option that asks for it, so the one to relax can be seen (a trial's beak arc found nothing with
    ``--min-transmission 20`` and ``--input-rocks``, where the line named only the swing)."""
    asked = ["whose input link cannot turn fully (--input-rocks)"] if input_rocks else []
    asked.append("with the targets on one swing of its input" + (", met in their order (--ordered)" if ordered else ""))
    deg = math.degrees(float(min_transmission))
    if deg > TOGGLE_FLOOR_DEG:
        asked.append(f"keeping the transmission angle {deg:.4g} deg from a toggle over that swing (--min-transmission)")
    else:
        asked.append(f"keeping the transmission angle {TOGGLE_FLOOR_DEG:g} deg from a toggle over that swing (the floor)")
    return (
        "the rocking search found no four-bar " + ", ".join(asked[:-1]) + " and " + asked[-1] + ": none it found "
        "is all of these; relaxing one of them may let one through"
    )


def synthesise_rocking_path(
    targets: Array,
    tolerance: float = DEFAULT_TOLERANCE,
    ordered: bool = False,
    max_ratio: float = 10.0,
    arcs: Any = None,
    budget: str = "normal",
    min_transmission: float = 0.0,
    input_rocks: bool = False,
    windows: Any = None,
) -> FourBarDesign:
    """A four-bar whose input *rocks* (swings between two angles, never turning fully) and whose coupler point
    passes through ``targets`` ``(N, 2)`` (untimed, in order along its arc), from the rocking-arc atlas.

    ``arcs``: the atlas (default: the cached one of :data:`planar.synth.arcs.DEFAULT_FOURBARS` four-bars, or
    :data:`~planar.synth.arcs.QUICK_FOURBARS` for ``budget="quick"``, built on first use).  ``windows``: the
    curve-window atlas (:mod:`planar.synth.windows`), looked up when the rocking arcs' first starts leave nothing
    within :data:`planar.synth.arcs.BASIN` (default: the cached one of the budget, read or built on that first
    need).  A refined four-bar whose input turns fully is replaced by its cognate on the same input pivot when that
    one's input rocks (:func:`planar.synth.cognates.input_cognate`: the same curve).  Returns a
    :class:`FourBarDesign` whose ``checks`` hold ``input_swing_rad`` and ``input_swing_deg`` (the input's swing,
    from the ground line, as ``[from, to]``), ``input_swing_world_deg`` (the same from the world's +x axis),
    ``ok_accuracy`` (largest distance over the targets' size within ``tolerance``), ``ok_swing_assembles``
    (planar's solver assembles the whole swing on the design's circuit), ``ok_on_one_swing`` (every target on
    that swing), ``ok_constraints`` (link ratio), ``ok_transmission`` (over the swing, the transmission angle at
    least ``min_transmission`` rad from a toggle and never nearer than :data:`TOGGLE_FLOOR_DEG`; the smallest is
    ``min_transmission_deg``, at the input angle ``min_transmission_at_rad``; the search returns only four-bars
    that keep it) and, with ``ordered``, ``ok_order`` (the targets met in their order as the input
    swings one way).  ``input_rocks``: only a four-bar whose input link itself cannot turn fully (a double- or
    triple-rocker; by default a cognate whose crank could turn fully, swung over the targets' span, is accepted
    too); ``checks["input_link"]`` says which the result is (``"rocks"`` or ``"could turn fully"``).  When no
    four-bar is all that (on one swing, in order, its transmission angle kept, its input rocking), ``checks["error"]``
    says what was asked and ``sse`` is inf.  Raises
    :class:`InputError` naming a bad argument (as :func:`synthesise_path`).
    """
    from threadpoolctl import threadpool_limits

    from planar.synth.arcs import BASIN as ARCS_BASIN
    from planar.synth.arcs import DEFAULT_FOURBARS, QUICK_FOURBARS, load_arcs, search_arcs

    if not (check_number("max_ratio", max_ratio) > 1 and math.isfinite(max_ratio)):
        raise InputError("max_ratio", max_ratio, "a finite ratio greater than 1")
    cons = Constraints(full_turn=False, max_ratio=float(max_ratio))
    t, _, cons = check_path_args(
        targets, None, cons, budget, 0, tolerance, ordered, min_transmission, {"input_rocks": input_rocks}
    )
    arcs = _check_arcs(arcs)
    windows = _check_arcs(windows, "windows", "windows")
    t0 = time.perf_counter()
    if arcs is None:
        arcs = load_arcs(QUICK_FOURBARS if budget == "quick" else DEFAULT_FOURBARS, progress=True)

    def the_windows() -> Any:  # read (or built) only when the search's curve-window round runs
        from planar.synth.windows import load_budget_windows

        return windows if windows is not None else load_budget_windows(budget)

    c, s = normalisation(t)
    basin = basin_for(tolerance, ARCS_BASIN)
    with threadpool_limits(1):
        r, swing = search_arcs(
            (t - c) / s, arcs, cons, ordered=ordered, input_rocks=input_rocks, windows=the_windows, basin=basin
        )
    if r is None or swing is None:
        d = FourBarDesign(1.0, 1.0, 1.0, 1.0, (0.0, 0.0), "open", (0.0, 0.0, 0.0), np.zeros(len(t)), math.inf, t, False, 0.0)
        d.checks = {"error": _rocking_asked(ordered, cons.min_transmission, input_rocks), "ok_found": False}
        return d
    d, p = design_from(r, c, s, t, False, time.perf_counter() - t0)
    source = "the rocking-arc atlas lookup and refinement" if "arcs_s" in r.stages else EQUATION_SOURCE
    if r.source == "windows":
        source += " (its start from the curve-window atlas: part of the curve of a four-bar whose crank turns fully)"
    elif "windows_s" in r.stages:
        source += " (the curve-window atlas looked up too; none of its starts did better)"
    return _rocking_checked(d, r, p, swing, tolerance, ordered, cons, source, s)


def first_turn(swing: tuple[float, float]) -> tuple[float, float]:
    """A swing ``(lo, hi)`` (rad) moved by whole turns so that it starts in [-pi, pi) (a trial read "between 335.36
    and 554.89 deg" where -24.64 and 194.89 was meant); the same angles of the input."""
    turns = math.floor((swing[0] + math.pi) / (2 * math.pi))
    return swing[0] - 2 * math.pi * turns, swing[1] - 2 * math.pi * turns


def _rocking_checked(
    d: FourBarDesign,
    r: Any,
    p: Array,
    swing: tuple[float, float],
    tolerance: float,
    ordered: bool,
    cons: Any,
    source: str,
    size: float,
) -> FourBarDesign:
    """A rocking design ``d`` (kernel row ``p``, search result ``r``, targets' size ``size``) checked over its
    ``swing`` (:func:`first_turn`): see :func:`synthesise_rocking_path`."""
    import dataclasses

    from planar.synth.arcs import rocking_range

    swing = first_turn(swing)

    _check_rocking(d, r.theta, swing, tolerance, ordered, size)
    _check_transmission(d, np.linspace(swing[0], swing[1], 721), cons.min_transmission)
    d.checks["constraint_failures"] = list(constraint_failures(p, dataclasses.replace(cons, full_turn=False)))
    d.checks["ok_constraints"] = not d.checks["constraint_failures"]
    d.checks["stages_s"] = r.stages
    a, b = d.checks["input_swing_deg"]
    d.checks["found_by"] = f"{source}; the input rocks between {a:.2f} and {b:.2f} deg from the ground line"
    d.checks["input"] = "rocks"
    d.checks["input_link"] = "rocks" if rocking_range(p, r.theta) is not None else "could turn fully"
    if d.checks["input_link"] != "rocks":
        d.checks["found_by"] += (
            "; its input link could turn fully (a crank swung back and forth over the targets' span: --input-rocks asks "
            "for one that cannot)"
        )
    d.checks["evaluations"] = r.evaluations
    d.checks["cautions"] = design_cautions(d, cons, True, None)
    return d


def _check_transmission(d: Any, theta: Array | None, min_transmission: float) -> None:
    """Fill the transmission checks of design ``d`` at input angles ``theta`` (rad from the ground line; None:
    the whole turn; a rocking design: its swing, which ends short of its toggles): the limit ``min_transmission``
    (rad), never under :data:`TOGGLE_FLOOR_DEG` (:func:`transmission_margin`, planar's own four-bar)."""
    margin, where = transmission_margin(d.fourbar(), theta)
    limit = max(float(min_transmission), math.radians(TOGGLE_FLOOR_DEG))
    d.checks["min_transmission_deg"] = math.degrees(margin)
    d.checks["min_transmission_at_rad"] = where
    d.checks["transmission_limit_deg"] = math.degrees(limit)
    d.checks["ok_transmission"] = bool(margin >= limit)


def _check_rocking(d: Any, theta: Array, swing: tuple[float, float], tolerance: float, ordered: bool, size: float) -> None:
    """Fill ``d.sse`` and ``d.checks`` from planar's solver: at the targets, and over the swing (dense, as a
    path, against the same angles as a scattered batch: the circuit never switches)."""
    fb = d.fourbar()
    lo, hi = swing
    from planar.synth.arcs import on_swing, one_way

    u = on_swing(theta, swing)  # the targets' input angles on the swing
    at = fb.solve(u)
    pts = at.points["coupler_point"]
    dist = np.hypot(*(pts - d.targets).T)
    d.sse = float(np.sum(dist**2)) if at.valid.all() else math.inf
    sweep = np.linspace(lo, hi, 721)
    path = fb.solve(sweep)
    perm = np.random.default_rng(0).permutation(len(sweep))
    batch = fb.solve(sweep[perm])
    same = bool(path.valid.all() and batch.valid.all()) and bool(
        np.max(np.abs(batch.points["coupler_point"] - path.points["coupler_point"][perm])) <= 1e-9 * size
    )
    phi = d.placement[2]
    d.checks = {
        "grashof": fb.grashof,
        "input_swing_rad": [lo, hi],
        "input_swing_deg": [math.degrees(lo), math.degrees(hi)],
        "input_swing_world_deg": [math.degrees(lo + phi), math.degrees(hi + phi)],
        "ok_valid_at_targets": bool(at.valid.all()),
        "ok_on_one_swing": bool(np.all((u >= lo - 1e-9) & (u <= hi + 1e-9))),
        "ok_swing_assembles": same,
        "max_target_distance": float(dist.max()) if at.valid.all() else math.inf,
        "worst_target": int(np.argmax(dist)) + 1,
        "size": size,
        "max_error": float(dist.max()) / size if at.valid.all() else math.inf,
        "rms_error": math.sqrt(d.sse / len(u)) / size if math.isfinite(d.sse) else math.inf,
        "tolerance": tolerance,
    }
    d.checks["ok_accuracy"] = bool(d.checks["max_error"] <= tolerance)
    if ordered:
        d.checks["ok_order"] = one_way(theta, swing)
