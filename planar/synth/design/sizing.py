"""Composition and sizing: chains scanned for their reach, trees ranked and sized (brentq)."""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from planar.errors import InputError
from planar.synth.design.request import CAMS, SCAN, Effector
from planar.windup.chain import Chain, _to_base, _to_world, tree_cost
from planar.windup.mechanisms import ELEMENTAL, check_params, params_for
from planar.windup.sizing import DESIGN_PARAMETER
from planar.windup.table import realise

Array = NDArray[np.float64]

# ----------------------------------------------------------------------------- composition and sizing


def _stage_params(number: int, kw: dict[str, Any], u: Array) -> Any:
    """The parameters :class:`ToyMechanism` builds a stage with (its oscillating drivers' amplitude from ``u``)."""
    kw = dict(kw)
    if u.ndim == 1 and ELEMENTAL[number].motions[0] != "Rz" and "amplitude" not in kw:
        amp = float(np.max(np.abs(u)))
        if amp > 0:
            kw["amplitude"] = amp
    return params_for(number, **kw)


def _compose(chain: Chain, cam_phase: float, overrides: dict[Chain, dict[str, Any]], q: Array) -> list[Array] | None:
    """Every stage's world output along ``chain`` (by depth) for motor angles ``q`` (rad), as
    :class:`ToyMechanism` composes it; None where a stage's parameters are refused or it fails at a sample."""
    outs = []
    world = q + cam_phase  # the cam's rotation drives the first stage
    for d in range(1, len(chain) + 1):
        r = realise(chain[d - 1])
        u = _to_base(r, world)
        try:
            P = _stage_params(r.number, overrides.get(chain[:d], {}), u)
            check_params(r.number, P)
        except InputError:
            return None
        res = ELEMENTAL[r.number].forward(P, u)
        if not np.all(res.valid):
            return None
        world = _to_world(r, res.out)
        outs.append(world)
    return outs


def _span(out: Array) -> float:
    """Peak-to-peak of an effector motion (the rotation of OzT)."""
    return float(np.ptp(out[:, 2] if out.ndim == 2 else out))


def _sized_depth(chain: Chain) -> int:
    """Which stage (depth, 1-based) sizes the effector: the last, or its parent for a #10 in a chain."""
    if len(chain) > 1 and realise(chain[-1]).number == 10:
        return len(chain) - 1
    return len(chain)


@dataclass
class _Scan:
    values: Array
    spans: Array  # NaN where invalid

    def reachable(self) -> tuple[float, float] | None:
        ok = np.isfinite(self.spans)
        return (float(self.spans[ok].min()), float(self.spans[ok].max())) if ok.any() else None


def _setter(number: int, base_kw: dict[str, Any], name: str, comp: int | None):
    default = getattr(params_for(number), name)

    def kw(v: float) -> dict[str, Any]:
        out = dict(base_kw)
        if comp is None:
            out[name] = float(v)
        else:
            cur = list(out.get(name, default))
            cur[comp] = float(v)
            out[name] = tuple(cur)
        return out

    return kw, float(default if comp is None else default[comp])


def _span_fn(chain: Chain, depth: int, cam_phase: float, overrides: dict[Chain, dict[str, Any]], q: Array):
    number = realise(chain[depth - 1]).number
    name, comp, bracket, _ = DESIGN_PARAMETER[number]
    kw_of, current = _setter(number, overrides.get(chain[:depth], {}), name, comp)

    def f(v: float) -> float:
        ov = dict(overrides)
        ov[chain[:depth]] = kw_of(v)
        outs = _compose(chain, cam_phase, ov, q)
        return float("nan") if outs is None else _span(outs[-1])

    return f, kw_of, name, bracket, current


def _scan(f, bracket: tuple[float, float], cache: dict | None = None, key: Any = None) -> _Scan:
    if cache is not None and key in cache:
        return cache[key]
    v = np.linspace(bracket[0], bracket[1], SCAN)
    sc = _Scan(v, np.array([f(x) for x in v]))
    if cache is not None:
        cache[key] = sc
    return sc


def _scan_key(chain: Chain, depth: int, overrides: dict[Chain, dict[str, Any]]) -> Any:
    """What a scan depends on: the chain, the sized stage and the overrides along the chain (a cam's phase
    only shifts the cycle)."""
    return (
        chain,
        depth,
        tuple(
            (k, tuple(sorted((n, repr(v)) for n, v in overrides[k].items())))
            for k in (chain[:d] for d in range(1, len(chain) + 1))
            if k in overrides
        ),
    )


def _solve(f, sc: _Scan, target: float, current: float) -> float | None:
    """The parameter value nearest ``current`` whose span is ``target`` (brentq between scan neighbours)."""
    from scipy.optimize import brentq

    d = sc.spans - target
    roots = []
    for k in range(sc.values.size - 1):
        a, b = d[k], d[k + 1]
        if not (np.isfinite(a) and np.isfinite(b)):
            continue
        if a == 0:
            roots.append(float(sc.values[k]))
        elif a * b < 0:
            try:
                roots.append(float(brentq(lambda v: f(v) - target, sc.values[k], sc.values[k + 1], xtol=1e-14, rtol=1e-13)))
            except ValueError:  # an invalid sliver between the scan values
                continue
    roots = [r for r in roots if np.isfinite(f(r))]
    return min(roots, key=lambda r: abs(r - current)) if roots else None


# ----------------------------------------------------------------------------- trees


def _candidates(
    effectors: list[Effector], options: list[list[Chain]], limit: int = 500_000
) -> list[tuple[float, int, list[tuple[str, Chain]]]]:
    """Every assignment of one chain and one cam per effector, cheapest first (cost, then enumeration order)."""
    cams = [[e.cam] if e.cam else list(CAMS) for e in effectors]
    if not any(e.cam for e in effectors):
        cams[0] = [CAMS[0]]  # with no cam named, a tree and its mirror image (cams swapped) are one design
    n = math.prod(len(o) for o in options) * math.prod(len(c) for c in cams)
    if n > limit:
        raise InputError(
            "request", [e.name for e in effectors], f"fewer chain and cam combinations than {limit:,} (this request has {n:,})"
        )
    out = []
    k = 0
    for combo in itertools.product(*options):
        for sides in itertools.product(*cams):
            k += 1
            pairs = list(zip(sides, combo))
            if len(set(pairs)) < len(pairs):
                continue  # two effectors cannot be one stage's follower
            ok = True
            for cam in CAMS:  # one cam turns its effectors at one phase
                ph = {round(e.phase % 1.0, 12) for e, s in zip(effectors, sides) if s == cam}
                if len(ph) > 1:
                    ok = False
            if not ok:
                continue
            tree: dict[str, list[Chain]] = {}
            for s, c in pairs:
                tree.setdefault(s, []).append(c)
            out.append((tree_cost(tree), k, pairs))
    out.sort(key=lambda x: (x[0], x[1]))
    return out


def _no_tree(effectors: list[Effector], options: list[list[Chain]]) -> tuple[str, Any, str]:
    """Why no assignment of chains and cams exists (the fields of an :class:`InputError`): two effectors that
    would be one stage's follower (one chain each, one cam), or the cams' phases."""
    cams = [[e.cam] if e.cam else list(CAMS) for e in effectors]
    for i, j in itertools.combinations(range(len(effectors)), 2):
        a, b = effectors[i], effectors[j]
        shared = set(options[i]) & set(options[j])
        if (
            shared
            and set(options[i]) == shared == set(options[j])
            and set(cams[i]) == set(cams[j])
            and len(cams[i]) * len(options[i]) == 1
        ):
            chain = " ".join(next(iter(shared)))
            return (
                f"effectors {a.name!r} and {b.name!r} ({a.motion}, {b.motion})",
                f"{cams[i][0]} cam",
                f"effectors with a follower each: their only chain, {chain}, on one cam is one stage "
                "(put them on different cams, or ask for different motions)",
            )
    return (
        "request",
        [e.name for e in effectors],
        "an assignment of one chain and one cam per effector (two effectors cannot be one stage's follower, "
        "and one cam turns its effectors at one phase)",
    )


def _size_tree(
    effectors: list[Effector], pairs: list[tuple[str, Chain]], phase: float, q: Array, cache: dict
) -> tuple[dict[tuple[str, Chain], dict[str, Any]], dict[str, tuple[str, str, float]]] | None:
    """Sized overrides (by ``(cam, prefix)``) for one tree, or None when some effector cannot be sized in it."""
    cam_phase = {"left": 0.0, "right": phase}
    per_cam: dict[str, dict[Chain, dict[str, Any]]] = {cam: {} for cam in CAMS}
    fixed: set[tuple[str, Chain]] = set()
    sizing: dict[str, tuple[str, str, float]] = {}
    order = sorted(range(len(effectors)), key=lambda i: (_sized_depth(pairs[i][1]), len(pairs[i][1]), i))
    for i in order:
        e, (cam, chain) = effectors[i], pairs[i]
        depth = _sized_depth(chain)
        key = (cam, chain[:depth])
        if key in fixed:
            return None  # another effector already sized this stage
        f, kw_of, name, bracket, current = _span_fn(chain, depth, cam_phase[cam], per_cam[cam], q)
        sc = _scan(f, bracket, cache, _scan_key(chain, depth, per_cam[cam]))
        v = _solve(f, sc, e.target, current)
        if v is None:
            return None
        per_cam[cam][chain[:depth]] = kw_of(v)
        fixed.add(key)
        sizing[e.name] = (" ".join(chain[:depth]), name, v)
    overrides = {(cam, k): kw for cam, d in per_cam.items() for k, kw in d.items()}
    return overrides, sizing


def _toy_phase(effectors: list[Effector], pairs: list[tuple[str, Chain]]) -> float:
    ph = {cam: e.phase for e, (cam, _) in zip(effectors, pairs)}
    if "left" in ph and "right" in ph:
        return float(2 * math.pi * ((ph["right"] - ph["left"]) % 1.0))
    return 0.0 if "left" in ph else float(2 * math.pi * (ph["right"] % 1.0))
