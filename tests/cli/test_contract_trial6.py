"""Issue 26: the sixth abuse trial's command-line findings (soft ones: the hard contract held in 576 cases)."""

from __future__ import annotations

from pathlib import Path

import pytest
from clicheck import fails_cleanly

GALLERY = Path(__file__).resolve().parents[2] / "gallery"


@pytest.mark.parametrize("field", ["pin_diameter_mm", "thickness_mm", "min_wall_mm", "min_part_mm", "min_label_mm"])
def test_a_hardware_size_beyond_100_mm_is_refused_naming_the_field(capsys, tmp_path: Path, field: str) -> None:
    """pin_diameter_mm = 1e300 was refused only later, as 'part ground: 0.00 mm of material ...', naming
    neither the field nor the value."""
    scene = tmp_path / "s.toml"
    text = (GALLERY / "slider-crank.toml").read_text()
    assert "\n[fabrication]\n" in text
    scene.write_text(text.replace("\n[fabrication]\n", f"\n[fabrication]\n{field} = 1e300\n", 1))
    out = tmp_path / "p.dxf"
    fails_cleanly(capsys, ["export", str(scene), "-o", str(out)], f"fabrication.{field}", "1e+300", out=out)


def test_fabsettings_bounds_the_same_fields() -> None:
    from planar.errors import InputError
    from planar.fabrication import FabSettings

    for name in ("pin_mm", "thickness_mm", "min_wall", "min_part", "min_label"):
        with pytest.raises(InputError, match=f"fabrication.{name}"):
            FabSettings(**{name: 1e300})
    FabSettings(pin_mm=100.0, thickness_mm=100.0)  # the bound itself is accepted


@pytest.mark.parametrize("var", ["PLANAR_MAX_SAMPLES", "PLANAR_MAX_MEMORY", "PLANAR_MAX_FRAMES", "PLANAR_MAX_CHAIN"])
@pytest.mark.parametrize("text", ["1.5", "0.0001", "inf", "nan", "-3", "ten"])
def test_a_limit_variable_that_is_not_a_whole_number_is_refused(monkeypatch, var: str, text: str) -> None:
    """PLANAR_MAX_SAMPLES=1.5 was cut to 1 (and PLANAR_MAX_MEMORY=1.5 accepted) while 0.0001 was refused."""
    from planar.core.limits import DEFAULTS, limit
    from planar.errors import InputError

    name = next(k for k, (v, _) in DEFAULTS.items() if v == var)
    monkeypatch.setenv(var, text)
    with pytest.raises(InputError, match=var):
        limit(name)
    monkeypatch.setenv(var, "1e6")  # a whole number written in exponent form is one
    assert limit(name) == 1_000_000


def test_an_svg_circle_of_negative_radius_is_refused(capsys, tmp_path: Path) -> None:
    """svgelements took |r|: a drawing SVG calls an error was synthesised as a circle of radius 5."""
    svg = tmp_path / "neg.svg"
    svg.write_text('<svg xmlns="http://www.w3.org/2000/svg"><circle cx="0" cy="0" r="-5"/></svg>')
    out = tmp_path / "s.toml"
    fails_cleanly(capsys, ["synth", "path", str(svg), "-o", str(out)], "<circle> r", "-5", out=out)


def test_an_unparsable_svg_says_what_the_parser_said(capsys, tmp_path: Path) -> None:
    """It said only 'ParseError' (the exception's class)."""
    svg = tmp_path / "bad.svg"
    svg.write_text("not xml <<")
    out = tmp_path / "s.toml"
    fails_cleanly(capsys, ["synth", "path", str(svg), "-o", str(out)], "not readable as SVG", "line 1", out=out)


def test_an_angle_beyond_float64s_resolution_in_function_pairs_is_refused(capsys, tmp_path: Path) -> None:
    """An output angle of 1e300 degrees was wrapped into noise and synthesised (exit 3)."""
    pairs = tmp_path / "f.csv"
    pairs.write_text("input,output\n0,10\n30,1e300\n60,40\n")
    out = tmp_path / "s.toml"
    fails_cleanly(capsys, ["synth", "function", str(pairs), "-o", str(out), "--deg"], "f.csv: output", "1e+300", out=out)


def test_a_synthesised_scene_from_an_svg_is_in_millimetres(capsys, tmp_path: Path) -> None:
    """An SVG's user units are millimetres: the scene says unit_mm = 1 (the default 10 made it ten times too big)."""
    import tomllib

    from planar.cli.main import main

    svg = tmp_path / "c.svg"
    svg.write_text('<svg xmlns="http://www.w3.org/2000/svg"><ellipse cx="40" cy="30" rx="30" ry="18"/></svg>')
    out = tmp_path / "s.toml"
    main(["synth", "path", str(svg), "-o", str(out), "--points", "12", "--budget", "quick"])
    assert tomllib.loads(out.read_text())["fabrication"]["unit_mm"] == 1.0


def test_a_link_width_beyond_100_mm_is_refused_naming_the_field(capsys, tmp_path: Path) -> None:
    """link_width_mm = 1e300 was refused as a gear reaching past its pitch circle ('shorten the crank')."""
    text = (GALLERY / "geared-five-bar.toml").read_text()
    scene = tmp_path / "g.toml"
    if "\n[fabrication]\n" in text:
        scene.write_text(text.replace("\n[fabrication]\n", "\n[fabrication]\nlink_width_mm = 1e300\n", 1))
    else:
        scene.write_text(text + "\n[fabrication]\nlink_width_mm = 1e300\n")
    out = tmp_path / "p.dxf"
    fails_cleanly(capsys, ["export", str(scene), "-o", str(out)], "fabrication.link_width_mm", "1e+300", out=out)


def test_a_standoff_far_from_the_walker_is_refused_naming_it(capsys, tmp_path: Path) -> None:
    """A standoff at 1e7 made a frame plate 10 km long, refused only as a part too big for the sheet."""
    text = (GALLERY / "jansen-walker-4.toml").read_text()
    assert "standoffs = " in text
    lines = ["standoffs = [[1e7, -32.0], [0.0, 32.0]]" if ln.startswith("standoffs = ") else ln for ln in text.splitlines()]
    scene = tmp_path / "w.toml"
    scene.write_text("\n".join(lines) + "\n")
    out = tmp_path / "p.dxf"
    fails_cleanly(capsys, ["export", str(scene), "-o", str(out)], "standoffs[0]", "10000000.0", out=out)


def test_targets_far_from_the_origin_are_refused_before_the_search(capsys, tmp_path: Path) -> None:
    """A 1-unit curve 1e6 from the origin passed the targets' check and was refused after 30 s of search, naming
    'fourbar: placement' instead of the file."""
    import numpy as np

    th = np.linspace(0, 6, 12)
    t = np.c_[np.cos(th), 0.6 * np.sin(th)] + 1e6
    f = tmp_path / "far.csv"
    f.write_text("x,y\n" + "\n".join(f"{float(x)!r},{float(y)!r}" for x, y in t) + "\n")
    out = tmp_path / "s.toml"
    fails_cleanly(capsys, ["synth", "path", str(f), "-o", str(out), "--budget", "quick"], "far.csv", "nearer the origin", out=out)


@pytest.mark.parametrize(
    ("size", "box", "circle", "scale"),
    [
        ('width="100mm" height="60mm"', "0 0 100 60", 'cx="15" cy="40" r="10"', 1.0),  # Inkscape's mm page
        ('width="4in" height="2in"', "0 0 4 2", 'cx="1" cy="1" r="0.5"', 25.4),  # inches, converted to mm
        ('width="100" height="60"', "0 0 100 60", 'cx="15" cy="40" r="10"', 1.0),  # user units read as mm
    ],
)
def test_svg_targets_are_in_millimetres(tmp_path: Path, size: str, box: str, circle: str, scale: float) -> None:
    """A drawing in mm came back in px at 96 dpi (3.78 times too big) while the scene said unit_mm = 1."""
    import re

    import numpy as np

    from planar.synth import read_targets

    f = tmp_path / "c.svg"
    f.write_text(f'<svg xmlns="http://www.w3.org/2000/svg" {size} viewBox="{box}"><circle {circle}/></svg>')
    got = read_targets(f, 24)
    pts = got[0] if isinstance(got, tuple) else got
    cx, cy, r = (float(re.search(rf'{k}="([^"]+)"', circle).group(1)) * scale for k in ("cx", "cy", "r"))
    np.testing.assert_allclose(np.hypot(pts[:, 0] - cx, pts[:, 1] + cy), r, rtol=1e-5)
