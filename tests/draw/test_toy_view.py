"""Issue 11 item 2: toys drawn assembled; #8's tab in its tapered window; #6/#9 with the pin's oval and contact."""

from __future__ import annotations

import math

import numpy as np
import pytest

from planar.core.geometry import poses_apply
from planar.draw.frames import Renderer, Style
from planar.windup.chain import bunny, horse
from planar.windup.mechanisms import elemental


def _place(g, p):
    from shapely import affinity

    c, s = math.cos(p[2]), math.sin(p[2])
    return affinity.affine_transform(g, [c, -s, s, c, p[0], p[1]])


def test_horse_is_drawn_as_its_assembly_and_exploded_on_request():
    from planar.toys.assembly import toy_assembly

    toy = horse(rate=math.pi)
    motion = toy.run(samples_per_cycle=8)
    r = Renderer(toy, motion, Style(width=96, height=72))
    assert {p.name for p in r.mech.parts} == {p.name for p in toy_assembly(toy).parts}
    from planar.draw.toyview import layer_order
    from planar.physics.toy import plane_mechanism

    layers = layer_order(plane_mechanism(toy_assembly(toy)))
    drawn = [layers[p.name] for p in r.mech.parts]
    assert drawn == sorted(drawn) and len(set(drawn)) > 1  # depth order: bottom layer first
    img = r.frame(3)
    assert img.size == (96, 72)
    ex = Renderer(toy, motion, Style(width=96, height=72, exploded=True))
    assert {p.name for p in ex.mech.parts} == {p.name for p in toy.parts}


def test_bunny_panels_beside_the_front_view_never_a_line():
    from planar.draw.toyview import assembled

    toy = bunny(rate=math.pi)
    view, vm, marks = assembled(toy, toy.run(samples_per_cycle=12))
    boxes = {}
    for plane, names in (
        ("xy", ("cam.left", "s0.follower+s1.driver")),
        ("xz", ("frame.xz", "s2.driver", "s2.follower")),
        ("yz", ("s1.follower",)),
    ):
        pts = np.concatenate(
            [poses_apply(vm.poses[n], np.asarray(view.part(n).outline.exterior.coords)).reshape(-1, 2) for n in names]
        )
        lo, hi = pts.min(0), pts.max(0)
        assert (hi - lo).min() > 0.05 * view.size, (plane, hi - lo)  # drawn in its own plane, not a line
        boxes[plane] = (lo, hi)
    # the panels do not overlap: each lies to the right of the one before
    assert boxes["xy"][1][0] < boxes["xz"][0][0] and boxes["xz"][1][0] < boxes["yz"][0][0]
    assert len(marks.rings) == 1 and len(marks.dots) == 1 and len(marks.lines) == 1  # #9's oval, contact; #8 taper


def test_eight_tab_stands_in_its_tapered_window():
    from planar.core.outlines import feature_shape
    from planar.draw.toyview import assembled

    m = elemental(8)
    mo = m.run(samples_per_cycle=12)
    tab, drv = m.part("follower"), m.part("driver")
    win = next(f for f in drv.features if type(f).__name__ == "Slot")
    from shapely.geometry import box

    for i in range(len(mo)):
        T = _place(tab.outline, mo.poses["follower"][i])
        W = _place(feature_shape(win), mo.poses["driver"][i])

        # the window plate crosses the tab at the contact's height: there the tab's section lies in the opening
        a = poses_apply(mo.poses["driver"][i], m.joints[2].centre)
        band = T.intersection(box(-10, a[1] - 0.005, 10, a[1] + 0.005))
        assert band.area > 0 and band.difference(W).area < 1e-2 * band.area, i  # the tilted face over the band: a sliver
    _, _vm, marks = assembled(m, mo)
    ((taper, _),) = marks.lines
    w = taper[0]
    # straight contact edge, far side D_w1 at the bottom and D_w2 at the top
    P = m.world
    assert abs(abs(w[0, 0] - w[3, 0]) - P.D_w1) < 1e-12 and abs(abs(w[1, 0] - w[2, 0]) - P.D_w2) < 1e-12


@pytest.mark.parametrize("number", [6, 9])
def test_spatial_pin_oval_touches_the_edge(number):
    from shapely.geometry import LineString, Polygon

    from planar.draw.toyview import assembled

    m = elemental(number)
    mo = m.run(samples_per_cycle=12)
    _, _, marks = assembled(m, mo)
    ((ring, _),) = marks.rings
    ((contact, _),) = marks.dots
    j = next(j for j in m.joints if type(j).__name__ == "SkewContact")
    for i in range(len(mo)):
        e0 = poses_apply(mo.poses["driver"][i], j.edge_point)
        a = mo.poses["driver"][i, 2] + math.atan2(j.edge_dir[1], j.edge_dir[0])
        edge = LineString([e0 - 5 * np.array([math.cos(a), math.sin(a)]), e0 + 5 * np.array([math.cos(a), math.sin(a)])])
        oval = Polygon(ring[i])
        # shapely: the edge touches the oval (distance ~0) without cutting into it, at the contact point
        assert edge.distance(oval) < 1.5 * j.radius * (1 - math.cos(math.pi / 48))  # the 48-gon's sagitta
        assert edge.intersection(oval).length < 2e-2 * j.radius
        assert edge.distance(__import__("shapely").Point(contact[i])) < 1e-12
        # and the contact point lies on the ellipse through the sampled ring (centre and semi-axes from the ring)
        c = ring[i].mean(0)
        ry = (ring[i][:, 1] - c[1]).max()
        rx = (ring[i][:, 0] - c[0]).max()
        q = ((contact[i] - c) / (rx, ry)) ** 2
        assert abs(q.sum() - 1) < 1e-9
