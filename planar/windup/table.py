"""The motion transfer table (the paper's Table 2) and chain enumeration.

Motions are strings: ``"Rz"`` (the motor's continuous rotation), ``"Ox"``,
``"Oy"``, ``"Oz"`` (oscillation about an axis), ``"Tx"``, ``"Ty"``, ``"Tz"``
(translation along an axis) and ``"OzT"`` (oscillation plus translation in the
xy plane).  A *pattern* ``"A->B"`` is one table entry; each is realised by one
of the 11 elemental mechanisms turned by a rotation of the cube (a quarter
turn about x, y or z, or a composition), found by search in
:func:`realise`.  A *chain* is a tuple of patterns from ``Rz`` to an end
effector.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass
from functools import cache, lru_cache

import numpy as np

from planar.errors import InputError
from planar.windup.mechanisms import MOTIONS

__all__ = ["MOTION_TYPES", "OPTIONAL", "TABLE", "Realisation", "chain_counts", "enumerate_chains", "patterns", "realise"]

#: driver motion -> follower motions (30 patterns)
TABLE: dict[str, tuple[str, ...]] = {
    "Rz": ("Oz", "Tx", "Ty", "OzT"),
    "Ox": ("Ox", "Oy", "Oz", "Ty", "Tz"),
    "Oy": ("Ox", "Oz", "Tx", "Tz"),
    "Oz": ("Ox", "Oy", "Oz", "Tx", "Ty"),
    "Tx": ("Ox", "Oy", "Oz"),
    "Ty": ("Ox", "Oy", "Oz"),
    "Tz": ("Ox", "Oy", "Oz"),
    "OzT": ("Oz", "Tx", "Ty"),
}

#: patterns the printed table lacks although a rotated mechanism gives them (reference file)
OPTIONAL: dict[str, tuple[str, ...]] = {"Oy": ("Oy",)}

MOTION_TYPES = ("Ox", "Oy", "Oz", "Tx", "Ty", "Tz", "OzT")

_AXIS = {"x": 0, "y": 1, "z": 2}


def _parse(m: str) -> tuple[str, int]:
    if m == "OzT":
        return "OT", 2
    if len(m) == 2 and m[0] in "ROT" and m[1] in _AXIS:
        return m[0], _AXIS[m[1]]
    raise InputError("motion", m, f"one of Rz, {', '.join(MOTION_TYPES)}")


@lru_cache(maxsize=1)
def _rotations() -> tuple[np.ndarray, ...]:
    """The 24 proper rotations of the cube, identity first, then by number of quarter turns."""
    mats = []
    for perm in itertools.permutations(range(3)):
        for signs in itertools.product((1, -1), repeat=3):
            m = np.zeros((3, 3), dtype=int)
            for i, (p, s) in enumerate(zip(perm, signs)):
                m[p, i] = s
            if round(np.linalg.det(m)) == 1:
                mats.append(m)
    mats.sort(key=lambda m: (int(np.trace(m) != 3), -int(np.trace(m))))
    return tuple(mats)


@dataclass(frozen=True)
class Realisation:
    """How a pattern is built: elemental mechanism ``number`` turned by ``rotation``.

    ``rotation`` maps the mechanism's own axes to the world's; ``sign_in`` and
    ``sign_out`` are +1 or -1 where it maps the driver's or follower's axis to
    the negative world axis (the motion value changes sign).
    """

    pattern: str
    number: int
    rotation: tuple[tuple[int, int, int], ...]
    sign_in: int
    sign_out: int

    @property
    def matrix(self) -> np.ndarray:
        return np.array(self.rotation, dtype=float)


def _maps(R: np.ndarray, base: str, world: str) -> int:
    """+1 / -1 if ``R`` maps motion ``base`` onto ``world`` (same kind, axis up to sign), else 0."""
    kb, ab = _parse(base)
    kw, aw = _parse(world)
    if kb != kw:
        return 0
    v = R[:, ab]
    if abs(v[aw]) != 1:
        return 0
    return int(v[aw])


@cache
def realise(pattern: str) -> Realisation:
    """The elemental mechanism and rotation that realise ``pattern`` (e.g. ``"Ox->Tz"``).

    The motor's axis stays z (rotations for ``Rz`` and ``OzT`` drivers keep z
    on z); among candidates the identity and the mechanism with the lowest
    number are preferred.
    """
    try:
        a, b = pattern.split("->")
    except ValueError:
        raise InputError("pattern", pattern, "'A->B', e.g. 'Rz->Tx'") from None
    _parse(a), _parse(b)
    for R in _rotations():
        for k, (ma, mb) in sorted(MOTIONS.items()):
            si, so = _maps(R, ma, a), _maps(R, mb, b)
            if si and so:
                if a in ("Rz", "OzT") and R[2, 2] != 1:
                    continue  # the motor turns one way: keep z up
                rows = tuple((int(row[0]), int(row[1]), int(row[2])) for row in R)
                return Realisation(pattern, k, rows, si, so)
    raise InputError("pattern", pattern, "a motion transfer that some elemental mechanism realises (planar chains lists them)")


def patterns(optional: bool = False) -> list[str]:
    """All table patterns ``"A->B"`` (30, or 31 with the optional Oy->Oy)."""
    out = [f"{a}->{b}" for a, bs in TABLE.items() for b in bs]
    if optional:
        out += [f"{a}->{b}" for a, bs in OPTIONAL.items() for b in bs]
    return out


def enumerate_chains(target: str | None = None, max_length: int = 3, optional: bool = False) -> dict[str, list[tuple[str, ...]]]:
    """Every chain from the motor (Rz) of length 1..``max_length``, grouped by end effector.

    A chain is a tuple of patterns, e.g. ``("Rz->Tx", "Tx->Ox")``.  Chains
    are listed by length, then in table order.  ``target`` narrows the result
    to one end-effector motion.
    """
    if max_length < 1:
        raise InputError("max_length", max_length, "at least 1")
    if target is not None and target not in MOTION_TYPES:  # Rz is the motor's, never an end effector's
        raise InputError("target", target, f"an end-effector motion, one of {', '.join(MOTION_TYPES)}")
    table = {a: list(bs) for a, bs in TABLE.items()}
    if optional:
        for a, bs in OPTIONAL.items():
            table[a] = table[a] + list(bs)
    out: dict[str, list[tuple[str, ...]]] = {m: [] for m in MOTION_TYPES}
    frontier: list[tuple[str, tuple[str, ...]]] = [("Rz", ())]
    for _ in range(max_length):
        nxt = []
        for motion, chain in frontier:
            for b in table.get(motion, ()):
                c = chain + (f"{motion}->{b}",)
                out[b].append(c)
                nxt.append((b, c))
        frontier = nxt
    if target is not None:
        return {target: out[target]}
    return out


def chain_counts(max_length: int = 3, optional: bool = False) -> dict[str, int]:
    """Number of chains per end-effector motion."""
    return {k: len(v) for k, v in enumerate_chains(None, max_length, optional).items()}
