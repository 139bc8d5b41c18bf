"""The results of the public API: immutable values with a one-line repr, their CSV rows (`rows()`),
their files (`save(folder)`, the same files the commands write) and a figure on the caller's axes
(`plot(ax=None)`, never switching matplotlib's backend)."""

from __future__ import annotations

import pathlib
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from fivebar_cli.errors import InputError, param
from fivebar_cli.io.files import user_path
from fivebar_cli.mechanisms.base import Mechanism, article, plural
from fivebar_cli.paving.tree import Tree


def _frozen(array) -> np.ndarray:
    """A read-only copy of an array (results are values: nothing in them can be changed)."""
    out = np.array(array, dtype=float)
    out.flags.writeable = False
    return out


def axes_of(ax):
    """The caller's axes, or new ones from pyplot on the current backend (never switched)."""
    if ax is not None:
        return ax
    import matplotlib.pyplot as plt

    return plt.subplots()[1]


def finite_points(value, n: int, many: bool = False) -> np.ndarray | None:
    """`value` read as one point of `n` finite numbers (with `many`, also a list of such points):
    a (k, n) float array, or None when it is not one (a string, a mapping, ragged or non-numeric
    values, NaN or infinity, another length). The one reading of the poses, joints and endpoints
    the calls take, each of which names its own parameter when it gets None."""
    from collections.abc import Mapping

    if isinstance(value, (str, bytes, Mapping)):
        return None
    try:
        a = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        return None
    if a.ndim == 1:
        a = a[None, :]
    elif not many:
        return None
    if a.ndim != 2 or a.shape[1] != n or not np.all(np.isfinite(a)):
        return None
    return a


@dataclass(frozen=True)
class Drawing:
    """A figure to draw when a result is saved: `function(*args)`, a function of a module of
    `fivebar_cli.plotting` (which imports matplotlib only when it draws). A value, not a closure,
    so that a result pickles (a process pool, a cache): a module's function pickles by its name."""

    function: Callable
    args: tuple = ()

    def __call__(self):
        return self.function(*self.args)


def check_geojson(m: Mechanism, space: str, geojson: bool, source: str) -> None:
    """GeoJSON is for 2-D spaces: InputError on `geojson` for a space of three axes or more."""
    dim = m.spaces()[space].dim
    if geojson and dim != 2:
        raise InputError(str(source), param("geojson"), f"GeoJSON is for 2-D spaces; the {space} of "
                         f"{article(m.kind)} has {dim} axes")


def save_command_files(folder, output: tuple, tables, drawings=(), figures: bool = False) -> list[pathlib.Path]:
    """A command's files in `folder` as one output set (`output`: its name, the patterns it owns,
    the command): its tables as CSV ((file name, columns, data) each) and, with `figures`, its
    figures ((file name, `Drawing` or any function making the figure) each, drawn on the backend
    in use); returns the paths written."""
    from fivebar_cli.io.files import write_csv
    from fivebar_cli.io.outputs import output_set
    from fivebar_cli.plotting.saving import draw_and_save

    folder = user_path(folder, "folder")
    with output_set(folder, *output):
        paths = [write_csv(folder / file, columns, data) for file, columns, data in tables]
        if figures:
            paths += [draw_and_save(make, folder / file) for file, make in drawings]
    return paths


def _plain(value):
    """A cell as Python has it: a numpy scalar (np.float64(10.0), np.int64, np.bool_) as its
    Python value, as every other table's cells are; anything else as it is."""
    return value.item() if isinstance(value, np.generic) else value


def _rows(header, rows) -> list[dict]:
    return [{k: _plain(v) for k, v in zip(header, row)} for row in rows]


# ---------------------------------------------------------------- pavings


@dataclass(frozen=True, repr=False)
class Paving:
    """A certified paving of one space (or one region of it) of a mechanism.

    `inside` holds only valid points, `outside` only invalid ones; the rest (`undetermined_area`)
    is undecided at this depth. `evaluations` counts the box tests.
    """

    mechanism: Mechanism
    space: str
    depth: int
    procedure: str
    region: str | None
    paving: object = field(compare=False)  # the engine's Paving (trees and undetermined cells)
    evaluations: int = 0
    files: str | None = None  # the stem of its files when read from them (`refine`), else derived

    @property
    def inside(self) -> Tree:
        return self.paving.inside

    @property
    def outside(self) -> Tree:
        return self.paving.outside

    @property
    def inside_area(self) -> float:
        return float(self.paving.inside.area)

    @property
    def outside_area(self) -> float:
        return float(self.paving.outside.area)

    @property
    def undetermined_area(self) -> float:
        return float(self.paving.undetermined_area + self.paving.band.area)

    @property
    def stem(self) -> str:
        """The files' stem: the space's name, or the region's file name for another region."""
        from fivebar_cli.io.layout import region_stem

        return self.files or region_stem(self.space, self.region)

    def __repr__(self) -> str:
        where = self.space + (f" ({self.region})" if self.region else "")
        return (f"<Paving {self.mechanism.name} {where}, depth {self.depth}: inside {self.inside_area:.6g}, "
                f"undetermined {self.undetermined_area:.4g}, {self.evaluations} evaluations>")

    def rows(self) -> list[dict]:
        """The summary row of `<space>.csv`, as a dict by column name."""
        from fivebar_cli.analyses.spaces import SUMMARY_HEADER, summary_row

        return _rows(SUMMARY_HEADER, [summary_row(self.mechanism, self.space, self.procedure, self.paving,
                                                  self.evaluations, self.region)])

    def summary(self, evaluations: int | None = None) -> str:
        """The line `fivebar workspace|jointspace|refine` prints: evaluations (those given: a refined
        paving's own), K and the areas."""
        from fivebar_cli.analyses.spaces import has_band, k_ratio

        m, p = self.mechanism, self.paving
        dim, depth = p.grid.dim, p.grid.depth
        n = self.evaluations if evaluations is None else evaluations
        head = (f"{m.name} {self.space}, depth {depth} ({self.procedure} tests): {n} evaluations "
                f"(K = {k_ratio(n, dim, depth):.4%}), ")
        if has_band(m):
            possible = float(p.grid.size.prod()) - p.outside.area
            exact = m.exact_measure(self.space)
            return head + (f"robust area {p.inside.area:.10g}, possible area {possible:.10g} "
                           f"(uncertain band {p.band.area:.4g}, undetermined {p.undetermined_area:.4g})"
                           + (f", nominal exact area {exact:.10g}" if exact is not None else ""))
        return head + (f"certified inside {'area' if dim == 2 else 'volume'} {p.inside.area:.10g}, "
                       f"undetermined {p.undetermined_area:.4g}")

    def save(self, folder: str | pathlib.Path, figures: bool = False, command: str | None = None,
             geojson: bool = False) -> list[pathlib.Path]:
        """The `.qt` pair (and band) and the summary CSV, as `fivebar workspace|jointspace` writes them,
        with `figures` the two PNG figures too (on the backend in use), with `geojson` the inside
        cells as `<space>.geojson` (`--geojson`; a quadtree's only); returns the paths written."""
        from fivebar_cli.io.layout import paving_files
        from fivebar_cli.io.outputs import output_set

        folder = user_path(folder, "folder")
        with output_set(folder, self.stem, paving_files(self.stem), command or f"fivebar {self.space}"):
            return self.write(folder, figures, geojson)

    def write(self, folder: pathlib.Path, figures: bool = False, geojson: bool = False) -> list[pathlib.Path]:
        """The files, inside an output set the caller opened (a GeoJSON of three axes refused
        before any is written)."""
        from fivebar_cli.analyses.spaces import write_paving

        m, p = self.mechanism, self.paving
        check_geojson(m, self.space, geojson, m.name)
        paths = write_paving(folder, m, self.space, p, self.procedure, self.evaluations, self.region, self.stem)
        if figures:
            from fivebar_cli.io.layout import paving_figure
            from fivebar_cli.plotting.saving import draw_and_save
            from fivebar_cli.plotting.trees import figure_paving

            und, s = p.undetermined_tree(), m.spaces()[self.space]
            marks = m.marks(self.space)
            for complement in (False, True):
                paths.append(draw_and_save(lambda: figure_paving(m.name, s, p.inside, p.outside, und, complement,
                                                                 p.band, self.region, marks),
                                           folder / paving_figure(self.stem, complement)))
        if geojson:
            from fivebar_cli.io.geojson import write_geojson
            from fivebar_cli.io.layout import geojson_path

            properties = {"name": m.name, "space": self.space, "region": self.region or m.spaces()[self.space].region,
                          "depth": self.depth, "procedure": self.procedure, "area": self.inside_area}
            paths.append(write_geojson(geojson_path(folder, self.stem), p.inside, properties))
        return paths

    def plot(self, ax=None):
        """Inside in black, undetermined in red, outside in grey on `ax` (a 3-D paving: its slice at
        the middle of the last axis); returns the axes."""
        from fivebar_cli.plotting.trees import draw_paving

        ax = axes_of(ax)
        draw_paving(ax, self.mechanism, self.mechanism.spaces()[self.space], self.paving)
        return ax


# ---------------------------------------------------------------- aspects


@dataclass(frozen=True, repr=False)
class Aspect:
    """One generalized aspect. Five-bar and 2-RPR: `working_mode` and `assembly_mode` ('+-', '+'),
    its certified cells in both spaces (`workspace`, `jointspace` trees and their areas), a
    configuration inside it (`pose`, `joints`) and its largest certified `circle` (x, y, r) and
    `square` (x, y, side). 3-RPR: `modes` (its sign class, e.g. {'det_sign': '+'}) and its octree
    of poses in `workspace` (`workspace_area` is its volume); no joint-space tree."""

    number: int
    modes: dict
    workspace: Tree
    jointspace: Tree | None
    pose: tuple[float, ...]
    joints: tuple[float, ...]
    certified: bool
    circle: tuple[float, float, float] | None = None
    square: tuple[float, float, float] | None = None

    @property
    def working_mode(self) -> str | None:
        return self.modes.get("working_mode")

    @property
    def assembly_mode(self) -> str | None:
        return self.modes.get("assembly_mode")

    @property
    def workspace_area(self) -> float:
        return float(self.workspace.area)

    @property
    def jointspace_area(self) -> float | None:
        return None if self.jointspace is None else float(self.jointspace.area)

    def __repr__(self) -> str:
        modes = ", ".join(f"{k} {v}" for k, v in self.modes.items())
        return (f"<Aspect {self.number}: {modes}, workspace {self.workspace_area:.6g}"
                + ("" if self.certified else ", not certified") + ">")


@dataclass(frozen=True, repr=False)
class Aspects:
    """The generalized aspects of a mechanism at a depth: iterable of the `Aspect`s found (`len`:
    how many); `count`, the number of aspects when it is `certified` (None otherwise: it lies in
    `bounds`, (L, U)); `adjacency`: the crossings (aspect a, aspect b, assembly mode, the serial
    singularity between them)."""

    mechanism: Mechanism
    depth: int
    analysis: object = field(compare=False)  # the library's AspectAnalysis (or PoseAspectAnalysis)
    aspects: tuple[Aspect, ...] = ()
    fates: tuple = ()  # with compare=True and interval lengths: what each nominal aspect becomes
    split: tuple | None = None  # with compare=True and constraints: each aspect's unconstrained aspect
    free: object = field(default=None, compare=False)  # the unconstrained analysis (constraints only)

    @property
    def count(self) -> int | None:
        """The number of generalized aspects when it is certified, else None: the true number is then
        only known to lie in `bounds`, and the aspects listed (`len(self)`) may be fewer (thin ones
        not found yet) or more (pieces of one aspect not proven joined): M1 at depth 5 lists 8,
        bounds 8..10 (10 at depth 6). Deeper, or with a larger `budget`, the count gets certified."""
        return len(self.aspects) if self.certified else None

    @property
    def certified(self) -> bool:
        return bool(self.analysis.certified)

    @property
    def bounds(self) -> tuple[int, int]:
        """(L, U): the number of aspects lies in L..U (L == U == count when certified)."""
        return (self.count, self.count) if self.certified else (self.analysis.lower, self.analysis.upper)

    @property
    def adjacency(self) -> tuple[tuple, ...]:
        from fivebar_cli.analyses.aspects import signs_text

        return tuple((c.a, c.b, signs_text(c.assembly), c.singularity) for c in self.analysis.crossings)

    @property
    def evaluations(self) -> int:
        return int(self.analysis.evaluations)

    @property
    def headline(self) -> str:
        """The line `fivebar aspects` prints first."""
        return self.analysis.headline()

    def lines(self) -> list[str]:
        """What `fivebar aspects` prints after the headline for each aspect and crossing."""
        from fivebar_cli.analyses.aspects import signs_text

        if self._pose_kind():
            return self._pose_lines()
        out = []
        for a in self.analysis.aspects:
            shapes = (f", largest circle r {a.circle.r:.6g}, square side {a.square.side:.6g}"
                      if a.circle is not None and a.square is not None else "")
            out.append(f"  aspect {a.number:2d}: working mode {signs_text(a.working)}, det A {signs_text(a.assembly)}, "
                       f"workspace area {a.workspace.area:.6g}, joint-space area {a.jointspace.area:.6g}{shapes}"
                       + ("" if a.certified else " (not certified)"))
        for c in self.analysis.crossings:
            out.append(f"  aspects {c.a} and {c.b} (det A {signs_text(c.assembly)}) touch across {c.singularity} = 0")
        return out

    def _pose_lines(self) -> list[str]:
        """Over a space of poses: each aspect's class, size, cells and a pose inside with its joints."""
        model = self.analysis.model
        space = self.mechanism.spaces()[model.space]
        unit = ("area" if space.dim == 2 else "volume") + " (" + " x ".join(a.unit or "length" for a in space.axes) + ")"
        values = lambda v: ", ".join(f"{x:g}" for x in v)  # noqa: E731
        return [f"  aspect {a.number:2d}: {a.signs.label}, {unit} {a.volume:.6g}, {len(a.tree)} cells, "
                f"({', '.join(ax.name for ax in space.axes)}) = ({values(a.pose)}), "
                f"({', '.join(ax.name for ax in model.joint_axes)}) = ({values(a.joints)})"
                + ("" if a.certified else " (not certified)") for a in self.analysis.aspects]

    def comparisons(self) -> list[str]:
        """What `fivebar aspects` prints last: the nominal aspects' fates (interval lengths), what the
        constraints cost, and the crossing graph of each assembly mode (the paper's claim on single
        working-mode changes for its own mechanisms)."""
        from fivebar_cli.analyses.aspect_split import cost_text
        from fivebar_cli.analyses.aspects import signs_text
        from fivebar_cli.analyses.crossings import crossing_pattern, paper_claim_verdict
        from fivebar_cli.analyses.tolerance import fate_text

        out = [f"  nominal aspect {f.number:2d}: {fate_text(f)}" for f in self.fates]
        if self.split is not None:
            out.append(f"  {cost_text(list(self.split), self.free)}")
        if self.mechanism.kind == "fivebar":
            from fivebar_cli.mechanisms.fivebar.paper import is_paper_mechanism

            a = self.analysis
            for am in a.model.assembly_modes:
                if is_paper_mechanism(self.mechanism):
                    verdict = paper_claim_verdict(a.aspects, a.crossings, am)
                    out.append(f"  paper's claim on single working-mode changes (det A {signs_text(am)}): {verdict}")
                elif a.aspects:
                    out.append(f"  crossing graph (det A {signs_text(am)}): {crossing_pattern(a.aspects, a.crossings, am)}")
        return out

    def __iter__(self):
        return iter(self.aspects)

    def __len__(self) -> int:
        return len(self.aspects)

    def __getitem__(self, k: int) -> Aspect:
        return self.aspects[k]

    def __repr__(self) -> str:
        what = "certified" if self.certified else "not certified: bounds {}..{}".format(*self.bounds)
        return f"<Aspects {self.mechanism.name}, depth {self.depth}: {plural(len(self), 'aspect')} ({what})>"

    def _pose_kind(self) -> bool:
        return self.mechanism.pose_aspect_model() is not None  # as `fb.aspects` chose

    def rows(self) -> list[dict]:
        """The rows of `aspects.csv`, as dicts by column name."""
        if self._pose_kind():
            from fivebar_cli.analyses.pose_aspect_files import aspect_header, aspect_rows
        else:
            from fivebar_cli.analyses.aspect_files import aspect_header, aspect_rows
        return _rows(aspect_header(self.mechanism), aspect_rows(self.analysis))

    def save(self, folder: str | pathlib.Path, figures: bool = False, jobs: int | None = 1,
             spelled=str) -> list[pathlib.Path]:
        """The files `fivebar aspects` writes: aspects.csv, the adjacency table, the aspect trees
        (and GeoJSON, or PLY surfaces for octrees), with `figures` its figures too (on the backend
        in use); the aspects' files made on `jobs` processes (the same bytes for any);
        `spelled(text)`: a text as the figures' titles write it (the command line: the parameters
        it names as its options)."""
        from fivebar_cli.analyses.aspect_files import aspect_set, write_aspects
        from fivebar_cli.analyses.aspect_split import write_split
        from fivebar_cli.analyses.pose_aspect_files import write_pose_aspects

        folder = user_path(folder, "folder")
        with aspect_set(folder):
            if self._pose_kind():
                paths = write_pose_aspects(folder, self.analysis)
            else:
                paths = write_aspects(folder, self.analysis, jobs) + write_split(folder, None if self.split is None
                                                                                 else list(self.split))
            return paths + (self._figures(folder, spelled) if figures else [])

    def _figures(self, folder: pathlib.Path, spelled) -> list[pathlib.Path]:
        """A five-bar's or 2-RPR's workspace figure (every aspect, its largest circle and square)
        and one joint-space figure per assembly mode; over poses, the slices and the map."""
        from fivebar_cli.io.layout import ASPECTS_MAP_PNG, ASPECTS_SLICES_PNG, ASPECTS_WORKSPACE_PNG
        from fivebar_cli.io.layout import aspects_jointspace_figure
        from fivebar_cli.plotting.saving import draw_and_save

        a = self.analysis
        if self._pose_kind():
            from fivebar_cli.plotting.pose_aspects import figure_aspect_map, figure_aspect_slices

            headline = spelled(self.headline)
            return [draw_and_save(lambda: figure_aspect_slices(a, headline), folder / ASPECTS_SLICES_PNG),
                    draw_and_save(lambda: figure_aspect_map(a, headline), folder / ASPECTS_MAP_PNG)]
        from fivebar_cli.analyses.aspects import signs_text
        from fivebar_cli.plotting.aspects import figure_aspects_jointspace, figure_aspects_workspace

        return [draw_and_save(lambda: figure_aspects_workspace(a), folder / ASPECTS_WORKSPACE_PNG),
                *(draw_and_save(lambda: figure_aspects_jointspace(a, am), folder / aspects_jointspace_figure(signs_text(am)))
                  for am in a.model.assembly_modes)]

    def plot(self, ax=None):
        """Every aspect's certified workspace cells in its colour, with its number (a 3-D space: the
        slice at the middle of the last axis); returns the axes."""
        from fivebar_cli.plotting.aspects import draw_aspects

        ax = axes_of(ax)
        draw_aspects(ax, self.mechanism, [(a.number, a.workspace) for a in self.aspects])
        return ax


# ---------------------------------------------------------------- path (Location: locations.py)


def motion_where(aspect) -> str:
    """Where a motion lies, as `fivebar path` says it: 'aspect N, certified' (or 'not certified'),
    or 'one generalized aspect' when the aspects were not numbered."""
    if aspect is None:
        return "one generalized aspect"
    return f"aspect {aspect.number}, {'certified' if aspect.certified else 'not certified'}"


@dataclass(frozen=True, repr=False)
class Path:
    """A certified motion: `points` (joints then pose per waypoint, the columns of path.csv),
    `length` in the joint space (five-bar, 2-RPR) or in the space of poses (3-RPR, 3-RRR: x, y and
    phi in degrees alike); `notes`, the lines `fivebar path` prints about it; `labels`, how they
    and the figure name the endpoints."""

    mechanism: Mechanism
    depth: int
    columns: tuple[str, ...]
    points: np.ndarray
    length: float
    result: object = field(compare=False)  # the library's PathResult (or pose motion)
    notes: tuple[str, ...] = ()
    trees: pathlib.Path | None = field(default=None, compare=False)  # the `aspects` folder whose trees were reused
    labels: tuple[str, str] = ("start", "goal")  # how the notes and the figure name the endpoints

    def __post_init__(self):
        object.__setattr__(self, "points", _frozen(self.points))

    def __repr__(self) -> str:
        return f"<Path {self.mechanism.name}, depth {self.depth}: {len(self.points)} waypoints, length {self.length:.6g}>"

    def rows(self) -> list[dict]:
        return [dict(zip(self.columns, map(float, p))) for p in self.points]

    def save(self, folder: str | pathlib.Path, figures: bool = False) -> list[pathlib.Path]:
        """path.csv, as `fivebar path` writes it (shortest exact floats), and with `figures` path.png
        (on the backend in use): a five-bar's or 2-RPR's motion over the workspace cells of its
        aspect; over a space of poses, the robot along the motion and its joints."""
        from fivebar_cli.analyses.paths import path_csv
        from fivebar_cli.io.files import write_text
        from fivebar_cli.io.layout import PATH_CSV, PATH_FILES, PATH_PNG
        from fivebar_cli.io.outputs import output_set

        folder = user_path(folder, "folder")
        with output_set(folder, "path", PATH_FILES, "fivebar path"):
            paths = [write_text(folder / PATH_CSV, path_csv(self.columns, self.points))]
            if figures:
                paths.append(self._figure(folder / PATH_PNG))
        return paths

    def _figure(self, path: pathlib.Path) -> pathlib.Path:
        from fivebar_cli.analyses.paths import PathResult, component_of, workspace_backdrop
        from fivebar_cli.plotting.paths import figure_path
        from fivebar_cli.plotting.saving import draw_and_save

        if not isinstance(self.result, PathResult):
            return draw_and_save(self._pose_figure, path)
        backdrop = workspace_backdrop(self.result, self.trees)
        return draw_and_save(lambda: figure_path(self.result, component_of(self.result), backdrop), path)

    def _pose_figure(self):
        """A motion over a space of poses: the robot along it, its joints against the path parameter."""
        from fivebar_cli.plotting.pose_aspects import figure_motion

        m, motion = self.mechanism, self.result
        model = m.pose_aspect_model()
        title = (f"{m.name}: a certified singularity-free motion, {model.classes[motion.cls].label}, "
                 f"{self.labels[0]} to {self.labels[1]}, depth {self.depth}")
        return figure_motion(model, m.spaces()[model.space], motion.motion.unwrapped(), motion.cls, title, *self.labels)

    def plot(self, ax=None):
        """The motion as a polyline in its first two joint coordinates; returns the axes."""
        ax = axes_of(ax)
        ax.plot(self.points[:, 0], self.points[:, 1], "-o", ms=2.5, color="black")
        ax.set_xlabel(self.columns[0])
        ax.set_ylabel(self.columns[1])
        return ax


# ---------------------------------------------------------------- tables


@dataclass(frozen=True, repr=False)
class Table:
    """A table of results (an atlas, a sweep, a synthesis): `columns`, and `rows()` as dicts."""

    what: str
    columns: tuple[str, ...]
    data: tuple[tuple, ...]
    notes: tuple[str, ...] = ()  # what the command reports besides the table (a recommendation, a limit)

    def rows(self) -> list[dict]:
        return _rows(self.columns, self.data)

    def column(self, name: str) -> list:
        """The cells of one column (KeyError naming the columns for another name, as a dict's)."""
        k = self._index(name)
        return [_plain(row[k]) for row in self.data]

    def _index(self, name: str) -> int:
        """The position of column `name`; KeyError naming the columns for a name of none."""
        if name not in self.columns:
            raise KeyError(f"no column {name!r} (the columns: {', '.join(self.columns)})")
        return self.columns.index(name)

    def __len__(self) -> int:
        return len(self.data)

    def __repr__(self) -> str:
        return f"<{self.what}: {plural(len(self.data), 'row')} of {', '.join(self.columns[:6])}" + (
            ", ...>" if len(self.columns) > 6 else ">")

    def save(self, path: str | pathlib.Path) -> pathlib.Path:
        """The table as CSV at `path`."""
        from fivebar_cli.io.files import write_csv

        return write_csv(user_path(path, "path"), self.columns, self.data)

    def plot(self, ax=None, *, x: str | None = None, y: str | None = None, by: str | None = None):
        """Column `y` against column `x` (default: the first two numeric columns), one line per value
        of column `by` (e.g. `config`); returns the axes."""
        numeric = [c for c, v in zip(self.columns, self.data[0] if self.data else ()) if _number(v) is not None]
        x = x or next(iter(numeric), None)
        y = y or next((c for c in numeric if c != x), None)
        if x is None or y is None:
            raise ValueError(f"{self.what}: no two numeric columns to plot by default: give x and y")
        for name in (x, y, by):  # (checked before any axes are made)
            if name is not None:
                self._index(name)
        ax = axes_of(ax)
        groups = {} if by is None else dict.fromkeys(self.column(by))
        for value in groups or [None]:
            rows = [r for r in self.rows() if by is None or r[by] == value]
            ax.plot([_number(r[x]) for r in rows], [_number(r[y]) for r in rows], ".-", lw=1,
                    label=None if by is None else str(value))
        ax.set_xlabel(x)
        ax.set_ylabel(y)
        if by is not None:
            ax.legend(fontsize=7)
        return ax


@dataclass(frozen=True, repr=False)
class Report(Table):
    """A command's table as a value: a `Table` (`columns`, `rows()`, `column()`, `plot()`) with the
    lines the command prints (`notes`), its figures (`drawings`: (file name, `Drawing`) each) and where
    `save` writes them (`output`: the output set's name, the patterns it owns, the command, the
    CSV's file name); `tables`: more CSVs of the set ((file name, columns, data) each).

    Examples
    --------
    >>> import fivebar_cli as fb
    >>> k = fb.kratio("m1", [3])
    >>> len(k), k.columns[:3], [r["evaluations"] for r in k.rows()]
    (2, ('space', 'mechanism', 'depth'), [77, 69])
    >>> paths = k.save("out/python-kratio")  # kratio.csv; with figures=True kratio.png too  # doctest: +SKIP
    """

    output: tuple = field(default=(), compare=False)
    drawings: tuple = field(default=(), compare=False)
    tables: tuple = field(default=(), compare=False)

    def csv(self) -> str:
        """The CSV's text (what `-o -` prints)."""
        from fivebar_cli.io.files import csv_text

        return csv_text(self.columns, self.data)

    def save(self, folder: str | pathlib.Path, figures: bool = False) -> list[pathlib.Path]:
        """The command's files in `folder` as one output set (not `Table.save`'s one CSV file): the
        CSVs and, with `figures`, its PNG figures (drawn on the backend in use); returns the paths
        written."""
        *output, table = self.output
        return save_command_files(folder, tuple(output), [(table, self.columns, self.data), *self.tables],
                                  self.drawings, figures)


@dataclass(frozen=True, repr=False)
class Verified(Report):
    """A verify command's report, with its exit status (0 certified singularity-free, 1 a singular
    pose found, 3 undecided): `fb.verify`'s, and `fb.rpr3.verify`'s (`api.rpr3.Verification`)."""

    exit_code: int = 0


def _number(v) -> float | None:
    """A cell as a number (atlas cells are text), None for other text."""
    if isinstance(v, bool):
        return None
    try:
        return float(v)
    except (TypeError, ValueError):
        return None
