"""Tab-and-slot joints of the pieces standing perpendicular to a toy's xy stack (planar.fabrication.tabs), read back.

The cut files are read by ezdxf and svgelements (tests/fabcheck.py); shapely measures them.  Each
part's contours are taken back to its own frame through the nesting's placement, then to the world
through the assembled toy's pose (the mechanism's own motion), where a tab and its slot must meet.
"""

from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np
import pytest
from fabcheck import dxf_cut_polygons, svg_closed_polygons
from shapely import affinity
from shapely.geometry import LineString, box

from planar.app.export import write_outputs
from planar.cli.main import main
from planar.fabrication.build import _fab_mechanism, build
from planar.fabrication.parts import FabSettings
from planar.scene.load import load_scene

GALLERY = Path(__file__).resolve().parents[2] / "gallery"


@pytest.fixture(scope="module")
def bunny(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("bunny")
    scene = load_scene(GALLERY / "bunny.toml")
    fab = build(scene, FabSettings.from_spec(scene.spec.fabrication))
    write_outputs(fab, dxf=tmp / "b.dxf", svg=tmp / "b.svg", bom=tmp / "b.csv")
    mech = _fab_mechanism(scene.mechanism)
    motion = mech.run(samples_per_cycle=24)
    k = int(np.flatnonzero(motion.valid)[0])
    pose = {n: motion.poses[n][k] for n in motion.poses}
    fab.test_motion = motion  # type: ignore[attr-defined]
    fab.test_mech = mech  # type: ignore[attr-defined]
    return fab, tmp, pose


def _inverse(poly, placed):
    a, dx, dy = placed
    c, s = math.cos(a), math.sin(a)
    return affinity.affine_transform(poly, [c, s, -s, c, -(c * dx + s * dy), -(-s * dx + c * dy)])


def _pose(poly, q, u):
    c, s = math.cos(q[2]), math.sin(q[2])
    return affinity.affine_transform(poly, [c, -s, s, c, q[0] * u, q[1] * u])


def _part_contours(polys, pc):
    """The file's outer contour of laid-out part ``pc`` (the one whose area matches, nearest its centre) and
    the inner contours inside it, both in the part's own frame."""
    from planar.fabrication.sheet import cut_polygon

    ref = cut_polygon(pc.outer)
    outer = min((p for p in polys if abs(p.area - ref.area) < 0.02 * ref.area), key=lambda p: p.centroid.distance(ref.centroid))
    inner = [p for p in polys if p is not outer and outer.contains(p)]
    return _inverse(outer, pc.placed), [_inverse(p, pc.placed) for p in inner]


def _rects(polys):
    """Rectangular cuts (area equal to their minimum rotated rectangle's): the tab slots."""
    return [p for p in polys if abs(p.minimum_rotated_rectangle.area - p.area) < 1e-6 * max(p.area, 1.0)]


def _sides(r):
    xy = np.asarray(r.minimum_rotated_rectangle.exterior.coords)[:4]
    e1, e2 = xy[1] - xy[0], xy[2] - xy[1]
    a, b = float(np.hypot(*e1)), float(np.hypot(*e2))
    long = e1 if a >= b else e2
    return max(a, b), min(a, b), math.atan2(long[1], long[0])


@pytest.mark.slow
@pytest.mark.parametrize("reader", ["dxf", "svg"])
def test_slots_and_tabs_meet_in_the_assembled_pose(bunny, reader):
    fab, tmp, pose = bunny
    s = fab.settings
    u, t, k = s.unit_mm, s.thickness_mm, s.kerf
    polys = dxf_cut_polygons(tmp / "b.dxf") if reader == "dxf" else svg_closed_polygons(tmp / "b.svg")
    by = {pc.name: pc for pc in fab.layout.parts}
    assert {jn.piece for jn in fab.joins} == {"frame.xz", "s2.driver", "frame.yz.s1.follower"}
    assert {jn.piece: jn.base for jn in fab.joins}["s2.driver"] == "s0.follower+s1.driver"  # the slider's body
    bottoms = []
    for jn in fab.joins:
        plane = jn.plane
        # --- the xy piece's slots, from the file, in the world
        _, inner = _part_contours(polys, by[jn.base])
        slots = [_pose(r, pose[jn.base], u) for r in _rects(inner)]
        # a slot of this joint: on the line where the piece's plane meets the xy plane (y = at for xz, x = at)
        across = 1 if plane == "xz" else 0
        mine = [r for r in slots if abs(r.centroid.coords[0][across] - jn.at) < 1.0]
        assert len(mine) == len(jn.spans) >= 2
        # --- the perpendicular piece's tabs, from the file, in its plane's world coordinates (u, z)
        outer, _ = _part_contours(polys, by[jn.piece])
        body = _pose(outer, pose[jn.piece], u)
        x0, z0, x1, z1 = body.bounds
        flip = jn.side > 0  # measure as if the piece lay below the stack (its tabs up)
        if flip:
            body = affinity.scale(body, 1.0, -1.0, origin=(0, 0))
            x0, z0, x1, z1 = body.bounds
        tabs = body.intersection(box(x0 - 1, z1 - 0.5 * t, x1 + 1, z1 + 1))
        tabs = sorted(getattr(tabs, "geoms", [tabs]), key=lambda g: g.bounds[0])
        assert len(tabs) == len(mine)
        # the edge the tabs stand on: the outline's top just beside a tab (grown by the kerf's half)
        beside = []
        for tab in tabs:
            for x in (tab.bounds[0] - 0.3, tab.bounds[2] + 0.3):
                cut = body.intersection(LineString([(x, z0 - 1), (x, z1 + 1)]))
                if not cut.is_empty and cut.bounds[3] < z1 - 0.5 * t:
                    beside.append(cut.bounds[3])
        edge = max(beside)
        assert abs((z1 - edge) - t) < 2e-3  # each tab is one sheet thickness long (nominal)
        face = edge - k / 2  # nominal: where the piece meets the xy piece's face
        bottoms.append((jn.base, -face if flip else face))
        for tab, slot in zip(tabs, sorted(mine, key=lambda r: r.centroid.coords[0][1 - across])):
            # the tab: 2 t wide and t long, nominal (the file's outline is grown by the kerf's half)
            tw = tab.bounds[2] - tab.bounds[0] - k
            assert abs(tw - 2 * t) < 2e-3
            # the slot: the sheet's thickness plus the clearance wide, the tab's width plus the clearance
            # long (nominal: the file's cut is shrunk by the kerf's half on every side), along the line
            length, width, ang = _sides(slot)
            assert abs(width + k - (t + s.clearance)) < 2e-3, (jn.letter, width)
            assert abs(length + k - (tw + s.clearance)) < 2e-3, (jn.letter, length)
            assert abs(math.sin(ang - (0.0 if plane == "xz" else math.pi / 2))) < 1e-6
            # on the intersection line, and where the tab is: their centres along the line agree
            assert abs(slot.centroid.coords[0][across] - jn.at) < 2e-3
            assert abs(slot.centroid.coords[0][1 - across] - tab.centroid.x) < 2e-3
    # the stack: each tab runs through its xy piece's layer (the lower faces one layer apart)
    layers = fab.assembly.layers
    base0 = {b: z - layers[b] * t for b, z in bottoms}  # pieces below the stack stand on their lower faces
    assert max(base0.values()) - min(base0.values()) < 2e-3, bottoms
    # the xz planes: one sheet thickness apart in the xz layer order
    xz = {jn.piece: jn.at for jn in fab.joins if jn.plane == "xz"}
    assert abs((xz["s2.driver"] - xz["frame.xz"]) - (layers["s2.driver"] - layers["frame.xz"]) * t) < 1e-9


@pytest.mark.slow
def test_walls_nesting_and_bom(bunny):
    fab, tmp, _ = bunny
    s = fab.settings
    polys = dxf_cut_polygons(tmp / "b.dxf")
    sheet = box(0, 0, *s.sheet)
    outers = []
    for pc in fab.layout.parts:
        outer, inner = _part_contours(polys, pc)
        outers.append(_inverse(outer, (-pc.placed[0], 0, 0)))  # any frame: only the overlaps below matter
        # every cut keeps min_wall to the outline and to every other cut (nominal: the file's gaps less the kerf)
        for i, a in enumerate(inner):
            assert outer.exterior.distance(a) - s.kerf >= s.min_wall - 5e-3, (pc.name, a.bounds)
            for b in inner[i + 1 :]:
                assert a.distance(b) - s.kerf >= s.min_wall - 5e-3, (pc.name, a.bounds, b.bounds)
    # nested: every outline on the sheet, none overlapping (the file's own contours)
    files = [p for p in polys if not any(q is not p and q.contains(p) for q in polys)]
    assert len(files) == len(fab.layout.parts)
    assert all(sheet.contains(p) for p in files)
    for i, a in enumerate(files):
        for b in files[i + 1 :]:
            assert a.intersection(b).area < 1e-6
    # the BOM says which tabs go into which slots
    rows = [r for r in csv.DictReader((tmp / "b.csv").open()) if r["item"] == "tabs"]
    assert {(r["id"], r["joins"]) for r in rows} == {(jn.letter, f"{jn.piece} -> {jn.base}") for jn in fab.joins}
    for r, jn in zip(rows, fab.joins):
        assert int(r["qty"]) == len(jn.spans)
        assert r["size_mm"] == f"{2 * s.thickness_mm:g} x {s.thickness_mm:g}"


def test_a_joint_without_room_is_refused(tmp_path, capsys):
    # #9's bracket on a 9 mm sheet: its tabs would be 18 mm wide, no room for two beside the pin's way
    text = (GALLERY / "windup-09.toml").read_text().replace("unit_mm = 100.0", "unit_mm = 100.0\nthickness_mm = 9.0")
    scene = tmp_path / "thick.toml"
    scene.write_text(text)
    out = tmp_path / "p.dxf"
    assert main(["export", str(scene), "-o", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "cannot be tab-joined" in err[0] and "frame.yz.follower" in err[0], err
    assert not out.exists()


def test_no_joint_without_an_xy_stack():
    # #8 alone moves wholly in xz: nothing stands perpendicular to anything, nothing is tabbed
    scene = load_scene(GALLERY / "windup-08.toml")
    fab = build(scene, FabSettings.from_spec(scene.spec.fabrication))
    assert fab.joins == []


def test_pieces_standing_perpendicular_pass_through_other_layers_clear(bunny):
    """Swept through the cycle, each perpendicular piece (the file's outline) meets no other xy piece's material
    (the file's outline less its cuts) in that piece's layer: travel slots let the #8 plate and the #9 pin by."""
    fab, tmp, _ = bunny
    s = fab.settings
    u, t = s.unit_mm, s.thickness_mm
    polys = dxf_cut_polygons(tmp / "b.dxf")
    by = {pc.name: pc for pc in fab.layout.parts}
    m, mech = fab.test_motion, fab.test_mech
    ok = np.flatnonzero(m.valid)
    plane = {p.name: p.plane for p in mech.parts}
    touching = {frozenset((j.a, j.b)) for j in mech.joints}
    base = {jn.piece: jn.base for jn in fab.joins}
    solid = {}
    for name, pc in by.items():
        if plane.get(name) == "xy":
            outer, inner = _part_contours(polys, pc)
            solid[name] = outer.difference(shapely_union(inner))
    assert set(fab.planes) >= {"s2.driver", "s1.follower", "frame.xz", "s2.follower"}
    crossed = set()
    for n, at in fab.planes.items():
        outer, _ = _part_contours(polys, by[n])
        for r, mat in solid.items():
            if base.get(n) == r or frozenset((n, r)) in touching:
                continue
            lz = fab.stack_z + fab.assembly.layers[r] * t
            band = box(-1e5, lz + s.kerf, 1e5, lz + t - s.kerf)  # the file's outlines are grown by half the kerf
            for k in ok:
                got = _pose(outer, m.poses[n][k], u).intersection(band)
                if got.area <= 1e-6:
                    continue
                crossed.add((n, r))
                a, _, b, _ = got.bounds
                strip = box(a, at - t / 2, b, at + t / 2) if plane[n] == "xz" else box(at - t / 2, a, at + t / 2, b)
                q = m.poses[r][k]
                here = _pose(mat, q, u)
                assert here.intersection(strip).area < 0.5, (n, r, int(k))
    # the #8 window plate passes through the frame's layer, and the #9 pin too: both had to be let by
    assert {("s2.driver", "frame"), ("s1.follower", "frame")} <= crossed


def shapely_union(polys):
    import shapely

    return shapely.union_all(polys)
