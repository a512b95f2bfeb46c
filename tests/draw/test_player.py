"""The HTML player: one self-contained page that plays in headless Chromium (Debian's ``chromium``)."""

from __future__ import annotations

import io
import re
import shutil
from pathlib import Path

import numpy as np
import pytest

from planar.cli.main import main

GALLERY = Path(__file__).resolve().parents[2] / "gallery"
CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
ARGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-background-networking",
    "--disable-component-update",
    "--no-first-run",
]


def test_page_is_self_contained_and_reproducible(tmp_path):
    a, b = tmp_path / "a.html", tmp_path / "b.html"
    assert main(["render", str(GALLERY / "jansen-leg.toml"), "-o", str(a)]) == 0
    assert main(["render", str(GALLERY / "jansen-leg.toml"), "-o", str(b)]) == 0
    assert a.read_bytes() == b.read_bytes()
    page = a.read_text()
    # nothing fetched: no src/href attributes, no URL but the SVG namespace
    assert not re.search(r"\b(src|href)\s*=", page)
    assert set(re.findall(r"https?://[^\s\"']+", page)) <= {"http://www.w3.org/2000/svg"}
    assert "<svg" in page and "requestAnimationFrame" in page


def _pixels(png: bytes) -> np.ndarray:
    from PIL import Image

    return np.asarray(Image.open(io.BytesIO(png)).convert("RGB")).astype(int)


@pytest.mark.slow
@pytest.mark.skipif(CHROMIUM is None, reason="no chromium on PATH (Debian: apt-get install chromium)")
def test_jansen_player_plays_in_headless_chromium(tmp_path):
    playwright = pytest.importorskip("playwright.sync_api", reason="the playwright package (test extra) drives chromium")
    out = tmp_path / "j.html"
    assert main(["render", str(GALLERY / "jansen-leg.toml"), "-o", str(out)]) == 0
    errors: list[str] = []
    with playwright.sync_playwright() as p:
        # playwright gives the browser a fresh temporary profile itself (it refuses --user-data-dir here)
        browser = p.chromium.launch(executable_path=CHROMIUM, args=ARGS[1:], headless=True)
        try:
            page = browser.new_page(viewport={"width": 400, "height": 320})
            page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
            page.on("pageerror", lambda e: errors.append(str(e)))
            page.goto(out.as_uri())
            page.wait_for_timeout(150)
            first = _pixels(page.locator("#view").screenshot())
            angle1 = page.locator("#angle").text_content()
            page.wait_for_timeout(450)  # the cycle plays in 1 s: about 11 frames later
            second = _pixels(page.locator("#view").screenshot())
            angle2 = page.locator("#angle").text_content()
            # the scrubber: a still at frame 0 and at frame 12 (half a turn) differ too
            page.goto(out.as_uri() + "#frame=0")
            page.reload()
            still0 = _pixels(page.locator("#view").screenshot())
            page.goto(out.as_uri() + "#frame=12")
            page.reload()
            still12 = _pixels(page.locator("#view").screenshot())
            label = page.locator("#angle").text_content()
        finally:
            browser.close()
    assert errors == []
    moved = np.abs(first - second).sum(axis=2) > 30
    assert moved.sum() > 200, (angle1, angle2)  # the mechanism moved between the two shots
    assert angle1 != angle2
    assert (np.abs(still0 - still12).sum(axis=2) > 30).sum() > 200
    assert label == "172.8\u00b0"  # frame 12 of 25 frames a turn: 12 * 360 / 25 degrees
    # something is drawn: the parts' colours cover a good part of the view
    assert (np.abs(first - 255).sum(axis=2) > 30).sum() > 2000
