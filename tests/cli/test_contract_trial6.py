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
