"""Rich display: compact reprs, HTML tables and inline players through the registry of planar.core.display."""

from __future__ import annotations

import html
import re
import subprocess
import sys
from pathlib import Path

import pytest

import planar.draw.notebook
from planar.core import display
from planar.linkages.fourbar import FourBar
from planar.physics.compare import Comparison, PartError
from planar.physics.toy import StageReport, ToyPhysics
from planar.scene.load import load_scene

GALLERY = Path(__file__).resolve().parents[2] / "gallery"


def _fourbar():
    return FourBar(ground=4, crank=1, coupler=3.5, rocker=3, coupler_point=(1.5, 1.0))


def test_compact_reprs_stay_short():
    m = _fourbar()
    motion = m.run(samples_per_cycle=2000)
    scene = load_scene(GALLERY / "horse.toml")
    comp = Comparison("fourbar", 5.0, 100, 1e-3, [PartError("crank", 1e-4, 1e-5, 2e-5, 1e-6, None)], {"B": 1e-6}, None)
    toy = ToyPhysics({"max_rel_diff": 0.001}, [StageReport("s0", "Rz->OzT", True, "")])
    for obj in (m, motion, scene, comp, toy):
        assert len(repr(obj)) < 2000, type(obj)
    assert repr(motion).startswith("<Motion of 'fourbar': 2000 samples, 4 parts, 0 invalid")
    assert "passed" in repr(comp)


def test_html_has_a_table_and_a_player():
    m = _fourbar()
    page = m._repr_html_()
    assert "<table>" in page and "crank-rocker" in page and "<iframe srcdoc=" in page
    inner = html.unescape(re.search(r'srcdoc="([^"]*)"', page).group(1))
    assert "<svg" in inner and '"valid":[' in inner
    motion = m.run(samples_per_cycle=1000)
    mh = motion._repr_html_()
    assert "1000 of 1000" in mh and "<iframe" in mh
    # a long motion is shown thinned to at most MAX_INLINE_FRAMES frames
    frames = re.search(r'max=\\?"(\d+)', html.unescape(mh)).group(1)
    assert int(frames) + 1 <= planar.draw.notebook.MAX_INLINE_FRAMES


def test_comparison_and_toy_tables():
    comp = Comparison("fourbar", 5.0, 100, 1e-3, [PartError("crank", 1e-2, 1e-5, 2e-2, 1e-6, 4)], {"B": 1e-6}, 4)
    h = comp._repr_html_()
    assert "<table>" in h and "False" in h and "crank" in h
    toy = ToyPhysics({"max_rel_diff": 0.001}, [StageReport("s0", "Rz->OzT", False, "no contact")])
    assert "no contact" in toy._repr_html_()


def test_without_a_renderer_the_front_end_falls_back_to_repr(monkeypatch):
    monkeypatch.setattr(display, "RENDERERS", {})
    assert _fourbar()._repr_html_() is None


def test_animate_and_save(tmp_path):
    m = _fourbar()
    p = m.animate(samples_per_cycle=24)
    assert p.frames == 24 and len(repr(p)) < 200
    p.save(tmp_path / "x.html")
    assert (tmp_path / "x.html").read_text().startswith("<!DOCTYPE html>")
    motion = m.run(samples_per_cycle=12)
    assert motion.take([0, 1, 2]).animate().frames == 3


def test_import_planar_under_ipython_registers_without_numpy():
    code = (
        "import sys, types; sys.modules['IPython'] = types.ModuleType('IPython'); import planar; "
        "print('numpy' in sys.modules, 'planar.draw.notebook' in sys.modules)"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.split()
    assert out == ["False", "True"]
    out = subprocess.run(
        [sys.executable, "-c", "import sys, planar; print('planar.draw.notebook' in sys.modules)"],
        capture_output=True,
        text=True,
        check=True,
    ).stdout.split()
    assert out == ["False"]


@pytest.mark.slow  # a fresh interpreter: about 1 s of CPU
def test_animate_and_html_in_plain_python_without_importing_draw():
    # no IPython: a bare `import planar` registers nothing, yet animate and _repr_html_ work (the loader)
    code = (
        "import sys, planar; assert 'IPython' not in sys.modules; "
        "m = planar.FourBar(ground=4, crank=1, coupler=3.5, rocker=3); "
        "before = 'planar.draw.notebook' in sys.modules; "
        "p = m.solve([0.0, 0.5, 1.0]).animate(); q = m.animate(samples_per_cycle=6); h = m._repr_html_(); "
        "print(before, p.frames, q.frames, h.startswith('<table>'), 'planar.draw.notebook' in sys.modules)"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.split()
    assert out == ["False", "3", "6", "True", "True"]


@pytest.mark.parametrize("name", ["jansen-leg", "windup-06", "cam-automaton"])
def test_scenes_display(name):
    s = load_scene(GALLERY / f"{name}.toml")
    assert "<iframe" in s._repr_html_()
