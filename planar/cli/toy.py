"""``planar toy SCENE``: a wind-up toy as one assembly, simulated coupled with its motor torque checked.

Prints the pieces (merged parts, one frame, keyed cams) and the worst joint
residual on them, the motor torque of the coupled run against inverse
dynamics, and every stage's fate (simulated, or why not; #8's lift-off).
Exit status 3 when a check fails (joint residual, torque beyond
``--torque-threshold`` of its torque scale, a simulation failure, #8 letting go at
the scene's speed, a #6/#9 edge that would have to pull its pin at the
scene's speed); 2 for bad input.
"""

from __future__ import annotations

import argparse
import json
import math
from typing import Any

EXIT_MISMATCH = 3


def _key_text(cam: str, angle: float, turn: float) -> str:
    """A cam's key angle (rad) in degrees, split into the cam's phase and its stage's own turn when it has one."""
    own = round(math.degrees(turn)) % 360
    if not own:
        return f"{cam} {math.degrees(angle) % 360:.0f} deg"
    return (
        f"{cam} {math.degrees(angle) % 360:.0f} deg (cam phase {math.degrees(angle - turn) % 360:.0f} + "
        f"the stage's own turn {own})"
    )


#: the fastest speed ``--speeds`` takes, cycles/s (a wind-up toy turns about once a second)
MAX_SPEED = 1000.0


def _speeds(text: str) -> list[float]:
    from planar.errors import InputError

    try:  # every item a number: an empty list or item ("", "1,,2") is a typo, not a default
        out = [float(v) for v in text.split(",")]
    except ValueError:
        raise InputError("--speeds", text, "comma-separated speeds in cycles per second, e.g. 0.5,1,2") from None
    if any(not (math.isfinite(v) and 0 < v <= MAX_SPEED) for v in out):
        raise InputError("--speeds", text, f"speeds greater than 0 and at most {MAX_SPEED:g} cycles per second, e.g. 0.5,1,2")
    return sorted(out)


def _cmd_toy(args: argparse.Namespace) -> int:
    from planar.errors import InputError
    from planar.physics.toy import simulate_toy
    from planar.scene.load import load_scene
    from planar.toys.assembly import assembly_residual, toy_assembly
    from planar.windup.chain import ToyMechanism

    if not (0 < args.torque_threshold < 1):
        raise InputError("--torque-threshold", args.torque_threshold, "a fraction between 0 and 1")
    speeds = _speeds(args.speeds) if args.speeds is not None else None
    scene = load_scene(args.scene)
    toy = scene.mechanism
    if not isinstance(toy, ToyMechanism):
        raise InputError(f"{args.scene}: mechanism.type", scene.spec.mechanism.type, 'a toy scene (type = "toy")')
    asm = toy_assembly(toy)
    res = assembly_residual(asm)
    worst = max(res.values(), default=0.0) / asm.size
    # the run solves its own motion: only the times here, so its memory check comes before any sample is solved
    phys = simulate_toy(toy, scene.times(), scene.effects, speeds=speeds)
    tq = phys.torque
    ok_joints = worst <= 1e-9
    ok_torque = tq["failure"] is None and tq["max_rel_diff"] <= args.torque_threshold
    speed = toy.driver.rate / (2 * math.pi)
    lets_go = [k for k, v in phys.liftoff.items() if v["liftoff_speed"] is not None and v["liftoff_speed"] <= speed]
    skew_go = [k for k, v in phys.skew.items() if not v["holds"]]
    lets_go += skew_go
    # a stage left out of the physics leaves its load out of the motor torque: the toy's check fails
    unsimulated = [s.stage for s in phys.stages if not s.simulated]
    ok = ok_joints and ok_torque and not lets_go and not unsimulated
    report: dict[str, Any] = {
        "toy": toy.name,
        "pieces": {p.name: p.plane for p in asm.parts},
        "bodies": asm.bodies,
        "keyed": {k: math.degrees(v) for k, v in asm.keyed.items()},
        "key_turn": {k: math.degrees(v) for k, v in getattr(asm, "key_turn", {}).items()},
        "worst_joint_residual": worst,
        "torque": {k: tq[k] for k in ("peak", "max_rel_diff", "samples_compared", "failure", "pose_error", "pieces")},
        "stages": [{"stage": s.stage, "pattern": s.pattern, "simulated": s.simulated, "detail": s.detail} for s in phys.stages],
        "liftoff": phys.liftoff,
        "skew_hold": phys.skew,
        "notes": asm.notes,
        "not_simulated": unsimulated,
        "ok": ok,
    }
    if args.json:
        print(json.dumps(report, indent=2, sort_keys=True, default=float))
    else:
        planes: dict[str, int] = {}
        for p in asm.parts:
            planes[p.plane] = planes.get(p.plane, 0) + 1
        print(
            f"{toy.name}: {len(asm.parts)} pieces ({', '.join(f'{k} {v}' for k, v in planes.items())}), "
            f"{len(asm.bodies)} rigid bodies; cams keyed at "
            + ", ".join(_key_text(k, v, getattr(asm, "key_turn", {}).get(k, 0.0)) for k, v in asm.keyed.items())
            + f"; worst joint residual on the merged pieces {worst:.2g} of the size "
            + ("[ok]" if ok_joints else "[FAIL]")
        )
        fail = f"; {tq['failure']}" if tq["failure"] else ""
        out_of_run = sorted({p.name for p in asm.parts} - set(tq["pieces"]))
        print(
            f"motor on the cam shaft, the only driver, turning {len(tq['pieces'])} pieces"
            + (f" (not {', '.join(out_of_run)})" if out_of_run else "")
            + f": torque peak {tq['peak']:.4g} (model units: density x unit^4/s^2; see README, Conventions)"
            + f", pymunk vs inverse dynamics {tq['max_rel_diff']:.2g} of the torque scale "
            f"over {tq['samples_compared']} samples, pose error {tq['pose_error']:.2g} of the size{fail} "
            + ("[ok]" if ok_torque else "[FAIL]")
        )
        for s in phys.stages:
            print(f"  {s.stage} {s.pattern}: {'simulated' if s.simulated else 'NOT simulated [FAIL]'}: {s.detail}")
        for k in lets_go:
            if k in phys.skew:
                v = phys.skew[k]
                c = v["critical_speed"]
                print(
                    f"  {k}: the edge lets the pin go at the scene's speed ({speed:g} cycles/s): it would have to "
                    f"pull from sample {v['sample']} (t = {v['time']:.4g} s); "
                    + (
                        "nothing holds the pin on it at any speed (no gravity or spring in its plane pushes it there)"
                        if c == 0.0
                        else f"it holds only below {c:.3g} cycles/s"
                    )
                    + " [FAIL]"
                )
            else:
                print(f"  {k}: lets go at the scene's speed ({speed:g} cycles/s) [FAIL]")
    return 0 if ok else EXIT_MISMATCH


def add_parser(sub: Any) -> None:
    """Register ``planar toy``."""
    t = sub.add_parser("toy", help="a wind-up toy as one assembly: pieces, coupled motor torque, every stage's physics")
    t.add_argument("scene", help='toy scene file (TOML, mechanism type = "toy")')
    t.add_argument("--json", action="store_true", help="print a JSON object")
    t.add_argument(
        "--torque-threshold",
        type=float,
        default=0.01,
        help="motor torque vs inverse dynamics, fraction of the torque scale (at least its peak; 0.01); exit status 3 beyond it",
    )
    t.add_argument(
        "--speeds",
        default=None,
        help="speeds (cycles/s, comma-separated) to scan #8 stages for lift-off (default: 1, 2, 4, 8 times the scene's)",
    )
    t.set_defaults(func=_cmd_toy)
