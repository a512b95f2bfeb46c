"""Scene files: the schema, loading and building, writing back, the built-in catalogue.

Every name in ``__all__`` is imported from its module on first use (:func:`planar.core.lazy.attach`).
"""

from planar.core.lazy import attach

__getattr__, __dir__, __all__ = attach(
    __name__,
    {
        "Scene": "planar.scene.load",
        "SceneSpec": "planar.scene.load",
        "load_scene": "planar.scene.load",
        "parse_scene": "planar.scene.load",
        "build_scene": "planar.scene.load",
        "scene_from_mechanism": "planar.scene.load",
        "scene_schema": "planar.scene.load",
        "scene_toml": "planar.scene.write",
        "write_scene": "planar.scene.write",
        "CATALOG": "planar.scene.catalog",
    },
)
