"""Stepping a rebuilt mechanism sample by sample, checking its poses in blocks, and the motor torque."""

from __future__ import annotations

import ctypes
import math
import time
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from planar.analysis.dynamics import inverse_dynamics_torque
from planar.core.effects import Effects
from planar.core.geometry import poses_apply, wrap_angle
from planar.core.model import Mechanism, Motion, joint_residuals
from planar.errors import InputError, PlanarError
from planar.physics.cycle import check_cycle
from planar.physics.rebuild import _JACC, _motor_impulse_offset, _Rebuild
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

if TYPE_CHECKING:
    from planar.scene.load import Scene

Array = NDArray[np.float64]


@dataclass(frozen=True)
class SimFailure:
    """Where and how a simulation left its analytic motion.

    ``kind``: ``"blow-up"`` (non-finite state or a joint came apart),
    ``"change-point"`` (a branch switch or drift within three samples after the
    analytic motion passes a change point or toggle, see :func:`change_point`),
    ``"branch"`` (every joint holds but a part is more than ten tolerances
    elsewhere: another assembly branch) or ``"drift"`` (the part is off by
    more than ``tolerance``, the joints by less than ``blowup_tol``).  ``error``: the part's distance from its
    analytic pose as a fraction of the size.
    """

    sample: int
    time: float
    part: str
    kind: str
    error: float
    message: str


@dataclass
class SimResult:
    """A simulated motion and what it took."""

    motion: Motion
    settings: SimSettings
    mode: str
    built: dict[str, Any]
    wall_time: float
    steps: int
    torque: Array | None = None
    failure: SimFailure | None = None
    #: the rebuild's pin bodies: (part, point in its frame, mass)
    pins: list[tuple[str, tuple[float, float], float]] = field(default_factory=list)
    residuals: dict[str, Array] = field(default_factory=dict)
    #: samples whose interval had a step with the motor at its force limit (motor mode)
    saturated: NDArray[np.intp] = field(default_factory=lambda: np.zeros(0, dtype=np.intp))
    #: largest deviation of every part from its analytic pose over the simulated samples, / size
    pose_error: dict[str, float] = field(default_factory=dict)

    @property
    def blowup(self) -> tuple[int, str] | None:
        """``(sample, message)`` of the failure, if any (any kind, not only blow-ups)."""
        return None if self.failure is None else (self.failure.sample, self.failure.message)


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


def _hull_points(mech: Mechanism, part: str) -> Array:
    """Points that stand for a part: its hull circle centres (so rotation errors count too)."""
    p = mech.part(part)
    return np.array([(x, y) for x, y, _ in p.hull] or [(0.0, 0.0)], float)


class _PoseCheck:
    """Deviation of simulated poses from the analytic ones, a block of samples at a time."""

    def __init__(self, mech: Mechanism, analytic: dict[str, Array], names: list[str], cogs: Array, settings: SimSettings) -> None:
        self.mech = mech
        self.names = names
        self.cogs = cogs  # (B, 2) body frame origin in the part frame
        self.pts = {n: _hull_points(mech, n) for n in names}
        self.ref = {n: poses_apply(analytic[n], self.pts[n]) for n in names}  # (N, M, 2)
        self.size = mech.size
        self.tol = settings.tolerance * self.size
        self.worst = dict.fromkeys(names, 0.0)

    def part_poses(self, raw: Array) -> Array:
        """``(N, B, 3)`` body states (centre of gravity, angle) -> part frame poses."""
        a = raw[..., 2]
        c, s = np.cos(a), np.sin(a)
        cx, cy = self.cogs[:, 0], self.cogs[:, 1]
        out = np.empty_like(raw)
        out[..., 0] = raw[..., 0] - (c * cx - s * cy)
        out[..., 1] = raw[..., 1] - (s * cx + c * cy)
        out[..., 2] = a
        return out

    def block(self, poses: Array, i0: int) -> tuple[int, str, float] | None:
        """First sample of the block (absolute index) where a part is off, that part and its error."""
        n = poses.shape[0]
        dev = np.empty((n, len(self.names)))
        for k, name in enumerate(self.names):
            pts = poses_apply(poses[:, k], self.pts[name])
            d = np.hypot(*(pts - self.ref[name][i0 : i0 + n]).transpose(2, 0, 1)).max(axis=1)
            dev[:, k] = np.where(np.isfinite(d), d, np.inf)
        bad = (dev > self.tol).any(axis=1)
        if not bad.any():
            for k, name in enumerate(self.names):
                self.worst[name] = max(self.worst[name], float(dev[:, k].max()))
            return None
        i = int(np.flatnonzero(bad)[0])
        for k, name in enumerate(self.names):
            self.worst[name] = max(self.worst[name], float(dev[: i + 1, k].max()))
        k = int(np.argmax(dev[i]))
        return i0 + i, self.names[k], float(dev[i, k])


def _classify(
    mech: Mechanism, poses: dict[str, Array], i: int, part: str, err: float, t: float, settings: SimSettings
) -> SimFailure:
    size = mech.size
    one = {k: v[i : i + 1] for k, v in poses.items()}
    finite = all(np.isfinite(v).all() for v in one.values())
    res = {j.name: float(np.max(j.residual(one))) for j in mech.joints} if finite else {}
    worst_joint = max(res, key=lambda k: res[k]) if res else None
    worst = res[worst_joint] if worst_joint is not None else math.inf
    where = f"at sample {i} (t = {t:.6g} s) part {part!r}"
    if not finite or not math.isfinite(err):
        return SimFailure(i, t, part, "blow-up", math.inf, f"blew up {where}: non-finite body state")
    rel = err / size
    if worst > settings.blowup_tol * size:
        return SimFailure(
            i,
            t,
            part,
            "blow-up",
            rel,
            f"blew up {where}: joint {worst_joint!r} residual {worst / size:.3g} of the size "
            f"(part off its analytic pose by {rel:.3g} of the size)",
        )
    if worst < 0.1 * err and rel > 10.0 * settings.tolerance:
        # every joint holds and the part is far off: another assembly branch (an offset of a few tolerances
        # with the joints holding is drift amplified by a long lever, reported below)
        return SimFailure(
            i,
            t,
            part,
            "branch",
            rel,
            f"switched assembly branch {where}: the part is {rel:.3g} of the size from its "
            f"analytic pose while every joint holds (worst residual {worst / size:.2g} of the size)",
        )
    return SimFailure(
        i,
        t,
        part,
        "drift",
        rel,
        f"left the analytic motion {where}: {rel:.3g} of the size off (tolerance "
        f"{settings.tolerance:g}); joint {worst_joint!r} residual {worst / size:.3g} of the size",
    )


def _check_mode(mech: Mechanism, mode: str) -> None:
    if mode not in ("kinematic", "motor"):
        raise SimulationError(f"{mech.name}: mode {mode!r} is neither 'kinematic' nor 'motor'")
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


#: physics steps whose imposed poses are solved at once (memory bounded by this, not by the run's length)
_STEP_CHUNK = 65536


class _Imposed:
    """The imposed parts of a kinematic run, moved step by step onto their analytic poses.

    Steady ones (fixed position, constant angular rate) get one velocity per
    sample; the others one per step, closing on the analytic pose at the end
    of each step, from targets solved a chunk of samples at a time.
    """

    def __init__(self, mech: Mechanism, rb: _Rebuild, t: Array, poses_a: dict[str, Array], sub: int, dt: float) -> None:
        self.mech, self.t, self.sub, self.dt = mech, t, sub, dt
        size = mech.size
        names = [nm for nm in rb.driven if nm in rb.bodies and rb.bodies[nm] is not rb.space.static_body]
        first = mech.solve(mech.driver.value(t[0] + dt * np.arange(1, min(sub, 2) + 1))).poses if names else {}
        self.steady: list[tuple[Any, float, float]] = []  # body, angle at the first step, angle per step
        self.per_step: list[tuple[Any, str]] = []
        for name in names:
            pa = poses_a[name]
            inc = np.diff(pa, axis=0)
            inc[:, 2] = wrap_angle(inc[:, 2])
            step0 = float(wrap_angle(first[name][0, 2] - pa[0, 2]))
            steady = (
                np.abs(inc[:, :2]).max(initial=0.0) <= 1e-12 * size
                and abs(float(np.ptp(inc[:, 2])) if len(inc) else 0.0) <= 1e-9 * abs(sub * step0) + 1e-15
            )
            if steady and np.abs(first[name][:, :2] - pa[0, :2]).max() <= 1e-12 * size:
                self.steady.append((rb.bodies[name], float(first[name][0, 2]), step0))
            else:
                self.per_step.append((rb.bodies[name], name))
        self.targets: list[tuple[Any, list[float], list[float], list[float]]] = []
        self.k_first = 0
        self.chunk = max(1, _STEP_CHUNK // sub)

    def targets_from(self, i: int) -> None:
        """Solve the per-step targets of the samples from ``i`` (1-based interval) on, a chunk of them."""
        if not self.per_step:
            return
        t, sub, dt = self.t, self.sub, self.dt
        m = min(self.chunk, t.size - i)
        k0 = (i - 1) * sub
        ts = t[0] + dt * np.arange(k0 + 1, k0 + m * sub + 1)
        poses = self.mech.solve(self.mech.driver.value(ts)).poses
        self.targets = [(b, poses[n][:, 0].tolist(), poses[n][:, 1].tolist(), poses[n][:, 2].tolist()) for b, n in self.per_step]
        self.k_first = k0
        self.k_end = k0 + m * sub

    def sample(self, i: int) -> None:
        """Before the steps of sample ``i``: one velocity for each steady part."""
        sub = self.sub
        k0 = (i - 1) * sub
        if self.per_step and (i == 1 or k0 >= self.k_end):
            self.targets_from(i)
        for body, angle0, rate in self.steady:
            # exact for a steady turn, closing on the analytic angle at the sample's end
            target = angle0 + rate * (k0 + sub - 1)
            body.angular_velocity = math.remainder(target - body.angle, 2 * math.pi) / sub
            body.velocity = (0.0, 0.0)

    def step(self, k: int) -> None:
        """Before step ``k`` (0-based over the run): the per-step parts' velocities."""
        kk = k - self.k_first
        for body, xs, ys, angs in self.targets:
            p = body.position
            body.velocity = (xs[kk] - p.x, ys[kk] - p.y)
            body.angular_velocity = math.remainder(angs[kk] - body.angle, 2 * math.pi)


class _MotorReader:
    """The motor's signed impulse, read every step (motor mode)."""

    def __init__(self, rb: _Rebuild, dt: float) -> None:
        self.motor: Any = rb.motor
        self.jacc: Any = None
        self.jmax = math.inf
        if self.motor is None:
            return
        if not _JACC:
            _JACC.append(_motor_impulse_offset())
        from pymunk._chipmunk import ffi

        addr = int(ffi.cast("uintptr_t", self.motor._constraint)) + 8 * _JACC[0]
        self.jacc = ctypes.c_double.from_address(addr)
        if rb.motor_limit is not None:
            self.jmax = rb.motor_limit * dt * dt * (1.0 - 1e-9)

    def check(self) -> None:
        if abs(self.jacc.value) != self.motor.impulse:
            raise SimulationError("the motor's signed impulse does not match pymunk's magnitude: unknown pymunk motor layout")


Load = tuple[Any, tuple[float, float], tuple[float, float]]


def _loads(rb: _Rebuild, dt: float) -> list[Load]:
    """Each load as (body, point in its frame, the force it pushes back with, per step)."""
    return [(rb.bodies[part], rb._local(part, xy), (float(-F[0]) * dt * dt, float(-F[1]) * dt * dt)) for part, xy, F in rb.loads]


def _run_steps(
    rb: _Rebuild, imposed: _Imposed | None, motor: _MotorReader, loads: list[Load], i: int, sub: int, dt: float
) -> tuple[float, bool]:
    """The physics steps of sample ``i``; returns the motor's mean torque over them (or nan) and whether it saturated."""
    step = rb.space.step
    if imposed is not None:
        imposed.sample(i)
    if (imposed is None or not imposed.per_step) and not loads and motor.jacc is None:
        for _ in range(sub):
            step(1.0)
        return math.nan, False
    jsum = 0.0
    jbig = 0.0
    k0 = (i - 1) * sub
    for s in range(sub):
        if imposed is not None:
            imposed.step(k0 + s)
        for body, xy, F in loads:
            # the mechanism exerts F on its load: the load pushes back with -F
            body.apply_force_at_world_point(F, body.local_to_world(xy))
        step(1.0)
        if motor.jacc is not None:
            j = motor.jacc.value
            jsum += j
            jbig = max(jbig, abs(j))
    if motor.jacc is None:
        return math.nan, False
    motor.check()
    return jsum / (sub * dt * dt), jbig >= motor.jmax


def _rebuilt(
    mech: Mechanism,
    analytic: Motion,
    effects: Effects | None,
    settings: SimSettings,
    mode: str,
    dt: float,
    densities: dict[str, float] | None,
) -> tuple[_Rebuild, dict[str, Any]]:
    rb = _Rebuild(mech, analytic, effects, settings, mode, dt, densities)
    comp = rb.compensation()
    if comp:  # rebuild with the pins' mass taken out of their parts
        rb = _Rebuild(mech, analytic, effects, settings, mode, dt, densities, overrides=comp)
    return rb, comp


def _failure_at(
    mech: Mechanism,
    rb: _Rebuild,
    check: _PoseCheck,
    raw: Array,
    hit: tuple[int, str, float],
    t: Array,
    settings: SimSettings,
    analytic: dict[str, Array],
) -> SimFailure:
    done = hit[0]
    poses_all = check.part_poses(raw[: done + 1])
    pp = {nm: poses_all[:, kk] for kk, nm in enumerate(check.names)}
    for p in mech.parts:
        if p.name not in pp:
            pp[p.name] = np.repeat(rb.static_pose[p.name][None, :], done + 1, axis=0)
    f = _classify(mech, pp, done, hit[1], hit[2], float(t[done]), settings)
    if f.kind in ("branch", "drift"):
        cp = change_point(mech, analytic, max(0, done - 3), done + 1)
        if cp is not None:
            k, parts = cp
            f = replace(
                f,
                kind="change-point",
                message=f"{f.message}; the analytic motion passes a change point or toggle at sample {k} (with the "
                f"input held, {' and '.join(repr(p) for p in parts)} can still move), where the mechanism may go on "
                "in either assembly",
            )
    return f


def _closure_error(mech: Mechanism, poses: dict[str, Array]) -> Array:
    """Sum of the squared joint residuals per sample (zero on the analytic motion)."""
    return sum((np.asarray(j.residual(poses), float) ** 2 for j in mech.joints), np.zeros(len(next(iter(poses.values())))))


def _mobility(mech: Mechanism, poses: dict[str, Array], free: list[str]) -> tuple[Array, Array]:
    """Per sample: the smallest over the largest eigenvalue of ``J^T J`` with the imposed parts held, and
    the eigenvector of the smallest (the free parts' way to move).

    ``J`` is the joints' constraint Jacobian in the free parts' poses (x, y
    and angle x size), found as the Hessian of the summed squared residuals
    by finite differences.  It is singular, the ratio near zero, where the
    mechanism can move with its input held: a change point or a toggle.
    """
    size = mech.size
    m = 3 * len(free)
    h = 1e-4 * size
    n = len(next(iter(poses.values())))

    def shifted(steps: list[int]) -> dict[str, Array]:
        out = dict(poses)
        for k in steps:
            part, c = free[k // 3], k % 3
            arr = out[part].copy() if out[part] is poses[part] else out[part]
            arr[:, c] += h if c < 2 else h / size
            out[part] = arr
        return out

    f0 = _closure_error(mech, poses)
    f1 = [_closure_error(mech, shifted([i])) for i in range(m)]
    H = np.empty((n, m, m))
    for i in range(m):
        for j in range(i, m):
            fij = _closure_error(mech, shifted([i, j]))
            H[:, i, j] = H[:, j, i] = (fij - f1[i] - f1[j] + f0) / (h * h)
    w, v = np.linalg.eigh(H)
    top = np.maximum(w[:, -1], 1e-300)
    return np.maximum(w[:, 0], 0.0) / top, v[:, :, 0]


def change_point(mech: Mechanism, poses: dict[str, Array], i0: int, i1: int) -> tuple[int, list[str]] | None:
    """A sample of ``i0:i1`` where the mechanism could move with its input held: a change point or toggle.

    There the constraints lose a rank (:func:`_mobility`) and the motion may
    go on in either assembly.  A sample counts when its ratio is below a
    hundredth of the median over 16 samples spread along the run.  Returns
    ``(sample, the parts that move most in the free motion)`` or ``None``.
    """
    imposed = set(_driven_parts(mech)) | {p.name for p in mech.parts if p.ground}
    free = [p.name for p in mech.parts if p.name not in imposed]
    if not free:
        return None
    n = len(next(iter(poses.values())))
    ref = np.unique(np.linspace(0, n - 1, 16).astype(int))
    idx = np.concatenate([np.arange(i0, i1), ref])
    ratio, vec = _mobility(mech, {k: v[idx] for k, v in poses.items()}, free)
    w = ratio[: i1 - i0]
    k = int(np.argmin(w))
    if not w[k] < 1e-2 * float(np.median(ratio[i1 - i0 :])):
        return None
    amount = np.abs(vec[k]).reshape(-1, 3).max(axis=1)
    parts = [free[q] for q in np.argsort(-amount)[:2]]
    return i0 + k, parts


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


def _check_simulate_args(mech: Any, t: Any, effects: Any, settings: Any, mode: Any, densities: Any) -> NDArray[np.float64]:
    """:func:`simulate`'s arguments checked at its entrance (each named); the output times as a 1-D array."""
    from planar.core.model import check_finite
    from planar.errors import InputError

    if not isinstance(mech, Mechanism):
        raise InputError("mech", type(mech).__name__, "a Mechanism (planar.FourBar, a Linkage, a scene's .mechanism)")
    times = check_finite("t", t)
    if times.ndim != 1:
        raise InputError("t", f"an array of shape {times.shape}", "a 1-D array of output times (s)")
    if times.size >= 2 and not bool(np.all(np.diff(times) > 0)):
        raise InputError("t", times, "increasing output times (s), evenly spaced")
    if effects is not None and not all(hasattr(effects, f) for f in ("gravity", "damping", "density", "springs", "loads")):
        raise InputError("effects", type(effects).__name__, "an Effects record, or a scene's effects (or None)")
    if not isinstance(settings, SimSettings):
        raise InputError("settings", type(settings).__name__, "a SimSettings")
    if not isinstance(mode, str):
        raise InputError("mode", mode, "'kinematic' or 'motor'")
    if densities is not None and not (isinstance(densities, dict) and all(isinstance(k, str) for k in densities)):
        raise InputError("densities", type(densities).__name__, "a dict of part name -> density (or None)")
    return times


def _check_memory(mech: Mechanism, n: int) -> None:
    """:class:`~planar.errors.LimitError` before a run of ``n`` samples would pass the memory limit.

    A run holds the analytic motion with its velocities, the recorded poses and the simulated motion built
    from them, and its caller the analytic motion it compares with: estimated at three times the motion's own
    bytes (:func:`planar.core.limits.motion_bytes`; a run of the Jansen leg measured 1.86 kB a sample by
    tracemalloc, estimated 2.88 kB), on top of what this process already holds."""
    from planar.core import limits

    per = 1.5 * limits.motion_bytes(len(mech.parts), len(mech.points), 2.0)  # 3 x one sample's (the bytes of 2)
    held = limits.resident_bytes()
    limits.check_memory(
        f"{mech.name}: simulation",
        f"{n:,} samples",
        held + per * n,
        "a simulated run",
        fits=f"{limits.units_within(held, per):,} samples",
    )


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
    if t.size < 2:
        raise PlanarError("simulate: needs at least two output times")
    _check_memory(mech, t.size)
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


#: samples of the run over which :func:`torque_scale` is measured (a cycle's worth is enough)
_SCALE_SAMPLES = 4096


def _interval_torque(mech: Mechanism, t: Array, K: int, effects: Effects | None, densities: dict[str, float] | None) -> Array:
    """Analytic torque averaged over the ``K`` steps' ends of the interval ending at each sample, in chunks.

    A step's impulse is what holds the motion at the step's end (symplectic
    Euler), so the steps' ends are where pymunk's torque is compared.
    """
    dt = float(t[1] - t[0])
    out = np.empty(t.size)
    chunk = max(1, _STEP_CHUNK // K)
    for i0 in range(0, t.size, chunk):
        m = min(chunk, t.size - i0)
        t_fine = t[i0] - dt + (np.arange(m * K) + 1.0) * (dt / K)
        fine = inverse_dynamics_torque(mech, t_fine, effects, densities, t_rest=float(t[0] - dt))
        out[i0 : i0 + m] = fine.reshape(m, K).mean(axis=1)
    return out


def torque_scale(mech: Mechanism, t: Array, effects: Effects | None = None, densities: dict[str, float] | None = None) -> float:
    """The mechanism's own torque scale at times ``t`` (force x length), for judging a torque difference.

    The largest over ``t`` of ``sum (m |a . v| + m |g . v| + I |alpha omega|) / w``
    over the moving parts plus ``sum |F . v| / w`` over the loads (``w`` the
    driver's rate): the torque each inertial and load term alone asks of the
    motor, without the cancellations that can leave the true torque at zero
    (a crank driving a slider at constant speed); and at least the largest
    kinetic energy per radian of the driver, ``sum (m |v|^2 + I omega^2) / 2``.
    A torque difference is reported as a fraction of this, never of a peak
    that may be round-off.  Only samples whose rates are defined count, not
    those within :data:`_SCALE_GUARD` samples of a change point or toggle
    (where differenced rates are singular), and the scale is at most
    :data:`_SCALE_SPREAD` times the 90th percentile of the samples kept.
    """
    from planar.analysis.dynamics import _wrapped, gravity_and_damping, part_mass_table, plane_gravity

    t = np.asarray(t, float)
    drv = mech.driver
    w = float(drv.rate)
    h = 1e-4 * drv.period
    m0, mp, mm = (mech.solve(drv.value(t + d)) for d in (0.0, h, -h))
    g, _ = gravity_and_damping(effects)
    work = np.zeros(t.size)
    energy = np.zeros(t.size)
    for name, (mass, cog, inertia) in part_mass_table(mech, effects, densities).items():
        gp = plane_gravity(getattr(mech.part(name), "plane", "xy"), g)
        X0, Xp, Xm = (poses_apply(m.poses[name], np.asarray(cog, float)) for m in (m0, mp, mm))
        v = (Xp - Xm) / (2 * h)
        a = (Xp - 2 * X0 + Xm) / (h * h)
        fwd = _wrapped(mp.poses[name][:, 2] - m0.poses[name][:, 2])
        back = _wrapped(m0.poses[name][:, 2] - mm.poses[name][:, 2])
        om = (fwd + back) / (2 * h)
        al = (fwd - back) / (h * h)
        work += (mass * (np.abs((a * v).sum(-1)) + np.abs((gp * v).sum(-1))) + inertia * np.abs(al * om)) / w
        energy += 0.5 * (mass * (v * v).sum(-1) + inertia * om * om)
    if effects is not None:
        for load in effects.loads:
            vp = (mp.points[load.point] - mm.points[load.point]) / (2 * h)
            work += np.abs((np.asarray(load.force, float) * vp).sum(-1)) / w
    keep = _scale_samples(mech, t) & np.isfinite(work) & np.isfinite(energy)
    return float(max(_robust_max(work[keep]), _robust_max(energy[keep])))


#: samples either side of one whose rates are undefined (a change point or toggle) left out of the torque scale
_SCALE_GUARD = 3

#: the torque scale is at most this many times the 90th percentile of its samples (a singular spike at a
#: few samples is not a scale; a quick return's genuine peak, ~2x its 90th percentile, is kept)
_SCALE_SPREAD = 10.0


def _scale_samples(mech: Mechanism, t: Array) -> NDArray[np.bool_]:
    """Samples where the rates are defined and at least :data:`_SCALE_GUARD` samples from where they are not.

    At a change point or toggle the differenced rates are singular (NaN or
    huge); they measure the singularity, not the mechanism.  A kind without
    closed-form rates keeps every sample (the finiteness check still applies).
    """
    from planar.analysis.rates import mechanism_rates
    from planar.core.registry import UnsupportedError

    try:
        _, valid, _ = mechanism_rates(mech, mech.driver.value(t), 1.0, 0.0)
    except UnsupportedError:
        return np.ones(t.size, bool)
    valid = np.asarray(valid, bool)
    bad = np.flatnonzero(~valid)
    keep = valid.copy()
    for d in range(1, _SCALE_GUARD + 1):
        keep[np.clip(bad - d, 0, t.size - 1)] = False
        keep[np.clip(bad + d, 0, t.size - 1)] = False
    return keep if keep.any() else valid


def _robust_max(x: Array) -> float:
    """The largest of ``x``, capped at :data:`_SCALE_SPREAD` times its 90th percentile (0 for none)."""
    if not x.size:
        return 0.0
    p90 = float(np.percentile(x, 90))
    return float(min(x.max(), _SCALE_SPREAD * p90)) if p90 > 0 else float(x.max())
