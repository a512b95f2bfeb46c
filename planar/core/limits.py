"""Bounds checked before work is allocated, each configurable by an environment variable.

A scene or an option can ask for any amount of work (``cycles = 1e5`` at
100 000 samples per cycle is 74 GiB of poses).  Every such request is checked
here *before* arrays are allocated, and refused with a
:class:`~planar.errors.LimitError` naming the field, the value, the limit and
the variable that raises it:

=========================  ======================  ==========================================
limit                      environment variable    default
=========================  ======================  ==========================================
samples of one solve       ``PLANAR_MAX_SAMPLES``  2 000 000
frames of one animation    ``PLANAR_MAX_FRAMES``   20 000
chain length (``chains``)  ``PLANAR_MAX_CHAIN``    8
memory estimate (MiB)      ``PLANAR_MAX_MEMORY``   2048
=========================  ======================  ==========================================

For example ``PLANAR_MAX_SAMPLES=50000000 planar motion big.toml -o big.csv``.
"""

from __future__ import annotations

import math
import os

from planar.errors import InputError, LimitError

__all__ = ["DEFAULTS", "check_count", "check_memory", "limit", "sample_count"]

#: name -> (environment variable, default)
DEFAULTS: dict[str, tuple[str, int]] = {
    "samples": ("PLANAR_MAX_SAMPLES", 2_000_000),
    "frames": ("PLANAR_MAX_FRAMES", 20_000),
    "chain": ("PLANAR_MAX_CHAIN", 8),
    "memory": ("PLANAR_MAX_MEMORY", 2048),
}


def limit(name: str) -> int:
    """The current value of limit ``name`` (the environment variable, else the default)."""
    var, default = DEFAULTS[name]
    text = os.environ.get(var)
    if text is None or not text.strip():
        return default
    try:
        value = int(float(text))
    except (ValueError, OverflowError):
        raise InputError(var, text, "a positive whole number (an environment variable raising a limit)") from None
    if value < 1:
        raise InputError(var, text, "a positive whole number (an environment variable raising a limit)")
    return value


def check_count(name: str, field: str, value: float, what: str, shown: object = None) -> int:
    """``value`` as an int, or :class:`LimitError` if it exceeds limit ``name`` (or is not finite).

    The message names ``field`` with ``shown`` (default ``value``): what the user wrote.
    """
    var, _ = DEFAULTS[name]
    cap = limit(name)
    if not math.isfinite(value) or value > cap:
        asked = "" if shown is None else f"; this asks for {value:.4g}"
        raise LimitError(
            field, value if shown is None else shown, f"at most {cap:,} {what}{asked} (the limit; raise it with {var}=N)"
        )
    return int(value)


def check_memory(field: str, value: object, n_bytes: float, what: str) -> None:
    """:class:`LimitError` if an estimated ``n_bytes`` exceed the memory limit (MiB)."""
    var, _ = DEFAULTS["memory"]
    cap = limit("memory")
    mib = n_bytes / 2**20
    if not math.isfinite(mib) or mib > cap:
        raise LimitError(
            field, value, f"{what} within {cap:,} MiB (it needs about {mib:,.0f} MiB; raise the limit with {var}=MIB)"
        )


def sample_count(
    samples_per_cycle: float, cycles: float, spc_field: str = "samples_per_cycle", cycles_field: str = "cycles"
) -> int:
    """Samples of ``cycles`` cycles at ``samples_per_cycle``, checked against the ``samples`` limit."""
    try:
        spc, cyc = float(samples_per_cycle), float(cycles)
    except (TypeError, ValueError):
        raise InputError(f"{spc_field}, {cycles_field}", (samples_per_cycle, cycles), "numbers") from None
    if not (math.isfinite(spc) and spc >= 1):
        raise InputError(spc_field, samples_per_cycle, "at least one sample per cycle")
    if not (math.isfinite(cyc) and cyc > 0):
        raise InputError(cycles_field, cycles, "a positive, finite number of cycles")
    n = spc * cyc
    return check_count("samples", f"{spc_field} x {cycles_field}", round(n) if math.isfinite(n) else n, "samples")
