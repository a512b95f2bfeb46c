"""The elemental mechanisms' parts and joints: one builder per mechanism (``_build_1`` ... ``_build_11``,
named in its :class:`~planar.windup.records.ElementalRecord`) and the pieces they share (cam and slotted
drivers, ground slides, arc slots), on :class:`ElementalBuilders`, which
:class:`~planar.windup.mechanisms.ElementalMechanism` is."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import NDArray

from planar.core.model import (
    ArcSlot,
    CamOnLine,
    Driver,
    Feature,
    Hole,
    Part,
    PinInArcSlot,
    PinInSlot,
    Pivot,
    Slide,
    Slot,
)
from planar.errors import InputError
from planar.windup.kinematics import Stage
from planar.windup.skew import SkewContact

Array = NDArray[np.float64]


def _xy(v) -> tuple[float, float]:
    return (float(v[0]), float(v[1]))


def _sub(a, b) -> tuple[float, float]:
    return (float(a[0] - b[0]), float(a[1] - b[1]))


class ElementalBuilders:
    """The builders of the elemental mechanisms' parts and joints, mixed into
    :class:`~planar.windup.mechanisms.ElementalMechanism` (they read its ``world`` parameters, its driver and
    its sizing input)."""

    # what the builders read of the mechanism they are mixed into
    world: Any
    params: Any
    number: int
    driver: Driver
    _sizing_input: Array | None
    forward: Callable[[Array], Stage]
    driver_motion: Callable[[Array], Array]

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
