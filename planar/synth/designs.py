"""What every synthesised design shares: its checks' verdict, and a four-bar from its dimensions."""

from __future__ import annotations

from typing import Any

#: transmission angle (degrees) nearer than this to a toggle (0 or 180) fails every synthesis's check whatever
#: ``min_transmission`` asks: coupler and rocker fold almost flat there and the coupler point jumps (a
#: design at 0.4 deg moved its coupler point by 20 units between two of a scene's 72 samples)
TOGGLE_FLOOR_DEG = 1.0


class Checked:
    """A design whose ``checks`` hold ``ok_...`` verdicts (and figures under other keys)."""

    checks: dict[str, Any]

    @property
    def ok(self) -> bool:
        """Every check passed."""
        return all(bool(v) for k, v in self.checks.items() if k.startswith("ok_"))


class FourBarLinks:
    """A design given as a four-bar's four lengths and circuit; :meth:`_coupler_and_placement` says the rest."""

    ground: float
    crank: float
    coupler: float
    rocker: float
    circuit: str

    def _coupler_and_placement(self) -> tuple[tuple[float, float], tuple[float, float, float]]:
        """The coupler point (coupler frame, model units) and the placement ``(x, y, angle)`` (model units, rad)."""
        raise NotImplementedError

    def lengths_dict(self) -> dict[str, Any]:
        """The start of every four-bar design's record: ``type`` and the four lengths."""
        return {"type": "fourbar", "ground": self.ground, "crank": self.crank, "coupler": self.coupler, "rocker": self.rocker}

    def fourbar(self, **kw: Any):
        """The design as a :class:`planar.linkages.FourBar`."""
        from planar.linkages import FourBar

        coupler_point, placement = self._coupler_and_placement()
        return FourBar(
            self.ground,
            self.crank,
            self.coupler,
            self.rocker,
            coupler_point=coupler_point,
            circuit=self.circuit,  # type: ignore[arg-type]
            placement=placement,
            **kw,
        )


class PlacedFourBar(FourBarLinks):
    """A design given as a four-bar's lengths, coupler point, circuit and placement."""

    coupler_point: tuple[float, float]
    placement: tuple[float, float, float]
    theta: Any  # the crank angle at each target, pose or pair (radians)

    def _coupler_and_placement(self) -> tuple[tuple[float, float], tuple[float, float, float]]:
        return self.coupler_point, self.placement

    def fourbar_dict(self) -> dict[str, Any]:
        """The four-bar's record shared by every design's ``to_dict``: ``type``, the four lengths,
        ``coupler_point``, ``circuit``, ``placement`` and ``theta`` (the crank angle at each target, pose or
        pair, radians)."""
        return {
            **self.lengths_dict(),
            "coupler_point": list(self.coupler_point),
            "circuit": self.circuit,
            "placement": list(self.placement),
            "theta": [float(t) for t in self.theta],
        }
