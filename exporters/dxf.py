"""DXF R2010 in millimetres for laser cutters: true arcs, closed contours, layers per operation.

Layers: ``CUT_INNER`` (blue, holes and slots: cut first), ``CUT_OUTER`` (red,
part outlines), ``ENGRAVE`` (green, part names), ``SHEET`` (grey, the sheet's
edge, for reference only: do not cut).  Contours are closed LWPOLYLINEs with
bulges (arcs as arcs), round holes are CIRCLEs.  Each part's entities form a
DXF group named after the part.  ``$INSUNITS`` = 4 (mm), ``$MEASUREMENT`` = 1.

Reproducible byte for byte: ezdxf's fixed metadata (no timestamps, constant
GUIDs) and a deterministic entity order.
"""

from __future__ import annotations

import contextlib
import io
import os
from typing import Iterator

from planar.fabrication import Circle, Contour, Layout
from planar.fileio import atomic_write

__all__ = ["write_dxf", "LAYERS", "preview_png"]

#: layer -> ACI colour
LAYERS = {"CUT_INNER": 5, "CUT_OUTER": 1, "ENGRAVE": 3, "SHEET": 8}


@contextlib.contextmanager
def _fixed_metadata() -> Iterator[None]:
    import ezdxf

    old = ezdxf.options.write_fixed_meta_data_for_testing
    ezdxf.options.write_fixed_meta_data_for_testing = True
    try:
        yield
    finally:
        ezdxf.options.write_fixed_meta_data_for_testing = old


def build_document(layout: Layout):
    """The ezdxf document for a layout."""
    import ezdxf

    doc = ezdxf.new("R2010", setup=False)
    doc.header["$INSUNITS"] = 4
    doc.header["$MEASUREMENT"] = 1
    doc.header["$LUNITS"] = 2
    for name, colour in LAYERS.items():
        doc.layers.add(name, color=colour)
    msp = doc.modelspace()
    W, H = layout.sheet_size
    for k in range(layout.sheets):
        x0, y0 = layout.sheet_origin(k)
        msp.add_lwpolyline([(x0, y0), (x0 + W, y0), (x0 + W, y0 + H), (x0, y0 + H)], close=True,
                           dxfattribs={"layer": "SHEET"})

    def add(cut, layer: str):
        if isinstance(cut, Circle):
            return msp.add_circle(cut.centre, cut.radius, dxfattribs={"layer": layer})
        return msp.add_lwpolyline([(x, y, 0.0, 0.0, b) for x, y, b in cut.vertices], format="xyseb", close=True,
                                  dxfattribs={"layer": layer})

    for part in layout.parts:
        ents = [add(c, "CUT_INNER") for c in part.inner]
        ents.append(add(part.outer, "CUT_OUTER"))
        text = msp.add_text(part.name, height=part.label_height, dxfattribs={"layer": "ENGRAVE"})
        text.set_placement(part.label_at, align=ezdxf.enums.TextEntityAlignment.MIDDLE_CENTER)
        ents.append(text)
        group = doc.groups.new(part.name.replace(" ", "_"))
        group.extend(ents)
    return doc


def _register_classes_in_order(doc) -> None:
    """Register the CLASSES of the entity types in use in sorted order.

    ezdxf adds them at write time by iterating a ``set`` of type names, so
    their order (and the file's bytes) would follow ``PYTHONHASHSEED``;
    classes already registered keep their place.
    """
    for name in sorted(doc.entitydb.dxf_types_in_use()):
        doc.classes.add_class(name)


def write_dxf(path: str | os.PathLike, layout: Layout) -> None:
    """Write the layout as DXF (atomically)."""
    with _fixed_metadata():
        doc = build_document(layout)
        _register_classes_in_order(doc)
        buf = io.StringIO()
        doc.write(buf)
    with atomic_write(path, "w") as fh:
        fh.write(buf.getvalue())


def preview_png(dxf_path: str | os.PathLike, png_path: str | os.PathLike, dpi: int = 100) -> None:
    """Render a DXF to PNG with ezdxf's drawing add-on (matplotlib backend), for a look before cutting."""
    import ezdxf
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from ezdxf.addons.drawing import Frontend, RenderContext
    from ezdxf.addons.drawing.matplotlib import MatplotlibBackend

    doc = ezdxf.readfile(dxf_path)
    fig = plt.figure(dpi=dpi)
    ax = fig.add_axes((0, 0, 1, 1))
    Frontend(RenderContext(doc), MatplotlibBackend(ax)).draw_layout(doc.modelspace(), finalize=True)
    with atomic_write(png_path, "wb") as fh:
        fig.savefig(fh, format="png", dpi=dpi, metadata={"Software": None})
    plt.close(fig)
