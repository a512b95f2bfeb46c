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


#: the scenes whose long render's peak memory ``bench render`` reports: the embedded demo's Horse and the Jansen leg
MEMORY_SCENES = ("horse", "jansen-leg")

_JANSEN = {
    "name": "jansen-leg",
    "mechanism": {
        "type": "linkage",
        "points": {"foot": "F"},
        "nodes": [
            {"name": "O", "kind": "fixed", "at": [0.0, 0.0]},
            {"name": "Z", "kind": "fixed", "at": [-38.0, -7.8]},
            {"name": "A", "kind": "crank", "centre": "O", "radius": 15.0},
            {"name": "B", "kind": "rrr", "a": "A", "ra": 50.0, "b": "Z", "rb": 41.5, "branch": -1},
            {"name": "C", "kind": "rrr", "a": "A", "ra": 61.9, "b": "Z", "rb": 39.3, "branch": 1},
            {"name": "D", "kind": "rrr", "a": "B", "ra": 55.8, "b": "Z", "rb": 40.1, "branch": -1},
            {"name": "E", "kind": "rrr", "a": "D", "ra": 39.4, "b": "C", "rb": 36.7, "branch": -1},
            {"name": "F", "kind": "rrr", "a": "E", "ra": 65.7, "b": "C", "rb": 49.0, "branch": -1},
        ],
        "links": [
            {"name": "crank", "nodes": ["O", "A"]},
            {"name": "j", "nodes": ["A", "B"]},
            {"name": "k", "nodes": ["A", "C"]},
            {"name": "upper", "nodes": ["Z", "B", "D"]},
            {"name": "c", "nodes": ["Z", "C"]},
            {"name": "f", "nodes": ["D", "E"]},
            {"name": "lower", "nodes": ["C", "E", "F"]},
        ],
    },
    "driver": {"speed": 1.0, "samples_per_cycle": 36},
    "render": {"width": 320, "height": 240},
}

_MEMORY_CHILD = """
import json, resource, sys, time
from planar.app.pipeline import render_scene
from planar.scene.load import build_scene, parse_scene
data = json.loads(sys.argv[1])
scene = build_scene(parse_scene(data, "<bench>"), "<bench>")
t0 = time.process_time()
n = render_scene(scene, sys.argv[2], progress=False)
peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
try:  # Linux keeps ru_maxrss across exec (a parent's size at fork counts): VmHWM is this image's own peak
    with open("/proc/self/status") as fh:
        peak = next(int(line.split()[1]) for line in fh if line.startswith("VmHWM:")) / 1024.0
except (OSError, StopIteration):
    pass
print(json.dumps({"frames": n, "cpu_s": time.process_time() - t0, "peak_mb": peak}))
"""


def render_peak_memory(name: str, frames: int) -> dict[str, Any]:
    """Peak resident memory (MB, ``ru_maxrss`` of a fresh process) of rendering ``frames`` frames of ``name``
    (``"horse"``: the demo's Horse, ``"jansen-leg"``) to a GIF at 25 frames/s, and the CPU seconds it took."""
    import json
    import subprocess
    import sys
    import tempfile

    from planar.app.pipeline import DEMO_SCENES

    data = json.loads(json.dumps(_JANSEN if name == "jansen-leg" else DEMO_SCENES[name]))
    speed = data["driver"]["speed"]
    data["driver"]["cycles"] = frames / (25.0 / speed)  # 25 frames/s: a cycle is 25/speed frames
    data["render"]["fps"] = 25.0
    with tempfile.TemporaryDirectory() as tmp:
        out = subprocess.run(
            [sys.executable, "-c", _MEMORY_CHILD, json.dumps(data), os.path.join(tmp, "x.gif")],
            capture_output=True,
            text=True,
            check=True,
        )
    return json.loads(out.stdout.strip().splitlines()[-1])


#: bytes the peer holds per frame and pixel: matplotlib's PillowWriter keeps every frame (RGBA) until it saves,
#: and converts them to palette images then (measured: see docs/explanation/memory.md)
PEER_FRAME_BYTES_PER_PX = 5.0
#: what the benchmark's libraries (matplotlib, its figure, the renderer) add to this process beside its frames,
#: bytes (measured: 20 frames peaked at 228 MiB and 120 at 313 MiB from 26 MiB held, 190 MiB beside 870 kB a frame)
PEER_LOAD_BYTES = 200 * 2**20


def _check_frames(n: int, width: int, height: int) -> None:
    """:class:`~planar.errors.LimitError` before ``n`` frames of ``width`` x ``height`` pixels would pass the
    frame limit, or the memory limit with the peer's frames held (``-n`` named)."""
    from planar.core.limits import check_count, check_memory, resident_bytes, units_within

    check_count("frames", "-n", n, "frames")
    per = PEER_FRAME_BYTES_PER_PX * width * height
    held = resident_bytes() + PEER_LOAD_BYTES
    check_memory(
        "-n", n, held + per * n, "the peer's frames (held until its GIF is saved)", fits=f"{units_within(held, per):,} frames"
    )


def bench_render(
    n: int = 120, repeats: int = 5, width: int = 480, height: int = 360, memory_frames: int = 10_000
) -> dict[str, Any]:
    """Frames per second and GIF size: planar's renderer vs matplotlib's animation writer; and peak memory.

    Both draw the same four-bar (parts as filled outlines, coupler trail) at
    the same size and frame count into a GIF; the best of ``repeats`` runs
    each, end to end (drawing, palette, encoding, file).  Then the Horse and
    the Jansen leg are rendered to ``memory_frames`` frames each in a fresh
    process, whose peak resident memory (MB) is reported (0 frames: skipped).
    """
    import tempfile

    from planar.app.formats import writer
    from planar.draw.frames import Renderer, Style, palette_colors
    from planar.scene.catalog import get

    _check_frames(n, width, height)
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
        "memory": {name: render_peak_memory(name, memory_frames) for name in MEMORY_SCENES} if memory_frames else {},
    }


def format_render(r: dict[str, Any]) -> str:
    return "\n".join(
        [
            f"four-bar GIF, {r['frames']} frames at {r['size_px'][0]}x{r['size_px'][1]}",
            f"  planar        {r['planar_fps']:8.1f} frames/s   {r['planar_gif_bytes']:>9,} bytes",
            f"  matplotlib    {r['peer_fps']:8.1f} frames/s   {r['peer_gif_bytes']:>9,} bytes",
            f"  ratio planar/matplotlib  {r['ratio']:.2f} (frames/s), size {r['size_ratio']:.2f}",
        ]
        + [
            f"peak memory, {m['frames']:,} frames of {name}: {m['peak_mb']:.0f} MB ({m['cpu_s']:.1f} s CPU)"
            for name, m in r.get("memory", {}).items()
        ]
    )
