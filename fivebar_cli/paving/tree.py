"""2^n-trees (quadtrees, octrees) as sets of cells: canonical leaves, set operations, point
location, adjacency and connected components (with periodic axes), rasters and slices.

A tree is stored as its black leaves only, each a (level, Morton code) pair, in canonical form:
no 2^n sibling leaves are all black (they would be one leaf of their parent). At the finest
level D every leaf is a run of consecutive depth-D Morton indices, so a set of cells is also a
union of integer intervals, and union, intersection and difference become interval sweeps.
All hot paths are numpy-vectorised over leaves; nothing recurses per cell in Python.
"""

from __future__ import annotations

import numpy as np

from fivebar_cli.paving.arrays import index_type, unique
from fivebar_cli.paving.codec import BodyError, decode, encode
from fivebar_cli.paving.grid import Grid
from fivebar_cli.paving.morton import aligned_blocks, axis_mask, deinterleave, finest_key, finest_order, interleave

__all__ = ["Tree", "BodyError", "cell_bounds", "finest_indices", "union_find", "union_find_blocks", "root_labels"]

PAIR_CHUNK = 1 << 18  # leaves whose neighbours are looked up together


class Tree:
    """A set of cells of a `Grid`, as canonical black leaves sorted in Morton (preorder) order."""

    def __init__(self, grid: Grid, level: np.ndarray, code: np.ndarray, *, canonical: bool = False):
        self.grid = grid
        level = np.asarray(level, dtype=np.int64).ravel()
        code = np.asarray(code, dtype=np.int64).ravel()
        if not canonical:
            level, code = _canonical(grid, level, code)
        self.level, self.code = level, code

    # -- construction

    @classmethod
    def empty(cls, grid: Grid) -> "Tree":
        return cls(grid, np.zeros(0), np.zeros(0), canonical=True)

    @classmethod
    def full(cls, grid: Grid) -> "Tree":
        return cls(grid, np.zeros(1), np.zeros(1), canonical=True)

    @classmethod
    def from_cells(cls, grid: Grid, level: np.ndarray, coords: np.ndarray) -> "Tree":
        """Tree of disjoint cells given by level and integer coordinates (shape (m, dim))."""
        level = np.broadcast_to(np.asarray(level, dtype=np.int64), (len(coords),))
        return cls(grid, level, interleave(coords, level) if len(coords) else np.zeros(0))

    @classmethod
    def from_intervals(cls, grid: Grid, start: np.ndarray, end: np.ndarray) -> "Tree":
        """Tree of the union of disjoint, sorted depth-D index intervals [start, end)."""
        level, code = _blocks(grid, *_merge_touching(start, end))
        return cls(grid, level, code, canonical=True)

    # -- basic properties

    def __len__(self) -> int:
        return int(self.level.size)

    def __eq__(self, other: object) -> bool:
        return (
            isinstance(other, Tree)
            and self.grid == other.grid
            and np.array_equal(self.level, other.level)
            and np.array_equal(self.code, other.code)
        )

    def __repr__(self) -> str:
        return f"Tree({len(self)} leaves, depth {self.grid.depth}, area {self.area:.6g})"

    @property
    def start(self) -> np.ndarray:
        """First depth-D Morton index of each leaf (a shift: computed when asked, not kept)."""
        return finest_key(self.code, self.level, self.grid.dim, self.grid.depth)

    @property
    def end(self) -> np.ndarray:
        """One past the last depth-D Morton index of each leaf (computed when asked, not kept: a
        tree's memory is its leaves, 16 bytes each)."""
        return self.start + self._sizes(self.level)

    def _sizes(self, level: np.ndarray) -> np.ndarray:
        """How many depth-D cells a leaf of each level holds: it covers the depth-D Morton indices
        [start, start + size)."""
        return np.int64(1) << (self.grid.dim * (self.grid.depth - level))

    @property
    def coords(self) -> np.ndarray:
        """Integer coordinates of each leaf at its own level, shape (m, dim) (computed when asked)."""
        return deinterleave(self.code, self.level, self.grid.dim)

    @property
    def area(self) -> float:
        """Total area (volume) of the cells: exact, as a sum of dyadic cell sizes."""
        return float(np.sum(self.grid.cell_volume(self.level)))

    def bounds(self, index: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Leaf bounds (lo, hi), each of shape (m, dim); of the leaves `index` (a mask or indices) only
        when given."""
        level, code = (self.level, self.code) if index is None else (self.level[index], self.code[index])
        return cell_bounds(self.grid, deinterleave(code, level, self.grid.dim), level)

    def centres(self, index: np.ndarray | None = None, out: np.ndarray | None = None) -> np.ndarray:
        """Leaf centres, (m, dim): 0.5 * (lo + hi) of `bounds`, the same floats, made axis by axis
        into contiguous columns (what the kinematics read); of the leaves `index` only when given;
        `out`: an (m, dim) array to write them into."""
        level, code = (self.level, self.code) if index is None else (self.level[index], self.code[index])
        grid = self.grid
        coords = deinterleave(code, level, grid.dim)
        points = np.empty((len(level), grid.dim), order="F") if out is None else out
        widths = np.ldexp(grid.size[:, None], -np.arange(int(level.max()) + 1 if len(level) else 1))
        for axis in range(grid.dim):
            width = widths[axis][level]
            centre = points[:, axis]
            np.multiply(coords[:, axis], width, out=centre)
            centre += grid.lo[axis]  # lo
            width += centre  # hi
            centre += width  # lo + hi
            centre *= 0.5
        return points

    # -- changing the grid

    def with_depth(self, depth: int) -> "Tree":
        """The same set on a grid of another maximum depth (leaves deeper than `depth` are an error)."""
        if len(self) and self.level.max() > depth:
            raise ValueError(f"tree has leaves at level {self.level.max()} > {depth}")
        return Tree(self.grid.with_depth(depth), self.level, self.code, canonical=True)

    # -- set operations (grids must be equal)

    def _intervals_at(self, depth: int) -> tuple[np.ndarray, np.ndarray]:
        shift = self.grid.dim * (depth - self.grid.depth)
        return self.start << shift, self.end << shift

    def _combine(self, other: "Tree", keep) -> "Tree":
        if self.grid.root != other.grid.root or self.grid.periodic != other.grid.periodic:
            raise ValueError("trees live on different root boxes")
        depth = max(self.grid.depth, other.grid.depth)
        grid = self.grid.with_depth(depth)
        start, end = _sweep([self._intervals_at(depth), other._intervals_at(depth)], keep)
        return Tree.from_intervals(grid, start, end)

    def union(self, other: "Tree") -> "Tree":
        return self._combine(other, lambda a, b: a | b)

    def intersection(self, other: "Tree") -> "Tree":
        return self._combine(other, lambda a, b: a & b)

    def difference(self, other: "Tree") -> "Tree":
        return self._combine(other, lambda a, b: a & ~b)

    def symmetric_difference(self, other: "Tree") -> "Tree":
        return self._combine(other, lambda a, b: a ^ b)

    def complement(self) -> "Tree":
        """The other cells of the root box: the gaps between the leaves' index intervals (no sweep)."""
        start, end = _merge_touching(self.start, self.end)
        gap_start = np.concatenate([np.zeros(1, np.int64), end])
        gap_end = np.concatenate([start, np.full(1, np.int64(1) << (self.grid.dim * self.grid.depth))])
        keep = gap_start < gap_end
        return Tree.from_intervals(self.grid, gap_start[keep], gap_end[keep])

    __or__, __and__, __sub__, __xor__ = union, intersection, difference, symmetric_difference

    def subset(self, mask: np.ndarray) -> "Tree":
        """The tree made of the leaves selected by a boolean mask or index array (already canonical)."""
        return Tree(self.grid, self.level[mask], self.code[mask], canonical=True)

    # -- point location

    def locate(self, points: np.ndarray) -> np.ndarray:
        """Index of the leaf containing each point, or -1 (points on a cell edge go to one side)."""
        return self.locate_finest(finest_indices(self.grid, points))

    def locate_finest(self, index: np.ndarray) -> np.ndarray:
        """Index of the leaf holding each depth-D Morton index (`finest_indices`), or -1 (and for -1)."""
        start = self.start
        leaf = _leaf_at(_search_keys(start, self.grid), np.maximum(index, 0))
        ok = (leaf >= 0) & (index >= 0)
        ok[ok] &= start[leaf[ok]] + self._sizes(self.level[leaf[ok]]) > index[ok]
        return np.where(ok, leaf, -1)

    # -- adjacency and connected components

    def adjacency(self, other: "Tree | None" = None, corners: bool = False) -> tuple[np.ndarray, np.ndarray]:
        """Pairs (i, j): leaf i of this tree and leaf j of `other` (default: this tree) share a face
        of positive size, or, with `corners`, any boundary point (an edge or a corner).

        For each leaf and direction, the same-size cell across it is looked up in `other`: the leaf
        containing it, if any, is a neighbour. A neighbour smaller than leaf i is not found from i
        but from its own side, so within one tree every pair appears (once per face of the smaller
        leaf); across two trees, pairs are complete when no leaf of `other` is smaller than its
        neighbours here. Periodic axes wrap around. The leaves need not be canonical (a tree built
        with `canonical=True` from sorted disjoint cells of several sets works the same).
        """
        pairs = list(self._pairs(other, corners))
        return np.concatenate([i for i, _ in pairs]), np.concatenate([j for _, j in pairs])

    def neighbour_pairs(self, other: "Tree | None" = None, corners: bool = False, itself: bool = False,
                        once: bool = False, other_index=None):
        """The pairs of `adjacency` as (i, j) arrays, one direction at a time (a generator: the
        memory of one direction's pairs, not of all 8 or 26). With `other` and `itself`: the pairs
        with the leaves of both trees (disjoint sets), `other`'s leaves numbered first, then this
        tree's (len(other) + index). With `once`, for a tree whose leaves share one level (each
        pair of its own leaves is found from both sides): its own pairs once, looked up in the
        directions whose first nonzero step is positive only, each followed by its opposite
        direction, whose own pairs are the reverse of those found and are not given again.
        `other_index`: `other.search_index()`, when at hand."""
        return self._pairs(other, corners, itself, once, other_index=other_index)

    def search_index(self) -> tuple[np.ndarray, np.ndarray]:
        """What a neighbour search among these leaves reads (`_pairs`): their sorted starts as
        `_search_keys`, `_padded`, and their ends (`_ends`), built once for several searches among
        the same leaves (a region's black leaves: their components, then the undetermined cells'
        and the serial bands' neighbours); the keys are `near[NEAR:len(near) - NEAR]`."""
        start = self.start
        return _padded(_search_keys(start, self.grid)), _ends(start, self._sizes(self.level))

    def _pairs(self, other: "Tree | None", corners: bool, itself: bool = False, once: bool = False, dtype=np.int64,
               index=None, other_index=None):
        """The pairs of `adjacency` (with `itself`, `once`: of `neighbour_pairs`), one direction at
        a time (each found PAIR_CHUNK leaves at a time: the temporaries of a block, not of every
        leaf); without `once`, as `dtype`; `index`, `other_index`: the trees' `search_index()`,
        when at hand."""
        grid = self.grid
        if other is not None and other.grid != grid:
            raise ValueError("trees live on different grids")
        start = self.start
        # leaves all of one level (undetermined cells): one size for all, else each leaf's, once
        # for every direction
        uniform = len(self) and self.level.min() == self.level.max()
        size = self._sizes(self.level[0] if uniform else self.level)
        # this tree's own leaves: each search starts from the leaf itself, among its neighbours in
        # Morton order (`_search_near`); another tree's: a binary search
        own = others = None
        if other is None or itself:
            near, end = index or (_padded(_search_keys(start, grid)), _ends(start, size))
            own = near, end, near[NEAR:len(near) - NEAR]  # (the keys: a view)
        if other is not None:
            near, end = other_index or other.search_index()
            others = near[NEAR:len(near) - NEAR], end
        torus = len(self) == 1 and self.level[0] == 0  # the root cell, its own neighbour on a torus
        offsets = _offsets(grid.dim, corners)
        if not once:
            for offset in offsets:
                yield self._direction(offset, start, size, own, others, torus, dtype=dtype)
            return
        if own is None or not (uniform or not len(self)):
            raise ValueError("own pairs once: for a tree's own leaves of one level")
        shift = 0 if others is None else len(others[0])
        for offset in offsets:
            if offset[np.flatnonzero(offset)[0]] < 0:  # looked up as the opposite of another
                continue
            i, j = self._direction(offset, start, size, own, others, torus)
            yield i, j
            mine = j >= shift
            back = np.full(len(self), -1, index_type(len(self)))  # the leaf each leaf is the neighbour of
            back[j[mine] - shift] = i[mine]
            del i, j, mine
            if others is None:  # the opposite direction holds the same pairs, reversed
                yield np.zeros(0, np.int64), np.zeros(0, np.int64)
                continue
            yield self._direction(-offset, start, size, None, others, torus, back)

    def _direction(self, offset, start, size, own, others, torus, back=None, dtype=np.int64):
        """The pairs of one direction (`_pairs_of`, block after block), as `dtype` (cast as they
        are gathered: a union-find's index type, no second copy)."""
        found = [self._pairs_of(s, offset, start, size, own, others, torus, back) for s in range(0, len(self), PAIR_CHUNK)]
        if not found:
            return np.zeros(0, dtype), np.zeros(0, dtype)
        return (np.concatenate([i for i, _ in found], dtype=dtype, casting="same_kind"),
                np.concatenate([j for _, j in found], dtype=dtype, casting="same_kind"))

    def _pairs_of(self, s: int, offset, start, size, own, others, torus: bool = False, back=None):
        """The pairs of leaves s .. s + PAIR_CHUNK in one direction `offset`: the same-size cell
        across each leaf (its first depth-D index, stepped from the leaf's own), then the leaf
        holding that index, which is a neighbour when it holds the whole cell: looked up among
        this tree's leaves (`own`: padded starts and ends), then, for the cells not found there,
        among `others` (`_search_keys` and ends) (either may be None). `size`: the leaves' counts of
        depth-D cells (one for all when they share a level); `torus`: the tree is the root cell
        alone (not its own neighbour); `back`: each leaf's own neighbour in this direction, known
        already (-1: none), whose pair is not given: only the cells without one are looked up, in
        `others`."""
        if np.ndim(size):
            size = size[s:s + PAIR_CHUNK]
        if back is not None:  # (only the cells without a neighbour here are stepped)
            other_keys, other_end = others
            rest = np.flatnonzero(back[s:s + PAIR_CHUNK] < 0)
            size = size[rest] if np.ndim(size) else size
            first, valid = _step_finest(start[s:s + PAIR_CHUNK][rest], size, self.grid, offset)
            leaf = _leaf_at(other_keys, first)
            hit = other_end[leaf] >= first + size
            if valid is not None:
                hit &= valid
            return rest[hit] + s, leaf[hit]
        first, valid = _step_finest(start[s:s + PAIR_CHUNK], size, self.grid, offset)
        last = first + size
        if own is not None:
            near, end, keys = own
            leaf = _search_near(near, keys, first, s, _morton_sign(offset))
            hit = end[leaf] >= last
            if torus:
                hit &= leaf != s
        if others is not None:
            other_keys, other_end = others
            if own is None:
                leaf = _leaf_at(other_keys, first)
                hit = other_end[leaf] >= last
            else:
                leaf += len(other_keys)
                rest = np.flatnonzero(~hit)
                found = _leaf_at(other_keys, first[rest])
                leaf[rest] = found
                hit[rest] = other_end[found] >= last[rest]
        if valid is not None:
            hit &= valid
        idx = np.flatnonzero(hit)
        return idx + s, leaf[idx]

    def components(self, corners: bool = False, index=None) -> tuple[np.ndarray, int]:
        """Label leaves by connected component (face-connected; with `corners`, touching at any
        point); labels are numbered in Morton order of their first leaf. `index`: `search_index()`,
        when at hand."""
        # one direction at a time: memory of one, not 26, sets of pairs
        pairs = self._pairs(None, corners, dtype=index_type(len(self)), index=index)
        return root_labels(union_find_blocks(len(self), pairs))

    def components_within(self, mask: np.ndarray, corners: bool = False) -> tuple[tuple[np.ndarray, int], tuple[np.ndarray, int]]:
        """`components(corners)` of the leaves, and those of the leaves `mask` alone (of the tree
        `subset(mask)`: labels in its order), from one neighbour search: a leaf's neighbour in a
        direction is the leaf holding the cell across, the same leaf in either tree (leaves are
        disjoint), so the subset's pairs are the pairs with both ends in it; the union-find's roots
        (each component's smallest index) do not depend on the pairs' order."""
        count = int(np.count_nonzero(mask))
        rank = (np.cumsum(mask) - 1).astype(index_type(count))  # a masked leaf's index in the subset
        parent = np.arange(len(self), dtype=index_type(len(self)))
        within = np.arange(count, dtype=index_type(count))
        fresh = True  # (as `union_find_blocks`: every node its own root before the first block)
        for i, j in self._pairs(None, corners, dtype=parent.dtype):
            keep = np.flatnonzero(mask[i] & mask[j])
            _join(within, rank[i[keep]], rank[j[keep]], fresh)
            _join(parent, i, j, fresh)
            fresh = False
        return root_labels(parent), root_labels(within)

    def split_components(self) -> list["Tree"]:
        """The face-connected components as trees, in Morton order of their first leaf."""
        labels, count = self.components()
        return [self.subset(labels == c) for c in range(count)]

    # -- rasters (2-D)

    def coverage(self, level: int) -> np.ndarray:
        """Fraction of each pixel of the 2^level x 2^level grid covered by the set, indexed [y, x]."""
        whole, finer = self._raster(level)
        image = whole.astype(float)
        for shift, sel in finer:
            np.add.at(image, (sel[:, 1] >> shift, sel[:, 0] >> shift), 0.25 ** shift)
        return image

    def covered(self, level: int) -> np.ndarray:
        """The pixels of the 2^level x 2^level grid that leaves at most `level` deep cover (bool,
        [y, x]): for a tree no deeper than `level`, `coverage(level) == 1` without the floats."""
        return self._raster(level)[0]

    def _raster(self, level: int):
        """(pixels covered by leaves at most `level` deep, [(levels below, coords) of the finer leaves])."""
        if self.grid.dim != 2:
            raise ValueError("coverage rasters are for quadtrees")
        coords, lev = self.coords, self.level
        covered, at = np.zeros((1, 1), dtype=bool), 0  # leaves at most `level` deep: whole pixels,
        finer = []                                       # painted coarse to fine, one upsampling a level
        for leaf_level in unique(lev):
            sel = coords[lev == leaf_level]
            if leaf_level > level:
                finer.append((leaf_level - level, sel))
                continue
            covered = _upsample(covered, leaf_level - at)
            covered[sel[:, 1], sel[:, 0]] = True  # leaves are disjoint
            at = leaf_level
        return _upsample(covered, level - at), finer

    # -- slices (an octree seen at one value of an axis)

    def slice(self, axis: int, value: float) -> "Tree":
        """The (dim - 1)-tree of the cells whose extent along `axis` holds `value` (cells are
        half-open [lo, hi), the last one closed), on the grid of the other axes."""
        grid = self.grid
        lo, hi = grid.root[axis]
        n = 1 << grid.depth
        layer = min(max(int(np.floor((value - lo) / (hi - lo) * n)), 0), n - 1)
        span = grid.depth - self.level
        coords = self.coords
        along = coords[:, axis]
        keep = ((along << span) <= layer) & (layer < ((along + 1) << span))
        rest = [a for a in range(grid.dim) if a != axis]
        sub = Grid(tuple(grid.root[a] for a in rest), grid.depth, tuple(grid.periodic[a] for a in rest))
        return Tree.from_cells(sub, self.level[keep], coords[keep][:, rest])

    # -- B/W/G body

    def to_bwg(self) -> str:
        """Preorder body: G grey (children follow), B black, W white."""
        return encode(self)

    @classmethod
    def from_bwg(cls, grid: Grid, body: str) -> "Tree":
        """Parse a preorder body; raises BodyError with the offending node position."""
        level, code, black = decode(grid, body)
        return cls(grid, level[black], code[black])


def cell_bounds(grid: Grid, coords: np.ndarray, level: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Bounds (lo, hi), each (m, dim), of the cells of integer coordinates `coords` (m, dim) at
    their levels (`Tree.bounds`, for a caller that has the coordinates already)."""
    width = np.ldexp(grid.size[None, :], -level[:, None])
    lo = grid.lo + coords * width
    return lo, lo + width


def finest_indices(grid: Grid, points: np.ndarray) -> np.ndarray:
    """The depth-D Morton index of the cell holding each point (periodic axes wrapped), -1 for the
    points outside the root box: where a point lies in any tree of the grid (`Tree.locate_finest`),
    found once for several trees, or where the trees are not at hand (another process)."""
    coords, inside = grid.cells_of_points(points)
    index = interleave(coords, grid.depth)
    if not inside.all():
        index[~inside] = -1
    return index


# ---------------------------------------------------------------- canonical form


def _offsets(dim: int, corners: bool) -> list[np.ndarray]:
    """Neighbour directions: the 2 dim face directions, or all 3^dim - 1 with corners and edges."""
    if not corners:
        return [np.eye(dim, dtype=np.int64)[axis] * step for axis in range(dim) for step in (-1, 1)]
    grid = np.stack(np.meshgrid(*([np.arange(-1, 2)] * dim), indexing="ij"), -1).reshape(-1, dim)
    return [o.astype(np.int64) for o in grid if o.any()]


def _canonical(grid: Grid, level: np.ndarray, code: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Sort disjoint leaves and merge complete sibling groups into their parents."""
    if level.size == 0:
        return level, code
    if level.max() > grid.depth:
        raise ValueError("leaf deeper than the grid depth")
    shift = grid.dim * (grid.depth - level)
    start = finest_key(code, level, grid.dim, grid.depth)
    end = start + (np.int64(1) << shift)
    if np.any(start[1:] < start[:-1]):  # (cells often come sorted: a serial band's)
        order = np.argsort(start, kind="stable")
        start, end = start[order], end[order]
    if np.any(start[1:] < end[:-1]):
        raise ValueError("cells overlap")
    return _blocks(grid, *_merge_touching(start, end))


def _merge_touching(start: np.ndarray, end: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Merge sorted disjoint intervals that touch end-to-start into maximal intervals."""
    if start.size == 0:
        return start, end
    new = np.ones(start.size, dtype=bool)
    new[1:] = start[1:] != end[:-1]
    last = np.ones(start.size, dtype=bool)
    last[:-1] = new[1:]
    return start[new], end[last]


def _blocks(grid: Grid, start: np.ndarray, end: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Split maximal intervals of depth-D indices into maximal aligned blocks (canonical leaves).

    Greedy from the left: the largest aligned block that starts at the current position and fits.
    Because the intervals are maximal, every block found is a maximal cell of the set.
    """
    dim, depth = grid.dim, grid.depth
    levels, codes = [], []
    for a, span, _ in aligned_blocks(start.astype(np.int64), end.astype(np.int64), dim, depth):
        levels.append(depth - span)
        codes.append(a >> (dim * span))
    if not levels:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    level, code = np.concatenate(levels), np.concatenate(codes)
    order = finest_order(code, level, dim, depth)
    return level[order], code[order]


def _sweep(interval_sets, keep) -> tuple[np.ndarray, np.ndarray]:
    """Combine unions of disjoint intervals with a boolean function `keep(in_a, in_b)`."""
    points = unique(np.concatenate([np.concatenate([s, e]) for s, e in interval_sets]))
    if points.size < 2:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    left = points[:-1]
    member = []
    for s, e in interval_sets:
        k = np.searchsorted(s, left, side="right") - 1
        inside = k >= 0
        inside[inside] &= e[k[inside]] > left[inside]
        member.append(inside)
    mask = keep(*member)
    return _merge_touching(left[mask], points[1:][mask])


# ---------------------------------------------------------------- neighbour search

NEAR = 16  # a leaf's neighbour is first looked for among the NEAR leaves either side in Morton order


def _ends(start: np.ndarray, size) -> np.ndarray:
    """One past the last depth-D index of each leaf (`start`, `size`: its first index and count of
    depth-D cells), then -1: a search that finds no leaf (-1) finds no end either."""
    end = np.empty(len(start) + 1, np.int64)
    np.add(start, size, out=end[:-1])
    end[-1] = -1
    return end


def _padded(keys: np.ndarray) -> np.ndarray:
    """Sorted leaf starts (`_search_keys`, in their type) with NEAR entries below every index (-1;
    unsigned: 0, at or below) and above every index (the type's largest; unsigned: at or above)."""
    out = np.empty(len(keys) + 2 * NEAR, keys.dtype)
    out[:NEAR], out[NEAR:len(out) - NEAR], out[len(out) - NEAR:] = -1 if keys.dtype.kind == "i" else 0, keys, \
        np.iinfo(keys.dtype).max
    return out


def _morton_sign(offset: np.ndarray) -> int:
    """+1 when a step along `offset` raises the Morton code (no wrap), -1 when it lowers it, 0 when
    it may do either (components of both signs)."""
    return 1 if np.all(offset >= 0) else -1 if np.all(offset <= 0) else 0


def _step_finest(start: np.ndarray, size: np.ndarray, grid: Grid, offset) -> tuple[np.ndarray, np.ndarray | None]:
    """First depth-D index of the cell of each leaf's size one step along `offset` from the leaf
    (`start`: the leaf's first depth-D index, `size`: its count of depth-D cells), by dilated
    arithmetic on the depth-D indices (wrapping around the root), and which steps stay inside the
    root along the axes that do not wrap (None: all)."""
    dim, depth = grid.dim, grid.depth
    first, valid = start, None
    for axis in np.flatnonzero(offset):
        mask = np.int64(axis_mask(dim, int(axis)) & ((1 << (dim * depth)) - 1))
        step = size << axis
        if offset[axis] > 0:  # the other axes' bits all set: the carry runs through them
            moved = first | ~mask
            moved += step
            moved &= mask
            inside = None if grid.periodic[axis] else moved != 0  # (0: carried out of the root)
        else:
            moved = first & mask
            inside = None if grid.periodic[axis] else moved != 0  # (0: on the root's lower side)
            moved -= step
            moved &= mask
        if first is start:
            first = first & ~mask
        else:  # (our own array already)
            first &= ~mask
        first |= moved
        if inside is not None:
            if valid is None:
                valid = inside
            else:
                valid &= inside
    return first, valid


def _search_keys(start: np.ndarray, grid: Grid) -> np.ndarray:
    """Sorted leaf starts as the keys of binary searches (`_leaf_at`): uint32 when the grid's
    depth-D indices fit in 32 bits (a 2-D grid up to depth 16), half the memory, and the cache
    misses, of int64 (a search among a million leaves costs about 25 % less)."""
    return start.astype(np.uint32) if grid.dim * grid.depth <= 32 else start


def _leaf_at(keys: np.ndarray, index: np.ndarray) -> np.ndarray:
    """np.searchsorted(keys, index, side="right") - 1 (int64): the last leaf starting at or before
    each depth-D index (>= 0), or -1; `keys`: `_search_keys`."""
    return np.searchsorted(keys, index.astype(keys.dtype, copy=False), side="right") - 1


def _search_near(near: np.ndarray, keys: np.ndarray, first: np.ndarray, s: int, sign: int) -> np.ndarray:
    """`_leaf_at(keys, first)` for the queries of leaves s, s + 1, ... of the tree whose sorted
    leaf starts are `keys` (`near`: them `_padded`, int64): most neighbours lie a
    few leaves away in Morton order, so the starts of the NEAR leaves on the side the step goes
    (`sign`, both sides when 0) are compared with each query as contiguous slices, and only the
    queries whose answer lies farther are searched (a binary search per query costs about as
    much as 100 such comparisons). `near` may be uint32 (`_search_keys`: the comparisons then
    read half the memory, about 2.5x faster): the queries are compared in its type (a query at
    the last depth-D index, equal to the upper padding, counts the padding as at or below it: the
    window is full, and it is searched)."""
    n = len(first)
    if first.dtype != near.dtype:
        first = first.astype(near.dtype)
    base = s + NEAR  # near[base + k] is the start of leaf s + k
    count = np.zeros(n, np.int8)
    below = np.empty(n, bool)
    ones = below.view(np.int8)  # (added without a cast)
    if sign > 0:  # the leaves after: the answer is s + k + (how many of them start at or before)
        for d in range(1, NEAR + 1):
            np.less_equal(near[base + d:base + d + n], first, out=below)
            np.add(count, ones, out=count)
        leaf = np.arange(s, s + n) + count
        found = (count < NEAR) & (near[base:base + n] <= first)
    elif sign < 0:  # the leaves before: s + k - 1 - (how many of them start after)
        for d in range(1, NEAR + 1):
            np.greater(near[base - d:base - d + n], first, out=below)
            np.add(count, ones, out=count)
        leaf = np.arange(s - 1, s - 1 + n) - count
        found = (count < NEAR) & (near[base:base + n] > first)
    else:  # both sides: s + k - NEAR - 1 + (how many of the 2 NEAR + 1 start at or before)
        for d in range(-NEAR, NEAR + 1):
            np.less_equal(near[base + d:base + d + n], first, out=below)
            np.add(count, ones, out=count)
        leaf = np.arange(s - NEAR - 1, s - NEAR - 1 + n) + count
        found = (count > 0) & (count <= 2 * NEAR)
    far = np.flatnonzero(~found)
    leaf[far] = _leaf_at(keys, first[far])
    return leaf


# ---------------------------------------------------------------- union-find


def root_labels(root: np.ndarray) -> tuple[np.ndarray, int]:
    """Components numbered 0, 1, ... in order of their smallest element, from `union_find` roots
    (each component's smallest element): the ranks of the roots, without a sort; and their count."""
    is_root = root == np.arange(len(root))
    return (np.cumsum(is_root) - 1)[root], int(np.count_nonzero(is_root))


def union_find(n: int, i: np.ndarray, j: np.ndarray, parent: np.ndarray | None = None) -> np.ndarray:
    """Connected-component roots (smallest index of each component) by hooking + pointer jumping;
    `parent`: roots found from other edges already (each node's smallest-index root), to add to."""
    return union_find_blocks(n, [(i, j)], parent).astype(np.int64)


def union_find_blocks(n: int, blocks, parent: np.ndarray | None = None) -> np.ndarray:
    """`union_find` of the edges given as blocks (i, j) (e.g. one neighbour direction each), joined
    one block after the other: most edges of a later block then join nodes already joined and
    leave in the first round (about 3x faster than all edges at once); roots in `index_type`."""
    small = index_type(n)
    fresh = parent is None  # every node its own root: the first block's ends are their roots
    parent = np.arange(n, dtype=small) if fresh else parent.astype(small)
    for i, j in blocks:
        _join(parent, i.astype(small, copy=False), j.astype(small, copy=False), fresh)
        fresh = False
    return parent


def _join(parent: np.ndarray, i: np.ndarray, j: np.ndarray, fresh: bool = False) -> np.ndarray:
    """`union_find` in place on `parent` (every node pointing at its root, on entry and on return;
    `fresh`: every node its own root, no need to read them): each round hooks the larger root of
    every edge joining two components to the smaller one and follows the hooked roots' pointers
    by doubling until each points at a root (only they moved); an edge's new roots are then its
    old roots' pointers, so the edges still across (all of them: no copies) need no pass over
    every node. A node's path to its root grows by one a round: the paths are halved over every
    node once the edges are joined, not once a round (about 10 % less on the black leaves)."""
    ri, rj = (i, j) if fresh else (parent[i], parent[j])
    rounds = 0
    while True:
        cross = np.flatnonzero(ri != rj)
        if not len(cross):
            break
        if len(cross) < len(ri):
            ri, rj = ri[cross], rj[cross]
        hooked = np.maximum(ri, rj)
        np.minimum.at(parent, hooked, np.minimum(ri, rj))
        while len(hooked):
            up = parent[hooked]
            root = parent[up]
            parent[hooked] = root
            hooked = hooked[root != up]
        ri, rj = parent[ri], parent[rj]  # (the old roots' roots)
        rounds += 1
    # every node reaches its root in at most rounds + 1 steps: halved in place until one (a node
    # read after its update points further along the same path)
    steps = rounds + 1
    while steps > 1:
        np.take(parent, parent, out=parent, mode="clip")
        steps = (steps + 1) // 2
    return parent


def _upsample(image: np.ndarray, levels: int) -> np.ndarray:
    """Each pixel as a block of 2^levels x 2^levels pixels."""
    if levels == 0:
        return image
    rep = 1 << levels
    return np.repeat(np.repeat(image, rep, axis=0), rep, axis=1)
