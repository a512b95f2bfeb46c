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
