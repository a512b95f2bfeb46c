"""Animated GIF: frames quantised to a fixed palette, written atomically with imageio.

Reproducible byte for byte: the palette is fixed by the style (no adaptive
quantisation), no dithering, no timestamps.  The GIF loops forever and every
frame delay is a whole number of 10 ms ticks, at least 20 ms (browsers play
shorter delays as 100 ms).
"""

from __future__ import annotations

import os
from typing import BinaryIO, cast, Iterable, Sequence

import numpy as np

from planar.fileio import atomic_write

__all__ = ["write_gif", "indexer", "frame_delay_ms", "MIN_DELAY_MS"]

MIN_DELAY_MS = 20


def frame_delay_ms(period_s: float, frames_per_cycle: int) -> int:
    """Delay per frame that plays one cycle in ``period_s``, rounded to 10 ms, at least 20 ms."""
    d = 1000.0 * period_s / max(1, frames_per_cycle)
    return max(MIN_DELAY_MS, int(round(d / 10.0)) * 10)


def _unique_palette(palette: Sequence[tuple[int, int, int]]) -> list[tuple[int, int, int]]:
    """The palette padded to 256 *distinct* entries.

    Pillow's GIF writer matches the given palette entry by entry; duplicate
    entries (zero padding) make that match quadratic, 25 ms a frame.
    """
    out: list[tuple[int, int, int]] = []
    for c in palette:
        if c not in out:
            out.append(tuple(int(v) for v in c))  # type: ignore[arg-type]
    used = set(out)
    k = 0
    while len(out) < 256:
        c = (k % 256, (k // 256) % 256, 255 - (k % 7))
        k += 1
        if c not in used:
            used.add(c)
            out.append(c)
    return out[:256]


def indexer(palette: Sequence[tuple[int, int, int]]):
    """A function mapping a PIL RGB frame to its palette indices (nearest colour, no dithering)."""
    from PIL import Image

    pal = _unique_palette(list(palette)[:255])
    pal_img = Image.new("P", (1, 1))
    pal_img.putpalette(bytes(c for rgb in pal for c in rgb))

    def index(frame) -> np.ndarray:
        return np.asarray(frame.quantize(palette=pal_img, dither=Image.Dither.NONE))

    return index


def write_gif(path: str | os.PathLike, frames: Iterable, delay_ms: int,
              palette: Sequence[tuple[int, int, int]]) -> int:
    """Write ``frames`` to ``path`` as a looping GIF; returns the number of frames.

    ``frames`` are PIL RGB images, or index arrays already made by
    :func:`indexer` with the same ``palette`` (so quantising can run where
    the frames are drawn).  The index frames go to imageio's pillow plugin
    with one global palette.
    """
    import imageio.v3 as iio

    from planar.errors import InputError

    if delay_ms < MIN_DELAY_MS:
        raise InputError("delay_ms", delay_ms, f"at least {MIN_DELAY_MS} ms (browsers slow shorter delays)")
    pal = _unique_palette(list(palette)[:255])
    flat = bytes(c for rgb in pal for c in rgb)
    index = indexer(palette[:255])
    idx = [f if isinstance(f, np.ndarray) else index(f) for f in frames]
    if not idx:
        raise InputError("frames", 0, "at least one frame")
    stack = np.stack(idx)
    with atomic_write(path, "wb") as fh:
        # mode "L" carries the indices; the palette argument gives them their colours
        iio.imwrite(cast(BinaryIO, fh), stack, plugin="pillow", extension=".gif", mode="L", palette=flat,
                    duration=[int(delay_ms)] * len(idx), loop=0, optimize=False, disposal=1)
    return len(idx)
