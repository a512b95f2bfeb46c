"""Velocities and accelerations of every part and named point, and the motor torque they imply.

Nothing here differences samples: each mechanism kind supplies its rates
from its closure equations differentiated in closed form
(:meth:`Mechanism.part_rates <planar.core.model.Mechanism.part_rates>`, asked by
:func:`mechanism_rates`):

* linkages (:class:`~planar.linkages.Linkage`, hence :class:`FourBar` and
  :class:`SliderCrank`): every node kind's closure differentiated twice
  (:meth:`~planar.linkages.NodeKind.acceleration`), solved as a 2x2 system per
  sample;
* cam mechanisms: the motion law's closed form through the follower's linkage
  (:meth:`planar.cams.mechanism.CamMechanism.part_rates`);
* wind-up mechanisms, toys and their assemblies: see :mod:`planar.windup.rates`
  and :meth:`planar.toys.assembly.ToyAssembly.part_rates`.

A part's rates are those of its pose track ``(x, y, angle)``: the velocity and
acceleration of its frame's origin (world frame, model units per s and per
s^2) and its angular velocity ``omega`` and acceleration ``alpha`` (rad/s,
rad/s^2, counter-clockwise positive).  A point fixed to the part at world
position ``P`` moves with ``v = v_O + omega perp(P - O)`` and
``a = a_O + alpha perp(P - O) - omega^2 (P - O)`` (:mod:`planar.core.rates`).

The motor torque (:func:`motor_torque`) is the one virtual-work sum of
:func:`planar.analysis.dynamics.motor_torque_from_rates` (inertia, gravity, loads,
springs, space damping) fed these exact rates in place of differences:
``tau = sum_parts [m (a_G - g + lam v_G) . dX_G/dq + I (alpha + lam omega) dphi/dq]
+ sum_loads F . dX/dq + sum_springs f dL/dq`` with ``d/dq`` the velocity
coefficients (the rates at unit driver speed), so it holds for a rocking
driver too.  Force x model unit, the torque the motor applies to the driven
part (force along the axis for a translating input).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from planar.core.rates import PartRates, RatesResult, point_rates
from planar.errors import InputError

if TYPE_CHECKING:
    from planar.core.model import Driver, Mechanism, Motion
    from planar.linkages import Linkage

__all__ = [
    "Derivatives",
    "PartRates",
    "derivative_columns",
    "driver_rates",
    "mechanism_rates",
    "motion_derivatives",
    "motor_torque",
    "point_rates",
    "rates_method",
    "transmission_angles",
]

Array = NDArray[np.float64]
Mask = NDArray[np.bool_]


@dataclass
class Derivatives:
    """Rates of a motion: per part, per named point, where defined, and how they were found."""

    parts: dict[str, PartRates]
    points: dict[str, tuple[Array, Array]]  # name -> (velocity (N, 2), acceleration (N, 2))
    valid: Mask
    method: str
    transmission: dict[str, Array] = field(default_factory=dict)


def _node_solve(mech: Linkage, q: Array) -> tuple[dict[str, Array], list[tuple[Mask, str, str]]]:
    """The linkage's node solve of ``q`` (remembered for the last ``q``: rates and angles of one table)."""
    return mech.cached_solve_nodes(q)


def driver_rates(driver: Driver, t: ArrayLike) -> tuple[Array, Array]:
    """The driver's rate and its rate of change at times ``t`` (s): ``(dq/dt, d2q/dt2)``."""
    tt = np.asarray(t, float)
    if driver.amplitude is None:
        return np.full_like(tt, driver.rate), np.zeros_like(tt)
    arg = driver.rate * tt + driver.phase
    return (driver.amplitude * driver.rate * np.cos(arg), -driver.amplitude * driver.rate**2 * np.sin(arg))


def mechanism_rates(mech: Mechanism, q: ArrayLike, qd: ArrayLike = 1.0, qdd: ArrayLike = 0.0) -> RatesResult:
    """Rates of every part for driver values ``q``, rates ``qd`` and ``qdd`` per sample (scalars broadcast).

    Returns ``(parts, valid, method)``; ``method`` names how they were found.
    Each mechanism kind answers for itself (:meth:`~planar.core.model.Mechanism.part_rates`);
    a kind with no closed-form rates raises
    :class:`~planar.core.registry.UnsupportedError` naming it (never a difference).
    """
    from planar.core.fields import check_kind, check_samples
    from planar.core.model import Mechanism

    check_kind("mechanism_rates(mech)", mech, Mechanism)
    mech._check_rates_scale("mechanism_rates(mech)")
    qa = check_samples("mechanism_rates(q)", q)
    qdv = np.broadcast_to(check_samples("mechanism_rates(qd)", qd, qa.shape[0]), qa.shape)
    qddv = np.broadcast_to(check_samples("mechanism_rates(qdd)", qdd, qa.shape[0]), qa.shape)
    parts, valid, method = mech.part_rates(qa, qdv, qddv)
    for r in parts.values():  # a rate beyond float64 (a speed of 1e300) is no rate: invalid, not inf
        valid = valid & np.isfinite(r.v).all(-1) & np.isfinite(r.a).all(-1) & np.isfinite(r.omega) & np.isfinite(r.alpha)
    return parts, valid, method


def rates_method(mech: Mechanism) -> str:
    """How :func:`mechanism_rates` finds ``mech``'s rates (one line, for reports), from one sample."""
    q = np.zeros(1)
    return mechanism_rates(mech, mech.driver.value(q), 1.0, 0.0)[2]


def transmission_angles(mech: Mechanism, q: ArrayLike) -> dict[str, Array]:
    """Transmission angle (rad, ``[0, pi]``) of every RRR dyad of a linkage, keyed by its node.

    The angle between the two links meeting at the dyad's joint (a four-bar's
    at ``C``: coupler and rocker); 90 degrees transmits best, near 0 or 180
    the linkage toggles.  Only dyads whose two links are different parts (a
    node fixed on a ternary link has none).  Empty for mechanisms without dyads.
    """
    from planar.core.fields import check_kind, check_samples
    from planar.core.model import Mechanism
    from planar.linkages import Linkage

    check_kind("transmission_angles(mech)", mech, Mechanism)
    mech._check_rates_scale("transmission_angles(mech)")
    qa = check_samples("transmission_angles(q)", q)
    if not isinstance(mech, Linkage):
        return {}
    # the node kinds that join two links at a transmitting angle; a node whose links are one part (a node on
    # a ternary link) transmits nothing: no angle
    nodes = [n for n in mech.nodes if n.transmits and not any({n.name, *n.refs()} <= set(lk.nodes) for lk in mech.links)]
    if not nodes:
        return {}
    pos, _ = _node_solve(mech, qa)
    angles = {n.name: n.transmission(pos) for n in nodes}
    return {k: v for k, v in angles.items() if v is not None}


def motion_derivatives(mech: Mechanism, motion: Motion) -> Derivatives:
    """Rates of a solved motion whose sample times ``motion.t`` are set (the driver's law gives the rates)."""
    from planar.core.fields import check_kind
    from planar.core.model import Mechanism
    from planar.core.model import Motion as MotionKind

    check_kind("motion_derivatives(mech)", mech, Mechanism)
    check_kind("motion_derivatives(motion)", motion, MotionKind, "a Motion (from mech.solve or mech.run)")
    if len(motion.poses) and set(motion.poses) != {p.name for p in mech.parts}:
        raise InputError("motion_derivatives(motion)", motion, f"a motion of {mech.name!r}'s parts")
    if motion.t is None:
        raise InputError(f"{mech.name}.motion.t", None, "sample times (solve with t=..., or Mechanism.run)")
    qd, qdd = driver_rates(mech.driver, motion.t)
    parts, ok, method = mechanism_rates(mech, motion.driver, qd, qdd)
    return _derivatives(mech, motion, parts, ok, method)


def _derivatives(mech: Mechanism, motion: Motion, parts: dict[str, PartRates], ok: Mask, method: str = "") -> Derivatives:
    points = {}
    for name, (part, _) in mech.points.items():
        points[name] = point_rates(motion.poses[part], parts[part], motion.points[name])
    return Derivatives(parts, points, ok & motion.valid, method, transmission_angles(mech, motion.driver))


def motor_torque(
    mech: Mechanism,
    motion: Motion,
    effects: Any = None,
    t_rest: float | None = None,
    densities: dict[str, float] | None = None,
) -> tuple[Array, Mask]:
    """Inverse-dynamics motor torque per sample from exact rates (see the module's note).

    ``effects``: an :class:`~planar.core.effects.Effects` (gravity, loads, springs,
    damping, density) or ``None`` (inertia at density 1 only); ``t_rest``:
    when a spring without a rest length has it (default the first sample);
    ``densities``: per-part densities overriding ``effects.density``.
    Returns ``(tau, valid)``.
    """
    rates, coef, ok = _rates_and_coefficients(mech, motion)
    return _torque(mech, motion, rates, coef, effects, t_rest, densities), ok


def _rates_and_coefficients(mech: Mechanism, motion: Motion) -> tuple[dict[str, PartRates], dict[str, PartRates], Mask]:
    """Rates at the driver's law and at unit driver speed (the velocity coefficients ``d/dq``)."""
    if motion.t is None:
        raise InputError(f"{mech.name}.motion.t", None, "sample times (solve with t=..., or Mechanism.run)")
    qd, qdd = driver_rates(mech.driver, motion.t)
    rates, ok, _ = mechanism_rates(mech, motion.driver, qd, qdd)
    coef, ok1, _ = mechanism_rates(mech, motion.driver, 1.0, 0.0)
    return rates, coef, ok & ok1 & motion.valid


def _torque(
    mech: Mechanism,
    motion: Motion,
    rates: dict[str, PartRates],
    coef: dict[str, PartRates],
    effects: Any,
    t_rest: float | None,
    densities: dict[str, float] | None,
) -> Array:
    from planar.analysis.dynamics import motor_torque_from_rates

    return motor_torque_from_rates(mech, motion, rates, coef, effects, t_rest, densities)


def derivative_columns(mech: Mechanism, motion: Motion, effects: Any = None) -> tuple[list[str], list[Array]]:
    """The ``--derivatives`` columns of a motion table.

    ``<point>.vx .vy .ax .ay`` for every named point, ``<part>.omega .alpha``
    for every part, ``<node>.transmission`` (rad) for every RRR dyad of a
    linkage (a four-bar's is ``C.transmission``), ``torque`` (the inverse
    dynamics of everything ``effects`` names, see :func:`motor_torque`) and
    ``torque.loads`` (the loads alone, ideal: ``sum F . dX/dq``), and
    ``rates_valid`` (0 where a rate is undefined: a toggle, an invalid
    sample or a number that overflowed float64; those samples' rate cells
    hold 0, never NaN, as every validity mask's invalid samples do).
    """
    from planar.core.effects import Effects

    rates, coef, ok = _rates_and_coefficients(mech, motion)
    der = _derivatives(mech, motion, rates, ok)
    names: list[str] = []
    cols: list[Array] = []
    for pname, (v, a) in der.points.items():
        names += [f"{pname}.vx", f"{pname}.vy", f"{pname}.ax", f"{pname}.ay"]
        cols += [v[:, 0], v[:, 1], a[:, 0], a[:, 1]]
    for p in mech.parts:
        r = der.parts[p.name]
        names += [f"{p.name}.omega", f"{p.name}.alpha"]
        cols += [r.omega, r.alpha]
    for node, ang in der.transmission.items():
        names.append(f"{node}.transmission")
        cols.append(ang)
    tau = _torque(mech, motion, rates, coef, effects, None, None)
    loads_only = Effects(loads=tuple(effects.loads)) if effects is not None else Effects()
    tau_l = _torque(mech, motion, rates, coef, loads_only, None, {p.name: 0.0 for p in mech.parts})
    names += ["torque", "torque.loads"]
    cols += [tau, tau_l]
    good = der.valid & ok
    for c in cols:  # a final finite check: a sample whose rates or torque overflowed is not valid
        good &= np.isfinite(c)
    cols = [np.where(good, c, 0.0) for c in cols]
    names.append("rates_valid")
    cols.append(good.astype(float))
    return names, cols
