"""One record per elemental mechanism (:data:`ELEMENTAL`): its motions, parameters, forward kinematics,
builder, contact joint, follower pose and rates; the checks and standalone driver laws read from them."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from planar.core.model import Driver, Part
from planar.errors import InputError
from planar.windup import kinematics as K
from planar.windup import params as P_
from planar.windup import rates as R
from planar.windup.builders import ElementalBuilders, _sub, _xy
from planar.windup.kinematics import Stage

Array = NDArray[np.float64]


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
    lengths = [float(v) for f in fields(P) if f.name.endswith(("r", "h", "w1", "w2")) and np.ndim(v := getattr(P, f.name)) == 0]
    for fld, label, fn in rec.lengths:
        length = float(fn(P))
        if not length > 1e-12:
            raise InputError(f"#{number}.{fld}", getattr(P, fld), f"a positive {label} (got {length:g})")
        lengths.append(length)
    _check_places(number, P, min(lengths, default=1.0))
    ref = rec.forward(P, np.zeros(1) if rec.motions[0] != "OzT" else np.zeros((1, 3)))
    if not ref.valid[0]:
        raise InputError(f"#{number}.params", P, f"a mechanism that assembles at rest ({ref.why})")


def _check_places(number: int, P: Any, smallest: float) -> None:
    """Refuse a position of ``P`` (its vectors but the angles ``D_theta``) that float64 resolves coarser than
    :data:`planar.core.limits.RESOLUTION` of the smallest length ``smallest``: the check a solve makes of the
    built mechanism (:func:`planar.core.limits.check_scale`), made where it is built and naming the parameter
    (``D_jc = (1e300, 0)`` overflowed the forward kinematics at rest)."""
    from dataclasses import fields

    from planar.core.limits import check_coordinates

    for f in fields(P):
        v = getattr(P, f.name)
        if f.name != "D_theta" and np.ndim(v) == 1:
            check_coordinates(f"#{number}.{f.name}", v, smallest)


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
    build: Callable[[ElementalBuilders], tuple[list[Part], list[Any]]]
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


EM = ElementalBuilders
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
