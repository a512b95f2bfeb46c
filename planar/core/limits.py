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
import numbers
import os
from collections.abc import Iterable
from typing import Any

from planar.errors import InputError, LimitError

__all__ = [
    "DEFAULTS",
    "RESOLUTION",
    "SIZE_RANGE",
    "check_angle",
    "check_coordinates",
    "check_count",
    "check_memory",
    "check_resolution",
    "check_scale",
    "limit",
    "motion_bytes",
    "pilot_bytes",
    "resident_bytes",
    "resolution_terms",
    "sample_count",
    "units_within",
]

#: name -> (environment variable, default)
DEFAULTS: dict[str, tuple[str, int]] = {
    "samples": ("PLANAR_MAX_SAMPLES", 2_000_000),
    "frames": ("PLANAR_MAX_FRAMES", 20_000),
    "chain": ("PLANAR_MAX_CHAIN", 8),
    "memory": ("PLANAR_MAX_MEMORY", 2048),
}


def limit(name: str) -> int:
    """The current value of limit ``name`` (the environment variable, else the default)."""
    if not isinstance(name, str) or name not in DEFAULTS:
        raise InputError("limit", name, "one of " + ", ".join(DEFAULTS))
    var, default = DEFAULTS[name]
    text = os.environ.get(var)
    if text is None or not text.strip():
        return default
    try:
        number = float(text)
    except ValueError:
        number = math.nan
    if not (math.isfinite(number) and number.is_integer() and number >= 1):  # 1.5 is refused, not cut to 1
        raise InputError(var, text, "a positive whole number (an environment variable raising a limit)")
    return int(number)


def check_count(name: str, field: str, value: float, what: str, shown: object = None) -> int:
    """``value`` as an int, or :class:`LimitError` if it exceeds limit ``name`` (or is not finite).

    The message names ``field`` with ``shown`` (default ``value``): what the user wrote.
    """
    cap = limit(name)
    var, _ = DEFAULTS[name]
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise InputError(field, value if shown is None else shown, f"a number of {what}")
    if not math.isfinite(value) or value > cap:
        asked = "" if shown is None else f"; this asks for {value:.4g}"
        raise LimitError(
            field, value if shown is None else shown, f"at most {cap:,} {what}{asked} (the limit; raise it with {var}=N)"
        )
    return int(value)


def check_memory(field: str, value: object, n_bytes: float, what: str, fits: str | None = None) -> None:
    """:class:`LimitError` if an estimated ``n_bytes`` exceed the memory limit (MiB).

    ``fits``: what would fit, named in the message (e.g. ``"1,234 samples"``, from :func:`units_within`).
    """
    var, _ = DEFAULTS["memory"]
    cap = limit("memory")
    if isinstance(n_bytes, bool) or not isinstance(n_bytes, numbers.Real):
        raise InputError(field, value, f"{what} of a size in bytes (a number)")
    mib = n_bytes / 2**20
    if not math.isfinite(mib) or mib > cap:
        room = f"; at most {fits} fit" if fits else ""
        raise LimitError(
            field,
            value,
            f"{what} within {cap:,} MiB (it needs about {mib:,.0f} MiB{room}; raise the limit with {var}=MIB)",
        )


#: share of the memory limit :func:`units_within` keeps back (at least :data:`MARGIN_MIB`), so that the count a
#: refusal names still fits when the user runs it: resident memory drifts between two processes (48 kB measured
#: in CI); kept small, as the count is sensitive to it where little room is left (a simulated run at 256 MiB
#: named 6,622 samples with none, 5,857 with 1 MiB, 3,359 with 5 MiB)
MARGIN_SHARE = 0.002
MARGIN_MIB = 1.0


def units_within(fixed_bytes: float, unit_bytes: float) -> int:
    """How many units of ``unit_bytes`` each fit in the memory limit beside ``fixed_bytes`` (0 if none).

    A margin of :data:`MARGIN_SHARE` of the limit (at least :data:`MARGIN_MIB` MiB) is kept back, so that a
    run of the count named passes the same check in a process whose resident memory is a little larger.
    """
    cap = limit("memory") * 2.0**20
    room = cap - max(MARGIN_SHARE * cap, MARGIN_MIB * 2.0**20) - fixed_bytes
    return max(0, int(room // unit_bytes)) if unit_bytes > 0 and math.isfinite(room) else 0


def motion_bytes(parts: int, points: int, n: float) -> float:
    """Bytes a solve of ``n`` samples holds at its peak: poses (x, y, angle) of every part, points (x, y),
    driver, time and validity, and the solver's working copies (4 of each; measured 880 bytes a sample for
    the 8-part Jansen leg, estimated 960)."""
    return 8.0 * (3 * parts + 2 * points + 4) * 4 * max(n, 2)


#: a solve of more samples than this measures its memory on a pilot of :data:`PILOT` samples first
PILOT_ABOVE = 200_000
PILOT = 32_768


def resident_bytes() -> float:
    """This process's resident memory now (bytes; 0 where ``/proc`` is not there to tell)."""
    try:
        with open("/proc/self/statm") as fh:
            return float(fh.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")
    except (OSError, ValueError, IndexError):
        return 0.0


def pilot_bytes(solve: Any, n: int) -> float | None:
    """Bytes a solve of ``n`` samples will hold at its peak, from the peak of a :data:`PILOT`-sample solve
    (``solve(k)``: run once untraced to warm the kernels, then traced by :mod:`tracemalloc`) scaled to
    ``n``; ``None`` when tracemalloc is already in use (the caller then keeps its static estimate).
    Measures what each kind really allocates (a cam's profile, a toy's stages), where
    :func:`motion_bytes` only counts the motion's numbers."""
    import tracemalloc

    if tracemalloc.is_tracing():
        return None
    from planar.core.buffers import release

    solve(PILOT)  # untraced first: loading or compiling the kernels is no cost of the samples
    release()  # and no recycled block from it: the traced pilot allocates what a first solve does
    tracemalloc.start()
    try:
        solve(PILOT)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    return peak / PILOT * n


#: the fewest samples of one cycle (a scene's ``samples_per_cycle``, ``catalog --samples``, ``run``)
MIN_SAMPLES_PER_CYCLE = 4


def sample_count(
    samples_per_cycle: float, cycles: float, spc_field: str = "samples_per_cycle", cycles_field: str = "cycles"
) -> int:
    """Samples of ``cycles`` cycles at ``samples_per_cycle``, checked against the ``samples`` limit."""
    for name, v in ((spc_field, samples_per_cycle), (cycles_field, cycles)):
        if isinstance(v, (str, bytes, bool)) or not hasattr(v, "__float__"):
            raise InputError(name, v, "a number (not text or a truth value)")
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


#: the smallest and largest characteristic length (model units) whose squares, products and sums of
#: squares float64 holds without overflow or underflow (a solve multiplies up to four lengths; synthesis
#: measured the same relative error from 1e-90 to 1e75, and at 1e90 its check in the file's units overflows)
SIZE_RANGE = (1e-60, 1e60)
#: how fine float64 must resolve a coordinate, as a fraction of the mechanism's smallest length (the
#: solver's validity tolerance is 1e-9 of the size: a coarser grid makes every check meaningless)
RESOLUTION = 1e-9


#: fabrication's bounds (mm), one place for the scene files' ``[fabrication]`` table and
#: :class:`planar.fabrication.FabSettings`: the largest sheet side the geometry is computed for, a small
#: gearmotor's dimensions (an N20's, or a 37 mm gearmotor's with an encoder, are well within), its body's
#: length, and the largest kerf or running clearance
MAX_SHEET_MM = 100_000.0
MAX_MOTOR_MM = 100.0
MAX_MOTOR_BODY_MM = 250.0
MAX_KERF_MM = 2.0
#: the largest pin diameter, sheet thickness, wall, part or label size (mm) a ``[fabrication]`` table may ask
#: for: a 100 mm pin or wall is past any laser cutter's stock; at 1e300 the holes swallowed the parts and
#: the refusal named neither the field nor the value
MAX_HARDWARE_MM = 100.0


#: the largest angle (rad, about 159 000 turns) a phase, amplitude or a clock's turns may reach: float64
#: spaces its numbers 1.2e-10 apart there, finer than :data:`RESOLUTION`; at 1e300 a phase is noise
MAX_ANGLE = 1e6


def check_angle(field: str, value: float, scale: float = 1.0) -> None:
    """:class:`InputError` if the angle ``value * scale`` (rad) is beyond :data:`MAX_ANGLE` (``value`` is shown)."""
    if not abs(float(value) * scale) <= MAX_ANGLE:
        raise InputError(
            field,
            value,
            f"a value reaching at most {MAX_ANGLE:g} rad (about {MAX_ANGLE / (2 * math.pi):.0f} turns): beyond, float64 "
            f"resolves an angle coarser than {RESOLUTION:g} rad",
        )


def check_scale(where: str, mech: object, size_range: bool = True) -> None:
    """:class:`InputError` if ``mech``'s numbers are beyond what float64 holds faithfully.

    Refused: a size (:attr:`Mechanism.size`) outside :data:`SIZE_RANGE`, and a
    placement or part coordinate so far from the origin that float64's spacing
    there exceeds :data:`RESOLUTION` times the mechanism's smallest length (its
    smallest pin or hull radius, at most its size): at y = 1e16 the nearest
    floats are 2 apart, so a four-bar of 4-unit links is computed into nonsense.
    ``where`` names the file or mechanism in the message; ``size_range=False`` checks the placement
    only (from Python a mechanism of any size solves, scaled).
    """
    parts = getattr(mech, "parts", ())
    with _quiet_numpy():
        import numpy as np

        size = float(getattr(mech, "size", 1.0))
        hulls = [np.asarray(p.hull, dtype=float).reshape(-1, 3) for p in parts if getattr(p, "hull", None)]
        h = np.concatenate(hulls) if hulls else np.zeros((0, 3))
        place = np.asarray(getattr(mech, "placement", (0.0, 0.0, 0.0)), dtype=float).ravel()[:2]
        extent = float(np.abs(place).max(initial=0.0)) + float(np.abs(h[:, :2]).max(initial=0.0))
        smallest = _smallest_length(mech)
    if size_range and not (math.isfinite(size) and SIZE_RANGE[0] <= size <= SIZE_RANGE[1]):
        raise InputError(
            f"{where}: mechanism size",
            size,
            f"a size (largest part diameter, model units) from {SIZE_RANGE[0]:g} to {SIZE_RANGE[1]:g}: "
            "beyond, its squares leave what float64 holds (choose another model unit, e.g. [fabrication] unit_mm)",
        )
    if not math.isfinite(extent) or float(np.spacing(extent)) > RESOLUTION * smallest:
        far = smallest * RESOLUTION / float(np.finfo(float).eps)
        raise InputError(
            f"{where}: placement and coordinates",
            f"{extent:.6g} from the origin",
            f"coordinates within about {far:.3g} model units of the origin: float64 resolves "
            f"{float(np.spacing(extent)) if math.isfinite(extent) else math.inf:.3g} there, coarser than "
            f"{RESOLUTION:g} of the mechanism's smallest length {smallest:.6g} (move it nearer the origin)",
        )


def _smallest_length(mech: object) -> float:
    """The mechanism's smallest length (model units): its smallest pin or hull radius, at most its size."""
    import numpy as np

    size = float(getattr(mech, "size", 1.0))
    hulls = [np.asarray(p.hull, dtype=float).reshape(-1, 3) for p in getattr(mech, "parts", ()) if getattr(p, "hull", None)]
    radii = np.concatenate(hulls)[:, 2] if hulls else np.zeros(0)
    radii = radii[radii > 0]
    return min(size, float(radii.min())) if radii.size else size


def check_coordinates(field: str, points: object, mech: object, shown: object = None) -> None:
    """:class:`InputError` naming ``field`` if a point of ``points`` (model units, ``[[x, y], ...]``) lies so far
    from the origin that float64 resolves it coarser than :data:`RESOLUTION` of ``mech``'s smallest length (the
    rule :func:`check_scale` applies to the placement: a standoff or a polygon vertex at 1e300 is refused, not cut
    into nonsense).  ``mech``: the mechanism, or its smallest length (model units) when it is not built yet (a
    wind-up mechanism's parameters).  ``shown``: the value as the user wrote it (default ``points``)."""
    with _quiet_numpy():
        import numpy as np

        pts = np.asarray(points, dtype=float).reshape(-1)
        extent = float(np.abs(pts).max(initial=0.0))
        smallest = float(mech) if isinstance(mech, (int, float)) else _smallest_length(mech)
        if math.isfinite(extent) and float(np.spacing(extent)) <= RESOLUTION * smallest:
            return
        far = smallest * RESOLUTION / float(np.finfo(float).eps)
    raise InputError(
        field,
        points if shown is None else shown,
        f"coordinates within about {far:.3g} model units of the origin (float64 resolves coarser there than "
        f"{RESOLUTION:g} of the mechanism's smallest length {smallest:.6g})",
    )


#: one number a resolution check weighs: ``(field, value as given, magnitude, is_length)``; a length (> 0) also sets
#: the smallest length the others are resolved against, a coordinate or signed offset only reaches
Term = tuple[str, object, float, bool]


def resolution_terms(obj: object, where: str) -> list[Term]:
    """The lengths and coordinates of one kind (a node, a joint, a feature) for :func:`check_resolution`.

    Each kind states them as class attributes: ``length_fields`` (lengths, model units: a radius, a pin's
    diameter, a slot's width) and ``point_fields`` (points ``(x, y)`` or signed offsets, model units); a field
    holding ``None`` is skipped.  The field is named ``where.FIELD``.
    """
    out: list[Term] = []
    for names, is_length in ((getattr(type(obj), "length_fields", ()), True), (getattr(type(obj), "point_fields", ()), False)):
        for name in names:
            v = getattr(obj, name, None)
            if v is None:
                continue
            flat = v if isinstance(v, (tuple, list)) else (v,)
            try:
                mag = max((abs(float(x)) for x in flat), default=0.0)
            except (TypeError, ValueError):  # not numbers: the kind's own checks name it
                continue
            out.append((f"{where}.{name}", v, mag, is_length))
    return out


def check_resolution(terms: Iterable[Term], what: str = "mechanism") -> None:
    """:class:`InputError` naming the term whose magnitude float64 resolves coarser than :data:`RESOLUTION` of the
    smallest length among ``terms`` (the rule :func:`check_scale` applies to a scene, for an assembly built in
    Python).

    A big but consistent linkage passes (every length 1e6: the smallest is 1e6 too); a coordinate or a length
    so far beyond the smallest length that float64 cannot tell positions apart on that length's scale is
    refused: ``RRR("B", "A", 1e300, "D", 1.0)``, ``Fixed("O", (1e300, 0))`` in a linkage of 1-unit links, a
    part's hull circle of radius 1 at x = 1e300.  Terms holding no positive length are not checked (nothing
    to resolve against).  ``what`` names the assembly in the message ("linkage", "part", ...).
    """
    terms = list(terms)
    lengths = [(t[2], t[0]) for t in terms if t[3] and t[2] > 0.0 and math.isfinite(t[2])]
    if not lengths or not terms:
        return
    smallest, small_field = min(lengths)
    field, value, mag, _ = max(terms, key=lambda t: t[2])
    spacing = math.ulp(mag) if math.isfinite(mag) else math.inf
    if spacing <= RESOLUTION * smallest:
        return
    far = math.ldexp(1.0, math.frexp(RESOLUTION * smallest)[1] + 52)  # the largest power of two resolved that finely
    raise InputError(
        field,
        value,
        f"a value within about {far:.3g} model units of zero: float64 resolves {spacing:.3g} there, coarser than "
        f"{RESOLUTION:g} of the {what}'s smallest length {smallest:.6g} ({small_field}); scale every length "
        "together (a big mechanism is fine) or move it nearer the origin",
    )


def _quiet_numpy() -> Any:
    """numpy's error state with every floating-point warning off (numpy is imported only when used)."""
    import numpy as np

    return np.errstate(all="ignore")
