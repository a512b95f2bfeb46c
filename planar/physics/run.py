"""A simulated run (:func:`simulate`): the mechanism rebuilt in pymunk, stepped, its poses checked and recorded,
and its motor torque compared with inverse dynamics (:func:`torque_comparison`).

The run's pieces live beside it: :mod:`planar.physics.stepping` (the steps), :mod:`planar.physics.failure`
(the pose checks and a failure's cause), :mod:`planar.physics.torquescale` (the torque scale) and
:mod:`planar.physics.result` (what a run returns)."""

from __future__ import annotations

import math
import time
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from planar.core.effects import Effects
from planar.core.geometry import poses_apply
from planar.core.model import Mechanism, Motion, joint_residuals
from planar.errors import InputError
from planar.physics.cycle import check_cycle
from planar.physics.failure import _failure_at, _PoseCheck, change_point
from planar.physics.rebuild import _Rebuild
from planar.physics.result import SimFailure, SimResult
from planar.physics.settings import (
    DEFAULT_SETTINGS,
    SimSettings,
    SimulationError,
    _check_mechanism,
    _driven_parts,
    joint_drift,
    mass_ratio_correction,
    moving_masses,
    substeps_for,
)
from planar.physics.stepping import _STEP_CHUNK, _Imposed, _loads, _MotorReader, _rebuilt, _run_steps
from planar.physics.torquescale import _SCALE_SAMPLES, _interval_torque, torque_scale

if TYPE_CHECKING:
    from planar.scene.load import Scene

__all__ = ["SimFailure", "SimResult", "change_point", "simulate", "simulate_scene", "torque_comparison", "torque_scale"]

Array = NDArray[np.float64]


def _analytic_pose_velocity(mech: Mechanism, t: Array) -> tuple[dict[str, Array], dict[str, Array], Any]:
    """Analytic poses at times ``t`` and their time derivatives (central differences, h = 1e-6 period)."""
    drv = mech.driver
    h = 1e-6 * drv.period
    m0 = mech.solve(drv.value(t), t=t)
    mp = mech.solve(drv.value(t + h))
    mm = mech.solve(drv.value(t - h))
    vel = {}
    for k in m0.poses:
        d = mp.poses[k] - mm.poses[k]
        d[:, 2] = np.angle(np.exp(1j * d[:, 2]))
        vel[k] = d / (2 * h)
    return m0.poses, vel, m0


def _check_mode(mech: Mechanism, mode: str) -> None:
    if mode != "motor":
        return
    if mech.driver.kind != "rotation" or mech.driver.amplitude is not None:
        raise SimulationError(f"{mech.name}: motor mode needs a driver turning at a constant rate")
    extra = list(getattr(mech, "extra_driven_parts", []))
    if extra:
        raise SimulationError(
            f"{mech.name}: motor mode drives one part; this linkage has more inputs "
            f"({', '.join(extra)}), each imposed kinematically"
        )
    if len(_driven_parts(mech)) > 1:
        raise SimulationError(
            f"{mech.name}: motor mode drives one part; this toy's stages are drawn apart, "
            "so each stage's driver must follow its parent kinematically"
        )


def _simulated_motion(
    mech: Mechanism, rb: _Rebuild, check: _PoseCheck, raw: Array, analytic: Motion, t: Array, failure: SimFailure | None
) -> Motion:
    n = t.size
    done = n if failure is None else failure.sample + 1
    poses_all = check.part_poses(raw[:done])
    names = check.names
    out: dict[str, Array] = {}
    for p in mech.parts:
        if p.name in names:
            track = poses_all[:, names.index(p.name)]
        else:
            track = np.repeat(np.asarray(rb.static_pose[p.name], float)[None, :], done, axis=0)
        full = np.empty((n, 3))
        full[:done] = track
        full[done:] = track[-1]
        full[~np.isfinite(full)] = 0.0
        out[p.name] = full
    valid = np.ones(n, dtype=bool)
    code = np.full(n, -1, dtype=np.int16)
    table: list[tuple[str, str]] = []
    if failure is not None:
        valid[failure.sample :] = False
        code[failure.sample :] = 0
        table.append(("simulation", failure.message))
    pts = {nm: poses_apply(out[part], xy) for nm, (part, xy) in mech.points.items()}
    return Motion(driver=analytic.driver, poses=out, valid=valid, fail_code=code, fail_table=table, points=pts, t=t)


def check_effects_settings(effects_field: str, effects: Any, settings_field: str, settings: Any) -> None:
    """:class:`~planar.errors.InputError` naming the argument unless ``effects`` is an Effects record (or a scene's
    effects, or None) and ``settings`` a :class:`SimSettings` (None: the caller's default)."""
    if effects is not None and not all(hasattr(effects, f) for f in ("gravity", "damping", "density", "springs", "loads")):
        raise InputError(effects_field, type(effects).__name__, "an Effects record, or a scene's effects (or None)")
    if settings is not None and not isinstance(settings, SimSettings):
        raise InputError(settings_field, type(settings).__name__, "a SimSettings (or None)")


def _check_simulate_args(mech: Any, t: Any, effects: Any, settings: Any, mode: Any, densities: Any) -> NDArray[np.float64]:
    """:func:`simulate`'s arguments checked at its entrance (each named); the output times as a 1-D array."""
    from planar.analysis.dynamics import check_densities
    from planar.core.model import check_finite
    from planar.errors import InputError

    if not isinstance(mech, Mechanism):
        raise InputError("mech", type(mech).__name__, "a Mechanism (planar.FourBar, a Linkage, a scene's .mechanism)")
    times = check_finite("t", t)
    if times.ndim != 1:
        raise InputError("t", f"an array of shape {times.shape}", "a 1-D array of output times (s)")
    if times.size >= 2 and not bool(np.all(np.diff(times) > 0)):
        raise InputError("t", times, "increasing output times (s), evenly spaced")
    check_effects_settings("effects", effects, "settings", settings)
    if settings is None:
        raise InputError("settings", settings, "a SimSettings")
    if not isinstance(mode, str) or mode not in ("kinematic", "motor"):
        raise InputError("mode", mode, "'kinematic' or 'motor'")
    if times.size < 2:
        raise InputError("t", t, "at least two output times (s)")
    check_densities(densities, mech)  # the one check inverse_dynamics_torque makes too
    return times


def _chunk_bytes(mech: Mechanism, steps: int) -> float:
    """Bytes the imposed poses of ``steps`` physics steps hold while a chunk of them is solved (:class:`_Imposed`):
    the solve's own (:func:`planar.core.limits.motion_bytes`) and the targets kept as Python floats (x, y and
    angle of each part, 32 bytes each with its list slot)."""
    from planar.core import limits

    return limits.motion_bytes(len(mech.parts), len(mech.points), float(steps)) + 3 * 32.0 * len(mech.parts) * steps


def _check_memory(mech: Mechanism, n: int, substeps: int = 1) -> None:
    """:class:`~planar.errors.LimitError` before a run of ``n`` samples would pass the memory limit.

    A run holds the analytic motion with its velocities, the recorded poses and the simulated motion built
    from them, and its caller the analytic motion it compares with: estimated at three times the motion's own
    bytes (:func:`planar.core.limits.motion_bytes`; a run of the Jansen leg measured 1.86 kB a sample by
    tracemalloc, estimated 2.88 kB), on top of what this process already holds and of one chunk of the
    imposed poses (and of the analytic torque a comparison averages) of its ``substeps`` steps a sample
    (:func:`_chunk_bytes`, at most :data:`_STEP_CHUNK` steps: a toy's coupled run at 128 substeps measured
    120 MiB more at 900 samples than at 36)."""
    from planar.core import limits

    per = 1.5 * limits.motion_bytes(len(mech.parts), len(mech.points), 2.0)  # 3 x one sample's (the bytes of 2)
    sub = max(substeps, 1)
    base = limits.resident_bytes()
    held = base + _chunk_bytes(mech, min(_STEP_CHUNK, max(n - 1, 1) * sub))
    # what fits: with a whole chunk when that many samples fill one, else with the chunk growing with the samples
    fits = limits.units_within(base + _chunk_bytes(mech, _STEP_CHUNK), per)
    if fits * sub < _STEP_CHUNK:
        fits = limits.units_within(base, per + sub * _chunk_bytes(mech, 2) / 2)
    limits.check_memory(f"{mech.name}: simulation", f"{n:,} samples", held + per * n, "a simulated run", fits=f"{fits:,} samples")


def simulate(
    mech: Mechanism,
    t: Array,
    effects: Effects | None = None,
    settings: SimSettings = DEFAULT_SETTINGS,
    mode: str = "kinematic",
    densities: dict[str, float] | None = None,
) -> SimResult:
    """Simulate ``mech`` at output times ``t`` (s, evenly spaced), driven by the analytic input.

    ``mode="motor"`` turns the driver with a ``SimpleMotor`` at the driver's
    rate; ``SimResult.torque[i]`` is the mean torque the motor applied to the
    driven part over the interval ending at sample ``i`` (counter-clockwise
    positive, model force x length units), and ``SimResult.saturated`` the
    samples where it reached ``effects.motor_force_limit``.  ``densities``
    overrides the density per part.  The run stops at the first failure
    (:class:`SimFailure`); later samples are marked invalid.  The imposed
    poses of the physics steps are solved a chunk at a time, so memory grows
    with the samples, not with the steps.
    """
    t = _check_simulate_args(mech, t, effects, settings, mode, densities)
    _check_mechanism(mech)
    _check_mode(mech, mode)
    _check_memory(mech, t.size, settings.substeps)
    dt_out = float(t[1] - t[0])
    poses_a, vel_a, analytic = _analytic_pose_velocity(mech, t)
    if not analytic.valid.all():
        i = int(np.flatnonzero(~analytic.valid)[0])
        raise SimulationError(
            f"{mech.name}: the analytic motion is invalid at sample {i} "
            f"({analytic.reason(i)}); the rebuild needs an assemblable cycle"
        )
    masses = moving_masses(mech, mode, effects, densities)
    sub = substeps_for(mech, poses_a, vel_a, dt_out, settings, mass_ratio_correction(settings, masses, mode))
    dt = dt_out / sub
    rb, comp = _rebuilt(mech, analytic, effects, settings, mode, dt, densities)
    rb.set_state({k: v[0] for k, v in poses_a.items()}, {k: v[0] for k, v in vel_a.items()})
    n = t.size
    names = rb.moving()
    bodies = [rb.bodies[k] for k in names]
    check = _PoseCheck(mech, poses_a, names, np.array([rb.cog[k] for k in names], float).reshape(-1, 2), settings)
    raw = np.empty((n, len(names), 3))
    raw[0] = [(b.position.x, b.position.y, b.angle) for b in bodies]
    imposed = _Imposed(mech, rb, t, poses_a, sub, dt) if mode == "kinematic" else None
    motor = _MotorReader(rb, dt)
    loads = _loads(rb, dt)
    torque = np.full(n, np.nan) if mode == "motor" else None
    sat = np.zeros(n, dtype=bool)
    block = max(4, min(64, 1024 // sub))
    failure: SimFailure | None = None
    checked = 1
    steps = 0
    t0 = time.perf_counter()
    for i in range(1, n):
        tau, sat[i] = _run_steps(rb, imposed, motor, loads, i, sub, dt)
        if torque is not None:
            torque[i] = tau
        steps += sub
        raw[i] = [(b.position.x, b.position.y, b.angle) for b in bodies]
        if i + 1 - checked >= block or i == n - 1:
            hit = check.block(check.part_poses(raw[checked : i + 1]), checked)
            checked = i + 1
            if hit is not None:
                failure = _failure_at(mech, rb, check, raw, hit, t, settings, poses_a)
                break
    wall = time.perf_counter() - t0
    motion = _simulated_motion(mech, rb, check, raw, analytic, t, failure)
    c = float(rb.built["correction"])
    # the joints' standing error from stepping alone: drift per step d, corrected by c per step, stands at d (1 - c) / c
    standing = joint_drift(mech, poses_a, vel_a) * dt * dt * (1.0 - c) / c if c > 0 else math.inf
    built = dict(rb.built, mode=mode, pins_compensated=sorted(comp), substeps=sub, standing_drift=standing)
    return SimResult(
        motion,
        settings,
        mode,
        built,
        wall,
        steps,
        torque,
        failure,
        pins=[(part, xy, body.mass) for body, part, xy in rb.pins],
        residuals=joint_residuals(mech, motion),
        saturated=np.flatnonzero(sat),
        pose_error={k: v / mech.size for k, v in check.worst.items()},
    )


def simulate_scene(scene: Scene, settings: SimSettings = DEFAULT_SETTINGS, mode: str | None = None) -> SimResult:
    """Simulate a scene over its cycles with its effects (kinematic driver unless a motor limit is named)."""
    from planar.core.fields import check_kind
    from planar.scene.build import Scene as SceneKind

    check_kind("scene", scene, SceneKind, "a Scene (planar.load_scene, or scene_from_mechanism)")
    e = scene.effects
    if mode is None:
        mode = "motor" if e.motor_force_limit is not None else "kinematic"
    motion = scene.motion()
    assert motion.t is not None  # a scene's motion is sampled in time
    check_cycle(scene, motion)  # a cycle that breaks is refused saying what to change, in the scene's unit
    return simulate(scene.mechanism, motion.t, e, settings, mode)


# --------------------------------------------------------------------------- torque


def torque_comparison(
    mech: Mechanism,
    t: Array,
    effects: Effects | None,
    settings: SimSettings = DEFAULT_SETTINGS,
    densities: dict[str, float] | None = None,
) -> dict[str, Any]:
    """pymunk's motor torque (signed, read every step) against inverse dynamics with every named effect.

    pymunk's torque over an output interval is the mean of its step
    impulses; it is compared with the mean of the analytic torque
    (:func:`planar.analysis.dynamics.inverse_dynamics_torque`) over the same interval,
    sampled at the steps' ends, after one sample of lead-in.  Only samples before a simulation
    failure are compared.  ``saturated`` lists the samples where the motor
    reached ``effects.motor_force_limit``.
    """
    from planar.core.fields import check_samples

    t = check_samples("torque_comparison(t)", t)
    if len(t) < 2:
        raise InputError("torque_comparison(t)", t, "two or more sample times (s)")
    t = np.asarray(t, float)
    dt = float(t[1] - t[0])
    # one sample of lead-in, so that the first compared interval starts with settled joint forces
    sim = simulate(mech, np.concatenate([[t[0] - dt], t]), effects, settings, mode="motor", densities=densities)
    K = int(sim.built["substeps"])
    analytic = _interval_torque(mech, t, K, effects, densities)
    tau = np.asarray(sim.torque, float)[1:]
    upto = t.size if sim.failure is None else sim.failure.sample - 1
    peak = float(np.abs(analytic[1:]).max()) if t.size > 1 else 0.0
    scale = max(peak, torque_scale(mech, t[: min(t.size, _SCALE_SAMPLES)], effects, densities))
    diff = np.abs(tau[1:upto] - analytic[1:upto]) if upto > 1 else np.zeros(0)
    worst = int(np.argmax(diff)) + 1 if diff.size else None
    limit = effects.motor_force_limit if effects is not None else None
    out = {
        "analytic": analytic.tolist(),
        "simulated": [None] + [None if not np.isfinite(v) else float(v) for v in tau[1:]],
        "peak": peak,
        "scale": scale,
        "max_abs_diff": float(diff.max()) if diff.size else None,
        "max_rel_diff": float(diff.max() / scale) if diff.size and scale > 0 else 0.0,
        "worst_sample": worst,
        "worst_angle_deg": None if worst is None else float(np.degrees(mech.driver.value(t[worst]))),
        "samples_compared": int(diff.size),
        "motor_force_limit": limit,
        "saturated": (sim.saturated[sim.saturated > 0] - 1).tolist(),
        "failure": None if sim.failure is None else sim.failure.message,
        "failure_kind": None if sim.failure is None else sim.failure.kind,
        "pose_error": max(sim.pose_error.values(), default=0.0),
        "pins": "each groove's pin is a body of its own whose mass is taken out of its part "
        "(same mass, centre and moment), so both sides model the same inertia",
        "note": "simulated torque: the motor's signed impulse per step / dt (mean over the interval); "
        "differences are fractions of 'scale', the mechanism's torque scale (planar.physics.run.torque_scale)",
        "wall_time": sim.wall_time,
        "substeps": K,
        "iterations": sim.built["iterations"],
        "correction": sim.built["correction"],
    }
    return out
