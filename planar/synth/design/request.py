"""The request: the effectors a toy is asked for, the design returned, and reading a request file."""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from planar.errors import InputError
from planar.windup.chain import Chain, ToyMechanism
from planar.windup.table import MOTION_TYPES

Array = NDArray[np.float64]


CAMS = ("left", "right")
#: samples of one motor turn used for sizing and for the checks
SAMPLES = 721
#: design-parameter values scanned per sized stage before root finding
SCAN = 97
#: relative range tolerance the check demands (the request says 1 %)
TOLERANCE = 0.01


@dataclass(frozen=True)
class Effector:
    """One requested end effector: ``range`` in degrees (O, OzT's rotation) or model units (T);
    ``phase`` in cycles, ``0 <= phase < 1`` (only differences between cams matter)."""

    name: str
    motion: str
    range: float
    cam: str | None = None
    phase: float = 0.0

    @property
    def target(self) -> float:
        """The range in the kinematics' units (radians or model units)."""
        return math.radians(self.range) if self.motion[0] == "O" else self.range

    def unit(self, value: float) -> str:
        """``value`` (kinematics units) in the request's units, with the unit."""
        return f"{math.degrees(value):.4g} deg" if self.motion[0] == "O" else f"{value:.4g} units"


@dataclass
class Design:
    """A designed toy: the sized mechanism, which tree, its cost and the checks' figures."""

    toy: ToyMechanism
    effectors: list[Effector]
    assignment: list[tuple[str, Chain]]
    cost: float
    ranges: dict[str, float]  # measured in the assembled toy, request units
    candidates: int  # trees considered (after the reachability filter)
    tried: int  # trees sized before one worked
    sizing: dict[str, tuple[str, str, float]]  # effector -> (stage chain, parameter, value)
    layers: dict[str, int] = field(default_factory=dict)
    collisions: list[tuple[str, str, float]] = field(default_factory=list)
    seconds: dict[str, float] = field(default_factory=dict)
    placement: Placement | None = None
    layers_before: int | None = None  # layers of the toy before placement
    clashes: list[str] = field(default_factory=list)  # pins crossing a piece between their layers
    rejected: list[str] = field(default_factory=list)  # cheaper trees whose fabrication collided
    before: dict[str, int] = field(default_factory=dict)  # layers, collisions, pin clashes before placement
    before_reason: str = ""  # why the export refused the pieces before placement, if it did
    physics: dict[str, Any] | None = None  # :func:`physics_check` of the written toy (None: not run)
    variant: str = ""  # how the tree differs from the tree as sized ("its cams grown into discs"), or ""
    fallback: bool = False  # every tree tried failed: this is the cheapest (``rejected[0]``), written with its failures

    @property
    def export_refused(self) -> str:
        """Why the export refuses the toy's pieces ("" when it cuts them; then ``clashes`` are pins only)."""
        return self.clashes[0] if not self.layers and self.clashes else ""

    @property
    def gravity_x(self) -> list[str]:
        """The #8 stages for which the toy is written with gravity along +x (:func:`design_scene`)."""
        return [st.label for st in self.toy.stages if st.mech.view == "xz"]

    @property
    def gravity_y(self) -> list[str]:
        """The #6/#9 stages for which the toy is written with gravity along -y (:func:`design_scene`)."""
        return [st.label for st in self.toy.stages if st.mech.spatial]

    def report(self) -> dict[str, Any]:
        return {
            "toy": self.toy.name,
            "cost": self.cost,
            "mechanisms": self.toy.mechanism_count,
            "cams": {cam: [list(c) for c in chains] for cam, chains in self.toy.cams.items()},
            "phase_deg": math.degrees(self.toy.phase),
            "effectors": [
                {
                    "name": e.name,
                    "motion": e.motion,
                    "cam": cam,
                    "chain": list(chain),
                    "requested": e.range,
                    "achieved": self.ranges[e.name],
                    "error": abs(self.ranges[e.name] - e.range) / e.range,
                    "sized": {
                        "stage": self.sizing[e.name][0],
                        "parameter": self.sizing[e.name][1],
                        "value": self.sizing[e.name][2],
                    },
                }
                for e, (cam, chain) in zip(self.effectors, self.assignment)
            ],
            "trees_considered": self.candidates,
            "trees_sized": self.tried,
            "layers": {k: v + 1 for k, v in self.layers.items()},  # numbered from 1, as in the BOM
            "layer_count": len(set(self.layers.values())),
            "before_placement": self.before,
            "placement": None
            if self.placement is None
            else {
                "variables": self.placement.variables,
                "objective": list(self.placement.objective),
                "footprint": list(self.placement.footprint),
                "overlap": list(self.placement.overlap),
                "evaluations": self.placement.evaluations,
                "rejected": self.placement.rejected,
                "kept": self.placement.kept,
                "checked": self.placement.checked,
            },
            "collisions": [{"a": a, "b": b, "overlap": ov} for a, b, ov in self.collisions],
            "pin_clashes": [] if self.export_refused else self.clashes,
            "export_refused": self.export_refused or None,
            "variant": self.variant or None,
            "fallback": self.fallback,
            "gravity": design_gravity(self.toy),
            "rejected_trees": self.rejected,
            "physics": self.physics,
            "seconds": self.seconds,
        }


# ----------------------------------------------------------------------------- the request


class _Missing:
    """A key the request does not give, as a message shows it (``effector[0].name = (missing)``)."""

    def __repr__(self) -> str:
        return "(missing)"


_MISSING = _Missing()


def load_request(path: str | Path) -> list[Effector]:
    """Read a request file (TOML ``[[effector]]`` tables); bad input is an :class:`InputError` naming the field."""
    import os

    from planar.fileio import read_text

    if not isinstance(path, (str, os.PathLike)):
        raise InputError("load_request(path)", path, "a path to a request file (TOML)")
    p = str(path)
    try:
        data = tomllib.loads(read_text(p, "request file (TOML)"))
    except tomllib.TOMLDecodeError as e:
        raise InputError(p, f"not TOML: {e}", "a request file in TOML ([[effector]] tables)") from None
    extra = sorted(set(data) - {"effector", "name"})
    if extra:
        raise InputError(f"{p}: {extra[0]}", data[extra[0]], "only [[effector]] tables and a toy name")
    rows = data.get("effector")
    if not isinstance(rows, list) or not rows or not all(isinstance(r, dict) for r in rows):
        raise InputError(f"{p}: effector", "missing" if rows is None else rows, "one or more [[effector]] tables")
    out = []
    for i, r in enumerate(rows):
        where = f"{p}: effector[{i}]"
        bad = sorted(set(r) - {"name", "motion", "range", "cam", "phase"})
        if bad:
            raise InputError(f"{where}.{bad[0]}", r[bad[0]], "one of name, motion, range, cam, phase")
        for req in ("name", "motion", "range"):
            if req not in r:  # missing, not None (TOML has no None): said so, with the keys it has
                raise InputError(
                    f"{where}.{req}",
                    _MISSING,
                    f"a {req} (a required field: every [[effector]] gives name, motion and range; "
                    f"this one has {', '.join(sorted(r)) or 'no keys'})",
                )
        name = r.get("name")
        if isinstance(name, str) and name.strip():
            where = f"{p}: effector {name!r}"
        if (
            not isinstance(name, str)
            or not name.strip()
            or any(c in name for c in '.:+,"')
            or name == "frame"
            or any(ord(c) < 32 or ord(c) == 127 for c in name)
        ):
            raise InputError(
                f"{where}.name",
                name,
                "a name without '.', ':', '+', ',', '\"' or control characters, not 'frame' (the effector's piece)",
            )
        motion = r.get("motion")
        if motion not in MOTION_TYPES:
            raise InputError(f"{where}.motion", motion, f"one of {', '.join(MOTION_TYPES)}")
        rng = r.get("range")
        if isinstance(rng, bool) or not isinstance(rng, (int, float)) or not math.isfinite(rng) or rng <= 0:
            raise InputError(f"{where}.range", rng, "a positive number (degrees for O and OzT, model units for T)")
        cam = r.get("cam")
        if cam is not None and cam not in CAMS:
            raise InputError(f"{where}.cam", cam, "'left' or 'right'")
        ph = r.get("phase", 0.0)
        if isinstance(ph, bool) or not isinstance(ph, (int, float)) or not math.isfinite(ph):
            raise InputError(f"{where}.phase", ph, "a number of cycles (0 <= phase < 1)")
        if not 0 <= ph < 1:
            raise InputError(f"{where}.phase", ph, _phase_hint(float(ph)))
        out.append(Effector(name, str(motion), float(rng), cam, float(ph)))
    names = [e.name for e in out]
    dup = next((n for n in names if names.count(n) > 1), None)
    if dup is not None:
        raise InputError(f"{p}: effector.name", dup, "distinct effector names")
    return out


def _phase_hint(ph: float) -> str:
    """What a phase outside [0, 1) should have been: cycles, with a guess at what was meant."""
    text = "a phase in cycles (0 <= phase < 1; a quarter turn is 0.25)"
    if 1 <= ph <= 360 and (ph >= 5 or ph == int(ph)):
        return text + f"; if {ph:g} is degrees, write phase = {ph / 360:.6g} (degrees / 360)"
    if 1 <= ph < 5:
        return text + f"; whole turns make no difference: {ph:g} cycles is phase = {ph % 1:.6g}"
    return text


@dataclass
class Placement:
    """What the annealing did: variables, objective and footprint before and after, evaluations."""

    variables: list[str]
    objective: tuple[float, float]
    footprint: tuple[float, float]
    overlap: tuple[float, float]
    evaluations: int
    rejected: int
    seconds: float
    kept: bool = True  # False when no annealed layout passed the fabrication check (the start is kept)
    checked: int = 0  # annealed layouts checked against the fabrication


#: the written toy's scene tables: half a cycle a second, 36 frames a cycle, a small GIF, 100 mm a unit
SCENE_TABLES: dict[str, Any] = {
    "driver": {"speed": 0.5, "samples_per_cycle": 36},
    "render": {"width": 360, "height": 270},
    "fabrication": {"unit_mm": 100.0},
}
#: Earth's gravity in the written scene's model units per s^2 (9810 mm/s^2 at its ``unit_mm``): physics runs in
#: model units, so a toy cut at 100 mm per unit falls at 98.1 units/s^2
EARTH_GRAVITY = 9810.0 / SCENE_TABLES["fabrication"]["unit_mm"]
#: the motor torque's largest allowed difference from inverse dynamics, fraction of the torque scale (as ``planar toy``)
TORQUE_TOLERANCE = 0.01


def design_gravity(toy: ToyMechanism) -> list[float] | None:
    """The gravity ``planar design`` writes for ``toy`` (None: none).  A #8 stage's tab is held on its face by
    gravity along +x (its plane xz), a #6/#9 follower's pin on its driver's edge by gravity along -y (its plane
    yz; README, "Wind-up toys"): a toy with them is written standing that way.  The -y side is the one the
    edge holds for the gallery's and the trial's followers; the physics check (:func:`physics_check`) says
    where it is not."""
    nums = {st.realisation.number for st in toy.stages}
    g = [1.0 if 8 in nums else 0.0, -1.0 if nums & {6, 9} else 0.0]
    norm = math.hypot(*g)
    # Earth's gravity (EARTH_GRAVITY model units/s^2), tilted 45 degrees between +x and -y when both are needed
    return [EARTH_GRAVITY * c / norm + 0.0 for c in g] if norm else None
