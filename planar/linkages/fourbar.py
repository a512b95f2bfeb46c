"""The four-bar linkage: closed-form position, circuits, Grashof class, limits.

Conventions (issue #2): before placement the ground pivots are ``O2 = (0, 0)``
and ``O4 = (ground, 0)``; the crank angle ``theta`` is measured
counter-clockwise from the ground line; the crank pin is ``B``, the rocker pin
``C``.  The coupler's frame has its origin at ``B`` and its x axis toward
``C``; a coupler point is given in that frame.  Lengths: ``a`` crank, ``b``
coupler, ``c`` rocker, ``d`` ground (Norton's notation, as the course notes).

Circuit ``"open"``: ``C`` lies to the left of the directed diagonal
``B -> O4`` (the quadrilateral ``O2 B C O4`` does not cross itself for the usual
upward assembly); ``"crossed"``: to the right.  A Grashof crank keeps its
circuit through the whole revolution (the triangle ``B C O4`` never
degenerates), so a fixed side is branch continuity.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from planar.core.model import check_finite, check_positive, check_samples
from planar.errors import InputError
from planar.linkages.linkage import Link, Linkage
from planar.linkages.nodes import RRR, Crank, Fixed, Rigid

__all__ = ["FourBar", "freudenstein_angles", "grashof_class"]

Array = NDArray[np.float64]
Circuit = Literal["open", "crossed"]


def grashof_class(a: float, b: float, c: float, d: float, tol: float = 1e-12) -> str:
    """Grashof class of a four-bar with crank ``a``, coupler ``b``, rocker ``c``, ground ``d``.

    Returns one of ``"crank-rocker"``, ``"double-crank"``, ``"double-rocker"``
    (Grashof, coupler shortest), ``"rocker-crank"`` (Grashof, output link
    shortest: the output turns fully, the input rocks), ``"change-point"``
    (``s + l == p + q`` within ``tol`` of the sum) or ``"non-Grashof"``
    (triple rocker).
    """
    lengths = [check_positive(f"grashof_class({k})", v) for k, v in zip("abcd", (a, b, c, d), strict=True)]
    if isinstance(tol, (bool, str)) or not (isinstance(tol, (int, float)) and 0.0 <= tol < 1.0):
        raise InputError("grashof_class(tol)", tol, "a relative tolerance, 0 <= tol < 1")
    s, l = min(lengths), max(lengths)
    pq = sum(lengths) - s - l
    scale = sum(lengths)
    if abs((s + l) - pq) <= tol * scale:
        return "change-point"
    if s + l > pq:
        return "non-Grashof"
    shortest = int(np.argmin(lengths))
    return ["crank-rocker", "double-rocker", "rocker-crank", "double-crank"][shortest]


def freudenstein_angles(
    a: float, b: float, c: float, d: float, theta: ArrayLike, circuit: Circuit = "open"
) -> tuple[Array, Array, NDArray[np.bool_]]:
    """Coupler and rocker angles ``(theta3, theta4, valid)`` by the tangent half-angle method.

    Freudenstein's equation in ``t = tan(theta4 / 2)``: ``A t^2 + B t + C = 0``
    with ``K1 = d/a, K2 = d/c, K3 = (a^2 - b^2 + c^2 + d^2) / (2 a c)``,
    ``A = cos th - K1 - K2 cos th + K3``, ``B = -2 sin th``,
    ``C = K1 - (K2 + 1) cos th + K3`` (Norton, as the course notes assume);
    ``theta3`` likewise with ``K4 = d/b, K5 = (c^2 - d^2 - a^2 - b^2) / (2 a b)``.

    Stable roots: ``q = -(B + sign(B) sqrt(B^2 - 4AC)) / 2`` and the two roots
    ``q / A`` and ``C / q``; each becomes an angle as ``2 atan2(num, den)``, so
    ``A = 0`` (``theta = pi``) is no division by zero.  Open circuit is the
    root ``(-B - sqrt(disc)) / (2A)`` for theta4 and ``(-E - sqrt)/(2D)`` for
    theta3, verified against the circle-circle solution in the tests.
    """
    a, b, c, d = (check_positive(f"freudenstein_angles({k})", v) for k, v in zip("abcd", (a, b, c, d), strict=True))
    if not isinstance(circuit, str) or circuit not in ("open", "crossed"):
        raise InputError("freudenstein_angles(circuit)", circuit, "'open' or 'crossed'")
    th = check_finite("freudenstein_angles(theta)", theta)
    if th.ndim > 1:
        raise InputError("freudenstein_angles(theta)", f"an array of shape {th.shape}", "a number or a 1-D array of angles")
    # the angles depend on the ratios only: lengths in units of the longest, so 1e-300 or 1e300 neither
    # underflows nor overflows the squares below; ratios past 1e100 (no mechanism) are refused
    s = max(a, b, c, d)
    small = min(zip((a, b, c, d), "abcd"))
    if small[0] < 1e-100 * s:
        raise InputError(f"freudenstein_angles({small[1]})", small[0], f"a length within 1e100 of the longest ({s:g})")
    a, b, c, d = a / s, b / s, c / s, d / s
    ct, st = np.cos(th), np.sin(th)
    K1, K2, K3 = d / a, d / c, (a * a - b * b + c * c + d * d) / (2 * a * c)
    K4, K5 = d / b, (c * c - d * d - a * a - b * b) / (2 * a * b)
    sign = -1.0 if circuit == "open" else 1.0

    def half_angle(A: Array, B: Array, C: Array) -> tuple[Array, NDArray[np.bool_]]:
        disc = B * B - 4 * A * C
        scale = np.maximum.reduce([np.abs(B * B), np.abs(4 * A * C), np.full_like(B, 1e-300)])
        valid = disc >= -1e-12 * scale
        sq = np.sqrt(np.maximum(disc, 0.0))
        sB = np.where(B >= 0, 1.0, -1.0)
        q = -0.5 * (B + sB * sq)
        # root_minus = (-B - sq) / 2A ; root_plus = (-B + sq) / 2A
        # when B >= 0, q = (-B - sq)/2 so q/A is root_minus, C/q root_plus; else swapped
        want_q_over_a = (sB > 0) == (sign < 0)
        num = np.where(want_q_over_a, q, C)
        den = np.where(want_q_over_a, A, q)
        return 2.0 * np.arctan2(num, den), valid

    th4, v4 = half_angle(ct - K1 - K2 * ct + K3, -2.0 * st, K1 - (K2 + 1.0) * ct + K3)
    th3, v3 = half_angle(ct - K1 + K4 * ct + K5, -2.0 * st, K1 + (K4 - 1.0) * ct + K5)
    return th3, th4, v3 & v4


@dataclass(frozen=True)
class _Dims:
    a: float
    b: float
    c: float
    d: float


#: the keyword options a four-bar passes on to :class:`Linkage` (the driver's and the drawing's)
_LINKAGE_OPTIONS = frozenset({"rate", "phase", "amplitude", "centre", "width", "pin_diameter"})


class FourBar(Linkage):
    """A four-bar linkage driven by its crank (part ``crank``).

    Parts: ``ground``, ``crank`` (O2 -> B), ``coupler`` (B -> C, plus the coupler
    point), ``rocker`` (O4 -> C).  The coupler point is the named point
    ``coupler_point``.  ``placement`` ``(x, y, angle)`` places the linkage in
    the world frame.  Driving the input past a toggle position gives invalid
    samples naming joint ``C``.
    """

    def __init__(
        self,
        ground: float,
        crank: float,
        coupler: float,
        rocker: float,
        coupler_point: Sequence[float] = (0.5, 0.0),
        circuit: Circuit = "open",
        placement: Sequence[float] = (0.0, 0.0, 0.0),
        name: str = "fourbar",
        **kw: Any,
    ) -> None:
        unknown = sorted(set(kw) - _LINKAGE_OPTIONS)
        if unknown:
            raise InputError(f"{name}: {unknown[0]}", kw[unknown[0]], f"one of the options {sorted(_LINKAGE_OPTIONS)}")
        a = check_positive(f"{name}.crank", crank)
        b = check_positive(f"{name}.coupler", coupler)
        c = check_positive(f"{name}.rocker", rocker)
        d = check_positive(f"{name}.ground", ground)
        if not isinstance(circuit, str) or circuit not in ("open", "crossed"):
            raise InputError(f"{name}.circuit", circuit, "'open' or 'crossed'")
        self.dims = _Dims(a, b, c, d)
        self.circuit: Circuit = circuit
        self.branch = 1 if circuit == "open" else -1
        cp = np.asarray(coupler_point, dtype=object)
        if cp.shape != (2,) or any(isinstance(v, bool) for v in cp):
            raise InputError(f"{name}.coupler_point", coupler_point, "a point (x, y) in the coupler's frame")
        cpf = check_finite(f"{name}.coupler_point", coupler_point)
        self.coupler_point = (float(cpf[0]), float(cpf[1]))
        if max(a, b, c, d) >= (a + b + c + d) - max(a, b, c, d):
            raise InputError(
                f"{name}.links",
                (a, b, c, d),
                "the longest link shorter than the sum of the other three (else it cannot close)",
            )
        nodes = [
            Fixed("O2", (0.0, 0.0)),
            Fixed("O4", (d, 0.0)),
            Crank("B", "O2", a),
            RRR("C", "B", b, "O4", c, self.branch),
            Rigid("P", "B", "C", self.coupler_point),
        ]
        links = [Link("crank", ("O2", "B")), Link("coupler", ("B", "C", "P")), Link("rocker", ("O4", "C"))]
        # the circuit is declared with the crank at pi/2 and carried from there by continuity, so a
        # change-point linkage is the same assembly whatever sample its motion starts from
        self.branch_reference = np.pi / 2
        super().__init__(name, nodes, links, points={"coupler_point": "P"}, placement=placement, **kw)

    def _path(self, q: NDArray[np.float64]) -> NDArray[np.bool_]:
        """Only a change-point four-bar has singular positions its motion passes through (the two circuits
        meet there), so only its circuit is carried by continuity; any other keeps its declared circuit at
        every sample, however coarse the sampling (a crossed crank-rocker sampled 4 or 7 times a turn was
        carried onto the open circuit by an extrapolation that coarse samples cannot support)."""
        if not self._carries_branches():
            return np.zeros(np.shape(q), dtype=bool)
        return super()._path(q)

    def _carries_branches(self) -> bool:
        """Only a change-point four-bar carries its circuit (see :meth:`_path`); kept with the dimensions it was
        found for, as every solve asks."""
        known = self.__dict__.get("_change_point_of")
        if known is None or known[0] is not self.dims:
            known = (self.dims, self.grashof == "change-point")
            self.__dict__["_change_point_of"] = known
        return bool(known[1])

    # -- classification and limits -----------------------------------------
    @property
    def grashof(self) -> str:
        """Grashof class (see :func:`grashof_class`)."""
        g = self.dims
        return grashof_class(g.a, g.b, g.c, g.d)

    def input_range(self) -> list[tuple[float, float]]:
        """Intervals of crank angle (radians, ascending) where the linkage assembles.

        ``[(0, 2 pi)]`` for a crank that turns fully.  Otherwise the ends are
        the toggle (limit) angles where coupler and rocker fall into line:
        ``|B - O4|^2 = a^2 + d^2 - 2 a d cos(theta) = (b +/- c)^2``.
        """
        a, b, c, d = self._unit_lengths()
        lo_c = (a**2 + d**2 - (b - c) ** 2) / (2 * a * d)
        hi_c = (a**2 + d**2 - (b + c) ** 2) / (2 * a * d)
        lo = float(np.arccos(np.clip(lo_c, -1, 1)))  # |B-O4| >= |b - c| for theta >= lo
        hi = float(np.arccos(np.clip(hi_c, -1, 1)))  # |B-O4| <= b + c for theta <= hi
        if lo > hi:
            return []
        if lo == 0.0 and hi == np.pi:
            return [(0.0, 2 * np.pi)]
        if lo == 0.0:
            return [(-hi, hi)]
        if hi == np.pi:
            return [(lo, 2 * np.pi - lo)]
        return [(lo, hi), (2 * np.pi - hi, 2 * np.pi - lo)]

    def toggle_angles(self) -> Array:
        """Crank angles (radians) at the limits of its motion; empty for a full crank."""
        ends = [e for iv in self.input_range() for e in iv]
        if ends == [0.0, 2 * np.pi]:
            return np.array([])
        return np.array(sorted({float(np.mod(e, 2 * np.pi)) for e in ends}))

    def angles(self, theta: ArrayLike) -> tuple[Array, Array, NDArray[np.bool_]]:
        """``(theta3, theta4, valid)``: coupler and rocker angles by the tangent half-angle method."""
        g = self.dims
        return freudenstein_angles(g.a, g.b, g.c, g.d, theta, self.circuit)

    def transmission_angle(self, theta: ArrayLike) -> Array:
        """Transmission angle (radians, in ``[0, pi]``) between coupler and rocker at ``C``."""
        a, b, c, d = self._unit_lengths()
        th = check_finite(f"{self.name}.transmission_angle(theta)", theta)
        bo2 = a**2 + d**2 - 2 * a * d * np.cos(th)
        return np.arccos(np.clip((b**2 + c**2 - bo2) / (2 * b * c), -1.0, 1.0))

    def _unit_lengths(self) -> tuple[float, float, float, float]:
        """Crank, coupler, rocker and ground lengths times a power of two that brings the longest near 1.

        Exact (a power of two changes only the exponent), so the angles above are the same bits at any
        scale from 1e-300 to 1e300, where their squares would overflow or underflow float64.
        """
        g = self.dims
        k = math.ldexp(1.0, -math.frexp(max(g.a, g.b, g.c, g.d))[1])
        return g.a * k, g.b * k, g.c * k, g.d * k

    def coupler_curve(self, theta: ArrayLike) -> tuple[Array, NDArray[np.bool_]]:
        """World coupler-point curve ``(N, 2)`` and validity for crank angles ``theta``."""
        m = self.solve(check_samples(f"{self.name}.coupler_curve(theta)", theta))
        return m.points["coupler_point"], m.valid
