"""Certified singularity-free motions between two configurations (`fivebar path`).

Without serial crossings the motion stays in one generalized aspect: its cells are the black
cells of the joint-space paving of the assembly mode whose working mode is the endpoints' (every
point of them assembles in that mode, with B11, B22 and det A non-zero and of fixed signs). A
chain of such cells from one endpoint to the other proves that both lie in one component of the
non-singular configurations of these modes, i.e. in one aspect, whatever the aspect analysis
says. With `allow_serial` the cells are those certified to assemble with det A != 0 (B11, B22
may vanish): the motion may change working mode across serial singularities, never across a
parallel one. The polyline is built and checked by `channel.py`.

The aspect trees an `aspects` run saved for the same mechanism and depth are reused (they name
the aspect and say whether it is certified); otherwise only the one paving the motion needs is
computed. Both give the same path: the chain only depends on the start's component of cells
sharing edges, which is the same in the aspect's cells and in the paving's cells of those modes.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from fivebar_cli.analyses import aspect_files
from fivebar_cli.analyses.aspects import Aspect, analyse_aspects, signs_text
from fivebar_cli.analyses.channel import (
    Chain, certified_polyline, containing_leaves, face_component, find_chain, lift,
)
from fivebar_cli.analyses.locate import locate_configurations
from fivebar_cli.errors import FivebarError, InputError
from fivebar_cli.mechanisms.base import Mechanism
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


@dataclass(frozen=True)
class Configuration:
    """One endpoint's configuration: the requested values exactly, the others computed."""

    endpoint: Endpoint
    joints: np.ndarray
    pose: np.ndarray
    working: str  # signs, '0' where one vanishes (on or near a serial singularity)
    assembly: str

    @property
    def label(self) -> str:
        return self.endpoint.label


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
    checked_cells: int  # cells the exact check used
    aspect: Aspect | None = None  # when saved aspect trees named it
    source: str = "computed"

    def unwrapped(self) -> np.ndarray:
        """The waypoints of the motion as one continuous polyline (periodic axes unwrapped)."""
        return self.joints + self.turns * self.cells.grid.size

    @property
    def length(self) -> float:
        return float(np.sum(np.hypot(*np.diff(self.unwrapped(), axis=0).T)))


# ---------------------------------------------------------------- endpoints


def _matches(signs: str, wanted: str) -> bool:
    """A configuration's signs match the ones asked for (a vanishing sign matches either)."""
    return all(s == w or s == "0" for s, w in zip(signs, wanted))


def _candidates(m: Mechanism, endpoint: Endpoint) -> list[dict]:
    space = "workspace" if endpoint.kind == "pose" else "jointspace"
    return locate_configurations(m, [], np.array([endpoint.value], float), space)


def resolve(m: Mechanism, endpoints: list[Endpoint], assembly: str | None, source: str) -> list[Configuration]:
    """The configuration of each endpoint: a pose in its working mode (required when several reach
    it), joints in the assembly mode (`assembly`, else the one of a pose endpoint; required when
    only joints are given). InputError (exit 2) for a choice left open, NoPath for a
    configuration that does not exist."""
    names = [a.name for a in m.spaces()["jointspace"].axes]
    found = []
    for e in endpoints:
        rows = _candidates(m, e)
        if e.kind == "pose":
            if e.working is not None:
                rows = [r for r in rows if _matches(r["working_mode"], e.working)]
            if not rows:
                where = f" in working mode {e.working}" if e.working else ""
                raise NoPath(f"{e.label} is not reachable{where}")
            if len(rows) > 1:
                modes = ", ".join(r["working_mode"] for r in rows)
                raise InputError(source, "--working-mode", f"{e.label} is reached in working modes {modes}: "
                                 "give the one to start or end in")
        elif not rows:
            raise NoPath(f"{e.label} cannot be assembled")
        found.append(rows)
    if assembly is None:
        poses = [rows[0]["assembly_mode"] for e, rows in zip(endpoints, found) if e.kind == "pose"]
        assembly = poses[0] if poses else None
    out = []
    for e, rows in zip(endpoints, found):
        if e.kind == "joints":
            if assembly is None and len(rows) > 1:
                raise InputError(source, "--assembly-mode", f"{e.label} assembles in both assembly modes: "
                                 "give --assembly-mode + or -")
            chosen = [r for r in rows if assembly is None or r["assembly_mode"] in (assembly, "0")]
            if not chosen:
                raise NoPath(f"{e.label} cannot be assembled in assembly mode {assembly}")
            r = chosen[0]
            joints, pose = np.array(e.value, float), np.array([r["x"], r["y"]])
        else:
            r = rows[0]
            if assembly is not None and r["assembly_mode"] not in (assembly, "0"):
                raise NoPath(f"{e.label} (working mode {r['working_mode']}) is in assembly mode "
                             f"{r['assembly_mode']}, not {assembly}: every motion between them crosses a "
                             "parallel singularity (det A = 0)")
            joints, pose = np.array([r[names[0]], r[names[1]]]), np.array(e.value, float)
        if r.get("violates"):  # limits and obstacles (`locate.with_violations`)
            raise NoPath(f"{e.label} violates the {r['violates']}: no motion within the constraints starts or "
                         "ends there")
        out.append(Configuration(e, joints, pose, r["working_mode"], r["assembly_mode"]))
    return out


def check_modes(m: Mechanism, start: Configuration, end: Configuration, allow_serial: bool) -> None:
    """The reasons no motion can exist, whatever the depth (NoPath)."""
    model = m.aspect_model()
    for c in (start, end):
        if c.assembly == "0":
            raise NoPath(f"{c.label} is on or near a parallel singularity (det A = 0): no motion avoiding "
                         "parallel singularities starts there")
        if "0" in c.working and not allow_serial:
            names = " and ".join(n for n, s in zip(model.serial_names, c.working) if s == "0")
            raise NoPath(f"{c.label} is on or near a serial singularity ({names} = 0): it is in no aspect "
                         "(--allow-serial allows motions across serial singularities)")
    if start.assembly != end.assembly:
        raise NoPath(f"different assembly modes ({start.assembly} for {start.label}, {end.assembly} for "
                     f"{end.label}): every motion between them crosses a parallel singularity (det A = 0)")
    if not allow_serial and start.working != end.working:
        raise NoPath(f"different working modes ({start.working} for {start.label}, {end.working} for {end.label}): "
                     "every motion between them crosses a serial singularity (--allow-serial allows that)")


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
    test_of = getattr(model, "parallel_free_test", None)
    if test_of is None:
        raise InputError(m.name, "--allow-serial", f"a {m.kind} has no test for parallel singularities")
    return pave(m.spaces()["jointspace"].grid(depth), test_of(_signs(assembly)[0])).inside


def _saved_aspect(folder: Path | None, m: Mechanism, depth: int, c: Configuration):
    """(aspect, usable): the saved aspect holding the configuration, if the folder holds the trees
    of an `aspects` run for this mechanism and depth; usable is False when it does not."""
    if folder is None:
        return None, False
    rows = aspect_files.read_aspect_table(folder, m)
    if rows is None:
        return None, False
    for row in rows:
        if signs_text(row.working) != c.working or signs_text(row.assembly) != c.assembly:
            continue
        tree = aspect_files.read_aspect_tree(folder, m, depth, row, "jointspace")
        if tree is None:
            return None, False
        if containing_leaves(tree, c.joints):
            return row.aspect(jointspace=tree), True
    return None, True


def _no_cell(c: Configuration, depth: int) -> NoPath:
    return NoPath(f"{c.label} lies in no certified cell at depth {depth} (too close to a singularity for "
                  f"cells this size: try --depth {depth + 2})")


# ---------------------------------------------------------------- the motion


def find_path(m: Mechanism, depth: int, start: Configuration, end: Configuration, allow_serial: bool = False,
              folder: Path | None = None) -> PathResult:
    """A certified singularity-free motion from `start` to `end` at this depth, or NoPath."""
    check_modes(m, start, end, allow_serial)
    aspect, source = None, "computed"
    if allow_serial:
        cells = parallel_free_cells(m, depth, start.assembly)
    else:
        aspect, usable = _saved_aspect(folder, m, depth, start)
        if usable:
            source = "saved"
            if aspect is None:
                raise _no_cell(start, depth)
            cells = aspect.jointspace
        else:
            cells = mode_cells(m, depth, start.working, start.assembly)
    first, last = containing_leaves(cells, start.joints), containing_leaves(cells, end.joints)
    if not first:
        raise _no_cell(start, depth)
    if not last:
        if source == "saved":
            other, _ = _saved_aspect(folder, m, depth, end)
            if other is not None:
                raise _different_aspects(start, end, aspect, other)
        raise _no_cell(end, depth)
    chain = find_chain(cells, first[0], last[0], start.joints)
    if chain is None:
        raise _why_not_joined(m, depth, start, end, allow_serial, folder)
    try:
        points, exact = certified_polyline(chain, start.joints, lift(chain, end.joints))
    except ValueError as exc:
        raise FivebarError(f"internal error: {exc}") from None
    joints = np.array([w.at for w in points])
    turns = np.array([w.turns for w in points])
    poses, ok = m.aspect_model().dkp(joints, _signs(start.assembly)[0])
    poses = np.where(ok[:, None], poses, np.nan)
    poses[0], poses[-1] = start.pose, end.pose
    return PathResult(m, depth, allow_serial, start, end, joints, turns, poses, cells, chain, len(exact.boxes),
                      aspect, source)


def _different_aspects(start: Configuration, end: Configuration, a: Aspect, b: Aspect) -> NoPath:
    caveat = "" if a.certified and b.certified else (
        " (not both certified at this depth: they may be one aspect; raise --depth)")
    return NoPath(f"{start.label} is in aspect {a.number}, {end.label} in aspect {b.number}: every motion "
                  f"between them crosses a singularity{caveat}")


def _why_not_joined(m: Mechanism, depth: int, start: Configuration, end: Configuration, allow_serial: bool,
                    folder: Path | None) -> NoPath:
    """Why no chain of certified cells joins the two configurations."""
    if allow_serial:
        return NoPath(f"no chain of cells certified free of parallel singularities joins {start.label} and "
                      f"{end.label} at depth {depth}: every motion between them crosses a parallel singularity, "
                      f"or they are joined only through cells finer than depth {depth}")
    aspects = aspect_files.load_aspects(folder, m, depth) if folder is not None else None
    if aspects is None:
        aspects = analyse_aspects(m, depth, shapes=False).aspects
    held = []
    for c in (start, end):
        held.append(next((a for a in aspects if signs_text(a.working) == c.working
                          and signs_text(a.assembly) == c.assembly and containing_leaves(a.jointspace, c.joints)), None))
    a, b = held
    if a is not None and b is not None and a.number != b.number:
        return _different_aspects(start, end, a, b)
    where = f"both lie in aspect {a.number}, but " if a is not None and b is not None else ""
    return NoPath(f"{where}no chain of certified cells sharing edges joins {start.label} and {end.label} at depth "
                  f"{depth} (their cells touch only at corners or through finer cells: try --depth {depth + 2})")


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
