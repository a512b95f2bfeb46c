"""Inverse sizing: the parameter value that gives a requested follower motion range.

The paper sizes each elemental mechanism from its requested motion range (its
"inverse equations", not in the supplement).  Here the forward kinematics is
the authority.  The follower's range over one standalone driver cycle (peak
to peak, 721 samples; the rotation for OzT followers), ``f(v)``, is a
function of one scalar design parameter ``v``; :func:`size_for_range`

1. scans the bracket densely (``SCAN`` values, closed forms only, no part
   building): a value is *valid* when the parameters pass
   :func:`~planar.windup.mechanisms.check_params` and the mechanism works at
   every sample of its cycle (the condition :func:`motion_range` and the
   builders need);
2. refines the scan: the edges of every valid run are bisected against
   validity, and every interior local extreme of ``f`` is polished with a
   bounded scalar minimisation, so the reachable range is that of ``f``
   itself, not of the scan;
3. finds a bracket ``[a, b]`` of neighbouring refined points within one
   valid run with ``f(a) - target`` and ``f(b) - target`` of opposite signs,
   and solves it with :func:`scipy.optimize.brentq` (to round-off).  If
   several exist (``f`` need not be monotone), the root nearest the
   parameter's current value is taken.

A target outside the reachable set is an :class:`InputError` naming it
(``between lo and hi``, one interval per valid run).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from planar.errors import InputError
from planar.windup.mechanisms import ELEMENTAL, ElementalMechanism, check_params, params_for, standalone_driver, standalone_motion

__all__ = ["DESIGN_PARAMETER", "SCAN", "Sizing", "motion_range", "reachable_ranges", "size_for_range"]

#: number of bracket values scanned before refining
SCAN = 257
#: samples of the driver's cycle in :func:`motion_range`
CYCLE_SAMPLES = 721

#: mechanism -> (parameter, component or None, bracket (lo, hi), meaning); parameters in the
#: supplement's frames (``F_o`` relative to ``D_o``, ``F_jc`` to ``F_o``; see ``params.py``)
DESIGN_PARAMETER: dict[int, tuple[str, int | None, tuple[float, float], str]] = {
    1: ("D_jc", 1, (1e-3, 0.2), "cam eccentricity -> stroke"),
    2: ("D_jc", 1, (1e-3, 0.3), "cam eccentricity -> oscillation"),
    3: ("D_jc", 1, (1e-3, 0.08), "cam eccentricity -> step rotation"),
    4: ("F_jc", 0, (-0.78, 2.0), "pin's x offset from the follower origin -> stroke"),
    5: ("F_jc", 0, (-0.9, -0.15), "pin radius about the pivot -> oscillation"),
    6: ("F_o", 0, (0.2, 1.5), "pin's distance from the driver axis -> tilt"),
    # the pin runs at D_jc.y = 0.25: below 0.26 the pivot comes down to the pin's line
    7: ("F_o", 1, (0.26, 1.5), "pivot height above the pin -> oscillation"),
    8: ("F_jh", None, (0.1, 1.2), "tab length -> oscillation"),
    9: ("phi", None, (0.15, 1.4), "slot slant -> tilt"),
    # #10's stroke follows its driver's travel; the arc's geometry hardly changes it (0.200-0.221
    # over the pin's whole x range), so the driver path's x excursion is what sizes it
    10: ("path", 0, (0.01, 0.3), "driver's x travel -> stroke"),
    11: ("F_jc", 1, (-0.6, -0.05), "pin's y offset from the pivot -> oscillation"),
}


def motion_range(mech: ElementalMechanism, samples: int = CYCLE_SAMPLES) -> float:
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


class _Range:
    """``f(v)``: the follower's range with the design parameter at ``v`` (NaN where invalid)."""

    def __init__(self, number: int, name: str, comp: int | None, fixed: dict[str, Any]) -> None:
        self.number, self.name, self.comp = number, name, comp
        self.base = params_for(number, **fixed)
        if not hasattr(self.base, name):
            raise InputError(f"#{number}.parameter", name, f"a parameter of #{number}")
        cur = getattr(self.base, name)
        if (comp is None) != (np.ndim(cur) == 0) or (comp is not None and not 0 <= comp < len(cur)):
            raise InputError(f"#{number}.{name}.component", comp, "None for a scalar parameter, else an index of its components")
        self.current = float(cur if comp is None else cur[comp])
        self.rec = ELEMENTAL[number]

    def params(self, v: float) -> Any:
        if self.comp is None:
            return self.base.replace(**{self.name: float(v)})
        t = list(getattr(self.base, self.name))
        t[self.comp] = float(v)
        return self.base.replace(**{self.name: tuple(t)})

    def __call__(self, v: float) -> float:
        P = self.params(v)
        try:
            check_params(self.number, P)
            drv = standalone_driver(self.number, P)
        except InputError:
            return float("nan")
        u = standalone_motion(self.number, P, drv.value(np.linspace(0, drv.period, CYCLE_SAMPLES)))
        st = self.rec.forward(P, u)
        if not st.valid.all():
            return float("nan")
        out = st.out[:, 2] if st.out.ndim == 2 else st.out
        return float(np.ptp(out))


def _refined_runs(f: _Range, lo: float, hi: float) -> list[tuple[np.ndarray, np.ndarray]]:
    """Valid runs of the scan, each as sorted (values, ranges) with its edges and extremes refined."""
    from scipy.optimize import minimize_scalar

    g = np.linspace(lo, hi, SCAN)
    y = np.array([f(v) for v in g])
    ok = np.isfinite(y)
    runs: list[tuple[np.ndarray, np.ndarray]] = []
    i = 0
    while i < g.size:
        if not ok[i]:
            i += 1
            continue
        j = i
        while j + 1 < g.size and ok[j + 1]:
            j += 1
        xs, ys = list(g[i : j + 1]), list(y[i : j + 1])
        # edges next to an invalid scan value: bisect validity to the boundary
        for edge, out in ((i, i - 1), (j, j + 1)):
            if 0 <= out < g.size:
                a, b = g[edge], g[out]  # a valid, b invalid
                for _ in range(45):
                    m = 0.5 * (a + b)
                    if np.isfinite(f(m)):
                        a = m
                    else:
                        b = m
                xs.append(a)
                ys.append(f(a))
        # interior extremes: polish with a bounded minimisation of -f (max) or f (min)
        for k in range(i + 1, j):
            for sgn in (1.0, -1.0):
                a, b = sgn * (y[k] - y[k - 1]), sgn * (y[k] - y[k + 1])
                if a >= 0 and b >= 0 and (a > 0 or b > 0):
                    r = minimize_scalar(
                        lambda v, s=sgn: -s * f(v),
                        bounds=(g[k - 1], g[k + 1]),
                        method="bounded",
                        options={"xatol": 1e-12 * max(1.0, abs(g[k]))},
                    )
                    if np.isfinite(r.fun):
                        xs.append(float(r.x))
                        ys.append(-sgn * float(r.fun))
        order = np.argsort(xs)
        runs.append((np.asarray(xs)[order], np.asarray(ys)[order]))
        i = j + 1
    return runs


def reachable_ranges(
    number: int,
    parameter: str | None = None,
    component: int | None = None,
    bracket: tuple[float, float] | None = None,
    **fixed: Any,
) -> list[tuple[float, float]]:
    """The follower ranges reachable by varying the design parameter in ``bracket``: one
    ``(lo, hi)`` per run of valid values (see the module's description)."""
    f, lo, hi = _setup(number, parameter, component, bracket, fixed)
    return [(float(ys.min()), float(ys.max())) for _, ys in _refined_runs(f, lo, hi)]


def _setup(
    number: int, parameter: str | None, component: int | None, bracket: tuple[float, float] | None, fixed: dict[str, Any]
) -> tuple[_Range, float, float]:
    if not isinstance(number, (int, np.integer)) or isinstance(number, bool) or number not in DESIGN_PARAMETER:
        raise InputError("mechanism", number, f"an elemental mechanism number, one of {sorted(DESIGN_PARAMETER)}")
    name, comp, br, _ = DESIGN_PARAMETER[int(number)]
    if parameter is not None:
        name, comp = parameter, component
    lo, hi = (float(x) for x in (bracket or br))
    if not (np.isfinite(lo) and np.isfinite(hi) and lo < hi):
        raise InputError(f"#{number}.bracket", bracket, "finite (lo, hi) with lo < hi")
    return _Range(int(number), name, comp, fixed), lo, hi


def size_for_range(
    number: int,
    target: float,
    parameter: str | None = None,
    component: int | None = None,
    bracket: tuple[float, float] | None = None,
    **fixed: Any,
) -> Sizing:
    """The mechanism whose follower range (peak to peak) equals ``target``.

    By default the design parameter of :data:`DESIGN_PARAMETER` is varied
    over its bracket; ``parameter``/``component``/``bracket`` choose another.
    ``fixed`` sets other parameters.  Raises :class:`InputError` naming the
    reachable ranges when ``target`` is outside them.
    """
    from scipy.optimize import brentq

    from planar.core.model import check_positive

    target = check_positive(f"#{number}.target", target, "motion range")
    f, lo, hi = _setup(number, parameter, component, bracket, fixed)
    runs = _refined_runs(f, lo, hi)
    if not runs:
        raise InputError(f"#{number}.{f.name}", (lo, hi), "a bracket where the mechanism works")
    roots: list[float] = []
    for xs, ys in runs:
        d = ys - target
        for k in np.flatnonzero(d == 0):
            roots.append(float(xs[k]))
        for k in np.flatnonzero(np.sign(d[:-1]) * np.sign(d[1:]) < 0):  # signs: a product may overflow
            try:
                roots.append(float(brentq(lambda v: f(v) - target, xs[k], xs[k + 1], xtol=1e-16, rtol=1e-15)))
            except ValueError:  # NaN inside: a sliver of invalid values the scan did not see
                continue
    if not roots:
        spans = " or ".join(f"between {ys.min():.6g} and {ys.max():.6g}" for _, ys in runs)
        raise InputError(
            f"#{number}.target", target, f"a range #{number} can reach by varying {f.name} in [{lo:g}, {hi:g}]: {spans}"
        )
    v = min(roots, key=lambda r: abs(r - f.current))
    mech = ElementalMechanism(int(number), f.params(v))
    return Sizing(mech, f.name, float(v), motion_range(mech))
