"""Rich display in notebooks: a registry of HTML renderers by kind, filled by the drawing side.

The model (:mod:`planar.core.model`) must not import the drawing code (core comes before
draw), yet a ``Mechanism`` evaluated in Jupyter should show a table and an animation.
So the model's ``_repr_html_`` asks this registry for the renderer of its kind
(``"mechanism"``, ``"motion"``, ``"scene"``, ``"comparison"``, ``"toy-report"``), and
:mod:`planar.draw.notebook` registers them when it is imported: ``import planar``
imports it when IPython is loaded (every notebook kernel), which any import of a
planar module does first.

In plain Python (no IPython) nothing is registered at ``import planar``; the package
face registers a *loader* here instead (:func:`set_loader`, a callable that imports
:mod:`planar.draw.notebook`), and :func:`renderer` calls it once when the registry
has no renderer of the kind asked for.  So ``motion.animate()`` and ``_repr_html_``
work after a bare ``import planar`` while core still never imports draw.  Without a
renderer even then, ``_repr_html_`` returns None and the front end shows the compact
``repr``.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

__all__ = ["RENDERERS", "html", "register", "renderer", "set_loader"]

#: kind -> function(obj) -> HTML
RENDERERS: dict[str, Callable[..., Any]] = {}

#: called once, when a kind has no renderer, to import the drawing side (set by ``planar/__init__.py``)
_LOADER: list[Callable[[], Any]] = []


def register(kind: str, renderer: Callable[..., Any]) -> None:
    """Register ``renderer`` as the HTML of objects of ``kind`` (a second registration replaces the first)."""
    RENDERERS[kind] = renderer


def set_loader(loader: Callable[[], Any]) -> None:
    """Set the callable that fills the registry on first need (it imports the drawing side)."""
    _LOADER[:] = [loader]


def renderer(kind: str) -> Callable[..., Any] | None:
    """The renderer of ``kind``; the loader runs first (once) if the kind is missing; None if still none."""
    if kind not in RENDERERS and _LOADER:
        _LOADER.pop()()
    return RENDERERS.get(kind)


def html(kind: str, obj: Any) -> str | None:
    """The HTML of ``obj`` by the renderer of ``kind``; None if there is none (the front end then uses repr)."""
    fn = renderer(kind)
    return None if fn is None else fn(obj)
