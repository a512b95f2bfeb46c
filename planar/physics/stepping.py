"""Stepping a rebuilt mechanism sample by sample: imposed parts moved onto their analytic poses a chunk of
samples at a time, the motor's impulse read, loads applied."""

from __future__ import annotations

import ctypes
import math
from typing import Any

import numpy as np
from numpy.typing import NDArray

from planar.core.effects import Effects
from planar.core.geometry import wrap_angle
from planar.core.model import Mechanism, Motion
from planar.physics.rebuild import _JACC, _motor_impulse_offset, _Rebuild
from planar.physics.settings import (
    SimSettings,
    SimulationError,
)

Array = NDArray[np.float64]


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
