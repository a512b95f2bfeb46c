"""The same mechanism rebuilt as pymunk bodies and joints, driven by the analytic input.

Rebuild:

* every part becomes a body whose mass and moment come from its outline
  (area x density, second moment of the polygon with its holes); the ground
  is the space's static body;
* each joint kind is rebuilt by the handler registered for it in
  :data:`REBUILDERS`: :class:`~planar.core.model.Pivot` -> ``PivotJoint``;
  :class:`~planar.core.model.PinInSlot` -> ``GrooveJoint`` (groove on the slot's
  part); :class:`~planar.core.model.Slide` -> ``GrooveJoint`` plus a ``GearJoint``
  (ratio 1) locking the rotation; :class:`~planar.core.model.PinInArcSlot` -> the
  equivalent link (a ``PinJoint`` holding the pin at the arc's radius);
  :class:`~planar.core.model.CamOnLine` -> ``GrooveJoint``, allowed only when the
  scene names what holds it there (gravity or a spring);
* grooves hold a pin that is a small body of its own; its mass is taken out
  of the part it rides on (mass, centre of gravity and moment of the pair are
  the part's), so the rebuilt mechanism has the model's inertia;
* the driver follows the analytic input: a kinematic body whose velocity is
  set so that it reaches the analytic pose at the end of each step
  (``mode="kinematic"``, the default); or a dynamic body turned by a
  ``SimpleMotor`` at the driver's rate (``mode="motor"``), whose signed
  torque is read every step (and checked against the motor's force limit).

Time is scaled so that one pymunk time unit is one step: the joint error
correction is then a fraction per step (:attr:`SimSettings.correction`),
the same at any rate and step, and never underflows (pymunk's per-second
``error_bias`` cannot express more than ~3 % per step at 64 substeps of a
1 s cycle).  Velocities, forces, stiffnesses and damping are scaled to match.

Only the effects a scene names exist in the space: no gravity, damping,
springs or loads otherwise (``SimResult.built`` lists what was built).
Wind-up #6 and #9 are spatial and are refused.  There are no collisions:
the parts of a mechanism sit on layers and never touch (a scene's
``contact`` and ``friction`` keys are refused when the scene is read).

Failures are found by comparing poses, in blocks of samples with arrays:
a sample where any part leaves its analytic pose by more than
``tolerance`` of the mechanism's size (worst hull point), or whose state is
not finite, stops the run and is reported with its sample and part, and
whether the joints came apart (a blow-up) or still hold (the mechanism took
another assembly branch).
"""

from __future__ import annotations

from planar.analysis.dynamics import inverse_dynamics_torque, mass_properties
from planar.physics.rebuild import REBUILDERS, _Rebuild
from planar.physics.run import (
    SimFailure,
    SimResult,
    _analytic_pose_velocity,
    simulate,
    simulate_scene,
    torque_comparison,
)
from planar.physics.settings import (
    DEFAULT_SETTINGS,
    SimSettings,
    SimulationError,
    joint_drift,
    lever,
    mass_ratio_correction,
    moving_masses,
    solver_iterations,
    substeps_for,
)

__all__ = [
    "DEFAULT_SETTINGS",
    "REBUILDERS",
    "SimFailure",
    "SimResult",
    "SimSettings",
    "SimulationError",
    "_Rebuild",
    "_analytic_pose_velocity",
    "inverse_dynamics_torque",
    "joint_drift",
    "lever",
    "mass_properties",
    "mass_ratio_correction",
    "moving_masses",
    "simulate",
    "simulate_scene",
    "solver_iterations",
    "substeps_for",
    "torque_comparison",
]
