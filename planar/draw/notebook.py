"""Rich display in notebooks: summary tables and inline players for planar's objects.

Importing this module registers an HTML renderer per kind in :mod:`planar.core.display`
(``"mechanism"``, ``"motion"``, ``"scene"``, ``"comparison"``, ``"toy-report"``) and the
player factory ``"animate"`` behind ``Mechanism.animate`` and ``Motion.animate``.
``import planar`` imports it when IPython is loaded, so in Jupyter, JupyterLab, VS Code
and Colab evaluating a mechanism shows a table and its animation.  The module itself is
light (numpy loads at the first display).
"""

from __future__ import annotations

import html
from typing import TYPE_CHECKING, Any

from planar.core.display import register

if TYPE_CHECKING:  # numpy loads with the model: only on first display
    from planar.core.model import Mechanism

__all__ = ["animate", "summary_table"]

#: the player's size inline (pixels)
INLINE_SIZE = (360, 270)


def summary_table(title: str, rows: list[tuple[str, Any]]) -> str:
    """A small HTML table: a caption and ``(label, value)`` rows (values escaped, at most 200 characters each)."""
    body = "".join(
        f"<tr><th style='text-align:left;padding-right:1em'>{html.escape(str(k))}</th>"
        f"<td style='text-align:left'>{html.escape(str(v)[:200])}</td></tr>"
        for k, v in rows
    )
    return f"<table><caption style='text-align:left'><b>{html.escape(title)}</b></caption>{body}</table>"


def animate(
    mech: Mechanism,
    motion: Any,
    width: int = INLINE_SIZE[0],
    height: int = INLINE_SIZE[1],
    trails: list[str] | None = None,
    frame_ms: float | None = None,
) -> Any:
    """An animation player (:class:`planar.draw.player.Player`) of ``motion`` of ``mech``.

    Parameters
    ----------
    mech, motion
        What to draw: one frame per sample of ``motion``.
    width, height
        Size of the drawing in pixels.
    trails
        Named points whose trails are drawn (default: every named point).
    frame_ms
        Milliseconds per frame (default: the motion's own time step, else a cycle in the driver's period).
    """
    from planar.draw.frames import Style
    from planar.draw.player import Player, player_html

    style = Style(width=width, height=height, trails=trails)
    page = player_html(mech, motion, style=style, frame_ms=frame_ms)
    return Player(page, width, height, len(motion), mech.name)


def _driver(mech: Mechanism) -> str:
    d = mech.driver
    law = "turns" if d.amplitude is None else f"oscillates +/- {d.amplitude:.4g}"
    return f"{d.kind} of {d.part}, {law}, {d.rate / 6.283185307179586:.4g} cycles/s"


def _mechanism_rows(mech: Mechanism) -> list[tuple[str, Any]]:
    rows: list[tuple[str, Any]] = [
        ("kind", type(mech).__name__),
        ("parts", ", ".join(p.name for p in mech.parts)),
        ("joints", len(mech.joints)),
        ("driver", _driver(mech)),
        ("size", f"{mech.size:.4g} units"),
    ]
    if mech.points:
        rows.append(("points", ", ".join(mech.points)))
    grashof = getattr(mech, "grashof", None)
    if isinstance(grashof, str):
        rows.append(("Grashof class", grashof))
    return rows


def _mechanism_html(mech: Mechanism) -> str:
    motion = mech.run(samples_per_cycle=48)
    rows = [*_mechanism_rows(mech), ("valid over a cycle", f"{int(motion.valid.sum())} of {len(motion)} samples")]
    return summary_table(mech.name, rows) + animate(mech, motion)._repr_html_()


def _motion_rows(motion: Any) -> list[tuple[str, Any]]:
    import numpy as np

    n = len(motion)
    bad = int(n - np.count_nonzero(motion.valid))
    rows: list[tuple[str, Any]] = [("samples", n), ("parts", len(motion.poses)), ("valid", f"{n - bad} of {n}")]
    if n:
        rows.append(("driver", f"{float(motion.driver.min()):.4g} to {float(motion.driver.max()):.4g}"))
    if motion.t is not None and n:
        rows.append(("time", f"{float(motion.t[0]):.4g} to {float(motion.t[-1]):.4g} s"))
    if bad:
        rows.append(("first invalid", motion.reason(int(np.argmin(motion.valid)))))
    if motion.points:
        rows.append(("points", ", ".join(motion.points)))
    return rows


#: frames shown inline for a long motion (every k-th sample)
MAX_INLINE_FRAMES = 360


def _motion_html(motion: Any) -> str:
    import numpy as np

    name = motion.mechanism.name if motion.mechanism is not None else "motion"
    out = summary_table(f"motion of {name}", _motion_rows(motion))
    if motion.mechanism is not None and len(motion):
        step = max(1, -(-len(motion) // MAX_INLINE_FRAMES))
        shown = motion if step == 1 else motion.take(np.arange(0, len(motion), step))
        out += animate(motion.mechanism, shown)._repr_html_()
    return out


def _scene_html(scene: Any) -> str:
    d = scene.spec.driver
    rows = [
        ("file", scene.path),
        *_mechanism_rows(scene.mechanism),
        ("samples per cycle", d.samples_per_cycle),
        ("cycles", d.cycles if d.cycles is not None else (f"{d.duration} s" if d.duration else 1)),
    ]
    motion = scene.mechanism.run(samples_per_cycle=min(int(d.samples_per_cycle), 120))
    r = scene.spec.render
    player = animate(scene.mechanism, motion, width=min(r.width, 480), height=min(r.height, 360), trails=r.trails)
    return summary_table(f"scene {scene.spec.name}", rows) + player._repr_html_()


def _comparison_html(c: Any) -> str:
    rows: list[tuple[str, Any]] = [
        ("samples", c.samples),
        ("size", f"{c.size:.4g}"),
        ("worst error / size", f"{c.max_rel_error:.3g} (threshold {c.threshold:g})"),
        ("passed", c.passed),
    ]
    worst = sorted(c.parts, key=lambda p: -p.max_rel_error)[:5]
    rows += [(f"part {p.part}", f"max {p.max_rel_error:.3g} of size, angle {p.max_angle_error:.3g} rad") for p in worst]
    if c.torque:
        rows.append(("motor torque differs", f"{c.torque.get('max_rel_diff', float('nan')):.3g} of its peak"))
    rows += [("problem", p) for p in c.problems()[:5]]
    return summary_table(f"pymunk vs analytic: {c.mechanism}", rows)


def _toy_html(t: Any) -> str:
    rows: list[tuple[str, Any]] = [("stages", len(t.stages)), ("not simulated", len(t.not_simulated))]
    if t.torque:
        rows.append(("motor torque differs", f"{t.torque.get('max_rel_diff', float('nan')):.3g} of its peak"))
    rows += [(f"stage {s.stage}", f"{s.pattern}: {'simulated' if s.simulated else s.detail}") for s in t.stages[:12]]
    return summary_table("toy physics", rows)


register("mechanism", _mechanism_html)
register("motion", _motion_html)
register("scene", _scene_html)
register("comparison", _comparison_html)
register("toy-report", _toy_html)
register("animate", animate)
