"""Rich display in notebooks: a registry of HTML renderers by kind, filled by the drawing side.

The model (:mod:`planar.core.model`) must not import the drawing code (core comes before
draw), yet a ``Mechanism`` evaluated in Jupyter should show a table and an animation.
So the model's ``_repr_html_`` asks this registry for the renderer of its kind
(``"mechanism"``, ``"motion"``, ``"scene"``, ``"comparison"``, ``"toy-report"``), and
:mod:`planar.draw.notebook` registers them when it is imported: ``import planar``
imports it when IPython is loaded (every notebook kernel), which any import of a
planar module does first.  Without a renderer, ``_repr_html_`` returns None and the
front end shows the compact ``repr``.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

__all__ = ["RENDERERS", "html", "register"]

#: kind -> function(obj) -> HTML
RENDERERS: dict[str, Callable[..., Any]] = {}


def register(kind: str, renderer: Callable[..., Any]) -> None:
    """Register ``renderer`` as the HTML of objects of ``kind`` (a second registration replaces the first)."""
    RENDERERS[kind] = renderer


def html(kind: str, obj: Any) -> str | None:
    """The HTML of ``obj`` by the renderer of ``kind``; None if there is none (the front end then uses repr)."""
    fn = RENDERERS.get(kind)
    return None if fn is None else fn(obj)
