"""Single-line engraving text: Hershey's "futural" stroke font (the hershey-fonts package).

Laser software engraves a path along its stroke; live ``TEXT`` needs a font
the cutter may not have and outline fonts cut twice.  :func:`text_strokes`
returns open polylines in millimetres.  ``height`` is the cap height (the
height of ``H``), text centred on ``centre`` and turned by ``angle`` (radians,
counter-clockwise, y up).
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

__all__ = ["text_box", "text_strokes"]

#: futural's cap height and baseline when normalised to 1
_CAP, _BASE = 0.75, 0.25


@lru_cache(maxsize=1)
def _font():
    from HersheyFonts import HersheyFonts

    f = HersheyFonts()
    f.load_default_font("futural")
    f.normalize_rendering(1.0)
    return f


@lru_cache(maxsize=512)
def _unit_strokes(text: str) -> tuple[tuple[tuple[float, float], ...], ...]:
    """Strokes at cap height 1, baseline at y = 0, starting at x = 0."""
    strokes = [tuple((float(x) / _CAP, (float(y) - _BASE) / _CAP) for x, y in s) for s in _font().strokes_for_text(text)]
    strokes = [s for s in strokes if len(s) >= 2]
    if not strokes:
        return ()
    x0 = min(x for s in strokes for x, _ in s)
    return tuple(tuple((x - x0, y) for x, y in s) for s in strokes)


def text_box(text: str) -> tuple[float, float, float]:
    """``(width, bottom, top)`` of ``text`` at cap height 1 (bottom < 0 with descenders)."""
    s = _unit_strokes(text)
    if not s:
        return 0.0, 0.0, 1.0
    pts = np.array([p for st in s for p in st])
    return float(pts[:, 0].max()), float(min(0.0, pts[:, 1].min())), float(max(1.0, pts[:, 1].max()))


def text_strokes(text: str, height: float, centre: tuple[float, float], angle: float = 0.0) -> list[np.ndarray]:
    """Open polylines ``(n, 2)`` (mm) engraving ``text`` at cap height ``height`` centred on ``centre``."""
    w, bottom, top = text_box(text)
    c, s = math.cos(angle), math.sin(angle)
    rot = np.array([[c, -s], [s, c]])
    out = []
    for st in _unit_strokes(text):
        p = (np.asarray(st) - [w / 2, (bottom + top) / 2]) * height
        out.append(p @ rot.T + centre)
    return out
