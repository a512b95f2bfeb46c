"""The SVG cuts exactly what the DXF cuts: every contour read back by svgelements vs ezdxf."""

from pathlib import Path

import pytest

from fabcheck import dxf_cut_polygons, match_contours, svg_closed_polygons
from planar.pipeline import export_scene, gallery_scenes
from planar.scene import load_scene

GALLERY = Path(__file__).resolve().parents[1] / "gallery"


def _pairs(tmp_path: Path, stem: str) -> list[tuple[Path, Path]]:
    one = (tmp_path / f"{stem}.dxf", tmp_path / f"{stem}.svg")
    if one[0].exists():
        return [one]
    k, out = 1, []
    while (tmp_path / f"{stem}-{k}.dxf").exists():
        out.append((tmp_path / f"{stem}-{k}.dxf", tmp_path / f"{stem}-{k}.svg"))
        k += 1
    return out


@pytest.mark.parametrize("path", gallery_scenes(GALLERY), ids=lambda p: p.stem)
def test_svg_contours_equal_the_dxf_contours(tmp_path, path):
    scene = load_scene(path)
    export_scene(scene, tmp_path / "p.dxf", tmp_path / "p.svg")
    pairs = _pairs(tmp_path, "p")
    assert pairs
    n = 0
    for dxf, svg in pairs:
        a = svg_closed_polygons(svg)
        b = dxf_cut_polygons(dxf)
        assert all(p.is_valid and p.area > 0 for p in a + b)
        rel = match_contours(a, b)
        assert max(rel) <= 1e-3, f"{svg.name}: worst contour differs by {max(rel):.2%} of its area"
        n += len(rel)
    assert n > 0
