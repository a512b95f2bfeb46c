"""Issue 24.6 / 26.4: every command's real peak stays within ``PLANAR_MAX_MEMORY`` x 1.25, or it refuses up front.

Each case runs the command in a subprocess at the default limit (2048 MiB) asking for the most
work the other limits allow (2 000 000 samples), and reads the child's peak resident memory
with ``resource.getrusage(RUSAGE_CHILDREN)`` (a fresh interpreter per case, so the figure is
that command's own).  A refusal must come before the work: exit 2, one line naming
``PLANAR_MAX_MEMORY`` or ``PLANAR_MAX_SAMPLES``, and a small peak.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
GALLERY = ROOT / "gallery"
#: the default memory limit, MiB (planar.core.limits)
LIMIT_MIB = 2048
#: what a refusal may cost: the interpreter, numpy and the scene, no samples
REFUSAL_MIB = 400

_PEAK = (
    "import resource, subprocess, sys\n"
    "p = subprocess.run(sys.argv[1:], capture_output=True, text=True)\n"
    "sys.stdout.write(p.stdout + p.stderr)\n"
    "print(f'\\nrc={p.returncode} peak_kib={resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss}')\n"
)


def peak(argv: list[str], cwd: Path) -> tuple[int, float, str]:
    """Exit status, peak resident memory (MiB) and output of ``planar ARGV`` in a fresh process."""
    env = {k: v for k, v in os.environ.items() if not k.startswith("PLANAR_")}
    env["PYTHONPATH"] = str(ROOT)
    r = subprocess.run(
        [sys.executable, "-c", _PEAK, sys.executable, "-m", "planar", *argv], capture_output=True, text=True, cwd=cwd, env=env
    )
    m = re.search(r"rc=(-?\d+) peak_kib=(\d+)", r.stdout)
    assert m is not None, r.stdout + r.stderr
    return int(m.group(1)), int(m.group(2)) / 1024, r.stdout[: m.start()].strip()


def _big(tmp_path: Path, name: str, samples: int = 2_000_000) -> Path:
    text = (GALLERY / f"{name}.toml").read_text()
    text = re.sub(r"samples_per_cycle = \d+", f"samples_per_cycle = {samples}", text, count=1)
    p = tmp_path / f"{name}.toml"
    p.write_text(text)
    return p


def _within_or_refused(rc: int, mib: float, out: str) -> None:
    if rc == 0:
        assert mib <= LIMIT_MIB * 1.25, f"peak {mib:.0f} MiB over {LIMIT_MIB} x 1.25: {out}"
    else:
        assert rc == 2 and len(out.splitlines()) == 1, out
        assert "PLANAR_MAX_MEMORY" in out or "PLANAR_MAX_SAMPLES" in out, out
        assert mib <= REFUSAL_MIB, f"refused after {mib:.0f} MiB (not up front): {out}"


@pytest.mark.slow
@pytest.mark.parametrize("scene", ["jansen-leg", "cam-automaton", "kangaroo-leg"])
@pytest.mark.parametrize("derivatives", [False, True])
def test_motion_at_the_sample_limit(tmp_path: Path, scene: str, derivatives: bool) -> None:
    argv = ["motion", str(_big(tmp_path, scene)), "-o", str(tmp_path / "m.csv")] + (["--derivatives"] if derivatives else [])
    _within_or_refused(*peak(argv, tmp_path))


@pytest.mark.slow
def test_catalog_at_the_sample_limit(tmp_path: Path) -> None:
    _within_or_refused(*peak(["catalog", "jansen", "-o", str(tmp_path / "c.csv"), "--samples", "2000000"], tmp_path))


@pytest.mark.slow
def test_plot_at_the_sample_limit(tmp_path: Path) -> None:
    argv = ["plot", str(GALLERY / "jansen-leg.toml"), "-o", str(tmp_path / "p.png"), "--samples", "2000000"]
    _within_or_refused(*peak(argv, tmp_path))


@pytest.mark.slow
def test_compare_of_a_long_scene_stays_within_the_limit(tmp_path: Path) -> None:
    """The comparison's own streaming is the physics room's; here only: within the limit, or refused up front."""
    # 100,000 samples of the scene (2.8 M solver steps): the memory of a long compare without an hour of CPU
    _within_or_refused(*peak(["compare", str(_big(tmp_path, "kangaroo-leg", 100_000))], tmp_path))


@pytest.mark.slow
def test_a_low_limit_refuses_before_the_work(tmp_path: Path) -> None:
    """At PLANAR_MAX_MEMORY=64 the same Jansen table is refused, naming the variable, before any sample."""
    env = {**os.environ, "PYTHONPATH": str(ROOT), "PLANAR_MAX_MEMORY": "64"}
    argv = ["motion", str(_big(tmp_path, "jansen-leg", 200_000)), "-o", str(tmp_path / "m.csv"), "--derivatives"]
    r = subprocess.run([sys.executable, "-m", "planar", *argv], capture_output=True, text=True, cwd=tmp_path, env=env)
    assert r.returncode == 2 and "PLANAR_MAX_MEMORY" in r.stderr and not (tmp_path / "m.csv").exists(), r.stderr
