"""Two motions of one mechanism side by side: analytic against simulated.

Per part: the largest and RMS distance between the part's hull points
(model units, and as a fraction of the mechanism's size) and the largest
angle difference; per joint: the residual of the second motion; and the
first sample where a part's error passes ``threshold`` (fraction of size).

A comparison *fails* (:attr:`Comparison.passed` is false, ``planar compare``
exits with :data:`EXIT_MISMATCH`) when a part's error passes the threshold,
when the simulation reported a failure (left its analytic pose, switched
assembly branch, blew up), when the motor torque differs from inverse
dynamics by more than ``torque_threshold`` of the mechanism's torque scale
(:func:`planar.physics.run.torque_scale`, at least the peak), or when the motor
saturated.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from planar.core.geometry import poses_apply, wrap_angle
from planar.core.model import Mechanism, Motion, joint_residuals

__all__ = ["EXIT_MISMATCH", "Comparison", "PartError", "compare", "format_comparison"]

#: exit status of ``planar compare`` when a check fails (2 is a user error, 0 all checks passed)
EXIT_MISMATCH = 3


@dataclass
class PartError:
    part: str
    max_error: float
    rms_error: float
    max_rel_error: float
    max_angle_error: float
    first_over: int | None


@dataclass
class Comparison:
    mechanism: str
    size: float
    samples: int
    threshold: float
    parts: list[PartError]
    joints: dict[str, float]
    first_over: int | None
    torque: dict[str, Any] | None = None
    notes: list[str] = field(default_factory=list)
    #: the simulation's own failure report (sample, part, how), if any
    failure: str | None = None
    #: largest torque difference allowed, fraction of the mechanism's torque scale
    torque_threshold: float = 0.01
    #: how the kinematic run's settings were found (:class:`planar.physics.converge.Search`)
    search: Any = None
    #: how the motor run's settings were found, when the scene names a motor
    torque_search: Any = None
    #: what helps, for the kinematic run's failure
    hint: str = ""
    #: the kinematic run's solver settings as used (substeps, iterations, step_drift, correction, error_bias)
    settings: dict[str, Any] | None = None

    @property
    def max_rel_error(self) -> float:
        return max((p.max_rel_error for p in self.parts), default=0.0)

    def problems(self) -> list[str]:
        """Every failed check, one line each (empty when all passed)."""
        out = []
        if self.search is not None and self.search.verdict == "unconverged":
            out.append(f"simulation {self.search.line()}; last: {self.failure}")
        elif self.failure:
            verdict = self.search.verdict if self.search is not None else None
            why = {"differs": " (the budgets agree: the mechanism differs)", "change-point": " at a change point"}.get(
                verdict or "", ""
            )
            out.append(f"simulation failed{why}: {self.failure}" + (f"; {self.hint}" if self.hint else ""))
        if self.max_rel_error > self.threshold and not self.failure:
            worst = max(self.parts, key=lambda p: p.max_rel_error)
            out.append(
                f"part {worst.part!r} is {worst.max_rel_error:.3g} of the size off (threshold "
                f"{self.threshold:g}) from sample {worst.first_over}"
            )
        if self.torque:
            out += _torque_problems(self.torque, self.torque_threshold, self.torque_search)
        return out

    @property
    def passed(self) -> bool:
        return not self.problems()

    def __repr__(self) -> str:
        return (
            f"<Comparison {self.mechanism!r}: {self.samples} samples, worst error {self.max_rel_error:.3g} of size "
            f"(threshold {self.threshold:g}), {'passed' if self.passed else 'FAILED'}>"
        )

    def _repr_html_(self) -> str | None:
        from planar.core.display import html

        return html("comparison", self)

    def to_dict(self) -> dict[str, Any]:
        return {
            "mechanism": self.mechanism,
            "size": self.size,
            "samples": self.samples,
            "threshold": self.threshold,
            "max_rel_error": self.max_rel_error,
            "first_over_threshold": self.first_over,
            "parts": {
                p.part: {
                    "max_error": p.max_error,
                    "rms_error": p.rms_error,
                    "max_rel_error": p.max_rel_error,
                    "max_angle_error": p.max_angle_error,
                    "first_over_threshold": p.first_over,
                }
                for p in self.parts
            },
            "joints": {k: {"max_residual": v, "max_rel_residual": v / self.size} for k, v in self.joints.items()},
            "torque": self.torque,
            "notes": self.notes,
            "failure": self.failure,
            "passed": self.passed,
            "problems": self.problems(),
            "settings": self.settings,
            "search": None if self.search is None else {"verdict": self.search.verdict, "tried": self.search.tried},
        }


def _torque_problems(t: dict[str, Any], threshold: float, search: Any) -> list[str]:
    from planar.physics.converge import hint

    out = []
    # a saturated motor explains the lines after it: no solver budget helps those
    if t.get("saturated"):
        s = t["saturated"]
        shown = ", ".join(str(i) for i in s[:12]) + (", ..." if len(s) > 12 else "")
        out.append(
            f"motor saturated at {len(s)} sample(s) [{shown}] "
            f"(force limit {t.get('motor_force_limit'):g}, needed peak {t['peak']:.4g}); "
            f"{hint('saturation', t.get('heaviest_part'))}"
        )
    why = "a consequence of the saturation" if t.get("saturated") else hint("constraint")
    if search is not None and search.verdict == "unconverged":
        out.append(f"motor-driven simulation {search.line()}")
    elif t.get("failure"):
        out.append(f"motor-driven simulation failed: {t['failure']}; {why}")
    if t["samples_compared"] and t["max_rel_diff"] > threshold:
        out.append(
            f"motor torque differs from inverse dynamics by {t['max_rel_diff']:.3g} of the torque scale "
            f"{t['scale']:.4g} at sample {t['worst_sample']} (driver at {t['worst_angle_deg']:.4g} deg; "
            f"threshold {threshold:g}); {why}"
        )
    return out


def _part_points(mech: Mechanism, part: str) -> NDArray[np.float64]:
    """Points that stand for a part: its hull circle centres (so rotation errors count too)."""
    p = mech.part(part)
    pts = np.array([(x, y) for x, y, _ in p.hull] or [(0.0, 0.0)])
    return pts


def compare(mech: Mechanism, reference: Motion, other: Motion, threshold: float = 1e-3) -> Comparison:
    """Errors of ``other`` against ``reference`` (same samples) for every part and joint."""
    size = mech.size
    # the sample the simulation failed at still counts (its pose is what it did), so the table agrees with the
    # failure it reports; the samples after it are not compared (nothing was simulated there, the imposed
    # driver included); a non-finite pose counts as infinitely far
    finite = np.ones(len(reference), bool)
    for p in mech.parts:
        finite &= np.isfinite(other.poses[p.name]).all(axis=1)
    ok = reference.valid.copy()
    stop = int(np.flatnonzero(~other.valid)[0]) if not other.valid.all() else None
    if stop is not None:  # the simulation stopped at its failure: the later samples hold no simulated pose
        ok[stop + 1 :] = False
    parts = []
    first_all: int | None = None
    for p in mech.parts:
        pts = _part_points(mech, p.name)
        a = poses_apply(reference.poses[p.name], pts)  # (N, M, 2)
        b = poses_apply(other.poses[p.name], pts)
        with np.errstate(invalid="ignore", over="ignore"):
            d = np.hypot(*(a - b).transpose(2, 0, 1)).max(axis=1)  # worst point per sample
        d = np.where(ok, np.where(finite, d, np.inf), 0.0)
        with np.errstate(invalid="ignore"):
            ang = np.abs(wrap_angle(reference.poses[p.name][:, 2] - other.poses[p.name][:, 2]))
        ang = np.where(ok & finite, ang, 0.0)
        over = np.flatnonzero(d > threshold * size)
        first = int(over[0]) if over.size else None
        if first is not None and (first_all is None or first < first_all):
            first_all = first
        n = max(int(ok.sum()), 1)
        parts.append(
            PartError(
                p.name,
                float(d.max()),
                float(np.sqrt((d[ok & finite] ** 2).sum() / n)),
                float(d.max() / size),
                float(ang.max()),
                first,
            )
        )
    res = joint_residuals(mech, other)
    joints = {k: float(np.max(np.where(ok & finite, v, 0.0))) for k, v in res.items()}
    failure = None
    if not other.valid.all():
        i = int(np.flatnonzero(~other.valid)[0])
        failure = other.fail_table[int(other.fail_code[i])][1] if other.fail_code[i] >= 0 else f"sample {i} invalid"
    notes = []
    if stop is not None and stop + 1 < len(reference):
        notes.append(
            f"compared up to sample {stop}, where the simulation stopped; the {len(reference) - stop - 1} later "
            "samples were not simulated"
        )
    return Comparison(mech.name, size, len(reference), threshold, parts, joints, first_all, notes=notes, failure=failure)


def torque_line(t: dict[str, Any]) -> str:
    """The motor check on one line: ``0 samples compared`` when none were."""
    if not t["samples_compared"]:
        return "motor torque: 0 samples compared (the motor-driven run failed before its second sample)"
    return (
        f"motor torque: pymunk vs inverse dynamics over {t['samples_compared']} samples: max |diff| "
        f"{t['max_abs_diff']:.3e} = {t['max_rel_diff']:.2g} of the torque scale {t['scale']:.4g} (peak {t['peak']:.4g}) "
        f"at sample {t['worst_sample']} (driver at {t['worst_angle_deg']:.4g} deg); motor-driven poses within "
        f"{t['pose_error']:.2e} of the size"
    )


def format_comparison(c: Comparison) -> str:
    """A table for the terminal."""
    from planar.core.fields import check_kind

    check_kind("format_comparison(c)", c, Comparison, "a Comparison (compare_scene's first result)")
    lines = [
        f"{c.mechanism}: {c.samples} samples, size {c.size:.4g}, threshold {c.threshold:g} of size",
        f"  {'part':<16}{'max err':>11}{'rms err':>11}{'max/size':>11}{'max angle':>11}  first over",
    ]
    for p in c.parts:
        first = "-" if p.first_over is None else str(p.first_over)
        lines.append(
            f"  {p.part:<16}{p.max_error:11.3e}{p.rms_error:11.3e}{p.max_rel_error:11.3e}{p.max_angle_error:11.3e}  {first}"
        )
    lines.append(f"  {'joint':<16}{'residual':>11}{'/size':>11}")
    for k, v in c.joints.items():
        lines.append(f"  {k:<16}{v:11.3e}{v / c.size:11.3e}")
    if c.search is not None:
        lines.append(f"  settings: {c.search.line()}")
    if c.torque:
        lines.append("  " + torque_line(c.torque))
        if c.torque_search is not None:
            lines.append(f"  motor settings: {c.torque_search.line()}")
    for n in c.notes:
        lines.append(f"  note: {n}")
    for n in c.problems():
        lines.append(f"  FAILED: {n}")
    return "\n".join(lines)


def _kinematic_outcome(mech: Mechanism) -> Any:
    from planar.physics.converge import failure_cause

    def outcome(sim: Any) -> tuple[str | None, int, float, dict[str, Any]]:
        f = sim.failure
        if f is None:
            return None, len(sim.motion), 0.0, sim.built
        i = f.sample
        res = max((float(v[i]) for v in sim.residuals.values()), default=0.0) / mech.size
        return failure_cause(f.kind, f.error, res, float(sim.built.get("standing_drift", 0.0))), i, f.error, sim.built

    return outcome


def _torque_outcome(threshold: float) -> Any:
    def outcome(tc: dict[str, Any]) -> tuple[str | None, int, float, dict[str, Any]]:
        built = {"substeps": tc["substeps"], "iterations": tc["iterations"], "correction": tc["correction"]}
        built["progress"] = tc["pose_error"]  # shrinks with the budget while the solver is what limits the torque
        if tc["saturated"]:  # the motor cannot give the torque: no solver budget changes that
            return "saturation", tc["samples_compared"], max(tc["max_rel_diff"], tc["pose_error"]), built
        if tc["failure"] is None and tc["max_rel_diff"] <= threshold:
            return None, tc["samples_compared"], 0.0, built
        if tc["failure_kind"] == "drift" and tc["max_rel_diff"] <= threshold:
            return "drift", tc["samples_compared"], tc["pose_error"], built
        return "constraint", tc["samples_compared"], max(tc["max_rel_diff"], tc["pose_error"]), built

    return outcome


def _heaviest_part(mech: Mechanism, effects: Any) -> str | None:
    """The heaviest part that moves (for the saturation hint), or ``None``."""
    from planar.analysis.dynamics import part_mass_table

    ground = {p.name for p in mech.parts if p.ground}
    masses = {k: v[0] for k, v in part_mass_table(mech, effects).items() if k not in ground}
    return max(masses, key=lambda k: masses[k]) if masses else None


#: samples either side of a failing sample searched for a change point or toggle
_NEAR = 3


def _near_change_point(mech: Mechanism, motion: Motion, i: int) -> str:
    """``"sample k (within 2 samples) is a change point or toggle ..."`` when one is within :data:`_NEAR` samples of ``i``."""
    from planar.physics.run import change_point

    n = len(motion)
    cp = change_point(mech, motion.poses, max(0, i - _NEAR), min(n, i + _NEAR + 1))
    if cp is None:
        return ""
    k, parts = cp
    return (
        f"the analytic motion passes a change point or toggle at sample {k}, {abs(k - i)} sample(s) from the "
        f"worst one (with the input held, {' and '.join(repr(p) for p in parts)} can still move)"
    )


#: a run that holds but is further than this fraction of the threshold from its analytic motion is refined
_AIM = 0.1


def compare_scene(
    scene: Any,
    settings: Any = None,
    threshold: float = 1e-3,
    torque_threshold: float = 0.01,
    with_series: bool = False,
    motor: bool | None = None,
    time_cap: float | None = None,
) -> tuple[Comparison, Any]:
    """Simulate a scene and compare it with its analytic motion; with a motor, its torque with inverse dynamics.

    The kinematic comparison always runs.  The motor-driven torque check runs
    when the scene names a motor (``[effects] motor = true`` or
    ``motor_force_limit``) or ``motor`` is true.  Each run's settings come
    from :func:`planar.physics.converge.converge` (raised from ``settings``
    until the run holds or two budgets agree, within ``time_cap`` CPU seconds
    each).  Returns the comparison and the last kinematic simulation.
    """
    from planar.core.fields import check_kind
    from planar.scene.build import Scene as SceneKind

    check_kind("scene", scene, SceneKind, "a Scene (planar.load_scene, or scene_from_mechanism)")
    _check_compare_args(settings, threshold, torque_threshold, with_series, motor, time_cap)
    from dataclasses import replace

    from planar.errors import PlanarError
    from planar.physics.converge import DEFAULT_TIME_CAP, converge, hint
    from planar.physics.simulate import DEFAULT_SETTINGS, simulate_scene, torque_comparison

    cap = DEFAULT_TIME_CAP if time_cap is None else time_cap
    settings = replace(settings or DEFAULT_SETTINGS, tolerance=threshold)
    mech = scene.mechanism
    motion = scene.motion()
    aim = threshold * _AIM

    def rough(sim: Any) -> float | None:
        e = max(sim.pose_error.values(), default=0.0)
        return e if e > aim else None

    sim, search = converge(
        lambda st: simulate_scene(scene, st, mode="kinematic"), _kinematic_outcome(mech), settings, cap, refine=rough
    )
    result = compare(mech, motion, sim.motion, threshold=threshold)
    result.torque_threshold = torque_threshold
    result.search = search
    if sim.failure is not None and search.verdict in ("differs", "unconverged"):
        search.near = _near_change_point(mech, motion, sim.failure.sample)
    result.settings = {
        "substeps": sim.built.get("substeps"),
        "iterations": sim.built.get("iterations"),
        "step_drift": settings.step_drift,
        "correction": sim.built.get("correction"),
        "error_bias": settings.error_bias,
    }
    if sim.failure is not None and search.verdict != "differs":
        cause, *_ = _kinematic_outcome(mech)(sim)
        result.hint = hint(cause)
    wants = scene.effects.wants_motor if motor is None else motor
    if not wants:
        return result, sim
    try:
        tc, tsearch = converge(
            lambda st: torque_comparison(mech, motion.t, scene.effects, st), _torque_outcome(torque_threshold), settings, cap
        )
    except PlanarError as err:
        result.notes.append(f"torque not compared: {err}")
        return result, sim
    keep: tuple[str, ...] = (
        "peak",
        "scale",
        "max_abs_diff",
        "max_rel_diff",
        "worst_sample",
        "worst_angle_deg",
        "samples_compared",
    )
    keep += ("motor_force_limit", "saturated", "failure", "pose_error", "pins", "note", "substeps", "iterations")
    result.torque = {k: tc[k] for k in keep}
    result.torque["heaviest_part"] = _heaviest_part(mech, scene.effects)
    if tsearch.verdict in ("differs", "unconverged") and tc["worst_sample"] is not None:
        tsearch.near = _near_change_point(mech, motion, int(tc["worst_sample"]))
    result.torque_search = tsearch
    if with_series:
        result.torque.update(analytic=tc["analytic"], simulated=tc["simulated"])
    return result, sim


def _check_compare_args(settings: Any, threshold: Any, torque_threshold: Any, series: Any, motor: Any, cap: Any) -> None:
    """:func:`compare_scene`'s options, each named when wrong."""
    from planar.core.fields import check_kind, check_number
    from planar.errors import InputError
    from planar.physics.settings import SimSettings

    if settings is not None:
        check_kind("settings", settings, SimSettings, "a SimSettings (or None)")
    for name, value in (("threshold", threshold), ("torque_threshold", torque_threshold)):
        if not check_number(name, value) > 0:
            raise InputError(name, value, "a positive fraction")
    if cap is not None and not check_number("time_cap", cap) > 0:
        raise InputError("time_cap", cap, "a positive number of seconds (or None)")
    if not isinstance(series, bool) or (motor is not None and not isinstance(motor, bool)):
        raise InputError("with_series, motor", (series, motor), "True or False (motor: or None)")
