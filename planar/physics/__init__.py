"""The pymunk rebuild of a mechanism, its run, and the comparison with the analytic motion.

Every name in ``__all__`` is imported from its module on first use (:func:`planar.core.lazy.attach`).
"""

from planar.core.lazy import attach

__getattr__, __dir__, __all__ = attach(
    __name__,
    {
        "SimSettings": "planar.physics.simulate",
        "SimResult": "planar.physics.simulate",
        "SimFailure": "planar.physics.simulate",
        "SimulationError": "planar.physics.simulate",
        "DEFAULT_SETTINGS": "planar.physics.simulate",
        "simulate_scene": "planar.physics.simulate",
        "torque_comparison": "planar.physics.simulate",
        "Comparison": "planar.physics.compare",
        "PartError": "planar.physics.compare",
        "EXIT_MISMATCH": "planar.physics.compare",
        "compare_scene": "planar.physics.compare",
        "format_comparison": "planar.physics.compare",
        "ToyPhysics": "planar.physics.toy",
        "StageReport": "planar.physics.toy",
        "simulate_toy": "planar.physics.toy",
    },
)
