"""The self-contained HTML page of `fivebar view`.

The template, style and script (`page.html`, `page.css`, `page.js`, package data beside this
module) are inlined around one JSON block, `<script type="application/json" id="fivebar-data">`,
holding each tree's header fields and B/W/G body (the `.qt` body itself, decoded by the page) and
the sections to draw. Nothing refers to the network; the same input gives the same bytes.
"""

from __future__ import annotations

import html
import json
import re
from importlib import resources
from pathlib import Path

from fivebar_cli.analyses.view import View, ViewTree
from fivebar_cli.io.files import write_text

FORMAT = 1  # version of the JSON block
PLACEHOLDER = re.compile(r"\{\{(title|style|script|data)\}\}")


def asset(name: str) -> str:
    """The text of one of the page's files shipped with the package."""
    return resources.files("fivebar_cli.webpage").joinpath(name).read_text(encoding="utf-8")


def tree_data(t: ViewTree) -> dict:
    grid, tree = t.qt.tree.grid, t.qt.tree
    hidden = ("name", "space", "region", "colour")
    return {
        "label": t.label, "name": t.qt.get("name"), "space": t.qt.get("space"), "region": t.qt.get("region"),
        "colour": t.qt.get("colour"), "role": t.role, "aspect": t.aspect, "dim": grid.dim,
        "root": [list(r) for r in grid.root], "depth": grid.depth, "periodic": list(grid.periodic),
        "axes": [list(a) for a in t.axes], "fields": {k: v for k, v in t.qt.fields.items() if k not in hidden},
        "leaves": len(tree), "measure": tree.area, "body": tree.to_bwg(), "marks": list(t.marks),
    }


def page_data(view: View) -> dict:
    """The JSON block: format version, title, trees, sections, path tables."""
    return {"format": FORMAT, "title": view.title, "trees": [tree_data(t) for t in view.trees],
            "sections": view.sections, "paths": view.paths}


def json_for_script(data: dict) -> str:
    """JSON that is safe inside a <script> element (no '<', '>' or '&' left as such)."""
    text = json.dumps(data, ensure_ascii=True, separators=(",", ":"), allow_nan=False)
    return text.replace("<", "\\u003c").replace(">", "\\u003e").replace("&", "\\u0026")


def render_page(view: View) -> str:
    """The whole page as text."""
    script, style = asset("page.js"), asset("page.css")
    if "</script" in script.lower() or "</style" in style.lower():
        raise ValueError("page.js or page.css closes its own element")
    values = {"title": html.escape(view.title), "style": style.rstrip("\n"), "script": script.rstrip("\n"),
              "data": json_for_script(page_data(view))}
    return PLACEHOLDER.sub(lambda m: values[m.group(1)], asset("page.html"))


def write_page(path: str | Path, view: View) -> Path:
    """Atomically write the page."""
    return write_text(path, render_page(view))
