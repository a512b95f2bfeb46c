"""``planar bench sim``: planar's simulation against a bare pymunk loop stepping the same space."""

from __future__ import annotations

import time
from typing import TYPE_CHECKING, Any

import numpy as np

from planar.bench.timing import _machine

if TYPE_CHECKING:
    from numpy.typing import NDArray

    Array = NDArray[np.float64]


def _bare_space(mech, t, settings):
    """The same pymunk space planar builds (bodies, joints, pins), placed at the first sample, and its step count."""
    from planar.physics.simulate import _analytic_pose_velocity, _Rebuild, substeps_for

    poses, vel, analytic = _analytic_pose_velocity(mech, t)
    sub = substeps_for(mech, poses, vel, float(t[1] - t[0]), settings)
    dt = float(t[1] - t[0]) / sub
    rb = _Rebuild(mech, analytic, None, settings, "kinematic", dt)
    comp = rb.compensation()
    if comp:
        rb = _Rebuild(mech, analytic, None, settings, "kinematic", dt, overrides=comp)
    rb.set_state({k: v[0] for k, v in poses.items()}, {k: v[0] for k, v in vel.items()})
    drv = rb.bodies[mech.driver.part]
    drv.angular_velocity = mech.driver.rate * dt  # one time unit per step, as planar runs it
    return rb.space, (t.size - 1) * sub


def bench_sim(n: int = 360, repeats: int = 7) -> dict[str, Any]:
    """Time per physics step: planar's ``simulate`` against a bare pymunk loop on the same space.

    Two figures per mechanism: the stepping loop alone (wall time inside
    ``simulate``, against the bare loop), and the whole call, set-up included
    (analytic poses, substeps, the rebuild, the checks; CPU time), against
    building the bare space and stepping it.

    For the four-bar leg and the Jansen leg, ``n`` samples of one cycle at
    the default settings: planar's run (driver, pose recording, failure
    checks in blocks) and a bare ``space.step`` loop over the same bodies
    and joints (the driver turned by a constant angular velocity), timed
    alternately ``repeats`` times.  ``ratio`` is the median of the per-repeat
    ratios planar / bare (worst mechanism), with their spread.
    """
    from planar.linkages import FourBar
    from planar.physics.simulate import DEFAULT_SETTINGS, simulate
    from planar.scene.catalog import get

    st = DEFAULT_SETTINGS
    mechs = {"four-bar": FourBar(4.0, 1.0, 4.0, 3.0, coupler_point=(2.0, 1.0)), "jansen": get("jansen")}
    out: dict[str, Any] = {
        "benchmark": "sim",
        "samples": n,
        "substeps": st.substeps,
        "repeats": repeats,
        "machine": _machine(),
        "mechanisms": {},
    }
    for name, mech in mechs.items():
        t = mech.driver.times(n)
        ratios, ours, bare = [], [], []
        call_ratios, call_ours, call_bare = [], [], []
        for _ in range(repeats):
            c0 = time.process_time()
            r = simulate(mech, t, None, st)
            whole_ours = (time.process_time() - c0) / r.steps
            per_ours = r.wall_time / r.steps
            c0 = time.process_time()
            space, steps = _bare_space(mech, t, st)
            step = space.step
            t0 = time.perf_counter()
            for _ in range(steps):
                step(1.0)
            per_bare = (time.perf_counter() - t0) / steps
            whole_bare = (time.process_time() - c0) / steps
            ours.append(per_ours)
            bare.append(per_bare)
            ratios.append(per_ours / per_bare)
            call_ours.append(whole_ours)
            call_bare.append(whole_bare)
            call_ratios.append(whole_ours / whole_bare)
        out["mechanisms"][name] = {
            "planar_us_per_step": float(np.median(ours)) * 1e6,
            "bare_pymunk_us_per_step": float(np.median(bare)) * 1e6,
            "ratio": float(np.median(ratios)),
            "ratio_spread": [float(min(ratios)), float(max(ratios))],
            "planar_call_us_per_step": float(np.median(call_ours)) * 1e6,
            "bare_call_us_per_step": float(np.median(call_bare)) * 1e6,
            "call_ratio": float(np.median(call_ratios)),
            "steps": int(r.steps),
            "substeps": int(r.built["substeps"]),
            "iterations": int(r.built["iterations"]),
        }
    worst = max(out["mechanisms"].values(), key=lambda m: m["ratio"])
    out["ratio"] = worst["ratio"]
    out["ratio_spread"] = worst["ratio_spread"]
    out["call_ratio"] = max(m["call_ratio"] for m in out["mechanisms"].values())
    return out


def format_sim(r: dict[str, Any]) -> str:
    head = (
        f"physics step cost, planar vs bare pymunk on the same space ({r['samples']} samples x "
        f"{r['substeps']} substeps, {r['repeats']} interleaved repeats; {r['machine']})"
    )
    lines = [head]
    for name, m in r["mechanisms"].items():
        lines.append(
            f"  {name:<10} planar {m['planar_us_per_step']:8.2f} us/step   bare {m['bare_pymunk_us_per_step']:8.2f}"
            f" us/step   ratio {m['ratio']:.2f} (spread {m['ratio_spread'][0]:.2f}-{m['ratio_spread'][1]:.2f})"
        )
        lines.append(
            f"  {'':<10} whole call (set-up included, CPU): planar {m['planar_call_us_per_step']:8.2f} us/step   "
            f"bare set-up + loop {m['bare_call_us_per_step']:8.2f} us/step   ratio {m['call_ratio']:.2f}"
        )
    lines.append(f"  stepping loop ratio (worst mechanism, median): {r['ratio']:.2f}")
    lines.append(f"  whole call ratio (worst mechanism, median): {r['call_ratio']:.2f}")
    return "\n".join(lines)
