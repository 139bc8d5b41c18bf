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

Distances. The complement's small cells are filed by the level-8 cells (level 9 on grids of
depth 14 or more: buckets) they meet; f at all the centres of a round is one vectorised pass over
(centre, cell) pairs: the cells of the buckets that meet the ball of radius f' around the centre, f' an upper bound on f (the box's bound,
the distance to the root's outside, to the big cells, and to the cell nearest its parent's
centre). Any cell nearer than f' is among them, so f is the minimum over every cell, whichever
were looked at: the same float.

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
import functools
import math

import numpy as np

from fivebar_cli.paving.arrays import unique
from fivebar_cli.paving.morton import deinterleave
from fivebar_cli.paving.tree import Tree

TOLERANCE = 0.01  # relative: the result is at least (1 - TOLERANCE) times the optimum
MAX_ROUNDS = 60
# complement cells above the big level are few: looked at for every centre; the others are filed
# by the cells of the bucket level they meet. Deeper grids have more fine cells in a bucket: finer
# buckets (fewer cells looked at for a centre) pay for their cost there.
LEVELS = {False: (6, 8), True: (8, 9)}  # (big level, bucket level), by grid depth >= DEEP
DEEP = 14
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
    """The complement cells and the root box, with distances from centres. The small cells (level
    >= the big level) are filed by the cells of the bucket level (buckets) they meet, bucket column
    by bucket column, so the cells of the buckets a box overlaps are a few runs of entries; the
    few big ones are looked at for every centre."""

    def __init__(self, tree: Tree):
        self.tree = tree
        self.cells = tree.complement()
        grid, level = tree.grid, self.cells.level
        coords = deinterleave(self.cells.code, level, 2)
        self.x0, self.x1 = _axis_bounds(grid, coords, level, 0)
        self.y0, self.y1 = _axis_bounds(grid, coords, level, 1)
        big_level, self.bucket_level = LEVELS[grid.depth >= DEEP]
        bucket_level = self.bucket_level
        self.big = np.flatnonzero(level < big_level)
        self.root_lo, self.root_hi = grid.lo, grid.lo + grid.size
        # each small cell filed in every bucket (cell of the bucket level) it meets, column by column:
        # a fine cell (level >= bucket level) in one, a coarse one in 4^(bucket level - level)
        n = 1 << bucket_level
        self.bucket_width = grid.size / n
        fine = np.flatnonzero(level >= bucket_level)
        table = _bucket_of_code(bucket_level)
        fine_bucket = table[self.cells.code[fine] >> (2 * (level[fine] - bucket_level))]
        coarse = np.flatnonzero((level >= big_level) & (level < bucket_level))
        span = 1 << (bucket_level - level[coarse])  # buckets a side
        count = span * span
        within = np.arange(int(count.sum())) - np.repeat(np.cumsum(count) - count, count)
        side = np.repeat(span, count)
        coarse_ij = (np.repeat(coords[coarse] * span[:, None], count, axis=0)
                     + np.stack([within // side, within % side], axis=1))
        del coords
        entry = np.concatenate([fine, np.repeat(coarse, count)])
        bucket = np.concatenate([fine_bucket, (coarse_ij[:, 0] * n + coarse_ij[:, 1]).astype(table.dtype)])
        del fine_bucket, coarse_ij
        by_bucket = np.argsort(bucket, kind="stable")  # (a radix sort with 16-bit keys)
        self.entries = entry[by_bucket]
        self.runs = np.concatenate([[0], np.cumsum(np.bincount(bucket, minlength=n * n))])  # bucket b: runs[b]:runs[b + 1]

    def distance(self, metric: str, centres: np.ndarray, bounds: np.ndarray | None = None) -> np.ndarray:
        """f at each centre: the distance to the nearest complement cell or to the outside of the
        root; `bounds` (upper bounds on f, one per centre) limit the cells looked at."""
        return self.nearest(metric, centres, bounds)[0]

    def nearest(self, metric: str, centres: np.ndarray, bounds: np.ndarray | None = None,
                hint: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        """(f, a nearest cell's index here, -1 where the root's outside is nearer) at each centre.
        Only the small cells in the buckets that meet the ball of the centre and radius f' are
        looked at, f' the least of the bound, the distance to the root's outside, to the nearest
        big cell and to the `hint` cell (-1: none), each at least f: a cell nearer than f' meets
        it. Each cell's distance is the same float whatever the cells looked at, so f is too (a
        bound that is truly above f leaves it alone)."""
        m = len(centres)
        out = np.min(np.concatenate([centres - self.root_lo, self.root_hi - centres], axis=1), axis=1)
        cell = np.full(m, -1, dtype=np.int64)
        if not len(self.x0):
            return out, cell
        cx, cy = centres[:, 0], centres[:, 1]
        self._nearest_big(metric, centres, out, cell)
        reach = out.copy() if bounds is None else np.minimum(bounds, out)
        if hint is not None:
            has = np.flatnonzero(hint >= 0)
            h = hint[has]
            d = _cell_distance(metric, cx[has], cy[has], self.x0[h], self.x1[h], self.y0[h], self.y1[h])
            reach[has] = np.minimum(reach[has], d)
        for which, near in self._pairs(centres, reach, metric):
            d = _cell_distance(metric, cx[which], cy[which], self.x0[near], self.x1[near], self.y0[near], self.y1[near])
            # each centre's pairs are one run (`_pairs`): its least distance by a segmented minimum
            first = np.flatnonzero(np.r_[True, which[1:] != which[:-1]]) if len(which) else np.zeros(0, np.int64)
            if len(first):
                held = which[first]
                out[held] = np.minimum(out[held], np.minimum.reduceat(d, first))
            at = np.flatnonzero(d == out[which])
            cell[which[at]] = near[at]
        return out, cell

    def beside(self, start: np.ndarray, centres: np.ndarray, metric: str) -> np.ndarray:
        """Per leaf of the set (its first depth-D Morton index, its centre): the nearer of the two
        complement cells next to it in Morton order (-1: none), a first hint for `nearest`."""
        if not len(self.x0):
            return np.full(len(start), -1, np.int64)
        after = np.searchsorted(self.cells.start, start)
        before = np.maximum(after - 1, 0)
        after = np.minimum(after, len(self.x0) - 1)
        d = [_cell_distance(metric, centres[:, 0], centres[:, 1], self.x0[k], self.x1[k], self.y0[k], self.y1[k])
             for k in (before, after)]
        return np.where(d[0] <= d[1], before, after)

    def _pairs(self, centres: np.ndarray, reach: np.ndarray, metric: str = "linf", most: int = 1 << 17):
        """(centre index, small cell index) pairs, a chunk of at most about `most` at a time: the
        small cells of the buckets that meet the ball ("l2": disc, "linf": square) of each centre
        and radius its reach, a run of buckets per bucket column (a margin of 1e-6 bucket, and of
        1e-9 relative on the radius, keeps every cell nearer than the reach, float rounding or not)."""
        n = 1 << self.bucket_level
        reach = np.maximum(reach, 0.0)  # (negative outside the root: no cell is nearer)
        (wx, wy), (x, y) = self.bucket_width, (centres - self.root_lo).T  # from the root's corner
        a = np.clip(np.floor((x - reach) / wx - 1e-6), 0, n - 1).astype(np.int64)
        z = np.clip(np.floor((x + reach) / wx + 1e-6), 0, n - 1).astype(np.int64)
        columns = z - a + 1
        owner = np.repeat(np.arange(len(centres)), columns)
        i = np.arange(len(owner)) - np.repeat(np.cumsum(columns) - columns, columns) + a[owner]
        y, h = y[owner], reach[owner]
        if metric == "l2":  # the disc's chord over the column: half height sqrt(r^2 - gap^2)
            gap = np.maximum(np.maximum(i * wx - x[owner], x[owner] - (i + 1) * wx), 0.0)
            h = np.sqrt(np.maximum((h * (1 + 1e-9)) ** 2 - gap * gap, 0.0))
        lo_y = np.clip(np.floor((y - h) / wy - 1e-6), 0, n - 1).astype(np.int64)
        hi_y = np.clip(np.floor((y + h) / wy + 1e-6), 0, n - 1).astype(np.int64)
        run_start = self.runs[i * n + lo_y]
        length = self.runs[i * n + hi_y + 1] - run_start
        per_centre = np.bincount(owner, length, minlength=len(centres)).astype(np.int64)
        chunk = np.cumsum(per_centre) // most
        run_chunk = chunk[owner]
        for c in unique(chunk).tolist():
            runs = run_chunk == c
            lengths = length[runs]
            total = int(lengths.sum())
            skip = np.repeat(np.cumsum(lengths) - lengths - run_start[runs], lengths)
            yield np.repeat(owner[runs], lengths), self.entries[np.arange(total) - skip]

    def _nearest_big(self, metric, centres, out, cell) -> None:
        """Lower `out` to the distance of the nearest big cell (a few, looked at for every centre,
        all at once), and set `cell` where one is nearer."""
        big = self.big
        if not len(big):
            return
        d = _cell_distance(metric, centres[:, :1], centres[:, 1:], self.x0[big], self.x1[big], self.y0[big], self.y1[big])
        k = d.argmin(axis=1)
        d = d[np.arange(len(d)), k]
        nearer = d < out
        out[nearer] = d[nearer]
        cell[nearer] = big[k[nearer]]

    def near(self, metric: str, centre, radius: float) -> np.ndarray:
        """Indices (in the complement tree) of the cells within `radius` of `centre`, in floats."""
        centres = np.array([centre], dtype=float)
        cell = np.concatenate([c for _, c in self._pairs(centres, np.array([radius], dtype=float), metric)]
                              + [self.big])
        cx, cy = centre
        d = _cell_distance(metric, cx, cy, self.x0[cell], self.x1[cell], self.y0[cell], self.y1[cell])
        return unique(cell[d <= radius])  # (a cell may sit in several buckets)


def _axis_bounds(grid, coords: np.ndarray, level: np.ndarray, axis: int) -> tuple[np.ndarray, np.ndarray]:
    """The cells' bounds (lo, hi) along one axis, the floats of `cell_bounds` (lo + coord * width,
    then + width; the widths, powers of two, looked up by level), written into the two arrays
    with no temporary of every cell: the shapes of the largest aspect were the peak memory of a
    whole analysis, and `cell_bounds`' per-cell `ldexp` and (m, 2) temporaries most of the
    obstacles' making after the complement."""
    widths = np.ldexp(grid.size[axis], -np.arange(int(level.max()) + 1 if len(level) else 1))
    width = widths[level]
    lo = np.multiply(coords[:, axis], width)
    lo += grid.lo[axis]
    width += lo
    return lo, width


@functools.cache
def _bucket_of_code(bucket_level: int) -> np.ndarray:
    """The bucket number (column by column) of each cell of the bucket level, by its Morton code:
    a fine cell's bucket is its ancestor's code looked up (no coordinates gathered)."""
    n = 1 << bucket_level
    ij = deinterleave(np.arange(n * n), bucket_level, 2)
    return (ij[:, 0] * n + ij[:, 1]).astype(np.uint16 if bucket_level <= 8 else np.uint32)  # (16-bit: a radix sort)


def _cell_distance(metric: str, cx, cy, x0, x1, y0, y1) -> np.ndarray:
    """The distance ("l2" or "linf") from points (cx, cy) to cells [x0, x1] x [y0, y1], in floats
    (0 inside a cell); the arrays broadcast (every centre against every cell)."""
    gx = np.maximum(np.maximum(x0 - cx, cx - x1), 0.0)
    gy = np.maximum(np.maximum(y0 - cy, cy - y1), 0.0)
    return np.hypot(gx, gy) if metric == "l2" else np.maximum(gx, gy)


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
    levels = np.flatnonzero(np.bincount(tree.level))
    first = np.zeros(levels[-1] + 1, np.int64)
    first[tree.level[::-1]] = np.arange(len(tree) - 1, -1, -1)  # (the last write wins: each level's first leaf)
    lo, hi = tree.bounds(first[levels])
    width = hi - lo
    inner = 0.5 * width.min(axis=1)  # f >= this at a leaf's centre (the leaf is in the set)
    best = float(inner.max())
    bound = 4.0 * _reach(width, metric)  # on a canonical leaf: its parent holds a complement point
    kept = np.zeros(levels[-1] + 1, bool)
    kept[levels[bound > best]] = True
    keep = np.flatnonzero(kept[tree.level])
    lo, hi = tree.bounds(keep)
    width = hi - lo
    bound = 4.0 * _reach(width, metric)
    hint = obstacles.beside(tree.start[keep], lo + 0.5 * width, metric)
    best_centre = None
    for _ in range(MAX_ROUNDS):
        if not len(lo):
            break
        centres = lo + 0.5 * width
        f, near = obstacles.nearest(metric, centres, bound, hint)
        k = int(np.argmax(f))
        if best_centre is None or f[k] > best:
            best, best_centre = float(f[k]), centres[k]
        upper = f + _reach(width, metric)
        alive = upper > best * (1.0 + TOLERANCE)
        lo, width, upper, near = lo[alive], width[alive], upper[alive], near[alive]
        hint = np.concatenate([near] * 4)  # a child's distance to its parent's nearest cell: a bound
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
