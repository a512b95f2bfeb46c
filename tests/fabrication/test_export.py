"""Laser-cut export read back: audit, units, closed contours, counts, distances, kerf, layout, SVG."""

import math
import subprocess
import sys
from pathlib import Path

import ezdxf
import numpy as np
import pytest
import shapely
from fabcheck import dxf_cut_polygons, match_contours, svg_closed_polygons
from hypothesis import given, settings
from hypothesis import strategies as st
from shapely.geometry import Point, Polygon

from planar.app.pipeline import export_scene, gallery_scenes
from planar.cli.main import main
from planar.core.model import ArcSlot, Part, Slot
from planar.fabrication.build import build
from planar.fabrication.parts import FabSettings, part_cuts
from planar.fabrication.sheet import Circle, Contour, bulge_points, hull_of_circles
from planar.linkages import FourBar
from planar.scene.load import load_scene

GALLERY = Path(__file__).resolve().parents[2] / "gallery"


@pytest.mark.slow
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


def _shape(e):
    if e.dxftype() == "CIRCLE":
        return Point(e.dxf.center.x, e.dxf.center.y).buffer(e.dxf.radius, quad_segs=64)
    pts = [(x, y, b) for x, y, _, _, b in e.get_points("xyseb")]
    return Polygon(bulge_points(Contour(pts), math.radians(1.0)))


def check_dxf(path, n_parts, kerf, sheet, min_wall=1.5):
    """Audit, units, extents, closed contours, inner cuts inside with the wall, parts apart and on the sheet."""
    doc = ezdxf.readfile(path)
    auditor = doc.audit()
    assert not auditor.has_errors, [str(e) for e in auditor.errors]
    assert doc.dxfversion == "AC1024"  # R2010
    assert doc.header["$INSUNITS"] == 4 and doc.header["$MEASUREMENT"] == 1
    W, H = sheet
    assert tuple(doc.header["$EXTMIN"])[:2] == (0, 0) and tuple(doc.header["$EXTMAX"])[:2] == (W, H)
    for layer in ("CUT_INNER", "CUT_OUTER", "ENGRAVE"):
        assert layer in doc.layers
    assert not doc.layers.get("SHEET").dxf.plot  # the sheet's edge is reference only
    assert not doc.modelspace().query("TEXT MTEXT")  # engraving is strokes, not live text
    groups = dict(doc.groups)
    assert len(groups) == n_parts
    outers = []
    k2 = kerf / 2
    for name, ents in groups.items():
        outer = [e for e in ents if e.dxf.layer == "CUT_OUTER"]
        inner = [e for e in ents if e.dxf.layer == "CUT_INNER"]
        assert len(outer) == 1
        for e in outer + inner:
            assert e.dxftype() == "CIRCLE" or e.closed
        o = _shape(outer[0])
        nominal = o.buffer(-k2, quad_segs=64)
        for e in inner:
            cut = _shape(e).buffer(k2, quad_segs=64)
            assert o.contains(_shape(e)), f"{name}: an inner cut leaves the part"
            wall = nominal.exterior.distance(cut)
            assert wall >= min_wall - 0.01, f"{name}: {wall:.3f} mm wall"
        outers.append(o)
    sheet_rect = Polygon([(0, 0), (W, 0), (W, H), (0, H)])
    for i in range(len(outers)):
        assert sheet_rect.contains(outers[i])
        for j in range(i + 1, len(outers)):
            assert outers[i].intersection(outers[j]).area < 1e-9
    return doc, groups


def _sheets(tmp_path, stem, ext):
    one = tmp_path / f"{stem}.{ext}"
    if one.exists():
        return [one]
    return sorted(tmp_path.glob(f"{stem}-*.{ext}"), key=lambda p: int(p.stem.rsplit("-", 1)[1]))


def test_fourbar_holes_at_the_joint_distances_and_kerf():
    fb = FourBar(4.0, 1.0, 4.0, 3.0, coupler_point=(2.0, 1.0))
    s0 = FabSettings(unit_mm=20.0, kerf=0.0)
    s1 = FabSettings(unit_mm=20.0, kerf=0.3)
    from planar.fabrication.joints import pin_features

    pinned = pin_features(fb)
    for n, part in enumerate(fb.parts):
        idx = {i for p, i in pinned if p == part.name}
        a = part_cuts(part, s0, n + 1, idx)
        b = part_cuts(part, s1, n + 1, idx)
        holes = [c for c in a.inner if isinstance(c, Circle)]
        assert len(holes) == 2
        # pivot holes: pin diameter plus running clearance, at the joint distance
        assert all(abs(2 * c.radius - 3.1) < 1e-9 for c in holes)
        d = math.dist(holes[0].centre, holes[1].centre)
        length = {"crank": 1.0, "coupler": 4.0, "rocker": 3.0, "ground": 4.0}[part.name]
        assert abs(d - length * 20.0) < 1e-9
        for c0, c1 in zip(a.inner, b.inner):
            assert abs(c0.radius - c1.radius - 0.15) < 1e-12 and np.allclose(c0.centre, c1.centre)
        if isinstance(a.outer, Contour):
            s_0 = Polygon(bulge_points(a.outer, math.radians(0.25)))
            s_1 = Polygon(bulge_points(b.outer, math.radians(0.25)))
            assert s_1.hausdorff_distance(s_0.buffer(0.15, quad_segs=64)) < 5e-3


def test_slot_kerf_and_arc_slots():
    part = Part("p", ((0, 0, 1.0), (4, 0, 1.0)), (Slot((0.5, 0), (3.5, 0), 0.4), ArcSlot((2, 0), 1.0, 0.9, 2.2, 0.3)))
    a = part_cuts(part, FabSettings(unit_mm=10.0, kerf=0.0, clearance=0.0, slot_end=0.0), 1)
    b = part_cuts(part, FabSettings(unit_mm=10.0, kerf=0.4, clearance=0.0, slot_end=0.0), 1)
    for c0, c1 in zip(a.inner, b.inner):
        p0 = Polygon(bulge_points(c0, math.radians(0.25)))
        p1 = Polygon(bulge_points(c1, math.radians(0.25)))
        assert p0.is_valid and p1.is_valid and p0.contains(p1)
        assert p1.hausdorff_distance(p0.buffer(-0.2, quad_segs=64)) < 5e-3
    slot = Polygon(bulge_points(a.inner[0], math.radians(0.25)))
    assert abs(slot.area - (30 * 4 + math.pi * 2**2)) < 0.05
    # end margin: 1.5 mm past each end of the travel
    c = part_cuts(part, FabSettings(unit_mm=10.0, kerf=0.0, clearance=0.0, slot_end=1.5), 1)
    slot = Polygon(bulge_points(c.inner[0], math.radians(0.25)))
    assert abs(slot.area - (33 * 4 + math.pi * 2**2)) < 0.05


@pytest.mark.slow
@pytest.mark.parametrize("path", gallery_scenes(GALLERY), ids=lambda p: p.stem)
def test_every_gallery_scene_exports_checked_files(tmp_path, path):
    scene = load_scene(path)
    fab = export_scene(scene, tmp_path / "p.dxf", tmp_path / "p.svg", bom=tmp_path / "b.csv", assembly=tmp_path / "a.svg")
    s = fab.settings
    dxfs = _sheets(tmp_path, "p", "dxf")
    assert len(dxfs) == fab.layout.sheets == len(_sheets(tmp_path, "p", "svg"))
    for k, d in enumerate(dxfs):
        check_dxf(d, len(fab.layout.on_sheet(k)), s.kerf, s.sheet, s.min_wall)
    # the SVG cuts what the DXF cuts: every contour read by svgelements vs ezdxf, within 0.1 % of its area
    for d, v in zip(dxfs, _sheets(tmp_path, "p", "svg")):
        a, b = svg_closed_polygons(v), dxf_cut_polygons(d)
        assert all(p.area > 0 for p in a + b)
        rel = match_contours(a, b)
        assert rel and max(rel) <= 1e-3, f"{v.name}: worst contour differs by {max(rel):.3%} of its area"
    # labels: single-line strokes at least min_label tall, or none (noted)
    for p in fab.layout.parts:
        assert p.label == "" or p.label_height >= s.min_label - 1e-9
    # parts on one layer never overlap at any instant of the cycle (shapely, from the parts' own outlines)
    cut = fab.mechanism  # as cut: a wind-up toy's assembly, polygons cut as parts of their own
    motion = cut.run(samples_per_cycle=24)
    from shapely import affinity

    asm = fab.assembly
    for a_name, b_name in [(a, b) for a in asm.layers for b in asm.layers if a < b]:
        if asm.layers[a_name] is None or asm.layers[a_name] != asm.layers[b_name]:
            continue
        if asm.plane[a_name] != asm.plane[b_name]:
            continue
        for i in np.flatnonzero(motion.valid):
            ga, gb = [
                affinity.affine_transform(
                    fab.own[n],
                    [math.cos(q[2]), -math.sin(q[2]), math.sin(q[2]), math.cos(q[2]), q[0] * s.unit_mm, q[1] * s.unit_mm],
                )
                for n, q in ((a_name, motion.poses[a_name][i]), (b_name, motion.poses[b_name][i]))
            ]
            assert ga.intersection(gb).area < 1.0, (a_name, b_name, i)
    # the motor sits under the ground plate it is screwed to: no part of that plate's plane lies below it (a
    # walker's other frame plates stand between its slabs)
    motor_plates = [g for g in fab.grounds if any(pp.shaft and g in pp.parts for pp in asm.pins)]
    for g in motor_plates or fab.grounds:
        if asm.layers.get(g) is not None:
            same_plane = [n for n, v in asm.layers.items() if v is not None and asm.plane[n] == asm.plane[g]]
            assert asm.layers[g] == min(asm.layers[n] for n in same_plane), (g, asm.layers)
    # BOM: pins as long as the layers they span plus each end's washer (DIN 125 M3: 0.5 mm) and e-clip (DIN 6799
    # 2.3: 0.6 mm) and 0.5 mm past the clip's groove, a rod cut to the next 0.5 mm
    import csv

    rows = list(csv.DictReader((tmp_path / "b.csv").open()))
    parts = [r for r in rows if r["item"] == "part"]
    assert {r["id"] for r in parts} == {p.name for p in cut.parts}
    for r in rows:
        if r["item"] == "pin":
            lo, hi = map(int, r["layer"].split("-"))
            d, length = map(float, r["size_mm"].split(" x "))
            rod = math.ceil((s.thickness_mm * (hi - lo + 1) + 2 * (0.5 + 0.6 + 0.5)) * 2 - 1e-9) / 2
            assert d == s.pin_mm and abs(length - rod) < 1e-9
    # the assembly drawing reads back with svgelements: one filled shape per layered part
    from svgelements import SVG
    from svgelements import Path as SPath

    shapes = [e for e in SVG.parse(str(tmp_path / "a.svg")).elements() if isinstance(e, SPath)]
    assert len(shapes) == sum(1 for v in asm.layers.values() if v is not None)


@pytest.mark.slow
def test_svg_conventions(tmp_path):
    from svgelements import SVG, Rect, Text
    from svgelements import Circle as SCircle
    from svgelements import Path as SPath

    export_scene(load_scene(GALLERY / "jansen-leg.toml"), svg=tmp_path / "j.svg")
    svg = SVG.parse(str(tmp_path / "j.svg"))
    els = [e for e in svg.elements() if isinstance(e, (SPath, SCircle, Rect, Text))]
    assert not [e for e in els if isinstance(e, (Rect, Text))]  # no sheet outline, no live text
    colours = {str(e.stroke) for e in els}
    assert colours == {"#ff0000", "#0000ff"}
    widths = {round(e.stroke_width / (svg.width / svg.viewbox.width), 6) for e in els}
    assert widths == {0.025}


@pytest.mark.slow
def test_export_is_reproducible_and_cli(tmp_path):
    scene = GALLERY / "jansen-leg.toml"
    for name in ("a", "b"):
        assert (
            main(
                [
                    "export",
                    str(scene),
                    "-o",
                    str(tmp_path / f"{name}.dxf"),
                    "--svg",
                    str(tmp_path / f"{name}.svg"),
                    "--kerf",
                    "0.2",
                    "--sheet",
                    "250x150",
                ]
            )
            == 0
        )
    for ext in ("dxf", "svg"):
        assert (tmp_path / f"a.{ext}").read_bytes() == (tmp_path / f"b.{ext}").read_bytes()
    doc = ezdxf.readfile(tmp_path / "a.dxf")
    sheet = [e for e in doc.modelspace().query("LWPOLYLINE") if e.dxf.layer == "SHEET"]
    w = max(x for x, *_ in sheet[0].get_points()) - min(x for x, *_ in sheet[0].get_points())
    assert abs(w - 250) < 1e-9


def _scene_file(tmp_path, src, extra):
    text = (GALLERY / src).read_text()
    p = tmp_path / "s.toml"
    p.write_text(
        text.replace("[fabrication]\n", "[fabrication]\n" + extra + "\n")
        if "[fabrication]" in text
        else text + "\n[fabrication]\n" + extra + "\n"
    )
    return p


@pytest.mark.slow
def test_export_errors_are_user_errors(tmp_path, capsys):
    scene = GALLERY / "jansen-leg.toml"
    cases = [
        (scene, ["--sheet", "30x20"]),
        (scene, ["--sheet", "big"]),
        (scene, ["--kerf", "-1"]),
        (scene, ["--sheet", "infx200"]),
        (_scene_file(tmp_path, "paddle-boat.toml", "widen = false"), []),
        (_scene_file(tmp_path, "jansen-leg.toml", "pin_diameter_mm = 0.3\nkerf_mm = 0.5"), []),
    ]
    for sc, args in cases:
        assert main(["export", str(sc), "-o", str(tmp_path / "x.dxf"), "--bom", str(tmp_path / "x.csv"), *args]) == 2
        err = capsys.readouterr().err
        assert len(err.strip().splitlines()) == 1 and err.startswith("planar: error:"), (args, err)
        assert not (tmp_path / "x.dxf").exists() and not (tmp_path / "x.csv").exists()
    # no traceback from the command itself either
    r = subprocess.run(
        [sys.executable, "-m", "planar", "export", str(scene), "-o", str(tmp_path / "x.dxf"), "--sheet", "infx200"],
        capture_output=True,
        text=True,
    )
    assert r.returncode == 2 and "Traceback" not in r.stderr and len(r.stderr.strip().splitlines()) == 1


@pytest.mark.slow
def test_narrow_links_are_widened_or_refused(tmp_path):
    scene = load_scene(GALLERY / "paddle-boat.toml")
    fab = build(scene, FabSettings.from_spec(scene.spec.fabrication))
    assert any("crank: widened" in n for n in fab.notes)
    r = subprocess.run(
        [
            sys.executable,
            "-m",
            "planar",
            "export",
            str(_scene_file(tmp_path, "paddle-boat.toml", "widen = false")),
            "-o",
            str(tmp_path / "x.dxf"),
        ],
        capture_output=True,
        text=True,
    )
    assert r.returncode == 2 and "wall" in r.stderr and "min_wall_mm" in r.stderr


@pytest.mark.slow
def test_thickness_and_pin_diameter_have_effect(tmp_path):
    import csv

    out = {}
    for t in (3, 6):
        sc = load_scene(_scene_file(tmp_path, "jansen-leg.toml", f"thickness_mm = {t}"))
        export_scene(sc, tmp_path / f"t{t}.dxf", bom=tmp_path / f"t{t}.csv")
        out[t] = [r for r in csv.DictReader((tmp_path / f"t{t}.csv").open()) if r["item"] == "pin"]
    assert (tmp_path / "t3.dxf").read_bytes() != (tmp_path / "t6.dxf").read_bytes()
    for a, b in zip(out[3], out[6]):
        lo, hi = map(int, a["layer"].split("-"))
        la, lb = (float(r["size_mm"].split(" x ")[1]) for r in (a, b))
        assert abs((lb - la) - 3 * (hi - lo + 1)) < 1e-9
    # a wind-up toy's pins follow pin_diameter_mm: the follower's pin hole and the ground's slot
    sc = load_scene(_scene_file(tmp_path, "windup-01.toml", "pin_diameter_mm = 4.0\nkerf_mm = 0.0"))
    fab = export_scene(sc, tmp_path / "w.dxf")
    follower = next(p for p in fab.layout.parts if p.name == "follower")
    radii = sorted(round(c.radius, 9) for c in follower.inner if isinstance(c, Circle))
    assert radii == [2.05, 2.05]


def test_slots_leave_margin_past_the_pins_travel():
    from planar.fabrication.joints import pin_features
    from planar.fabrication.parts import _features

    for name in ("windup-01", "windup-04", "slider-crank", "windup-07"):
        scene = load_scene(GALLERY / f"{name}.toml")
        mech = scene.mechanism
        s = FabSettings.from_spec(scene.spec.fabrication)
        motion = mech.run(samples_per_cycle=90)
        for j in mech.joints:
            if type(j).__name__ not in ("PinInSlot", "Slide"):
                continue
            pin_part, slot_part = j.b, j.a  # the slot on a, the pin on b (the joint protocol)
            pin = j.pin if hasattr(j, "pin") else j.anchor
            part = mech.part(slot_part)
            feats = _features(part, s, {i for p, i in pin_features(mech) if p == slot_part}, None, None)
            slot = next(f for f in feats if f.kind == "slot")
            # pin centre over the cycle, in the slot part's frame, mm
            from planar.core.geometry import poses_apply

            w = poses_apply(motion.poses[pin_part], pin)
            q = motion.poses[slot_part]
            c, sn = np.cos(q[:, 2]), np.sin(q[:, 2])
            d = w - q[:, :2]
            local = np.c_[c * d[:, 0] + sn * d[:, 1], -sn * d[:, 0] + c * d[:, 1]] * s.unit_mm
            a, b = np.array(slot.a), np.array(slot.b)
            e = (b - a) / np.hypot(*(b - a))
            t = (local - a) @ e
            L = float(np.hypot(*(b - a)))
            assert t.min() >= s.slot_end - 1e-6 and t.max() <= L - s.slot_end + 1e-6, (name, j.name, t.min(), L - t.max())


@pytest.mark.slow
def test_nesting_horse_on_two_sheets_and_several_files(tmp_path):
    scene = load_scene(GALLERY / "horse.toml")
    # the Horse is cut as its assembly (one frame spanning both cam trees, across the shaft from each other,
    # merged parts): two 400 x 300 mm sheets at most
    fab = export_scene(scene, tmp_path / "h.dxf", sheet=(400, 300))
    n0 = fab.layout.sheets
    assert n0 in (1, 2) and ((tmp_path / "h.dxf").exists() or (tmp_path / "h-1.dxf").exists())
    area = sum(
        Polygon(bulge_points(p.outer, math.radians(1))).area if isinstance(p.outer, Contour) else math.pi * p.outer.radius**2
        for p in fab.layout.parts
    )
    assert abs(sum(fab.layout.utilisation) - area / (400 * 300)) < 1e-3
    fab = export_scene(scene, tmp_path / "s.dxf", tmp_path / "s.svg", sheet=(320, 200))
    n = fab.layout.sheets
    assert n >= 2
    assert [p.name for p in _sheets(tmp_path, "s", "dxf")] == [f"s-{k + 1}.dxf" for k in range(n)]
    assert not (tmp_path / "s.dxf").exists()
    for k, p in enumerate(_sheets(tmp_path, "s", "dxf")):
        check_dxf(p, len(fab.layout.on_sheet(k)), fab.settings.kerf, (320, 200))


@pytest.mark.slow
def test_drive_and_mounting_holes(tmp_path):
    scene = load_scene(GALLERY / "jansen-leg.toml")
    export_scene(scene, tmp_path / "j.dxf", kerf=0.0)
    groups = dict(ezdxf.readfile(tmp_path / "j.dxf").groups)
    d = [e for e in groups["crank"] if e.dxf.layer == "CUT_INNER" and e.dxftype() == "LWPOLYLINE"]
    assert len(d) == 1  # the D-shaped shaft hole
    poly = _shape(d[0])
    r, f = 1.55, 1.05  # 3 mm shaft, 2.5 mm across the flat, each plus the 0.1 mm clearance
    alpha = math.acos(f / r)
    assert abs(poly.area - (r * r * (math.pi - alpha) + f * math.sqrt(r * r - f * f))) < 1e-3
    radii = sorted(round(e.dxf.radius, 6) for e in groups["ground"] if e.dxftype() == "CIRCLE")
    assert radii.count(1.6) == 2 and radii.count(0.9) == 2  # M3 mounting holes (3.2 as cut), motor screws


@pytest.mark.slow
def test_kerf_test_piece(tmp_path):
    assert main(["export", str(GALLERY / "jansen-leg.toml"), "--kerf", "0.2", "--kerf-test", str(tmp_path / "k.dxf")]) == 0
    doc = ezdxf.readfile(tmp_path / "k.dxf")
    outer = [e for e in doc.modelspace() if e.dxf.layer == "CUT_OUTER"]
    x0, _y0, x1, _y1 = _shape(outer[0]).bounds
    assert abs((x1 - x0) - 20.2) < 1e-9  # the square grows by half the kerf per side
    assert doc.modelspace().query("CIRCLE")[0].dxf.radius == pytest.approx(4.9)
    assert len([e for e in doc.modelspace() if e.dxf.layer == "ENGRAVE"]) > 3


@pytest.mark.slow
def test_preview_png(tmp_path):
    assert (
        main(["export", str(GALLERY / "windup-03.toml"), "-o", str(tmp_path / "p.dxf"), "--preview", str(tmp_path / "p.png")])
        == 0
    )
    from PIL import Image

    im = np.asarray(Image.open(tmp_path / "p.png").convert("RGB"))
    assert len(np.unique(im.reshape(-1, 3), axis=0)) > 3


@pytest.mark.slow
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

    def centres(name):
        return [(e.dxf.center.x, e.dxf.center.y) for e in groups[name] if e.dxftype() == "CIRCLE"]

    # Jansen's holy numbers (unit_mm = 1): each two-hole link's hole centres are its length apart
    for name, length in {"j": 50.0, "k": 61.9, "c": 39.3, "f": 39.4}.items():
        cs = centres(name)
        assert len(cs) == 2
        assert abs(math.dist(*cs) - length) < 1e-6, name
    tri = sorted(math.dist(a, b) for i, a in enumerate(centres("upper")) for j, b in enumerate(centres("upper")) if i < j)
    assert np.allclose(tri, sorted([41.5, 40.1, 55.8]), atol=1e-6)  # the ternary link Z-B-D
    assert len(centres("lower")) == 2  # the foot F is a point of the lower link, not a joint


def test_holes_running_into_each_other_are_refused(tmp_path, capsys):
    # at 1 mm per unit a 2.5 mm crank's D-shaped drive hole and its pin hole overlap: widening the outline
    # cannot mend that, so the export stops with one line naming the part and the two cuts
    scene = tmp_path / "small.toml"
    scene.write_text(
        '[mechanism]\ntype = "fourbar"\nground = 8.0\ncrank = 2.5\ncoupler = 7.0\nrocker = 6.0\n[fabrication]\nunit_mm = 1.0\n'
    )
    out = tmp_path / "p.dxf"
    assert main(["export", str(scene), "-o", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "of material between its" in err[0] and "min_wall_mm" in err[0], err
    assert not out.exists()
    # and the geometry: pin hole (3 mm pin + 0.1 clearance) 2.5 mm from the drive hole's centre overlaps it
    from planar.fabrication.parts import FabSettings

    st_ = FabSettings()
    assert (st_.pin_mm + st_.clearance) / 2 + st_.shaft_mm / 2 > 2.5
