"""Accelerations by the differentiated closures, checked against differences and independent formulations."""

from __future__ import annotations

import csv
from typing import ClassVar

import numpy as np
import pytest

from planar.analysis import statics as analysis
from planar.analysis.dynamics import inverse_dynamics_torque
from planar.analysis.rates import driver_rates, motion_derivatives, motor_torque
from planar.cli.main import main
from planar.linkages import RRR, FourBar, Linkage, SliderCrank
from planar.scene.catalog import CATALOG, get
from planar.scene.load import load_scene

LINKAGES = [n for n in CATALOG if isinstance(get(n), Linkage)]
GALLERY = [
    "quick-return",
    "oscillating-cylinder",
    "peaucellier",
    "watt-straight-line",
    "double-rocker",
    "jansen-leg",
    "slider-crank",
]


def _central(x: np.ndarray, h: float) -> tuple[np.ndarray, np.ndarray]:
    """First and second central differences along axis 0 (interior samples only)."""
    return (x[2:] - x[:-2]) / (2 * h), (x[2:] - 2 * x[1:-1] + x[:-2]) / (h * h)


def _check_against_differences(mech, n: int) -> float:
    """Worst relative difference of analytic rates from central differences over one cycle of ``n`` samples."""
    t = mech.driver.times(n)
    mo = mech.solve(mech.driver.value(t), t=t)
    der = motion_derivatives(mech, mo)
    h = t[1] - t[0]
    ok = der.valid[1:-1] & der.valid[:-2] & der.valid[2:]
    assert ok.mean() > 0.9
    worst = 0.0
    w = mech.driver.rate
    for name, (v, a) in der.points.items():
        fv, fa = _central(mo.points[name], h)
        # a point on a pivoting part's axis stands still: measure against the mechanism's size x rate
        worst = max(
            worst,
            np.abs(fv - v[1:-1])[ok].max() / max(np.abs(v).max(), mech.size * w),
            np.abs(fa - a[1:-1])[ok].max() / max(np.abs(a).max(), mech.size * w * w),
        )
    for name, r in der.parts.items():
        ang = np.unwrap(mo.poses[name][:, 2])
        fo, fal = _central(ang, h)
        # a part turning with the crank has alpha 0 (to round-off): measure against the driver's rate
        scale_o = max(np.abs(r.omega).max(), mech.driver.rate)
        scale_a = max(np.abs(r.alpha).max(), mech.driver.rate**2)
        worst = max(worst, np.abs(fo - r.omega[1:-1])[ok].max() / scale_o, np.abs(fal - r.alpha[1:-1])[ok].max() / scale_a)
        fv, fa = _central(mo.poses[name][:, :2], h)
        worst = max(
            worst,
            np.abs(fv - r.v[1:-1])[ok].max() / max(np.abs(r.v).max(), mech.size * w),
            np.abs(fa - r.a[1:-1])[ok].max() / max(np.abs(r.a).max(), mech.size * w * w),
        )
    return worst


@pytest.mark.parametrize("name", LINKAGES)
def test_catalog_linkage_rates_match_central_differences_second_order(name: str) -> None:
    mech = get(name)
    e1 = _check_against_differences(mech, 720)
    e2 = _check_against_differences(mech, 1440)
    assert e1 < 2e-3
    assert e2 < e1 / 3  # second order: halving the step quarters the difference


@pytest.mark.parametrize("name", GALLERY)
def test_gallery_linkages_rates_match_differences(name: str) -> None:
    """Moving guides (quick return, oscillating cylinder), straight-line linkages and rocking drivers."""
    mech = load_scene(f"gallery/{name}.toml").mechanism
    assert _check_against_differences(mech, 2000) < 1e-3


def test_fourbar_node_accelerations_equal_angle_formulation_rocking_input() -> None:
    """Point formulation (node kinds) against Norton's link-angle loop equations, with a nonzero crank alpha."""
    fb = FourBar(4.0, 1.0, 4.0, 3.0, coupler_point=(5.5, -2.0), amplitude=0.8, centre=1.0, rate=3.0)
    t = np.linspace(0.0, fb.driver.period, 97)
    q = fb.driver.value(t)
    qd, qdd = driver_rates(fb.driver, t)
    assert np.abs(qdd).max() > 1.0
    mo = fb.solve(q, t=t)
    der = motion_derivatives(fb, mo)
    w3, w4, okv = analysis.fourbar_velocities(fb, q, qd)
    al3, al4, oka = analysis.fourbar_accelerations(fb, q, qd, qdd)
    assert okv.all() and oka.all() and der.valid.all()
    scale = np.abs(al3).max()
    assert np.abs(der.parts["coupler"].omega - w3).max() < 1e-12 * np.abs(w3).max()
    assert np.abs(der.parts["rocker"].omega - w4).max() < 1e-12 * np.abs(w4).max()
    assert np.abs(der.parts["coupler"].alpha - al3).max() < 1e-11 * scale
    assert np.abs(der.parts["rocker"].alpha - al4).max() < 1e-11 * np.abs(al4).max()
    # and the transmission angle against the law-of-cosines formula
    assert np.allclose(der.transmission["C"], fb.transmission_angle(q), atol=1e-12)


def test_slider_crank_acceleration_equals_textbook_closed_form() -> None:
    """x = r cos t + sqrt(l^2 - (r sin t - e)^2), differentiated by hand."""
    r, l, e = 1.0, 3.0, 0.4
    sc = SliderCrank(r, l, offset=e, rate=5.0)
    t = np.linspace(0, sc.driver.period, 50, endpoint=False)
    th = sc.driver.value(t)
    mo = sc.solve(th, t=t)
    v, a = motion_derivatives(sc, mo).points["slider_pin"]
    w = 5.0
    h, hd, hdd = r * np.sin(th) - e, r * np.cos(th), -r * np.sin(th)
    s = np.sqrt(l * l - h * h)
    xd = -r * np.sin(th) - h * hd / s
    xdd = -r * np.cos(th) - (hd * hd + h * hdd) / s - (h * hd) ** 2 / s**3
    assert np.allclose(v[:, 0], w * xd, rtol=0, atol=1e-12 * w)
    assert np.allclose(a[:, 0], w * w * xdd, rtol=0, atol=1e-11 * w * w)
    assert np.abs(v[:, 1]).max() < 1e-12 and np.abs(a[:, 1]).max() < 1e-10


def test_torque_equals_inverse_dynamics_by_differences() -> None:
    """Exact-rate torque against planar.analysis.dynamics (central differences in time): inertia, gravity, loads, springs."""
    from planar.core.effects import Effects, Load, Spring

    mech = get("jansen")
    eff = Effects(
        gravity=(0.0, -9.81),
        damping=0.9,
        density=0.01,
        loads=(Load("foot", (3.0, 10.0)),),
        springs=(Spring("crank", "lower", 2.0, damping=0.3),),
    )
    t = mech.driver.times(90)
    mo = mech.solve(mech.driver.value(t), t=t)
    tau, ok = motor_torque(mech, mo, eff)
    ref = inverse_dynamics_torque(mech, t, eff)
    assert ok.all()
    assert np.abs(tau - ref).max() < 1e-5 * np.abs(ref).max()


def test_torque_of_a_rocking_driver_divides_power_by_its_own_speed() -> None:
    """planar.analysis.dynamics divides power by the constant rate; a rocking input's torque is power / dq/dt."""
    sc = load_scene("gallery/double-rocker.toml")
    mech = sc.mechanism
    t = np.linspace(0, mech.driver.period, 40, endpoint=False)
    mo = mech.solve(mech.driver.value(t), t=t)
    tau, _ok = motor_torque(mech, mo, sc.effects)
    power_over_rate = inverse_dynamics_torque(mech, t, sc.effects)
    qd, _ = driver_rates(mech.driver, t)
    keep = np.abs(qd) > 0.2 * np.abs(qd).max()
    assert np.allclose(tau[keep], (power_over_rate * mech.driver.rate / qd)[keep], rtol=1e-5, atol=1e-6 * np.abs(tau).max())


def test_motion_derivatives_columns(tmp_path) -> None:
    out = tmp_path / "m.csv"
    assert main(["motion", "gallery/kangaroo-leg.toml", "-o", str(out), "--derivatives"]) == 0
    rows = list(csv.DictReader(out.open()))
    cols = rows[0].keys()
    for c in (
        "coupler_point.vx",
        "coupler_point.vy",
        "coupler_point.ax",
        "coupler_point.ay",
        "coupler.omega",
        "rocker.alpha",
        "C.transmission",
        "torque",
        "torque.loads",
        "rates_valid",
    ):
        assert c in cols
    assert list(cols)[-1] == "valid"
    sc = load_scene("gallery/kangaroo-leg.toml")
    mo = sc.motion()
    ax = np.array([float(r["coupler_point.ax"]) for r in rows])
    assert np.array_equal(ax, motion_derivatives(sc.mechanism, mo).points["coupler_point"][1][:, 0])
    # the loads' torque is the velocity-coefficient torque of planar.analysis.statics
    tau_l = np.array([float(r["torque.loads"]) for r in rows])
    ref, _ = analysis.motor_torque(sc.mechanism, mo.driver, {"coupler_point": [0.0, 10.0]})
    assert np.allclose(tau_l, ref, rtol=1e-12, atol=1e-12)
    # the plain table is unchanged by the option's existence
    plain = tmp_path / "p.csv"
    assert main(["motion", "gallery/kangaroo-leg.toml", "-o", str(plain)]) == 0
    assert "torque" not in plain.read_text().splitlines()[0]


def _spectral(x: np.ndarray, period: float) -> tuple[np.ndarray, np.ndarray]:
    """First and second time derivatives of one periodic cycle of samples by FFT (no differencing)."""
    n = x.shape[0]
    k = 2 * np.pi * np.fft.fftfreq(n, d=period / n)
    ik = (1j * k).reshape((-1,) + (1,) * (x.ndim - 1))
    X = np.fft.fft(x, axis=0)
    return np.fft.ifft(ik * X, axis=0), np.fft.ifft(ik * ik * X, axis=0)


GALLERY_ALL = sorted(
    p.stem for p in __import__("pathlib").Path("gallery").glob("*.toml") if "cam" not in p.stem
)  # a cam's motion law is piecewise: not for FFT (see below)


def test_cam_rates_equal_central_differences_of_the_poses() -> None:
    """A cam's program is piecewise (dwell, rise, return), so its poses are not analytic and an FFT converges
    slowly; instead central differences at two steps: the rates sit where second-order differences converge."""
    mech = load_scene("gallery/cam-automaton.toml").mechanism
    t = mech.driver.times(97) + 0.0013  # off the segment joins
    mo = mech.solve(mech.driver.value(t), t=t)
    der = motion_derivatives(mech, mo)
    assert der.valid.all() and {"cam", "roller", "follower"} <= set(der.parts)
    w = mech.driver.rate
    for h in (1e-4,):
        up, dn = (mech.solve(mech.driver.value(t + e), t=t + e) for e in (h, -h))
        for part, r in der.parts.items():
            P, Pp, Pm = mo.poses[part], up.poses[part], dn.poses[part]
            dang = np.angle(np.exp(1j * (Pp[:, 2] - Pm[:, 2])))
            om = dang / (2 * h)
            al = np.angle(np.exp(1j * (Pp[:, 2] - P[:, 2]))) - np.angle(np.exp(1j * (P[:, 2] - Pm[:, 2])))
            al = al / h**2
            v = (Pp[:, :2] - Pm[:, :2]) / (2 * h)
            a = (Pp[:, :2] - 2 * P[:, :2] + Pm[:, :2]) / h**2
            so, sa = max(np.abs(r.omega).max(), w), max(np.abs(r.alpha).max(), w * w)
            assert np.abs(om - r.omega).max() < 1e-5 * so, part
            assert np.abs(al - r.alpha).max() < 1e-3 * sa, part
            sv, sA = max(np.abs(r.v).max(), mech.size * w), max(np.abs(r.a).max(), mech.size * w * w)
            assert np.abs(v - r.v).max() < 1e-5 * sv, part
            assert np.abs(a - r.a).max() < 1e-3 * sA, part


@pytest.mark.parametrize("name", GALLERY_ALL)
def test_rates_equal_spectral_derivatives_of_the_poses(name: str) -> None:
    """An independent method: one cycle's poses differentiated by FFT (exponentially convergent for a smooth
    periodic motion) against the closed-form rates, for every gallery scene: linkages, the 11 wind-up
    mechanisms, the Horse and the Bunny.  Angles through exp(i phi): phi' = Im(conj(z) z')."""
    mech = load_scene(f"gallery/{name}.toml").mechanism
    t = mech.driver.times(256)
    mo = mech.solve(mech.driver.value(t), t=t)
    der = motion_derivatives(mech, mo)
    assert der.valid.all()
    T = mech.driver.period
    for part, r in der.parts.items():
        z = np.exp(1j * mo.poses[part][:, 2])
        z1, z2 = _spectral(z, T)
        v, a = _spectral(mo.poses[part][:, :2], T)
        so, sa = max(np.abs(r.omega).max(), mech.driver.rate), max(np.abs(r.alpha).max(), mech.driver.rate**2)
        assert np.abs((np.conj(z) * z1).imag - r.omega).max() < 1e-8 * so, part
        assert np.abs((np.conj(z) * z2).imag - r.alpha).max() < 1e-8 * sa, part
        w = mech.driver.rate
        sv, sA = max(np.abs(r.v).max(), mech.size * w), max(np.abs(r.a).max(), mech.size * w * w)
        assert np.abs(v.real - r.v).max() < 1e-8 * sv, part
        assert np.abs(a.real - r.a).max() < 1e-8 * sA, part


@pytest.mark.parametrize("name", ["windup-03", "windup-06", "windup-11", "horse"])
def test_windup_rates_match_central_differences_second_order(name: str) -> None:
    mech = load_scene(f"gallery/{name}.toml").mechanism
    e1 = _check_against_differences(mech, 500)
    e2 = _check_against_differences(mech, 1000)
    assert e1 < 1e-3 and e2 < e1 / 3


def test_windup_torque_equals_inverse_dynamics_by_differences() -> None:
    sc = load_scene("gallery/horse.toml")
    mech = sc.mechanism
    from planar.core.effects import Effects

    eff = Effects(gravity=(0.0, -9.81), density=2.0)
    t = mech.driver.times(48)
    mo = mech.solve(mech.driver.value(t), t=t)
    tau, ok = motor_torque(mech, mo, eff)
    ref = inverse_dynamics_torque(mech, t, eff)
    assert ok.all()
    assert np.abs(tau - ref).max() < 1e-5 * np.abs(ref).max()


def test_motion_derivatives_of_a_toy(tmp_path) -> None:
    out = tmp_path / "h.csv"
    assert main(["motion", "gallery/horse.toml", "-o", str(out), "--derivatives"]) == 0
    head = out.read_text().splitlines()[0].split(",")
    assert "cam.left.omega" in head and "torque" in head  # the assembled pieces (the cam keyed on the shaft)
    assert not any(c.endswith(".transmission") for c in head)  # no dyads in a toy


def test_rrp_on_a_moving_line_with_offset_and_an_actuator() -> None:
    """The RRP terms a fixed guide leaves untested: a slot on the turning crank, shifted off its centre line;
    and a translating input that rocks (qdd != 0)."""
    from planar.linkages import RRP, RRR, Actuator, Crank, Fixed, Link, Rigid

    slot = Linkage(
        "slot",
        [
            Fixed("O", (0.0, 0.0)),
            Fixed("Z", (2.5, 0.5)),
            Crank("A", "O", 3.0),
            RRP("S", "Z", 3.0, "O", "A", 1, 0.3),
            Rigid("T", "Z", "S", (3.0, 0.5)),
        ],
        [Link("crank", ("O", "A")), Link("arm", ("Z", "S", "T"))],
        points={"tip": "T", "pin": "S"},
    )
    act = Linkage(
        "act",
        [Fixed("O", (0.0, 0.0)), Fixed("Z", (0.0, 2.0)), Actuator("P", "O", (1.0, 0.2)), RRR("B", "P", 2.5, "Z", 2.0)],
        [Link("rod", ("P", "B")), Link("arm", ("Z", "B"))],
        points={"b": "B"},
        amplitude=0.6,
        centre=0.5,
    )
    for mech in (slot, act):
        assert _check_against_differences(mech, 2000) < 1e-3
        t = mech.driver.times(256)
        mo = mech.solve(mech.driver.value(t), t=t)
        der = motion_derivatives(mech, mo)
        assert der.valid.all()
        for name, (v, a) in der.points.items():
            fv, fa = _spectral(mo.points[name], mech.driver.period)
            assert np.abs(fv.real - v).max() < 1e-8 * np.abs(v).max(), (mech.name, name)
            assert np.abs(fa.real - a).max() < 1e-8 * np.abs(a).max(), (mech.name, name)


def test_a_node_kind_without_acceleration_is_refused_by_name() -> None:
    from dataclasses import dataclass

    from planar.core.registry import UnsupportedError
    from planar.linkages import NODE_KINDS, Crank, Fixed, Link, NodeKind, node_kind

    @dataclass(frozen=True)
    class Pinned(NodeKind):  # a ground point that does not say how it accelerates
        kind: ClassVar[str] = "test-no-acceleration"
        name: str
        xy: tuple[float, float]

        def position(self, pos, q, path):  # type: ignore[no-untyped-def]
            return np.broadcast_to(np.asarray(self.xy, float), (q.shape[0], 2)), None

        def velocity(self, pos, vel, qd):  # type: ignore[no-untyped-def]
            return np.zeros((qd.shape[0], 2)), None

    node_kind(Pinned)
    try:
        link = Linkage(
            "l",
            [Fixed("O", (0.0, 0.0)), Pinned("Z", (3.0, 0.0)), Crank("A", "O", 1.0), RRR("B", "A", 3.0, "Z", 2.0)],
            [Link("crank", ("O", "A")), Link("c", ("A", "B")), Link("r", ("Z", "B"))],
        )
        t = link.driver.times(8)
        with pytest.raises(UnsupportedError, match="test-no-acceleration"):
            motion_derivatives(link, link.solve(link.driver.value(t), t=t))
    finally:
        del NODE_KINDS["test-no-acceleration"]
