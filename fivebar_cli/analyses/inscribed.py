"""The largest disc and the largest axis-aligned square inside a 2-D tree's cells (a union of
closed boxes), found within `TOLERANCE` of the optimum and certified by exact arithmetic.

Search. f(c), the distance (Euclidean for the disc, Chebyshev for the square) from a centre c to
the cells *not* in the set (the complement tree's leaves and the outside of the root box), is the
radius (half side) of the largest disc (square) centred at c; it is 1-Lipschitz, so over a box of
centres f <= f(box centre) + half its diagonal (half its widest side). Branch and bound on the
set's leaves: a canonical leaf of side s has a parent that is not all in the set, so f <= 2 s
hypot(1, 1) on it, while the largest leaf already gives f >= s_max / 2: only leaves at most three
levels below the largest can hold the optimum. Boxes whose bound is not above the best value by
more than the tolerance are dropped, the others split in four, until none is left: the result is
within TOLERANCE of the best that the cells allow.

Certificate. The reported numbers are those written to CSV (`%.10g`): the centre is rounded to 10
significant digits, the radius (side) rounded *down* to 10 digits, then checked exactly (Python
fractions on the exact dyadic cells of the grid): the closed disc (square) stays in the root box
and meets no complement cell in more than boundary points, hence lies in the union of the set's
closed cells (a point of it outside every set cell would lie inside a complement cell). Only the
complement cells whose floating-point distance is within a relative 1e-6 of the radius are
checked exactly: rounding errs by about 1e-15 relative, so the others are certainly farther.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
import math

import numpy as np

from fivebar_cli.paving.morton import deinterleave
from fivebar_cli.paving.tree import Tree

TOLERANCE = 0.01  # relative: the result is at least (1 - TOLERANCE) times the optimum
MAX_ROUNDS = 60
BIG_LEVEL = 6  # complement cells above this level are few: looked at for every centre
NEAR = 1e-6  # complement cells within this relative margin of the radius are checked exactly


@dataclass(frozen=True)
class Disc:
    x: float
    y: float
    r: float


@dataclass(frozen=True)
class Square:
    x: float  # centre
    y: float
    side: float


def largest_disc(tree: Tree, obstacles: "_Obstacles | None" = None) -> Disc | None:
    """The largest disc in the tree's cells (within TOLERANCE), certified; None for an empty tree."""
    found = _search(tree, "l2", obstacles)
    if found is None:
        return None
    (x, y), r = found
    return Disc(x, y, r)


def largest_square(tree: Tree, obstacles: "_Obstacles | None" = None) -> Square | None:
    """The largest axis-aligned square in the tree's cells (within TOLERANCE), certified; None when empty."""
    found = _search(tree, "linf", obstacles)
    if found is None:
        return None
    (x, y), half = found
    return Square(x, y, 2.0 * half)  # exact: the half side is a 10-digit side halved


def largest_shapes(tree: Tree) -> tuple[Disc | None, Square | None]:
    """`largest_disc` and `largest_square` of one tree, from one complement of its cells."""
    obstacles = _Obstacles(tree) if len(tree) and tree.grid.dim == 2 else None
    return largest_disc(tree, obstacles), largest_square(tree, obstacles)


# ---------------------------------------------------------------- search


class _Obstacles:
    """The complement cells (sorted by their low x) and the root box, with distances from centres."""

    def __init__(self, tree: Tree):
        self.tree = tree
        self.cells = tree.complement()
        lo, hi = self.cells.bounds()
        # small cells sorted by their low x (found by bisection); the few big ones always looked at
        big = self.cells.level < BIG_LEVEL
        order = np.concatenate([np.flatnonzero(~big)[np.argsort(lo[~big, 0], kind="stable")], np.flatnonzero(big)])
        self.order = order
        self.x0, self.y0 = lo[order, 0], lo[order, 1]  # contiguous: sliced per centre
        self.x1, self.y1 = hi[order, 0], hi[order, 1]
        self.n_small = int(np.count_nonzero(~big))
        self.widest = float((hi[~big, 0] - lo[~big, 0]).max()) if self.n_small else 0.0
        self.root_lo, self.root_hi = tree.grid.lo, tree.grid.lo + tree.grid.size

    def distance(self, metric: str, centres: np.ndarray, bounds: np.ndarray | None = None) -> np.ndarray:
        """f at each centre: the distance to the nearest complement cell or to the outside of the
        root. `bounds` (upper bounds on f, one per centre) limit the cells looked at."""
        out = np.min(np.concatenate([centres - self.root_lo, self.root_hi - centres], axis=1), axis=1)
        if not len(self.x0):
            return out
        bounds = out if bounds is None else np.minimum(bounds, out)
        xs = self.x0[:self.n_small]
        from_x, to_x = centres[:, 0] - bounds - self.widest, centres[:, 0] + bounds
        first = np.searchsorted(xs, from_x, side="left")
        last = np.searchsorted(xs, to_x, side="right")
        self._nearest_big(metric, centres, bounds, out)
        cx_lo, cy_lo, cy_hi = centres[:, 0] - bounds, centres[:, 1] - bounds, centres[:, 1] + bounds
        cells = self.x0, self.x1, self.y0, self.y1
        for group in _near_one_another(centres, bounds):
            if len(group) == 1:
                k = int(group[0])
                out[k] = _nearest(metric, centres[k], bounds[k], [v[first[k]:last[k]] for v in cells], out[k])
                continue
            # the small cells any centre of the group may look at, found in one pass over their
            # common span; each centre then looks at those of its own span (the same cells as in
            # a pass of its own: its span's cells that pass its test all pass the group's)
            a, z = first[group].min(), last[group].max()
            keep = a + np.flatnonzero((self.y0[a:z] <= cy_hi[group].max()) & (self.y1[a:z] >= cy_lo[group].min())
                                      & (self.x1[a:z] >= cx_lo[group].min()))
            kept = [v[keep] for v in cells]
            starts = np.searchsorted(kept[0], from_x[group], side="left")
            stops = np.searchsorted(kept[0], to_x[group], side="right")
            for k, i, j in zip(group.tolist(), starts.tolist(), stops.tolist()):
                out[k] = _nearest(metric, centres[k], bounds[k], [v[i:j] for v in kept], out[k])
        return out

    def _nearest_big(self, metric, centres, bounds, out) -> None:
        """Lower `out` to the distance of the nearest big cell (a few, looked at for every centre,
        all at once) that the centre's bound does not rule out by its extent alone."""
        big = slice(self.n_small, len(self.x0))
        if big.start == big.stop:
            return
        cx, cy, b = centres[:, :1], centres[:, 1:], bounds[:, None]
        x0, x1, y0, y1 = self.x0[big], self.x1[big], self.y0[big], self.y1[big]
        d = _cell_distance(metric, cx, cy, x0, x1, y0, y1)
        d[~((y0 <= cy + b) & (y1 >= cy - b) & (x1 >= cx - b))] = np.inf
        np.minimum(out, d.min(axis=1), out=out)

    def near(self, metric: str, centre, radius: float) -> np.ndarray:
        """Indices (in the complement tree) of the cells within `radius` of `centre`, in floats."""
        cx, cy = centre
        d = _cell_distance(metric, cx, cy, self.x0, self.x1, self.y0, self.y1)
        return np.sort(self.order[d <= radius], kind="stable")


def _nearest(metric: str, centre: np.ndarray, b: float, cells: list[np.ndarray], best: float) -> float:
    """min(best, the distance from the centre to the nearest of these cells (x0, x1, y0, y1) whose
    extent reaches within b of it)."""
    (cx, cy), (x0, x1, y0, y1) = centre, cells
    near = np.flatnonzero((y0 <= cy + b) & (y1 >= cy - b) & (x1 >= cx - b))
    if not len(near):
        return best
    d = _cell_distance(metric, cx, cy, x0[near], x1[near], y0[near], y1[near])
    return min(best, float(d.min()))


def _cell_distance(metric: str, cx, cy, x0, x1, y0, y1) -> np.ndarray:
    """The distance ("l2" or "linf") from points (cx, cy) to cells [x0, x1] x [y0, y1], in floats
    (0 inside a cell); the arrays broadcast (every centre against every cell)."""
    gx = np.maximum(np.maximum(x0 - cx, cx - x1), 0.0)
    gy = np.maximum(np.maximum(y0 - cy, cy - y1), 0.0)
    return np.hypot(gx, gy) if metric == "l2" else np.maximum(gx, gy)


def _near_one_another(centres: np.ndarray, bounds: np.ndarray) -> list[np.ndarray]:
    """The centres in groups (index arrays) whose centres lie within half the group's smallest
    bound of one another along each axis: their cells to look at mostly coincide. Late
    rounds of the search, around the optimum, make one group; early ones mostly groups of one."""
    order = np.lexsort((centres[:, 1], centres[:, 0]))
    groups, current = [], []
    for k in order.tolist():
        if current:
            x, y = centres[current + [k], 0], centres[current + [k], 1]
            reach = 0.5 * min(bounds[current].min(), bounds[k])
            if x.max() - x.min() > reach or y.max() - y.min() > reach:
                groups.append(np.array(current))
                current = []
        current.append(k)
    if current:
        groups.append(np.array(current))
    return groups


def _reach(width: np.ndarray, metric: str) -> np.ndarray:
    """How far f can rise above its value at a box's centre: half the diagonal (half the widest side)."""
    return 0.5 * (np.hypot(width[:, 0], width[:, 1]) if metric == "l2" else width.max(axis=1))


def _search(tree: Tree, metric: str, obstacles: "_Obstacles | None" = None):
    """Branch and bound for the best centre, then the certified (centre, radius or half side)."""
    if tree.grid.dim != 2:
        raise ValueError("inscribed shapes are for 2-D trees")
    if not len(tree):
        return None
    obstacles = obstacles or _Obstacles(tree)
    # which leaves may hold the optimum depends on their level alone (widths are powers of two
    # apart, far from the factor 4 sqrt 2 of the test): one leaf a level decides, only those kept
    # get their bounds
    levels, first = np.unique(tree.level, return_index=True)
    lo, hi = tree.bounds(first)
    width = hi - lo
    inner = 0.5 * width.min(axis=1)  # f >= this at a leaf's centre (the leaf is in the set)
    best = float(inner.max())
    bound = 4.0 * _reach(width, metric)  # on a canonical leaf: its parent holds a complement point
    keep = np.flatnonzero(np.isin(tree.level, levels[bound > best]))
    lo, hi = tree.bounds(keep)
    width = hi - lo
    bound = 4.0 * _reach(width, metric)
    best_centre = None
    for _ in range(MAX_ROUNDS):
        if not len(lo):
            break
        centres = lo + 0.5 * width
        f = obstacles.distance(metric, centres, bound)
        k = int(np.argmax(f))
        if best_centre is None or f[k] > best:
            best, best_centre = float(f[k]), centres[k]
        upper = f + _reach(width, metric)
        alive = upper > best * (1.0 + TOLERANCE)
        lo, width, upper = lo[alive], width[alive], upper[alive]
        half = 0.5 * width
        lo = np.concatenate([lo, lo + half * [1, 0], lo + half * [0, 1], lo + half])
        width = np.concatenate([half] * 4)
        bound = np.concatenate([upper] * 4)  # f at a child's centre is at most its parent's bound
    return _certify(obstacles, metric, best_centre)


# ---------------------------------------------------------------- certificate


def _round_down(value: float) -> float:
    """The largest number of at most 10 significant digits that is below `value` (by > 1e-12 relative)."""
    if value <= 0:
        return 0.0
    quantum = 10.0 ** (math.floor(math.log10(value)) - 9)
    out = float(f"{math.floor(value * (1 - 1e-12) / quantum) * quantum:.10g}")
    while out >= value * (1 - 1e-12):
        out = float(f"{out - quantum:.10g}")
    return out


def _exact_cells(tree: Tree, index: np.ndarray) -> list[tuple[Fraction, Fraction, Fraction, Fraction]]:
    """Exact dyadic bounds (x0, x1, y0, y1) of some leaves of a tree, on the grid's float root box."""
    grid = tree.grid
    (ax, bx), (ay, by) = grid.root
    out = []
    coords = deinterleave(tree.code[index], tree.level[index], grid.dim)
    for level, (cx, cy) in zip(tree.level[index].tolist(), coords.tolist()):
        n = 1 << level
        fx, fy = (Fraction(bx) - Fraction(ax)) / n, (Fraction(by) - Fraction(ay)) / n
        out.append((Fraction(ax) + cx * fx, Fraction(ax) + (cx + 1) * fx,
                    Fraction(ay) + cy * fy, Fraction(ay) + (cy + 1) * fy))
    return out


def _contained(obstacles: _Obstacles, metric: str, centre: tuple[float, float], radius: float) -> bool:
    """Exactly: the closed disc (square) of this centre and radius (half side) lies in the root box
    and meets no complement cell in more than boundary points."""
    cx, cy = (Fraction(v) for v in centre)
    r = Fraction(radius)
    (ax, bx), (ay, by) = obstacles.tree.grid.root
    if not (Fraction(ax) + r <= cx <= Fraction(bx) - r and Fraction(ay) + r <= cy <= Fraction(by) - r):
        return False
    if not len(obstacles.x0):
        return True
    slack = 1e-9 * float(np.max(np.abs(obstacles.tree.grid.root)))
    for x0, x1, y0, y1 in _exact_cells(obstacles.cells, obstacles.near(metric, centre, radius * (1 + NEAR) + slack)):
        gx = max(x0 - cx, cx - x1, Fraction(0))
        gy = max(y0 - cy, cy - y1, Fraction(0))
        if metric == "l2":
            if gx * gx + gy * gy < r * r:
                return False
        elif max(gx, gy) < r:
            return False
    return True


def _certify(obstacles: _Obstacles, metric: str, centre: np.ndarray):
    """The centre rounded to 10 digits and the radius (half side) rounded down, checked exactly;
    shrunk by 1e-9 relative steps if rounding ever defeats the check (it has not been seen to)."""
    c = tuple(float(f"{v:.10g}") for v in centre)
    value = float(obstacles.distance(metric, np.array([c]))[0])
    if metric == "linf":  # the side is what gets rounded: make the half side exact
        radius = _round_down(2.0 * value) / 2.0
    else:
        radius = _round_down(value)
    for _ in range(8):
        if radius <= 0:
            break
        if _contained(obstacles, metric, c, radius):
            return c, radius
        radius = _round_down(radius * (1 - 1e-9)) if metric == "l2" else _round_down(2 * radius * (1 - 1e-9)) / 2
    return c, 0.0
