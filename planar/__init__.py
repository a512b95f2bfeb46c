"""planar: 2D rigid-body mechanisms with exact (closed-form) kinematics.

``import planar`` stays light: numpy only.  shapely, pymunk, ezdxf and imageio
are imported by the modules that use them.
"""

from .errors import AssemblyError, InputError, LimitError, PlanarError, SceneError
from .model import Driver, Mechanism, Motion, Part, joint_residuals

__all__ = [
    "AssemblyError", "InputError", "LimitError", "PlanarError", "SceneError",
    "Driver", "Mechanism", "Motion", "Part", "joint_residuals",
]
__version__ = "0.1.0"
