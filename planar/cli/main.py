"""The ``planar`` command.

Every subcommand exits 0 on success and 2 on a user error, printing one line
``planar: error: ...`` (no traceback; ``--debug`` shows it).  Anything
unexpected is one line too, ``planar: internal error: ...``, with exit 1.
Output paths are checked before any work (folder exists, extension matches
the format, not one of the inputs); every output is written to a temporary
and renamed only when the whole command succeeded.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
from collections.abc import Sequence
from typing import NoReturn

from planar.errors import InputError, PlanarError

__all__ = ["main"]


class _Parser(argparse.ArgumentParser):
    """An argument parser whose errors are one line: ``planar: error: render: ... (see planar render --help)``."""

    def error(self, message: str) -> NoReturn:
        sub = self.prog.split(" ", 1)[1] + ": " if " " in self.prog else ""
        self.exit(2, f"planar: error: {sub}{message} (see {self.prog} --help)\n")


def _outputs(args: argparse.Namespace, inputs: Sequence[str], *specs: tuple[str, str, tuple[str, ...]]) -> None:
    """Check each output ``(option, attribute, suffixes)`` of ``args`` before any work; refuse two alike."""
    from planar.fileio import check_output

    seen: dict[str, str] = {}
    for option, attr, suffixes in specs:
        path = getattr(args, attr)
        check_output(option, path, suffixes, inputs)
        if path is not None:
            key = os.path.realpath(path)
            if key in seen:
                raise InputError(option, path, f"a different file from {seen[key]} (both name it)")
            seen[key] = option


def _positive(option: str, value: float | None, integer: bool = False) -> None:
    if value is not None and not (math.isfinite(value) and value > 0):
        raise InputError(option, value, "a positive whole number" if integer else "a positive, finite number")


def _cmd_demo(args: argparse.Namespace) -> int:
    """The embedded default: a wind-up toy and a four-bar walking leg, animated (and cut)."""
    from planar.app.pipeline import run_demo
    from planar.fileio import check_output

    # each file is written atomically; not one transaction, as DEMO_EXTRAS may read what the demo wrote
    check_output("-o", args.output, (), directory=True)
    for line in run_demo(args.output):
        print(line)
    return 0


def _cmd_bench(args: argparse.Namespace) -> int:
    from planar.bench.suite import BENCHMARKS

    fn, fmt = BENCHMARKS[args.name]
    _positive("-n", args.n, integer=True)
    _positive("--repeats", args.repeats, integer=True)
    if args.n is not None:
        from planar.core.limits import check_count

        check_count("samples", "-n", args.n, "samples")
    kwargs = {}
    if args.n is not None:
        if args.name == "accuracy":
            raise InputError("-n", args.n, "no problem size for the accuracy benchmark (it runs the scenes of --scenes)")
        kwargs["n"] = args.n
    if args.repeats is not None:
        kwargs["repeats"] = args.repeats
    if args.name == "synthesis":
        kwargs["quick"] = args.quick
    if args.name == "accuracy":
        kwargs["scenes"] = args.scenes
        kwargs["out_dir"] = args.output
        kwargs["quick"] = args.quick
    result = fn(**kwargs)
    print(json.dumps(result, indent=2) if args.json else fmt(result))
    return 0 if result.get("ok", True) else 1


def _cmd_motion_catalog(args: argparse.Namespace) -> int:
    from planar.app.pipeline import write_catalog_motion
    from planar.core.limits import check_count

    _outputs(args, (), ("-o", "output", (".csv",)))
    _positive("--samples", args.samples, integer=True)
    check_count("samples", "--samples", args.samples, "samples")
    motion = write_catalog_motion(args.mechanism, args.output, args.samples)
    print(f"wrote {args.output}: {len(motion)} samples, {int(motion.valid.sum())} valid")
    return 0


def _cmd_chains(args: argparse.Namespace) -> int:
    from planar.core.limits import check_count
    from planar.windup.table import enumerate_chains

    _positive("--max-length", args.max_length, integer=True)
    check_count("chain", "--max-length", args.max_length, "patterns in a chain")
    chains = enumerate_chains(args.target, args.max_length, args.optional)
    if args.json:
        print(json.dumps({k: [list(c) for c in v] for k, v in chains.items()}))
        return 0
    from planar.toys.assembly import assembly_refusal

    for motion, cs in chains.items():
        why = {c: assembly_refusal(c) for c in cs}
        print(f"{motion}: {len(cs)} chains, {sum(w is None for w in why.values())} assemble")
        for c in cs:
            path = " -> ".join([c[0].split("->")[0]] + [p.split("->")[1] for p in c])
            # the second column pastes into a scene; the third says whether render, export and toy can build it
            print(
                f"   {path:<28} chain = {json.dumps(list(c)):<40} "
                + ("assembles" if why[c] is None else f"motion only: {why[c]}")
            )
    return 0


def _cmd_render(args: argparse.Namespace) -> int:
    from planar.app.pipeline import ANIMATION_SUFFIXES, animation_plan, overlay_motion, render_scene
    from planar.scene.load import load_scene

    _outputs(args, (args.scene,), ("-o", "output", ANIMATION_SUFFIXES))
    scene = load_scene(args.scene)
    overlay = overlay_motion(scene) if args.overlay else None
    notes: list[str] = []
    n = render_scene(scene, args.output, overlay=overlay, fps=args.fps, notes=notes)
    for note in notes:
        print(f"note: {note}")
    plan = animation_plan(scene, args.output, args.fps)  # arithmetic only: what render_scene drew
    print(f"wrote {args.output}: {n} frames, {plan.fps:.3g} frames/s, a cycle plays {plan.cycle_play_s:.3g} s")
    return 0


def _cmd_motion(args: argparse.Namespace) -> int:
    from planar.app.pipeline import write_scene_motion
    from planar.scene.load import load_scene

    _outputs(args, (args.scene,), ("-o", "output", (".csv",)))
    scene = load_scene(args.scene)
    notes: list[str] = []
    motion = write_scene_motion(scene, args.output, derivatives=args.derivatives, notes=notes)
    print(f"wrote {args.output}: {len(motion)} samples, {int(motion.valid.sum())} valid")
    for note in notes:
        print(f"note: {note}")
    if args.derivatives:
        from planar.analysis.rates import rates_method
        from planar.app.pipeline import table_motion

        print(f"rates: {rates_method(table_motion(scene.mechanism, motion)[0])}")
    return 0


def _cmd_gallery(args: argparse.Namespace) -> int:
    from planar.app.pipeline import build_gallery
    from planar.fileio import check_output, output_transaction

    check_output("-o", args.output, (), directory=True)
    with output_transaction():  # all GIFs or none: a bad scene leaves no half gallery
        done = list(build_gallery(args.source, args.output))
    for path, target, n in done:
        print(f"{path.name}: {n} frames -> {target}")
    return 0


def _cmd_schema(args: argparse.Namespace) -> int:
    from planar.fileio import atomic_write
    from planar.scene.load import scene_schema

    text = json.dumps(scene_schema(), indent=2, sort_keys=True) + "\n"
    _outputs(args, (), ("-o", "output", (".json",)))
    if args.output is not None:
        with atomic_write(args.output, "w") as fh:
            fh.write(text)
        print(f"wrote {args.output}")
    else:
        if sys.stdout is None:  # standard output closed (planar schema >&-)
            raise InputError("standard output", "closed", "an open standard output, or -o FILE")
        sys.stdout.write(text)
    return 0


def _cmd_compare(args: argparse.Namespace) -> int:
    from dataclasses import replace

    from planar.app.pipeline import compare_scene
    from planar.physics.compare import EXIT_MISMATCH, format_comparison
    from planar.physics.simulate import SimSettings
    from planar.scene.load import load_scene

    for option, v in (("--threshold", args.threshold), ("--torque-threshold", args.torque_threshold)):
        _positive(option, v)
    _positive("--substeps", args.substeps, integer=True)
    _positive("--iterations", args.iterations, integer=True)
    for option, v, cap in (("--substeps", args.substeps, 100_000), ("--iterations", args.iterations, 100_000)):
        if v is not None and v > cap:  # checked before pymunk allocates steps x samples
            raise InputError(option, v, f"at most {cap:,} (more gains nothing in float64 and runs for hours)")
    if args.step_drift is not None and not (math.isfinite(args.step_drift) and args.step_drift >= 0):
        raise InputError("--step-drift", args.step_drift, "a drift fraction >= 0 (0 keeps --substeps fixed)")
    if args.error_bias is not None and not (0 <= args.error_bias <= 1):
        raise InputError("--error-bias", args.error_bias, "a number between 0 and 1")
    scene = load_scene(args.scene)
    settings = SimSettings(
        **{
            k: v
            for k, v in (("substeps", args.substeps), ("iterations", args.iterations), ("error_bias", args.error_bias))
            if v is not None
        }
    )
    if args.step_drift is not None:  # 0: fixed substeps
        settings = replace(settings, step_drift=args.step_drift or None)
    result, sim = compare_scene(scene, settings, args.threshold, args.torque_threshold, with_series=args.json)
    t = sim.motion.t
    assert t is not None  # a simulation records its output times
    if args.json:
        d = result.to_dict()
        d["settings"] = {
            "substeps": sim.built.get("substeps"),
            "iterations": sim.built.get("iterations"),
            "step_drift": settings.step_drift,
            "correction": sim.built.get("correction"),
            "error_bias": settings.error_bias,
        }
        d["wall_time_s"] = sim.wall_time
        d["built"] = dict(sim.built.items())
        print(json.dumps(d, indent=2, default=str))
    else:
        print(format_comparison(result))
        print(
            f"  simulated in {sim.wall_time:.3f} s ({sim.steps} steps; substeps {sim.built.get('substeps')}, "
            f"iterations {sim.built.get('iterations')}, correction per step {sim.built.get('correction'):.3g})"
        )
    return 0 if result.passed else EXIT_MISMATCH


def _sheet(text: str) -> tuple[float, float]:
    try:
        w, h = (float(v) for v in text.lower().split("x"))
    except ValueError:
        raise InputError("--sheet", text, "WIDTHxHEIGHT in millimetres, e.g. 300x200") from None
    if not (math.isfinite(w) and math.isfinite(h) and w > 0 and h > 0):
        raise InputError("--sheet", text, "a positive, finite width and height in millimetres")
    return w, h


#: export's outputs: (option, attribute, suffixes)
_EXPORT_OUTPUTS = (
    ("-o", "output", (".dxf",)),
    ("--svg", "svg", (".svg",)),
    ("--preview", "preview", (".png",)),
    ("--bom", "bom", (".csv",)),
    ("--assembly", "assembly", (".svg",)),
    ("--kerf-test", "kerf_test", (".dxf", ".svg")),
)


def _cmd_export(args: argparse.Namespace) -> int:
    from planar.app.pipeline import export_scene
    from planar.fabrication.build import summary
    from planar.scene.load import load_scene

    if all(getattr(args, attr) is None for _, attr, _ in _EXPORT_OUTPUTS):
        raise InputError(
            "export",
            args.scene,
            "an output: -o parts.dxf, --svg, --preview, --bom, --assembly or --kerf-test (nothing would be written)",
        )
    _outputs(args, (args.scene,), *_EXPORT_OUTPUTS)
    if args.kerf is not None and not (0 <= args.kerf <= 2):
        raise InputError("--kerf", args.kerf, "a kerf between 0 and 2 mm")
    scene = load_scene(args.scene)
    sheet = _sheet(args.sheet) if args.sheet else None
    fab = export_scene(scene, args.output, args.svg, args.kerf, sheet, args.preview, args.bom, args.assembly, args.kerf_test)
    for note in fab.notes:
        print(f"note: {note}")
    for w in fab.warnings:  # a toy's motion the cut parts will not make (the design exits 3 for it; cut anyway)
        print(f"warning: {w}")
    print(f"{summary(fab)} -> {', '.join(map(str, fab.written)) or 'nothing written'}")
    return 0


def build_parser() -> argparse.ArgumentParser:
    from planar.bench.suite import BENCHMARKS

    p = _Parser(
        prog="planar",
        description="2D rigid-body mechanisms: exact kinematics and more.",
        epilog="Exit status: 0 success, 2 a user error (one line naming the file, field or option), "
        "3 a result that failed its own check (compare, toy, design, synth; each failure named, "
        "design and synth still write their result), 1 an internal error (run with --debug for the traceback). "
        "Limits on work (PLANAR_MAX_SAMPLES, PLANAR_MAX_FRAMES, PLANAR_MAX_CHAIN, "
        "PLANAR_MAX_MEMORY): see the README.",
    )
    p.add_argument("--debug", action="store_true", help="show the Python traceback of an error")
    sub = p.add_subparsers(dest="command", required=True, metavar="COMMAND")

    d = sub.add_parser("demo", help="run the embedded default and write its outputs")
    d.add_argument("-o", "--output", default="planar-demo", help="output directory (default: planar-demo)")
    d.set_defaults(func=_cmd_demo)

    b = sub.add_parser("bench", help="benchmarks against a peer, measured in the same run")
    b.add_argument("name", choices=sorted(BENCHMARKS))
    b.add_argument("--json", action="store_true", help="print a JSON object (with a 'ratio' key)")
    b.add_argument("-n", type=int, default=None, help="problem size (samples)")
    b.add_argument(
        "--repeats",
        type=int,
        default=None,
        help="timing repeats (kinematics: 7 by default, interleaved with the peer; median and spread reported)",
    )
    b.add_argument("-o", "--output", default="planar-bench-accuracy", help="accuracy: folder for the CSV and chart")
    b.add_argument(
        "--quick", action="store_true", help="accuracy: a small grid on three mechanisms; synthesis: one repeat, small budgets"
    )
    b.add_argument(
        "--scenes", default="gallery", help="accuracy: folder of scene files to measure (default: ./gallery, the repository's)"
    )
    b.set_defaults(func=_cmd_bench)

    ch = sub.add_parser("chains", help="motion transfer chains from the motor (Rz) to an end effector")
    ch.add_argument("target", nargs="?", default=None, help="end-effector motion (Ox, Oy, Oz, Tx, Ty, Tz, OzT)")
    ch.add_argument("--max-length", type=int, default=3, help="longest chain (default 3)")
    ch.add_argument("--optional", action="store_true", help="include the Oy->Oy pattern the printed table lacks")
    ch.add_argument("--json", action="store_true", help='print {"Ox": [["Rz->Tx", "Tx->Ox"], ...], ...}')
    ch.set_defaults(func=_cmd_chains)

    r = sub.add_parser("render", help="render a scene's animation to a GIF (or MP4/WebM)")
    r.add_argument("scene", help="scene file (TOML)")
    r.add_argument(
        "-o",
        "--output",
        required=True,
        help="animation to write: .gif, or .mp4/.webm with the video extra (pip install 'planar[video]')",
    )
    r.add_argument(
        "--fps",
        type=float,
        default=None,
        help="frames per second (default: the scene's [render] fps, else 25, or 50 for fast cycles; "
        "a GIF plays at most 50); a cycle plays for 1/speed seconds within one frame",
    )
    r.add_argument("--overlay", action="store_true", help="draw the pymunk simulation over the analytic motion")
    r.set_defaults(func=_cmd_render)

    mo = sub.add_parser("motion", help="write a scene's motion table (CSV)")
    mo.add_argument("scene", help="scene file (TOML)")
    mo.add_argument("-o", "--output", required=True, help="CSV file to write")
    mo.add_argument(
        "--derivatives",
        action="store_true",
        help="add <point>.vx/.vy/.ax/.ay, <part>.omega/.alpha, transmission angles and motor torque",
    )
    mo.set_defaults(func=_cmd_motion)

    g = sub.add_parser("gallery", help="render every scene of a folder to a GIF")
    g.add_argument("-o", "--output", default=None, help="output directory (default: beside the scenes)")
    g.add_argument("--source", default="gallery", help="folder of scenes (default: ./gallery, the repository's)")
    g.set_defaults(func=_cmd_gallery)

    sc = sub.add_parser("schema", help="print (or write) the JSON schema of scene files")
    sc.add_argument("-o", "--output", default=None, help="file to write (default: standard output)")
    sc.set_defaults(func=_cmd_schema)

    cp = sub.add_parser("compare", help="simulate a scene in pymunk and compare with the analytic motion")
    cp.add_argument("scene", help="scene file (TOML)")
    cp.add_argument("--json", action="store_true", help="print JSON (each part carries max_rel_error)")
    cp.add_argument(
        "--threshold", type=float, default=1e-3, help="error threshold, fraction of size (1e-3); exit status 3 when a check fails"
    )
    cp.add_argument(
        "--torque-threshold", type=float, default=0.01, help="motor torque vs inverse dynamics, fraction of its peak (0.01)"
    )
    cp.add_argument(
        "--substeps",
        type=int,
        default=None,
        help="physics steps per sample, at least (28); raised where joints turn fast, see --step-drift",
    )
    cp.add_argument(
        "--step-drift",
        type=float,
        default=None,
        help="largest predicted joint drift per step, fraction of size (3.5e-6); 0 keeps --substeps fixed",
    )
    cp.add_argument("--iterations", type=int, default=None, help="solver iterations per step, at least (40)")
    cp.add_argument(
        "--error-bias",
        type=float,
        default=None,
        help="joint error left after one second (replaces the correction of 0.2 per step)",
    )
    cp.set_defaults(func=_cmd_compare)

    ex = sub.add_parser("export", help="every part laid flat for a laser cutter (DXF, SVG)")
    ex.add_argument("scene", help="scene file (TOML)")
    ex.add_argument("-o", "--output", default=None, help="DXF file to write")
    ex.add_argument("--svg", default=None, help="SVG file to write")
    ex.add_argument("--kerf", type=float, default=None, help="beam width in mm (default: the scene's kerf_mm)")
    ex.add_argument("--sheet", default=None, help="sheet size WIDTHxHEIGHT in mm (default: the scene's)")
    ex.add_argument("--preview", default=None, help="PNG preview of each sheet (photo-like)")
    ex.add_argument("--bom", default=None, help="bill of materials (CSV): parts, layers, pins, spacers, tab joints")
    ex.add_argument("--assembly", default=None, help="assembly drawing (SVG): parts in place, layers, letters")
    ex.add_argument("--kerf-test", default=None, help="a kerf calibration piece (.dxf or .svg)")
    ex.set_defaults(func=_cmd_export)

    __import__("planar.cli.toy", fromlist=["add_parser"]).add_parser(sub)
    __import__("planar.cli.design", fromlist=["add_parser"]).add_parser(sub)

    c = sub.add_parser("catalog", help="write the motion table of a built-in mechanism")
    c.add_argument("mechanism", help="catalog name, e.g. jansen, kangaroo, slider-crank")
    c.add_argument("-o", "--output", required=True, help="CSV file to write")
    c.add_argument("--samples", type=int, default=360)
    c.set_defaults(func=_cmd_motion_catalog)
    from planar.cli.plot import add_parser as add_plot_parser

    add_plot_parser(sub)
    from planar.cli.synth import add_parser as add_synth

    add_synth(sub)
    return p


def _one_line(text: object) -> str:
    return " ".join(str(text).split())


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point: parse, run, turn user errors into exit status 2 (one line, no traceback).

    Warnings (numpy's RuntimeWarnings on invalid samples) are silenced: the
    validity masks carry that information.  ``--debug`` re-raises errors.
    """
    hook = sys.unraisablehook
    debug = "--debug" in (sys.argv[1:] if argv is None else argv)
    if not debug:  # a writer abandoned by an error complains from its __del__: not a user's concern
        sys.unraisablehook = _quiet
    try:
        return _main(argv)
    except KeyboardInterrupt:  # while parsing or importing, or a second Ctrl-C while unwinding
        print("planar: interrupted (no output written)", file=sys.stderr)
        rc = 130
    finally:
        import gc

        gc.collect()
        sys.unraisablehook = hook
    if argv is None:  # the command itself: leave now, before shutdown handlers (threads, writers) can print
        sys.stderr.flush()
        os._exit(rc)
    return rc


def _main(argv: Sequence[str] | None) -> int:
    import warnings

    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as e:  # --help, or a usage error already printed on one line
        return e.code if isinstance(e.code, int) else (0 if e.code is None else 2)
    try:
        import numpy as np

        with warnings.catch_warnings(), np.errstate(all="ignore"):
            if not args.debug:
                warnings.simplefilter("ignore")
            return int(args.func(args) or 0)
    except PlanarError as e:
        if args.debug:
            raise
        print(f"planar: error: {_one_line(e)}", file=sys.stderr)
        return 2
    except BrokenPipeError:
        # the reader of our output went away (``planar compare | head``): stop quietly, as Unix tools do
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return 141
    except OSError as e:  # a file the user named: unreadable, a loop of links, a full disc
        if args.debug:
            raise
        where = f"{e.filename}: " if e.filename else ""
        print(f"planar: error: {where}{_one_line(e.strerror or e)}", file=sys.stderr)
        return 2
    except MemoryError:
        if args.debug:
            raise
        print(
            "planar: error: out of memory; ask for fewer samples or frames (or lower PLANAR_MAX_MEMORY "
            "so this is refused before it starts)",
            file=sys.stderr,
        )
        return 2
    except Exception as e:  # the guard: a bug in planar, still one line
        if args.debug:
            raise
        print(
            f"planar: internal error: {type(e).__name__}: {_one_line(e)[:300]} "
            f"(a bug in planar; run again with --debug for the traceback)",
            file=sys.stderr,
        )
        return 1


def _quiet(unraisable: object) -> None:
    """An unraisable-exception hook that prints nothing (used while an interrupted command unwinds)."""


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
