"""2^n-trees (quadtrees, octrees) as sets of cells: canonical leaves, set operations, B/W/G codec,
point location and connected components (with periodic axes).

A tree is stored as its black leaves only, each a (level, Morton code) pair, in canonical form:
no 2^n sibling leaves are all black (they would be one leaf of their parent). At the finest
level D every leaf is a run of consecutive depth-D Morton indices, so a set of cells is also a
union of integer intervals, and union, intersection and difference become interval sweeps.
Child k of a cell has bit j of k set when it is the high half along axis j: (x low, y low),
(x high, y low), (x low, y high), (x high, y high), then phi low before phi high for octrees.
All hot paths are numpy-vectorised over leaves; nothing recurses per cell in Python.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property, lru_cache

import numpy as np

MAX_INDEX_BITS = 52  # dim * depth: Morton indices stay exact in float64 and int64


@dataclass(frozen=True)
class Grid:
    """The geometry shared by a paving and all its trees: root box, maximum depth, periodic axes."""

    root: tuple[tuple[float, float], ...]
    depth: int
    periodic: tuple[bool, ...]

    def __post_init__(self) -> None:
        if len(self.periodic) != len(self.root):
            raise ValueError("periodic needs one flag per axis")
        if self.depth < 0 or self.dim * self.depth > MAX_INDEX_BITS:
            raise ValueError(f"depth {self.depth} out of range 0..{MAX_INDEX_BITS // self.dim}")
        for lo, hi in self.root:
            if not (np.isfinite(lo) and np.isfinite(hi) and lo < hi):
                raise ValueError(f"bad root interval [{lo}, {hi}]")

    @property
    def dim(self) -> int:
        return len(self.root)

    @property
    def lo(self) -> np.ndarray:
        return np.array([r[0] for r in self.root])

    @property
    def size(self) -> np.ndarray:
        return np.array([r[1] - r[0] for r in self.root])

    def with_depth(self, depth: int) -> "Grid":
        return Grid(self.root, depth, self.periodic)

    def cell_volume(self, level) -> np.ndarray:
        """Area (volume) of a cell at `level` (array-friendly, exact for dyadic levels)."""
        return float(np.prod(self.size)) * np.ldexp(1.0, -self.dim * np.asarray(level, dtype=np.int64))

    def boxes(self, level: int, coords: np.ndarray, pad: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
        """Bounds (lo, hi), shape (m, dim), of the cells `coords` at `level`, widened by `pad`."""
        width = np.ldexp(self.size, -level)
        lo = self.lo + coords * width
        hi = self.lo + (coords + 1) * width
        return lo - pad, hi + pad

    def cells_of_points(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Depth-D cell coordinates of points and a mask of the points inside the root box.

        Periodic axes are wrapped into the root first.
        """
        points = np.atleast_2d(np.asarray(points, dtype=float))
        rel = (points - self.lo) / self.size
        for axis, wrap in enumerate(self.periodic):
            if wrap:
                rel[:, axis] = np.mod(rel[:, axis], 1.0)
        inside = np.all((rel >= 0) & (rel <= 1), axis=1)
        n = 1 << self.depth
        coords = np.clip(np.floor(np.where(inside[:, None], rel, 0) * n), 0, n - 1).astype(np.int64)
        return coords, inside


# ---------------------------------------------------------------- Morton codes


@lru_cache(maxsize=None)
def _spread_table(dim: int, bits: int) -> np.ndarray:
    """table[c] = the `bits` low bits of c spread to every dim-th bit position."""
    c = np.arange(1 << bits, dtype=np.int64)
    out = np.zeros_like(c)
    for b in range(bits):
        out |= ((c >> b) & 1) << (b * dim)
    return out


@lru_cache(maxsize=None)
def _compact_table(dim: int, bits: int) -> np.ndarray:
    """table[v, axis] = the bits of axis `axis` gathered from a (bits * dim)-bit Morton chunk v."""
    v = np.arange(1 << (bits * dim), dtype=np.int64)
    out = np.zeros((v.size, dim), dtype=np.int64)
    for b in range(bits):
        for axis in range(dim):
            out[:, axis] |= ((v >> (b * dim + axis)) & 1) << b
    return out


def _chunk(dim: int) -> int:
    return 16 // dim  # coordinate bits per table lookup (tables of 2^16 entries at most)


def interleave(coords: np.ndarray, level: int | np.ndarray) -> np.ndarray:
    """Morton codes of integer cell coordinates, shape (m, dim) -> (m,), bit j of a child index = axis j."""
    coords = np.asarray(coords, dtype=np.int64)
    m, dim = coords.shape
    bits = int(np.max(level)) if np.size(level) else 0
    step = _chunk(dim)
    table = _spread_table(dim, step)
    code = np.zeros(m, dtype=np.int64)
    for k in range(0, bits, step):
        for axis in range(dim):
            code |= table[(coords[:, axis] >> k) & ((1 << step) - 1)] << (k * dim + axis)
    return code


def deinterleave(code: np.ndarray, level: int | np.ndarray, dim: int) -> np.ndarray:
    """Inverse of `interleave`: Morton codes -> integer coordinates, shape (m, dim)."""
    code = np.asarray(code, dtype=np.int64)
    bits = int(np.max(level)) if np.size(level) else 0
    step = _chunk(dim)
    table = _compact_table(dim, step)
    coords = np.zeros((code.size, dim), dtype=np.int64)
    for k in range(0, bits, step):
        coords |= table[(code >> (k * dim)) & ((1 << (step * dim)) - 1)] << k
    return coords


def _floor_log2(x: np.ndarray) -> np.ndarray:
    """floor(log2(x)) for positive integers below 2**53 (exact through frexp)."""
    return np.frexp(x.astype(np.float64))[1].astype(np.int64) - 1


def _trailing_zeros(x: np.ndarray, cap: int) -> np.ndarray:
    """Number of trailing zero bits of non-negative int64 values (x == 0 gives `cap`)."""
    low = x & -x
    return np.where(x == 0, cap, _floor_log2(np.where(x == 0, 1, low)))


# ---------------------------------------------------------------- trees


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

    @cached_property
    def start(self) -> np.ndarray:
        """First depth-D Morton index of each leaf."""
        return self.code << (self.grid.dim * (self.grid.depth - self.level))

    @cached_property
    def end(self) -> np.ndarray:
        """One past the last depth-D Morton index of each leaf."""
        return self.start + (np.int64(1) << (self.grid.dim * (self.grid.depth - self.level)))

    @cached_property
    def coords(self) -> np.ndarray:
        """Integer coordinates of each leaf at its own level, shape (m, dim)."""
        return deinterleave(self.code, self.level, self.grid.dim)

    @property
    def area(self) -> float:
        """Total area (volume) of the cells: exact, as a sum of dyadic cell sizes."""
        return float(np.sum(self.grid.cell_volume(self.level)))

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """Leaf bounds (lo, hi), each of shape (m, dim)."""
        width = np.ldexp(self.grid.size[None, :], -self.level[:, None])
        lo = self.grid.lo + self.coords * width
        return lo, lo + width

    def centres(self) -> np.ndarray:
        lo, hi = self.bounds()
        return 0.5 * (lo + hi)

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
        return Tree.full(self.grid).difference(self)

    __or__, __and__, __sub__, __xor__ = union, intersection, difference, symmetric_difference

    def subset(self, mask: np.ndarray) -> "Tree":
        """The tree made of the leaves selected by a boolean mask or index array (already canonical)."""
        return Tree(self.grid, self.level[mask], self.code[mask], canonical=True)

    # -- point location

    def locate(self, points: np.ndarray) -> np.ndarray:
        """Index of the leaf containing each point, or -1 (points on a cell edge go to one side)."""
        coords, inside = self.grid.cells_of_points(points)
        index = interleave(coords, self.grid.depth)
        leaf = np.searchsorted(self.start, index, side="right") - 1
        ok = inside & (leaf >= 0)
        ok[ok] &= self.end[leaf[ok]] > index[ok]
        return np.where(ok, leaf, -1)

    # -- adjacency and connected components

    def adjacency(self, other: "Tree | None" = None) -> tuple[np.ndarray, np.ndarray]:
        """Pairs (i, j): leaf i of this tree and leaf j of `other` (default: this tree) share a face
        of positive size (corner contact does not count).

        For each leaf and face, the same-size cell across the face is looked up in `other`: the leaf
        containing it, if any, is a neighbour. A neighbour smaller than leaf i is not found from i
        but from its own side, so within one tree every pair appears (once per face of the smaller
        leaf); across two trees, pairs are complete when no leaf of `other` is smaller than its
        neighbours here. Periodic axes wrap around.
        """
        target = self if other is None else other
        grid, coords, level = self.grid, self.coords, self.level
        if target.grid != grid:
            raise ValueError("trees live on different grids")
        n_side = np.int64(1) << level
        pairs_i, pairs_j = [], []
        for axis in range(grid.dim):
            for step in (-1, 1):
                nb = coords.copy()
                nb[:, axis] += step
                if grid.periodic[axis]:
                    nb[:, axis] %= n_side
                    valid = np.ones(len(self), dtype=bool)
                else:
                    valid = (nb[:, axis] >= 0) & (nb[:, axis] < n_side)
                idx = np.flatnonzero(valid)
                shift = grid.dim * (grid.depth - level[idx])
                first = interleave(nb[idx], level[idx]) << shift
                last = first + (np.int64(1) << shift)
                leaf = np.searchsorted(target.start, first, side="right") - 1
                hit = leaf >= 0
                hit[hit] &= target.end[leaf[hit]] >= last[hit]
                if other is None:
                    hit &= leaf != idx  # a root-sized periodic cell touching itself
                pairs_i.append(idx[hit])
                pairs_j.append(leaf[hit])
        return np.concatenate(pairs_i), np.concatenate(pairs_j)

    def components(self) -> tuple[np.ndarray, int]:
        """Label leaves by face-connected component; labels are numbered in Morton order of first leaf."""
        i, j = self.adjacency()
        root = union_find(len(self), i, j)
        _, first, labels = np.unique(root, return_index=True, return_inverse=True)
        order = np.argsort(first, kind="stable")
        rank = np.empty_like(order)
        rank[order] = np.arange(order.size)
        return rank[labels], int(order.size)

    def split_components(self) -> list["Tree"]:
        """The face-connected components as trees, in Morton order of their first leaf."""
        labels, count = self.components()
        return [self.subset(labels == c) for c in range(count)]

    # -- rasters (2-D)

    def coverage(self, level: int) -> np.ndarray:
        """Fraction of each pixel of the 2^level x 2^level grid covered by the set, indexed [y, x]."""
        if self.grid.dim != 2:
            raise ValueError("coverage rasters are for quadtrees")
        n = 1 << level
        image = np.zeros((n, n))
        coords, lev = self.coords, self.level
        for leaf_level in np.unique(lev):
            sel = coords[lev == leaf_level]
            if leaf_level <= level:
                small = np.zeros((1 << leaf_level, 1 << leaf_level))
                small[sel[:, 1], sel[:, 0]] = 1.0
                rep = 1 << (level - leaf_level)
                image += np.repeat(np.repeat(small, rep, axis=0), rep, axis=1)
            else:
                shift = leaf_level - level
                np.add.at(image, (sel[:, 1] >> shift, sel[:, 0] >> shift), 0.25 ** shift)
        return image

    # -- B/W/G body

    def to_bwg(self) -> str:
        """Preorder body: G grey (children follow), B black, W white."""
        return _encode(self)

    @classmethod
    def from_bwg(cls, grid: Grid, body: str) -> "Tree":
        """Parse a preorder body; raises BodyError with the offending node position."""
        level, code, black = _decode(grid, body)
        return cls(grid, level[black], code[black])


class BodyError(ValueError):
    """A malformed B/W/G body; `position` is the 0-based index of the offending letter."""

    def __init__(self, position: int, message: str):
        self.position = position
        super().__init__(message)


# ---------------------------------------------------------------- canonical form


def _canonical(grid: Grid, level: np.ndarray, code: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Sort disjoint leaves and merge complete sibling groups into their parents."""
    if level.size == 0:
        return level, code
    if level.max() > grid.depth:
        raise ValueError("leaf deeper than the grid depth")
    shift = grid.dim * (grid.depth - level)
    start = code << shift
    end = start + (np.int64(1) << shift)
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
    a, b = start.astype(np.int64), end.astype(np.int64)
    while a.size:
        span = np.minimum(_trailing_zeros(a, dim * depth) // dim, _floor_log2(b - a) // dim)
        span = np.minimum(span, depth)
        levels.append(depth - span)
        codes.append(a >> (dim * span))
        a = a + (np.int64(1) << (dim * span))
        keep = a < b
        a, b = a[keep], b[keep]
    if not levels:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    level, code = np.concatenate(levels), np.concatenate(codes)
    order = np.argsort(code << (dim * (depth - level)), kind="stable")
    return level[order], code[order]


def _sweep(interval_sets, keep) -> tuple[np.ndarray, np.ndarray]:
    """Combine unions of disjoint intervals with a boolean function `keep(in_a, in_b)`."""
    points = np.unique(np.concatenate([np.concatenate([s, e]) for s, e in interval_sets]))
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


# ---------------------------------------------------------------- union-find


def union_find(n: int, i: np.ndarray, j: np.ndarray) -> np.ndarray:
    """Connected-component roots (smallest index of each component) by hooking + pointer jumping."""
    parent = np.arange(n, dtype=np.int64)
    while True:
        while True:  # pointer jumping until every node points at its root
            grand = parent[parent]
            if np.array_equal(grand, parent):
                break
            parent = grand
        ri, rj = parent[i], parent[j]
        cross = ri != rj
        if not cross.any():
            return parent
        i, j, ri, rj = i[cross], j[cross], ri[cross], rj[cross]
        np.minimum.at(parent, np.maximum(ri, rj), np.minimum(ri, rj))


# ---------------------------------------------------------------- B/W/G codec


def _encode(tree: Tree) -> str:
    grid = tree.grid
    dim, depth, k = grid.dim, grid.depth, 1 << grid.dim
    if len(tree) == 0:
        return "W"
    if tree.level[0] == 0:
        return "B"
    grey_level, grey_code = [], []
    for lev in range(depth):  # grey nodes: the proper ancestors of black leaves
        deeper = tree.level > lev
        anc = np.unique(tree.code[deeper] >> (dim * (tree.level[deeper] - lev)))
        grey_level.append(np.full(anc.size, lev, dtype=np.int64))
        grey_code.append(anc)
    g_level, g_code = np.concatenate(grey_level), np.concatenate(grey_code)
    child_level = np.repeat(g_level + 1, k)
    child_code = (np.repeat(g_code, k) << dim) | np.tile(np.arange(k, dtype=np.int64), g_code.size)
    key_grey = g_code << (dim * (depth - g_level))
    key_child = child_code << (dim * (depth - child_level))
    # children that are neither grey nor black are white
    is_grey = _member(child_level, child_code, g_level, g_code, depth, dim)
    is_black = _member(child_level, child_code, tree.level, tree.code, depth, dim)
    white = ~is_grey & ~is_black
    levels = np.concatenate([g_level, tree.level, child_level[white]])
    keys = np.concatenate([key_grey, tree.start, key_child[white]])
    letters = np.concatenate(
        [np.full(g_level.size, ord("G")), np.full(len(tree), ord("B")), np.full(int(white.sum()), ord("W"))]
    ).astype(np.uint8)
    order = np.lexsort((levels, keys))
    return letters[order].tobytes().decode("ascii")


def _member(level, code, set_level, set_code, depth, dim) -> np.ndarray:
    """Whether each (level, code) node belongs to the node set (set_level, set_code)."""
    if set_code.size == 0:
        return np.zeros(level.size, dtype=bool)
    key = (code << (dim * (depth - level))) * (depth + 1) + level
    set_key = np.sort((set_code << (dim * (depth - set_level))) * (depth + 1) + set_level)
    pos = np.minimum(np.searchsorted(set_key, key), set_key.size - 1)
    return set_key[pos] == key


def _decode(grid: Grid, body: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Levels, codes and black mask of every node of a preorder body (vectorised).

    With e = k-1 for G and -1 for a leaf, the prefix sum S counts nodes still owed; a well-formed
    body has S >= 0 before its last letter and S = -1 at the end. The subtree of a grey node at i
    ends at the first t >= i with S[t] = S[i-1] - 1, which gives every node's depth; the nodes of a
    level, in body order, are the children of the grey nodes of the level above, k at a time.
    """
    dim, depth, k = grid.dim, grid.depth, 1 << grid.dim
    letters = np.frombuffer(body.encode("ascii", errors="replace"), dtype=np.uint8)
    n = letters.size
    if n == 0:
        raise BodyError(0, "empty tree body")
    bad = np.flatnonzero((letters != ord("G")) & (letters != ord("B")) & (letters != ord("W")))
    if bad.size:
        raise BodyError(int(bad[0]), f"unexpected character {body[bad[0]]!r} (expected B, W or G)")
    grey = letters == ord("G")
    s = np.cumsum(np.where(grey, k - 1, -1))
    done = np.flatnonzero(s < 0)
    if done.size == 0:
        raise BodyError(n, f"truncated tree body: {int(s[-1]) + 1} more node(s) expected")
    if done[0] != n - 1:
        raise BodyError(int(done[0]) + 1, "extra letters after the end of the tree")
    prev = np.concatenate([[0], s[:-1]])
    g = np.flatnonzero(grey)
    order = np.lexsort((np.arange(n), s))
    key_sorted = s[order] * (n + 1) + order
    pos = np.searchsorted(key_sorted, (prev[g] - 1) * (n + 1) + g)
    end = order[pos]
    delta = np.zeros(n + 1, dtype=np.int64)
    np.add.at(delta, g + 1, 1)
    np.add.at(delta, end + 1, -1)
    level = np.cumsum(delta)[:n]
    too_deep = np.flatnonzero(grey & (level >= depth))
    if too_deep.size:
        raise BodyError(int(too_deep[0]), f"grey node at level {int(level[too_deep[0]])}: the tree is deeper than its depth {depth}")
    code = np.zeros(n, dtype=np.int64)
    by_level = np.argsort(level, kind="stable")
    counts = np.bincount(level, minlength=1)
    bounds = np.concatenate([[0], np.cumsum(counts)])
    for lev in range(1, counts.size):
        nodes = by_level[bounds[lev]:bounds[lev + 1]]
        parents = by_level[bounds[lev - 1]:bounds[lev]]
        parents = parents[grey[parents]]
        rank = np.arange(nodes.size)
        code[nodes] = (code[parents[rank // k]] << dim) | (rank % k)
    return level, code, letters == ord("B")
