"""Issue 11 items 1, 3, 4: a toy as one assembly (merged parts, one frame, keyed cams), cut and simulated coupled."""

from __future__ import annotations

import math

import numpy as np
import pytest

from planar.core.geometry import poses_compose, poses_invert
from planar.core.outlines import feature_shape
from planar.toys.assembly import KeyedShaft, assembly_residual, toy_assembly
from planar.windup.chain import bunny, horse


@pytest.fixture(scope="module")
def toys():
    return {"horse": toy_assembly(horse(rate=math.pi)), "bunny": toy_assembly(bunny(rate=math.pi))}


def test_every_joint_closes_on_the_merged_parts(toys):
    # the placement is physically consistent: every stage's joint, moved onto the merged pieces, holds
    for asm in toys.values():
        res = assembly_residual(asm, samples=37)
        assert max(res.values()) < 1e-9 * asm.size, res


def test_piece_count_is_the_rigid_bodies(toys):
    for name, asm in toys.items():
        m = asm.run(samples_per_cycle=24)
        # independent of the assembly's own grouping: pieces of one plane whose relative pose is constant over
        # the cycle are one rigid body; only the cams (keyed to the shaft) may be so and still be cut apart
        keyed = {frozenset((j.a, j.b)) for j in asm.joints if isinstance(j, KeyedShaft)}
        for plane in ("xy", "xz"):
            names = [p.name for p in asm.parts if p.plane == plane]
            for i, a in enumerate(names):
                for b in names[i + 1 :]:
                    rel = poses_compose(poses_invert(m.poses[a]), m.poses[b])
                    rel[:, 2] = np.unwrap(rel[:, 2])
                    rigid = float(np.ptp(rel, axis=0).max()) < 1e-9
                    assert not rigid or frozenset((a, b)) in keyed, (name, a, b)
        # one frame per plane, every stage ground in it
        assert sum(p.ground for p in asm.parts if p.plane == "xy") == 1
        # every stage part is in exactly one piece; distinct bodies = grounds merged, merged groups, the rest
        toy = asm.toy
        stage_parts = {f"{s.label}.{p.name}" for s in toy.stages for p in s.mech.parts}
        assert set(asm.piece_of) == stage_parts
        merged = {n for g in toy.merged for n in g}
        bodies = 1 + len(toy.merged) + sum(1 for n in stage_parts if n not in merged and not n.endswith("ground"))
        assert len(asm.bodies) == bodies
    assert len(toys["horse"].parts) == len(toys["horse"].bodies) == 8  # all in xy: one piece per body


def test_merged_part_keeps_every_feature(toys):
    import shapely

    for asm in toys.values():
        for piece, members in asm.members.items():
            part = asm.part(piece)
            material = part.outline
            for full, m in members:
                src = asm._stage_part(full)
                for f in src.features:
                    # the member's feature placed by its own transform must be a hole in the merged material
                    shape = feature_shape(f).buffer(-1e-6)
                    from shapely import affinity

                    c, s = math.cos(m[2]), math.sin(m[2])
                    placed = affinity.affine_transform(shape, [c, -s, s, c, m[0], m[1]])
                    gone = [feature_shape(g) for pc, g in asm.removed_features if pc == piece]
                    if any(placed.hausdorff_distance(g) < 1e-5 for g in gone):
                        continue  # the cut of a slide that repeated another on the same line (Bunny s1.driver)
                    assert placed.intersection(material).area < 1e-9, (piece, full, f)
                    assert shapely.union_all([material, placed]).area > material.area  # inside the outline's reach


@pytest.mark.slow
def test_export_cuts_the_assembly_once(tmp_path, toys):
    import ezdxf
    from fabcheck import dxf_cut_polygons

    from planar.app.export import write_outputs
    from planar.fabrication.build import build
    from planar.fabrication.parts import FabSettings
    from planar.scene.load import load_scene

    scene = load_scene("gallery/horse.toml")
    fab = build(scene, FabSettings(unit_mm=100.0, sheet=(600.0, 400.0)))
    names = [pc.name for pc in fab.layout.parts if not pc.name.startswith("spacer")]
    assert sorted(names) == sorted(p.name for p in toys["horse"].parts)
    assert names.count("frame") == 1
    assert any("keyed to the motor shaft at 0 degrees = cam phase 180 + the stage's own turn 180" in n for n in fab.notes)
    out = tmp_path / "h.dxf"
    write_outputs(fab, dxf=out)
    doc = ezdxf.readfile(out)
    outer = [e for e in doc.modelspace() if e.dxf.layer == "CUT_OUTER"]
    assert len(outer) == len(fab.layout.parts)
    polys = dxf_cut_polygons(out)
    # the merged leg piece: the DXF's outer contour of its area holds as many inner cuts as its features (+ none lost)
    pc = next(p for p in fab.layout.parts if p.name == "s2.follower+s3.driver+s4.driver")
    from planar.fabrication.sheet import cut_polygon

    target = cut_polygon(pc.outer)
    best = max(polys, key=lambda p: p.intersection(target).area / max(p.union(target).area, 1e-12))
    assert best.symmetric_difference(target).area < 1e-3 * target.area, "merged part outline not found in the DXF"
    inner = [p for p in polys if p is not best and best.contains(p)]
    assert len(inner) == len(toys["horse"].part("s2.follower+s3.driver+s4.driver").features)


def test_cam_d_holes_are_turned_by_their_phase(toys):
    from planar.fabrication.parts import FabSettings, part_cuts
    from planar.fabrication.sheet import cut_polygon

    asm = toys["horse"]
    s = FabSettings(unit_mm=100.0)
    m = asm.solve([0.0])
    world = []
    for cam, phase in asm.keyed.items():
        pc = part_cuts(asm.part(cam), s, 1, set(), (0.0, 0.0), None, drive_flat=math.pi / 2 - phase)
        d = min((cut_polygon(c) for c in pc.inner), key=lambda q: q.area)
        cx, cy = d.centroid.coords[0]
        # the D's centroid lies opposite its flat
        flat = math.atan2(-cy, -cx)
        world.append(flat + m.poses[cam][0, 2])
    assert abs(math.remainder(world[0] - world[1], 2 * math.pi)) < 1e-3


def test_horse_motor_torque_matches_inverse_dynamics(toys):
    from planar.physics.simulate import simulate, torque_comparison
    from planar.physics.toy import plane_mechanism

    flat = plane_mechanism(toys["horse"])
    t = flat.driver.times(24, 1.0)
    sim = simulate(flat, t, None, mode="motor")
    assert sim.failure is None
    assert sim.built["mode"] == "motor" and len(sim.pose_error) >= 7  # every moving piece is one body
    r = torque_comparison(flat, t, None)
    assert r["failure"] is None and r["samples_compared"] >= 20
    assert r["max_rel_diff"] < 0.01, r["max_rel_diff"]
    assert r["pose_error"] < 1e-3


@pytest.mark.slow
def test_bunny_simulates_every_stage_with_its_scene():
    from planar.physics.toy import simulate_toy
    from planar.scene.load import load_scene

    sc = load_scene("gallery/bunny.toml")
    toy = sc.mechanism
    tp = simulate_toy(toy, toy.driver.times(24, 1.0), sc.effects, speeds=[1.0, 8.0])  # Earth's gravity, tilted: 5.69
    assert tp.torque["failure"] is None and tp.torque["max_rel_diff"] < 0.01
    # the motor turns every piece: the #8 stage (its window plate shares the slider's x) and the #9 follower
    assert {"s1.follower", "s2.driver", "s2.follower"} <= set(tp.torque["pieces"])
    assert [s.simulated for s in tp.stages] == [True, True, True], [s.detail for s in tp.stages]
    lift = tp.liftoff["s2"]
    # pymunk's one-sided contact lets go where inverse dynamics says the contact would have to pull (bisection: 1/32)
    assert abs(lift["liftoff_speed"] - lift["predicted_speed"]) < 0.1 * lift["predicted_speed"], lift
    # without what holds it, the #8 stage is reported, not the whole toy refused
    tp0 = simulate_toy(toy, toy.driver.times(24, 1.0), None, speeds=[1.0])
    assert [s.stage for s in tp0.not_simulated] == ["s2"] and "names none" in tp0.not_simulated[0].detail


@pytest.mark.parametrize("number", [6, 9])
def test_spatial_stage_rebuilt_in_the_followers_plane(number):
    from planar.physics.toy import skew_stage
    from planar.windup.mechanisms import elemental

    err, why = skew_stage(elemental(number), 0.5, samples_per_cycle=36)
    assert why is None and err < 1e-3, (err, why)
    # too few steps: refused with the measured error, not passed
    err, why = skew_stage(elemental(number), 0.5, samples_per_cycle=12, substeps=4, tolerance=1e-6)
    assert why is not None and f"{err:.3g}" in why


def test_eight_holds_at_its_gallery_speed_and_lets_go_faster():
    from planar.physics.toy import contact_hold, hold_margin, liftoff_speed
    from planar.scene.load import load_scene

    sc = load_scene("gallery/windup-08.toml")
    g = tuple(sc.effects.gravity)
    mech = sc.mechanism
    crit = hold_margin(mech, g)
    assert crit > 0.5  # inverse dynamics: the contact pushes over the whole cycle at the gallery's 0.5 cycles/s
    assert contact_hold(mech, 0.5, g, samples_per_cycle=36, substeps=32).liftoff is None
    lift, runs = liftoff_speed(mech, g, [2.0, 8.0], refine=4)  # 72 samples x 64 substeps (36 x 32 lets go early)
    assert lift is not None and runs[-1].liftoff is not None  # the sample where it lets go is reported
    assert abs(lift - crit) < 0.1 * crit, (lift, crit)
    # gravity the other way cannot hold it even at rest
    assert hold_margin(mech, (-g[0], -g[1])) == 0.0


@pytest.mark.slow
def test_cli_toy(capsys):
    import json

    from planar.cli.main import main

    assert main(["toy", "gallery/horse.toml", "--json"]) == 0
    rep = json.loads(capsys.readouterr().out)
    assert len(rep["pieces"]) == 8 and rep["keyed"] == {"cam.left": 0.0, "cam.right": 0.0}
    assert rep["torque"]["max_rel_diff"] < 0.01 and all(s["simulated"] for s in rep["stages"])
    assert main(["toy", "gallery/windup-01.toml"]) == 2
    assert "a toy scene" in capsys.readouterr().err
    assert main(["toy", "gallery/horse.toml", "--speeds", "0,1"]) == 2


def test_every_short_chain_assembles_exactly_or_is_refused():
    from planar.errors import InputError
    from planar.windup.chain import chain_mechanism
    from planar.windup.table import enumerate_chains

    chains = sorted({c for v in enumerate_chains(None, 2).values() for c in v})
    ok = 0
    for c in chains:
        toy = chain_mechanism(c)
        try:
            asm = toy_assembly(toy)
        except InputError as e:  # a turned out-of-plane stage or a mirrored one: said, not drawn wrong
            assert "turned" in str(e)
            continue
        res = assembly_residual(asm, samples=13)
        assert max(res.values()) < 1e-9 * asm.size, (c, res)
        ok += 1
    assert ok >= 15  # measured: 15 of the 18 chains of length <= 2 (39 of 77 up to length 3)


def test_a_slide_repeated_on_one_line_is_cut_once(toys):
    # the Bunny's s0 follower and s1 driver are one body guided on one line by both stages' slides: one slide
    # (the longer slot) is kept; the other's slot and pin holes are not cut (they overlapped the kept ones)
    asm = toys["bunny"]
    assert [j.name for j in asm.redundant] == ["s1.driver-slide"]
    assert {pc for pc, _ in asm.removed_features} == {"frame", "s0.follower+s1.driver"}
    from planar.core.model import Slide

    slides = [j for j in asm.joints if isinstance(j, Slide)]
    pairs = [(j.a, j.b) for j in slides]
    assert len(pairs) == len(set(pairs))


def test_merged_grounds_keep_separate_tracks():
    """The Horse's two cam trees start with one pattern: the second is turned half a turn about the motor axis,
    so the frame's two track slots do not coincide and the pins riding them stay apart over the cycle."""
    asm = toy_assembly(horse(rate=math.pi))
    tracks = [j for j in asm.joints if "frame" in (j.a, j.b) and j.name.endswith(".track")]
    assert len(tracks) == 2
    (c0, c1) = (np.array(j.centre) for j in tracks)
    assert np.linalg.norm(c0 + c1) < 1e-12 and np.linalg.norm(c0 - c1) > 2 * tracks[0].radius
    motion = asm.run(samples_per_cycle=97)
    ends = []
    for j in tracks:
        part = j.b if j.a == "frame" else j.a
        x, y, a = np.asarray(motion.poses[part], float).T
        ends.append(np.c_[x + np.cos(a) * j.pin[0] - np.sin(a) * j.pin[1], y + np.sin(a) * j.pin[0] + np.cos(a) * j.pin[1]])
    assert np.linalg.norm(ends[0] - ends[1], axis=1).min() > 2 * tracks[0].radius
    assert max(assembly_residual(asm).values()) < 1e-9
