"""Off-screen raster frames of a mechanism's motion (no display, no window system).

Parts are drawn as filled outlines with their holes and slots cut out
(optionally translucent), pins as dots, the ground as a light plate, trails
of named points (coupler curves, drawn above the parts) and polygons swept
along with a part (a foot).  Drawing happens at
``supersample`` times the size and is reduced with a box filter, which
antialiases every edge.  The camera fits every part over the whole motion,
so nothing leaves the frame.  Invalid samples are drawn at their nearest real
configuration, tinted, with the failing joint ringed and named.

Coordinates: the mechanism's view plane (x right, y up); renderers flip y,
nobody else does.  Parts that move in another plane (wind-up #6 and #9 turn
about x) are projected orthographically onto the view plane.

All geometry is transformed for every frame at once with numpy; the per-frame
loop only issues drawing calls.
"""

from __future__ import annotations

import threading
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from planar.core.fields import check_fields, check_finite, check_kind
from planar.core.geometry import poses_apply
from planar.core.model import Mechanism, Motion, Part
from planar.errors import InputError

__all__ = ["CHUNK_FRAMES", "Renderer", "Style", "palette_colors", "project"]

Array = NDArray[np.float64]
RGB = tuple[int, int, int]

#: frames whose outlines are computed together: the renderer's memory is bounded by this, not by the animation
CHUNK_FRAMES = 256


@dataclass
class _Chunk:
    """Pixel geometry of frames ``start`` to ``stop`` (exclusive): per part its rings ``(K, M, 2)``,
    the swept polygons, the pins ``(K, 2)`` and the overlay's parts."""

    start: int
    stop: int
    parts: list[list[Array]]
    sweeps: list[list[Array]]
    pins: dict[str, Array]
    overlay: list[list[Array]]


def _extent(tracks: Sequence[Array]) -> tuple[Array, Array] | None:
    """Lowest and highest finite point of ``tracks`` (arrays of points, last axis 2), or None if none is finite."""
    if not tracks:
        return None
    allp = np.concatenate([np.asarray(v).reshape(-1, 2) for v in tracks])
    allp = allp[np.all(np.isfinite(allp), axis=1)]
    if allp.size == 0:
        return None
    return allp.min(0), allp.max(0)


PART_COLORS = ("#4e79a7", "#f28e2b", "#59a14f", "#e15759", "#76b7b2", "#edc948", "#b07aa1", "#ff9da7", "#9c755f", "#bab0ac")


def _rgb(c: str | Sequence[int]) -> RGB:
    if isinstance(c, str):
        c = c.lstrip("#")
        return (int(c[0:2], 16), int(c[2:4], 16), int(c[4:6], 16))
    return (int(c[0]), int(c[1]), int(c[2]))


@dataclass
class Style:
    """How to draw: size in pixels, colours, what to show."""

    width: int = 480
    height: int = 360
    supersample: int = 2
    background: str = "#ffffff"
    ground: str = "#ebebeb"
    ground_outline: str = "#a0a0a0"
    outline: str = "#303030"
    pin: str = "#202020"
    trail: str = "#7f3fbf"
    invalid: str = "#d62728"
    overlay: str = "#e377c2"
    sweep: str = "#8c564b"
    part_colors: tuple[str, ...] = PART_COLORS
    margin: float = 0.05
    line_width: float = 1.2
    #: named points whose trail is drawn (None: all of them)
    trails: Sequence[str] | None = None
    show_pins: bool = True
    labels: bool = False
    #: opacity of moving parts' fill (1: opaque); what lies under a part shows through below 1
    opacity: float = 1.0
    #: a wind-up toy as its exploded stage panels instead of assembled (planar.draw.toyview)
    exploded: bool = False

    def __post_init__(self) -> None:
        check_fields(self, "render")
        for f, low, high in (("width", 8, 16384), ("height", 8, 16384), ("supersample", 1, 8)):
            if not low <= getattr(self, f) <= high:
                raise InputError(f"render.{f}", getattr(self, f), f"a whole number from {low} to {high}")
        for name, least, most in (("margin", 0.0, 0.49), ("line_width", 1e-3, 100.0), ("opacity", 1e-3, 1.0)):
            if not least <= getattr(self, name) <= most:
                raise InputError(f"render.{name}", getattr(self, name), f"a number from {least:g} to {most:g}")
        if not isinstance(self.part_colors, (tuple, list)) or not self.part_colors:
            raise InputError("render.part_colors", self.part_colors, "one or more colours '#rrggbb'")
        if self.trails is not None and (isinstance(self.trails, str) or not isinstance(self.trails, Sequence)):
            raise InputError("render.trails", self.trails, "a list of point names (or None: every point)")
        named = [(f, getattr(self, f)) for f in _COLOUR_FIELDS] + [("part_colors", c) for c in self.part_colors]
        for f, c in named:
            if not (isinstance(c, str) and len(c.lstrip("#")) == 6 and all(ch in _HEX for ch in c.lstrip("#"))):
                raise InputError(f"render.{f}", c, "a colour '#rrggbb'")


_COLOUR_FIELDS = ("background", "ground", "ground_outline", "outline", "pin", "trail", "invalid", "overlay", "sweep")
_HEX = frozenset("0123456789abcdefABCDEF")


def project(part: Part, pts: Array, view: str) -> Array:
    """Points in a part's plane coordinates -> view coordinates (orthographic).

    A part in plane ``"xy"`` has 3D points ``(u, v, offset)``; ``"xz"``:
    ``(u, offset, v)``; ``"yz"``: ``(offset, u, v)``.  The view keeps two of
    the three axes.
    """
    if part.plane == view:
        return pts
    u, v = pts[..., 0], pts[..., 1]
    off = np.full_like(u, part.offset)
    xyz = {"xy": (u, v, off), "xz": (u, off, v), "yz": (off, u, v)}[part.plane]
    keep = {"xy": (0, 1), "xz": (0, 2), "yz": (1, 2)}[view]
    return np.stack([xyz[keep[0]], xyz[keep[1]]], axis=-1)


def _rings(part: Part) -> list[Array]:
    """Exterior then interiors of the part's outline, as (M, 2) arrays in its frame."""
    poly = part.outline
    rings = [np.asarray(poly.exterior.coords)[:-1]]
    rings += [np.asarray(r.coords)[:-1] for r in poly.interiors]
    return rings


def palette_colors(style: Style, n_parts: int) -> list[RGB]:
    """A fixed palette (<= 256 colours): base colours and their blends toward the background
    and toward the outline, so antialiased edges quantise without dithering, identically every run."""
    bg = np.array(_rgb(style.background), float)
    ol = np.array(_rgb(style.outline), float)
    base = [
        _rgb(c)
        for c in (
            style.background,
            style.ground,
            style.outline,
            style.pin,
            style.trail,
            style.invalid,
            style.overlay,
            style.sweep,
            style.ground_outline,
        )
    ]
    base += [_rgb(style.part_colors[i % len(style.part_colors)]) for i in range(min(n_parts, len(style.part_colors)))]
    out: list[RGB] = []
    for c in base:
        if c not in out:
            out.append(c)
    levels = (0.125, 0.25, 0.375, 0.5, 0.625, 0.75, 0.875)
    for c in list(out):
        for t in levels:
            for other in (bg, ol):
                b = tuple(int(round(x)) for x in (1 - t) * np.array(c, float) + t * other)
                if b not in out and len(out) < 256:
                    out.append(b)  # type: ignore[arg-type]
    return out


def _check_renderer(r: Renderer) -> None:
    """Refuse what a renderer cannot draw, naming the argument."""
    check_kind("Renderer(mech)", r.mech, Mechanism)
    for f in ("motion", "overlay", "trail_motion"):
        v = getattr(r, f)
        if v is not None or f == "motion":
            check_kind(f"Renderer({f})", v, Motion, "a Motion of the mechanism")
    check_kind("Renderer(style)", r.style, Style)
    if not isinstance(r.polygons, Mapping):
        raise InputError("Renderer(polygons)", r.polygons, "a mapping of name to (part, (M, 2) points)")
    if not isinstance(r.view, str) or r.view not in ("", "xy", "xz", "yz"):
        raise InputError("Renderer(view)", r.view, "'xy', 'xz' or 'yz' (or '': the mechanism's)")
    if r.targets is not None:
        t = check_finite("Renderer(targets)", r.targets)
        if t.ndim != 2 or t.shape[1] != 2:
            raise InputError("Renderer(targets)", f"an array of shape {t.shape}", "points (M, 2)")


@dataclass
class Renderer:
    """Renders ``motion`` of ``mech`` (and optionally an ``overlay`` motion) frame by frame.

    ``polygons`` maps a name to ``(part, points)`` in that part's frame: drawn
    swept with the part (the notes' foot).  ``trail_motion`` (default:
    ``motion``) is the finer motion the trails are drawn from when ``motion``
    holds only the frames.  ``targets`` ``(M, 2)``: fixed points (world
    coordinates of an ``xy`` view, model units; e.g. the targets a synthesis
    aimed at) drawn as dots of the overlay colour over the trails in every frame, and framed.

    How: every part's outline is transformed for all frames at once (numpy);
    a frame is the static layer (ground, parts that do not move, drawn once,
    supersampled) plus, for each moving part, a scanline fill through a
    coverage mask (holes cleared) and its outline strokes drawn at twice the
    size and box-reduced: the antialiasing.  The fill's aliased edge lies
    under the antialiased outline.  The trails (drawn once, supersampled, as
    a mask) are pasted over the parts.
    """

    mech: Mechanism
    motion: Motion
    style: Style = field(default_factory=Style)
    overlay: Motion | None = None
    polygons: Mapping[str, tuple[str, Array]] = field(default_factory=dict)
    view: str = ""  # default: the mechanism's own view plane ("xy" unless it says otherwise)
    trail_motion: Motion | None = None
    targets: Array | None = None

    def __post_init__(self) -> None:
        from planar.draw.toyview import Marks, assembled

        _check_renderer(self)
        self.marks = Marks()
        if not self.style.exploded and self.overlay is None:  # toys, #6, #8, #9: the assembled view
            orig = self.mech
            self.mech, self.motion, self.marks = assembled(orig, self.motion)
            if self.mech is not orig and self.trail_motion is not None:
                self.trail_motion = assembled(orig, self.trail_motion)[1]
        self.view = self.view or self.mech.view
        s = self.style
        self.S = max(1, int(s.supersample))
        self.W, self.H = s.width, s.height
        fine = self.trail_motion if self.trail_motion is not None else self.motion
        self._fine_valid = np.asarray(fine.valid, bool)
        self._lock = threading.Lock()
        self._cached: _Chunk | None = None
        self._fit(fine)
        self.lw = max(1.0, s.line_width)
        # static parts (pose constant over the motion) go into the pre-drawn layer
        self.static: list[int] = []
        self.moving: list[int] = []
        for i, p in enumerate(self.mech.parts):
            pose = self.motion.poses[p.name]
            if np.ptp(pose, axis=0).max() <= 1e-12 * max(1.0, float(np.abs(pose).max())):
                self.static.append(i)
            else:
                self.moving.append(i)
        # trails are one point per sample: held whole (the outlines are computed a chunk of frames at a time)
        self.trails = {k: self._px(v) for k, v in self._trails(fine).items()}
        self.trail_dots = {k: self._px(v) for k, v in self._trails(self.motion).items()}
        self.base = self._static_layer()
        self.trail_layer = self._trail_layer()
        self.dot = {c: self._dot(_rgb(c), 2.2) for c in (s.pin, s.trail, s.invalid)}
        self.target_px = self._px(self._targets()) if len(self._targets()) else None
        self.target_dot = self._dot(_rgb(s.overlay), 2.8)  # a colour of the GIF's fixed palette
        self.mark_px = (
            [(self._px(r), c) for r, c in self.marks.rings],
            [(self._px(r), c) for r, c in self.marks.lines],
            [(self._px(r), c) for r, c in self.marks.dots],
        )

    # -- geometry, a chunk of frames at once ----------------------------------------
    def _world_geometry(self, motion: Motion) -> dict:
        """Every part's rings, the swept polygons and the pins of ``motion``'s samples, in view coordinates."""
        parts = []
        for p in self.mech.parts:
            pose = motion.poses[p.name]
            parts.append([project(p, poses_apply(pose, r), self.view) for r in _rings(p)])
        sweeps = {}
        for n, (pname, pts) in self.polygons.items():
            part = self.mech.part(pname)
            sweeps[n] = project(part, poses_apply(motion.poses[pname], np.asarray(pts, float)), self.view)
        pins = {}
        for j in self.mech.joints:
            # every joint kind states where its pins are (model.JointProtocol.pins)
            for k, (pname, xy) in enumerate(j.pins()):
                part = self.mech.part(pname)
                key = j.name if k == 0 else f"{j.name}#{k}"
                pins[key] = project(part, poses_apply(motion.poses[pname], xy), self.view)
        return {"parts": parts, "sweeps": sweeps, "pins": pins}

    def chunk(self, i: int) -> _Chunk:
        """The pixel geometry of the chunk of :data:`CHUNK_FRAMES` frames holding frame ``i`` (the last one is kept)."""
        with self._lock:
            c = self._cached
            if c is not None and c.start <= i < c.stop:
                return c
        start = (i // CHUNK_FRAMES) * CHUNK_FRAMES
        stop = min(len(self), start + CHUNK_FRAMES)
        idx = np.arange(start, stop)
        world = self._world_geometry(self.motion.take(idx))
        overlay: list[list[Array]] = []
        if self.overlay is not None:
            ow = self._world_geometry(self.overlay.take(idx))
            overlay = [[self._px(r) for r in rings] for rings in ow["parts"]]
        c = _Chunk(
            start,
            stop,
            [[self._px(r) for r in rings] for rings in world["parts"]],
            [[self._px(v)] for v in world["sweeps"].values()],
            {k: self._px(v) for k, v in world["pins"].items()},
            overlay,
        )
        with self._lock:
            self._cached = c
        return c

    def part_rings(self, k: int, i: int) -> list[Array]:
        """Part ``k``'s rings (exterior first) at frame ``i``, in output pixels."""
        c = self.chunk(i)
        return [r[i - c.start] for r in c.parts[k]]

    def _trails(self, motion: Motion) -> dict[str, Array]:
        names = self.style.trails if self.style.trails is not None else list(motion.points)
        trails = {}
        for n in names:
            if n in motion.points:
                part = self.mech.part(self.mech.points[n][0])
                trails[n] = project(part, motion.points[n], self.view)
        return trails

    def _fit(self, fine: Motion) -> None:
        """Scale and origin that frame the geometry of the motion's valid samples.

        Invalid samples (a linkage that cannot close there) may hold any
        numbers, so they never move the camera; with no valid sample at all,
        every finite point is framed.  The extent is gathered a chunk of
        frames at a time (the minimum and maximum of the chunks' extents are
        those of the whole, exactly).
        """
        valid = np.asarray(self.motion.valid, bool)
        keep = valid if valid.any() else np.ones_like(valid)
        fine_keep = self._fine_valid if self._fine_valid.any() else np.ones_like(self._fine_valid)
        boxes = [_extent([np.asarray(v)[fine_keep] for v in self._trails(fine).values()]), _extent([self._targets()])]
        for start in range(0, len(self), CHUNK_FRAMES):
            idx = np.arange(start, min(len(self), start + CHUNK_FRAMES))
            world = self._world_geometry(self.motion.take(idx))
            tracks = [r for rings in world["parts"] for r in rings]  # (K, M, 2) each
            tracks += list(world["sweeps"].values())  # (K, M, 2)
            boxes.append(_extent([np.asarray(v)[keep[idx]] for v in tracks]))
        found = [b for b in boxes if b is not None]
        if found:
            lo = np.min([b[0] for b in found], axis=0)
            hi = np.max([b[1] for b in found], axis=0)
        else:
            lo = hi = np.zeros(2)
        span = np.maximum(hi - lo, 1e-12)
        m = self.style.margin
        scale = min(self.W * (1 - 2 * m) / span[0], self.H * (1 - 2 * m) / span[1])
        self.scale = scale
        centre = 0.5 * (lo + hi)
        self.origin = np.array([self.W / 2 - scale * centre[0], self.H / 2 + scale * centre[1]])

    def _targets(self) -> Array:
        """The fixed target points ``(M, 2)`` (none: ``(0, 2)``)."""
        return np.empty((0, 2)) if self.targets is None else np.asarray(self.targets, float).reshape(-1, 2)

    def _px(self, xy: Array) -> Array:
        """World view coordinates -> output pixel coordinates (y flipped)."""
        out = np.empty_like(xy)
        out[..., 0] = self.origin[0] + self.scale * xy[..., 0]
        out[..., 1] = self.origin[1] - self.scale * xy[..., 1]
        return out

    def _outline(self, part: Part) -> RGB:
        return _rgb(self.style.ground_outline if part.ground else self.style.outline)

    def _fill(self, i: int, part: Part) -> RGB:
        if part.ground:
            return _rgb(self.style.ground)
        return _rgb(self.style.part_colors[(i - 1) % len(self.style.part_colors)])

    # -- pre-drawn layers ------------------------------------------------------------
    def _dot(self, colour: RGB, radius: float):
        from PIL import Image, ImageDraw

        k = 4
        r = radius * k
        size = int(2 * r + 4)
        img = Image.new("RGBA", (size, size), (0, 0, 0, 0))
        ImageDraw.Draw(img).ellipse([2, 2, 2 + 2 * r, 2 + 2 * r], fill=colour + (255,))
        small = img.resize((size // k + 1, size // k + 1), Image.Resampling.BOX)
        return small

    def _static_layer(self):
        """Background, parts that do not move and the trails, antialiased by supersampling."""
        from PIL import Image, ImageDraw

        s = self.style
        S = self.S
        img = Image.new("RGB", (self.W * S, self.H * S), _rgb(s.background))
        draw = ImageDraw.Draw(img)
        lw = max(1, int(round(self.lw * S)))
        for i in self.static:
            p = self.mech.parts[i]
            rings = [r * S for r in self.part_rings(i, 0)]
            mask = Image.new("L", img.size, 0)
            md = ImageDraw.Draw(mask)
            md.polygon([tuple(q) for q in rings[0]], fill=255)
            for hole in rings[1:]:
                md.polygon([tuple(q) for q in hole], fill=0)
            img.paste(self._fill(i, p), (0, 0, *img.size), mask)
            for r in rings:
                pts = [tuple(q) for q in r]
                draw.line(pts + [pts[0]], fill=self._outline(p), width=lw, joint="curve")
        return img.reduce(S) if S > 1 else img

    def _trail_layer(self):
        """The trails (valid samples of the fine motion) as an antialiased mask, pasted above the parts."""
        from PIL import Image, ImageDraw

        if not self.trails:
            return None
        S = self.S
        mask = Image.new("L", (self.W * S, self.H * S), 0)
        draw = ImageDraw.Draw(mask)
        lw = max(1, int(round(self.lw * S)))
        for tr in self.trails.values():
            seg = (tr[self._fine_valid] * S).ravel().tolist()
            if len(seg) > 2:
                draw.line(seg + seg[:2], fill=255, width=lw, joint="curve")
        return mask.reduce(S) if S > 1 else mask

    # -- per frame ---------------------------------------------------------------------
    def __len__(self) -> int:
        return len(self.motion)

    def _draw_rings(self, img, rings: list[Array], fill: RGB, opacity: float = 1.0) -> None:
        """Fill a polygon with holes (``opacity`` of the fill, 0..1) and stroke its rings, antialiased,
        within its bounding box."""
        from PIL import Image, ImageDraw

        ext = rings[0]
        x0, y0 = np.floor(ext.min(0)).astype(int) - 2
        x1, y1 = np.ceil(ext.max(0)).astype(int) + 3
        x0, y0 = max(int(x0), 0), max(int(y0), 0)
        x1, y1 = min(int(x1), self.W), min(int(y1), self.H)
        if x1 <= x0 or y1 <= y0:
            return
        box = (x0, y0, x1, y1)
        size = (x1 - x0, y1 - y0)
        off = np.array([x0, y0], float)
        fm = Image.new("L", size, 0)
        md = ImageDraw.Draw(fm)
        md.polygon((ext - off).ravel().tolist(), fill=int(round(255 * min(1.0, max(0.0, opacity)))))  # flat lists
        for hole in rings[1:]:
            md.polygon((hole - off).ravel().tolist(), fill=0)
        img.paste(fill, box, fm)
        S = 2
        lm = Image.new("L", (size[0] * S, size[1] * S), 0)
        ld = ImageDraw.Draw(lm)
        width = max(1, int(round(self.lw * S)))
        for ring in rings:
            pts = (np.vstack([ring, ring[:1]]) - off) * S
            ld.line(pts.ravel().tolist(), fill=255, width=width, joint="curve")
        img.paste(_rgb(self.style.outline), box, lm.reduce(S))

    def frame(self, i: int):
        """Frame ``i`` as a PIL RGB image of the style's size."""
        return self._frame(i, self.chunk(i))

    def _frame(self, i: int, c: _Chunk):
        """Frame ``i`` drawn from the chunk ``c`` that holds it."""
        from PIL import ImageDraw

        s = self.style
        k = i - c.start
        img = self.base.copy()
        valid = bool(self.motion.valid[i])
        draw = ImageDraw.Draw(img)
        tint = _rgb(s.invalid)
        for idx in self.moving:
            fill = self._fill(idx, self.mech.parts[idx])
            if not valid:
                fill = tuple(int(0.5 * a + 0.5 * b) for a, b in zip(fill, tint))  # type: ignore[assignment]
            self._draw_rings(img, [r[k] for r in c.parts[idx]], fill, self.style.opacity)
        for rings in c.sweeps:
            self._draw_rings(img, [r[k] for r in rings], _rgb(s.sweep), self.style.opacity)
        self._draw_marks(img, draw, i)
        if self.trail_layer is not None:
            img.paste(_rgb(s.trail), (0, 0, self.W, self.H), self.trail_layer)
        if self.target_px is not None:
            h = self.target_dot.size[0] // 2
            for x, y in self.target_px:
                img.paste(self.target_dot, (int(round(x)) - h, int(round(y)) - h), self.target_dot)
        for rings in c.overlay:
            for r in rings:
                pts = np.vstack([r[k], r[k][:1]]).ravel().tolist()
                draw.line(pts, fill=_rgb(s.overlay), width=max(1, int(round(self.lw))))
        if s.show_pins:
            dot = self.dot[s.pin]
            h = dot.size[0] // 2
            for track in c.pins.values():
                x, y = track[k]
                img.paste(dot, (int(round(x)) - h, int(round(y)) - h), dot)
        dot = self.dot[s.trail]
        h = dot.size[0] // 2
        for tr in self.trail_dots.values():
            x, y = tr[i]
            img.paste(dot, (int(round(x)) - h, int(round(y)) - h), dot)
        if not valid:
            self._mark_invalid(draw, k, c)
        return img

    def _draw_marks(self, img, draw, i: int) -> None:
        """The view's per-frame marks (a #6/#9 pin's oval and contact point, #8's window taper)."""
        s = self.style
        rings, lines, dots = self.mark_px
        for ring, c in rings:
            self._draw_rings(img, [ring[i]], _rgb(getattr(s, c)))
        for line, c in lines:
            draw.line(line[i].ravel().tolist(), fill=_rgb(getattr(s, c)), width=max(1, int(round(self.lw))))
        for pts, c in dots:
            dot = self.dot[getattr(s, c)]
            h = dot.size[0] // 2
            x, y = pts[i]
            img.paste(dot, (int(round(x)) - h, int(round(y)) - h), dot)

    def _mark_invalid(self, draw, k: int, c: _Chunk) -> None:
        s = self.style
        code = int(self.motion.fail_code[c.start + k])
        joint = self.motion.fail_table[code][0] if code >= 0 else ""
        red = _rgb(s.invalid)
        draw.rectangle([0, 0, self.W - 1, self.H - 1], outline=red, width=3)
        for name, pts in c.pins.items():
            if name == joint or name.split(":")[0] == joint or joint.endswith("." + name) or joint == name.split(".")[-1]:
                x, y = pts[k]
                r = 7
                draw.ellipse([x - r, y - r, x + r, y + r], outline=red, width=2)
        draw.text((6, 4), f"invalid: joint {joint}", fill=red)

    def frames(self, progress: bool = False, threads: int | None = None, post=None) -> Iterator:
        """All frames in order (a progress bar on a terminal when ``progress``).

        Frames are independent, and Pillow releases the GIL while it
        resamples and pastes, so ``threads`` (default: all cores) draw them
        in parallel; the order, and every pixel, is the same as with one.
        ``post`` (e.g. palette quantisation) is applied to each frame in the
        same worker.
        """
        import os

        n = len(self)
        threads = threads or os.cpu_count() or 1
        bar = None
        if progress:
            from planar.core.progress import progress_bar

            bar = progress_bar(n, "render", "frame")
        from concurrent.futures import ThreadPoolExecutor

        # the geometry is computed a chunk at a time and only that chunk's frames are queued: memory stays flat
        pool = ThreadPoolExecutor(threads) if threads > 1 and n >= 8 else None
        try:
            for start in range(0, n, CHUNK_FRAMES):
                c = self.chunk(start)

                def work(i: int, c: _Chunk = c):
                    img = self._frame(i, c)
                    return img if post is None else post(img)

                frames = range(c.start, c.stop)
                for img in map(work, frames) if pool is None else pool.map(work, frames):
                    yield img
                    if bar is not None:
                        bar.update()
        finally:
            if pool is not None:
                pool.shutdown()
            if bar is not None:
                bar.close()
