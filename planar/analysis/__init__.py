"""Rates, torque, statics and dynamics of a solved mechanism.

Every name in ``__all__`` is imported from its module on first use (:func:`planar.core.lazy.attach`).
"""

from planar.core.lazy import attach

__getattr__, __dir__, __all__ = attach(
    __name__,
    {
        "Derivatives": "planar.analysis.rates",
        "PartRates": "planar.analysis.rates",
        "motion_derivatives": "planar.analysis.rates",
        "mechanism_rates": "planar.analysis.rates",
        "point_rates": "planar.analysis.rates",
        "transmission_angles": "planar.analysis.rates",
        "fourbar_velocities": "planar.analysis.statics",
        "fourbar_instant_centre": "planar.analysis.statics",
        "node_velocities": "planar.analysis.statics",
        "point_velocities": "planar.analysis.statics",
        "virtual_work_torque": "planar.analysis.statics",
        "static_foot_loads": "planar.analysis.statics",
        "instant_centre": "planar.analysis.statics",
        "inverse_dynamics_torque": "planar.analysis.dynamics",
        "mass_properties": "planar.analysis.dynamics",
    },
)
