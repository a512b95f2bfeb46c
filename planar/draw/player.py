"""A self-contained animation player: one HTML page of SVG and a few lines of JavaScript, no network.

:func:`player_html` writes the page; :class:`Player` holds it and shows it inline in
Jupyter, JupyterLab, VS Code and Colab (``_repr_html_``: the page in an ``<iframe
srcdoc>``, so it runs the same in every front end, trusted or not).  ``planar render
SCENE -o x.html`` writes the same page (:mod:`exporters.html`).

What the page holds: each part's outline once, in its own frame (holes cut by the
even-odd rule), and per frame each moving part's pose ``(x, y, angle)``; the browser
places the parts with an SVG ``transform``.  So the page grows by a few numbers per
part and frame, not by the outlines.  Parts that move in another plane (a toy's
followers turning about x) are drawn as their projected outline per frame.  Trails
of the named points are polylines of the fine motion; invalid frames tint the parts
red.  Controls: play/pause, a scrubber over the driver angle (degrees), and the
scene's speed (a cycle plays in ``1 / speed`` seconds).  ``#frame=K`` in the page's
address opens it paused at frame ``K`` (what the tests use for still shots).

Coordinates: the mechanism's view plane, y up; the page's SVG flips y once.
Same input, same bytes: numbers are written with a fixed number of digits.
"""

from __future__ import annotations

import html
import json
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from planar.core.geometry import poses_apply
from planar.core.model import Mechanism, Motion
from planar.draw.frames import PART_COLORS, Style, _rings, project

__all__ = ["Player", "player_html"]

Array = NDArray[np.float64]

#: significant digits of the coordinates written (relative to the mechanism's extent)
DIGITS = 5


def _round(a: Any, q: float) -> list:
    """``a`` rounded to multiples of ``q`` as nested lists of floats (deterministic text)."""
    return (np.round(np.asarray(a, float) / q) * q).round(12).tolist()


def _path(rings: Sequence[Array], q: float) -> str:
    """An SVG path of closed rings (exterior then holes)."""
    out = []
    for r in rings:
        pts = _round(r, q)
        out.append("M" + "L".join(f"{x:.6g},{y:.6g}" for x, y in pts) + "Z")
    return "".join(out)


@dataclass
class _Scene:
    """What the page draws, in view coordinates."""

    box: tuple[float, float, float, float]
    static: list[dict]
    moving: list[dict]
    trails: dict[str, list]
    valid: list[int]
    driver_deg: list[float]


def _geometry(mech: Mechanism, motion: Motion, fine: Motion, trails: Sequence[str] | None) -> _Scene:
    """Outlines, per-frame poses (or projected outlines), trails and the view box of ``motion``."""
    from planar.draw.toyview import assembled

    mech0 = mech
    mech, motion, _ = assembled(mech0, motion)
    if mech is not mech0:
        fine = assembled(mech0, fine)[1]
    view = getattr(mech, "view", "xy")
    valid = np.asarray(motion.valid, bool)
    keep = valid if valid.any() else np.ones_like(valid)
    lo, hi = np.full(2, np.inf), np.full(2, -np.inf)
    for p in mech.parts:
        for r in _rings(p)[:1]:
            w = project(p, poses_apply(motion.poses[p.name][keep], r), view).reshape(-1, 2)
            lo, hi = np.minimum(lo, w.min(0)), np.maximum(hi, w.max(0))
    names = list(trails) if trails is not None else list(fine.points)
    fine_ok = np.asarray(fine.valid, bool)
    tr = {}
    for n in names:
        if n in fine.points:
            part = mech.part(mech.points[n][0])
            tr[n] = project(part, fine.points[n], view)
            if fine_ok.any():
                lo, hi = np.minimum(lo, tr[n][fine_ok].min(0)), np.maximum(hi, tr[n][fine_ok].max(0))
    span = float(max(hi - lo)) if np.all(np.isfinite(hi - lo)) else 1.0
    span = span if span > 0 else 1.0
    q = span * 10.0**-DIGITS
    pad = 0.05 * span
    box = (float(lo[0] - pad), float(-hi[1] - pad), float(hi[0] - lo[0] + 2 * pad), float(hi[1] - lo[1] + 2 * pad))
    static, moving = [], []
    for i, p in enumerate(mech.parts):
        colour = "#ebebeb" if p.ground else PART_COLORS[(i - 1) % len(PART_COLORS)]
        pose = motion.poses[p.name]
        rings = _rings(p)
        still = np.ptp(pose, axis=0).max() <= 1e-12 * max(1.0, float(np.abs(pose).max()))
        if still:
            world = [project(p, poses_apply(pose[0], r), view) for r in rings]
            static.append({"d": _path(world, q), "fill": colour, "ground": bool(p.ground)})
        elif p.plane == view:
            moving.append({"d": _path(rings, q), "fill": colour, "poses": _poses(pose, q)})
        else:  # another plane: its projected exterior, frame by frame
            track = project(p, poses_apply(pose, rings[0]), view)
            moving.append({"fill": colour, "paths": [_path([w], q) for w in track]})
    return _Scene(
        box,
        static,
        moving,
        {n: _round(v[fine_ok] if fine_ok.any() else v, q) for n, v in tr.items()},
        valid.astype(int).tolist(),
        [round(math.degrees(float(v)) % 360.0, 3) for v in motion.driver],
    )


def _poses(pose: Array, q: float) -> list:
    """Per frame ``[x, y, angle in degrees]`` rounded (the angle to 1e-3 degrees)."""
    xy = _round(pose[:, :2], q)
    deg = np.round(np.degrees(pose[:, 2]), 3).tolist()
    return [[x, y, a] for (x, y), a in zip(xy, deg)]


_PAGE = """<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>{title}</title>
<style>
body{{margin:0;font:13px system-ui,sans-serif;background:#fff;color:#222}}
#planar-player{{width:{width}px}}
svg{{display:block;background:{background}}}
.part{{stroke:#303030;stroke-width:{stroke};fill-rule:evenodd;stroke-linejoin:round}}
.ground{{stroke:#a0a0a0}}
.bad .part{{fill:#e88;}}
.trail{{fill:none;stroke:{trail};stroke-width:{stroke}}}
.dot{{fill:{trail}}}
#bar{{display:flex;gap:6px;align-items:center;padding:4px 2px}}
#bar input[type=range]{{flex:1}}
button{{min-width:4.5em}}
</style></head><body>
<div id="planar-player">
<svg id="view" width="{width}" height="{height}" viewBox="{viewbox}" xmlns="http://www.w3.org/2000/svg">
<g transform="scale(1,-1)">{static}<g id="moving"></g>{trails}{dots}</g></svg>
<div id="bar"><button id="play" type="button">pause</button>
<input id="scrub" type="range" min="0" max="{last}" value="0" step="1" aria-label="frame">
<span id="angle">0.0&#176;</span></div></div>
<script>
"use strict";
(function () {{
  const D = {data};
  const NS = "http://www.w3.org/2000/svg";
  const view = document.getElementById("view"), holder = document.getElementById("moving");
  const scrub = document.getElementById("scrub"), play = document.getElementById("play");
  const label = document.getElementById("angle");
  const parts = D.moving.map(function (m) {{
    const p = document.createElementNS(NS, "path");
    p.setAttribute("class", "part");
    p.setAttribute("fill", m.fill);
    if (m.d) p.setAttribute("d", m.d);
    holder.appendChild(p);
    return p;
  }});
  const dots = Array.from(document.querySelectorAll(".dot"));
  const n = D.valid.length;
  let frame = 0, playing = true, start = null;
  function show(i) {{
    frame = i;
    D.moving.forEach(function (m, k) {{
      if (m.poses) {{
        const q = m.poses[i];
        parts[k].setAttribute("transform", "translate(" + q[0] + "," + q[1] + ") rotate(" + q[2] + ")");
      }} else {{
        parts[k].setAttribute("d", m.paths[i]);
      }}
    }});
    dots.forEach(function (el) {{
      const pt = D.dots[el.dataset.name][i];
      el.setAttribute("cx", pt[0]);
      el.setAttribute("cy", pt[1]);
    }});
    view.classList.toggle("bad", !D.valid[i]);
    scrub.value = i;
    label.textContent = D.driver[i].toFixed(1) + "\\u00b0";
  }}
  function tick(now) {{
    if (!playing) return;
    if (start === null) start = now - frame * D.frame_ms;
    show(Math.floor((now - start) / D.frame_ms) % n);
    window.requestAnimationFrame(tick);
  }}
  function setPlaying(on) {{
    playing = on;
    play.textContent = on ? "pause" : "play";
    start = null;
    if (on) window.requestAnimationFrame(tick);
  }}
  play.addEventListener("click", function () {{ setPlaying(!playing); }});
  scrub.addEventListener("input", function () {{ setPlaying(false); show(parseInt(scrub.value, 10)); }});
  const m = /frame=(\\d+)/.exec(window.location.hash);
  show(m ? Math.min(parseInt(m[1], 10), n - 1) : 0);
  setPlaying(!m);
}})();
</script></body></html>
"""


def _num(v: float) -> str:
    return f"{v:.6g}"


def player_html(
    mech: Mechanism,
    motion: Motion,
    fine: Motion | None = None,
    style: Style | None = None,
    frame_ms: float | None = None,
    title: str | None = None,
) -> str:
    """The player page of ``motion`` of ``mech`` (a complete HTML document, no network).

    Parameters
    ----------
    mech, motion
        The mechanism and the frames to show (one frame per sample).
    fine
        The finer motion the trails are drawn from (default ``motion``).
    style
        Size in pixels, background, trail colour and which named points leave trails
        (:class:`planar.draw.frames.Style`; default: 480 x 360, every point).
    frame_ms
        Milliseconds a frame shows; default: a driver cycle in its period (``1 / speed`` s).
    title
        The page title (default: the mechanism's name).
    """
    style = style or Style()
    fine = fine if fine is not None else motion
    g = _geometry(mech, motion, fine, style.trails)
    n = len(motion)
    if frame_ms is None:
        per_cycle = n if motion.t is None or n < 2 else mech.driver.period / max(float(motion.t[1] - motion.t[0]), 1e-12)
        frame_ms = 1000.0 * mech.driver.period / max(1.0, per_cycle)
    bx, by, bw, bh = g.box
    stroke = _num(1.2 * max(bw / style.width, bh / style.height))
    static = "".join(f'<path class="part{" ground" if s["ground"] else ""}" fill="{s["fill"]}" d="{s["d"]}"/>' for s in g.static)
    trails = "".join(
        f'<polyline class="trail" points="{" ".join(f"{x:.6g},{y:.6g}" for x, y in pts)} {pts[0][0]:.6g},{pts[0][1]:.6g}"/>'
        for pts in g.trails.values()
        if pts
    )
    r = _num(2.5 * max(bw / style.width, bh / style.height))
    dot_tracks = {}
    for name in g.trails:
        part = mech.part(mech.points[name][0])
        track = project(part, motion.points[name], getattr(mech, "view", "xy")) if name in motion.points else None
        if track is not None and part.plane == getattr(mech, "view", "xy"):
            dot_tracks[name] = _round(track, bw * 10.0**-DIGITS)
    dots = "".join(f'<circle class="dot" data-name="{html.escape(k)}" r="{r}"/>' for k in dot_tracks)
    data = {
        "moving": g.moving,
        "dots": dot_tracks,
        "valid": g.valid,
        "driver": g.driver_deg,
        "frame_ms": round(float(frame_ms), 6),
    }
    return _PAGE.format(
        title=html.escape(title or mech.name),
        width=style.width,
        height=style.height,
        background=style.background,
        trail=style.trail,
        stroke=stroke,
        viewbox=f"{_num(bx)} {_num(by)} {_num(bw)} {_num(bh)}",
        static=static,
        trails=trails,
        dots=dots,
        last=n - 1,
        data=json.dumps(data, separators=(",", ":")).replace("</", "<\\/"),
    )


class Player:
    """An animation that shows itself inline in a notebook and saves as one HTML file.

    Made by :func:`planar.draw.notebook.animate` (``mech.animate()``, ``motion.animate()``).
    """

    def __init__(self, page: str, width: int, height: int, frames: int, name: str) -> None:
        self.page = page
        self.width = width
        self.height = height
        self.frames = frames
        self.name = name

    def __repr__(self) -> str:
        return f"<Player {self.name!r}: {self.frames} frames, {len(self.page):,} bytes of HTML>"

    def _repr_html_(self) -> str:
        return (
            f'<iframe srcdoc="{html.escape(self.page, quote=True)}" width="{self.width + 8}" '
            f'height="{self.height + 48}" style="border:0" title="{html.escape(self.name)}"></iframe>'
        )

    def save(self, path: Any) -> None:
        """Write the page to ``path`` (an ``.html`` file), atomically."""
        from planar.fileio import atomic_write

        with atomic_write(path, "w") as fh:
            fh.write(self.page)
