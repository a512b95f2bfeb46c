"""The 11 elemental mechanisms as :class:`~planar.core.model.Mechanism` objects.

Each has three parts, ``ground``, ``driver`` and ``follower``, with outlines
built from its parameters (cam discs, windows, slots, pins, supports: the
convex hull around the joints, rounded, as in the paper), the paper's joint
kinds (reference table), and a driver law for standalone use:

* ``Rz`` drivers turn fully; ``Oz`` drivers oscillate by ``amplitude`` (rad);
  ``Tx`` drivers stroke by ``amplitude`` (units);
* ``OzT`` drivers (#10, #11) follow a closed step: the reference point moves
  ``(a_x sin psi, a_y (cos psi - 1))`` while turning ``theta_max sin psi``
  (``theta_max`` from the supplement's ``D_theta``), ``psi`` the driver value.

View planes: #1-5, 7, 10, 11 move in xy.  #8 moves in xz; its poses are in
``(x, z)`` coordinates and the mechanism's ``view`` is ``"xz"``.  #6 and #9
are spatial: the driver moves in xy and the follower turns about an x-parallel
axis, so the follower's pose is given in its own ``"yz"`` plane (``offset``
is its x); drawings project orthographically onto xy.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from planar.core.model import Mechanism
from planar.core.rates import RatesResult
from planar.errors import InputError
from planar.windup import params as P_
from planar.windup import rates as R
from planar.windup.builders import ElementalBuilders, _xy
from planar.windup.kinematics import Stage
from planar.windup.records import (
    CONTACT_JOINT,
    ELEMENTAL,
    MOTIONS,
    ElementalRecord,
    check_params,
    elemental_record,
    params_for,
    register_elemental,
    standalone_driver,
    standalone_motion,
)
from planar.windup.skew import SkewContact

__all__ = [
    "CONTACT_JOINT",
    "ELEMENTAL",
    "MOTIONS",
    "ElementalMechanism",
    "ElementalRecord",
    "SkewContact",
    "check_params",
    "elemental",
    "params_for",
    "register_elemental",
    "standalone_driver",
    "standalone_motion",
]

Array = NDArray[np.float64]


class ElementalMechanism(ElementalBuilders, Mechanism):
    """Elemental mechanism ``number`` (a key of :data:`ELEMENTAL`, 1-11) with parameters ``params``."""

    def __init__(
        self,
        number: int,
        params: P_.Params | None = None,
        rate: float = 2 * np.pi,
        phase: float = 0.0,
        sizing_input: Array | None = None,
        **overrides: Any,
    ) -> None:
        """``sizing_input``: the driver motions the parts must serve (slot and track lengths);
        by default one cycle of the standalone driver law."""
        self.record = rec = elemental_record(number)
        self.number = rec.number
        from planar.core.fields import check_finite, check_kind

        self._sizing_input = None if sizing_input is None else check_finite("sizing_input", sizing_input)
        if self._sizing_input is not None and (self._sizing_input.ndim not in (1, 2) or not len(self._sizing_input)):
            raise InputError("sizing_input", sizing_input, "driver motions: one value (or one row) per sample")
        if params is not None:
            check_kind("params", params, rec.params, f"the parameters of mechanism #{rec.number} (params_for({rec.number}))")
        #: the mechanism's parameter record (its ``ElementalRecord.params`` class; fields vary by mechanism)
        self.params: Any = params.replace(**overrides) if params is not None else params_for(self.number, **overrides)
        check_params(self.number, self.params)
        #: ``params`` with ``D_jc`` and ``F_o`` resolved to world (``params.in_world``); the builders use it
        self.world: Any = P_.in_world(self.params)
        self.motion_in, self.motion_out = rec.motions
        self.view = rec.view
        self.spatial = rec.spatial
        self.driver = standalone_driver(self.number, self.params, rate, phase)
        parts, joints = rec.build(self)
        super().__init__(f"#{number} {self.motion_in}->{self.motion_out}", parts, joints, self.driver)

    # -- kinematics ---------------------------------------------------------
    def driver_motion(self, q: Array) -> Array:
        """The driver's motion value for driver values ``q`` (identity except for OzT paths)."""
        return standalone_motion(self.number, self.params, q)

    def forward(self, u: Array) -> Stage:
        """Follower motion for driver motion ``u`` (see :mod:`planar.windup.kinematics`)."""
        return self.record.forward(self.params, np.asarray(u, float))

    def _solve_poses(self, q: Array):
        u = self.driver_motion(q)
        st = self.forward(u)
        poses = {"ground": np.zeros((q.size, 3))}
        poses["driver"] = self._driver_pose(u)
        poses["follower"] = self._follower_pose(st.out)
        return poses, [(st.valid, self.record.contact_joint, st.why)]

    def _driver_pose(self, u: Array) -> Array:
        P = self.world
        o = (P.D_o[0], P.D_o[2]) if self.view == "xz" else _xy(P.D_o)
        n = u.shape[0]
        if self.motion_in in ("Rz", "Oz"):
            return np.column_stack([np.full(n, o[0]), np.full(n, o[1]), u])
        if self.motion_in == "Tx":
            return np.column_stack([o[0] + u, np.full(n, o[1]), np.zeros(n)])
        return np.column_stack([o[0] + u[:, 0], o[1] + u[:, 1], u[:, 2]])  # OzT

    def _follower_pose(self, out: Array) -> Array:
        """The follower's pose track for follower motions ``out`` (the record's ``follower_pose``, world)."""
        return self.record.follower_pose(self.params, out)

    def stage(self, q: Array) -> Stage:
        """Forward kinematics for driver values ``q`` (the standalone law applied)."""
        return self.forward(self.driver_motion(np.asarray(q, float)))

    def part_rates(self, q: Array, qd: Array, qdd: Array) -> RatesResult:
        """Rates of the three parts (see :meth:`Mechanism.part_rates`): the record's ``rates`` (its forward
        kinematics differentiated twice) through the driver's and follower's pose rules, in the view plane's
        coordinates."""
        from planar.core.fields import check_driver_rates

        q, qd, qdd = check_driver_rates(f"{self.name}.part_rates", q, qd, qdd, names=("qd", "qdd"))
        u = R.driver_motion_rates(self.motion_in, self.params, self.driver_motion(q), q, qd, qdd)
        out1, out2, ok = self.record.rates(self.params, u[0], u[1], u[2])
        parts = R.stage_part_rates(self.motion_in, self.record.follower_motion, u, out1, out2)
        return parts, ok & self.forward(u[0]).valid, "wind-up closed forms differentiated analytically"


def elemental(number: int, **overrides: Any) -> ElementalMechanism:
    """Elemental mechanism ``number`` at the supplement's defaults, with ``overrides``."""
    return ElementalMechanism(number, **overrides)
