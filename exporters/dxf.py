"""DXF R2010 in millimetres for laser cutters: true arcs, closed contours, layers per operation.

Layers: ``CUT_INNER`` (holes and slots: cut first) and ``CUT_OUTER`` (part
outlines) in the cut colour (red by default), ``ENGRAVE`` (labels and hole
letters as single-line polylines, not live text) in the engrave colour (blue),
``SHEET`` (grey, not plotted: the sheet's edge, reference only).  The material
and kerf are noted in a custom drawing property (``planar``).  Contours are closed LWPOLYLINEs with bulges (arcs as arcs),
round holes are CIRCLEs.  Each part's entities form a DXF group named after the
part.  ``$INSUNITS`` = 4 (mm), ``$MEASUREMENT`` = 1, ``$EXTMIN``/``$EXTMAX``
the sheet, ``$PSVPSCALE`` = 1 (LibreCAD shows a blank page at its default options when it is 0).
One file per sheet.  Colours follow the ``[fabrication] colours`` preset
(:meth:`planar.fabrication.parts.FabSettings.layer_colours`): ``"boxes"`` gives Boxes.py's black outer cut,
blue inner cut and green engraving.

Reproducible byte for byte in any process: ezdxf's fixed metadata (no
timestamps, constant GUIDs), a deterministic entity order and CLASSES
registered in sorted order.
"""

from __future__ import annotations

import contextlib
import io
import logging
import os
from collections.abc import Iterator
from typing import Any

from planar.fabrication.sheet import Circle, Layout
from planar.fileio import atomic_write, check_name

__all__ = ["LAYERS", "aci", "dxf_bytes", "preview_png", "write_dxf"]


def _no_cache_notes(record: logging.LogRecord) -> bool:
    """Drop ezdxf's notes that its font cache cannot be saved (an unwritable ``$HOME/.cache``): the cache
    only speeds up ezdxf's next start, it changes nothing in our files, and the notes would follow every export."""
    text = str(record.msg)
    return not (text.startswith("Cannot create cache home directory") or text.startswith("Error writing cache file"))


logging.getLogger("ezdxf").addFilter(_no_cache_notes)  # before any import of ezdxf (it builds the cache on import)

#: layer -> default ACI colour
LAYERS = {"CUT_INNER": 1, "CUT_OUTER": 1, "ENGRAVE": 5, "SHEET": 8}

_ACI = {
    1: (255, 0, 0),
    2: (255, 255, 0),
    3: (0, 255, 0),
    4: (0, 255, 255),
    5: (0, 0, 255),
    6: (255, 0, 255),
    7: (255, 255, 255),
    8: (128, 128, 128),
}


def aci(colour: str) -> int:
    """The nearest of AutoCAD's first eight colour indices to ``#rrggbb``."""
    rgb = tuple(int(colour[i : i + 2], 16) for i in (1, 3, 5))
    return min(_ACI, key=lambda k: sum((a - b) ** 2 for a, b in zip(_ACI[k], rgb)))


@contextlib.contextmanager
def _fixed_metadata() -> Iterator[None]:
    import ezdxf

    old = ezdxf.options.write_fixed_meta_data_for_testing
    ezdxf.options.write_fixed_meta_data_for_testing = True
    try:
        yield
    finally:
        ezdxf.options.write_fixed_meta_data_for_testing = old


def build_document(layout: Layout, sheet: int = 0, settings: Any = None, note: str = ""):
    """The ezdxf document for one sheet of a layout."""
    import ezdxf

    cut = getattr(settings, "cut_colour", "#ff0000")
    eng = getattr(settings, "engrave_colour", "#0000ff")
    colours = {"CUT_INNER": cut, "CUT_OUTER": cut, "ENGRAVE": eng}
    if hasattr(settings, "layer_colours"):
        colours = settings.layer_colours()
    colours["SHEET"] = "#808080"
    doc = ezdxf.new("R2010", setup=False)
    doc.header["$INSUNITS"] = 4
    doc.header["$PSVPSCALE"] = 1.0  # LibreCAD draws nothing at its default options when the view scale is 0
    doc.header["$MEASUREMENT"] = 1
    doc.header["$LUNITS"] = 2
    W, H = layout.sheet_size
    msp = doc.modelspace()
    # ezdxf copies the modelspace's extents and limits into the header at write time
    msp.dxf.extmin = (0.0, 0.0, 0.0)
    msp.dxf.extmax = (W, H, 0.0)
    msp.dxf.limmin = (0.0, 0.0)
    msp.dxf.limmax = (W, H)
    doc.header["$EXTMIN"] = (0.0, 0.0, 0.0)  # (ezdxf keeps these when the layout's minimum is the origin)
    doc.header["$EXTMAX"] = (W, H, 0.0)
    for name, hexcol in colours.items():
        layer = doc.layers.add(name, color=aci(hexcol))
        layer.rgb = (int(hexcol[1:3], 16), int(hexcol[3:5], 16), int(hexcol[5:7], 16))
        if name == "SHEET":
            layer.dxf.plot = 0
    msp.add_lwpolyline([(0, 0), (W, 0), (W, H), (0, H)], close=True, dxfattribs={"layer": "SHEET"})
    if note:  # a drawing property, not an entity: nothing for the cutter to import
        doc.header.custom_vars.append("planar", note)

    def add(c, layer: str):
        if isinstance(c, Circle):
            return msp.add_circle(c.centre, c.radius, dxfattribs={"layer": layer})
        return msp.add_lwpolyline(
            [(x, y, 0.0, 0.0, b) for x, y, b in c.vertices], format="xyseb", close=True, dxfattribs={"layer": layer}
        )

    for part in layout.on_sheet(sheet):
        ents = [add(c, "CUT_INNER") for c in part.inner]
        ents.append(add(part.outer, "CUT_OUTER"))
        for stroke in part.engrave:
            ents.append(msp.add_lwpolyline([(float(x), float(y)) for x, y in stroke], dxfattribs={"layer": "ENGRAVE"}))
        group = doc.groups.new(check_name("part name", part.name).replace(" ", "_"))
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


def dxf_bytes(layout: Layout, sheet: int = 0, settings: Any = None, note: str = "") -> bytes:
    """One sheet of the layout as DXF bytes."""
    with _fixed_metadata():
        doc = build_document(layout, sheet, settings, note)
        _register_classes_in_order(doc)
        buf = io.StringIO()
        doc.write(buf)
    return buf.getvalue().encode("utf-8")


def write_dxf(path: str | os.PathLike, layout: Layout, sheet: int = 0, settings: Any = None) -> None:
    """Write one sheet of the layout as DXF (atomically)."""
    data = dxf_bytes(layout, sheet, settings)
    with atomic_write(path, "wb") as fh:
        fh.write(data)


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
