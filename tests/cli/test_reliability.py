"""Issue 13: bad scenes and command-line misuse give one line, exit 2, and leave the disc as it was.

Every case runs ``planar.cli.main.main`` in-process (fast) with an existing output
file present, and checks: exit status 2, exactly one line on stderr starting
``planar: error:`` and naming the field or option, no traceback, no file
created or left behind (temporaries included), the existing output untouched.
A few cases run the real command in a subprocess for the guard and
``--debug``.
"""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

from planar.cli.main import main

ROOT = Path(__file__).resolve().parents[2]
SENTINEL = b"an existing output that a failed command must not touch\n"


def toml(d: dict[str, Any]) -> str:
    """A TOML document of ``d`` (top-level keys as inline tables; enough for scenes)."""

    def val(v: Any) -> str:
        if isinstance(v, bool):
            return "true" if v else "false"
        if isinstance(v, int):
            return str(v)
        if isinstance(v, float):
            return "nan" if math.isnan(v) else ("inf" if v == math.inf else "-inf" if v == -math.inf else repr(v))
        if isinstance(v, str):
            return json.dumps(v)
        if isinstance(v, (list, tuple)):
            return "[" + ", ".join(val(x) for x in v) + "]"
        if isinstance(v, dict):
            return "{ " + ", ".join(f"{json.dumps(k)} = {val(x)}" for k, x in v.items()) + " }"
        raise TypeError(type(v))

    return "".join(f"{json.dumps(k)} = {val(v)}\n" for k, v in d.items())


FOURBAR = {"type": "fourbar", "ground": 4.0, "crank": 1.0, "coupler": 4.0, "rocker": 3.0, "coupler_point": [5.5, -2.0]}


def scene(mech: dict | None = None, **top: Any) -> dict[str, Any]:
    d: dict[str, Any] = {"mechanism": dict(FOURBAR if mech is None else mech)}
    d["driver"] = {"samples_per_cycle": 12}
    for k, v in top.items():
        if isinstance(v, dict) and isinstance(d.get(k), dict):
            d[k] = {**d[k], **v}
        else:
            d[k] = v
    return d


def fb(**kw: Any) -> dict[str, Any]:
    return scene({**FOURBAR, **kw})


def linkage(**kw: Any) -> dict[str, Any]:
    m = {
        "type": "linkage",
        "nodes": [
            {"name": "O", "kind": "fixed", "at": [0.0, 0.0]},
            {"name": "Q", "kind": "fixed", "at": [4.0, 0.0]},
            {"name": "A", "kind": "crank", "centre": "O", "radius": 1.0},
            {"name": "B", "kind": "rrr", "a": "A", "ra": 4.0, "b": "Q", "rb": 3.0},
        ],
        "links": [
            {"name": "crank", "nodes": ["O", "A"]},
            {"name": "coupler", "nodes": ["A", "B"]},
            {"name": "rocker", "nodes": ["Q", "B"]},
        ],
    }
    m.update(kw)
    return scene(m)


# (id, scene dict or raw text/bytes, text the one-line message must contain)
BAD_SCENES: list[tuple[str, Any, str]] = [
    # strict types: no bool or string to number, no string to flag
    ("crank-true", fb(crank=True), "mechanism.crank"),
    ("ground-str", fb(ground="4"), "mechanism.ground"),
    ("coupler-list", fb(coupler=[4.0]), "mechanism.coupler"),
    ("exploded-yes", fb() | {"render": {"exploded": "yes"}}, "render.exploded"),
    ("exploded-1", fb() | {"render": {"exploded": 1}}, "render.exploded"),
    ("samples-float", fb() | {"driver": {"samples_per_cycle": 12.0}}, "driver.samples_per_cycle"),
    ("samples-bool", fb() | {"driver": {"samples_per_cycle": True}}, "driver.samples_per_cycle"),
    ("samples-str", fb() | {"driver": {"samples_per_cycle": "12"}}, "driver.samples_per_cycle"),
    ("speed-str", fb() | {"driver": {"speed": "1"}}, "driver.speed"),
    ("width-float", fb() | {"render": {"width": 480.0}}, "render.width"),
    ("show-pins-str", fb() | {"render": {"show_pins": "no"}}, "render.show_pins"),
    ("widen-int", fb() | {"fabrication": {"widen": 0}}, "fabrication.widen"),
    ("number-float", scene({"type": "elemental", "number": 5.0}), "mechanism.number"),
    ("number-bool", scene({"type": "elemental", "number": True}), "mechanism.number"),
    ("branch-bool", scene({"type": "slidercrank", "crank": 1.0, "rod": 3.0, "branch": True}), "mechanism.branch"),
    ("branch-2", scene({"type": "slidercrank", "crank": 1.0, "rod": 3.0, "branch": 2}), "mechanism.branch"),
    ("cp-bool", fb(coupler_point=[True, 0.0]), "mechanism.coupler_point"),
    ("name-int", fb() | {"name": 5}, "name"),
    ("gravity-str", fb() | {"effects": {"gravity": ["0", "-9.8"]}}, "effects.gravity"),
    ("damping-str", fb() | {"effects": {"damping": "0.9"}}, "effects.damping"),
    # values
    ("crank-neg", fb(crank=-1.0), "mechanism.crank"),
    ("crank-zero", fb(crank=0.0), "mechanism.crank"),
    ("crank-nan", fb(crank=math.nan), "mechanism.crank"),
    ("crank-inf", fb(crank=math.inf), "mechanism.crank"),
    ("cp-nan", fb(coupler_point=[math.nan, 0.0]), "mechanism.coupler_point"),
    ("cp-short", fb(coupler_point=[1.0]), "mechanism.coupler_point"),
    ("cp-long", fb(coupler_point=[1.0, 2.0, 3.0]), "mechanism.coupler_point"),
    ("placement-short", fb(placement=[0.0, 0.0]), "mechanism.placement"),
    ("circuit-bad", fb(circuit="sideways"), "mechanism.circuit"),
    ("no-close", fb(ground=100.0), "mechanism"),
    ("unknown-key", fb(colour="red"), "mechanism.colour"),
    ("unknown-top", fb() | {"extra": 1}, "extra"),
    ("no-mechanism", {"driver": {"speed": 1.0}}, "mechanism"),
    ("type-bad", scene({"type": "gearbox"}), "mechanism"),
    ("speed-zero", fb() | {"driver": {"speed": 0.0}}, "driver.speed"),
    ("speed-tiny", fb() | {"driver": {"speed": 1e-320}}, "driver.speed"),
    ("speed-huge", fb() | {"driver": {"speed": 1e308}}, "driver.speed"),
    ("speed-nan", fb() | {"driver": {"speed": math.nan}}, "driver.speed"),
    ("cycles-huge", fb() | {"driver": {"cycles": 1e308}}, "driver.cycles"),
    ("cycles-many", fb() | {"driver": {"cycles": 1e5, "samples_per_cycle": 100000}}, "driver.cycles"),
    ("duration-huge", fb() | {"driver": {"duration": 1e12}}, "driver.duration"),
    ("cycles-and-duration", fb() | {"driver": {"cycles": 1.0, "duration": 1.0}}, "driver"),
    ("samples-3", fb() | {"driver": {"samples_per_cycle": 3}}, "driver.samples_per_cycle"),
    ("samples-huge", fb() | {"driver": {"samples_per_cycle": 10**9}}, "driver.samples_per_cycle"),
    ("amplitude-toy", scene({"type": "toy", "left": [["Rz->Tx"]]}, driver={"amplitude": 1.0}), "driver.amplitude"),
    ("centre-alone", fb() | {"driver": {"centre": 1.0}}, "driver"),
    ("phase-inf", fb() | {"driver": {"phase": math.inf}}, "driver.phase"),
    ("angle-unit", fb() | {"angle_unit": "grad"}, "angle_unit"),
    ("width-small", fb() | {"render": {"width": 2}}, "render.width"),
    ("background", fb() | {"render": {"background": "white"}}, "render.background"),
    ("trail-missing", fb() | {"render": {"trails": ["nope"]}}, "render.trails[0]"),
    ("sweep-missing", fb() | {"render": {"sweep": ["nope"]}}, "render.sweep[0]"),
    ("load-point", fb() | {"effects": {"loads": [{"point": "nope", "force": [0.0, 1.0]}]}}, "effects.loads[0].point"),
    ("load-nan", fb() | {"effects": {"loads": [{"point": "coupler_point", "force": [math.nan, 1.0]}]}}, "effects.loads[0].force"),
    ("load-short", fb() | {"effects": {"loads": [{"point": "coupler_point", "force": [1.0]}]}}, "effects.loads[0].force"),
    ("spring-part", fb() | {"effects": {"springs": [{"a": "crank", "b": "nope", "stiffness": 1.0}]}}, "effects.springs[0].b"),
    (
        "spring-stiff",
        fb() | {"effects": {"springs": [{"a": "crank", "b": "rocker", "stiffness": -1.0}]}},
        "effects.springs[0].stiffness",
    ),
    ("kerf-big", fb() | {"fabrication": {"kerf_mm": 5.0}}, "fabrication.kerf_mm"),
    ("sheet-inf", fb() | {"fabrication": {"sheet_mm": [math.inf, 200.0]}}, "fabrication.sheet_mm"),
    ("unit-neg", fb() | {"fabrication": {"unit_mm": -1.0}}, "fabrication.unit_mm"),
    # names
    (
        "poly-dup",
        fb(
            polygons=[
                {"name": "foot", "part": "coupler", "points": [[0, 0], [1, 0], [1, 1]]},
                {"name": "foot", "part": "coupler", "points": [[0, 0], [1, 0], [1, 1]]},
            ]
        ),
        "mechanism.polygons[1].name",
    ),
    (
        "poly-part",
        fb(polygons=[{"name": "foot", "part": "nope", "points": [[0, 0], [1, 0], [1, 1]]}]),
        "mechanism.polygons[0].part",
    ),
    (
        "poly-2pts",
        fb(polygons=[{"name": "foot", "part": "coupler", "points": [[0, 0], [1, 0]]}]),
        "mechanism.polygons.foot.points",
    ),
    (
        "poly-comma",
        fb(polygons=[{"name": "a,b", "part": "coupler", "points": [[0, 0], [1, 0], [1, 1]]}]),
        "mechanism.polygons[0].name",
    ),
    ("name-newline", fb() | {"name": "leg\nfoot"}, "name"),
    ("name-control", fb() | {"name": "leg\u0007"}, "name"),
    ("name-quote", fb() | {"name": 'a"b'}, "name"),
    (
        "link-comma",
        linkage(
            links=[
                {"name": "cr,ank", "nodes": ["O", "A"]},
                {"name": "coupler", "nodes": ["A", "B"]},
                {"name": "rocker", "nodes": ["Q", "B"]},
            ]
        ),
        "mechanism.links[0].name",
    ),
    (
        "link-newline",
        linkage(
            links=[
                {"name": "cr\nank", "nodes": ["O", "A"]},
                {"name": "coupler", "nodes": ["A", "B"]},
                {"name": "rocker", "nodes": ["Q", "B"]},
            ]
        ),
        "mechanism.links[0].name",
    ),
    ("node-missing", linkage(links=[{"name": "crank", "nodes": ["O", "Z"]}]), "mechanism"),
    ("node-kind", linkage(nodes=[{"name": "O", "kind": "weld"}]), "mechanism.nodes.O.kind"),
    (
        "node-needs",
        linkage(nodes=[{"name": "O", "kind": "fixed"}, {"name": "A", "kind": "crank", "centre": "O"}]),
        "mechanism.nodes",
    ),
    # elemental parameters: vectors of the wrong length, numbers for vectors
    ("D_jc-number", scene({"type": "elemental", "number": 1, "params": {"D_jc": 0.5}}), "params.D_jc"),
    ("D_o-short", scene({"type": "elemental", "number": 1, "params": {"D_o": [0.0]}}), "params.D_o"),
    ("F_o-long", scene({"type": "elemental", "number": 1, "params": {"F_o": [0.3, 0.0, 0.0, 0.0]}}), "params.F_o"),
    ("D_jr-vector", scene({"type": "elemental", "number": 1, "params": {"D_jr": [0.1, 0.2]}}), "params.D_jr"),
    ("D_jr-neg", scene({"type": "elemental", "number": 1, "params": {"D_jr": -0.1}}), "params.D_jr = -0.1"),
    ("param-unknown", scene({"type": "elemental", "number": 2, "params": {"Q": 1.0}}), "params.Q"),
    ("param-bool", scene({"type": "elemental", "number": 2, "params": {"D_jr": True}}), "mechanism.params.D_jr = True"),
    ("D_theta-short", scene({"type": "elemental", "number": 10, "params": {"D_theta": [0.3]}}), "params.D_theta"),
    ("path-number", scene({"type": "elemental", "number": 11, "params": {"path": 0.1}}), "params.path"),
    ("number-12", scene({"type": "elemental", "number": 12}), "mechanism.number"),
    # chains and toys
    ("chain-bad", scene({"type": "chain", "chain": ["Rz->Tx", "Tx->Qz"]}), "chain[1]"),
    ("chain-break", scene({"type": "chain", "chain": ["Rz->Tx", "Oz->Ox"]}), "chain[1]"),
    ("chain-form", scene({"type": "chain", "chain": ["RzTx"]}), "chain[0]"),
    ("chain-empty", scene({"type": "chain", "chain": []}), "mechanism.chain"),
    ("toy-empty", scene({"type": "toy"}), "mechanism"),
    ("toy-bad", scene({"type": "toy", "right": [["Rz->Tx", "Oz->Ox"]]}), "right[0][1]"),
    ("toy-phase-nan", scene({"type": "toy", "left": [["Rz->Tx"]], "phase": math.nan}), "mechanism.phase"),
    ("catalog-bad", scene({"type": "catalog", "name": "nope"}), "mechanism: name = 'nope'"),
    # files that are not scenes
    ("binary", b"\x00\x01\x02\xff\xfe garbage", "not a text file"),
    ("utf16-bom", "\ufeff" + toml({"mechanism": FOURBAR}) + "bad = = 1\n", "not valid TOML"),
    ("bad-utf8", b'name = "\xff\xfe\xfa"\n', "UTF-8"),
    ("not-toml", "this is not toml", "not valid TOML"),
    ("empty", "", "mechanism"),
]


def _write_scene(path: Path, content: Any) -> None:
    if isinstance(content, dict):
        path.write_text(toml(content))
    elif isinstance(content, bytes):
        path.write_bytes(content)
    elif content.startswith("\ufeff"):
        path.write_bytes(content[1:].encode("utf-16"))  # what Notepad writes: UTF-16 with a byte-order mark
    else:
        path.write_text(content)


def _run(argv: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    rc = main(argv)
    out, err = capsys.readouterr()
    return rc, out, err


def _check_one_line(rc: int, err: str, needle: str) -> None:
    assert rc == 2, err
    lines = err.splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("planar: error: "), err
    assert "Traceback" not in err
    assert needle in lines[0], f"{needle!r} not in {lines[0]!r}"


def _snapshot(folder: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in folder.iterdir() if p.is_file()}


@pytest.mark.slow
@pytest.mark.parametrize("content,needle", [c[1:] for c in BAD_SCENES], ids=[c[0] for c in BAD_SCENES])
def test_bad_scene(tmp_path: Path, capsys: pytest.CaptureFixture[str], content: Any, needle: str) -> None:
    src = tmp_path / "scene.toml"
    _write_scene(src, content)
    out = tmp_path / "out.csv"
    out.write_bytes(SENTINEL)
    before = _snapshot(tmp_path)
    rc, _, err = _run(["motion", str(src), "-o", str(out)], capsys)
    _check_one_line(rc, err, needle)
    assert str(src) in err or "scene.toml" in err  # the user's path, never a temporary
    assert ".out.csv." not in err  # a temporary is named .out.csv.XXXX.part
    assert _snapshot(tmp_path) == before  # nothing written, nothing left behind, the output intact


GOOD = toml(scene())


# (id, argv with {scene}/{out}/{dir} placeholders, needle); every output that exists holds SENTINEL first
MISUSES: list[tuple[str, list[str], str]] = [
    ("no-command", [], "required"),
    ("bad-command", ["frobnicate"], "invalid choice"),
    ("render-no-output", ["render", "{scene}"], "-o/--output"),
    ("render-no-scene", ["render"], "scene"),
    ("unknown-option", ["motion", "{scene}", "-o", "{dir}/m.csv", "--fast"], "--fast"),
    ("missing-scene", ["motion", "{dir}/nope.toml", "-o", "{dir}/m.csv"], "nope.toml"),
    ("scene-is-dir", ["motion", "{dir}", "-o", "{dir}/m.csv"], "directory"),
    ("empty-output", ["motion", "{scene}", "-o", ""], "-o"),
    ("output-is-input", ["motion", "{scene}", "-o", "{scene}"], "-o"),
    ("output-wrong-ext", ["motion", "{scene}", "-o", "{dir}/m.gif"], ".csv"),
    ("output-no-dir", ["motion", "{scene}", "-o", "{dir}/nodir/m.csv"], "nodir"),
    ("output-is-dir", ["motion", "{scene}", "-o", "{dir}"], "-o"),
    ("render-ext", ["render", "{scene}", "-o", "{dir}/x.csv"], ".gif or .mp4 or .webm"),
    ("render-is-input", ["render", "{scene}", "-o", "{scene}"], "-o"),
    ("export-nothing", ["export", "{scene}"], "an output"),
    ("export-dxf-ext", ["export", "{scene}", "-o", "{dir}/parts.svg"], ".dxf"),
    ("export-svg-ext", ["export", "{scene}", "-o", "{dir}/parts.dxf", "--svg", "{dir}/parts.dxf"], "--svg"),
    ("export-svg-nodir", ["export", "{scene}", "-o", "{dir}/parts.dxf", "--svg", "{dir}/nodir/x.svg"], "nodir"),
    ("export-bom-ext", ["export", "{scene}", "-o", "{dir}/parts.dxf", "--bom", "{dir}/bom.txt"], "--bom"),
    ("export-preview-ext", ["export", "{scene}", "--preview", "{dir}/p.jpg"], "--preview"),
    ("export-kerf-test-ext", ["export", "{scene}", "--kerf-test", "{dir}/k.png"], "--kerf-test"),
    ("export-same-twice", ["export", "{scene}", "--svg", "{dir}/a.svg", "--assembly", "{dir}/a.svg"], "--assembly"),
    ("export-kerf-nan", ["export", "{scene}", "-o", "{dir}/parts.dxf", "--kerf", "nan"], "--kerf"),
    ("export-kerf-neg", ["export", "{scene}", "-o", "{dir}/parts.dxf", "--kerf", "-1"], "--kerf"),
    ("export-kerf-text", ["export", "{scene}", "-o", "{dir}/parts.dxf", "--kerf", "wide"], "--kerf"),
    ("export-sheet-inf", ["export", "{scene}", "-o", "{dir}/parts.dxf", "--sheet", "infx200"], "--sheet"),
    ("export-sheet-nan", ["export", "{scene}", "-o", "{dir}/parts.dxf", "--sheet", "nanx200"], "--sheet"),
    ("export-sheet-form", ["export", "{scene}", "-o", "{dir}/parts.dxf", "--sheet", "300"], "--sheet"),
    ("export-sheet-zero", ["export", "{scene}", "-o", "{dir}/parts.dxf", "--sheet", "0x200"], "--sheet"),
    ("catalog-unknown", ["catalog", "nope", "-o", "{dir}/c.csv"], "nope"),
    ("catalog-samples-0", ["catalog", "jansen", "-o", "{dir}/c.csv", "--samples", "0"], "--samples"),
    ("catalog-samples-huge", ["catalog", "jansen", "-o", "{dir}/c.csv", "--samples", "1000000000"], "--samples"),
    ("catalog-samples-float", ["catalog", "jansen", "-o", "{dir}/c.csv", "--samples", "1e9"], "--samples"),
    ("catalog-ext", ["catalog", "jansen", "-o", "{dir}/c.gif"], ".csv"),
    ("chains-long", ["chains", "--max-length", "12"], "--max-length"),
    ("chains-zero", ["chains", "--max-length", "0"], "--max-length"),
    ("chains-target", ["chains", "Qx"], "Qx"),
    ("bench-n-0", ["bench", "kinematics", "-n", "0"], "-n"),
    ("bench-n-huge", ["bench", "kinematics", "-n", "10000000000"], "-n"),
    ("bench-repeats-0", ["bench", "kinematics", "--repeats", "0"], "--repeats"),
    ("bench-unknown", ["bench", "nope"], "invalid choice"),
    ("compare-threshold-nan", ["compare", "{scene}", "--threshold", "nan"], "--threshold"),
    ("compare-threshold-neg", ["compare", "{scene}", "--threshold", "-1"], "--threshold"),
    ("compare-substeps-0", ["compare", "{scene}", "--substeps", "0"], "--substeps"),
    ("compare-bias", ["compare", "{scene}", "--error-bias", "2"], "--error-bias"),
    ("gallery-output-file", ["gallery", "--source", "{dir}", "-o", "{dir}/m.csv"], "-o"),
    ("gallery-no-source", ["gallery", "--source", "{dir}/nodir"], "nodir"),
    ("schema-ext", ["schema", "-o", "{dir}/s.txt"], ".json"),
    ("demo-output-file", ["demo", "-o", "{dir}/m.csv"], "-o"),
    ("plot-samples-huge", ["plot", "{scene}", "-o", "{dir}/p.png", "--samples", "100000000"], "PLANAR_MAX_SAMPLES"),
    ("plot-ext", ["plot", "{scene}", "-o", "{dir}/p.txt"], "-o"),
    ("plot-is-input", ["plot", "{scene}", "-o", "{scene}"], "-o"),
    ("synth-output-is-input", ["synth", "path", "{dir}/m.csv", "-o", "{dir}/m.csv"], "-o"),
    ("synth-ext", ["synth", "function", "{dir}/m.csv", "-o", "{dir}/s.txt"], ".toml"),
]


@pytest.mark.slow
@pytest.mark.parametrize("argv,needle", [c[1:] for c in MISUSES], ids=[c[0] for c in MISUSES])
def test_cli_misuse(tmp_path: Path, capsys: pytest.CaptureFixture[str], argv: list[str], needle: str) -> None:
    src = tmp_path / "scene.toml"
    src.write_text(GOOD)
    for name in ("m.csv", "parts.dxf", "a.svg", "c.csv"):
        (tmp_path / name).write_bytes(SENTINEL)
    before = _snapshot(tmp_path)
    args = [a.format(scene=src, dir=tmp_path) for a in argv]
    rc, _, err = _run(args, capsys)
    _check_one_line(rc, err, needle)
    assert _snapshot(tmp_path) == before
    assert not list(tmp_path.glob("nodir"))


# scenes that validate but cannot be cut or drawn: (id, scene, command, needle)
BAD_JOBS: list[tuple[str, dict, str, str]] = [
    ("holes-overlap", fb() | {"fabrication": {"unit_mm": 3.0, "pin_diameter_mm": 20.0}}, "export", "min_wall_mm"),
    ("kerf-wider-than-parts", fb() | {"fabrication": {"unit_mm": 0.05, "kerf_mm": 2.0}}, "export", "kerf"),
    ("too-many-frames", fb() | {"driver": {"samples_per_cycle": 72, "cycles": 1000.0}}, "render", "PLANAR_MAX_FRAMES"),
    (
        "parts-larger-than-sheet",
        scene({"type": "elemental", "number": 6}, fabrication={"unit_mm": 1e20}),
        "export",
        "fabrication.unit_mm",
    ),
    ("sheet-too-large", fb() | {"fabrication": {"sheet_mm": [1e30, 200.0]}}, "export", "fabrication.sheet_mm"),
    (
        "cycle-too-slow-to-draw",
        scene({"type": "elemental", "number": 3}, driver={"speed": 1e-9}),
        "render",
        "driver.cycles = 1.0: expected an animation of at most",
    ),
    ("coupler-point-1e305", fb(coupler_point=[0.75, -9.24e305]), "render", "mechanism"),
    ("frames-by-duration", fb() | {"driver": {"samples_per_cycle": 72, "duration": 1e5}}, "render", "driver.duration"),
]


@pytest.mark.slow
@pytest.mark.parametrize("content,command,needle", [c[1:] for c in BAD_JOBS], ids=[c[0] for c in BAD_JOBS])
def test_bad_job(tmp_path: Path, capsys: pytest.CaptureFixture[str], content: dict, command: str, needle: str) -> None:
    src = tmp_path / "scene.toml"
    src.write_text(toml(content))
    outs = {
        "export": ["-o", str(tmp_path / "parts.dxf"), "--svg", str(tmp_path / "parts.svg"), "--bom", str(tmp_path / "bom.csv")],
        "render": ["-o", str(tmp_path / "parts.gif")],
    }[command]
    (tmp_path / "parts.dxf").write_bytes(SENTINEL)
    (tmp_path / "parts.gif").write_bytes(SENTINEL)
    before = _snapshot(tmp_path)
    rc, _, err = _run([command, str(src), *outs], capsys)
    _check_one_line(rc, err, needle)
    assert _snapshot(tmp_path) == before


def test_utf16_scene_with_a_byte_order_mark_is_read(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    src = tmp_path / "scene.toml"
    src.write_bytes(GOOD.encode("utf-16"))
    rc, _out, err = _run(["motion", str(src), "-o", str(tmp_path / "m.csv")], capsys)
    assert rc == 0, err
    assert (tmp_path / "m.csv").read_text().count("\n") == 13


def test_corpus_is_large_enough() -> None:
    assert len(BAD_SCENES) + len(MISUSES) + len(BAD_JOBS) >= 100


def test_interrupted_gallery_writes_nothing(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """Ctrl-C after the first GIF is finished: one line, exit 130, the finished GIF's temporary removed."""
    import planar.app.pipeline as pipeline

    src = tmp_path / "scenes"
    src.mkdir()
    for name in ("a", "b"):
        (src / f"{name}.toml").write_text(GOOD)
    real = pipeline.render_scene
    calls = []

    def render_then_interrupt(*a: Any, **k: Any) -> int:
        calls.append(1)
        if len(calls) == 2:
            raise KeyboardInterrupt
        return real(*a, **k)

    monkeypatch.setattr(pipeline, "render_scene", render_then_interrupt)
    rc, _, err = _run(["gallery", "--source", str(src), "-o", str(tmp_path / "out")], capsys)
    assert rc == 130 and len(err.splitlines()) == 1 and "interrupted" in err
    assert list((tmp_path / "out").iterdir()) == []


def test_gallery_is_all_or_nothing(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A bad scene among good ones: no GIF written (not the earlier ones either); an existing GIF intact."""
    src = tmp_path / "scenes"
    src.mkdir()
    (src / "a.toml").write_text(GOOD)
    (src / "b.toml").write_text(toml(fb(crank=True)))
    (src / "c.toml").write_text(GOOD)
    out = tmp_path / "out"
    out.mkdir()
    (out / "a.gif").write_bytes(SENTINEL)
    rc, _, err = _run(["gallery", "--source", str(src), "-o", str(out)], capsys)
    _check_one_line(rc, err, "b.toml")
    assert sorted(p.name for p in out.iterdir()) == ["a.gif"]
    assert (out / "a.gif").read_bytes() == SENTINEL


def test_export_failure_after_some_outputs_leaves_none(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Fabrication refuses the parts (overlapping holes): neither the DXF nor the SVG is written or replaced."""
    src = tmp_path / "scene.toml"
    src.write_text(toml(fb() | {"fabrication": {"unit_mm": 3.0, "pin_diameter_mm": 20.0}}))
    (tmp_path / "parts.dxf").write_bytes(SENTINEL)
    before = _snapshot(tmp_path)
    rc, _, err = _run(["export", str(src), "-o", str(tmp_path / "parts.dxf"), "--svg", str(tmp_path / "p.svg")], capsys)
    _check_one_line(rc, err, "min_wall_mm")
    assert _snapshot(tmp_path) == before


@pytest.mark.slow
def test_limits_are_configurable(tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch) -> None:
    """The message names the variable; raising it lets the same request through."""
    src = tmp_path / "scene.toml"
    src.write_text(toml(fb() | {"driver": {"samples_per_cycle": 12, "cycles": 10.0}}))
    monkeypatch.setenv("PLANAR_MAX_SAMPLES", "100")
    rc, _, err = _run(["motion", str(src), "-o", str(tmp_path / "m.csv")], capsys)
    _check_one_line(rc, err, "PLANAR_MAX_SAMPLES")
    assert "driver.cycles = 10.0" in err
    monkeypatch.setenv("PLANAR_MAX_SAMPLES", "200")
    rc, _out, err = _run(["motion", str(src), "-o", str(tmp_path / "m.csv")], capsys)
    assert rc == 0, err
    assert len((tmp_path / "m.csv").read_text().splitlines()) == 121
    monkeypatch.setenv("PLANAR_MAX_MEMORY", "1")  # MiB: 120 samples fit, 12 000 do not
    src.write_text(toml(fb() | {"driver": {"samples_per_cycle": 12, "cycles": 1000.0}}))
    monkeypatch.setenv("PLANAR_MAX_SAMPLES", "20000")
    rc, _, err = _run(["motion", str(src), "-o", str(tmp_path / "m.csv")], capsys)
    _check_one_line(rc, err, "PLANAR_MAX_MEMORY")
    assert len((tmp_path / "m.csv").read_text().splitlines()) == 121  # the earlier output intact
    monkeypatch.setenv("PLANAR_MAX_SAMPLES", "many")
    rc, _, err = _run(["motion", str(src), "-o", str(tmp_path / "m.csv")], capsys)
    _check_one_line(rc, err, "PLANAR_MAX_SAMPLES")


def test_names_are_quoted_or_refused_in_outputs(tmp_path: Path) -> None:
    """From Python a point may be named with a comma: the CSV quotes it; a newline is refused, naming it."""
    import csv

    from planar.errors import InputError
    from planar.fileio import write_motion_csv
    from planar.linkages import Crank, Fixed, Link, Linkage

    def leg(point: str) -> Linkage:
        return Linkage("leg", [Fixed("O", (0.0, 0.0)), Crank("A", "O", 1.0)], [Link("crank", ("O", "A"))], points={point: "A"})

    mech = leg("toe, left")
    write_motion_csv(tmp_path / "m.csv", mech, mech.run(8))
    rows = list(csv.reader((tmp_path / "m.csv").open()))
    assert "toe, left.x" in rows[0]
    assert {len(r) for r in rows} == {len(rows[0])}
    mech = leg("toe\nleft")
    with pytest.raises(InputError, match="control characters"):
        write_motion_csv(tmp_path / "n.csv", mech, mech.run(8))
    assert not (tmp_path / "n.csv").exists()


def test_internal_error_is_one_line_and_debug_shows_it(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    import planar.windup.table as table

    def boom(*a: Any, **k: Any) -> Any:
        raise RuntimeError("boom\nsecond line")

    monkeypatch.setattr(table, "enumerate_chains", boom)
    rc, _, err = _run(["chains"], capsys)
    assert rc == 1
    assert err.count("\n") == 1 and "internal error: RuntimeError: boom second line" in err and "--debug" in err
    rc, _, err = _run(["--debug", "chains"], capsys)  # the traceback, and still the exit status of a bug
    assert rc == 1 and "Traceback (most recent call last)" in err and "RuntimeError: boom" in err


def _subprocess(args: list[str], cwd: Path) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    return subprocess.run([sys.executable, "-m", "planar", *args], cwd=cwd, env=env, capture_output=True, text=True, timeout=120)


@pytest.mark.slow
def test_subprocess_errors_are_one_line_without_traceback(tmp_path: Path) -> None:
    (tmp_path / "bad.toml").write_bytes(b"\xff\xfe" + "crank = = \n".encode("utf-16-le"))
    (tmp_path / "loop.toml").symlink_to(tmp_path / "loop.toml")
    for args, needle in (
        (["render", "bad.toml", "-o", "x.gif"], "bad.toml"),
        (["motion", "loop.toml", "-o", "x.csv"], "loop.toml"),
        (["render", "bad.toml"], "-o/--output"),
    ):
        r = _subprocess(args, tmp_path)
        assert r.returncode == 2, r.stderr
        assert len(r.stderr.splitlines()) == 1 and needle in r.stderr and "Traceback" not in r.stderr, r.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.toml", "loop.toml"]


@pytest.mark.slow
def test_awkward_names_survive_every_format_or_are_refused(tmp_path: Path) -> None:
    """From Python a link may be named with a comma, quotes and XML specials: ezdxf, the csv module and
    svgelements read the outputs back; a newline is refused with the name, and nothing is written."""
    import csv

    import ezdxf
    import svgelements

    from planar.app.pipeline import export_scene
    from planar.errors import InputError
    from planar.linkages import RRR, Crank, Fixed, Link, Linkage
    from planar.scene.load import Scene, parse_scene

    spec = parse_scene(linkage())

    def leg(name: str) -> Scene:
        mech = Linkage(
            "leg",
            [Fixed("O", (0.0, 0.0)), Fixed("Q", (4.0, 0.0)), Crank("A", "O", 1.0), RRR("B", "A", 4.0, "Q", 3.0)],
            [Link(name, ("O", "A")), Link("coupler", ("A", "B")), Link("rocker", ("Q", "B"))],
        )
        return Scene(spec, mech, "leg.toml")

    outs = {"dxf": tmp_path / "p.dxf", "svg": tmp_path / "p.svg", "bom": tmp_path / "b.csv", "assembly": tmp_path / "a.svg"}
    export_scene(leg('cr,ank "x" <&>'), **outs)
    groups = [g for g, _ in ezdxf.readfile(outs["dxf"]).groups]
    assert 'cr,ank_"x"_<&>' in groups
    rows = list(csv.reader(outs["bom"].open()))
    assert {len(r) for r in rows} == {8} and any(r[1] == 'cr,ank "x" <&>' for r in rows)
    assert list(svgelements.SVG.parse(outs["assembly"]).elements())  # well-formed XML
    assert 'cr,ank "x" &lt;&amp;&gt;' in outs["assembly"].read_text()  # the name, escaped
    for p in outs.values():
        p.unlink()
    with pytest.raises(InputError, match="control characters"):
        export_scene(leg("cr\nank"), **outs)
    assert list(tmp_path.iterdir()) == []
