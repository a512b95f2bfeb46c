"""A new user's trial of ``synth path`` on drawn curves: crank angles, stages, messages, transmission."""

import json
import math

import numpy as np
import pytest

from planar.cli.main import main
from planar.synth.kernel import coupler_points
from planar.synth.path import wrapped


def _curve(row, circ, th):
    x, y, _ = coupler_points(np.asarray(row, float)[None, :], np.asarray(th, float)[None, :], np.array([circ]))
    return np.column_stack([x[0], y[0]])


def _csv(path, T, theta=None):
    head = "x,y" + (",theta" if theta is not None else "")
    ts = [float(t) for t in theta] if theta is not None else [None] * len(T)
    rows = [f"{x!r},{y!r}" + (f",{t!r}" if t is not None else "") for (x, y), t in zip(T.tolist(), ts)]
    path.write_text(head + "\n" + "\n".join(rows) + "\n")
    return path


def test_wrapped_is_in_one_turn():
    t = wrapped(np.array([-1e-20, -0.000291448, 6.2619, 7.0, -7.0, 0.0]))
    assert np.all((t >= 0) & (t < 2 * np.pi))
    assert np.allclose(np.exp(1j * t), np.exp(1j * np.array([-1e-20, -0.000291448, 6.2619, 7.0, -7.0, 0.0])))


@pytest.mark.slow
def test_scene_comment_and_json_give_the_same_wrapped_crank_angles(tmp_path, capsys):
    """Timed targets with negative crank angles: the comment and the JSON both give them in [0, 2 pi)."""
    th = np.linspace(-np.pi, np.pi, 10, endpoint=False)
    T = _curve([1.0, 0.3, 1.1, 0.9, 0.5, 0.4, 0.0, 0.0, 0.0], 1.0, th)
    src = _csv(tmp_path / "t.csv", T, th)
    out = tmp_path / "s.toml"
    main(["synth", "path", str(src), "-o", str(out), "--budget", "quick", "--json"])
    rep = json.loads(capsys.readouterr().out)
    line = next(s for s in out.read_text().splitlines() if s.startswith("# crank angle"))
    comment = np.array([float(v) for v in line.split(":", 1)[1].split(",")])
    js = np.array(rep["theta"])
    assert np.all((js >= 0) & (js < 2 * math.pi)) and np.all((comment >= 0) & (comment < 2 * math.pi))
    assert np.allclose(comment, js, atol=1e-5)
