"""Drawing: animation frames, their timing, charts, a toy's view.

Every name in ``__all__`` is imported from its module on first use (:func:`planar.core.lazy.attach`).
"""

from planar.core.lazy import attach

__getattr__, __dir__, __all__ = attach(
    __name__,
    {
        "Renderer": "planar.draw.frames",
        "Style": "planar.draw.frames",
        "FramePlan": "planar.draw.timing",
        "plan_frames": "planar.draw.timing",
        "animation_motion": "planar.draw.timing",
        "CHARTS": "planar.draw.charts",
        "available_charts": "planar.draw.charts",
        "write_plot": "planar.draw.charts",
    },
)
