"""Errors a user can cause.

Every error carries a message that names *where* (file, field path or joint)
and *what* (the offending value and what was expected).  The CLI prints the
message on one line and exits with status 2; no traceback is shown.  Every
class here derives from :class:`PlanarError`; :class:`InputError` and
:class:`LimitError` are also :class:`ValueError`, so Python callers may catch
either; so are :class:`AssemblyError` and :class:`SceneError`.  :class:`CheckError` is not a user
error but a result that failed its own check (the CLI's exit status 3); it carries the result.
"""

from __future__ import annotations

import os

__all__ = ["AssemblyError", "CheckError", "InputError", "LimitError", "PlanarError", "SceneError", "short_repr"]


class PlanarError(Exception):
    """Base class for errors caused by user input."""


def short_repr(value: object, limit: int = 80) -> str:
    """``repr(value)`` on one line and at most ``limit`` characters (an array is summarised)."""
    try:
        import numpy as np

        if isinstance(value, np.ndarray) and value.size > 4:
            finite = value[np.isfinite(value)] if value.dtype.kind == "f" else value
            rng = (
                f", from {finite.min().item()!r} to {finite.max().item()!r}" if finite.size and value.dtype.kind in "fiu" else ""
            )
            odd = int(value.size - finite.size) if value.dtype.kind == "f" else 0
            nan = int(np.isnan(value).sum()) if odd else 0
            odd_text = ", ".join(t for t in (f"{nan} NaN" if nan else "", f"{odd - nan} inf" if odd - nan else "") if t)
            return f"<array of shape {value.shape}{rng}{', with ' + odd_text if odd else ''}>"
        if isinstance(value, np.generic):
            value = value.item()
    except Exception:  # pragma: no cover - numpy is a dependency; repr below still works
        pass
    text = repr(value).replace("\n", " ")
    if isinstance(value, str | os.PathLike):
        limit = max(limit, 240)  # a file name is what the reader needs: keep paths whole up to a long limit
    if len(text) <= limit:
        return text
    tail = limit // 2  # the end of a long value (a path's file name) is kept, the middle elided
    return text[: limit - 3 - tail] + "..." + text[-tail:]


class InputError(PlanarError, ValueError):
    """A parameter has a value the model cannot use.

    ``field`` names the parameter (e.g. ``"fourbar.coupler"``), ``value`` is the
    offending value and ``expected`` says what would be accepted.
    """

    def __init__(self, field: str, value: object, expected: str) -> None:
        self.field = field
        self.value = value
        self.expected = expected
        super().__init__(f"{field} = {short_repr(value)}: expected {expected}")


class LimitError(InputError):
    """A request needs more work or memory than a configured limit allows (see :mod:`planar.core.limits`)."""


class AssemblyError(PlanarError, ValueError):
    """A mechanism cannot be assembled at any (or at a required) driver value."""


class SceneError(PlanarError, ValueError):
    """A scene file is malformed; the message names the file and field path."""


class CheckError(PlanarError):
    """A result failed its own check (what the command line reports with exit status 3).

    Raised after the result's files are written (to look at), as the command line writes them and exits 3.
    ``result`` is the result itself (:func:`planar.export`: the :class:`~planar.fabrication.build.Fabrication`,
    whose ``violations`` list the collisions the build check found); ``problems`` its failures, one line each.
    """

    def __init__(self, message: str, result: object = None, problems: tuple[str, ...] = ()) -> None:
        self.result = result
        self.problems = tuple(problems)
        super().__init__(message)
