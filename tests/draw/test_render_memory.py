"""Render memory is bounded by a chunk of frames, not by the animation's length (issue 24.3)."""

from __future__ import annotations

import pytest

from planar.bench.render import render_peak_memory


@pytest.mark.slow
@pytest.mark.parametrize("name", ["jansen-leg", "horse"])
def test_ten_thousand_frames_peak_under_300_mb(name):
    m = render_peak_memory(name, 10_000)
    assert m["frames"] == 10_000
    assert m["peak_mb"] <= 300.0, m


@pytest.mark.slow
def test_peak_memory_does_not_grow_with_frames():
    short = render_peak_memory("jansen-leg", 500)["peak_mb"]
    long = render_peak_memory("jansen-leg", 5_000)["peak_mb"]
    # before the chunked geometry, 10x the frames cost ~110 KB a frame more (about +500 MB here)
    assert long - short < 60.0, (short, long)
