"""Issue 24.6 / 26.4: every command's real peak stays within ``PLANAR_MAX_MEMORY`` x 1.25, or it refuses up front.

Each case runs the command in a subprocess at the default limit (2048 MiB) asking for the most
work the other limits allow (2 000 000 samples), and reads the child's peak resident memory
with ``resource.getrusage(RUSAGE_CHILDREN)`` (a fresh interpreter per case, so the figure is
that command's own).  A refusal must come before the work: exit 2, one line naming
``PLANAR_MAX_MEMORY`` or ``PLANAR_MAX_SAMPLES``, and a small peak.
"""

from __future__ import annotations

import math
import os
import re
import subprocess
import sys
from collections.abc import Callable
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


def peak(argv: list[str], cwd: Path, limit_mib: int | None = None) -> tuple[int, float, str]:
    """Exit status, peak resident memory (MiB) and output of ``planar ARGV`` in a fresh process
    (``PLANAR_MAX_MEMORY=limit_mib`` when given, else the default limit)."""
    env = {k: v for k, v in os.environ.items() if not k.startswith("PLANAR_")}
    env["PYTHONPATH"] = str(ROOT)
    if limit_mib is not None:
        env["PLANAR_MAX_MEMORY"] = str(limit_mib)
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


# --------------------------------------------------------------------------- every command, at a small limit
# The same checks at PLANAR_MAX_MEMORY=SMALL_MIB, where the sizes at the limit are cheap to run: asked for far
# too much, each command refuses up front naming the limit and the size that fits; at that size it runs within
# the limit x 1.25; a little more is refused with nothing written.  That the size named fits proves the estimate
# counts what the command allocates, at every limit (the estimate is the held memory plus a cost per unit).

#: the small limit, MiB
SMALL_MIB = 256
#: a refusal names what fits: "at most 123,456 samples fit"
_FITS = re.compile(r"at most ([\d,]+) ([a-z-]+(?: [a-z-]+)?) fit")


def _fits(out: str) -> int:
    m = _FITS.search(out)
    assert m is not None, f"the refusal names no size that fits: {out}"
    return int(m.group(1).replace(",", ""))


def _refused(rc: int, mib: float, out: str, written: list[Path]) -> None:
    assert rc == 2 and len(out.splitlines()) == 1 and "PLANAR_MAX_MEMORY" in out, out
    assert mib <= REFUSAL_MIB, f"refused after {mib:.0f} MiB (not up front): {out}"
    assert not [p for p in written if p.exists()], f"written on a refusal: {out}"


def _at_the_limit(
    argv: Callable[[int], list[str]],
    big: int,
    cwd: Path,
    written: list[Path],
    limit_mib: int = SMALL_MIB,
    search: bool = True,
) -> tuple[int, float]:
    """The largest size ``argv(n)`` accepts at ``limit_mib`` and its peak (MiB): ``big`` is refused up front naming
    the size that fits; from there, each size accepted peaks within ``limit_mib`` x 1.25 and the next, 25 % more, is
    tried until one is refused (up front, nothing written); the size named is a lower bound (what is held at a
    larger request counts too).  Returns the largest size accepted and its peak."""

    def run(n: int) -> tuple[int, float, str]:
        for p in written:
            p.unlink(missing_ok=True)
        return peak(argv(n), cwd, limit_mib)

    rc, mib, out = run(big)
    _refused(rc, mib, out, written)
    n, best = _fits(out), None
    assert n > 0, out
    for _ in range(8):
        rc, mib, out = run(n)
        if rc != 0:
            _refused(rc, mib, out, written)
            if best is not None:  # accepted, then refused 25 % above: the boundary is found
                return best
            assert 0 < _fits(out) < n, out  # a finer estimate (a pilot solve of what the kind allocates) names less
            n = _fits(out)
            continue
        assert mib <= limit_mib * 1.25, f"{n:,}: peak {mib:.0f} MiB over {limit_mib} x 1.25: {out}"
        best = (n, mib)
        if not search:  # the size named runs within the limit (the boundary above it is not looked for)
            return best
        n = int(n * 1.25) + 1
    raise AssertionError(f"no boundary found near the size named: last {n:,} ({rc}: {out})")


def _scene(tmp_path: Path, name: str, samples: int, cycles: float | None = None) -> Path:
    text = (GALLERY / f"{name}.toml").read_text()
    text = re.sub(r"samples_per_cycle = \d+", f"samples_per_cycle = {samples}", text, count=1)
    if cycles is not None:
        text = re.sub(r"\[driver\]\n", f"[driver]\ncycles = {cycles}\n", text, count=1)
    p = tmp_path / f"{name}-{samples}.toml"
    p.write_text(text)
    return p


@pytest.mark.slow
def test_motion_with_rates_at_the_small_limit(tmp_path: Path) -> None:
    out = tmp_path / "m.csv"

    def argv(n: int) -> list[str]:
        return ["motion", str(_scene(tmp_path, "jansen-leg", n)), "-o", str(out), "--derivatives"]

    _at_the_limit(argv, 2_000_000, tmp_path, [out])


@pytest.mark.slow
def test_catalog_at_the_small_limit(tmp_path: Path) -> None:
    out = tmp_path / "c.csv"
    _at_the_limit(lambda n: ["catalog", "kangaroo", "-o", str(out), "--samples", str(n)], 2_000_000, tmp_path, [out])


@pytest.mark.slow
def test_plot_at_the_small_limit(tmp_path: Path) -> None:
    out = tmp_path / "p.png"
    scene = str(GALLERY / "jansen-leg.toml")
    _at_the_limit(lambda n: ["plot", scene, "-o", str(out), "--samples", str(n)], 2_000_000, tmp_path, [out])


@pytest.mark.slow
def test_plot_of_a_fine_scene_counts_the_charts(tmp_path: Path) -> None:
    """Without --samples the scene's own count is checked with the charts' cost, not the motion's alone."""
    out = tmp_path / "p.png"
    _at_the_limit(lambda n: ["plot", str(_scene(tmp_path, "jansen-leg", n)), "-o", str(out)], 2_000_000, tmp_path, [out])


@pytest.mark.slow
def test_render_at_the_small_limit(tmp_path: Path) -> None:
    """The samples a render draws from (its frames are bounded by PLANAR_MAX_FRAMES and drawn a chunk at a time)."""
    out = tmp_path / "r.gif"
    _at_the_limit(lambda n: ["render", str(_scene(tmp_path, "jansen-leg", n)), "-o", str(out)], 2_000_000, tmp_path, [out])


@pytest.mark.slow
def test_gallery_at_the_small_limit(tmp_path: Path) -> None:
    """A folder of scenes renders each within the limit; one scene too fine is refused before any GIF."""
    src = tmp_path / "scenes"
    src.mkdir()
    out = tmp_path / "gifs"
    out.mkdir()

    def argv(n: int) -> list[str]:
        for p in src.iterdir():
            p.unlink()
        (src / "horse.toml").write_text((GALLERY / "horse.toml").read_text())
        _scene(tmp_path, "jansen-leg", n).rename(src / "jansen-leg.toml")
        return ["gallery", "--source", str(src), "-o", str(out)]

    _at_the_limit(argv, 2_000_000, tmp_path, [out / "horse.gif", out / "jansen-leg.gif"])


@pytest.mark.slow
def test_atlas_build_at_a_small_limit(tmp_path: Path) -> None:
    """The atlas is built into its float32 arrays a chunk at a time: its size is bounded by the limit (420 MiB here,
    beside one chunk's 300 MiB of temporaries: about 450,000 four-bars), refused beyond before any is solved."""
    out = tmp_path / "a.npz"
    _at_the_limit(lambda n: ["synth", "atlas", "--size", str(n), "-o", str(out)], 100_000_000, tmp_path, [out], 420)


@pytest.mark.slow
def test_a_searched_atlas_is_checked_from_its_header(tmp_path: Path) -> None:
    """An atlas file too large to search within the limit is refused before its arrays are read."""
    from planar.synth.atlas import build_atlas

    atlas = tmp_path / "a.npz"
    build_atlas(20_000, 0).save(atlas)
    target = tmp_path / "t.csv"
    target.write_text("x,y\n" + "".join(f"{math.cos(a):.6f},{0.5 * math.sin(a):.6f}\n" for a in (0.0, 1.0, 2.0, 3.0, 4.0, 5.0)))
    out = tmp_path / "d.toml"
    argv = ["synth", "path", str(target), "--atlas", str(atlas), "-o", str(out), "--budget", "quick"]
    rc, mib, text = peak(argv, tmp_path, 1)  # below what the interpreter holds: no atlas fits
    _refused(rc, mib, text, [out])
    assert "an atlas search" in text and "at most 0 four-bars fit" in text and str(atlas) in text, text
    rc, mib, text = peak(argv, tmp_path, SMALL_MIB)
    assert rc in (0, 3) and mib <= SMALL_MIB * 1.25, (rc, mib, text)


def _child_peak(code: str, limit_mib: int) -> tuple[str, float]:
    """Output and peak resident memory (MiB) of ``python -c code`` in a fresh process at ``limit_mib``; it must
    exit 0."""
    env = {k: v for k, v in os.environ.items() if not k.startswith("PLANAR_")}
    env.update(PYTHONPATH=str(ROOT), PLANAR_MAX_MEMORY=str(limit_mib))
    r = subprocess.run([sys.executable, "-c", _PEAK, sys.executable, "-c", code], capture_output=True, text=True, env=env)
    m = re.search(r"rc=(-?\d+) peak_kib=(\d+)", r.stdout)
    assert m is not None and m.group(1) == "0", r.stdout[-1000:] + r.stderr[-1000:]
    return r.stdout[: m.start()], int(m.group(2)) / 1024


#: run ``{fn}({big}, ...)``; its refusal names how many ``{unit}`` fit; run that many (``ran N`` printed)
_AT_THE_SIZE_NAMED = (
    "import re\nfrom planar.errors import LimitError\nfrom {module} import {fn}\n"
    "try:\n    {fn}({big}, {kwargs})\n    msg = ''\nexcept LimitError as e:\n    msg = str(e)\n"
    "n = int(re.search(r'at most ([\\d,]+) {unit} fit', msg).group(1).replace(',', ''))\n"
    "{fn}(n, {kwargs})\nprint('ran', n)\n"
)


@pytest.mark.slow
def test_bench_render_frames_are_checked(tmp_path: Path) -> None:
    """The peer holds every frame until it saves: -n is refused up front where those frames pass the limit,
    naming how many fit.  Every run of the command also renders two 10,000-frame memory checks in child processes
    (minutes of CPU whatever -n is), so the size named is run as the benchmark without them, in a child at the
    small limit (its 200 MiB of libraries leave room for about 30 frames; measured 235 MiB): within 256 MiB x
    1.25.  The estimate is linear in -n beside them: the same check at 2 GiB, where about 2,200 frames fit."""
    rc, mib, out = peak(["bench", "render", "-n", "20000", "--repeats", "1"], tmp_path)
    _refused(rc, mib, out, [])
    n = _fits(out)
    assert 1_000 < n < 20_000, out  # 480 x 360 px at 5 bytes a pixel: about 2,200 frames in 2 GiB
    code = _AT_THE_SIZE_NAMED.format(
        module="planar.bench.render", fn="bench_render", big=20_000, kwargs="repeats=1, memory_frames=0", unit="frames"
    )
    text, mib = _child_peak(code, SMALL_MIB)
    assert int(text.split("ran ")[1].split()[0]) >= 10 and mib <= SMALL_MIB * 1.25, (text, f"{mib:.0f} MiB")


@pytest.mark.slow
def test_compare_at_a_small_limit(tmp_path: Path) -> None:
    """A simulated run holds its recorded poses and motions: refused up front beyond the limit."""

    def argv(n: int) -> list[str]:
        return ["compare", str(_scene(tmp_path, "slider-crank", n)), "--time-cap", "5"]

    # 100,000 samples, not 2,000,000: a refusal names the size that fits beside what it holds, and the motion of
    # 2 million samples is held when the run is checked (the size named then is far below the boundary)
    _at_the_limit(argv, 100_000, tmp_path, [])


@pytest.mark.slow
def test_bench_sim_at_a_small_limit(tmp_path: Path) -> None:
    """Refused up front, and the size named runs within the limit (the refusal at 2e6 holds that request's time
    arrays, so the size it names is far below the boundary: 8 steps of 25 % did not reach it)."""
    argv = ["bench", "sim", "--repeats", "1", "-n"]
    _at_the_limit(lambda n: [*argv, str(n)], 2_000_000, tmp_path, [], search=False)


@pytest.mark.slow
def test_toy_at_a_small_limit(tmp_path: Path) -> None:
    """A toy's coupled run takes 128 physics steps a sample (5 ms of CPU a sample for the Horse): the largest size
    the default limit accepts (about a million samples) would take more than an hour, and even 256 MiB accepts
    tens of thousands.  At 160 MiB the run's own check (its samples beside one chunk of the imposed poses of
    65,536 steps, 120 MiB for the Horse) accepts about 440 samples: the Horse at 2,000,000 is refused where its
    motion is checked; at 5,000 by the run's check, which names the size that runs within 160 MiB x 1.25 (3 s of
    CPU), and 25 % more is refused.  The estimate is linear in the samples beside the
    chunk: the same check at any limit."""
    rc, mib, out = peak(["toy", str(_scene(tmp_path, "horse", 2_000_000))], tmp_path, 160)
    _refused(rc, mib, out, [])
    assert "samples_per_cycle" in out, out
    # from 5,000 (whose motion the check holds is small): refused by the run's check, naming the size that fits
    _at_the_limit(lambda n: ["toy", str(_scene(tmp_path, "horse", n))], 5_000, tmp_path, [], 160)


@pytest.mark.slow
def test_chains_table_at_the_chain_limit_holds_one_assembly_at_a_time(tmp_path: Path) -> None:
    """The table form of `chains --max-length 8 --optional` checks each of its 128,054 chains' assembly, one at a
    time (4.6 ms each: about 10 minutes of CPU, too long to run here): its memory is the enumeration (the --json
    form, run whole in the fixed-size test: 95 MiB) and one chain's assembly.  Here with a time budget: the process
    is stopped after 10 s of CPU (RLIMIT_CPU), past the enumeration of all 128,054 and a few thousand assemblies of
    chains of up to 8 stages; its peak is within the default limit, and at most 64 MiB above the --json form's."""
    import resource
    import signal

    def run(argv: list[str]) -> tuple[int, float]:
        def budget() -> None:
            resource.setrlimit(resource.RLIMIT_CPU, (10, 10))

        env = {k: v for k, v in os.environ.items() if not k.startswith("PLANAR_")}
        env["PYTHONPATH"] = str(ROOT)
        r = subprocess.run(
            [sys.executable, "-c", _PEAK, sys.executable, "-m", "planar", *argv],
            capture_output=True,
            text=True,
            cwd=tmp_path,
            env=env,
            preexec_fn=budget,
        )
        m = re.search(r"rc=(-?\d+) peak_kib=(\d+)", r.stdout)
        assert m is not None, r.stdout[-500:] + r.stderr[-500:]
        return int(m.group(1)), int(m.group(2)) / 1024

    rc_json, enum_mib = run(["chains", "--max-length", "8", "--optional", "--json"])
    assert rc_json == 0, rc_json
    rc, mib = run(["chains", "--max-length", "8", "--optional"])
    assert rc in (-signal.SIGXCPU, -signal.SIGKILL), rc  # still at work when its budget ran out (not refused, not failed)
    assert mib <= LIMIT_MIB * 1.25 and mib <= enum_mib + 64, (f"{mib:.0f} MiB", f"--json {enum_mib:.0f} MiB")


#: commands whose work does not grow with any option beyond what their inputs hold (a scene's parts, a request's
#: effectors, a file's targets: each bounded where it is read): their peak at the small limit on the largest inputs
_FIXED: dict[str, list[str]] = {
    "info": ["info", "{fine}"],
    "export": [
        "export",
        "{fine}",
        "-o",
        "{tmp}/p.dxf",
        "--svg",
        "{tmp}/p.svg",
        "--preview",
        "{tmp}/p.png",
        "--bom",
        "{tmp}/b.csv",
        "--assembly",
        "{tmp}/a.svg",
        "--plan",
        "{tmp}/p.json",
        "--motion",
        "{tmp}/m.csv",
        "--steps",
        "{tmp}/s.svg",
    ],
    # the whole enumeration at the limit's 8 (128,054 chains, 95 MiB, under a second); the table form also checks
    # each chain's assembly, one at a time (4.6 ms each: 10 minutes at 8), tested at 8 with a CPU budget above
    # (it replaces a run of the table at 6: 27 s of CPU, 46 MiB)
    "chains-json": ["chains", "--max-length", "8", "--optional", "--json"],
    "schema": ["schema", "-o", "{tmp}/s.json"],
    # 3 to 5 poses: fixed work (measured 194 MiB)
    "synth-motion": ["synth", "motion", "{poses}", "-o", "{tmp}/m.toml"],
    "demo": ["demo", "-o", "{tmp}/demo"],
}


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(_FIXED))
def test_fixed_size_commands_within_the_small_limit(tmp_path: Path, name: str) -> None:
    fine = _scene(tmp_path, "jansen-leg", 2_000_000)
    poses = tmp_path / "poses.csv"
    poses.write_text("x,y,angle\n0,0,0\n1,0.3,0.2\n2,0.5,0.35\n3,0.4,0.5\n4,0.1,0.6\n")
    argv = [a.format(fine=fine, tmp=tmp_path, poses=poses) for a in _FIXED[name]]
    rc, mib, out = peak(argv, tmp_path, SMALL_MIB)
    assert rc == 0 and mib <= SMALL_MIB * 1.25, (rc, f"{mib:.0f} MiB", out[-500:])


# --------------------------------------------------------------------------- the rest, at their largest accepted size
# Each command the tests above leave out, at the default limit and the most work the other limits accept (or, where
# that takes too long, the reason and what is run instead, in the test's docstring).


def _design_request(tmp_path: Path) -> Path:
    """Three free-cam effectors at --max-length 4: 81 x 38 x 38 chains x 4 cam choices = 467,856 combinations,
    the most under the 500,000 the design accepts (one more stage, 5, is refused up front)."""
    req = tmp_path / "r.toml"
    req.write_text(
        "".join(
            f'[[effector]]\nname = "{n}"\nmotion = "{m}"\nrange = {r}\n\n'
            for n, m, r in (("head", "Oz", 30.0), ("tail", "Tx", 0.3), ("arm", "Ty", 0.3))
        )
    )
    return req


@pytest.mark.slow
def test_design_at_the_combination_limit(tmp_path: Path) -> None:
    """The request's chain and cam combinations are bounded (500,000); the largest accepted here is 467,856: every
    one is enumerated and ranked before the cheapest trees are sized (about 25 s of CPU, 320 MiB)."""
    req, out = _design_request(tmp_path), tmp_path / "d.toml"
    rc, mib, text = peak(["design", str(req), "-o", str(out), "--max-length", "4"], tmp_path)
    assert rc in (0, 3) and mib <= LIMIT_MIB * 1.25, (rc, f"{mib:.0f} MiB", text[-500:])
    rc, mib, text = peak(["design", str(req), "-o", str(out), "--max-length", "5"], tmp_path)
    assert rc == 2 and len(text.splitlines()) == 1 and "combinations" in text, text
    assert mib <= REFUSAL_MIB, f"refused after {mib:.0f} MiB (not up front): {text}"


@pytest.mark.slow
def test_synth_function_at_the_pair_limit(tmp_path: Path) -> None:
    """5,000 pairs, the most a pairs file may hold (the synthesis samples the input range at a fixed count
    besides): within the default limit (measured 316 MiB, 12 s of CPU)."""
    pairs = tmp_path / "p.csv"
    pairs.write_text(
        "input,output\n"
        + "".join(f"{a:.9f},{0.5 + 0.6 * math.sin(a):.9f}\n" for a in (0.2 + 1.2 * i / 4999 for i in range(5000)))
    )
    rc, mib, text = peak(["synth", "function", str(pairs), "-o", str(tmp_path / "f.toml")], tmp_path)
    assert rc in (0, 3) and mib <= LIMIT_MIB * 1.25, (rc, f"{mib:.0f} MiB", text[-500:])
    pairs.write_text(pairs.read_text() + "1.5,0.9\n")  # one pair more is refused where the file is read
    rc, mib, text = peak(["synth", "function", str(pairs), "-o", str(tmp_path / "f.toml")], tmp_path)
    assert rc == 2 and "at most 5000 pairs" in text and mib <= REFUSAL_MIB, (rc, mib, text)


@pytest.mark.slow
def test_synth_path_at_the_target_limit(tmp_path: Path) -> None:
    """500 targets, the most a targets file (or --points along an SVG) may give, on a four-bar's coupler curve, at
    the default budget (its atlas of 1,000,000 four-bars read from the cache, or built on first use within the
    atlas's own check): measured 638 MiB, 6 s of CPU.  Targets no four-bar reaches make the global search run for
    minutes at 500 targets; its memory does not grow with them (populations of the search's size x the targets,
    measured 106 MiB at the quick budget)."""
    import numpy as np

    from planar.linkages import FourBar

    q = np.linspace(0.0, 2 * np.pi, 500, endpoint=False)
    pts = np.asarray(FourBar(4.0, 1.0, 4.0, 3.0, coupler_point=(2.0, 1.0)).solve(q).points["coupler_point"])
    targets = tmp_path / "t.csv"
    targets.write_text("x,y\n" + "".join(f"{x:.9f},{y:.9f}\n" for x, y in pts))
    rc, mib, text = peak(["synth", "path", str(targets), "-o", str(tmp_path / "p.toml")], tmp_path)
    assert rc in (0, 3) and mib <= LIMIT_MIB * 1.25, (rc, f"{mib:.0f} MiB", text[-500:])


@pytest.mark.slow
def test_bench_kinematics_at_the_sample_limit(tmp_path: Path) -> None:
    """-n is checked against PLANAR_MAX_SAMPLES: 2,000,000 samples (one timing repeat; measured 958 MiB, 6 s)."""
    rc, mib, text = peak(["bench", "kinematics", "-n", "2000000", "--repeats", "1"], tmp_path)
    assert rc in (0, 3) and mib <= LIMIT_MIB * 1.25, (rc, f"{mib:.0f} MiB", text[-500:])


@pytest.mark.slow
def test_bench_synthesis_candidates_are_checked(tmp_path: Path) -> None:
    """-n candidates of the kernel-rate measurement (1.2 kB each: float64 coupler points at 64 angles) are
    checked before the benchmark's problems run: 2,000,000 is refused at the default limit, naming how many fit.
    The benchmark around them takes minutes whatever -n is (pylinkage's runs, the reachable curves), so the size
    named is run as the measurement alone, in a child at the small limit (the estimate is linear in -n: a run at
    256 MiB checks the same cost per candidate as one at 2 GiB)."""
    rc, mib, text = peak(["bench", "synthesis", "--quick", "-n", "2000000"], tmp_path)
    _refused(rc, mib, text, [])
    assert 1_000_000 < _fits(text) < 2_000_000, text
    code = _AT_THE_SIZE_NAMED.format(
        module="planar.bench.synthesis", fn="kernel_rate", big=10**8, kwargs="repeats=1", unit="candidates"
    )
    text, mib = _child_peak(code, SMALL_MIB)
    assert int(text.split("ran ")[1].split()[0]) > 50_000 and mib <= SMALL_MIB * 1.25, (text, f"{mib:.0f} MiB")


@pytest.mark.slow
def test_bench_accuracy_of_a_fine_scene_is_refused_up_front(tmp_path: Path) -> None:
    """bench accuracy simulates every scene of --scenes over one cycle at each setting of its grid (about 30 runs
    with --quick): a scene at the size the limit accepts (466,033 samples of the slider-crank at 256 MiB, 2 million
    at the default limit) would take hours, so here only its refusals: a scene too fine for its motion is refused
    where it is loaded; one whose motion fits but whose simulated runs do not is refused by the runs' check
    (`compare`'s, tested above at the size it names) before the first run; nothing is written either way."""
    src = tmp_path / "scenes"
    src.mkdir()
    out = tmp_path / "acc"
    argv = ["bench", "accuracy", "--quick", "--scenes", str(src), "-o", str(out)]
    written = [out / "accuracy.csv", out / "accuracy.png"]
    _scene(tmp_path, "slider-crank", 2_000_000).rename(src / "slider-crank.toml")
    rc, mib, text = peak(argv, tmp_path, SMALL_MIB)
    _refused(rc, mib, text, written)
    assert "samples_per_cycle" in text, text
    _scene(tmp_path, "slider-crank", _fits(text)).rename(src / "slider-crank.toml")
    rc, mib, text = peak(argv, tmp_path, SMALL_MIB)
    _refused(rc, mib, text, written)
    assert "simulated run" in text and _fits(text) > 0, text


# --------------------------------------------------------------------------- at the default limit, by a line
# `toy` and `bench accuracy` spend milliseconds of CPU a sample (128 physics steps each; some 30 simulated runs),
# so the largest size the default limit accepts (hundreds of thousands of samples) would run for an hour.  Their
# test at the default limit: far too much is refused up front naming the count that fits, and the peak is
# measured at three sizes past the one where the physics chunk (65,536 steps) is full, up to about a minute of
# CPU in all; the peak is linear in the samples there (checked: the middle size lies on the line through the
# others), its slope is at most the estimate's cost per sample, and the line reaches at most the limit x 1.25 at
# the count the refusal named.


def _peak_line(argv: Callable[[int], list[str]], sizes: tuple[int, int, int], cwd: Path) -> tuple[float, float]:
    """Intercept (MiB) and slope (MiB a sample) of the peak of ``argv(n)`` at the default limit over ``sizes``;
    each run succeeds and the middle one lies within 4 MiB of the line through the outer two."""
    peaks = []
    for n in sizes:
        rc, mib, out = peak(argv(n), cwd)
        assert rc == 0, out
        peaks.append(mib)
    (n0, n1, n2), (p0, p1, p2) = sizes, peaks
    slope = (p2 - p0) / (n2 - n0)
    print(f"peaks (MiB) {dict(zip(sizes, (round(p, 1) for p in peaks)))}: {slope * 2**20:.0f} B a sample")
    assert abs(p0 + slope * (n1 - n0) - p1) <= 4.0, f"not linear in the samples: {dict(zip(sizes, peaks))}"
    return p0 - slope * n0, slope


def _estimated_per_sample_mib(scene: Path) -> float:
    """The simulated run's estimate per sample (MiB): three times the motion's bytes, as planar.physics counts it."""
    import planar
    from planar.core.limits import motion_bytes
    from planar.physics.toy import coupled_mechanism
    from planar.toys.assembly import toy_assembly

    mech = planar.load_scene(scene).mechanism
    if mech.stages:  # a toy's run is of its coupled pieces
        mech = coupled_mechanism(toy_assembly(mech))
    return 1.5 * motion_bytes(len(mech.parts), len(mech.points), 2.0) / 2**20


@pytest.mark.slow
def test_toy_at_the_default_limit(tmp_path: Path) -> None:
    """The Horse: 2,000,000 samples are refused where its motion is checked, naming what fits; that many are
    refused by the coupled run's check, up front (before, the scene's motion of 1.2 million samples was solved
    first: 1.1 GB, then refused), naming the count the run fits.  Peaks at 800, 2,400 and 7,200 samples (about a
    minute of CPU; measured 189 MiB at 600 and 199 MiB at 5,000) put that count within 2,048 MiB x 1.25."""

    def argv(n: int) -> list[str]:
        return ["toy", str(_scene(tmp_path, "horse", n))]

    rc, mib, out = peak(argv(2_000_000), tmp_path)
    _refused(rc, mib, out, [])
    assert "samples_per_cycle" in out, out
    rc, mib, out = peak(argv(_fits(out)), tmp_path)
    _refused(rc, mib, out, [])
    assert "simulated run" in out, out
    fits = _fits(out)
    base, slope = _peak_line(argv, (800, 2_400, 7_200), tmp_path)
    assert 0 < slope <= _estimated_per_sample_mib(_scene(tmp_path, "horse", 800)), f"{slope * 2**20:.0f} B a sample"
    print(f"{fits:,} samples fit: the line reaches {base + slope * fits:.0f} MiB there")
    assert base + slope * fits <= LIMIT_MIB * 1.25, f"{fits:,} samples: {base:.0f} + {slope * 2**20:.0f} B a sample"


@pytest.mark.slow
def test_bench_accuracy_at_the_default_limit(tmp_path: Path) -> None:
    """The slider-crank at 2,000,000 samples is refused before its first run, naming what fits (about a million;
    every setting of the quick grid runs at it: hours).  Peaks at 4,000, 8,000 and 16,000 samples (about a
    minute of CPU; below about 2,400 the physics chunk is still growing) put that count within 2,048 MiB x 1.25."""
    src = tmp_path / "scenes"
    src.mkdir()
    out_dir = tmp_path / "acc"
    written = [out_dir / "accuracy.csv", out_dir / "accuracy.png"]

    def argv(n: int) -> list[str]:
        for p in src.iterdir():
            p.unlink()
        _scene(tmp_path, "slider-crank", n).rename(src / "slider-crank.toml")
        return ["bench", "accuracy", "--quick", "--repeats", "1", "--scenes", str(src), "-o", str(out_dir)]

    rc, mib, out = peak(argv(2_000_000), tmp_path)
    _refused(rc, mib, out, written)
    assert "simulated run" in out, out
    fits = _fits(out)
    base, slope = _peak_line(argv, (4_000, 8_000, 16_000), tmp_path)
    assert 0 < slope <= _estimated_per_sample_mib(src / "slider-crank.toml"), f"{slope * 2**20:.0f} B a sample"
    print(f"{fits:,} samples fit: the line reaches {base + slope * fits:.0f} MiB there")
    assert base + slope * fits <= LIMIT_MIB * 1.25, f"{fits:,} samples: {base:.0f} + {slope * 2**20:.0f} B a sample"
