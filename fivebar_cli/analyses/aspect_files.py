"""The files of an aspect analysis: `aspects.csv`, `aspects-adjacency.csv` and one `.qt` per
aspect and space; written so that a folder holds exactly one run's set, and read back so that
`locate` reuses them instead of recomputing.
"""

from __future__ import annotations

import csv
from pathlib import Path

from fivebar_cli.analyses.aspects import Aspect, AspectAnalysis, signs_text
from fivebar_cli.errors import InputError
from fivebar_cli.io.files import write_csv
from fivebar_cli.io.layout import ASPECTS_CSV, CROSSINGS_CSV, aspect_path
from fivebar_cli.io.qtfile import read_qt, write_qt
from fivebar_cli.mechanisms.base import Mechanism

SPACES = ("workspace", "jointspace")
CROSSING_HEADER = (
    "aspect_a", "aspect_b", "assembly_mode", "singularity", "working_mode_a", "working_mode_b", "band_cells",
)


def aspect_header(m: Mechanism) -> tuple[str, ...]:
    """`aspects.csv` columns; the configuration columns are named after the axes of the two spaces
    (x, y, theta1, theta2 for the five-bar)."""
    spaces = m.spaces()
    axes = [a.name for s in SPACES for a in spaces[s].axes]
    return ("aspect", "working_mode", "assembly_mode", "workspace_area", "jointspace_area",
            "workspace_cells", "jointspace_cells", *axes, "certified")


def aspect_rows(analysis: AspectAnalysis) -> list[tuple]:
    return [
        (a.number, signs_text(a.working), signs_text(a.assembly), a.workspace.area, a.jointspace.area,
         len(a.workspace), len(a.jointspace), *a.pose, *a.joints, "true" if a.certified else "false")
        for a in analysis.aspects
    ]


def crossing_rows(analysis: AspectAnalysis) -> list[tuple]:
    modes = {a.number: signs_text(a.working) for a in analysis.aspects}
    return [(c.a, c.b, signs_text(c.assembly), c.singularity, modes[c.a], modes[c.b], c.band_cells)
            for c in analysis.crossings]


def _qt_fields(m: Mechanism, a: Aspect, space: str) -> dict:
    return {"name": m.name, "space": space, "region": f"aspect {a.number}", "colour": "inside",
            "mechanism": m.describe(), "working_mode": signs_text(a.working), "assembly_mode": signs_text(a.assembly)}


def write_aspects(folder: Path, analysis: AspectAnalysis) -> list[Path]:
    """Write the two CSV tables and every aspect tree; then remove the aspect trees of an earlier
    run that this one does not have, so the folder holds exactly this run's set."""
    m = analysis.mechanism
    paths = [
        write_csv(folder / ASPECTS_CSV, aspect_header(m), aspect_rows(analysis)),
        write_csv(folder / CROSSINGS_CSV, CROSSING_HEADER, crossing_rows(analysis)),
    ]
    for a in analysis.aspects:
        for space in SPACES:
            tree = a.workspace if space == "workspace" else a.jointspace
            paths.append(write_qt(aspect_path(folder, a.number, space), tree, **_qt_fields(m, a, space)))
    keep = {p.name for p in paths}
    for old in sorted((folder / "aspects").glob("aspect-*.qt")):
        if old.name not in keep:
            old.unlink(missing_ok=True)
    return paths


def load_aspects(folder: Path, m: Mechanism, depth: int) -> list[Aspect] | None:
    """The aspects a run of `aspects` wrote into `folder` for this mechanism at this depth, or None
    when the folder does not hold such a complete set (then the caller recomputes them)."""
    table = folder / ASPECTS_CSV
    if not table.is_file():
        return None
    try:
        with open(table, newline="", encoding="utf-8") as fh:
            rows = list(csv.reader(fh))
        header, body = tuple(rows[0]), rows[1:]
        if header != aspect_header(m):
            return None
        aspects = []
        for row in body:
            number = int(row[0])
            trees = {}
            for space in SPACES:
                qt = read_qt(aspect_path(folder, number, space))
                if (qt.get("mechanism") != m.describe() or qt.tree.grid.depth != depth
                        or qt.tree.grid != m.spaces()[space].grid(depth) or qt.get("region") != f"aspect {number}"
                        or qt.get("working_mode") != row[1] or qt.get("assembly_mode") != row[2]):
                    return None
                trees[space] = qt.tree
            working = tuple(1 if c == "+" else -1 for c in row[1])
            values = [float(v) for v in row[7:11]]
            if row[11] not in ("true", "false"):
                return None
            aspects.append(Aspect(number, working, 1 if row[2] == "+" else -1, trees["workspace"],
                                  trees["jointspace"], tuple(values[:2]), tuple(values[2:]), row[11] == "true"))
    except (OSError, ValueError, IndexError, InputError):
        return None
    return aspects
