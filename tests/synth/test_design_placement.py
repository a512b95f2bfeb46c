"""planar design: placement of every stage's free joint positions, and the physics check (issue 15, item 5).

The placement is checked from the outside: the effector's range is read from
the assembled toy's solved piece poses, the joints' residuals from the
assembly, the export's pieces are checked with shapely for same-layer overlaps
at sampled poses, and the footprint is recomputed here.  The physics check is
checked on a toy whose #8 stage has nothing holding its tab.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from test_design import _leaf_ranges, _same_layer_overlaps

from planar.cli.main import main
from planar.synth.design import physics_check, place_stages, placement_variables
from planar.toys.assembly import assembly_residual, toy_assembly
from planar.windup.chain import ToyMechanism

CHAINS = {
    1: ("Rz->Tx",),
    2: ("Rz->Oz",),
    3: ("Rz->OzT",),
    4: ("Rz->Oz", "Oz->Ty"),
    5: ("Rz->Oz", "Oz->Oz"),
    6: ("Rz->Oz", "Oz->Ox"),
    7: ("Rz->Tx", "Tx->Oz"),
    8: ("Rz->Tx", "Tx->Oy"),
    9: ("Rz->Tx", "Tx->Ox"),
    10: ("Rz->OzT", "OzT->Tx"),
    11: ("Rz->OzT", "OzT->Oz"),
}


def test_placement_variables_of_every_mechanism() -> None:
    """The moves found are the ones the geometry allows: a follower that only translates (#1, #4, #10) can move
    about its pin; #7's pin and pivot move together; #8's and #9's pivots; a pivot whose distance from its driver
    sets the motion (#2, #3, #5, #6, #11) has none.  Each found move, applied, leaves the effector's range (read
    from the assembled toy's piece poses) unchanged and the assembly's joints closed."""
    expect = {
        1: {"F_o"},
        2: set(),
        3: set(),
        4: {"F_o-F_jc"},
        5: set(),
        6: set(),
        7: {"F_o+D_jc"},
        8: {"F_o"},
        9: {"F_o"},
        10: {"F_o-F_jc"},
        11: set(),
    }
    for number, chain in CHAINS.items():
        toy = ToyMechanism({"left": [chain]}, name=f"m{number}", samples=181)
        last = [v for v in placement_variables(toy) if v.key == chain]
        assert {v.move for v in last} == expect[number], number
        if number not in (4, 7, 8):
            continue
        before = _leaf_ranges(toy)[("left", chain)]
        for v in last:
            kw = dict(toy.stage_overrides.get(("left", chain), {}))
            from planar.synth.design import _shifted

            moved = ToyMechanism(
                {"left": [chain]}, name="moved", samples=181, overrides={("left", chain): _shifted(kw, number, v, 0.15)}
            )
            assert _leaf_ranges(moved)[("left", chain)] == pytest.approx(before, rel=1e-6), (number, v.label)
            assert max(assembly_residual(toy_assembly(moved), samples=24).values()) < 1e-6


def _footprint(toy: ToyMechanism, samples: int = 24) -> float:
    """Convex hull area (units^2) of every xy piece over ``samples`` poses (shapely, outlines as cut)."""
    import shapely
    from shapely import affinity

    asm = toy_assembly(toy)
    m = asm.run(samples_per_cycle=samples)
    geoms = []
    for p in asm.parts:
        if p.plane != "xy":
            continue
        for x, y, a in np.asarray(m.poses[p.name]):
            geoms.append(affinity.affine_transform(p.outline, [math.cos(a), -math.sin(a), math.sin(a), math.cos(a), x, y]))
    return float(shapely.union_all(geoms).convex_hull.area)


@pytest.mark.slow
def test_placement_moves_a_pin_and_pivot_together(tmp_path) -> None:
    """A slider turning a rocker (#1 then #7): the annealing moves #7's pin and pivot, not only #1's slider; the
    placed toy is smaller, its rocker swings as far, and its export has no same-layer overlap."""
    chain = ("Rz->Tx", "Tx->Oz")
    cams = {"left": [chain]}
    names = {("left", chain): "head"}
    start = ToyMechanism(cams, name="rocker", names=names)
    options, pl = place_stages(cams, 0.0, "rocker", {}, names)
    assert "left Rz->Tx Tx->Oz: F_o+D_jc[x]" in pl.variables and options
    placed, _ = options[0]
    toy = ToyMechanism(cams, name="rocker", overrides=placed, names=names)
    p7 = placed[("left", chain)]
    assert p7["F_o"][:2] != (0.70, 0.55)  # #7's pivot moved ...
    assert np.subtract(p7["F_o"][:2], (0.70, 0.55)) == pytest.approx(np.subtract(p7["D_jc"], (0.50, 0.25)))  # with its pin
    assert _leaf_ranges(toy)[("left", chain)] == pytest.approx(_leaf_ranges(start)[("left", chain)], rel=1e-6)
    assert _footprint(toy) < _footprint(start)
    from planar.scene.load import scene_from_mechanism

    path = tmp_path / "rocker.toml"
    scene_from_mechanism(toy, name="rocker", fabrication={"unit_mm": 100.0}).save(path)
    overlaps, clashes = _same_layer_overlaps(path)
    assert overlaps == [] and clashes == []


@pytest.mark.slow
def test_a_stage_left_unsimulated_fails_by_name(tmp_path, capsys, monkeypatch) -> None:
    """A #8 stage with nothing holding its tab is not simulated: the design names the stage, its effector and
    why, in the text and the JSON, and exits 3 (here the scene is written without the gravity the design adds)."""
    import planar.synth.design as design
    import planar.synth.design.pipeline as pipeline
    from planar.scene.load import scene_from_mechanism

    def bare(toy, name):
        return scene_from_mechanism(toy, name=name, **design.SCENE_TABLES)

    monkeypatch.setattr(pipeline, "design_scene", bare)  # what design_toy's physics check runs
    monkeypatch.setattr(design, "design_scene", bare)  # what planar design writes
    req = tmp_path / "r.toml"
    req.write_text('[[effector]]\nname = "ear"\nmotion = "Oy"\nrange = 20.0\n')
    out = tmp_path / "toy.toml"
    rc = main(["design", str(req), "-o", str(out), "--max-length", "2", "--json"])
    rep = json.loads(capsys.readouterr().out)
    assert rc == 3 and not rep["ok"] and not rep["physics"]["ok"]
    miss = rep["physics"]["not_simulated"]
    assert [(m["pattern"], m["effector"]) for m in miss] == [("Tx->Oy", "ear")] and "gravity" in miss[0]["reason"]
    # the check itself, on the written scene: the same stage, not simulated
    from planar.scene.load import load_scene

    phys = physics_check(load_scene(out))
    assert not phys["ok"] and [m["stage"] for m in phys["not_simulated"]] == [miss[0]["stage"]]


def test_two_tracks_on_one_circle_are_cut_once() -> None:
    """Two #3 stages on two cams put their tracks on one circle of the frame, one within the other's angles
    (an OzT on each cam): the export cuts the longer once (their polygons' chords differ, so a polygon
    containment test missed it and the frame was refused); a track off that circle is still refused."""
    from planar.core.model import ArcSlot, Part
    from planar.fabrication.joints import FabricationError
    from planar.fabrication.parts import FabSettings, part_cuts

    s = FabSettings(unit_mm=100.0)
    big = ArcSlot(centre=(0.5, -0.5), radius=0.2236, angle0=0.28, angle1=1.72, width=0.15)
    small = ArcSlot(centre=(0.5, -0.5), radius=0.2236, angle0=0.366, angle1=1.696, width=0.15)
    cut = part_cuts(Part("frame", ((0.5, -0.5, 0.4),), (big, small), ground=True), s, 1)
    assert len(cut.inner) == 1
    off = ArcSlot(centre=(0.5, -0.5), radius=0.26, angle0=0.366, angle1=1.696, width=0.15)
    with pytest.raises(FabricationError):
        part_cuts(Part("frame", ((0.5, -0.5, 0.4),), (big, off), ground=True), s, 1)


def test_two_effectors_that_would_be_one_follower_are_refused_by_name(tmp_path, capsys) -> None:
    """Two OzT effectors on the left cam: OzT has one chain (Rz->OzT), so both would be one stage's follower."""
    req = tmp_path / "r.toml"
    req.write_text(
        '[[effector]]\nname = "walk"\nmotion = "OzT"\nrange = 8.0\ncam = "left"\n'
        '[[effector]]\nname = "step"\nmotion = "OzT"\nrange = 6.0\ncam = "left"\n'
    )
    out = tmp_path / "toy.toml"
    rc = main(["design", str(req), "-o", str(out)])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and len(err.splitlines()) == 1 and not out.exists()
    assert "'walk' and 'step'" in err and "Rz->OzT" in err and "different cams" in err
