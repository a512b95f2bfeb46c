"""Synthesis: from a path, a function or a set of poses to a four-bar (issue 15).

* :mod:`.path` — path generation, timed or not, by global search over the
  vectorised kernel (:mod:`.kernel`, :mod:`.search`) and local refinement;
* :mod:`.function` — function generation by Freudenstein's equation, and
  :mod:`.function_search` — a search for a valid four-bar on one circuit when it is none;
* :mod:`.motion` — motion generation by Burmester theory (3, 4, 5 poses);
* :mod:`.scene_out` — the result as a scene file;
* :mod:`.targets` — the targets read from a file (:func:`read_targets`: an SVG drawing or a CSV table).

Every name in ``__all__`` is imported from its module on first use (:func:`planar.core.lazy.attach`).
"""

from planar.core.lazy import attach

__getattr__, __dir__, __all__ = attach(
    __name__,
    {
        "FourBarDesign": "planar.synth.path",
        "synthesise_path": "planar.synth.path",
        "SixBarDesign": "planar.synth.sixbar",
        "synthesise_sixbar": "planar.synth.sixbar",
        "FunctionDesign": "planar.synth.function",
        "synthesise_function": "planar.synth.function",
        "search_function": "planar.synth.function_search",
        "MotionDesign": "planar.synth.motion",
        "burmester": "planar.synth.motion",
        "Design": "planar.synth.design",
        "design_toy": "planar.synth.design",
        "load_request": "planar.synth.design",
        "read_targets": "planar.synth.targets",
    },
)
