"""The package's shape: one way for data, no import cycles, few top-level modules.

Every import counts: module level, inside functions and under ``TYPE_CHECKING``.
The modules are read as text (``ast``), so nothing is imported to check them.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

# The rooms in the order data flows: a room may import only rooms before it
# (and itself).  docs/explanation/architecture.md explains the order.
ORDER = [
    "errors",
    "core",
    "fileio",
    "linkages",
    "cams",
    "windup",
    "toys",
    "analysis",
    "scene",
    "physics",
    "fabrication",
    "draw",
    "synth",
    "app",
    "bench",
    "cli",
]
# top-level modules that are not rooms of the order
ENTRY = {"__init__", "__main__"}


def _module_name(path: Path) -> str:
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts)


def _modules() -> dict[str, Path]:
    files = sorted((ROOT / "planar").rglob("*.py")) + sorted((ROOT / "exporters").rglob("*.py"))
    return {_module_name(p): p for p in files}


def _imports(name: str, path: Path, known: set[str]) -> set[str]:
    """Every planar or exporters module that ``path`` imports, wherever the import stands."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    is_pkg = path.name == "__init__.py"
    found: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = name.split(".") if is_pkg else name.split(".")[:-1]
                base = base[: len(base) - (node.level - 1)]
                mod = ".".join([*base, node.module] if node.module else base)
            else:
                mod = node.module or ""
            for alias in node.names:
                sub = f"{mod}.{alias.name}"
                found.add(sub if sub in known else mod)
        elif isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names)
    return {m for m in found if m in known and m != name}


def _graph() -> dict[str, set[str]]:
    mods = _modules()
    known = set(mods)
    return {name: _imports(name, path, known) for name, path in mods.items()}


def _room(module: str) -> str:
    parts = module.split(".")
    if parts[0] == "exporters":
        return "exporters"
    return parts[1] if len(parts) > 1 else "__init__"


def test_no_import_cycles() -> None:
    graph = _graph()
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    cycles: list[list[str]] = []
    counter = [0]

    def visit(v: str) -> None:  # Tarjan's strongly connected components
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on_stack.add(v)
        for w in sorted(graph[v]):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                cycles.append(sorted(comp))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    assert cycles == []


@pytest.mark.slow
def test_data_flows_one_way() -> None:
    rank = {room: i for i, room in enumerate(ORDER)}
    back = []
    for mod, deps in sorted(_graph().items()):
        src = _room(mod)
        for dep in sorted(deps):
            dst = _room(dep)
            if src in ENTRY or src == dst:
                continue
            if dst == "exporters":
                if src != "app":
                    back.append(f"{mod} -> {dep} (only planar.app imports exporters)")
                continue
            if src == "exporters":
                if rank.get(dst, len(ORDER)) >= rank["app"]:
                    back.append(f"{mod} -> {dep}")
                continue
            if dst in ENTRY:
                back.append(f"{mod} -> {dep} (the package's face)")
                continue
            if rank[dst] > rank[src]:
                back.append(f"{mod} -> {dep}")
    assert back == []


def test_every_room_is_known() -> None:
    rooms = {_room(m) for m in _modules()} - ENTRY - {"exporters"}
    assert rooms <= set(ORDER), rooms - set(ORDER)


def test_few_top_level_modules() -> None:
    top = [p.stem for p in (ROOT / "planar").glob("*.py") if p.stem not in ENTRY]
    assert len(top) <= 8, top


def test_tests_mirror_the_package() -> None:
    folders = {p.name for p in (ROOT / "tests").iterdir() if p.is_dir() and not p.name.startswith((".", "_"))}
    packages = {p.name for p in (ROOT / "planar").iterdir() if (p / "__init__.py").exists()}
    assert folders <= packages | {"exporters", "docs"}, folders - packages
