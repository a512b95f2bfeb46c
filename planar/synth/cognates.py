"""Roberts cognates: another four-bar whose coupler point traces the same curve.

Write points as complex numbers, the input pivot ``A0``, the other ground pivot ``B0``, the input's pin ``A``, the
rocker's pin ``B`` and the coupler point ``P = A + lam (B - A)`` (``lam`` fixed in the coupler: the coupler point
``(u, v)`` over the coupler's length ``b``).  Then

    ``P = A0 + lam (B - A) + (A - A0)``

reads as another four-bar on the same input pivot (Cayley's diagram): its input link is ``lam (B - A)``, which
turns with the old coupler, its coupler carries the old input link ``A - A0`` to ``P``, and its other ground pivot
is ``C0 = A0 + lam (B0 - A0)`` (the ground triangle is similar to the coupler triangle: the Roberts-Chebyshev
theorem).  In lengths it is the old four-bar's ``(ground, input, coupler, rocker)`` scaled by ``|lam|`` with the
input and coupler exchanged, and the construction applied to it gives the old four-bar back.

Its use here: a Grashof double-rocker's coupler turns fully relative to the ground, so this cognate's input turns
fully (a crank-rocker tracing the double-rocker's arc); a crank-rocker found for an arc gives back, by the same
construction, a double-rocker when its coupler only rocks.  The rocking search
(:func:`planar.synth.arcs.search_arcs`) prefers such an input that rocks.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from planar.synth.kernel import coupler_points

__all__ = ["input_cognate"]

Array = NDArray[np.float64]


def input_cognate(row: Array, theta: Array, tol: float = 1e-9) -> tuple[Array, Array] | None:
    """The Roberts cognate of a four-bar (kernel row: the 9 parameters of
    :data:`planar.synth.kernel.PARAM_NAMES` and the circuit, +1 or -1) that shares its input pivot and whose input
    link turns with the old coupler (module docstring), and its input angles (rad from its own ground line) where
    the four-bar is at ``theta`` (rad, from its ground line).

    Returns ``(row, angles)`` with the cognate's circuit the one on which its coupler point meets the four-bar's at
    every angle of ``theta`` (within ``tol`` of their extent), or None when the four-bar does not assemble there,
    neither circuit does so, or the coupler point is on the input's pin (``lam = 0``: no cognate)."""
    r = np.asarray(row, float)
    th = np.asarray(theta, float)
    g, a, b, c, u, v, x0, y0, phi0 = (float(x) for x in r[:9])
    lam = complex(u, v) / b
    if lam == 0:
        return None
    x, y, ok = coupler_points(r[None, :9], th[None], r[9:10])
    if not ok.all():
        return None
    p = x[0] + 1j * y[0]
    pin = complex(x0, y0) + a * np.exp(1j * (th + phi0))  # A, the input's pin
    coupler = np.angle((p - pin) / lam)  # the world angle of B - A
    k = abs(lam)
    w = k * a / lam  # the coupler point from the cognate's input pin, x toward its other pin
    cog = np.array([k * g, k * b, k * a, k * c, w.real, w.imag, x0, y0, phi0 + float(np.angle(lam))])
    angles = np.mod(coupler - phi0, 2 * np.pi)  # its input's world angle, coupler + arg(lam), from its ground line
    scale = max(float(np.ptp(p.real)), float(np.ptp(p.imag)), 1e-300)
    for circuit in (1.0, -1.0):
        cx, cy, cok = coupler_points(cog[None], angles[None], np.array([circuit]))
        if cok.all() and float(np.max(np.abs(cx[0] + 1j * cy[0] - p))) <= tol * scale:
            return np.append(cog, circuit), angles
    return None
