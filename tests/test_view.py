"""`fivebar view` (issue 14): one self-contained HTML page of the trees, checked as a file and in a
real headless browser.

As a file: written by the CLI (in-process), no reference to the network, the embedded JSON block
decodes back to exactly the trees given (its B/W/G bodies read with our own codec), the same
input gives the same bytes wherever it lies, and bad input gets the one-line error. In Chromium
(tests/browser.py): the page sets data-ready and counts at least every black leaf it was given
(an M1 aspects folder at depth 10, a joint space on the torus, a workspace pair, an octree); a
screenshot is not blank; pointing at a panel reads the cell under the cursor and highlights the
aspects there in both spaces; panning the torus by one period repaints the same image.
"""

from __future__ import annotations

import json
import re
import shutil
from pathlib import Path

import numpy as np
import pytest
from browser import body_attributes, image, not_blank, require_chromium
from cli_helpers import ok, one_line, run_cli

from fivebar_cli.io.qtfile import read_qt, write_qt
from fivebar_cli.paving.engine import pave
from fivebar_cli.paving.grid import Grid
from fivebar_cli.paving.tree import Tree

REPO = Path(__file__).resolve().parents[1]
GOLDEN_M1 = REPO / "tests" / "golden" / "M1"  # aspects at depth 10 with the workspace and joint-space pairs
M1_YAML = REPO / "configs" / "m1.yaml"
DATA = re.compile(r'<script type="application/json" id="fivebar-data">(.*?)</script>', re.S)
SVG_NAMESPACE = "http://www.w3.org/2000/svg"  # an identifier for createElementNS, never fetched


def view(*args, cwd: Path | None = None):
    return run_cli("view", *args, cwd=cwd or REPO)


def embedded(page: Path) -> dict:
    match = DATA.search(page.read_text(encoding="utf-8"))
    assert match, "no JSON data block"
    return json.loads(match.group(1))


def black_leaves(paths) -> int:
    return sum(len(read_qt(p).tree) for p in paths)


def sphere_octree(folder: Path, depth: int = 5) -> list[Path]:
    """An (x, y, phi) octree pair like `rpr3 pave` writes (header `axes: x y phi[deg]`): the cone
    x^2 + y^2 <= r(phi)^2, r = 0.4 + (phi - 100) / 50, paved with an exact box test."""
    grid = Grid(((-2.0, 2.0), (-2.0, 2.0), (100.0, 165.0)), depth, (False, False, False))

    def squares(lo, hi):
        return np.where((lo <= 0) & (hi >= 0), 0.0, np.minimum(lo * lo, hi * hi)), np.maximum(lo * lo, hi * hi)

    def test(lo, hi):
        (ax, bx), (ay, by) = squares(lo[:, 0], hi[:, 0]), squares(lo[:, 1], hi[:, 1])
        rmin, rmax = 0.4 + (lo[:, 2] - 100) / 50, 0.4 + (hi[:, 2] - 100) / 50
        return np.where(bx + by <= rmin ** 2, 1, np.where(ax + ay > rmax ** 2, -1, 0)).astype(np.int8)

    paving = pave(grid, test)
    fields = {"name": "cone", "space": "workspace", "region": "reachable", "axes": "x y phi[deg]"}
    lo, _ = paving.inside.bounds()
    return [write_qt(folder / "workspace.qt", paving.inside, colour="inside", **fields),
            write_qt(folder / "workspace.complement.qt", paving.outside, colour="outside", **fields),
            write_qt(folder / "singularity-free.plus.qt", paving.inside.subset(lo[:, 0] >= 0),
                     **{**fields, "region": "singularity-free (+)", "colour": "inside"})]


# ---------------------------------------------------------------- inputs and pages (module-wide)


@pytest.fixture(scope="module")
def inputs(tmp_path_factory) -> dict[str, Path]:
    root = tmp_path_factory.mktemp("view-inputs")
    ok(run_cli("jointspace", M1_YAML, "--depth", "8", "-o", root / "joint", "--no-plot", "-q"))
    ok(run_cli("workspace", M1_YAML, "--depth", "8", "-o", root / "work", "--no-plot", "-q"))
    (root / "octree").mkdir()
    sphere_octree(root / "octree")
    return {"aspects": GOLDEN_M1, "joint": root / "joint", "work": root / "work" / "workspace.qt",
            "octree": root / "octree"}


@pytest.fixture(scope="module")
def pages(inputs, tmp_path_factory) -> dict[str, Path]:
    out = tmp_path_factory.mktemp("view-pages")
    made = {}
    for key, path in inputs.items():
        result = ok(view(path, "-o", out / f"{key}.html"))
        assert f"wrote {out / f'{key}.html'}" in result.stdout
        made[key] = out / f"{key}.html"
    return made


def given_trees(path: Path) -> list[Path]:
    if path.is_dir():
        return sorted(path.glob("*.qt")) + sorted((path / "aspects").glob("*.qt"))
    partner = path.with_name(path.name[: -len(".qt")] + ".complement.qt")
    return [path, partner]


# ---------------------------------------------------------------- the file


@pytest.mark.parametrize("key", ["aspects", "joint", "work", "octree"])
def test_page_is_one_offline_file(pages, key):
    text = pages[key].read_text(encoding="utf-8")
    assert text.startswith("<!DOCTYPE html>") and text.endswith("</html>\n")
    assert not re.search(r"\b(src|href|srcset|action|poster)\s*=", text, re.I), "an element loads a resource"
    assert not re.search(r"@import|url\(|\bimport\s*\(|\bimport\s+[\w{*]|fetch\(|XMLHttpRequest|WebSocket|"
                         r"EventSource|sendBeacon|<link|<iframe|<object|<embed", text), "a network reference"
    urls = {url_at(text, m.start()) for m in re.finditer("://", text)}
    assert urls <= {SVG_NAMESPACE}, urls
    assert text.count("<script") == 2  # the data block and the inline script, neither with a src


def url_at(text: str, colon: int) -> str:
    """The URL around the '://' at `colon` (scheme letters before it, up to a quote, space or bracket after)."""
    scheme = re.search(r"[A-Za-z][A-Za-z0-9+.-]{0,15}$", text[max(0, colon - 16):colon])
    end = re.compile(r"[\s\"'<>()]").search(text, colon)
    return (scheme.group(0) if scheme else "") + text[colon:end.start() if end else len(text)]


@pytest.mark.parametrize("key", ["aspects", "joint", "work", "octree"])
def test_embedded_data_is_the_trees(pages, inputs, key):
    data = embedded(pages[key])
    files = given_trees(inputs[key])
    assert len(data["trees"]) == len(files)
    by_label = {t["label"]: t for t in data["trees"]}
    base = inputs[key] if inputs[key].is_dir() else inputs[key].parent
    for path in files:
        qt = read_qt(path)
        t = by_label[path.relative_to(base).as_posix()]
        grid = Grid(tuple(map(tuple, t["root"])), t["depth"], tuple(t["periodic"]))
        assert grid == qt.tree.grid
        decoded = Tree.from_bwg(grid, t["body"])
        assert decoded == qt.tree and t["leaves"] == len(qt.tree)
        assert t["measure"] == pytest.approx(qt.tree.area)
    used = set()
    for sec in data["sections"]:
        for layer in sec.get("layers", []) + [ly for p in sec.get("panels", []) for ly in p["layers"]]:
            used.add(layer["tree"])
    assert used == set(range(len(data["trees"])))  # every tree is drawn somewhere


def test_aspect_folder_sections(pages):
    data = embedded(pages["aspects"])
    kinds = [s["kind"] for s in data["sections"]]
    assert kinds == ["aspects", "paving", "paving"]
    asp = data["sections"][0]
    assert [p["space"] for p in asp["panels"]] == ["workspace", "jointspace"]
    assert [a["aspect"] for a in asp["aspects"]] == list(range(1, 11))
    assert len(asp["crossings"]) == 12 and {c["singularity"] for c in asp["crossings"]} == {"B11", "B22"}
    rows = [line.split(",") for line in (GOLDEN_M1 / "aspects.csv").read_text().splitlines()]
    columns = {name: k for k, name in enumerate(rows[0])}
    for a, row in zip(asp["aspects"], rows[1:]):  # issue 12's columns, as `aspects` writes them
        assert a["circle"] == [float(row[columns[c]]) for c in ("circle_x", "circle_y", "circle_r")]
        assert a["square"] == [float(row[columns[c]]) for c in ("square_x", "square_y", "square_side")]
    joint = next(s for s in data["sections"] if "jointspace" in s["title"])
    trees = data["trees"]
    assert trees[joint["undetermined"]["inside"]]["label"] == "jointspace.qt"
    assert trees[joint["undetermined"]["outside"]]["label"] == "jointspace.complement.qt"
    assert trees[joint["layers"][0]["tree"]]["periodic"] == [True, True]
    assert trees[joint["layers"][0]["tree"]]["axes"] == [["theta1", "rad"], ["theta2", "rad"]]


def test_octree_section(pages):
    data = embedded(pages["octree"])
    (sec,) = data["sections"]
    assert sec["kind"] == "octree"
    labels = [data["trees"][ly["tree"]]["label"] for ly in sec["layers"]]
    assert labels == ["workspace.qt", "workspace.complement.qt", "singularity-free.plus.qt"]
    assert data["trees"][0]["axes"] == [["x", ""], ["y", ""], ["phi", "deg"]]


def test_optional_tables_of_later_analyses(tmp_path):
    """Issue 12's columns and path.csv are drawn when present: circle/square per aspect, the path."""
    folder = tmp_path / "m1"
    shutil.copytree(GOLDEN_M1, folder)
    lines = [",".join(line.split(",")[:12]) for line in (folder / "aspects.csv").read_text().splitlines()]
    assert lines[0].endswith(",certified")  # the columns before issue 12
    lines[0] += ",circle_x,circle_y,circle_r,square_x,square_y,square_side"
    lines[1:] = [line + (",4.5,5,1.25,4.5,5,1.5" if i == 0 else ",,,,,,") for i, line in enumerate(lines[1:])]
    (folder / "aspects.csv").write_text("\n".join(lines) + "\n")
    (folder / "path.csv").write_text("theta1,theta2,x,y\n0.1,0.7,4.9,4.9\n0.2,0.8,4.5,5.2\n")
    out = tmp_path / "page.html"
    ok(view(folder, "-o", out))
    data = embedded(out)
    asp = data["sections"][0]
    assert asp["aspects"][0]["circle"] == [4.5, 5.0, 1.25] and asp["aspects"][0]["square"] == [4.5, 5.0, 1.5]
    assert all(a["circle"] is None for a in asp["aspects"][1:])
    assert data["paths"] == [{"label": "path.csv", "columns": ["theta1", "theta2", "x", "y"],
                              "rows": [[0.1, 0.7, 4.9, 4.9], [0.2, 0.8, 4.5, 5.2]]}]
    assert all(s["path"] == 0 for s in data["sections"])


def test_same_input_same_bytes_anywhere(pages, inputs, tmp_path):
    elsewhere = tmp_path / "somewhere" / "else"
    shutil.copytree(inputs["aspects"], elsewhere)
    ok(view(elsewhere, "-o", tmp_path / "again.html", cwd=tmp_path))
    assert (tmp_path / "again.html").read_bytes() == pages["aspects"].read_bytes()
    ok(view(inputs["octree"], "-o", tmp_path / "octree.html"))
    assert (tmp_path / "octree.html").read_bytes() == pages["octree"].read_bytes()


def test_default_output_and_partner(inputs, tmp_path):
    folder = tmp_path / "work"
    shutil.copytree(inputs["work"].parent, folder)
    result = ok(view(folder / "workspace.complement.qt", cwd=tmp_path))  # the partner brings its inside tree
    assert "2 trees" in result.stdout and (folder / "view.html").is_file()
    assert [t["label"] for t in embedded(folder / "view.html")["trees"]] == ["workspace.qt", "workspace.complement.qt"]
    (folder / "workspace.complement.qt").unlink()
    ok(view(folder / "workspace.qt", "-o", tmp_path / "alone.html", "-q"))
    data = embedded(tmp_path / "alone.html")
    assert len(data["trees"]) == 1 and data["sections"][0]["undetermined"] is None


# ---------------------------------------------------------------- bad input: one line, exit 2


def test_folder_without_trees(tmp_path):
    (tmp_path / "empty").mkdir()
    (tmp_path / "empty" / "aspects.csv").write_text("aspect\n1\n")
    one_line(view(tmp_path / "empty", "-o", tmp_path / "x.html"), 2, "empty", "no .qt trees")
    assert not (tmp_path / "x.html").exists()


def test_corrupted_tree(tmp_path):
    folder = tmp_path / "bad"
    shutil.copytree(GOLDEN_M1, folder)
    path = folder / "aspects" / "aspect-03.workspace.qt"
    path.write_text(path.read_text().replace("# depth: 10", "# depth: ten"))
    one_line(view(folder, "-o", tmp_path / "x.html"), 2, "aspect-03.workspace.qt", "depth", "expected an integer")
    body = folder / "jointspace.qt"
    body.write_text(read_qt_text_cut(body))
    one_line(view(body, "-o", tmp_path / "x.html"), 2, "jointspace.qt", "truncated tree body")
    assert not (tmp_path / "x.html").exists()


def read_qt_text_cut(path: Path) -> str:
    text = path.read_text()
    return text[: len(text) - 200] + "\n"


@pytest.mark.parametrize("case, needles", [
    ("missing", ("nowhere", "no such file or folder")),
    ("not-qt", ("notes.txt", "not a .qt file")),
    ("bad-table", ("aspects.csv", "line 3 (aspect)", "expected an integer")),
    ("bad-path", ("path.csv", "line 2 (x)", "expected a number")),
    ("bad-axes", ("axes", "expected 3 axis names")),
])
def test_bad_input_one_line(tmp_path, case, needles):
    target = tmp_path / "in"
    if case == "missing":
        target = tmp_path / "nowhere"
    elif case == "not-qt":
        target = tmp_path / "notes.txt"
        target.write_text("hello\n")
    elif case in ("bad-table", "bad-path"):
        shutil.copytree(GOLDEN_M1, target)
        if case == "bad-table":
            lines = (target / "aspects.csv").read_text().splitlines()
            lines[2] = "two" + lines[2][1:]
            (target / "aspects.csv").write_text("\n".join(lines) + "\n")
        else:
            (target / "path.csv").write_text("theta1,theta2,x,y\n0,0,oops,1\n")
    else:
        target.mkdir()
        paths = sphere_octree(target, depth=2)
        paths[0].write_text(paths[0].read_text().replace("# axes: x y phi[deg]", "# axes: x y"))
    one_line(view(target, "-o", tmp_path / "x.html"), 2, *needles)
    assert not (tmp_path / "x.html").exists()


def test_no_path_is_a_usage_error():
    one_line(view(), 2, "fivebar view: error", "PATH")


# ---------------------------------------------------------------- in a real browser


@pytest.fixture(scope="module")
def chromium() -> str:
    return require_chromium()


@pytest.mark.parametrize("key", ["aspects", "joint", "work", "octree"])
def test_page_paints_every_leaf_in_chromium(chromium, pages, inputs, key, tmp_path):
    state = body_attributes(chromium, pages[key], png=tmp_path / f"{key}.png")  # one Chromium run: DOM and image
    assert state.get("data-ready") == "true", state
    leaves = black_leaves(given_trees(inputs[key]))
    assert int(state["data-cells"]) >= leaves > 0
    assert 0 < float(state["data-paint-ms"]) < 10_000
    coloured, distinct = not_blank(image(tmp_path / f"{key}.png"))
    assert coloured > 0.05 and distinct > 20, (coloured, distinct)


def test_pointing_reads_cells_and_links_aspects_in_chromium(chromium, pages):
    """#probe points at the centre of each panel in turn with real mouse events (entering one, leaving
    it for the next): the read-outs name the cells there, the aspects under the cursor are highlighted
    (in both spaces) while it rests on an aspects panel and none once it has left them, and panning
    the torus by one period repaints the same image."""
    # (virtual time: the page idles once the probe is done, so a generous budget costs no real time)
    state = body_attributes(chromium, pages["aspects"], fragment="probe", budget_ms=2000)
    probe = json.loads(state["data-probe"])
    workspace, joint, joint_pair, work_pair = probe["readouts"]
    for readout, space, variable in ((workspace, "workspace", r"[xy]"), (joint, "jointspace", r"theta\d")):
        point = [float(v) for v in re.findall(variable + r" = (\S+?)[,\n]", readout)]
        expected, cells = [], []
        for number in range(1, 11):
            tree = read_qt(GOLDEN_M1 / "aspects" / f"aspect-{number:02d}.{space}.qt").tree
            leaf = tree.locate(np.array([point]))[0]
            if leaf >= 0:
                expected.append(number)
                lo, hi = (b[leaf] for b in tree.bounds())
                cells.append(f"cell [{lo[0]:.6g}, {hi[0]:.6g}] x [{lo[1]:.6g}, {hi[1]:.6g}], level {tree.level[leaf]}")
        assert len(point) == 2 and (expected or space == "workspace" and "in no shown aspect" in readout), readout
        assert probe["highlighted"][["workspace", "jointspace"].index(space)] == [expected], space
        for number, cell in zip(expected, cells):  # the page decoded the same leaf as our codec
            assert f"aspect {number}: working mode" in readout and cell in readout, (cell, readout)
    assert probe["highlighted"][2:] == [[[]], [[]]]  # left: the pairs' panels highlight no aspect
    assert "jointspace.qt: inside, cell [" in joint_pair
    assert "workspace.complement.qt: outside" in work_pair or "workspace.qt: inside" in work_pair
    assert probe["torus"] == [0, 0]  # the aspects' joint space and the joint-space pair


def test_reproduce_writes_the_pages_of_m1_m2_and_the_3rpr_octree():
    """`fivebar reproduce` views each five-bar folder after its aspects, and the 3-RPR octrees after
    `rpr3 pave` (skipped with --no-plot)."""
    from fivebar_cli.cli.reproduce import FIGURE_STEPS, REPRODUCTION

    steps = [args for _, args, *_ in REPRODUCTION]
    for name, command in (("M1", ["aspects"]), ("M2", ["aspects"]), ("rpr3-general", ["rpr3", "pave"])):
        page = ["view", f"{{out}}/{name}", "-o", f"{{out}}/{name}/view.html"]
        assert page in steps
        made = next(i for i, a in enumerate(steps) if a[:len(command)] == command and a[-1] == f"{{out}}/{name}")
        assert steps.index(page) > made
    assert "view" in FIGURE_STEPS
