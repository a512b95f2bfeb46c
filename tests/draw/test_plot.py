"""planar plot: the charts hold the motion's numbers, read back from the figure and from the SVG."""

from __future__ import annotations

import numpy as np
import pytest

from planar.analysis import statics as analysis
from planar.analysis.rates import motor_torque
from planar.cli.main import main
from planar.scene.load import load_scene

KANGAROO = "gallery/kangaroo-leg.toml"


def _line(fig, gid: str):
    for ax in fig.axes:
        for ln in ax.get_lines():
            if ln.get_gid() == gid:
                return ln
    raise AssertionError(f"no line {gid!r}")


def test_figure_lines_hold_the_motion_and_independent_formulas() -> None:
    from planar.draw.charts import scene_figure

    sc = load_scene(KANGAROO)
    fig = scene_figure(sc)
    assert [ax.get_gid() for ax in fig.axes if ax.get_gid()] == [
        "chart-curve",
        "chart-transmission",
        "chart-angle",
        "chart-velocity",
        "chart-speed",
        "chart-acceleration",
        "chart-torque",
    ]
    mo = sc.motion()
    curve = _line(fig, "curve:coupler_point")
    xy = np.column_stack([curve.get_xdata(), curve.get_ydata()])
    assert np.array_equal(xy[:-1], mo.points["coupler_point"]) and np.array_equal(xy[-1], xy[0])  # closed
    # transmission against the four-bar's law-of-cosines formula, in degrees, over crank angle in degrees
    tr = _line(fig, "transmission:C")
    assert np.allclose(tr.get_xdata(), np.degrees(mo.driver))
    assert np.allclose(tr.get_ydata(), np.degrees(sc.mechanism.transmission_angle(mo.driver)), atol=1e-9)
    # the rocker's angle against Freudenstein's (tangent half-angle) closed form, turned by the placement
    _, th4, _ = sc.mechanism.angles(mo.driver)
    turn = np.degrees(sc.mechanism.placement[2])
    got = _line(fig, "angle:rocker").get_ydata()
    assert np.allclose(np.mod(got - np.degrees(th4) - turn + 180, 360) - 180, 0, atol=1e-9)
    assert np.all(np.abs(np.diff(got)) < 90)  # unwrapped: no jump of a turn
    # the coupler's angular velocity against Norton's loop equations
    w3, _, _ = analysis.fourbar_velocities(sc.mechanism, mo.driver, sc.mechanism.driver.rate)
    assert np.allclose(_line(fig, "omega:coupler").get_ydata(), w3, rtol=1e-10, atol=1e-12)
    # the foot's speed against the velocity of planar.analysis.statics (loop equations, the velocity coefficient x rate)
    vel, _ = analysis.point_velocities(sc.mechanism, mo.driver, sc.mechanism.driver.rate)
    assert np.allclose(_line(fig, "speed:coupler_point").get_ydata(), np.hypot(*vel["coupler_point"].T), rtol=1e-12)
    # torque: the loads' line is planar.analysis.statics' velocity-coefficient torque; the total is the inverse dynamics
    ref, _ = analysis.motor_torque(sc.mechanism, mo.driver, {"coupler_point": [0.0, 10.0]})
    assert np.allclose(_line(fig, "torque.loads").get_ydata(), ref, atol=1e-12)
    tau, _ = motor_torque(sc.mechanism, mo, sc.effects)
    assert np.array_equal(_line(fig, "torque").get_ydata(), tau)


def test_svg_read_back_with_svgelements_keeps_the_curve_shape(tmp_path) -> None:
    """The drawn coupler curve (equal axes) is the motion's curve up to scale and a y flip."""
    from svgelements import SVG, Line, Move, Path

    out = tmp_path / "k.svg"
    assert main(["plot", KANGAROO, "-o", str(out), "--what", "curve,torque"]) == 0
    svg = SVG.parse(str(out))
    groups = {getattr(e, "id", None): e for e in svg.elements()}
    assert "chart-curve" in groups and "chart-torque" in groups and "chart-velocity" not in groups
    paths = [e for e in groups["curve:coupler_point"].select() if isinstance(e, Path)]
    pts = np.array([(seg.end.x, seg.end.y) for seg in paths[0] if isinstance(seg, (Move, Line))])
    mo = load_scene(KANGAROO).motion()
    data = mo.points["coupler_point"]
    n = len(data)
    assert len(pts) == n + 1
    drawn = pts[:n]
    # an affine map with a uniform scale and y flipped: fit drawn = s * (x, -y) + c by least squares
    A = np.column_stack(
        [
            np.concatenate([data[:, 0], -data[:, 1]]),
            np.concatenate([np.ones(n), np.zeros(n)]),
            np.concatenate([np.zeros(n), np.ones(n)]),
        ]
    )
    b = np.concatenate([drawn[:, 0], drawn[:, 1]])
    coef, *_ = np.linalg.lstsq(A, b, rcond=None)
    assert coef[0] > 0
    assert np.abs(A @ coef - b).max() < 0.05  # SVG coordinates are written to 6 digits: hundredths of a point


@pytest.mark.slow
def test_plot_bytes_reproducible(tmp_path) -> None:
    for ext in ("svg", "png"):
        a, b = tmp_path / f"a.{ext}", tmp_path / f"b.{ext}"
        assert main(["plot", "gallery/windup-03.toml", "-o", str(a), "--what", "velocity"]) == 0
        assert main(["plot", "gallery/windup-03.toml", "-o", str(b), "--what", "velocity"]) == 0
        assert a.read_bytes() == b.read_bytes()


@pytest.mark.parametrize(
    "args, msg",
    [
        (["-o", "x.pdf"], ".png or .svg"),
        (["-o", "x.png", "--what", "jerk"], "one of curve"),
        (["-o", "x.png", "--what", "transmission"], "no RRR dyad"),
    ],
)
def test_plot_user_errors_exit_2_and_write_nothing(tmp_path, capsys, monkeypatch, args, msg) -> None:
    monkeypatch.chdir(tmp_path)
    import shutil

    shutil.copy(f"{__import__('pathlib').Path(__file__).parents[2]}/gallery/horse.toml", "horse.toml")
    assert main(["plot", "horse.toml", *args]) == 2
    err = capsys.readouterr().err
    assert msg in err and len(err.strip().splitlines()) == 1
    assert sorted(p.name for p in tmp_path.iterdir()) == ["horse.toml"]
