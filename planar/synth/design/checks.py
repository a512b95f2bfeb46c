"""Independent checks of a designed toy: effector ranges, layer collisions and pin clashes, physics."""

from __future__ import annotations

import itertools
import math
from typing import Any

import numpy as np
from numpy.typing import NDArray

from planar.errors import InputError, PlanarError
from planar.synth.design.request import SAMPLES, SCENE_TABLES, TORQUE_TOLERANCE, design_gravity
from planar.windup.chain import ToyMechanism

Array = NDArray[np.float64]

# ----------------------------------------------------------------------------- checks


def effector_ranges(toy: ToyMechanism, samples: int = SAMPLES) -> dict[str, tuple[str, float]]:
    """Each named effector's range measured on the assembled toy's piece poses: ``name -> (motion, range)``.

    The range is the peak-to-peak of the piece's pose track (its angle for O
    and OzT, rad; its coordinate along the axis for T, model units) over one
    cycle, read from the assembly's solved motion (not from the sizing).
    """
    from planar.toys.assembly import toy_assembly

    asm = toy_assembly(toy)
    m = asm.run(samples_per_cycle=samples)
    if not np.all(m.valid):
        raise InputError(toy.name, "motion", "a toy valid over its whole cycle")
    out = {}
    for (_cam, chain), name in toy.names.items():
        motion = chain[-1].split("->")[1]
        piece = name if any(p.name == name for p in asm.parts) else asm.points[name][0]
        pose = np.asarray(m.poses[piece])
        plane = next(p.plane for p in asm.parts if p.name == piece)
        if motion[0] == "O":
            val = float(np.ptp(np.unwrap(pose[:, 2])))
        else:
            axis = plane.index(motion[1])  # the piece's plane names its pose's two coordinates
            val = float(np.ptp(pose[:, axis]))
        out[name] = (motion, val)
    return out


def layer_collisions(
    toy: ToyMechanism, samples: int = 24, unit_mm: float = 100.0
) -> tuple[dict[str, int], list[tuple[str, str, float]], list[str]]:
    """The toy's fabrication (what ``planar export`` cuts) checked for collisions over ``samples`` poses.

    Returns ``(layers, collisions, pin clashes)``: the export's layer of every
    piece; every pair of pieces on one layer (same plane) whose cut material
    (outline minus holes and slots, mm) overlaps at some sampled pose by more
    than the fabrication's tolerance (``planar.fabrication.layers.OVERLAP_MM2``, 0.5 mm^2),
    with the worst overlap (mm^2); and the export's pin clashes (a pin whose
    path crosses a piece on a layer between its ends), or the export's refusal
    of the pieces (no layers) as the one clash.
    """
    from shapely import affinity

    from planar.fabrication.build import build
    from planar.fabrication.layers import OVERLAP_MM2
    from planar.fabrication.parts import FabSettings
    from planar.scene.load import scene_from_mechanism
    from planar.toys.assembly import toy_assembly

    scene = scene_from_mechanism(toy, fabrication={"unit_mm": unit_mm})
    try:
        fab = build(scene, FabSettings.from_spec(scene.spec.fabrication, None, None))
    except PlanarError as e:  # the export refuses these pieces (e.g. no material left between two cuts)
        return {}, [], [f"the export refuses it: {e}"]
    plan = fab.assembly
    layers = {k: (v if v is not None else 0) for k, v in plan.layers.items()}
    clashes = [f"pin {pp.letter} ({', '.join(pp.joints)}) through {q}" for pp in plan.pins for q in pp.clashes]
    asm = toy_assembly(toy)
    m = asm.run(samples_per_cycle=samples)
    ok = np.flatnonzero(m.valid)
    plane = {p.name: p.plane for p in asm.parts}

    def placed(name: str, k: int) -> Any:
        x, y, a = m.poses[name][k]
        c, s = math.cos(a), math.sin(a)
        return affinity.affine_transform(fab.own[name], [c, -s, s, c, x * unit_mm, y * unit_mm])

    found = []
    names = [p.name for p in asm.parts]
    for a, b in itertools.combinations(names, 2):
        if plane[a] != plane[b] or layers.get(a) != layers.get(b):
            continue
        worst = max(placed(a, int(k)).intersection(placed(b, int(k))).area for k in ok)
        if worst > OVERLAP_MM2:
            found.append((a, b, float(worst)))
    return layers, found, clashes


def design_scene(toy: ToyMechanism, name: str) -> Any:
    """The scene ``planar design`` writes for ``toy``, with :func:`design_gravity`."""
    from planar.scene.load import scene_from_mechanism

    g = design_gravity(toy)
    effects = {"gravity": g} if g is not None else {}
    return scene_from_mechanism(toy, name=name, effects=effects, **SCENE_TABLES)


def physics_check(scene: Any) -> dict[str, Any]:
    """Run the scene's toy as ``planar toy`` does and judge it: a dict with ``ok`` and the figures.

    Coupled pymunk physics, the motor the only driver, its torque against
    inverse dynamics at the scene's speed (``torque_rel_diff``, fraction of
    the peak; ``failure``), each #8 tab's lift-off (``lets_go``: stages whose
    tab lets go at that speed) and every stage the physics did not simulate,
    or simulated with a result it does not accept (``not_simulated``: stage
    label, pattern, the effector it ends, the reason).  ``ok`` is false for
    any of them; a physics run that refuses the toy (a :class:`PlanarError`)
    is ``failure``.
    """
    from planar.physics.toy import simulate_toy

    toy = scene.mechanism
    speed = toy.driver.rate / (2 * math.pi)
    effector = {st.label: toy.names.get((st.cam, st.key)) for st in toy.stages}
    try:
        motion = scene.motion()
        phys = simulate_toy(toy, motion.t, scene.effects, speeds=[speed])
    except PlanarError as e:
        return {
            "ok": False,
            "torque_rel_diff": None,
            "failure": f"the physics refuses the toy: {e}",
            "lets_go": [],
            "pin_lets_go": [],
            "not_simulated": [],
            "stages": [],
            "speed": speed,
        }
    tq = phys.torque
    lets_go = sorted(k for k, v in phys.liftoff.items() if v["liftoff_speed"] is not None and v["liftoff_speed"] <= speed)
    pin_lets_go = sorted(k for k, v in phys.skew.items() if not v["holds"])  # #6/#9: the edge would have to pull
    missing = [
        {"stage": s.stage, "pattern": s.pattern, "effector": effector.get(s.stage), "reason": s.detail}
        for s in phys.not_simulated
    ]
    ok = tq["failure"] is None and tq["max_rel_diff"] <= TORQUE_TOLERANCE and not lets_go and not pin_lets_go and not missing
    return {
        "ok": bool(ok),
        "torque_rel_diff": float(tq["max_rel_diff"]),
        "failure": tq["failure"],
        "lets_go": lets_go,
        "pin_lets_go": pin_lets_go,
        "not_simulated": missing,
        "speed": speed,
        "stages": [{"stage": s.stage, "pattern": s.pattern, "simulated": s.simulated, "detail": s.detail} for s in phys.stages],
    }


def physics_failures(phys: dict[str, Any]) -> list[str]:
    """One line per reason the physics check failed (empty when it passed)."""
    out = []
    if phys["failure"]:
        out.append(str(phys["failure"]))
    elif phys["torque_rel_diff"] is not None and phys["torque_rel_diff"] > TORQUE_TOLERANCE:
        out.append(
            f"motor torque strays {phys['torque_rel_diff']:.2g} of its peak from inverse dynamics "
            f"(more than {TORQUE_TOLERANCE:g})"
        )
    for k in phys["lets_go"]:
        out.append(f"stage {k}'s tab lets go at {phys['speed']:g} cycles/s")
    for k in phys.get("pin_lets_go", []):
        out.append(f"stage {k}'s pin leaves its driver's edge at {phys['speed']:g} cycles/s")
    for m in phys["not_simulated"]:
        who = f" (effector {m['effector']!r})" if m["effector"] else ""
        out.append(f"stage {m['stage']} {m['pattern']}{who} not simulated: {m['reason']}")
    return out
