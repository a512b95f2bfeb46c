"""A notebook that builds a four-bar, shows it, solves it and animates it, executed by ``jupyter nbconvert --execute``."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

NOTEBOOK = Path(__file__).resolve().parent / "data" / "fourbar.ipynb"
ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.slow
def test_notebook_shows_tables_and_players(tmp_path):
    pytest.importorskip("nbconvert", reason="nbconvert and ipykernel (test extra) execute the notebook")
    pytest.importorskip("ipykernel")
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]).rstrip(os.pathsep))
    out = tmp_path / "run.ipynb"
    subprocess.run(
        [sys.executable, "-m", "jupyter", "nbconvert", "--to", "notebook", "--execute", str(NOTEBOOK), "--output", str(out)],
        check=True,
        env=env,
        capture_output=True,
    )
    nb = json.loads(out.read_text())
    code = [c for c in nb["cells"] if c["cell_type"] == "code"]
    outputs = [o for c in code for o in c.get("outputs", [])]
    assert not [o for o in outputs if o["output_type"] == "error"]
    for o in outputs:  # no output over 2,000 characters of plain text
        text = o.get("data", {}).get("text/plain", o.get("text", ""))
        assert len("".join(text)) <= 2000, text
    html = ["".join(c["outputs"][0]["data"].get("text/html", "")) for c in code[:3]]
    mech, motion, player = html
    assert "<table>" in mech and "crank-rocker" in mech and "<iframe srcdoc=" in mech
    assert "<table>" in motion and "360 of 360" in motion and "<iframe srcdoc=" in motion
    assert player.startswith("<iframe srcdoc=") and "requestAnimationFrame" in player
    ratio = float("".join(code[3]["outputs"][0]["data"]["text/plain"]))
    assert 1.0 < ratio < 1.2
