"""``planar synth path|function|motion``: a four-bar from target points, angle pairs or poses, as a scene.

Exit status 0 when the design passes its own checks (solved again by
planar's solver), 3 when it was written but fails one (the failing check is
printed), 2 on bad input (one line, nothing written).  ``path`` and
``function`` exit 3 writing nothing, with the reason, when no valid design
(one that keeps the constraints) is found.
"""

from __future__ import annotations

import argparse
import json
import math
from typing import TYPE_CHECKING, Any

from planar.errors import InputError

if TYPE_CHECKING:
    import numpy as np

__all__ = ["add_parser"]

#: exit status of a design written that fails its own check (as ``planar compare``)
EXIT_CHECK = 3


def _region(text: str | None) -> tuple[float, float, float, float] | None:
    if text is None:
        return None
    try:
        x0, y0, x1, y1 = (float(v) for v in text.split(","))
    except ValueError:
        raise InputError("--pivots", text, "XMIN,YMIN,XMAX,YMAX (four numbers)") from None
    if not (x0 < x1 and y0 < y1) or not all(math.isfinite(v) for v in (x0, y0, x1, y1)):
        raise InputError("--pivots", text, "a region with XMIN < XMAX and YMIN < YMAX")
    return x0, y0, x1, y1


def grashof_words(kind: str) -> str:
    """A four-bar's Grashof class (:func:`planar.linkages.fourbar.grashof_class`) as the printed line says it: the
    non-Grashof kind is named for what it is, a triple-rocker (a trial's point: the others name their motion)."""
    return "triple-rocker, non-Grashof" if kind == "non-Grashof" else kind


def _rocking(fb: Any, theta: np.ndarray) -> tuple[float | None, float]:
    """``(amplitude, centre)`` of a rocking driver over the crank angles ``theta``, or ``(None, 0)`` for a full turn."""
    import numpy as np

    if fb.grashof in ("crank-rocker", "double-crank"):
        return None, 0.0
    t = theta[0] + (np.asarray(theta) - theta[0] + np.pi) % (2 * np.pi) - np.pi
    lo, hi = float(t.min()), float(t.max())
    return max(0.5 * (hi - lo), 1e-6), 0.5 * (hi + lo)


def _check_output(args: argparse.Namespace, source: str) -> None:
    """The scene to write, checked before the search: a .toml file in an existing folder, not the input."""
    from planar.fileio import check_output

    check_output("-o/--output", args.output, (".toml",), (source,))


def _finish(args: argparse.Namespace, what: str, text: str, report: dict[str, Any], ok: bool, failing: list[str]) -> int:
    from planar.synth.scene_out import write_scene

    scene = write_scene(args.output, text)
    mo = scene.motion()
    report["scene_valid_samples"] = int(mo.valid.sum())
    report["scene_samples"] = len(mo)
    if not mo.valid.all():
        ok = False
        failing.append(f"the written scene's motion has {int((~mo.valid).sum())} invalid samples")
    report["ok"] = ok
    if not ok:  # what failed, as the text output's "check failed" lines
        report["reason"] = "; ".join(failing) or "a check failed (see checks)"
    report["output"] = str(args.output)
    notes = []
    if "[fabrication]" not in text:  # a trial's CSV in millimetres would have been cut ten times too large
        from planar.scene.schema import FabricationSpec

        mm = FabricationSpec.model_fields["unit_mm"].default
        notes.append(
            f"no --unit-mm: the scene is cut at planar's default of {mm:g} mm a unit (--unit-mm N says what "
            "one unit of your numbers is in millimetres, e.g. --unit-mm 1 for millimetres)"
        )
    report["notes"] = notes  # with --json too (a re-trial found the note in neither the JSON nor the text)
    if args.json:
        print(json.dumps(report, indent=2, default=float))
    else:
        print(f"wrote {args.output}: {what}")
        for f in failing:
            print(f"check failed: {f}")
        for c in report.get("checks", {}).get("cautions", []):
            print(f"caution: {c}")
        for n in notes:
            print(f"note: {n}")
    return 0 if ok else EXIT_CHECK


def _path_failing(
    d: Any,
    kind: str = "four-bar",
    box: str = "",
    budget: str = "normal",
    max_ratio: float = math.inf,
    asked: tuple[str, ...] = (),
) -> list[str]:
    """One line per failed check of a path design, naming what failed and by how much (``kind`` and ``box``:
    as :func:`_unreachable`'s; ``max_ratio``: ``--max-ratio``, named when a missing four-bar sits at it; ``asked``:
    the options given that keep four-bars out of the search, named beside the noise as a reason for a near miss)."""
    out: list[str] = []
    for k, v in d.checks.items():
        if not k.startswith("ok_") or v:
            continue
        if k == "ok_constraints":
            out += d.checks["constraint_failures"]
        elif k == "ok_accuracy":
            out.append(
                f"largest distance to a target {d.checks['max_error']:.3g} of their size (RMS distance from "
                f"their centroid, {d.checks['size']:.6g}), over --tolerance {d.checks['tolerance']:g} "
                f"(RMS distance {d.checks['rms_error']:.3g} of the size, sse {d.sse:.6g})"
            )
            if d.checks["max_error"] > FAR_OFF * d.checks["tolerance"]:
                out.append(_unreachable(d, kind, box, budget))
            elif d.checks["rms_error"] <= NOISE_RMS:  # a near miss: the likeliest reason in the same line
                out[-1] += (
                    f"; points measured with noise, or a shape drawn by hand, depart from every {kind}'s curve a little: "
                    "misses like these "
                    f"(RMS {d.checks['rms_error']:.2g} of the size) may be the noise, and a --tolerance a few times it "
                    "accepts the fit"
                )
                if asked:
                    out[-1] += f"; or {' and '.join(asked)} keep the nearer {kind}s out: without them it may come closer"
            out[-1] += _ratio_limit(d, max_ratio)
        elif k == "ok_transmission":
            c = d.checks
            where = f"at crank angle {math.degrees(c['min_transmission_at_rad']):.4g} deg from the ground line"
            out.append(_transmission_word(c["min_transmission_deg"], where, c["transmission_limit_deg"]))
        elif k == "ok_order":
            out.append("the branch does not pass the targets in their order (--ordered)")
        elif k == "ok_follows_drawing":
            out.append(_stray_word(d.checks["drawing_stray"]))
        elif k == "ok_valid_over_turn" and d.checks.get("failures"):
            out += d.checks["failures"]
        else:
            out.append(k[3:].replace("_", " "))
    return out


def _stray_word(stray: float) -> str:
    """A failed drawing check in words: how far (``stray``, over the targets' size) the coupler path and the drawing
    part between the targets, against the limit (:data:`planar.synth.drawing.DETOUR`), and what to do."""
    from planar.synth.drawing import DETOUR

    return (
        f"the coupler path does not trace the drawing: between the targets the two stray up to {stray:.3g} of the "
        f"targets' size apart (limit {DETOUR:g}; the check at the targets does not see between them): more --points "
        "hold the search to more of the drawing, and planar render shows the path"
    )


def _ratio_limit(d: Any, max_ratio: float) -> str:
    """Words to add to a missed accuracy check when four-bar design ``d`` has its longest link within 1 % of
    ``max_ratio`` times its shortest (``--max-ratio``): the search stopped against that limit, which explains its
    tiny link (a trial's 9 drawn points came back 0.004 of the size off at a ratio of 9.98, nothing saying why);
    else empty."""
    links = [abs(float(getattr(d, k, math.nan))) for k in ("ground", "crank", "coupler", "rocker")]
    if not all(math.isfinite(v) and v > 0 for v in links) or not math.isfinite(max_ratio):
        return ""
    ratio = max(links) / min(links)
    if ratio < 0.99 * max_ratio:
        return ""
    return (
        f". The best found stops against the link-ratio limit: its longest link is {ratio:.3g} times its shortest "
        f"(--max-ratio {max_ratio:g}); a larger --max-ratio lets the search look beyond it, not always closer"
    )


def _transmission_word(deg: float, where: str, asked: float) -> str:
    """A failed transmission check in words: the smallest angle ``deg`` (deg from a toggle), ``where`` it falls
    (e.g. ``"at crank angle 1.2 rad from the ground line"``), the limit (``--min-transmission`` ``asked``, deg, or
    the 1 deg floor) and what it means: a near-toggle under the floor, else a rocker driven poorly."""
    from planar.synth.path import TOGGLE_FLOOR_DEG

    limit = f"limit {asked:g} deg, --min-transmission" if asked > TOGGLE_FLOOR_DEG else f"the floor, {TOGGLE_FLOOR_DEG:g} deg"
    head = f"the transmission angle falls to {deg:.4g} deg from a toggle {where} ({limit})"
    if deg < TOGGLE_FLOOR_DEG:
        return head + (
            ": coupler and rocker fold nearly flat there, so the coupler point moves far for a small crank step "
            "and the linkage may lock or flip"
        )
    return head + ": the coupler pushes the rocker mostly along its length there, so it drives it poorly (stiff, loads the pins)"


#: a best design whose RMS distance is at most this (a fraction of the targets' size) may be off by measurement noise
NOISE_RMS = 0.05

#: a best design more than this many times the tolerance off is reported as no four-bar tracing the curve
FAR_OFF = 10.0


def _sharpest_turn(t: np.ndarray) -> tuple[float, int]:
    """``(degrees, target)``: the largest turn of the targets' polyline at one target (1-based), closing it
    when its last target is about as near its first as its neighbours are; 0 when no turn stands out (at
    least twice its neighbours' turns: a smooth curve sampled coarsely turns alike at neighbouring targets)."""
    import numpy as np

    seg = np.diff(t, axis=0)
    gap = np.hypot(*(t[0] - t[-1]))
    closed = len(t) > 3 and gap <= 2 * float(np.median(np.hypot(*seg.T)))
    if closed:
        seg = np.vstack([seg, t[:1] - t[-1:]])
    a = np.arctan2(seg[:, 1], seg[:, 0])
    turn = np.abs((np.diff(np.append(a, a[0]) if closed else a) + np.pi) % (2 * np.pi) - np.pi)
    k = int(np.argmax(turn))
    near = [turn[i % len(turn)] for i in (k - 1, k + 1) if closed or 0 <= i < len(turn)]
    if turn[k] < 2 * max(near, default=0.0):
        return 0.0, 0
    return float(np.degrees(turn[k])), (k + 1) % len(t) + 1


def _rad(x: float, deg: bool) -> str:
    """An angle (rad) as the report prints it: in radians (``--tolerance``'s unit), with degrees beside when the
    pairs were given in degrees (``--deg``)."""
    return f"{x:.3g} rad ({math.degrees(x):.3g} deg)" if deg else f"{x:.3g} rad"


def _unreachable(d: Any, kind: str = "four-bar", box: str = "", budget: str = "normal") -> str:
    """The plain word for a best design far beyond the tolerance: nothing of ``kind`` found traces the curve,
    and the likely reasons (a sharp corner; the ``--pivots`` box, ``box`` saying how the unboxed atlas does)."""
    deg, at = _sharpest_turn(d.targets)
    if deg >= 60:
        why = (
            f"the targets turn by {deg:.0f} deg at target {at}: a sharp corner, or a tight bend with few targets on it, "
            "and a coupler curve is smooth: it rounds corners (round them in the drawing, sample a bend with more "
            "--points, or accept a larger --tolerance)"
        )
    elif box:
        why = box
    else:
        more = ", --type sixbar" if kind == "four-bar" else ""
        thorough = "" if budget == "thorough" else "--budget thorough, "
        rms = d.checks.get("rms_error", math.inf)
        noise = (
            f"points measured with noise, or a shape drawn by hand, depart from every {kind}'s curve a little (if that is "
            f"why, the RMS distance, {rms:.2g} of the size, is about that departure: a --tolerance a few times it accepts "
            "the fit); or "
            if rms <= NOISE_RMS
            else ""
        )
        why = (
            f"{noise}it may be a shape no {kind} traces, or one the search missed (try {thorough}another "
            f"--seed{more}, or a larger --tolerance)"
        )
        n = len(d.targets)
        if kind == "four-bar" and getattr(d, "timed", False) and n >= 5:
            why += (
                f". {n} targets at given crank angles are {2 * n} equations and a four-bar has 9 dimensions: beyond 4 "
                "such targets, only points of one four-bar's curve at those very angles are met exactly (drop the "
                "theta column to let the angles free)"
            )
    return (
        f"no {kind} found traces this curve within --tolerance {d.checks['tolerance']:g}: the best found is "
        f"{d.checks['max_error']:.3g} of the targets' size off at target {d.checks['worst_target']} "
        f"({d.checks['max_error'] / d.checks['tolerance']:.0f} times the tolerance). Likely why: {why}"
    )


def _angles_comment(d: Any) -> str:
    """The scene comment listing the input angle at each target (rad from the ground line, full precision): on a
    rocking input's swing, as the swing's own angles (the line printed gives the swing in the same terms; "input
    angle", as the input does not turn as a crank), else in ``[0, 2 pi)`` ("crank angle")."""
    import numpy as np

    theta = np.asarray(d.theta, float)
    where, word = "in [0, 2 pi)", "crank"
    if "input_swing_rad" in d.checks:
        from planar.synth.arcs import on_swing

        lo, hi = d.checks["input_swing_rad"]
        theta = on_swing(theta, (lo, hi))
        where, word = f"on the input's swing, {lo!r} to {hi!r}", "input"
    return f"{word} angle at each target (rad from the ground line, {where}): " + ", ".join(repr(float(t)) for t in theta)


def _unusable(d: Any, kind: str, region: bool, rocking: bool = False) -> str | None:
    """Why a design is no valid linkage at all (a constraint broken, or it misses a target's crank angle; with
    ``rocking``, the rocking search's own words for finding none: what it asked of every four-bar)."""
    if d.checks.get("constraint_failures"):
        what = f"no {kind} keeping the constraints" + (" (every ground pivot in the --pivots box)" if region else "")
        return f"{what} reaches the targets; the best found: " + "; ".join(d.checks["constraint_failures"])
    if not math.isfinite(d.sse):
        if rocking and d.checks.get("error"):
            return str(d.checks["error"])
        return f"no {kind} found that can be assembled at every target's crank angle" + (
            f" ({d.checks['error']})" if d.checks.get("error") else ""
        )
    return None


def _closed_svg(target: str) -> bool:
    """Whether the targets are a closed SVG shape (:func:`planar.synth.targets.svg_closed`): a rocking input traces
    it only as an arc, back and forth, so only inputs that turn fully are searched."""
    from planar.synth.targets import svg_closed

    return str(target).lower().endswith(".svg") and svg_closed(target)


def _cmd_path(args: argparse.Namespace) -> int:
    import numpy as np

    _check_output(args, args.target)
    from planar.synth.path import synthesise_path
    from planar.synth.scene_out import fourbar_scene_text
    from planar.synth.search import Constraints
    from planar.synth.targets import check_theta, normalisation, read_path_targets, target_unit_mm

    if not (args.max_ratio > 1 and math.isfinite(args.max_ratio)):
        raise InputError("--max-ratio", args.max_ratio, "a finite ratio greater than 1")
    if not 0 <= args.seed < 2**32:
        raise InputError("--seed", args.seed, "a seed from 0 to 2**32 - 1")
    if not (args.tolerance > 0 and math.isfinite(args.tolerance)):
        raise InputError("--tolerance", args.tolerance, "a positive fraction of the targets' size")
    min_transmission = _min_transmission_rad(args)
    _unit_mm(args)  # refused before the search, not after it
    if args.topology is not None and args.type != "sixbar":
        raise InputError("--topology", args.topology, "--topology only with --type sixbar")
    if args.rocking and args.type == "sixbar":  # the six-bar search has no rocking input: refused, not dropped
        raise InputError("--rocking", True, "--type fourbar (the rocking search finds four-bars only)")
    if args.input_rocks and not args.rocking:
        raise InputError("--input-rocks", True, "--rocking with it (it asks the rocking search for a rocking input link)")
    if args.points is not None and not 3 <= args.points <= MAX_TARGETS:
        raise InputError("--points", args.points, f"3 to {MAX_TARGETS} points sampled along the SVG (a path is matched at each)")
    targets, theta = read_path_targets(args.target, args.points)
    if len(targets) > MAX_TARGETS:
        raise InputError(
            args.target,
            f"{len(targets)} targets",
            f"at most {MAX_TARGETS} targets (a path is matched at each; thin the file or use --points for an SVG)",
        )
    normalisation(targets, str(args.target))
    if theta is not None:
        if args.deg:
            theta = np.radians(theta)
        check_theta(theta, str(args.target), args.deg)
    cons = Constraints(full_turn=True, max_ratio=args.max_ratio, region=_region(args.pivots))
    if args.type == "sixbar":
        return _sixbar(args, targets, theta, cons)
    atlas = None
    if args.atlas is not None:  # timed targets search the atlas too (it was ignored, and the cache built)
        from planar.synth.atlas import read_atlas

        atlas = read_atlas(args.atlas)
    if args.full_turn and args.rocking:
        raise InputError(
            "--full-turn",
            "given with --rocking",
            "one of them (--rocking asks for an input that rocks, --full-turn for one that turns fully)",
        )
    if args.rocking:
        d = _rocking_design(args, targets, theta, cons)
    else:
        d = synthesise_path(
            targets,
            theta,
            cons,
            budget=args.budget,
            seed=args.seed,
            tolerance=args.tolerance,
            atlas=atlas,
            ordered=args.ordered,
            min_transmission=min_transmission,
            full_turn=bool(args.full_turn or _closed_svg(args.target)),
        )
    if str(args.target).lower().endswith(".svg") and "error" not in d.checks:
        from planar.synth.drawing import BETWEEN_CAUTION, DETOUR, drawing_cautions, drawing_gaps, drawing_stray

        gaps = drawing_gaps(d, args.target)
        d.checks.update(gaps)
        rocks = d.checks.get("input") == "rocks"
        # the drawing itself, not a smooth curve through its sampled points, is what the path is measured against
        kept = [c for c in d.checks.get("cautions", []) if not c.startswith(BETWEEN_CAUTION)]
        d.checks["cautions"] = [*kept, *drawing_cautions(gaps, args.tolerance, rocks)]
        stray = drawing_stray(gaps, rocks)
        if stray is not None:  # the path should follow the drawing all along: far off it, the design fails
            d.checks["drawing_stray"] = stray
            d.checks["ok_follows_drawing"] = stray <= DETOUR

    def scene() -> tuple[str, str]:
        fb = d.fourbar()
        amp, centre = _rocking(fb, d.theta)
        if "input_swing_rad" in d.checks:  # a rocking input swings over its found range
            lo, hi = d.checks["input_swing_rad"]
            amp, centre = max(0.5 * (hi - lo), 1e-6), 0.5 * (hi + lo)
        text = fourbar_scene_text(
            "synth-path",
            d.ground,
            d.crank,
            d.coupler,
            d.rocker,
            d.coupler_point,
            d.circuit,
            d.placement,
            comments=[
                f"planar synth path {args.target}: {len(targets)} targets, {'timed' if d.timed else 'untimed'}, sse {d.sse:.6g}",
                _angles_comment(d),
            ],
            amplitude=amp,
            centre=centre,
            targets=targets.tolist(),
            unit_mm=_unit_mm(args, target_unit_mm(args.target)),
        )
        motion = d.checks.get("input", "rocks")
        if motion == "rocks" and fb.grashof in ("crank-rocker", "double-crank"):  # a cognate whose crank could turn
            motion = "rocks over the targets' span (its crank could turn fully)"
        return text, f"four-bar ({grashof_words(fb.grashof)}, {d.circuit}, the input {motion})"

    return _path_result(args, d, targets, "four-bar", lambda: _box_word(d, targets, cons, atlas, args), scene)


def _path_result(args: argparse.Namespace, d: Any, targets: np.ndarray, kind: str, box: Any, scene: Any) -> int:
    """The end of ``synth path`` for any design ``d`` of ``kind``: no design (nothing written, exit 3) when it is
    unusable, else its scene written (``scene()``: the text and the design in a few words) and reported, with
    each failed check (``box()``: what a ``--pivots`` box costs, in words)."""
    why = _unusable(d, kind, args.pivots is not None, bool(getattr(args, "rocking", False)))
    if why is not None:
        return _no_design(args, "synth path", {"targets": len(targets)}, why)
    asked = tuple(
        flag
        for flag, on in (
            ("--min-transmission", args.min_transmission > 0),
            ("--full-turn", bool(args.full_turn)),
            ("--pivots", args.pivots is not None),
        )
        if on
    )
    failing = _path_failing(d, kind, box(), args.budget, args.max_ratio, asked)
    text, what = scene()
    found = f"; found by {d.checks['found_by']}" if d.checks.get("found_by") else ""
    if "min_transmission_deg" in d.checks:  # a four-bar's (a six-bar's are in its checks)
        over = "swing" if d.checks.get("input") == "rocks" else "turn"
        what += f", transmission angle >= {d.checks['min_transmission_deg']:.4g} deg from a toggle over the {over}"
    report = {"command": "synth path", "targets": len(targets), "target_points": targets.tolist(), **d.to_dict()}
    return _finish_path(
        args,
        f"{what}, largest distance {d.checks['max_error']:.3g} of the targets' size (RMS {d.checks['rms_error']:.3g}) "
        f"over {len(targets)} targets, synthesised in {d.seconds:.2f} s (wall){found}",
        text,
        report,
        d.ok,
        failing,
    )


def _rocking_design(args: argparse.Namespace, targets: np.ndarray, theta: Any, cons: Any) -> Any:
    """``--rocking``: a four-bar whose input swings between two angles, from the rocking-arc atlas."""
    from planar.synth.path import synthesise_rocking_path

    if theta is not None:
        raise InputError("--rocking", str(args.target), "untimed targets (x, y only: the swing finds its own input angles)")
    if args.pivots is not None:
        raise InputError("--pivots", args.pivots, "no --pivots box with --rocking (the rocking search does not keep one)")
    return synthesise_rocking_path(
        targets,
        args.tolerance,
        args.ordered,
        cons.max_ratio,
        budget=args.budget,
        min_transmission=_min_transmission_rad(args),
        input_rocks=args.input_rocks,
    )


def _box_word(d: Any, targets: np.ndarray, cons: Any, atlas: Any, args: argparse.Namespace) -> str:
    """With a ``--pivots`` box and a design far off: how the atlas does without the box (one lookup), in words."""
    if cons.region is None or not d.checks["max_error"] > FAR_OFF * d.checks["tolerance"]:
        return ""
    from planar.synth.path import unboxed_error

    e = unboxed_error(targets, cons, atlas, args.budget)
    head = f"every ground pivot was kept in the --pivots box; without the box the atlas's best four-bar is {e:.3g} of the size"
    head += " off"
    if e <= d.checks["tolerance"]:
        return f"{head}, within the tolerance: the box is why (widen or move it)"
    if e < 0.5 * d.checks["max_error"]:
        return f"{head}: the box is part of why (widen or move it), and the shape is not traced exactly even without it"
    return f"{head} too: the box is not why; no four-bar the search found traces this shape closer (try --type sixbar)"


def _finish_path(args: argparse.Namespace, what: str, text: str, report: dict[str, Any], ok: bool, failing: list[str]) -> int:
    """:func:`_finish`, except that a scene planar cannot build is no design (nothing written, exit 3)."""
    from planar.errors import PlanarError
    from planar.scene.load import build_scene, parse_scene

    try:
        import tomllib

        build_scene(parse_scene(tomllib.loads(text), str(args.output)), str(args.output))
    except PlanarError as e:
        msg = str(e).replace(f"{args.output}: ", "", 1)
        return _no_design(
            args, "synth path", {"targets": report["targets"]}, f"the design found does not assemble as a scene ({msg})"
        )
    return _finish(args, what, text, report, ok, failing)


def _sixbar(args: argparse.Namespace, targets: np.ndarray, theta: np.ndarray | None, cons: Any) -> int:
    from planar.synth.path import wrapped
    from planar.synth.scene_out import linkage_scene_text
    from planar.synth.sixbar import synthesise_sixbar
    from planar.synth.targets import target_unit_mm

    topology = args.topology or "stephenson"
    atlas = None
    if args.atlas is not None and theta is None:
        from planar.synth.atlas import read_atlas

        atlas = read_atlas(args.atlas)
    d = synthesise_sixbar(
        targets,
        theta,
        topology,
        cons,
        budget=args.budget,
        seed=args.seed,
        tolerance=args.tolerance,
        atlas=atlas,
        ordered=args.ordered,
    )
    box = "every ground pivot was kept in the --pivots box, which may be why (try without it)" if cons.region is not None else ""

    def scene() -> tuple[str, str]:
        text = linkage_scene_text(
            f"synth-sixbar-{d.topology}",
            d.nodes(),
            d.links(),
            {"tracer": "T"},
            targets=targets.tolist(),
            unit_mm=_unit_mm(args, target_unit_mm(args.target)),
            comments=[
                f"planar synth path {args.target} --type sixbar --topology {d.topology}: {len(targets)} targets, "
                f"{'timed' if d.timed else 'untimed'}, sse {d.sse:.6g}",
                "crank angle at each target (rad, from the ground line O2-O4): "
                + ", ".join(f"{t:.6g}" for t in wrapped(d.theta)),
            ],
        )
        return text, f"{d.topology} six-bar"

    return _path_result(args, d, targets, f"{topology} six-bar", lambda: box, scene)


def _cmd_atlas(args: argparse.Namespace) -> int:
    import os
    import time

    from planar.synth.atlas import DEFAULT_SIZE, atlas_path, build_atlas, check_atlas_memory, read_atlas

    if args.rocking or args.windows:
        return _cmd_arcs(args)
    size = DEFAULT_SIZE if args.size is None else args.size
    if size < 100:
        raise InputError("--size", size, "at least 100 four-bars")
    if not 0 <= args.seed < 2**32:
        raise InputError("--seed", args.seed, "a seed from 0 to 2**32 - 1")
    check_atlas_memory("--size", size)  # before any output is checked or any four-bar solved
    path = _atlas_output(args, str(atlas_path(size, args.seed)))
    if os.path.exists(path) and not args.force:
        a = read_atlas(path)
        print(f"{path}: atlas of {len(a)} four-bars exists (built in {a.build_seconds:.1f} s CPU); --force rebuilds it")
        return 0
    t0 = time.process_time()
    a = build_atlas(size, args.seed, progress=True)
    a.save(path)
    size_b = os.path.getsize(path)
    print(f"wrote {path}: {len(a)} four-bars, {size_b / 1e6:.1f} MB, built in {time.process_time() - t0:.1f} s CPU")
    return 0


def _atlas_output(args: argparse.Namespace, default: str) -> str:
    """``-o/--output`` of ``synth atlas`` checked (an .npz file in an existing folder), or ``default``."""
    if args.output is not None:  # like every output: an existing folder, no folder made for it
        from planar.fileio import check_output

        check_output("-o/--output", args.output, (".npz",))
    path = args.output if args.output is not None else default
    if not path.endswith(".npz"):
        raise InputError("-o/--output", path, "an .npz file")
    return str(path)


#: most four-bars of a rocking-arc atlas ``synth atlas --rocking --size`` builds (four arcs each, 176 bytes an arc:
#: about 700 MB on disk)
MAX_ARC_FOURBARS = 1_000_000


def _cmd_arcs(args: argparse.Namespace) -> int:
    """``synth atlas --rocking``: the rocking-arc atlas plain ``synth path`` also tries (and ``--rocking`` uses);
    ``synth atlas --windows``: the curve-window atlas (:mod:`planar.synth.windows`) ``synth path`` looks part of a
    closed curve up in (built on first need otherwise)."""
    import os
    import time

    from planar.synth import arcs, windows

    if args.windows:
        flag, what, default, per = "--windows", "curve-window atlas", windows.DEFAULT_FOURBARS, len(windows.SPANS_DEG)
        where, build = windows.windows_path, windows.build_windows

        def read(path: str) -> Any:
            return arcs.read_arcs(path, windows.KIND, per)

        whose = "full-turn four-bars"
    else:
        flag, what, default, per = "--rocking", "rocking-arc atlas", arcs.DEFAULT_FOURBARS, len(arcs.WINDOWS)
        where, build, read, whose = arcs.arcs_path, arcs.build_arcs, arcs.read_arcs, "rocking four-bars"
    size = default if args.size is None else args.size
    if not 100 <= size <= MAX_ARC_FOURBARS:
        raise InputError("--size", size, f"100 to {MAX_ARC_FOURBARS:,} four-bars (with {flag})")
    if not 0 <= args.seed < 2**32:
        raise InputError("--seed", args.seed, "a seed from 0 to 2**32 - 1")
    path = _atlas_output(args, str(where(size, args.seed)))
    if os.path.exists(path) and not args.force:
        a = read(path)
        print(f"{path}: {what} of {len(a)} arcs exists (built in {a.build_seconds:.1f} s CPU); --force rebuilds it")
        return 0
    t0 = time.process_time()
    a = build(size, args.seed, progress=True)
    a.save(path)
    print(
        f"wrote {path}: {len(a)} arcs of {size} {whose} ({per} windows each), "
        f"{os.path.getsize(path) / 1e6:.1f} MB, built in {time.process_time() - t0:.1f} s CPU"
    )
    return 0


def _plus(v: float) -> str:
    return f"{'-' if v < 0 else '+'} {abs(v):.9g}"


def _free_hint(phi: np.ndarray, psi: np.ndarray, args: argparse.Namespace, cons: Any) -> str:
    """What ``--free-offsets`` would give, for a request that fails with the angles as given."""
    import dataclasses

    from planar.synth.function import synthesise_function

    d, _ = synthesise_function(phi, psi, args.ground, dataclasses.replace(cons, free_offsets=True), args.tolerance)
    if d is None or not d.ok:
        return ""
    return (
        f"with --free-offsets (only the pairs' differences kept) a valid four-bar has error {d.max_error:.3g} rad, "
        f"input zero at {math.degrees(d.input_offset):.6g} deg, output zero at "
        f"{math.degrees(d.output_offset):.6g} deg from the ground line"
    )


def _cmd_function(args: argparse.Namespace) -> int:
    import numpy as np

    _check_output(args, args.pairs)
    from planar.synth.function import synthesise_function
    from planar.synth.function_search import FunctionConstraints
    from planar.synth.scene_out import fourbar_scene_text
    from planar.synth.targets import read_table

    if not (args.max_ratio > 1 and math.isfinite(args.max_ratio)):
        raise InputError("--max-ratio", args.max_ratio, "a finite ratio greater than 1")
    from planar.core.limits import SIZE_RANGE

    if not (math.isfinite(args.ground) and SIZE_RANGE[0] <= args.ground <= SIZE_RANGE[1]):
        raise InputError("--ground", args.ground, f"a ground length from {SIZE_RANGE[0]:g} to {SIZE_RANGE[1]:g} (model units)")
    min_transmission = _min_transmission_rad(args)
    _unit_mm(args)  # refused before the search, not after it
    if not (args.tolerance > 0 and math.isfinite(args.tolerance)):
        raise InputError("--tolerance", args.tolerance, "a positive angle in radians")
    t = read_table(args.pairs, ("input", "output"), min_rows=3)
    phi, psi = t["input"], t["output"]
    if len(phi) > MAX_PAIRS:
        raise InputError(str(args.pairs), f"{len(phi)} pairs", f"at most {MAX_PAIRS} pairs")
    if len(np.unique(phi)) < len(phi):
        raise InputError(f"{args.pairs}: input", phi.tolist(), "a different input angle in every row")
    if len(np.unique(psi)) < 2:
        raise InputError(f"{args.pairs}: output", psi.tolist(), "output angles that change")
    from planar.core.limits import check_angle

    for name, col in (("input", phi), ("output", psi)):  # 1e300 degrees is no angle: refused, not wrapped
        big = col[int(np.argmax(np.abs(col)))]
        check_angle(f"{args.pairs}: {name}", float(big), math.pi / 180 if args.deg else 1.0)
    if args.deg:
        phi, psi = np.radians(phi), np.radians(psi)
    from planar.synth.function import spans

    for name, span in zip(("input", "output"), spans(phi, psi)):
        if span > 2 * math.pi:
            raise InputError(
                f"{args.pairs}: {name}",
                f"a span of {span:.6g} rad",
                "a span of at most 2 pi rad (one turn" + ("" if args.deg else "; --deg for degrees") + ")",
            )
    cons = FunctionConstraints(
        free_offsets=args.free_offsets,
        full_turn=args.full_turn,
        max_ratio=args.max_ratio,
        min_transmission=min_transmission,
    )
    d, why = synthesise_function(phi, psi, args.ground, cons, args.tolerance)
    hint = "" if (d is not None and d.ok) or args.free_offsets else _free_hint(phi, psi, args, cons)
    if d is None:  # nothing valid to write
        return _no_design(args, "synth function", {"pairs": len(phi)}, why, hint)
    th = d.phi + d.input_offset  # crank angles from the ground line
    amp, centre = (
        (None, 0.0) if d.checks["crank_turns_fully"] else (max(0.5 * float(np.ptp(th)), 1e-6), 0.5 * float(th.max() + th.min()))
    )
    failing = [k[3:].replace("_", " ") for k, v in d.checks.items() if k.startswith("ok_") and not v]
    if not d.checks["ok_output_error"]:
        failing[failing.index("output error")] = (
            f"output angle error {_rad(d.max_error, args.deg)} (limit {args.tolerance:g} rad) on the best four-bar "
            "that moves over the inputs' arc on one circuit" + (f"; {d.note}" if d.note else "") + (f"; {hint}" if hint else "")
        )
    if not d.checks["ok_transmission"]:
        failing[failing.index("transmission")] = _transmission_word(
            d.checks["min_transmission_deg"], "over the input's arc", args.min_transmission
        )
    offs = (
        f"crank angle from the ground line = input {_plus(d.input_offset)} rad, "
        f"rocker angle = output {_plus(d.output_offset)} rad"
    )
    text = fourbar_scene_text(
        "synth-function",
        d.ground,
        d.crank,
        d.coupler,
        d.rocker,
        (0.5 * d.coupler, 0.0),
        d.circuit,
        (0.0, 0.0, d.ground_angle),
        comments=[
            f"planar synth function {args.pairs}: {len(phi)} pairs, max output error {d.max_error:.3g} rad ({d.method})",
            offs + " (the placement turns both by its angle)",
        ],
        amplitude=amp,
        centre=centre,
        unit_mm=_unit_mm(args),
        trails=(),  # the coupler point of a function generator traces nothing anyone asked for
    )
    report = {"command": "synth function", "pairs": len(phi), **d.to_dict(), **({"hint": hint} if hint else {})}
    shift = (
        ""
        if not args.free_offsets
        else (
            f"; input zero at {math.degrees(d.input_offset):.6g} deg, output zero "
            f"at {math.degrees(d.output_offset):.6g} deg from the ground line"
        )
    )
    return _finish(
        args,
        f"four-bar ({grashof_words(d.grashof)}, {d.circuit}, {d.method}), max output angle error {_rad(d.max_error, args.deg)}, "
        f"transmission angle >= {d.checks['min_transmission_deg']:.3g} deg{shift}",
        text,
        report,
        d.ok,
        failing,
    )


def _no_design(args: argparse.Namespace, command: str, count: dict[str, int], why: str, hint: str = "") -> int:
    """No design meets the constraints: say why (JSON ``reason``), write nothing, exit 3."""
    if args.json:
        print(json.dumps({"command": command, **count, "ok": False, "reason": why, **({"hint": hint} if hint else {})}, indent=2))
    else:
        print(f"check failed: {why}; nothing written" + (f"\n{hint}" if hint else ""))
    return EXIT_CHECK


def _check_poses(name: str, poses: np.ndarray) -> None:
    """Refuse poses Burmester synthesis cannot use: duplicates, or a body that never turns."""
    import numpy as np

    L = max(float(np.hypot(*np.ptp(poses[:, :2], axis=0))), 1e-3)
    ang = poses[:, 2]
    for i in range(len(poses)):
        for j in range(i + 1, len(poses)):
            dth = abs((ang[j] - ang[i] + math.pi) % (2 * math.pi) - math.pi)
            if math.hypot(*(poses[j, :2] - poses[i, :2])) <= 1e-9 * L and dth <= 1e-9:
                raise InputError(name, f"rows {i + 1} and {j + 1}", "different poses (these two are the same position and angle)")
    turn = np.abs((ang - ang[0] + math.pi) % (2 * math.pi) - math.pi)
    if turn.max() <= 1e-9:
        raise InputError(
            f"{name}: angle",
            ang.tolist(),
            "a body that turns between poses (every angle is the "
            "same: a pure translation, which no Burmester four-bar's coupler makes except a "
            "parallelogram whose positions lie on one circle)",
        )


def _cmd_motion(args: argparse.Namespace) -> int:
    import numpy as np

    _check_output(args, args.poses)
    from planar.synth.motion import NoMotionDesign, burmester
    from planar.synth.scene_out import fourbar_scene_text
    from planar.synth.targets import read_table

    if not (args.max_ratio > 1 and math.isfinite(args.max_ratio)):
        raise InputError("--max-ratio", args.max_ratio, "a finite ratio greater than 1")
    min_transmission = _min_transmission_rad(args)
    _unit_mm(args)  # refused before the search, not after it
    t = read_table(args.poses, ("x", "y", "angle"), min_rows=3)
    from planar.core.limits import check_angle

    for i, a in enumerate(t["angle"]):
        check_angle(f"{args.poses}: row {i + 1}: angle", a, math.pi / 180 if args.deg else 1.0)
    ang = np.radians(t["angle"]) if args.deg else t["angle"]
    poses = np.column_stack([t["x"], t["y"], ang])
    if len(poses) > 5:
        raise InputError(str(args.poses), f"{len(poses)} poses", "3, 4 or 5 poses (Burmester theory)")
    from planar.synth.targets import normalisation

    normalisation(poses[:, :2], str(args.poses))  # coordinates float64 holds faithfully at the poses' size
    _check_poses(str(args.poses), poses)
    why = ""
    try:
        d = burmester(poses, max_ratio=args.max_ratio, min_transmission=min_transmission)
    except NoMotionDesign as e:
        if e.nearest is None:
            return _no_design(args, "synth motion", {"poses": len(poses)}, str(e))
        d, why = e.nearest, str(e)  # the nearest four-bar, written and failing its check
    amp, centre = (
        (None, 0.0)
        if d.crank_range is None
        else (max(0.5 * (d.crank_range[1] - d.crank_range[0]), 1e-6), 0.5 * (d.crank_range[0] + d.crank_range[1]))
    )
    failing = [k[3:].replace("_", " ") for k, v in d.checks.items() if k.startswith("ok_") and not v]
    if why and "reaches every pose" in failing:
        failing[failing.index("reaches every pose")] = (
            f"no four-bar meets every pose ({why}); the nearest, written, is "
            f"{d.checks['max_position_error']:.3g} off in position and {d.checks['max_angle_error_rad']:.3g} rad in angle"
        )
    if not d.checks["ok_transmission"]:
        failing[failing.index("transmission")] = _transmission_word(
            d.checks["min_transmission_deg"], f"at {d.checks['min_transmission_at']}", args.min_transmission
        )
    text = fourbar_scene_text(
        "synth-motion",
        d.ground,
        d.crank,
        d.coupler,
        d.rocker,
        d.coupler_point,
        d.circuit,
        d.placement,
        comments=[
            f"planar synth motion {args.poses}: {len(poses)} poses; the body's angle is the coupler's + {d.angle_offset:.9g} rad",
            "crank angle at each pose (rad): " + ", ".join(repr(float(v)) for v in d.theta),
        ],
        amplitude=amp,
        centre=centre,
        unit_mm=_unit_mm(args),
    )
    report = {"command": "synth motion", "poses": len(poses), "angle_offset": d.angle_offset, **d.to_dict()}
    return _finish(
        args,
        f"four-bar ({grashof_words(d.grashof)}, {d.circuit}) through {len(poses)} poses, position error "
        f"{d.checks['max_position_error']:.3g}"
        f", transmission angle >= {d.checks['min_transmission_deg']:.3g} deg ({d.checks['min_transmission_at']})",
        text,
        report,
        d.ok,
        failing,
    )


#: most target points ``synth path`` takes (the search evaluates every candidate at each)
MAX_TARGETS = 500
#: most pairs ``synth function`` takes (2000 pairs: about 4.5 s, 150 MB)
MAX_PAIRS = 5000


def _min_transmission_parent() -> argparse.ArgumentParser:
    """The ``--min-transmission`` option path, function and motion share (one parent parser)."""
    parent = argparse.ArgumentParser(add_help=False)
    parent.add_argument(
        "--min-transmission",
        type=float,
        default=0.0,
        help="keep the transmission angle (between the coupler and the output link) at least this far from 0 and 180 (a toggle) "
        "over the motion (path: the crank's whole turn, or with --rocking the input's swing), degrees (0; never "
        "accepted nearer than 1 deg). path: a "
        "constraint of the search (with --rocking, a four-bar not keeping it is not returned: nothing is written "
        "when none does); motion: chooses among the four-bars through the poses; when the best found does "
        "not keep it, it is written and exits 3 naming the angle and where",
    )
    parent.add_argument(
        "--unit-mm",
        type=float,
        default=None,
        help="millimetres one unit of the file's numbers (and of the design) is, written into the scene's [fabrication] "
        "unit_mm for export (default: 1 for an SVG drawing, whose units are mm; else the scene's default, 10)",
    )
    return parent


def _unit_mm(args: argparse.Namespace, default: float | None = None) -> float | None:
    """``--unit-mm`` (or ``default`` when not given); :class:`InputError` naming the option unless a positive,
    finite number of millimetres."""
    if args.unit_mm is None:
        return default
    if not (math.isfinite(args.unit_mm) and 0 < args.unit_mm <= 1e6):
        raise InputError("--unit-mm", args.unit_mm, "a positive number of millimetres per unit, at most 1e6")
    return float(args.unit_mm)


def _min_transmission_rad(args: argparse.Namespace) -> float:
    """``--min-transmission`` in radians; :class:`InputError` naming the option unless 0 <= it < 90 degrees."""
    if not 0 <= args.min_transmission < 90:
        raise InputError("--min-transmission", args.min_transmission, "degrees from 0 up to (not including) 90")
    return math.radians(args.min_transmission)


def add_parser(sub: Any) -> None:
    """Register ``planar synth`` on the top-level subparsers."""
    s = sub.add_parser("synth", help="synthesise a four-bar from a path, angle pairs or poses (writes a scene)")
    ss = s.add_subparsers(dest="synth_kind", required=True, metavar="KIND")

    trans = _min_transmission_parent()
    p = ss.add_parser("path", parents=[trans], help="coupler curve through target points (CSV x,y[,theta] or an SVG path)")
    p.add_argument("target", help="CSV with columns x,y and optional theta (crank angle), or an .svg file")
    p.add_argument("-o", "--output", required=True, help="scene file (TOML) to write")
    p.add_argument("--type", choices=("fourbar", "sixbar"), default="fourbar", help="linkage type (fourbar)")
    p.add_argument(
        "--topology",
        choices=("stephenson", "watt"),
        default=None,
        help="six-bar only: a dyad hung from the coupler (stephenson, the default) or from the rocker (watt)",
    )
    p.add_argument(
        "--json",
        action="store_true",
        help="print the design, sse, checks (max_error, rms_error, worst_target, evaluations...), time_s and "
        "target_points (the targets read, y up) as JSON; reason when ok is false",
    )
    p.add_argument(
        "--budget",
        choices=("quick", "normal", "thorough"),
        default="normal",
        help="search effort of the atlas and the global search (normal, untimed: 15 or more targets on a four-bar's "
        "curve need neither, under 2 s of CPU in all; fewer on a whole curve, about 3 s when the atlas's nearest "
        "curves find it, most of it loading the atlas; on an arc of a curve about 3 to 7 s more (reading the "
        "curve-window atlas, its lookup); when the later stages run, 5 to 15 s; up to about 20 s when the global "
        "search runs too, as with noisy or drawn targets; sixbar: about twice that; a first run also builds the "
        "atlases it needs, once: about 25 and 14 s, peaking near 1.2 GB of memory)",
    )
    p.add_argument(
        "--max-ratio",
        type=float,
        default=10.0,
        help="longest / shortest link at most this (10; six-bar: every side of every link, the ground's three included)",
    )
    p.add_argument(
        "--pivots", default=None, help="ground pivots inside XMIN,YMIN,XMAX,YMAX (write --pivots=-1,... when XMIN is negative)"
    )
    p.add_argument(
        "--points",
        type=int,
        default=None,
        help="points at equal arc lengths along an SVG target, drawing (x, y) read as (x, -y) (12; SVG only); a "
        "design whose coupler path strays over 0.25 of the targets' size from the drawing between them is written "
        "and exits 3 (more points hold the search to more of the drawing)",
    )
    p.add_argument("--deg", action="store_true", help="the theta column is in degrees")
    p.add_argument(
        "--tolerance",
        type=float,
        default=1e-3,
        help="largest distance from a target to the coupler point accepted, as a fraction of the targets' size "
        "(their RMS distance from their centroid; the RMS is reported beside it); beyond it the design is "
        "written and exits 3 (0.001)",
    )
    p.add_argument(
        "--ordered", action="store_true", help="the coupler point must pass the targets in their order (one way round)"
    )
    p.add_argument(
        "--rocking",
        action="store_true",
        help="only a four-bar whose input swings between two angles (a double-rocker, rocker-crank or triple-rocker, "
        "or a cognate whose crank could turn fully, swung over the targets' span) tracing the targets as an open arc, "
        "from the rocking-arc atlas, and when its first starts leave nothing within 1e-6 of the size, the "
        "curve-window atlas (parts of full-turn four-bars' curves) too (untimed targets; each "
        "built on first use; --min-transmission is checked over the swing). Without "
        "it, untimed synth path tries that atlas too when the coupler-curve atlas is not within --tolerance, once "
        "planar synth atlas --rocking has built it",
    )
    p.add_argument(
        "--full-turn",
        action="store_true",
        help="only a four-bar whose input turns fully: untimed, the rocking arcs are not tried (a closed SVG shape, "
        "which a rocking input traces only as an arc, asks for this itself)",
    )
    p.add_argument(
        "--input-rocks",
        action="store_true",
        help="with --rocking: only a four-bar whose input link itself cannot turn fully (a double-rocker, rocker-crank "
        "or triple-rocker), "
        "not a cognate whose crank could turn fully swung back and forth over the targets' span",
    )
    p.add_argument(
        "--atlas",
        default=None,
        help="coupler-curve atlas file (from planar synth atlas -o) the search starts from (default: the cached one, "
        "built on first use: 1,000,000 curves, about 25 s of CPU; 20,000 with --budget quick)",
    )
    p.add_argument("--seed", type=int, default=0, help="random seed of the search (same seed, same result)")
    p.set_defaults(func=_cmd_path)

    a = ss.add_parser(
        "atlas",
        help="build the coupler-curve atlas (or --rocking: the rocking-arc atlas; --windows: the curve-window atlas) "
        "untimed path synthesis searches (cached)",
    )
    a.add_argument(
        "--size",
        type=int,
        default=None,
        help="four-bars in the atlas (1000000: about 25 s CPU, a 112 MB file, 580 MB of memory while building; "
        "with --rocking or --windows 250000: about 14 s CPU, a 176 MB file)",
    )
    kind = a.add_mutually_exclusive_group()
    kind.add_argument(
        "--rocking",
        action="store_true",
        help="build the rocking-arc atlas instead (four-bars whose input swings between two angles: double-rockers, "
        "rocker-cranks, triple-rockers): once it is in the cache folder, untimed synth path tries it too when the "
        "coupler-curve atlas's best is not within --tolerance",
    )
    kind.add_argument(
        "--windows",
        action="store_true",
        help="build the curve-window atlas instead (parts of full-turn four-bars' coupler curves: 75 to 260 degree "
        "windows of the crank's turn), which untimed synth path looks targets on part of a curve up in; otherwise "
        "built on first need (250000 four-bars: about 14 s CPU, a 176 MB file)",
    )
    a.add_argument("--seed", type=int, default=0, help="random seed (same size and seed, same atlas)")
    a.add_argument("-o", "--output", default=None, help="atlas file (.npz) to write (default: the user cache folder)")
    a.add_argument("--force", action="store_true", help="rebuild even if the file exists")
    a.set_defaults(func=_cmd_atlas)

    f = ss.add_parser("function", parents=[trans], help="input/output angle pairs (Freudenstein): CSV input,output")
    f.add_argument(
        "pairs",
        help="CSV with columns input,output (crank and rocker angles counter-clockwise from "
        "the world +x axis, the crank pivot at the origin, the rocker pivot on the x axis, either side; "
        "the crank turning from the smallest input to the largest; each span at most one turn)",
    )
    f.add_argument("-o", "--output", required=True, help="scene file (TOML) to write")
    f.add_argument("--ground", type=float, default=1.0, help="ground link length (sets the scale; 1)")
    f.add_argument("--deg", action="store_true", help="angles in degrees")
    f.add_argument(
        "--tolerance", type=float, default=0.01, help="largest output angle error accepted on the chosen circuit, rad (0.01)"
    )
    f.add_argument(
        "--free-offsets",
        action="store_true",
        help="only the pairs' differences matter: the synthesis chooses where input and output angles are zero (reported)",
    )
    f.add_argument("--full-turn", action="store_true", help="the crank must turn fully (Grashof crank)")
    f.add_argument("--max-ratio", type=float, default=10.0, help="longest / shortest link at most this (10)")
    f.add_argument("--json", action="store_true", help="print the design and its errors as JSON")
    f.set_defaults(func=_cmd_function)

    m = ss.add_parser("motion", parents=[trans], help="3, 4 or 5 poses of the coupler (Burmester): CSV x,y,angle")
    m.add_argument(
        "poses",
        help="CSV with columns x,y,angle (the guided body's origin and angle), 3 to 5 rows, "
        "reached in this order as the crank moves one way (exit 3, nothing written, when no four-bar "
        "does)",
    )
    m.add_argument("-o", "--output", required=True, help="scene file (TOML) to write")
    m.add_argument("--max-ratio", type=float, default=10.0, help="longest / shortest link at most this, a finite number > 1 (10)")
    m.add_argument("--deg", action="store_true", help="angles in degrees")
    m.add_argument("--json", action="store_true", help="print the design and its checks as JSON")
    m.set_defaults(func=_cmd_motion)
