"""The homework figures of a mechanism: mobility, Grashof class, toggles, transmission, strokes, time ratio.

:func:`info` reads any one-input mechanism the same way, by asking it:

* **degrees of freedom** by Gruebler/Kutzbach, ``M = 3 (n - 1) - 2 j1 - j2``,
  with ``n`` the moving parts plus one ground (every ground part is one
  body), ``j1`` the joints that remove two freedoms (pivots, slides) and ``j2``
  those that remove one (a pin in a slot, a cam or gear contact).  Each joint
  kind's count is an entry of :data:`CONSTRAINTS`; an unknown kind is an error.
* **Grashof class** and **which link turns fully**, when the mechanism states
  a class (a four-bar's ``grashof``); otherwise which parts turn fully over a
  cycle, measured.
* **toggle angles**: the driver angles where the input cannot go on (the ends
  of the valid range: a four-bar says them in closed form, any other
  mechanism's are found on the sampled motion);
* **outputs**: every part other than the input joined to the ground.  Each
  output that rocks or slides has a swing (degrees) or stroke (model units),
  the two driver angles where it stops and turns back (its dead centres,
  refined to 1e-12 rad) and its **time ratio**: the driver angle of the slower
  (working) stroke over that of the faster (return) one, ``>= 1``;
* **transmission angles** of every dyad (:func:`planar.analysis.rates.transmission_angles`):
  the range over the valid samples and the driver angle where the angle is
  farthest from 90 degrees;
* the motion's **valid range** (driver angle intervals that assemble);
* for a wind-up toy, its stages and chains.

Angles are reported in degrees at the edges (record and text), counter-clockwise
positive; lengths in model units.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field
from typing import TYPE_CHECKING, Any

from planar.errors import InputError

if TYPE_CHECKING:
    import numpy as np
    from numpy.typing import NDArray

    from planar.core.model import Mechanism

    Array = NDArray[np.float64]

__all__ = ["CONSTRAINTS", "Info", "Output", "Transmission", "info"]

#: freedoms each joint kind removes between its two parts (Gruebler/Kutzbach): a consumer's registry
CONSTRAINTS: dict[str, int] = {
    "pivot": 2,
    "slide": 2,
    "pin-in-slot": 1,
    "pin-in-arc-slot": 1,
    "cam-on-line": 1,
    "cam-profile": 1,
    "gear": 1,
    "skew-contact": 1,
    "shared-x": 1,
    "keyed-shaft": 3,
}

#: the links of a four-bar that turn fully relative to the others, by Grashof class
FULL_TURN = {
    "crank-rocker": ["crank"],
    "double-crank": ["crank", "rocker"],
    "rocker-crank": ["rocker"],
    "double-rocker": ["coupler"],
    "change-point": ["crank", "coupler", "rocker"],
    "non-Grashof": [],
}

#: what each class's full turns are relative to (``planar info``'s text)
FULL_TURN_NOTE = {
    "crank-rocker": "the crank turns fully relative to the ground and the coupler; the rocker rocks",
    "double-crank": "the ground is the shortest link: crank and rocker both turn fully relative to it",
    "rocker-crank": "the rocker turns fully relative to the ground and the coupler; the crank (the input) rocks",
    "double-rocker": (
        "the coupler (the shortest link) turns fully relative to the crank, the rocker and the ground; "
        "crank and rocker only rock, so a crank driven through a full turn assembles only over the valid range"
    ),
    "change-point": "every link can turn fully, through change points where the linkage may switch circuit",
    "non-Grashof": "a triple rocker: every link only rocks relative to its neighbours",
}

#: samples of one driver cycle the figures are found on (then refined)
SAMPLES = 3600


@dataclass
class Output:
    """A part joined to the ground other than the input: how it moves over one driver cycle.

    ``motion`` is ``"turns"`` (a full turn per cycle), ``"rocks"`` (angle swings, ``swing`` in degrees)
    or ``"slides"`` (no rotation, ``swing`` is the stroke in model units).  ``dead_centres`` are the driver
    angles (degrees, in ``[0, 360)``) where it stops and turns back; ``time_ratio`` the driver angle of
    the slower stroke over the faster's (``>= 1``; None when it turns or the input does not turn fully).
    ``ranges``: when a full-turn driver assembles only over parts of its turn, ``(from, to, swing)`` per
    assemblable driver range (degrees; the swing in degrees or model units as ``swing``), and ``swing``
    is the largest of them.
    """

    part: str
    motion: str
    swing: float
    dead_centres: list[float] = field(default_factory=list)
    time_ratio: float | None = None
    working_deg: float | None = None
    return_deg: float | None = None
    ranges: list[tuple[float, float, float]] = field(default_factory=list)


@dataclass
class Transmission:
    """A dyad's transmission angle (degrees) over the valid samples; ``worst_at``: driver angle (degrees)
    where it is farthest from 90 degrees, ``worst`` its value there."""

    joint: str
    low: float
    high: float
    worst: float
    worst_at: float


@dataclass
class Info:
    """What :func:`info` found (degrees and model units; see the module's notes)."""

    name: str
    kind: str
    parts: int
    joints: int
    dof: int
    driver: str
    grashof: str | None
    turns_fully: list[str]
    toggle_angles: list[float]
    valid_range: list[tuple[float, float]]
    outputs: list[Output]
    transmission: list[Transmission]
    time_ratio: float | None
    stages: list[str] = field(default_factory=list)
    chains: dict[str, list[list[str]]] = field(default_factory=dict)
    #: the driver angles (degrees, in the valid range's terms) a rocking rotary driver swings between; None when it
    #: turns fully or slides
    driven_swing: tuple[float, float] | None = None

    def as_dict(self) -> dict[str, Any]:
        """A JSON-ready dict of every field."""
        return asdict(self)

    def __str__(self) -> str:
        return format_info(self)


def _output_coordinate(poses: Array) -> tuple[str, Array, Any]:
    """How a part joined to the ground moves: ``("turns"|"rocks", unwrapped angle)`` or ``("slides", position
    along its line, direction)``."""
    import numpy as np

    ang = np.unwrap(poses[:, 2])
    span = float(np.ptp(ang))
    if span > 1e-9:
        return ("turns" if abs(ang[-1] - ang[0]) > math.pi else "rocks"), ang, None
    xy = poses[:, :2] - poses[:, :2].mean(0)
    _, _, vt = np.linalg.svd(xy, full_matrices=False)
    return "slides", xy @ vt[0], vt[0]


def _refine(f, q0: float, step: float, sign: float) -> tuple[float, float]:
    """The driver angle near ``q0`` (within ``step``) where ``sign * f`` is largest, and ``f`` there.

    Found as the root of the central difference ``f(q + h) - f(q - h)`` (h = 1e-5 rad) by Brent's
    method: an extremum located by its value alone is only good to the square root of the rounding
    (1e-8 rad), its slope's zero to about 1e-11.
    """
    from scipy.optimize import brentq, minimize_scalar

    h = 1e-5

    def slope(q: float) -> float:
        return f(q + h) - f(q - h)

    lo, hi = q0 - step, q0 + step
    if slope(lo) * slope(hi) < 0:
        x = float(brentq(slope, lo, hi, xtol=1e-14, rtol=1e-15))
    else:  # no sign change inside (a flat stretch): the largest value found
        r = minimize_scalar(lambda q: -sign * f(q), bounds=(lo, hi), method="bounded", options={"xatol": 1e-12})
        x = float(r.x)
    return x, float(f(x))


def _output(mech: Mechanism, part: str, q: Array, poses: Array, full_input: bool) -> Output:
    """Swing or stroke, dead centres and time ratio of ``part`` over the driver cycle ``q`` (radians)."""
    import numpy as np

    how, coord, axis = _output_coordinate(poses)
    if how == "turns" or not full_input:
        swing = 360.0 if how == "turns" else float(np.ptp(coord))
        return Output(part, how, math.degrees(swing) if how == "rocks" else swing)
    centre = poses[:, :2].mean(0)

    def f(x: float) -> float:
        p = mech.solve(np.array([x])).poses[part][0]
        if axis is None:  # the angle, unwrapped near the sampled one
            a = float(p[2])
            return a + 2 * math.pi * round((ref - a) / (2 * math.pi))
        return float((p[:2] - centre) @ axis)

    step = float(q[1] - q[0])
    ref = float(coord[int(np.argmax(coord))])
    q_hi, hi = _refine(f, float(q[int(np.argmax(coord))]), step, 1.0)
    ref = float(coord[int(np.argmin(coord))])
    q_lo, lo = _refine(f, float(q[int(np.argmin(coord))]), step, -1.0)
    forward = (q_hi - q_lo) % (2 * math.pi)  # driver angle from the low to the high dead centre
    back = 2 * math.pi - forward
    swing = math.degrees(hi - lo) if how == "rocks" else hi - lo
    return Output(
        part,
        how,
        swing,
        sorted(math.degrees(v % (2 * math.pi)) for v in (q_lo, q_hi)),
        max(forward, back) / min(forward, back),
        math.degrees(max(forward, back)),
        math.degrees(min(forward, back)),
    )


def _edge(mech: Mechanism, good: float, bad: float) -> float:
    """The driver angle between ``good`` (assembles) and ``bad`` (does not) where assembly ends, to 1e-12 rad."""
    import numpy as np

    for _ in range(60):
        if abs(bad - good) < 1e-12:
            break
        mid = 0.5 * (good + bad)
        if bool(mech.solve(np.array([mid])).valid[0]):
            good = mid
        else:
            bad = mid
    return good


def _runs(mech: Mechanism, q: Array, ok: Any) -> list[Array]:
    """The driver angles of each run of assemblable samples of a full turn ``q``, with the run's ends refined."""
    import numpy as np

    start = int(np.argmin(ok))  # an invalid sample: no run is cut by the roll
    n = len(q)
    idx = np.roll(np.arange(n), -start)
    qq = q[idx] + 2 * math.pi * (idx < start)  # increasing through the roll
    okr = ok[idx]
    d = np.diff(np.concatenate([[0], okr.astype(int), [0]]))
    runs = []
    for s, e in zip(np.flatnonzero(d == 1), np.flatnonzero(d == -1)):
        lo = _edge(mech, float(qq[s]), float(qq[s - 1]))  # s >= 1: sample 0 is invalid
        hi = _edge(mech, float(qq[e - 1]), float(qq[e]) if e < n else float(qq[0]) + 2 * math.pi)
        runs.append(np.concatenate([[lo], qq[s:e], [hi]]))
    return runs


def _partial_output(mech: Mechanism, part: str, runs: list[Array]) -> Output:
    """Swing or stroke of ``part`` over each run of driver angles ``runs`` (radians) that assembles."""
    import numpy as np

    ranges, hows = [], []
    for r in runs:
        how, coord, _ = _output_coordinate(mech.solve(r).poses[part])
        if how == "turns" and float(np.ptp(coord)) < 2 * math.pi:  # over part of a turn: a swing, however wide
            how = "rocks"
        swing = 360.0 if how == "turns" else float(np.ptp(coord))
        hows.append(how)
        ranges.append((math.degrees(r[0]) % 360.0, math.degrees(r[-1]) % 360.0, math.degrees(swing) if how == "rocks" else swing))
    how = "turns" if "turns" in hows else ("rocks" if "rocks" in hows else "slides")
    return Output(part, how, max((v[2] for v in ranges), default=0.0), ranges=ranges)


def _dof(mech: Mechanism) -> int:
    """Gruebler/Kutzbach mobility: 3 (n - 1) - sum of the freedoms each joint removes (ground parts are one body).

    A wind-up toy is counted as assembled (one frame, the cams keyed to one shaft,
    :func:`planar.toys.assembly.toy_assembly`), not as its stages' side-by-side panels."""
    if isinstance(getattr(mech, "cams", None), dict):
        from planar.toys.assembly import toy_assembly

        mech = toy_assembly(mech)
    ground = {p.name for p in mech.parts if p.ground}
    n = len(mech.parts) - len(ground) + (1 if ground else 0)
    removed = 0
    for j in mech.joints:
        kind = type(j).kind
        if kind not in CONSTRAINTS:
            raise InputError(f"{mech.name}.joints.{j.name}", kind, f"a joint kind info knows, one of {sorted(CONSTRAINTS)}")
        if {j.a, j.b} <= ground:
            continue  # two ground parts held together: one body already
        removed += CONSTRAINTS[kind]
    return 3 * (n - 1) - removed


def _intervals(q: Array, ok: Any) -> list[tuple[float, float]]:
    """Runs of ``ok`` over the cycle ``q`` (radians) as degree intervals (a run through 0 is joined up)."""
    import numpy as np

    if ok.all():
        return [(0.0, 360.0)]
    if not ok.any():
        return []
    d = np.diff(np.concatenate([[0], ok.astype(int), [0]]))
    starts, ends = np.flatnonzero(d == 1), np.flatnonzero(d == -1) - 1
    runs = [(math.degrees(q[s]), math.degrees(q[e])) for s, e in zip(starts, ends)]
    if ok[0] and ok[-1] and len(runs) > 1:
        runs = [(runs[-1][0] - 360.0, runs[0][1]), *runs[1:-1]]
    return runs


def _transmission(mech: Mechanism, q: Array, ok: Any) -> list[Transmission]:
    import numpy as np

    from planar.analysis.rates import transmission_angles

    out = []
    for name, mu in transmission_angles(mech, q).items():
        mu = np.asarray(mu)
        if not ok.any():
            continue
        m = np.degrees(mu[ok])
        worst = int(np.argmax(np.abs(m - 90.0)))
        out.append(Transmission(name, float(m.min()), float(m.max()), float(m[worst]), float(np.degrees(q[ok][worst]))))
    return out


def info(mech: Mechanism, samples: int = SAMPLES) -> Info:
    """The homework figures of ``mech`` over one driver cycle (see the module's notes).

    Parameters
    ----------
    mech
        Any one-input mechanism (a four-bar, a linkage, a cam, a wind-up toy ...).
    samples
        Samples of the cycle the figures are found on; extremes are refined between them.

    Returns
    -------
    Info
        Degrees of freedom, Grashof class, toggle angles (degrees), valid range, each output's swing
        (degrees) or stroke (model units) with its dead centres and time ratio, transmission angles.

    Examples
    --------
    >>> from planar.linkages.fourbar import FourBar
    >>> r = info(FourBar(ground=4, crank=1, coupler=3.5, rocker=3))
    >>> r.dof, r.grashof, r.turns_fully
    (1, 'crank-rocker', ['crank'])
    """
    import numpy as np

    from planar.core.fields import check_kind, check_number
    from planar.core.limits import check_count
    from planar.core.model import Mechanism

    check_kind("info(mech)", mech, Mechanism, "a Mechanism (a four-bar, a linkage, a cam, a wind-up toy ...)")
    if check_number("info(samples)", samples, integer=True) < 8:
        raise InputError("info(samples)", samples, "a whole number of samples, 8 or more")
    samples = check_count("samples", "info(samples)", samples, "samples")
    d = mech.driver
    full_input = d.kind == "rotation" and d.amplitude is None
    if full_input:
        q: Array = np.asarray(d.phase + np.arange(samples) * (2 * math.pi / samples), dtype=np.float64)
    else:
        q = d.value(np.arange(samples) * (d.period / samples))
    motion = mech.solve(q)
    ok = np.asarray(motion.valid, bool)
    grashof = getattr(mech, "grashof", None)
    ranges_fn = getattr(mech, "input_range", None)  # a four-bar states its range in closed form
    if ranges_fn is not None:
        valid_range = [(math.degrees(a), math.degrees(b)) for a, b in ranges_fn()]
    else:
        valid_range = _intervals(q - d.phase if full_input else q, ok)
    toggles_fn = getattr(mech, "toggle_angles", None)
    if toggles_fn is not None:
        toggles = [math.degrees(v) for v in np.asarray(toggles_fn())]
    else:
        toggles = sorted({v % 360.0 for iv in _intervals(q, ok) for v in iv} - {0.0, 360.0}) if not ok.all() else []
    ground = {p.name for p in mech.parts if p.ground}
    joined = {j.b if j.a in ground else j.a for j in mech.joints if (j.a in ground) != (j.b in ground)}
    outputs = []
    runs = _runs(mech, q, ok) if full_input and ok.any() and not ok.all() else []
    for p in mech.parts:
        if p.name not in joined or p.name == d.part:
            continue
        if ok.all():
            outputs.append(_output(mech, p.name, q, motion.poses[p.name], full_input))
        elif runs:  # over the ranges the linkage assembles (a double rocker's input)
            outputs.append(_partial_output(mech, p.name, runs))
    if isinstance(grashof, str):
        turns = list(FULL_TURN.get(grashof, []))
    else:
        turns = [p.name for p in mech.parts if not p.ground and _output_coordinate(motion.poses[p.name])[0] == "turns"]
    ratios = [o for o in outputs if o.time_ratio is not None]
    cams = getattr(mech, "cams", None)
    return Info(
        name=mech.name,
        kind=type(mech).__name__,
        parts=len(mech.parts),
        joints=len(mech.joints),
        dof=_dof(mech),
        driver=f"{d.kind} of part {d.part}",
        grashof=grashof if isinstance(grashof, str) else None,
        turns_fully=turns,
        toggle_angles=toggles,
        valid_range=valid_range,
        outputs=outputs,
        transmission=_transmission(mech, q, ok),
        time_ratio=ratios[0].time_ratio if ratios else None,
        stages=[f"{s.cam}: {' -> '.join(s.key)} ({s.mech.name})" for s in mech.stages] if cams else [],
        chains={cam: [list(c) for c in chains] for cam, chains in cams.items()} if isinstance(cams, dict) else {},
        driven_swing=_driven_swing(d),
    )


def _driven_swing(d: Any) -> tuple[float, float] | None:
    """The driver angles (degrees) a rocking rotary driver ``d`` swings between: ``centre -+ amplitude``."""
    if d.kind != "rotation" or d.amplitude is None:
        return None
    c, a = math.degrees(d.centre), math.degrees(abs(d.amplitude))
    return (c - a, c + a)


def _like_the_range(toggles: list[float], valid_range: list[tuple[float, float]]) -> list[float]:
    """The toggle angles (degrees in ``[0, 360)``) as the valid range's ends name them (a range from -102.6 to
    102.6 deg has its toggles at -102.6 and 102.6 deg, not 257.4 and 102.6), in the range's order."""
    ends = [e for iv in valid_range for e in iv]
    out = [next((e for e in ends if abs((e - a + 180.0) % 360.0 - 180.0) < 1e-6), a) for a in toggles]
    return sorted(out)


def _within_the_range(swing: tuple[float, float], valid_range: list[tuple[float, float]]) -> tuple[float, float]:
    """A driven swing (degrees) turned by whole turns into the valid range interval holding it, so both are said in
    the same terms (as given when none holds it)."""
    lo, hi = swing
    for a, b in valid_range:
        k = math.floor((lo - a) / 360.0 + 1e-12)
        if a - 1e-9 <= lo - 360.0 * k and hi - 360.0 * k <= b + 1e-9:
            return lo - 360.0 * k, hi - 360.0 * k
    return lo, hi


def format_info(r: Info) -> str:
    """``r`` as the text ``planar info`` prints."""
    lines = [
        f"{r.name} ({r.kind}): {r.parts} parts, {r.joints} joints, driver: {r.driver}",
        f"degrees of freedom (Gruebler/Kutzbach): {r.dof}",
    ]
    if r.grashof is not None:
        note = FULL_TURN_NOTE.get(r.grashof)
        lines.append(
            f"Grashof class: {r.grashof}; turns fully: {', '.join(r.turns_fully) or 'no link'}" + (f" ({note})" if note else "")
        )
    elif r.turns_fully:
        lines.append(f"turns fully: {', '.join(r.turns_fully)}")
    if r.toggle_angles:
        shown = _like_the_range(r.toggle_angles, r.valid_range)
        lines.append("toggle (limit) driver angles: " + ", ".join(f"{a:.4f} deg" for a in shown))
    lines.append("valid range: " + (", ".join(f"{a:.4g} to {b:.4g} deg" for a, b in r.valid_range) or "none"))
    if r.driven_swing is not None:  # a trial read only the whole valid range of a scene whose driver rocks
        lo, hi = _within_the_range(r.driven_swing, r.valid_range)
        lines.append(f"driven swing (the scene's driver rocks): {lo:.4g} to {hi:.4g} deg")
    for o in r.outputs:
        what = {"turns": "turns fully", "rocks": f"rocks {o.swing:.6g} deg", "slides": f"slides, stroke {o.swing:.6g}"}
        line = f"output {o.part}: {what[o.motion]}"
        if o.ranges:
            unit = "deg" if o.motion == "rocks" else ""
            line = line.replace("rocks", "rocks up to").replace("stroke", "stroke up to")
            line += (
                " (over the driver ranges that assemble: "
                + ", ".join(f"{sw:.6g}{' ' + unit if unit else ''} over {a:.4g} to {b:.4g} deg" for a, b, sw in o.ranges)
                + ")"
            )
        if o.dead_centres:
            line += "; dead centres at driver " + ", ".join(f"{a:.4f}" for a in o.dead_centres) + " deg"
        if o.time_ratio is not None:
            line += f"; time ratio {o.time_ratio:.6g} ({o.working_deg:.4f} / {o.return_deg:.4f} deg)"
        lines.append(line)
    for t in r.transmission:
        lines.append(
            f"transmission angle at {t.joint}: {t.low:.4f} to {t.high:.4f} deg, worst {t.worst:.4f} deg "
            f"at driver {t.worst_at:.4f} deg"
        )
    if r.stages:
        lines.append(f"stages: {', '.join(r.stages)}")
    for cam, chains in r.chains.items():
        lines.append(f"{cam} cam chains: " + "; ".join(" ".join(c) for c in chains))
    return "\n".join(lines)
