"""Solver settings chosen by measured behaviour: escalate the budget until two budgets agree.

A run at the given settings that holds its analytic motion is taken as it
is (no extra cost).  One that does not is run again with the budget its
failure asks for: more solver iterations where a joint's constraint error
moved the part (a blow-up, a branch switch, or a drift with a joint residual
comparable to the pose error), more substeps where the part drifted while its
joints held.  The search ends with one of three verdicts:

* ``"pass"``: a budget at which the run holds (its settings are reported);
* ``"differs"``: two budgets agree (the same first failing sample, errors
  within a factor of two): the mechanism itself leaves the analytic motion;
* ``"change-point"``: the run left its assembly where the analytic motion
  passes a change point or toggle (either assembly is a solution there);
* ``"unconverged"``: the CPU-time cap was reached while each budget still
  changed the result ("could not converge within N s"), or the run drifted
  with the substeps fixed (``step_drift`` None, ``--step-drift 0``: the search
  then turns only the iterations, never the substeps).
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


@dataclass
class Search:
    """What the search tried and concluded."""

    verdict: str
    settings: SimSettings
    tried: list[str] = field(default_factory=list)
    cpu_s: float = 0.0
    cap_s: float = DEFAULT_TIME_CAP

    def line(self) -> str:
        """One line for the terminal."""
        if self.verdict == "unconverged":
            if self.settings.step_drift is None and self.cpu_s * 3.0 <= self.cap_s:  # stopped by the fixed substeps
                return (
                    f"could not converge with the substeps fixed (--step-drift 0): the run drifted "
                    f"(tried {'; '.join(self.tried)}; raise --substeps)"
                )
            return f"could not converge within {self.cap_s:g} s (tried {'; '.join(self.tried)})"
        if self.verdict == "change-point":
            return f"at {self.tried[-1]}, the simulation took the other assembly at a change point (no budget decides that)"
        if self.verdict == "differs":
            return f"two budgets agree ({'; '.join(self.tried[-2:])}): the mechanism differs from its analytic motion"
        if len(self.tried) > 1:
            return f"converged at {self.tried[-1]} (tried {'; '.join(self.tried[:-1])})"
        return f"held at {self.tried[-1]}"


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


def hint(cause: str | None) -> str:
    """The change that helps for a cause of failure (checked by the tests)."""
    return {
        "constraint": "raise the solver iterations (--iterations): the joints' constraint error moved the part",
        "drift": "raise the substeps (--substeps): the part drifted while its joints held",
        "saturation": "raise [effects] motor_force_limit above the needed peak, or lighten the heavy part "
        "(a lower [effects] density or a smaller coupler)",
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
    failing sample, error / size, built settings)``, cause ``None`` when it held.
    ``refine(result)``: for a run that held, its error when that is above the
    accuracy aimed at (else ``None``); such a run is raised once more (iterations)
    and the better of the two kept: two budgets that agree within the aim settle it.
    """
    t0 = time.process_time()
    tried: list[str] = []
    last: tuple[int, float] | None = None
    knob_failed: str | None = None
    held: tuple[Any, float, SimSettings] | None = None
    res = None
    for _ in range(_MAX_TRIES):
        res = run(settings)
        cause, sample, err, built = outcome(res)
        tried.append(label(settings, built))
        spent = time.process_time() - t0
        if cause is None:
            rough = refine(res) if refine is not None and held is None else None
            if rough is None or spent * 3.0 > cap_s:
                if held is not None and _error(refine, res) > held[1]:
                    return held[0], Search("pass", held[2], tried, spent, cap_s)
                return res, Search("pass", settings, tried, spent, cap_s)
            held = (res, rough, settings)
            settings = replace(settings, iterations=2 * settings.iterations)
            continue
        if held is not None:  # the refinement failed where the coarser budget held: keep that one
            return held[0], Search("pass", held[2], tried, spent, cap_s)
        if cause == "change-point":  # either assembly is right there: no budget decides it
            return res, Search("change-point", settings, tried, spent, cap_s)
        if last is not None and abs(sample - last[0]) <= 1 and 0.5 <= err / max(last[1], 1e-300) <= 2.0:
            return res, Search("differs", settings, tried, spent, cap_s)
        if last is not None and sample < last[0]:
            knob_failed = cause  # this knob made it fail earlier: turn the other one
        if knob_failed == cause:
            cause = "drift" if cause == "constraint" else "constraint"
        last = (sample, err)
        if spent * 3.0 > cap_s:  # the next budget costs about twice this one
            break
        if cause != "constraint" and settings.step_drift is None:  # substeps fixed (--step-drift 0): no knob left
            break
        settings = _next(settings, built, cause)
    return res, Search("unconverged", settings, tried, time.process_time() - t0, cap_s)


def _error(refine: Callable[[Any], float | None] | None, res: Any) -> float:
    e = refine(res) if refine is not None else None
    return 0.0 if e is None else e
