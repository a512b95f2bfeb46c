"""The pipeline (a scene in, files out) and the registry of output formats: the only importer of ``exporters``.

Every name in ``__all__`` is imported from its module on first use (:func:`planar.core.lazy.attach`).
"""

from planar.core.lazy import attach

__getattr__, __dir__, __all__ = attach(
    __name__,
    {
        "render_scene": "planar.app.pipeline",
        "render_mechanism": "planar.app.pipeline",
        "export_scene": "planar.app.pipeline",
        "export_mechanism": "planar.app.pipeline",
        "compare_scene": "planar.app.pipeline",
        "write_scene_motion": "planar.app.pipeline",
        "write_mechanism_motion": "planar.app.pipeline",
        "plot_mechanism": "planar.app.pipeline",
        "build_gallery": "planar.app.pipeline",
        "run_demo": "planar.app.pipeline",
        "FORMATS": "planar.app.formats",
        "writer": "planar.app.formats",
    },
)
