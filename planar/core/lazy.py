"""A package's public names, declared once and imported on first use (as scikit-image's ``lazy_loader``).

A subpackage ``__init__`` names what it exports and the module that defines
each name; nothing is imported until a name is read, so ``import planar.x``
stays light whatever ``x`` holds::

    __getattr__, __dir__, __all__ = attach(__name__, {"Scene": "planar.scene.load"})
"""

from __future__ import annotations

import importlib
import sys
from collections.abc import Callable
from typing import Any

__all__ = ["attach"]


def attach(package: str, names: dict[str, str]) -> tuple[Callable[[str], Any], Callable[[], list[str]], list[str]]:
    """The ``__getattr__``, ``__dir__`` and ``__all__`` of ``package`` exporting ``names`` lazily.

    Parameters
    ----------
    package : str
        The package's ``__name__``.
    names : dict
        Exported name -> the module (absolute) that defines it.

    Returns
    -------
    (__getattr__, __dir__, __all__)
        ``__getattr__`` imports the defining module on first read and caches the
        value in the package; an unknown name raises :class:`AttributeError`.
    """

    def __getattr__(name: str) -> Any:
        module = names.get(name)
        if module is None:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        value = getattr(importlib.import_module(module), name)
        setattr(sys.modules[package], name, value)
        return value

    def __dir__() -> list[str]:
        return sorted(set(vars(sys.modules[package])) | set(names))

    return __getattr__, __dir__, sorted(names)
