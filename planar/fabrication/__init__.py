"""Laser-cut parts: outlines, pins, tabs, layers and the assembly plan, nesting, the build check.

Every name in ``__all__`` is imported from its module on first use (:func:`planar.core.lazy.attach`).
"""

from planar.core.lazy import attach

__getattr__, __dir__, __all__ = attach(
    __name__,
    {
        "Fabrication": "planar.fabrication.build",
        "FabSettings": "planar.fabrication.parts",
        "part_cuts": "planar.fabrication.parts",
        "FabricationError": "planar.fabrication.joints",
        "PIN_RULES": "planar.fabrication.joints",
        "Assembly": "planar.fabrication.layers",
        "plan_assembly": "planar.fabrication.layers",
        "nest": "planar.fabrication.nesting",
    },
)
