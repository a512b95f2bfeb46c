"""The package's import structure: no cycles (counting imports inside functions), a light ``import planar``."""

from __future__ import annotations

import ast
import json
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("planar", "exporters")
HEAVY = ("pymunk", "ezdxf", "imageio", "matplotlib", "shapely")


def _modules(root: Path, packages: tuple[str, ...]) -> dict[str, Path]:
    out = {}
    for pkg in packages:
        for f in sorted((root / pkg).rglob("*.py")):
            parts = f.relative_to(root).with_suffix("").parts
            out[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = f
    return out


def _is_type_checking(test: ast.expr) -> bool:
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or (
        isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING"
    )


class _Imports(ast.NodeVisitor):
    """The modules one module's import statements name (package ``pkg``, known modules ``mods``)."""

    def __init__(self, pkg: str, mods: set[str]) -> None:
        self.pkg, self.mods, self.names = pkg, mods, set()

    def visit_If(self, node: ast.If) -> None:
        if _is_type_checking(node.test):
            for n in node.orelse:
                self.visit(n)
        else:
            self.generic_visit(node)

    def visit_Import(self, node: ast.Import) -> None:
        self.names.update(a.name for a in node.names)

    def visit_ImportFrom(self, node: ast.ImportFrom) -> None:
        if node.level:
            parts = self.pkg.split(".")
            mod = ".".join(parts[: len(parts) - node.level + 1] + ([node.module] if node.module else []))
        else:
            mod = node.module or ""
        for a in node.names:
            sub = f"{mod}.{a.name}"
            self.names.add(sub if sub in self.mods else mod)


def import_graph(root: Path, packages: tuple[str, ...] = PACKAGES) -> dict[str, set[str]]:
    """Module -> the package modules it imports at run time, wherever the import statement is.

    Imports inside functions count (they run when the function does); imports
    under ``if TYPE_CHECKING:`` do not.  ``from .x import name`` counts as an
    import of module ``x.name`` when that is a module, else of ``x``.  A
    module's own ancestors are left out (they are already being imported).
    """
    mods = _modules(root, packages)
    graph: dict[str, set[str]] = {}
    for name, path in mods.items():
        pkg = name if path.name == "__init__.py" else name.rpartition(".")[0]
        found = _Imports(pkg, set(mods))
        found.visit(ast.parse(path.read_text(), str(path)))
        deps = set()
        for d in found.names:
            if d not in mods:
                continue
            parts = d.split(".")
            # importing a.b.c runs a/__init__ and a/b/__init__ first
            for i in range(1, len(parts) + 1):
                m = ".".join(parts[:i])
                if m in mods and m != name and not name.startswith(m + "."):
                    deps.add(m)
        graph[name] = deps
    return graph


def find_cycle(graph: dict[str, set[str]]) -> list[str] | None:
    """One import cycle ``[a, b, ..., a]`` if the graph has any, else ``None`` (depth-first search)."""
    state: dict[str, int] = {}  # 1: on the current path, 2: done
    path: list[str] = []

    def visit(v: str) -> list[str] | None:
        state[v] = 1
        path.append(v)
        for w in sorted(graph.get(v, ())):
            if state.get(w) == 1:
                return path[path.index(w) :] + [w]
            if w not in state:
                c = visit(w)
                if c:
                    return c
        path.pop()
        state[v] = 2
        return None

    for v in sorted(graph):
        if v not in state:
            c = visit(v)
            if c:
                return c
    return None


def test_the_cycle_finder_finds_a_lazy_cycle(tmp_path):
    # a imports b at module level; b imports a inside a function: still a cycle
    pkg = tmp_path / "pkg"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("")
    (pkg / "a.py").write_text("from . import b\n")
    (pkg / "b.py").write_text(
        "from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    from .c import C\ndef f():\n    from .a import g\n"
    )
    (pkg / "c.py").write_text("from .b import f\n")
    g = import_graph(tmp_path, ("pkg",))
    assert g["pkg.a"] == {"pkg.b"} and g["pkg.b"] == {"pkg.a"}  # the TYPE_CHECKING import is not counted
    assert find_cycle(g) in (["pkg.a", "pkg.b", "pkg.a"], ["pkg.b", "pkg.a", "pkg.b"])
    (pkg / "b.py").write_text("def f():\n    import pkg\n")  # an ancestor package: not a cycle
    assert find_cycle(import_graph(tmp_path, ("pkg",))) is None


def test_no_import_cycles_in_the_package():
    graph = import_graph(ROOT)
    assert "planar.app.pipeline" in graph and "planar.core.features" in graph
    assert find_cycle(graph) is None, " -> ".join(find_cycle(graph) or [])


@pytest.mark.slow
def test_every_module_imports_on_its_own_in_a_fresh_interpreter():
    names = sorted(m for m in _modules(ROOT, PACKAGES) if not m.endswith("__main__"))  # that one runs the CLI
    code = (
        "import importlib, json, sys\n"
        "bad = {}\n"
        f"for name in {names!r}:\n"
        "    for m in [m for m in sys.modules if m.split('.')[0] in ('planar', 'exporters')]:\n"
        "        del sys.modules[m]\n"
        "    try:\n"
        "        importlib.import_module(name)\n"
        "    except Exception as e:\n"
        "        bad[name] = repr(e)\n"
        "print(json.dumps(bad))\n"
    )
    r = subprocess.run(
        [sys.executable, "-c", code],
        check=False,
        capture_output=True,
        text=True,
        cwd=ROOT,
        env={"PYTHONPATH": str(ROOT), "PATH": "", "MPLBACKEND": "Agg"},
    )
    assert r.returncode == 0, r.stderr
    assert json.loads(r.stdout) == {}


@pytest.mark.parametrize("module", ["planar", "planar.app.pipeline", "planar.cli.main"])
def test_light_imports(module):
    code = f"import sys, json; import {module}; print(json.dumps(sorted(m for m in {HEAVY!r} if m in sys.modules)))"
    r = subprocess.run(
        [sys.executable, "-c", code],
        check=False,
        capture_output=True,
        text=True,
        cwd=ROOT,
        env={"PYTHONPATH": str(ROOT), "PATH": ""},
    )
    assert r.returncode == 0, r.stderr
    assert json.loads(r.stdout) == []
