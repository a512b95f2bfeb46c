"""Each part's cuts, checked before anything is written.

Sizes (millimetres):

* a hole or slot a pin goes through (see :mod:`planar.fabrication.joints`) is cut at
  the scene's ``pin_diameter_mm`` plus ``clearance_mm``; other holes (an axle
  sized by the mechanism, a round cam's hole) keep their size plus the
  clearance;
* slots run ``slot_end_margin_mm`` past each end of the pin's travel
  (straight slots along their axis, arc slots along their arc);
* the driven part's hole on the motor axis is a D (``shaft_diameter_mm``,
  ``shaft_flat_mm`` across the flat, each plus ``clearance_mm``: a snug fit
  that still goes on a real shaft; the flat carries the torque); the ground
  plate holding the motor gets a shaft clearance hole, two motor screw holes
  of ``motor_screw_mm`` ``motor_screw_spacing_mm`` apart and two mounting
  holes of ``mounting_hole_mm``, each cut at the size given (clearance holes:
  the screw threads into the motor or the standoff, not the plate; the BOM
  lists the same sizes).

Checks: every inner cut keeps ``min_wall_mm`` of material to the outline.  A
rounded part (a hull of circles) that is too narrow is widened — a circle of
the cut's radius plus the wall joins its hull, so the new hull contains the cut
with the wall (arc slots: a chain of such circles along the arc, close enough
that the hull's chords stay outside) — and the part's notes say so; with
``widen = false``, or for a part with an explicit polygon, it is refused with
one line naming the part and the wall.  A part narrower than ``min_part_mm`` is
refused.  Labels are engraved in a stroke font along the part's long axis at
the largest height that fits (at most 6 mm); when the name does not fit at
``min_label_mm`` the part's number is engraved instead, and the notes say so.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from planar.core.model import ArcSlot, Hole, Part, Slot
from planar.fabrication.joints import FabricationError
from planar.fabrication.sheet import (
    Circle,
    Contour,
    Cut,
    PartCut,
    arc_slot,
    cut_polygon,
    d_hole,
    hull_of_circles,
    rectangle,
    stadium,
)

__all__ = ["MAX_LABEL", "FabSettings", "Feature", "part_cuts"]

MAX_LABEL = 6.0  # mm, tallest label
WALL_TOL = 5e-3  # mm: sampled arcs lie inside the true ones by less than this


#: the FabSettings fields that are a gearmotor's dimensions (bounded as the scene files bound them)
_MOTOR_FIELDS = ("shaft_mm", "shaft_flat_mm", "motor_screw_mm", "motor_screw_spacing_mm", "motor_shaft_mm", "mounting_hole_mm")


def _check_bounds(s: Any) -> None:
    """The upper bounds the scene files' ``[fabrication]`` table has, from the same place (mm)."""
    from planar.core import limits
    from planar.errors import InputError
    from planar.fabrication.hardware import HARDWARE

    if not max(s.sheet) <= limits.MAX_SHEET_MM:
        raise InputError("fabrication.sheet", s.sheet, f"sides of at most {limits.MAX_SHEET_MM:g} mm (100 m)")
    bounds = dict.fromkeys(_MOTOR_FIELDS, (limits.MAX_MOTOR_MM, "a motor dimension"))
    bounds |= {"motor_body_mm": (limits.MAX_MOTOR_BODY_MM, "a motor body length")}
    bounds |= dict.fromkeys(("kerf", "clearance"), (limits.MAX_KERF_MM, "a width"))
    bounds |= dict.fromkeys(("pin_mm", "thickness_mm", "min_wall", "min_part", "min_label"), (limits.MAX_HARDWARE_MM, "a size"))
    for name, (most, what) in bounds.items():
        if not getattr(s, name) <= most:
            raise InputError(f"fabrication.{name}", getattr(s, name), f"{what} of at most {most:g} mm")
    if s.hardware not in HARDWARE:
        raise InputError("fabrication.hardware", s.hardware, "one of " + ", ".join(sorted(HARDWARE)))


@dataclass(frozen=True)
class FabSettings:
    """Everything fabrication needs, in millimetres (from the scene's ``[fabrication]`` table)."""

    unit_mm: float = 10.0
    thickness_mm: float = 3.0
    kerf: float = 0.15
    pin_mm: float = 3.0
    clearance: float = 0.1
    sheet: tuple[float, float] = (300.0, 200.0)
    min_wall: float = 1.5
    min_part: float = 5.0
    min_label: float = 1.5
    slot_end: float = 1.0
    widen: bool = True
    pin_head: float = 1.5
    shaft_mm: float = 3.0
    shaft_flat_mm: float = 2.5
    motor_screw_mm: float = 1.8
    motor_screw_spacing_mm: float = 9.0
    #: the motor's shaft above its face (mm; an N20's D shaft: 9) and its body below the face (mm; an N20: 26)
    motor_shaft_mm: float = 9.0
    motor_body_mm: float = 26.0
    mounting_hole_mm: float = 3.2
    spacing: float = 3.0
    margin: float = 5.0
    svg_stroke_mm: float = 0.025
    cut_colour: str = "#ff0000"
    engrave_colour: str = "#0000ff"
    #: the fastener every pin is (:data:`planar.fabrication.hardware.HARDWARE`)
    hardware: str = "rod-eclip"
    #: colours of the cuts: "planar" (``cut_colour`` for both cuts) or "boxes" (Boxes.py's: black outer, blue inner,
    #: green engrave)
    colours: str = "planar"
    #: side of a reference square cut in a corner of each sheet (mm; 0: none), to measure the scale after cutting
    reference_square_mm: float = 0.0

    def __post_init__(self) -> None:
        from planar.core.fields import check_fields
        from planar.errors import InputError

        check_fields(self, "fabrication")
        for f in ("unit_mm", "thickness_mm", "pin_mm"):
            if not getattr(self, f) > 0:
                raise InputError(f"fabrication.{f}", getattr(self, f), "a positive size in mm")
        if not min(self.sheet) > 0:
            raise InputError("fabrication.sheet", self.sheet, "a sheet (width, height) of positive sides in mm")
        for name, value in vars(self).items():
            if isinstance(value, (int, float)) and not isinstance(value, bool) and value < 0:
                raise InputError(f"fabrication.{name}", value, "a size >= 0 in mm")
        _check_bounds(self)
        if self.colours not in COLOUR_PRESETS:
            raise InputError("fabrication.colours", self.colours, "one of " + ", ".join(sorted(COLOUR_PRESETS)))

    def layer_colours(self) -> dict[str, str]:
        """``#rrggbb`` of each cut-file layer under the colour preset: ``"planar"`` (both cuts ``cut_colour``,
        engraving ``engrave_colour``) or ``"boxes"`` (Boxes.py's: outer cut black, inner cut blue, engrave green)."""
        if self.colours not in COLOUR_PRESETS:
            from planar.errors import InputError

            raise InputError("fabrication.colours", self.colours, "one of " + ", ".join(sorted(COLOUR_PRESETS)))
        preset = COLOUR_PRESETS[self.colours]
        return {
            "CUT_INNER": preset.get("CUT_INNER", self.cut_colour),
            "CUT_OUTER": preset.get("CUT_OUTER", self.cut_colour),
            "ENGRAVE": preset.get("ENGRAVE", self.engrave_colour),
        }

    @classmethod
    def from_spec(cls, fab: Any, kerf: float | None = None, sheet: tuple[float, float] | None = None) -> FabSettings:
        from planar.core.fields import check_number, check_point
        from planar.errors import InputError

        if not all(hasattr(fab, f) for f in ("unit_mm", "thickness_mm", "kerf_mm", "sheet_mm")):
            raise InputError("from_spec(fab)", fab, "a scene's fabrication table (scene.spec.fabrication)")
        if kerf is not None:
            check_number("kerf", kerf)
        if sheet is not None:
            sheet = check_point("sheet", sheet, "a sheet (width, height) in mm: two finite numbers")
        return cls(
            unit_mm=fab.unit_mm,
            thickness_mm=fab.thickness_mm,
            kerf=fab.kerf_mm if kerf is None else kerf,
            pin_mm=fab.pin_diameter_mm,
            clearance=fab.clearance_mm,
            sheet=(float((sheet or fab.sheet_mm)[0]), float((sheet or fab.sheet_mm)[1])),
            min_wall=fab.min_wall_mm,
            min_part=fab.min_part_mm,
            min_label=fab.min_label_mm,
            slot_end=fab.slot_end_margin_mm,
            widen=fab.widen,
            pin_head=fab.pin_head_mm,
            shaft_mm=fab.shaft_diameter_mm,
            shaft_flat_mm=fab.shaft_flat_mm,
            motor_screw_mm=fab.motor_screw_mm,
            motor_screw_spacing_mm=fab.motor_screw_spacing_mm,
            motor_shaft_mm=getattr(fab, "motor_shaft_mm", 9.0),
            motor_body_mm=getattr(fab, "motor_body_mm", 26.0),
            mounting_hole_mm=fab.mounting_hole_mm,
            spacing=fab.spacing_mm,
            margin=fab.margin_mm,
            svg_stroke_mm=fab.svg_stroke_mm,
            cut_colour=fab.cut_colour,
            engrave_colour=fab.engrave_colour,
            hardware=getattr(fab, "hardware", "rod-eclip"),
            colours=getattr(fab, "colours", "planar"),
            reference_square_mm=getattr(fab, "reference_square_mm", 0.0),
        )


#: colour presets of the cut files (a layer missing from a preset takes ``cut_colour`` / ``engrave_colour``)
COLOUR_PRESETS: dict[str, dict[str, str]] = {
    "planar": {},
    "boxes": {"CUT_OUTER": "#000000", "CUT_INNER": "#0000ff", "ENGRAVE": "#00ff00"},
}


@dataclass(frozen=True)
class Feature:
    """A nominal (zero-kerf) inner cut in mm, own frame.

    ``kind``: ``"hole"`` (``a`` = centre, ``r``), ``"slot"`` (``a``, ``b`` ends of the centre line,
    ``r`` half-width), ``"arc"`` (``a`` = centre, ``R``, angles ``t0 < t1``, ``r`` half-width),
    ``"d"`` (``a`` = centre, ``r``, ``flat`` from the centre along ``t0``), ``"rect"`` (a tab's
    through-slot: ``a`` = centre, ``R`` half its length along ``t0``, ``r`` half its width).
    """

    kind: str
    what: str
    a: tuple[float, float]
    r: float
    b: tuple[float, float] = (0.0, 0.0)
    R: float = 0.0
    t0: float = 0.0
    t1: float = 0.0
    flat: float = 0.0

    def cut(self, k2: float) -> Cut:
        """The cut with the beam's half-width ``k2`` taken off every side."""
        r = self.r - k2
        if self.kind == "hole":
            return Circle(self.a, r)
        if self.kind == "slot":
            return stadium(self.a, self.b, r)
        if self.kind == "arc":
            return arc_slot(self.a, self.R, self.t0, self.t1, r)
        if self.kind == "rect":
            return rectangle(self.a, self.R - k2, r, self.t0)
        return d_hole(self.a, r, self.flat - k2, self.t0)

    def wall_circles(self, wall: float) -> list[tuple[float, float, float]]:
        """Circles whose convex hull holds this cut with ``wall`` of material all round."""
        if self.kind in ("hole", "d"):
            return [(self.a[0], self.a[1], self.r + wall)]
        if self.kind == "slot":
            return [(self.a[0], self.a[1], self.r + wall), (self.b[0], self.b[1], self.r + wall)]
        if self.kind == "rect":
            c, s = math.cos(self.t0), math.sin(self.t0)
            return [
                (self.a[0] + c * x - s * y, self.a[1] + s * x + c * y, wall) for x in (-self.R, self.R) for y in (-self.r, self.r)
            ]
        # along the arc: chords between neighbours sag by at most 0.02 mm, made up by a larger radius
        sag = 0.02
        dmax = 2 * math.acos(max(-1.0, 1 - sag / max(self.R, 1e-9)))
        n = max(2, int(math.ceil((self.t1 - self.t0) / dmax)) + 1)
        step = (self.t1 - self.t0) / (n - 1)
        rho = self.r + wall + self.R * (1 - math.cos(step / 2))
        return [
            (self.a[0] + self.R * math.cos(t), self.a[1] + self.R * math.sin(t), rho) for t in np.linspace(self.t0, self.t1, n)
        ]


def _features(
    part: Part,
    s: FabSettings,
    pinned: set[int],
    drive_at: tuple[float, float] | None,
    motor_at: tuple[float, float] | None,
    drive_flat: float = math.pi / 2,
) -> list[Feature]:
    u = s.unit_mm
    out: list[Feature] = []
    for i, f in enumerate(part.features):
        pin = i in pinned or getattr(f, "role", "sized") == "pin"
        if isinstance(f, Hole):
            c = (f.centre[0] * u, f.centre[1] * u)
            if drive_at is not None and math.dist(f.centre, drive_at) < 1e-9 * max(1.0, u):
                if not s.shaft_flat_mm < s.shaft_mm:
                    raise FabricationError(
                        f"fabrication.shaft_flat_mm: {s.shaft_flat_mm:g} mm across the flat must be "
                        f"less than the shaft diameter {s.shaft_mm:g} mm"
                    )
                # snug, not zero: the clearance on the diameter and across the flat (half of it each side)
                out.append(
                    Feature(
                        "d",
                        f"motor shaft D-hole {s.shaft_mm:g} mm",
                        c,
                        (s.shaft_mm + s.clearance) / 2,
                        flat=s.shaft_flat_mm - s.shaft_mm / 2 + s.clearance / 2,
                        t0=drive_flat,
                    )
                )
                continue
            if motor_at is not None and math.dist(f.centre, motor_at) < 1e-9 * max(1.0, u):
                d = s.shaft_mm + 4 * s.clearance + 0.5
                out.append(Feature("hole", "motor shaft clearance", c, d / 2))
                for sx in (-1, 1):
                    out.append(
                        Feature(
                            "hole",
                            "motor screw",
                            (c[0] + sx * s.motor_screw_spacing_mm / 2, c[1]),
                            s.motor_screw_mm / 2,  # the cut diameter itself, as the BOM says (a clearance hole)
                        )
                    )
                continue
            d = (s.pin_mm if pin else f.diameter * u) + s.clearance
            out.append(Feature("hole", "pin hole" if pin else "hole", c, d / 2))
        elif isinstance(f, Slot):
            w = (s.pin_mm if pin else f.width * u) + s.clearance
            p0, p1 = np.array(f.start, float) * u, np.array(f.end, float) * u
            L = float(np.hypot(*(p1 - p0)))
            e = (p1 - p0) / L if L > 1e-12 else np.array([1.0, 0.0])
            p0, p1 = p0 - s.slot_end * e, p1 + s.slot_end * e
            out.append(Feature("slot", "slot", (float(p0[0]), float(p0[1])), w / 2, b=(float(p1[0]), float(p1[1]))))
        elif isinstance(f, ArcSlot):
            w = (s.pin_mm if pin else f.width * u) + s.clearance
            R = f.radius * u
            t0, t1 = sorted((f.angle0, f.angle1))
            dt = s.slot_end / R
            t0, t1 = t0 - dt, t1 + dt
            if t1 - t0 >= 2 * math.pi:
                raise FabricationError(f"part {part.name!r}: arc slot with its end margins runs all round")
            out.append(Feature("arc", "arc slot", (f.centre[0] * u, f.centre[1] * u), w / 2, R=R, t0=t0, t1=t1))
        else:
            raise FabricationError(f"part {part.name!r}: no fabrication rule for feature kind {type(f).__name__}")
    return out


def _mounting_holes(circles: list[tuple[float, float, float]], s: FabSettings) -> list[Feature]:
    """Two mounting holes on ears beyond the ends of the plate's long axis."""
    pts = np.array([(x, y) for x, y, _ in circles])
    rad = np.array([r for _, _, r in circles])
    c0 = pts.mean(axis=0)
    if len(pts) > 1 and np.ptp(pts, axis=0).max() > 1e-9:
        _, _, vt = np.linalg.svd(pts - c0)
        axis = vt[0]
    else:
        axis = np.array([1.0, 0.0])
    if axis[0] < 0 or (axis[0] == 0 and axis[1] < 0):
        axis = -axis
    r = s.mounting_hole_mm / 2  # the cut diameter itself (a clearance hole for its screw; the BOM says the same)
    out = []
    for sgn in (-1, 1):
        reach = float(((pts - c0) @ (sgn * axis) + rad).max())
        c = c0 + sgn * axis * (reach + r + s.min_wall / 2)
        out.append(Feature("hole", "mounting hole", (float(c[0]), float(c[1])), r))
    return out


def _outer(part: Part, s: FabSettings, feats: list[Feature], k2: float) -> tuple[Cut, list[str]]:
    """The outer profile grown by ``k2``, widened (or refused) so every cut keeps the wall."""
    u = s.unit_mm
    notes: list[str] = []
    if part.polygon is not None:
        from shapely.geometry import Polygon

        grown = Polygon([(x * u, y * u) for x, y in part.polygon]).buffer(k2, join_style="mitre")
        return Contour([(float(x), float(y), 0.0) for x, y in list(grown.exterior.coords)[:-1]]), notes
    base = [(x * u, y * u, r * u) for x, y, r in part.hull]
    own = [f for f in feats if f.what not in ("mounting hole", "motor screw")]
    extra = [c for f in own for c in f.wall_circles(s.min_wall)]
    ears = [c for f in feats if f not in own for c in f.wall_circles(s.min_wall)]
    before = cut_polygon(hull_of_circles(base), math.radians(0.25))
    after = cut_polygon(hull_of_circles(base + extra), math.radians(0.25))
    if after.area > before.area * (1 + 1e-6) + 1e-6:
        wall = _min_wall(before, own)
        if not s.widen:
            raise FabricationError(
                f"part {part.name!r}: {wall:.3f} mm wall between a cut and the outline, less than "
                f"min_wall_mm {s.min_wall:g} (widen = false)"
            )
        # a negative wall is a cut reaching out of the part (e.g. a frame's travel slot past its plate)
        was = f"a {wall:.3f} mm wall" if wall >= 0 else f"a cut reaching {-wall:.3f} mm out of the outline"
        notes.append(
            f"{part.name}: widened from {was} to a {s.min_wall:g} mm wall (area {before.area:.0f} -> {after.area:.0f} mm^2)"
        )
        base = base + extra
    if ears:
        base = base + ears
    return hull_of_circles([(x, y, r + k2) for x, y, r in base]), notes


def _min_wall(outer, feats: Sequence[Feature]) -> float:
    """Least material (mm) between any cut and the outline; negative when a cut leaves the part."""
    best = math.inf
    for f in feats:
        c = cut_polygon(f.cut(0.0))
        d = outer.exterior.distance(c)
        if not outer.contains(c):  # minus how far the cut reaches out of the part
            import shapely

            d = -float(shapely.distance(outer, shapely.points(np.asarray(c.exterior.coords))).max())
        best = min(best, d)
    return best


def _drop_contained(feats: list[Feature]) -> list[Feature]:
    """``feats`` without a cut that lies wholly inside another one (it removes nothing more: e.g. a merged
    toy body sliding on one line through two stages' slots, one inside the other)."""
    polys = [cut_polygon(f.cut(0.0)) for f in feats]
    keep = []
    for i, p in enumerate(polys):
        inside = any(
            j != i
            and (
                (polys[j].buffer(1e-6).contains(p) and (polys[j].area > p.area or j < i))
                or _same_guide(feats[i], feats[j], j < i)
                or _same_arc(feats[i], feats[j], j < i)
            )
            for j in range(len(polys))
        )
        if not inside:
            keep.append(feats[i])
    return keep


def _pins_held(name: str, feats: list[Feature], kept: list[Feature]) -> list[Feature]:
    """``kept``, after refusing a pin hole of ``feats`` that a larger cut swallowed (the pin would rattle in
    it; the Bunny's pin B once sat in a 6.1 mm hole): only the same hole again may stand for it."""
    for f in feats:
        if (
            f.kind == "hole"
            and f.what == "pin hole"
            and f not in kept
            and not any(g.kind == "hole" and math.dist(g.a, f.a) < 1e-6 and abs(g.r - f.r) < 1e-9 for g in kept)
        ):
            big = next((g for g in kept if cut_polygon(g.cut(0.0)).buffer(1e-6).contains(cut_polygon(f.cut(0.0)))), None)
            what = f"its {big.what} {2 * big.r:.2f} mm wide" if big is not None else "another cut"
            raise FabricationError(
                f"part {name!r}: its pin hole {2 * f.r:.2f} mm at ({f.a[0]:.1f}, {f.a[1]:.1f}) mm "
                f"lies inside {what}; the pin would not be held"
            )
    return kept


def _same_guide(f: Feature, g: Feature, g_first: bool, tol: float = 1e-6) -> bool:
    """Whether slot ``f`` runs on the line of slot ``g`` within ``g``'s ends (mm): one guide, cut once as ``g``.

    A merged toy body is guided on one line by two stages' slots of different widths; only the slot the
    pins run in is kept (the ``g`` that is not itself inside a longer one; ties: the first)."""
    if f.kind != "slot" or g.kind != "slot" or f is g:
        return False
    a, b = np.asarray(g.a), np.asarray(g.b)
    L = float(np.hypot(*(b - a)))
    if tol >= L:
        return False
    e = (b - a) / L
    ends = [np.asarray(f.a) - a, np.asarray(f.b) - a]
    off = [abs(float(e[0] * v[1] - e[1] * v[0])) for v in ends]
    along = [float(e @ v) for v in ends]
    if max(off) > tol or min(along) < -tol or max(along) > L + tol:
        return False
    flen = float(np.hypot(*(np.asarray(f.b) - np.asarray(f.a))))
    return flen + tol < L or (abs(L - flen) <= tol and g_first)


def _same_arc(f: Feature, g: Feature, g_first: bool, tol: float = 1e-6) -> bool:
    """Whether arc slot ``f`` lies on arc slot ``g`` (one centre and radius, no wider, within ``g``'s angles):
    one track, cut once as ``g`` (two toy stages' tracks on one frame; their polygons' chords differ, so the
    polygon test above misses it)."""
    if f.kind != "arc" or g.kind != "arc" or f is g:
        return False
    if math.dist(f.a, g.a) > tol or abs(f.R - g.R) > tol or f.r > g.r + tol:
        return False
    start = (f.t0 - g.t0) % (2 * math.pi)
    if start > 2 * math.pi - tol / max(g.R, tol):
        start -= 2 * math.pi
    end, span = start + (f.t1 - f.t0), g.t1 - g.t0
    if start < -tol / max(g.R, tol) or end > span + tol / max(g.R, tol):
        return False
    same = abs(start) <= tol / max(g.R, tol) and abs(end - span) <= tol / max(g.R, tol) and abs(f.r - g.r) <= tol
    return not same or g_first


def _closest_cuts(feats: Sequence[Feature]) -> tuple[float, Feature | None, Feature | None]:
    """The least material (mm) between two cuts of one part and the two features (0 where they overlap).

    Widening the outline cannot mend this, so a part whose holes run into each other is refused.
    """
    polys = [cut_polygon(f.cut(0.0)) for f in feats]
    best, fa, fb = math.inf, None, None
    for i in range(len(polys)):
        for j in range(i + 1, len(polys)):
            d = float(polys[i].distance(polys[j]))
            if d < best:
                best, fa, fb = d, feats[i], feats[j]
    return best, fa, fb


def _fit_text(poly, text: str, angle: float, centres: list[tuple[float, float]]) -> tuple[float, tuple[float, float]]:
    """Largest cap height (<= MAX_LABEL) at which ``text`` fits inside ``poly`` at one of ``centres``."""
    from shapely import affinity
    from shapely.geometry import box

    from planar.fabrication.strokefont import text_box

    w, bottom, top = text_box(text)
    best = (0.0, centres[0])
    for c in centres:
        lo, hi = 0.0, MAX_LABEL
        if best[0] >= hi:
            break
        if not poly.contains(_text_rect(w, bottom, top, max(best[0], 1e-3), angle, c, affinity, box)):
            continue
        lo = max(best[0], 1e-3)
        for _ in range(14):
            mid = (lo + hi) / 2
            if poly.contains(_text_rect(w, bottom, top, mid, angle, c, affinity, box)):
                lo = mid
            else:
                hi = mid
        if lo > best[0]:
            best = (lo, c)
    return best


def _text_rect(w, bottom, top, h, angle, c, affinity, box):
    pad = 0.15 * h
    r = box(-w * h / 2 - pad, -(top - bottom) * h / 2 - pad, w * h / 2 + pad, (top - bottom) * h / 2 + pad)
    return affinity.translate(affinity.rotate(r, angle, origin=(0, 0), use_radians=True), c[0], c[1])


def _label(material, name: str, number: int, s: FabSettings, notes: list[str]) -> tuple[list[np.ndarray], str, float]:
    from shapely.ops import polylabel

    from planar.fabrication.strokefont import text_strokes

    if material.is_empty or material.area <= 0:
        return [], "", 0.0
    room = material.buffer(-0.3)
    if room.is_empty:
        notes.append(f"{name}: no room for a label")
        return [], "", 0.0
    rect = material.minimum_rotated_rectangle
    xy = np.asarray(rect.exterior.coords)[:4]
    e1, e2 = xy[1] - xy[0], xy[2] - xy[1]
    long = e1 if np.hypot(*e1) >= np.hypot(*e2) else e2
    angle = math.atan2(long[1], long[0])
    if angle <= -math.pi / 2 + 1e-9:
        angle += math.pi
    elif angle > math.pi / 2 + 1e-9:
        angle -= math.pi
    angle = round(angle, 12)
    big = max(room.geoms, key=lambda g: g.area) if hasattr(room, "geoms") else room
    p = polylabel(big, tolerance=1e-2)
    c = np.asarray(rect.centroid.coords[0])
    d = np.array([math.cos(angle), math.sin(angle)])
    half = 0.5 * max(np.hypot(*e1), np.hypot(*e2))
    along = (c + t * half * d for t in np.linspace(-0.6, 0.6, 7))
    centres = [(float(p.x), float(p.y))] + [(float(x), float(y)) for x, y in along]
    for text in (name, str(number)):
        h, at = _fit_text(room, text, angle, centres)
        if h >= s.min_label:
            if text != name:
                notes.append(f"{name}: label shortened to {text!r} (the name would be under {s.min_label:g} mm)")
            return text_strokes(text, h, at, angle), text, h
    notes.append(f"{name}: no label (not even {str(number)!r} fits at {s.min_label:g} mm)")
    return [], "", 0.0


def letter_marks(material, holes: list[tuple[tuple[float, float], float, str]], h: float) -> list[np.ndarray]:
    """Engrave each hole's letter beside it (cap height ``h``) where it fits in ``material``; skip it otherwise."""
    from shapely import affinity
    from shapely.geometry import box

    from planar.fabrication.strokefont import text_box, text_strokes

    out: list[np.ndarray] = []
    taken = material.buffer(-0.2)
    for (cx, cy), r, letter in holes:
        w, bottom, top = text_box(letter)
        dist = r + 0.4 + 0.75 * h
        for k in range(12):
            a = math.pi / 2 - k * math.pi / 6
            at = (cx + dist * math.cos(a), cy + dist * math.sin(a))
            rect = _text_rect(w, bottom, top, h, 0.0, at, affinity, box)
            if taken.contains(rect):
                out.extend(text_strokes(letter, h, at, 0.0))
                taken = taken.difference(rect.buffer(0.3))
                break
    return out


def _check_cut_args(
    part: Any,
    s: Any,
    number: Any,
    pinned: Any,
    drive_at: Any,
    motor_at: Any,
    mounting: Any,
    letters: Any,
    flat: Any,
    extra: Any,
    tabs: Any,
) -> None:
    """:func:`part_cuts`' arguments, each named when wrong (its entrance from Python)."""
    from planar.core.fields import check_kind, check_number, check_point
    from planar.errors import InputError

    check_kind("part_cuts(part)", part, Part)
    check_kind("part_cuts(s)", s, FabSettings)
    if check_number("part_cuts(number)", number, integer=True) < 0:
        raise InputError("part_cuts(number)", number, "a part number >= 0")
    if not isinstance(pinned, (set, frozenset)) or not all(isinstance(i, int) for i in pinned):
        raise InputError("part_cuts(pinned)", pinned, "a set of feature indices")
    for name, at in (("drive_at", drive_at), ("motor_at", motor_at)):
        if at is not None:
            check_point(f"part_cuts({name})", at)
    if not isinstance(mounting, bool):
        raise InputError("part_cuts(mounting)", mounting, "True or False")
    check_number("part_cuts(drive_flat)", flat)
    ok_letters = isinstance(letters, (tuple, list)) and all(
        isinstance(x, (tuple, list)) and len(x) == 2 and isinstance(x[1], str) for x in letters
    )
    if not ok_letters:
        raise InputError("part_cuts(letters)", letters, "a list of ((x, y), letter)")
    if not isinstance(extra, (tuple, list)) or not all(isinstance(f, Feature) for f in extra):
        raise InputError("part_cuts(extra)", extra, "a list of cut features (mm)")
    if tabs is not None and not hasattr(tabs, "edge"):
        raise InputError("part_cuts(tabs)", tabs, "a TabJoin (or None)")


def part_cuts(
    part: Part,
    s: FabSettings,
    number: int,
    pinned: set[int] = frozenset(),  # type: ignore[assignment]
    drive_at: tuple[float, float] | None = None,
    motor_at: tuple[float, float] | None = None,
    mounting: bool = False,
    letters: Sequence[tuple[tuple[float, float], str]] = (),
    drive_flat: float = math.pi / 2,
    extra: Sequence[Feature] = (),
    tabs: Any = None,
) -> PartCut:
    """A part's cuts in mm in its own frame, kerf applied, checked (see the module docstring).

    ``pinned``: indices of the part's features a pin goes through; ``drive_at`` / ``motor_at``: the
    motor axis (model units, own frame) on the driven part / the plate holding the motor;
    ``letters``: hole letters at pin positions (model units, own frame); ``drive_flat``: direction
    (rad, own frame) of the D-hole's flat (a toy's cams are keyed to one shaft at their phase);
    ``extra``: more cuts in mm (a perpendicular piece's tab slots); ``tabs``: a
    :class:`~planar.fabrication.tabs.TabJoin` whose piece this is (cut flat along its edge, tabs added).
    """
    _check_cut_args(part, s, number, pinned, drive_at, motor_at, mounting, letters, drive_flat, extra, tabs)
    k2 = s.kerf / 2.0
    feats = _features(part, s, set(pinned), drive_at, motor_at, drive_flat) + list(extra)
    for f in feats:
        if f.r - k2 <= 0 or (f.kind == "d" and f.flat - k2 <= -(f.r - k2)):
            raise FabricationError(f"part {part.name!r}: {f.what} {2 * f.r:.2f} mm wide is not wider than the kerf {s.kerf:g} mm")
    if mounting:
        base = [(x * s.unit_mm, y * s.unit_mm, r * s.unit_mm) for x, y, r in part.hull] + [
            c for f in feats for c in f.wall_circles(s.min_wall)
        ]
        feats = feats + _mounting_holes(base, s)
    feats = _pins_held(part.name, feats, _drop_contained(feats))
    gap, fa, fb = _closest_cuts(feats)
    if fa is not None and fb is not None and gap < s.min_wall - WALL_TOL:
        raise FabricationError(
            f"part {part.name!r}: {gap:.2f} mm of material between its {fa.what} at "
            f"({fa.a[0]:.1f}, {fa.a[1]:.1f}) mm and its {fb.what} at ({fb.a[0]:.1f}, {fb.a[1]:.1f}) mm, less than "
            f"min_wall_mm {s.min_wall:g} (a larger unit_mm, a smaller pin_diameter_mm or a smaller min_wall_mm)"
        )
    nominal_outer, notes = _outer(part, s, feats, 0.0)
    widened = bool(notes)  # the outline's only note is its widening
    outer = nominal_outer if k2 == 0 else _outer(part, s, feats, k2)[0]
    if tabs is not None:
        nominal_outer, outer = _with_tabs(part.name, cut_polygon(nominal_outer), tabs, k2)
    outer_poly = cut_polygon(nominal_outer)
    wall = _min_wall(outer_poly, feats)
    if wall < s.min_wall - WALL_TOL:
        raise FabricationError(
            f"part {part.name!r}: {wall:.2f} mm wall between a cut and the outline, less than "
            f"min_wall_mm {s.min_wall:g}"
            + (
                " (a part with an explicit outline, such as a "
                "cam, roller or flat follower, is not widened: make "
                "it larger or the pin smaller)"
                if part.polygon is not None
                else ""
            )
        )
    rect = outer_poly.minimum_rotated_rectangle
    xy = np.asarray(rect.exterior.coords)[:4]
    narrow = float(min(np.hypot(*(xy[1] - xy[0])), np.hypot(*(xy[2] - xy[1]))))
    if narrow < s.min_part:
        raise FabricationError(f"part {part.name!r}: {narrow:.2f} mm across, less than min_part_mm {s.min_part:g}")
    material = outer_poly
    for f in feats:
        material = material.difference(cut_polygon(f.cut(0.0)).buffer(0.2))
    engrave, text, height = _label(material, part.name, number, s, notes)
    if letters:
        from shapely.geometry import LineString

        for e in engrave:
            material = material.difference(LineString(e).buffer(0.3 * max(height, 1.0)))
        u = s.unit_mm
        holes = []
        for (x, y), letter in letters:
            near = min(feats, key=lambda f: math.dist(f.a, (x * u, y * u)))
            holes.append(((x * u, y * u), near.r if near.kind != "arc" else 0.0, letter))
        engrave = engrave + letter_marks(material, [h for h in holes if h[1] > 0], max(s.min_label, 1.5))
    nominal = [(f.a, f.r) for f in feats if f.kind == "hole"]
    pc = PartCut(part.name, outer, [f.cut(k2) for f in feats], engrave, text, height, nominal_holes=nominal, notes=notes)
    pc.widened = widened
    pc.mounting_at = [f.a for f in feats if f.what == "mounting hole"]
    return pc


def _with_tabs(name: str, poly: Any, jn: Any, k2: float) -> tuple[Contour, Contour]:
    """The outline cut flat along a tab joint's edge with its tabs added: nominal and grown by ``k2``."""
    import shapely

    got = shapely.union_all([poly.intersection(jn.keep)] + list(jn.tabs)).simplify(1e-4)
    if got.geom_type != "Polygon" or len(got.interiors):
        raise FabricationError(
            f"part {name!r}: cut flat along the xy plane it stands on, it falls apart ({got.geom_type}); it cannot be tab-joined"
        )

    def contour(p: Any) -> Contour:
        p = shapely.geometry.polygon.orient(p, 1.0)
        return Contour([(float(x), float(y), 0.0) for x, y in list(p.exterior.coords)[:-1]])

    grown = got.buffer(k2, join_style="mitre") if k2 else got
    return contour(got), contour(grown)


def nominal_material(pc_outer: Cut, inner: Sequence[Cut], k2: float = 0.0):
    """Outline minus cuts as a shapely polygon, the kerf ``k2`` per side taken back off (for swept areas)."""
    poly = cut_polygon(pc_outer)
    if k2:
        poly = poly.buffer(-k2, quad_segs=32)
    for c in inner:
        poly = poly.difference(cut_polygon(c).buffer(k2, quad_segs=32) if k2 else cut_polygon(c))
    return poly
