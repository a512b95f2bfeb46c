"""Reading synthesis targets: CSV tables (points, angle pairs, poses) and SVG paths.

Every bad input is one :class:`planar.InputError` naming the file, the row
and the field.  Angles in files are radians unless the caller says degrees.
"""

from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError

__all__ = ["read_table", "read_path_targets", "read_svg_points"]

Array = NDArray[np.float64]


def read_table(path: str | Path, required: tuple[str, ...], optional: tuple[str, ...] = (),
               min_rows: int = 1) -> dict[str, Array]:
    """Columns of a CSV file with a header row: every ``required`` column and the ``optional`` ones present."""
    p = str(path)
    try:
        with open(path, newline="") as fh:
            rows = list(csv.reader(fh))
    except FileNotFoundError:
        raise InputError(p, "missing", "an existing CSV file") from None
    except (IsADirectoryError, UnicodeDecodeError) as e:
        raise InputError(p, type(e).__name__, "a readable CSV text file") from None
    rows = [r for r in rows if r and any(c.strip() for c in r) and not r[0].lstrip().startswith("#")]
    if not rows:
        raise InputError(p, "empty", f"a header row with columns {', '.join(required)}")
    header = [h.strip().lower() for h in rows[0]]
    for col in required:
        if col not in header:
            raise InputError(f"{p}: header", rows[0], f"columns {', '.join(required + optional)} "
                             f"({', '.join(optional) or 'none'} optional)")
    cols = [c for c in required + optional if c in header]
    out: dict[str, list[float]] = {c: [] for c in cols}
    for i, r in enumerate(rows[1:], start=2):
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


def read_svg_points(path: str | Path, n: int) -> Array:
    """``n`` points spaced evenly by arc length along the first shape of an SVG file (y up).

    The SVG is read by svgelements (transforms applied); a closed shape gives
    ``n`` distinct points around it, an open one ``n`` points from end to end.
    SVG's y axis points down, planar's up: y is negated.
    """
    import svgelements as se

    p = str(path)
    if n < 3:
        raise InputError("--points", n, "3 or more points to sample from the SVG path")
    try:
        svg = se.SVG.parse(p)
    except FileNotFoundError:
        raise InputError(p, "missing", "an existing SVG file") from None
    except Exception as e:  # svgelements raises parser errors of several kinds
        raise InputError(p, type(e).__name__, "a readable SVG file") from None
    for el in svg.elements():
        if isinstance(el, se.Shape) and not isinstance(el, se.Group):
            path_ = se.Path(el)
            if len(path_) == 0 or path_.length() <= 0:
                continue
            d = path_.d()
            closed = d.rstrip().upper().endswith("Z")
            s = np.linspace(0.0, 1.0, n, endpoint=not closed)
            pts = np.asarray(path_.npoint(s), float)
            pts[:, 1] = -pts[:, 1]
            return pts
    raise InputError(p, "no path", "an SVG with a path or shape of non-zero length")


def read_path_targets(path: str | Path, svg_points: int = 12) -> tuple[Array, Array | None]:
    """Targets ``(N, 2)`` and crank angles ``(N,)`` or ``None``, from ``x,y[,theta]`` CSV or an SVG path."""
    if str(path).lower().endswith(".svg"):
        return read_svg_points(path, svg_points), None
    t = read_table(path, ("x", "y"), ("theta",), min_rows=3)
    return np.column_stack([t["x"], t["y"]]), t.get("theta")
