"""Profile cams: motion laws, exact outlines, curvature, pressure angle, checks, scenes.

Independent checks: derivatives against finite differences, the outline
against shapely (the roller circle tangent to the outline polygon, the knife
on it, the flat face its support line), curvature against the circle through
three neighbouring points, the pressure angle against the normal shapely's
nearest point gives, the DXF's cam contour read back with ezdxf.
"""

import math

import numpy as np
import pytest

from planar.cams import CamError, CamProfile, FollowerGeometry, Program, Segment
from planar.cams.laws import LAWS
from planar.core.model import joint_residuals
from planar.errors import InputError, SceneError
from planar.scene.load import build_scene, parse_scene

d = math.radians


def rdrd(lift):
    """Rise, dwell, return, dwell."""
    return Program(
        [
            Segment("polynomial-345", d(100), lift),
            Segment("dwell", d(50)),
            Segment("cycloidal", d(130), -lift),
            Segment("dwell", d(80)),
        ]
    )


FOLLOWERS = {
    "roller-translating": (FollowerGeometry("roller", "translating", 0.3, axis=(0.2, 1.0), offset=0.25), 0.5),
    "knife-translating": (FollowerGeometry("knife", "translating", offset=-0.2), 0.5),
    "flat-translating": (FollowerGeometry("flat", "translating", axis=(1.0, 0.3)), 0.5),
    "roller-oscillating": (FollowerGeometry("roller", "oscillating", 0.25, pivot=(2.2, 1.1), arm=2.0), d(14)),
    "knife-oscillating": (FollowerGeometry("knife", "oscillating", pivot=(2.2, 1.1), arm=2.0, branch=-1), d(14)),
    "flat-oscillating": (FollowerGeometry("flat", "oscillating", pivot=(2.6, 0.4), arm=2.0, face_offset=0.3), d(10)),
}


def profile(name):
    geom, lift = FOLLOWERS[name]
    return CamProfile(rdrd(lift), 1.2, geom)


def _rot(theta, v):
    c, s = np.cos(theta), np.sin(theta)
    return np.stack([c * v[:, 0] - s * v[:, 1], s * v[:, 0] + c * v[:, 1]], -1)


# ------------------------------------------------------------------ laws and programs


@pytest.mark.parametrize("name", sorted(set(LAWS) - {"dwell"}))
def test_law_ends_and_derivatives_match_finite_differences(name):
    law = LAWS[name]
    u = np.linspace(0.0, 1.0, 2001)
    h = u[1] - u[0]
    assert law.y(np.array([0.0, 1.0])) == pytest.approx([0.0, 1.0], abs=1e-15)
    assert np.abs(np.gradient(law.y(u), h)[1:-1] - law.dy(u)[1:-1]).max() < 1e-5
    assert np.abs(np.gradient(law.dy(u), h)[1:-1] - law.d2y(u)[1:-1]).max() < 1e-4
    ends = law.dy(np.array([0.0, 1.0]))
    assert np.abs(ends).max() < 1e-12  # every law starts and stops at rest
    if name in ("cycloidal", "polynomial-345"):
        assert np.abs(law.d2y(np.array([0.0, 1.0]))).max() < 1e-12  # and without an acceleration jump


def test_program_derivatives_and_continuity():
    prog = Program(
        [
            Segment("cycloidal", d(120), 0.5),
            Segment("dwell", d(60)),
            Segment("harmonic", d(90), -0.2),
            Segment("polynomial-345", d(90), -0.3),
        ]
    )
    th = np.linspace(-2 * np.pi, 4 * np.pi, 60001)  # three turns: the program repeats
    s, v, a = prog.evaluate(th)
    h = th[1] - th[0]
    interior = np.ones_like(th, bool)
    for b in np.concatenate([prog.starts, [2 * np.pi]]):
        interior &= np.abs(np.angle(np.exp(1j * (th - b)))) > 3 * h
    assert np.abs(np.gradient(s, h) - v)[interior].max() < 1e-6
    assert np.abs(np.gradient(v, h) - a)[interior].max() < 1e-4
    assert np.abs(np.diff(s)).max() < 1e-3  # no jump at a segment boundary
    assert s.min() > -1e-12 and s.max() == pytest.approx(0.5)
    assert prog.evaluate([d(120)])[0][0] == pytest.approx(0.5)
    # just below a whole turn (np.mod rounds -1e-17 to 2 pi itself): the end of the last segment, not past it
    assert np.abs(np.concatenate(prog.evaluate([-1e-17, 2 * np.pi, -1e-300]))).max() < 1e-12


@pytest.mark.parametrize(
    "segments, words",
    [
        ([("cycloidal", 120, 0.5), ("cycloidal", 120, -0.5)], ["one turn", "240"]),
        ([("cycloidal", 180, 0.5), ("cycloidal", 180, -0.4)], ["summing to 0", "0.1"]),
        ([("cycloidal", 180, -0.5), ("cycloidal", 180, 0.5)], ["[0].lift", "inside the base circle"]),
        ([("dwell", 180, 0.5), ("cycloidal", 180, -0.5)], ["[0].lift", "0 for a dwell"]),
        ([("spline", 180, 0.5), ("cycloidal", 180, -0.5)], ["Segment.law", "'spline'"]),  # refused by the segment
    ],
)
def test_bad_programs_name_the_segment(segments, words):
    with pytest.raises(InputError) as e:
        Program([Segment(law, d(a), lift) for law, a, lift in segments], "mechanism.segments")
    assert all(w in str(e.value) for w in words), str(e.value)


# ------------------------------------------------------------------ outline geometry


@pytest.mark.parametrize("name", sorted(FOLLOWERS))
def test_follower_touches_the_cut_outline_at_every_sample(name):
    from shapely.geometry import LineString, Point, Polygon

    cp = profile(name)
    cp.check(d(60))
    poly, sag = cp.outline_polygon()
    assert sag < 2e-5
    P = Polygon(poly)
    assert P.is_valid and P.exterior.is_ccw
    th = np.linspace(0, 2 * np.pi, 181)[:-1]
    tol = 3e-5  # the polygon's chords lie within ~1e-5 of the exact curve
    if cp.follower.kind != "flat":
        W, _, _ = cp.follower_point(th)
        q = _rot(-th, W)  # the roller centre / knife tip in the cam's frame
        dist = np.array([P.exterior.distance(Point(x)) for x in q])
        assert np.abs(dist - cp.rr).max() < tol
        if cp.rr > 0:
            assert not any(P.contains(Point(x)) for x in q)
            # the roller never cuts into the cam: no outline vertex inside its circle
            r = np.hypot(poly[:, None, 0] - q[None, :, 0], poly[:, None, 1] - q[None, :, 1]).min(0)
            assert r.min() > cp.rr - tol
    else:
        F = cp.face(th)
        n = np.stack([np.cos(F["beta"]), np.sin(F["beta"])], -1)
        sup = (poly @ n.T).max(0)  # the polygon's support in the face's direction is the face line
        assert np.abs(sup - F["h"]).max() < tol
        x, _, _ = cp.envelope(th)
        assert max(P.exterior.distance(Point(p)) for p in x) < tol
        # the contact lies on the face: face segments cover it (the face's own reference line)
        for k in range(0, len(th), 20):
            c = F["h"][k] * n[k]
            t = np.array([-n[k, 1], n[k, 0]])
            face = LineString([c - 10 * t, c + 10 * t])
            assert face.distance(Point(x[k])) < 1e-9


@pytest.mark.parametrize("name", sorted(FOLLOWERS))
def test_pitch_and_envelope_derivatives_against_differences(name):
    cp = profile(name)
    th = np.linspace(0.01, 2 * np.pi - 0.01, 4001)
    h = th[1] - th[0]
    keep = np.ones_like(th, bool)
    keep[:2] = keep[-2:] = False  # np.gradient is one-sided at the ends
    for b in cp.program.starts:
        keep &= np.abs(th - b) > 3 * h
    if cp.follower.kind != "flat":
        P, P1, P2 = cp.pitch(th)
        assert np.abs(np.gradient(P, h, axis=0) - P1)[keep].max() < 1e-5
        assert np.abs(np.gradient(P1, h, axis=0) - P2)[keep].max() < 1e-3
    else:
        F = cp.face(th)
        for k, k1 in (("h", "h1"), ("h1", "h2"), ("b1", "b2")):
            assert np.abs(np.gradient(F[k], h) - F[k1])[keep].max() < 1e-3, k
        assert np.abs(np.gradient(np.unwrap(F["beta"]), h) - F["b1"])[keep].max() < 1e-6


@pytest.mark.parametrize("name", sorted(FOLLOWERS))
def test_radius_of_curvature_against_three_point_circles(name):
    cp = profile(name)
    th = np.linspace(0, 2 * np.pi, 20001)[:-1]
    pts = cp.pitch(th)[0] if cp.follower.kind != "flat" else cp.envelope(th)[0]
    a, b, c = pts[:-2], pts[1:-1], pts[2:]
    ab, bc, ca = (np.hypot(*(b - a).T), np.hypot(*(c - b).T), np.hypot(*(a - c).T))
    cross = (b - a)[:, 0] * (c - a)[:, 1] - (b - a)[:, 1] * (c - a)[:, 0]
    R = ab * bc * ca / (2 * np.abs(cross))
    rho = np.abs(cp.radius_of_curvature(th[1:-1]))
    keep = (rho < 50) & np.all(np.abs(th[1:-1, None] - cp.program.starts[None, :]) > 2e-3, axis=1)
    assert np.abs(R[keep] / rho[keep] - 1).max() < 1e-3


@pytest.mark.parametrize("name", sorted(FOLLOWERS))
def test_pressure_angle_against_the_outline_normal_found_by_shapely(name):
    from shapely.geometry import Point, Polygon
    from shapely.ops import nearest_points

    cp = profile(name)
    P = Polygon(cp.outline_polygon(sag=1e-9)[0])  # 16384 points: chords turn by < 1e-3 rad
    th = np.linspace(0, 2 * np.pi, 37)[:-1]
    phi = cp.pressure_angle(th)
    if cp.follower.kind == "flat":
        if cp.follower.motion == "translating":
            assert np.abs(phi).max() < 1e-9  # a face square to its stroke
        return
    W, _, _ = cp.follower_point(th)
    q = _rot(-th, W)
    for k in range(len(th)):
        near = np.asarray(nearest_points(P.exterior, Point(q[k]))[0].coords[0])
        nrm = q[k] - near if cp.rr > 0 else None
        if nrm is None:  # knife: the outline's normal from the polygon's neighbouring vertices
            poly = np.asarray(P.exterior.coords)
            j = int(np.argmin(np.hypot(*(poly - q[k]).T)))
            t = poly[(j + 1) % (len(poly) - 1)] - poly[j - 1]
            nrm = np.array([t[1], -t[0]])
        nw = _rot(np.array([th[k]]), (nrm / np.hypot(*nrm))[None])[0]
        if cp.follower.motion == "translating":
            move = np.asarray(cp.follower.axis, float) / np.hypot(*cp.follower.axis)
        else:
            psi = cp.follower_output(th[k : k + 1])[0][0]
            move = np.array([-math.sin(psi), math.cos(psi)])
        expect = math.acos(min(1.0, abs(float(nw @ move))))
        assert abs(expect - phi[k]) < 1e-3, (k, expect, phi[k])


def test_translating_pressure_angle_is_the_textbook_formula():
    # zero offset: tan(phi) = |ds/dtheta| / (sqrt(Rp^2) + s)
    cp = CamProfile(rdrd(0.5), 1.2, FollowerGeometry("roller", "translating", 0.3))
    th = np.linspace(0, 2 * np.pi, 721)
    s, v, _ = cp.program.evaluate(th)
    assert np.abs(np.tan(cp.pressure_angle(th)) - np.abs(v) / (1.5 + s)).max() < 1e-12


# ------------------------------------------------------------------ checks: loud, not wrong


def test_undercut_is_refused_naming_the_segment():
    prog = Program(
        [Segment("cycloidal", d(50), 1.0), Segment("cycloidal", d(50), -1.0), Segment("dwell", d(260))], "mechanism.segments"
    )
    cp = CamProfile(prog, 0.6, FollowerGeometry("roller", "translating", 0.8))
    with pytest.raises(CamError) as e:
        cp.check(d(80))
    msg = str(e.value)
    assert msg.startswith("mechanism.segments[") and "undercut" in msg and "roller radius 0.8" in msg
    assert "\n" not in msg
    # the figure it names is the pitch curve's least convex radius there (three-point circle check above)
    k = int(msg.split("segments[")[1][0])
    th = prog.starts[k] + prog.segments[k].angle * np.linspace(0, 1, 721)
    rho = cp.radius_of_curvature(th)
    assert f"{rho[rho > 0].min():.4g}" in msg


def test_flat_face_cusp_and_pressure_angle_are_refused():
    prog = Program(
        [Segment("harmonic", d(50), 1.0), Segment("harmonic", d(50), -1.0), Segment("dwell", d(260))], "mechanism.segments"
    )
    with pytest.raises(CamError, match=r"mechanism\.segments\[\d\] \(harmonic .*cusp"):
        CamProfile(prog, 0.5, FollowerGeometry("flat", "translating")).check(d(30))
    with pytest.raises(CamError, match=r"segments\[0\] \(harmonic rise over 0-50 deg\): pressure angle"):
        CamProfile(prog, 2.0, FollowerGeometry("roller", "translating", 0.2)).check(d(30))


# ------------------------------------------------------------------ scenes


def cam_scene(follower, segments=None, **extra):
    segs = segments or [
        {"law": "cycloidal", "angle": 120, "lift": 0.5},
        {"law": "dwell", "angle": 60},
        {"law": "polynomial-345", "angle": 120, "lift": -0.5},
        {"law": "dwell", "angle": 60},
    ]
    mech = {"type": "cam", "base_radius": 1.5, "follower": follower, "segments": segs, **extra}
    return build_scene(
        parse_scene({"angle_unit": "deg", "mechanism": mech, "driver": {"samples_per_cycle": 90}}, "c.toml"), "c.toml"
    )


@pytest.mark.parametrize(
    "follower",
    [
        {"kind": "roller", "roller_radius": 0.4},
        {"kind": "knife", "offset": 0.3},
        {"kind": "flat", "axis": [0.0, -1.0]},
    ],
)
def test_scene_cam_joints_close_and_the_contact_residual_sees_a_gap(follower):
    sc = cam_scene(follower)
    m = sc.mechanism
    mo = sc.motion()
    assert mo.valid.all()
    res = joint_residuals(m, mo)
    assert max(float(r.max()) for r in res.values()) <= 1e-9 * m.size
    # the follower lifted by delta along its axis: the contact residual is the gap, delta times the cosine
    # of the pressure angle (Newton finds the nearest point of the exact curve)
    delta = 1e-3
    moved = dict(mo.poses)
    ax = np.asarray(follower.get("axis", (0.0, 1.0)), float)
    for part in ("follower", "roller"):
        if part in moved:
            moved[part] = moved[part] + np.r_[delta * ax, 0.0]
    gap = next(j for j in m.joints if j.name == "contact").residual(moved)
    phi = m.profile.pressure_angle(mo.driver)
    assert np.abs(gap - delta * np.cos(phi)).max() < 1e-7


def test_scene_errors_are_one_line_naming_the_field():
    with pytest.raises(SceneError, match=r"c\.toml: mechanism\.follower: .*roller_radius"):
        cam_scene({"kind": "roller"})
    with pytest.raises(SceneError, match=r"c\.toml: mechanism: mechanism\.segments\[\d\] \(.*\): undercut"):
        cam_scene(
            {"kind": "roller", "roller_radius": 1.4},
            [
                {"law": "cycloidal", "angle": 40, "lift": 1.0},
                {"law": "cycloidal", "angle": 40, "lift": -1.0},
                {"law": "dwell", "angle": 280},
            ],
            max_pressure_angle=89.0,
        )
    with pytest.raises(SceneError, match="pivot and arm are for an oscillating follower"):
        cam_scene({"kind": "knife", "arm": 2.0})


def test_oscillating_follower_drives_a_lever_through_a_coupler():
    # the gallery's structure in small: the arm (input crank) drives a rocker through a coupler
    sc = cam_scene(
        {"kind": "roller", "roller_radius": 0.4, "motion": "oscillating", "pivot": [3.0, 1.5], "arm": 2.6, "branch": -1},
        [{"law": "cycloidal", "angle": 180, "lift": 12}, {"law": "cycloidal", "angle": 180, "lift": -12}],
        nodes=[
            {"name": "E", "kind": "rigid", "a": "pivot", "b": "tip", "local": [-1.0, 0.0]},
            {"name": "Q", "kind": "fixed", "at": [4.5, 3.0]},
            {"name": "H", "kind": "rrr", "a": "E", "ra": 2.0, "b": "Q", "rb": 1.0},
        ],
        links=[
            {"name": "follower", "nodes": ["E"]},
            {"name": "coupler", "nodes": ["E", "H"]},
            {"name": "lever", "nodes": ["Q", "H"]},
        ],
        points={"H": "H"},
    )
    m = sc.mechanism
    mo = sc.motion()
    assert mo.valid.all()
    # the arm turns by the program exactly, and the lever's pin keeps its distances (an independent closure)
    psi = m.profile.follower_output(mo.driver)[0]
    tip = mo.poses["roller"][:, :2]
    assert np.abs(np.angle(np.exp(1j * (np.arctan2(tip[:, 1] - 1.5, tip[:, 0] - 3.0) - psi)))).max() < 1e-12
    E = np.array([3.0, 1.5]) - 1.0 * np.column_stack([np.cos(psi), np.sin(psi)])
    H = mo.points["H"]
    assert np.abs(np.hypot(*(H - E).T) - 2.0).max() < 1e-9
    assert np.abs(np.hypot(*(H - [4.5, 3.0]).T) - 1.0).max() < 1e-9
    assert np.ptp(mo.poses["lever"][:, 2]) > math.radians(5)


# ------------------------------------------------------------------ the gallery's automaton

GALLERY = __import__("pathlib").Path(__file__).resolve().parents[2] / "gallery"


def test_gallery_cam_scene_compare_is_refused_with_the_reason(capsys):
    from planar.cli.main import main

    assert main(["compare", str(GALLERY / "cam-automaton.toml")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "'cam-profile'" in err and "joint 'contact'" in err and "Traceback" not in err


@pytest.mark.slow
def test_gallery_cam_dxf_cuts_the_exact_outline(tmp_path):
    import ezdxf
    from shapely.geometry import Polygon

    from planar.app.pipeline import export_scene
    from planar.scene.load import load_scene

    sc = load_scene(GALLERY / "cam-automaton.toml")
    fab = export_scene(sc, tmp_path / "p.dxf")
    s = fab.settings
    cp = sc.mechanism.profile
    exact = Polygon(cp.outline_polygon(sag=1e-9)[0] * s.unit_mm).buffer(s.kerf / 2, join_style="mitre")
    doc = ezdxf.readfile(tmp_path / "p.dxf")
    polys = [e for e in doc.modelspace().query("LWPOLYLINE") if len(e) > 500]
    assert len(polys) == 2  # the cam's outline and the roller's (an explicit 720-gon)
    cam = max((Polygon([(x, y) for x, y, *_ in e.get_points()]) for e in polys), key=lambda p: p.area)
    assert abs(cam.area / exact.area - 1) < 1e-5
    assert abs(cam.length / exact.exterior.length - 1) < 1e-4
    # the shaft hole (a D) lies inside the cam, at its centre of rotation: the hole's centre is where the
    # outline's distance to the centre matches the analytic radii (least and largest)
    r_exact = np.hypot(*cp.outline_polygon()[0].T) * s.unit_mm
    from ezdxf import path as dxfpath

    centres = []
    for e in doc.modelspace().query("LWPOLYLINE"):
        if len(e) > 4 or not e.closed:  # open polylines are engraved strokes
            continue
        hole = Polygon([(v.x, v.y) for v in dxfpath.make_path(e).flattening(0.01)])
        if cam.contains(hole):
            centres.append(np.asarray(hole.centroid.coords[0]))
    assert len(centres) == 1  # one D-hole in the cam
    ring = np.asarray(cam.exterior.coords)
    r = np.hypot(*(ring - centres[0]).T)
    # a D's vertices average off its centre by under half a millimetre; the radii follow the outline
    assert abs(r.min() - r_exact.min()) < 0.6 and abs(r.max() - r_exact.max()) < 0.6


def test_gallery_cam_scene_joints_close():
    from planar.scene.load import load_scene

    sc = load_scene(GALLERY / "cam-automaton.toml")
    mo = sc.mechanism.run(samples_per_cycle=720)
    assert mo.valid.all()
    res = joint_residuals(sc.mechanism, mo)
    assert max(float(r.max()) for r in res.values()) <= 1e-9 * sc.mechanism.size
    assert math.degrees(sc.mechanism.report.max_pressure_angle) < 45.0


def test_follower_motion_in_time_matches_differences_of_the_solved_poses():
    # the solved arm angle over time (from the Motion, through the linkage) against the law's derivatives
    sc = cam_scene(
        {"kind": "roller", "roller_radius": 0.4, "motion": "oscillating", "pivot": [3.0, 1.5], "arm": 2.6, "branch": -1},
        [
            {"law": "harmonic", "angle": 150, "lift": 10},
            {"law": "dwell", "angle": 30},
            {"law": "polynomial-345", "angle": 150, "lift": -10},
            {"law": "dwell", "angle": 30},
        ],
    )
    m = sc.mechanism
    t = np.linspace(0.0, 1.0, 20001)
    mo = m.solve(m.driver.value(t), t=t)
    psi = np.unwrap(mo.poses["follower"][:, 2])
    fm = m.follower_motion(mo.driver)
    h = t[1] - t[0]
    keep = np.ones_like(t, bool)
    keep[:2] = keep[-2:] = False
    for b in np.radians([0.0, 150.0, 180.0, 330.0, 360.0]):
        keep &= np.abs(mo.driver - b) > 4 * h * m.driver.rate
    assert np.abs(np.angle(np.exp(1j * (psi - fm["q"])))).max() < 1e-12
    assert np.abs(np.gradient(psi, h) - fm["dq_dt"])[keep].max() < 1e-6
    assert np.abs(np.gradient(np.gradient(psi, h), h) - fm["d2q_dt2"])[keep].max() < 1e-3 * np.abs(fm["d2q_dt2"]).max()


def test_export_notes_report_the_checked_figures(tmp_path):
    sc = cam_scene({"kind": "roller", "roller_radius": 0.4})
    notes = sc.mechanism.design_notes
    r = sc.mechanism.report
    assert f"{math.degrees(r.max_pressure_angle):.3g} deg" in notes[0] and "mechanism.segments[" in notes[0]
    assert f"{r.min_radius:.4g}" in notes[1] and "roller radius 0.4" in notes[1]


@pytest.mark.parametrize("motion", ["translating", "oscillating"])
def test_roller_rolls_on_the_cam_without_slipping(motion):
    # the roller's material point at the contact moves with the cam's material point there: differences
    # of the solved poses (the roller's angle comes from the pitch curve's arc length, Gauss-Legendre)
    from planar.core.geometry import poses_apply

    fol = {"kind": "roller", "roller_radius": 0.4}
    if motion == "oscillating":
        fol.update(motion="oscillating", pivot=[3.0, 1.5], arm=2.6, branch=-1)
    sc = cam_scene(
        fol,
        [
            {"law": "cycloidal", "angle": 150, "lift": 12 if motion == "oscillating" else 0.5},
            {"law": "dwell", "angle": 30},
            {"law": "harmonic", "angle": 150, "lift": -12 if motion == "oscillating" else -0.5},
            {"law": "dwell", "angle": 30},
        ],
    )
    m = sc.mechanism
    th = np.linspace(0.05, 4 * np.pi, 97)  # two turns: the arc length carries on
    h = 1e-6
    c = _rot(th, m.profile.outline(th)[0])  # the contact in the world
    rel = []
    for part in ("roller", "cam"):
        pose = m.solve(th).poses[part]
        c_local = np.array([poses_apply(_inv(pz), cz) for pz, cz in zip(pose, c)])
        plus = m.solve(th + h).poses[part]
        minus = m.solve(th - h).poses[part]
        v = (
            np.array([poses_apply(p, x) for p, x in zip(plus, c_local)])
            - np.array([poses_apply(p, x) for p, x in zip(minus, c_local)])
        ) / (2 * h)
        rel.append(v)
    slip = np.hypot(*(rel[0] - rel[1]).T)
    assert slip.max() < 1e-6 * np.hypot(*rel[1].T).max()
    spin = np.ptp(np.unwrap(m.solve(th).poses["roller"][:, 2]))
    assert spin > 2 * 2 * np.pi  # it does turn (a roller keeping its arm's angle would fail the slip check)


def _inv(pose):
    x, y, a = pose
    c, s = math.cos(a), math.sin(a)
    return np.array([-(c * x + s * y), s * x - c * y, -a])


def test_a_follower_that_cuts_into_the_cam_is_refused():
    # a knife on a straight arm nearly along the cam's tangent: its flank crosses the outline (shapely, in
    # the cam's frame); the roller on the same arm sits in another layer and is accepted
    segs = [
        {"law": "harmonic", "angle": 150, "lift": 15},
        {"law": "dwell", "angle": 30},
        {"law": "cycloidal", "angle": 150, "lift": -15},
        {"law": "dwell", "angle": 30},
    ]
    arm = {"motion": "oscillating", "pivot": [2.6, 1.2], "arm": 2.2}
    with pytest.raises(
        SceneError,
        match=r"mechanism\.follower: the follower's outline overlaps the cam by .* at cam "
        r"angle \d+ deg",
    ):
        cam_scene({"kind": "knife", **arm}, segs)
    assert cam_scene({"kind": "roller", "roller_radius": 0.3, **arm}, segs).motion().valid.all()
    # a flat face whose pivot boss would stand proud of the face: the face_offset it needs is named
    with pytest.raises(SceneError, match=r"follower\.face_offset: .* a face_offset of at least"):
        cam_scene(
            {"kind": "flat", "motion": "oscillating", "pivot": [2.6, 0.4], "arm": 2.0, "face_offset": 0.0},
            [
                {"law": "harmonic", "angle": 150, "lift": 10},
                {"law": "dwell", "angle": 30},
                {"law": "cycloidal", "angle": 150, "lift": -10},
                {"law": "dwell", "angle": 30},
            ],
        )
