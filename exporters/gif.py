"""Animated GIF, streamed: each frame is encoded and written as soon as it is drawn.

Reproducible byte for byte: the palette is fixed by the style (no adaptive
quantisation), no dithering, no timestamps.  The GIF loops forever and every
frame delay is a whole number of 10 ms ticks, at least 20 ms (browsers play
shorter delays as 100 ms).

Memory stays flat in the number of frames: the file is written frame by frame
(a GIF89a header with one global palette, then per frame a graphic control
extension and the LZW-coded rectangle that changed since the previous frame,
Pillow's encoder), never holding more than two frames.  The result is read by
any GIF decoder (the tests read it back with Pillow and compare every pixel).
"""

from __future__ import annotations

import os
import struct
from collections.abc import Iterable, Sequence

import numpy as np

from planar.fileio import atomic_write

__all__ = ["MIN_DELAY_MS", "frame_delay_ms", "indexer", "write_gif"]

MIN_DELAY_MS = 20


def frame_delay_ms(period_s: float, frames_per_cycle: int) -> int:
    """Delay per frame that plays one cycle in ``period_s``, rounded to 10 ms, at least 20 ms."""
    d = 1000.0 * period_s / max(1, frames_per_cycle)
    return max(MIN_DELAY_MS, int(round(d / 10.0)) * 10)


def _unique_palette(palette: Sequence[tuple[int, int, int]]) -> list[tuple[int, int, int]]:
    """The palette padded to 256 *distinct* entries.

    Pillow's quantiser matches the given palette entry by entry; duplicate
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


def _header(width: int, height: int, palette: bytes) -> bytes:
    """GIF89a signature, logical screen (global 256-colour table), the table, and loop-forever."""
    screen = b"GIF89a" + struct.pack("<HHBBB", width, height, 0xF7, 0, 0)
    loop = b"!\xff\x0bNETSCAPE2.0\x03\x01" + struct.pack("<H", 0) + b"\x00"
    return screen + palette + loop


def _changed_box(prev: np.ndarray | None, cur: np.ndarray) -> tuple[int, int, int, int]:
    """``(x0, y0, x1, y1)`` of the pixels that differ from ``prev`` (the whole frame first; 1x1 if none)."""
    if prev is None:
        return 0, 0, cur.shape[1], cur.shape[0]
    diff = prev != cur
    rows = np.flatnonzero(diff.any(axis=1))
    if rows.size == 0:
        return 0, 0, 1, 1
    cols = np.flatnonzero(diff.any(axis=0))
    return int(cols[0]), int(rows[0]), int(cols[-1]) + 1, int(rows[-1]) + 1


def _frame_bytes(idx: np.ndarray, box: tuple[int, int, int, int], delay_ms: int, palette: bytes) -> bytes:
    """One frame: graphic control extension (delay, disposal "leave in place") and the rectangle ``box``."""
    from PIL import GifImagePlugin, Image

    x0, y0, x1, y1 = box
    crop = np.ascontiguousarray(idx[y0:y1, x0:x1])
    im = Image.frombytes("P", (x1 - x0, y1 - y0), crop.tobytes())
    im.putpalette(palette)
    gce = b"!\xf9\x04" + struct.pack("<BHBB", 1 << 2, delay_ms // 10, 0, 0)
    # Pillow's LZW encoder for the image descriptor and data (no local palette: the global one applies)
    return gce + b"".join(GifImagePlugin.getdata(im, offset=(x0, y0)))


def write_gif(path: str | os.PathLike, frames: Iterable, delay_ms: int, palette: Sequence[tuple[int, int, int]]) -> int:
    """Write ``frames`` to ``path`` as a looping GIF, streaming; returns the number of frames.

    ``frames`` are PIL RGB images, or index arrays already made by
    :func:`indexer` with the same ``palette`` (so quantising can run where
    the frames are drawn).  The file appears (atomically) only when every
    frame has been written.
    """
    from planar.errors import InputError

    if delay_ms < MIN_DELAY_MS or delay_ms % 10:
        raise InputError("delay_ms", delay_ms, f"a multiple of 10 ms, at least {MIN_DELAY_MS} ms (browsers slow shorter delays)")
    pal = _unique_palette(list(palette)[:255])
    flat = bytes(c for rgb in pal for c in rgb)
    index = indexer(palette[:255])
    n = 0
    prev: np.ndarray | None = None
    with atomic_write(path, "wb") as fh:
        for f in frames:
            idx = f if isinstance(f, np.ndarray) else index(f)
            idx = np.asarray(idx, dtype=np.uint8)
            if prev is None:
                fh.write(_header(idx.shape[1], idx.shape[0], flat))
            elif idx.shape != prev.shape:
                raise InputError("frames", idx.shape, f"every frame the size of the first {prev.shape}")
            fh.write(_frame_bytes(idx, _changed_box(prev, idx), int(delay_ms), flat))
            prev = idx
            n += 1
        if n == 0:
            raise InputError("frames", 0, "at least one frame")
        fh.write(b";")
    return n
