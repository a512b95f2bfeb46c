"""Errors a user can cause.

Every error carries a message that names *where* (file, field path or joint)
and *what* (the offending value and what was expected).  The CLI prints the
message on one line and exits with status 2; no traceback is shown.
"""

from __future__ import annotations

__all__ = ["PlanarError", "InputError", "AssemblyError", "SceneError"]


class PlanarError(Exception):
    """Base class for errors caused by user input."""


class InputError(PlanarError, ValueError):
    """A parameter has a value the model cannot use.

    ``field`` names the parameter (e.g. ``"fourbar.coupler"``), ``value`` is the
    offending value and ``expected`` says what would be accepted.
    """

    def __init__(self, field: str, value: object, expected: str) -> None:
        self.field = field
        self.value = value
        self.expected = expected
        super().__init__(f"{field} = {value!r}: expected {expected}")


class AssemblyError(PlanarError):
    """A mechanism cannot be assembled at any (or at a required) driver value."""


class SceneError(PlanarError):
    """A scene file is malformed; the message names the file and field path."""
