"""Tab-and-slot joints for pieces standing perpendicular to the toy's plane (xz, yz).

A wind-up toy's #8 stage moves in xz and its #6/#9 followers in yz; each of
those pieces is cut flat and must be joined to the xy stack it belongs to.
The joint is the usual laser-cut tab and slot (Boxes.py's finger joint on one
side, through-slots on the other):

* **rigid pieces**: a perpendicular piece that is one rigid body with an xy
  piece (``ToyAssembly.bodies``: the #8 window plate with the slider, the
  xz frame with the frame) is cut flat where it meets that piece's layer face,
  keeping its side, and gets tabs ``thickness_mm`` long standing out of that
  edge through the layer; the xy piece gets a rectangular through-slot for
  each tab on the line where the two planes meet (``thickness_mm +
  clearance_mm`` wide, the tab's width + ``clearance_mm`` long: the fit
  allowance holes get).  Tabs are ``2 x thickness`` wide with ``2 x
  thickness`` gaps (Boxes.py's default finger and space), as many as fit
  where both pieces have material with ``min_wall_mm`` round each slot and
  clear of every other cut; at least two per joint.  A hull-outlined xy piece
  (the frame) grows to hold its slots; an explicit outline (the merged slider)
  must already have room.
* **the stack along z**: xy layer k lies between ``z0 + k t`` and ``z0 + (k + 1) t``
  (mm) of the model's z.  The model's xy plane (``z = 0``: where the #8 driver
  slides, where the #6/#9 pin meets its driver's edge) is the mid-plane of the
  layer the perpendicular stages ride on, as near as the pieces' own cuts
  allow (each keeps ``min_wall_mm`` between its edge and its cuts).  Pieces
  on the model's -z side hang below the stack from their xy piece's lower
  face; pieces on the +z side stand on its upper face.
* **plane positions**: a plane's pieces stand in its layer order, one sheet
  thickness apart (``y = y0 + (layer + 1/2) t`` for xz).  The model fixes no
  y for xz pieces, so ``y0`` is the nearest position (0.5 mm steps from the
  model's ``y = 0``, up to 60 mm) where every xz joint has room and every
  travel slot (below) keeps its walls.  A yz piece stays at its x
  (``Part.offset``: the #6/#9 pin must meet the driver's edge there); its
  bracket stands in its layer beside it.
* **brackets**: a moving perpendicular piece that no pin holds (the #6/#9
  follower, whose axle the model leaves in the air) gets a bracket: a frame
  piece in its plane with a hole on the axle (the piece's stationary hole)
  and a base reaching past the piece's way through the stack, tab-joined to
  the frame like any frame piece (its tabs clear of that way).  A #8 tab is
  held by the xz frame already (pin through both), so the xz frame is its
  bracket.
* **repeated guides**: a slide between two perpendicular pieces that are both
  joined to the xy stack repeats the xy slide of their bodies (the #8 side
  view of the slider's own guide): it is not cut (no slot, no pin holes).
* **travel slots**: a perpendicular piece passing through another xy piece's
  layer where that piece has material gets a rectangular travel slot there
  (its way over the cycle, ``clearance_mm`` round it; ways closer than
  ``min_wall_mm`` are one slot).  Pieces joined by a joint (the #6/#9 pin on
  its driver's edge) touch by design and get none.

Refused (``FabricationError``, exit 2, one line): a perpendicular piece whose
xy piece turns or moves across the line where they meet, one that does not
reach its xy piece's face, one with a moving axle, a joint with room for fewer
than two tabs, travel slots running into other cuts.  Sizes in millimetres;
the tabs' and slots' positions (``TabJoin``) are what the tests read back from
the files.
"""

from __future__ import annotations

from planar.fabrication.tabs.model import TabJoin, TabPlan
from planar.fabrication.tabs.plan import plan_tabs
from planar.fabrication.tabs.slots import merge_travel, slot_features, travel_slots
from planar.fabrication.tabs.view import FabView, fab_view

__all__ = ["FabView", "TabJoin", "TabPlan", "fab_view", "merge_travel", "plan_tabs", "slot_features", "travel_slots"]
