"""The ``planar`` command.

Every subcommand exits 0 on success and 2 on a user error, printing one line
``planar: error: ...`` (no traceback; ``--debug`` shows it).  Anything
unexpected is one line too, ``planar: internal error: ...``, with exit 1.
Output paths are checked before any work (folder exists, extension matches
the format, not one of the inputs); every output is written to a temporary
and renamed only when the whole command succeeded.
"""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Sequence
from typing import ClassVar, NoReturn

from planar.errors import PlanarError

__all__ = ["COMMANDS", "build_parser", "main"]


class _Parser(argparse.ArgumentParser):
    """An argument parser whose errors are one line: ``planar: error: render: ... (see planar render --help)``."""

    #: the command line being parsed (for :meth:`_explain`)
    argv: ClassVar[list[str]] = []

    def error(self, message: str) -> NoReturn:
        sub = self.prog.split(" ", 1)[1] + ": " if " " in self.prog else ""
        self.exit(2, f"planar: error: {sub}{self._explain(message)} (see {self.prog} --help)\n")

    def _explain(self, message: str) -> str:
        """argparse's "expected one argument" said with what the option takes; a value that starts with '-'
        (read as an option) is shown in the form that passes it (``--sheet=-5x-5``)."""
        import re

        m = re.fullmatch(r"argument (\S+): expected one argument", message)
        if m is None:
            return message
        names = m.group(1).split("/")
        action = next((a for a in self._actions if set(a.option_strings) & set(names)), None)
        what = re.sub(r"\s*\(default[^)]*\)", "", action.help) if action is not None and action.help else "a value"
        text = f"argument {m.group(1)}: expected a value after it ({what})"
        argv = type(self).argv
        for i, tok in enumerate(argv[:-1]):
            nxt = argv[i + 1]
            if tok in names and nxt.startswith("-") and len(nxt) > 1:
                text += f"; {nxt!r} was read as an option: a value starting with '-' is written {tok}={nxt}"
                break
        return text


#: every command: its name and the module that adds it (``add_parser(sub)``); a module is imported only
#: to build the parser, and each keeps its heavy imports inside the function that runs the command
COMMANDS: tuple[tuple[str, str], ...] = (
    ("demo", "planar.cli.demo"),
    ("bench", "planar.cli.bench"),
    ("chains", "planar.cli.chains"),
    ("render", "planar.cli.render"),
    ("motion", "planar.cli.motion"),
    ("gallery", "planar.cli.gallery"),
    ("schema", "planar.cli.schema"),
    ("compare", "planar.cli.compare"),
    ("export", "planar.cli.export"),
    ("toy", "planar.cli.toy"),
    ("design", "planar.cli.design"),
    ("plot", "planar.cli.plot"),
    ("info", "planar.cli.info"),
    ("synth", "planar.cli.synth"),
)


def build_parser() -> argparse.ArgumentParser:
    """The ``planar`` argument parser with every command of :data:`COMMANDS`."""
    import importlib

    p = _Parser(
        prog="planar",
        description="2D rigid-body mechanisms: exact kinematics and more.",
        epilog="Exit status: 0 success, 2 a user error (one line naming the file, field or option), "
        "3 a result that failed its own check (compare, toy, design, synth, export's build check; each failure "
        "named; design, synth and export still write their outputs), 1 an internal error (run with --debug for the traceback). "
        "Limits on work (PLANAR_MAX_SAMPLES, PLANAR_MAX_FRAMES, PLANAR_MAX_CHAIN, "
        "PLANAR_MAX_MEMORY): see the README.",
    )
    p.add_argument("--debug", action="store_true", help="show the Python traceback of an error")
    p.add_argument("--version", action="version", version=f"planar {_version()}")
    sub = p.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for _name, module in COMMANDS:
        importlib.import_module(module).add_parser(sub)
    return p


def _version() -> str:
    """The installed distribution's version (``unknown`` when run from a checkout that was never installed)."""
    from importlib import metadata

    try:
        return metadata.version("planar")
    except metadata.PackageNotFoundError:
        return "unknown (not installed: pip install .)"


def _one_line(text: object) -> str:
    return " ".join(str(text).split())


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point: parse, run, turn user errors into exit status 2 (one line, no traceback).

    Warnings (numpy's RuntimeWarnings on invalid samples) are silenced: the
    validity masks carry that information.  ``--debug`` prints an error's traceback
    before its one line, and keeps its exit status (2 for a user error, 1 for a bug).
    """
    hook = sys.unraisablehook
    debug = "--debug" in (sys.argv[1:] if argv is None else argv)
    if not debug:  # a writer abandoned by an error complains from its __del__: not a user's concern
        sys.unraisablehook = _quiet
    try:
        return _main(argv)
    except KeyboardInterrupt:  # while parsing or importing, or a second Ctrl-C while unwinding
        print("planar: interrupted (no output written)", file=sys.stderr)
        rc = 130
    finally:
        import gc

        gc.collect()
        sys.unraisablehook = hook
    if argv is None:  # the command itself: leave now, before shutdown handlers (threads, writers) can print
        sys.stderr.flush()
        os._exit(rc)
    return rc


def _main(argv: Sequence[str] | None) -> int:
    import warnings

    parser = build_parser()
    _Parser.argv = list(argv) if argv is not None else sys.argv[1:]
    try:
        args = parser.parse_args(argv)
    except SystemExit as e:  # --help, or a usage error already printed on one line
        return e.code if isinstance(e.code, int) else (0 if e.code is None else 2)
    _quiet_cache_notes()
    try:
        import numpy as np

        if argv is None:  # the command itself: no interrupt between its outputs' renames and its exit
            from planar.fileio import hold_signals_after_commit

            hold_signals_after_commit()

        with warnings.catch_warnings(), np.errstate(all="ignore"):
            if not args.debug:
                warnings.simplefilter("ignore")
            return int(args.func(args) or 0)
    except PlanarError as e:
        _traceback(args.debug)
        print(f"planar: error: {_one_line(e)}", file=sys.stderr)
        return 2
    except BrokenPipeError:
        # the reader of our output went away (``planar compare | head``): stop quietly, as Unix tools do
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return 141
    except OSError as e:  # a file the user named: unreadable, a loop of links, a full disc
        _traceback(args.debug)
        where = f"{e.filename}: " if e.filename else ""
        print(f"planar: error: {where}{_one_line(e.strerror or e)}", file=sys.stderr)
        return 2
    except MemoryError:
        _traceback(args.debug)
        print(
            "planar: error: out of memory; ask for fewer samples or frames (or lower PLANAR_MAX_MEMORY "
            "so this is refused before it starts)",
            file=sys.stderr,
        )
        return 2
    except Exception as e:  # the guard: a bug in planar, still one line
        if _interrupted(e):  # a Ctrl-C that a library turned into its own error (an import, a worker)
            raise KeyboardInterrupt from None
        _traceback(args.debug)
        print(
            f"planar: internal error: {type(e).__name__}: {_one_line(e)[:300]} "
            f"(a bug in planar; run again with --debug for the traceback)",
            file=sys.stderr,
        )
        return 1


def _traceback(debug: bool) -> None:
    """With ``--debug``, print the traceback of the error being handled (the exit status stays its class's)."""
    if debug:
        import traceback

        traceback.print_exc()


def _interrupted(e: BaseException) -> bool:
    """Whether ``e`` was caused by a Ctrl-C (a ``KeyboardInterrupt`` in its chain of causes)."""
    seen: set[int] = set()
    cur: BaseException | None = e
    while cur is not None and id(cur) not in seen:
        if isinstance(cur, KeyboardInterrupt):
            return True
        seen.add(id(cur))
        cur = cur.__cause__ or cur.__context__
    return False


#: what a library logs when it cannot keep its cache in ``$HOME/.cache`` (it works on without; the notes
#: would follow every command): dropped by :func:`_quiet_cache_notes`
_CACHE_NOTES = {
    "matplotlib": ("mkdir -p failed for path", "Matplotlib created a temporary cache directory"),
    "ezdxf": ("Cannot create cache home directory", "Error writing cache file"),
}


def _quiet_cache_notes() -> None:
    """Drop the libraries' notes that their caches cannot be saved (an unwritable ``$HOME/.cache``)."""
    import logging

    for name, starts in _CACHE_NOTES.items():
        log = logging.getLogger(name)
        if not any(isinstance(f, _NotStarting) for f in log.filters):
            log.addFilter(_NotStarting(starts))


class _NotStarting:
    """A logging filter dropping the records whose message starts with one of ``starts``."""

    def __init__(self, starts: tuple[str, ...]) -> None:
        self.starts = starts

    def filter(self, record: object) -> bool:
        return not str(getattr(record, "msg", "")).startswith(self.starts)


def _quiet(unraisable: object) -> None:
    """An unraisable-exception hook that prints nothing (used while an interrupted command unwinds)."""


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
