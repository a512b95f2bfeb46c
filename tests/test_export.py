"""Laser-cut export read back: audit, units, closed contours, counts, distances, kerf, layout, SVG."""

import hashlib
import math
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import ezdxf
import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st
from shapely.geometry import Point, Polygon

from planar.catalog import CATALOG
from planar.cli import main
from planar.pipeline import export_scene, gallery_scenes
from planar.fabrication import Circle, Contour, bulge_points, hull_of_circles, layout_parts
from planar.linkages import FourBar
from planar.model import ArcSlot, Hole, Pivot, Slot
from planar.scene import load_scene

GALLERY = Path(__file__).resolve().parents[1] / "gallery"


@given(st.lists(st.tuples(st.floats(-50, 50), st.floats(-50, 50), st.floats(0.1, 20)), min_size=1, max_size=7))
@settings(max_examples=150, deadline=None)
def test_hull_of_circles_is_the_convex_hull_of_the_discs(circles):
    h = hull_of_circles(circles)
    ref = shapely.union_all([Point(x, y).buffer(r, quad_segs=128) for x, y, r in circles]).convex_hull
    if isinstance(h, Circle):
        poly = Point(h.centre).buffer(h.radius, quad_segs=128)
    else:
        poly = Polygon(bulge_points(h, math.radians(0.5)))
        # arcs run counter-clockwise (positive bulge) and meet their lines tangentially
        assert all(b >= 0 for _, _, b in h.vertices)
    assert poly.is_valid
    assert poly.hausdorff_distance(ref) < 2e-3 * max(r for _, _, r in circles) + 1e-9


def _entities_by_part(doc):
    out = {}
    for name, group in doc.groups:
        out[name] = list(group)
    return out


def _closed_polys(doc):
    return [e for e in doc.modelspace().query("LWPOLYLINE") if e.dxf.layer != "SHEET"]


def _shape(e):
    if e.dxftype() == "CIRCLE":
        return Point(e.dxf.center.x, e.dxf.center.y).buffer(e.dxf.radius, quad_segs=64)
    pts = [(x, y, b) for x, y, _, _, b in e.get_points("xyseb")]
    return Polygon(bulge_points(Contour(pts), math.radians(1.0)))


def check_dxf(path, mech, kerf, unit_mm, sheet):
    doc = ezdxf.readfile(path)
    auditor = doc.audit()
    assert not auditor.has_errors, [str(e) for e in auditor.errors]
    assert doc.dxfversion == "AC1024"  # R2010
    assert doc.header["$INSUNITS"] == 4 and doc.header["$MEASUREMENT"] == 1
    for layer in ("CUT_INNER", "CUT_OUTER", "ENGRAVE"):
        assert layer in doc.layers
    for e in _closed_polys(doc):
        assert e.closed
        pts = np.array([(x, y) for x, y, *_ in e.get_points("xyseb")])
        seg = np.hypot(*(np.roll(pts, -1, axis=0) - pts).T)
        assert seg.min() > 1e-6, "zero-length segment"
    groups = _entities_by_part(doc)
    assert len(groups) == len(mech.parts)
    W, H = sheet
    outers = []
    for part in mech.parts:
        ents = groups[part.name.replace(" ", "_")]
        outer = [e for e in ents if e.dxf.layer == "CUT_OUTER"]
        inner = [e for e in ents if e.dxf.layer == "CUT_INNER"]
        text = [e for e in ents if e.dxf.layer == "ENGRAVE"]
        assert len(outer) == 1 and len(text) == 1 and text[0].dxf.text == part.name
        assert len(inner) == len(part.features)
        assert sum(isinstance(f, Hole) for f in part.features) == sum(e.dxftype() == "CIRCLE" for e in inner)
        o = _shape(outer[0])
        for e in inner:
            assert o.contains(_shape(e)), f"{part.name}: an inner cut leaves the part"
        outers.append(o)
    # apart and on their sheets
    for i in range(len(outers)):
        for j in range(i + 1, len(outers)):
            assert outers[i].intersection(outers[j]).area < 1e-9
        k = int(outers[i].bounds[0] // (W + 20.0))
        sheet_rect = Polygon([(k * (W + 20), 0), (k * (W + 20) + W, 0), (k * (W + 20) + W, H), (k * (W + 20), H)])
        assert sheet_rect.contains(outers[i])
    return doc, groups


def test_fourbar_holes_at_the_joint_distances_and_kerf(tmp_path):
    fb = FourBar(4.0, 1.0, 4.0, 3.0, coupler_point=(2.0, 1.0))
    unit = 20.0
    lay0 = layout_parts(fb, unit_mm=unit, kerf=0.0, pin_mm=3.0, clearance=0.1, sheet=(300, 200))
    from exporters.dxf import write_dxf

    write_dxf(tmp_path / "k0.dxf", lay0)
    doc, groups = check_dxf(tmp_path / "k0.dxf", fb, 0.0, unit, (300, 200))
    # hole centre distances equal the joint distances
    expected = {"crank": 1.0, "coupler": 4.0, "rocker": 3.0, "ground": 4.0}
    for name, length in expected.items():
        cs = [e for e in groups[name] if e.dxftype() == "CIRCLE"]
        assert len(cs) == 2
        d = math.dist((cs[0].dxf.center.x, cs[0].dxf.center.y), (cs[1].dxf.center.x, cs[1].dxf.center.y))
        assert abs(d - length * unit) < 1e-6, name
        # pivot holes: pin diameter plus running clearance
        assert all(abs(2 * c.dxf.radius - 3.1) < 1e-9 for c in cs)
    # kerf: outlines grow by kerf/2, holes shrink by kerf/2; the centres stay
    kerf = 0.3
    lay1 = layout_parts(fb, unit_mm=unit, kerf=kerf, pin_mm=3.0, clearance=0.1, sheet=(300, 200))
    for p0, p1 in zip(lay0.parts, lay1.parts):
        dx = np.subtract(p1.nominal_holes[0][0], p0.nominal_holes[0][0])
        for c0, c1 in zip(p0.inner, p1.inner):
            assert abs(c0.radius - c1.radius - kerf / 2) < 1e-12
            assert np.allclose(np.add(c0.centre, dx), c1.centre, atol=1e-9)
        s0 = Polygon(bulge_points(p0.outer, math.radians(0.25))) if isinstance(p0.outer, Contour) else None
        s1 = Polygon(bulge_points(p1.outer, math.radians(0.25))) if isinstance(p1.outer, Contour) else None
        from shapely import affinity

        s1 = affinity.translate(s1, -dx[0], -dx[1])
        # the kerfed outline is the nominal one grown by kerf/2
        assert s1.hausdorff_distance(s0.buffer(kerf / 2, quad_segs=64)) < 5e-3
        assert abs(s1.area - s0.buffer(kerf / 2, quad_segs=64).area) < 1e-2 * s1.area


def test_slot_kerf_and_arc_slots():
    from planar.fabrication import part_cuts
    from planar.model import Part

    part = Part("p", ((0, 0, 1.0), (4, 0, 1.0)), (Slot((0.5, 0), (3.5, 0), 0.4), ArcSlot((2, 0), 1.0, 0.2, 2.0, 0.3)))
    a = part_cuts(part, 10.0, 0.0, 3.0, 0.0)
    b = part_cuts(part, 10.0, 0.4, 3.0, 0.0)
    for c0, c1 in zip(a.inner, b.inner):
        p0 = Polygon(bulge_points(c0, math.radians(0.25)))
        p1 = Polygon(bulge_points(c1, math.radians(0.25)))
        assert p0.is_valid and p1.is_valid
        assert p0.contains(p1)
        assert p1.hausdorff_distance(p0.buffer(-0.2, quad_segs=64)) < 5e-3
    # the straight slot's nominal width: 0.4 units at 10 mm/unit
    slot = Polygon(bulge_points(a.inner[0], math.radians(0.25)))
    assert abs(slot.area - (30 * 4 + math.pi * 2 ** 2)) < 0.05


@pytest.mark.parametrize("path", gallery_scenes(GALLERY), ids=lambda p: p.stem)
def test_every_gallery_scene_exports_valid_dxf_and_svg(tmp_path, path):
    scene = load_scene(path)
    fab = scene.spec.fabrication
    layout = export_scene(scene, tmp_path / "p.dxf", tmp_path / "p.svg")
    check_dxf(tmp_path / "p.dxf", scene.mechanism, fab.kerf_mm, fab.unit_mm, fab.sheet_mm)
    root = ET.parse(tmp_path / "p.svg").getroot()
    assert root.get("width").endswith("mm") and root.get("height").endswith("mm")
    ns = "{http://www.w3.org/2000/svg}"
    doc = ezdxf.readfile(tmp_path / "p.dxf")
    n_circles = len(doc.modelspace().query("CIRCLE"))
    n_paths = len([e for e in _closed_polys(doc)])
    assert len(root.findall(f".//{ns}circle")) == n_circles
    assert len(root.findall(f".//{ns}path")) == n_paths
    assert len(root.findall(f".//{ns}text")) == len(scene.mechanism.parts)
    for p in root.findall(f".//{ns}path"):
        assert p.get("d").rstrip().endswith("Z")


def test_export_is_reproducible_and_cli(tmp_path):
    scene = GALLERY / "jansen-leg.toml"
    for name in ("a", "b"):
        assert main(["export", str(scene), "-o", str(tmp_path / f"{name}.dxf"), "--svg", str(tmp_path / f"{name}.svg"),
                     "--kerf", "0.2", "--sheet", "250x150"]) == 0
    for ext in ("dxf", "svg"):
        assert (tmp_path / f"a.{ext}").read_bytes() == (tmp_path / f"b.{ext}").read_bytes()
    doc = ezdxf.readfile(tmp_path / "a.dxf")
    sheet = [e for e in doc.modelspace().query("LWPOLYLINE") if e.dxf.layer == "SHEET"]
    w = max(x for x, *_ in sheet[0].get_points()) - min(x for x, *_ in sheet[0].get_points())
    assert abs(w - 250) < 1e-9


def test_export_errors_are_user_errors(tmp_path):
    scene = GALLERY / "jansen-leg.toml"
    for args in (["--sheet", "30x20"], ["--sheet", "big"], ["--kerf", "-1"]):
        r = subprocess.run([sys.executable, "-m", "planar", "export", str(scene), "-o", str(tmp_path / "x.dxf"), *args],
                           capture_output=True, text=True)
        assert r.returncode == 2 and "Traceback" not in r.stderr, (args, r.stderr)
        assert not (tmp_path / "x.dxf").exists()


def test_preview_png(tmp_path):
    assert main(["export", str(GALLERY / "windup-03.toml"), "-o", str(tmp_path / "p.dxf"),
                 "--preview", str(tmp_path / "p.png")]) == 0
    from PIL import Image

    im = np.asarray(Image.open(tmp_path / "p.png").convert("RGB"))
    assert len(np.unique(im.reshape(-1, 3), axis=0)) > 3


def test_no_duplicate_cut_entities_and_jansen_link_lengths(tmp_path):
    scene = load_scene(GALLERY / "jansen-leg.toml")
    export_scene(scene, tmp_path / "j.dxf", kerf=0.0)
    doc = ezdxf.readfile(tmp_path / "j.dxf")
    seen = set()
    for e in doc.modelspace():
        if e.dxf.layer in ("CUT_INNER", "CUT_OUTER"):
            if e.dxftype() == "CIRCLE":
                key = ("C", round(e.dxf.center.x, 6), round(e.dxf.center.y, 6), round(e.dxf.radius, 6))
            else:
                key = ("P",) + tuple(round(v, 6) for p in e.get_points("xyb") for v in p)
            assert key not in seen, "duplicate cut"
            seen.add(key)
    groups = dict(doc.groups)
    # Jansen's holy numbers (unit_mm = 1): each two-hole link's hole centres are its length apart
    for name, length in {"j": 50.0, "k": 61.9, "c": 39.3, "f": 39.4, "crank": 15.0}.items():
        cs = [e for e in groups[name] if e.dxftype() == "CIRCLE"]
        d = math.dist((cs[0].dxf.center.x, cs[0].dxf.center.y), (cs[1].dxf.center.x, cs[1].dxf.center.y))
        assert abs(d - length) < 1e-6, name
    tri = sorted(math.dist((a.dxf.center.x, a.dxf.center.y), (b.dxf.center.x, b.dxf.center.y))
                 for i, a in enumerate(c for c in groups["upper"] if c.dxftype() == "CIRCLE")
                 for j, b in enumerate(c for c in groups["upper"] if c.dxftype() == "CIRCLE") if i < j)
    assert np.allclose(tri, sorted([41.5, 40.1, 55.8]), atol=1e-6)  # the ternary link Z-B-D
    # the foot F is a point of the lower link, not a joint: no hole there
    assert sum(c.dxftype() == "CIRCLE" for c in groups["lower"]) == 2
