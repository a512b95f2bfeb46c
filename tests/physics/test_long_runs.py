"""Long runs are streamed: memory bounded by a chunk, PLANAR_MAX_SAMPLES on the scene's own samples."""

import os
import subprocess
import sys
import textwrap

import pytest

LONG = """\
name = "long-four-bar"
[mechanism]
type = "fourbar"
ground = 4.0
crank = 1.0
coupler = 4.0
rocker = 3.0
[driver]
speed = 1.0
samples_per_cycle = 10
cycles = {cycles}
"""


def _peak_rss_of_compare(tmp_path, cycles: int, limit: int) -> tuple[int, str, int]:
    scene = tmp_path / "long.toml"
    scene.write_text(LONG.format(cycles=cycles))
    probe = textwrap.dedent(
        f"""
        import resource, subprocess, sys
        r = subprocess.run([sys.executable, "-m", "planar", "compare", {str(scene)!r}], capture_output=True, text=True)
        peak = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss  # KiB on Linux
        print(r.returncode, peak)
        sys.stderr.write(r.stdout + r.stderr)
        """
    )
    env = dict(os.environ, PLANAR_MAX_SAMPLES=str(limit))
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, env=env)
    code, peak = (int(x) for x in out.stdout.split())
    return code, out.stderr, peak


@pytest.mark.slow
def test_ten_thousand_revolutions_within_a_gigabyte(tmp_path):
    # 100,000 samples, 13 million physics steps: the limit is the scene's own sample count, so no internal grid
    # (per-step poses, the torque's fine grid) may be solved in one piece
    code, text, peak_kib = _peak_rss_of_compare(tmp_path, 10_000, 100_000)
    assert code == 0, text
    assert "100000 samples" in text and "held at" in text
    assert peak_kib < 1024 * 1024, peak_kib  # 1 GiB


@pytest.mark.slow
def test_the_sample_limit_is_the_scenes_own(tmp_path):
    code, text, _ = _peak_rss_of_compare(tmp_path, 10, 99)  # 100 samples against a limit of 99
    assert code == 2 and "PLANAR_MAX_SAMPLES" in text and "Traceback" not in text
