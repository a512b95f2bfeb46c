"""Issue 15: ``synth motion`` order defect, dead zones, exit codes and input errors."""

from __future__ import annotations

import json

import numpy as np
import pytest

from planar.cli.main import main
from planar.synth.motion import NoMotionDesign, burmester, crank_order

# the trial's order/p8.csv (degrees): the old design met them at theta 0.112, 0.05, 2.99, -0.988
P8 = "x,y,angle\n-0.3941,0.1539,25.257\n0.7391,-0.0688,38.802\n1.6195,0.3673,57.393\n2.8448,0.1321,67.301\n"
# the trial's order/p0.csv: the old design's crank rocked across a dead zone between poses
P0 = "x,y,angle\n0.0118,-0.1882,18.740\n1.4623,-0.0767,24.429\n2.1064,0.3277,48.267\n3.5551,-0.0908,66.720\n"
P4 = "x,y,angle\n0,0,0\n1,0.2,0.3\n1.8,0.9,0.7\n2.2,1.8,1.1\n"


def _write(tmp_path, text, name="p.csv"):
    p = tmp_path / name
    p.write_text(text)
    return p


def _coupler_pose(L, theta, sign):
    """Own loop closure (not planar's solver): coupler origin B and coupler angle at crank angle theta."""
    d, a, b, r = L
    B = np.stack([a * np.cos(theta), a * np.sin(theta)], -1)
    v = np.array([d, 0.0]) - B
    s = np.hypot(*v.T)
    cg = (b * b + s * s - r * r) / (2 * b * s)
    ok = np.abs(cg) <= 1
    ang = np.arctan2(v[:, 1], v[:, 0]) + sign * np.arccos(np.clip(cg, -1, 1))
    return B, ang, ok


@pytest.mark.slow
def test_order_defect_exits_3_naming_it_nearest_written(tmp_path, capsys):
    # no four-bar meets these 4 poses in order: the nearest one that does pass them in order is written, its
    # error named, exit 3
    for i, text in enumerate((P8, P0)):
        out = tmp_path / f"m{i}.toml"
        rc = main(["synth", "motion", str(_write(tmp_path, text)), "--deg", "-o", str(out), "--json"])
        rep = json.loads(capsys.readouterr().out)
        assert rc == 3 and rep["ok"] is False and "order defect" in rep["reason"] and "the nearest" in rep["reason"]
        assert out.exists() and rep["checks"]["ok_poses_in_order"] and not rep["checks"]["ok_reaches_every_pose"]
        assert 1e-6 < rep["checks"]["max_position_error"] < 1.0


def test_old_p0_design_crosses_a_dead_zone():
    # the design the old code wrote for p0 (d, a, b, r and crank angles at the poses): planar's solver finds
    # no assembly somewhere between poses 2 and 3 both ways round, and crank_order refuses it
    L = (1.0651118969922353, 1.0687863388634298, 1.0329889207004483, 0.9832065741328921)
    th = np.array([0.2868, 1.5016, 3.8090, 3.9686])
    ok, full, _, _ = crank_order(th[None], *(np.array([v]) for v in L))
    assert not ok[0] and not full[0]
    for sweep in (np.linspace(th[1], th[2], 400), np.linspace(th[1], th[2] - 2 * np.pi, 400)):
        assert not _coupler_pose(L, sweep, 1)[2].all()


def test_crank_order_full_turn_cyclic_either_direction():
    L = [np.array([v]) for v in (3.0, 1.0, 3.5, 2.5)]  # crank-rocker: the crank turns fully
    good = [[0.1, 1.0, 2.0, 3.0], [3.0, 5.0, 0.5, 1.0], [3.0, 2.0, 1.0, -2.5]]
    bad = [[1.0, 0.1, 2.0, 3.0], [0.1, 2.0, 1.0, 3.0]]
    for t in good:
        ok, full, _, _ = crank_order(np.array([t]), *L)
        assert ok[0] and full[0]
    for t in bad:
        assert not crank_order(np.array([t]), *L)[0][0]


def test_design_meets_poses_in_order_checked_by_own_sweep(tmp_path):
    t = np.loadtxt(_write(tmp_path, P4), delimiter=",", skiprows=1)
    d = burmester(t)
    assert d.ok and d.checks["ok_poses_in_order"] and d.checks["ok_assembles_between_poses"]
    # own loop closure at the design's crank angles reaches the poses; the crank, going one way through one
    # turn at most, passes them in order and assembles at every angle between them (dense own sweep)
    L = (d.ground, d.crank, d.coupler, d.rocker)
    px, py, pa = d.placement
    Rp = np.array([[np.cos(pa), -np.sin(pa)], [np.sin(pa), np.cos(pa)]])
    errs = []
    for sign in (1, -1):
        B, ang, ok = _coupler_pose(L, d.theta, sign)
        e = np.stack([np.cos(ang), np.sin(ang)], -1)
        n = np.stack([-e[:, 1], e[:, 0]], -1)
        P = (B + d.coupler_point[0] * e + d.coupler_point[1] * n) @ Rp.T + [px, py]
        errs.append(float(np.hypot(*(P - t[:, :2]).T).max()) if ok.all() else np.inf)
    sign = 1 if errs[0] < errs[1] else -1
    assert min(errs) < 1e-9
    for direction in (1, -1):
        steps = (direction * np.diff(d.theta)) % (2 * np.pi)
        if steps.sum() < 2 * np.pi:
            break
    else:
        raise AssertionError(f"poses out of order at theta {d.theta}")
    for t0, s in zip(d.theta[:-1], steps):
        assert _coupler_pose(L, t0 + direction * np.linspace(0, s, 2000), sign)[2].all()


@pytest.mark.slow
def test_no_design_exits_3_with_reason(tmp_path, capsys):
    # the trial's poses5.csv read as radians: two Burmester dyads, no pair usable
    five = "x,y,angle\n0,0,0\n1,0.5,20\n2,0.6,45\n2.8,0.2,70\n3.2,-0.5,95\n"
    out = tmp_path / "m.toml"
    rc = main(["synth", "motion", str(_write(tmp_path, five)), "-o", str(out), "--json"])
    rep = json.loads(capsys.readouterr().out)
    # the nearest four-bar is written, its errors named (its own check finds them), exit 3
    assert rc == 3 and rep["ok"] is False and "the nearest" in rep["reason"] and out.exists()
    assert not rep["checks"]["ok_reaches_every_pose"] and rep["checks"]["ok_poses_in_order"]
    with pytest.raises(NoMotionDesign):
        burmester(np.loadtxt(_write(tmp_path, five), delimiter=",", skiprows=1))


@pytest.mark.slow
@pytest.mark.parametrize("ratio", ["0", "1", "inf", "nan"])
def test_motion_max_ratio_refused_like_function(tmp_path, capsys, ratio):
    out = tmp_path / "m.toml"
    assert main(["synth", "motion", str(_write(tmp_path, P4)), "-o", str(out), "--max-ratio", ratio]) == 2
    assert "--max-ratio" in capsys.readouterr().err and not out.exists()


def test_duplicate_pose_and_translation_exit_2(tmp_path, capsys):
    out = tmp_path / "m.toml"
    dup = "x,y,angle\n0,0,0\n1,0.5,20\n0,0,0\n2,0.6,45\n"
    assert main(["synth", "motion", str(_write(tmp_path, dup)), "--deg", "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert "rows 1 and 3" in err and len(err.strip().splitlines()) == 1 and not out.exists()
    trans = "x,y,angle\n0,0,0.3\n1,0,0.3\n2,0.5,0.3\n"
    assert main(["synth", "motion", str(_write(tmp_path, trans)), "-o", str(out)]) == 2
    assert "pure translation" in capsys.readouterr().err and not out.exists()


@pytest.mark.slow
def test_min_transmission_checked_like_function(tmp_path, capsys):
    # own loop closure over the crank's sweep: the angle at C between coupler (C->B) and rocker (C->O4)
    path = _write(tmp_path, P4)
    d = burmester(np.loadtxt(path, delimiter=",", skiprows=1))
    L = (d.ground, d.crank, d.coupler, d.rocker)
    lo, hi = d.crank_range if d.crank_range is not None else (0.0, 2 * np.pi)
    theta = np.linspace(lo, hi, 20001)
    margins = []
    for sign in (1, -1):
        B, ang, ok = _coupler_pose(L, theta, sign)
        C = B + d.coupler * np.stack([np.cos(ang), np.sin(ang)], -1)
        u, v = B - C, np.array([d.ground, 0.0]) - C
        mu = np.abs(np.arctan2(u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0], (u * v).sum(1)))
        margins.append(float(np.degrees(np.minimum(mu, np.pi - mu)).min()) if ok.all() else np.inf)
    own = min(margins)  # the design's circuit is one of the two; both circuits have the same |mu| here
    assert abs(d.checks["min_transmission_deg"] - own) < 0.05
    out = tmp_path / "m.toml"
    # --min-transmission selects: asked for more than this design has, another four-bar through the poses
    # that keeps it is chosen, or, when none does, the nearest is written and fails its check
    rc = main(["synth", "motion", str(path), "-o", str(out), "--min-transmission", f"{own + 0.5:.4f}", "--json"])
    rep = json.loads(capsys.readouterr().out)
    assert (rc == 0 and rep["checks"]["min_transmission_deg"] >= own + 0.5) or (rc == 3 and not rep["checks"]["ok_transmission"])
    rc = main(["synth", "motion", str(path), "-o", str(out), "--min-transmission", "89"])
    err = capsys.readouterr()
    assert rc == 3 and "check failed: the transmission angle falls to" in err.err + err.out and "crank angle" in err.err + err.out
    rc = main(["synth", "motion", str(path), "-o", str(out), "--min-transmission", f"{own - 0.5:.4f}", "--json"])
    rep = json.loads(capsys.readouterr().out)
    assert rc == 0 and rep["checks"]["ok_transmission"] and "between poses" in rep["checks"]["min_transmission_at"]
    assert main(["synth", "motion", str(path), "-o", str(out), "--min-transmission", "90"]) == 2
