"""The docs: the README stays short and its Python example runs on the public names; every tutorial runs.

The tutorials' ``python`` blocks run in order, in one namespace, in a fresh
folder holding the repository's ``gallery/`` (as a reader would, from the
repository's folder).  The student's page is quick and runs by default; the
others render, cut and simulate, and run with ``--runslow``.
"""

from __future__ import annotations

import ast
import importlib.util
import re
from pathlib import Path

import pytest

import planar

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
README = ROOT / "README.md"
TUTORIALS = sorted(p for p in (DOCS / "tutorials").glob("*.md") if p.stem != "index")
FAST_TUTORIALS = {"student"}  # under half a second of CPU; the rest are marked slow


def python_blocks(path: Path) -> list[str]:
    """The ```python blocks of a Markdown page, in order."""
    return re.findall(r"^```python\n(.*?)^```", path.read_text(encoding="utf-8"), re.S | re.M)


def _run_blocks(path: Path, where: Path, monkeypatch: pytest.MonkeyPatch) -> dict[str, object]:
    (where / "gallery").symlink_to(ROOT / "gallery", target_is_directory=True)
    monkeypatch.chdir(where)
    monkeypatch.setenv("MPLBACKEND", "Agg")
    namespace: dict[str, object] = {"__name__": "__docs__"}
    blocks = python_blocks(path)
    assert blocks, f"{path.name} has no python block"
    for i, code in enumerate(blocks):
        exec(compile(code, f"{path.name}[block {i}]", "exec"), namespace)
    return namespace


def test_readme_is_at_most_250_lines() -> None:
    n = len(README.read_text(encoding="utf-8").splitlines())
    assert n <= 250, n


def test_readme_python_example_uses_only_top_level_names() -> None:
    blocks = python_blocks(README)
    assert len(blocks) == 1
    tree = ast.parse(blocks[0])
    imports = [n for n in ast.walk(tree) if isinstance(n, ast.Import | ast.ImportFrom)]
    assert [(type(n).__name__, [a.name for a in n.names]) for n in imports] == [("Import", ["planar"])]
    used = {n.attr for n in ast.walk(tree) if isinstance(n, ast.Attribute) and getattr(n.value, "id", None) == "planar"}
    assert used and used <= set(planar.__all__), used - set(planar.__all__)
    assert len(blocks[0].strip().splitlines()) <= 12


@pytest.mark.slow
def test_readme_python_example_runs(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    _run_blocks(README, tmp_path, monkeypatch)
    assert (tmp_path / "leg.gif").read_bytes()[:6] == b"GIF89a"
    assert (tmp_path / "leg.dxf").stat().st_size > 0 and (tmp_path / "leg.svg").stat().st_size > 0


def test_readme_test_counts_name_both_sets() -> None:
    text = README.read_text(encoding="utf-8")
    assert re.search(r"\d[\d,]* tests", text) and "s of CPU" in text
    assert "TESTS_" not in text


@pytest.mark.parametrize(
    "page",
    [pytest.param(p, id=p.stem, marks=() if p.stem in FAST_TUTORIALS else pytest.mark.slow) for p in TUTORIALS],
)
def test_tutorial_runs(page: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    _run_blocks(page, tmp_path, monkeypatch)


def test_there_is_a_tutorial_per_audience() -> None:
    assert {p.stem for p in TUTORIALS} >= {"maker", "student", "researcher"}


def test_every_page_starts_with_a_title_and_the_indexes_glob() -> None:
    generated = {DOCS / "_build", DOCS / "reference" / "api", DOCS / "gallery" / "scenes"}
    pages = [p for p in DOCS.rglob("*.md") if not any(g in p.parents for g in generated)]
    assert len(pages) >= 20
    untitled = [str(p.relative_to(DOCS)) for p in pages if not p.read_text(encoding="utf-8").startswith("# ")]
    assert untitled == []
    for folder in ("how-to", "explanation", "tutorials"):
        index = (DOCS / folder / "index.md").read_text(encoding="utf-8")
        assert ":glob:" in index and "\n*\n" in index, folder


def test_the_gallery_extension_writes_a_page_per_scene(tmp_path: Path) -> None:
    spec = importlib.util.spec_from_file_location("planar_gallery", DOCS / "_ext" / "planar_gallery.py")
    assert spec and spec.loader
    ext = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(ext)
    scenes = sorted((ROOT / "gallery").glob("*.toml"))
    (tmp_path / "stale.md").write_text("# gone\n")
    pages = ext.write_pages(ROOT / "gallery", tmp_path)
    assert [p.stem for p in pages] == [s.stem for s in scenes] and not (tmp_path / "stale.md").exists()
    horse = (tmp_path / "horse.md").read_text(encoding="utf-8")
    assert horse.startswith("# horse") and "horse.gif)" in horse and "planar render gallery/horse.toml" in horse


@pytest.mark.slow
def test_the_python_how_to_runs(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """docs/how-to/python.md's blocks in order, synthesis included: an SVG drawn, a four-bar found, made a
    scene with its targets and unit, and cut (at the unit the build check names, when it fails)."""
    import tomllib

    ns = _run_blocks(DOCS / "how-to" / "python.md", tmp_path, monkeypatch)
    assert ns["fab"].violations == []  # type: ignore[attr-defined]
    assert (tmp_path / "bean.dxf").stat().st_size > 0 and (tmp_path / "bean-bom.csv").exists()
    saved = tomllib.loads((tmp_path / "bean.toml").read_text(encoding="utf-8"))
    assert saved["fabrication"]["unit_mm"] == 1.0 and len(saved["render"]["targets"]) == 25
