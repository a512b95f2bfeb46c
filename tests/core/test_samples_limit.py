"""Issue 15: ``samples_per_cycle`` is bounded by PLANAR_MAX_SAMPLES (samples x cycles), not a hidden 100000."""

from __future__ import annotations

import pytest

from planar.cli.main import main

SCENE = '[mechanism]\ntype = "fourbar"\nground = 4\ncrank = 1\ncoupler = 4\nrocker = 3\n[driver]\nsamples_per_cycle = {n}\n'


@pytest.mark.slow
def test_samples_per_cycle_follows_the_documented_limit(tmp_path, capsys, monkeypatch):
    scene = tmp_path / "s.toml"
    out = tmp_path / "m.csv"
    scene.write_text(SCENE.format(n=150_000))
    monkeypatch.delenv("PLANAR_MAX_SAMPLES", raising=False)
    assert main(["motion", str(scene), "-o", str(out)]) == 0  # was refused at 100000
    assert sum(1 for _ in out.open()) == 150_001
    out.unlink()
    monkeypatch.setenv("PLANAR_MAX_SAMPLES", "100000")
    assert main(["motion", str(scene), "-o", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "driver.samples_per_cycle = 150000" in err and "PLANAR_MAX_SAMPLES" in err
    assert not out.exists()


def test_env_text_reads_what_os_environ_get_reads(monkeypatch: pytest.MonkeyPatch) -> None:
    """The settings' quick read gives os.environ.get's answer: unset, set, changed, non-ASCII, deleted."""
    import os

    from planar.core.limits import env_text

    name = "PLANAR_TEST_ENV_TEXT"
    monkeypatch.delenv(name, raising=False)
    assert env_text(name) is None and os.environ.get(name) is None
    for value in ("1", "", " 2 ", "caf\u00e9", "x" * 300):
        monkeypatch.setenv(name, value)
        assert env_text(name) == os.environ.get(name) == value
    monkeypatch.delenv(name)
    assert env_text(name) is None
    monkeypatch.setattr(os, "environ", {name: "other mapping"})  # not CPython's: os.environ.get itself
    assert env_text(name) == "other mapping"
