"""The assembly planner's last step: pin lengths from the hardware, and empty layers where a pin's end needs room.

:func:`planar.fabrication.layers.plan_assembly` chooses the layers (fewest, no pin crossing a part between its
ends where it can).  A pin's ends (washer and clip, head, nut) stand beyond its outer layers; where the build check
(:mod:`planar.fabrication.check`) finds an end striking a part on the next layer, :func:`settle` opens empty
layers there (every part above moves up; pins crossing the gap get spacer rings) and checks again, until nothing
strikes or no gap helps.  What is left is reported by the check and names the pair.
"""

from __future__ import annotations

import math
import re
from typing import Any

__all__ = ["blocking", "refit_pins", "settle"]

#: rounds of opening gaps before the plan is left to the check's verdict
MAX_ROUNDS = 6

_END = re.compile(r"^(?:pin|motor shaft) (\S+) (lower|upper) end$")


def refit_pins(asm: Any, settings: Any) -> None:
    """Each pin's layer span, spacer count and bought length from the parts' layers (in place)."""
    from planar.fabrication.hardware import pin_length

    for pp in asm.pins:
        ls = sorted({lp for p in pp.parts if (lp := asm.layers.get(p)) is not None})
        lo, hi = (ls[0], ls[-1]) if ls else (0, 0)
        pp.layers = (lo, hi)
        pp.spacers = (hi - lo + 1) - len(ls)
        if not pp.shaft:
            pp.length_mm = pin_length(settings, pp)
    for plane in asm.n_layers:
        used = [v for n, v in asm.layers.items() if v is not None and asm.plane.get(n, "xy") == plane]
        asm.n_layers[plane] = max(used) + 1 if used else 0


def _gaps(asm: Any, violations: list[Any], t: float, ends: dict[str, float]) -> dict[int, int]:
    """Empty layers to open, ``{layer boundary: count}``: an end striking a part above a pin opens the
    boundary above its top layer, one below it the boundary at its bottom layer (parts from there move up)."""
    pins = {pp.letter: pp for pp in asm.pins}
    out: dict[int, int] = {}
    for v in violations:
        if v.what != "pin end strikes part":
            continue
        m = _END.match(v.b) or _END.match(v.a)
        if m is None or m.group(1) not in pins:
            continue
        pp = pins[m.group(1)]
        lo, hi = pp.layers or (0, 0)
        at = hi + 1 if m.group(2) == "upper" else lo
        if at == 0:
            continue
        need = math.ceil(ends[f"{m.group(1)} {m.group(2)}"] / t - 1e-9)
        out[at] = max(out.get(at, 0), need)
    return out


def settle(fab: Any, samples: int = 120, final: int = 240) -> list[Any]:
    """Open empty layers until no pin end strikes a part (at most ``MAX_ROUNDS`` rounds); the check's verdict.

    Changes ``fab.assembly`` in place (layers, pins) and returns the violations of the check at ``final``
    samples per cycle (the rounds check at ``samples``).
    """
    from planar.fabrication.check import build_check
    from planar.fabrication.hardware import end_height, pin_ends

    asm, s = fab.assembly, fab.settings
    refit_pins(asm, s)
    violations = build_check(fab, samples)
    for _ in range(MAX_ROUNDS):
        ends: dict[str, float] = {}  # a longer pin (a gap opened across it) may stand further out
        for pp in asm.pins:
            lower, upper = pin_ends(s, pp)
            ends[f"{pp.letter} lower"], ends[f"{pp.letter} upper"] = end_height(lower), end_height(upper)
        gaps = _gaps(asm, violations, s.thickness_mm, ends)
        if not gaps:
            break
        for name, layer in list(asm.layers.items()):
            if layer is not None and asm.plane.get(name, "xy") == "xy":
                asm.layers[name] = layer + sum(k for at, k in gaps.items() if layer >= at)
        refit_pins(asm, s)
        violations = build_check(fab, samples)
    return build_check(fab, final)


def _pin_letter(body: str) -> str | None:
    m = re.match(r"^(?:pin|motor shaft) (\S+)", body)
    return m.group(1) if m else None


def blocking(asm: Any, violations: list[Any]) -> list[str]:
    """Why no plan clears what is left, one line per blocked pair: the constraint that holds it.

    * two pins colliding that both ride a part they share (one slot, one frame): every layer order passes both
      through that part's layer, so no plan separates them; the tracks must be apart in the design;
    * a pin crossing a part between its ends: every order of the fewest layers (and up to two more) that keeps
      parts whose swept areas overlap apart puts that part between the pin's ends;
    * anything else: the pair and the layer, as the check found it.
    """
    pins = {pp.letter: pp for pp in asm.pins}
    out: list[str] = []
    seen: set[tuple[str, ...]] = set()
    for v in violations:
        pa, pb = _pin_letter(v.a), _pin_letter(v.b)
        if v.what == "pins collide" and pa is not None and pb is not None and pa in pins and pb in pins:
            shared = sorted(set(pins[pa].parts) & set(pins[pb].parts))
            key = ("pins", *sorted((pa, pb)))
            if key in seen:
                continue
            seen.add(key)
            if shared:
                out.append(
                    f"no plan: pins {pa} and {pb} both ride {', '.join(shared)} and come closer than a pin plus the "
                    "clearance; every layer order passes both through its layer (keep their tracks apart in the design)"
                )
            else:
                out.append(f"no plan found: pins {pa} and {pb} collide on layer {v.layer} (their layers overlap)")
        elif v.what in ("pin through part", "spacer strikes part") and (pa in pins or pb in pins):
            letter_ = str(pa if pa in pins else pb)
            part = v.b if pa in pins else v.a
            key = ("through", letter_, part)
            if key in seen:
                continue
            seen.add(key)
            out.append(
                f"no plan: pin {letter_} crosses {part} between its ends; no order of the fewest layers (or up to two "
                f"more) that keeps overlapping parts apart puts {part} outside the pin's layers"
            )
    return out
