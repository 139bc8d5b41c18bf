"""docs/python.md and the notebook docs/examples/m1-tutorial.ipynb run as written: their code in
order, in one namespace, from a copy of the repository's configs (as a reader would from its root),
and what each block prints is the text shown after it (the `text` block that follows it in the
tutorial, the cell's stored output in the notebook).

The notebook is run without Jupyter: it is JSON (nbformat 4), its code cells are executed here with
the output captured, the lightest dependable way (no kernel, no extra dependency, the same Python
as the tests)."""

from __future__ import annotations

import contextlib
import io
import json
import os
import re
import shutil

import pytest

from tests.cli_helpers import REPO

README = REPO / "README.md"
TUTORIAL = REPO / "docs" / "python.md"
NOTEBOOK = REPO / "docs" / "examples" / "m1-tutorial.ipynb"
BLOCK = re.compile(r"^```(python|text)\n(.*?)^```\n", re.M | re.S)


def markdown_blocks(text: str) -> list[tuple[str, str]]:
    """(code, expected output) of every python block, in order; the output is the text block right
    after it ('' when the next block is not a text block)."""
    blocks = [(m.group(1), m.group(2), m.start(), m.end()) for m in BLOCK.finditer(text)]
    out = []
    for k, (kind, body, _, end) in enumerate(blocks):
        if kind != "python":
            continue
        following = blocks[k + 1] if k + 1 < len(blocks) else None
        close = following is not None and following[0] == "text" and not text[end:following[2]].strip()
        out.append((body, following[1] if close else ""))
    return out


def notebook_cells(path) -> list[tuple[str, str]]:
    """(code, stored stdout) of every code cell of an nbformat-4 notebook."""
    cells = json.loads(path.read_text())["cells"]
    return [("".join(c["source"]), "".join("".join(o.get("text", "")) for o in c.get("outputs", [])
                                           if o.get("output_type") == "stream" and o.get("name") == "stdout"))
            for c in cells if c["cell_type"] == "code"]


@pytest.fixture
def in_a_copy(tmp_path):
    """The working directory: a folder holding a copy of configs/, as the repository's root would."""
    shutil.copytree(REPO / "configs", tmp_path / "configs")
    before = os.getcwd()
    os.chdir(tmp_path)
    try:
        yield tmp_path
    finally:
        os.chdir(before)
        import matplotlib.pyplot as plt

        plt.close("all")


def run_blocks(blocks, where: str) -> None:
    namespace = {"__name__": "__doc__"}
    for k, (code, expected) in enumerate(blocks, start=1):
        printed = io.StringIO()
        with contextlib.redirect_stdout(printed):
            exec(compile(code, f"{where}, block {k}", "exec"), namespace)
        assert printed.getvalue() == expected, f"{where}, block {k}:\n{code}"


def test_the_tutorial_runs_and_prints_what_it_shows(in_a_copy):
    blocks = markdown_blocks(TUTORIAL.read_text())
    assert len(blocks) >= 10 and sum(bool(out) for _, out in blocks) >= 9
    run_blocks(blocks, "docs/python.md")
    assert (in_a_copy / "out" / "python-m1" / "m1.png").read_bytes()[:4] == b"\x89PNG"
    assert (in_a_copy / "out" / "python-m1" / "workspace.qt").read_bytes() == \
        (REPO / "tests" / "golden" / "M1" / "workspace.qt").read_bytes()


def test_the_notebook_runs_and_prints_its_stored_outputs(in_a_copy):
    cells = notebook_cells(NOTEBOOK)
    assert len(cells) >= 4 and all(out for _, out in cells[1:])
    run_blocks(cells, NOTEBOOK.name)


def test_the_readmes_python_block_runs_and_its_comments_are_what_it_gives(in_a_copy):
    """The README's first Python block (the section "From Python", the first code a newcomer
    reads): it runs, each `name = ...  # <repr>` comment is that value's repr, and the files its
    `save` writes are the golden ones of `fivebar reproduce` (depth 10)."""
    text = README.read_text()
    code = markdown_blocks(text[text.index("## From Python"):])[0][0]
    namespace = {"__name__": "__doc__"}
    with contextlib.redirect_stdout(io.StringIO()) as printed:
        exec(compile(code, "README.md, From Python", "exec"), namespace)
    claims = re.findall(r"^(\w+) = .*#\s*(<.*>)\s*$", code, re.M)
    assert claims and all(repr(namespace[name]) == shown for name, shown in claims), claims
    assert len(printed.getvalue().splitlines()) == len(namespace["a"])  # one line per aspect
    for name in ("aspects.csv", "aspects-adjacency.csv"):
        assert (in_a_copy / "out" / "m1-python" / name).read_bytes() == (REPO / "tests" / "golden" / "M1" / name).read_bytes()
    assert (in_a_copy / "out" / "m1-python" / "aspects-workspace.png").read_bytes()[:4] == b"\x89PNG"
