"""Scene files (good and bad), the CSV columns, GIF properties, the gallery."""

import hashlib
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from planar import SceneError
from planar.app.pipeline import gallery_scenes, render_scene
from planar.cli.main import main
from planar.scene.load import load_scene, scene_schema

ROOT = Path(__file__).resolve().parents[2]
GALLERY = ROOT / "gallery"

FOURBAR = """
name = "leg"
[mechanism]
type = "fourbar"
ground = 4.0
crank = 1.0
coupler = 4.0
rocker = 3.0
coupler_point = [2.0, 1.0]
[[mechanism.polygons]]
name = "foot"
part = "coupler"
points = [[2.0, 1.0], [2.5, 1.0], [2.5, 1.2]]
[driver]
speed = 2.0
samples_per_cycle = 24
[render]
width = 200
height = 150
sweep = ["foot"]
"""


def write(tmp_path, text, name="s.toml"):
    p = tmp_path / name
    p.write_text(text)
    return p


def test_good_scene_builds_and_moves(tmp_path):
    scene = load_scene(write(tmp_path, FOURBAR))
    m = scene.motion()
    assert len(m) == 24 and m.valid.all()
    assert scene.mechanism.driver.period == pytest.approx(0.5)
    assert "foot" in scene.polygons


@pytest.mark.parametrize(
    "edit,expect",
    [
        (("crank = 1.0", "crank = -1.0"), "mechanism.crank"),
        (("crank = 1.0", "crank = 1.0\ncrankk = 2"), "crankk"),
        (('type = "fourbar"', 'type = "sixbar"'), "mechanism"),
        (("samples_per_cycle = 24", "samples_per_cycle = 2"), "driver.samples_per_cycle"),
        (("speed = 2.0", 'speed = "fast"'), "driver.speed"),
        (('sweep = ["foot"]', 'sweep = ["hand"]'), "render.sweep"),
        (('part = "coupler"', 'part = "tail"'), "polygons[0].part"),
        (("rocker = 3.0", "rocker = 30.0"), "mechanism"),
        (("width = 200", "width = 200\nwidht = 3"), "widht"),
    ],
)
def test_bad_scenes_name_file_field_and_value(tmp_path, edit, expect):
    text = FOURBAR.replace(*edit)
    assert text != FOURBAR
    p = write(tmp_path, text)
    with pytest.raises(SceneError) as e:
        load_scene(p)
    msg = str(e.value)
    assert str(p) in msg and expect in msg
    assert "\n" not in msg


def test_not_toml_and_missing_file(tmp_path):
    with pytest.raises(SceneError, match="not valid TOML"):
        load_scene(write(tmp_path, "[mechanism\ntype="))
    with pytest.raises(SceneError, match="no such file"):
        load_scene(tmp_path / "nope.toml")


def test_bad_scene_from_cli_exit_2_no_output(tmp_path):
    p = write(tmp_path, FOURBAR.replace("crank = 1.0", "crank = 0"))
    out = tmp_path / "o.gif"
    r = subprocess.run([sys.executable, "-m", "planar", "render", str(p), "-o", str(out)], capture_output=True, text=True)
    assert r.returncode == 2 and "Traceback" not in r.stderr
    assert len(r.stderr.strip().splitlines()) == 1 and "mechanism.crank" in r.stderr
    assert not out.exists() and not list(tmp_path.glob("*.part"))


def test_schema_is_published_and_current():
    committed = json.loads((GALLERY / "scene.schema.json").read_text())
    assert committed == json.loads(json.dumps(scene_schema(), sort_keys=True))
    assert committed["additionalProperties"] is False


def test_motion_csv_columns(tmp_path):
    p = write(tmp_path, FOURBAR)
    out = tmp_path / "m.csv"
    assert main(["motion", str(p), "-o", str(out)]) == 0
    header = out.read_text().splitlines()[0].split(",")
    parts = ["ground", "crank", "coupler", "rocker"]
    expected = (
        ["t", "driver"]
        + [f"{q}.{c}" for q in parts for c in ("x", "y", "angle")]
        + ["coupler_point.x", "coupler_point.y", "valid"]
    )
    assert header == expected
    data = np.genfromtxt(out, delimiter=",", skip_header=1)
    assert data.shape == (24, len(expected))
    scene = load_scene(p)
    m = scene.motion()
    np.testing.assert_array_equal(data[:, 1], m.driver)
    np.testing.assert_array_equal(data[:, header.index("coupler.angle")], m.poses["coupler"][:, 2])


def _gif_frames(path):
    im = Image.open(path)
    frames, delays = [], []
    for i in range(im.n_frames):
        im.seek(i)
        frames.append(np.asarray(im.convert("RGB")))
        delays.append(im.info.get("duration"))
    return im, frames, delays


@pytest.mark.slow
def test_gif_properties_and_reproducibility(tmp_path):
    p = write(tmp_path, FOURBAR)
    a, b = tmp_path / "a.gif", tmp_path / "b.gif"
    assert main(["render", str(p), "-o", str(a)]) == 0
    assert main(["render", str(p), "-o", str(b)]) == 0
    assert hashlib.sha256(a.read_bytes()).digest() == hashlib.sha256(b.read_bytes()).digest()
    im, frames, delays = _gif_frames(a)
    assert im.info.get("loop") == 0  # loops forever
    # speed 2 cycles/s: 0.5 s per cycle at the default 25 frames/s -> 12 frames of 40 ms (not 24 samples)
    assert len(frames) == 12 and delays == [40] * 12
    assert all(d is not None and d >= 20 and d % 10 == 0 for d in delays)
    assert frames[0].shape == (150, 200, 3)
    for f in frames:
        assert len(np.unique(f.reshape(-1, 3), axis=0)) > 3  # not blank
    assert not all(np.array_equal(frames[0], f) for f in frames[1:])


def test_render_marks_invalid_samples(tmp_path):
    # a non-Grashof linkage driven through a full turn: the samples past the toggles are drawn, in red
    text = (
        FOURBAR.replace("ground = 4.0", "ground = 4.5")
        .replace("crank = 1.0", "crank = 3.0")
        .replace("coupler = 4.0", "coupler = 3.0")
        .replace("rocker = 3.0", "rocker = 3.0")
    )
    p = write(tmp_path, text)
    scene = load_scene(p)
    m = scene.motion()
    assert m.valid.any() and not m.valid.all()
    out = tmp_path / "inv.gif"
    notes: list[str] = []
    render_scene(scene, out, progress=False, notes=notes)
    assert any("cannot be assembled" in n for n in notes)  # and the command says so
    _, frames, _ = _gif_frames(out)
    from planar.draw.timing import animation_motion, plan_frames, scene_duration

    m, _ = animation_motion(scene, plan_frames(scene.mechanism.driver.period, scene_duration(scene)))
    assert len(frames) == len(m)  # invalid frames are not skipped
    assert m.valid.any() and not m.valid.all()
    red = np.array([214, 39, 40])
    for i in range(len(m)):
        has_red = np.any(np.all(np.abs(frames[i][:3, :, :].astype(int) - red) < 30, axis=-1))
        assert has_red == (not m.valid[i])


def test_every_gallery_scene_loads_and_has_its_gif():
    scenes = gallery_scenes(GALLERY)
    names = {p.stem for p in scenes}
    from planar.windup.mechanisms import ELEMENTAL

    for k in sorted(ELEMENTAL):  # every elemental record has its gallery scene
        assert f"windup-{k:02d}" in names
    for n in ("horse", "bunny", "kangaroo-leg", "paddle-boat", "jansen-leg", "slider-crank"):
        assert n in names
    for p in scenes:
        scene = load_scene(p)
        assert scene.motion().valid.all(), p.name
        gif = p.with_suffix(".gif")
        assert gif.exists(), f"{gif.name} is not committed"
        assert gif.stat().st_size < 400_000


def test_gallery_renders_byte_identical_to_committed(tmp_path):
    # the committed GIFs are what `planar gallery` makes (reproducible output)
    for name in ("slider-crank", "windup-05"):
        scene = load_scene(GALLERY / f"{name}.toml")
        out = tmp_path / f"{name}.gif"
        render_scene(scene, out, progress=False)
        assert out.read_bytes() == (GALLERY / f"{name}.gif").read_bytes(), name


def test_every_mechanism_type_in_a_scene(tmp_path):
    kinds = {
        "slidercrank": 'type = "slidercrank"\ncrank = 1.0\nrod = 3.0',
        "elemental": 'type = "elemental"\nnumber = 9\nparams = { phi = 50.0 }',
        "chain": 'type = "chain"\nchain = ["Rz->Tx", "Tx->Oz"]',
        "toy": 'type = "toy"\nleft = [["Rz->Oz"]]\nright = [["Rz->Tx"]]\nphase = 90.0',
        "catalog": 'type = "catalog"\nname = "jansen"',
    }
    for kind, body in kinds.items():
        p = write(tmp_path, f'angle_unit = "deg"\n[mechanism]\n{body}\n[driver]\nsamples_per_cycle = 8\n', f"{kind}.toml")
        scene = load_scene(p)
        assert scene.motion().valid.all(), kind
    s = load_scene(tmp_path / "elemental.toml")
    assert s.mechanism.params.phi == pytest.approx(np.radians(50.0))


def test_gallery_command_renders_every_scene(tmp_path):
    src = tmp_path / "scenes"
    src.mkdir()
    (src / "a.toml").write_text(FOURBAR)
    (src / "b.toml").write_text(FOURBAR.replace("speed = 2.0", "speed = 1.0"))
    assert main(["gallery", "--source", str(src), "-o", str(tmp_path / "out")]) == 0
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["a.gif", "b.gif"]


def test_gallery_command_away_from_the_repository_is_a_user_error(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)  # no gallery/ here, and none is looked for beside the code
    assert main(["gallery"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "scenes folder" in err and "'gallery'" in err
    assert list(tmp_path.iterdir()) == []
    (tmp_path / "empty").mkdir()
    assert main(["gallery", "--source", "empty"]) == 2
    assert "it has none" in capsys.readouterr().err


def test_camera_fits_valid_samples_only():
    # one invalid sample holding huge numbers must not shrink every frame to a dot
    from dataclasses import replace

    from planar.draw.frames import Renderer, Style, _rgb
    from planar.linkages import FourBar

    fb = FourBar(4.0, 1.0, 4.0, 3.0, coupler_point=(2.0, 1.0))
    clean = fb.run(24)
    poses = {k: v.copy() for k, v in clean.poses.items()}
    points = {k: v.copy() for k, v in clean.points.items()}
    for v in (*poses.values(), *points.values()):
        v[5, :2] = 3e16
    valid = clean.valid.copy()
    valid[5] = False
    code = clean.fail_code.copy()
    code[5] = 0
    bad = replace(clean, poses=poses, points=points, valid=valid, fail_code=code, fail_table=[("C", "test")])
    style = Style(width=160, height=120)
    ref, r = Renderer(fb, clean, style), Renderer(fb, bad, style)
    assert r.scale == pytest.approx(ref.scale, rel=1e-12)
    assert r.origin == pytest.approx(ref.origin, rel=1e-12)
    bg = np.array(_rgb(style.background))
    drawn = [int(np.any(np.asarray(x.frame(0).convert("RGB")) != bg, axis=-1).sum()) for x in (ref, r)]
    assert drawn[0] > 500 and drawn[1] > 0.9 * drawn[0]
