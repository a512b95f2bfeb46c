"""Animations play at the scene's speed; GIFs stream; trails above parts; translucency; video output."""

import tracemalloc
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from planar.cli.main import main
from planar.draw.timing import animation_motion, plan_frames, resample, scene_duration
from planar.errors import InputError
from planar.scene.load import load_scene

GALLERY = Path(__file__).resolve().parents[2] / "gallery"


def _scene(tmp_path, speed=1.0, samples=360, extra=""):
    p = tmp_path / "leg.toml"
    p.write_text(f"""
[mechanism]
type = "fourbar"
ground = 4.0
crank = 1.0
coupler = 4.0
rocker = 3.0
coupler_point = [5.5, -2.0]
[driver]
speed = {speed}
samples_per_cycle = {samples}
[render]
width = 160
height = 120
{extra}
""")
    return p


def _durations(path):
    im = Image.open(path)
    out = []
    for i in range(im.n_frames):
        im.seek(i)
        out.append(im.info["duration"])
    return out


@pytest.mark.parametrize("speed", [0.05, 0.3, 1.0, 2.7, 7.0, 20.0])
def test_a_cycle_plays_for_its_period_within_one_frame(speed):
    period = 1.0 / speed
    plan = plan_frames(period, period)
    assert plan.delay_ms % 10 == 0 and plan.delay_ms >= 20
    assert abs(plan.cycle_play_s - period) <= plan.delay_ms / 1000.0 / 2 + 1e-12 or plan.note()
    if period >= 0.5:
        assert plan.frames_per_cycle >= 12


def test_fps_asked_for_and_refused():
    plan = plan_frames(1.0, 3.0, fps=10)
    assert plan.delay_ms == 100 and plan.frames_per_cycle == 10 and plan.frames == 30
    with pytest.raises(InputError, match="50 frames per second"):
        plan_frames(1.0, 1.0, fps=60)
    with pytest.raises(InputError, match=r"^fps = nan"):  # the Python argument; the command line names --fps
        plan_frames(1.0, 1.0, fps=float("nan"))
    with pytest.raises(InputError, match=r"^--fps = nan"):
        plan_frames(1.0, 1.0, fps=float("nan"), fps_option="--fps")
    with pytest.raises(InputError, match="at most"):
        plan_frames(1.0, 1e6)
    # video: any rate
    assert plan_frames(1.0, 1.0, fps=60, tick_ms=None).frames_per_cycle == 60
    # an fps too low to show a cycle (a new user's --fps 1 at 10 cycles/s played 2 frames for 2 s): refused
    with pytest.raises(InputError, match="at least 4 frames per cycle"):
        plan_frames(0.1, 0.1, fps=1)
    with pytest.raises(InputError, match="at least 4 frames per cycle"):
        plan_frames(1 / 3, 1 / 3, fps=2)
    # a cycle too fast for a GIF (20 cycles/s): 4 frames of 20 ms, and a note says it plays slower
    fast = plan_frames(0.05, 0.05)
    assert fast.frames_per_cycle == 4 and fast.delay_ms == 20 and fast.slowdown == pytest.approx(1.6)
    assert "slower" in fast.note() and plan_frames(1.0, 1.0).note() == ""
    # ... and in a video it plays at speed
    v = plan_frames(0.05, 0.05, tick_ms=None)
    assert v.cycle_play_s == pytest.approx(0.05) and v.note() == ""


def test_gif_plays_at_the_scene_speed(tmp_path):
    # 360 samples of a 1 cycle/s scene used to play for 7.2 s; now one second
    out = tmp_path / "a.gif"
    assert main(["render", str(_scene(tmp_path)), "-o", str(out)]) == 0
    d = _durations(out)
    assert sum(d) == pytest.approx(1000.0, abs=max(d))
    assert main(["render", str(_scene(tmp_path, speed=0.25)), "-o", str(out), "--fps", "20"]) == 0
    d = _durations(out)
    assert set(d) == {50} and sum(d) == pytest.approx(4000.0, abs=50)


def test_frames_are_the_motion_at_the_frame_instants(tmp_path):
    scene = load_scene(_scene(tmp_path, samples=100))
    plan = plan_frames(scene.mechanism.driver.period, scene_duration(scene))
    frames, fine = animation_motion(scene, plan)
    t = plan.times()
    direct = scene.mechanism.solve(scene.mechanism.driver.value(t), t=t)
    for k in direct.poses:
        np.testing.assert_allclose(frames.poses[k], direct.poses[k], atol=1e-12)
    assert len(fine) >= 100 and len(frames) == plan.frames == 25
    # an overlay interpolated to the frames: exact for a linear motion
    back = resample(fine, t)
    np.testing.assert_allclose(back.poses["crank"][:, 2] % (2 * np.pi), direct.poses["crank"][:, 2] % (2 * np.pi), atol=1e-9)


def test_streamed_gif_decodes_to_the_drawn_frames(tmp_path):
    from exporters.gif import indexer, write_gif
    from planar.draw.frames import Renderer, Style, palette_colors

    scene = load_scene(_scene(tmp_path, samples=36))
    m = scene.motion()
    r = Renderer(scene.mechanism, m, Style(width=120, height=90))
    pal = palette_colors(r.style, len(scene.mechanism.parts))
    idx = list(r.frames(post=indexer(pal), threads=1))
    out = tmp_path / "s.gif"
    assert write_gif(out, idx, 40, pal) == len(m)
    from exporters.gif import _unique_palette

    colours = np.array(_unique_palette(pal[:255]), np.uint8)
    im = Image.open(out)  # Pillow's decoder, not ours
    assert im.n_frames == len(m)
    for i in range(im.n_frames):
        im.seek(i)
        np.testing.assert_array_equal(np.asarray(im.convert("RGB")), colours[idx[i]])


def test_gif_memory_is_flat_in_the_number_of_frames(tmp_path):
    from exporters.gif import write_gif

    pal = [(i, i, i) for i in range(256)]

    def frames(n):
        for k in range(n):
            f = np.zeros((200, 300), np.uint8)
            f[:, (k * 7) % 300] = 200
            yield f

    write_gif(tmp_path / "warm.gif", frames(5), 40, pal)  # imports and first-use caches out of the measure
    peaks = []
    for n in (20, 400):
        tracemalloc.start()
        write_gif(tmp_path / f"m{n}.gif", frames(n), 40, pal)
        peaks.append(tracemalloc.get_traced_memory()[1])
        tracemalloc.stop()
    # 380 more frames of 60 kB each would be 23 MB if they were held; allow ten frames' worth
    assert peaks[1] - peaks[0] < 10 * 200 * 300, peaks


def test_trails_are_drawn_above_the_parts(tmp_path):
    from shapely.geometry import Point, Polygon

    from planar.draw.frames import Renderer, Style, _rgb

    scene = load_scene(GALLERY / "jansen-leg.toml")
    plan = plan_frames(scene.mechanism.driver.period, scene_duration(scene))
    frames, fine = animation_motion(scene, plan)
    r = Renderer(scene.mechanism, frames, Style(supersample=1), trail_motion=fine)
    trail = np.array(_rgb(r.style.trail))
    found = 0
    for i in range(0, len(frames), 5):
        img = np.asarray(r.frame(i)).astype(int)
        for k in r.moving:
            ext = Polygon(r.part_rings(k, i)[0]).buffer(-3)
            for pts in r.trails.values():
                for x, y in pts[::3]:
                    if ext.contains(Point(x, y)):
                        px = img[int(round(y)), int(round(x))]
                        found += 1
                        assert np.abs(px - trail).max() < 90, (i, k, px)
    assert found > 0  # the trail crosses parts somewhere


def test_translucent_parts_show_what_is_under_them(tmp_path):
    opaque = tmp_path / "o.gif"
    clear = tmp_path / "c.gif"
    assert main(["render", str(_scene(tmp_path, samples=36)), "-o", str(opaque)]) == 0
    assert main(["render", str(_scene(tmp_path, samples=36, extra="opacity = 0.4")), "-o", str(clear)]) == 0
    a = np.asarray(Image.open(opaque).convert("RGB")).astype(int)
    b = np.asarray(Image.open(clear).convert("RGB")).astype(int)
    # part fills are lighter (closer to the white background) where they are translucent
    changed = np.abs(a - b).sum(-1) > 30
    assert changed.sum() > 200
    assert (b[changed].sum(-1) > a[changed].sum(-1)).mean() > 0.9


def test_wrong_suffix_is_refused_and_nothing_written(tmp_path, capsys):
    deep = tmp_path / ("a-long-folder-name-" * 6)  # CI's temporary paths are long: the file name must still show
    deep.mkdir()
    out = deep / "x.csv"
    assert main(["render", str(_scene(tmp_path)), "-o", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "x.csv" in err[0] and ".gif" in err[0]
    assert not out.exists() and sorted(tmp_path.iterdir()) == [deep, tmp_path / "leg.toml"] and not any(deep.iterdir())


def test_video_without_the_extra_is_one_clear_line(tmp_path, monkeypatch, capsys):
    import exporters.video as v

    monkeypatch.setattr(v, "video_available", lambda: False)
    out = tmp_path / "x.mp4"
    assert main(["render", str(_scene(tmp_path)), "-o", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "planar[video]" in err[0]
    assert not out.exists()


@pytest.mark.slow
def test_mp4_through_ffmpeg(tmp_path):
    pytest.importorskip("imageio_ffmpeg")  # the test extra installs it; the video extra for users
    import imageio.v3 as iio

    out = tmp_path / "x.mp4"
    assert main(["render", str(_scene(tmp_path, speed=0.5, samples=36)), "-o", str(out), "--fps", "30"]) == 0
    meta = iio.immeta(out, plugin="pyav") if _has_pyav() else iio.immeta(out, plugin="FFMPEG")
    frames = iio.imread(out, plugin="FFMPEG", index=None)
    assert frames.shape[0] == 60 and frames.shape[1:] == (120, 160, 3)
    assert meta["fps"] == pytest.approx(30.0)
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]  # no temporary left


def _has_pyav():
    try:
        import av  # noqa: F401
    except ImportError:
        return False
    return True
