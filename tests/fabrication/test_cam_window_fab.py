"""A wind-up eccentric cam is cut so that it drives its follower (new users found both ways wrong).

- An eccentric disc that holds its axle's boss runs in its follower's window in one layer: no pin, the
  window as wide as the disc (a 3 mm pin slot was cut before, so nothing could drive the follower).
- A larger eccentricity (a toy sized for a long stroke) is a crank: its boss would sweep across the window's
  rim, so a pin at the disc's centre runs in a pin-wide slot across layers (before, the cam was moved to
  another layer with nothing joining it to the follower).
- A contact that must share a layer but whose parts overlap is refused, naming the joint.
"""

import csv

import pytest

from planar.cli.main import main


def _scene(tmp_path, params=""):
    p = tmp_path / "e1.toml"
    p.write_text(f'[mechanism]\ntype = "elemental"\nnumber = 1\n{params}\n')
    return p


def _bom(tmp_path, scene):
    out = tmp_path / "p.dxf"
    bom = tmp_path / "b.csv"
    assert main(["export", str(scene), "-o", str(out), "--bom", str(bom)]) == 0
    return list(csv.DictReader(bom.open()))


def test_an_eccentric_disc_runs_in_its_window_in_one_layer(tmp_path):
    rows = _bom(tmp_path, _scene(tmp_path))
    layer = {r["id"]: r["layer"] for r in rows if r["item"] == "part"}
    assert layer["driver"] == layer["follower"]
    assert not any("cam-window" in r["notes"] for r in rows if r["item"] == "pin")
    # the window is cut as wide as the disc: its cut (ezdxf) is wider than a pin
    import ezdxf
    from shapely.geometry import Polygon

    doc = ezdxf.readfile(tmp_path / "p.dxf")
    widths = []
    for e in doc.modelspace():
        if e.dxf.layer == "CUT_INNER" and e.dxftype() == "LWPOLYLINE":
            pts = [(p[0], p[1]) for p in e.get_points()]
            if len(pts) >= 4:
                r = Polygon(pts).minimum_rotated_rectangle
                xy = list(r.exterior.coords)
                a = ((xy[0][0] - xy[1][0]) ** 2 + (xy[0][1] - xy[1][1]) ** 2) ** 0.5
                b = ((xy[1][0] - xy[2][0]) ** 2 + (xy[1][1] - xy[2][1]) ** 2) ** 0.5
                widths.append(min(a, b))
    assert max(widths) > 10.0  # the disc's window, not a 3 mm pin slot


def test_a_large_eccentricity_is_a_pin_in_a_slot(tmp_path):
    p = tmp_path / "e2.toml"
    p.write_text('[mechanism]\ntype = "elemental"\nnumber = 2\nparams = { D_jc = [0.0, 0.11] }\n')
    rows = _bom(tmp_path, p)
    pins = [r for r in rows if r["item"] == "pin" and "cam-window" in r["notes"]]
    assert len(pins) == 1 and set(pins[0]["joins"].split(" + ")) == {"driver", "follower"}


def test_a_same_layer_contact_that_overlaps_is_refused(tmp_path):
    # the rule, through the public path: a roller larger than its cam's clearance would overlap; here the
    # check is driven directly with a contact between two parts that overlap
    from planar.app.pipeline import export_scene
    from planar.fabrication.joints import Contact, FabricationError  # noqa: F401
    from planar.fabrication.layers import plan_assembly  # noqa: F401  (the rule lives there)
    from planar.scene.load import load_scene

    scene = load_scene(_scene(tmp_path))
    import planar.fabrication.joints as fj

    orig = fj.PIN_RULES.get

    def rules(j, what):  # the axle pivot as a same-layer contact: the driver's boss overlaps the ground's
        rule = orig(j, what)
        if getattr(j, "name", "") == "axle":
            return lambda mech, jj: ([], [fj.Contact(jj.name, (jj.a, jj.b), True)])
        return rule

    fj.PIN_RULES.get = rules  # type: ignore[method-assign]
    try:
        with pytest.raises(FabricationError, match=r"joint 'axle'.*must touch.*in one layer"):
            export_scene(scene, tmp_path / "x.dxf")
    finally:
        fj.PIN_RULES.get = orig  # type: ignore[method-assign]
    assert not (tmp_path / "x.dxf").exists()
