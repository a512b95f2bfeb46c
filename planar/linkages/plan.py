"""The plan of one linkage's fast solve, and the shape of what it is planned from.

:mod:`planar.linkages.chunked` builds a :class:`_Plan` from a linkage
(:class:`planar.linkages.linkage.Linkage`, which imports the solver); the compiled
kernels (:mod:`planar.linkages.compiled`) read it.  The linkage and its node kinds
are described here by the members the solver reads, so this module imports
neither.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any, ClassVar, Protocol

import numpy as np
from numpy.typing import NDArray

__all__ = ["Linkage", "NodeKind", "_Plan"]


class NodeKind(Protocol):
    """A node kind as the fast solve reads it (:class:`planar.linkages.nodes.NodeKind`)."""

    kind: ClassVar[str]

    @property
    def name(self) -> str: ...

    def refs(self) -> Sequence[str]: ...


class Linkage(Protocol):
    """A linkage as the fast solve reads it (:class:`planar.linkages.linkage.Linkage`)."""

    @property
    def name(self) -> str: ...

    @property
    def nodes(self) -> Sequence[Any]: ...

    @property
    def links(self) -> Sequence[Any]: ...

    @property
    def ground_name(self) -> str: ...

    @property
    def point_nodes(self) -> Mapping[str, str]: ...

    @property
    def points(self) -> Mapping[str, Any]: ...

    @property
    def placement(self) -> tuple[float, ...]: ...

    def _fast_plan(self) -> Any: ...

    def solve_nodes(self, q: NDArray[np.float64]) -> tuple[Any, Any]: ...


Kernel = Callable[..., Any]


@dataclass
class _Plan:
    """What one linkage's fast solve needs, built once."""

    nodes: list[NodeKind]
    kernels: list[Kernel]
    checks: list[tuple[int, str, str]]  # (node index, node, why) in solve order
    links: list[tuple[str, int, int, int]]  # (link, origin, from, to); origin -1: the ground
    points: list[tuple[str, int]]
    placement: tuple[float, float, float]
    bound: list[float]  # a bound on |coordinate| of each node, for q = 0 (actuators add |q|)
    grows: list[bool]  # node moves with |q| (downstream of an actuator)
    program: Any = None  # the compiled program (planar.linkages.compiled), built on first use
