"""The joint protocol, sliders on moving links, rigid links and branch continuity (issue 9)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import ClassVar

import numpy as np
import pytest

from planar.core.geometry import poses_apply, wrap_angle
from planar.core.model import JOINT_KINDS, Driver, Hole, Mechanism, Part, Pivot, Slot, joint_kind, joint_residuals
from planar.core.registry import UnsupportedError
from planar.errors import InputError
from planar.linkages import RRR, Crank, Fixed, FourBar, Link, Linkage, Rigid
from planar.scene.catalog import CATALOG
from planar.scene.load import load_scene

GALLERY = Path(__file__).resolve().parents[2] / "gallery"


def _quick_return(r: float = 1.0, d: float = 2.0, lever: float = 4.0) -> Linkage:
    nodes = [Fixed("O", (0, 0)), Fixed("Q", (0, -d)), Crank("A", "O", r), Rigid("T", "Q", "A", (lever, 0.0))]
    links = [Link("crank", ("O", "A")), Link("lever", ("Q", "T")), Link("block", ("A",), guide=("Q", "T"))]
    return Linkage("qr", nodes, links, points={"tip": "T"})


@pytest.mark.parametrize("name", sorted(CATALOG))
def test_every_joint_states_its_parts_and_its_pins_sit_in_holes_or_slots(name):
    mech = CATALOG[name]()
    parts = {p.name: p for p in mech.parts}
    for j in mech.joints:
        assert type(j) is JOINT_KINDS[j.kind]
        assert j.a in parts and j.b in parts and j.a != j.b
        # every feature a joint declares is cut in the part it names
        for part, feat in j.features():
            assert feat in parts[part].features, (name, j.name, part, feat)


def test_quick_return_block_slides_in_a_slot_of_the_moving_lever():
    qr = _quick_return()
    slide = [j for j in qr.joints if j.kind == "slide"]
    assert len(slide) == 1 and (slide[0].a, slide[0].b) == ("lever", "block")
    lever = qr.part("lever")
    slots = [f for f in lever.features if isinstance(f, Slot)]
    assert len(slots) == 1
    # drawn and cut: the slot is a hole in the lever's outline
    assert len(lever.outline.interiors) == len(lever.features)
    m = qr.run(720)
    assert m.valid.all()
    assert max(r.max() for r in joint_residuals(qr, m).values()) < 1e-12 * qr.size
    # the crank pin stays on the lever's line, inside the slot's length (independent geometry)
    A = poses_apply(m.poses["crank"], (1.0, 0.0))
    s0 = poses_apply(m.poses["lever"], slots[0].start)
    s1 = poses_apply(m.poses["lever"], slots[0].end)
    d = s1 - s0
    t = ((A - s0) * d).sum(-1) / (d * d).sum(-1)
    assert t.min() > 0.0 and t.max() < 1.0


def test_quick_return_time_ratio_from_its_geometry():
    r, d = 1.0, 2.5
    qr = _quick_return(r, d)
    th = np.linspace(0.0, 2 * np.pi, 200_001)
    m = qr.solve(th)
    phi = np.unwrap(m.poses["lever"][:, 2])
    i_max, i_min = int(np.argmax(phi)), int(np.argmin(phi))
    # crank angle spent going from one extreme to the other, and back
    one = (th[i_min] - th[i_max]) % (2 * np.pi)
    ratio = max(one, 2 * np.pi - one) / min(one, 2 * np.pi - one)
    alpha = np.arccos(r / d)
    assert ratio == pytest.approx((2 * np.pi - 2 * alpha) / (2 * alpha), rel=1e-4)


def test_oscillating_cylinder_swings_by_asin_r_over_d():
    scene = load_scene(GALLERY / "oscillating-cylinder.toml")
    mech = scene.mechanism
    m = mech.solve(np.linspace(0.0, 2 * np.pi, 100_001))
    ang = np.unwrap(m.poses["cylinder"][:, 2])
    assert 0.5 * np.ptp(ang) == pytest.approx(np.arcsin(0.6 / 2.4), rel=1e-8)
    assert [j.kind for j in mech.joints].count("slide") == 1


@pytest.mark.parametrize("scene", ["quick-return", "oscillating-cylinder"])
def test_inverted_slider_crank_scenes_simulate_close_to_the_analytic_motion(scene):
    from planar.physics.compare import compare
    from planar.physics.simulate import simulate

    sc = load_scene(GALLERY / f"{scene}.toml")
    ref = sc.motion()
    sim = simulate(sc.mechanism, ref.t, sc.effects)
    assert sim.blowup is None
    c = compare(sc.mechanism, ref, sim.motion)
    assert c.max_rel_error < 1e-3


def test_a_guide_no_other_link_carries_is_refused():
    nodes = [Fixed("O", (0, 0)), Fixed("Q", (0, -2)), Crank("A", "O", 1.0), Rigid("T", "Q", "A", (4.0, 0.0))]
    links = [Link("crank", ("O", "A")), Link("lever", ("Q",)), Link("block", ("A",), guide=("Q", "T"))]
    with pytest.raises(InputError, match=r"qr.links.lever .*'Q' and 'A' move relative.*changes by 2\b"):
        Linkage("qr", nodes, links[:1] + [Link("lever", ("Q", "A", "T"))] + links[2:])  # A slides: not rigid
    with pytest.raises(InputError, match=r"qr\.links\.block\.guide"):
        Linkage("qr", nodes, [links[0], Link("lever2", ("O", "Q")), links[2]])


def test_an_unregistered_joint_kind_is_refused_by_the_mechanism():
    @dataclass(frozen=True)
    class MyPivot:  # a look-alike copy of Pivot with other field names
        kind: ClassVar[str] = "pivot"
        name: str
        first: str
        second: str

        def residual(self, poses):
            return np.zeros(len(next(iter(poses.values()))))

    parts = [Part("ground", ((0, 0, 1),), ground=True), Part("p", ((0, 0, 1),))]
    with pytest.raises(InputError, match="registered joint kind"):
        Mechanism("m", parts, [MyPivot("j", "ground", "p")], CATALOG["slider-crank"]().driver)


def test_a_registered_kind_a_consumer_lacks_is_an_error_naming_it():
    from planar.physics.simulate import simulate

    @joint_kind
    @dataclass(frozen=True)
    class Weld:
        kind: ClassVar[str] = "test-weld"
        name: str
        a: str
        b: str

        def residual(self, poses):
            return np.zeros(len(poses[self.a]))

        def features(self):
            return ()

        def pins(self):
            return ()

    try:
        fb = FourBar(4.0, 1.0, 4.0, 3.0)
        mech = Mechanism("welded", fb.parts, list(fb.joints) + [Weld("w", "coupler", "rocker")], fb.driver)
        mech._solve_poses = fb._solve_poses  # type: ignore[method-assign]
        with pytest.raises(UnsupportedError, match="simulate has no handler for joint kind 'test-weld'"):
            simulate(mech, np.linspace(0, 1, 5))
        from planar.windup.chain import _rename_joint

        with pytest.raises(UnsupportedError, match=r"chain composition.*'test-weld'"):
            _rename_joint(Weld("w", "a", "b"), "s0", 0.0)
        with pytest.raises(TypeError, match="double registration"):
            joint_kind(Weld)
    finally:
        JOINT_KINDS.pop("test-weld", None)


def test_joint_features_are_cut_once():
    parts = [Part("ground", ((0, 0, 1),), ground=True), Part("p", ((0, 0, 1), (2, 0, 1)), (Hole((0, 0), 0.2, "pin"),))]
    j = Pivot("o", "ground", "p", (0, 0), (0, 0), diameter=0.2)
    mech = Mechanism("m", parts, [j], Driver("p"))
    assert mech.part("p").features == (Hole((0, 0), 0.2, "pin"),)
    assert mech.part("ground").features == (Hole((0, 0), 0.2, "pin"),)


# ---------------------------------------------------------------------------------------- branches


def test_parallelogram_runs_its_whole_turn_as_a_parallelogram():
    fb = FourBar(2.0, 1.0, 2.0, 1.0, circuit="open")  # change point: ground 2, crank 1, coupler 2, rocker 1
    th = np.linspace(0.0, 4 * np.pi, 721)
    pos = fb.node_positions(th)
    # a parallelogram keeps its coupler parallel to the ground: C - B = (2, 0) at every sample
    err = np.hypot(*(pos["C"] - pos["B"] - np.array([2.0, 0.0])).T)
    assert err.max() < 1e-9
    m = fb.solve(th)
    assert m.valid.all()
    # the rocker turns with the crank (same angle), no jump in speed
    assert np.abs(wrap_angle(m.poses["rocker"][:, 2] - th)).max() < 1e-9


def test_parallelogram_branch_is_kept_at_any_sampling_phase():
    fb = FourBar(2.0, 1.0, 2.0, 1.0)
    for n, off in [(37, 0.0), (100, 0.013), (360, 0.5)]:
        th = off + np.linspace(0.0, 2 * np.pi, n)
        pos = fb.node_positions(th)
        assert np.hypot(*(pos["C"] - pos["B"] - np.array([2.0, 0.0])).T).max() < 1e-9, (n, off)


def test_kite_does_not_flip_its_rocker():
    # ground = crank, coupler = rocker (a kite / deltoid): the crank pin passes over the rocker pivot
    fb = FourBar(1.0, 1.0, 2.0, 2.0)
    th = np.linspace(0.0, 2 * np.pi, 361)
    m = fb.solve(th)
    rocker = m.poses["rocker"][:, 2]
    steps = np.abs(wrap_angle(np.diff(rocker)))[m.valid[1:] & m.valid[:-1]]
    assert steps.max() < 0.1  # was a 3.1 rad flip between two valid samples
    # the continued motion still closes every joint (an independent check: link lengths)
    pos = fb.node_positions(th)
    ok = m.valid
    assert np.allclose(np.hypot(*(pos["C"] - pos["B"]).T)[ok], 2.0, atol=1e-9)
    assert np.allclose(np.hypot(*(pos["C"] - np.array([1.0, 0.0])).T)[ok], 2.0, atol=1e-9)


def test_scattered_samples_keep_the_declared_branch():
    fb = FourBar(2.0, 1.0, 2.0, 1.0)
    th = np.random.default_rng(1).uniform(0, 2 * np.pi, 500)
    pos = fb.node_positions(th)
    # declared "open" circuit: C to the left of B -> O4 at every sample
    B, C = pos["B"], pos["C"]
    side = (np.array([2.0, 0.0]) - B)[:, 0] * (C - B)[:, 1] - (np.array([2.0, 0.0]) - B)[:, 1] * (C - B)[:, 0]
    assert np.all(side >= -1e-9)


def test_crank_rocker_is_unchanged_by_continuity():
    fb = FourBar(4.0, 1.0, 4.0, 3.0, coupler_point=(2.0, 1.0))
    th = np.linspace(0.0, 2 * np.pi, 361)
    ordered = fb.solve(th)
    single = [fb.solve(np.array([t])).poses["rocker"][0, 2] for t in th[::30]]
    assert np.allclose(ordered.poses["rocker"][::30, 2], single, atol=1e-14)


# ---------------------------------------------------------------------------------------- size


@pytest.mark.parametrize("name", ["kangaroo", "jansen", "windup-4", "horse"])
def test_size_is_the_largest_part_diameter(name):
    mech = CATALOG[name]()
    # independent: the largest distance between two points of any part's outline (shapely geometry)
    best = 0.0
    for p in mech.parts:
        xy = np.asarray(p.outline.exterior.coords)
        d = np.hypot(xy[:, None, 0] - xy[None, :, 0], xy[:, None, 1] - xy[None, :, 1])
        best = max(best, float(d.max()))
    assert mech.size == pytest.approx(best, rel=2e-3)


@pytest.mark.parametrize(
    "start, stop, n",
    [(0.0, 2 * np.pi, 73), (np.pi, 3 * np.pi, 73), (4.0, 4.0 + 2 * np.pi, 73), (2 * np.pi, 0.0, 361), (0.0, -2 * np.pi, 361)],
)
def test_parallelogram_is_a_parallelogram_whatever_sample_the_motion_starts_from(start, stop, n):
    # the circuit is declared with the crank at pi/2 and carried from there, so the assembly does not
    # depend on the phase or the direction of the driver (a singular first sample included)
    fb = FourBar(3.0, 1.5, 3.0, 1.5)
    pos = fb.node_positions(np.linspace(start, stop, n))
    assert np.hypot(*(pos["C"] - pos["B"] - np.array([3.0, 0.0])).T).max() < 1e-9


def test_size_does_not_depend_on_the_driver_phase():
    # (outline widths follow the box the nodes sweep over a cycle, sampled at 721 driver values)
    sizes = [FourBar(4.0, 1.0, 4.0, 3.0, coupler_point=(5.5, -2.0), phase=p).size for p in (0.0, 0.1, 1.0, 2.0)]
    assert max(sizes) - min(sizes) < 1e-6 * sizes[0]  # was 0.1 % with the outline sized at the first pose


def test_a_node_no_link_holds_is_refused():
    from planar.linkages import RRP

    # P is placed 1.5 from T, but no link carries both: nothing would hold that distance
    nodes = [Fixed("O", (0, 0)), Fixed("G1", (2, -1)), Fixed("G2", (4, -1)), Crank("T", "O", 0.5), RRP("P", "T", 1.5, "G1", "G2")]
    links = [Link("crank", ("O", "T")), Link("plunger", ("P",), guide=("G1", "G2"))]
    with pytest.raises(InputError, match=r"nodes.P .*a link carrying 'P' with 'T'"):
        Linkage("pump", nodes, links)
    Linkage("pump", nodes, links + [Link("rod", ("T", "P"))])  # with the rod it builds


def test_a_point_named_like_a_part_is_refused():
    with pytest.raises(InputError, match="points"):
        Linkage(
            "l",
            [Fixed("O", (0, 0)), Fixed("Q", (3, 0)), Crank("A", "O", 1.0), RRR("B", "A", 3.0, "Q", 2.0)],
            [Link("crank", ("O", "A")), Link("coupler", ("A", "B")), Link("rocker", ("Q", "B"))],
            points={"coupler": "B"},
        )


def test_parallelogram_path_that_starts_past_a_flat_position_stays_a_parallelogram():
    # no singular sample inside the path: the circuit still comes from the reference (crank at pi/2)
    fb = FourBar(3.0, 1.5, 3.0, 1.5)
    th = np.linspace(3.5, 6.0, 100)
    m = fb.solve(th)
    assert np.abs(wrap_angle(m.poses["coupler"][:, 2])).max() < 1e-9  # the coupler stays parallel to the ground
    assert np.abs(wrap_angle(m.poses["rocker"][:, 2] - th)).max() < 1e-9
