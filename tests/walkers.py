"""Legs nobody tuned, for the walker tests: random Jansen-like legs and random four-bar legs (node kinds and
links of :class:`planar.linkages.legs.Legs`), and their scene tables."""

from __future__ import annotations

import math

import numpy as np

from planar.linkages import RRR, Crank, Fixed, Link, Rigid

#: Theo Jansen's "holy numbers" (a..m, model units)
HOLY = {
    **{"a": 38.0, "l": 7.8, "m": 15.0, "j": 50.0, "b": 41.5, "k": 61.9, "c": 39.3},
    **{"e": 55.8, "d": 40.1, "g": 36.7, "f": 39.4, "h": 65.7, "i": 49.0},
}


def jansen_leg(rng: np.random.Generator | None = None, spread: float = 0.05) -> tuple[list, list]:
    """A Jansen leg; with ``rng`` every length scaled by a random factor within ``1 +- spread``."""
    v = {k: x * (1 + (rng.uniform(-spread, spread) if rng is not None else 0.0)) for k, x in HOLY.items()}
    nodes = [
        Fixed("O", (0.0, 0.0)),
        Fixed("Z", (-v["a"], -v["l"])),
        Crank("A", "O", v["m"]),
        RRR("B", "A", v["j"], "Z", v["b"], -1),
        RRR("C", "A", v["k"], "Z", v["c"], 1),
        RRR("D", "B", v["e"], "Z", v["d"], -1),
        RRR("E", "D", v["f"], "C", v["g"], -1),
        RRR("F", "E", v["h"], "C", v["i"], -1),
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
    return nodes, links


def fourbar_leg(rng: np.random.Generator) -> tuple[list, list]:
    """A random Grashof crank-rocker (the crank the shortest link) with a foot on its coupler."""
    crank = 10.0
    ground, coupler, rocker = (crank * rng.uniform(2.8, 4.0) for _ in range(3))
    ang = rng.uniform(math.pi, 1.5 * math.pi)
    nodes = [
        Fixed("O", (0.0, 0.0)),
        Fixed("Z", (ground * math.cos(ang), ground * math.sin(ang))),
        Crank("A", "O", crank, rng.uniform(-math.pi, math.pi)),
        RRR("B", "A", coupler, "Z", rocker, 1 if rng.uniform() < 0.5 else -1),
        Rigid("F", "A", "B", (rng.uniform(0.3, 1.2) * coupler, rng.uniform(-0.6, 0.6) * coupler)),
    ]
    links = [Link("crank", ("O", "A")), Link("coupler", ("A", "B", "F")), Link("rocker", ("Z", "B"))]
    return nodes, links


def scene_tables(nodes: list, links: list) -> tuple[list[dict], list[dict]]:
    """The ``[[mechanism.nodes]]`` and ``[[mechanism.links]]`` tables of a leg (angles in radians)."""
    keys = {Fixed: {"at": "xy"}, Crank: {"centre": "centre", "radius": "radius", "phase": "phase"}}
    keys[RRR] = {k: k for k in ("a", "ra", "b", "rb", "branch")}
    keys[Rigid] = {k: k for k in ("a", "b", "local")}
    out = []
    for n in nodes:
        t = {"name": n.name, "kind": n.kind}
        for k, f in keys[type(n)].items():
            v = getattr(n, f)
            t[k] = [float(x) for x in v] if isinstance(v, tuple) else v
        out.append(t)
    return out, [{"name": lk.name, "nodes": list(lk.nodes)} for lk in links]
