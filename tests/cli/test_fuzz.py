"""Fuzzers over the contract (slow, derandomized): scene files of every kind and the public API.

Scene fuzzer: one number (or two) of a gallery scene -- four-bars, cams, gears, triads, driven
nodes, toys, elementals -- replaced by a hostile value (NaN, inf, 1e308, 1e-308, a string, a
truth value, ...); ``planar motion`` must exit 0, 2 (one line, nothing written) or 3, never 1, and
a table it writes holds no NaN in a valid row.  API fuzzer: every public constructor and function
called with wrong types and values raises a :class:`planar.errors.PlanarError` or returns, never
another exception.
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from planar.cli.main import main  # noqa: E402
from planar.errors import PlanarError  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
SCENES = sorted((ROOT / "gallery").glob("*.toml"))
_NUMBER = re.compile(r"(?<=[=\[,(\s])-?\d+(\.\d+)?([eE][-+]?\d+)?(?=[\s,\]\n])")
HOSTILE = [
    "nan",
    "inf",
    "-inf",
    "0",
    "-1",
    "0.0",
    "1e308",
    "-1e308",
    "1e-308",
    "1e16",
    "1e-200",
    "1e200",
    "4e7",
    '"1"',
    "true",
    "[]",
    "[1, 2, 3]",
    "99999999999999999999",
    "-0.0",
    "3.5",
]
FUZZ = settings(derandomize=True, max_examples=120, deadline=None, suppress_health_check=list(HealthCheck), database=None)


def _mutate(text: str, picks: list[tuple[int, str]]) -> str:
    spans = [m.span() for m in _NUMBER.finditer(text)]
    if not spans:
        return text
    for k, value in sorted(((k % len(spans), v) for k, v in picks), reverse=True):
        a, b = spans[k]
        text = text[:a] + value + text[b:]
    return text


@pytest.mark.slow
@FUZZ
@given(
    scene=st.sampled_from(SCENES),
    picks=st.lists(st.tuples(st.integers(0, 10_000), st.sampled_from(HOSTILE)), min_size=1, max_size=2),
)
def test_scene_fuzz_never_exit_1(tmp_path_factory: pytest.TempPathFactory, scene: Path, picks) -> None:
    import io
    from contextlib import redirect_stderr, redirect_stdout

    tmp = tmp_path_factory.mktemp("fuzz")
    text = re.sub(r"samples_per_cycle = \d+", "samples_per_cycle = 24", scene.read_text())
    src = tmp / scene.name
    src.write_text(_mutate(text, picks))
    out = tmp / "m.csv"
    err = io.StringIO()
    with redirect_stdout(io.StringIO()), redirect_stderr(err):
        rc = main(["motion", str(src), "-o", str(out)])
    msg = err.getvalue().strip()
    assert rc in (0, 2, 3), f"{scene.name} {picks}: {msg}"
    if rc == 2:
        assert len(msg.splitlines()) == 1 and not out.exists(), msg
    if rc == 0:
        table = np.genfromtxt(out, delimiter=",", skip_header=1)
        table = table.reshape(-1, table.shape[-1])
        valid = table[:, -1] == 1
        assert np.isfinite(table[valid]).all(), f"{scene.name} {picks}: NaN in a valid row"


def _public_calls():
    """``(name, callable(*args))`` for the public entrances under fuzz (built lazily: heavy imports inside)."""
    from planar import Driver, Mechanism, Part
    from planar.analysis import statics
    from planar.core.model import check_finite, check_positive
    from planar.linkages import FourBar, SliderCrank
    from planar.synth.function import synthesise_function
    from planar.windup import elemental

    leg = FourBar(4.0, 1.0, 4.0, 3.0, coupler_point=(5.5, -2.0))
    motion = leg.solve(np.linspace(0.0, 1.0, 5))
    return [
        ("Driver", lambda a, b: Driver(a, phase=b)),
        ("Driver.axis", lambda a, b: Driver("a", kind="translation", axis=(a, b), amplitude=1.0)),
        ("Driver.origin", lambda a, b: Driver("a", origin=(a, b))),
        ("Driver.rate", lambda a, b: Driver("a", rate=a, amplitude=b)),
        ("Part", lambda a, b: Part("p", hull=((a, b, 1.0),))),
        ("Part.name", lambda a, b: Part(a, hull=((0.0, 0.0, b),))),
        ("Mechanism", lambda a, b: Mechanism("m", a, [], Driver("a")) if b else Mechanism(a, [], [], Driver("a"))),
        ("FourBar", lambda a, b: FourBar(a, 1.0, 4.0, b)),
        ("FourBar.coupler_point", lambda a, b: FourBar(4.0, 1.0, 4.0, 3.0, coupler_point=(a, b))),
        ("SliderCrank", lambda a, b: SliderCrank(a, b)),
        ("solve", lambda a, b: leg.solve(a)),
        ("solve.t", lambda a, b: leg.solve([0.0, 1.0], t=[a, b])),
        ("run", lambda a, b: leg.run(samples_per_cycle=a, cycles=b)),
        ("take", lambda a, b: motion.take([a])),
        ("elemental", lambda a, b: elemental(a)),
        ("elemental.D_jr", lambda a, b: elemental(2, D_jr=a)),
        ("synthesise_function", lambda a, b: synthesise_function([0.0, a, 1.0], [0.0, 1.0, 2.0], b)),
        ("motor_torque", lambda a, b: statics.motor_torque(leg, np.linspace(0, 1, 4), {"coupler_point": [a, b]})),
        ("check_finite", lambda a, b: check_finite("x", a)),
        ("check_positive", lambda a, b: check_positive("x", a)),
    ]


WRONG = st.one_of(
    st.sampled_from([math.nan, math.inf, -math.inf, 0, -1, 1e308, -1e308, 1e-308, True, None, "1", "", b"1", [], (), {}]),
    st.floats(allow_nan=True, allow_infinity=True),
    st.integers(-(10**20), 10**20),
    st.text(max_size=3),
    st.lists(st.floats(), max_size=3),
)


@pytest.mark.slow
@settings(FUZZ, max_examples=400)
@given(which=st.integers(0, 19), a=WRONG, b=WRONG)
def test_api_fuzz_raises_planar_errors_only(which: int, a, b) -> None:
    calls = _public_calls()
    name, call = calls[which % len(calls)]
    try:
        with np.errstate(all="ignore"):
            call(a, b)
    except PlanarError as e:
        assert "\n" not in str(e), f"{name}({a!r}, {b!r}): {e}"
    except Exception as e:  # anything else is a raw exception: the contract is broken
        pytest.fail(f"{name}({a!r}, {b!r}) raised {type(e).__name__}: {e}")
