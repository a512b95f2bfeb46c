"""planar info: the homework figures checked against hand computations written here (closed forms)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from planar.analysis.info import info
from planar.cli.main import main
from planar.linkages.fourbar import FourBar
from planar.scene.load import load_scene

GALLERY = Path(__file__).resolve().parents[2] / "gallery"


def _hand_crank_rocker(a: float, b: float, c: float, d: float):
    """Crank-rocker by the law of cosines: the rocker's dead centres (crank and coupler in line, O2 C = b + a
    extended and b - a folded), its swing, the time ratio (180 + alpha) / (180 - alpha) and the transmission
    angle's extremes (crank along the ground line, theta = 0 and 180 deg)."""
    # angle at O2 of the triangle O2 C O4 (sides O2C, c, d), C above the ground line (open circuit)
    ext = math.acos(((b + a) ** 2 + d**2 - c**2) / (2 * (b + a) * d))
    fold = math.acos(((b - a) ** 2 + d**2 - c**2) / (2 * (b - a) * d))
    theta_ext = ext  # crank along O2 -> C
    theta_fold = fold + math.pi  # crank pointing away from C
    alpha = abs(fold - ext)  # crank angle beyond 180 deg of the slow stroke
    ratio = (math.pi + alpha) / (math.pi - alpha)
    psi_ext = math.acos((d**2 + c**2 - (b + a) ** 2) / (2 * d * c))  # rocker angle at O4 from O4->O2
    psi_fold = math.acos((d**2 + c**2 - (b - a) ** 2) / (2 * d * c))
    swing = abs(psi_ext - psi_fold)
    mu0 = math.acos((b**2 + c**2 - (d - a) ** 2) / (2 * b * c))
    mu180 = math.acos((b**2 + c**2 - (d + a) ** 2) / (2 * b * c))
    return sorted(map(math.degrees, (theta_ext, theta_fold))), ratio, math.degrees(swing), math.degrees(mu0), math.degrees(mu180)


@pytest.mark.parametrize(
    "dims",
    [(4.0, 1.0, 3.5, 3.0), (7.0, 2.0, 6.0, 5.5), (1.0, 0.11, 0.98, 0.35)],  # the last: extreme ratios
)
def test_crank_rocker_figures_match_the_law_of_cosines(dims):
    d, a, b, c = dims
    r = info(FourBar(ground=d, crank=a, coupler=b, rocker=c))
    assert r.dof == 1
    assert r.grashof == "crank-rocker" and r.turns_fully == ["crank"]
    assert r.toggle_angles == [] and r.valid_range == [(0.0, 360.0)]
    dead, ratio, swing, mu0, mu180 = _hand_crank_rocker(a, b, c, d)
    (rocker,) = [o for o in r.outputs if o.part == "rocker"]
    assert rocker.motion == "rocks"
    assert rocker.dead_centres == pytest.approx(dead, abs=1e-6)
    assert rocker.time_ratio == pytest.approx(ratio, rel=1e-9)
    assert r.time_ratio == pytest.approx(ratio, rel=1e-9)
    assert rocker.swing == pytest.approx(swing, abs=1e-6)
    (t,) = r.transmission
    assert min(t.low, t.high) == pytest.approx(min(mu0, mu180), abs=1e-9)
    assert max(t.low, t.high) == pytest.approx(max(mu0, mu180), abs=1e-9)
    worst = mu0 if abs(mu0 - 90) > abs(mu180 - 90) else mu180
    assert t.worst == pytest.approx(worst, abs=1e-9)


def test_random_crank_rockers():
    rng = np.random.default_rng(7)
    done = 0
    while done < 4:
        a, b, c, d = rng.uniform(0.2, 5.0, 4)
        if not (a < min(b, c, d) and a + max(b, c, d) < sum((a, b, c, d)) - a - max(b, c, d)):
            continue
        r = info(FourBar(ground=d, crank=a, coupler=b, rocker=c), samples=720)
        dead, ratio, swing, _, _ = _hand_crank_rocker(a, b, c, d)
        (rocker,) = [o for o in r.outputs if o.part == "rocker"]
        assert rocker.time_ratio == pytest.approx(ratio, rel=1e-8), (a, b, c, d)
        assert rocker.dead_centres == pytest.approx(dead, abs=1e-6)
        assert rocker.swing == pytest.approx(swing, abs=1e-6)
        done += 1


def test_triple_rocker_toggles_are_the_law_of_cosines():
    d, a, b, c = 2.0, 2.2, 1.9, 2.5  # s + l = 4.4 > p + q = 4.2: non-Grashof
    r = info(FourBar(ground=d, crank=a, coupler=b, rocker=c))
    assert r.grashof == "non-Grashof" and r.turns_fully == []
    # toggles where B O4 = b + c or |b - c|: a^2 + d^2 - 2 a d cos(theta) = (b +/- c)^2
    ends = []
    for L in (b + c, abs(b - c)):
        cs = (a * a + d * d - L * L) / (2 * a * d)
        if -1 <= cs <= 1:
            th = math.acos(cs)
            ends += [math.degrees(th), 360 - math.degrees(th)]
    assert r.toggle_angles == pytest.approx(sorted(ends), abs=1e-9)
    # the input cannot turn: the rocker's swing over the one range that assembles, no dead centres or time ratio
    (out,) = r.outputs
    assert out.part == "rocker" and out.motion == "rocks" and len(out.ranges) == 1 and out.dead_centres == []
    assert out.ranges[0][:2] == pytest.approx(sorted(ends), abs=1e-6)  # the refined ends are the toggles
    assert r.time_ratio is None


def test_quick_return_time_ratio_is_the_closed_form():
    scene = load_scene(GALLERY / "quick-return.toml")
    r = info(scene.mechanism)
    # crank radius r, pivots d apart: the lever's extremes are tangent to the crank circle,
    # alpha = 2 asin(r / d) ... the slow stroke spans 180 + alpha: ratio (180 + alpha) / (180 - alpha)
    rad, dist = 1.0, 2.0
    alpha = 180.0 - 2 * math.degrees(math.acos(rad / dist))
    hand = (180.0 + alpha) / (180.0 - alpha)
    (lever,) = [o for o in r.outputs if o.part == "lever"]
    assert lever.time_ratio == pytest.approx(hand, rel=1e-9)
    assert lever.swing == pytest.approx(2 * math.degrees(math.asin(rad / dist)), abs=1e-6)
    assert r.dof == 1


def test_offset_slider_crank_stroke_and_ratio():
    scene = load_scene(GALLERY / "slider-crank.toml")
    r = info(scene.mechanism)
    a, rod, e = 1.0, 3.0, 0.4
    hand_stroke = math.sqrt((a + rod) ** 2 - e**2) - math.sqrt((rod - a) ** 2 - e**2)
    beta = math.asin(e / (rod - a)) - math.asin(e / (rod + a))
    hand_ratio = (math.pi + beta) / (math.pi - beta)
    (slider,) = [o for o in r.outputs if o.motion == "slides"]
    assert slider.swing == pytest.approx(hand_stroke, rel=1e-9)
    assert slider.time_ratio == pytest.approx(hand_ratio, rel=1e-8)


@pytest.mark.slow
def test_gruebler_counts_for_linkage_and_toy():
    assert info(load_scene(GALLERY / "jansen-leg.toml").mechanism).dof == 1
    horse = info(load_scene(GALLERY / "horse.toml").mechanism)
    assert horse.dof == 1  # counted assembled: one frame, the cams on one shaft
    assert horse.chains == {"left": [["Rz->OzT", "OzT->Oz"]], "right": [["Rz->OzT", "OzT->Ty"], ["Rz->OzT", "OzT->Oz"]]}
    assert len(horse.stages) == 5


def test_cli_text_and_json(capsys):
    assert main(["info", str(GALLERY / "quick-return.toml")]) == 0
    text = capsys.readouterr().out
    assert "time ratio 2" in text and "degrees of freedom (Gruebler/Kutzbach): 1" in text
    assert main(["info", str(GALLERY / "quick-return.toml"), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["time_ratio"] == pytest.approx(2.0)


def test_cli_missing_scene_is_one_line(tmp_path, capsys):
    assert main(["info", str(tmp_path / "nope.toml")]) == 2
    assert len(capsys.readouterr().err.strip().splitlines()) == 1


def _own_rocker_swings(a: float, b: float, c: float, d: float):
    """Per assemblable crank interval, the rocker's swing (deg) on each circuit, by circle intersection (B on
    the crank circle, C at distance b from B and c from O4 = (d, 0)), from toggle to toggle."""
    # |B - O4|^2 = a^2 + d^2 - 2 a d cos(theta) must lie in [(b - c)^2, (b + c)^2]
    lo = math.acos(np.clip((a * a + d * d - (b + c) ** 2) / (2 * a * d), -1, 1))
    hi = math.acos(np.clip((a * a + d * d - (b - c) ** 2) / (2 * a * d), -1, 1))
    out = []
    for t0, t1 in ((min(lo, hi), max(lo, hi)), (-max(lo, hi), -min(lo, hi))):
        th = np.linspace(t0, t1, 200001)
        B = np.stack([a * np.cos(th), a * np.sin(th)], -1)
        v = np.array([d, 0.0]) - B
        s = np.hypot(*v.T)
        u = v / s[:, None]
        along = (b * b - c * c + s * s) / (2 * s)
        h = np.sqrt(np.clip(b * b - along**2, 0, None))
        swings = []
        for sign in (1, -1):
            C = B + along[:, None] * u + sign * h[:, None] * np.stack([-u[:, 1], u[:, 0]], -1)
            psi = np.unwrap(np.arctan2(C[:, 1], C[:, 0] - d))
            swings.append(math.degrees(float(np.ptp(psi))))
        out.append(swings)
    return out


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(4))
def test_double_rocker_under_a_full_turn_reports_the_rocker_swing(seed):
    rng = np.random.default_rng(seed)
    while True:  # a Grashof double rocker: the coupler shortest, s + l < p + q
        c_, a, r, d = rng.uniform(0.2, 1.0), *rng.uniform(1.0, 5.0, 3)
        L = sorted([a, c_, r, d])
        if L[0] == c_ and L[0] + L[3] < L[1] + L[2] - 0.05:
            break
    m = FourBar(ground=d, crank=a, coupler=c_, rocker=r)
    assert m.grashof == "double-rocker"
    rep = info(m)
    (out,) = [o for o in rep.outputs if o.part == "rocker"]
    own = _own_rocker_swings(a, c_, r, d)
    assert out.motion == "rocks" and len(out.ranges) == 2
    for lo, hi, swing in out.ranges:
        mid = math.radians(0.5 * (lo + hi))
        k = 0 if math.sin(mid) > 0 else 1  # the interval above or below the ground line
        assert min(abs(swing - w) for w in own[k]) < 1e-3, (swing, own[k])
    assert out.swing == max(r_[2] for r_ in out.ranges)
    text = str(rep)
    assert "turns fully: coupler (the coupler" in text and "relative to the crank, the rocker and the ground" in text
    assert "output rocker: rocks up to" in text


def test_the_text_names_toggles_as_the_valid_range_does():
    # a trial read "toggle (limit) driver angles: 102.6356 deg, 257.3644 deg" beside "valid range: -102.6 to
    # 102.6 deg": the same two angles in two conventions
    from planar.analysis.info import format_info

    r = info(FourBar(ground=4.0, crank=3.0, coupler=3.0, rocker=2.5))  # s + l = 6.5 > p + q = 6: non-Grashof
    text = format_info(r)
    ((lo, hi),) = r.valid_range
    assert lo < 0 < hi
    toggles = next(x for x in text.splitlines() if x.startswith("toggle (limit)"))
    assert toggles == f"toggle (limit) driver angles: {lo:.4f} deg, {hi:.4f} deg"
    assert sorted(a % 360 for a in (lo, hi)) == pytest.approx(r.toggle_angles, abs=1e-9)


def test_the_text_gives_a_rocking_drivers_swing_in_the_valid_ranges_terms():
    # a trial read "valid range: -53.3 to 53.3 deg" for a scene whose driver rocks from -32.4 to 42.1 deg, and
    # nothing of that swing; the swing is centre -+ amplitude, said within the valid range (here shifted by a turn)
    from planar.analysis.info import format_info

    fb = FourBar(ground=4.0, crank=3.0, coupler=3.0, rocker=2.5, amplitude=0.5, centre=2 * math.pi + 0.2)
    r = info(fb)
    ((lo, hi),) = r.valid_range
    assert r.driven_swing == pytest.approx((math.degrees(2 * math.pi - 0.3), math.degrees(2 * math.pi + 0.7)))
    line = next(x for x in format_info(r).splitlines() if x.startswith("driven swing"))
    a, b = (float(v) for v in line.split(": ")[1].removesuffix(" deg").split(" to "))
    assert (a, b) == pytest.approx((math.degrees(-0.3), math.degrees(0.7)), abs=0.01) and lo <= a < b <= hi
    assert info(FourBar(ground=4.0, crank=1.0, coupler=3.5, rocker=3.0)).driven_swing is None  # turns fully
    assert "driven swing" not in format_info(info(FourBar(ground=4.0, crank=1.0, coupler=3.5, rocker=3.0)))
