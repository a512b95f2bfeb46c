"""The cam's profile from its program and follower: pitch curve, outline, curvature, pressure angle.

Frames and signs: the cam turns counter-clockwise about the world origin by
the cam angle ``theta`` (rad); the cam's own frame coincides with the world
at ``theta = 0``.  A point fixed in the world is seen in the cam's frame
turned by ``-theta``, so as the cam turns the contact runs clockwise round
the cam.  Every curve is given in closed form with its first two
derivatives with respect to ``theta`` (no differencing):

* knife-edge and roller followers: the **pitch curve** ``P(theta)`` is the
  path of the knife's tip or the roller's centre in the cam's frame,
  ``P = R(-theta) W`` for the follower point ``W(theta)`` in the world,
  ``P' = R(-theta)(W' - J W)``, ``P'' = R(-theta)(W'' - 2 J W' - W)``
  (``J`` turns a vector by +90 deg).  The cam's outline is the pitch curve
  offset inward by the roller radius along its normal, exactly:
  ``C = P - r J P'/|P'|`` (a knife edge: ``C = P``).  Undercut: where the
  pitch curve is convex with a radius of curvature below the roller radius
  the offset folds over itself.
* flat-faced followers: the outline is the **envelope** of the face lines
  ``x . n(theta) = h(theta)`` seen from the cam.  With the face normal's
  angle ``beta(theta)`` in the cam's frame and the support function
  ``p(beta) = h``, the contact is ``x = p n + dp/dbeta J n`` and the radius
  of curvature is ``p + d2p/dbeta2`` (for a translating face:
  ``base_radius + s + s''``); where it is not positive the outline has a
  cusp and the face cannot follow the program.

The pressure angle is the angle between the contact normal and the
direction in which the follower's contact point moves (0 is best).

Lengths are model units; angles radians.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from planar.cams.laws import TWO_PI, Program
from planar.core.fields import check_fields, check_number, check_positive, check_samples
from planar.core.limits import RESOLUTION
from planar.errors import InputError, PlanarError

__all__ = ["CamError", "CamProfile", "CamReport", "FollowerGeometry"]

Array = NDArray[np.float64]
Vec = tuple[float, float]


class CamError(PlanarError):
    """A cam that cannot be made or cannot follow its program (one line naming the segment)."""


def _rot(theta: Array, v: Array) -> Array:
    """``R(theta) v`` per sample; ``v`` is ``(N, 2)``."""
    c, s = np.cos(theta), np.sin(theta)
    return np.stack([c * v[:, 0] - s * v[:, 1], s * v[:, 0] + c * v[:, 1]], -1)


def _J(v: Array) -> Array:
    """``v`` turned by +90 degrees."""
    return np.stack([-v[..., 1], v[..., 0]], -1)


def _cross(a: Array, b: Array) -> Array:
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def _unit(v: Array) -> Array:
    return v / np.hypot(v[..., 0], v[..., 1])[..., None]


@dataclass(frozen=True)
class FollowerGeometry:
    """Where the follower is and what touches the cam.

    ``kind``: ``"knife"`` (a point), ``"roller"`` (a disc of ``roller_radius``)
    or ``"flat"`` (a flat face).  ``motion``: ``"translating"`` along the unit
    direction of ``axis`` (pointing away from the cam), the axis line
    ``offset`` to the left of the cam's centre (seen along ``axis``); or
    ``"oscillating"`` about the ground ``pivot``, the knife tip or roller
    centre ``arm`` from the pivot.  An oscillating flat face runs parallel to
    the arm, ``face_offset`` from the pivot's line toward the cam.  ``branch``
    (+1 or -1) picks which of the two arm positions touching the base circle
    the follower starts from (roller and knife: the arm turned clockwise
    (+1) or counter-clockwise (-1) from the line pivot-cam centre; flat: the
    cam on the arm's right (+1) or left (-1)).
    """

    kind: Literal["knife", "roller", "flat"] = "roller"
    motion: Literal["translating", "oscillating"] = "translating"
    roller_radius: float = 0.0
    axis: Vec = (0.0, 1.0)
    offset: float = 0.0
    pivot: Vec = (0.0, 0.0)
    arm: float = 0.0
    face_offset: float = 0.0
    branch: int = 1

    def __post_init__(self) -> None:
        if not isinstance(self.kind, str) or self.kind not in ("knife", "roller", "flat"):
            raise InputError("follower.kind", self.kind, "'knife', 'roller' or 'flat'")
        if not isinstance(self.motion, str) or self.motion not in ("translating", "oscillating"):
            raise InputError("follower.motion", self.motion, "'translating' or 'oscillating'")
        check_fields(self, "follower")
        if self.branch not in (1, -1):
            raise InputError("follower.branch", self.branch, "+1 or -1")
        if self.roller_radius < 0 or self.arm < 0:
            bad = "roller_radius" if self.roller_radius < 0 else "arm"
            raise InputError(f"follower.{bad}", getattr(self, bad), "a length >= 0")
        if self.axis[0] == 0 and self.axis[1] == 0:
            raise InputError("follower.axis", self.axis, "a non-zero direction")


@dataclass
class CamReport:
    """What the checks found: the worst figures over the cycle and per segment (angles in radians)."""

    max_pressure_angle: float
    pressure_angle_at: float
    pressure_segment: int
    min_radius: float
    min_radius_at: float
    radius_segment: int
    #: per segment: (max pressure angle, least radius of curvature of the pitch curve (roller, knife:
    #: convex parts; +inf where it is concave throughout) or of the outline (flat))
    segments: list[tuple[float, float]]
    #: flat faces: the range of the contact along the face (model units, from the face's reference point)
    face_travel: tuple[float, float] = (0.0, 0.0)
    #: largest gap between the outline polygon's chords and the exact curve (model units)
    chord_sag: float = 0.0


class CamProfile:
    """The exact cam for ``program`` and ``follower``; ``base_radius`` is the cam outline's least radius.

    Raises :class:`~planar.errors.InputError` naming the field for a follower
    that cannot touch the base circle; :meth:`check` raises :class:`CamError`
    naming the segment where the cam undercuts, cusps or exceeds its pressure
    angle.
    """

    def __init__(self, program: Program, base_radius: float, follower: FollowerGeometry, where: str = "mechanism") -> None:
        if not isinstance(program, Program):
            raise InputError(f"{where}.program", program, "a cams.Program")
        if not isinstance(follower, FollowerGeometry):
            raise InputError(f"{where}.follower", follower, "a cams.FollowerGeometry")
        self.program = program
        self.follower = f = follower
        self.where = where
        check_positive(f"{where}.base_radius", base_radius)
        self.base_radius = rb = float(base_radius)
        fw = f"{where}.follower"
        if f.kind not in ("knife", "roller", "flat"):
            raise InputError(f"{fw}.kind", f.kind, "'knife', 'roller' or 'flat'")
        if f.motion not in ("translating", "oscillating"):
            raise InputError(f"{fw}.motion", f.motion, "'translating' or 'oscillating'")
        if f.kind == "roller" and not (f.roller_radius > 0):
            raise InputError(f"{fw}.roller_radius", f.roller_radius, "a positive radius for a roller follower")
        self.rr = float(f.roller_radius) if f.kind == "roller" else 0.0
        rp = rb + self.rr  # prime circle
        if rb < RESOLUTION * rp:  # the base circle below float64's grain at the roller's size: no cam outline
            raise InputError(
                f"{where}.base_radius", base_radius, f"a base radius at least {RESOLUTION:g} of the roller's ({self.rr:g})"
            )
        self.prime_radius = rp
        if f.motion == "translating":
            a = np.asarray(f.axis, float)
            if not np.all(np.isfinite(a)) or np.hypot(*a) == 0:
                raise InputError(f"{fw}.axis", f.axis, "a non-zero direction")
            self.a = a / np.hypot(*a)
            self.n = _J(self.a)
            self.e = float(f.offset)
            if f.kind != "flat" and abs(self.e) >= rp:
                raise InputError(
                    f"{fw}.offset", f.offset, f"an offset smaller than the prime circle's radius {rp:g} (base + roller radius)"
                )
            self.s0 = math.sqrt(rp * rp - self.e * self.e) if f.kind != "flat" else rb
            self.sign = 1.0
            self.psi0 = 0.0
        else:
            if not (f.arm > 0):
                raise InputError(f"{fw}.arm", f.arm, "a positive arm length")
            if f.branch not in (1, -1):
                raise InputError(f"{fw}.branch", f.branch, "+1 or -1")
            P0 = np.asarray(f.pivot, float)
            D = float(np.hypot(*P0))
            gamma = math.atan2(P0[1], P0[0])
            self.P0 = P0
            if f.kind != "flat":
                c = (rp * rp - D * D - f.arm**2) / (2 * f.arm * D) if D > 0 else 2.0
                if abs(c) >= 1:
                    raise InputError(
                        f"{fw}.arm",
                        f.arm,
                        f"an arm that reaches the prime circle (radius {rp:g}) from the pivot {D:g} from the cam's centre",
                    )
                self.psi0 = gamma - f.branch * math.acos(c)
                self.sign = -float(np.sign(math.sin(self.psi0 - gamma)))
            else:
                sf = float(f.branch)  # the face normal (away from the cam) is sf * J u
                if not (rb + f.face_offset < D):
                    raise InputError(
                        f"{fw}.pivot",
                        f.pivot,
                        f"a pivot farther than base_radius + face_offset ({rb + f.face_offset:g}) from the cam's centre",
                    )
                alpha = math.asin(-sf * (rb + f.face_offset) / D)
                self.psi0 = gamma + math.pi - alpha
                self.sf = sf
                u0 = np.array([math.cos(self.psi0), math.sin(self.psi0)])
                self.sign = float(np.sign(-sf * float(P0 @ u0))) or 1.0

    # ------------------------------------------------------------------ follower motion
    def follower_output(self, theta: ArrayLike) -> tuple[Array, Array, Array]:
        """The follower's coordinate and its derivatives in ``theta``: the lift ``s`` (translating,
        model units) or the arm angle ``psi`` (oscillating, rad, counter-clockwise from +x)."""
        s, v, acc = self.program.evaluate(theta)
        if self.follower.motion == "translating":
            return s, v, acc
        return self.psi0 + self.sign * s, self.sign * v, self.sign * acc

    def follower_point(self, theta: ArrayLike) -> tuple[Array, Array, Array]:
        """World position ``W`` (N, 2) of the knife tip / roller centre (flat: the face's reference point:
        on the axis, or ``arm`` along the arm) and ``dW/dtheta``, ``d2W/dtheta2``."""
        th = check_samples("theta", theta)
        q, q1, q2 = self.follower_output(th)
        f = self.follower
        if f.motion == "translating":
            base = self.s0
            W = self.e * self.n + (base + q)[:, None] * self.a
            return W, q1[:, None] * self.a, q2[:, None] * self.a
        u = np.stack([np.cos(q), np.sin(q)], -1)
        up = _J(u)
        L = f.arm
        W = self.P0 + L * u
        return W, L * q1[:, None] * up, L * (q2[:, None] * up - (q1 * q1)[:, None] * u)

    # ------------------------------------------------------------------ knife and roller
    def pitch(self, theta: ArrayLike) -> tuple[Array, Array, Array]:
        """The pitch curve ``P`` in the cam's frame and ``dP/dtheta``, ``d2P/dtheta2`` (knife, roller)."""
        th = check_samples("theta", theta)
        W, W1, W2 = self.follower_point(th)
        P = _rot(-th, W)
        P1 = _rot(-th, W1 - _J(W))
        P2 = _rot(-th, W2 - 2 * _J(W1) - W)
        return P, P1, P2

    # ------------------------------------------------------------------ flat face
    def face(self, theta: ArrayLike) -> dict[str, Array]:
        """The face line in the cam's frame: normal angle ``beta`` (away from the cam) and its
        distance ``h`` from the cam's centre, with derivatives in ``theta`` (flat faces)."""
        th = check_samples("theta", theta)
        q, q1, q2 = self.follower_output(th)
        f = self.follower
        if f.motion == "translating":
            alpha = math.atan2(self.a[1], self.a[0])
            h, h1, h2 = self.base_radius + q, q1, q2
            beta, b1, b2 = alpha - th, -np.ones_like(th), np.zeros_like(th)
        else:
            sf = self.sf
            u = np.stack([np.cos(q), np.sin(q)], -1)
            up = _J(u)
            m = sf * up
            h = m @ self.P0 - f.face_offset
            h_psi = -sf * (u @ self.P0)
            h_psipsi = -sf * (up @ self.P0)
            h1 = h_psi * q1
            h2 = h_psipsi * q1 * q1 + h_psi * q2
            beta = np.arctan2(m[:, 1], m[:, 0]) - th
            b1, b2 = q1 - 1.0, q2
        return {"beta": beta, "b1": b1, "b2": b2, "h": h, "h1": h1, "h2": h2}

    def envelope(self, theta: ArrayLike) -> tuple[Array, Array, Array]:
        """Contact point on the outline (cam frame), the face normal there and the radius of curvature."""
        F = self.face(theta)
        b1 = F["b1"]
        p1 = F["h1"] / b1
        p2 = (F["h2"] * b1 - F["h1"] * F["b2"]) / b1**3
        nrm = np.stack([np.cos(F["beta"]), np.sin(F["beta"])], -1)
        x = F["h"][:, None] * nrm + p1[:, None] * _J(nrm)
        return x, nrm, F["h"] + p2

    # ------------------------------------------------------------------ shared
    def outline(self, theta: ArrayLike) -> tuple[Array, Array]:
        """The cam outline's contact point (cam frame) and its outward unit normal at cam angles ``theta``."""
        if self.follower.kind == "flat":
            x, nrm, _ = self.envelope(theta)
            return x, nrm
        P, P1, _ = self.pitch(theta)
        N = _J(_unit(P1))  # the pitch curve runs clockwise: its outward normal is on the tangent's left
        return P - self.rr * N, N

    def radius_of_curvature(self, theta: ArrayLike) -> Array:
        """Knife, roller: the pitch curve's (convex positive); flat: the outline's (a cusp where <= 0)."""
        if self.follower.kind == "flat":
            return self.envelope(theta)[2]
        _, P1, P2 = self.pitch(theta)
        cr = _cross(P1, P2)
        sp = np.hypot(P1[:, 0], P1[:, 1]) ** 3
        with np.errstate(divide="ignore"):
            return np.where(cr != 0, -sp / np.where(cr != 0, cr, 1.0), np.inf)

    def pressure_angle(self, theta: ArrayLike) -> Array:
        """Angle (rad, 0 to pi/2) between the contact normal and the path of the follower's contact point."""
        th = check_samples("theta", theta)
        x, N = self.outline(th)
        Nw = _rot(th, N)
        f = self.follower
        if f.motion == "translating":
            t = np.broadcast_to(self.a, Nw.shape)
        elif f.kind == "flat":
            xw = _rot(th, x)
            t = _unit(_J(xw - self.P0))
        else:
            q, _, _ = self.follower_output(th)
            t = np.stack([-np.sin(q), np.cos(q)], -1)
        return np.arctan2(np.abs(_cross(Nw, t)), np.abs((Nw * t).sum(-1)))

    def face_position(self, theta: ArrayLike) -> Array:
        """Flat faces: the contact's position along the face (model units) from the face's reference point
        (translating: the axis, positive along ``J axis``; oscillating: the pivot's foot, positive along the arm)."""
        th = check_samples("theta", theta)
        x, _ = self.outline(th)
        xw = _rot(th, x)
        if self.follower.motion == "translating":
            return (xw - self.e * self.n) @ self.n
        q, _, _ = self.follower_output(th)
        u = np.stack([np.cos(q), np.sin(q)], -1)
        return ((xw - self.P0) * u).sum(-1)

    def outline_polygon(self, sag: float | None = None, n_max: int = 16384) -> tuple[Array, float]:
        """The closed outline as a counter-clockwise polygon ``(M, 2)`` (cam frame, no repeated end point)
        whose chords stay within ``sag`` (default 1e-5 of the base radius) of the exact curve where they can
        (at most ``n_max`` points); returns the polygon and the largest sag estimated."""
        tol = 1e-5 * self.base_radius if sag is None else check_positive("outline_polygon(sag)", sag)
        if not 16 <= check_number("outline_polygon(n_max)", n_max, integer=True) <= 1 << 24:
            raise InputError("outline_polygon(n_max)", n_max, "a whole number of points, 16 to 16 777 216")
        n = 1024
        while True:
            th = self._grid(n)
            x, _ = self.outline(th)
            chord = np.hypot(*np.diff(np.vstack([x, x[:1]]), axis=0).T)
            rho = np.abs(self._outline_radius(th))
            rho_mid = np.minimum(rho, np.roll(rho, -1))
            est = float(np.max(chord**2 / (8.0 * np.maximum(rho_mid, 1e-300))))
            if est <= tol or n >= n_max:
                return x[::-1].copy(), est
            n = min(n_max, int(n * math.sqrt(est / tol) * 1.2) + 1)

    def _outline_radius(self, theta: Array) -> Array:
        if self.follower.kind == "flat":
            return self.envelope(theta)[2]
        rho = self.radius_of_curvature(theta)
        return np.where(rho > 0, rho - self.rr, rho - self.rr)  # convex: rho - r; concave: -(|rho| + r)

    def _grid(self, n: int) -> Array:
        """``n`` cam angles over one turn, every segment boundary among them."""
        starts = self.program.starts
        out = []
        for i, sg in enumerate(self.program.segments):
            k = max(2, int(round(n * sg.angle / TWO_PI)))
            out.append(starts[i] + sg.angle * np.arange(k) / k)
        return np.concatenate(out)

    # ------------------------------------------------------------------ rolling
    _GL_X, _GL_W = np.polynomial.legendre.leggauss(6)

    def _speed(self, theta: Array) -> Array:
        P1 = self.pitch(theta)[1]
        return np.hypot(P1[:, 0], P1[:, 1])

    def _gauss(self, a: Array, b: Array) -> Array:
        """``integral |P'| dtheta`` from ``a`` to ``b`` per sample (6-point Gauss-Legendre)."""
        mid, half = 0.5 * (a + b), 0.5 * (b - a)
        t = mid[:, None] + half[:, None] * self._GL_X[None, :]
        return half * (self._speed(t.ravel()).reshape(t.shape) @ self._GL_W)

    def pitch_length(self, theta: ArrayLike, cells: int = 4096) -> Array:
        """Arc length of the pitch curve from cam angle 0 to ``theta`` (rad, any real value; model units).

        Gauss-Legendre over ``cells`` equal cells per turn, cumulated once, plus the part cell up to
        ``theta``; a whole turn adds the pitch curve's length.
        """
        if not 1 <= check_number("pitch_length(cells)", cells, integer=True) <= 1 << 22:
            raise InputError("pitch_length(cells)", cells, "a whole number of cells, 1 to 4 194 304")
        if "_cum" not in self.__dict__:
            edges = np.linspace(0.0, TWO_PI, cells + 1)
            self.__dict__["_cum"] = np.concatenate([[0.0], np.cumsum(self._gauss(edges[:-1], edges[1:]))])
        cum: Array = self.__dict__["_cum"]
        n = cum.shape[0] - 1
        th = check_samples("theta", theta)
        turns = np.floor(th / TWO_PI)
        t = th - turns * TWO_PI
        k = np.clip((t / TWO_PI * n).astype(np.intp), 0, n - 1)
        start = k * (TWO_PI / n)
        return turns * cum[-1] + cum[k] + self._gauss(start, t)

    # ------------------------------------------------------------------ contact (joint residuals)
    def pitch_distance(self, q_cam: Array, t0: Array) -> Array:
        """Distance from points ``q_cam`` (cam frame) to the pitch curve, by Newton from parameters ``t0``."""
        t = np.asarray(t0, float).copy()
        for _ in range(8):
            P, P1, P2 = self.pitch(t)
            d = P - q_cam
            g = (d * P1).sum(-1)
            dg = (P1 * P1).sum(-1) + (d * P2).sum(-1)
            t = t - g / np.where(dg > 0, dg, (P1 * P1).sum(-1))
        P, _, _ = self.pitch(t)
        return np.hypot(*(P - q_cam).T)

    def support(self, beta: Array, t0: Array) -> Array:
        """The outline's support ``max x . n(beta)`` (cam frame), by Newton on the face angle from ``t0``."""
        t = np.asarray(t0, float).copy()
        for _ in range(8):
            F = self.face(t)
            g = np.angle(np.exp(1j * (F["beta"] - beta)))
            t = t - g / F["b1"]
        x, _, _ = self.envelope(t)
        return (x * np.stack([np.cos(beta), np.sin(beta)], -1)).sum(-1)

    # ------------------------------------------------------------------ checks
    def check(self, max_pressure_angle: float, samples: int = 721, unit: str = "deg") -> CamReport:
        """Refuse (:class:`CamError`, one line naming the segment) an undercut, a cusp or a pressure angle
        over ``max_pressure_angle`` (rad); otherwise the worst figures."""
        if not 0 < check_number("check(max_pressure_angle)", max_pressure_angle) <= math.pi / 2:
            raise InputError("check(max_pressure_angle)", max_pressure_angle, "an angle between 0 and pi/2 rad")
        if not 2 <= check_number("check(samples)", samples, integer=True) <= 1 << 20:
            raise InputError("check(samples)", samples, "a whole number of samples per segment, 2 to 1 048 576")
        if not isinstance(unit, str) or unit not in ("deg", "rad"):
            raise InputError("check(unit)", unit, "'deg' or 'rad'")
        prog = self.program
        segs: list[tuple[float, float]] = []
        worst_p = (-1.0, 0.0, 0)
        worst_r = (math.inf, 0.0, 0)
        travel = [math.inf, -math.inf]
        f = self.follower
        fmt = (lambda a: f"{math.degrees(a):.4g} deg") if unit == "deg" else (lambda a: f"{a:.4g} rad")
        for i, sg in enumerate(prog.segments):
            th = prog.starts[i] + sg.angle * np.linspace(0.0, 1.0, samples)
            if f.kind == "flat":
                b1 = self.face(th)["b1"]
                if np.any(b1 >= 0):
                    k = int(np.argmax(b1 >= 0))
                    raise CamError(
                        f"{prog.describe(i, unit)}: the oscillating face turns as fast as the cam at "
                        f"cam angle {fmt(th[k])}: no envelope (a smaller lift or a longer segment)"
                    )
            rho = self.radius_of_curvature(th)
            phi = self.pressure_angle(th)
            kp = int(np.argmax(phi))
            if f.kind == "flat":
                kr = int(np.argmin(rho))
                rmin = float(rho[kr])
                pos = self.face_position(th)
                travel = [min(travel[0], float(pos.min())), max(travel[1], float(pos.max()))]
            else:
                convex = np.where(rho > 0, rho, np.inf)
                kr = int(np.argmin(convex))
                rmin = float(convex[kr])
            segs.append((float(phi[kp]), rmin))
            if phi[kp] > worst_p[0]:
                worst_p = (float(phi[kp]), float(th[kp]), i)
            if rmin < worst_r[0]:
                worst_r = (rmin, float(th[kr]), i)
            if f.kind == "flat" and rmin <= 0:
                raise CamError(
                    f"{prog.describe(i, unit)}: cusp: the flat face's outline has radius of curvature "
                    f"{rmin:.4g} (base_radius + s + s'' must stay positive) at cam angle {fmt(th[kr])}; "
                    "a larger base_radius or a longer segment avoids it"
                )
            if f.kind == "roller" and rmin <= self.rr:
                raise CamError(
                    f"{prog.describe(i, unit)}: undercut: the pitch curve's radius of curvature falls to "
                    f"{rmin:.4g} at cam angle {fmt(th[kr])}, not more than the roller radius {self.rr:g} "
                    "(a larger base_radius, a smaller roller or a longer segment avoids it)"
                )
            if phi[kp] > max_pressure_angle:
                raise CamError(
                    f"{prog.describe(i, unit)}: pressure angle {fmt(float(phi[kp]))} at cam angle "
                    f"{fmt(th[kp])} exceeds max_pressure_angle {fmt(max_pressure_angle)} "
                    "(a larger base_radius or a longer segment lowers it)"
                )
        poly, sag = self.outline_polygon()
        self._check_simple(poly)
        return CamReport(
            worst_p[0],
            worst_p[1],
            worst_p[2],
            worst_r[0],
            worst_r[1],
            worst_r[2],
            segs,
            (travel[0], travel[1]) if f.kind == "flat" else (0.0, 0.0),
            sag,
        )

    def _check_simple(self, poly: Array) -> None:
        """The outline does not cross itself and is turned counter-clockwise (shapely)."""
        from shapely.geometry import Polygon

        p = Polygon(poly)
        if not p.is_valid or p.exterior.is_ccw is False or p.area <= 0:
            raise CamError(
                f"{self.where}: the cam outline crosses itself (the follower cannot stay on it); "
                "a larger base_radius or gentler segments avoid it"
            )
