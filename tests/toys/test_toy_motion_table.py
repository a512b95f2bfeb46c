"""A toy's motion table is its assembly in the toy's frame (a Ty effector moves along y), with rates that
agree with central differences of the positions."""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np
import pytest

from planar.analysis.rates import mechanism_rates
from planar.cli.main import main
from planar.scene.load import load_scene
from planar.toys.assembly import toy_assembly

GALLERY = Path(__file__).resolve().parents[2] / "gallery"


def _table(path: Path) -> dict[str, np.ndarray]:
    rows = list(csv.reader(path.open()))
    data = np.array(rows[1:], float)
    return {name: data[:, i] for i, name in enumerate(rows[0])}


def test_a_turned_ty_stage_moves_along_y_in_the_table(tmp_path: Path) -> None:
    out = tmp_path / "horse.csv"
    assert main(["motion", str(GALLERY / "horse.toml"), "-o", str(out)]) == 0
    col = _table(out)
    # the Horse's right cam drives a Ty leg through a turned #-stage: in the toy's frame it moves along y only
    assert np.ptp(col["right:Ty@s3.y"]) > 0.04
    assert np.ptp(col["right:Ty@s3.x"]) < 1e-12
    # the table's pieces are the assembly's (one frame, merged bodies), not the stages' panels
    assert "frame.x" in col and "s0.ground.x" not in col


def test_pieces_in_other_planes_name_their_axes(tmp_path: Path) -> None:
    out = tmp_path / "bunny.csv"
    assert main(["motion", str(GALLERY / "bunny.toml"), "-o", str(out)]) == 0
    col = _table(out)
    assert {"s1.follower.y", "s1.follower.z", "s2.follower.x", "s2.follower.z"} <= set(col)
    assert "s1.follower.x" not in col and "s2.follower.y" not in col


@pytest.mark.parametrize("scene", ["horse.toml", "bunny.toml"])
def test_assembly_rates_agree_with_central_differences(scene: str) -> None:
    toy = load_scene(GALLERY / scene).mechanism
    asm = toy_assembly(toy)
    w = toy.driver.rate
    t = np.linspace(0.1, 0.9, 17) * toy.driver.period
    h = 1e-5 * toy.driver.period
    q = toy.driver.value(t)
    rates, valid, method = mechanism_rates(asm, q, w, 0.0)
    assert valid.all() and "turned to each piece's place" in method
    p0, pp, pm = (asm.solve(toy.driver.value(x)).poses for x in (t, t + h, t - h))
    size = asm.size
    for piece, r in rates.items():
        v = (pp[piece][:, :2] - pm[piece][:, :2]) / (2 * h)
        a = (pp[piece][:, :2] - 2 * p0[piece][:, :2] + pm[piece][:, :2]) / (h * h)
        dang = np.angle(np.exp(1j * (pp[piece][:, 2] - pm[piece][:, 2])))
        np.testing.assert_allclose(r.v, v, atol=1e-6 * size * abs(w), err_msg=piece)
        np.testing.assert_allclose(r.omega, dang / (2 * h), atol=1e-6 * abs(w), err_msg=piece)
        np.testing.assert_allclose(r.a, a, atol=2e-3 * size * w * w, err_msg=piece)


@pytest.mark.parametrize("gravity", [(9.81, 0.0), (0.0, -9.81), (5.0, -7.0)])
def test_table_torque_is_the_toys_inverse_dynamics_with_gravity_in_each_plane(gravity) -> None:
    """The motion table's torque (closed-form rates) and inverse dynamics by differencing (planar.analysis.dynamics, the
    torque `planar toy` checks pymunk against) agree for the Bunny, whose #9 ear turns in yz and #8 tab in xz:
    gravity acts on each piece in its own plane."""
    from dataclasses import replace

    from planar.analysis.dynamics import inverse_dynamics_torque
    from planar.analysis.rates import motor_torque

    sc = load_scene(GALLERY / "bunny.toml")
    asm = toy_assembly(sc.mechanism)
    eff = replace(sc.effects, gravity=gravity)
    t = asm.driver.times(24)
    mo = asm.solve(asm.driver.value(t), t=t)
    tau, ok = motor_torque(asm, mo, eff)
    ref = inverse_dynamics_torque(asm, t, eff)
    assert ok.all()
    assert np.abs(tau - ref).max() < 1e-5 * np.abs(ref).max()


def test_a_toy_that_cannot_be_assembled_gets_its_panels_and_a_note(tmp_path: Path, capsys) -> None:
    scene = tmp_path / "turned8.toml"
    scene.write_text(
        'name = "ns"\nangle_unit = "deg"\n[mechanism]\ntype = "toy"\nleft = [["Rz->Ty"]]\n'
        'right = [["Rz->Ty", "Ty->Ox"]]\n[driver]\nspeed = 0.5\nsamples_per_cycle = 36\n'
        "[effects]\ngravity = [9.81, 0.0]\n"
    )
    out = tmp_path / "m.csv"
    assert main(["motion", str(scene), "-o", str(out)]) == 0
    text = capsys.readouterr().out
    assert "cannot be assembled" in text and "turned 90 deg about z" in text and "own frame" in text
    assert "s0.ground.x" in _table(out)  # the stages' panels


@pytest.mark.slow
def test_chains_says_which_chains_assemble(capsys) -> None:
    assert main(["chains"]) == 0
    out = capsys.readouterr().out
    rows = [r for r in out.splitlines() if "chain = [" in r]
    assert len(rows) == 77
    assert sum(r.rstrip().endswith("assembles") for r in rows) == 39
    (row,) = [r for r in rows if 'chain = ["Rz->Ty", "Ty->Ox"] ' in r]
    assert "motion only: its stage Ty->Ox is realised as #8 turned 90 deg about z" in row
    # the gallery's toys are built from chains the table marks as assembling
    for chain in ('["Rz->Tx", "Tx->Ox"]', '["Rz->Tx", "Tx->Oy"]', '["Rz->OzT", "OzT->Ty"]'):
        (r,) = [r for r in rows if f"chain = {chain} " in r]
        assert r.rstrip().endswith("assembles")
