"""Which searches a path synthesis runs, in which order, and the sentence saying which one found the result.

:class:`PathSearch` holds one synthesis's normalised targets (centroid 0, size 1) and what was asked of it, and runs
the searches of :mod:`planar.synth.search`, :mod:`planar.synth.algebraic` and :mod:`planar.synth.arcs` in turn:

- timed targets: the closed form, then the atlas with the timing, then the global search when neither is within the
  tolerance (:meth:`PathSearch.timed`);
- untimed targets: from :data:`planar.synth.algebraic.MIN_TARGETS` targets their own curve equation (no atlas is
  loaded when it gives the four-bar, :meth:`PathSearch.from_equation`), then the closed-curve atlas, the rocking arcs
  and the global search (:meth:`PathSearch.searched`).

The atlas is loaded (or built) on first need only; every stage that runs adds its seconds to
:attr:`PathSearch.stages`.  :mod:`planar.synth.path` builds and checks the design from the result.
"""

from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from planar.synth.search import Constraints, PathObjective, basin_for, search_fourbar

__all__ = ["BUDGETS", "EQUATION_ORDER_SOURCE", "EQUATION_SOURCE", "PathSearch"]

Array = NDArray[np.float64]
#: a search's result, the sentence saying which stage produced it, and the input's swing (rad from the ground line)
#: when the result's input rocks (None when it turns fully)
Found = tuple[Any, str, "tuple[float, float] | None"]

#: effort of the global search (random sample, differential evolution, least-squares starts) per budget
BUDGETS: dict[str, dict[str, Any]] = {
    "quick": {"n_sample": 20_000, "maxiter": 60, "popsize": 15, "refine": 3},
    "normal": {"n_sample": 100_000, "maxiter": 200, "popsize": 30, "refine": 8},
    "thorough": {"n_sample": 500_000, "maxiter": 600, "popsize": 40, "refine": 16},
}

#: ``found_by`` of a result the targets' own curve equation gave (:func:`planar.synth.algebraic.search_algebraic`)
EQUATION_SOURCE = "the targets' own curve equation (its singular foci; no atlas lookup: within the tolerance)"
#: ``found_by`` when that equation's four-bars pass through every target but meet them out of the given order
EQUATION_ORDER_SOURCE = (
    "the targets' own curve equation: a four-bar passes through every target, but meets them in another order than "
    "listed, as every four-bar tracing this curve does (with --ordered list them in their order along the curve, "
    "or drop --ordered); no atlas lookup"
)


def keeps_transmission(r: Any, cons: Constraints) -> bool:
    """Whether a search result keeps ``cons.min_transmission`` over the turn (True when none is asked)."""
    from planar.synth.search import violation

    only = Constraints(full_turn=False, max_ratio=np.inf, min_transmission=cons.min_transmission)
    return bool(violation(np.asarray(r.params, float)[None, :], only, 1.0, 0.0)[0] <= 1e-12)


def _windows_word(r: Any) -> str:
    """Words saying the curve-window atlas was looked up too for search result ``r`` (empty when it was not)."""
    return "the curve-window atlas looked up too, as for part of a curve; " if "windows_s" in r.stages else ""


def _prefixed(stages: dict[str, float]) -> dict[str, float]:
    """The global search's stages named as such (``global_sample_s``, ``global_de_s``, ``global_refine_s``)."""
    return {f"global_{k}": v for k, v in stages.items()}


@dataclass
class PathSearch:
    """The search of one path synthesis on normalised targets ``t`` ``(N, 2)`` (centroid 0, size 1; ``cons``
    normalised with them).

    ``budget``: a key of :data:`BUDGETS`; ``tolerance``: the largest distance (the targets' size 1) that ends the
    search; ``atlas``: the closed-curve atlas (None: the cached one of the budget, loaded on first need);
    ``ordered``: the branch must pass the targets in their order; ``arcs``: the rocking-arc atlas (None: the cached
    one of the budget when it is on disk); ``full_turn``: only an input that turns fully (the rocking arcs are not
    tried); ``windows``: the curve-window atlas (None: the cached one of the budget, loaded on first need).
    :meth:`run` returns the result (a
    :class:`planar.synth.search.SearchResult` whose ``stages`` hold every stage's seconds: ``atlas_load_s``,
    ``algebraic_s``, ``atlas_s``, ``windows_load_s``, ``windows_s``, ``refine_s``, ``timed_s`` or ``closed_form_s``,
    ``rocking_s``, and
    ``global_sample_s``, ``global_de_s``, ``global_refine_s`` when the global search ran), the sentence saying which
    stage produced it, and the input's swing when it rocks."""

    t: Array
    cons: Constraints
    budget: str = "normal"
    seed: int = 0
    tolerance: float = 1e-3
    atlas: Any = None
    ordered: bool = False
    arcs: Any = None
    stages: dict[str, float] = field(default_factory=dict)
    full_turn: bool = False
    windows: Any = None

    def __post_init__(self) -> None:
        self._given = self.atlas

    def run(self, theta: Array | None) -> Found:
        """The search: :meth:`timed` with crank angles ``theta`` (rad), :meth:`untimed` without."""
        return self.untimed() if theta is None else self.timed(theta)

    def loaded_atlas(self) -> Any:
        """The closed-curve atlas, loaded (or built) on first need: timed targets the closed form solves need none."""
        if self.atlas is None:
            from planar.synth.atlas import DEFAULT_SIZE, QUICK_SIZE, load_atlas

            t0 = time.perf_counter()
            self.atlas = load_atlas(QUICK_SIZE if self.budget == "quick" else DEFAULT_SIZE, progress=True)
            self.stages["atlas_load_s"] = time.perf_counter() - t0
        elif self.atlas is self._given:
            self.stages.setdefault("atlas_load_s", 0.0)
        return self.atlas

    def loaded_windows(self) -> Any:
        """The curve-window atlas (:mod:`planar.synth.windows`), loaded (or built) on first need: only when the closed
        curve's first starts fail."""
        if self.windows is None:
            from planar.synth.windows import load_budget_windows

            t0 = time.perf_counter()
            self.windows = load_budget_windows(self.budget)
            self.stages["windows_load_s"] = time.perf_counter() - t0
        return self.windows

    def _search_atlas(self, cons: Constraints) -> Any:
        """:func:`planar.synth.search.search_atlas` on the targets with ``cons``, the curve-window atlas loaded if its
        stage runs; its stages each count a second once (``windows_s`` without the loading, ``windows_load_s``)."""
        from planar.synth.search import search_atlas

        before = self.stages.get("windows_load_s", 0.0)
        basin = basin_for(self.tolerance)
        r = search_atlas(self.t, self.loaded_atlas(), cons, ordered=self.ordered, windows=self.window_candidates, basin=basin)
        if "windows_s" in r.stages:
            r.stages["windows_s"] -= self.stages.get("windows_load_s", 0.0) - before
        return r

    def window_candidates(self, t: Array, k: int) -> Array:
        """Candidate rows for targets ``t`` from the curve-window atlas (:func:`planar.synth.windows.window_candidates`,
        ``k`` neighbours a view), the atlas loaded on this first need (:meth:`loaded_windows`)."""
        from planar.synth.windows import window_candidates

        return window_candidates(self.loaded_windows(), t, k)

    def _distance(self, r: Any, theta: Array | None, cons: Constraints | None = None) -> float:
        """Largest distance from a target to the coupler point of result ``r`` (at ``theta``, or at its own angles)."""
        from planar.synth.search import max_distance

        th = r.theta if theta is None else theta
        obj = PathObjective(self.t, theta, self.cons if cons is None else cons)
        return max_distance(obj, np.append(r.params, r.circuit), th)

    def _usable(self, r: Any) -> bool:
        """Whether an untimed result keeps the constraints, the order (when asked) and the transmission limit."""
        from planar.synth.search import in_order

        return bool(r.feasible and (in_order(r.theta) or not self.ordered) and keeps_transmission(r, self.cons))

    def timed(self, theta: Array) -> Found:
        """Timed targets: the closed form, then the curve from the atlas and the timing (exact when the atlas finds
        the four-bar itself; a cognate traces the same curve at other crank angles), then the global search when
        neither is within the tolerance."""
        from planar.synth.search import timed_from_atlas

        timed = timed_from_atlas(self.t, theta, self.loaded_atlas, self.cons)
        e_atlas = self._distance(timed, theta) if timed is not None else math.inf
        good = timed is not None and timed.feasible and keeps_transmission(timed, self.cons)
        if timed is not None and good and e_atlas <= self.tolerance:
            how = (
                "the closed-form timed solution (no atlas lookup"
                if "closed_form_s" in timed.stages
                else "the atlas lookup and refinement ("
            )
            timed.stages = {**self.stages, **timed.stages}
            sep = "; " if how.endswith("lookup") else ""
            return timed, f"{how}{sep}the global search did not run: within the tolerance)", None
        g = search_fourbar(self.t, theta, self.cons, seed=self.seed, **BUDGETS[self.budget])
        stages = {**self.stages, **(timed.stages if timed is not None else {}), **_prefixed(g.stages)}
        e_global = self._distance(g, theta)
        g_good = g.feasible and keeps_transmission(g, self.cons)
        if timed is not None and (good, -e_atlas) > (g_good, -e_global):  # the atlas's is usable and closer: kept
            timed.stages = stages
            other = f"found no better: {e_global:.3g}" if g_good else "found none usable"
            return (
                timed,
                f"the atlas lookup and refinement (the global search, budget {self.budget}, ran too and {other})",
                None,
            )
        g.stages = stages
        return g, f"the global search (budget {self.budget}; the atlas's best was {e_atlas:.3g} of the size off)", None

    def untimed(self) -> Found:
        """Untimed targets: from :data:`planar.synth.algebraic.MIN_TARGETS` targets their own curve equation
        (:meth:`from_equation`: no atlas is loaded when it gives the four-bar), then :meth:`searched`."""
        from planar.synth.algebraic import MIN_TARGETS

        if len(self.t) < MIN_TARGETS:
            return self.off_toggle(*self.searched())
        t0 = time.perf_counter()
        alg, how, swing = self.from_equation()
        self.stages["algebraic_s"] = time.perf_counter() - t0
        if alg is not None:
            alg.stages = dict(self.stages)
            return alg, how, swing
        r, source, swing = self.searched()
        # "within the tolerance": with a looser one the same four-bar may come from the equation (a trial's drawn foot
        # path: this line at the default tolerance, the equation's four-bar at 0.01)
        gave = "; the targets' own curve equation gave no four-bar within the tolerance (see the curve equation docs)"
        return self.off_toggle(r, source + gave, swing)

    def off_toggle(self, r: Any, source: str, swing: tuple[float, float] | None) -> Found:
        """An untimed result not within the tolerance whose crank turns fully but brings the linkage within
        :data:`planar.synth.designs.TOGGLE_FLOOR_DEG` of a toggle (a linkage that nearly folds: no answer, though
        the nearest) is searched again keeping that floor (:func:`planar.synth.search.search_atlas` with it as
        ``min_transmission``); the new result is kept when it keeps the floor, the order and the constraints."""
        from planar.synth.designs import TOGGLE_FLOOR_DEG

        floor = math.radians(TOGGLE_FLOOR_DEG)
        floored = dataclasses.replace(self.cons, min_transmission=floor)
        if swing is not None or self.cons.min_transmission >= floor or keeps_transmission(r, floored):
            return r, source, swing
        e_before = self._distance(r, None)
        if e_before <= self.tolerance:
            return r, source, swing
        t0 = time.perf_counter()
        again = self._search_atlas(floored)
        stages = {**r.stages, "floor_s": time.perf_counter() - t0}
        if not (keeps_transmission(again, floored) and self._usable(again)):
            r.stages = stages
            return r, source + f"; searched again {TOGGLE_FLOOR_DEG:g} deg from a toggle, none found usable", swing
        again.stages = stages
        why = (
            f"the atlas lookup and refinement searched again keeping the transmission angle at least "
            f"{TOGGLE_FLOOR_DEG:g} deg from a toggle (largest distance {self._distance(again, None):.3g} of the size): "
            f"the nearest found without that floor, {e_before:.3g} of the size off, nearly folds and is not offered "
            f"(that first search: {source})"
        )
        return again, why, swing

    def from_equation(self) -> Found:
        """The four-bar of the targets' own curve equation (:func:`planar.synth.algebraic.search_algebraic`): a crank
        keeping the constraints and the order first, then a rocking input (when the rocking search may be tried: no
        pivots box, no transmission limit), then, with ``ordered``, one through every target in another order (every
        four-bar tracing that curve meets them so: no search would do better).  The result is None when none."""
        from planar.synth.algebraic import search_algebraic
        from planar.synth.arcs import usable_swing
        from planar.synth.search import in_order, violation

        cons, ordered = self.cons, self.ordered
        rocking = cons.region is None and cons.min_transmission == 0
        free = dataclasses.replace(cons, full_turn=False)

        def choose(r: Array, tt: Array) -> tuple[int, Any] | None:
            keeps = violation(r[None, :9], cons, 1.0, 0.0)[0] <= 0
            if keeps and (in_order(tt) or not ordered):
                return 0, None
            swing = usable_swing(r, tt, free, 1.0, ordered) if rocking else None
            if swing is not None:
                return 1, swing
            return (2, "order") if keeps else None

        alg, extra = search_algebraic(self.t, cons, choose, stop=min(1e-9, self.tolerance), accept=self.tolerance)
        if alg is None:
            return None, "", None
        if extra == "order":
            return alg, EQUATION_ORDER_SOURCE, None
        return alg, EQUATION_SOURCE, extra

    def searched(self) -> Found:
        """Untimed targets by search: the closed-curve atlas, the rocking arcs (:meth:`rocking`), then the global
        search; the best of them when none is within the tolerance (usable first, then the smaller largest
        distance, what the check judges)."""

        r = self._search_atlas(self.cons)
        good = self._usable(r)
        e_atlas = self._distance(r, None)
        if good and e_atlas <= self.tolerance:
            r.stages = {**self.stages, **r.stages}
            how = f"the atlas lookup and refinement ({_windows_word(r)}the global search did not run: within the tolerance)"
            return r, how, None
        stages = {**self.stages, **r.stages}
        rock, swing, e_rock, rock_word = self.rocking(stages)
        if rock is not None and e_rock <= self.tolerance:
            rock.stages = stages
            why = f"the closed-curve atlas's best was {e_atlas:.3g} of the size off; the global search did not run"
            return rock, f"{rock_word} ({why})", swing
        g = search_fourbar(self.t, None, self.cons, seed=self.seed, **BUDGETS[self.budget])
        g_good = self._usable(g)
        e_global = self._distance(g, None)
        stages.update(_prefixed(g.stages))
        if rock is not None and (True, -e_rock) > max((g_good, -e_global), (good, -e_atlas)):
            rock.stages = stages
            why = f"better than the closed-curve atlas's {e_atlas:.3g} and the global search's {e_global:.3g}"
            return rock, f"{rock_word} (largest distance {e_rock:.3g} of the size; {why})", swing
        tried = f"; {rock_word}: {e_rock:.3g}" if rock is not None else f"; {rock_word}" if rock_word else ""
        if (g_good, -e_global) > (good, -e_atlas):
            g.stages = stages
            # preferred because the atlas's best was closer but unusable, or because it is closer
            than = (
                f"closer than the atlas's {e_atlas:.3g}"
                if good
                else f"the atlas's best, {e_atlas:.3g}, was out of order or broke a constraint"
            )
            return (
                g,
                f"the global search (budget {self.budget}; largest distance {e_global:.3g} of the size, {than}{tried})",
                None,
            )
        r.stages = stages
        other = f"found no better: {e_global:.3g}" if g_good else "found none usable (out of order or breaking a constraint)"
        head = f"the atlas lookup and refinement (largest distance {e_atlas:.3g} of the size; the global search, "
        return r, f"{head}budget {self.budget}, ran too and {other}{tried})", None

    def rocking(self, stages: dict[str, float]) -> tuple[Any, tuple[float, float] | None, float, str]:
        """The rocking arcs (:func:`planar.synth.arcs.search_arcs`), when they may be tried: not ``full_turn``, no
        pivots box, no transmission limit (the rocking search keeps neither), and the arcs given or the cached arc atlas of the
        budget on disk (it is not built here: ``planar synth atlas --rocking`` builds it).

        Returns the result (None when not tried or nothing keeps the targets on one swing, in order when
        ``ordered``), its swing, its largest distance (the targets' size 1) and a few words saying what was tried
        (empty when nothing was); ``stages`` gains ``rocking_s``."""
        from planar.synth import arcs as arcs_mod

        cons, budget, arcs = self.cons, self.budget, self.arcs
        if self.full_turn:
            return None, None, math.inf, "the rocking arcs not tried (the input must turn fully)"
        if cons.region is not None or cons.min_transmission > 0:
            return None, None, math.inf, ""
        if arcs is None:
            size = arcs_mod.QUICK_FOURBARS if budget == "quick" else arcs_mod.DEFAULT_FOURBARS
            path = arcs_mod.arcs_path(size)
            if not path.exists():
                which = f"the rocking-arc atlas of --budget {budget} ({size:,} four-bars)"
                build = "planar synth atlas --rocking" + ("" if size == arcs_mod.DEFAULT_FOURBARS else f" --size {size}")
                return None, None, math.inf, f"{which} is not built ({build} builds it)"
            arcs = arcs_mod.read_arcs(path)
        t0 = time.perf_counter()
        rock_cons = dataclasses.replace(cons, full_turn=False)
        basin = basin_for(self.tolerance, arcs_mod.BASIN)
        r, swing = arcs_mod.search_arcs(self.t, arcs, rock_cons, ordered=self.ordered, basin=basin)
        stages["rocking_s"] = time.perf_counter() - t0
        word = "the rocking-arc atlas lookup and refinement"
        if r is None or swing is None or (self.ordered and not arcs_mod.one_way(r.theta, swing)):
            return None, None, math.inf, word + " found none on one swing" + (" in order" if self.ordered else "")
        return r, swing, self._distance(r, None, rock_cons), word
