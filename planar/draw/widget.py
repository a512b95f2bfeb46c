"""Live editing in a notebook: a slider per dimension, the coupler curve redrawn as you drag (``planar[notebook]``).

:class:`Editor` is the state (pure Python, testable without a browser): a scene's
dimensions, and for their current values the curve of a named point over one driver
cycle, which samples cannot be assembled (dead zones, drawn grey) and where the input
toggles (marked).  :func:`editor` wraps it in an `anywidget <https://anywidget.dev>`_
widget (Jupyter, JupyterLab, VS Code, Colab, marimo): moving a slider sets the
widget's ``dims`` trait, the Python side recomputes and sends back ``curve``,
``valid`` and ``toggles``.  ``save(path)`` writes the edited scene as TOML
(:func:`planar.scene.write.write_scene`).  anywidget is the optional extra
``planar[notebook]``: a well-kept library that runs in every notebook front end,
so planar ships no front-end build of its own.
"""

from __future__ import annotations

import copy
import math
from typing import Any

from planar.errors import InputError, PlanarError

__all__ = ["Editor", "editor"]

#: the keys of a linkage node that are dimensions (lengths)
NODE_DIMENSIONS = ("radius", "ra", "rb")


class Editor:
    """A scene's dimensions and what they give: the curve of ``point``, its valid samples, the toggle points.

    Parameters
    ----------
    scene
        A loaded scene (:func:`planar.scene.load.load_scene`).
    point
        The named point whose curve is drawn (default: the mechanism's first named point).
    samples
        Samples of one driver cycle.
    """

    def __init__(self, scene: Any, point: str | None = None, samples: int = 180) -> None:
        self.path = scene.path
        self.data: dict[str, Any] = scene.spec.model_dump(mode="json", exclude_unset=True)
        self.samples = samples
        first = point or next(iter(scene.mechanism.points), None)
        if first is None:
            raise InputError("point", None, f"a named point of {scene.mechanism.name} (it has none)")
        self.point: str = first
        self.dims = self._dimensions()
        self.ranges = {k: (v / 4.0, v * 2.5) if v > 0 else (v - 1.0, v + 1.0) for k, v in self.dims.items()}
        self.error = ""
        self.scene = scene
        self.curve: list[list[float]] = []
        self.valid: list[bool] = []
        self.toggles: list[list[float]] = []
        self.recompute()
        if self.error:
            raise InputError(f"{self.path}: mechanism", "the scene as given", f"a scene that builds ({self.error})")

    def _dimensions(self) -> dict[str, float]:
        m = self.data["mechanism"]
        dims: dict[str, float] = {}
        for k, v in m.items():
            if isinstance(v, float | int) and not isinstance(v, bool) and k not in ("phase", "branch"):
                dims[k] = float(v)
        for node in m.get("nodes", []):
            for k in NODE_DIMENSIONS:
                if isinstance(node.get(k), float | int):
                    dims[f"{node['name']}.{k}"] = float(node[k])
        return dims

    def _apply(self, dims: dict[str, float]) -> dict[str, Any]:
        data = copy.deepcopy(self.data)
        m = data["mechanism"]
        nodes = {n.get("name"): n for n in m.get("nodes", [])}
        for key, v in dims.items():
            if key not in self.dims:
                raise InputError("dims", key, f"one of {sorted(self.dims)}")
            if not math.isfinite(v):
                raise InputError(f"dims.{key}", v, "a finite number")
            name, _, field = key.rpartition(".")
            if name:
                nodes[name][field] = float(v)
            else:
                m[key] = float(v)
        return data

    def set(self, **dims: float) -> None:
        """Set dimensions (``crank=1.2``; a linkage node's as ``{"B.ra": 50.0}`` through ``set(**{...})``) and recompute.

        Values that cannot be built keep the last good curve and set :attr:`error` to the reason.
        """
        self.dims = {**self.dims, **{k: float(v) for k, v in dims.items()}}
        self.recompute()

    def recompute(self) -> None:
        """Rebuild the scene from :attr:`dims` and compute the curve, validity and toggles."""
        import numpy as np

        from planar.scene.load import build_scene, parse_scene

        try:
            data = self._apply(self.dims)
            scene = build_scene(parse_scene(data, str(self.path)), str(self.path))
            mech = scene.mechanism
            d = mech.driver
            q = d.phase + np.arange(self.samples) * (2 * math.pi / self.samples)
            motion = mech.solve(q)
        except PlanarError as e:
            self.error = str(e)
            return
        self.error = ""
        self.scene = scene
        self.curve = np.asarray(motion.points[self.point]).round(9).tolist()
        self.valid = [bool(v) for v in motion.valid]
        toggles = np.asarray(getattr(mech, "toggle_angles", lambda: np.array([]))(), float)
        self.toggles = np.asarray(mech.solve(toggles).points[self.point]).round(9).tolist() if toggles.size else []

    def save(self, path: Any) -> None:
        """Write the edited scene to ``path`` as TOML (what is saved is what was last built)."""
        from planar.scene.write import write_scene

        write_scene(self.scene.spec, path)


_ESM = """
function render({ model, el }) {
  const NS = "http://www.w3.org/2000/svg";
  const box = document.createElement("div");
  const sliders = document.createElement("div");
  const svg = document.createElementNS(NS, "svg");
  svg.setAttribute("width", "360"); svg.setAttribute("height", "270");
  svg.style.background = "#fff";
  const err = document.createElement("div");
  err.style.color = "#d62728";
  const dims = model.get("dims"), ranges = model.get("ranges");
  Object.keys(dims).forEach(function (k) {
    const row = document.createElement("label");
    row.style.display = "block";
    const input = document.createElement("input");
    input.type = "range"; input.min = ranges[k][0]; input.max = ranges[k][1];
    input.step = (ranges[k][1] - ranges[k][0]) / 500; input.value = dims[k];
    const out = document.createElement("span");
    out.textContent = " " + k + " = " + Number(dims[k]).toPrecision(4);
    input.addEventListener("input", function () {
      const d = Object.assign({}, model.get("dims"));
      d[k] = parseFloat(input.value);
      out.textContent = " " + k + " = " + d[k].toPrecision(4);
      model.set("dims", d); model.save_changes();
    });
    row.appendChild(input); row.appendChild(out); sliders.appendChild(row);
  });
  function draw() {
    const c = model.get("curve"), ok = model.get("valid"), tg = model.get("toggles");
    while (svg.firstChild) svg.removeChild(svg.firstChild);
    const xs = c.map(p => p[0]), ys = c.map(p => p[1]);
    const x0 = Math.min(...xs), x1 = Math.max(...xs), y0 = Math.min(...ys), y1 = Math.max(...ys);
    const s = Math.min(340 / Math.max(x1 - x0, 1e-9), 250 / Math.max(y1 - y0, 1e-9));
    const X = x => 10 + (x - x0) * s, Y = y => 260 - (y - y0) * s;
    for (let i = 0; i < c.length; i++) {
      const j = (i + 1) % c.length;
      const l = document.createElementNS(NS, "line");
      l.setAttribute("x1", X(c[i][0])); l.setAttribute("y1", Y(c[i][1]));
      l.setAttribute("x2", X(c[j][0])); l.setAttribute("y2", Y(c[j][1]));
      l.setAttribute("stroke", ok[i] && ok[j] ? "#7f3fbf" : "#c8c8c8");
      l.setAttribute("stroke-width", "2");
      svg.appendChild(l);
    }
    tg.forEach(function (p) {
      const m = document.createElementNS(NS, "circle");
      m.setAttribute("cx", X(p[0])); m.setAttribute("cy", Y(p[1])); m.setAttribute("r", "4");
      m.setAttribute("fill", "#d62728");
      svg.appendChild(m);
    });
    err.textContent = model.get("error");
  }
  model.on("change:curve", draw); model.on("change:error", draw);
  draw();
  box.appendChild(sliders); box.appendChild(svg); box.appendChild(err);
  el.appendChild(box);
}
export default { render };
"""


def editor(scene: Any, point: str | None = None, samples: int = 180) -> Any:
    """A live editor of ``scene`` (an anywidget widget; needs ``pip install 'planar[notebook]'``).

    The widget's traits: ``dims`` (name -> value, set by the sliders), ``ranges``, ``curve``
    (``[[x, y], ...]`` of ``point`` over one cycle), ``valid`` (per sample), ``toggles`` (the
    point at the input's toggle angles) and ``error``; ``widget.editor`` is the :class:`Editor`,
    ``widget.save(path)`` writes the edited scene as TOML.
    """
    try:
        import anywidget
        import traitlets
    except ImportError:
        raise InputError("editor", "anywidget", "the notebook extra: pip install 'planar[notebook]'") from None

    state = Editor(scene, point, samples)

    class _Widget(anywidget.AnyWidget):
        _esm = _ESM
        dims = traitlets.Dict().tag(sync=True)
        ranges = traitlets.Dict().tag(sync=True)
        curve: Any = traitlets.List().tag(sync=True)
        valid: Any = traitlets.List().tag(sync=True)
        toggles: Any = traitlets.List().tag(sync=True)
        error = traitlets.Unicode("").tag(sync=True)

        def __init__(self) -> None:
            super().__init__()
            self.editor = state
            self.ranges = {k: list(v) for k, v in state.ranges.items()}
            self._push()
            self.dims = dict(state.dims)
            self.observe(self._on_dims, names="dims")

        def _push(self) -> None:
            self.curve, self.valid, self.toggles, self.error = state.curve, state.valid, state.toggles, state.error

        def _on_dims(self, change: dict[str, Any]) -> None:
            state.set(**change["new"])
            self._push()

        def save(self, path: Any) -> None:
            state.save(path)

    return _Widget()
