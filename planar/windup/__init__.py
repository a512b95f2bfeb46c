"""Wind-up toy mechanisms (Song et al., SIGGRAPH Asia 2017): the 11 elemental
mechanisms, the motion transfer table, chains and trees.

See ``ERRATA.md`` beside this file for every correction to the supplement's
equations and how it was verified.
"""

from planar.windup.mechanisms import ELEMENTAL, MOTIONS, ElementalMechanism, ElementalRecord, elemental, params_for

__all__ = ["ELEMENTAL", "MOTIONS", "ElementalMechanism", "ElementalRecord", "elemental", "params_for"]
