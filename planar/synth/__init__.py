"""Synthesis: from a path, a function or a set of poses to a four-bar (issue 15).

* :mod:`.path` — path generation, timed or not, by global search over the
  vectorised kernel (:mod:`.kernel`, :mod:`.search`) and local refinement;
* :mod:`.function` — function generation by Freudenstein's equation, and
  :mod:`.function_search` — a search for a valid four-bar on one circuit when it is none;
* :mod:`.motion` — motion generation by Burmester theory (3, 4, 5 poses);
* :mod:`.scene_out` — the result as a scene file.
"""
