"""Hypothesis runs the same examples on every run (``derandomize``), so the suite's verdict does not depend on
the run; ``HYPOTHESIS_PROFILE=explore`` draws new random examples (how the nearly-equal-radii circle-circle
bug was found), to be run by hand."""

from __future__ import annotations

import os

from hypothesis import settings

settings.register_profile("repeatable", derandomize=True)
settings.register_profile("explore", derandomize=False)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "repeatable"))


# --------------------------------------------------------------------------- slow tests
# Tests marked ``slow`` (about half a second of CPU or more each) are left out of the
# default run and run with ``--runslow`` (networkx's pattern); CI runs both sets.


def pytest_addoption(parser):  # type: ignore[no-untyped-def]
    parser.addoption("--runslow", action="store_true", default=False, help="run the tests marked slow too")


def pytest_configure(config):  # type: ignore[no-untyped-def]
    config.addinivalue_line("markers", "slow: a test of half a second of CPU or more; run with --runslow")


def pytest_collection_modifyitems(config, items):  # type: ignore[no-untyped-def]
    if config.getoption("--runslow"):
        return
    import pytest

    skip = pytest.mark.skip(reason="slow: run with --runslow")
    for item in items:
        if "slow" in item.keywords:
            item.add_marker(skip)
