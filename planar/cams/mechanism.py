"""A disc cam turning about the world origin, its follower, and the linkage the follower drives.

The follower is the input link of a :class:`~planar.linkages.Linkage`
whose input is driven by the cam instead of a motor: a translating
follower is an ``actuator`` node ``tip`` sliding along the follower's axis
(its link ``follower`` a block on the ground's line ``axis0 -> axis1``,
held by two pins either side of its node ``stem``, two link widths behind
the tip);
an oscillating follower is a ``crank`` node ``tip`` turning about the
ground node ``pivot`` (link ``follower``, the arm).  The cam's centre is the
ground node ``cam_centre`` at ``(0, 0)``.  Further nodes and links (a
lever, a four-bar, a bird's head) attach to these nodes exactly as in a
``linkage`` scene; nodes listed for a link called ``follower`` ride on the
follower.  Parts: ``ground``, ``cam`` (its outline the exact profile,
:mod:`planar.cams.profile`), ``follower``, ``roller`` (roller followers),
and the linkage's links.  The driver turns the cam counter-clockwise.

The roller is a disc pinned to the follower that rolls on the cam without
slipping: relative to the cam it turns by minus the pitch curve's arc length
over its radius (its angle at cam angle 0 is the follower's).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from planar.cams.joint import CamContact
from planar.cams.profile import CamError, CamProfile, CamReport
from planar.core.geometry import poses_apply
from planar.core.model import Driver, Mechanism, Part, Pivot
from planar.core.rates import PartRates, RatesResult, point_rates
from planar.errors import InputError
from planar.linkages import Link, Linkage
from planar.linkages.nodes import Actuator, Crank, Fixed, NodeKind

__all__ = ["RESERVED", "CamMechanism"]

Array = NDArray[np.float64]
#: names the cam mechanism gives its own nodes and parts
RESERVED = ("cam_centre", "pivot", "axis0", "axis1", "tip", "stem", "cam", "roller", "ground")


class CamMechanism(Mechanism):
    """``profile``'s cam, its follower and the linkage of ``nodes``/``links`` it drives (see the module).

    ``max_pressure_angle`` (rad) is the largest pressure angle allowed; the
    cam is checked when built (:meth:`CamProfile.check`) and :attr:`report`
    keeps the figures.  ``points`` maps names to node names (default: the
    follower's ``tip``).  ``width``: the links' width (model units; default
    the linkage's, 8 % of its span).
    """

    def __init__(
        self,
        name: str,
        profile: CamProfile,
        nodes: Sequence[NodeKind] = (),
        links: Sequence[Link] = (),
        points: Mapping[str, str] | None = None,
        rate: float = 2 * math.pi,
        phase: float = 0.0,
        max_pressure_angle: float = math.radians(30.0),
        unit: str = "deg",
        width: float | None = None,
    ) -> None:
        from planar.core.fields import _check_name, check_kind, check_number

        _check_name("CamMechanism.name", name)
        check_kind("CamMechanism(profile)", profile, CamProfile)
        check_number("CamMechanism(max_pressure_angle)", max_pressure_angle)
        if not isinstance(unit, str) or unit not in ("deg", "rad"):
            raise InputError("CamMechanism(unit)", unit, "'deg' or 'rad' (how angles are shown in messages)")
        for arg, items in (("nodes", nodes), ("links", links)):
            if isinstance(items, (str, bytes)) or not isinstance(items, Sequence):
                raise InputError(f"CamMechanism({arg})", items, f"a sequence of {'node kinds' if arg == 'nodes' else 'Link'}")
        self.profile = profile
        self._width = width
        self._unit = unit
        #: the largest pressure angle allowed (rad)
        self.max_pressure_angle = float(max_pressure_angle)
        self.report: CamReport = profile.check(max_pressure_angle, unit=unit)
        where = profile.where
        f = profile.follower
        for n in nodes:
            if n.name in RESERVED:
                raise InputError(f"{where}.nodes.{n.name}", n.name, f"a name the cam does not use ({', '.join(RESERVED)})")
        extra_follower: tuple[str, ...] = ()
        user_links = []
        for link in links:
            if link.name in ("cam", "roller", "ground"):
                raise InputError(f"{where}.links.{link.name}", link.name, "a link name other than cam, roller, ground")
            if link.name == "follower":
                if link.guide is not None:
                    raise InputError(f"{where}.links.follower.guide", link.guide, "no guide (the follower's is given)")
                extra_follower = tuple(n for n in link.nodes if n not in ("tip", "pivot", "stem"))
            else:
                user_links.append(link)
        q = self._q_range()
        self._back = 0.0
        self.linkage = self._linkage(name, nodes, extra_follower, user_links, points, q)
        if f.motion == "translating":
            # the follower slides on two pins either side of its node "stem", two widths behind the tip
            if self._width is None:
                self._width = self.linkage.width
            self._back = 2.0 * self._width
            self.linkage = self._linkage(name, nodes, extra_follower, user_links, points, q)
        lk = self.linkage
        w = lk.width
        parts = {p.name: p for p in lk.parts}
        fol = parts["follower"]
        tip_local = (-self._back, 0.0) if f.motion == "translating" else (float(f.arm), 0.0)
        hull = list(fol.hull)
        joints: list[Any] = list(lk.joints)
        contact_point, normal = tip_local, (0.0, 1.0)
        if f.kind == "knife":
            # a pointed tip: the hull circle at the tip becomes a point (a circle of 1e-4 of the base radius)
            hull = [c for c in hull if math.dist(c[:2], tip_local) > 1e-12] + [
                (tip_local[0], tip_local[1], 1e-4 * profile.base_radius)
            ]
            contact_body = "follower"
        elif f.kind == "roller":
            contact_body = "roller"
            contact_point = (0.0, 0.0)
        else:
            contact_body = "follower"
            hull, contact_point, normal = self._face_hull(hull, tip_local, w)
        polygon = _hull_polygon(hull) if f.kind == "flat" else None  # a flat face is never widened, only refused
        parts["follower"] = Part("follower", tuple(hull), fol.features, polygon=polygon)
        poly, _ = profile.outline_polygon()
        self._outline_points = len(poly)
        rmax = float(np.hypot(*poly.T).max())
        cam = Part("cam", ((0.0, 0.0, rmax),), polygon=tuple((float(x), float(y)) for x, y in poly))
        out_parts = list(parts.values()) + [cam]
        pin = lk.pin_diameter
        joints.append(Pivot("cam-shaft", "ground", "cam", (0.0, 0.0), (0.0, 0.0), diameter=pin))
        if f.kind == "roller":
            # an explicit outline (a 720-gon within 1e-5 of the radius): fabrication refuses a roller too small
            # for its pin rather than widening it, which would no longer fit the cam
            a = np.linspace(0.0, 2 * np.pi, 720, endpoint=False)
            ring = tuple((float(profile.rr * math.cos(t)), float(profile.rr * math.sin(t))) for t in a)
            out_parts.append(Part("roller", ((0.0, 0.0, profile.rr),), polygon=ring))
            joints.append(Pivot("roller", "follower", "roller", tip_local, (0.0, 0.0), diameter=pin))
        joints.append(CamContact("contact", "cam", contact_body, profile, contact_point, normal))
        self.tip_local = tip_local
        self._roller0 = 0.0
        if f.kind == "roller":  # the roller's angle at cam angle 0: the follower's
            self._roller0 = float(self.linkage.solve(self.profile.follower_output(np.zeros(1))[0]).poses["follower"][0, 2])
        pts = {k: (lk.points[k][0], lk.points[k][1]) for k in lk.points}
        if not pts:
            pts = {"tip": ("follower", tip_local)}
        super().__init__(name, out_parts, joints, Driver("cam", "rotation", (0.0, 0.0), rate=rate, phase=phase), pts)
        if f.kind != "roller":
            self._check_clear()

    @property
    def design_notes(self) -> list[str]:
        """The checks' figures, one line each (``planar export`` prints them as notes)."""
        r = self.report
        p = self.profile
        deg = self._unit == "deg"
        ang = (lambda a: f"{math.degrees(a):.3g} deg") if deg else (lambda a: f"{a:.3g} rad")
        what = "the outline's" if p.follower.kind == "flat" else "the pitch curve's convex"
        out = [
            f"cam: largest pressure angle {ang(r.max_pressure_angle)} at cam angle {ang(r.pressure_angle_at)}, "
            f"in {p.program.describe(r.pressure_segment, self._unit)}",
            f"cam: least radius of curvature ({what}) {r.min_radius:.4g} at cam angle {ang(r.min_radius_at)}"
            + (f" against the roller radius {p.rr:g}" if p.follower.kind == "roller" else ""),
            f"cam: outline cut as {self._outline_points} straight segments within {r.chord_sag:.2g} of the exact "
            "curve (model units)",
        ]
        return out

    # ------------------------------------------------------------------ building
    def _q_range(self) -> tuple[float, float]:
        th = self.profile._grid(4096)
        q = self.profile.follower_output(th)[0]
        return float(q.min()), float(q.max())

    def _linkage(
        self,
        name: str,
        nodes: Sequence[NodeKind],
        extra: tuple[str, ...],
        links: list[Link],
        points: Mapping[str, str] | None,
        q: tuple[float, float],
    ) -> Linkage:
        p = self.profile
        f = p.follower
        own: list[NodeKind] = [Fixed("cam_centre", (0.0, 0.0))]
        if f.motion == "translating":
            o = p.e * p.n
            ax = (float(p.a[0]), float(p.a[1]))
            own += [
                Fixed("axis0", (float(o[0]), float(o[1]))),
                Fixed("axis1", (float(o[0] + p.a[0]), float(o[1] + p.a[1]))),
                Actuator("tip", "axis0", ax, p.s0),
                Actuator("stem", "axis0", ax, p.s0 + (self._back or 1.0)),
            ]
            follower = Link("follower", ("stem", "tip") + extra, guide=("axis0", "axis1"))
        else:
            own += [Fixed("pivot", (float(f.pivot[0]), float(f.pivot[1]))), Crank("tip", "pivot", float(f.arm))]
            follower = Link("follower", ("pivot", "tip") + extra)
        lo, hi = q
        return Linkage(
            name,
            own + list(nodes),
            [follower] + links,
            points=points,
            amplitude=max(0.5 * (hi - lo), 1e-12),
            centre=0.5 * (hi + lo),
            width=self._width,
        )

    def _face_hull(
        self, hull: list[tuple[float, float, float]], tip: tuple[float, float], w: float
    ) -> tuple[list[tuple[float, float, float]], tuple[float, float], tuple[float, float]]:
        """The follower's hull with a flat face covering the contact's travel (plus half a width each way)."""
        p = self.profile
        f = p.follower
        lo, hi = self.report.face_travel
        r = w / 2
        hull = [c for c in hull if math.dist(c[:2], tip) > 1e-12]  # the tip is on the face
        if f.motion == "translating":
            # link frame: origin at the node "stem" (``_back`` behind the face), x along the axis, y along J axis
            x_face = -self._back
            add = [(x_face + r, lo - r, r), (x_face + r, hi + r, r)]
            point, normal = (x_face, 0.0), (1.0, 0.0)
            behind = [(c[0] - x_face) - c[2] for c in hull]
        else:
            # link frame: origin at the pivot, x along the arm, y along J arm; the face at y = -sf * face_offset
            sf = p.sf
            y_face = -sf * f.face_offset
            add = [(lo - r, y_face + sf * r, r), (hi + r, y_face + sf * r, r)]
            point, normal = (0.0, y_face), (0.0, sf)
            behind = [sf * (c[1] - y_face) - c[2] for c in hull]
        worst = min(behind, default=0.0)
        if worst < -1e-9 * max(1.0, p.base_radius):
            need = f.face_offset - worst
            raise CamError(
                f"{p.where}.follower.face_offset: the follower's pin boss ({r:.4g} in radius) reaches "
                f"{-worst:.4g} past the flat face toward the cam; a face_offset of at least {need:.4g} "
                "keeps it behind the face"
            )
        return hull + add, point, normal

    def _check_clear(self, samples: int = 72) -> None:
        """A knife-edge or flat-faced follower touches the cam in one layer: refuse one that cuts into it."""
        from shapely import affinity

        cam = self.part("cam").outline
        fol = self.part("follower").outline
        th = np.arange(samples) * (2 * np.pi / samples)
        pose = self.solve(th).poses["follower"]
        limit = 1e-4 * self.profile.base_radius**2
        for k in range(samples):
            x, y, a = pose[k]
            c, s = math.cos(a - th[k]), math.sin(a - th[k])  # the follower seen from the cam
            cx, cy = math.cos(-th[k]), math.sin(-th[k])
            seen = affinity.affine_transform(fol, [c, -s, s, c, cx * x - cy * y, cy * x + cx * y])
            area = float(seen.intersection(cam).area)
            if area > limit:
                raise CamError(
                    f"{self.profile.where}.follower: the follower's outline overlaps the cam by {area:.3g} "
                    f"(model units^2) at cam angle {math.degrees(th[k]):.4g} deg; it touches the cam in one "
                    "layer, so move its pivot or give a smaller link_width"
                )

    # ------------------------------------------------------------------ solving
    def _solve_poses(self, q: Array) -> tuple[dict[str, Array], list[tuple[NDArray[np.bool_], str, str]]]:
        out = self.profile.follower_output(q)[0]
        lm = self.linkage.solve(out)
        poses = dict(lm.poses)
        poses["cam"] = np.column_stack([np.zeros_like(q), np.zeros_like(q), q])
        fol = poses["follower"]
        if self.profile.follower.kind == "roller":
            # rolling without slip: relative to the cam the roller turns by -(pitch arc length) / radius
            c = poses_apply(fol, self.tip_local)
            spin = q - self.profile.pitch_length(q) / self.profile.rr
            poses["roller"] = np.column_stack([c, self._roller0 + spin])
        checks = [(lm.fail_code != k, joint, why) for k, (joint, why) in enumerate(lm.fail_table)]
        return poses, checks

    def follower_motion(self, q: Array) -> dict[str, Array]:
        """The follower's coordinate (lift or arm angle) and its first two derivatives in time (driver law)."""
        from planar.core.fields import check_samples

        qa = check_samples(f"{self.name}.follower_motion(q)", q)
        s, v, a = self.profile.follower_output(qa)
        w = self.driver.rate
        return {"q": s, "dq_dt": v * w, "d2q_dt2": a * w * w}

    def part_rates(self, q: Array, qd: Array, qdd: Array) -> RatesResult:
        """Rates of every part (see :meth:`Mechanism.part_rates`).

        The follower's coordinate ``s(theta)`` from the motion law (closed form,
        with ``s'``, ``s''``) is the input of its linkage, by the chain rule
        ``ds/dt = s' qd``, ``d2s/dt2 = s'' qd^2 + s' qdd``; the cam turns with
        the driver; a roller rolls without slip, its angle
        ``theta - L(theta) / r_roller`` (``L`` the pitch curve's arc length), so
        ``omega = qd (1 - |P'| / r)`` and
        ``alpha = qdd (1 - |P'| / r) - qd^2 (P' . P'') / (|P'| r)``.
        """
        from planar.core.fields import check_driver_rates

        q, qd, qdd = check_driver_rates(f"{self.name}.part_rates", q, qd, qdd, names=("qd", "qdd"))
        prof = self.profile
        s, s1, s2 = prof.follower_output(q)
        parts, valid, _ = self.linkage.part_rates(s, s1 * qd, s2 * qd * qd + s1 * qdd)
        zero = np.zeros((q.shape[0], 2))
        parts["cam"] = PartRates(zero, zero.copy(), np.array(qd, float), np.array(qdd, float))
        if prof.follower.kind == "roller":
            fol = self.linkage.solve(s).poses["follower"]
            c = poses_apply(fol, self.tip_local)
            vc, ac = point_rates(fol, parts["follower"], c)
            _, P1, P2 = prof.pitch(q)
            speed = np.hypot(P1[:, 0], P1[:, 1])
            dspeed = np.einsum("ij,ij->i", P1, P2) / np.maximum(speed, 1e-300)
            r = prof.rr
            parts["roller"] = PartRates(vc, ac, qd * (1.0 - speed / r), qdd * (1.0 - speed / r) - qd * qd * dspeed / r)
        return parts, valid, "cam motion law (closed form) through the linkage's closure equations, differentiated twice"


def _hull_polygon(hull: Sequence[tuple[float, float, float]]) -> tuple[tuple[float, float], ...]:
    """The convex hull of circles as a counter-clockwise polygon (arcs every 1 deg; flat edges exact)."""
    a = np.radians(np.arange(360.0))
    pts = np.concatenate([np.column_stack([x + r * np.cos(a), y + r * np.sin(a)]) for x, y, r in hull])
    from shapely.geometry import MultiPoint

    ring = np.asarray(MultiPoint([tuple(p) for p in pts]).convex_hull.exterior.coords)[:-1]
    return tuple((float(x), float(y)) for x, y in ring)
