"""``python -m planar``: the same entrance as the ``planar`` console script."""

from planar.cli.entry import run

run()
