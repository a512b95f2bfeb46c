"""Inverse sizing: the parameter value that gives a requested follower motion range.

The paper sizes each elemental mechanism from its requested motion range (its
"inverse equations", not in the supplement).  Here the forward kinematics is
the authority: the follower's range over one driver cycle is a monotone
function of one scalar design parameter, whose value is found by a bracketed
root find (``scipy.optimize.brentq`` is not needed: a safeguarded bisection on
the monotone function, to 1e-12 relative).  Monotonicity is checked on the
bracket; a target outside the reachable range is an error that states it.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import InputError
from .mechanisms import ElementalMechanism, params_for

__all__ = ["DESIGN_PARAMETER", "motion_range", "size_for_range", "Sizing"]

#: mechanism -> (parameter, component or None, bracket (lo, hi), meaning)
DESIGN_PARAMETER: dict[int, tuple[str, int | None, tuple[float, float], str]] = {
    1: ("D_jc", 1, (1e-3, 0.2), "cam eccentricity -> stroke"),
    2: ("D_jc", 1, (1e-3, 0.3), "cam eccentricity -> oscillation"),
    3: ("D_jc", 1, (1e-3, 0.08), "cam eccentricity -> step rotation"),
    4: ("F_jc", 0, (-0.75, -0.02), "pin's x offset from the follower origin -> stroke"),
    5: ("F_jc", 0, (-0.9, -0.15), "pin radius about the pivot -> oscillation"),
    6: ("F_o", 0, (0.2, 1.5), "pin's distance from the driver axis -> tilt"),
    7: ("F_o", 1, (0.45, 1.5), "pivot height above the pin -> oscillation"),
    8: ("F_jh", None, (0.1, 1.2), "tab length -> oscillation"),
    9: ("phi", None, (0.15, 1.4), "slot slant -> tilt"),
    # #10's stroke follows its driver's travel; the arc's geometry hardly changes it (0.200-0.221
    # over the pin's whole x range), so the driver path's x excursion is what sizes it
    10: ("path", 0, (0.01, 0.3), "driver's x travel -> stroke"),
    11: ("F_jc", 1, (-0.6, -0.3), "pin's y offset from the pivot -> oscillation"),
}


def _with(number: int, name: str, comp: int | None, value: float, extra: dict[str, Any]) -> ElementalMechanism:
    base = params_for(number, **extra)
    if comp is None:
        return ElementalMechanism(number, base.replace(**{name: float(value)}))
    v = list(getattr(base, name))
    v[comp] = float(value)
    return ElementalMechanism(number, base.replace(**{name: tuple(v)}))


def motion_range(mech: ElementalMechanism, samples: int = 721) -> float:
    """Peak-to-peak follower motion over one standalone driver cycle (rotation for OzT)."""
    q = mech.driver.value(np.linspace(0, mech.driver.period, samples))
    st = mech.stage(q)
    if not st.valid.all():
        raise InputError(f"#{mech.number}", mech.params, f"a mechanism valid over its whole cycle ({st.why})")
    out = st.out[:, 2] if st.out.ndim == 2 else st.out
    return float(np.ptp(out))


@dataclass(frozen=True)
class Sizing:
    mechanism: ElementalMechanism
    parameter: str
    value: float
    achieved: float


def size_for_range(number: int, target: float, parameter: str | None = None, component: int | None = None,
                   bracket: tuple[float, float] | None = None, **fixed: Any) -> Sizing:
    """The mechanism whose follower range (peak to peak) equals ``target``.

    By default the design parameter of :data:`DESIGN_PARAMETER` is varied;
    ``parameter``/``component``/``bracket`` choose another.  ``fixed`` sets
    other parameters.  Raises :class:`InputError` naming the reachable range
    when ``target`` is outside it.
    """
    if number not in DESIGN_PARAMETER:
        raise InputError("mechanism", number, "an elemental mechanism number 1-11")
    if not np.isfinite(target) or target <= 0:
        raise InputError(f"#{number}.target", target, "a positive motion range")
    name, comp, br, _ = DESIGN_PARAMETER[number]
    if parameter is not None:
        name, comp = parameter, component
    lo, hi = bracket or br

    def f(v: float) -> float:
        try:
            return motion_range(_with(number, name, comp, v, fixed))
        except InputError:
            return float("nan")

    grid = np.linspace(lo, hi, 33)
    vals = np.array([f(v) for v in grid])
    ok = np.isfinite(vals)
    if ok.sum() < 2:
        raise InputError(f"#{number}.{name}", (lo, hi), "a bracket where the mechanism works")
    g, v = grid[ok], vals[ok]
    d = np.diff(v)
    if not (np.all(d > 0) or np.all(d < 0)):
        raise InputError(f"#{number}.{name}", (lo, hi), "a bracket on which the range is monotone")
    vmin, vmax = float(v.min()), float(v.max())
    if not (vmin <= target <= vmax):
        raise InputError(f"#{number}.target", target,
                         f"a range #{number} can reach by varying {name}: between {vmin:.6g} and {vmax:.6g}")
    i = int(np.searchsorted(v if d[0] > 0 else -v, target if d[0] > 0 else -target))
    a, b = g[max(i - 1, 0)], g[min(i, len(g) - 1)]
    fa = f(a) - target
    for _ in range(200):
        m = 0.5 * (a + b)
        fm = f(m) - target
        if fm == 0 or abs(b - a) <= 1e-13 * max(1.0, abs(m)):
            break
        if np.sign(fm) == np.sign(fa):
            a, fa = m, fm
        else:
            b = m
    mech = _with(number, name, comp, m, fixed)
    return Sizing(mech, name, float(m), motion_range(mech))
