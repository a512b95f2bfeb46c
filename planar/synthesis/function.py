"""Function generation by Freudenstein's equation: input/output angle pairs to a four-bar.

With input (crank) angle ``phi`` and output (rocker) angle ``psi``, both
radians counter-clockwise from the ground line (FourBar's ``theta`` and
``theta4``), a four-bar satisfies ``K1 cos psi - K2 cos phi + K3 = cos(phi -
psi)`` with ``K1 = d/a, K2 = d/c, K3 = (a^2 - b^2 + c^2 + d^2) / (2 a c)``
(Norton's form, as :func:`planar.linkages.freudenstein_angles`).  Linear in
``K1, K2, K3``: exact for 3 pairs, least squares (in the equation's residual)
for more.  The ground length ``d`` sets the scale.  Angles are measured from
the world x axis with the crank pivot at the origin; when ``K1`` and ``K2``
come out negative the rocker pivot is on the negative x axis (``d < 0``): the
four-bar is placed turned by pi (``ground_angle``), its own angles being the
pairs' minus pi.  The circuit is the one
whose solved output angles are closer to the pairs; the structural error (the
solved output angle minus the requested one) is reported.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError

__all__ = ["FunctionDesign", "freudenstein_fit"]

Array = NDArray[np.float64]


def _wrap(a: Array) -> Array:
    return (np.asarray(a) + np.pi) % (2 * np.pi) - np.pi


@dataclass
class FunctionDesign:
    ground: float
    crank: float
    coupler: float
    rocker: float
    circuit: str
    K: Array
    phi: Array
    psi: Array
    output_error: Array               # solved output angle - requested, radians
    grashof: str
    ground_angle: float = 0.0         # placement angle: 0, or pi when the rocker pivot is on the negative x axis

    @property
    def max_error(self) -> float:
        return float(np.max(np.abs(self.output_error)))

    def fourbar(self, **kw: Any):
        from ..linkages import FourBar

        return FourBar(self.ground, self.crank, self.coupler, self.rocker, coupler_point=(0.5 * self.coupler, 0.0),
                       circuit=self.circuit, placement=(0.0, 0.0, self.ground_angle), **kw)  # type: ignore[arg-type]

    def to_dict(self) -> dict[str, Any]:
        return {"type": "fourbar", "ground": self.ground, "crank": self.crank, "coupler": self.coupler,
                "rocker": self.rocker, "circuit": self.circuit, "ground_angle": self.ground_angle,
                "K": [float(k) for k in self.K],
                "grashof": self.grashof, "max_output_error_rad": self.max_error,
                "output_error_rad": [float(e) for e in self.output_error]}


def freudenstein_fit(phi: Array, psi: Array, ground: float = 1.0) -> FunctionDesign:
    """The four-bar whose output follows ``psi`` at inputs ``phi`` (radians; see the module)."""
    from ..linkages import freudenstein_angles, grashof_class

    phi = np.asarray(phi, float)
    psi = np.asarray(psi, float)
    if len(phi) < 3 or len(phi) != len(psi):
        raise InputError("pairs", len(phi), "3 or more (input, output) angle pairs")
    if not ground > 0:
        raise InputError("--ground", ground, "a positive ground length")
    M = np.column_stack([np.cos(psi), -np.cos(phi), np.ones_like(phi)])
    rhs = np.cos(phi - psi)
    if np.linalg.matrix_rank(M) < 3:
        raise InputError("pairs", [[float(a), float(b)] for a, b in zip(phi, psi)],
                         "pairs with 3 different input angles and 3 different output angles (the system is singular)")
    K = np.linalg.solve(M, rhs) if len(phi) == 3 else np.linalg.lstsq(M, rhs, rcond=None)[0]
    K1, K2, K3 = (float(k) for k in K)
    if K1 * K2 <= 0:
        raise InputError("pairs", f"K1 = {K1:.4g}, K2 = {K2:.4g}",
                         "pairs a four-bar can generate (K1 and K2 of one sign)")
    turn = 0.0 if K1 > 0 else np.pi      # rocker pivot on the negative x axis: the four-bar turned by pi
    d = float(ground)
    a, c = d / abs(K1), d / abs(K2)
    b2 = a * a + c * c + d * d - 2 * a * c * K3
    if b2 <= 0:
        raise InputError("pairs", f"coupler^2 = {b2:.4g}", "pairs that give a real coupler length")
    b = float(np.sqrt(b2))
    best: tuple[float, str, Array] | None = None
    for circuit in ("open", "crossed"):
        _, th4, ok = freudenstein_angles(a, b, c, d, phi - turn, circuit)
        err = np.where(ok, _wrap(th4 + turn - psi), np.inf)
        e = float(np.max(np.abs(err)))
        if best is None or e < best[0]:
            best = (e, circuit, err)
    assert best is not None
    return FunctionDesign(d, a, b, c, best[1], K, phi, psi, best[2], grashof_class(a, b, c, d), turn)
