"""Issue 26: the API calls the third abuse trial found still raising raw exceptions or naming values badly.

Each call must raise a :class:`planar.errors.PlanarError` naming the argument (these fail on the code
before the fix with ZeroDivisionError, ValueError, TypeError, MemoryError or AttributeError).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from planar.analysis.info import info
from planar.errors import InputError, LimitError, PlanarError, short_repr
from planar.linkages import FourBar
from planar.synth import synthesise_function, synthesise_path

LEG = FourBar(4.0, 1.0, 4.0, 3.0, coupler_point=(5.5, -2.0))
TARGETS = np.c_[np.cos(np.linspace(0.0, 5.0, 10)), np.sin(np.linspace(0.0, 5.0, 10))]


@pytest.mark.parametrize(
    "call,needle",
    [
        (lambda: info(LEG, samples=0), "samples"),
        (lambda: info(LEG, samples=-5), "samples"),
        (lambda: info(LEG, samples=math.nan), "samples"),
        (lambda: info(LEG, samples="10"), "samples"),
        (lambda: info(None), "mech"),
        (lambda: synthesise_path(TARGETS, atlas="atlas.npz"), "atlas"),
        (lambda: synthesise_path(TARGETS, atlas=123), "atlas"),
        (lambda: FourBar(4, 1, 4, 3, bogus=1), "bogus"),
        (lambda: synthesise_function(np.linspace(0, 1, 6), np.sin(np.linspace(0, 1, 6)), tolerance=math.nan), "tolerance"),
        (lambda: synthesise_function(np.linspace(0, 1, 6), np.sin(np.linspace(0, 1, 6)), tolerance=-1), "tolerance"),
        (lambda: synthesise_function(np.linspace(0, 1, 6), np.sin(np.linspace(0, 1, 6)), tolerance=None), "tolerance"),
    ],
)
def test_the_call_raises_a_named_planar_error(call, needle: str) -> None:
    with pytest.raises(PlanarError) as e:
        call()
    assert needle in str(e.value), str(e.value)


def test_a_huge_sample_count_is_refused_before_allocation() -> None:
    with pytest.raises(LimitError, match="PLANAR_MAX_SAMPLES"):
        info(LEG, samples=10**12)


@pytest.mark.slow
def test_info_still_works_at_a_small_count() -> None:
    assert info(LEG, samples=8).dof == 1


def test_array_summaries_show_plain_numbers_and_count_nan() -> None:
    text = short_repr(np.array([[0.0, 0.0, 0.0], [1.0, math.nan, 0.1], [2.0, 0.1, math.inf], [3.0, -0.2, 0.2]]))
    assert text == "<array of shape (4, 3), from -0.2 to 3.0, with 1 NaN, 1 inf>", text


def test_an_output_under_a_file_says_it_is_a_file(tmp_path: Path) -> None:
    from planar.fileio import atomic_write

    (tmp_path / "afile").write_text("x")
    with pytest.raises(InputError, match="is a file, not a folder"), atomic_write(tmp_path / "afile" / "x.gif"):
        pass
