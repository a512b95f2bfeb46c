"""Animation timing: which instants become frames, and how long each frame shows.

A GIF frame lasts a whole number of 10 ms ticks (at least 20 ms: browsers
play shorter delays as 100 ms), so an animation plays at the scene's speed
only if the frames are *resampled* to the frame rate, not one frame per
motion sample.  :func:`plan_frames` picks the frames of one cycle so that a
cycle plays within one frame delay of its period; :func:`animation_motion`
solves the mechanism at those instants.

The motion is solved on a grid at least as fine as the scene's own samples
(the frames are every ``m``-th point of it), so a branch is carried by
continuity exactly as in ``planar motion``; the trails are drawn from that
fine grid.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from planar.core.fields import check_fields, check_kind, check_number
from planar.core.model import Motion
from planar.errors import InputError, LimitError

if TYPE_CHECKING:  # pragma: no cover
    from planar.scene.load import Scene

__all__ = ["DEFAULT_DELAY_MS", "MAX_FRAMES", "FramePlan", "animation_motion", "plan_frames", "resample", "scene_duration"]

#: default frame delay: 25 frames per second
DEFAULT_DELAY_MS = 40
#: at least this many frames per cycle before the default falls back to 20 ms frames (50 per second)
MIN_FRAMES_PER_CYCLE = 12
#: fewest frames of one cycle (an explicit --fps giving fewer is refused; a cycle too fast for a GIF plays slower)
MIN_FRAMES_ASKED = 4
#: an animation longer than this many frames is refused before anything is drawn
MAX_FRAMES = 20_000


@dataclass(frozen=True)
class FramePlan:
    """Frames of an animation.

    ``frames_per_cycle`` frames sample one driver period uniformly (the last
    frame of a cycle is followed by the first of the next, so a one-cycle
    animation loops without a seam); each shows for ``delay_ms``.  One cycle
    plays for ``frames_per_cycle * delay_ms``, within ``delay_ms / 2`` of
    ``period_s`` (the rounding to whole frames).
    """

    period_s: float
    delay_ms: float
    frames_per_cycle: int
    frames: int

    def __post_init__(self) -> None:
        check_fields(self, "FramePlan")
        for f in ("period_s", "delay_ms", "frames_per_cycle", "frames"):
            if not getattr(self, f) > 0:
                raise InputError(f"FramePlan.{f}", getattr(self, f), "a positive number")

    @property
    def fps(self) -> float:
        """Frames per second actually played."""
        return 1000.0 / self.delay_ms

    @property
    def cycle_play_s(self) -> float:
        """How long one cycle plays, seconds."""
        return self.frames_per_cycle * self.delay_ms / 1000.0

    @property
    def slowdown(self) -> float:
        """How much slower than the scene's speed the animation plays (1: at speed)."""
        return self.cycle_play_s / self.period_s

    def note(self) -> str:
        """A one-line note when a cycle plays more than one frame delay away from its period, else ``""``."""
        if abs(self.cycle_play_s - self.period_s) <= self.delay_ms / 1000.0:
            return ""
        return (
            f"a cycle of {self.period_s:.3g} s plays in {self.cycle_play_s:.3g} s ({self.slowdown:.3g}x slower: "
            f"{self.frames_per_cycle} frames of {self.delay_ms:g} ms, the fewest that show the motion at the "
            "fastest rate a GIF plays; an .mp4 plays it at speed)"
        )

    def times(self) -> np.ndarray:
        """The motion time (s) of each frame."""
        return np.arange(self.frames, dtype=np.float64) * (self.period_s / self.frames_per_cycle)


def plan_frames(
    period_s: float, duration_s: float, fps: float | None = None, tick_ms: float | None = 10.0, fps_option: str = "fps"
) -> FramePlan:
    """The frames that play ``duration_s`` of motion (period ``period_s``) at the scene's speed.

    ``fps``: frames per second asked for; the delay is ``1000 / fps`` rounded
    to a whole number of ``tick_ms`` (GIF: 10 ms, at least 20 ms, so at most
    50 frames per second; ``tick_ms=None``: video, any rate).  By default
    25 frames per second, or 50 (video: 12 frames a cycle) when a cycle would
    otherwise get fewer than 12 frames; a cycle gets at least 4 frames, so a
    cycle faster than 80 ms plays slower in a GIF (:meth:`FramePlan.note`).
    Raises :class:`InputError` for a rate a GIF cannot play, an ``fps`` that
    gives fewer than 4 frames a cycle, or more than :data:`MAX_FRAMES` frames (a :class:`LimitError`);
    the message names the argument (``fps_option`` names ``fps``: ``--fps`` for the command line).
    """
    check_number("period_s", period_s)
    check_number("duration_s", duration_s)
    if fps is not None:
        check_number(fps_option, fps)
    if tick_ms is not None and not check_number("tick_ms", tick_ms) > 0:
        raise InputError("tick_ms", tick_ms, "a positive frame tick in ms (GIF: 10), or None (video)")
    if not (math.isfinite(period_s) and period_s > 0):
        raise InputError("period_s", period_s, "a finite, positive period (s)")
    if not (math.isfinite(duration_s) and duration_s > 0):
        raise InputError("duration_s", duration_s, "a finite, positive duration (or number of cycles)")
    if fps is not None:
        if not (math.isfinite(fps) and fps > 0):
            raise InputError(fps_option, fps, "a positive number of frames per second")
        delay = 1000.0 / fps
        if tick_ms is not None:
            delay = round(delay / tick_ms) * tick_ms
            if fps > 50 or delay < 20:
                raise InputError(
                    fps_option, fps, "at most 50 frames per second in a GIF (browsers slow shorter frame delays than 20 ms)"
                )
        if period_s * 1000.0 / delay < MIN_FRAMES_ASKED:
            raise InputError(
                fps_option,
                fps,
                f"at least {MIN_FRAMES_ASKED} frames per cycle: {MIN_FRAMES_ASKED / period_s:.3g} "
                f"frames per second or more for a cycle of {period_s:.3g} s",
            )
    else:
        delay = float(DEFAULT_DELAY_MS)
        if 1000.0 * period_s / delay < MIN_FRAMES_PER_CYCLE:
            delay = 20.0 if tick_ms is not None else 1000.0 * period_s / MIN_FRAMES_PER_CYCLE
    per_cycle = max(MIN_FRAMES_ASKED, int(round(1000.0 * period_s / delay)))
    from planar.core.limits import limit

    if fps is not None and per_cycle > limit("frames"):  # one cycle alone too many: the rate is at fault
        raise InputError(
            fps_option,
            fps,
            f"at most {limit('frames') / period_s:.3g} frames per second: one cycle of {period_s:.3g} s would take "
            f"{per_cycle} frames, over the limit of {limit('frames')} (PLANAR_MAX_FRAMES)",
        )
    # MAX_FRAMES unless PLANAR_MAX_FRAMES raises it
    frames_f = per_cycle * duration_s / period_s  # inf for a duration 1e300 periods long: refused below
    if not frames_f <= limit("frames"):
        _refuse_frames(period_s, duration_s, delay, per_cycle, frames_f, fps_option)
    frames = max(1, int(round(frames_f)))
    return FramePlan(float(period_s), float(delay), per_cycle, frames)


def _refuse_frames(period_s: float, duration_s: float, delay: float, per_cycle: int, frames_f: float, fps_option: str) -> None:
    """The :class:`LimitError` of an animation of more than ``PLANAR_MAX_FRAMES`` frames, naming its culprit: the
    duration when it alone, played at the frame rate, takes too many frames; else the period, whose cycles
    (each of at least ``MIN_FRAMES_ASKED`` frames) are too short and too many."""
    from planar.core.limits import limit

    most = limit("frames")
    if duration_s * 1000.0 / delay <= most:  # a short period: each of its many cycles still takes per_cycle frames
        raise LimitError(
            "period_s",
            period_s,
            f"at most {most} frames in all (PLANAR_MAX_FRAMES): each cycle takes at least {per_cycle} frames, so "
            f"cycles of {period_s:.3g} s over {duration_s:.3g} s ask {frames_f:.3g} (a period of at least "
            f"{per_cycle * duration_s / most:.3g} s fits)",
        )
    raise LimitError(
        "duration_s",
        duration_s,
        f"an animation of at most {most} frames ({frames_f:.3g} asked for at {1000.0 / delay:.3g} frames per "
        f"second; shorten the duration, lower {fps_option} or raise PLANAR_MAX_FRAMES)",
    )


def scene_duration(scene: Scene) -> float:
    """Seconds of motion the scene asks for (``duration``, or ``cycles`` periods; one cycle by default)."""
    d = scene.spec.driver
    if d.duration is not None:
        return float(d.duration)
    return float(d.cycles if d.cycles is not None else 1.0) * scene.mechanism.driver.period


def animation_motion(scene: Scene, plan: FramePlan) -> tuple[Motion, Motion]:
    """``(frames, fine)``: the motion at the frames of ``plan`` and on the fine grid they are taken from.

    The fine grid has at least the scene's ``samples_per_cycle`` per cycle and
    holds every frame instant, so branch continuity is what the scene's own
    motion has; the trails are drawn from it.
    """
    from planar.scene.build import Scene as SceneKind

    check_kind("animation_motion(scene)", scene, SceneKind)
    check_kind("animation_motion(plan)", plan, FramePlan)
    drv = scene.mechanism.driver
    m = max(1, math.ceil(scene.spec.driver.samples_per_cycle / plan.frames_per_cycle))

    def solved(m: int) -> Motion:
        t = np.arange(plan.frames * m, dtype=np.float64) * (plan.period_s / (plan.frames_per_cycle * m))
        return scene.mechanism.solve(drv.value(t), t=t)

    fine = solved(m)
    ratio = chord_ratio(fine)
    if ratio > CHORD_RATIO:  # a point sweeping fast (near a toggle): its trail would cut across its curve
        cap = min(MAX_SAMPLES_PER_CYCLE // plan.frames_per_cycle, MAX_FINE_SAMPLES // plan.frames)
        finer = min(m * math.ceil(ratio), cap)
        if finer > m:
            m, fine = finer, solved(finer)
    return fine.take(np.arange(plan.frames) * m), fine


#: a motion is drawn from a finer grid when a named point's longest step between samples is more than this many times
#: its median step (:func:`chord_ratio`), up to :data:`MAX_SAMPLES_PER_CYCLE` a cycle and :data:`MAX_FINE_SAMPLES` in
#: all (memory bounded whatever the animation's length)
CHORD_RATIO, MAX_SAMPLES_PER_CYCLE, MAX_FINE_SAMPLES = 4.0, 20_000, 400_000


def chord_ratio(motion: Motion) -> float:
    """The largest ratio over the named points of ``motion`` of the longest step between consecutive valid samples
    to the median step (1 when no point moves): over :data:`CHORD_RATIO`, straight chords between the samples cut
    across the point's curve where it sweeps fast (a linkage near a toggle)."""
    ratio = 1.0
    ok = np.asarray(motion.valid[1:] & motion.valid[:-1], bool)
    for xy in motion.points.values():
        step = np.hypot(*np.diff(np.asarray(xy, float), axis=0).T)[ok]
        step = step[np.isfinite(step)]
        med = float(np.median(step)) if len(step) else 0.0
        if med > 0:
            ratio = max(ratio, float(step.max()) / med)
    return ratio


def resample(motion: Motion, t: np.ndarray) -> Motion:
    """``motion`` (with times) interpolated linearly to the times ``t`` (angles unwrapped first).

    For drawing a simulated motion over the analytic one at the frame
    instants; a sample is valid if both neighbours are.
    """
    if motion.t is None:
        raise InputError("motion.t", None, "a motion with sample times")
    src = motion.t
    t = np.asarray(t, dtype=np.float64)

    def lerp(v: np.ndarray) -> np.ndarray:
        return np.stack([np.interp(t, src, v[:, k]) for k in range(v.shape[1])], axis=1)

    poses = {}
    for k, v in motion.poses.items():
        u = v.copy()
        u[:, 2] = np.unwrap(u[:, 2])
        poses[k] = lerp(u)
    j = np.clip(np.searchsorted(src, t), 1, len(src) - 1)
    valid = motion.valid[j] & motion.valid[j - 1]
    code = np.where(valid, -1, np.maximum(motion.fail_code[j], motion.fail_code[j - 1])).astype(np.int16)
    return Motion(
        driver=np.interp(t, src, motion.driver),
        poses=poses,
        valid=valid,
        fail_code=code,
        fail_table=list(motion.fail_table),
        points={k: lerp(v) for k, v in motion.points.items()},
        t=t,
    )
