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
import os
import re
import signal
import tempfile
import time
from collections.abc import Callable, Iterable, Iterator, Sequence
from pathlib import Path
from typing import IO, Any

import numpy as np

from planar.core.model import Mechanism, Motion
from planar.errors import InputError

__all__ = [
    "atomic_write",
    "check_name",
    "check_output",
    "clean_stale",
    "hold_signals_after_commit",
    "motion_columns",
    "output_transaction",
    "read_text",
    "write_motion_csv",
]

#: the wall-clock time this process started writing (near enough to its start): a temporary older than this,
#: whose writer process is gone, was left by a killed run (``kill -9``) and is removed (:func:`clean_stale`)
_STARTED = time.time()
#: folders already swept for stale temporaries by this process
_SWEPT: set[str] = set()
#: a temporary's name: ``.<target>.<writer pid>.<random>.part``
_PART = re.compile(r"^\..+\.(\d+)\.[A-Za-z0-9_]{8}\.part$")
#: signals held from the first rename of a command's outputs until the process exits (see :func:`hold_signals`)
_HELD = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP, signal.SIGQUIT)
_HOLD = {"until_exit": False}


def hold_signals_after_commit(on: bool = True) -> None:
    """Once outputs start being renamed into place, keep Ctrl-C and ``kill`` (SIGINT, SIGTERM, SIGHUP,
    SIGQUIT) blocked until the process exits, so an interrupt never lands between a finished rename and
    the command's exit (the ``planar`` command turns this on; the Python API blocks them only during renames)."""
    _HOLD["until_exit"] = on


@contextlib.contextmanager
def _renaming() -> Iterator[None]:
    """Hold the interrupt signals while outputs are renamed (and after, with :func:`hold_signals_after_commit`).

    Dispositions, not a thread's mask: numpy's BLAS threads keep the old mask, and a signal sent to the
    process would reach one of them.  A signal that arrives meanwhile is delivered after the renames
    (from Python) or ignored until the process exits (the ``planar`` command).
    """
    import threading

    if threading.current_thread() is not threading.main_thread():
        yield
        return
    got: list[int] = []
    old = {s: signal.signal(s, lambda n, _f: got.append(n)) for s in _HELD}
    try:
        yield
    finally:
        if _HOLD["until_exit"]:
            for s in _HELD:
                signal.signal(s, signal.SIG_IGN)
        else:
            for s, h in old.items():
                signal.signal(s, h)
            for n in dict.fromkeys(got):
                signal.raise_signal(n)


def _alive(pid: int) -> bool:
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:  # another user's live process
        return True
    return True


def clean_stale(folder: str | os.PathLike) -> list[str]:
    """Remove the temporaries a killed run left in ``folder`` (``.NAME.PID.xxxxxxxx.part`` older than this
    process, whose writer ``PID`` is no longer running); the names removed.  Done once per folder per process
    by :func:`atomic_write`; a live writer's temporaries (another run writing now) are left alone."""
    removed: list[str] = []
    try:
        entries = list(os.scandir(os.fspath(str(folder))))
    except OSError:
        return removed
    for entry in entries:
        m = _PART.match(entry.name)
        if m is None:
            continue
        try:
            if entry.stat(follow_symlinks=False).st_mtime >= _STARTED or _alive(int(m.group(1))):
                continue
            if not entry.is_file(follow_symlinks=False):
                continue
            os.unlink(entry.path)
            removed.append(entry.name)
        except OSError:
            continue
    return removed


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
        with _renaming():
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
        where = next((a for a in (parent, *parent.parents) if a.exists()), None)
        if where is not None and not where.is_dir():
            raise InputError("output", str(path), f"a path in a folder ({where} is a file, not a folder)")
        raise InputError("output", str(path), f"a path in an existing directory ({parent} does not exist)")
    if target.is_dir():
        raise InputError("output", str(path), "a file name (it is a directory)")
    key = os.path.realpath(parent)
    if key not in _SWEPT:
        _SWEPT.add(key)
        clean_stale(parent)
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.{os.getpid()}.", suffix=".part", dir=parent)
    except OSError as e:
        raise InputError("output", str(path), f"a writable place ({e.strerror})") from None
    try:
        try:
            with os.fdopen(fd, mode) as fh:
                yield fh
        except OSError as e:  # a full disc, a file size limit: name the file the user asked for
            if e.filename is not None or e.errno is None:
                raise
            raise OSError(
                e.errno, f"{e.strerror} (while writing it; the old file, if any, is left as it was)", str(target)
            ) from None
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)  # mkstemp makes 0600; give the file the usual permissions
        pending = _PENDING.get()
        if pending is not None:
            pending.append((tmp, target))
        else:
            with _renaming():
                os.replace(tmp, target)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise


def read_text(path: str | os.PathLike, what: str = "text file", max_bytes: int = 64 * 2**20) -> str:
    """The file ``path`` as text: UTF-8 (a byte-order mark skipped) or UTF-16 with its byte-order mark.

    Anything else (a binary file, another encoding, a folder, a missing or
    unreadable file, more than ``max_bytes``) is an :class:`InputError` naming
    the file and what was expected (``what``: "request file", "CSV file", ...).
    """
    p = str(path)
    try:
        with open(p, "rb") as fh:
            raw = fh.read(max_bytes + 1)
    except FileNotFoundError:
        raise InputError(p, "no such file", f"an existing {what}") from None
    except IsADirectoryError:
        raise InputError(p, "a folder", f"a {what}") from None
    except OSError as e:  # a loop of symbolic links, no permission, a device
        raise InputError(p, f"cannot be read ({e.strerror or e})", f"a readable {what}") from None
    if len(raw) > max_bytes:
        raise InputError(p, f"more than {max_bytes // 2**20} MiB", f"a {what} of at most {max_bytes // 2**20} MiB")
    codec = "utf-16" if raw[:2] in (b"\xff\xfe", b"\xfe\xff") else "utf-8-sig"
    try:
        text = raw.decode(codec)
    except UnicodeDecodeError as e:
        raise InputError(
            p,
            f"byte {e.start} is {raw[e.start : e.start + 1]!r}",
            f"a {what} in UTF-8 (or UTF-16 with a byte-order mark)",
        ) from None
    text = text.removeprefix("\ufeff")
    if "\x00" in text:
        raise InputError(p, "NUL bytes", f"a {what} (text, not binary)")
    return text


def _same_file(a: Path, b: Path) -> bool:
    try:
        return a.exists() and b.exists() and os.path.samefile(a, b)
    except OSError:
        return False


def check_outputs(
    outputs: Iterable[tuple[str, str | os.PathLike | None, Sequence[str]]], inputs: Iterable[str | os.PathLike] = ()
) -> None:
    """:func:`check_output` of each ``(option, path, suffixes)`` (``None``: not asked for), and refuse two outputs
    naming one file (the second is named: ``svg='x.svg', assembly='x.svg'`` would leave one of the two)."""
    inputs = tuple(inputs)
    seen: dict[str, str] = {}
    for option, path, suffixes in outputs:
        check_output(option, path, suffixes, inputs)
        if path is not None:
            key = os.path.realpath(path)
            if key in seen:
                raise InputError(option, str(path), f"a different file from {seen[key]} (both name it)")
            seen[key] = option


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
    if not isinstance(path, (str, os.PathLike)):
        raise InputError(option, path, "a file name (a string or a pathlib.Path)")
    text = str(path)
    if not text.strip():
        raise InputError(option, text, "a file name (got an empty one)")
    p = Path(text)
    if directory:
        if p.exists() and not p.is_dir():
            raise InputError(option, text, "a folder (it is an existing file)")
        # the nearest folder that exists: the folder is made under it (a file there cannot hold one)
        home = next((a for a in (p, *p.parents) if a.exists()), Path("."))
        if not home.is_dir():
            raise InputError(option, text, f"a folder path ({home} is a file, not a folder)")
        _check_writable(option, text, home)
        return
    if p.is_dir() or text.endswith(("/", os.sep)):
        raise InputError(option, text, "a file name (it is a folder)")
    parent = p.parent if str(p.parent) else Path(".")
    if not parent.is_dir():
        where = next((a for a in (parent, *parent.parents) if a.exists()), None)
        if where is not None and not where.is_dir():
            raise InputError(option, text, f"a path in a folder ({where} is a file, not a folder)")
        raise InputError(option, text, f"a path in an existing folder ({parent} does not exist)")
    if suffixes and p.suffix.lower() not in suffixes:
        raise InputError(option, text, f"a file name ending in {' or '.join(suffixes)} (the format it writes)")
    for src in inputs:
        if _same_file(p, Path(src)) or os.path.realpath(p) == os.path.realpath(src):
            raise InputError(option, text, f"an output other than the input {src} (it would be overwritten)")
    _check_writable(option, text, parent)


def _check_writable(option: str, text: str, parent: Path) -> None:
    """Refuse a folder no file can be created in, before any work (a temporary is made there and removed:
    permission bits alone do not tell, e.g. for root on a read-only mount)."""
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{Path(text).name}.{os.getpid()}.", suffix=".part", dir=parent)
    except OSError as e:
        raise InputError(
            option, text, f"a path in a folder it can write to (no file can be created in {parent}: {e.strerror})"
        ) from None
    os.close(fd)
    with contextlib.suppress(OSError):
        os.unlink(tmp)


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


#: rows formatted at a time by :func:`write_motion_csv`: memory for formatting (and for ``extra`` columns)
#: is bounded by this many rows, not by the motion's length
CSV_CHUNK = 16384


def write_motion_csv(
    path: str | os.PathLike,
    mech: Mechanism,
    motion: Motion,
    extra: Callable[[Motion], tuple[list[str], list[np.ndarray]]] | None = None,
) -> None:
    """Write the motion table as CSV (17 significant digits: round-trips exactly), streamed.

    ``extra(sub_motion) -> (names, columns)`` adds columns (before ``valid``), computed on
    :data:`CSV_CHUNK` samples at a time (so they must depend on each sample alone, as the
    analytic rates do).  A row holding NaN or inf in the motion's own columns is refused
    (:class:`InputError`) and nothing is written.
    """
    n = len(motion)
    names = None
    with atomic_write(path, "w") as fh:
        for lo in range(0, max(n, 1), CSV_CHUNK):
            sub = motion if n <= CSV_CHUNK else motion.take(np.arange(lo, min(n, lo + CSV_CHUNK)))
            cols, table = motion_columns(mech, sub)
            bad = ~np.isfinite(table.sum(axis=1))  # one float per row: NaN or inf anywhere in it
            if bad.any():
                i = int(np.flatnonzero(bad)[0])
                raise InputError(
                    f"{mech.name}: motion row {lo + i}",
                    table[i].tolist(),
                    "finite numbers (a time or pose of NaN or inf is no sample)",
                )
            if extra is not None:
                more, extra_cols = extra(sub)
                cols = cols[:-1] + more + cols[-1:]
                table = np.column_stack([table[:, :-1], *extra_cols, table[:, -1]])
            if names is None:
                names = cols
                for name in names:
                    check_name(f"{mech.name}: column", name)
                csv.writer(fh, lineterminator="\n").writerow(names)  # a comma or quote in a name is quoted
            np.savetxt(fh, table, fmt=",".join(["%.17g"] * (len(names) - 1) + ["%d"]))
