"""Certified motions through the certified cells of one class in a space of poses of any
dimension (`fivebar path` for a kind with a `PoseAspectModel`): every segment proven, in exact
rational arithmetic, to lie in cells whose every pose is valid and non-singular in that class.

1. Chain: the black cells of the class's paving (or of one aspect) that share a face of positive
   size form a graph (wrapping periodic axes); A* on the distances between cell centres finds a
   chain from the start's cell to the end's. Faces, not edges or corners: a polyline through a
   point or segment shared by two cells only would have to hit it exactly. A chain of black cells
   of one class is also the proof that both ends lie in one aspect.
2. Unwrap: on a periodic axis each cell of the chain is shifted by whole periods so that
   consecutive cells touch in one chart.
3. Waypoints: the start, the centre of every face two consecutive cells share, the end; the
   segment between two of them lies in the (convex) cell both belong to. Then shortcuts: from
   each kept waypoint, the farthest later one (found by doubling, then bisection) whose segment
   is proven to lie in the chain's cells; then waypoints whose neighbours see each other are
   dropped; segments moving a periodic axis by 0.45 of its period or more are halved, so that
   each written step is the short way round.
4. Exact check: the chain's cells are the exact dyadic cells of the float root box widened by one
   ulp of the largest root bound (the paving tested every box widened by four, `paving/engine.py`),
   shifted by whole periods (the root's width, exactly); a waypoint is the float written plus its
   whole periods. A segment is proven when the parameter intervals of its passage through the
   cells cover [0, 1], in Python fractions. A floating-point pre-check skips hopeless shortcuts.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction

import numpy as np

from fivebar_cli.analyses.channel import (
    Chain, face_neighbours, from_lattice, lattice_boxes, segment_cover, shifted_boxes, to_lattice, unwrap_shifts,
    wrapped_delta,
)
from fivebar_cli.analyses.pose_aspects import PoseAspect, analyse_pose_aspects, aspect_at, class_region, pose_model
from fivebar_cli.analyses.slabs import astar
from fivebar_cli.errors import FivebarError, InputError, param
from fivebar_cli.mechanisms.base import Mechanism
from fivebar_cli.paving.tree import Tree

STEP = 0.45  # on a periodic axis, consecutive written waypoints differ by less than this many periods


@dataclass(frozen=True)
class Motion:
    """A certified polyline: waypoints as written (periodic axes wrapped into the root) and the
    whole periods each lies below its place in the unwrapped motion."""

    chain: Chain
    points: np.ndarray  # (n, dim) floats, the first and last as given
    turns: np.ndarray  # (n, dim) integers
    checked_cells: int

    def unwrapped(self) -> np.ndarray:
        return self.points + self.turns * self.chain.cells.grid.size


# ---------------------------------------------------------------- lattice geometry


def containing_leaves(tree: Tree, point: np.ndarray) -> list[int]:
    """The leaves whose closed cell holds the point (periodic axes wrapped), in index order."""
    grid = tree.grid
    n = float(1 << grid.depth)
    u = to_lattice(tree, np.asarray(point, float)[None, :])[0]
    for axis, wrap in enumerate(grid.periodic):
        if wrap:
            u[axis] %= n
    tiny = 1e-9
    offsets = np.stack(np.meshgrid(*([np.array([-tiny, 0.0, tiny])] * grid.dim), indexing="ij"), -1)
    leaves = np.unique(tree.locate(from_lattice(tree, offsets.reshape(-1, grid.dim) + u)))
    lo, hi = lattice_boxes(tree)
    return sorted(int(k) for k in leaves[leaves >= 0] if np.all(lo[k] - 1e-7 <= u) and np.all(u <= hi[k] + 1e-7))


# ---------------------------------------------------------------- 1-2. the chain


def find_chain(cells: Tree, start: int, end: int, start_point: np.ndarray) -> Chain | None:
    """A chain of face-sharing cells from leaf `start` to leaf `end` (A*, ties by Morton order),
    or None when none joins them."""
    first, targets = face_neighbours(cells)
    lo, hi = lattice_boxes(cells)
    centre = 0.5 * (lo + hi).astype(float)
    path = astar(first, targets, centre, start, end, lambda d: wrapped_delta(d, cells.grid))
    if path is None:
        return None
    leaves = np.array(path, np.int64)
    return Chain(cells, leaves, unwrap_shifts(cells, leaves, start_point))


def face_centres(chain: Chain) -> np.ndarray:
    """The centre of the face each pair of consecutive cells shares (lattice units, unwrapped)."""
    lo, hi = shifted_boxes(chain)
    a, b = np.maximum(lo[:-1], lo[1:]), np.minimum(hi[:-1], hi[1:])
    if np.any(np.count_nonzero(a == b, axis=1) != 1) or np.any(a > b):
        raise ValueError("consecutive cells of a chain must share a face")
    return 0.5 * (a + b)


# ---------------------------------------------------------------- 4. exact check


class ExactCells:
    """The chain's cells as exact rational boxes (see the module docstring), and the proof that a
    segment between two written waypoints lies in their union."""

    def __init__(self, chain: Chain):
        grid = chain.cells.grid
        self.grid, self.n = grid, 1 << grid.depth
        lo, hi = shifted_boxes(chain)
        self.float_lo, self.float_hi = from_lattice(chain.cells, lo), from_lattice(chain.cells, hi)
        self.periods = [Fraction(b) - Fraction(a) for a, b in grid.root]
        widen = Fraction(float(np.spacing(max(abs(v) for r in grid.root for v in r))))
        raw_lo, raw_hi = lattice_boxes(chain.cells)
        raw_lo, raw_hi = raw_lo[chain.leaves], raw_hi[chain.leaves]
        self.boxes = []
        for k in range(len(chain.leaves)):
            box = []
            for axis, (a, b) in enumerate(grid.root):
                step = (Fraction(b) - Fraction(a)) / self.n
                shift = int(chain.shifts[k, axis]) * self.periods[axis]
                box.append((Fraction(a) + int(raw_lo[k, axis]) * step - widen + shift,
                            Fraction(a) + int(raw_hi[k, axis]) * step + widen + shift))
            self.boxes.append(box)

    def exact(self, point: np.ndarray, turns) -> list[Fraction]:
        return [Fraction(float(v)) + int(t) * p for v, t, p in zip(point, turns, self.periods)]

    def _float_covers(self, p: np.ndarray, q: np.ndarray) -> bool:
        """The same test in floating point, with a small tolerance: a cheap necessary condition."""
        d = q - p
        with np.errstate(divide="ignore", invalid="ignore"):
            ta = (self.float_lo - 1e-9 - p) / d
            tb = (self.float_hi + 1e-9 - p) / d
        fixed = d == 0
        inside = (self.float_lo - 1e-9 <= p) & (p <= self.float_hi + 1e-9)
        t0 = np.where(fixed, np.where(inside, 0.0, 2.0), np.minimum(ta, tb)).max(axis=1)
        t1 = np.where(fixed, np.where(inside, 1.0, -1.0), np.maximum(ta, tb)).min(axis=1)
        t0, t1 = np.maximum(t0, 0.0), np.minimum(t1, 1.0)
        keep = t0 <= t1
        reach = 0.0
        for a, b in sorted(zip(t0[keep].tolist(), t1[keep].tolist())):
            if a > reach + 1e-9:
                return False
            reach = max(reach, b)
        return reach >= 1.0 - 1e-9

    def covers(self, p: np.ndarray, p_turns, q: np.ndarray, q_turns) -> bool:
        """Whether the straight segment between two written waypoints (each with its whole
        periods) lies in the union of the cells, exactly."""
        size = self.grid.size
        pu, qu = p + np.asarray(p_turns) * size, q + np.asarray(q_turns) * size
        if not self._float_covers(pu, qu):
            return False
        margin = 1e-9 * (1.0 + float(np.max(np.abs(np.concatenate([pu, qu])))))
        lo, hi = np.minimum(pu, qu) - margin, np.maximum(pu, qu) + margin
        near = np.flatnonzero(np.all((self.float_hi >= lo) & (self.float_lo <= hi), axis=1))
        P, Q = self.exact(p, p_turns), self.exact(q, q_turns)
        D = [b - a for a, b in zip(P, Q)]
        return segment_cover(((k, self.boxes[k]) for k in near.tolist()), P, D) is not None


# ---------------------------------------------------------------- 3. the polyline


def written(grid, point: np.ndarray) -> tuple[np.ndarray, tuple[int, ...]]:
    """A point of the unwrapped chart as written: periodic axes wrapped into the root, and the
    whole periods it was moved by."""
    at = np.asarray(point, float).copy()
    turns = [0] * grid.dim
    for axis in np.flatnonzero(grid.periodic):
        lo, size = grid.lo[axis], grid.size[axis]
        k = int(np.floor((at[axis] - lo) / size))
        at[axis] -= k * size
        if not lo <= at[axis] < lo + size:  # rounding at the seam
            at[axis], k = lo, k + (1 if at[axis] >= lo else 0)
        turns[axis] = k
    return at, tuple(turns)


def certified_motion(chain: Chain, start: np.ndarray, end: np.ndarray) -> Motion:
    """Waypoints from `start` to `end` (both inside the root box, kept exactly), every segment
    proven to lie in the chain's cells. ValueError if a segment cannot be proven (the segments
    through face centres always are)."""
    grid = chain.cells.grid
    exact = ExactCells(chain)
    lo, hi = shifted_boxes(chain)
    n = 1 << grid.depth
    u_end = to_lattice(chain.cells, np.asarray(end, float)[None, :])[0]
    end_turns = tuple(int(np.round((0.5 * (lo[-1, a] + hi[-1, a]) - u_end[a]) / n)) if grid.periodic[a] else 0
                      for a in range(grid.dim))
    points = [(np.asarray(start, float).copy(), (0,) * grid.dim)]
    points += [written(grid, from_lattice(chain.cells, c)) for c in face_centres(chain)]
    points.append((np.asarray(end, float).copy(), end_turns))
    ok = lambda a, b: exact.covers(a[0], a[1], b[0], b[1])  # noqa: E731
    for a, b in zip(points, points[1:]):
        if not ok(a, b):
            raise ValueError("a segment through the chain's face centres could not be proven to lie in its cells")
    kept = _shortcuts(points, ok)
    kept = _halved(grid, kept, ok)
    return Motion(chain, np.array([p for p, _ in kept]), np.array([t for _, t in kept], np.int64), len(exact.boxes))


def _shortcuts(points: list, ok) -> list:
    """From each kept waypoint, the farthest later one it sees within the cells (doubling, then
    bisection); then every waypoint whose two neighbours see each other is dropped."""
    out, i, last = [points[0]], 0, len(points) - 1
    while i < last:
        good, step = i + 1, 1
        while good + step <= last and ok(points[i], points[good + step]):
            good, step = good + step, 2 * step
        bad = min(good + step, last + 1)
        while bad - good > 1:
            mid = (good + bad) // 2
            if ok(points[i], points[mid]):
                good = mid
            else:
                bad = mid
        out.append(points[good])
        i = good
    k = 1
    while k < len(out) - 1:
        if ok(out[k - 1], out[k + 1]):
            del out[k]
        else:
            k += 1
    return out


def _halved(grid, points: list, ok) -> list:
    """Segments that move a periodic axis by STEP periods or more, halved until none does."""
    periodic = np.array(grid.periodic)
    out, todo = [points[0]], list(points[1:])[::-1]
    while todo:
        b, a = todo.pop(), out[-1]
        pa, pb = a[0] + np.array(a[1]) * grid.size, b[0] + np.array(b[1]) * grid.size
        if np.any(np.abs(pb - pa)[periodic] >= STEP * grid.size[periodic]):
            middle = written(grid, 0.5 * (pa + pb))
            if not (ok(a, middle) and ok(middle, b)):
                raise ValueError("a halved segment could not be proven to lie in the chain's cells")
            todo += [b, middle]
            continue
        out.append(b)
    return out


# ---------------------------------------------------------------- a mechanism's motion


class NoMotion(FivebarError):
    """No certified motion: proven impossible, or not decided at this depth (exit status 1)."""


@dataclass(frozen=True)
class PoseMotion:
    """A certified motion of a mechanism between two poses of one class, with the joints at its
    waypoints and, when aspects were given, the aspect it stays in."""

    mechanism: Mechanism
    depth: int
    cls: int
    motion: Motion
    joints: np.ndarray
    aspect: PoseAspect | None = None

    @property
    def poses(self) -> np.ndarray:
        return self.motion.points

    @property
    def length(self) -> float:
        """Length of the polyline in the space's units (x, y and phi in degrees alike)."""
        return float(np.sum(np.linalg.norm(np.diff(self.motion.unwrapped(), axis=0), axis=1)))


def check_pose(m: Mechanism, pose: np.ndarray, label: str, source: str, sheet: int | None = None) -> None:
    """InputError (exit 2) when a requested pose is outside the root box on a non-periodic axis
    (the orientation range of a 3-RPR) or not valid (a joint out of its range); NoMotion (exit 1)
    when it violates a joint limit or an obstacle in `sheet` (a 3-RRR's working mode), as a
    five-bar's path endpoint does."""
    model = pose_model(m)
    space = m.spaces()[model.space]
    for axis, value in zip(space.axes, pose):
        if not axis.periodic and not axis.lo <= value <= axis.hi:
            what = "orientation range" if axis.unit == "deg" else "root box"
            raise InputError(source, param("pose"), f"{label}: {axis.name} = {value:g} is outside the {what} "
                                               f"[{axis.lo:g}, {axis.hi:g}]")
    free = pose_model(m.unconstrained()) if m.constraints else model
    if not free.valid(pose[None, :])[0]:
        joints, exists = model.ikp(pose[None, :], 0)
        if not exists[0]:
            raise InputError(source, param("pose"), f"{label} is not a valid pose: no joint values reach it "
                                               "(a leg cannot reach it, or only stretched or folded)")
        names = ", ".join(f"{a.name} = {v:.6g} in [{a.lo:g}, {a.hi:g}]" for a, v in zip(model.joint_axes, joints[0]))
        raise InputError(source, param("pose"), f"{label} is not a valid pose: {names} (a joint out of its range)")
    if sheet is not None and not model.valid(pose[None, :], sheet)[0]:
        labels = model.violated_constraints(pose[None, :], sheet)[0]
        raise NoMotion(f"{label} violates the {' and the '.join(labels)} ({model.sheets[sheet].label}): no motion "
                       "within the constraints starts or ends there")


def endpoint_class(m: Mechanism, pose: np.ndarray, label: str, source: str, sheet: int = 0) -> int:
    """The class of a requested endpoint in a sheet (`check_pose` first); NoMotion when it is on or
    near a singularity (the class's signs are not certified there)."""
    check_pose(m, pose, label, source, sheet)
    cls = int(pose_model(m).classes_of_boxes(pose[None, :], pose[None, :], sheet)[0])
    if cls < 0:
        raise NoMotion(f"{label} is on or near a singularity (its signs are not certified there): no "
                       "singularity-free motion starts there")
    return cls


def wrap_pose(space, pose) -> np.ndarray:
    """A pose with its periodic coordinates wrapped into the root interval."""
    at, _ = written(space.grid(0), np.asarray(pose, float))
    return at


def find_motion(m: Mechanism, depth: int, start: np.ndarray, end: np.ndarray, labels: tuple[str, str],
                source: str, aspects: list[PoseAspect] | None = None, sheets: tuple[int, int] = (0, 0)) -> PoseMotion:
    """A certified motion from `start` to `end` (poses in the space of the pose model, periodic
    axes wrapped; each in its sheet) at this depth, in one class's black cells, or NoMotion saying
    why: proven (different classes, or different certified aspects) or not decided at this depth."""
    model = pose_model(m)
    classes = [endpoint_class(m, p, lab, source, sheet) for p, lab, sheet in zip((start, end), labels, sheets)]
    if classes[0] != classes[1]:
        a, b = (model.classes[k].label for k in classes)
        raise NoMotion(f"{labels[0]} ({a}) and {labels[1]} ({b}) are in different classes: every motion between "
                       "them crosses a singularity")
    cls = classes[0]
    aspect = None
    if aspects is not None:
        _, aspect = aspect_at(aspects, model, start, sheets[0])
        if aspect is None:
            raise _no_cell(labels[0], depth)
        cells = aspect.tree
    else:
        cells = class_region(model, m.spaces()[model.space].grid(depth), cls).paving.inside
    first, last = containing_leaves(cells, start), containing_leaves(cells, end)
    if not first:
        raise _no_cell(labels[0], depth)
    chain = find_chain(cells, first[0], last[0], start) if last else None
    if chain is None:
        if aspects is None:
            aspects = analyse_pose_aspects(m, depth).aspects
        raise _why_not(model, aspects, start, end, labels, depth, sheets[0])
    try:
        motion = certified_motion(chain, start, end)
    except ValueError as exc:
        raise FivebarError(f"internal error: {exc}") from None
    joints, _ = model.ikp(motion.points, cls)
    return PoseMotion(m, depth, cls, motion, joints, aspect)


def _no_cell(label: str, depth: int) -> NoMotion:
    return NoMotion(f"not decided at depth {depth}: {label} lies in no certified cell (too close to a singularity "
                    "or a joint limit for cells this size: try " + param("depth", depth + 1) + ")")


def _why_not(model, aspects: list[PoseAspect], start, end, labels, depth: int, sheet: int) -> NoMotion:
    """Why no chain of face-sharing certified cells of one class of `sheet` joins the two poses:
    different certified aspects (proven), or not decided at this depth."""
    held = [aspect_at(aspects, model, p, sheet)[1] for p in (start, end)]
    a, b = held
    if a is not None and b is not None and a.number != b.number:
        if a.certified and b.certified:
            return NoMotion(f"{labels[0]} is in aspect {a.number}, {labels[1]} in aspect {b.number}: every motion "
                            "between them crosses a singularity")
        return NoMotion(f"not decided at depth {depth}: {labels[0]} is in aspect {a.number}, {labels[1]} in aspect "
                        f"{b.number}, not both certified (they may be one aspect: raise " + param("depth") + ")")
    if a is None or b is None:
        return _no_cell(labels[0] if a is None else labels[1], depth)
    return NoMotion(f"not decided at depth {depth}: both lie in aspect {a.number}, but no chain of certified cells "
                    "sharing faces joins them (they touch only along edges or through finer cells: try "
                    + param("depth", depth + 1) + ")")
