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

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from planar.core.geometry import poses_apply
from planar.core.model import (
    ArcSlot,
    CamOnLine,
    Driver,
    Feature,
    Hole,
    Mechanism,
    Part,
    PinInArcSlot,
    PinInSlot,
    Pivot,
    Slide,
    Slot,
    joint_kind,
)
from planar.core.rates import RatesResult
from planar.errors import InputError
from planar.windup import kinematics as K
from planar.windup import params as P_
from planar.windup import rates as R
from planar.windup.kinematics import Stage

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


def _xy(v) -> tuple[float, float]:
    return (float(v[0]), float(v[1]))


def _sub(a, b) -> tuple[float, float]:
    return (float(a[0] - b[0]), float(a[1] - b[1]))


@joint_kind
@dataclass(frozen=True)
class SkewContact:
    """A driver edge (part ``a``, in the xy plane) touching a follower's tilting pin (part ``b``; spatial #6, #9).

    Residual: ``| distance(edge line, pin axis) - r |`` in 3D, from the
    driver's pose (xy) and the follower's pose in its ``"yz"`` plane.
    """

    kind: ClassVar[str] = "skew-contact"
    name: str
    a: str  # the driver, carrying the edge
    b: str  # the follower, carrying the pin
    edge_point: tuple[float, float]  # on the edge, driver frame
    edge_dir: tuple[float, float]  # driver frame
    pin_x: float  # the pin's x (the follower's offset)
    radius: float
    plane_z: float = 0.0

    def features(self) -> tuple[tuple[str, Feature], ...]:
        return ()

    def pins(self) -> tuple[tuple[str, tuple[float, float]], ...]:
        return ()  # the pin tilts out of the driver's plane; drawn with the follower's outline

    def residual(self, poses) -> Array:
        dp = poses[self.a]
        e0 = poses_apply(dp, self.edge_point)
        c, s = np.cos(dp[:, 2]), np.sin(dp[:, 2])
        ex = c * self.edge_dir[0] - s * self.edge_dir[1]
        ey = s * self.edge_dir[0] + c * self.edge_dir[1]
        fp = poses[self.b]  # (y, z, alpha) of the pivot axis point
        a = fp[:, 2]
        P0 = np.column_stack([np.full_like(a, self.pin_x), fp[:, 0], fp[:, 1]])
        d1 = np.column_stack([np.zeros_like(a), -np.sin(a), np.cos(a)])
        d2 = np.column_stack([ex, ey, np.zeros_like(a)])
        E0 = np.column_stack([e0[:, 0], e0[:, 1], np.full_like(a, self.plane_z)])
        n = np.cross(d1, d2)
        dist = np.abs(((E0 - P0) * n).sum(-1)) / np.linalg.norm(n, axis=1)
        return np.abs(dist - self.radius)


class ElementalMechanism(Mechanism):
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
        u = R.driver_motion_rates(self.motion_in, self.params, self.driver_motion(q), q, qd, qdd)
        out1, out2, ok = self.record.rates(self.params, u[0], u[1], u[2])
        parts = R.stage_part_rates(self.motion_in, self.record.follower_motion, u, out1, out2)
        return parts, ok & self.forward(u[0]).valid, "wind-up closed forms differentiated analytically"

    # -- travel helper --------------------------------------------------------
    def _sweep(self, n: int = 721) -> tuple[Array, Stage]:
        """Driver motions and follower stage of the valid samples of one cycle (to size slots, tracks)."""
        if self._sizing_input is not None:
            q = self._sizing_input
            st = self.forward(q)
        else:
            q = self.driver_motion(self.driver.value(np.linspace(0, self.driver.period, n)))
            st = self.forward(q)
        ok = st.valid
        if not ok.any():
            raise InputError(f"#{self.number}.params", self.params, f"a mechanism that moves ({st.why} everywhere)")
        return q[ok], Stage(st.out[ok], ok[ok], st.why, {k: v[ok] for k, v in st.aux.items()})

    # -- builders: parts and joints -------------------------------------------
    def _ground_slide(self, fo, axis, travel, pin_r, label="support"):
        """Ground slot + follower pins for a pure translation along ``axis`` (kind (h))."""
        ax = np.asarray(axis, float)
        L = 4 * pin_r
        lo, hi = travel
        g0 = np.asarray(fo) + (lo - L) * ax
        g1 = np.asarray(fo) + (hi + 2 * L) * ax
        slot = Slot(_xy(g0), _xy(g1), 2 * pin_r)
        pins = [(0.0, 0.0), _xy(L * ax)]
        joint = Slide(f"{label}-slide", "ground", "follower", start=slot.start, end=slot.end, anchor=pins[0], axis=_xy(L * ax))
        return slot, pins, joint

    def _build_1(self):
        P = self.world
        d = float(np.hypot(*_sub(P.D_jc, P.D_o)))
        _, st = self._sweep()
        fo = _xy(P.F_o)
        wc = _sub(P.D_o, fo)  # window centre in the follower frame
        window = Slot((wc[0], wc[1] - d), (wc[0], wc[1] + d), 2 * P.D_jr)
        slot, pins, slide = self._ground_slide(fo, (1.0, 0.0), (st.out.min(), st.out.max()), P.F_sr)
        m = P.D_jr * 0.35
        follower = Part(
            "follower",
            (
                (wc[0], wc[1] - d, P.D_jr + m),
                (wc[0], wc[1] + d, P.D_jr + m),
                (pins[0][0], pins[0][1], 2 * P.F_sr),
                (pins[1][0], pins[1][1], 2 * P.F_sr),
            ),
            (window, Hole(pins[0], 2 * P.F_sr), Hole(pins[1], 2 * P.F_sr)),
        )
        drv = self._cam_driver()
        ground = Part(
            "ground",
            ((*_xy(P.D_o), 3 * P.D_ar), (*slot.start, 2 * P.F_sr), (*slot.end, 2 * P.F_sr)),
            (Hole(_xy(P.D_o), 2 * P.D_ar), slot),
            ground=True,
        )
        joints = [
            Pivot("axle", "ground", "driver", anchor_a=_xy(P.D_o), anchor_b=(0.0, 0.0)),
            PinInSlot("cam-window", "follower", "driver", start=window.start, end=window.end, pin=_sub(P.D_jc, P.D_o)),
            slide,
        ]
        return [ground, drv, follower], joints

    def _build_2(self):
        P = self.world
        _, st = self._sweep()
        s = _xy(P.F_o)
        m = st.aux["m"]
        # along-line coordinate of the cam centre in the follower frame
        a = st.out
        rel = m - np.asarray(s)
        c, sn = np.cos(-a), np.sin(-a)
        loc = np.column_stack([c * rel[:, 0] - sn * rel[:, 1], sn * rel[:, 0] + c * rel[:, 1]])
        y0 = float(_sub(P.D_jc, s)[1])
        x0, x1 = float(loc[:, 0].min()), float(loc[:, 0].max())
        window = Slot((x0, y0), (x1, y0), 2 * P.D_jr)
        mg = P.D_jr * 0.35
        follower = Part(
            "follower",
            ((0.0, 0.0, 2 * P.F_sr), (x0, y0, P.D_jr + mg), (x1, y0, P.D_jr + mg)),
            (Hole((0.0, 0.0), 2 * P.F_sr), window),
        )
        drv = self._cam_driver()
        ground = Part(
            "ground",
            ((*_xy(P.D_o), 3 * P.D_ar), (*s, 3 * P.F_sr)),
            (Hole(_xy(P.D_o), 2 * P.D_ar), Hole(s, 2 * P.F_sr)),
            ground=True,
        )
        joints = [
            Pivot("axle", "ground", "driver", anchor_a=_xy(P.D_o), anchor_b=(0.0, 0.0)),
            Pivot("pivot", "ground", "follower", anchor_a=s, anchor_b=(0.0, 0.0)),
            PinInSlot("cam-window", "follower", "driver", start=window.start, end=window.end, pin=_sub(P.D_jc, P.D_o)),
        ]
        return [ground, drv, follower], joints

    def _build_3(self):
        P = self.world
        _, st = self._sweep()
        p0 = _xy(P.F_o)
        s = (p0[0] + P.S_c[0], p0[1] + P.S_c[1])
        r = float(np.hypot(P.S_c[0], P.S_c[1]))
        hole = _sub(P.D_jc, p0)  # the cam's hole, in the follower frame (origin at the track pin)
        # track: an arc slot about s covering the pin's travel
        p = st.aux["p"]
        ang = np.unwrap(np.arctan2(p[:, 1] - s[1], p[:, 0] - s[0]))
        pad = 1.5 * P.F_jr / r
        track = ArcSlot(s, r, float(ang.min() - pad), float(ang.max() + pad), 2 * P.F_jr)
        follower = Part(
            "follower", ((0.0, 0.0, 2 * P.F_jr), (*hole, P.D_jr * 1.35)), (Hole((0.0, 0.0), 2 * P.F_jr), Hole(hole, 2 * P.D_jr))
        )
        drv = self._cam_driver()
        mid = 0.5 * (track.angle0 + track.angle1)
        ends = [(s[0] + r * np.cos(a), s[1] + r * np.sin(a)) for a in (track.angle0, track.angle1, mid)]
        ground = Part(
            "ground",
            ((*_xy(P.D_o), 3 * P.D_ar), *[(x, y, 2 * P.F_jr) for x, y in ends]),
            (Hole(_xy(P.D_o), 2 * P.D_ar), track),
            ground=True,
        )
        joints = [
            Pivot("axle", "ground", "driver", anchor_a=_xy(P.D_o), anchor_b=(0.0, 0.0)),
            Pivot("cam-hole", "driver", "follower", anchor_a=_sub(P.D_jc, P.D_o), anchor_b=hole),
            PinInArcSlot("track", "ground", "follower", centre=s, radius=r, pin=(0.0, 0.0)),
        ]
        return [ground, drv, follower], joints

    def _build_4(self):
        P = self.world
        q, st = self._sweep()
        fo = _xy(P.F_o)
        pin = _xy(P.F_jc)
        p0 = (fo[0] + pin[0], fo[1] + pin[1])
        # the slot in the driver frame: y = Y0, x over the pin's travel
        Y0 = p0[1] - P.D_o[1]
        slot = self._driver_slot(q, st.aux["p"], Y0, 2 * P.F_jr)
        gslot, pins, slide = self._ground_slide(fo, (0.0, 1.0), (st.out.min(), st.out.max()), P.F_sr)
        follower = Part(
            "follower",
            ((*pin, 2 * P.F_jr), (*pins[0], 2 * P.F_sr), (*pins[1], 2 * P.F_sr)),
            (Hole(pin, 2 * P.F_jr), Hole(pins[0], 2 * P.F_sr), Hole(pins[1], 2 * P.F_sr)),
        )
        drv = self._slotted_driver(slot)
        ground = Part(
            "ground",
            ((*_xy(P.D_o), 3 * P.D_ar), (*gslot.start, 2 * P.F_sr), (*gslot.end, 2 * P.F_sr)),
            (Hole(_xy(P.D_o), 2 * P.D_ar), gslot),
            ground=True,
        )
        joints = [
            Pivot("axle", "ground", "driver", anchor_a=_xy(P.D_o), anchor_b=(0.0, 0.0)),
            PinInSlot("pin-slot", "driver", "follower", start=slot.start, end=slot.end, pin=pin),
            slide,
        ]
        return [ground, drv, follower], joints

    def _build_5(self):
        P = self.world
        q, st = self._sweep()
        s = _xy(P.F_o)
        pin = _xy(P.F_jc)
        p0 = (s[0] + pin[0], s[1] + pin[1])
        d = p0[1] - P.D_o[1]
        slot = self._driver_slot(q, st.aux["p"], d, 2 * P.F_jr)
        follower = Part(
            "follower", ((0.0, 0.0, 2 * P.F_ar), (*pin, 2 * P.F_jr)), (Hole((0.0, 0.0), 2 * P.F_ar), Hole(pin, 2 * P.F_jr))
        )
        drv = self._slotted_driver(slot)
        ground = Part(
            "ground",
            ((*_xy(P.D_o), 3 * P.D_ar), (*s, 3 * P.F_ar)),
            (Hole(_xy(P.D_o), 2 * P.D_ar), Hole(s, 2 * P.F_ar)),
            ground=True,
        )
        joints = [
            Pivot("axle", "ground", "driver", anchor_a=_xy(P.D_o), anchor_b=(0.0, 0.0)),
            Pivot("pivot", "ground", "follower", anchor_a=s, anchor_b=(0.0, 0.0)),
            PinInSlot("pin-slot", "driver", "follower", start=slot.start, end=slot.end, pin=pin),
        ]
        return [ground, drv, follower], joints

    def _cam_driver(self) -> Part:
        """The round cam of #1-#3: a disc of radius D_jr about D_jc, turning on an axle at D_o.

        An eccentric disc holds its axle's boss (``|D_jc - D_o| + 2 D_ar <= D_jr``) and runs in its follower's
        window in one layer.  A larger eccentricity makes it a crank whose boss would sweep across the
        window's rim: then the disc's centre carries a pin hole, and a pin in the follower's slot joins them
        across layers (a Scotch yoke), which is how it is cut (``planar.fabrication.joints``)."""
        P = self.world
        c = _sub(P.D_jc, P.D_o)
        feats: tuple[Feature, ...] = (Hole((0.0, 0.0), 2 * P.D_ar),)
        if float(np.hypot(*c)) + 2 * P.D_ar > P.D_jr:
            feats += (Hole(c, 2 * P.D_ar),)
        return Part("driver", ((*c, P.D_jr), (0.0, 0.0, 2 * P.D_ar)), feats)

    def _slotted_driver(self, slot: Slot) -> Part:
        """The oscillating arm of #4/#5: an axle at its origin and ``slot`` (parallel to x) for the follower's pin."""
        P = self.world
        y = slot.start[1]
        return Part(
            "driver",
            ((0.0, 0.0, 3 * P.D_ar), (slot.start[0], y, slot.width), (slot.end[0], y, slot.width)),
            (Hole((0.0, 0.0), 2 * P.D_ar), slot),
        )

    def _driver_slot(self, theta: Array, pins: Array, y: float, width: float) -> Slot:
        """The slot, parallel to x at height ``y`` in the (turning) driver's frame, covering the pin's travel."""
        rel = pins - np.asarray(_xy(self.world.D_o))
        c, s = np.cos(-theta), np.sin(-theta)
        xs = c * rel[:, 0] - s * rel[:, 1]
        return Slot((float(xs.min()), y), (float(xs.max()), y), width)

    def _spatial_follower(self, P, N: float, r: float, arm: float) -> Part:
        """Follower of #6/#9 in its own yz plane: pivot at (0, 0), pin up to the driver's plane."""
        top = -N  # the driver's plane, relative to the pivot axis
        return Part(
            "follower",
            ((0.0, 0.0, 2 * P.F_ar), (0.0, top, r)),
            (Hole((0.0, 0.0), 2 * P.F_ar),),
            plane="yz",
            offset=float(P.F_o[0]),
        )

    def _build_6(self):
        P = self.world
        p0 = _xy(P.F_o)
        r = P.F_jr
        h = p0[1] - P.D_o[1] - r
        ex = p0[0] - P.D_o[0]
        N = P.F_o[2] - P.D_o[2]
        drv = Part(
            "driver", ((0.0, 0.0, 3 * P.D_ar), (ex - 2 * r, h - r, r), (ex + 2 * r, h - r, r)), (Hole((0.0, 0.0), 2 * P.D_ar),)
        )
        follower = self._spatial_follower(P, N, r, abs(N))
        ground = Part("ground", ((*_xy(P.D_o), 3 * P.D_ar),), (Hole(_xy(P.D_o), 2 * P.D_ar),), ground=True)
        joints = [
            Pivot("axle", "ground", "driver", anchor_a=_xy(P.D_o), anchor_b=(0.0, 0.0)),
            SkewContact(
                "edge-pin",
                "driver",
                "follower",
                edge_point=(0.0, h),
                edge_dir=(1.0, 0.0),
                pin_x=float(P.F_o[0]),
                radius=r,
                plane_z=float(P.D_o[2]),
            ),
        ]
        return [ground, drv, follower], joints

    def _build_7(self):
        P = self.world
        _, st = self._sweep()
        s = _xy(P.F_o)
        pin = _sub(P.D_jc, P.D_o)
        p = st.aux["p"]
        dist = np.hypot(p[:, 0] - s[0], p[:, 1] - s[1])
        u = np.asarray(_sub(P.D_jc, s))
        u = u / np.hypot(*u)
        slot = Slot(_xy(u * dist.min()), _xy(u * dist.max()), 2 * P.D_jr)
        follower = Part(
            "follower",
            ((0.0, 0.0, 2 * P.F_ar), (*slot.start, 2 * P.D_jr), (*slot.end, 2 * P.D_jr)),
            (Hole((0.0, 0.0), 2 * P.F_ar), slot),
        )
        gslot_lo, gslot_hi = -P.amplitude, P.amplitude
        L = 4 * P.D_sr
        g0 = (P.D_o[0] + gslot_lo - L, P.D_o[1])
        g1 = (P.D_o[0] + gslot_hi + 2 * L, P.D_o[1])
        gslot = Slot(g0, g1, 2 * P.D_sr)
        drv = Part(
            "driver",
            ((0.0, 0.0, 2 * P.D_sr), (L, 0.0, 2 * P.D_sr), (*pin, 2 * P.D_jr)),
            (Hole((0.0, 0.0), 2 * P.D_sr), Hole((L, 0.0), 2 * P.D_sr), Hole(pin, 2 * P.D_jr)),
        )
        ground = Part(
            "ground", ((*g0, 2 * P.D_sr), (*g1, 2 * P.D_sr), (*s, 3 * P.F_ar)), (gslot, Hole(s, 2 * P.F_ar)), ground=True
        )
        joints = [
            Slide("driver-slide", "ground", "driver", start=g0, end=g1, anchor=(0.0, 0.0), axis=(L, 0.0)),
            Pivot("pivot", "ground", "follower", anchor_a=s, anchor_b=(0.0, 0.0)),
            PinInSlot("pin-slot", "follower", "driver", start=slot.start, end=slot.end, pin=pin),
        ]
        return [ground, drv, follower], joints

    def _build_8(self):
        P = self.world
        B = (float(P.F_o[0]), float(P.F_o[2]))
        A0 = (B[0] + P.F_jcx, B[1] + P.F_jh)
        o = (float(P.D_o[0]), float(P.D_o[2]))
        a_loc = _sub(A0, o)  # the window edge point in the driver frame
        L = 4 * P.D_ar
        g0 = (o[0] - P.amplitude - L, o[1])
        g1 = (o[0] + P.amplitude + 2 * L, o[1])
        gslot = Slot(g0, g1, 2 * P.D_ar)
        # driver plate: a window whose right edge passes through the contact point A, so that the tab
        # (its face x = F_jcx is the tab's +x side) stands in the window (drawn as a straight-sided slot
        # of width D_w1; the taper to D_w2 does not change the contact)
        w = P.D_w1
        cx = a_loc[0] - w / 2
        win = Slot((cx, a_loc[1] - 0.08), (cx, a_loc[1] + 0.08), w)
        rim = w / 2 + 0.04
        drv = Part(
            "driver",
            ((0.0, 0.0, 2 * P.D_ar), (L, 0.0, 2 * P.D_ar), (cx, a_loc[1] - 0.08, rim), (cx, a_loc[1] + 0.08, rim)),
            (Hole((0.0, 0.0), 2 * P.D_ar), Hole((L, 0.0), 2 * P.D_ar), win),
        )
        # the contact slides along the tab's face: the face must cover its travel t (distance along
        # the tab from the pivot), which grows past F_jh as the window moves away
        _, st = self._sweep()
        w = st.aux["A"] - np.asarray(B)
        t = np.sqrt(np.maximum((w * w).sum(-1) - P.F_jcx**2, 0.0))
        t_lo, t_hi = float(t.min()) - P.F_jr, float(t.max()) + P.F_jr
        # the tab's +x side is its contact face x = F_jcx all along (a convex hull: the pivot's boss
        # reaches no further than the face where it can, keeping 0.3 F_ar of wall round the hole)
        boss = min(2 * P.F_ar, max(P.F_jcx, 1.3 * P.F_ar))
        follower = Part(
            "follower", ((0.0, 0.0, boss), (P.F_jcx - P.F_jr, t_hi, P.F_jr)), (Hole((0.0, 0.0), 2 * P.F_ar),), plane="xz"
        )
        ground = Part(
            "ground",
            ((*g0, 2 * P.D_ar), (*g1, 2 * P.D_ar), (*B, 3 * P.F_ar)),
            (gslot, Hole(B, 2 * P.F_ar)),
            ground=True,
            plane="xz",
        )
        drv = Part(drv.name, drv.hull, drv.features, plane="xz")
        # the tab's face in its frame (origin B, x along the tab's initial direction rotated): the follower's
        # pose angle is psi - psi0 with psi0 the rest direction (+z); in the follower frame the tab runs
        # along +y (z) and the face is the line x = F_jcx
        joints = [
            Slide("driver-slide", "ground", "driver", start=g0, end=g1, anchor=(0.0, 0.0), axis=(L, 0.0)),
            Pivot("pivot", "ground", "follower", anchor_a=B, anchor_b=(0.0, 0.0)),
            CamOnLine("window-tab", "follower", "driver", start=(P.F_jcx, t_lo), end=(P.F_jcx, t_hi), centre=a_loc, radius=0.0),
        ]
        return [ground, drv, follower], joints

    def _build_9(self):
        P = self.world
        p0 = _xy(P.F_o)
        r = P.F_jr
        phi = P.phi
        N = P.F_o[2] - P.D_o[2]
        e_loc = (p0[0] - P.D_o[0], p0[1] - P.D_o[1] - r / np.cos(phi))  # on the edge, driver frame
        L = 4 * P.D_ar
        g0 = (P.D_o[0] - P.amplitude - L, P.D_o[1])
        g1 = (P.D_o[0] + P.amplitude + 2 * L, P.D_o[1])
        gslot = Slot(g0, g1, 2 * P.D_ar)
        d = np.array([np.cos(phi), -np.sin(phi)])
        a = np.asarray(e_loc) - 0.15 * d
        b = np.asarray(e_loc) + 0.15 * d
        drv = Part(
            "driver",
            ((0.0, 0.0, 2 * P.D_ar), (L, 0.0, 2 * P.D_ar), (*_xy(a - [0, r]), r), (*_xy(b - [0, r]), r)),
            (Hole((0.0, 0.0), 2 * P.D_ar), Hole((L, 0.0), 2 * P.D_ar)),
        )
        follower = self._spatial_follower(P, N, r, abs(N))
        ground = Part("ground", ((*g0, 2 * P.D_ar), (*g1, 2 * P.D_ar)), (gslot,), ground=True)
        joints = [
            Slide("driver-slide", "ground", "driver", start=g0, end=g1, anchor=(0.0, 0.0), axis=(L, 0.0)),
            SkewContact(
                "slot-pin",
                "driver",
                "follower",
                edge_point=e_loc,
                edge_dir=_xy(d),
                pin_x=float(P.F_o[0]),
                radius=r,
                plane_z=float(P.D_o[2]),
            ),
        ]
        return [ground, drv, follower], joints

    def _arc_driver(self, P, qs, st, p0, R) -> tuple[Part, ArcSlot]:
        """OzT driver plate with an arc slot of radius R about its origin, covering the pin's travel."""
        m = st.aux["m"]
        p = st.aux["p"]
        ang = np.unwrap(np.arctan2(p[:, 1] - m[:, 1], p[:, 0] - m[:, 0]) - qs[:, 2])
        w = 2 * P.F_jr
        pad = 1.5 * P.F_jr / R
        arc = ArcSlot((0.0, 0.0), R, float(ang.min() - pad), float(ang.max() + pad), w)
        pts = [(R * np.cos(a), R * np.sin(a)) for a in (arc.angle0, arc.angle1, 0.5 * (arc.angle0 + arc.angle1))]
        part = Part("driver", ((0.0, 0.0, 2 * P.F_jr), *[(x, y, 1.6 * P.F_jr) for x, y in pts]), (arc,))
        return part, arc

    def _build_10(self):
        P = self.world
        qs, st = self._sweep()
        fo = _xy(P.F_o)
        pin = _xy(P.F_jc)
        p0 = (fo[0] + pin[0], fo[1] + pin[1])
        R = float(np.hypot(*_sub(p0, P.D_o)))
        drv, arc = self._arc_driver(P, qs, st, p0, R)
        gslot, pins, slide = self._ground_slide(fo, (1.0, 0.0), (st.out.min(), st.out.max()), P.F_sr)
        follower = Part(
            "follower",
            ((*pin, 2 * P.F_jr), (*pins[0], 2 * P.F_sr), (*pins[1], 2 * P.F_sr)),
            (Hole(pin, 2 * P.F_jr), Hole(pins[0], 2 * P.F_sr), Hole(pins[1], 2 * P.F_sr)),
        )
        ground = Part("ground", ((*gslot.start, 2 * P.F_sr), (*gslot.end, 2 * P.F_sr)), (gslot,), ground=True)
        joints = [
            PinInArcSlot("pin-arc", "driver", "follower", centre=arc.centre, radius=R, pin=pin),
            slide,
        ]
        return [ground, drv, follower], joints

    def _build_11(self):
        P = self.world
        qs, st = self._sweep()
        s = _xy(P.F_o)
        pin = _xy(P.F_jc)
        p0 = (s[0] + pin[0], s[1] + pin[1])
        R = float(np.hypot(*_sub(p0, P.D_o)))
        drv, arc = self._arc_driver(P, qs, st, p0, R)
        follower = Part(
            "follower", ((0.0, 0.0, 2 * P.F_ar), (*pin, 2 * P.F_jr)), (Hole((0.0, 0.0), 2 * P.F_ar), Hole(pin, 2 * P.F_jr))
        )
        ground = Part("ground", ((*s, 3 * P.F_ar),), (Hole(s, 2 * P.F_ar),), ground=True)
        joints = [
            Pivot("pivot", "ground", "follower", anchor_a=s, anchor_b=(0.0, 0.0)),
            PinInArcSlot("pin-arc", "driver", "follower", centre=arc.centre, radius=R, pin=pin),
        ]
        return [ground, drv, follower], joints


def check_params(number: int, P: Any) -> None:
    """Raise :class:`InputError` unless ``P`` can make mechanism ``number``: finite values, positive
    sizes, positive derived lengths (the record's ``lengths``), assembled at rest."""
    from dataclasses import fields

    rec = ELEMENTAL[number]
    if not isinstance(P, rec.params):
        raise InputError(f"#{number}.params", type(P).__name__, f"a {rec.params.__name__} record")
    P_.check_shapes(number, P)  # a vector of the wrong length, a vector for a number: one clear line
    for f in fields(P):
        v = getattr(P, f.name)
        arr = np.asarray(v, dtype=float)
        if not np.all(np.isfinite(arr)):
            raise InputError(f"#{number}.{f.name}", v, "finite numbers")
        if f.name.endswith(("r", "h", "w1", "w2", "amplitude")) and arr.ndim == 0 and arr <= 0:
            raise InputError(f"#{number}.{f.name}", v, "a positive length")
    for fld, label, fn in rec.lengths:
        length = float(fn(P))
        if not length > 1e-12:
            raise InputError(f"#{number}.{fld}", getattr(P, fld), f"a positive {label} (got {length:g})")
    ref = rec.forward(P, np.zeros(1) if rec.motions[0] != "OzT" else np.zeros((1, 3)))
    if not ref.valid[0]:
        raise InputError(f"#{number}.params", P, f"a mechanism that assembles at rest ({ref.why})")


def standalone_driver(number: int, P: Any, rate: float = 2 * np.pi, phase: float = 0.0) -> Driver:
    """The standalone driver law of mechanism ``number``: ``Rz`` turns, ``Oz``/``Tx`` oscillate by
    ``P.amplitude``, ``OzT`` runs its path parameter (see :func:`standalone_motion`)."""
    kind = ELEMENTAL[number].motions[0]
    o = _xy(P.D_o)
    if kind == "Rz":
        return Driver("driver", "rotation", origin=o, rate=rate, phase=phase)
    if kind == "Oz":
        return Driver("driver", "rotation", origin=o, rate=rate, phase=phase, amplitude=P.amplitude)
    if kind == "Tx":
        return Driver("driver", "translation", origin=o, rate=rate, phase=phase, amplitude=P.amplitude)
    return Driver("driver", "path", origin=o, rate=rate, phase=phase)


def standalone_motion(number: int, P: Any, q: Array) -> Array:
    """The driver's motion for driver values ``q``: ``q`` itself, except for ``OzT`` drivers, whose
    reference point moves ``(a_x sin q, a_y (cos q - 1))`` while turning ``theta_max sin q``."""
    q = np.asarray(q, float)
    if ELEMENTAL[number].motions[0] != "OzT":
        return q
    ax, ay = P.path
    th = P.D_theta[1]
    return np.column_stack([ax * np.sin(q), ay * (np.cos(q) - 1.0), th * np.sin(q)])


def elemental(number: int, **overrides: Any) -> ElementalMechanism:
    """Elemental mechanism ``number`` at the supplement's defaults, with ``overrides``."""
    return ElementalMechanism(number, **overrides)


# --------------------------------------------------------------------------
# One record per elemental mechanism
# --------------------------------------------------------------------------


def _fo(P: Any) -> tuple[float, float]:
    """The follower's origin ``F_o`` in world (xy)."""
    return _xy(P_.in_world(P).F_o)


def _slide_x(P: Any, out: Array) -> Array:
    """Follower translating along x from ``F_o``."""
    fo = _fo(P)
    n = out.shape[0]
    return np.column_stack([fo[0] + out, np.full(n, fo[1]), np.zeros(n)])


def _slide_y(P: Any, out: Array) -> Array:
    """Follower translating along y from ``F_o``."""
    fo = _fo(P)
    n = out.shape[0]
    return np.column_stack([np.full(n, fo[0]), fo[1] + out, np.zeros(n)])


def _free(P: Any, out: Array) -> Array:
    """Follower moving in the plane: ``out`` is ``(dx, dy, angle)`` from ``F_o``."""
    fo = _fo(P)
    return np.column_stack([fo[0] + out[:, 0], fo[1] + out[:, 1], out[:, 2]])


def _pivot(P: Any, out: Array) -> Array:
    """Follower turning by ``out`` about its pivot ``F_o``."""
    fo = _fo(P)
    n = out.shape[0]
    return np.column_stack([np.full(n, fo[0]), np.full(n, fo[1]), out])


def _tilt_yz(P: Any, out: Array) -> Array:
    """Spatial follower turning about an x-parallel axis: pose in its ``"yz"`` plane."""
    n = out.shape[0]
    fo = P_.in_world(P).F_o
    return np.column_stack([np.full(n, fo[1]), np.full(n, fo[2]), out])


def _pivot_xz(P: Any, out: Array) -> Array:
    """Follower turning about a y-parallel axis at ``F_o``, in ``(x, z)`` coordinates (+Oy is -angle in xz)."""
    n = out.shape[0]
    fo = P_.in_world(P).F_o
    return np.column_stack([np.full(n, fo[0]), np.full(n, fo[2]), -out])


def _norm2(v: Any) -> float:
    return float(np.hypot(v[0], v[1]))


_CAM_ECC = ("D_jc", "cam eccentricity |D_jc| (driver frame)", lambda P: _norm2(P.D_jc))


@dataclass(frozen=True)
class ElementalRecord:
    """Everything that makes elemental mechanism ``number`` what it is, in one place.

    ``motions``: (driver, follower) motion types; ``params``: its parameter
    class (the supplement's defaults and frames); ``forward``: closed-form
    follower motion from driver motion (:mod:`planar.windup.kinematics`);
    ``build``: parts and joints; ``contact_joint``: the joint the forward
    kinematics closes (named in failures); ``view``: the plane it moves in;
    ``spatial``: its follower turns out of the driver's plane;
    ``follower_pose``: pose track from follower motion (``forward`` and
    ``follower_pose`` take the parameters in the supplement's frames, see
    :mod:`planar.windup.params`, and resolve them to world themselves); ``rates``: the forward
    kinematics differentiated twice in time, ``(params, u, u1, u2) -> (out1, out2, ok)``
    (:mod:`planar.windup.rates`); ``follower_motion``: how ``follower_pose`` moves with the follower
    motion (``"x"``, ``"y"``, ``"pivot"``, ``"-pivot"``, ``"free"``), for the parts' rates; ``lengths``: derived
    lengths that must be positive; ``angle_params``: parameters a scene gives
    in its angle unit.
    """

    number: int
    motions: tuple[str, str]
    params: type[P_.Params]
    forward: Callable[[Any, Array], Stage]
    build: Callable[[ElementalMechanism], tuple[list[Part], list[Any]]]
    contact_joint: str
    follower_pose: Callable[[Any, Array], Array]
    rates: Callable[[Any, Array, Array, Array], tuple[Array, Array, NDArray[np.bool_]]]
    follower_motion: str
    view: str = "xy"
    spatial: bool = False
    lengths: tuple[tuple[str, str, Callable[[Any], float]], ...] = ()
    angle_params: tuple[str, ...] = ("phi", "D_theta")


#: every elemental mechanism, by number (filled by :func:`register_elemental`)
ELEMENTAL: dict[int, ElementalRecord] = {}


def register_elemental(rec: ElementalRecord) -> ElementalRecord:
    """Add ``rec`` to :data:`ELEMENTAL` (a number registered twice is a :class:`TypeError`)."""
    if rec.number in ELEMENTAL:
        raise TypeError(f"double registration for elemental mechanism #{rec.number}")
    ELEMENTAL[rec.number] = rec
    return rec


EM = ElementalMechanism
for _rec in (
    ElementalRecord(
        1, ("Rz", "Tx"), P_.P1, K.forward_1, EM._build_1, "cam-window", _slide_x, R.rates_1, "x", lengths=(_CAM_ECC,)
    ),
    ElementalRecord(
        2, ("Rz", "Oz"), P_.P2, K.forward_2, EM._build_2, "cam-window", _pivot, R.rates_2, "pivot", lengths=(_CAM_ECC,)
    ),
    ElementalRecord(
        3,
        ("Rz", "OzT"),
        P_.P3,
        K.forward_3,
        EM._build_3,
        "track",
        _free,
        R.rates_3,
        "free",
        lengths=(
            _CAM_ECC,
            ("S_c", "track radius |S_c|", lambda P: _norm2(P.S_c)),
            ("F_o", "cam-to-pin distance |F_o - D_jc|", lambda P: _norm2(_sub(P.F_o, P.D_jc))),
        ),
    ),
    ElementalRecord(
        4,
        ("Oz", "Ty"),
        P_.P4,
        K.forward_4,
        EM._build_4,
        "pin-slot",
        _slide_y,
        R.rates_4,
        "y",
        angle_params=("phi", "D_theta", "amplitude"),
    ),
    ElementalRecord(
        5,
        ("Oz", "Oz"),
        P_.P5,
        K.forward_5,
        EM._build_5,
        "pin-slot",
        _pivot,
        R.rates_5,
        "pivot",
        lengths=(("F_jc", "pin radius |F_jc|", lambda P: _norm2(P.F_jc)),),
        angle_params=("phi", "D_theta", "amplitude"),
    ),
    ElementalRecord(
        6,
        ("Oz", "Ox"),
        P_.P6,
        K.forward_6,
        EM._build_6,
        "edge-pin",
        _tilt_yz,
        R.rates_6,
        "pivot",
        spatial=True,
        angle_params=("phi", "D_theta", "amplitude"),
    ),
    ElementalRecord(
        7,
        ("Tx", "Oz"),
        P_.P7,
        K.forward_7,
        EM._build_7,
        "pin-slot",
        _pivot,
        R.rates_7,
        "pivot",
        lengths=(("F_o", "pin-to-pivot distance |F_o - D_jc|", lambda P: _norm2(_sub(P.F_o, P.D_jc))),),
    ),
    ElementalRecord(8, ("Tx", "Oy"), P_.P8, K.forward_8, EM._build_8, "window-tab", _pivot_xz, R.rates_8, "-pivot", view="xz"),
    ElementalRecord(9, ("Tx", "Ox"), P_.P9, K.forward_9, EM._build_9, "slot-pin", _tilt_yz, R.rates_9, "pivot", spatial=True),
    ElementalRecord(10, ("OzT", "Tx"), P_.P10, K.forward_10, EM._build_10, "pin-arc", _slide_x, R.rates_10, "x"),
    ElementalRecord(
        11,
        ("OzT", "Oz"),
        P_.P11,
        K.forward_11,
        EM._build_11,
        "pin-arc",
        _pivot,
        R.rates_11,
        "pivot",
        lengths=(("F_jc", "pin radius |F_jc|", lambda P: _norm2(P.F_jc)),),
    ),
):
    register_elemental(_rec)

#: (driver motion, follower motion) of each elemental mechanism (from the records)
MOTIONS: dict[int, tuple[str, str]] = {k: r.motions for k, r in ELEMENTAL.items()}
#: the joint whose closure the forward kinematics solves, per mechanism (from the records)
CONTACT_JOINT: dict[int, str] = {k: r.contact_joint for k, r in ELEMENTAL.items()}


def params_for(number: int, **overrides: Any) -> P_.Params:
    """Parameters of elemental mechanism ``number``: the supplement's defaults with ``overrides``."""
    return elemental_record(number).params().replace(**overrides)


def elemental_record(number: object) -> ElementalRecord:
    """The record of elemental mechanism ``number``; :class:`InputError` for anything else."""
    if not isinstance(number, (int, np.integer)) or isinstance(number, bool) or number not in ELEMENTAL:
        raise InputError("mechanism", number, f"an elemental mechanism number, one of {sorted(ELEMENTAL)}")
    return ELEMENTAL[int(number)]
