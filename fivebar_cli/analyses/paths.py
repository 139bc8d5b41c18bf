"""Certified singularity-free motions between two configurations (`fivebar path`).

Without serial crossings the motion stays in one generalized aspect: its cells are the black
cells of the joint-space paving of the assembly mode whose working mode is the endpoints' (every
point of them assembles in that mode, with B11, B22 and det A non-zero and of fixed signs). A
chain of such cells from one endpoint to the other proves that both lie in one component of the
non-singular configurations of these modes, i.e. in one aspect, whatever the aspect analysis
says. With `allow_serial` the cells are those certified to assemble with det A != 0 (B11, B22
may vanish): the motion may change working mode across serial singularities, never across a
parallel one. The polyline is built and checked by `channel.py`: the straight segment when it
lies in the cells, else the shortest polyline through them.

The aspect trees an `aspects` run saved for the same mechanism and depth are reused (they name
the aspect and say whether it is certified); otherwise only the one paving the motion needs is
computed. When no chain joins the two configurations, the reason is `locate.decide`'s verdict on
the aspects (saved, else computed then): the very answer `locate` gives, "no" only when proven,
else "not decided at depth D" with what to try.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from fivebar_cli.analyses import aspect_files
from fivebar_cli.analyses.aspects import Aspect, analyse_aspects
from fivebar_cli.analyses.channel import (
    Chain, certified_polyline, containing_leaves, face_component, find_chain, lift,
)
from fivebar_cli.analyses.locate import (
    UNDECIDED, YES, Configuration, Verdict, configurations, decide, deeper, holders, mode_verdict,
)
from fivebar_cli.errors import FivebarError, InputError, param
from fivebar_cli.io.files import csv_text
from fivebar_cli.mechanisms.base import Mechanism, article
from fivebar_cli.paving.engine import pave
from fivebar_cli.paving.tree import Tree


class NoPath(FivebarError):
    """No certified motion at this depth, with the reason (exit status 1)."""


@dataclass(frozen=True)
class Endpoint:
    kind: str  # "pose" or "joints"
    value: tuple[float, float]
    working: str | None = None  # the working mode asked for a pose (e.g. "+-")

    @property
    def label(self) -> str:
        return f"{self.kind} ({self.value[0]:g}, {self.value[1]:g})"


@dataclass
class PathResult:
    mechanism: Mechanism
    depth: int
    allow_serial: bool
    start: Configuration
    end: Configuration
    joints: np.ndarray  # (n, 2) waypoints as written: periodic angles wrapped, the ends as requested
    turns: np.ndarray  # (n, 2) whole periods below their place in the unwrapped motion
    poses: np.ndarray  # (n, 2) their poses
    cells: Tree  # the certified cells the motion may use
    chain: Chain
    checked_cells: int  # cells the exact check of the written segments used
    aspect: Aspect | None = None  # when saved aspect trees named it
    source: str = "computed"

    def unwrapped(self) -> np.ndarray:
        """The waypoints of the motion as one continuous polyline (periodic axes unwrapped)."""
        return self.joints + self.turns * self.cells.grid.size

    @property
    def length(self) -> float:
        return float(np.sum(np.hypot(*np.diff(self.unwrapped(), axis=0).T)))


def path_columns(m: Mechanism) -> tuple[str, ...]:
    """The columns of `path.csv`: the joint axes, then the workspace axes (theta1,theta2,x,y)."""
    return tuple(a.name for s in ("jointspace", "workspace") for a in m.spaces()[s].axes)


def path_points(result: "PathResult") -> np.ndarray:
    """The rows of `path.csv` as numbers: joints then pose of each waypoint."""
    return np.hstack([result.joints, result.poses])


def exact_text(value: float) -> str:
    """A float in its shortest form that reads back exactly (so the file holds the checked path)."""
    v = float(value)
    if v != v:
        return ""
    return "0" if v == 0 else repr(v)


def path_csv(columns, points) -> str:
    """`path.csv`: one row per waypoint, exact shortest floats (a pose the DKP did not give: empty)."""
    return csv_text(list(columns), [[exact_text(v) for v in row] for row in points])


# ---------------------------------------------------------------- endpoints


def _matches(signs: str, wanted: str) -> bool:
    """A configuration's signs match the ones asked for (a vanishing sign matches either)."""
    return all(s == w or s == "0" for s, w in zip(signs, wanted))


def resolve(m: Mechanism, endpoints: list[Endpoint], assembly: str | None, source: str) -> list[Configuration]:
    """The configuration of each endpoint: a pose in its working mode (required when several reach
    it), joints in the assembly mode (`assembly`, else the one of a pose endpoint; required when
    only joints are given). InputError (exit 2) for a choice left open, NoPath for a
    configuration that does not exist."""
    found = []
    for e in endpoints:
        space = "workspace" if e.kind == "pose" else "jointspace"
        rows = configurations(m, e.value, space, e.label)
        if e.kind == "pose":
            if e.working is not None:
                rows = [r for r in rows if _matches(r.working, e.working)]
            if not rows:
                where = f" in working mode {e.working}" if e.working else ""
                raise NoPath(f"{e.label} is not reachable{where}")
            if len(rows) > 1:
                modes = ", ".join(r.working for r in rows)
                raise InputError(source, param("working_mode"), f"{e.label} is reached in working modes {modes}: "
                                 "give the one to start or end in")
        elif not rows:
            raise NoPath(f"{e.label} cannot be assembled")
        found.append(rows)
    if assembly is None:
        poses = [rows[0].assembly for e, rows in zip(endpoints, found) if e.kind == "pose"]
        assembly = poses[0] if poses else None
    out = []
    for e, rows in zip(endpoints, found):
        if e.kind == "joints":
            if assembly is None and len(rows) > 1:
                raise InputError(source, param("assembly_mode"), f"{e.label} assembles in both assembly modes: "
                                 "give " + param("assembly_mode") + " + or -")
            chosen = [r for r in rows if assembly is None or r.assembly in (assembly, "0")]
            if not chosen:
                raise NoPath(f"{e.label} cannot be assembled in assembly mode {assembly}")
            out.append(chosen[0])
        else:
            r = rows[0]
            if assembly is not None and r.assembly not in (assembly, "0"):
                raise NoPath(f"{e.label} (working mode {r.working}) is in assembly mode {r.assembly}, not {assembly}: "
                             "every motion between them crosses a parallel singularity (det A = 0)")
            out.append(r)
        if out[-1].violates:  # limits and obstacles
            raise NoPath(f"{e.label} violates the {out[-1].violates}: no motion within the constraints starts or "
                         "ends there")
    return out


# ---------------------------------------------------------------- cells


def _signs(text: str) -> tuple[int, ...]:
    return tuple(1 if c == "+" else -1 for c in text)


def mode_cells(m: Mechanism, depth: int, working: str, assembly: str) -> Tree:
    """The black joint-space cells of one working and assembly mode (one paving)."""
    model = m.aspect_model()
    am = _signs(assembly)[0]
    paving = pave(m.spaces()["jointspace"].grid(depth), model.jointspace_test(am))
    inside = paving.inside
    if not len(inside):
        return inside
    free = np.asarray(model.working_signs(am, inside.centres()))
    return inside.subset(np.flatnonzero(np.all(free == np.array(_signs(working)), axis=1)))


def parallel_free_cells(m: Mechanism, depth: int, assembly: str) -> Tree:
    """The joint-space cells certified to assemble with det A != 0 (serial singularities allowed)."""
    model = m.aspect_model()
    if not m.crosses_serial:
        raise InputError(m.name, param("allow_serial"), f"{article(m.kind)} has no test for parallel singularities")
    return pave(m.spaces()["jointspace"].grid(depth), model.parallel_free_test(_signs(assembly)[0])).inside


# ---------------------------------------------------------------- the motion


def find_path(m: Mechanism, depth: int, start: Configuration, end: Configuration, allow_serial: bool = False,
              folder: Path | None = None, max_depth: int | None = None, cells: Tree | None = None,
              aspects: list[Aspect] | None = None) -> PathResult:
    """A certified singularity-free motion from `start` to `end` at this depth, or NoPath with the
    verdict of `locate.decide` (the answer `locate` gives): a chain of certified joint-space cells
    is the proof that the motion exists; without one, the aspects say why. The cells are `cells`
    when given, else the joint-space cells of the saved aspect holding the start (an `aspects` run
    in `folder` for this mechanism and depth; the motion then names it), else one paving of the
    start's modes. The aspects are `aspects` when given, else the saved ones, else computed (only
    when no motion is found)."""
    model = m.aspect_model()
    verdict = mode_verdict(model, start, end, depth, allow_serial, offer_serial=True)
    if verdict is not None:
        raise NoPath(verdict.text())
    saved = aspect_files.load_aspects(folder, m, depth) if folder is not None and not allow_serial else None
    aspects = aspects if aspects is not None else saved
    aspect = None
    if allow_serial:
        cells = parallel_free_cells(m, depth, start.assembly)
    elif cells is None and saved is not None:
        aspect = next((a for a, space, _ in holders(saved, start) if space == "jointspace"), None)
        cells = aspect.jointspace if aspect is not None else None
    elif cells is None:
        cells = mode_cells(m, depth, start.working, start.assembly)
    chain = None
    if cells is not None:
        first, last = containing_leaves(cells, start.joints), containing_leaves(cells, end.joints)
        if first and last:
            chain = find_chain(cells, first[0], last[0], start.joints)
    if chain is None:
        raise NoPath(_why_not(m, depth, start, end, allow_serial, aspects, max_depth).text())
    try:
        points, exact = certified_polyline(chain, start.joints, lift(chain, end.joints))
    except ValueError as exc:
        raise FivebarError(f"internal error: {exc}") from None
    joints = np.array([w.at for w in points])
    turns = np.array([w.turns for w in points])
    poses, ok = model.dkp(joints, _signs(start.assembly)[0])
    poses = np.where(ok[:, None], poses, np.nan)
    poses[0], poses[-1] = start.pose, end.pose
    return PathResult(m, depth, allow_serial, start, end, joints, turns, poses, cells, chain, len(exact.used),
                      aspect, "saved" if saved is not None else "computed")


def _why_not(m: Mechanism, depth: int, start: Configuration, end: Configuration, allow_serial: bool,
             aspects: list[Aspect] | None, max_depth: int | None) -> Verdict:
    """Why no chain of certified joint-space cells joins the two configurations: `decide` on the
    aspects; when they prove a motion exists, that the cells at this depth do not show it."""
    if allow_serial:
        return Verdict(UNDECIDED, f"no chain of cells certified free of parallel singularities joins {start.label} "
                                  f"and {end.label}", depth, deeper(depth, max_depth))
    if aspects is None:
        aspects = analyse_aspects(m, depth, shapes=False).aspects
    verdict = decide(m.aspect_model(), aspects, start, end, depth, m.is_interval, max_depth,
                     offer_serial=True, constrained=bool(m.constraints))
    if verdict.answer != YES:
        return verdict
    return Verdict(UNDECIDED, f"{verdict.reason}, so a singularity-free motion joins them, but no chain of certified "
                              "joint-space cells sharing edges does (their cells touch only at corners, or are "
                              "joined through the workspace or through finer cells)", depth, deeper(depth, max_depth))


def component_of(result: PathResult) -> Tree:
    """The cells sharing edges with the motion's cells (for figures)."""
    return result.cells.subset(face_component(result.cells, int(result.chain.leaves[0])))


BACKDROP_DEPTH = 10  # figures are rasters of 2^10 pixels a side: a deeper backdrop shows nothing more


def workspace_backdrop(result: PathResult, folder: Path | None) -> Tree | None:
    """The workspace cells to draw under the motion's image: the aspect's saved workspace tree, or
    the black workspace cells of the working mode (det A of the motion's sign) that the motion's
    image meets (all of them if it meets none at this depth); for a motion across serial
    singularities, the certified workspace. Paved at most BACKDROP_DEPTH deep: only drawn."""
    m = result.mechanism
    if result.aspect is not None and folder is not None:
        rows = aspect_files.read_aspect_table(folder, m) or []
        row = next((r for r in rows if r.number == result.aspect.number), None)
        if row is not None:
            tree = aspect_files.read_aspect_tree(folder, m, result.depth, row, "workspace")
            if tree is not None:
                return tree
    grid = m.spaces()["workspace"].grid(min(result.depth, BACKDROP_DEPTH))
    if result.allow_serial:
        return pave(grid, m.box_test("workspace")).inside
    model = m.aspect_model()
    inside = pave(grid, model.workspace_test(_signs(result.start.working))).inside
    if not len(inside):
        return inside
    sign = np.asarray(model.assembly_signs(_signs(result.start.working), inside.centres())).reshape(-1)
    mine = inside.subset(np.flatnonzero(sign == _signs(result.start.assembly)[0]))
    labels, _ = mine.components(corners=True)
    hit = mine.locate(result.poses[np.all(np.isfinite(result.poses), axis=1)])
    hit = hit[hit >= 0]
    return mine.subset(np.isin(labels, labels[hit])) if len(hit) else mine
