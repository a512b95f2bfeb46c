"""The shared checks of public arguments and of the kinds' fields: each raises :class:`~planar.errors.InputError`
naming the argument (or ``where.field``) and the value.

This module imports nothing from planar but :mod:`planar.errors` (numpy only inside the checks), so every
room (and :mod:`planar.core.features`, which :mod:`planar.core.model` imports) can use it.
"""

from __future__ import annotations

import dataclasses
import math
import numbers
from typing import TYPE_CHECKING, Any

from planar.errors import InputError

if TYPE_CHECKING:
    import numpy as np
    from numpy.typing import ArrayLike, NDArray

__all__ = [
    "check_driver_rates",
    "check_fields",
    "check_finite",
    "check_kind",
    "check_number",
    "check_point",
    "check_positive",
    "check_samples",
]

Vec = tuple[float, float]


def check_finite(field_name: str, value: ArrayLike) -> NDArray[np.float64]:
    """Return ``value`` as a float array or raise :class:`InputError` on NaN/inf (or what is not numbers)."""
    import numpy as np

    try:
        raw = np.asarray(value)
    except (TypeError, ValueError, OverflowError):  # ragged nesting
        raise InputError(field_name, value, "numbers (a number or an array of them)") from None
    if raw.dtype.kind == "c":  # numpy would drop the imaginary part with only a warning
        raise InputError(field_name, "complex numbers", "real numbers")
    if isinstance(value, (str, bytes)) or raw.dtype.kind in "USVb":  # "1.0" is text, True no number
        raise InputError(field_name, value, "numbers (not text or truth values)")
    try:
        arr = np.asarray(raw, dtype=float)
    except (TypeError, ValueError, OverflowError):
        raise InputError(field_name, value, "numbers (a number or an array of them)") from None
    # a sum is finite only if every term is (NaN and inf propagate); a finite array whose sum
    # overflows is looked at element by element
    if not np.isfinite(arr.sum()) and not np.all(np.isfinite(arr)):
        raise InputError(field_name, value, "finite numbers")
    return arr


def check_positive(field_name: str, value: float, what: str = "length") -> float:
    """Return ``value`` as float or raise :class:`InputError` unless a finite number > 0 (not a bool or a string).

    ``what`` names the quantity in the message (``"a positive, finite rate"``).
    """
    import numpy as np

    if isinstance(value, (bool, str, bytes, np.bool_)):
        raise InputError(field_name, value, "a positive number")
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise InputError(field_name, value, "a positive number") from None
    if not np.isfinite(v) or v <= 0.0:
        raise InputError(field_name, value, f"a positive, finite {what}")
    return v


def check_point(field_name: str, value: ArrayLike, what: str = "a point (x, y): two finite numbers") -> Vec:
    """Return ``value`` as ``(x, y)`` or raise :class:`InputError` unless it is two finite numbers."""
    a = check_finite(field_name, value)
    if a.shape != (2,):
        raise InputError(field_name, value, what)
    return (float(a[0]), float(a[1]))


def check_samples(field_name: str, value: ArrayLike, n: int | None = None) -> NDArray[np.float64]:
    """Return ``value`` as a 1-D float array (a number is one sample) or raise :class:`InputError`.

    Finite numbers only (not text, truth values or NaN), at most one dimension; with ``n``, a number
    or exactly ``n`` values (a rate given per driver value).
    """
    import numpy as np

    a = np.atleast_1d(check_finite(field_name, value))
    if a.ndim != 1:
        raise InputError(field_name, f"an array of shape {a.shape}", "a number or a 1-D array of numbers")
    if n is not None and np.ndim(value) and a.shape[0] != n:
        raise InputError(field_name, f"an array of shape {a.shape}", f"a number or one value per driver value ({n})")
    return a


def check_driver_rates(
    where: str, q: ArrayLike, *rates: ArrayLike, names: tuple[str, ...] = ("qdot", "qddot")
) -> tuple[Any, ...]:
    """``q`` and its ``rates`` (a number or one value per driver value each) checked as :func:`check_samples`
    does, named ``where(q)``, ``where(qdot)``, ``where(qddot)`` (``names``: the rates' argument names); returns
    them as 1-D float arrays of ``q``'s length (a rate given as a number is repeated)."""
    import numpy as np

    qa = check_samples(f"{where}(q)", q)
    named = zip(names[: len(rates)], rates, strict=True)  # a rate without a name is the caller's mistake
    out = [np.broadcast_to(check_samples(f"{where}({n})", r, qa.shape[0]), qa.shape) for n, r in named]
    return (qa, *out)


def _check_name(field: str, name: object) -> None:
    """Refuse a name that is not a non-empty string or holds a control character (it names CSV columns, DXF groups)."""
    if not isinstance(name, str) or not name:
        raise InputError(field, name, "a non-empty string")
    if any(ord(c) < 32 or ord(c) == 127 for c in name):
        raise InputError(field, name, "a name without control characters (newline, tab, NUL)")


def check_number(field_name: str, value: object, integer: bool = False) -> float:
    """Return ``value`` as a float or raise :class:`InputError` unless one finite real number (not a bool or
    a string; with ``integer``, a whole number type)."""
    kind = numbers.Integral if integer else numbers.Real
    if isinstance(value, bool) or not isinstance(value, kind) or type(value).__name__ == "bool_":
        raise InputError(field_name, value, "a whole number" if integer else "a number")
    v = float(value)
    if not math.isfinite(v):
        raise InputError(field_name, value, "a finite number")
    return v


def _check_field(field: str, annotation: str, value: object) -> None:
    base, optional = annotation.removesuffix(" | None"), annotation.endswith(" | None")
    if value is None and optional:
        return
    if base == "float":
        check_number(field, value)
    elif base == "int":
        check_number(field, value, integer=True)
    elif base == "bool":
        if not isinstance(value, bool) and type(value).__name__ != "bool_":
            raise InputError(field, value, "True or False")
    elif base == "str":
        if not isinstance(value, str) or any(ord(c) < 32 or ord(c) == 127 for c in value):
            raise InputError(field, value, "a string without control characters")
    elif base in ("Vec", "tuple[float, float]"):
        check_point(field, value)  # type: ignore[arg-type]


def check_fields(obj: Any, where: str, skip: tuple[str, ...] = ()) -> None:
    """Check each field of the dataclass ``obj`` against its annotation: ``float`` one finite number, ``int`` a
    whole number, ``bool`` a truth value, ``str`` a string, ``Vec`` two finite numbers (``... | None`` also
    ``None``); other annotations are the kind's own to check.  The message names ``where.FIELD``."""
    for f in dataclasses.fields(obj):
        if f.name not in skip and isinstance(f.type, str):
            _check_field(f"{where}.{f.name}", f.type, getattr(obj, f.name))


def check_kind(field_name: str, value: object, kind: type | tuple[type, ...], what: str = "") -> None:
    """:class:`InputError` unless ``value`` is an instance of ``kind`` (``what`` says it in words)."""
    if not isinstance(value, kind):
        names = " or ".join(k.__name__ for k in (kind if isinstance(kind, tuple) else (kind,)))
        raise InputError(field_name, value, what or f"a {names}")
