"""``planar design REQUEST.toml -o toy.toml``: a wind-up toy from requested end-effector motions.

Enumerates chains, merges them into trees, ranks by the paper's cost, sizes
the cheapest tree that works and writes it as a toy scene (renders
assembled, simulates with ``planar toy``, exports).  Prints the tree, its
cost, each effector's requested and measured range, the layers and any
same-layer collision.  Exit status 2 for bad input or an unreachable request
(one line naming the effector and what its chains reach; nothing written);
3 when the written toy fails its own check (a range off by more than 1 %, a
same-layer collision, a pin through a piece, an export that refuses it, a
motor torque off inverse dynamics by more than 1 %, a #8 tab letting go, a
stage the physics did not simulate, or a cam throw or effector stroke under 3
times the fit's play (:mod:`planar.toys.fitcheck`): each named with its reason).
"""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path
from typing import Any

EXIT_MISMATCH = 3


def _cmd_design(args: argparse.Namespace) -> int:
    import tomllib

    from planar.errors import InputError
    from planar.fileio import check_output
    from planar.synth.design import TOLERANCE, design_scene, design_toy, load_request, physics_check

    check_output("-o/--output", args.output, (".toml",), (args.request,))  # before any work, as every command
    from planar.core.limits import check_count

    if args.max_length < 1:
        raise InputError("--max-length", args.max_length, "a chain length of at least 1")
    check_count("chain", "--max-length", args.max_length, "stages in a chain")
    effectors = load_request(args.request)
    from planar.fileio import read_text

    name = tomllib.loads(read_text(args.request, "request file (TOML)")).get("name") or Path(args.request).stem
    import re

    from planar.scene.messages import NAME_PATTERN as _NAME

    if not isinstance(name, str) or not re.match(_NAME, name) or len(name) > 80:
        raise InputError(
            f"{args.request}: name", name, "a string of at most 80 characters without commas, double quotes or control characters"
        )
    d = design_toy(effectors, name=name, max_length=args.max_length, source=str(args.request))
    scene = design_scene(d.toy, name)
    scene.save(args.output)
    # the toy as it will run (as `planar toy` checks it): the design has run it unless the tree failed before
    phys = d.physics if d.physics is not None else physics_check(scene)
    rep = d.report()
    rep["physics"] = phys
    rep["output"] = str(args.output)
    bad = [e for e in rep["effectors"] if e["error"] > TOLERANCE]
    # a motion the cut parts will not make (a cam throw or effector stroke lost in the fit's play) fails too
    from planar.fabrication.parts import FabSettings
    from planar.toys.fitcheck import small_motion_text, small_motions

    fab = FabSettings.from_spec(scene.spec.fabrication, None, None)
    small = small_motions(d.toy, fab)
    rep["small_motions"] = [dict(m, text=small_motion_text(m, fab)) for m in small]
    ok = not bad and not d.collisions and not d.clashes and phys["ok"] and not small
    rep["ok"] = ok
    if args.json:
        print(json.dumps(rep, indent=2, sort_keys=True, default=float))
    else:
        print("\n".join(summary_lines(d, rep, phys, name, str(args.output))))
    return 0 if ok else EXIT_MISMATCH


def summary_lines(d: Any, rep: dict[str, Any], phys: dict[str, Any], name: str, output: str) -> list[str]:
    """The text ``planar design`` prints for design ``d`` (its report ``rep``, the physics verdict ``phys``)."""
    from planar.synth.design import TOLERANCE, TORQUE_TOLERANCE, physics_failures

    failures = physics_failures(phys)
    out: list[str] = []
    trees = "; ".join(f"{cam}: " + ", ".join(" ".join(c) for c in chains) for cam, chains in rep["cams"].items())
    lead = f"; right cam {math.degrees(d.toy.phase):.0f} deg ahead" if len(d.toy.cams) == 2 else ""
    out.append(
        f"{name}: cost {d.cost:g} ({d.toy.mechanism_count} mechanisms), {trees}{lead}; {d.tried} of {d.candidates} trees sized"
    )
    for k, r in enumerate(d.rejected):
        if k == 0 and d.fallback:
            out.append(f"  written although it failed a check (no tree tried passed; the cheapest): {r}")
        else:
            out.append(f"  passed over (it failed a check): {r}")
    if d.variant:
        out.append(f"  written: the tree as sized with {d.variant} (the same motion)")
    for e in rep["effectors"]:
        unit = "deg" if e["motion"][0] == "O" else "units"
        flag = "[ok]" if e["error"] <= TOLERANCE else "[FAIL]"
        out.append(
            f"  {e['name']} ({e['motion']}, {e['cam']} cam): requested {e['requested']:g} {unit}, "
            f"measured {e['achieved']:.6g} {unit} ({100 * e['error']:.2g} %) {flag}; "
            f"{e['sized']['stage']}: {e['sized']['parameter']} = {e['sized']['value']:.6g}"
        )
    n_layers = len(set(d.layers.values()))
    pl = d.placement
    b = d.before
    if pl is not None and pl.variables:
        if b["export_refused"]:
            out.append(f"  before placement: {d.before_reason}")
        else:
            out.append(
                f"  before placement: {b['layers']} layers, {b['collisions']} same-layer collisions, "
                f"{b['pin_clashes']} pins through pieces"
            )
        if pl.kept:
            out.append(
                f"  placement ({', '.join(pl.variables)}; {pl.evaluations} layouts annealed, "
                f"{pl.checked} checked against the export): footprint {pl.footprint[0]:.3g} -> "
                f"{pl.footprint[1]:.3g} units^2, overlap of unjoined pieces {pl.overlap[0]:.3g} -> "
                f"{pl.overlap[1]:.3g}"
            )
        elif pl.checked:
            out.append(
                f"  placement ({', '.join(pl.variables)}; {pl.evaluations} layouts annealed): none of the "
                f"{pl.checked} best kept (each added a collision, pin clash or layer); the start kept"
            )
        else:
            out.append(
                f"  placement ({', '.join(pl.variables)}; {pl.evaluations} layouts annealed): no layout "
                "improved on the start; the start kept"
            )
    else:
        out.append("  placement: no stage of this tree can move without changing a motion")
    if d.export_refused:
        why = d.export_refused.removeprefix("the export refuses it: ")
        out.append(f"  export: it refuses the pieces [FAIL]: {why} (no layer plan, so no collision or pin check)")
    else:
        out.append(
            f"  {len(d.layers)} pieces in {n_layers} layers (the export's plan); same-layer collisions over "
            f"24 poses: {len(d.collisions)}, pins through pieces: {len(d.clashes)} "
            + (
                "[ok]"
                if not (d.collisions or d.clashes)
                else "[FAIL] " + ", ".join([f"{a}/{b} {ov:.3g} mm^2" for a, b, ov in d.collisions] + d.clashes)
            )
        )
    tq = phys["torque_rel_diff"]
    if tq is None:
        out.append("  physics (as planar toy): not run [FAIL]")
    else:
        tq_ok = tq <= TORQUE_TOLERANCE  # a failure of another kind is its own [FAIL] line below
        out.append(
            f"  physics (as planar toy): motor torque vs inverse dynamics {tq:.2g} of the peak "
            f"(limit {TORQUE_TOLERANCE:g}) " + ("[ok]" if tq_ok else "[FAIL]")
        )
    for why in failures:
        out.append(f"    [FAIL] {why}")
    if d.gravity_x:
        out.append(
            f"  gravity along +x in the written toy (it holds the tab of #8 stage {', '.join(d.gravity_x)} on "
            "its face): stand the real toy with the drawing's +x axis pointing down"
        )
    if d.gravity_y:
        out.append(
            f"  gravity along -y in the written toy (it holds the pin of #6/#9 stage {', '.join(d.gravity_y)} on "
            "its driver's edge): tilt the real toy so that the drawing's -y axis points down"
            + (" as well (+x and -y at 45 degrees)" if d.gravity_x else "")
        )
    for m in rep.get("small_motions", []):
        out.append(f"  [FAIL] {m['text']}")
    out.append(f"  wrote {output} ({sum(d.seconds.values()):.2f} s)")
    return out


def add_parser(sub: Any) -> None:
    """Register ``planar design``."""
    d = sub.add_parser(
        "design",
        help="a wind-up toy from requested end-effector motions (writes a toy scene)",
        description="Design a wind-up toy from a request file of [[effector]] tables (name, motion "
        "Ox Oy Oz Tx Ty Tz OzT, range in degrees for O/OzT or model units for T, "
        "optional cam left/right and phase in cycles, 0 <= phase < 1: a quarter turn is "
        "0.25). Exit status 2 for bad input or a range no buildable chain reaches "
        "(one line naming the file, effector and value; nothing written); 3 when the toy "
        "written fails a check (a range off by more than 1 %, a same-layer collision, a "
        "pin through a piece, the export refusing it, its physics: motor torque, a #8 "
        "tab letting go, a stage not simulated; or a cam throw or effector stroke under "
        "3 times the fit's play, which the cut parts will not make), each failure named.",
    )
    d.add_argument("request", help="request file (TOML, [[effector]] tables)")
    d.add_argument("-o", "--output", required=True, help="toy scene file to write (TOML)")
    d.add_argument("--json", action="store_true", help="print a JSON report")
    d.add_argument("--max-length", type=int, default=3, help="longest chain considered (default 3)")
    d.set_defaults(func=_cmd_design)
