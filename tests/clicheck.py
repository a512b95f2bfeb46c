"""The command line's contract for a bad input, checked in-process: exit 2, one line, nothing written."""

from __future__ import annotations

from pathlib import Path

import pytest

from planar.cli.main import main


def fails_cleanly(capsys: pytest.CaptureFixture[str], argv: list[str], *needles: str, out: Path | None = None) -> str:
    """``main(argv)`` exits 2 with one line holding every needle, and leaves ``out`` unwritten."""
    rc = main(argv)
    err = capsys.readouterr().err.strip()
    assert rc == 2, err
    assert len(err.splitlines()) == 1 and err.startswith("planar: error: "), err
    for n in needles:
        assert n in err, err
    if out is not None:
        assert not out.exists()
    return err
