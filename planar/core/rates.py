"""Rates of a part: the time derivatives of its pose track, and of points fixed to it.

Every mechanism kind answers :meth:`planar.core.model.Mechanism.part_rates` with
one :class:`PartRates` per part; the consumers (motion tables, the motor torque
in :mod:`planar.analysis.rates`) read them without asking what kind it is.

A part's rates are those of its pose track ``(x, y, angle)``: the velocity and
acceleration of its frame's origin (world frame, model units per s and per
s^2) and its angular velocity ``omega`` and acceleration ``alpha`` (rad/s,
rad/s^2, counter-clockwise positive).  A point fixed to the part at world
position ``P`` moves with ``v = v_O + omega perp(P - O)`` and
``a = a_O + alpha perp(P - O) - omega^2 (P - O)`` (:func:`point_rates`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from planar.errors import InputError

__all__ = ["PartRates", "RatesResult", "point_rates", "rotate_vectors"]

Array = NDArray[np.float64]
Mask = NDArray[np.bool_]


@dataclass(frozen=True)
class PartRates:
    """Time derivatives of one part's pose track (world frame)."""

    v: Array  # (N, 2) velocity of the frame's origin
    a: Array  # (N, 2) its acceleration
    omega: Array  # (N,) rad/s
    alpha: Array  # (N,) rad/s^2


#: what :meth:`~planar.core.model.Mechanism.part_rates` returns: per part its rates, where they are
#: defined, and how they were found (one line, for reports)
RatesResult = tuple[dict[str, PartRates], Mask, str]


def rotate_vectors(v: Array, ang: float) -> Array:
    """Vectors ``v`` (N, 2) turned by ``ang`` (rad, counter-clockwise); ``v`` itself for ``ang = 0``."""
    if ang == 0.0:
        return v
    c, s = math.cos(ang), math.sin(ang)
    return np.column_stack([c * v[:, 0] - s * v[:, 1], s * v[:, 0] + c * v[:, 1]])


def point_rates(poses: ArrayLike, rates: PartRates, world_points: ArrayLike) -> tuple[Array, Array]:
    """Velocity and acceleration ``(N, 2)`` of points fixed to a part, at world positions ``(N, 2)``.

    ``poses``: the part's pose track ``(N, 3)``; ``rates``: its :class:`PartRates`.
    Model units per s and per s^2.
    """
    from planar.core.fields import check_finite, check_kind

    P, O = check_finite("point_rates(world_points)", world_points), check_finite("point_rates(poses)", poses)
    check_kind("point_rates(rates)", rates, PartRates)
    n = rates.omega.shape[0] if isinstance(rates.omega, np.ndarray) and rates.omega.ndim == 1 else -1
    if P.shape != (n, 2) or O.shape != (n, 3):
        raise InputError(
            "point_rates(poses, world_points)", f"arrays of shapes {O.shape}, {P.shape}", f"poses ({n}, 3) and points ({n}, 2)"
        )
    rx, ry = P[:, 0] - O[:, 0], P[:, 1] - O[:, 1]
    om, al = rates.omega, rates.alpha
    om2 = om * om
    v = np.column_stack([rates.v[:, 0] - om * ry, rates.v[:, 1] + om * rx])
    a = np.column_stack([rates.a[:, 0] - al * ry - om2 * rx, rates.a[:, 1] + al * rx - om2 * ry])
    return v, a
