"""Ready-made mechanisms: the examples, the gallery's linkages and the test corpus.

``CATALOG`` maps a name to a zero-argument factory.  Every mechanism the
project ships is listed here, so that generic tests (joint residuals, outlines,
export) run over all of them.
"""

from __future__ import annotations

from collections.abc import Callable

from planar.core.model import Mechanism
from planar.linkages import RRR, Crank, Fixed, FourBar, Link, Linkage, SliderCrank
from planar.windup.mechanisms import ELEMENTAL

__all__ = ["CATALOG", "get", "jansen_leg", "kangaroo_leg", "paddle_boat"]


def jansen_leg(crank: float = 15.0) -> Linkage:
    """Theo Jansen's Strandbeest leg with his 'holy numbers' (crank 15, a = 38, l = 7.8, ...).

    Crank axle at the origin, the fixed pivot ``Z`` at ``(-38, -7.8)``; the
    foot ``F`` traces the flat-bottomed stride below.  Two ternary links
    (``upper``: Z-B-D and ``lower``: C-E-F) make it a multi-loop linkage.
    """
    nodes = [
        Fixed("O", (0.0, 0.0)),
        Fixed("Z", (-38.0, -7.8)),
        Crank("A", "O", crank),
        RRR("B", "A", 50.0, "Z", 41.5, -1),
        RRR("C", "A", 61.9, "Z", 39.3, 1),
        RRR("D", "B", 55.8, "Z", 40.1, -1),
        RRR("E", "D", 39.4, "C", 36.7, -1),
        RRR("F", "E", 65.7, "C", 49.0, -1),
    ]
    links = [
        Link("crank", ("O", "A")),
        Link("j", ("A", "B")),
        Link("k", ("A", "C")),
        Link("upper", ("Z", "B", "D")),
        Link("c", ("Z", "C")),
        Link("f", ("D", "E")),
        Link("lower", ("C", "E", "F")),
    ]
    return Linkage("jansen", nodes, links, points={"foot": "F"})


def kangaroo_leg() -> FourBar:
    """A crank-rocker hind leg; the foot (coupler point) sweeps a long, flat stride.

    The coupler carries the foot; sweep a foot polygon with the coupler's pose
    (notes section 1.2).
    """
    return FourBar(
        ground=4.0, crank=1.0, coupler=4.0, rocker=3.0, coupler_point=(5.5, -2.0), placement=(0.0, 0.0, 0.0), name="kangaroo"
    )


def paddle_boat() -> FourBar:
    """The paddling-boat linkage of notes Fig. 4: a crank-rocker whose coupler is the paddle."""
    return FourBar(ground=3.0, crank=0.8, coupler=3.2, rocker=2.4, coupler_point=(1.2, -2.6), name="paddle")


CATALOG: dict[str, Callable[[], Mechanism]] = {
    "fourbar-crank-rocker": lambda: FourBar(4.0, 1.0, 4.0, 3.0, coupler_point=(2.0, 1.0)),
    "fourbar-crossed": lambda: FourBar(4.0, 1.0, 4.0, 3.0, coupler_point=(2.0, 1.0), circuit="crossed"),
    "fourbar-double-crank": lambda: FourBar(1.0, 3.0, 3.5, 3.2, coupler_point=(1.0, 0.5)),
    "fourbar-placed": lambda: FourBar(4.0, 1.5, 3.5, 3.0, coupler_point=(1.0, 1.0), placement=(2.0, -1.0, 0.7)),
    "slider-crank": lambda: SliderCrank(1.0, 3.0, offset=0.0),
    "slider-crank-offset": lambda: SliderCrank(1.0, 3.0, offset=0.6),
    "jansen": jansen_leg,
    "kangaroo": kangaroo_leg,
    "paddle": paddle_boat,
}


def _windup(k: int) -> Callable[[], Mechanism]:
    def make() -> Mechanism:
        from planar.windup import elemental

        return elemental(k)

    return make


for _k in sorted(ELEMENTAL):  # the elemental records say which numbers exist
    CATALOG[f"windup-{_k}"] = _windup(_k)


def _toy(name: str) -> Callable[[], Mechanism]:
    def make() -> Mechanism:
        from planar.windup import chain

        return getattr(chain, name)()

    return make


CATALOG["horse"] = _toy("horse")
CATALOG["bunny"] = _toy("bunny")


def get(name: str) -> Mechanism:
    """Build the catalog mechanism ``name``."""
    from planar.errors import InputError

    if name not in CATALOG:
        raise InputError("mechanism", name, f"one of {sorted(CATALOG)}")
    return CATALOG[name]()
