"""The command line: exit codes, one-line errors, no partial files; README and CI agree."""

import json
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from planar.cli.main import main

ROOT = Path(__file__).resolve().parents[2]


def run(*args, **kw):
    return subprocess.run([sys.executable, "-m", "planar", *args], capture_output=True, text=True, **kw)


def test_readme_opens_with_two_commands_and_ci_runs_the_test_one():
    text = (ROOT / "README.md").read_text()
    block = re.search(r"```(?:sh|bash|console)?\n(.*?)```", text, re.S)
    assert block, "README has no command block"
    cmds = [l for l in block.group(1).splitlines() if l.strip()]
    assert len(cmds) == 2
    assert "planar demo" in cmds[0]
    assert "pytest" in cmds[1]
    ci = (ROOT / ".ci" / "run").read_text()
    assert cmds[1].strip() in ci.splitlines()


@pytest.mark.slow
def test_demo_writes_outputs(tmp_path):
    import time

    t0 = time.perf_counter()
    r = run("demo", "-o", str(tmp_path))
    elapsed = time.perf_counter() - t0
    assert r.returncode == 0, r.stderr
    csv = tmp_path / "kangaroo-leg.csv"
    header = csv.read_text().splitlines()[0].split(",")
    assert header[:2] == ["t", "driver"] and header[-1] == "valid"
    assert "coupler_point.x" in header
    for name in ("horse", "kangaroo-leg"):
        assert (tmp_path / f"{name}.gif").stat().st_size > 1000
    print(f"planar demo took {elapsed:.1f} s")


def test_user_error_exit_2_one_line_no_traceback(tmp_path):
    r = run("catalog", "no-such-thing", "-o", str(tmp_path / "x.csv"))
    assert r.returncode == 2
    assert "Traceback" not in r.stderr
    assert len(r.stderr.strip().splitlines()) == 1 and "no-such-thing" in r.stderr
    assert not (tmp_path / "x.csv").exists()
    assert list(tmp_path.iterdir()) == []


def test_missing_output_directory_is_a_user_error(tmp_path):
    assert main(["catalog", "jansen", "-o", str(tmp_path / "nope" / "x.csv")]) == 2


def test_motion_csv_round_trips(tmp_path):
    from planar.scene.catalog import get

    out = tmp_path / "j.csv"
    assert main(["catalog", "jansen", "-o", str(out), "--samples", "90"]) == 0
    data = np.genfromtxt(out, delimiter=",", names=True)
    m = get("jansen").run(90)
    np.testing.assert_array_equal(data["footx"], m.points["foot"][:, 0])
    assert data["valid"].all()


@pytest.mark.slow
def test_bench_kinematics_json_has_ratio_and_agrees_with_peer():
    pytest.importorskip("pylinkage")
    from planar.bench.kinematics import bench_kinematics

    r = bench_kinematics(sizes=(50, 20_000), repeats=3)
    assert [c["linkage"] for c in r["cases"]] == ["fourbar-crank-rocker", "jansen"]
    for c in r["cases"]:
        assert [row["n"] for row in c["curve"]] == [50, 20_000]
        for row in c["curve"]:
            for key in ("planar_cpu_s", "peer_cpu_s", "planar_wall_s", "peer_wall_s"):
                s = row[key]
                assert 0 < s["min"] <= s["median"] <= s["max"]
            assert row["cpu_ratio"] == pytest.approx(row["peer_cpu_s"]["median"] / row["planar_cpu_s"]["median"])
            assert row["wall_ratio"] == pytest.approx(row["peer_wall_s"]["median"] / row["planar_wall_s"]["median"])
        assert c["ratio"] == min(row["wall_ratio"] for row in c["curve"])
        assert c["cpu_ratio"] == min(row["cpu_ratio"] for row in c["curve"])
        # every joint agrees with pylinkage (an independent solver) at the same crank angles
        assert c["max_abs_diff_vs_peer"] < 1e-9 and c["max_abs_diff_points_vs_peer"] < 1e-9
        assert c["all_valid"] and c["agrees"]
    assert r["ratio"] == min(c["ratio"] for c in r["cases"]) and r["ok"]
    out = run("bench", "kinematics", "--json", "-n", "20000", "--repeats", "1")
    assert out.returncode == 0, out.stderr
    assert "ratio" in json.loads(out.stdout)


def test_output_piped_into_a_closed_reader_gives_no_traceback():
    import subprocess
    import sys

    root = Path(__file__).resolve().parents[2]
    cmd = f"{sys.executable} -m planar chains | head -c 10"  # the reader closes after 10 bytes
    r = subprocess.run(["bash", "-c", cmd], capture_output=True, text=True, cwd=root)
    assert "Traceback" not in r.stderr and "BrokenPipe" not in r.stderr, r.stderr


def test_bench_kinematics_disagreement_changes_the_exit_status(monkeypatch, capsys):
    pytest.importorskip("pylinkage")
    import planar.bench.kinematics

    monkeypatch.setattr(planar.bench.kinematics, "AGREEMENT", -1.0)  # no difference can pass
    assert main(["bench", "kinematics", "-n", "2000", "--repeats", "1"]) == 3  # a failed check, as compare's
    assert "DISAGREES" in capsys.readouterr().out


@pytest.mark.slow
@pytest.mark.parametrize("unit", ["deg", "rad"])
def test_render_note_says_the_driver_value_in_the_scene_unit(tmp_path, capsys, unit):
    import math
    import re

    # crank 2, rod 1.5, offset 0.5: the rod reaches the guide only while 2 sin(theta) - 0.5 >= -1.5
    scene = tmp_path / "sc.toml"
    head = 'angle_unit = "deg"\n' if unit == "deg" else ""
    scene.write_text(
        f'name = "sc"\n{head}[mechanism]\ntype = "slidercrank"\ncrank = 2.0\nrod = 1.5\noffset = 0.5\n'
        "[driver]\nsamples_per_cycle = 36\n"
    )
    assert main(["render", str(scene), "-o", str(tmp_path / "sc.gif")]) == 0
    err = capsys.readouterr().out  # the notes go with the summary line
    m = re.search(r"cannot close at driver value ([0-9.]+)( deg)?: (.*)", err)
    assert m is not None, err
    value = float(m.group(1))
    assert (m.group(2) is not None) == (unit == "deg")
    theta = math.radians(value) if unit == "deg" else value
    assert 2 * math.sin(theta) - 0.5 < -1.5 and 0 <= theta < 2 * math.pi
    assert "G1" not in m.group(3) and "slider's guide" in m.group(3)
