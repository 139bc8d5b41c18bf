"""What `fivebar view` shows: the trees found in the paths given, grouped into sections.

A path is a `.qt` file (its `.complement.qt` partner, or the tree it is the complement of, comes
along when present) or an output folder: its `*.qt` files and `aspects/*.qt`, with `aspects.csv`,
`aspects-adjacency.csv` and `path.csv` when present. Trees whose region is `aspect N` form one
aspects section (one panel per space, the crossings graph, the largest circles and squares); the
other trees are grouped by space and grid into paving sections (2-D) or octree sections (3-D),
where a tree and its complement also show the undetermined cells between them.

Sections refer to trees by their index in `View.trees`; labels are paths relative to the path
given (never absolute), so the page does not depend on where the files are.

Only files of complete runs are shown (`io.outputs`): in a folder, a tree or table of an
interrupted run, or of a run partly replaced by another one, is left out and `View.ignored` says
which and why (the CLI prints it), so that one section never mixes two runs.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Sequence

from fivebar_cli.analyses.view_tables import read_aspect_table, read_crossing_table, read_path_table
from fivebar_cli.errors import InputError
from fivebar_cli.io.layout import ASPECTS_CSV, COMPLEMENT, CROSSINGS_CSV, PATH_CSV, sibling_paths
from fivebar_cli.io.outputs import FolderRuns, read_runs
from fivebar_cli.io.qtfile import QtFile, read_qt
from fivebar_cli.mechanisms.registry import from_description

ASPECT_REGION = re.compile(r"^aspect (\d+)$")
AXIS_TOKEN = re.compile(r"^([^\[\]]+)(?:\[([^\[\]]*)\])?$")
SPACE_ORDER = ("workspace", "jointspace")
FOLDERS = "workspace, jointspace, aspects, refine or rpr3 pave"


@dataclass(frozen=True)
class ViewTree:
    """One tree of the page: its label (relative path), the file's tree and header, its axes."""

    label: str
    qt: QtFile
    axes: tuple[tuple[str, str], ...]  # (name, unit) per axis; unit '' is the mechanism's length unit
    marks: tuple = ()  # obstacles and joint limits of the mechanism over this space (`FiveBar.marks`)

    @property
    def role(self) -> str:
        """'inside', 'outside' (a complement) or 'other', from the `colour` header."""
        colour = self.qt.get("colour")
        return colour if colour in ("inside", "outside") else "other"

    @property
    def aspect(self) -> int | None:
        match = ASPECT_REGION.match(self.qt.get("region"))
        return int(match.group(1)) if match else None


@dataclass
class View:
    """Everything the page shows: trees, sections (JSON-ready dicts), path tables."""

    title: str
    trees: list[ViewTree]
    sections: list[dict]
    paths: list[dict]
    ignored: list[str] = field(default_factory=list)  # one line per file left out, with the reason

    def ignored_summary(self) -> list[str]:
        """The files left out, one line per reason: the first two named, then how many more."""
        by_reason: dict[str, list[str]] = {}
        for line in self.ignored:
            name, _, reason = line.partition(": ")
            by_reason.setdefault(reason, []).append(name)
        return [f"{', '.join(names[:2])}{f' and {len(names) - 2} more files' if len(names) > 2 else ''}: {reason}"
                for reason, names in by_reason.items()]

    @property
    def leaves(self) -> int:
        return sum(len(t.qt.tree) for t in self.trees)


def gather(paths: Sequence[str | Path]) -> View:
    """Read the trees and tables of every path; InputError for a missing path, a folder without
    trees, a corrupted `.qt` file or table."""
    view = View("", [], [], [])
    seen: set[Path] = set()
    for path in map(Path, paths):
        runs = read_runs(path if path.is_dir() else path.parent)
        files = [(label, p) for label, p in _source_files(path, runs, view.ignored) if p.resolve() not in seen]
        seen.update(p.resolve() for _, p in files)
        if files:
            _add_source(view, path, files, runs)
    names = list(dict.fromkeys(t.qt.get("name") or t.label for t in view.trees))
    view.title = "fivebar view: " + " + ".join(names)
    return view


def _source_files(path: Path, runs: FolderRuns, ignored: list[str]) -> list[tuple[str, Path]]:
    """(label, file) of the trees of one path given on the command line; files of a folder that are
    not of a complete run are left out (a line in `ignored`)."""
    if path.is_dir():
        files = [p for p in sorted(path.glob("*.qt")) + sorted((path / "aspects").glob("*.qt"))
                 if p.is_file() and not p.name.startswith(".")]
        kept = [p for p in files if runs.accepts(p)]
        ignored += [f"{p}: not shown ({runs.why(p)})" for p in files if not runs.accepts(p)]
        if not kept:
            found = "no .qt trees" if not files else "no .qt trees of a complete run"
            tables = sorted(p.name for p in path.glob("*.csv"))
            held = f"; it holds {', '.join(tables[:4])}{', ...' if len(tables) > 4 else ''}" if tables else ""
            raise InputError(str(path), "", f"{found} in this folder{held} (expected a .qt file or an output "
                                            f"folder of {FOLDERS})")
        return [(p.relative_to(path).as_posix(), p) for p in kept]
    if not path.exists():
        raise InputError(str(path), "", "no such file or folder")
    if not path.name.endswith(".qt"):
        raise InputError(str(path), "", f"not a .qt file (expected a .qt file or an output folder of {FOLDERS})")
    inside, outside = sibling_paths(path)
    if not runs.accepts(path):
        ignored.append(f"{path}: shown as given, but {runs.why(path)}")
    partner = outside if path == inside else inside
    run = (runs.accepts(path), runs.set_of(path))
    if partner.is_file() and (runs.accepts(partner), runs.set_of(partner)) != run:  # never pair two runs' files
        ignored.append(f"{partner}: not shown with {path.name} (not of the same complete run)")
        return [(path.name, path)]
    return [(p.name, p) for p in (inside, outside) if p == path or p.is_file()]


def _add_source(view: View, path: Path, files: list[tuple[str, Path]], runs: FolderRuns) -> None:
    """Read one path's trees and tables and append its sections."""
    first = len(view.trees)
    for label, file in files:
        qt = read_qt(file)
        view.trees.append(ViewTree(label, qt, tree_axes(qt, str(file)), tree_marks(qt, str(file))))
    indices = list(range(first, len(view.trees)))
    folder = path if path.is_dir() else None
    tables = {name: _table(folder, name, runs, view.ignored) for name in (PATH_CSV, ASPECTS_CSV, CROSSINGS_CSV)}
    path_index = None
    if tables[PATH_CSV] is not None:
        view.paths.append(read_path_table(tables[PATH_CSV]))
        path_index = len(view.paths) - 1
    aspects = [i for i in indices if view.trees[i].aspect is not None]
    if aspects:
        view.sections.append(_aspect_section(view, aspects, tables[ASPECTS_CSV], tables[CROSSINGS_CSV], path_index))
    others = [i for i in indices if view.trees[i].aspect is None]
    view.sections += _paving_sections(view, others, path_index)


def tree_axes(qt: QtFile, source: str) -> tuple[tuple[str, str], ...]:
    """(name, unit) of each axis: from the `axes:` header, else from the mechanism's space, else
    generic names."""
    dim = qt.tree.grid.dim
    text = qt.get("axes")
    if text:
        tokens = text.split()
        if len(tokens) != dim:
            raise InputError(source, "axes", f"expected {dim} axis names, got {len(tokens)}: {text!r}")
        axes = []
        for token in tokens:
            match = AXIS_TOKEN.match(token)
            if not match:
                raise InputError(source, "axes", f"bad axis {token!r} (expected name or name[unit])")
            axes.append((match.group(1), match.group(2) or ""))
        return tuple(axes)
    space = qt.get("space")
    if qt.get("mechanism") and space:
        try:
            s = from_description(qt.get("mechanism"), qt.get("name") or "?", source).spaces().get(space)
        except InputError:  # an unknown or newer mechanism line: the axes get generic names
            s = None
        if s is not None and s.dim == dim:
            return tuple((a.name, a.unit) for a in s.axes)
    if space == "workspace" and dim == 2:
        return (("x", ""), ("y", ""))
    return tuple((f"axis{i + 1}", "") for i in range(dim))


def tree_marks(qt: QtFile, source: str) -> tuple:
    """What to draw over the tree's space: the obstacles and joint limits its mechanism header names
    (none for a kind without `marks`, or a header this version cannot read)."""
    if not (qt.get("mechanism") and qt.get("space")):
        return ()
    try:
        m = from_description(qt.get("mechanism"), qt.get("name") or "?", source)
    except InputError:
        return ()
    return tuple(m.marks(qt.get("space")))


def _space_key(space: str) -> tuple:
    return (SPACE_ORDER.index(space) if space in SPACE_ORDER else len(SPACE_ORDER), space)


def _table(folder: Path | None, name: str, runs: FolderRuns, ignored: list[str]) -> Path | None:
    """A folder's table when it is there and of a complete run (else a line in `ignored`)."""
    if folder is None or not (folder / name).is_file():
        return None
    if not runs.accepts(folder / name):
        ignored.append(f"{folder / name}: not shown ({runs.why(folder / name)})")
        return None
    return folder / name


def _aspect_section(view: View, indices: list[int], aspects_csv: Path | None, crossings_csv: Path | None,
                    path_index: int | None) -> dict:
    """Panels of aspect trees (one per space), the aspect table and the crossings graph."""
    trees = view.trees
    table = read_aspect_table(aspects_csv) if aspects_csv else []
    known = {row["aspect"] for row in table}
    for i in sorted(indices, key=lambda i: trees[i].aspect):
        t = trees[i]
        if t.aspect not in known:
            known.add(t.aspect)
            table.append({"aspect": t.aspect, "working_mode": t.qt.get("working_mode"),
                          "assembly_mode": t.qt.get("assembly_mode"), "det_sign": t.qt.get("det_sign"),
                          "certified": "", "circle": None,
                          "square": None, "cells": []})
    numbers = {t.aspect for t in (trees[i] for i in indices)}
    table = sorted((row for row in table if row["aspect"] in numbers), key=lambda row: row["aspect"])
    crossings = []
    if crossings_csv:
        crossings = [c for c in read_crossing_table(crossings_csv) if c["a"] in numbers and c["b"] in numbers]
    spaces = sorted({trees[i].qt.get("space") for i in indices}, key=_space_key)
    panels = []
    for space in spaces:
        members = sorted((i for i in indices if trees[i].qt.get("space") == space), key=lambda i: trees[i].aspect)
        panels.append({"space": space, "layers": [{"tree": i, "aspect": trees[i].aspect} for i in members]})
    first = trees[indices[0]].qt
    return {"kind": "aspects", "title": f"{first.get('name')} generalized aspects, depth {first.tree.grid.depth}",
            "panels": panels, "aspects": table, "crossings": crossings, "path": path_index}


def _paving_sections(view: View, indices: list[int], path_index: int | None) -> list[dict]:
    """Trees grouped by space and grid, each group one section; a tree with its complement gives
    the undetermined cells."""
    trees = view.trees
    groups: dict[tuple, list[int]] = {}
    for i in indices:
        t = trees[i]
        grid = t.qt.tree.grid
        groups.setdefault((t.qt.get("space"), grid.root, grid.periodic), []).append(i)
    sections = []
    for members in groups.values():
        members.sort(key=lambda i: (_stem(trees[i].label), trees[i].role == "outside", trees[i].label))
        pair = _pair(trees, members)
        if pair:  # the pair first (its inside drawn in black), then the other trees
            members.sort(key=lambda i: i not in pair.values())
        t = trees[members[0]]
        space = t.qt.get("space") or "tree"
        depth = max(trees[i].qt.tree.grid.depth for i in members)
        sections.append({
            "kind": "octree" if t.qt.tree.grid.dim == 3 else "paving",
            "title": f"{t.qt.get('name') or t.label} {space}, depth {depth}",
            "layers": [{"tree": i, "role": trees[i].role} for i in members],
            "undetermined": pair, "path": path_index,
        })
    return sections


def _stem(label: str) -> str:
    return label[: -len(COMPLEMENT)] if label.endswith(COMPLEMENT) else label[: -len(".qt")]


def _pair(trees: list[ViewTree], members: list[int]) -> dict | None:
    """The tree of the group named after its space (`workspace.qt`, not one of the 3-RPR's other
    regions), else the first one, with its complement (same stem), or None."""
    by_label = {trees[i].label: i for i in members}
    for i in sorted(members, key=lambda i: _stem(trees[i].label).split("/")[-1] != trees[i].qt.get("space")):
        label = trees[i].label
        if trees[i].role != "outside" and not label.endswith(COMPLEMENT):
            j = by_label.get(_stem(label) + COMPLEMENT)
            if j is not None and trees[j].role == "outside":
                return {"inside": i, "outside": j}
    return None
