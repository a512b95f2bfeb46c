"""MP4 and WebM through imageio's ffmpeg plugin (the optional ``video`` extra).

``pip install 'planar[video]'`` installs ``imageio-ffmpeg``, which bundles an
ffmpeg binary.  Frames are streamed to ffmpeg as they are drawn; the file is
written beside the target under a temporary name and renamed when complete.
Metadata that would differ between runs (creation time, encoder string) is
left out, so the same input gives the same bytes with the same ffmpeg.
"""

from __future__ import annotations

import contextlib
import os
from collections.abc import Iterable
from pathlib import Path

import numpy as np

from planar.errors import InputError

__all__ = ["VIDEO_CODECS", "video_available", "write_video"]

#: container suffix -> (codec, extra ffmpeg output arguments)
VIDEO_CODECS: dict[str, tuple[str, list[str]]] = {
    ".mp4": ("libx264", ["-preset", "medium", "-crf", "20", "-movflags", "+faststart"]),
    ".webm": ("libvpx-vp9", ["-b:v", "0", "-crf", "32", "-row-mt", "0"]),
}


def video_available() -> bool:
    """Whether the ``video`` extra (imageio-ffmpeg) is installed."""
    try:
        import imageio_ffmpeg  # noqa: F401
    except ImportError:
        return False
    return True


def write_video(path: str | os.PathLike, frames: Iterable, fps: float) -> int:
    """Encode RGB ``frames`` (PIL images or ``(H, W, 3)`` uint8 arrays) to ``path`` at ``fps``; returns the count."""
    target = Path(path)
    suffix = target.suffix.lower()
    if suffix not in VIDEO_CODECS:
        raise InputError("-o", str(path), f"a video file ending in {' or '.join(VIDEO_CODECS)}")
    if not video_available():
        raise InputError(
            "-o", str(path), "the video extra for MP4/WebM output: pip install 'planar[video]' (imageio-ffmpeg), or write a .gif"
        )
    import imageio.v2 as iio2

    parent = target.parent if str(target.parent) else Path(".")
    if not parent.is_dir():
        raise InputError("output", str(path), f"a path in an existing directory ({parent} does not exist)")
    tmp = parent / f".{target.name}.part{suffix}"
    codec, extra = VIDEO_CODECS[suffix]
    params = extra + ["-threads", "1", "-map_metadata", "-1", "-fflags", "+bitexact", "-flags:v", "+bitexact"]
    n = 0
    try:
        writer = iio2.get_writer(
            str(tmp),
            format="FFMPEG",
            mode="I",
            fps=fps,
            codec=codec,
            quality=None,
            pixelformat="yuv420p",
            macro_block_size=2,
            ffmpeg_log_level="error",
            output_params=params,
        )
        try:
            for f in frames:
                writer.append_data(np.asarray(f.convert("RGB") if hasattr(f, "convert") else f, dtype=np.uint8))
                n += 1
        finally:
            writer.close()
        if n == 0:
            raise InputError("frames", 0, "at least one frame")
        os.replace(tmp, target)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise
    return n
