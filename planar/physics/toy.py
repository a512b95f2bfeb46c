"""Coupled physics of a wind-up toy: one body per rigid piece, the motor the only driver.

* **The toy's plane (xy)**: every xy piece of the :class:`~planar.toys.assembly.ToyAssembly`
  is one pymunk body (merged parts share it), the cams are keyed to the shaft,
  and a ``SimpleMotor`` on the first cam is the only driver
  (:func:`planar.physics.simulate.simulate`, ``mode="motor"``).  The pieces of #8
  stages (xz) join the same space, each tied to its body's xy piece by its x
  (:class:`SharedX`), and so do the yz followers of #6/#9: each in a space of
  its own stepped in lockstep, its contact's load put on its driver every step
  (:func:`_skew_load`).  The motor's signed torque is compared with inverse
  dynamics (:func:`planar.physics.simulate.torque_comparison`), which takes every
  piece's gravity in its plane (:func:`planar.analysis.dynamics.plane_gravity`).
* **#8 in xz** (:func:`contact_hold`): its own 2D space.  The window plate is
  a kinematic body following the slider's x; the tab pivots on the frame and
  touches the window's edge through a pair of collision shapes (a thick segment
  behind the tab's face, a small circle on the edge), so the contact can only
  push: it separates when what holds the tab (gravity or a spring in the
  stage's plane) cannot keep it there.  Lift-off is the first sample where the
  gap exceeds ``1e-3`` of the size; :func:`liftoff_speed` scans speeds, and
  :func:`hold_margin` gives the speed at which inverse dynamics says the
  contact force changes sign (an independent prediction).
* **#6 and #9 alone** (:func:`skew_stage`): rebuilt in the follower's plane (yz).
  The driver's edge meets that plane in a point moving along a line (a
  kinematic body); the pin holds it at the skew-line distance, whose in-plane
  value ``r sqrt(cos^2 a + sin^2 a cos^2 phi) / cos phi`` follows the pin's
  tilt ``a`` (``phi`` the edge's angle to x): the kinematic point is moved
  along the pin's normal by the change every step.  The rebuild is accepted
  when it stays within ``tolerance`` of the size, else refused with the
  measured error.

:func:`simulate_toy` runs all of them and reports, per stage, what was
simulated and what was not (with the reason) instead of refusing the toy.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from planar.physics.contact import (
    ContactRun,
    contact_hold,
    format_speed,
    hold_margin,
    liftoff_resolution,
    liftoff_speed,
)
from planar.physics.skew import SkewHold, _skew_load, skew_hold, skew_stage
from planar.physics.toyviews import SharedX, StageDrive, _poses, coupled_mechanism, plane_mechanism

__all__ = [
    "ContactRun",
    "SkewHold",
    "StageReport",
    "ToyPhysics",
    "_poses",
    "contact_hold",
    "coupled_mechanism",
    "hold_margin",
    "liftoff_speed",
    "plane_mechanism",
    "simulate_toy",
    "skew_hold",
    "skew_stage",
]
from planar.toys.assembly import toy_assembly
from planar.windup.mechanisms import SkewContact

Array = NDArray[np.float64]


def _register() -> None:
    from planar.physics.simulate import REBUILDERS

    @REBUILDERS.register(SharedX)
    def _shared_x(rb: Any, j: SharedX, effects: Any) -> list[Any]:
        """A groove along the second axis through ``a``'s origin holding ``b``'s anchor (a pin body)."""
        return rb._groove(j.a, rb._local(j.a, (0.0, -j.reach)), rb._local(j.a, (0.0, j.reach)), j.b, j.anchor)

    REBUILDERS.register(SkewContact)(_skew_load)


# ---------------------------------------------------------------------------- the whole toy


@dataclass
class StageReport:
    stage: str
    pattern: str
    simulated: bool
    detail: str


@dataclass
class ToyPhysics:
    """What :func:`simulate_toy` found: the motor torque of the toy's plane and every stage's fate."""

    torque: dict[str, Any]
    stages: list[StageReport] = field(default_factory=list)
    liftoff: dict[str, Any] = field(default_factory=dict)
    skew: dict[str, Any] = field(default_factory=dict)  # #6/#9: does the edge hold the pin (skew_hold, pymunk)

    @property
    def not_simulated(self) -> list[StageReport]:
        return [s for s in self.stages if not s.simulated]

    def __repr__(self) -> str:
        diff = self.torque.get("max_rel_diff") if self.torque else None
        shown = f", motor torque within {diff:.3g} of its scale" if isinstance(diff, float) else ""
        return f"<ToyPhysics: {len(self.stages)} stages, {len(self.not_simulated)} not simulated{shown}>"

    def _repr_html_(self) -> str | None:
        from planar.core.display import html

        return html("toy-report", self)


def simulate_toy(
    toy: Any, t: Array, effects: Any = None, settings: Any = None, speeds: Any = None, densities: dict[str, float] | None = None
) -> ToyPhysics:
    """The toy's coupled motor run with its torque against inverse dynamics, and every stage's own physics.

    ``t``: output times (s) at the toy's speed.  The coupled run holds the xy
    pieces and, when the scene names gravity, the xz pieces of #8 stages (tied
    to their body's xy piece by :class:`SharedX`; one 2D space, the toy's
    gravity ``(gx, gy, 0)`` acting on them as ``(gx, 0)`` along (x, z):
    :func:`planar.analysis.dynamics.plane_gravity`) and the yz followers of #6/#9 (co-simulated in their plane,
    gravity ``(gy, 0)``, their load on their driver: :func:`_skew_load`), so
    the motor torque and the inverse dynamics it is compared with both carry
    every stage.  ``densities``: per piece (assembly part name), overriding the
    scene's density in the coupled run and its inverse dynamics (e.g. a
    heavier follower).  Each #8 stage also runs alone, one-sided, scanned over
    ``speeds`` (cycles/s) for lift-off; #6/#9 are also rebuilt alone in their
    follower's plane.  A stage that cannot be simulated is reported with the
    reason.
    """
    from planar.core.fields import check_kind
    from planar.windup.chain import ToyMechanism

    check_kind("simulate_toy(toy)", toy, ToyMechanism, "a ToyMechanism (planar.windup.chain)")
    from planar.core.fields import check_samples
    from planar.errors import InputError

    t = check_samples("simulate_toy(t)", t)
    from planar.physics.run import check_effects_settings

    check_effects_settings("simulate_toy(effects)", effects, "simulate_toy(settings)", settings)
    if len(t) < 2:
        raise InputError("simulate_toy(t)", t, "two or more sample times (s)")
    from planar.analysis.dynamics import gravity_and_damping, plane_gravity
    from planar.physics.simulate import SimSettings, torque_comparison

    asm = toy_assembly(toy)
    gx, gy = (float(v) for v in gravity_and_damping(effects)[0])
    g3 = (gx, gy)  # the toy's gravity (gx, gy, 0), zero when the scene names none
    gxz = plane_gravity("xz", g3)
    g = (float(gxz[0]), float(gxz[1]))  # what an #8 stage's pieces (xz) feel of the toy's gravity (gx, gy, 0)
    has_xz = any(p.plane == "xz" and not p.ground for p in asm.parts)
    # the motor turns the xy pieces and, through the bodies they share, the xz stages (whose contact needs what
    # holds it: without gravity or a spring they are left out of the coupled run)
    flat = coupled_mechanism(asm, xz=has_xz and g != (0.0, 0.0))
    # 128 substeps, 80 iterations: measured, the motor torque's start transient at 32 substeps is 4 % of the peak
    # for the Bunny (its #8 tab coupled), 0.7 % at 64 and 1e-6 at 128 (Horse 2.6e-3, 2.6e-4, 2.9e-5)
    tq = torque_comparison(
        flat, np.asarray(t, float), effects, settings or SimSettings(substeps=128, iterations=80), densities=densities
    )
    tq["pieces"] = [p.name for p in flat.parts]
    speed = toy.driver.rate / (2 * math.pi)
    out = ToyPhysics(tq)
    for p in asm.placed:
        st = p.stage
        label, pat, num = st.label, st.realisation.pattern, st.realisation.number

        def stage_u(q: Array, _i: int = st.index) -> Array:
            toy.world_motion(q)
            return np.asarray(toy._last_bases[_i][0], float)

        drive: StageDrive = (toy.driver, stage_u)  # the stage as the toy drives it
        if num == 8:
            if g == (0.0, 0.0):
                out.stages.append(
                    StageReport(
                        label,
                        pat,
                        False,
                        (
                            "#8: its contact is held by gravity or a spring in its plane (xz); "
                            + (
                                "the scene names none"
                                if g3 == (0.0, 0.0)
                                else f"the scene's gravity ({g3[0]:g}, {g3[1]:g}) has no x component, and its y is normal to "
                                "the xz plane"
                            )
                        ),
                    )
                )
                continue
            crit = hold_margin(st.mech, g, getattr(effects, "density", 1.0), drive=drive)
            sc = list(speeds) if speeds is not None else [speed * f for f in (1.0, 2.0, 4.0, 8.0)]
            lift, runs = liftoff_speed(st.mech, g, sc, drive=drive)
            r0 = runs[0]
            out.liftoff[label] = {
                "predicted_speed": crit,
                "scanned": sc,
                "liftoff_speed": lift,
                "resolution": None if lift is None else liftoff_resolution(sc, lift),
                "sample": runs[-1].liftoff,
                "pose_error": r0.pose_error,
            }
            held = r0.liftoff is None
            agrees = r0.pose_error <= 1e-3
            out.stages.append(
                StageReport(
                    label,
                    pat,
                    agrees,
                    (
                        (
                            ""
                            if agrees
                            else f"#8: the one-sided run strays {r0.pose_error:.2g} of the size from the analytic "
                            "motion (not accepted); "
                        )
                        + f"#8 one-sided contact: {'holds' if held else 'lets go'} at {speed:g} cycles/s "
                        f"(pose error {r0.pose_error:.2g} of the size); lift-off "
                        + (
                            f"at {format_speed(lift, res)} cycles/s (measured to {res:.2g}), sample {runs[-1].liftoff}"
                            if lift is not None and (res := liftoff_resolution(sc, lift)) > 0
                            else "not seen in the scan"
                        )
                        + f"; inverse dynamics predicts {crit:.3g} cycles/s"
                    ),
                )
            )
        elif st.mech.spatial:
            out.stages.append(_skew_report(st, toy, drive, effects, g3, speed, np.asarray(t, float), out))
        else:
            out.stages.append(StageReport(label, pat, True, "in the motor's plane (coupled)"))
    return out


def _skew_report(
    st: Any, toy: Any, drive: StageDrive, effects: Any, g3: tuple[float, float], speed: float, t: Array, out: ToyPhysics
) -> StageReport:
    """#6/#9 in :func:`simulate_toy`: the rebuild alone (pymunk, with gravity) and whether the edge holds the pin."""
    from planar.analysis.dynamics import plane_gravity

    label, pat, mech = st.label, st.realisation.pattern, st.mech
    j = next(j for j in mech.joints if isinstance(j, SkewContact))
    sprung = [f"{s.a}-{s.b}" for s in getattr(effects, "springs", ()) or () if mech.part(j.b).name in (s.a, s.b)]
    if sprung:
        return StageReport(
            label,
            pat,
            False,
            f"#{st.realisation.number}: a spring on the yz follower ({sprung[0]}) is not modelled in its hold check",
        )
    gp = plane_gravity("yz", g3)
    g = (float(gp[0]), float(gp[1]))
    per = max(int(round(1.0 / (speed * float(t[1] - t[0])))), 4) if t.size > 1 else 72
    dens = float(getattr(effects, "density", 1.0) or 1.0)
    hold = skew_hold(mech, g, speed, dens, per, drive)
    rec: list[tuple[float, float]] = []
    err, why = skew_stage(mech, speed, drive=drive, gravity=g, record=rec, density=dens)
    tr, mr = np.array(rec, float).T if rec else (np.zeros(0), np.zeros(0))
    keep = tr > tr[0] + 1.0 / (72 * speed) if tr.size else tr > 0  # its first sample interval: a start transient
    tr, mr = tr[keep], mr[keep]
    # pymunk's contact moment against the side the edge can push (the push sign at the nearest sample)
    pk = hold.push[np.clip(np.rint(tr * speed * per).astype(int), 0, per - 1)] if tr.size else np.zeros(0)
    pulls = np.flatnonzero(pk * mr < -1e-6 * max(float(np.abs(mr).max(initial=0.0)), 1e-300))
    sim_t = float(tr[pulls[0]]) if pulls.size else None
    held = hold.letgo is None
    out.skew[label] = {
        "holds": held,
        "sample": hold.letgo,
        "time": None if held else float(hold.t[hold.letgo]),
        "critical_speed": hold.critical_speed,
        "gravity_yz": list(g),
        "moment_range": [float(hold.moment.min()), float(hold.moment.max())],
        "push_sign": float(hold.push[0]) if np.all(hold.push == hold.push[0]) else 0.0,
        "pymunk_pull_time": sim_t,
    }
    crit = hold.critical_speed
    hold_txt = (
        f"#{st.realisation.number} edge on the pin (it can only push): {'holds' if held else 'lets go'} at "
        f"{speed:g} cycles/s"
        + ("" if held else f" (first at sample {hold.letgo}, t = {hold.t[hold.letgo]:.4g} s)")
        + "; inverse dynamics: lets go "
        + ("at any speed" if crit == 0.0 else "never" if math.isinf(crit) else f"above {crit:.3g} cycles/s")
        + f" (gravity in its plane ({g[0]:g}, {g[1]:g}))"
        + ("; the rebuild (pymunk, two-sided) pulls first at " + (f"t = {sim_t:.4g} s" if sim_t is not None else "no step"))
    )
    if why is not None:
        return StageReport(label, pat, False, why + "; " + hold_txt)
    return StageReport(
        label,
        pat,
        True,
        (
            f"in the motor run, co-simulated in its plane (yz); alone, rebuilt in the follower's plane: "
            f"{err:.2g} of the size; " + hold_txt
        ),
    )


_register()
