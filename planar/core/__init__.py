"""Geometry, features, the model (parts, joints, drivers, mechanisms, motions), kind registries, limits.

Every name in ``__all__`` is imported from its module on first use (:func:`planar.core.lazy.attach`).
"""

from planar.core.lazy import attach

__getattr__, __dir__, __all__ = attach(
    __name__,
    {
        "Driver": "planar.core.model",
        "Mechanism": "planar.core.model",
        "Motion": "planar.core.model",
        "Part": "planar.core.model",
        "Pivot": "planar.core.model",
        "Slide": "planar.core.model",
        "PinInSlot": "planar.core.model",
        "PinInArcSlot": "planar.core.model",
        "CamOnLine": "planar.core.model",
        "Joint": "planar.core.model",
        "JOINT_KINDS": "planar.core.model",
        "joint_kind": "planar.core.model",
        "joint_residuals": "planar.core.model",
        "Hole": "planar.core.features",
        "Slot": "planar.core.features",
        "ArcSlot": "planar.core.features",
        "Effects": "planar.core.effects",
        "Load": "planar.core.effects",
        "Spring": "planar.core.effects",
        "NO_EFFECTS": "planar.core.effects",
        "Registry": "planar.core.registry",
        "UnsupportedError": "planar.core.registry",
        "limit": "planar.core.limits",
        "check_count": "planar.core.limits",
        "check_memory": "planar.core.limits",
    },
)
