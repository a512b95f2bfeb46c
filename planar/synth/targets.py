"""Reading synthesis targets: CSV tables (points, angle pairs, poses) and SVG paths.

Every bad input is one :class:`planar.InputError` naming the file, the row
and the field.  Angles in files are radians unless the caller says degrees.
"""

from __future__ import annotations

import csv
import math
import re
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from planar.core.limits import RESOLUTION, SIZE_RANGE
from planar.errors import InputError

__all__ = [
    "SIZE_RANGE",
    "SVG_UNIT_MM",
    "check_theta",
    "normalisation",
    "read_path_targets",
    "read_svg_points",
    "read_svg_shape",
    "read_table",
    "read_targets",
    "svg_closed",
    "target_unit_mm",
]

#: millimetres per SVG user unit: a drawing's coordinates are read as millimetres (the ``viewBox`` of a drawing
#: made in mm, as Inkscape's default document is; a drawing in px is read 1 px = 1 mm: scale it, or export with
#: ``--unit-mm``)
SVG_UNIT_MM = 1.0


def target_unit_mm(path: str | Path) -> float | None:
    """What one unit of the targets in ``path`` is in millimetres: :data:`SVG_UNIT_MM` for an SVG drawing,
    ``None`` for a CSV table (its numbers have no unit: the scene's default ``unit_mm`` applies)."""
    return SVG_UNIT_MM if str(path).lower().endswith(".svg") else None


# SIZE_RANGE (re-exported): the sizes and coordinates planar synthesises at, from planar.core.limits

Array = NDArray[np.float64]


def read_table(
    path: str | Path, required: tuple[str, ...], optional: tuple[str, ...] = (), min_rows: int = 1, strict: bool = False
) -> dict[str, Array]:
    """Columns of a CSV file with a header row: every ``required`` column and the ``optional`` ones present.

    A UTF-8 byte-order mark is skipped.  ``strict``: a column that is neither required nor optional
    (a misspelt one) is an error naming it and the accepted ones.
    """
    p = str(path)
    import io

    from planar.fileio import read_text

    rows = list(csv.reader(io.StringIO(read_text(p, "CSV file"), newline="")))
    rows = [r for r in rows if r and any(c.strip() for c in r) and not r[0].lstrip().startswith("#")]
    if not rows:
        raise InputError(p, "empty", f"a header row with columns {', '.join(required)}")
    header = [h.strip().lower() for h in rows[0]]
    twice = next((h for i, h in enumerate(header) if h and h in header[:i]), None)
    if twice is not None:
        raise InputError(f"{p}: header: column", twice, "each column once (which of the two would be read?)")
    for col in required:
        if col not in header:
            raise InputError(
                f"{p}: header", rows[0], f"columns {', '.join(required + optional)} ({', '.join(optional) or 'none'} optional)"
            )
    if strict:
        for h, raw in zip(header, rows[0]):
            if h not in required + optional:
                raise InputError(
                    f"{p}: header: column",
                    raw.strip(),
                    f"one of the columns {', '.join(required + optional)} ({', '.join(optional) or 'none'} optional)",
                )
    cols = [c for c in required + optional if c in header]
    out: dict[str, list[float]] = {c: [] for c in cols}
    for i, r in enumerate(rows[1:], start=2):
        if any(c.strip() for c in r[len(header) :]):  # a ragged row: which cell belongs to which column?
            raise InputError(f"{p}: row {i}", ",".join(r), f"{len(header)} cells, one per header column ({','.join(rows[0])})")
        for c in cols:
            j = header.index(c)
            cell = r[j].strip() if j < len(r) else ""
            try:
                v = float(cell)
            except ValueError:
                raise InputError(f"{p}: row {i}: {c}", cell, "a number") from None
            if not math.isfinite(v):
                raise InputError(f"{p}: row {i}: {c}", cell, "a finite number")
            out[c].append(v)
    n = len(rows) - 1
    if n < min_rows:
        raise InputError(p, f"{n} rows", f"at least {min_rows} data rows")
    return {c: np.asarray(v, float) for c, v in out.items()}


#: samples per target (at least this many in all) of the dense polyline whose lengths place SVG targets
DENSE_PER_POINT, DENSE_MIN = 400, 20_000


def _even_by_length(path: Any, n: int, closed: bool) -> Array:
    """``n`` points of an svgelements ``path`` at equal arc lengths (a closed path: ``n`` gaps round it).

    svgelements' ``point(t)`` spreads ``t`` over the segments by their lengths but runs along a Bezier by its
    parameter, not its length (a 25-point bean's gaps varied 1.78 times); so the path is sampled densely,
    its cumulative chord length taken, and the parameters at equal lengths interpolated from it."""
    m = max(DENSE_MIN, DENSE_PER_POINT * n)
    u = np.linspace(0.0, 1.0, m)
    dense = np.asarray(path.npoint(u), float)
    cum = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(dense, axis=0).T))])
    want = np.linspace(0.0, cum[-1], n, endpoint=not closed)
    return np.asarray(path.npoint(np.interp(want, cum, u)), float)


def _metric_page_factor(svg: Any) -> float:
    """What undoes svgelements' inch of 25.40000 mm made of ``1 / 0.0393701`` (0.54 ppm long) in a drawing whose
    ``viewBox`` is mapped onto a page sized in mm or cm: 1 for any other drawing (and once svgelements is exact)."""
    import svgelements as se

    size = str(svg.values.get("width") or svg.values.get("height") or "").strip().lower()
    if svg.viewbox is None or not size.endswith(("mm", "cm")):
        return 1.0
    return 1.0 / float(se.Length("1mm").value(ppi=25.4))


def read_svg_points(path: str | Path, n: int, option: str = "--points") -> Array:
    """``n`` points spaced evenly by arc length along the first shape of an SVG file (y up).

    The SVG is read by svgelements (transforms applied); a closed shape gives
    ``n`` distinct points around it, an open one ``n`` points from end to end,
    the first at the path's start.  Equal arc lengths to 1e-4 of the length or
    better (:func:`_even_by_length`).  SVG's y axis points down, planar's up:
    a point ``(x, y)`` of the drawing (after every transform, the
    ``viewBox``'s included) is the target ``(x, -y)``.
    """
    return read_svg_shape(path, n, option)[0]


def read_svg_shape(path: str | Path, n: int, option: str = "--points") -> tuple[Array, bool]:
    """:func:`read_svg_points`'s points and whether the shape is closed (:func:`svg_closed`), from one reading of
    the file."""
    if n < 3:
        raise InputError(option, n, "3 or more points to sample from the SVG path")
    path_, closed, factor = _first_shape(path)
    pts = _even_by_length(path_, n, closed) * factor
    pts[:, 1] = -pts[:, 1]
    return pts, closed


def svg_closed(path: str | Path) -> bool:
    """Whether the first shape of an SVG file (the one :func:`read_svg_points` samples) is closed: a path ending
    in ``Z``, or a closed shape (circle, ellipse, rectangle, polygon).  A rocking input traces such a shape only as
    an arc, back and forth: ``planar synth path`` then searches only inputs that turn fully."""
    return _first_shape(path)[1]


def _first_shape(path: str | Path) -> tuple[Any, bool, float]:
    """The first shape of non-zero length of an SVG file as an svgelements path, whether it is closed, and the
    page's factor to millimetres (:func:`_metric_page_factor`); :class:`InputError` naming the file otherwise."""
    import svgelements as se

    p = str(path)
    try:
        svg = se.SVG.parse(p, ppi=25.4)  # 25.4 per inch: a length in mm (or in, cm) is read as mm, px as 1
    except FileNotFoundError:
        raise InputError(p, "missing", "an existing SVG file") from None
    except Exception as e:  # svgelements raises parser errors of several kinds: say what the parser said
        why = " ".join(str(e).split())[:160] or type(e).__name__
        raise InputError(p, f"not readable as SVG ({why})", "a readable SVG file") from None
    _check_finite_attributes(p)
    for el in svg.elements():
        if isinstance(el, se.Shape) and not isinstance(el, se.Group):
            path_ = se.Path(el)
            box = path_.bbox()
            if box is not None:  # coordinates first: a length integrated at 1e160 differs from run to run
                big = max(abs(float(v)) for v in box)
                if not (math.isfinite(big) and big <= SIZE_RANGE[1]):
                    raise InputError(
                        p,
                        f"a coordinate of {big:.3g}",
                        f"coordinates within {SIZE_RANGE[1]:g} (the solvers multiply four lengths; scale the drawing)",
                    )
            if len(path_) == 0 or path_.length() <= 0:
                continue
            return path_, path_.d().rstrip().upper().endswith("Z"), _metric_page_factor(svg)
    raise InputError(p, "no path", "an SVG with a path or shape of non-zero length")


#: the SVG attributes that carry coordinates or lengths (svgelements reads ``cx="nan"`` as 0)
_GEOMETRY = ("cx", "cy", "r", "rx", "ry", "x", "y", "width", "height", "x1", "y1", "x2", "y2", "points", "d", "transform")
#: the attributes that are lengths: a negative one is an error in SVG (svgelements took its absolute value)
_SIZES = ("r", "rx", "ry", "width", "height")
_NON_FINITE = re.compile(r"(?i)(?<![a-z])(nan|inf(inity)?)(?![a-z])")


def _check_finite_attributes(path: str) -> None:
    """:class:`InputError` naming the file, the element and the attribute if a coordinate is NaN or infinite
    (svgelements reads ``cx="nan"`` as 0, or drops the element).  A file XML cannot parse is left to
    svgelements, which names it."""
    import xml.etree.ElementTree as ET

    try:
        root = ET.parse(path).getroot()
    except (ET.ParseError, OSError, ValueError):
        return
    for el in root.iter():
        tag = str(el.tag).rsplit("}", 1)[-1]
        for name in _GEOMETRY:
            text = el.attrib.get(name)
            if text is not None and _NON_FINITE.search(text):
                raise InputError(f"{path}: <{tag}> {name}", text, "finite numbers (SVG coordinates)")
            if text is not None and name in _SIZES and text.strip().startswith("-"):  # SVG: an error, not |r|
                raise InputError(f"{path}: <{tag}> {name}", text, "a length >= 0 (SVG refuses a negative one)")


def read_path_targets(path: str | Path, svg_points: int | None = None, option: str = "--points") -> tuple[Array, Array | None]:
    """Targets ``(N, 2)`` and crank angles ``(N,)`` or ``None``, from ``x,y[,theta]`` CSV or an SVG path.

    ``svg_points``: points sampled along an SVG (12 when ``None``); given with a CSV it is an error, naming
    ``option`` (the command line's ``--points``).  A CSV column other than ``x``, ``y``, ``theta`` is an error.
    """
    if str(path).lower().endswith(".svg"):
        return read_svg_points(path, 12 if svg_points is None else svg_points, option), None
    if svg_points is not None:
        raise InputError(option, svg_points, f"no {option} with a CSV target ({path}: every row is a target)")
    t = read_table(path, ("x", "y"), ("theta",), min_rows=3, strict=True)
    return np.column_stack([t["x"], t["y"]]), t.get("theta")


#: how fine float64 must resolve a target coordinate, as a fraction of the targets' size (:data:`RESOLUTION` of a
#: design's smallest length, its pins, a hundredth of the size)
TARGET_RESOLUTION = RESOLUTION * 1e-2


def normalisation(targets: Array, name: str = "targets") -> tuple[Array, float]:
    """The targets' centroid ``(2,)`` and size ``s`` (RMS distance from the centroid, model units).

    Synthesis works on ``(targets - centroid) / s`` so its tolerances and steps do not depend on the
    units.  Raises :class:`InputError` when ``s`` or a coordinate is outside :data:`SIZE_RANGE`.
    """
    t = np.asarray(targets, float)
    lo, hi = SIZE_RANGE
    big = float(np.max(np.abs(t)))
    if not big <= hi:
        raise InputError(
            name,
            f"a coordinate of {big:.3g}",
            f"coordinates within {hi:g} model units (the solvers multiply four lengths; scale the targets down)",
        )
    c = t.mean(0)
    d = t - c
    m = float(np.max(np.abs(d)))  # squares of 1e-300 underflow to 0: the RMS is taken of d / m, then scaled back
    s = m * float(np.sqrt(np.mean(np.sum((d / m) ** 2, axis=1)))) if m > 0 else 0.0
    if not lo <= s <= hi:
        raise InputError(
            name,
            f"size {s:.3g} (RMS distance from the centroid)",
            f"a size between {lo:g} and {hi:g} model units (the solvers multiply four lengths; scale the targets)",
        )
    # the design's pins are a few hundredths of the targets' size: its own check (check_scale) refuses a
    # placement float64 resolves coarser than 1e-9 of them, so the targets are held to 1e-11 of their size
    # here, before any search (a 1-unit curve 1e6 from the origin was refused only after 30 s of search)
    if float(np.spacing(big)) > TARGET_RESOLUTION * s:
        raise InputError(
            name,
            f"a coordinate of {big:.6g} with the targets {s:.3g} across",
            f"targets nearer the origin: float64 resolves {float(np.spacing(big)):.3g} there, coarser than "
            f"{TARGET_RESOLUTION:g} of their size, and the design's pins are smaller still (move them toward the origin)",
        )
    return c, s


def check_theta(theta: Array, name: str | None, deg: bool) -> None:
    """Refuse crank angles (radians) spanning more than a turn, or two targets at the same angle.

    ``name``: the file they were read from (the field is then ``FILE: theta``), or None for the Python
    argument ``theta``; ``deg``: whether the file's angles were given in degrees (``--deg``)."""
    field = "theta" if name is None else f"{name}: theta"
    span = float(np.ptp(theta))
    if span > 2 * np.pi * (1 + 1e-12):
        unit = "deg" if deg else "rad"
        shown = np.degrees(span) if deg else span
        hint = "" if deg else " (they look like degrees: add --deg)" if name is not None else " (degrees? numpy.radians them)"
        raise InputError(field, f"values spanning {shown:.6g} {unit}", "crank angles within one turn" + hint)
    w = np.mod(theta, 2 * np.pi)
    order = np.argsort(w, kind="stable")
    gap = np.diff(np.append(w[order], w[order[0]] + 2 * np.pi))
    k = int(np.argmin(gap))
    if gap[k] <= 1e-12 * 2 * np.pi:
        i, j = sorted((int(order[k]), int(order[(k + 1) % len(order)])))
        raise InputError(
            field,
            f"targets {i + 1} and {j + 1} (in data-row order) at the same crank angle {theta[i]:.6g}",
            "a different crank angle (modulo a turn) at every target",
        )


def check_search_args(
    targets: Any, theta: Any = None, seed: Any = 0, tolerance: Any = 1.0, flags: dict[str, Any] | None = None, width: int = 2
) -> tuple[Array, Array | None]:
    """The Python entrance of a synthesis: ``targets`` ``(N, width)`` finite numbers (``N >= 3``), ``theta`` one
    finite crank angle per target (or ``None``), ``seed`` a whole number >= 0, ``tolerance`` a positive number and
    each of ``flags`` True or False; :class:`InputError` naming the argument.  Returns ``(targets, theta)`` as arrays.
    """
    from planar.core.fields import check_finite, check_number, check_positive, check_samples

    t = check_finite("targets", targets)
    if t.ndim != 2 or t.shape[1] != width or len(t) < 3:
        raise InputError("targets", f"an array of shape {t.shape}", f"3 or more points, an array ({'N'}, {width})")
    th = None if theta is None else check_samples("theta", theta, len(t))
    if th is not None and len(th) != len(t):
        raise InputError("theta", len(th), f"one crank angle per target ({len(t)})")
    if not 0 <= check_number("seed", seed, integer=True) < 2**32:
        raise InputError("seed", seed, "a whole number from 0 to 2**32 - 1")
    check_positive("tolerance", tolerance, "tolerance")
    for name, value in (flags or {}).items():
        if not isinstance(value, (bool, np.bool_)):
            raise InputError(name, value, "True or False")
    return t, th


#: the most points :func:`read_targets` samples along an SVG (a path is matched at each; ``synth path``'s cap)
MAX_SVG_POINTS = 500


def read_targets(path: str | Path, points: int | None = None) -> tuple[Array, Array | None]:
    """The targets of a path synthesis from a file, as ``planar synth path FILE`` reads them.

    Parameters
    ----------
    path : str or Path
        An SVG drawing (``.svg``: the first shape with a non-zero length, in millimetres,
        :data:`planar.synth.targets.SVG_UNIT_MM`: a page sized in mm, cm or in is converted, and unitless or px user units are
        read as mm; y is turned up: a drawing's ``(x, y)`` is the target
        ``(x, -y)``) or a CSV table with columns ``x``, ``y`` and optionally ``theta`` (the crank angle at each
        target, radians: ``numpy.radians`` a table in degrees before passing it on).
    points : int, optional
        For an SVG: how many points to sample along the shape, evenly by arc length (3 to
        :data:`MAX_SVG_POINTS`; 12 when ``None``).  None for a CSV (every row is a target).

    Returns
    -------
    targets : ndarray, shape (N, 2)
        The points (the file's units, y up).
    theta : ndarray, shape (N,), or None
        The CSV's ``theta`` column (radians), or ``None``.

    Examples
    --------
    >>> targets, theta = read_targets("bean.svg", points=25)  # doctest: +SKIP
    >>> design = planar.synth.synthesise_path(targets, theta)  # doctest: +SKIP
    """
    from planar.core.fields import check_number

    if not isinstance(path, (str, Path)):
        raise InputError("path", path, "a file name (str or Path): an .svg drawing or a CSV table")
    if points is not None and not 3 <= check_number("points", points, integer=True) <= MAX_SVG_POINTS:
        raise InputError("points", points, f"3 to {MAX_SVG_POINTS} points sampled along the SVG")
    return read_path_targets(path, points, option="points")
