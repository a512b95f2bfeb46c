"""planar: 2D rigid-body mechanisms with exact (closed-form) kinematics.

``import planar`` is light: the errors only.  The model's names
(``planar.Mechanism`` ...) load numpy on first use; shapely, pymunk, ezdxf and
imageio are imported by the modules that use them.  So the ``planar`` command
holds nothing heavy until its interrupt handling is in place (a Ctrl-C while
numpy loads is one line, not a traceback).
"""

from __future__ import annotations

import sys
from typing import TYPE_CHECKING, Any

from planar.errors import AssemblyError, InputError, LimitError, PlanarError, SceneError

if TYPE_CHECKING:  # pragma: no cover
    from planar.core.model import Driver, Mechanism, Motion, Part, joint_residuals

__all__ = [
    "AssemblyError",
    "Driver",
    "InputError",
    "LimitError",
    "Mechanism",
    "Motion",
    "Part",
    "PlanarError",
    "SceneError",
    "joint_residuals",
]
__version__ = "0.1.0"

if "IPython" in sys.modules:  # a notebook: mechanisms and motions display as tables and players
    import planar.draw.notebook  # noqa: F401  (light: registers renderers (planar.core.display); numpy loads on first display)

_MODEL_NAMES = ("Driver", "Mechanism", "Motion", "Part", "joint_residuals")


def __getattr__(name: str) -> Any:
    if name in _MODEL_NAMES:
        from planar.core import model

        return getattr(model, name)
    raise AttributeError(f"module 'planar' has no attribute {name!r}")
