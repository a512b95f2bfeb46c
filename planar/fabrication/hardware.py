"""Fasteners you can buy: what holds each pin in place, its ends' size, its length, and the BOM's items.

A pin is one of these kinds (``[fabrication] hardware``), sized from ``pin_diameter_mm``:

* ``"rod-eclip"`` (the default): a steel rod (silver steel, drill rod) of the pin's diameter, cut to
  length, a DIN 125 washer and a DIN 6799 e-clip at each end (a groove for the clip near each end).
  Each end stands a washer plus a clip above its layer (1.1 mm for 3 mm), and the rod 0.5 to 0.75 mm past the
  clip (cut to 0.5 mm steps): 1.75 mm for 3 mm on 9 mm of layers (a 12.5 mm rod).
* ``"screw"``: an ISO 7380 button-head screw, a DIN 125 washer under the head and under the nut,
  and a DIN 985 nylon lock nut (the lock nut keeps the joint free without tightening it).  The head end stands
  the head and a washer (2.15 mm for M3).  The length is the shortest sold one whose thread passes the whole nut
  and at least one pitch (ISO 261 coarse: the chamfered end, ISO 4753, so full thread fills the nylon insert);
  where a sold length leaves more, extra washers go under the nut until less than a pitch plus a washer stands
  proud (1 to 2 pitches for M3).  The nut end stands ``length - washer - stack`` (the screw's tip): M3 x 16 on
  9 mm of layers (14.5 mm needed, 16 sold) takes 3 more washers under the nut, the nut's top 6 mm above the
  stack (4 washers 7 mm across and the nut) and the tip 6.5 mm: :func:`screw_fit` gives the numbers of any stack.

Each end is a list of :class:`Tier` (round bodies stacked outwards from the stack's face, each to its height),
which the build check (:mod:`planar.fabrication.check`) and ``plan.json`` use as they are.

The motor shaft (an N20 gearmotor's D shaft: no groove for a clip) is held by its driven part: that part's D
hole fits the shaft's flat (snug: the flat carries the torque) and a drop of glue (cyanoacrylate or epoxy) on the
flat keeps it from sliding off.
The shaft ends flush with its top layer (shorten a longer one): nothing stands above it.  The motor's shaft is
``motor_shaft_mm`` long above its face (default 9: the 3 mm D shaft of Pololu's micro metal gearmotors, the N20
size, is 9 mm long); a plan that needs it longer is the build check's :class:`ShortShaft` (exit 3).

Under the bottom layer hang the motor's body (``motor_body_mm``, default 26: Pololu's gearbox is 9 mm long, the
motor behind it about 15 mm, then its end cap and terminals) and the pins' lower ends.  Each ground plate stands on
two hex standoffs (female-female, M3, nylon or brass) of the shortest length sold that clears them by
``STANDOFF_CLEAR_MM``, held by screws through its mounting holes (and, from below, through a base board).
The motor's two M1.6 face screws pass through ``motor_screw_mm`` clearance holes (1.8 mm: ISO 273's medium series
for M1.6) down into the threaded holes of the gearbox's face.
Sizes are the standard tables' for the diameters makers use (2, 2.5, 3, 4, 5 and 6 mm); another
diameter is an error naming ``pin_diameter_mm``.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from planar.errors import InputError

__all__ = [
    "HARDWARE",
    "Item",
    "PinHardware",
    "ScrewFit",
    "Tier",
    "below_mm",
    "end_height",
    "hardware_of",
    "mounting_items",
    "pin_closing",
    "pin_ends",
    "pin_items",
    "screw_fit",
    "shaft_check",
    "shaft_items",
    "shaft_length",
    "standoff_length",
    "standoffs",
]

#: DIN 125 washer per nominal diameter: (outer diameter, thickness) mm
WASHER = {2.0: (5.0, 0.3), 2.5: (6.0, 0.5), 3.0: (7.0, 0.5), 4.0: (9.0, 0.8), 5.0: (10.0, 1.0), 6.0: (12.0, 1.6)}
#: DIN 6799 e-clip per shaft diameter: (clip size = groove diameter, outer diameter, thickness) mm
ECLIP = {
    2.0: (1.5, 4.25, 0.4),
    2.5: (1.9, 4.8, 0.5),
    3.0: (2.3, 6.0, 0.6),
    4.0: (3.2, 7.3, 0.6),
    5.0: (4.0, 9.3, 0.7),
    6.0: (5.0, 11.3, 0.7),
}
#: ISO 7380 button head: (head diameter, head height) mm
BUTTON = {2.0: (3.5, 1.1), 2.5: (4.7, 1.3), 3.0: (5.7, 1.65), 4.0: (7.6, 2.2), 5.0: (9.5, 2.75), 6.0: (10.5, 3.3)}
#: DIN 985 nylon lock nut: (width across corners, height) mm
NYLOC = {2.0: (4.4, 2.8), 2.5: (5.5, 3.5), 3.0: (6.0, 4.0), 4.0: (7.7, 5.0), 5.0: (8.8, 5.0), 6.0: (11.1, 6.0)}
#: ISO 261 coarse thread pitch per nominal diameter (mm)
PITCH = {2.0: 0.4, 2.5: 0.45, 3.0: 0.5, 4.0: 0.7, 5.0: 0.8, 6.0: 1.0}
#: screw lengths sold (mm)
SCREW_LENGTHS = (4, 5, 6, 8, 10, 12, 14, 16, 18, 20, 22, 25, 28, 30, 35, 40, 45, 50, 55, 60, 70, 80)


@dataclass(frozen=True)
class Item:
    """One line of the shopping list: what, its size, how many."""

    item: str
    size: str
    qty: int


@dataclass(frozen=True)
class Tier:
    """A round body of a pin's end beyond the stack's face: from the tier below it (or the face) out to ``height``
    mm from the face, ``diameter`` mm across (a washer and nut, a head, the thread or rod standing proud)."""

    height: float
    diameter: float


#: one end of a pin: its tiers from the stack's face outwards (heights increasing); empty: nothing stands there
End = tuple[Tier, ...]


def end_height(end: End) -> float:
    """How far an end stands beyond the stack's face (mm): its outermost tier's height (0 for none)."""
    return max((tr.height for tr in end), default=0.0)


@dataclass(frozen=True)
class PinHardware:
    """One kind of fastener: its two ends (tiers beyond the stack: ``ends(d, stack)``, mm), its length and items."""

    name: str
    ends: Callable[[float, float], tuple[End, End]]
    length: Callable[[float, float], float]
    items: Callable[[float, float], list[Item]]
    #: what closes the lower end, fitted first (e.g. ``"washer, e-clip"``)
    lower: str = ""
    #: what closes the upper end, fitted last (e.g. ``"washer, nylon lock nut"``)
    upper: str = ""
    #: the pin's body in the steps (``"rod"``, ``"screw"``)
    body: str = "pin"
    #: the step actions closing the lower end (before the pin goes in) and the upper end (last), ``{pin}`` its name
    fit_lower: str = ""
    fit_upper: str = ""


def _size(d: float, table: dict[float, Any]) -> Any:
    for k, v in table.items():
        if math.isclose(k, d, abs_tol=1e-6):
            return v
    raise InputError("fabrication.pin_diameter_mm", d, "a diameter hardware is sold in: " + ", ".join(f"{k:g}" for k in table))


def _rod_ends(d: float, stack: float) -> tuple[End, End]:
    """Each end: a washer and an e-clip against the face, then the rod past the clip to half the rod's spare length."""
    wd, wt = _size(d, WASHER)
    _, cd, ct = _size(d, ECLIP)
    proud = (_rod_length(d, stack) - stack) / 2
    end = (Tier(wt + ct, max(wd, cd)), Tier(proud, d))
    return end, end


def _rod_length(d: float, stack: float) -> float:
    """Rod length (mm): the stack, a washer and a clip each end and 0.5 mm past each groove, up to 0.5 mm."""
    _, wt = _size(d, WASHER)
    _, _, ct = _size(d, ECLIP)
    return math.ceil((stack + 2 * (wt + ct + 0.5)) * 2 - 1e-9) / 2


def _rod_items(d: float, stack: float) -> list[Item]:
    wd, wt = _size(d, WASHER)
    size, _, _ = _size(d, ECLIP)
    return [
        Item(
            f"steel rod (an e-clip groove {size:g} mm near each end: bought grooved or cut)",
            f"{d:g} mm x {_rod_length(d, stack):g} mm",
            1,
        ),
        Item("washer DIN 125", f"M{d:g} ({wd:g} x {wt:g} mm)", 2),
        Item("e-clip DIN 6799", f"{size:g} (for {d:g} mm shaft)", 2),
    ]


@dataclass(frozen=True)
class ScrewFit:
    """How a screw sits on a stack (mm): its sold ``length`` under the head, the ``washers`` under its nut (one,
    plus any taking up a sold length's spare), the nut's top and the screw's tip above the stack's top face,
    and the thread standing ``proud`` of the nut (at least a pitch, less than a pitch plus a washer)."""

    length: float
    washers: int
    nut_top: float
    tip: float
    proud: float
    head: float


def screw_fit(d: float, stack: float) -> ScrewFit:
    """The screw an M``d`` joint through ``stack`` mm of layers takes, and where its ends stand.

    Head side: a washer and the ISO 7380 head (``head`` mm below the stack).  Nut side: the shortest sold length
    that passes both washers, the DIN 985 nut and one ISO 261 pitch (the chamfered end: the full thread then
    fills the nut's nylon insert); extra DIN 125 washers under the nut take up what the sold length leaves beyond
    that, so the thread stands between one pitch and a pitch plus a washer proud of the nut.  ``tip`` =
    ``length - washer - stack``: the screw's end above the stack's top face (6.5 mm for M3 x 16 on 9 mm).
    """
    _, wt = _size(d, WASHER)
    _, hh = _size(d, BUTTON)
    _, nh = _size(d, NYLOC)
    p = _size(d, PITCH)
    need = stack + 2 * wt + nh + p
    length = next((float(n) for n in SCREW_LENGTHS if n >= need - 1e-9), None)
    if length is None:
        raise InputError("fabrication.hardware", "screw", f"a stack under {SCREW_LENGTHS[-1] - 2 * wt - nh - p:g} mm")
    extra = int(math.floor((length - need) / wt + 1e-9))
    washers = 1 + extra
    nut_top = washers * wt + nh
    tip = length - wt - stack
    return ScrewFit(length, washers, nut_top, tip, tip - nut_top, wt + hh)


def _screw_ends(d: float, stack: float) -> tuple[End, End]:
    """The head end (a washer and the head) and the nut end (washers and the nut, then the thread to its tip)."""
    wd, _ = _size(d, WASHER)
    hd, _ = _size(d, BUTTON)
    ne, _ = _size(d, NYLOC)
    fit = screw_fit(d, stack)
    return (Tier(fit.head, max(wd, hd)),), (Tier(fit.nut_top, max(wd, ne)), Tier(fit.tip, d))


def _screw_length(d: float, stack: float) -> float:
    """Screw length sold (mm): :func:`screw_fit`'s."""
    return screw_fit(d, stack).length


def _screw_items(d: float, stack: float) -> list[Item]:
    wd, wt = _size(d, WASHER)
    fit = screw_fit(d, stack)
    return [
        Item("button head screw ISO 7380", f"M{d:g} x {fit.length:g}", 1),
        Item("washer DIN 125", f"M{d:g} ({wd:g} x {wt:g} mm)", 1 + fit.washers),
        Item("nylon lock nut DIN 985", f"M{d:g}", 1),
    ]


#: fastener kinds by ``[fabrication] hardware``
HARDWARE: dict[str, PinHardware] = {
    "rod-eclip": PinHardware(
        "rod-eclip",
        _rod_ends,
        _rod_length,
        _rod_items,
        "e-clip, washer",
        "washer, e-clip",
        "rod",
        "snap an e-clip into the lower groove of {pin} and slide a washer down the rod onto it",
        "slide a washer down {pin} and snap an e-clip into its upper groove",
    ),
    "screw": PinHardware(
        "screw",
        _screw_ends,
        _screw_length,
        _screw_items,
        "button head screw, washer",
        "washer, nylon lock nut",
        "screw",
        "slide a washer onto {pin} up to its head",
        "slide a washer onto {pin} and turn a nylon lock nut on until it touches (the joint must still turn)",
    ),
}


def hardware_of(settings: Any) -> PinHardware:
    """The fastener kind the settings name (an unknown one is an error naming ``fabrication.hardware``)."""
    name = getattr(settings, "hardware", "rod-eclip")
    if name not in HARDWARE:
        raise InputError("fabrication.hardware", name, "one of " + ", ".join(sorted(HARDWARE)))
    return HARDWARE[name]


def pin_ends(settings: Any, pin: Any) -> tuple[End, End]:
    """``(lower, upper)``: the tiers of a pin's ends beyond its layers (mm from the stack's faces).

    The motor shaft has none: the motor is below it, and it ends flush with its top layer (held by glue).
    """
    if pin.shaft:
        return (), ()
    return hardware_of(settings).ends(pin.diameter_mm, stack_mm(settings, pin))


def stack_mm(settings: Any, pin: Any) -> float:
    """The thickness of the layers a pin spans (mm)."""
    lo, hi = pin.layers or (0, 0)
    return (hi - lo + 1) * settings.thickness_mm


def pin_length(settings: Any, pin: Any) -> float:
    """A pin's length (mm) as bought: a rod cut to length or a screw's sold length."""
    return hardware_of(settings).length(pin.diameter_mm, stack_mm(settings, pin))


def pin_closing(settings: Any, pin: Any) -> tuple[str, str]:
    """``(lower, upper)``: what closes a pin's lower end (fitted first) and its upper end (fitted last), in words."""
    hw = hardware_of(settings)
    return hw.lower, hw.upper


def pin_items(settings: Any, pin: Any) -> list[Item]:
    """What to buy for one pin."""
    return hardware_of(settings).items(pin.diameter_mm, stack_mm(settings, pin))


def shaft_length(settings: Any, pin: Any) -> float:
    """The motor shaft's length above the motor's face (mm): through every layer up to its top one, ending flush,
    rounded up to 0.5 mm (the motor sits under the bottom layer; a longer shaft is shortened to it)."""
    _, hi = pin.layers or (0, 0)
    return math.ceil((hi + 1) * settings.thickness_mm * 2 - 1e-9) / 2


#: what holds the driven part on the motor shaft (an N20's D shaft has no groove for an e-clip)
SHAFT_GLUE = Item("glue (cyanoacrylate or epoxy)", "a drop on the shaft's flat", 1)


def shaft_items(settings: Any, pin: Any) -> list[Item]:
    """What holds the motor shaft in its driven part: a drop of glue on the flat (the D hole is a snug fit)."""
    return [SHAFT_GLUE]


#: metric screw sizes (mm) and the short lengths sold for the small ones
METRIC = (1.6, 2.0, 2.5, 3.0, 4.0, 5.0, 6.0)
SMALL_LENGTHS = (2, 2.5, 3, 4, 5, 6, 8, 10)
#: thread a motor screw engages in an N20 gearmotor's face (its holes are 2-3 mm deep) (mm)
MOTOR_THREAD_MM = 1.5
#: the motor screws' countersunk heads (ISO 7046 M1.6: 3.0 mm across, 0.96 mm tall) sink into the plate's top face,
#: flush: the part turning on the layer above passes over them (pan heads, 1.3 mm proud, would strike it)
MOTOR_SCREW_HEAD = "countersunk head screw ISO 7046"


def _metric_for(hole: float) -> float:
    """The largest metric screw a clearance hole of ``hole`` mm takes (at least 0.1 mm of play)."""
    fits = [m for m in METRIC if m <= hole - 0.1 + 1e-9]
    return fits[-1] if fits else METRIC[0]


def _sold(need: float) -> float:
    """The shortest screw length sold (mm) of at least ``need`` mm."""
    for n in sorted(set(SMALL_LENGTHS) | set(SCREW_LENGTHS)):
        if n >= need - 1e-9:
            return float(n)
    raise InputError("fabrication.thickness_mm", need, f"a plate a screw under {SCREW_LENGTHS[-1]} mm passes")


def motor_items(settings: Any) -> list[Item]:
    """The motor (an N20 gearmotor with the settings' D shaft) and its two face screws: countersunk flush into the
    plate holding it (nothing stands above its top face) and ``MOTOR_THREAD_MM`` into the motor's face (M1.6 for
    the default 1.8 mm holes: check your motor)."""
    m = _metric_for(settings.motor_screw_mm)
    n = _sold(settings.thickness_mm + MOTOR_THREAD_MM)
    return [
        Item(
            "N20 gearmotor",
            f"D {settings.shaft_mm:g} shaft ({settings.shaft_flat_mm:g} across flat) x {settings.motor_shaft_mm:g}, "
            f"face screws {settings.motor_screw_spacing_mm:g} mm apart",
            1,
        ),
        Item(MOTOR_SCREW_HEAD, f"M{m:g} x {n:g} (check your motor)", 2),
    ]


#: hex standoffs (female-female) sold in nylon and brass, M3 (mm)
STANDOFF_LENGTHS = (5, 6, 8, 10, 12, 15, 20, 25, 30, 35, 40, 45, 50, 60)
#: thread a mounting screw engages in its standoff (mm)
STANDOFF_THREAD_MM = 4.0
#: air left between the lowest thing under the plate and the surface the standoffs stand on (mm)
STANDOFF_CLEAR_MM = 1.0


def below_mm(settings: Any, pins: Any, hang: float = 0.0) -> float:
    """How far below the bottom layer's lower face things hang (mm, >= 0): the motor's body (``motor_body_mm``)
    when a pin is the motor shaft, the lower ends (clip and washer, a screw's head) of every pin starting on
    the bottom layer, and ``hang`` (mm: the lowest reach of pieces standing perpendicular below the stack)."""
    low = max(0.0, hang)
    for pp in pins:
        lo, _ = pp.layers or (0, 0)
        if pp.shaft:
            low = max(low, settings.motor_body_mm)
        elif lo == 0:
            low = max(low, end_height(pin_ends(settings, pp)[0]))
    return low


def _mount_screw(settings: Any) -> tuple[float, float, float, float]:
    """The mounting screws: ``(metric size, washer diameter, washer thickness, length sold)`` mm, long enough for
    the plate (or a base board as thick), a washer and ``STANDOFF_THREAD_MM`` into the standoff."""
    m = _metric_for(settings.mounting_hole_mm)
    wd, wt = WASHER.get(m, (2 * m + 1, 0.5))
    return m, wd, wt, _sold(settings.thickness_mm + wt + STANDOFF_THREAD_MM)


def standoffs(settings: Any, below: float) -> tuple[int, float]:
    """``(count, length mm)`` of the standoffs stacked under each mounting hole: one of the shortest length sold
    that holds the plate ``below`` mm plus ``STANDOFF_CLEAR_MM`` above the surface it stands on and leaves 1 mm
    between the ends of the screws turned into it from above and below, or, past the longest, the fewest of one
    length sold that reach it stacked (male-female ones screwed into each other)."""
    _, _, wt, n = _mount_screw(settings)
    need = max(below + STANDOFF_CLEAR_MM, 2 * (n - settings.thickness_mm - wt) + 1.0)
    k = max(1, math.ceil(need / STANDOFF_LENGTHS[-1] - 1e-9))
    return k, float(next(n for n in STANDOFF_LENGTHS if k * n >= need - 1e-9))


def standoff_length(settings: Any, below: float) -> float:
    """The standoffs' height under a mounting hole (mm, stacked ones together): at least ``below`` plus
    ``STANDOFF_CLEAR_MM`` (:func:`standoffs`)."""
    k, n = standoffs(settings, below)
    return k * n


def mounting_items(settings: Any, below: float = 0.0) -> list[Item]:
    """One ground plate's mounting: a hex standoff (female-female; stacked male-female ones where one is too short)
    under each of its two mounting holes, tall enough to clear ``below`` mm (what hangs under the plate:
    :func:`below_mm`), four screws with washers (two down through the plate's mounting holes into the standoffs'
    tops, two up through a base board as thick as the sheet into their bottoms: ``STANDOFF_THREAD_MM`` into the
    standoff)."""
    m, wd, wt, n = _mount_screw(settings)
    k, length = standoffs(settings, below)
    stack = [Item(f"hex standoff M{m:g} female-female (nylon or brass)", f"M{m:g} x {length:g}", 2)]
    if k > 1:  # stacked: male-female ones screwed into each other on the female-female one at the bottom
        stack.append(Item(f"hex standoff M{m:g} male-female (nylon or brass)", f"M{m:g} x {length:g}", 2 * (k - 1)))
    return [
        *stack,
        Item("button head screw ISO 7380", f"M{m:g} x {n:g}", 4),
        Item("washer DIN 125", f"M{m:g} ({wd:g} x {wt:g} mm)", 4),
    ]


class ShortShaft:
    """The build check's verdict on a motor shaft the plan needs longer than the motor's (``motor_shaft_mm``): a
    violation like the collisions of :mod:`planar.fabrication.check` (exit 3, named, outputs still written)."""

    what = "motor shaft too short"

    def __init__(self, pin: str, need: float, have: float, layers: tuple[int, int], at: tuple[float, float]) -> None:
        self.a, self.b = f"motor shaft {pin}", "motor"
        self.need, self.have = need, have
        # too short in every sample of the cycle: first at sample 0, counted as one (no sample is better or worse)
        self.layer, self.sample, self.count, self.depth = layers[1] + 1, 0, 1, need - have
        self.layers = layers
        self.at = at

    def text(self) -> str:
        lo, hi = self.layers
        return (
            f"{self.what}: {self.a} must reach {self.need:g} mm above the motor's face (through layers {lo + 1}-{hi + 1})"
            f" and the motor's shaft is {self.have:g} mm (fabrication.motor_shaft_mm): a motor with a longer shaft "
            "(set motor_shaft_mm to it), a thinner sheet or the driven part on a lower layer"
        )


def shaft_check(settings: Any, pins: Any, at: tuple[float, float] = (0.0, 0.0)) -> list[ShortShaft]:
    """A :class:`ShortShaft` for the motor shaft when the plan needs more than ``motor_shaft_mm`` (else none)."""
    out = []
    for pp in pins:
        if pp.shaft and pp.layers is not None:
            need = shaft_length(settings, pp)
            if need > settings.motor_shaft_mm + 1e-9:
                out.append(ShortShaft(pp.letter, need, settings.motor_shaft_mm, pp.layers, at))
    return out


def driven_part(pin: Any, grounds: Any) -> str:
    """The part the motor shaft turns (the one with the D hole): the first of the shaft's parts that is no ground."""
    return next((p for p in pin.parts if p not in grounds), pin.parts[-1])


def shaft_retention(driven: str) -> str:
    """How the driven part (named) is held on the motor shaft, in words (the BOM, plan.json and the steps say it)."""
    return (
        f"{driven}'s D hole fits the shaft's flat (a snug fit, the flat carries the torque); a drop of glue "
        "(cyanoacrylate or epoxy) on the flat keeps it on the shaft (no e-clip: a D shaft has no groove)"
    )
