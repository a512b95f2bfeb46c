"""Issue 26: numbers float64 cannot hold faithfully are refused where a linkage or mechanism is built from Python.

The rule is the scene's (:func:`planar.core.limits.check_scale`): a coordinate or a length whose float64 spacing
is coarser than 1e-9 of the assembly's smallest length.  A big but consistent linkage passes at any scale; the
same linkage moved far from the origin, or one link of 1e300 beside 1-unit links, is refused naming the node and
field.  Before, a far ``Fixed`` node was refused as "not a rigid link" (a reason it does not have), an RRR of
1e300 as "its pivots coincide", and a part or a slot at 1e300 was accepted.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import planar as L
from planar.errors import InputError


def _linkage(rng: np.random.Generator, s: float, shift: float = 0.0, placement: float = 0.0) -> L.Linkage:
    """A random Grashof crank-rocker with a coupler point, every length times ``s``, its fixed nodes moved by
    ``shift`` (model units, both axes) and the whole placed at ``(placement, -placement)``."""
    while True:
        a = 1.0
        b, c, d = rng.uniform(1.5, 5.0, 3)
        lengths = sorted([a, b, c, d])
        if lengths[0] == a and lengths[0] + lengths[3] < lengths[1] + lengths[2] - 0.2:
            break
    phi = rng.uniform(-math.pi, math.pi)
    o = np.array([shift, shift]) + s * rng.uniform(-3.0, 3.0, 2)
    dd = o + s * d * np.array([math.cos(phi), math.sin(phi)])
    nodes = [
        L.Fixed("O", (float(o[0]), float(o[1]))),
        L.Crank("A", "O", s * a),
        L.Fixed("D", (float(dd[0]), float(dd[1]))),
        L.RRR("B", "A", s * b, "D", s * c),
        L.Rigid("P", "A", "B", tuple(s * rng.uniform(-2.0, 2.0, 2))),
    ]
    links = [L.Link("crank", ("O", "A")), L.Link("coupler", ("A", "B", "P")), L.Link("rocker", ("D", "B"))]
    return L.Linkage("l", nodes, links, points={"tip": "P"}, placement=(placement, -placement, 0.3))


@pytest.mark.parametrize("seed", range(3))
def test_random_linkages_pass_at_any_scale_and_solve_scaled(seed: int) -> None:
    """1e-6 ... 1e6: built, solved, every sample valid, and the motion is the unit linkage's, scaled."""
    q = np.linspace(0.0, 2 * np.pi, 16)
    ref = _linkage(np.random.default_rng(seed), 1.0).solve(q)
    assert ref.valid.all()
    for s in (1e-6, 3.7e-3, 1.0, 41.0, 1e6):
        m = _linkage(np.random.default_rng(seed), s).solve(q)
        assert m.valid.all()
        np.testing.assert_allclose(m.points["tip"] / s, ref.points["tip"], rtol=0, atol=1e-8)
    # moved within what float64 resolves on its smallest length (the crank): still built
    _linkage(np.random.default_rng(seed), 1e-3, shift=1e-3 * 1e6)


@pytest.mark.parametrize("seed", range(3))
def test_random_linkages_far_from_the_origin_are_refused_naming_the_node(seed: int) -> None:
    for s in (1e-6, 1.0, 1e6):
        with pytest.raises(InputError, match=r"l\.nodes\.[OD]\.xy = .*float64 resolves .* smallest length .*nodes\.A\.radius"):
            _linkage(np.random.default_rng(seed), s, shift=s * 1e8)
        with pytest.raises(InputError, match=r"l\.placement = .*float64 resolves"):
            _linkage(np.random.default_rng(seed), s, placement=s * 1e9)


def test_a_big_but_consistent_linkage_is_fine() -> None:
    """Every length 1e12 and its ground pivots 1e12 from the origin: the smallest length is 1e12 too."""
    s = 1e12
    leg = L.FourBar(4.0 * s, 1.0 * s, 4.0 * s, 3.0 * s, coupler_point=(5.5 * s, -2.0 * s), placement=(3 * s, 2 * s, 0.0))
    assert leg.run(36).valid.all()


def test_the_brief_s_cases_are_refused_naming_the_field() -> None:
    with pytest.raises(InputError, match=r"nodes\.B\.ra = 1e\+300: .*float64 resolves .*nodes\.B\.rb"):
        L.RRR("B", "A", 1e300, "C", 1.0)
    with pytest.raises(InputError, match=r"Part 'p'\.hull\[0\] = \(1e\+300, 0, 1\): .*float64 resolves"):
        L.Part("p", hull=((1e300, 0, 1),))
    with pytest.raises(InputError, match=r"PinInSlot 'j'\.end = \(1e\+300, 0\): .*float64 resolves"):
        L.PinInSlot("j", "p", "q", start=(0, 0), end=(1e300, 0), pin=(0, 0), width=0.1)
    # a slot with no width has no length of its own: the mechanism it joins is checked
    slot = L.PinInSlot("j", "p", "q", start=(0, 0), end=(1e300, 0), pin=(0, 0))
    p, q = L.Part("p", hull=((0, 0, 1),)), L.Part("q", hull=((0, 0, 1),))
    with pytest.raises(InputError, match=r"m\.joints\.j\.end = \(1e\+300, 0\): .*mechanism's smallest length 1"):
        L.Mechanism("m", [p, q], [slot], L.Driver("q"))
    nodes = [L.Fixed("O", (1e300, 0.0)), L.Crank("A", "O", 1.0), L.Fixed("D", (4.0, 0.0)), L.RRR("B", "A", 4.0, "D", 3.0)]
    links = [L.Link("crank", ("O", "A")), L.Link("coupler", ("A", "B")), L.Link("rocker", ("D", "B"))]
    with pytest.raises(InputError, match=r"l\.nodes\.O\.xy = \(1e\+300, 0\.0\): .*float64 resolves"):
        L.Linkage("l", nodes, links)
    with pytest.raises(InputError, match=r"fourbar\.nodes\.P\.local = \(1e\+300, -2\.0\)"):
        L.FourBar(4.0, 1.0, 4.0, 3.0, coupler_point=(1e300, -2.0))
    # a part of radius 1e300 at 1e300 is consistent on its own
    assert L.Part("p", hull=((1e300, 0, 1e300),)).hull[0][2] == 1e300


def _four_bar(ground: str) -> L.Linkage:
    nodes = [L.Fixed("O", (0.0, 0.0)), L.Crank("A", "O", 1.0), L.Fixed("D", (4.0, 0.0)), L.RRR("B", "A", 4.0, "D", 3.0)]
    links = [L.Link("crank", ("O", "A")), L.Link("coupler", ("A", "B")), L.Link("rocker", ("D", "B"))]
    return L.Linkage("l", nodes, links, ground=ground)


def test_ground_names_the_ground_part_not_a_node() -> None:
    """``ground`` names the ground part: a new name is the part the fixed nodes make (accepted, and it is the
    part that never moves); a link carrying a moving node is refused (before, its motion was marked valid with
    the crank's joint 1.7 units open)."""
    lk = _four_bar("nothere")
    assert (lk.parts[0].name, lk.parts[0].ground) == ("nothere", True)
    m = lk.run(36)
    assert m.valid.all()
    assert np.ptp(m.poses["nothere"], axis=0).max() == 0.0
    residuals = L.joint_residuals(lk, m)
    assert max(float(np.max(r)) for r in residuals.values()) < 1e-9
    with pytest.raises(InputError, match=r"l\.ground = 'crank': .*link 'crank' carries node 'A', which moves"):
        _four_bar("crank")
