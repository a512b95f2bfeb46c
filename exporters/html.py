"""The animation player as one self-contained HTML file (SVG and a few lines of JavaScript, no network).

The page is made by :func:`planar.draw.player.player_html`; this module only writes it.
"""

from __future__ import annotations

import os

from planar.fileio import atomic_write

__all__ = ["write_html"]


def write_html(path: str | os.PathLike, page: str) -> int:
    """Write ``page`` to ``path`` (UTF-8, atomically); returns the bytes written."""
    data = page.encode("utf-8")
    with atomic_write(path, "wb") as fh:
        fh.write(data)
    return len(data)
