"""Settings from the environment (``PLANAR_MAX_*``, ``PLANAR_THREADS``, ``PLANAR_JIT``) take effect at the next call.

A guard for any cache of the settings: whatever is read must follow every change of ``os.environ``
(from this thread or another, through ``os.environ`` or ``os.environb``), and a bad value must be refused
at every call, naming the variable.
"""

from __future__ import annotations

import os
import random
import threading

import numpy as np
import pytest

from planar.core import limits
from planar.errors import InputError, LimitError
from planar.linkages.chunked import jit_available, threads_default

VARS = ("PLANAR_MAX_SAMPLES", "PLANAR_MAX_MEMORY", "PLANAR_THREADS", "PLANAR_JIT")


def _expected(var: str, text: str | None) -> object:
    """What the setting should be for ``text`` (None: unset), from the documented rules."""
    if var == "PLANAR_JIT":
        return text != "0" and _numba()
    if var == "PLANAR_THREADS":
        return int(text) if text and text.strip() else (os.cpu_count() or 1)
    name = {"PLANAR_MAX_SAMPLES": "samples", "PLANAR_MAX_MEMORY": "memory"}[var]
    return int(text) if text and text.strip() else limits.DEFAULTS[name][1]


def _read(var: str) -> object:
    if var == "PLANAR_JIT":
        return jit_available()
    if var == "PLANAR_THREADS":
        return threads_default()
    return limits.limit({"PLANAR_MAX_SAMPLES": "samples", "PLANAR_MAX_MEMORY": "memory"}[var])


def _numba() -> bool:
    try:
        import numba  # noqa: F401
    except ImportError:
        return False
    return True


def test_every_setting_follows_random_changes(monkeypatch: pytest.MonkeyPatch) -> None:
    for var in VARS:
        monkeypatch.delenv(var, raising=False)  # restored as they were after the test
        assert _read(var) == _expected(var, None)
    rng = random.Random(11)
    now: dict[str, str | None] = dict.fromkeys(VARS)
    for step in range(300):
        var = rng.choice(VARS)
        how = rng.randrange(3)
        if how == 0:
            now[var] = rng.choice(["0", "1", " 3 "]) if var == "PLANAR_JIT" else str(rng.randrange(1, 10**6))
            monkeypatch.setenv(var, now[var])
        elif how == 1:
            monkeypatch.delenv(var, raising=False)
            now[var] = None
        elif os.supports_bytes_environ:
            now[var] = rng.choice(["", " ", "7"])
            os.environb[var.encode()] = now[var].encode()
        for v in VARS:
            assert _read(v) == _expected(v, now[v]), (step, v, now[v])


def test_a_limit_changes_at_the_next_call_and_a_bad_value_is_refused_every_time(monkeypatch: pytest.MonkeyPatch) -> None:
    from planar.linkages import FourBar

    leg = FourBar(4.0, 1.0, 4.0, 3.0)
    q = np.linspace(0.0, 1.0, 50)
    assert leg.solve(q).valid.all()  # the warm path, with the setting read before the change
    monkeypatch.setenv("PLANAR_MAX_SAMPLES", "49")
    with pytest.raises(LimitError, match="PLANAR_MAX_SAMPLES"):
        leg.solve(q)
    monkeypatch.setenv("PLANAR_MAX_SAMPLES", "50")
    assert leg.solve(q).valid.all()
    for _ in range(2):  # not remembered as good after one refusal
        monkeypatch.setenv("PLANAR_MAX_SAMPLES", "lots")
        with pytest.raises(InputError, match="PLANAR_MAX_SAMPLES = 'lots'"):
            leg.solve(q)
        monkeypatch.setenv("PLANAR_THREADS", "zero")
        with pytest.raises(InputError, match="PLANAR_THREADS"):
            threads_default()
        monkeypatch.delenv("PLANAR_THREADS")
    monkeypatch.delenv("PLANAR_MAX_SAMPLES")
    assert leg.solve(q).valid.all()


def test_a_change_from_another_thread_is_seen(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("PLANAR_MAX_CHAIN", raising=False)
    assert limits.limit("chain") == limits.DEFAULTS["chain"][1]
    t = threading.Thread(target=os.environ.__setitem__, args=("PLANAR_MAX_CHAIN", "5"))
    t.start()
    t.join()
    assert limits.limit("chain") == 5
    monkeypatch.delenv("PLANAR_MAX_CHAIN")
    assert limits.limit("chain") == limits.DEFAULTS["chain"][1]
