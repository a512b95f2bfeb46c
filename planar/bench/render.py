"""``planar bench render``: planar's renderer against matplotlib's animation writer, same four-bar, same GIF."""

from __future__ import annotations

import os
from typing import TYPE_CHECKING, Any

import numpy as np

from planar.bench.timing import _best_time

if TYPE_CHECKING:
    from numpy.typing import NDArray

    Array = NDArray[np.float64]


def _matplotlib_gif(mech, motion, path: str, width: int, height: int, delay_ms: int) -> None:
    """The peer: matplotlib's FuncAnimation + PillowWriter drawing the same parts and trail."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.animation import FuncAnimation, PillowWriter
    from matplotlib.patches import Polygon

    from planar.core.geometry import poses_apply
    from planar.draw.frames import PART_COLORS, _rings

    fig = plt.figure(figsize=(width / 100, height / 100), dpi=100)
    ax = fig.add_axes((0, 0, 1, 1))
    ax.set_aspect("equal")
    ax.axis("off")
    rings = {p.name: poses_apply(motion.poses[p.name], _rings(p)[0]) for p in mech.parts}
    allp = np.concatenate([r.reshape(-1, 2) for r in rings.values()])
    pad = 0.05 * np.ptp(allp, axis=0).max()
    ax.set_xlim(allp[:, 0].min() - pad, allp[:, 0].max() + pad)
    ax.set_ylim(allp[:, 1].min() - pad, allp[:, 1].max() + pad)
    patches = {}
    for i, p in enumerate(mech.parts):
        colour = "#c8c8c8" if p.ground else PART_COLORS[(i - 1) % len(PART_COLORS)]
        patches[p.name] = ax.add_patch(Polygon(rings[p.name][0], closed=True, fc=colour, ec="#303030"))
    for pts in motion.points.values():
        ax.plot(pts[:, 0], pts[:, 1], lw=1, color="#7f3fbf")

    def update(i: int):
        for n, patch in patches.items():
            patch.set_xy(rings[n][i])  # type: ignore[attr-defined]  # Polygon patches
        return list(patches.values())

    anim = FuncAnimation(fig, update, frames=len(motion), blit=False)
    anim.save(path, writer=PillowWriter(fps=int(round(1000.0 / delay_ms))))
    plt.close(fig)


def bench_render(n: int = 120, repeats: int = 5, width: int = 480, height: int = 360) -> dict[str, Any]:
    """Frames per second and GIF size: planar's renderer vs matplotlib's animation writer.

    Both draw the same four-bar (parts as filled outlines, coupler trail) at
    the same size and frame count into a GIF; the best of ``repeats`` runs
    each, end to end (drawing, palette, encoding, file).
    """
    import tempfile

    from planar.app.formats import writer
    from planar.draw.frames import Renderer, Style, palette_colors
    from planar.scene.catalog import get

    gif = writer("gif")
    frame_delay_ms, indexer, write_gif = gif.frame_delay_ms, gif.indexer, gif.write_gif
    mech = get("fourbar-crank-rocker")
    motion = mech.run(samples_per_cycle=n)
    delay = frame_delay_ms(mech.driver.period, n)
    with tempfile.TemporaryDirectory() as tmp:
        ours_path = os.path.join(tmp, "planar.gif")
        peer_path = os.path.join(tmp, "matplotlib.gif")

        def ours() -> None:
            r = Renderer(mech, motion, Style(width=width, height=height))
            pal = palette_colors(r.style, len(mech.parts))
            write_gif(ours_path, r.frames(post=indexer(pal)), delay, pal)

        def peer() -> None:
            _matplotlib_gif(mech, motion, peer_path, width, height, delay)

        ours()
        peer()
        t_ours = _best_time(ours, repeats)
        t_peer = _best_time(peer, repeats)
        size_ours = os.path.getsize(ours_path)
        size_peer = os.path.getsize(peer_path)
    return {
        "benchmark": "render",
        "frames": n,
        "size_px": [width, height],
        "planar_fps": n / t_ours,
        "peer": "matplotlib FuncAnimation + PillowWriter",
        "peer_fps": n / t_peer,
        "ratio": (n / t_ours) / (n / t_peer),
        "planar_gif_bytes": size_ours,
        "peer_gif_bytes": size_peer,
        "size_ratio": size_ours / size_peer,
    }


def format_render(r: dict[str, Any]) -> str:
    return "\n".join(
        [
            f"four-bar GIF, {r['frames']} frames at {r['size_px'][0]}x{r['size_px'][1]}",
            f"  planar        {r['planar_fps']:8.1f} frames/s   {r['planar_gif_bytes']:>9,} bytes",
            f"  matplotlib    {r['peer_fps']:8.1f} frames/s   {r['peer_gif_bytes']:>9,} bytes",
            f"  ratio planar/matplotlib  {r['ratio']:.2f} (frames/s), size {r['size_ratio']:.2f}",
        ]
    )
