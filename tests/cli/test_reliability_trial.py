"""Abuses a new user found breaking the contract (exit 2 with one line, never NaN marked valid, no abort)."""

import csv

import numpy as np
import pytest

from planar.cli.main import main

LEG = """
[mechanism]
type = "fourbar"
ground = {g}
crank = {c}
coupler = {g}
rocker = {r}
coupler_point = [{px}, {py}]
[driver]
samples_per_cycle = 24
{extra}
"""


def _leg(tmp_path, scale=1.0, extra=""):
    p = tmp_path / "leg.toml"
    p.write_text(LEG.format(g=4 * scale, c=1 * scale, r=3 * scale, px=5.5 * scale, py=-2 * scale, extra=extra))
    return p


def _one_line(capsys):
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("planar: error:"), err
    return err[0]


def test_a_density_that_overflows_the_mass_is_refused_not_an_abort(tmp_path, capsys):
    # Chipmunk aborted the process (SIGABRT, exit 134) on an infinite mass
    p = _leg(tmp_path, extra="[effects]\ndensity = 1e308\ngravity = [0.0, -9.81]")
    assert main(["compare", str(p)]) == 2
    assert "mass" in _one_line(capsys)


def test_an_overflowing_torque_is_not_marked_valid(tmp_path):
    p = _leg(tmp_path, extra="[effects]\ndensity = 1e308\ngravity = [0.0, -9.81]")
    out = tmp_path / "m.csv"
    assert main(["motion", str(p), "-o", str(out), "--derivatives"]) == 0
    rows = list(csv.DictReader(out.open()))
    for r in rows:
        tau = float(r["torque"])
        assert np.isfinite(tau) and (r["rates_valid"] == "1" or tau == 0.0)  # an overflowed rate holds 0, not NaN


def test_a_chart_of_overflowing_loads_is_one_line(tmp_path, capsys):
    p = _leg(tmp_path, extra='[effects]\nloads = [{ point = "coupler_point", force = [1e308, 1e308] }]')
    out = tmp_path / "f.png"
    assert main(["plot", str(p), "-o", str(out), "--what", "torque"]) == 2
    assert "leg.toml" in _one_line(capsys) and not out.exists()


@pytest.mark.parametrize("scale", [1e300, 1e-300])
def test_rates_at_extreme_scales_are_one_line_or_computed(tmp_path, capsys, scale):
    p = _leg(tmp_path, scale)
    out = tmp_path / "m.csv"
    rc = main(["motion", str(p), "-o", str(out), "--derivatives"])
    if rc == 2:
        _one_line(capsys)
        assert not out.exists()
    else:
        assert rc == 0


@pytest.mark.slow
def test_synth_seed_and_design_options(tmp_path, capsys):
    t = tmp_path / "t.csv"
    t.write_text("x,y\n0,0\n1,0.2\n2,0\n1,-0.5\n")
    assert main(["synth", "path", str(t), "-o", str(tmp_path / "s.toml"), "--seed", "-1"]) == 2
    assert "--seed" in _one_line(capsys)
    r = tmp_path / "r.toml"
    r.write_text('[[effector]]\nname = "head"\nmotion = "Oz"\nrange = 30.0\n')
    assert main(["design", str(r), "-o", str(tmp_path / "toy.toml"), "--max-length", "99"]) == 2
    assert "PLANAR_MAX_CHAIN" in _one_line(capsys)
    r.write_text('[[effector]]\nname = "he\\nad"\nmotion = "Oz"\nrange = 30.0\n')
    assert main(["design", str(r), "-o", str(tmp_path / "toy.toml"), "--max-length", "3"]) == 2
    assert "control characters" in _one_line(capsys)
    assert not (tmp_path / "toy.toml").exists()


def test_python_api_refuses_bools_strings_complex_and_a_wrong_suffix(tmp_path):
    from planar.app.pipeline import write_mechanism_motion
    from planar.errors import PlanarError
    from planar.linkages import FourBar

    for bad in (True, "1"):
        with pytest.raises(PlanarError, match="crank"):
            FourBar(ground=4, crank=bad, coupler=4, rocker=3)
    with pytest.raises(PlanarError, match="real numbers"):
        FourBar(4, 1, 4, 3).solve(np.zeros(4) + 1j)
    with pytest.raises(PlanarError, match="csv"):
        write_mechanism_motion(FourBar(4, 1, 4, 3), tmp_path / "m.gif")
    assert not (tmp_path / "m.gif").exists()


def test_ctrl_c_while_numpy_loads_is_one_line(tmp_path):
    # `import planar.cli.main` no longer loads numpy, so the command's interrupt handling covers numpy's import
    import subprocess
    import sys

    code = "import sys, planar.cli.main; print('numpy' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "False"


@pytest.mark.slow
def test_schema_to_a_closed_stdout(tmp_path):
    import subprocess
    import sys

    r = subprocess.run(
        [sys.executable, "-m", "planar", "schema"], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, check=False
    )
    assert r.returncode == 0
    r = subprocess.run(f"{sys.executable} -m planar schema >&-", shell=True, stderr=subprocess.PIPE, text=True)
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1 and "standard output" in r.stderr
