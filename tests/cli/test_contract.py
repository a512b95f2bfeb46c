"""Issue 26: the contract on the newer surfaces, case by case as a user met them.

Each case: exit 2 with one line naming the file, field or option and the value; nothing written; no
traceback; or (where planar can honour the request) a correct result.  The numbers come from the
issue's abuse trial (``--ground 1e300``, a placement at 1e308 or 1e16, a leg scaled by 1e-200, ...).
"""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from clicheck import fails_cleanly as _fails_cleanly

from planar.cli.main import main

ROOT = Path(__file__).resolve().parents[2]
GALLERY = ROOT / "gallery"
KANGAROO = (GALLERY / "kangaroo-leg.toml").read_text()


def _scene(tmp_path: Path, text: str, name: str = "s.toml") -> Path:
    p = tmp_path / name
    p.write_text(text)
    return p


# ----------------------------------------------------------------------------- exit 1 before the fix


@pytest.mark.parametrize("ground", ["1e300", "1e-300", "inf", "nan", "-1", "0", "1e61"])
def test_synth_function_ground_out_of_range(tmp_path: Path, capsys: pytest.CaptureFixture[str], ground: str) -> None:
    pairs = tmp_path / "p.csv"
    pairs.write_text("input,output\n0.3,1.0\n1.1,1.4\n2.0,1.9\n")
    out = tmp_path / "f.toml"
    _fails_cleanly(capsys, ["synth", "function", str(pairs), "-o", str(out), "--ground", ground], "--ground", out=out)


def test_synth_function_ground_at_the_range_ends_works(tmp_path: Path) -> None:
    """Angles do not depend on the scale: the same pairs at ground 1e-59 and 1e59 give a valid scene."""
    pairs = tmp_path / "p.csv"
    pairs.write_text("input,output\n0.3,1.0\n1.1,1.4\n2.0,1.9\n")
    for g in ("1e-59", "1e59"):
        assert main(["synth", "function", str(pairs), "-o", str(tmp_path / "f.toml"), "--ground", g]) == 0


def test_request_file_in_utf16_is_read(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A request saved as UTF-16 (byte-order mark FF FE) reads as its UTF-8 twin; undecodable bytes are one line."""
    from planar.synth.design import load_request

    text = '[[effector]]\nname = "ear"\nmotion = "Oz"\nrange = 20.0\n'
    u8, u16 = tmp_path / "a.toml", tmp_path / "b.toml"
    u8.write_text(text, encoding="utf-8")
    u16.write_bytes(b"\xff\xfe" + text.encode("utf-16-le"))
    assert load_request(u16) == load_request(u8)
    bad = tmp_path / "bad.toml"
    bad.write_bytes(b"\xff\xfe[\x00\x00\xd8")  # a lone surrogate half: not UTF-16 either
    _fails_cleanly(capsys, ["design", str(bad), "-o", str(tmp_path / "t.toml")], str(bad), out=tmp_path / "t.toml")
    binary = tmp_path / "bin.toml"
    binary.write_bytes(b"\x89PNG\r\n\x1a\n\x00\x00")
    _fails_cleanly(capsys, ["design", str(binary), "-o", str(tmp_path / "t.toml")], "UTF-8", out=tmp_path / "t.toml")


@pytest.mark.parametrize("where", ["1e308", "-1e308", "1e16", "4e7"])
@pytest.mark.parametrize("command", ["motion", "export", "compare", "plot"])
def test_placement_beyond_float64_resolution(tmp_path: Path, capsys, where: str, command: str) -> None:
    """At y = 1e16 float64's spacing is 2: a four-bar of 1-4 unit links would be computed into nonsense."""
    scene = _scene(tmp_path, KANGAROO.replace("[mechanism]\n", f"[mechanism]\nplacement = [0, {where}, 0]\n", 1))
    suffix = {"motion": ".csv", "export": ".dxf", "plot": ".png"}.get(command)
    out = tmp_path / f"o{suffix}" if suffix else None
    argv = [command, str(scene)] + (["-o", str(out)] if out else [])
    _fails_cleanly(capsys, argv, "placement", "float64", out=out)


def test_placement_near_the_origin_still_works(tmp_path: Path) -> None:
    """1e5 units away from a mechanism of 0.3-unit pins is resolved to 1.5e-11: allowed, and the same motion."""
    import numpy as np

    from planar.scene.load import load_scene

    near = load_scene(_scene(tmp_path, KANGAROO.replace("[mechanism]\n", "[mechanism]\nplacement = [0, 1e5, 0]\n", 1)))
    home = load_scene(GALLERY / "kangaroo-leg.toml")
    a, b = near.motion(), home.motion()
    assert a.valid.all()
    np.testing.assert_allclose(a.points["coupler_point"] - [0, 1e5], b.points["coupler_point"], atol=1e-9)


def test_windup_pivot_at_the_float_limit(tmp_path: Path, capsys) -> None:
    scene = _scene(
        tmp_path,
        'name = "w1"\n[mechanism]\ntype = "elemental"\nnumber = 1\nparams = { D_o = [-1e308, 0] }\n'
        "[driver]\nspeed = 0.5\nsamples_per_cycle = 36\n[fabrication]\nunit_mm = 100.0\n",
    )
    for command, out in (("export", tmp_path / "w.dxf"), ("motion", tmp_path / "w.csv")):
        _fails_cleanly(capsys, [command, str(scene), "-o", str(out)], str(scene), out=out)


# ----------------------------------------------------------------------------- exit 0 on absurd input


@pytest.mark.parametrize("scale", [1e-200, 1e-61, 1e61, 1e200])
def test_a_leg_scaled_out_of_range_is_refused(tmp_path: Path, capsys, scale: float) -> None:
    text = KANGAROO
    for a, b in (("ground = 4.0", 4.0), ("crank = 1.0", 1.0), ("coupler = 4.0", 4.0), ("rocker = 3.0", 3.0)):
        text = text.replace(a, f"{a.split(' = ')[0]} = {b * scale!r}", 1)
    text = re.sub(r"-?\d+\.\d+(?=[,\]])", lambda m: repr(float(m.group()) * scale), text)  # every point
    text = re.sub(r"force = \[[^\]]*\]", "force = [0.0, 10.0]", text)  # a force is no length: as it was
    scene = _scene(tmp_path, text)
    out = tmp_path / "k.dxf"
    _fails_cleanly(capsys, ["export", str(scene), "-o", str(out)], "mechanism size", out=out)


# ----------------------------------------------------------------------------- messages


def test_cam_lift_in_degrees_is_shown_in_degrees(tmp_path: Path, capsys) -> None:
    """``lift = -16`` in a scene with angle_unit = "deg" is named as -16 (it said -0.279...)."""
    text = (GALLERY / "cam-automaton.toml").read_text()
    text = text.replace("lift = 16.0", "lift = X", 1).replace("lift = -16.0", "lift = 16.0", 1).replace("X", "-16.0")
    err = _fails_cleanly(capsys, ["motion", str(_scene(tmp_path, text)), "-o", str(tmp_path / "c.csv")], "lift = -16")
    assert "0.279" not in err and "-16 deg" in err
    text = (GALLERY / "cam-automaton.toml").read_text().replace("lift = -16.0", "lift = -12.0", 1)
    err = _fails_cleanly(capsys, ["motion", str(_scene(tmp_path, text)), "-o", str(tmp_path / "c.csv")], "4 deg")


def test_a_gear_meshing_with_itself_says_so(tmp_path: Path, capsys) -> None:
    text = (GALLERY / "geared-five-bar.toml").read_text().replace('mesh = "A"', 'mesh = "B"', 1)
    _fails_cleanly(capsys, ["motion", str(_scene(tmp_path, text)), "-o", str(tmp_path / "g.csv")], "mesh with itself")


@pytest.mark.parametrize(
    "rows,needle",
    [
        ("1e300,0,0\n1e300,1e299,0.5\n2e300,1e300,1.0\n", "1e+60"),
        ("1e10,0,0\n1e10,1,0.5\n1e10,2,1.0\n", "float64"),
        ("nan,0,0\n1,1,0.5\n2,2,1.0\n", "x"),
    ],
)
def test_synth_motion_far_or_huge_poses(tmp_path: Path, capsys, rows: str, needle: str) -> None:
    poses = tmp_path / "m.csv"
    poses.write_text("x,y,angle\n" + rows)
    out = tmp_path / "m.toml"
    _fails_cleanly(capsys, ["synth", "motion", str(poses), "-o", str(out)], needle, out=out)


def test_an_svg_target_at_1e160_gives_one_message(tmp_path: Path, capsys) -> None:
    """The same refusal, word for word, on every run (its length integrated at 1e160 differed per run)."""
    pytest.importorskip("svgelements")
    svg = tmp_path / "big.svg"
    svg.write_text('<svg xmlns="http://www.w3.org/2000/svg"><path d="M 1e160 0 C 2e160 1e160 3e160 0 4e160 2e160"/></svg>')
    out = tmp_path / "s.toml"
    a = _fails_cleanly(capsys, ["synth", "path", str(svg), "-o", str(out)], "4e+160", out=out)
    b = _fails_cleanly(capsys, ["synth", "path", str(svg), "-o", str(out)], "4e+160", out=out)
    assert a == b


@pytest.mark.parametrize("points", ["2", "501", "100000000"])
def test_svg_points_bounded_before_sampling(tmp_path: Path, capsys, points: str) -> None:
    svg = tmp_path / "c.svg"
    svg.write_text('<svg xmlns="http://www.w3.org/2000/svg"><circle cx="0" cy="0" r="1"/></svg>')
    t0 = time.process_time()
    _fails_cleanly(capsys, ["synth", "path", str(svg), "-o", str(tmp_path / "s.toml"), "--points", points], "--points")
    assert time.process_time() - t0 < 0.5  # refused before any sampling


def test_bench_accuracy_output_checked_before_work(tmp_path: Path, capsys) -> None:
    existing = tmp_path / "EXISTING"
    existing.write_text("keep")
    t0 = time.process_time()
    _fails_cleanly(capsys, ["bench", "accuracy", "-o", str(existing), "--quick"], "-o", "existing file")
    assert time.process_time() - t0 < 0.5 and existing.read_text() == "keep"
    _fails_cleanly(capsys, ["bench", "accuracy", "-o", str(tmp_path / "a" / "b"), "--quick"], "does not exist")
    _fails_cleanly(capsys, ["bench", "accuracy", "-o", str(tmp_path / "o"), "--scenes", str(tmp_path / "no")], "--scenes")


# ----------------------------------------------------------------------------- files and processes


def _run(args: list[str], env: dict[str, str] | None = None, **kw) -> subprocess.CompletedProcess[str]:
    e = {**os.environ, "PYTHONPATH": str(ROOT), **(env or {})}
    return subprocess.run([sys.executable, *args], capture_output=True, text=True, cwd=ROOT, env=e, **kw)


@pytest.mark.slow
def test_unwritable_cache_adds_no_lines(tmp_path: Path) -> None:
    """``$HOME/.cache`` a file (so no cache folder can be made): an export with a preview prints its summary only."""
    home = tmp_path / "home"
    home.mkdir()
    (home / ".cache").write_text("not a folder")
    env = {"HOME": str(home), "XDG_CACHE_HOME": "", "MPLCONFIGDIR": "", "XDG_CONFIG_HOME": ""}  # empty: the defaults
    dxf, png = tmp_path / "k.dxf", tmp_path / "k.png"
    r = _run(["-m", "planar", "export", str(GALLERY / "kangaroo-leg.toml"), "-o", str(dxf), "--preview", str(png)], env=env)
    assert r.returncode == 0, r.stderr
    # the summary and the build check's verdict, nothing from ezdxf's or matplotlib's caches
    lines = r.stdout.strip().splitlines()
    assert r.stderr == "" and len(lines) == 2 and lines[1].startswith("build check: "), r.stdout + r.stderr


@pytest.mark.slow
def test_a_full_disc_names_the_file_and_keeps_the_old_one(tmp_path: Path) -> None:
    """A file size limit (as a full disc) while writing: one line naming the output; the old file intact."""
    import resource

    out = tmp_path / "m.csv"
    out.write_text("old\n")
    scene = tmp_path / "big.toml"
    scene.write_text(KANGAROO.replace("samples_per_cycle = 36", "samples_per_cycle = 20000"))

    def limit() -> None:
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (100_000, 100_000))

    r = _run(["-m", "planar", "motion", str(scene), "-o", str(out)], preexec_fn=limit)
    assert r.returncode == 2, r.stderr
    assert len(r.stderr.strip().splitlines()) == 1 and str(out) in r.stderr, r.stderr
    assert out.read_text() == "old\n"
    assert not [p for p in os.listdir(tmp_path) if p.endswith(".part")]


def _dead_pid() -> int:
    p = subprocess.Popen([sys.executable, "-c", "pass"])
    p.wait()
    return p.pid


def test_stale_temporaries_are_removed_on_the_next_run(tmp_path: Path) -> None:
    """A ``kill -9`` leaves ``.NAME.PID.xxxxxxxx.part``: the next write into that folder removes it when it is older
    than the process and its writer is gone; a live writer's, a fresh one and a stranger's file stay."""
    import planar.fileio as fileio

    dead, old = _dead_pid(), time.time() - 3600
    stale = tmp_path / f".m.csv.{dead}.ab_cd123.part"
    live = tmp_path / f".m.csv.{os.getppid()}.zz_cd123.part"
    fresh = tmp_path / f".n.csv.{dead}.qq_cd123.part"
    other = tmp_path / ".notes.part"
    for p in (stale, live, other):
        p.write_text("x")
        os.utime(p, (old, old))
    fresh.write_text("x")
    os.utime(fresh, (time.time() + 60, time.time() + 60))  # written after this process started
    fileio._SWEPT.discard(os.path.realpath(tmp_path))
    with fileio.atomic_write(tmp_path / "m.csv", "w") as fh:
        fh.write("new\n")
    assert not stale.exists() and live.exists() and fresh.exists() and other.exists()
    assert (tmp_path / "m.csv").read_text() == "new\n"
    assert sorted(p.name for p in tmp_path.iterdir() if p.name.endswith(".part")) == sorted([live.name, fresh.name, other.name])


def test_a_handled_failure_leaves_no_temporary(tmp_path: Path, capsys) -> None:
    """A command that fails after it started writing (a motion row of NaN) leaves neither output nor ``.part``."""
    import math

    import numpy as np

    from planar.fileio import write_motion_csv
    from planar.linkages import FourBar

    leg = FourBar(4.0, 1.0, 4.0, 3.0)
    m = leg.solve(np.linspace(0, 1, 4), t=np.zeros(4))
    m.t = np.array([0.0, math.nan, 0.0, 0.0])  # a Motion built by hand: the writer's own check
    from planar.errors import InputError

    with pytest.raises(InputError, match="motion row 1"):
        write_motion_csv(tmp_path / "m.csv", leg, m)
    assert os.listdir(tmp_path) == []


def test_signals_are_held_from_the_rename_to_the_exit(tmp_path: Path) -> None:
    """After the outputs are renamed a Ctrl-C (or SIGTERM) no longer kills the command: it finishes and exits 0."""
    code = (
        "import os, signal, sys\n"
        "from planar.fileio import atomic_write, hold_signals_after_commit\n"
        "hold_signals_after_commit()\n"
        f"with atomic_write({str(tmp_path / 'o.txt')!r}, 'w') as fh: fh.write('done')\n"
        "os.kill(os.getpid(), signal.SIGINT); os.kill(os.getpid(), signal.SIGTERM)\n"
        "print('finished'); sys.stdout.flush(); os._exit(0)\n"
    )
    r = _run(["-c", code])
    assert r.returncode == 0 and r.stdout.strip() == "finished" and r.stderr == "", r.stderr
    assert (tmp_path / "o.txt").read_text() == "done"


def test_api_renames_restore_the_signal_handlers(tmp_path: Path, monkeypatch) -> None:
    """From Python (no hold): a Ctrl-C during the renames arrives after them, and the handlers are given back."""
    import planar.fileio as fileio

    outer = signal.signal(signal.SIGINT, signal.default_int_handler)  # a test worker may ignore SIGINT
    before = signal.getsignal(signal.SIGINT)
    real = os.replace

    def replace_then_interrupt(a, b):
        real(a, b)
        os.kill(os.getpid(), signal.SIGINT)  # lands while the rename is held

    monkeypatch.setattr(fileio.os, "replace", replace_then_interrupt)
    with pytest.raises(KeyboardInterrupt), fileio.output_transaction():
        for name in ("a.txt", "b.txt"):
            with fileio.atomic_write(tmp_path / name, "w") as fh:
                fh.write(name)
    assert (tmp_path / "a.txt").read_text() == "a.txt" and (tmp_path / "b.txt").read_text() == "b.txt"
    assert signal.getsignal(signal.SIGINT) is before
    signal.signal(signal.SIGINT, outer)


def test_an_interrupt_a_library_turned_into_its_error_exits_130(tmp_path: Path, capsys, monkeypatch) -> None:
    """matplotlib's import turns a Ctrl-C into a RuntimeError: planar still exits 130, quietly."""
    import planar.app.pipeline as pipeline

    def interrupted(*a, **k):
        try:
            raise KeyboardInterrupt
        except KeyboardInterrupt as e:
            raise RuntimeError("import failed") from e

    monkeypatch.setattr(pipeline, "write_scene_motion", interrupted)
    out = tmp_path / "m.csv"
    assert main(["motion", str(GALLERY / "kangaroo-leg.toml"), "-o", str(out)]) == 130
    err = capsys.readouterr().err.strip()
    assert err == "planar: interrupted (no output written)" and not out.exists()


# ----------------------------------------------------------------------------- the second abuse trial


def test_debug_shows_the_traceback_and_keeps_the_exit_status(tmp_path: Path, capsys) -> None:
    """``--debug`` prints the traceback of a user error and still exits 2 (it used to exit 1)."""
    rc = main(["--debug", "info", str(tmp_path / "nofile.toml")])
    err = capsys.readouterr().err
    assert rc == 2, err
    assert "Traceback (most recent call last)" in err
    assert err.strip().splitlines()[-1].startswith("planar: error: ")


def test_synth_atlas_into_a_missing_folder_is_refused(tmp_path: Path, capsys) -> None:
    out = tmp_path / "nodir" / "a.npz"
    _fails_cleanly(capsys, ["synth", "atlas", "--size", "100", "-o", str(out)], "-o", "does not exist", out=out)
    assert not out.parent.exists()


def test_an_output_with_a_trailing_slash_is_refused(tmp_path: Path, capsys) -> None:
    out = tmp_path / "o.html"
    _fails_cleanly(capsys, ["render", str(GALLERY / "kangaroo-leg.toml"), "-o", f"{out}/"], "-o", out=out)


@pytest.mark.parametrize("speeds", ["", "1,,2", "1e300", "nan", "0"])
def test_toy_speeds_list_is_strict(capsys, speeds: str) -> None:
    _fails_cleanly(capsys, ["toy", str(GALLERY / "windup-01.toml"), "--speeds", speeds], "--speeds")


@pytest.mark.parametrize("what", ["", "curve,,torque"])
def test_plot_what_list_is_strict(tmp_path: Path, capsys, what: str) -> None:
    out = tmp_path / "p.png"
    _fails_cleanly(capsys, ["plot", str(GALLERY / "kangaroo-leg.toml"), "-o", str(out), "--what", what], "--what", out=out)


def test_synth_path_ragged_target_row_is_named(tmp_path: Path, capsys) -> None:
    target = tmp_path / "t.csv"
    target.write_text("x,y\n0,0\n1,0,5\n1,1\n0,1\n")
    out = tmp_path / "s.toml"
    _fails_cleanly(capsys, ["synth", "path", str(target), "-o", str(out)], "row 3", out=out)


@pytest.mark.parametrize("samples", ["3", "1"])
def test_catalog_samples_at_least_four(tmp_path: Path, capsys, samples: str) -> None:
    out = tmp_path / "c.csv"
    _fails_cleanly(capsys, ["catalog", "jansen", "-o", str(out), "--samples", samples], "--samples", out=out)


@pytest.mark.parametrize(
    "scene,old,new,needle",
    [
        ("two-input-five-bar.toml", "cycles = 2.0", "cycles = 1e300", "cycles"),
        ("two-input-five-bar.toml", "amplitude = 35.0", "amplitude = 1e308", "amplitude"),
        ("horse.toml", "phase = 180", "phase = 1e300", "phase"),
    ],
)
def test_angles_float64_cannot_resolve_are_refused(tmp_path: Path, capsys, scene: str, old: str, new: str, needle: str) -> None:
    text = (GALLERY / scene).read_text()
    assert old in text
    s = _scene(tmp_path, text.replace(old, new, 1))
    out = tmp_path / "m.csv"
    _fails_cleanly(capsys, ["motion", str(s), "-o", str(out)], needle, out=out)


def test_render_fps_beyond_the_frame_limit_names_fps(tmp_path: Path, capsys) -> None:
    out = tmp_path / "o.html"
    err = _fails_cleanly(capsys, ["render", str(GALLERY / "kangaroo-leg.toml"), "-o", str(out), "--fps", "1e9"], "--fps", out=out)
    assert "driver.cycles" not in err
