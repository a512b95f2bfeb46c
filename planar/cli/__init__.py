"""The ``planar`` command: one module per command, one ``COMMANDS`` table.

Every name in ``__all__`` is imported from its module on first use (:func:`planar.core.lazy.attach`).
"""

from planar.core.lazy import attach

__getattr__, __dir__, __all__ = attach(
    __name__,
    {
        "COMMANDS": "planar.cli.main",
        "build_parser": "planar.cli.main",
    },
)
