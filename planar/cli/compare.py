"""``planar compare SCENE``: the pymunk rebuild against the analytic motion."""

from __future__ import annotations

import argparse
import json
import math
from typing import Any

from planar.cli.common import positive
from planar.errors import InputError

__all__ = ["add_parser"]


def settings_from_args(args: argparse.Namespace) -> Any:
    """:class:`~planar.physics.simulate.SimSettings` from ``--substeps``, ``--iterations``, ``--step-drift``,
    ``--error-bias`` (checked: exit 2 naming the option)."""
    from dataclasses import replace

    from planar.physics.simulate import SimSettings

    positive("--substeps", args.substeps, integer=True)
    positive("--iterations", args.iterations, integer=True)
    for option, v, cap in (("--substeps", args.substeps, 100_000), ("--iterations", args.iterations, 100_000)):
        if v is not None and v > cap:  # checked before pymunk allocates steps x samples
            raise InputError(option, v, f"at most {cap:,} (more gains nothing in float64 and runs for hours)")
    if args.step_drift is not None and not (math.isfinite(args.step_drift) and args.step_drift >= 0):
        raise InputError("--step-drift", args.step_drift, "a drift fraction >= 0 (0 keeps --substeps fixed)")
    if args.error_bias is not None and not (0 <= args.error_bias <= 1):
        raise InputError("--error-bias", args.error_bias, "a number between 0 and 1")
    given = (("substeps", args.substeps), ("iterations", args.iterations), ("error_bias", args.error_bias))
    settings = SimSettings(**{k: v for k, v in given if v is not None})
    if args.step_drift is not None:  # 0: fixed substeps
        settings = replace(settings, step_drift=args.step_drift or None)
    return settings


def _search_dict(search: Any) -> dict[str, Any] | None:
    """A settings search for the JSON report (``None`` when that run did not happen)."""
    if search is None:
        return None
    return {
        "verdict": search.verdict,
        "line": search.line(),
        "tried": search.tried,
        "stopped": search.stopped or None,
        "cpu_s": search.cpu_s,
    }


def add_solver_options(p: Any) -> None:
    """The solver settings ``compare`` and ``render --overlay`` take."""
    p.add_argument(
        "--substeps",
        type=int,
        default=None,
        help="physics steps per sample, at least (28); raised where joints turn fast, see --step-drift",
    )
    p.add_argument(
        "--step-drift",
        type=float,
        default=None,
        help="largest predicted joint drift per step, fraction of size (3.5e-6); 0 keeps --substeps fixed "
        "(the settings search then turns only --iterations)",
    )
    p.add_argument("--iterations", type=int, default=None, help="solver iterations per step, at least (40)")
    p.add_argument(
        "--error-bias",
        type=float,
        default=None,
        help="joint error left after one second (replaces the correction of 0.2 per step)",
    )


def _cmd_compare(args: argparse.Namespace) -> int:
    from planar.app.pipeline import compare_scene
    from planar.physics.compare import EXIT_MISMATCH, format_comparison
    from planar.scene.load import load_scene

    for option, v in (("--threshold", args.threshold), ("--torque-threshold", args.torque_threshold)):
        positive(option, v)
    positive("--time-cap", args.time_cap)
    settings = settings_from_args(args)
    scene = load_scene(args.scene)
    motor = True if args.motor else None
    result, sim = compare_scene(
        scene, settings, args.threshold, args.torque_threshold, with_series=args.json, motor=motor, time_cap=args.time_cap
    )
    if args.json:
        d = result.to_dict()  # with the settings used and the search, as from Python
        d["search"] = {"kinematic": _search_dict(result.search), "motor": _search_dict(result.torque_search)}
        d["wall_time_s"] = sim.wall_time
        d["built"] = dict(sim.built.items())
        if result.torque is not None:  # a motor run happened too: say so, with its own settings
            d["built"]["mode"] = "kinematic and motor"
            d["built"]["motor"] = {k: result.torque.get(k) for k in ("substeps", "iterations")}
        print(json.dumps(d, indent=2, default=str))
    else:
        print(format_comparison(result))
        print(
            f"  simulated in {sim.wall_time:.3f} s ({sim.steps} steps; substeps {sim.built.get('substeps')}, "
            f"iterations {sim.built.get('iterations')}, correction per step {sim.built.get('correction'):.3g})"
        )
    return 0 if result.passed else EXIT_MISMATCH


def add_parser(sub: Any) -> None:
    """Add ``planar compare`` to the subcommands ``sub``."""

    cp = sub.add_parser("compare", help="simulate a scene in pymunk and compare with the analytic motion")
    cp.add_argument("scene", help="scene file (TOML)")
    cp.add_argument("--json", action="store_true", help="print JSON (each part carries max_rel_error)")
    cp.add_argument(
        "--threshold", type=float, default=1e-3, help="error threshold, fraction of size (1e-3); exit status 3 when a check fails"
    )
    cp.add_argument(
        "--torque-threshold",
        type=float,
        default=0.01,
        help="motor torque vs inverse dynamics, fraction of the torque scale (at least its peak; 0.01)",
    )
    add_solver_options(cp)
    cp.add_argument(
        "--motor",
        action="store_true",
        help="also drive with a motor and check its torque (on by default when the scene's [effects] names a motor)",
    )
    cp.add_argument(
        "--time-cap",
        type=float,
        default=None,
        help="CPU seconds the settings search may spend per run (60); past it the verdict is 'could not converge'",
    )
    cp.set_defaults(func=_cmd_compare)
