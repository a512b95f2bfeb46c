"""Whether a scene's driver can run its cycle, and what to change when it cannot."""

from __future__ import annotations

import math
import re
from typing import Any

import numpy as np

from planar.physics.settings import SimulationError

__all__ = ["check_cycle"]

#: driver values per turn searched for the range that assembles
_SWEEP = 3600


def _unit(scene: Any, q: float) -> str:
    """A driver value in the scene's unit: degrees when ``angle_unit = "deg"``."""
    if scene.mechanism.driver.kind == "rotation" and scene.spec.angle_unit == "deg":
        return f"{math.degrees(q):.4g} deg"
    return f"{q:.6g} rad" if scene.mechanism.driver.kind == "rotation" else f"{q:.6g}"


def _assembles(scene: Any, q0: float) -> tuple[float, float] | None:
    """The driver values ``lo <= q0 <= hi`` that assemble without a break, from a sweep of one turn each way."""
    mech = scene.mechanism
    step = 2 * math.pi / _SWEEP
    fwd = q0 + step * np.arange(_SWEEP + 1)
    back = q0 - step * np.arange(_SWEEP + 1)
    ok_f = np.asarray(mech.solve(fwd).valid, bool)
    ok_b = np.asarray(mech.solve(back).valid, bool)
    if not ok_f[0]:
        return None
    hi = fwd[np.argmin(ok_f) - 1] if not ok_f.all() else math.inf
    lo = back[np.argmin(ok_b) - 1] if not ok_b.all() else -math.inf
    return float(lo), float(hi)


def check_cycle(scene: Any, motion: Any) -> None:
    """Raise :class:`SimulationError` when the scene's analytic motion breaks, saying what to change.

    The message names the first invalid sample, the driver value there in the
    scene's unit (degrees for ``angle_unit = "deg"``), the range of driver
    values that assembles, and the two ways out: a rocking input inside that
    range (``[driver] amplitude`` and ``centre``, with values) or other link
    lengths (a crank turns fully when shortest + longest <= the sum of the
    other two links, Grashof).
    """
    if motion.valid.all():
        return
    from planar.scene.build import _ROCKING

    mech = scene.mechanism
    i = int(np.flatnonzero(~motion.valid)[0])
    q = float(np.asarray(mech.driver.value(motion.t[i : i + 1]))[0])
    reason = re.sub(r"at driver value [-+0-9.eE]+", f"at driver value {_unit(scene, q)}", motion.reason(i))
    at = "" if "driver value" in reason else f"driver at {_unit(scene, q)}: "
    msg = f"{mech.name}: the analytic motion is invalid at sample {i} ({at}{reason})"
    span = _assembles(scene, float(np.asarray(mech.driver.value(motion.t[:1]))[0])) if mech.driver.kind == "rotation" else None
    lengths = "other link lengths (for a crank that turns fully: shortest + longest <= the sum of the other two)"
    if span is not None and all(map(math.isfinite, span)) and scene.spec.mechanism.type in _ROCKING:
        lo, hi = span
        centre, amp = 0.5 * (lo + hi), 0.45 * (hi - lo)  # 90 % of the range: clear of the toggles at its ends
        deg = scene.spec.angle_unit == "deg"
        val = (lambda x: f"{math.degrees(x):.4g}") if deg else (lambda x: f"{x:.4g}")
        msg += (
            f"; it assembles for driver values from {_unit(scene, lo)} to {_unit(scene, hi)}: make the input rock "
            f"inside that range ([driver] amplitude = {val(amp)}, centre = {val(centre)}"
            f"{'' if deg else ', radians'}) or choose {lengths}"
        )
    else:
        msg += f"; choose {lengths}"
    raise SimulationError(msg)
