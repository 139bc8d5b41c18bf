"""The files of an aspect analysis: `aspects.csv`, `aspects-adjacency.csv`, one `.qt` per aspect
and space and one GeoJSON per aspect's workspace; written as one output set (`io.outputs`), so that
a folder holds exactly one run's set, and read back, when they are of one complete run, so that
`locate` and `path` reuse them instead of recomputing.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from fivebar_cli.analyses.aspect_texts import aspect_texts, signs_text
from fivebar_cli.analyses.aspects import Aspect, AspectAnalysis
from fivebar_cli.analyses.inscribed import Disc, Square
from fivebar_cli.errors import InputError
from fivebar_cli.analyses.jobs import Texts, Workers
from fivebar_cli.io.files import read_csv_table, write_csv, write_text
from fivebar_cli.io.layout import ASPECT_FILES, ASPECTS_CSV, CROSSINGS_CSV, aspect_geojson_path, aspect_path
from fivebar_cli.io.outputs import of_complete_runs, output_set
from fivebar_cli.io.qtfile import read_qt
from fivebar_cli.mechanisms.base import Mechanism
from fivebar_cli.paving.tree import Tree

SPACES = ("workspace", "jointspace")
SHAPE_COLUMNS = ("circle_x", "circle_y", "circle_r", "square_x", "square_y", "square_side")
CROSSING_HEADER = (
    "aspect_a", "aspect_b", "assembly_mode", "singularity", "working_mode_a", "working_mode_b", "band_cells",
)


def aspect_header(m: Mechanism) -> tuple[str, ...]:
    """`aspects.csv` columns; the configuration columns are named after the axes of the two spaces
    (x, y, theta1, theta2 for the five-bar)."""
    return ("aspect", "working_mode", "assembly_mode", "workspace_area", "jointspace_area",
            "workspace_cells", "jointspace_cells", *_axis_columns(m), "certified", *SHAPE_COLUMNS)


def _axis_columns(m: Mechanism) -> list[str]:
    """The configuration columns: the workspace's axes, then the joint space's."""
    spaces = m.spaces()
    return [a.name for s in SPACES for a in spaces[s].axes]


def _shape_cells(a: Aspect) -> tuple:
    """The six circle and square cells; empty for an aspect without workspace cells."""
    circle = (a.circle.x, a.circle.y, a.circle.r) if a.circle is not None else ("", "", "")
    square = (a.square.x, a.square.y, a.square.side) if a.square is not None else ("", "", "")
    return (*circle, *square)


def aspect_rows(analysis: AspectAnalysis) -> list[tuple]:
    return [
        (a.number, signs_text(a.working), signs_text(a.assembly), a.workspace.area, a.jointspace.area,
         len(a.workspace), len(a.jointspace), *a.pose, *a.joints, "true" if a.certified else "false",
         *_shape_cells(a))
        for a in analysis.aspects
    ]


def crossing_rows(analysis: AspectAnalysis) -> list[tuple]:
    modes = {a.number: signs_text(a.working) for a in analysis.aspects}
    return [(c.a, c.b, signs_text(c.assembly), c.singularity, modes[c.a], modes[c.b], c.band_cells)
            for c in analysis.crossings]


def aspect_set(folder: Path):
    """The output set of `fivebar aspects` (its figures are written inside it too): on success the
    aspect files of an earlier run that this one does not have are removed, so the folder holds
    exactly this run's set."""
    return output_set(folder, "aspects", ASPECT_FILES, "fivebar aspects")


def write_aspects(folder: Path, analysis: AspectAnalysis, jobs: int | None = 1) -> list[Path]:
    """Write the two CSV tables, every aspect tree and every aspect's workspace GeoJSON (inside
    `aspect_set(folder)`); the texts of the aspects' files are those the analysis made in its
    aspects' tasks on workers, or else they are made on `jobs` processes, and each aspect's are
    written (and dropped) as they come."""
    m = analysis.mechanism
    paths = [
        write_csv(folder / ASPECTS_CSV, aspect_header(m), aspect_rows(analysis)),
        write_csv(folder / CROSSINGS_CSV, CROSSING_HEADER, crossing_rows(analysis)),
    ]
    made = analysis.texts is not None
    with Workers(1 if made else jobs, len(analysis.aspects)) as pool:
        texts = analysis.texts if made else pool.map(
            _aspect_texts, [(m, a, analysis.depth) for a in analysis.aspects],
            cost=lambda task: len(task[1].workspace) + len(task[1].jointspace))
        for a, (workspace, jointspace, geojson) in zip(analysis.aspects, texts):
            paths.append(write_text(aspect_path(folder, a.number, "workspace"), workspace))
            paths.append(write_text(aspect_path(folder, a.number, "jointspace"), jointspace))
            paths.append(write_text(aspect_geojson_path(folder, a.number), geojson))
    return paths


def _aspect_texts(task: tuple) -> Texts:
    """One aspect's `.qt` texts (workspace, joint space) and workspace GeoJSON text."""
    return Texts(aspect_texts(*task))


@dataclass(frozen=True)
class SavedRow:
    """One row of a saved `aspects.csv` (its trees are read on demand)."""

    number: int
    working: tuple[int, ...]
    assembly: int
    pose: tuple[float, float]
    joints: tuple[float, float]
    certified: bool
    circle: Disc | None
    square: Square | None

    def aspect(self, workspace: Tree | None = None, jointspace: Tree | None = None) -> Aspect:
        """The aspect with the trees given (empty trees of size 0 grids stand for those not read)."""
        empty = workspace if workspace is not None else jointspace
        return Aspect(self.number, self.working, self.assembly,
                      workspace if workspace is not None else Tree.empty(empty.grid),
                      jointspace if jointspace is not None else Tree.empty(empty.grid),
                      self.pose, self.joints, self.certified, self.circle, self.square)


def read_aspect_table(folder: Path, m: Mechanism) -> list[SavedRow] | None:
    """The rows of `aspects.csv` in `folder` when it was written for this kind of mechanism (its
    header), else None. The trees' headers say which mechanism and depth (`read_aspect_tree`)."""
    table = folder / ASPECTS_CSV
    if not table.is_file():
        return None
    try:
        header, rows = read_csv_table(table)
        if tuple(header) != aspect_header(m):
            return None
        axes = _axis_columns(m)
        out = []
        for _, row in rows:
            working, assembly, certified = row["working_mode"], row["assembly_mode"], row["certified"]
            if certified not in ("true", "false") or not set(working) <= {"+", "-"} or assembly not in ("+", "-"):
                return None
            values = [float(row[c]) for c in axes]
            circle, square = _read_shapes([row[c] for c in SHAPE_COLUMNS])
            out.append(SavedRow(int(row["aspect"]), tuple(1 if c == "+" else -1 for c in working),
                                1 if assembly == "+" else -1, tuple(values[:2]), tuple(values[2:]),
                                certified == "true", circle, square))
        return out
    except (InputError, ValueError):
        return None


def read_aspect_tree(folder: Path, m: Mechanism, depth: int, row: SavedRow, space: str) -> Tree | None:
    """An aspect's saved tree in one space, or None unless it is this mechanism's at this depth."""
    try:
        qt = read_qt(aspect_path(folder, row.number, space))
    except InputError:
        return None
    if (qt.get("mechanism") != m.describe() or qt.tree.grid.depth != depth
            or qt.tree.grid != m.spaces()[space].grid(depth) or qt.get("region") != f"aspect {row.number}"
            or qt.get("working_mode") != signs_text(row.working) or qt.get("assembly_mode") != signs_text(row.assembly)):
        return None
    return qt.tree


def load_aspects(folder: Path, m: Mechanism, depth: int) -> list[Aspect] | None:
    """The aspects a run of `aspects` wrote into `folder` for this mechanism at this depth, or None
    when the folder does not hold such a complete set (then the caller recomputes them). Files that
    are not of one complete run (`io.outputs`) are not read: a FivebarWarning says why."""
    rows = read_aspect_table(folder, m)
    if rows is None:
        return None
    files = [folder / ASPECTS_CSV] + [aspect_path(folder, row.number, space) for row in rows for space in SPACES]
    if not of_complete_runs(folder, files, "the aspects are computed"):
        return None
    aspects = []
    for row in rows:
        trees = {space: read_aspect_tree(folder, m, depth, row, space) for space in SPACES}
        if any(t is None for t in trees.values()):
            return None
        aspects.append(row.aspect(**trees))
    return aspects


def _read_shapes(cells: list[str]) -> tuple[Disc | None, Square | None]:
    """The circle and square of an `aspects.csv` row (None where the cells are empty)."""
    circle = Disc(*(float(v) for v in cells[:3])) if all(cells[:3]) else None
    square = Square(*(float(v) for v in cells[3:6])) if all(cells[3:6]) else None
    return circle, square
