"""A Sphinx extension: the gallery, one page per scene of ``gallery/*.toml``, written when the build starts.

Each page shows the scene's animation (``<name>.gif`` beside it), the comment
that opens the scene file, the commands that remake its outputs and the scene
file itself.  The pages go to ``docs/gallery/scenes/`` (ignored by git):
nothing generated is committed, and a scene added to ``gallery/`` gets its page
on the next build.
"""

from __future__ import annotations

import os
import tomllib
from pathlib import Path
from typing import Any


def _intro(text: str) -> str:
    """The comment lines that open a scene file, as one paragraph."""
    lines = []
    for line in text.splitlines():
        if not line.startswith("#"):
            break
        lines.append(line.lstrip("#").strip())
    return " ".join(x for x in lines if x)


def scene_page(toml: Path, pages: Path) -> str:
    """The Markdown page of one scene file."""
    text = toml.read_text(encoding="utf-8")
    data = tomllib.loads(text)
    name = data.get("name", toml.stem)
    kind = data.get("mechanism", {}).get("type", "?")
    gif = toml.with_suffix(".gif")
    out = [f"# {name}", ""]
    if gif.exists():
        out += [f"![{name}]({os.path.relpath(gif, pages)})", ""]
    intro = _intro(text)
    if intro:
        out += [intro, ""]
    out += [
        f"Mechanism type `{kind}`; scene file `gallery/{toml.name}`.",
        "",
        "```sh",
        f"planar render gallery/{toml.name} -o {toml.stem}.gif",
        f"planar motion gallery/{toml.name} -o {toml.stem}.csv",
        f"planar export gallery/{toml.name} -o {toml.stem}.dxf --svg {toml.stem}.svg",
        "```",
        "",
        "```toml",
        text.rstrip("\n"),
        "```",
        "",
    ]
    return "\n".join(out)


def write_pages(source: Path, pages: Path) -> list[Path]:
    """Write a page per ``source/*.toml`` into ``pages`` (and remove pages of scenes that are gone)."""
    pages.mkdir(parents=True, exist_ok=True)
    written = []
    for toml in sorted(source.glob("*.toml")):
        page = pages / f"{toml.stem}.md"
        text = scene_page(toml, pages)
        if not page.exists() or page.read_text(encoding="utf-8") != text:  # unchanged pages keep their time
            page.write_text(text, encoding="utf-8")
        written.append(page)
    for old in set(pages.glob("*.md")) - set(written):
        old.unlink()
    return written


def _generate(app: Any) -> None:
    write_pages(Path(app.config.planar_gallery_source), Path(app.config.planar_gallery_pages))


def setup(app: Any) -> dict[str, Any]:
    app.add_config_value("planar_gallery_source", "", "env")
    app.add_config_value("planar_gallery_pages", "", "env")
    app.connect("builder-inited", _generate)
    return {"version": "1.0", "parallel_read_safe": True, "parallel_write_safe": True}
