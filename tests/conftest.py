"""Hypothesis runs the same examples on every run (``derandomize``), so the suite's verdict does not depend on
the run; ``HYPOTHESIS_PROFILE=explore`` draws new random examples (how the nearly-equal-radii circle-circle
bug was found), to be run by hand."""

from __future__ import annotations

import os

from hypothesis import settings

settings.register_profile("repeatable", derandomize=True)
settings.register_profile("explore", derandomize=False)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "repeatable"))
