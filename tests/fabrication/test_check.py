"""The build check's pieces on hand-made cases (closed forms), the hardware tables, and export's exit status."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import shapely
from shapely.geometry import box

from planar.fabrication.check import BodyZ, check_bodies, placed_array
from planar.fabrication.hardware import HARDWARE

GALLERY = Path(__file__).resolve().parents[2] / "gallery"


def _still(poly, n=5):
    return np.array([poly] * n, dtype=object)


def test_placed_array_moves_every_sample_like_shapely_affinity():
    rng = np.random.default_rng(3)
    poly = box(0, 0, 4, 1).difference(box(1, 0.25, 2, 0.75))
    poses = np.c_[rng.uniform(-5, 5, (20, 2)), rng.uniform(-3, 3, 20)]
    got = placed_array(poly, poses, 2.0)
    for g, (x, y, a) in zip(got, poses):
        ref = shapely.affinity.translate(shapely.affinity.rotate(poly, a, origin=(0, 0), use_radians=True), 2 * x, 2 * y)
        assert g.symmetric_difference(ref).area < 1e-9


def test_two_parts_on_one_layer_collide_only_where_they_overlap():
    moving = placed_array(box(0, 0, 2, 2), np.c_[np.linspace(0, 6, 7), np.zeros(7), np.zeros(7)], 1.0)
    fixed = _still(box(4.5, 0, 6, 2), 7)
    a = BodyZ("a", moving, 0.0, 3.0, "part")
    b = BodyZ("b", fixed, 0.0, 3.0, "part")
    (v,) = check_bodies([a, b], 3.0)
    # the square [x, x + 2] overlaps [4.5, 6] for x = 3, 4, 5 (at x = 6 they only touch)
    assert (v.what, v.layer, v.sample, v.count) == ("parts overlap", 1, 3, 3)
    assert v.depth == pytest.approx(3.0)  # x = 4.5 .. 6: the full 1.5 x 2
    c = BodyZ("c", fixed, 3.0, 6.0, "part")  # the next layer up: never meets
    assert check_bodies([a, c], 3.0) == []
    assert check_bodies([a, b], 3.0, skip={frozenset(("a", "b"))}) == []


def test_round_bodies_keep_their_radii_plus_clearance_apart():
    t = np.linspace(0, 1, 11)
    p = np.c_[t * 10, np.zeros_like(t)]
    q = np.c_[np.full_like(t, 7.0), np.zeros_like(t)]
    disc = shapely.buffer(shapely.points(p), 1.5)
    a = BodyZ("pin A", disc, 0, 6, "pin", track=p, radius=1.5)
    b = BodyZ("pin B", disc, 3, 9, "pin", track=q, radius=1.5)
    (v,) = check_bodies([a, b], 3.0, clearance=0.1)
    # |10 t - 7| < 3.1 for t in (0.39, 1.0]: samples 4..10
    assert (v.what, v.sample, v.count, v.layer) == ("pins collide", 4, 7, 2)
    far = BodyZ("pin B", disc, 6.5, 9, "pin", track=q, radius=1.5)  # z-ranges apart
    assert check_bodies([a, far], 3.0, clearance=0.1) == []


@pytest.mark.parametrize(
    ("kind", "stack", "length", "ends"),
    [
        # rod: stack + 2 x (washer 0.5 + clip 0.6 + 0.5 past the groove) = 12.2, up to 0.5 mm: 12.5, 1.75 each side
        ("rod-eclip", 9.0, 12.5, (((1.1, 7.0), (1.75, 3.0)), ((1.1, 7.0), (1.75, 3.0)))),
        # screw: stack + 2 washers + nut 4 + a pitch 0.5 = 14.5 -> sold 16; its tip 16 - 0.5 - 9 = 6.5 mm proud of
        # the stack, 3 more washers under the nut (nut top 4 x 0.5 + 4 = 6 mm), the head 1.65 + a washer 0.5 below
        ("screw", 9.0, 16.0, (((2.15, 7.0),), ((6.0, 7.0), (6.5, 3.0)))),
    ],
)
def test_hardware_lengths_and_ends_from_the_standard_tables(kind, stack, length, ends):
    hw = HARDWARE[kind]
    assert hw.length(3.0, stack) == pytest.approx(length)
    got = hw.ends(3.0, stack)
    assert [[(t.height, t.diameter) for t in end] for end in got] == [[pytest.approx(t) for t in end] for end in ends]
    assert all(i.qty >= 1 and i.size for i in hw.items(3.0, stack))


#: by hand from the standards: ISO 261 pitch, DIN 125-A washer thickness, DIN 985 nut height, ISO 7380 head height
HAND = {3.0: (0.5, 0.5, 4.0, 1.65), 4.0: (0.7, 0.8, 5.0, 2.2), 5.0: (0.8, 1.0, 5.0, 2.75)}


@pytest.mark.parametrize("d", sorted(HAND))
def test_the_chosen_screw_engages_its_whole_nut_and_its_extents_are_the_hand_sum(d):
    """Random stacks: the screw is a sold length, its thread passes the whole nut by a pitch to a pitch plus a
    washer (1 to 2 pitches for M3), no shorter sold screw would, and the check's ends are the hand sums."""
    from planar.fabrication.hardware import SCREW_LENGTHS, screw_fit

    pitch, washer, nut, head = HAND[d]
    rng = np.random.default_rng(int(d * 10))
    for stack in rng.uniform(1.0, 40.0, 60):
        fit = screw_fit(d, float(stack))
        assert fit.length in SCREW_LENGTHS
        need = stack + 2 * washer + nut + pitch  # head washer, layers, nut washer, nut, the chamfered pitch
        assert fit.length >= need - 1e-9
        assert not any(need - 1e-9 <= n < fit.length for n in SCREW_LENGTHS)  # the shortest that does
        nut_top = fit.washers * washer + nut  # above the stack's top face
        proud = fit.length - washer - stack - nut_top
        assert pitch - 1e-9 <= proud < pitch + washer - 1e-9, (stack, fit)
        lower, upper = HARDWARE["screw"].ends(d, float(stack))
        assert lower[-1].height == pytest.approx(head + washer)
        assert upper[0].height == pytest.approx(nut_top)
        assert upper[-1].height == pytest.approx(fit.length - washer - stack)  # the tip
        assert upper[-1].diameter == pytest.approx(d)
        items = {i.item: i for i in HARDWARE["screw"].items(d, float(stack))}
        assert items["washer DIN 125"].qty == 1 + fit.washers


def test_a_rod_stands_its_clip_and_half_its_spare_length_past_each_face():
    rng = np.random.default_rng(5)
    for stack in rng.uniform(1.0, 40.0, 40):
        length = HARDWARE["rod-eclip"].length(3.0, float(stack))
        lower, upper = HARDWARE["rod-eclip"].ends(3.0, float(stack))
        assert lower == upper
        assert lower[-1].height == pytest.approx((length - stack) / 2)
        assert 0.5 - 1e-9 <= lower[-1].height - (0.5 + 0.6) < 0.75  # 0.5 mm past the groove, cut to 0.5 mm


@pytest.mark.slow
def test_export_exits_3_naming_the_pair_and_still_writes(tmp_path, monkeypatch, capsys):
    """The Horse with both cam trees untuned (its tracks merged into one slot of the frame, as before the
    second tree was turned half a turn): pins B and E collide, export says so and still writes."""
    from planar.cli.main import main
    from planar.toys import assembly

    monkeypatch.setattr(assembly, "_track_turns", lambda toy: [0.0] * len(toy.stages))
    out = tmp_path / "h.dxf"
    code = main(["export", str(GALLERY / "horse.toml"), "-o", str(out), "--assembly", str(tmp_path / "a.svg")])
    stdout = capsys.readouterr().out
    assert code == 3
    assert "pins collide: pin B and pin E" in stdout
    assert "no plan: pins B and E both ride frame" in stdout
    assert out.exists() and 'stroke="#ff0000"' in (tmp_path / "a.svg").read_text()


@pytest.mark.slow
def test_export_of_a_clean_scene_exits_0(tmp_path):
    res = subprocess.run(
        [sys.executable, "-m", "planar", "export", str(GALLERY / "slider-crank.toml"), "-o", str(tmp_path / "s.dxf")],
        capture_output=True,
        text=True,
    )
    assert res.returncode == 0, res.stdout
    assert "build check: every part" in res.stdout


def test_the_check_stacks_each_end_as_its_tiers_beyond_the_faces():
    """A screw through layers 2-4 (3 mm each, 9 mm): the check's end bodies are the head (2.15 mm below the stack,
    7 mm across), then above it the washers and nut to 6 mm (7 mm across) and the thread to the tip, 16 - 0.5 - 9 =
    6.5 mm (3 mm across): the hand sums, as z-ranges."""
    from types import SimpleNamespace

    from planar.fabrication.check import pin_bodies
    from planar.fabrication.parts import FabSettings

    s = FabSettings(thickness_mm=3.0, pin_mm=3.0, hardware="screw")
    spec = SimpleNamespace(parts=("a", "b"), at=((0.0, 0.0), (0.0, 0.0)))
    pp = SimpleNamespace(letter="B", spec=spec, layers=(1, 3), shaft=False, diameter_mm=3.0, parts=("a", "b"))
    poses = {"a": np.zeros((4, 3))}
    ends = [(b.z0, b.z1, 2 * b.radius) for b in pin_bodies(pp, poses, s, {1, 3}) if b.kind == "end"]
    assert ends == [
        pytest.approx((3.0 - 2.15, 3.0, 7.0)),
        pytest.approx((12.0, 12.0 + 6.0, 7.0)),
        pytest.approx((18.0, 12.0 + 6.5, 3.0)),
    ]
