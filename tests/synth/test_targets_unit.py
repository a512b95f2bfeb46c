"""A synthesised scene says its unit: an SVG drawing's user units are millimetres, written as [fabrication] unit_mm."""

from __future__ import annotations

import tomllib

import numpy as np
import pytest

import planar
from planar.errors import InputError
from planar.synth.scene_out import fourbar_scene_text, linkage_scene_text, write_scene
from planar.synth.targets import SVG_UNIT_MM, target_unit_mm


def test_an_svg_target_is_in_millimetres_and_a_csv_has_no_unit() -> None:
    assert target_unit_mm("curve.svg") == target_unit_mm("C.SVG") == SVG_UNIT_MM == 1.0
    assert target_unit_mm("points.csv") is None


def test_the_scene_text_carries_the_unit_it_is_given(tmp_path) -> None:
    args = ("t", 40.0, 10.0, 35.0, 30.0, (15.0, 10.0), "open", (0.0, 0.0, 0.0))
    scene = write_scene(tmp_path / "mm.toml", fourbar_scene_text(*args, unit_mm=1.0))
    assert scene.spec.fabrication.unit_mm == 1.0
    assert tomllib.loads((tmp_path / "mm.toml").read_text())["fabrication"] == {"unit_mm": 1.0}
    plain = write_scene(tmp_path / "plain.toml", fourbar_scene_text(*args))
    assert plain.spec.fabrication.unit_mm == 10.0 and "[fabrication]" not in (tmp_path / "plain.toml").read_text()
    for bad in (0.0, -1.0, float("nan"), "1"):
        with pytest.raises(InputError, match="unit_mm"):
            fourbar_scene_text(*args, unit_mm=bad)
    nodes = [{"name": "O2", "kind": "fixed", "at": [0.0, 0.0]}, {"name": "A", "kind": "crank", "at": [0.0, 0.0]}]
    text = linkage_scene_text("l", nodes, [], {"tracer": "A"}, unit_mm=0.5)
    assert tomllib.loads(text)["fabrication"] == {"unit_mm": 0.5}


def test_read_targets_samples_an_svg_circle_on_its_circle(tmp_path) -> None:
    """Twelve points on a circle of radius 20 at (50, 30), y turned up: each 20 from (50, -30), equally spaced."""
    svg = tmp_path / "c.svg"
    svg.write_text(
        '<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 100 100"><circle cx="50" cy="30" r="20"/></svg>',
        encoding="utf-8",
    )
    pts, theta = planar.synth.read_targets(svg, points=12)
    assert theta is None and pts.shape == (12, 2)
    assert np.hypot(pts[:, 0] - 50.0, pts[:, 1] + 30.0) == pytest.approx(np.full(12, 20.0), abs=1e-6)
    gaps = np.hypot(*np.diff(np.vstack([pts, pts[:1]]), axis=0).T)
    assert gaps == pytest.approx(np.full(12, 2 * 20.0 * np.sin(np.pi / 12)), rel=1e-3)
    for bad in (2, 501, 3.5, "12"):
        with pytest.raises(InputError, match=r"^points = "):
            planar.synth.read_targets(svg, points=bad)
    with pytest.raises(InputError, match=r"^path = "):
        planar.synth.read_targets(None)
