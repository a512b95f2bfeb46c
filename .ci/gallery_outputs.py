"""Every output of every gallery scene, written to a folder, and two such folders compared.

Used to show that a change which should not change outputs (a refactor, a move)
changes none: run ``write`` on the commit before and on the commit after, then
``compare``.  GIF, DXF, SVG, CSV (motion, derivatives, BOM), PNG and the assembly
drawing must be byte-identical; JSON is compared without wall-clock times; logs
without the folder names.

    python .ci/gallery_outputs.py write OUT_DIR [GALLERY_DIR]
    python .ci/gallery_outputs.py compare BEFORE_DIR AFTER_DIR
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

COMMANDS = {
    "render": ["render", "{scene}", "-o", "{out}/{name}.gif"],
    "motion": ["motion", "{scene}", "-o", "{out}/{name}.csv"],
    "motiond": ["motion", "{scene}", "-o", "{out}/{name}.d.csv", "--derivatives"],
    "export": ["export", "{scene}", "-o", "{out}/{name}.dxf", "--svg", "{out}/{name}.svg", "--bom",
               "{out}/{name}.bom.csv", "--assembly", "{out}/{name}.asm.svg", "--preview", "{out}/{name}.preview.png"],
    "plot": ["plot", "{scene}", "-o", "{out}/{name}.plot.svg"],
}
JSON_COMMANDS = {"compare": ["compare", "{scene}", "--json"]}
TIMES = {"wall_time_s"}


def write(out: Path, gallery: Path) -> None:
    out.mkdir(parents=True, exist_ok=True)
    for scene in sorted(gallery.glob("*.toml")):
        name = scene.stem
        log = []
        for cmd, args in COMMANDS.items():
            argv = [a.format(scene=scene, out=out, name=name) for a in args]
            r = subprocess.run([sys.executable, "-m", "planar", *argv], capture_output=True, text=True)
            log.append(f"{cmd} {r.returncode}\n{r.stdout}{r.stderr}")
        for cmd, args in JSON_COMMANDS.items():
            argv = [a.format(scene=scene, out=out, name=name) for a in args]
            r = subprocess.run([sys.executable, "-m", "planar", *argv], capture_output=True, text=True)
            (out / f"{name}.{cmd}.json").write_text(r.stdout)
            log.append(f"{cmd} {r.returncode}\n{r.stderr}")
        (out / f"{name}.log").write_text("\n".join(log).replace(str(out), "OUT"))
        print(name, flush=True)


def _strip(d: object) -> object:
    if isinstance(d, dict):
        return {k: _strip(v) for k, v in d.items() if k not in TIMES}
    if isinstance(d, list):
        return [_strip(x) for x in d]
    return d


def compare(a: Path, b: Path) -> int:
    bad = 0
    names = sorted({p.name for p in a.iterdir()} | {p.name for p in b.iterdir()})
    for n in names:
        pa, pb = a / n, b / n
        if not (pa.exists() and pb.exists()):
            print(f"only in one: {n}")
            bad += 1
            continue
        if n.endswith(".json"):
            ta, tb = pa.read_text(), pb.read_text()
            same = ta == tb
            if not same and ta.strip().startswith("{") and tb.strip().startswith("{"):
                same = _strip(json.loads(ta)) == _strip(json.loads(tb))
        else:
            same = pa.read_bytes() == pb.read_bytes()
        if not same:
            print(f"differs: {n}")
            bad += 1
    print(f"{len(names) - bad} of {len(names)} files the same")
    return 1 if bad else 0


if __name__ == "__main__":
    if sys.argv[1] == "write":
        write(Path(sys.argv[2]), Path(sys.argv[3] if len(sys.argv) > 3 else "gallery"))
    else:
        sys.exit(compare(Path(sys.argv[2]), Path(sys.argv[3])))
