"""Atomic file output, output-path checks and the motion table (CSV).

Every writer goes through :func:`atomic_write`: the data lands in a temporary
file beside the target, which is renamed over it only when complete, so a
failure never leaves a partial output file.  Inside :func:`output_transaction`
the renames wait until the whole block has succeeded, so a command writing
several files (a gallery of GIFs) leaves either all of them or none, and
existing files untouched on failure.
"""

from __future__ import annotations

import contextlib
import contextvars
import csv
import io
import os
import tempfile
from collections.abc import Iterable, Iterator, Sequence
from pathlib import Path
from typing import IO, Any

import numpy as np

from planar.core.model import Mechanism, Motion
from planar.errors import InputError

__all__ = ["atomic_write", "check_name", "check_output", "motion_columns", "output_transaction", "write_motion_csv"]

#: the temporaries ``(tmp, target)`` of the innermost :func:`output_transaction`, renamed at its end
_PENDING: contextvars.ContextVar[list[tuple[str, Path]] | None] = contextvars.ContextVar("_PENDING", default=None)


@contextlib.contextmanager
def output_transaction() -> Iterator[None]:
    """Defer every :func:`atomic_write` rename in the block until the block has succeeded.

    On success the temporaries are renamed over their targets; on any
    exception (``KeyboardInterrupt`` included) they are removed and the
    targets are left as they were.
    """
    outer = _PENDING.get()
    pending: list[tuple[str, Path]] = []
    token = _PENDING.set(pending)
    try:
        yield
    except BaseException:
        _PENDING.reset(token)
        for tmp, _ in pending:
            with contextlib.suppress(FileNotFoundError):
                os.unlink(tmp)
        raise
    _PENDING.reset(token)
    if outer is not None:  # nested: the outer transaction renames
        outer.extend(pending)
        return
    done = 0
    try:
        for tmp, target in pending:
            os.replace(tmp, target)
            done += 1
    except BaseException:
        for tmp, _ in pending[done:]:
            with contextlib.suppress(FileNotFoundError):
                os.unlink(tmp)
        raise


@contextlib.contextmanager
def atomic_write(path: str | os.PathLike, mode: str = "wb") -> Iterator[IO[Any]]:
    """Open a temporary file beside ``path``; rename it over ``path`` on success.

    Inside :func:`output_transaction` the rename waits for the transaction.
    """
    target = Path(path)
    if not str(path):
        raise InputError("output", str(path), "a file name (got an empty one)")
    parent = target.parent if str(target.parent) else Path(".")
    if not parent.is_dir():
        raise InputError("output", str(path), f"a path in an existing directory ({parent} does not exist)")
    if target.is_dir():
        raise InputError("output", str(path), "a file name (it is a directory)")
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".part", dir=parent)
    except OSError as e:
        raise InputError("output", str(path), f"a writable place ({e.strerror})") from None
    try:
        with os.fdopen(fd, mode) as fh:
            yield fh
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)  # mkstemp makes 0600; give the file the usual permissions
        pending = _PENDING.get()
        if pending is not None:
            pending.append((tmp, target))
        else:
            os.replace(tmp, target)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise


def _same_file(a: Path, b: Path) -> bool:
    try:
        return a.exists() and b.exists() and os.path.samefile(a, b)
    except OSError:
        return False


def check_output(
    option: str,
    path: str | os.PathLike | None,
    suffixes: Sequence[str],
    inputs: Iterable[str | os.PathLike] = (),
    directory: bool = False,
) -> None:
    """Refuse an output path before any work: empty, in a missing folder, a directory (or, with
    ``directory``, a file), one of the ``inputs``, or (for a file) a suffix not in ``suffixes``.

    ``option`` names the command-line option (``-o``, ``--svg``) in the message.
    """
    if path is None:
        return
    text = str(path)
    if not text.strip():
        raise InputError(option, text, "a file name (got an empty one)")
    p = Path(text)
    if directory:
        if p.exists() and not p.is_dir():
            raise InputError(option, text, "a folder (it is an existing file)")
        return
    if p.is_dir():
        raise InputError(option, text, "a file name (it is a folder)")
    parent = p.parent if str(p.parent) else Path(".")
    if not parent.is_dir():
        raise InputError(option, text, f"a path in an existing folder ({parent} does not exist)")
    if suffixes and p.suffix.lower() not in suffixes:
        raise InputError(option, text, f"a file name ending in {' or '.join(suffixes)} (the format it writes)")
    for src in inputs:
        if _same_file(p, Path(src)) or os.path.realpath(p) == os.path.realpath(src):
            raise InputError(option, text, f"an output other than the input {src} (it would be overwritten)")


def check_name(field: str, name: str) -> str:
    """``name`` if it can stand in a CSV header, a DXF group and SVG text; else :class:`InputError`.

    Control characters (newline, tab, NUL, ...) cannot be represented in a DXF
    group name or in XML, and would break a CSV row, so they are refused;
    commas and quotes are quoted by the CSV writers.
    """
    bad = [c for c in str(name) if ord(c) < 32 or 127 <= ord(c) < 160]
    if bad or not str(name):
        raise InputError(field, name, "a name without control characters (newline, tab, ...)" if bad else "a non-empty name")
    return str(name)


#: the two axes of a part's plane, as its columns are named (a wind-up toy's pieces move in xy, xz or yz)
PLANE_AXES = {"xy": ("x", "y"), "xz": ("x", "z"), "yz": ("y", "z")}


def motion_columns(mech: Mechanism, motion: Motion) -> tuple[list[str], np.ndarray]:
    """Column names and an ``(N, k)`` float table for a motion.

    Columns: ``t``, ``driver`` (and ``driver.<node>`` per input node of a
    linkage with several), then ``<part>.x, <part>.y, <part>.angle`` for
    every part, ``<point>.x, <point>.y`` for every named point, and ``valid``
    (1 or 0).  Model units and radians.  A part moving in another plane
    (a toy's xz or yz piece) names its plane's axes: ``<part>.x, <part>.z``
    or ``<part>.y, <part>.z`` (its angle about the plane's normal).
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
        u, v = PLANE_AXES[getattr(p, "plane", "xy")]
        names += [f"{p.name}.{u}", f"{p.name}.{v}", f"{p.name}.angle"]
        cols += [pose[:, 0], pose[:, 1], pose[:, 2]]
    points = getattr(mech, "points", {})
    for pname, xy in motion.points.items():
        part = points[pname][0] if pname in points else None
        u, v = PLANE_AXES[getattr(mech.part(part), "plane", "xy")] if part is not None else ("x", "y")
        names += [f"{pname}.{u}", f"{pname}.{v}"]
        cols += [xy[:, 0], xy[:, 1]]
    names.append("valid")
    cols.append(motion.valid.astype(float))
    return names, np.column_stack(cols)


def write_motion_csv(path: str | os.PathLike, mech: Mechanism, motion: Motion) -> None:
    """Write the motion table as CSV (17 significant digits: round-trips exactly)."""
    names, table = motion_columns(mech, motion)
    for name in names:
        check_name(f"{mech.name}: column", name)
    buf = io.StringIO()
    csv.writer(buf, lineterminator="\n").writerow(names)  # a comma or quote in a name is quoted
    fmt = ",".join(["%.17g"] * (len(names) - 1) + ["%d"])
    np.savetxt(buf, table, fmt=fmt)
    with atomic_write(path, "w") as fh:
        fh.write(buf.getvalue())
