"""Short polylines through a set of certified cells of a 2-D tree (periodic axes wrap), each
straight segment proven to lie in the cells.

1. Chain: the cells that share an edge of positive length (face adjacency, wrapping around
   periodic axes) form a graph; A* by the distance between cell centres (torus-aware) finds a
   chain of cells from the start's cell to the end's: the proof that the cells join the two
   points. Face contact, not corner contact: a path through a corner shared by two cells only
   would have to pass through one exact point, which floating-point waypoints cannot do.
2. Unwrap: on a torus, each cell of the chain is shifted by whole periods so that consecutive
   cells touch in the plane (the lifted chart in which the path is one continuous polyline).
3. First motion: string pulling (the funnel algorithm) through the portals, the edges
   consecutive cells share, each shortened at both ends by a small margin so that the polyline
   keeps off cell corners: the shortest polyline through that chain. Its length L bounds the
   shortest motion through the cells.
4. Corridor: every lifted copy of a cell holding a point p with |p - start| + |p - end| <= L (an
   ellipse): the shortest motion through the cells lies in them. Their union is cut into vertical
   slabs at every cell edge; in each slab it is a set of disjoint intervals, i.e. rectangles, and
   rectangles of consecutive slabs sharing an edge of positive length are neighbours. When the
   corridor has no hole this graph is a tree: the sequence of rectangles from the start to the end
   is unique, and string pulling through their shared edges gives the shortest polyline through
   the cells (up to the portal margins). With holes, A* on the rectangles picks the sequence. The
   straight segment is tried first and kept when it lies in the cells; otherwise the shorter of
   the two pulled strings.
5. Exact check: every segment is checked to lie in the union of the corridor's closed cells, in
   rational arithmetic (Python fractions), the points being the floats the path is written with:
   the parameter intervals [t0, t1] of the segment in the cells must cover [0, 1]. A cell is the
   exact dyadic cell of the float root box widened by one ulp of the largest root bound: the
   paving tested every box widened by four (`paving/engine.py`), so the widened cell was proven
   too. On a periodic axis the written waypoints are wrapped into the root box, consecutive ones
   joined the short way round, and cells and points are shifted by whole periods, the period
   taken as 2 pi to 40 digits when the root is the float [-pi, pi] (within 1e-38 of the truth,
   left as slack in the widening); the widening also covers the sliver between fl(pi) and
   2 pi - fl(pi) that the float root box misses. A segment that fails (it has not been seen to)
   is replaced by the polyline through the middles of the portals it crosses, checked the same
   way; then waypoints are merged or dropped where the new segments are proven, and segments
   moving a periodic axis by 3 or more are split so that the short way is unambiguous.

Geometry (portals, strings, lengths) is computed in the space's own units, measured from the root
box's low corner, so that the strings are shortest in the space's metric; adjacency is computed on
the integer lattice of depth-D cells, exactly.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction

import numpy as np

from fivebar_cli.analyses.slabs import Slabs, astar, csr
from fivebar_cli.paving.tree import Tree

PI_40 = Fraction("3.141592653589793238462643383279502884197")  # within 1e-39 of pi
MARGIN = 2.0 ** -10  # portal shortening, in depth-D cells (at most a quarter of the portal)


@dataclass(frozen=True)
class Chain:
    """Cells of a tree, each shifted by whole periods: a chain (in order, consecutive cells sharing
    an edge) or any set of lifted cells (a corridor)."""

    cells: Tree
    leaves: np.ndarray  # leaf indices, start cell first
    shifts: np.ndarray  # (k, dim) integer periods per cell (0 on non-periodic axes)


# ---------------------------------------------------------------- lattice geometry


def lattice_boxes(tree: Tree) -> tuple[np.ndarray, np.ndarray]:
    """Integer bounds of every leaf in depth-D cells: (lo, hi), each (m, dim)."""
    span = np.int64(1) << (tree.grid.depth - tree.level)
    lo = tree.coords * span[:, None]
    return lo, lo + span[:, None]


def to_lattice(tree: Tree, points: np.ndarray) -> np.ndarray:
    """Points of the space in depth-D cell units (floats; periodic axes are not wrapped)."""
    grid = tree.grid
    return (np.asarray(points, float) - grid.lo) / grid.size * float(1 << grid.depth)


def from_lattice(tree: Tree, points: np.ndarray) -> np.ndarray:
    grid = tree.grid
    return grid.lo + np.asarray(points, float) * (grid.size / float(1 << grid.depth))


def cell_size(tree: Tree) -> np.ndarray:
    """The side of a depth-D cell on each axis, in the space's units."""
    return tree.grid.size / float(1 << tree.grid.depth)


def containing_leaves(tree: Tree, point: np.ndarray) -> list[int]:
    """The leaves whose closed cell holds the point (periodic axes wrapped), in index order; a
    leaf counts when the exact check holds it (its cell widened by one ulp, as for segments)."""
    grid = tree.grid
    n = float(1 << grid.depth)
    u = to_lattice(tree, point[None, :])[0]
    for axis, wrap in enumerate(grid.periodic):
        if wrap:
            u[axis] %= n
    tiny = 1e-9
    probes = np.array([[dx, dy] for dx in (-tiny, 0, tiny) for dy in (-tiny, 0, tiny)]) + u
    leaves = np.unique(tree.locate(from_lattice(tree, probes)))
    leaves = leaves[leaves >= 0]
    held = []
    for k in leaves:
        one = np.array([k], np.int64)
        chain = Chain(tree, one, unwrap_shifts(tree, one, np.asarray(point, float)))
        at = Waypoint(np.asarray(point, float), (0,) * grid.dim)
        if ExactCells(chain).covers(at, at):
            held.append(int(k))
    return sorted(held)


def wrapped_delta(delta: np.ndarray, grid) -> np.ndarray:
    """Lattice differences the short way round every periodic axis of `grid`."""
    n = float(1 << grid.depth)
    out = np.array(delta, float)
    for axis, wrap in enumerate(grid.periodic):
        if wrap:
            out[..., axis] = (out[..., axis] + n / 2) % n - n / 2
    return out


# ---------------------------------------------------------------- 1. chain


def face_neighbours(cells: Tree) -> tuple[np.ndarray, np.ndarray]:
    """Edge-sharing neighbours as CSR: leaf k's are targets[first[k]:first[k + 1]], in Morton order."""
    i, j = cells.adjacency(corners=False)
    return csr(len(cells), np.concatenate([i, j]), np.concatenate([j, i]))


def face_component(cells: Tree, start: int) -> np.ndarray:
    """The leaves joined to `start` by chains of cells sharing edges (sorted leaf indices)."""
    first, targets = face_neighbours(cells)
    reached = np.zeros(len(cells), bool)
    reached[start] = True
    frontier = np.array([start])
    while len(frontier):
        count = first[frontier + 1] - first[frontier]
        at = np.repeat(first[frontier] - np.cumsum(count) + count, count) + np.arange(int(count.sum()))
        nxt = np.unique(targets[at])
        nxt = nxt[~reached[nxt]]
        reached[nxt] = True
        frontier = nxt
    return np.flatnonzero(reached)


def find_chain(cells: Tree, start: int, end: int, start_point: np.ndarray) -> Chain | None:
    """A chain of edge-sharing cells from leaf `start` to leaf `end` by A* on the distances between
    cell centres (torus-aware), or None when no chain joins them. Ties break by Morton order and
    only the start's component is explored, so the chain depends on that component alone."""
    first, targets = face_neighbours(cells)
    lo, hi = lattice_boxes(cells)
    centre = 0.5 * (lo + hi).astype(float) * cell_size(cells)
    scale = cell_size(cells)
    path = astar(first, targets, centre, start, end,
                  lambda d: wrapped_delta(d / scale, cells.grid) * scale)
    if path is None:
        return None
    leaves = np.array(path, np.int64)
    return Chain(cells, leaves, unwrap_shifts(cells, leaves, start_point))


# ---------------------------------------------------------------- 2. unwrap


def unwrap_shifts(cells: Tree, leaves: np.ndarray, start_point: np.ndarray) -> np.ndarray:
    """Whole periods per cell so that the first holds the start point and consecutive cells touch."""
    grid = cells.grid
    n = 1 << grid.depth
    lo, hi = lattice_boxes(cells)
    lo, hi = lo[leaves], hi[leaves]
    u = to_lattice(cells, np.asarray(start_point, float)[None, :])[0]
    shifts = np.zeros((len(leaves), grid.dim), np.int64)
    for axis, wrap in enumerate(grid.periodic):
        if wrap:  # the cell holds the start point wrapped: the shift is the nearest whole period
            shifts[0, axis] = int(np.round((u[axis] - 0.5 * (lo[0, axis] + hi[0, axis])) / n))
    for k in range(1, len(leaves)):
        for axis, wrap in enumerate(grid.periodic):
            a0, a1 = lo[k - 1, axis] + shifts[k - 1, axis] * n, hi[k - 1, axis] + shifts[k - 1, axis] * n
            shifts[k, axis] = shifts[k - 1, axis]
            if wrap:
                for s in (0, -1, 1):
                    base = shifts[k - 1, axis] + s
                    if lo[k, axis] + base * n <= a1 and hi[k, axis] + base * n >= a0:
                        shifts[k, axis] = base
                        break
    return shifts


def shifted_boxes(chain: Chain) -> tuple[np.ndarray, np.ndarray]:
    """Integer bounds of the chain's cells in the unwrapped chart."""
    n = 1 << chain.cells.grid.depth
    lo, hi = lattice_boxes(chain.cells)
    return lo[chain.leaves] + chain.shifts * n, hi[chain.leaves] + chain.shifts * n


# ---------------------------------------------------------------- 3. string pulling


def box_portals(lo: np.ndarray, hi: np.ndarray, scale: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
    """(left, right) ends of the edge each pair of consecutive integer boxes shares, as seen when
    moving along them, in the space's units (`scale`: the side of a lattice step per axis),
    shortened by MARGIN lattice steps (at most a quarter of the edge) at both ends."""
    out = []
    for k in range(1, len(lo)):
        a0, a1, b0, b1 = lo[k - 1], hi[k - 1], lo[k], hi[k]
        touch = [axis for axis in range(2) if a1[axis] == b0[axis] or b1[axis] == a0[axis]]
        if len(touch) != 1:
            raise ValueError("consecutive cells of a chain must share an edge")
        t = touch[0]
        o = 1 - t
        plane = a1[t] if a1[t] == b0[t] else a0[t]
        forward = 1 if a1[t] == b0[t] else -1
        low, high = max(a0[o], b0[o]), min(a1[o], b1[o])
        margin = min(MARGIN, 0.25 * (high - low))
        p_low, p_high = np.zeros(2), np.zeros(2)
        p_low[t] = p_high[t] = plane * scale[t]
        p_low[o], p_high[o] = (low + margin) * scale[o], (high - margin) * scale[o]
        # left of the direction of travel (+t rotated by +90 degrees) is +o when moving +x or -y
        left_is_high = (forward > 0) == (t == 0)
        out.append((p_high, p_low) if left_is_high else (p_low, p_high))
    return out


def portals(chain: Chain) -> list[tuple[np.ndarray, np.ndarray]]:
    """The portals of a chain of cells (see `box_portals`)."""
    return box_portals(*shifted_boxes(chain), cell_size(chain.cells))


def pull_string(start: np.ndarray, end: np.ndarray, gates: list) -> list[tuple[np.ndarray, int]]:
    """The funnel algorithm: the shortest polyline from start to end crossing every gate (left,
    right) in order; returns its points with the index of the gate each one is on (0: start)."""
    pts = [(tuple(map(float, start)), tuple(map(float, start)))]
    pts += [(tuple(map(float, a)), tuple(map(float, b))) for a, b in gates]
    pts.append((tuple(map(float, end)), tuple(map(float, end))))

    def cross(o, a, b) -> float:
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    apex = left = right = pts[0][0]
    apex_i = left_i = right_i = 0
    path = [(apex, 0)]
    i = 1
    while i < len(pts):
        new_left, new_right = pts[i]
        if cross(apex, right, new_right) >= 0:  # the right side narrows the funnel
            if apex == right or cross(apex, left, new_right) < 0:
                right, right_i = new_right, i
            else:  # it crosses the left side: the path bends at the left point
                path.append((left, left_i))
                apex, apex_i = left, left_i
                left = right = apex
                left_i = right_i = apex_i
                i = apex_i + 1
                continue
        if cross(apex, left, new_left) <= 0:  # the left side narrows the funnel
            if apex == left or cross(apex, right, new_left) > 0:
                left, left_i = new_left, i
            else:
                path.append((right, right_i))
                apex, apex_i = right, right_i
                left = right = apex
                left_i = right_i = apex_i
                i = apex_i + 1
                continue
        i += 1
    last = pts[-1][0]
    if path[-1][0] != last or len(path) == 1:
        path.append((last, len(pts) - 1))
    return [(np.array(p), k) for p, k in path]


def string_length(pulled: list[tuple[np.ndarray, int]]) -> float:
    points = np.array([p for p, _ in pulled])
    return float(np.sum(np.hypot(*np.diff(points, axis=0).T)))


# ---------------------------------------------------------------- 4. corridor


def corridor(cells: Tree, start: np.ndarray, end: np.ndarray, bound: float) -> Chain:
    """Every lifted copy of a cell that holds a point p with |p - start| + |p - end| <= bound
    (points in the space's units from the root's low corner, unwrapped): every polyline from start
    to end no longer than `bound` stays in them."""
    grid = cells.grid
    n = 1 << grid.depth
    scale = cell_size(cells)
    lo, hi = lattice_boxes(cells)
    slack = 1e-9 * (1.0 + bound)
    reach = bound + slack
    ranges = []
    for axis in range(grid.dim):
        a, b = lo[:, axis] * scale[axis], hi[:, axis] * scale[axis]
        if grid.periodic[axis]:
            period = n * scale[axis]
            k0 = np.ceil((start[axis] - reach - b) / period).astype(np.int64)
            k1 = np.floor((start[axis] + reach - a) / period).astype(np.int64)
        else:
            near = (a <= start[axis] + reach) & (b >= start[axis] - reach)
            k0, k1 = np.zeros(len(a), np.int64), np.where(near, 0, -1).astype(np.int64)
        ranges.append((k0, np.maximum(k1 - k0 + 1, 0)))
    count = ranges[0][1] * ranges[1][1]
    leaf = np.repeat(np.arange(len(cells)), count)
    index = np.arange(int(count.sum())) - np.repeat(np.cumsum(count) - count, count)
    shifts = np.column_stack([ranges[0][0][leaf] + index // np.maximum(ranges[1][1][leaf], 1),
                              ranges[1][0][leaf] + index % np.maximum(ranges[1][1][leaf], 1)])
    box_lo = (lo[leaf] + shifts * n) * scale
    box_hi = (hi[leaf] + shifts * n) * scale

    def distance(p):
        return np.hypot(*np.maximum(np.maximum(box_lo - p, p - box_hi), 0.0).T)

    keep = distance(start) + distance(end) <= reach
    return Chain(cells, leaf[keep], shifts[keep])


def corridor_string(lifted: Chain, start: np.ndarray, end: np.ndarray, bound: float):
    """The string pulled through the corridor's rectangles that the shortest polyline from start to
    end crosses (`Slabs.route`), with its gates and the rectangles' bounds (space units); None if
    they are not joined."""
    scale = cell_size(lifted.cells)
    slabs = Slabs(*shifted_boxes(lifted))
    path = slabs.route(start / scale, end / scale, scale, bound)
    if path is None:
        return None
    gates = box_portals(slabs.lo[path], slabs.hi[path], scale)
    return pull_string(start, end, gates), gates, (slabs.lo[path] * scale, slabs.hi[path] * scale)


# ---------------------------------------------------------------- 5. exact check


def _nominal_period(grid, axis: int) -> tuple[Fraction, Fraction]:
    """(rational period, how far it may be from the true one per period): 2 pi to 40 digits when
    the root is the float [-pi, pi], else the root's width (taken as exact)."""
    lo, hi = grid.root[axis]
    if lo == -np.pi and hi == np.pi:
        return 2 * PI_40, Fraction(1, 10 ** 38)
    return Fraction(hi) - Fraction(lo), Fraction(0)


@dataclass(frozen=True)
class Waypoint:
    """A point of the path as written (`at`, floats) and the whole periods it lies below its place
    in the unwrapped chart of the chain (`turns`, integers; 0 on non-periodic axes)."""

    at: np.ndarray
    turns: tuple[int, ...]

    def unwrapped(self, grid) -> np.ndarray:
        return self.at + np.array(self.turns) * grid.size


def waypoint(grid, point: np.ndarray) -> Waypoint:
    """An unwrapped point written in the root box (periodic axes wrapped)."""
    at = np.asarray(point, float).copy()
    turns = [0] * grid.dim
    for axis, wrap in enumerate(grid.periodic):
        if wrap:
            k = int(np.floor((at[axis] - grid.lo[axis]) / grid.size[axis]))
            at[axis] -= k * grid.size[axis]
            if not grid.lo[axis] <= at[axis] < grid.lo[axis] + grid.size[axis]:  # rounding at the seam
                at[axis], k = grid.lo[axis], k + (1 if at[axis] >= grid.lo[axis] else 0)
            turns[axis] = k
    return Waypoint(at, tuple(turns))


class ExactCells:
    """Lifted cells as exact rational boxes (see the module docstring): the dyadic cells of the
    float root box, widened by one ulp of the largest root bound (the paving tested every box
    widened by four), shifted by whole nominal periods. Boxes are made exact only for the cells a
    segment may meet (a float test with generous slack picks them)."""

    def __init__(self, chain: Chain):
        grid = chain.cells.grid
        self.chain, self.grid = chain, grid
        self.n = 1 << grid.depth
        lo_int, hi_int = shifted_boxes(chain)
        self.float_lo = from_lattice(chain.cells, lo_int)
        self.float_hi = from_lattice(chain.cells, hi_int)
        raw_lo, raw_hi = lattice_boxes(chain.cells)
        self.raw_lo, self.raw_hi = raw_lo[chain.leaves], raw_hi[chain.leaves]
        self.widen = Fraction(float(np.spacing(max(abs(v) for r in grid.root for v in r)))) - Fraction(1, 10 ** 30)
        self.periods = [_nominal_period(grid, axis) for axis in range(grid.dim)]
        self._boxes: dict[int, list[tuple[Fraction, Fraction]]] = {}
        self.used: set[int] = set()  # cells whose spans made a segment proven

    def __len__(self) -> int:
        return len(self.chain.leaves)

    def box(self, k: int) -> list[tuple[Fraction, Fraction]]:
        """The exact box of cell k."""
        if k not in self._boxes:
            box = []
            for axis in range(self.grid.dim):
                root_lo, root_hi = (Fraction(v) for v in self.grid.root[axis])
                step = (root_hi - root_lo) / self.n
                shift = int(self.chain.shifts[k, axis]) * self.periods[axis][0]
                box.append((root_lo + int(self.raw_lo[k, axis]) * step - self.widen + shift,
                            root_lo + int(self.raw_hi[k, axis]) * step + self.widen + shift))
            self._boxes[k] = box
        return self._boxes[k]

    def _exact(self, w: Waypoint) -> list[Fraction]:
        return [Fraction(float(v)) + t * period for v, t, (period, _) in zip(w.at, w.turns, self.periods)]

    def _near(self, p: np.ndarray, q: np.ndarray) -> np.ndarray:
        """Cells the float segment p -> q passes within a small slack of."""
        margin = 1e-9 * (1.0 + float(np.max(np.abs(np.concatenate([p, q])))))
        lo, hi = self.float_lo - margin, self.float_hi + margin
        d = q - p
        t0, t1 = np.zeros(len(lo)), np.ones(len(lo))
        for axis in range(len(p)):
            if d[axis] == 0:
                outside = (p[axis] < lo[:, axis]) | (p[axis] > hi[:, axis])
                t0[outside] = 2.0
                continue
            ta, tb = (lo[:, axis] - p[axis]) / d[axis], (hi[:, axis] - p[axis]) / d[axis]
            t0 = np.maximum(t0, np.minimum(ta, tb))
            t1 = np.minimum(t1, np.maximum(ta, tb))
        return np.flatnonzero(t0 <= t1 + 1e-12)

    def covers(self, a: Waypoint, b: Waypoint) -> bool:
        """Whether the straight segment between two written waypoints (each angle moving by the
        difference of their unwrapped places) lies in the cells, exactly. The nominal period is
        within 1e-38 of the true one; the widening keeps 1e-30 of slack for it."""
        p, q = a.unwrapped(self.grid), b.unwrapped(self.grid)
        P, Q = self._exact(a), self._exact(b)
        D = [y - x for x, y in zip(P, Q)]
        used = segment_cover(((k, self.box(k)) for k in self._near(p, q).tolist()), P, D)
        if used is None:
            return False
        self.used.update(used)
        return True


def segment_cover(boxes, start, step) -> list | None:
    """Whether the segment start + t * step, t in [0, 1], lies in the union of the closed boxes
    ((key, box) pairs), exactly: the keys of the boxes that extend its covered part (`covering`),
    or None (a part of it in none of them)."""
    return covering([(*span, k) for k, box in boxes if (span := segment_span(box, start, step))])


def segment_span(box, start, step) -> tuple[Fraction, Fraction] | None:
    """The parameters t in [0, 1] at which start + t * step lies in the closed box ((lo, hi) per
    axis), exactly (fractions: clipping against each axis's slab): (t0, t1), or None when the
    segment misses the box."""
    t0, t1 = Fraction(0), Fraction(1)
    for (lo, hi), x, d in zip(box, start, step):
        if d == 0:
            if not lo <= x <= hi:
                return None
            continue
        ta, tb = (lo - x) / d, (hi - x) / d
        if ta > tb:
            ta, tb = tb, ta
        t0, t1 = max(t0, ta), min(t1, tb)
        if t0 > t1:
            return None
    return t0, t1


def covering(spans) -> list | None:
    """Whether the parameter intervals (t0, t1, key) cover [0, 1]: the keys of those that extend
    the covered part, swept in order of t0, or None (a gap)."""
    reach, used = Fraction(0), []
    for t0, t1, k in sorted(spans):
        if t0 > reach:
            return None
        if t1 > reach:
            used.append(k)
        reach = max(reach, t1)
        if reach >= 1:
            return used
    return None


def lift(chain: Chain, point: np.ndarray) -> Waypoint:
    """The point as written, with the whole periods that place it in the chain's last cell."""
    grid = chain.cells.grid
    n = 1 << grid.depth
    lo, hi = shifted_boxes(chain)
    u = to_lattice(chain.cells, point[None, :])[0]
    turns = [0] * grid.dim
    for axis, wrap in enumerate(grid.periodic):
        if wrap:
            turns[axis] = int(np.round((0.5 * (lo[-1, axis] + hi[-1, axis]) - u[axis]) / n))
    return Waypoint(np.asarray(point, float).copy(), tuple(turns))


MAX_STEP = 3.0  # on a periodic axis, consecutive written waypoints differ by less than this (< pi)


def certified_polyline(chain: Chain, start: np.ndarray, end: Waypoint) -> tuple[list[Waypoint], ExactCells]:
    """Waypoints from `start` to `end` (both kept exactly as given), every segment proven to lie in
    the cells: the shortest of the string pulled through the chain and, for every place of the end
    in the unwrapped chart (`end` lifted by whole periods) that a motion no longer can reach, the
    straight segment when it lies in the cells, else the string pulled through the corridor
    (module docstring). Other waypoints are written wrapped into the root box, and on a periodic
    axis consecutive ones differ by less than MAX_STEP in the unwrapped chart, so each segment is
    the short way round. Raises ValueError if a segment cannot be proven even through the centres
    of the boxes it crosses (it has not been seen to)."""
    cells = chain.cells
    grid = cells.grid
    first = Waypoint(np.asarray(start, float).copy(), (0,) * grid.dim)
    s = np.asarray(start, float) - grid.lo
    gates = portals(chain)
    lo, hi = shifted_boxes(chain)
    pulled = pull_string(s, end.unwrapped(grid) - grid.lo, gates)
    bound = string_length(pulled)
    best = None  # (length, end, exact cells, string or None for the straight segment)
    for target in _lifts(grid, s, end, bound):
        t = target.unwrapped(grid) - grid.lo
        if best is not None and float(np.hypot(*(t - s))) >= best[0]:
            break
        exact = ExactCells(corridor(cells, s, t, bound))
        if exact.covers(first, target):
            best = (float(np.hypot(*(t - s))), target, exact, None)
            continue
        options = [corridor_string(exact.chain, s, t, bound)]
        if target.turns == end.turns:
            options.append((pulled, gates, (lo * cell_size(cells), hi * cell_size(cells))))
        for string in options:
            if string is not None and (best is None or string_length(string[0]) < best[0]):
                best = (string_length(string[0]), target, exact, string)
    _, target, exact, string = best
    if string is None:
        points = [first, target]
    else:
        points = _proven(exact, first, target, *string)
        points = _tidy(points, exact, float(MARGIN * cell_size(cells).max()))
    points = _short_steps(points, exact)
    exact.used.clear()
    for a, b in zip(points, points[1:]):
        exact.covers(a, b)
    return points, exact


def _lifts(grid, start: np.ndarray, end: Waypoint, bound: float) -> list[Waypoint]:
    """The end shifted by whole periods to every place within `bound` of the start (always its own
    place), nearest first."""
    t = end.unwrapped(grid) - grid.lo
    ranges = []
    for axis, wrap in enumerate(grid.periodic):
        if wrap:
            period = float(grid.size[axis])
            lo = int(np.ceil((start[axis] - bound - t[axis]) / period))
            ranges.append(range(min(lo, 0), max(int(np.floor((start[axis] + bound - t[axis]) / period)), 0) + 1))
        else:
            ranges.append(range(0, 1))
    out = []
    for k in ((a, b) for a in ranges[0] for b in ranges[1]):
        place = t + np.array(k) * grid.size
        distance = float(np.hypot(*(place - start)))
        if distance <= bound or k == (0, 0):
            out.append((distance, k, Waypoint(end.at, tuple(int(a + b) for a, b in zip(end.turns, k)))))
    return [w for _, _, w in sorted(out, key=lambda item: item[:2])]


def _proven(exact: ExactCells, first: Waypoint, end: Waypoint, pulled, gates, boxes) -> list[Waypoint]:
    """The pulled string as waypoints, each segment proven. A segment that is not (the string can
    run along an edge of the cells, round an obstacle, where rounding may leave it a hair outside)
    is replaced by the polyline through the points nearest its middle of the boxes it crosses,
    each box shrunk by MARGIN steps, and of the portals between them: every piece then joins a
    point inside a portal to a point inside a box it bounds."""
    grid = exact.grid
    step = cell_size(exact.chain.cells)
    box_lo, box_hi = boxes

    def at(v: np.ndarray) -> Waypoint:
        return waypoint(grid, grid.lo + v)

    def near(v: np.ndarray, lo: np.ndarray, hi: np.ndarray, inset: np.ndarray) -> np.ndarray:
        inset = np.minimum(inset, 0.25 * (hi - lo))
        return np.clip(v, lo + inset, hi - inset)

    points = [first]
    for (u, i), (v, j) in zip(pulled, pulled[1:]):
        target = end if j == len(gates) + 1 else at(v)
        if exact.covers(points[-1], target):
            points.append(target)
            continue
        middle, detour = 0.5 * (u + v), []
        for k in range(i, j):  # box k lies between gate k (k >= 1) and gate k + 1 (gates[k - 1], gates[k])
            if k > i:
                a, b = gates[k - 1]
                detour.append(at(near(middle, np.minimum(a, b), np.maximum(a, b), 0 * step)))
            detour.append(at(near(middle, box_lo[k], box_hi[k], MARGIN * step)))
        for point in detour + [target]:
            if not exact.covers(points[-1], point):
                raise ValueError("a segment of the path could not be proven to lie in certified cells")
            points.append(point)
    return points


def _middle(grid, a: Waypoint, b: Waypoint) -> Waypoint:
    return waypoint(grid, 0.5 * (a.unwrapped(grid) + b.unwrapped(grid)))


def _tidy(points: list[Waypoint], exact: ExactCells, margin: float) -> list[Waypoint]:
    """Fewer waypoints, each change proven like the rest: two waypoints closer than a few portal
    margins (the path turning round one cell corner through two shortened portals) become their
    middle; then a waypoint whose neighbours see each other within the cells is dropped. The ends
    are kept."""
    grid = exact.grid
    out = list(points)
    k = 1
    while k < len(out) - 2:
        p, q = out[k].unwrapped(grid), out[k + 1].unwrapped(grid)
        if np.hypot(*(q - p)) < 4 * margin:
            middle = _middle(grid, out[k], out[k + 1])
            if exact.covers(out[k - 1], middle) and exact.covers(middle, out[k + 2]):
                out[k:k + 2] = [middle]
                continue
        k += 1
    k = 1
    while k < len(out) - 1:
        if exact.covers(out[k - 1], out[k + 1]):
            del out[k]
        else:
            k += 1
    return out


def _short_steps(points: list[Waypoint], exact: ExactCells) -> list[Waypoint]:
    """Split segments that move a periodic axis by MAX_STEP or more at their middles (each half
    proven again), so that every written step is the short way round."""
    grid = exact.grid
    periodic = np.array(grid.periodic)
    out = [points[0]]
    todo = list(points[1:])[::-1]
    while todo:
        b = todo.pop()
        a = out[-1]
        step = np.abs(b.unwrapped(grid) - a.unwrapped(grid))
        if np.any(step[periodic] >= MAX_STEP):
            middle = _middle(grid, a, b)
            if not (exact.covers(a, middle) and exact.covers(middle, b)):
                raise ValueError("a segment of the path could not be proven to lie in certified cells")
            todo += [b, middle]
            continue
        out.append(b)
    return out
