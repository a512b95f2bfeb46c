"""Issue 15: ``synth function`` angle convention, JSON clarity and input spans."""

from __future__ import annotations

import json

import numpy as np
import pytest

from planar.cli.main import build_parser, main

LOG5 = "input,output\n1.468,7.780\n12.366,41.004\n30.000,66.633\n47.634,81.980\n58.532,89.130\n"


def _rocker_world_angles(phi, d, a, b, c):
    """Own loop closure: crank pivot (0, 0), rocker pivot (d, 0) (d < 0: on the negative x axis); world angles."""
    B = np.stack([a * np.cos(phi), a * np.sin(phi)], -1)
    O4 = np.array([d, 0.0])
    v = B - O4
    s = np.hypot(*v.T)
    base = np.arctan2(v[:, 1], v[:, 0])
    return base + np.arccos((c * c + s * s - b * b) / (2 * c * s))


def test_angles_are_from_the_world_x_axis(tmp_path, capsys):
    # a four-bar with its rocker pivot at (-1, 0): pairs as world angles (the trial's neg3.csv case)
    phi = np.radians([20.0, 50.0, 80.0, 110.0])
    psi = _rocker_world_angles(phi, -1.0, 0.4, 1.2, 0.8)
    pairs = tmp_path / "neg.csv"
    pairs.write_text("input,output\n" + "".join(f"{float(p)!r},{float(q)!r}\n" for p, q in zip(phi, psi)))
    assert main(["synth", "function", str(pairs), "-o", str(tmp_path / "n.toml"), "--json"]) == 0
    rep = json.loads(capsys.readouterr().out)
    assert rep["max_output_error_rad"] < 1e-9
    assert abs(rep["ground_angle"] - np.pi) < 1e-12  # placed turned by pi: the angles are world angles
    sub = build_parser()._subparsers._group_actions[0].choices["synth"]  # type: ignore[union-attr]
    helptext = sub._subparsers._group_actions[0].choices["function"].format_help()
    assert "world +x axis" in " ".join(helptext.split()) and "from the ground line" not in helptext


@pytest.mark.slow
def test_json_full_turn_only_when_asked_and_no_negative_zero(tmp_path, capsys):
    pairs = tmp_path / "log5.csv"
    pairs.write_text(LOG5)
    main(["synth", "function", str(pairs), "--deg", "-o", str(tmp_path / "a.toml"), "--json"])
    text = capsys.readouterr().out
    rep = json.loads(text)
    assert "ok_full_turn" not in rep["checks"] and rep["checks"]["crank_turns_fully"] is False
    assert "-0.0," not in text and "-0.0\n" not in text
    main(["synth", "function", str(pairs), "--deg", "--full-turn", "--free-offsets", "-o", str(tmp_path / "b.toml"), "--json"])
    rep = json.loads(capsys.readouterr().out)
    assert rep["checks"]["ok_full_turn"] is rep["checks"]["crank_turns_fully"]


def test_span_beyond_one_turn_refused(tmp_path, capsys):
    pairs = tmp_path / "wide.csv"
    pairs.write_text("input,output\n0.1,0.5\n2.0,0.9\n4.5,1.2\n7.0,1.4\n")
    out = tmp_path / "w.toml"
    assert main(["synth", "function", str(pairs), "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert "input" in err and "2 pi" in err and len(err.strip().splitlines()) == 1 and not out.exists()
    pairs.write_text("input,output\n0,0\n100,170\n200,340\n300,510\n")
    assert main(["synth", "function", str(pairs), "--deg", "-o", str(out)]) == 2
    assert "output" in capsys.readouterr().err and not out.exists()
