"""The public API: every exported name resolves, lazily, and the face functions run a mechanism or a scene."""

from __future__ import annotations

import ast
import importlib
import json
import pkgutil
import subprocess
import sys
import types
from pathlib import Path

import pytest

import planar

ROOT = Path(__file__).resolve().parents[1]


def _module_names(module: str) -> set[str]:
    """The names a module defines or imports at its top level, read from its source (nothing imported)."""
    path = ROOT / (module.replace(".", "/") + ".py")
    if not path.exists():
        path = ROOT / module.replace(".", "/") / "__init__.py"
    names: set[str] = set()
    for node in ast.parse(path.read_text(encoding="utf-8")).body:
        if isinstance(node, ast.FunctionDef | ast.ClassDef):
            names.add(node.name)
        elif isinstance(node, ast.Assign | ast.AnnAssign):
            targets = node.targets if isinstance(node, ast.Assign) else [node.target]
            names.update(t.id for t in targets if isinstance(t, ast.Name))
        elif isinstance(node, ast.ImportFrom):
            names.update(a.asname or a.name for a in node.names)
    return names


def test_every_name_in_all_has_a_home() -> None:
    # quick and import-free: each lazy name is defined (or re-exported) by the module it is loaded from
    lazy = planar._LAZY
    homeless = [n for n in planar.__all__ if n not in vars(planar) and n not in _module_names(lazy.get(n, "planar"))]
    assert homeless == []
    assert set(lazy) <= set(planar.__all__)


@pytest.mark.slow  # imports every room the names live in (pymunk, pydantic): about a second of CPU
def test_every_name_in_all_resolves() -> None:
    assert len(planar.__all__) == len(set(planar.__all__))
    for name in planar.__all__:
        assert getattr(planar, name) is not None, name
    assert set(planar.__all__) <= set(dir(planar))
    with pytest.raises(AttributeError, match="no_such_name"):
        planar.no_such_name  # noqa: B018


def test_the_working_set_is_there() -> None:
    for name in ("FourBar", "SliderCrank", "Linkage", "Mechanism", "Motion", "Part", "Driver", "load_scene", "Scene"):
        assert name in planar.__all__, name
    for name in ("scene_from_mechanism", "compare", "simulate", "export", "render", "PlanarError", "InputError"):
        assert name in planar.__all__, name
    from planar.core.model import Mechanism
    from planar.linkages.fourbar import FourBar

    assert planar.FourBar is FourBar and planar.Mechanism is Mechanism
    assert issubclass(planar.FourBar, planar.Mechanism)


def _subpackages() -> list[str]:
    return sorted(m.name for m in pkgutil.iter_modules(planar.__path__) if m.ispkg)


@pytest.mark.parametrize("room", _subpackages())
def test_every_subpackage_declares_all_without_shadowing_its_modules(room: str) -> None:
    pkg = importlib.import_module(f"planar.{room}")  # light: the names load on first use
    names = pkg.__all__
    assert names, room
    modules = {m.name for m in pkgutil.iter_modules(pkg.__path__)}
    assert not set(names) & modules, f"planar.{room} exports names that shadow its modules: {set(names) & modules}"
    # a room's __init__ loads names from its own modules only (the import scan in test_layout.py does not
    # see a module named in a string)
    source = (ROOT / "planar" / room / "__init__.py").read_text(encoding="utf-8")
    named = {n.value for n in ast.walk(ast.parse(source)) if isinstance(n, ast.Constant) and str(n.value).startswith("planar.")}
    assert all(m.startswith(f"planar.{room}.") for m in named), named


@pytest.mark.slow  # imports every module of every room
@pytest.mark.parametrize("room", _subpackages())
def test_every_subpackage_name_resolves(room: str) -> None:
    pkg = importlib.import_module(f"planar.{room}")
    for name in pkg.__all__:
        assert not isinstance(getattr(pkg, name), types.ModuleType), name


def test_import_planar_and_its_light_rooms_load_no_numpy() -> None:
    code = (
        "import sys, json, planar, planar.scene, planar.physics, planar.app, planar.synth, planar.draw;"
        "planar.PlanarError; print(json.dumps('numpy' in sys.modules))"
    )
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, env={"PYTHONPATH": str(ROOT)})
    assert r.returncode == 0, r.stderr
    assert json.loads(r.stdout) is False


@pytest.mark.slow
def test_face_functions_take_a_mechanism_or_a_scene(tmp_path: Path) -> None:
    leg = planar.FourBar(ground=4, crank=1, coupler=4, rocker=3, coupler_point=(5.5, -2.0))
    frames = planar.render(leg, tmp_path / "leg.gif", driver={"samples_per_cycle": 12}, render={"width": 96})
    assert frames > 0 and (tmp_path / "leg.gif").read_bytes()[:6] == b"GIF89a"
    scene = planar.scene_from_mechanism(leg, fabrication={"unit_mm": 15.0})
    fab = planar.export(scene, dxf=tmp_path / "leg.dxf")
    assert (tmp_path / "leg.dxf").stat().st_size > 0 and len(fab.written) == 1
    with pytest.raises(planar.InputError, match="render"):
        planar.render(scene, tmp_path / "x.gif", render={"width": 96})  # tables belong to a mechanism
    assert not (tmp_path / "x.gif").exists()
