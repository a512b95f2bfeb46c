"""Issue 26: the fourth abuse trial's command-line findings (each exited 1, or accepted what the contract refuses)."""

from __future__ import annotations

from pathlib import Path

import pytest
from clicheck import fails_cleanly

GALLERY = Path(__file__).resolve().parents[2] / "gallery"


def test_a_seed_beyond_32_bits_is_refused_naming_the_option(capsys, tmp_path: Path) -> None:
    targets = tmp_path / "t.csv"
    targets.write_text("x,y\n0,0\n1,1\n2,0\n3,1\n4,0\n")
    out = tmp_path / "s.toml"
    argv = ["synth", "path", str(targets), "-o", str(out), "--seed", str(10**23)]
    fails_cleanly(capsys, argv, "--seed", "2**32 - 1", out=out)


@pytest.mark.parametrize("kerf", ["1e-300", "1e-9", "0.0009"])
def test_a_kerf_finer_than_a_micrometre_is_refused(capsys, tmp_path: Path, kerf: str) -> None:
    out = tmp_path / "p.dxf"
    fails_cleanly(capsys, ["export", str(GALLERY / "cam-automaton.toml"), "-o", str(out), f"--kerf={kerf}"], "--kerf", out=out)


def test_a_pose_angle_beyond_float64s_resolution_is_refused(capsys, tmp_path: Path) -> None:
    poses = tmp_path / "p.csv"
    poses.write_text("x,y,angle\n0,0,0\n1,0.5,1e300\n2,0.3,0.7\n")
    out = tmp_path / "m.toml"
    fails_cleanly(capsys, ["synth", "motion", str(poses), "-o", str(out)], "row 2: angle", "1e+300", out=out)


_TWICE = [
    ("path", "x,y,x", "{i},{j},{i}"),
    ("function", "input,output,input", "{i},{j},{i}"),
    ("motion", "x,y,angle,x", "{i},{j},0.{i},{i}"),
]


@pytest.mark.parametrize("command,header,row", _TWICE)
def test_a_column_named_twice_is_refused(capsys, tmp_path: Path, command: str, header: str, row: str) -> None:
    table = tmp_path / "t.csv"
    table.write_text(header + "\n" + "".join(row.format(i=i, j=i % 2) + "\n" for i in range(1, 5)))
    out = tmp_path / "s.toml"
    fails_cleanly(capsys, ["synth", command, str(table), "-o", str(out)], "header: column", "each column once", out=out)
