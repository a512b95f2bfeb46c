"""The ``planar`` command.

Every subcommand exits 0 on success and 2 on a user error, printing one line
``planar: error: ...`` (no traceback).  Output files are written atomically.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Callable, Sequence

from .errors import PlanarError

__all__ = ["main"]


#: the embedded default: a wind-up toy and a four-bar walking leg
DEMO_SCENES: dict[str, dict] = {
    "horse": {
        "name": "horse", "angle_unit": "deg",
        "mechanism": {"type": "toy", "left": [["Rz->OzT", "OzT->Oz"]],
                      "right": [["Rz->OzT", "OzT->Ty"], ["Rz->OzT", "OzT->Oz"]], "phase": 180},
        "driver": {"speed": 0.5, "samples_per_cycle": 48},
        "render": {"width": 480, "height": 360},
        "fabrication": {"unit_mm": 100.0},
    },
    "kangaroo-leg": {
        "name": "kangaroo-leg",
        "mechanism": {"type": "fourbar", "ground": 4.0, "crank": 1.0, "coupler": 4.0, "rocker": 3.0,
                      "coupler_point": [5.5, -2.0],
                      "polygons": [{"name": "foot", "part": "coupler",
                                    "points": [[5.1, -2.25], [6.6, -2.25], [6.6, -1.95], [5.1, -1.95]]}]},
        "driver": {"speed": 1.0, "samples_per_cycle": 48},
        "effects": {"loads": [{"point": "coupler_point", "force": [0.0, 10.0]}]},
        "render": {"width": 480, "height": 360, "sweep": ["foot"]},
        "fabrication": {"unit_mm": 15.0},
    },
}


def _cmd_demo(args: argparse.Namespace) -> int:
    """The embedded default: a wind-up toy and a four-bar walking leg, animated (and cut)."""
    import numpy as np

    from . import analysis
    from .fileio import write_motion_csv
    from .scene import build_scene, parse_scene

    out = Path(args.output)
    out.mkdir(parents=True, exist_ok=True)
    for name, data in DEMO_SCENES.items():
        scene = build_scene(parse_scene(data, f"<demo {name}>"), f"<demo {name}>")
        motion = scene.motion()
        gif = out / f"{name}.gif"
        n = render_scene(scene, gif)
        csv = out / f"{name}.csv"
        write_motion_csv(csv, scene.mechanism, motion)
        line = f"{name}: {n} frames, all valid: {bool(motion.valid.all())} -> {gif}, {csv}"
        if name == "kangaroo-leg":
            leg = scene.mechanism
            loads = {l.point: np.array(l.force) for l in scene.spec.effects.loads}
            tau, _ = analysis.motor_torque(leg, motion.driver, loads)
            line += f"; peak motor torque {np.abs(tau).max():.3f} (force x unit) for a 10 N foot push"
        dxf = out / f"{name}.dxf"
        layout = export_scene(scene, dxf=dxf)
        line += f"; {len(layout.parts)} parts -> {dxf}"
        print(line)
        for extra in _DEMO_EXTRAS:
            extra(scene, out)
    return 0


#: later features append writers here (scene, output dir) so the demo grows with the package
_DEMO_EXTRAS: list[Callable[..., None]] = []


def _cmd_bench(args: argparse.Namespace) -> int:
    from .bench import BENCHMARKS

    fn, fmt = BENCHMARKS[args.name]
    kwargs = {}
    if args.n is not None:
        if args.name == "accuracy":
            from .errors import InputError

            raise InputError("-n", args.n, "no problem size for the accuracy benchmark (it runs the gallery)")
        kwargs["n"] = args.n
    if args.repeats is not None:
        kwargs["repeats"] = args.repeats
    if args.name == "accuracy":
        kwargs["out_dir"] = args.output
        kwargs["quick"] = args.quick
    result = fn(**kwargs)
    print(json.dumps(result, indent=2) if args.json else fmt(result))
    return 0 if result.get("ok", True) else 1


def _cmd_motion_catalog(args: argparse.Namespace) -> int:
    from .catalog import get
    from .fileio import write_motion_csv

    mech = get(args.mechanism)
    motion = mech.run(samples_per_cycle=args.samples)
    write_motion_csv(args.output, mech, motion)
    print(f"wrote {args.output}: {len(motion)} samples, {int(motion.valid.sum())} valid")
    return 0


def _cmd_chains(args: argparse.Namespace) -> int:
    from .windup.table import enumerate_chains

    chains = enumerate_chains(args.target, args.max_length, args.optional)
    if args.json:
        print(json.dumps({k: [list(c) for c in v] for k, v in chains.items()}))
        return 0
    for motion, cs in chains.items():
        print(f"{motion}: {len(cs)} chains")
        for c in cs:
            print("   " + " -> ".join([c[0].split("->")[0]] + [p.split("->")[1] for p in c]))
    return 0


def _style(scene):
    from .render import Style

    r = scene.spec.render
    return Style(width=r.width, height=r.height, supersample=r.supersample, background=r.background,
                 trails=r.trails, show_pins=r.show_pins)


def render_scene(scene, out: str | Path, overlay=None, progress: bool = True) -> int:
    """Render a scene's analytic motion (and optionally an overlay motion) to a GIF; returns frames."""
    from exporters.gif import frame_delay_ms, indexer, write_gif

    from .render import Renderer, palette_colors

    motion = scene.motion()
    polys = {n: scene.polygons[n] for n in scene.spec.render.sweep}
    r = Renderer(scene.mechanism, motion, _style(scene), overlay=overlay, polygons=polys)
    pal = palette_colors(r.style, len(scene.mechanism.parts))
    delay = frame_delay_ms(scene.mechanism.driver.period, scene.spec.driver.samples_per_cycle)
    return write_gif(out, r.frames(progress=progress, post=indexer(pal)), delay, pal)


def _cmd_render(args: argparse.Namespace) -> int:
    from .scene import load_scene

    scene = load_scene(args.scene)
    overlay = None
    if args.overlay:
        from .simulate import SimulationError, simulate_scene

        sim = simulate_scene(scene)
        if sim.blowup is not None:
            raise SimulationError(f"{args.scene}: the simulation {sim.motion.reason(sim.blowup[0])}; "
                                  "no animation written (try more substeps: planar compare --substeps)")
        overlay = sim.motion
    n = render_scene(scene, args.output, overlay=overlay)
    print(f"wrote {args.output}: {n} frames")
    return 0


def _cmd_motion(args: argparse.Namespace) -> int:
    from .fileio import write_motion_csv
    from .scene import load_scene

    scene = load_scene(args.scene)
    motion = scene.motion()
    write_motion_csv(args.output, scene.mechanism, motion)
    print(f"wrote {args.output}: {len(motion)} samples, {int(motion.valid.sum())} valid")
    return 0


def gallery_scenes(folder: Path | None = None) -> list[Path]:
    """The gallery's scene files, sorted by name."""
    if folder is None:
        here = Path.cwd() / "gallery"
        folder = here if here.is_dir() else Path(__file__).resolve().parents[1] / "gallery"
    return sorted(folder.glob("*.toml"))


def _cmd_gallery(args: argparse.Namespace) -> int:
    from .scene import load_scene

    src = Path(args.source) if args.source else None
    scenes = gallery_scenes(src)
    if not scenes:
        from .errors import InputError

        raise InputError("gallery", str(src or "gallery/"), "a folder with .toml scene files")
    out = Path(args.output) if args.output else scenes[0].parent
    out.mkdir(parents=True, exist_ok=True)
    for path in scenes:
        scene = load_scene(path)
        target = out / (path.stem + ".gif")
        n = render_scene(scene, target, progress=False)
        print(f"{path.name}: {n} frames -> {target}")
    return 0


def _cmd_schema(args: argparse.Namespace) -> int:
    from .fileio import atomic_write
    from .scene import scene_schema

    text = json.dumps(scene_schema(), indent=2, sort_keys=True) + "\n"
    if args.output:
        with atomic_write(args.output, "w") as fh:
            fh.write(text)
        print(f"wrote {args.output}")
    else:
        sys.stdout.write(text)
    return 0


def _cmd_compare(args: argparse.Namespace) -> int:
    from .compare import compare, format_comparison
    from .scene import load_scene
    from .simulate import SimSettings, simulate_scene, torque_comparison

    scene = load_scene(args.scene)
    settings = SimSettings(**{k: v for k, v in (("substeps", args.substeps), ("iterations", args.iterations),
                                                 ("error_bias", args.error_bias)) if v is not None})
    sim = simulate_scene(scene, settings)
    result = compare(scene.mechanism, scene.motion(), sim.motion, threshold=args.threshold)
    e = scene.spec.effects
    mech = scene.mechanism
    if (e.loads or e.gravity is not None) and mech.driver.kind == "rotation" and mech.driver.amplitude is None:
        from .errors import PlanarError

        try:
            period_t = mech.driver.times(scene.spec.driver.samples_per_cycle, 1.0)
            tc = torque_comparison(mech, period_t, e, settings)
            result.torque = {k: tc[k] for k in ("peak", "max_abs_diff", "max_rel_diff", "note")}
            if args.json:
                result.torque.update(analytic=tc["analytic"], simulated=tc["simulated"])
        except PlanarError as err:
            result.notes.append(f"torque not compared: {err}")
    if args.json:
        d = result.to_dict()
        d["settings"] = {"substeps": settings.substeps, "iterations": settings.iterations,
                         "error_bias": settings.error_bias}
        d["wall_time_s"] = sim.wall_time
        d["built"] = {k: v for k, v in sim.built.items()}
        print(json.dumps(d, indent=2, default=str))
    else:
        print(format_comparison(result))
        print(f"  simulated in {sim.wall_time:.3f} s ({sim.steps} steps; substeps {settings.substeps}, "
              f"iterations {settings.iterations}, error bias {settings.error_bias:g})")
    return 0


def _sheet(text: str) -> tuple[float, float]:
    from .errors import InputError

    try:
        w, h = (float(v) for v in text.lower().split("x"))
    except ValueError:
        raise InputError("--sheet", text, "WIDTHxHEIGHT in millimetres, e.g. 300x200") from None
    if not (w > 0 and h > 0):
        raise InputError("--sheet", text, "a positive width and height")
    return w, h


def export_scene(scene, dxf: str | Path | None = None, svg: str | Path | None = None, kerf: float | None = None,
                 sheet: tuple[float, float] | None = None, preview: str | Path | None = None):
    """Lay a scene's parts on sheets and write DXF and/or SVG (and a PNG preview of the DXF)."""
    from .fabrication import layout_parts

    fab = scene.spec.fabrication
    layout = layout_parts(scene.mechanism, unit_mm=fab.unit_mm, kerf=fab.kerf_mm if kerf is None else kerf,
                          pin_mm=fab.pin_diameter_mm, clearance=fab.clearance_mm, sheet=sheet or fab.sheet_mm)
    if dxf is not None:
        from exporters.dxf import write_dxf

        write_dxf(dxf, layout)
        if preview is not None:
            from exporters.dxf import preview_png

            preview_png(dxf, preview)
    if svg is not None:
        from exporters.svg import write_svg

        write_svg(svg, layout)
    return layout


def _cmd_export(args: argparse.Namespace) -> int:
    from .errors import InputError
    from .scene import load_scene

    if args.kerf is not None and not (0 <= args.kerf <= 2):
        raise InputError("--kerf", args.kerf, "a kerf between 0 and 2 mm")
    if args.preview and not args.output:
        raise InputError("--preview", args.preview, "a DXF output (-o) to preview")
    scene = load_scene(args.scene)
    sheet = _sheet(args.sheet) if args.sheet else None
    layout = export_scene(scene, args.output, args.svg, args.kerf, sheet, args.preview)
    outs = [p for p in (args.output, args.svg, args.preview) if p]
    print(f"{len(layout.parts)} parts on {layout.sheets} sheet(s) of {layout.sheet_size[0]:g} x "
          f"{layout.sheet_size[1]:g} mm, kerf {layout.kerf:g} mm -> {', '.join(outs)}")
    return 0


def build_parser() -> argparse.ArgumentParser:
    from .bench import BENCHMARKS

    p = argparse.ArgumentParser(prog="planar", description="2D rigid-body mechanisms: exact kinematics and more.")
    sub = p.add_subparsers(dest="command", required=True, metavar="COMMAND")

    d = sub.add_parser("demo", help="run the embedded default and write its outputs")
    d.add_argument("-o", "--output", default="planar-demo", help="output directory (default: planar-demo)")
    d.set_defaults(func=_cmd_demo)

    b = sub.add_parser("bench", help="benchmarks against a peer, measured in the same run")
    b.add_argument("name", choices=sorted(BENCHMARKS))
    b.add_argument("--json", action="store_true", help="print a JSON object (with a 'ratio' key)")
    b.add_argument("-n", type=int, default=None, help="problem size (samples)")
    b.add_argument("--repeats", type=int, default=None, help="timing repeats (best is kept)")
    b.add_argument("-o", "--output", default="planar-bench-accuracy", help="accuracy: folder for the CSV and chart")
    b.add_argument("--quick", action="store_true", help="accuracy: a small grid on three mechanisms")
    b.set_defaults(func=_cmd_bench)

    ch = sub.add_parser("chains", help="motion transfer chains from the motor (Rz) to an end effector")
    ch.add_argument("target", nargs="?", default=None, help="end-effector motion (Ox, Oy, Oz, Tx, Ty, Tz, OzT)")
    ch.add_argument("--max-length", type=int, default=3, help="longest chain (default 3)")
    ch.add_argument("--optional", action="store_true", help="include the Oy->Oy pattern the printed table lacks")
    ch.add_argument("--json", action="store_true", help='print {"Ox": [["Rz->Tx", "Tx->Ox"], ...], ...}')
    ch.set_defaults(func=_cmd_chains)

    r = sub.add_parser("render", help="render a scene's animation to a GIF")
    r.add_argument("scene", help="scene file (TOML)")
    r.add_argument("-o", "--output", required=True, help="GIF file to write")
    r.add_argument("--overlay", action="store_true", help="draw the pymunk simulation over the analytic motion")
    r.set_defaults(func=_cmd_render)

    mo = sub.add_parser("motion", help="write a scene's motion table (CSV)")
    mo.add_argument("scene", help="scene file (TOML)")
    mo.add_argument("-o", "--output", required=True, help="CSV file to write")
    mo.set_defaults(func=_cmd_motion)

    g = sub.add_parser("gallery", help="render every scene in gallery/ to a GIF")
    g.add_argument("-o", "--output", default=None, help="output directory (default: beside the scenes)")
    g.add_argument("--source", default=None, help="folder of scenes (default: the repository's gallery/)")
    g.set_defaults(func=_cmd_gallery)

    sc = sub.add_parser("schema", help="print (or write) the JSON schema of scene files")
    sc.add_argument("-o", "--output", default=None, help="file to write (default: standard output)")
    sc.set_defaults(func=_cmd_schema)

    cp = sub.add_parser("compare", help="simulate a scene in pymunk and compare with the analytic motion")
    cp.add_argument("scene", help="scene file (TOML)")
    cp.add_argument("--json", action="store_true", help="print JSON (each part carries max_rel_error)")
    cp.add_argument("--threshold", type=float, default=1e-3, help="error threshold, fraction of size (1e-3)")
    cp.add_argument("--substeps", type=int, default=None)
    cp.add_argument("--iterations", type=int, default=None)
    cp.add_argument("--error-bias", type=float, default=None)
    cp.set_defaults(func=_cmd_compare)

    ex = sub.add_parser("export", help="every part laid flat for a laser cutter (DXF, SVG)")
    ex.add_argument("scene", help="scene file (TOML)")
    ex.add_argument("-o", "--output", default=None, help="DXF file to write")
    ex.add_argument("--svg", default=None, help="SVG file to write")
    ex.add_argument("--kerf", type=float, default=None, help="beam width in mm (default: the scene's kerf_mm)")
    ex.add_argument("--sheet", default=None, help="sheet size WIDTHxHEIGHT in mm (default: the scene's)")
    ex.add_argument("--preview", default=None, help="PNG preview of the DXF (ezdxf's drawing add-on)")
    ex.set_defaults(func=_cmd_export)

    c = sub.add_parser("catalog", help="write the motion table of a built-in mechanism")
    c.add_argument("mechanism", help="catalog name, e.g. jansen, kangaroo, slider-crank")
    c.add_argument("-o", "--output", required=True, help="CSV file to write")
    c.add_argument("--samples", type=int, default=360)
    c.set_defaults(func=_cmd_motion_catalog)
    return p


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point: parse, run, turn user errors into exit status 2."""
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args.func(args) or 0)
    except PlanarError as e:
        print(f"planar: error: {e}", file=sys.stderr)
        return 2
    except (FileNotFoundError, IsADirectoryError, PermissionError) as e:
        print(f"planar: error: {e.filename}: {e.strerror}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:  # pragma: no cover
        return 130


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
