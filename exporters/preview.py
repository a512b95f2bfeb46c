"""A photo-like PNG of one cut sheet (matplotlib): birch plywood, scorched cut lines, engraving.

For a look before cutting: the sheet in plywood colour, every cut as a dark
kerf line, holes showing the dark cutting bed, engraving as thin brown
strokes.  Deterministic bytes (no software tag).
"""

from __future__ import annotations

import io
import math
from typing import Any

import numpy as np

from planar.fabrication.sheet import Circle, Layout, bulge_points

__all__ = ["sheet_png"]


def sheet_png(layout: Layout, sheet: int = 0, settings: Any = None, px_per_mm: float = 3.0) -> bytes:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import PathPatch, Rectangle
    from matplotlib.path import Path as MPath

    W, H = layout.sheet_size
    pad = 6.0
    fig = plt.figure(figsize=((W + 2 * pad) * px_per_mm / 100, (H + 2 * pad) * px_per_mm / 100), dpi=100)
    ax = fig.add_axes((0, 0, 1, 1))
    ax.set_xlim(-pad, W + pad)
    ax.set_ylim(-pad, H + pad)
    ax.set_aspect("equal")
    ax.axis("off")
    fig.patch.set_facecolor("#2b2b2b")
    ax.add_patch(Rectangle((0, 0), W, H, facecolor="#e3c9a0", edgecolor="none"))
    # faint grain: fixed stripes, no randomness
    ys = np.linspace(0, H, 60)
    for k, yv in enumerate(ys):
        ax.plot([0, W], [yv + 0.8 * math.sin(k * 1.7), yv + 0.8 * math.sin(k * 1.7 + 2)], color="#d6b98c", lw=0.6, alpha=0.5)

    def ring(c) -> np.ndarray:
        if isinstance(c, Circle):
            a = np.linspace(0, 2 * math.pi, 97)
            return np.c_[c.centre[0] + c.radius * np.cos(a), c.centre[1] + c.radius * np.sin(a)]
        p = bulge_points(c, math.radians(3.0))
        return np.vstack([p, p[:1]])

    for p in layout.on_sheet(sheet):
        rings = [ring(p.outer)] + [ring(c) for c in p.inner]
        verts = np.vstack(rings)
        codes = np.concatenate([[MPath.MOVETO] + [MPath.LINETO] * (len(r) - 1) for r in rings])
        ax.add_patch(PathPatch(MPath(verts, codes), facecolor="#ecd5ae", edgecolor="#4a2c14", lw=0.9))
        for r in rings[1:]:
            ax.fill(r[:, 0], r[:, 1], color="#2b2b2b", lw=0)
        for st in p.engrave:
            ax.plot(st[:, 0], st[:, 1], color="#7a4a24", lw=0.6, solid_capstyle="round")
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=100, metadata={"Software": None})
    plt.close(fig)
    return buf.getvalue()
