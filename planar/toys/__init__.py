"""A wind-up toy as one assembly: merged pieces, their placement, fit checks and rates.

Every name in ``__all__`` is imported from its module on first use (:func:`planar.core.lazy.attach`).
"""

from planar.core.lazy import attach

__getattr__, __dir__, __all__ = attach(
    __name__,
    {
        "ToyAssembly": "planar.toys.assembly",
        "KeyedShaft": "planar.toys.assembly",
        "toy_assembly": "planar.toys.assembly",
        "PLACERS": "planar.toys.assembly",
        "fit_play": "planar.toys.fitcheck",
        "small_motions": "planar.toys.fitcheck",
    },
)
