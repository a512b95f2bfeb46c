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

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from planar.errors import InputError
from planar.synth.designs import TOGGLE_FLOOR_DEG, Checked, FourBarLinks

__all__ = ["FunctionDesign", "check_function", "freudenstein_fit", "synthesise_function"]

Array = NDArray[np.float64]
#: a closed-form design this close (rad) at every pair is kept without a search
EXACT = 1e-9


def _wrap(a: Array) -> Array:
    return (np.asarray(a) + np.pi) % (2 * np.pi) - np.pi


def spans(phi: Array, psi: Array) -> tuple[float, float]:
    """Input and output spans (rad): the inputs' as given (the crank turns from the smallest to the largest),
    the outputs' unwrapped in the inputs' order (a step between neighbours taken as less than pi, as
    :func:`check_function` compares them)."""
    phi, psi = np.asarray(phi, float), np.asarray(psi, float)
    return float(np.ptp(phi)), float(np.ptp(np.unwrap(psi[np.argsort(phi)])))


@dataclass
class FunctionDesign(Checked, FourBarLinks):
    ground: float
    crank: float
    coupler: float
    rocker: float
    circuit: str
    K: Array
    phi: Array
    psi: Array
    output_error: Array  # solved output angle - requested, radians
    grashof: str
    ground_angle: float = 0.0  # placement angle: 0, or pi when the rocker pivot is on the negative x axis
    input_offset: float = 0.0  # crank angle from the ground line = input + input_offset (rad)
    output_offset: float = 0.0  # rocker angle from the ground line = output + output_offset (rad)
    method: str = "closed form"  # "closed form" (Freudenstein) or "search" (see .function_search)
    checks: dict[str, Any] = field(default_factory=dict)
    note: str = ""  # why Freudenstein's closed form was not the design (search only)

    @property
    def max_error(self) -> float:
        return float(np.max(np.abs(self.output_error)))

    def _coupler_and_placement(self) -> tuple[tuple[float, float], tuple[float, float, float]]:
        return (0.5 * self.coupler, 0.0), (0.0, 0.0, self.ground_angle)

    def to_dict(self) -> dict[str, Any]:
        return {
            **self.lengths_dict(),
            "circuit": self.circuit,
            "ground_angle": self.ground_angle,
            "input_offset_rad": self.input_offset,
            "output_offset_rad": self.output_offset,
            "method": self.method,
            "K": [float(k) for k in self.K],
            "grashof": self.grashof,
            "max_output_error_rad": self.max_error,
            "output_error_rad": [float(e) for e in self.output_error],
            "checks": self.checks,
            **({"note": self.note} if self.note else {}),
        }


def _pairs(phi: Array, psi: Array, ground: float) -> tuple[Array, Array]:
    """The (input, output) angles as float arrays, refused unless 3 or more pairs with a positive ground."""
    from planar.core.limits import SIZE_RANGE
    from planar.core.model import check_finite, check_positive

    phi = check_finite("phi", phi).ravel()
    psi = check_finite("psi", psi).ravel()
    if len(phi) != len(psi):
        raise InputError("psi", f"{len(psi)} output angles", f"one output angle per input angle (phi has {len(phi)})")
    if len(phi) < 3:
        raise InputError("pairs", len(phi), "3 or more (input, output) angle pairs")
    if not SIZE_RANGE[0] <= check_positive("ground", ground) <= SIZE_RANGE[1]:
        raise InputError("ground", ground, f"a ground length from {SIZE_RANGE[0]:g} to {SIZE_RANGE[1]:g} (model units)")
    return phi, psi


def freudenstein_fit(phi: Array, psi: Array, ground: float = 1.0) -> FunctionDesign:
    """The four-bar whose output follows ``psi`` at inputs ``phi`` (radians; see the module)."""
    from planar.linkages import freudenstein_angles, grashof_class

    phi, psi = _pairs(phi, psi, ground)
    M = np.column_stack([np.cos(psi), -np.cos(phi), np.ones_like(phi)])
    rhs = np.cos(phi - psi)
    if np.linalg.matrix_rank(M) < 3:
        raise InputError(
            "pairs",
            [[float(a), float(b)] for a, b in zip(phi, psi)],
            "pairs with 3 different input angles and 3 different output angles (the system is singular)",
        )
    K = np.linalg.solve(M, rhs) if len(phi) == 3 else np.linalg.lstsq(M, rhs, rcond=None)[0]
    K1, K2, K3 = (float(k) for k in K)
    if K1 * K2 <= 0:
        raise InputError("pairs", f"K1 = {K1:.4g}, K2 = {K2:.4g}", "pairs a four-bar can generate (K1 and K2 of one sign)")
    turn = 0.0 if K1 > 0 else np.pi  # rocker pivot on the negative x axis: the four-bar turned by pi
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
    off = 0.0 - turn  # never -0.0
    return FunctionDesign(d, a, b, c, best[1], K, phi, psi, best[2], grashof_class(a, b, c, d), turn, off, off)


def _normalised(d: FunctionDesign) -> Array:
    g = d.ground
    return np.array([d.crank / g, d.coupler / g, d.rocker / g, d.input_offset, d.output_offset])


def _design(x: Array, circuit: int, phi: Array, psi: Array, ground: float, free: bool) -> FunctionDesign:
    """A search candidate (unit ground) as a design scaled to ``ground``; fixed offsets place it turned by ``-A``."""
    from planar.linkages import grashof_class

    a, b, c, A, B = (float(v) for v in x)
    K = np.array([1.0 / a, 1.0 / c, (a * a - b * b + c * c + 1.0) / (2.0 * a * c)])
    g = float(ground)
    turn = 0.0 if free else float(-A) + 0.0  # + 0.0: never -0.0
    return FunctionDesign(
        g,
        a * g,
        b * g,
        c * g,
        "open" if circuit > 0 else "crossed",
        K,
        phi,
        psi,
        np.full(len(phi), np.nan),
        grashof_class(a, b, c, 1.0),
        turn,
        A + 0.0,
        B + 0.0,
        "search",
    )


def check_function(d: FunctionDesign, cons: Any, tolerance: float, dense: int = 361) -> None:
    """Fill ``d.checks`` and ``d.output_error`` from planar's own solve of the four-bar.

    The crank is driven over the inputs' arc (``dense`` samples and the pairs'
    inputs); the rocker's world angle, unwrapped along that motion, is compared
    with the requested outputs (plus the offset; unwrapped in the inputs' order,
    so a step between neighbours is taken as less than pi) relative to the
    smallest input, so an output that went round a whole turn between two
    pairs counts as a turn of error.
    """
    fb = d.fourbar()
    th = d.phi + d.input_offset  # crank angles from the ground line
    t = np.unique(np.concatenate([np.linspace(th.min(), th.max(), dense), th]))
    m = fb.solve(t)
    rocker = np.unwrap(m.poses["rocker"][:, 2])
    at = np.searchsorted(t, th)
    want = d.psi + d.output_offset + d.ground_angle  # requested rocker world angles,
    order = np.argsort(th)  # unwrapped in the crank's order (steps < pi)
    want[order] = np.unwrap(want[order])
    i0 = int(np.argmin(th))
    e0 = float(_wrap(rocker[at[i0]] - want[i0]))
    d.output_error = (rocker[at] - rocker[at[i0]]) - (want - want[i0]) + e0
    mu = fb.transmission_angle(t)
    margin = float(np.minimum(mu, np.pi - mu).min())
    if cons.full_turn:  # the linkage passes the whole turn: its margin too
        mu = fb.transmission_angle(np.linspace(0.0, 2 * np.pi, 721))
        margin_turn = float(np.minimum(mu, np.pi - mu).min())
    lengths = np.array([d.ground, d.crank, d.coupler, d.rocker])
    ratio = float(lengths.max() / lengths.min())
    limit = max(float(cons.min_transmission), math.radians(TOGGLE_FLOOR_DEG))  # never nearer a toggle than the floor
    full = fb.input_range() == [(0.0, 2 * np.pi)]
    d.checks = {
        "ok_assembles_over_arc": bool(m.valid.all()),
        "ok_output_error": bool(np.isfinite(d.max_error) and d.max_error <= tolerance),
        "ok_link_ratio": ratio <= cons.max_ratio * (1 + 1e-9),
        "ok_transmission": bool(min(margin, margin_turn if cons.full_turn else margin) >= limit - 1e-9),
        "input_arc_deg": float(np.degrees(th.max() - th.min())),
        "min_transmission_deg": float(np.degrees(margin)),
        "transmission_limit_deg": float(np.degrees(limit)),
        "link_ratio": ratio,
        "crank_turns_fully": bool(full),
    }
    if cons.full_turn:  # only when asked (--full-turn)
        d.checks["ok_full_turn"] = bool(full)
        d.checks["min_transmission_full_turn_deg"] = float(np.degrees(margin_turn))


def synthesise_function(
    phi: Array, psi: Array, ground: float = 1.0, cons: Any = None, tolerance: float = 0.01
) -> tuple[FunctionDesign | None, str]:
    """The four-bar that follows ``psi`` at ``phi`` on one circuit, checked; or ``None`` and why none is valid.

    Freudenstein's closed form is kept when it is valid and exact (``EXACT``)
    or no less accurate than the search's best (:mod:`.function_search`); ``cons`` is a
    :class:`.function_search.FunctionConstraints` (default: fixed offsets,
    link ratio 10).
    """
    from planar.core.fields import check_positive
    from planar.synth.function_search import FunctionConstraints, output_errors, search_function, violations

    if cons is not None and not isinstance(cons, FunctionConstraints):
        raise InputError("cons", cons, "a FunctionConstraints (or None)")
    tolerance = check_positive("tolerance", tolerance, "tolerance (rad)")
    cons = FunctionConstraints() if cons is None else cons
    phi, psi = _pairs(phi, psi, ground)
    if len(np.unique(phi)) < len(phi):
        raise InputError("phi", [float(v) for v in phi], "a different input angle in every pair")
    if len(np.unique(psi)) < 2:
        raise InputError("psi", [float(v) for v in psi], "output angles that change")
    for name, span in zip(("phi", "psi"), spans(phi, psi)):
        if span > 2 * np.pi:
            raise InputError(name, f"a span of {span:.6g} rad", "a span of at most 2 pi rad (one turn; angles in radians)")
    closed: FunctionDesign | None = None
    note = ""
    if not cons.free_offsets:
        try:
            closed = freudenstein_fit(phi, psi, ground)
        except InputError as exc:  # no real four-bar at these offsets: search
            note = f"Freudenstein's closed form gives no four-bar ({exc.value})"
    if closed is not None:
        x = _normalised(closed)[None, :]
        circ = np.array([1.0 if closed.circuit == "open" else -1.0])
        e, ok = output_errors(x, circ, phi, psi)
        cerr = float(np.abs(e).max()) if ok.all() else np.inf
        v = violations(x, phi, cons)[0]
    r = None if closed is not None and v.sum() == 0 and cerr <= EXACT else search_function(phi, psi, cons)
    if closed is not None:
        if v.sum() == 0 and (r is None or cerr <= r.max_error + 1e-12):
            check_function(closed, cons, tolerance)
            return closed, ""
        lengths = np.array([closed.ground, closed.crank, closed.coupler, closed.rocker])
        why = [
            text
            for bad, text in zip(
                v > 0,
                (
                    "does not move over the inputs' arc on one circuit"
                    + (
                        ""
                        if cons.min_transmission == 0
                        else f" keeping the transmission angle {np.degrees(cons.min_transmission):g} deg from a toggle"
                    ),
                    "its crank cannot turn fully",
                    f"link ratio {lengths.max() / lengths.min():.3g} > {cons.max_ratio:g}",
                ),
            )
            if bad
        ]
        how = f"error {cerr:.3g} rad at the pairs" if np.isfinite(cerr) else "some pairs not on its circuit"
        note = f"Freudenstein's closed form ({closed.grashof}, {closed.circuit}, {how}) " + (
            "was less accurate than the search's" if not why else "is no valid four-bar: " + ", ".join(why)
        )
    assert r is not None
    if r.x is None:
        return None, r.reason + (f"; {note}" if note else "")
    d = _design(r.x, r.circuit, phi, psi, ground, cons.free_offsets)
    d.note = note
    check_function(d, cons, tolerance)
    return d, ""
