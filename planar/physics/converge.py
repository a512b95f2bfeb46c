"""Solver settings chosen by measured behaviour: escalate the budget until two budgets agree.

A run at the given settings that holds its analytic motion is taken as it
is (no extra cost).  One that does not is run again with the budget its
failure asks for: more solver iterations where a joint's constraint error
moved the part (a blow-up, a branch switch, or a drift with a joint residual
comparable to the pose error), more substeps where the part drifted while its
joints held.  The search ends with one of these verdicts:

* ``"pass"``: a budget at which the run holds (its settings are reported);
* ``"differs"``: three budgets in a row agree (the same first failing
  sample, errors within a factor of two of the one before, and the last
  error not meaningfully smaller than the first of the three): the mechanism
  itself leaves the analytic motion;
* ``"change-point"``: the run left its assembly where the analytic motion
  passes a change point or toggle (either assembly is a solution there);
* ``"saturated"``: the motor reached its force limit (no budget changes that);
* ``"unconverged"``: a limit of the search stopped it while each budget
  still changed the result: the CPU-time cap ("could not converge within
  N s") or the number of budgets it tries ("gave up after 6 tries, up to 1280
  iterations, in 2.5 s CPU"), or the run drifted with the substeps fixed
  (``step_drift`` None, ``--step-drift 0``: the search then turns only the
  iterations); :attr:`Search.stopped` says which.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import Any

from planar.physics.settings import SimSettings

__all__ = ["DEFAULT_TIME_CAP", "Search", "converge", "failure_cause", "hint"]

#: CPU seconds the search may spend on one mechanism by default
DEFAULT_TIME_CAP = 60.0

#: most budgets tried (each doubles one knob)
_MAX_TRIES = 6

#: "differs" needs the last error at least this fraction of the error two budgets before (it stopped shrinking)
_NO_SHRINK = 0.7


@dataclass
class Search:
    """What the search tried and concluded."""

    verdict: str
    settings: SimSettings
    tried: list[str] = field(default_factory=list)
    cpu_s: float = 0.0
    cap_s: float = DEFAULT_TIME_CAP
    #: what ended an unconverged search: ``"time"`` (the CPU cap) or ``"tries"`` (:data:`_MAX_TRIES` budgets)
    stopped: str = ""
    #: the budget the search would have tried next (for the hint of an unconverged search)
    next_settings: SimSettings | None = None
    #: each failing budget's outcome: (first failing sample or samples run, error, progress), fractions
    outcomes: list[tuple[int, float, float]] = field(default_factory=list)
    #: a change point or toggle near where the runs fail (said with "differs" and "unconverged")
    near: str = ""

    def line(self) -> str:
        """One line for the terminal: the verdict and the limit or budgets that decided it."""
        near = f"; {self.near}" if self.near else ""
        if self.verdict == "unconverged":
            return self._unconverged() + near
        if self.verdict == "differs":
            last = "; ".join(self.tried[-3:])
            return f"{len(self.tried[-3:])} budgets agree ({last}): the mechanism differs from its analytic motion{near}"
        if self.verdict == "saturated":
            return f"at {self.tried[-1]}, the motor saturated (a solver budget does not change that)"
        if self.verdict == "change-point":
            return f"at {self.tried[-1]}, the simulation took the other assembly at a change point (no budget decides that)"
        if len(self.tried) > 1:
            return f"converged at {self.tried[-1]} (tried {'; '.join(self.tried[:-1])})"
        return f"held at {self.tried[-1]}"

    def _unconverged(self) -> str:
        tried = f"tried {'; '.join(self.tried)}"
        nxt = self.next_settings
        more = f"; try --iterations {nxt.iterations} --substeps {nxt.substeps}" if nxt is not None else ""
        if self.stopped == "substeps":
            return f"could not converge with the substeps fixed (--step-drift 0): the run drifted ({tried}; raise --substeps)"
        if self.stopped == "tries":
            its = max((_knob(x, "iterations") for x in self.tried), default=0)
            subs = max((_knob(x, "substeps") for x in self.tried), default=0)
            return (
                f"not converged: gave up after {len(self.tried)} tries, up to {its} iterations and {subs} substeps, "
                f"in {self.cpu_s:.2g} s CPU ({tried}){more}"
            )
        return f"could not converge within {self.cap_s:g} s CPU ({self.cpu_s:.2g} s spent; {tried}){more}"


def _knob(label: str, name: str) -> int:
    """The value of ``name`` in a :func:`label` (``substeps 28, iterations 40, ...``)."""
    for part in label.split(","):
        key, _, value = part.strip().partition(" ")
        if key == name:
            return int(float(value))
    return 0


def failure_cause(kind: str | None, error: float, residual: float, standing: float = 0.0) -> str | None:
    """Why a run failed, from its first failing sample.

    ``"change-point"`` (it took the other assembly at a change point);
    ``"drift"`` when the joints' residual is what stepping alone leaves
    standing (``standing``: the predicted drift per step over the correction
    per step, see :func:`planar.physics.settings.joint_drift`), so smaller steps
    help; else ``"constraint"``: the solver left more error than stepping
    explains (a blow-up, a branch switch, a residual beyond three times the
    standing drift), so more iterations help.  ``None`` for no failure.
    ``error``, ``residual`` and ``standing`` are fractions of the size.
    """
    if kind is None:
        return None
    if kind == "change-point":
        return "change-point"
    if kind == "drift" and residual <= 3.0 * standing:
        return "drift"
    return "constraint"


def hint(cause: str | None, part: str | None = None) -> str:
    """The change that helps for a cause of failure (checked by the tests).

    ``part``: for ``"saturation"``, the heaviest moving part, named as the one to lighten.
    """
    if cause == "saturation":
        what = f"a lighter {part!r}, the heaviest moving part" if part else "lighter moving parts"
        return (
            "raise [effects] motor_force_limit above the needed peak, or lighten the heavy part "
            f"(a lower [effects] density or {what})"
        )
    return {
        "constraint": "raise the solver iterations (--iterations): the joints' constraint error moved the part",
        "drift": "raise the substeps (--substeps): the part drifted while its joints held",
    }.get(cause or "", "")


def label(settings: SimSettings, built: dict[str, Any]) -> str:
    """``substeps 28, iterations 40, correction 0.2`` as the run used them."""
    return (
        f"substeps {built.get('substeps', settings.substeps)}, iterations {built.get('iterations', settings.iterations)}, "
        f"correction {float(built.get('correction', settings.correction)):.3g}"
    )


def _next(settings: SimSettings, built: dict[str, Any], cause: str) -> SimSettings:
    if cause == "constraint":
        return replace(settings, iterations=2 * settings.iterations)
    return replace(settings, substeps=2 * int(built.get("substeps", settings.substeps)))


def converge(
    run: Callable[[SimSettings], Any],
    outcome: Callable[[Any], tuple[str | None, int, float, dict[str, Any]]],
    settings: SimSettings,
    cap_s: float = DEFAULT_TIME_CAP,
    refine: Callable[[Any], float | None] | None = None,
) -> tuple[Any, Search]:
    """Run at ``settings``, escalating on failure; returns the last result and the :class:`Search`.

    ``run(settings)`` simulates; ``outcome(result)`` gives ``(cause, first
    failing sample, error / size, built settings)``, cause ``None`` when it held;
    ``built["progress"]``, when given, is what a larger budget should shrink
    while the solver limits the result (else the error is).
    ``refine(result)``: for a run that held, its error when that is above the
    accuracy aimed at (else ``None``); such a run is raised once more (iterations)
    and the better of the two kept: two budgets that agree within the aim settle it.
    """
    t0 = time.process_time()
    tried: list[str] = []
    outcomes: list[tuple[int, float, float]] = []
    knob_failed: str | None = None
    held: tuple[Any, float, SimSettings] | None = None
    res = None
    stopped = "tries"

    def search(verdict: str, st: SimSettings, spent: float) -> Search:
        return Search(verdict, st, tried, spent, cap_s, outcomes=outcomes)

    for _ in range(_MAX_TRIES):
        res = run(settings)
        cause, sample, err, built = outcome(res)
        tried.append(label(settings, built))
        spent = time.process_time() - t0
        if cause is None:
            rough = refine(res) if refine is not None and held is None else None
            if rough is None or spent * 3.0 > cap_s:
                if held is not None and _error(refine, res) > held[1]:
                    return held[0], search("pass", held[2], spent)
                return res, search("pass", settings, spent)
            held = (res, rough, settings)
            settings = replace(settings, iterations=2 * settings.iterations)
            continue
        if held is not None:  # the refinement failed where the coarser budget held: keep that one
            return held[0], search("pass", held[2], spent)
        if cause == "change-point":  # either assembly is right there: no budget decides it
            return res, search("change-point", settings, spent)
        if cause == "saturation":  # the motor is at its limit: no solver budget gives it more torque
            return res, search("saturated", settings, spent)
        outcomes.append((sample, err, float(built.get("progress", err))))
        if _agree(outcomes):
            return res, search("differs", settings, spent)
        last = outcomes[-2] if len(outcomes) > 1 else None
        if last is not None and sample < last[0]:
            knob_failed = cause  # this knob made it fail earlier: turn the other one
        if knob_failed == cause:
            cause = "drift" if cause == "constraint" else "constraint"
        if cause != "constraint" and settings.step_drift is None:  # substeps fixed (--step-drift 0): no knob left
            stopped = "substeps"
            break
        settings = _next(settings, built, cause)
        if spent * 3.0 > cap_s:  # the next budget costs about twice this one
            stopped = "time"
            break
    s = search("unconverged", settings, time.process_time() - t0)
    s.stopped, s.next_settings = stopped, settings
    return res, s


def _agree(outcomes: list[tuple[int, float, float]]) -> bool:
    """Three budgets in a row fail alike and stopped improving: the mechanism, not the solver.

    Alike: the same first failing sample (within one) and each error within a
    factor of two of the one before; stopped improving: the last error and the
    last progress measure (what a larger budget shrinks while the solver is
    what limits: the motor run's pose error) are each at least
    :data:`_NO_SHRINK` of those of the first of the three.
    """
    if len(outcomes) < 3:
        return False
    a, b, c = outcomes[-3:]
    alike = all(abs(y[0] - x[0]) <= 1 and 0.5 <= y[1] / max(x[1], 1e-300) <= 2.0 for x, y in ((a, b), (b, c)))
    return alike and c[1] >= _NO_SHRINK * a[1] and c[2] >= _NO_SHRINK * a[2]


def _error(refine: Callable[[Any], float | None] | None, res: Any) -> float:
    e = refine(res) if refine is not None else None
    return 0.0 if e is None else e
