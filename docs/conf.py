"""Sphinx configuration of planar's documentation (Markdown pages through myst-parser)."""

from __future__ import annotations

import sys
import types
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))  # the planar being documented: this checkout
sys.path.insert(0, str(HERE / "_ext"))

# ``planar/__main__.py`` runs the command line when imported; the reference walks every module,
# so that one is stood in for by an empty module marked as a mock (autosummary skips mocks)
_main = types.ModuleType("planar.__main__")
_main.__sphinx_mock__ = True  # type: ignore[attr-defined]
sys.modules["planar.__main__"] = _main

project = "planar"
author = "planar developers"
copyright = "planar developers"  # noqa: A001 (Sphinx's name)
release = version = "0.1.0"

extensions = [
    "myst_parser",
    "numpydoc",
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.intersphinx",
    "sphinx.ext.mathjax",
    "planar_gallery",
]
source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
root_doc = "index"
exclude_patterns = ["_build", "README.md"]
myst_enable_extensions = ["colon_fence", "deflist", "dollarmath"]
myst_heading_anchors = 3

html_theme = "furo"
html_title = "planar"

# the API reference: generated at build time from the docstrings (reference/api/ is not committed)
autosummary_generate = True
autosummary_imported_members = False
templates_path = ["_templates"]  # autosummary/module.rst: the module's own members, then its modules
# a module documents what it defines (not what its __all__ re-exports from elsewhere: one page per object)
autodoc_default_options = {"members": True, "show-inheritance": True, "ignore-module-all": True}
autodoc_typehints = "none"  # numpydoc's Parameters sections say the types
numpydoc_show_class_members = False
numpydoc_validation_checks: set[str] = set()
numpydoc_xref_param_type = False
# docstrings name classes by their short names and refer to private helpers; an unresolved
# cross-reference is not an error in a docstring (a broken page link or toctree still is)
nitpicky = False
intersphinx_mapping: dict[str, tuple[str, None]] = {}
suppress_warnings = ["ref.python"]  # "more than one target for cross-reference" between re-exports

# the gallery (planar_gallery): a page per scene of ../gallery, generated at build time
planar_gallery_source = str(HERE.parent / "gallery")
planar_gallery_pages = str(HERE / "gallery" / "scenes")


def _skip_type_aliases(app: object, what: str, name: str, obj: object, skip: bool, options: object) -> bool | None:
    """Leave out what autodoc cannot sign: type aliases (``Placed = tuple[...]``) and imported builtins (``Lock``)."""
    if what == "module" and (
        type(obj).__name__ in ("GenericAlias", "UnionType", "_GenericAlias", "_UnionGenericAlias")
        or type(obj).__name__ == "builtin_function_or_method"
    ):
        return True
    return None


def setup(app: object) -> None:
    app.connect("autodoc-skip-member", _skip_type_aliases)  # type: ignore[attr-defined]
