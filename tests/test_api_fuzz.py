"""Issue 26: an API fuzzer over every public name.

Every callable in ``planar.__all__`` and in each room's ``__all__`` (classes: their constructors and their
public methods on a valid instance; functions) is called with wrong values, one parameter at a time, the
other parameters valid.  Each call must either return a sane result (finite numbers; in a result that
carries a validity mask, finite where the mask says valid; a motion finite at its valid samples) or raise
a :class:`planar.errors.PlanarError`.  Any other exception fails the test with the call shown.

The valid arguments of each callable are in :data:`EXAMPLES` (by the callable's public name) and
:data:`PARAMS` (by parameter name, for methods); a public callable, or a method's parameter, without a
valid example fails :func:`test_every_public_callable_has_valid_examples`, naming it, so a new public
function cannot slip past the fuzzer.  Names that are not entrances are listed with the reason in
:data:`NOT_FUZZED`.

The default run calls a fixed sample of the cases (a few per cheap callable, about a second of CPU);
``--runslow`` calls every callable with every wrong value for every parameter.
"""

from __future__ import annotations

import dataclasses
import importlib
import inspect
import math
import os
import random
import signal
import types
import warnings
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import planar
from planar.errors import PlanarError, short_repr

ROOMS = ("core", "linkages", "cams", "windup", "toys", "analysis", "scene", "physics", "fabrication", "draw")
ROOMS += ("synth", "app", "bench")

#: the wrong values each parameter is given in turn
BAD: tuple[Any, ...] = (
    None,
    "x",
    math.nan,
    math.inf,
    -1,
    0,
    1e300,
    1e-300,
    [],
    np.zeros((2, 3, 4)),
    object(),
)

#: CPU seconds one call may take before it counts as a failure (a limit that should have refused it)
CALL_BUDGET = 20.0


def public_callables() -> dict[str, Any]:
    """Every public callable, by its first public name (``planar.X`` before ``planar.room.X``)."""
    found: dict[int, tuple[str, Any]] = {}
    for module in (planar, *(importlib.import_module(f"planar.{room}") for room in ROOMS)):
        for name in module.__all__:
            obj = getattr(module, name)
            if callable(obj) and id(obj) not in found:
                found[id(obj)] = (f"{module.__name__}.{name}", obj)
    return dict(sorted(found.values()))


# ----------------------------------------------------------------------------- what is not an entrance

#: public callables the fuzzer does not call, with the reason (a new name must be fuzzed or listed here)
NOT_FUZZED: dict[str, str] = {
    "planar.core.Joint": "a typing Protocol (the joint kinds' shape), not instantiable",
    "planar.linkages.NodeKind": "the base class of the node kinds; each kind is fuzzed on its own",
    "planar.core.joint_kind": "a class decorator for authors of a new kind: a malformed kind is a TypeError at import",
    "planar.linkages.node_kind": "a class decorator for authors of a new kind: a malformed kind is a TypeError at import",
}
#: the errors themselves: they take any message parts
for _name in ("PlanarError", "InputError", "LimitError", "AssemblyError", "SceneError", "CheckError"):
    NOT_FUZZED[f"planar.{_name}"] = "an error class"
for _name in ("core.UnsupportedError", "cams.CamError", "physics.SimulationError", "fabrication.FabricationError"):
    NOT_FUZZED[f"planar.{_name}"] = "an error class"
#: result records: planar builds them and returns them (the user reads them, never constructs one)
RESULTS = (
    "planar.analysis.Derivatives",
    "planar.analysis.PartRates",
    "planar.cams.CamReport",
    "planar.fabrication.Assembly",
    "planar.fabrication.Fabrication",
    "planar.physics.Comparison",
    "planar.physics.PartError",
    "planar.physics.SimFailure",
    "planar.physics.SimResult",
    "planar.physics.StageReport",
    "planar.physics.ToyPhysics",
    "planar.synth.Design",
    "planar.synth.FourBarDesign",
    "planar.synth.FunctionDesign",
    "planar.synth.MotionDesign",
    "planar.synth.SixBarDesign",
    "planar.windup.ElementalRecord",
    "planar.linkages.GearMesh",  # built by Geared.extra_joints from checked gears
    "planar.toys.KeyedShaft",  # built by the toy assembly from checked stages
)
NOT_FUZZED.update(dict.fromkeys(RESULTS, "a result record planar builds and returns"))

#: methods of the kinds' solver protocol: the solver calls them with the arrays it has checked
PROTOCOL = frozenset(
    [
        "acceleration",
        "acceleration_at",
        "bind",
        "branch_of",
        "extra_joints",
        "held_by",
        "position",
        "refs",
        "toggle_margin",
        "transmission",
        "validate",
        "velocity",
        "velocity_at",
        "features",
        "pins",
        "residual",
        "input_angle",
        "input_rate",
        "input_accel",
        "make_driver",
        "solve_nodes",
        "cached_solve_nodes",
        "part_rates",
        "link_rates",
        "stage",
        "forward",
        "driver_motion",
        "stage_poses",
        "piece_poses",
        "support",
        "pitch_distance",
        "chunk",
        "part_rings",
        "frame",
        "frames",
        "register",
        "kinds",
        "get",
        "step_correction",
    ]
)


# ----------------------------------------------------------------------------- valid examples


class Ctx:
    """Valid objects, built on first use; ``tmp`` is a fresh folder (the current directory during a call)."""

    def __init__(self, tmp: Path) -> None:
        self.tmp = tmp
        self._cache: dict[str, Any] = {}

    def _get(self, key: str, make: Callable[[], Any]) -> Any:
        if key not in self._cache:
            self._cache[key] = make()
        return self._cache[key]

    @property
    def leg(self) -> Any:
        return planar.FourBar(4.0, 1.0, 4.0, 3.0, coupler_point=(5.5, -2.0))

    @property
    def motion(self) -> Any:
        return self._get("motion", lambda: self.leg.solve(np.linspace(0.0, 1.0, 5)))

    @property
    def scene(self) -> Any:
        return self._get("scene", lambda: planar.scene_from_mechanism(self.leg, driver={"samples_per_cycle": 12}))

    @property
    def profile(self) -> Any:
        from planar.cams import CamProfile, FollowerGeometry, Program, Segment

        prog = Program([Segment("cycloidal", math.pi, 0.5), Segment("cycloidal", math.pi, -0.5)])
        return self._get("profile", lambda: CamProfile(prog, 2.0, FollowerGeometry("roller", "translating", 0.3)))

    @property
    def toy(self) -> Any:
        from planar.windup.chain import ToyMechanism

        return self._get("toy", lambda: ToyMechanism({"left": [("Rz->Tx",)]}))

    @property
    def linkage(self) -> Any:
        L = planar
        nodes = [L.Fixed("O", (0.0, 0.0)), L.Crank("A", "O", 1.0), L.Fixed("D", (4.0, 0.0)), L.RRR("B", "A", 4.0, "D", 3.0)]
        return L.Linkage("l", nodes, [L.Link("crank", ("O", "A")), L.Link("coupler", ("A", "B")), L.Link("rocker", ("D", "B"))])

    def out(self, suffix: str) -> Path:
        return self.tmp / f"out{suffix}"


def _T(ctx: Ctx) -> np.ndarray:
    return np.linspace(0.0, 1.0, 5)


#: valid arguments (the required ones, and a cheap choice of others) of each public callable
EXAMPLES: dict[str, Callable[[Ctx], dict[str, Any]]] = {
    "planar.RRP": lambda c: {"name": "C", "a": "A", "ra": 2.0, "p": "P", "q": "Q"},
    "planar.RRR": lambda c: {"name": "B", "a": "A", "ra": 4.0, "b": "D", "rb": 3.0},
    "planar.Actuator": lambda c: {"name": "S", "origin": "O"},
    "planar.Crank": lambda c: {"name": "A", "centre": "O", "radius": 1.0},
    "planar.Driver": lambda c: {"part": "crank"},
    "planar.Fixed": lambda c: {"name": "O", "xy": (0.0, 0.0)},
    "planar.FourBar": lambda c: {"ground": 4.0, "crank": 1.0, "coupler": 4.0, "rocker": 3.0},
    "planar.Link": lambda c: {"name": "l", "nodes": ("O", "A")},
    "planar.Linkage": lambda c: {"name": "l", "nodes": c.linkage.nodes, "links": c.linkage.links},
    "planar.Mechanism": lambda c: {"name": "m", "parts": c.leg.parts, "joints": c.leg.joints, "driver": c.leg.driver},
    "planar.Motion": lambda c: {
        "driver": c.motion.driver,
        "poses": dict(c.motion.poses),
        "valid": c.motion.valid,
        "fail_code": c.motion.fail_code,
    },
    "planar.Part": lambda c: {"name": "p", "hull": ((0.0, 0.0, 1.0),)},
    "planar.PinInSlot": lambda c: {"name": "j", "a": "p", "b": "q", "start": (0, 0), "end": (1, 0), "pin": (0, 0)},
    "planar.Pivot": lambda c: {"name": "j", "a": "p", "b": "q", "anchor_a": (0, 0), "anchor_b": (0, 0)},
    "planar.Rigid": lambda c: {"name": "C", "a": "A", "b": "B", "local": (0.5, 0.5)},
    "planar.Scene": lambda c: {"spec": c.scene.spec, "mechanism": c.scene.mechanism},
    "planar.SimSettings": lambda c: {},
    "planar.Slide": lambda c: {
        "name": "j",
        "a": "p",
        "b": "q",
        "start": (0, 0),
        "end": (1, 0),
        "anchor": (0, 0),
        "axis": (1, 0),
    },
    "planar.SliderCrank": lambda c: {"crank": 1.0, "rod": 3.0},
    "planar.Triad": lambda c: {"name": "T", "a": "A", "ra": 1.0, "local": (0.0, 0.5), "at": (0.0, 0.0)},
    "planar.compare": lambda c: {"obj": c.leg, "driver": {"samples_per_cycle": 12}},
    "planar.export": lambda c: {"obj": c.leg, "dxf": c.out(".dxf"), "fabrication": {"unit_mm": 15.0}},
    "planar.joint_residuals": lambda c: {"mech": c.leg, "motion": c.motion},
    "planar.load_scene": lambda c: {"path": _saved_scene(c)},
    "planar.render": lambda c: {"obj": c.leg, "out": c.out(".gif"), "driver": {"samples_per_cycle": 6}, "render": {"width": 48}},
    "planar.scene_from_mechanism": lambda c: {"mech": c.leg},
    "planar.simulate": lambda c: {"mech": c.leg, "t": np.linspace(0.0, 0.05, 3)},
    "planar.core.ArcSlot": lambda c: {"centre": (0, 0), "radius": 1.0, "angle0": 0.0, "angle1": 1.0, "width": 0.2},
    "planar.core.CamOnLine": lambda c: {
        "name": "j",
        "a": "p",
        "b": "q",
        "start": (0, 0),
        "end": (1, 0),
        "centre": (0, 0),
        "radius": 1.0,
    },
    "planar.core.Effects": lambda c: {},
    "planar.core.Hole": lambda c: {"centre": (0, 0), "diameter": 0.3},
    "planar.core.Load": lambda c: {"point": "coupler_point", "force": (0.0, -1.0)},
    "planar.core.PinInArcSlot": lambda c: {"name": "j", "a": "p", "b": "q", "centre": (0, 0), "radius": 1.0, "pin": (1, 0)},
    "planar.core.Registry": lambda c: {"consumer": "test"},
    "planar.core.Slot": lambda c: {"start": (0, 0), "end": (1, 0), "width": 0.2},
    "planar.core.Spring": lambda c: {"a": "crank", "b": "rocker", "stiffness": 1.0},
    "planar.core.check_count": lambda c: {"name": "samples", "field": "n", "value": 10, "what": "samples"},
    "planar.core.check_memory": lambda c: {"field": "n", "value": 10, "n_bytes": 1000.0, "what": "a motion"},
    "planar.core.limit": lambda c: {"name": "samples"},
    "planar.linkages.Driven": lambda c: {"name": "A", "centre": "O", "radius": 1.0},
    "planar.linkages.Geared": lambda c: {"name": "B", "centre": "O", "radius": 1.0, "mesh": "A", "ratio": -1.0},
    "planar.linkages.freudenstein_angles": lambda c: {"a": 4.0, "b": 1.0, "c": 4.0, "d": 3.0, "theta": _T(c)},
    "planar.linkages.grashof_class": lambda c: {"a": 4.0, "b": 1.0, "c": 4.0, "d": 3.0},
    "planar.cams.CamContact": lambda c: {"name": "j", "a": "cam", "b": "f", "profile": c.profile, "point": (0, 0)},
    "planar.cams.CamMechanism": lambda c: {"name": "cam", "profile": c.profile},
    "planar.cams.CamProfile": lambda c: {
        "program": c.profile.program,
        "base_radius": 2.0,
        "follower": c.profile.follower,
    },
    "planar.cams.FollowerGeometry": lambda c: {},
    "planar.cams.Program": lambda c: {"segments": list(c.profile.program.segments)},
    "planar.cams.Segment": lambda c: {"law": "cycloidal", "angle": 1.0, "lift": 0.5},
    "planar.windup.ElementalMechanism": lambda c: {"number": 1},
    "planar.windup.elemental": lambda c: {"number": 1},
    "planar.windup.params_for": lambda c: {"number": 1},
    "planar.toys.ToyAssembly": lambda c: {"toy": c.toy},
    "planar.toys.fit_play": lambda c: {"settings": planar.fabrication.FabSettings()},
    "planar.toys.small_motions": lambda c: {"toy": c.toy, "settings": planar.fabrication.FabSettings(), "samples": 9},
    "planar.toys.toy_assembly": lambda c: {"toy": c.toy},
    "planar.analysis.fourbar_instant_centre": lambda c: {"fb": c.leg, "theta": _T(c)},
    "planar.analysis.fourbar_velocities": lambda c: {"fb": c.leg, "theta": _T(c)},
    "planar.analysis.instant_centre": lambda c: {"p1": (0, 0), "v1": (0, 1), "p2": (1, 0), "v2": (0, 2)},
    "planar.analysis.inverse_dynamics_torque": lambda c: {"mech": c.leg, "t": _T(c)},
    "planar.analysis.mass_properties": lambda c: {"part": c.leg.parts[1], "density": 1.0},
    "planar.analysis.mechanism_rates": lambda c: {"mech": c.leg, "q": _T(c)},
    "planar.analysis.motion_derivatives": lambda c: {"mech": c.leg, "motion": c.leg.run(8)},
    "planar.analysis.node_velocities": lambda c: {"link": c.leg, "q": _T(c)},
    "planar.analysis.point_rates": lambda c: _point_rates(c),
    "planar.analysis.point_velocities": lambda c: {"link": c.leg, "q": _T(c)},
    "planar.analysis.static_foot_loads": lambda c: {
        "weight": 1.0,
        "com_x": np.zeros(3),
        "foot_x": np.array([[-1.0, 1.0]] * 3),
        "contact": np.ones((3, 2), bool),
    },
    "planar.analysis.transmission_angles": lambda c: {"mech": c.leg, "q": _T(c)},
    "planar.analysis.virtual_work_torque": lambda c: {
        "points": c.motion.points["coupler_point"][:, None, :],
        "q": c.motion.driver,
        "forces": [0.0, -1.0],
    },
    "planar.scene.SceneSpec": lambda c: {"mechanism": c.scene.spec.mechanism},
    "planar.scene.build_scene": lambda c: {"spec": c.scene.spec},
    "planar.scene.parse_scene": lambda c: {"data": __import__("tomllib").loads(planar.scene.scene_toml(c.scene.spec))},
    "planar.scene.scene_schema": lambda c: {},
    "planar.scene.scene_toml": lambda c: {"spec": c.scene.spec},
    "planar.scene.write_scene": lambda c: {"spec": c.scene.spec, "path": c.out(".toml")},
    "planar.physics.compare_scene": lambda c: {"scene": c.scene},
    "planar.physics.format_comparison": lambda c: {"c": planar.compare(c.leg, driver={"samples_per_cycle": 12})[0]},
    "planar.physics.simulate_scene": lambda c: {"scene": c.scene},
    "planar.physics.simulate_toy": lambda c: {"toy": c.toy, "t": np.linspace(0.0, 0.05, 3)},
    "planar.physics.torque_comparison": lambda c: {"mech": c.leg, "t": np.linspace(0.0, 0.05, 3), "effects": None},
    "planar.fabrication.FabSettings": lambda c: {},
    "planar.fabrication.nest": lambda c: _nest(c),
    "planar.fabrication.part_cuts": lambda c: {"part": c.leg.parts[1], "s": planar.fabrication.FabSettings(), "number": 1},
    "planar.fabrication.plan_assembly": lambda c: {
        "mech": c.leg,
        "material": {},
        "pins": [],
        "contacts": [],
        "unit_mm": 10.0,
        "thickness": 3.0,
        "pin_mm": 3.0,
        "pin_head": 1.0,
    },
    "planar.draw.FramePlan": lambda c: {"period_s": 1.0, "delay_ms": 100.0, "frames_per_cycle": 10, "frames": 10},
    "planar.draw.Renderer": lambda c: {"mech": c.leg, "motion": c.motion, "style": planar.draw.Style(width=48, height=36)},
    "planar.draw.Style": lambda c: {},
    "planar.draw.animation_motion": lambda c: {"scene": c.scene, "plan": planar.draw.plan_frames(1.0, 1.0, 5)},
    "planar.draw.available_charts": lambda c: {"scene": c.scene},
    "planar.draw.plan_frames": lambda c: {"period_s": 1.0, "duration_s": 1.0},
    "planar.draw.write_plot": lambda c: {"scene": c.scene, "out": c.out(".png"), "what": "curve", "samples_per_cycle": 12},
    "planar.synth.burmester": lambda c: {"poses": _poses(), "grid": 4},
    "planar.synth.design_toy": lambda c: {
        "effectors": [planar.synth.design.Effector("ear", "Oy", 30.0)],
        "place": False,
        "physics": False,
        "max_fabricated": 1,
        "max_trees": 4,
    },
    "planar.synth.load_request": lambda c: {"path": _request(c)},
    "planar.synth.read_targets": lambda c: {"path": _svg(c), "points": 5},
    "planar.synth.search_function": lambda c: {
        "phi": np.linspace(0.0, 1.0, 5),
        "psi": np.linspace(0.0, 0.5, 5),
        "cons": _function_constraints(),
        "n_random": 64,
        "grid": 8,
        "starts": 1,
    },
    "planar.synth.synthesise_function": lambda c: {"phi": np.linspace(0.0, 1.0, 5), "psi": np.linspace(0.0, 0.5, 5)},
    "planar.synth.synthesise_path": lambda c: {"targets": _targets(), "budget": "fast"},
    "planar.synth.synthesise_sixbar": lambda c: {"targets": _targets(), "budget": "fast"},
    "planar.app.build_gallery": lambda c: {"source": _saved_scene(c), "output": c.tmp / "gal"},
    "planar.app.compare_scene": lambda c: {"scene": c.scene},
    "planar.app.export_mechanism": lambda c: {"mech": c.leg, "dxf": c.out(".dxf"), "fabrication": {"unit_mm": 15.0}},
    "planar.app.export_scene": lambda c: {"scene": _fab_scene(c), "dxf": c.out(".dxf")},
    "planar.app.plot_mechanism": lambda c: {
        "mech": c.leg,
        "out": c.out(".png"),
        "what": "curve",
        "driver": {"samples_per_cycle": 12},
    },
    "planar.app.render_mechanism": lambda c: {
        "mech": c.leg,
        "out": c.out(".gif"),
        "driver": {"samples_per_cycle": 6},
        "render": {"width": 48},
    },
    "planar.app.render_scene": lambda c: {"scene": _small_scene(c), "out": c.out(".gif"), "progress": False},
    "planar.app.run_demo": lambda c: {"output": c.tmp / "demo"},
    "planar.app.write_mechanism_motion": lambda c: {"mech": c.leg, "out": c.out(".csv"), "driver": {"samples_per_cycle": 12}},
    "planar.app.write_scene_motion": lambda c: {"scene": c.scene, "out": c.out(".csv")},
    "planar.app.writer": lambda c: {"suffix": "gif"},
    "planar.bench.benchmark": lambda c: {"name": "kinematics"},
}

#: callables too costly for the default sample (seconds of CPU a call); their cases run under --runslow
COSTLY = frozenset(
    {
        "planar.compare",
        "planar.render",
        "planar.simulate",
        "planar.export",
        "planar.physics.compare_scene",
        "planar.physics.format_comparison",
        "planar.physics.simulate_scene",
        "planar.physics.simulate_toy",
        "planar.physics.torque_comparison",
        "planar.synth.burmester",
        "planar.synth.design_toy",
        "planar.synth.search_function",
        "planar.synth.synthesise_function",
        "planar.synth.synthesise_path",
        "planar.synth.synthesise_sixbar",
        "planar.app.build_gallery",
        "planar.app.compare_scene",
        "planar.app.export_mechanism",
        "planar.app.export_scene",
        "planar.app.plot_mechanism",
        "planar.app.render_mechanism",
        "planar.app.render_scene",
        "planar.app.run_demo",
        "planar.draw.write_plot",
        "planar.fabrication.plan_assembly",
        "planar.fabrication.nest",
        "planar.toys.small_motions",
        "planar.toys.ToyAssembly",
        "planar.toys.toy_assembly",
        "planar.analysis.inverse_dynamics_torque",
    }
)


def _saved_scene(c: Ctx) -> Path:
    path = c.tmp / "leg.toml"
    if not path.exists():
        c.scene.save(path)
    return path


def _small_scene(c: Ctx) -> Any:
    return planar.scene_from_mechanism(c.leg, driver={"samples_per_cycle": 6}, render={"width": 48, "height": 36})


def _fab_scene(c: Ctx) -> Any:
    return planar.scene_from_mechanism(c.leg, fabrication={"unit_mm": 15.0})


def _point_rates(c: Ctx) -> dict[str, Any]:
    from planar.analysis import PartRates

    n = 3
    rates = PartRates(np.zeros((n, 2)), np.zeros((n, 2)), np.ones(n), np.zeros(n))
    return {"poses": np.zeros((n, 3)), "rates": rates, "world_points": np.ones((n, 2))}


def _nest(c: Ctx) -> dict[str, Any]:
    from planar.fabrication import FabSettings, part_cuts

    s = FabSettings()
    cuts = [part_cuts(p, s, i + 1) for i, p in enumerate(c.leg.parts[1:])]
    return {"cuts": cuts, "sheet": s.sheet, "spacing": s.spacing, "margin": s.margin, "kerf": s.kerf, "unit_mm": 10.0}


def _poses() -> np.ndarray:
    leg = planar.FourBar(4.0, 1.0, 4.0, 3.0, coupler_point=(1.0, 1.0))
    m = leg.solve(np.linspace(0.0, 2.0, 5))
    return np.c_[m.points["coupler_point"], m.poses["coupler"][:, 2]]


def _targets() -> np.ndarray:
    leg = planar.FourBar(4.0, 1.0, 4.0, 3.0, coupler_point=(1.0, 1.0))
    return leg.solve(np.linspace(0.0, 2 * math.pi, 8, endpoint=False)).points["coupler_point"]


def _function_constraints() -> Any:
    from planar.synth.function_search import FunctionConstraints

    return FunctionConstraints()


def _svg(c: Ctx) -> Path:
    path = c.tmp / "drawn.svg"
    path.write_text(
        '<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 100 100"><path d="M 10 10 C 40 0 90 40 60 90 Z"/></svg>',
        encoding="utf-8",
    )
    return path


def _request(c: Ctx) -> Path:
    path = c.tmp / "req.toml"
    path.write_text('[[effector]]\nname = "ear"\nmotion = "Oy"\nrange = 30.0\n', encoding="utf-8")
    return path


def _instance_part(c: Ctx, inst: Any) -> str:
    return inst.parts[0].name


#: valid arguments of methods, by parameter name: ``(ctx, instance) -> value``
PARAMS: dict[str, Callable[[Ctx, Any], Any]] = {
    "q": lambda c, i: _T(c),
    "theta": lambda c, i: _T(c),
    "t": lambda c, i: _T(c),
    "u": lambda c, i: _T(c),
    "qdot": lambda c, i: 1.0,
    "qddot": lambda c, i: 0.0,
    "solved": lambda c, i: None,
    "samples_per_cycle": lambda c, i: 8,
    "cycles": lambda c, i: 1.0,
    "index": lambda c, i: [0, 1],
    "i": lambda c, i: 0,
    "angle_unit": lambda c, i: "rad",
    "unit": lambda c, i: "deg",
    "name": _instance_part,
    "path": lambda c, i: c.out(".toml"),
    "max_pressure_angle": lambda c, i: 0.7,
    "samples": lambda c, i: 31,
    "sag": lambda c, i: None,
    "n_max": lambda c, i: 1024,
    "cells": lambda c, i: 64,
    "start": lambda c, i: 0.0,
    "fab": lambda c, i: _fab_scene(c).spec.fabrication,
    "kerf": lambda c, i: None,
    "sheet": lambda c, i: None,
}

#: methods whose instance is not the class's example (a designed result, a scene)
INSTANCES: dict[str, Callable[[Ctx], Any]] = {
    "planar.SliderCrank": lambda c: planar.SliderCrank(1.0, 3.0),
    "planar.Motion": lambda c: c.motion,
    "planar.Mechanism": lambda c: c.leg,  # a bare Mechanism has no solver: its methods on a kind that has one
}


# ----------------------------------------------------------------------------- one call, judged


class _OverBudget(Exception):
    pass


def _alarm(signum: int, frame: Any) -> None:
    raise _OverBudget


def _consume(result: Any) -> Any:
    if isinstance(result, types.GeneratorType | Iterator) and not isinstance(result, (str, bytes, dict, list, tuple)):
        return list(result)
    return result


def _insane(result: Any, depth: int = 0) -> str | None:
    """What is not finite in ``result`` (None when all is), honouring a validity mask beside the values."""
    if depth > 4:
        return None
    if isinstance(result, planar.Motion):
        ok = np.asarray(result.valid, bool)
        for key, arr in (*result.poses.items(), *result.points.items()):
            if not np.isfinite(np.asarray(arr)[ok]).all():
                return f"motion {key} not finite at a valid sample"
        return None if np.isfinite(result.driver).all() else "motion driver values not finite"
    if isinstance(result, float | np.floating):
        return None if math.isfinite(result) else f"a number {result!r}"
    if isinstance(result, np.ndarray):
        if result.dtype.kind in "fc" and not np.isfinite(result).all():
            return f"an array {short_repr(result)} holding NaN or inf"
        return None
    if isinstance(result, tuple | list):
        items = list(result)[:64]
        masks = [x for x in items if isinstance(x, np.ndarray) and x.dtype == bool]
        for x in items:
            if masks:  # values beside a validity mask: finite where it says valid (NaN may mark an invalid sample)
                x = _at_valid(x, masks[-1])
            why = _insane(x, depth + 1)
            if why:
                return why
        return None
    if isinstance(result, dict):
        for v in list(result.values())[:64]:
            why = _insane(v, depth + 1)
            if why:
                return why
        return None
    if dataclasses.is_dataclass(result) and not isinstance(result, type):
        return _insane([getattr(result, f.name) for f in dataclasses.fields(result)], depth + 1)
    return None


def _at_valid(x: Any, mask: np.ndarray) -> Any:
    """``x`` (an array, a dict of arrays or a record of them) at the samples ``mask`` marks valid."""
    if isinstance(x, np.ndarray) and x.dtype.kind == "f" and x.shape[:1] == mask.shape[:1]:
        return x[mask]
    if isinstance(x, dict):
        return {k: _at_valid(v, mask) for k, v in x.items()}
    if dataclasses.is_dataclass(x) and not isinstance(x, type):
        return [_at_valid(getattr(x, f.name), mask) for f in dataclasses.fields(x)]
    return x


def judge(where: str, fn: Callable[..., Any], kwargs: dict[str, Any]) -> str | None:
    """Call ``fn(**kwargs)``: ``None`` when it kept the contract, else what went wrong (with the call)."""
    shown = ", ".join(f"{k}={short_repr(v, 40)}" for k, v in kwargs.items())
    old = signal.signal(signal.SIGPROF, _alarm)
    signal.setitimer(signal.ITIMER_PROF, CALL_BUDGET)
    try:
        with warnings.catch_warnings(), np.errstate(all="ignore"):
            warnings.simplefilter("ignore")
            result = _consume(fn(**kwargs))
    except PlanarError:
        return None
    except _OverBudget:
        return f"{where}({shown}): took more than {CALL_BUDGET:g} s of CPU"
    except TypeError as exc:
        if "bogus" in kwargs and "unexpected keyword argument 'bogus'" in str(exc):
            return None  # Python's own refusal of an unknown keyword, naming it
        return f"{where}({shown}): TypeError: {short_repr(str(exc), 160)}"
    except Exception as exc:  # the finding: a raw exception
        return f"{where}({shown}): {type(exc).__name__}: {short_repr(str(exc), 160)}"
    finally:
        signal.setitimer(signal.ITIMER_PROF, 0)
        signal.signal(signal.SIGPROF, old)
    try:
        why = _insane(result)
    except Exception as exc:  # a result whose numbers cannot even be read
        why = f"a result that cannot be read ({type(exc).__name__}: {short_repr(str(exc), 80)})"
    return f"{where}({shown}): returned {why}" if why else None


# ----------------------------------------------------------------------------- the cases


@dataclasses.dataclass(frozen=True)
class Case:
    """One call: a public callable (or a method of its example instance), a parameter and a wrong value."""

    target: str  # "planar.X" or "planar.X.method"
    param: str
    bad: int  # index into BAD; -1: an unknown keyword

    def __str__(self) -> str:
        value = "bogus=1" if self.bad < 0 else f"{self.param}={short_repr(BAD[self.bad], 30)}"
        return f"{self.target}({value})"


def _fuzzed_params(fn: Callable[..., Any]) -> tuple[list[str], bool]:
    sig = inspect.signature(fn)
    params = [p for p in sig.parameters.values() if p.name != "self"]
    names = [p.name for p in params if p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD)]
    return names, any(p.kind is p.VAR_KEYWORD for p in params)


def _methods(cls: type) -> dict[str, Callable[..., Any]]:
    out = {}
    for name, member in inspect.getmembers(cls):
        if name.startswith("_") or name in PROTOCOL:
            continue
        is_function = inspect.isfunction(member) or inspect.ismethod(member)
        if is_function and getattr(member, "__module__", "").startswith("planar"):
            out[name] = member
    return out


def targets() -> dict[str, Callable[..., Any]]:
    """Every fuzzed public callable, and every public method of each fuzzed class, by name."""
    out: dict[str, Callable[..., Any]] = {}
    for name, obj in public_callables().items():
        if name in NOT_FUZZED:
            continue
        out[name] = obj
        if inspect.isclass(obj):
            for m, member in _methods(obj).items():
                out[f"{name}.{m}"] = member
    return out


def all_cases() -> list[Case]:
    cases = []
    for name, fn in targets().items():
        try:
            params, var_kw = _fuzzed_params(fn)
        except (TypeError, ValueError):
            continue
        cases += [Case(name, p, b) for p in params for b in range(len(BAD))]
        if var_kw:
            cases.append(Case(name, "bogus", -1))
    return cases


def _owner(target: str) -> tuple[str, str | None]:
    if target in EXAMPLES or target in NOT_FUZZED:
        return target, None
    cls, _, method = target.rpartition(".")
    return cls, method


def valid_kwargs(ctx: Ctx, target: str) -> tuple[Callable[..., Any], dict[str, Any]]:
    """The callable and a valid set of keyword arguments for ``target`` (KeyError naming what is missing)."""
    owner, method = _owner(target)
    if owner not in EXAMPLES:
        raise KeyError(f"{owner}: no valid example in EXAMPLES")
    cls = public_callables()[owner]
    if method is None:
        return cls, EXAMPLES[owner](ctx)
    inst = INSTANCES[owner](ctx) if owner in INSTANCES else cls(**EXAMPLES[owner](ctx))
    fn = getattr(inst, method)
    kwargs = {}
    for p in inspect.signature(fn).parameters.values():
        if p.kind in (p.VAR_POSITIONAL, p.VAR_KEYWORD) or p.default is not p.empty:
            continue
        if p.name not in PARAMS:
            raise KeyError(f"{target}({p.name}): no valid example in PARAMS")
        kwargs[p.name] = PARAMS[p.name](ctx, inst)
    return fn, kwargs


def run_case(case: Case, tmp: Path) -> str | None:
    ctx = Ctx(tmp)
    fn, kwargs = valid_kwargs(ctx, case.target)
    if case.bad < 0:
        kwargs["bogus"] = 1
    else:
        kwargs[case.param] = BAD[case.bad]
    return judge(case.target, fn, kwargs)


#: the (callable, parameter) pairs still known to raise a raw exception or return NaN: a ratchet, it only
#: shrinks (``--runslow`` fails on an entry that now keeps the contract, so it is struck off when fixed)
KNOWN = frozenset(
    line.strip()
    for line in (Path(__file__).with_name("api_fuzz_known.txt")).read_text(encoding="utf-8").splitlines()
    if line.strip() and not line.startswith("#")
)


def _key(case: Case) -> str:
    return f"{case.target}({case.param})"


def run_cases(cases: list[Case], tmp: Path) -> list[tuple[str, str]]:
    """The failures of ``cases``: ``(callable(parameter), the call and what went wrong)`` each."""
    failures = []
    here = os.getcwd()
    for k, case in enumerate(cases):
        folder = tmp / f"c{k}"
        folder.mkdir()
        os.chdir(folder)  # a wrong output name ("x") lands here, not in the repository
        try:
            why = run_case(case, folder)
        finally:
            os.chdir(here)
        if why:
            failures.append((_key(case), why))
    return failures


def _room(target: str) -> str:
    parts = _owner(target)[0].split(".")
    return parts[1] if len(parts) == 3 else ""


def default_sample(cases: list[Case], per_target: int = 2, costly: bool = False) -> list[Case]:
    """A fixed sample: ``per_target`` cases of each cheap (or each costly) callable, chosen by a seeded generator."""
    rng = random.Random(26)
    by_target: dict[str, list[Case]] = {}
    for case in cases:
        if (_owner(case.target)[0] in COSTLY) == costly:
            by_target.setdefault(case.target, []).append(case)
    return [c for group in by_target.values() for c in rng.sample(group, min(per_target, len(group)))]


# ----------------------------------------------------------------------------- the tests


def test_every_public_callable_has_valid_examples(tmp_path: Path) -> None:
    """A public callable (or a method's parameter) the fuzzer has no valid example for fails here, named."""
    missing = [n for n in public_callables() if n not in NOT_FUZZED and n not in EXAMPLES]
    assert missing == [], f"public callables without a valid example in EXAMPLES (or a reason in NOT_FUZZED): {missing}"
    assert not set(EXAMPLES) & set(NOT_FUZZED)
    stale = sorted(set(EXAMPLES) - set(public_callables()))
    assert stale == [], f"EXAMPLES names no public callable: {stale}"
    for target in targets():
        if _owner(target)[1] is not None:
            fn = getattr(public_callables()[_owner(target)[0]], _owner(target)[1])
            for p in inspect.signature(fn).parameters.values():
                if p.name != "self" and p.default is p.empty and p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD):
                    assert p.name in PARAMS, f"{target}({p.name}): no valid example in PARAMS"


def test_the_fuzzer_sees_a_raw_exception(tmp_path: Path) -> None:
    """The judge can fail: a raw TypeError, a NaN returned and a NaN under a mask are told apart."""

    def raw(x: Any) -> None:
        raise TypeError("boom")

    assert "TypeError: 'boom'" in str(judge("f", raw, {"x": 1}))
    assert "NaN" in str(judge("f", lambda x: np.array([math.nan]), {"x": 1}))
    assert judge("f", lambda x: (np.array([math.nan, 1.0]), np.array([False, True])), {"x": 1}) is None
    assert judge("f", lambda x: planar.FourBar(4, 1, 4, "x"), {"x": 1}) is None  # a PlanarError


@pytest.mark.slow  # about a second of CPU: every cheap callable once
def test_valid_examples_keep_the_contract(tmp_path: Path) -> None:
    """Each cheap callable's own valid example runs (a broken example would make every case pass vacuously)."""
    failures = []
    for target in targets():
        if _owner(target)[0] in COSTLY:
            continue
        folder = tmp_path / target
        folder.mkdir()
        ctx = Ctx(folder)
        fn, kwargs = valid_kwargs(ctx, target)
        try:
            fn(**kwargs)
        except Exception as exc:
            failures.append(f"{target}: {type(exc).__name__}: {exc}")
    assert failures == [], "\n".join(failures)


def test_api_fuzz_sample(tmp_path: Path) -> None:
    failures = run_cases(default_sample([c for c in all_cases() if _key(c) not in KNOWN]), tmp_path)
    assert failures == [], "\n".join(why for _, why in failures)


def _ratchet(cases: list[Case], tmp: Path) -> None:
    failures = run_cases(cases, tmp)
    assert [why for key, why in failures if key not in KNOWN] == []
    fixed = sorted({_key(c) for c in cases} & KNOWN - {key for key, _ in failures})
    assert fixed == [], f"now keep the contract: strike them off api_fuzz_known.txt: {fixed}"


@pytest.mark.slow
@pytest.mark.parametrize("room", ("", *ROOMS))
def test_api_fuzz_everything(room: str, tmp_path: Path) -> None:
    """Every case of the cheap public callables first named in ``planar`` (room "") or in ``planar.<room>``."""
    mine = [c for c in all_cases() if _room(c.target) == room and _owner(c.target)[0] not in COSTLY]
    _ratchet(mine, tmp_path)


@pytest.mark.slow
def test_api_fuzz_costly_sample(tmp_path: Path) -> None:
    """Two seeded cases of each costly callable (synthesis, physics, export, render: a second or more a call;
    their whole product is hours of CPU)."""
    _ratchet(default_sample(all_cases(), 2, costly=True), tmp_path)


@pytest.mark.slow
@pytest.mark.parametrize("costly", sorted(COSTLY))
def test_api_fuzz_costly_everything(costly: str, tmp_path: Path) -> None:
    """Every case of one costly callable (each parameter with every wrong value, and its methods'): the whole
    product the seeded sample above leaves out, one test per callable (about 1,800 calls in all, from 11 of
    ``format_comparison`` to 132 of ``export_scene``; minutes of CPU each, an hour or more in all)."""
    _ratchet([c for c in all_cases() if _owner(c.target)[0] == costly], tmp_path)
