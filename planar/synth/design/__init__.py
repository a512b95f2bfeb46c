"""Toy design from requested motions: the paper's pipeline, end to end (``planar design``).

A request lists end effectors (``[[effector]]``: ``name``, ``motion``,
``range``, optional ``cam`` and ``phase``).  :func:`design_toy`

1. **enumerates** every chain from the motor to each effector's motion (up to
   three stages, :func:`~planar.windup.table.enumerate_chains`);
2. **merges** one chain per effector into trees on the two cams (chains on one
   cam share their common prefix: one stage each), respecting a requested
   ``cam`` and putting effectors with different ``phase`` on different cams;
3. **ranks** the trees by the paper's cost (:func:`~planar.windup.chain.tree_cost`:
   mechanisms + 2 x mean chain length), cheapest first, skipping trees with a
   chain that cannot reach its effector's range (each chain's reachable range
   is scanned once, lazily, its sized stage's parameter varied) or that the toy
   assembly cannot build (a mirrored stage, a stage turned out of its plane);
   an unreachable range is refused naming the reach of the buildable chains;
4. **sizes** the cheapest tree that works: each effector's last stage's design
   parameter (:data:`~planar.windup.sizing.DESIGN_PARAMETER`; its parent's for a
   #10, whose stroke follows its driver's travel) is solved with
   :func:`scipy.optimize.brentq` so that the effector's range, composed
   through the tree (its parent's actual output, not a standalone law), is the
   request; stages are sized parents first;
5. **places** the stages (:func:`place_stages`): a toy's stages sit where the
   assembly puts them (a child's driver on its parent's follower, the roots on
   the motor axis); the free variables are each stage's joint moves that
   change no motion (:func:`placement_variables`: found per stage on its real
   input among :data:`MOVES`, e.g. #1's slider, #4's follower origin about its
   pin, #7's pin and pivot together), annealed toward a small footprint and
   little overlap of unjoined pieces or crowding of cuts; the result is kept
   only if it adds no export refusal, collision, pin clash or layer;
6. **checks** the result independently: each effector's range is measured on
   the assembled toy's piece poses, and the export's own layer plan
   (:func:`planar.app.export.build`) is checked with shapely for pieces of one
   layer overlapping at any of 24 sampled poses and for pins running through
   a piece; then the toy's physics (:func:`physics_check`, as ``planar toy``).
   A tree that fails is tried again with its cranks grown into disc cams
   (:func:`_disc_cams`, same motion), then passed over for the next cheapest
   (up to ``max_fabricated``); if all fail, the cheapest is returned with its
   failures (``planar design`` exits 3).

Units: ranges of O motions (and the rotation of OzT) in degrees, of T
motions in model units (one unit is 100 mm when cut); phases in cycles.

The package, by concern: :mod:`~planar.synth.design.request` (the request, the design record, what is written),
:mod:`~planar.synth.design.sizing` (chains' reach, trees ranked and sized), :mod:`~planar.synth.design.checks`
(ranges measured, layer collisions, physics), :mod:`~planar.synth.design.placement` (the stages' free moves
annealed, disc cams) and :mod:`~planar.synth.design.pipeline` (:func:`design_toy`).
"""

from planar.synth.design.checks import (
    design_scene,
    effector_ranges,
    layer_collisions,
    physics_check,
    physics_failures,
)
from planar.synth.design.pipeline import design_toy
from planar.synth.design.placement import _shifted, place_stages, placement_variables
from planar.synth.design.request import (
    CAMS,
    EARTH_GRAVITY,
    SAMPLES,
    SCENE_TABLES,
    TOLERANCE,
    TORQUE_TOLERANCE,
    Design,
    Effector,
    Placement,
    design_gravity,
    load_request,
)

__all__ = [
    "CAMS",
    "EARTH_GRAVITY",
    "SAMPLES",
    "SCENE_TABLES",
    "TOLERANCE",
    "TORQUE_TOLERANCE",
    "Design",
    "Effector",
    "Placement",
    "_shifted",
    "design_gravity",
    "design_scene",
    "design_toy",
    "effector_ranges",
    "layer_collisions",
    "load_request",
    "physics_check",
    "physics_failures",
    "place_stages",
    "placement_variables",
]
