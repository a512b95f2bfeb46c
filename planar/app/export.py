"""``planar export``: every file of a :class:`~planar.fabrication.build.Fabrication` written at once.

:func:`build` turns a scene into a :class:`Fabrication` (layout, assembly,
notes); :func:`write_outputs` renders every requested file in memory and only
then writes them (each to a temporary beside its target, all renamed at the
end), so bad input or a failed check leaves no file written or clobbered.
With several sheets, ``parts.dxf`` becomes ``parts-1.dxf``, ``parts-2.dxf``
(same for SVG and the preview PNG).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from planar.errors import InputError
from planar.fabrication.build import Fabrication, build, kerf_test_layout, sheet_paths, summary
from planar.fabrication.parts import FabSettings

__all__ = [
    "Fabrication",
    "build",
    "check_lines",
    "kerf_test_layout",
    "scene_with_unit",
    "sheet_paths",
    "summary",
    "write_outputs",
]


def scene_with_unit(scene: Any, unit_mm: float | None, where: str, sheet: tuple[float, float] | None = None) -> Any:
    """``scene`` with its ``[fabrication] unit_mm`` replaced by ``unit_mm`` (mm per model unit; ``None``: as it is).

    Checked like the scene's field, and named ``where`` (``--unit-mm`` on the command line, ``unit_mm`` from
    Python): a positive, finite number whose largest part is at least ``min_part_mm`` across and fits the
    sheet's diagonal (``sheet`` in mm, the scene's when ``None``), the bounds ``planar export`` puts on the
    scene's own ``unit_mm``.
    """
    import math

    from planar.core.fields import check_number
    from planar.core.limits import MAX_SHEET_MM
    from planar.fabrication.scale import scene_at_unit

    if unit_mm is None:
        return scene
    u = check_number(where, unit_mm)
    if not (math.isfinite(u) and u > 0):
        raise InputError(where, unit_mm, "a positive, finite number of millimetres per model unit")
    spec = scene.spec.fabrication
    w, h = sheet if sheet is not None else spec.sheet_mm
    across = scene.mechanism.size * u  # the largest part's diameter, mm
    if not (math.isfinite(w) and math.isfinite(h) and min(w, h) > 0 and max(w, h) <= MAX_SHEET_MM):
        return scene_at_unit(scene, u)  # the sheet itself is refused by the export, naming it
    if not across <= math.hypot(w, h):
        raise InputError(
            where,
            unit_mm,
            f"parts that fit the {w:g} x {h:g} mm sheet (the largest part would be {across:.4g} mm across; "
            f"at most {math.hypot(w, h) / scene.mechanism.size:.4g} on this sheet)",
        )
    if not across >= spec.min_part_mm:
        raise InputError(
            where,
            unit_mm,
            f"a unit whose largest part is at least min_part_mm = {spec.min_part_mm:g} mm across (it would be "
            f"{across:.4g} mm; at least {spec.min_part_mm / scene.mechanism.size:.4g})",
        )
    return scene_at_unit(scene, u)


def check_lines(scene: Any, fab: Fabrication, hint: bool = True, option: str = "--unit-mm ") -> list[str]:
    """What the build check found, one line each (empty: it builds), and, when it failed and ``hint``, what would
    make it build: the smallest ``unit_mm`` found at which the same scene builds
    (:func:`planar.fabrication.scale.unit_hint`; ``option`` names how to ask for it), or that none up to the
    sheet's size does, or why it was not searched (kept as ``fab.unit_hint``).  The hint is the last line."""
    from planar.fabrication.scale import unit_hint

    lines = [v.text() for v in fab.violations]
    if lines and hint:
        fab.unit_hint = unit_hint(scene, fab)
        lines.append(fab.unit_hint.text(option))
    return lines


def _commit(files: dict[Path, bytes]) -> None:
    """Write every file to a temporary beside it, then rename them all; on any failure remove the temporaries.

    Inside a command's :func:`planar.fileio.output_transaction` the renames wait for the whole command.
    """
    from planar.fileio import atomic_write, output_transaction

    for target in files:
        parent = target.parent if str(target.parent) else Path(".")
        if not parent.is_dir():
            raise InputError("output", str(target), f"a path in an existing directory ({parent} does not exist)")
    with output_transaction():
        for target, data in files.items():
            with atomic_write(target, "wb") as fh:
                fh.write(data)


def _motion_csv(fab: Fabrication, samples: int = 240) -> bytes:
    """The motion table (CSV) of the mechanism as cut: the parts of ``plan.json`` (a toy's merged pieces), one
    cycle of ``samples`` samples, 17 significant digits."""
    import csv
    import io

    import numpy as np

    from planar.fileio import motion_columns

    mech = fab.mechanism
    names, table = motion_columns(mech, mech.run(samples_per_cycle=samples))
    buf = io.StringIO()
    csv.writer(buf, lineterminator="\n").writerow(names)
    np.savetxt(buf, table, fmt=",".join(["%.17g"] * (len(names) - 1) + ["%d"]))
    return buf.getvalue().encode()


def write_outputs(
    fab: Fabrication | None,
    dxf=None,
    svg=None,
    preview=None,
    bom=None,
    assembly=None,
    kerf_test=None,
    settings: FabSettings | None = None,
    plan=None,
    motion=None,
    steps=None,
) -> list[Path]:
    """Render every requested output in memory, then write them all (see the module docstring)."""
    from planar.app.formats import writer

    dxf_bytes = writer("dxf").dxf_bytes
    svg_text = writer("svg").svg_text

    files: dict[Path, bytes] = {}
    if fab is not None:
        lay, s = fab.layout, fab.settings
        meta = f"{fab.name}: {s.thickness_mm:g} mm sheet, kerf {s.kerf:g} mm"
        if dxf is not None:
            for k, p in enumerate(sheet_paths(dxf, lay.sheets)):
                files[p] = dxf_bytes(lay, k, s, f"{meta}, sheet {k + 1} of {lay.sheets}")
        if svg is not None:
            for k, p in enumerate(sheet_paths(svg, lay.sheets)):
                files[p] = svg_text(lay, k, s).encode()
        if preview is not None:
            sheet_png = writer("png").sheet_png

            for k, p in enumerate(sheet_paths(preview, lay.sheets)):
                files[p] = sheet_png(lay, k, s)
        if bom is not None:
            bom_text = writer("bom").bom_text

            files[Path(bom)] = bom_text(fab).encode()
        if assembly is not None:
            assembly_svg_text = writer("svg").assembly_svg_text

            files[Path(assembly)] = assembly_svg_text(fab).encode()
        if plan is not None:
            files[Path(plan)] = writer("json").plan_json(fab).encode()
        if motion is not None:
            files[Path(motion)] = _motion_csv(fab)
        if steps is not None:
            pages = writer("svg").assembly_steps_svg(fab)
            for k, p in enumerate(sheet_paths(steps, len(pages))):
                files[p] = pages[k].encode()
    if kerf_test is not None:
        s = settings or (fab.settings if fab is not None else FabSettings())
        lay = kerf_test_layout(s)
        p = Path(kerf_test)
        if p.suffix.lower() == ".svg":
            files[p] = svg_text(lay, 0, s).encode()
        elif p.suffix.lower() == ".dxf":
            files[p] = dxf_bytes(lay, 0, s, f"kerf test, kerf {s.kerf:g} mm")
        else:
            raise InputError("--kerf-test", str(p), "a .dxf or .svg file name")
    if len({str(p.resolve()) for p in files}) != len(files):
        raise InputError("output", ", ".join(map(str, files)), "distinct output files")
    _commit(files)
    return list(files)
