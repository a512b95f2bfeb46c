"""N legs phased on one crankshaft (``type = "legs"``): each leg's foot against the single leg solved at its own
crank angle (a second method), on legs nobody tuned: random Jansen-like and four-bar legs, N = 2..8, random
phases, mirrored pairs."""

from __future__ import annotations

import math
import zlib

import numpy as np
import pytest
from walkers import fourbar_leg, jansen_leg

from planar.errors import InputError, SceneError
from planar.linkages import Crank, Link, Linkage, Rigid
from planar.linkages.legs import Legs
from planar.scene.load import parse_scene


def _legs(rng: np.random.Generator, kind: str, count: int, mirror: bool, phases: bool) -> Legs:
    for _ in range(50):  # a random leg that turns fully (every sample of the cycle closes)
        nodes, links = jansen_leg(rng) if kind == "jansen" else fourbar_leg(rng)
        try:
            leg = Linkage("leg", nodes, links)
        except Exception:
            continue
        if leg.run(samples_per_cycle=90).valid.all():
            break
    else:  # pragma: no cover
        raise AssertionError("no random leg turns fully")
    ph = list(rng.uniform(-math.pi, math.pi, count)) if phases else None
    return Legs("walker", nodes, links, count, ph, mirror=mirror, points={"foot": "F"})


CASES = [
    ("jansen", 2, False, True),
    ("jansen", 4, True, False),
    ("jansen", 6, True, True),
    ("fourbar", 3, False, True),
    ("fourbar", 5, False, False),
    ("fourbar", 8, True, True),
]


@pytest.mark.parametrize(
    "kind,count,mirror,phases", [c if c[1] in (3, 4) else pytest.param(*c, marks=pytest.mark.slow) for c in CASES]
)
def test_each_foot_is_the_single_leg_at_its_phase(kind, count, mirror, phases):
    rng = np.random.default_rng(zlib.crc32(f"{kind}{count}{mirror}{phases}".encode()))
    w = _legs(rng, kind, count, mirror, phases)
    crank = next(n for n in w.leg.nodes if isinstance(n, Crank))
    q = np.linspace(0.0, 2 * math.pi, 181)
    feet = w.solve(q).points
    ox = w.leg.nodes[0].xy[0]
    for i in range(count):
        got = feet[f"foot_{i + 1}"]
        if w.mirrored[i]:
            # the mirror image of the leg at crank angle pi - (q + phase + own phase)
            ref = w.leg.solve(math.pi - (q + w.phases[i] + crank.phase) - crank.phase).points["foot"]
            ref = np.c_[2 * ox - ref[:, 0], ref[:, 1]]
        else:
            ref = w.leg.solve(q + w.phases[i]).points["foot"]
        np.testing.assert_allclose(got, ref, rtol=0, atol=1e-10)


def test_default_phases_spread_evenly_and_pairs_share_an_angle():
    nodes, links = jansen_leg()
    assert np.allclose(Legs("w", nodes, links, 4).phases, [0, math.pi / 2, math.pi, 1.5 * math.pi])
    assert np.allclose(Legs("w", nodes, links, 4, mirror=True).phases, [0, 0, math.pi, math.pi])


def test_the_built_walker_moves_as_the_walker():
    """Every web turns with the crankshaft; plates stand as the ground; the legs' parts keep their poses."""
    nodes, links = jansen_leg()
    w = Legs("w", nodes, links, 4, mirror=True, points={"foot": "F"}, standoffs=[(0.0, -32.0)])
    b = w.as_built()
    q = np.linspace(0, 2 * math.pi, 37)
    mw, mb = w.solve(q), b.solve(q)
    for name in ("crank_1a", "crank_1b", "crank_4a"):
        np.testing.assert_array_equal(mb.poses[name], mw.poses["crankshaft"])
    for name in ("frame_0", "frame_4"):
        np.testing.assert_array_equal(mb.poses[name], mw.poses["ground"])
    np.testing.assert_array_equal(mb.poses["lower_3"], mw.poses["lower_3"])
    # every joint of the built walker closes along the motion (an independent residual per joint)
    for j in b.joints:
        assert np.abs(j.residual(mb.poses)).max() < 1e-9, j.name
    assert b.driver.part == "crank_1b" and sum(p.ground for p in b.parts) == 5


def test_the_built_walker_leaves_its_poses_lazy():
    """The built walker's solve hands over its poses uncomputed, as the walker's does: reading the points
    computes none of them; read, they are the walker's renamed (webs the crankshaft's, plates the ground's)."""
    nodes, links = jansen_leg()
    w = Legs("w", nodes, links, 4, mirror=True, points={"foot": "F"}, standoffs=[(0.0, -32.0)])
    b = w.as_built()
    q = np.linspace(0, 2 * math.pi, 2001)
    mw = w.solve(q)
    if "_lazy_poses" not in mw.__dict__:
        pytest.skip("the walker's own solve computes its poses at once here (no compiled kernels)")
    mb = b.solve(q)
    assert "_lazy_poses" in mb.__dict__
    np.testing.assert_array_equal(mb.points["foot_3"], mw.points["foot_3"])
    assert "_lazy_poses" in mb.__dict__  # the points are read without the poses
    assert set(mb.poses) == {p.name for p in b.parts}
    for name in ("crank_1a", "crank_2b", "crank_4a"):
        np.testing.assert_array_equal(mb.poses[name], mw.poses["crankshaft"])
    for name in ("frame_0", "frame_2", "frame_4"):
        np.testing.assert_array_equal(mb.poses[name], mw.poses["ground"])
    np.testing.assert_array_equal(mb.poses["upper_2"], mw.poses["upper_2"])


def _scene(**mech) -> dict:
    nodes = [
        {"name": "O", "kind": "fixed", "at": [0.0, 0.0]},
        {"name": "Z", "kind": "fixed", "at": [-30.0, -5.0]},
        {"name": "A", "kind": "crank", "centre": "O", "radius": 10.0},
        {"name": "B", "kind": "rrr", "a": "A", "ra": 35.0, "b": "Z", "rb": 30.0, "branch": 1},
    ]
    links = [
        {"name": "crank", "nodes": ["O", "A"]},
        {"name": "coupler", "nodes": ["A", "B"]},
        {"name": "rocker", "nodes": ["Z", "B"]},
    ]
    return {"mechanism": {"type": "legs", "nodes": nodes, "links": links, "count": 2, **mech}}


def test_bad_walkers_are_refused_by_name():
    from planar.scene.build import build_scene

    with pytest.raises(SceneError, match="count"):
        build_scene(parse_scene(_scene(count=3, mirror=True)), "w.toml")
    with pytest.raises(SceneError, match="phases"):
        build_scene(parse_scene(_scene(phases=[0.0])), "w.toml")
    with pytest.raises(SceneError, match="count"):
        parse_scene(_scene(count=0), "w.toml")
    nodes, links = jansen_leg()
    with pytest.raises(InputError, match="crank link"):
        Legs("w", [*nodes, Rigid("X", "O", "A", (5.0, 0.0))], [Link("crank", ("O", "A", "X")), *links[1:]], 2)
    assert build_scene(parse_scene(_scene(phases=[0.0, 90.0]), "w.toml")).mechanism.count == 2
