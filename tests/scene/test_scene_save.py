"""Scene.save and the Python route: a mechanism built in code becomes a scene, renders and exports."""

from __future__ import annotations

import tomllib
from dataclasses import fields
from pathlib import Path

import numpy as np
import pytest

from planar.app.pipeline import export_mechanism, render_mechanism, write_mechanism_motion
from planar.errors import InputError
from planar.linkages import NODE_KINDS, RRR, Crank, Fixed, FourBar, Link, Linkage, SliderCrank
from planar.scene.catalog import get
from planar.scene.load import load_scene, scene_from_mechanism, scene_schema
from planar.windup import ELEMENTAL, elemental
from planar.windup.chain import ToyMechanism, horse

ROOT = Path(__file__).resolve().parents[2]
#: the node kinds planar ships (tests elsewhere register their own)
SHIPPED_KINDS = [k for k, c in NODE_KINDS.items() if c.__module__.startswith("planar.")]
GALLERY = sorted((ROOT / "gallery").glob("*.toml"))


def _same_motion(a, b) -> None:
    assert set(a.poses) == set(b.poses)
    for k in a.poses:
        assert np.array_equal(a.poses[k], b.poses[k]), k
    assert np.array_equal(a.valid, b.valid)


@pytest.mark.parametrize("path", GALLERY, ids=[p.stem for p in GALLERY])
def test_gallery_scene_save_load_round_trip(path: Path, tmp_path: Path) -> None:
    sc = load_scene(path)
    out = tmp_path / "again.toml"
    sc.save(out)
    back = load_scene(out)
    assert back.spec == sc.spec
    _same_motion(sc.motion(), back.motion())


@pytest.mark.parametrize(
    "make",
    [
        lambda: FourBar(4, 1, 4, 3, coupler_point=(5.5, -2), placement=(1, 2, 0.3), rate=3.0, phase=0.2, circuit="crossed"),
        lambda: FourBar(4, 1, 4, 3, amplitude=0.5, centre=1.2),
        lambda: SliderCrank(1, 3, offset=0.4, branch=-1),
        lambda: get("jansen"),
        lambda: elemental(2, D_jc=(0.0, 0.08)),
        lambda: elemental(10),
        lambda: horse(phase=1.0),
    ],
    ids=["fourbar", "rocking", "slidercrank", "jansen", "elemental-2", "elemental-10", "horse"],
)
def test_python_mechanism_saved_as_scene_moves_the_same(make, tmp_path: Path) -> None:
    mech = make()
    sc = scene_from_mechanism(mech, driver={"samples_per_cycle": 30})
    out = tmp_path / "m.toml"
    sc.save(out)
    tomllib.loads(out.read_text())  # a plain TOML file
    back = load_scene(out)
    m = back.motion()
    assert m.t is not None
    _same_motion(mech.solve(mech.driver.value(m.t), t=m.t), m)


def test_what_a_scene_cannot_say_is_refused() -> None:
    link = Linkage(
        "w",
        [Fixed("O", (0, 0)), Fixed("Z", (3, 0)), Crank("A", "O", 1.0), RRR("B", "A", 3, "Z", 2)],
        [Link("crank", ("O", "A")), Link("c", ("A", "B")), Link("r", ("Z", "B"))],
        width=0.5,
    )
    with pytest.raises(InputError, match="width"):
        scene_from_mechanism(link)
    # a toy's stage overrides are scene keys now ([[mechanism.stages]]): what is saved is what runs
    toy = ToyMechanism({"left": [("Rz->Tx",)]}, overrides={("Rz->Tx",): {"D_jc": (0.0, 0.09)}})
    assert scene_from_mechanism(toy).mechanism.stages[0].mech.params.D_jc == (0.0, 0.09)


def test_render_export_and_motion_of_a_python_mechanism(tmp_path: Path) -> None:
    import ezdxf

    leg = FourBar(4, 1, 4, 3, coupler_point=(5.5, -2.0), name="leg")
    n = render_mechanism(leg, tmp_path / "leg.gif", driver={"samples_per_cycle": 12}, render={"width": 96, "height": 72})
    assert n == 25 and (tmp_path / "leg.gif").stat().st_size > 0  # 1 cycle/s at 25 frames/s
    fab = export_mechanism(leg, tmp_path / "leg.dxf", fabrication={"unit_mm": 15.0})
    doc = ezdxf.readfile(tmp_path / "leg.dxf")
    cut = [p for p in fab.layout.parts if not p.name.startswith("spacer ")]  # spacer rings are cut beside the parts
    assert len(cut) == len(list(leg.parts))
    assert len(doc.modelspace()) > 0
    mo = write_mechanism_motion(leg, tmp_path / "leg.csv", derivatives=True)
    head = (tmp_path / "leg.csv").read_text().splitlines()[0]
    assert len(mo) == 72 and "coupler_point.ax" in head


def test_every_scene_key_is_described_and_every_node_kind_has_an_example() -> None:
    sch = scene_schema()
    missing = [k for k, v in sch["properties"].items() if not v.get("description")]
    for name, d in sch["$defs"].items():
        if not d.get("description"):
            missing.append(name)
        missing += [f"{name}.{k}" for k, v in d.get("properties", {}).items() if not v.get("description")]
    assert missing == []
    node_doc = sch["$defs"]["NodeSpec"]["description"]
    assert len(SHIPPED_KINDS) >= 6
    for kind in SHIPPED_KINDS:
        assert f'kind = "{kind}"' in node_doc, kind


def test_docs_table_every_elemental_parameter_and_node_kind() -> None:
    section = (ROOT / "docs" / "how-to" / "wind-up-toys.md").read_text()
    section = section.split("## Elemental parameters", 1)[1].split("\n## ", 1)[0]
    rows = {line.split("|")[1].strip().strip("`") for line in section.splitlines() if line.startswith("| `")}
    names = {f.name for rec in ELEMENTAL.values() for f in fields(rec.params)}
    assert names <= rows, names - rows
    kinds = (ROOT / "docs" / "how-to" / "linkage-scenes.md").read_text()
    for kind in SHIPPED_KINDS:
        assert f"`{kind}`" in kinds
