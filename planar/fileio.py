"""Atomic file output and the motion table (CSV).

Every writer goes through :func:`atomic_write`: the data lands in a temporary
file beside the target, which is renamed over it only when complete, so a
failure never leaves a partial output file.
"""

from __future__ import annotations

import contextlib
import io
import os
import tempfile
from pathlib import Path
from typing import Any, IO, Iterator

import numpy as np

from .errors import InputError
from .model import Mechanism, Motion

__all__ = ["atomic_write", "motion_columns", "write_motion_csv"]


@contextlib.contextmanager
def atomic_write(path: str | os.PathLike, mode: str = "wb") -> Iterator[IO[Any]]:
    """Open a temporary file beside ``path``; rename it over ``path`` on success."""
    target = Path(path)
    parent = target.parent if str(target.parent) else Path(".")
    if not parent.is_dir():
        raise InputError("output", str(path), f"a path in an existing directory ({parent} does not exist)")
    fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".part", dir=parent)
    try:
        with os.fdopen(fd, mode) as fh:
            yield fh
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)  # mkstemp makes 0600; give the file the usual permissions
        os.replace(tmp, target)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise


def motion_columns(mech: Mechanism, motion: Motion) -> tuple[list[str], np.ndarray]:
    """Column names and an ``(N, k)`` float table for a motion.

    Columns: ``t``, ``driver`` (and ``driver.<node>`` per input node of a
    linkage with several), then ``<part>.x, <part>.y, <part>.angle`` for
    every part, ``<point>.x, <point>.y`` for every named point, and ``valid``
    (1 or 0).  Model units and radians.
    """
    n = len(motion)
    t = motion.t if motion.t is not None else np.arange(n, dtype=float)
    names = ["t", "driver"]
    cols = [t, motion.driver]
    inputs = getattr(mech, "input_values", None)  # a linkage with several inputs: each one's value
    for node, value in (inputs(motion.driver) if inputs is not None else {}).items():
        names.append(f"driver.{node}")
        cols.append(value)
    for p in mech.parts:
        pose = motion.poses[p.name]
        names += [f"{p.name}.x", f"{p.name}.y", f"{p.name}.angle"]
        cols += [pose[:, 0], pose[:, 1], pose[:, 2]]
    for pname, xy in motion.points.items():
        names += [f"{pname}.x", f"{pname}.y"]
        cols += [xy[:, 0], xy[:, 1]]
    names.append("valid")
    cols.append(motion.valid.astype(float))
    return names, np.column_stack(cols)


def write_motion_csv(path: str | os.PathLike, mech: Mechanism, motion: Motion) -> None:
    """Write the motion table as CSV (17 significant digits: round-trips exactly)."""
    names, table = motion_columns(mech, motion)
    buf = io.StringIO()
    buf.write(",".join(names) + "\n")
    fmt = ",".join(["%.17g"] * (len(names) - 1) + ["%d"])
    np.savetxt(buf, table, fmt=fmt)
    with atomic_write(path, "w") as fh:
        fh.write(buf.getvalue())
