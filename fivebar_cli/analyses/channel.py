"""Shortest-looking polylines through a set of certified cells of a 2-D tree (periodic axes wrap),
each straight segment proven to lie in the cells.

1. Channel: the cells that share an edge of positive length (face adjacency, wrapping around
   periodic axes) form a graph; A* by the distance between cell centres (torus-aware) finds a
   chain of cells from the start's cell to the end's. Face contact, not corner contact: a path
   through a corner shared by two cells only would have to pass through one exact point, which
   floating-point waypoints cannot do.
2. Unwrap: on a torus, each cell of the chain is shifted by whole periods so that consecutive
   cells touch in the plane (the lifted chart in which the path is one continuous polyline).
3. String pulling (the funnel algorithm) through the portals, the edges consecutive cells share,
   each shortened at both ends by a small margin so that the polyline keeps off cell corners.
   The result is the shortest polyline through the shortened portals in that order: between two
   portals it stays in the (convex) cell they bound.
4. Exact check: every segment is checked to lie in the union of the chain's closed cells, in
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
"""

from __future__ import annotations

import heapq
from dataclasses import dataclass
from fractions import Fraction

import numpy as np

from fivebar_cli.paving.tree import Tree

PI_40 = Fraction("3.141592653589793238462643383279502884197")  # within 1e-39 of pi
MARGIN = 2.0 ** -10  # portal shortening, in depth-D cells (at most a quarter of the portal)


@dataclass(frozen=True)
class Chain:
    """Cells of a tree joined edge to edge, with the whole periods each is shifted by."""

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


def containing_leaves(tree: Tree, point: np.ndarray) -> list[int]:
    """The leaves whose closed cell holds the point (periodic axes wrapped), in index order."""
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
    lo, hi = lattice_boxes(tree)
    held = [int(k) for k in leaves if np.all(lo[k] - 1e-7 <= u) and np.all(u <= hi[k] + 1e-7)]
    return sorted(held)


def _wrapped_delta(delta: np.ndarray, grid) -> np.ndarray:
    n = float(1 << grid.depth)
    out = delta.copy()
    for axis, wrap in enumerate(grid.periodic):
        if wrap:
            out[..., axis] = (out[..., axis] + n / 2) % n - n / 2
    return out


# ---------------------------------------------------------------- 1. channel


def _neighbours(cells: Tree) -> tuple[np.ndarray, np.ndarray]:
    """Edge-sharing neighbours as CSR: leaf k's are targets[first[k]:first[k + 1]], in Morton order."""
    i, j = cells.adjacency(corners=False)
    pairs = np.unique(np.column_stack([np.concatenate([i, j]), np.concatenate([j, i])]), axis=0)
    return np.searchsorted(pairs[:, 0], np.arange(len(cells) + 1)), pairs[:, 1]


def face_component(cells: Tree, start: int) -> np.ndarray:
    """The leaves joined to `start` by chains of cells sharing edges (sorted leaf indices)."""
    first, targets = _neighbours(cells)
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
    first, targets = _neighbours(cells)
    lo, hi = lattice_boxes(cells)
    centre = 0.5 * (lo + hi).astype(float)
    guess = np.hypot(*_wrapped_delta(centre - centre[end], cells.grid).T).tolist()
    best = {start: 0.0}
    parent = {start: -1}
    heap = [(guess[start], 0.0, start)]
    done = set()
    while heap:
        _, g, node = heapq.heappop(heap)
        if node in done:
            continue
        done.add(node)
        if node == end:
            break
        near = targets[first[node]:first[node + 1]]
        steps = np.hypot(*_wrapped_delta(centre[near] - centre[node], cells.grid).T)
        for other, step in zip(near.tolist(), steps.tolist()):
            cost = g + step
            if other not in done and cost < best.get(other, np.inf):
                best[other] = cost
                parent[other] = node
                heapq.heappush(heap, (cost + guess[other], cost, other))
    if end not in done:
        return None
    chain = [end]
    while parent[chain[-1]] >= 0:
        chain.append(parent[chain[-1]])
    leaves = np.array(chain[::-1], np.int64)
    return Chain(cells, leaves, _unwrap(cells, leaves, start_point))


# ---------------------------------------------------------------- 2. unwrap


def _unwrap(cells: Tree, leaves: np.ndarray, start_point: np.ndarray) -> np.ndarray:
    """Whole periods per cell so that the first holds the start point and consecutive cells touch."""
    grid = cells.grid
    n = 1 << grid.depth
    lo, hi = lattice_boxes(cells)
    lo, hi = lo[leaves], hi[leaves]
    u = to_lattice(cells, start_point[None, :])[0]
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


def portals(chain: Chain) -> list[tuple[np.ndarray, np.ndarray]]:
    """(left, right) ends of the edge each pair of consecutive cells shares, as seen when moving
    along the chain, shortened by MARGIN (at most a quarter of the edge) at both ends."""
    lo, hi = shifted_boxes(chain)
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
        p_low[t] = p_high[t] = plane
        p_low[o], p_high[o] = low + margin, high - margin
        # left of the direction of travel (+t rotated by +90 degrees) is +o when moving +x or -y
        left_is_high = (forward > 0) == (t == 0)
        out.append((p_high, p_low) if left_is_high else (p_low, p_high))
    return out


def _cross(a: np.ndarray, b: np.ndarray) -> float:
    return float(a[0] * b[1] - a[1] * b[0])


def pull_string(start: np.ndarray, end: np.ndarray, gates: list) -> list[tuple[np.ndarray, int]]:
    """The funnel algorithm: the shortest polyline from start to end crossing every gate (left,
    right) in order; returns its points with the index of the gate each one is on (0: start)."""
    pts = [(start, start)] + list(gates) + [(end, end)]
    apex, left, right = start, start, start
    apex_i = left_i = right_i = 0
    path = [(start, 0)]
    i = 1
    while i < len(pts):
        new_left, new_right = pts[i]
        if _cross(right - apex, new_right - apex) >= 0:  # the right side narrows the funnel
            if np.array_equal(apex, right) or _cross(left - apex, new_right - apex) < 0:
                right, right_i = new_right, i
            else:  # it crosses the left side: the path bends at the left point
                path.append((left, left_i))
                apex, apex_i = left, left_i
                left, right, left_i, right_i = apex, apex, apex_i, apex_i
                i = apex_i + 1
                continue
        if _cross(left - apex, new_left - apex) <= 0:  # the left side narrows the funnel
            if np.array_equal(apex, left) or _cross(right - apex, new_left - apex) > 0:
                left, left_i = new_left, i
            else:
                path.append((right, right_i))
                apex, apex_i = right, right_i
                left, right, left_i, right_i = apex, apex, apex_i, apex_i
                i = apex_i + 1
                continue
        i += 1
    if not np.array_equal(path[-1][0], end) or len(path) == 1:
        path.append((end, len(pts) - 1))
    return path


# ---------------------------------------------------------------- 4. exact check


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
    """The chain's cells as exact rational boxes (see the module docstring): the dyadic cells of
    the float root box, widened by one ulp of the largest root bound (the paving tested every box
    widened by four), shifted by whole nominal periods."""

    def __init__(self, chain: Chain):
        grid = chain.cells.grid
        self.chain, self.grid = chain, grid
        n = 1 << grid.depth
        lo_int, hi_int = shifted_boxes(chain)
        self.float_lo = from_lattice(chain.cells, lo_int)
        self.float_hi = from_lattice(chain.cells, hi_int)
        raw_lo, raw_hi = lattice_boxes(chain.cells)
        raw_lo, raw_hi = raw_lo[chain.leaves], raw_hi[chain.leaves]
        widen = Fraction(float(np.spacing(max(abs(v) for r in grid.root for v in r)))) - Fraction(1, 10 ** 30)
        self.periods = [_nominal_period(grid, axis) for axis in range(grid.dim)]
        self.boxes = []
        for k in range(len(chain.leaves)):
            box = []
            for axis in range(grid.dim):
                root_lo, root_hi = (Fraction(v) for v in grid.root[axis])
                step = (root_hi - root_lo) / n
                shift = int(chain.shifts[k, axis]) * self.periods[axis][0]
                box.append((root_lo + int(raw_lo[k, axis]) * step - widen + shift,
                            root_lo + int(raw_hi[k, axis]) * step + widen + shift))
            self.boxes.append(box)

    def _exact(self, w: Waypoint) -> list[Fraction]:
        return [Fraction(float(v)) + t * period for v, t, (period, _) in zip(w.at, w.turns, self.periods)]

    def covers(self, a: Waypoint, b: Waypoint) -> bool:
        """Whether the straight segment between two written waypoints (each angle moving by the
        difference of their unwrapped places) lies in the cells, exactly. The nominal period is
        within 1e-38 of the true one; the widening keeps 1e-30 of slack for it."""
        p, q = a.unwrapped(self.grid), b.unwrapped(self.grid)
        margin = 1e-9 * (1.0 + float(np.max(np.abs(np.concatenate([p, q])))))
        seg_lo, seg_hi = np.minimum(p, q) - margin, np.maximum(p, q) + margin
        near = np.flatnonzero(np.all((self.float_hi >= seg_lo) & (self.float_lo <= seg_hi), axis=1))
        P, Q = self._exact(a), self._exact(b)
        D = [y - x for x, y in zip(P, Q)]
        spans = []
        for k in near:
            t0, t1 = Fraction(0), Fraction(1)
            for (lo, hi), x, d in zip(self.boxes[k], P, D):
                if d == 0:
                    if not lo <= x <= hi:
                        t0, t1 = Fraction(1), Fraction(0)
                        break
                    continue
                ta, tb = (lo - x) / d, (hi - x) / d
                if ta > tb:
                    ta, tb = tb, ta
                t0, t1 = max(t0, ta), min(t1, tb)
                if t0 > t1:
                    break
            if t0 <= t1:
                spans.append((t0, t1))
        reach = Fraction(0)
        for t0, t1 in sorted(spans):
            if t0 > reach:
                return False
            reach = max(reach, t1)
            if reach >= 1:
                return True
        return False


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
    the chain's cells; other waypoints are written wrapped into the root box, and on a periodic
    axis consecutive ones differ by less than MAX_STEP in the unwrapped chart, so each segment is
    the short way round. Raises ValueError if a segment cannot be proven even through the
    middles of the portals it crosses (it has not been seen to)."""
    cells = chain.cells
    grid = cells.grid
    gates = portals(chain)
    first = Waypoint(np.asarray(start, float).copy(), (0,) * grid.dim)
    pulled = pull_string(to_lattice(cells, start[None, :])[0], to_lattice(cells, end.unwrapped(grid)[None, :])[0], gates)
    exact = ExactCells(chain)

    def at(u: np.ndarray) -> Waypoint:
        return waypoint(grid, from_lattice(cells, u[None, :])[0])

    points = [first]
    for (_, i), (v, j) in zip(pulled, pulled[1:]):
        target = end if j == len(gates) + 1 else at(v)
        if exact.covers(points[-1], target):
            points.append(target)
            continue
        for g in range(i + 1, j):  # through the middles of the portals crossed
            middle = at(0.5 * (gates[g - 1][0] + gates[g - 1][1]))
            if not exact.covers(points[-1], middle):
                raise ValueError("a segment of the path could not be proven to lie in certified cells")
            points.append(middle)
        if not exact.covers(points[-1], target):
            raise ValueError("a segment of the path could not be proven to lie in certified cells")
        points.append(target)
    points = _tidy(points, exact, float(MARGIN * grid.size.max() / (1 << grid.depth)))
    return _short_steps(points, exact), exact


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
