"""Synthesis tests build their atlases in a temporary cache folder, never the user's."""

import pytest


@pytest.fixture(autouse=True)
def _atlas_cache(tmp_path_factory, monkeypatch):
    monkeypatch.setenv("PLANAR_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "atlas-cache"))
