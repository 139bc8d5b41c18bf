"""Certified subdivision: (grid, box test, depth) -> Paving.

Breadth-first: all boxes of a level go to the box test in one vectorised call (in chunks, to bound
memory). A box test takes arrays lo, hi of shape (m, dim) (and, when it has a parameter `ends`,
the boxes' ends per axis as tables, `grid.AxisEnds`) and returns int8: 1 if every point of
the box has the property, -1 if no point has it, 0 if it cannot tell. Boxes answering 0 are split
into their 2^dim children until the maximum depth. A test may also answer 2 (BAND): the box is
certified to lie in a region that is neither inside nor outside, such as the uncertain band of a
mechanism whose lengths are intervals (every point valid for some lengths, invalid for others);
such boxes are decided and kept in the `band` tree, not split. The number of evaluations is the number of
boxes tested: the root plus 2^dim per undetermined box above the maximum depth (the paper's
n_quadtree).

Soundness of the cells against rounding: the cell bounds computed in floating point may differ
from the exact dyadic cells of the root box by a few ulps, so every box is widened by
`pad = 4 ulp(max |root bound|)` before it is tested; the test thus sees a box containing the exact cell.
"""

from __future__ import annotations

import ctypes
import inspect
import sys
from dataclasses import dataclass
from typing import Callable

import numpy as np

from fivebar_cli.paving.arrays import unique
from fivebar_cli.paving.grid import AxisEnds, Grid, boxes_of
from fivebar_cli.paving.morton import finest_key, interleave
from fivebar_cli.paving.tree import Tree

BoxTest = Callable[[np.ndarray, np.ndarray], np.ndarray]
# several box tests at once: (lo, hi, open, ends) -> int8 statuses (m, count); column c is read only
# where open[:, c] (the box is still undetermined for test c), so it may skip the other boxes;
# ends: the boxes' bounds per axis as tables (`grid.AxisEnds`), for what depends on one axis alone
MultiTest = Callable[[np.ndarray, np.ndarray, np.ndarray, tuple[AxisEnds, ...]], np.ndarray]
INSIDE, OUTSIDE, UNDETERMINED, BAND = 1, -1, 0, 2
CHUNK = 1 << 16
MAX_REFINE_CELLS = 1 << 26
HEAP_MMAP_THRESHOLD = 32 << 20  # glibc malloc: blocks of this size and more mapped apart (its dynamic maximum)
HEAP_TRIM_THRESHOLD = 64 << 20  # ... and free memory at the heap's top returned beyond this


def keep_heap() -> None:
    """Let glibc's malloc keep the memory the box tests' temporaries free, instead of returning it
    to the system at every call and faulting it in again (a chunk's arrays, half a MiB each, are
    above its default thresholds: a tenth of a depth-12 analysis's CPU went to page faults). Both
    thresholds are set: setting one turns off malloc's own adjustment of the other (setting the trim
    threshold alone maps every such array apart: slower). Peak memory is not raised (max RSS of a
    depth-16 analysis 392 -> 385 MiB). Nothing elsewhere than on Linux."""
    if sys.platform == "linux":
        try:
            libc = ctypes.CDLL(None)
            libc.mallopt(-3, HEAP_MMAP_THRESHOLD)  # M_MMAP_THRESHOLD
            libc.mallopt(-1, HEAP_TRIM_THRESHOLD)  # M_TRIM_THRESHOLD
        except (AttributeError, OSError):  # (no mallopt: not glibc's malloc)
            pass


keep_heap()


@dataclass(frozen=True)
class Paving:
    """Result of a paving: certified inside and outside trees, undetermined cells, evaluation counts."""

    grid: Grid
    inside: Tree
    outside: Tree
    undetermined: np.ndarray  # integer coordinates of the undetermined cells at the maximum depth
    per_level: tuple[int, ...]  # boxes tested at each level 0..D
    band: Tree | None = None  # cells certified neither inside nor outside (tests answering BAND)

    def __post_init__(self) -> None:
        if self.band is None:
            object.__setattr__(self, "band", Tree.empty(self.grid))

    @property
    def evaluations(self) -> int:
        return int(sum(self.per_level))

    @property
    def undetermined_area(self) -> float:
        return float(len(self.undetermined) * self.grid.cell_volume(self.grid.depth))

    def undetermined_tree(self) -> Tree:
        return Tree.from_cells(self.grid, self.grid.depth, self.undetermined)


def box_pad(grid: Grid) -> float:
    """Outward widening of every tested box, covering the rounding of its computed bounds."""
    return 4.0 * float(np.spacing(max(abs(v) for r in grid.root for v in r)))


def children(coords: np.ndarray) -> np.ndarray:
    """The 2^dim children of each cell, in child order (bit j of the child index = high along axis j)."""
    dim = coords.shape[1]
    k = np.arange(1 << dim)
    offsets = (k[:, None] >> np.arange(dim)[None, :]) & 1
    out = np.repeat(coords * 2, 1 << dim, axis=0).reshape(len(coords), 1 << dim, dim)  # (a broadcast
    out += offsets  # multiply into the children's array costs twice as much)
    return out.reshape(-1, dim)


def child_codes(codes: np.ndarray, dim: int) -> np.ndarray:
    """The Morton codes of the children of cells of Morton codes `codes`, in `children`'s order."""
    out = np.repeat(codes << dim, 1 << dim).reshape(len(codes), 1 << dim)  # (as `children`)
    out |= np.arange(1 << dim, dtype=codes.dtype)
    return out.reshape(-1)


def chunked(fn, *arrays: np.ndarray):
    """fn(*arrays) -> an array or a tuple of arrays (one row per row of the arrays), computed CHUNK
    rows at a time: a box function's temporaries take the memory of one chunk, not of every box."""
    if len(arrays[0]) <= CHUNK:
        return fn(*arrays)
    parts = [fn(*(a[s:s + CHUNK] for a in arrays)) for s in range(0, len(arrays[0]), CHUNK)]
    if isinstance(parts[0], tuple):
        return tuple(np.concatenate(p) for p in zip(*parts))
    return np.concatenate(parts)


def on_cells(fn, grid: Grid, coords: np.ndarray, ends: bool = False):
    """fn(lo, hi) of the depth-D cells `coords` (their boxes, not padded), CHUNK cells at a time
    (`chunked`: neither the boxes of every cell nor fn's temporaries are held at once); with
    `ends`, fn(lo, hi, ends=...) is also given the boxes' ends as tables (`grid.AxisEnds`), so what
    depends on one axis's interval alone is computed per distinct end, as the paving's tests do."""
    if not ends:
        return chunked(lambda c: fn(*grid.boxes(grid.depth, c)), coords)

    def one(c: np.ndarray):
        tables = grid.axis_ends(grid.depth, c)
        return fn(*boxes_of(tables), ends=tables)

    return chunked(one, coords)


def _classify_many(grid: Grid, level: int, coords: np.ndarray, open_: np.ndarray, tests: MultiTest) -> np.ndarray:
    """Run a multi-test on cells of one level, in chunks; returns int8 statuses (m, count)."""
    pad = box_pad(grid)
    status = np.empty(open_.shape, dtype=np.int8)
    for s in range(0, len(coords), CHUNK):
        ends = grid.axis_ends(level, coords[s:s + CHUNK], pad)
        lo, hi = boxes_of(ends)
        status[s:s + CHUNK] = tests(lo, hi, open_[s:s + CHUNK], ends)
    return status


def single(test: BoxTest) -> MultiTest:
    """A box test as a multi-test of one column; a test with an `ends` parameter is given the
    boxes' ends as tables (`grid.AxisEnds`), for what depends on one axis alone."""
    if _takes_ends(test):
        return lambda lo, hi, open_, ends=None: test(lo, hi, ends=ends)[:, None]
    return lambda lo, hi, open_, ends=None: test(lo, hi)[:, None]


def _takes_ends(test) -> bool:
    """Whether the callable `test` has a parameter `ends`."""
    try:
        return "ends" in inspect.signature(test).parameters
    except (TypeError, ValueError):  # (no signature: a builtin)
        return False


def stacked(tests: list[BoxTest]) -> MultiTest:
    """Box tests as one multi-test: each evaluated on the boxes still open for it only."""

    def test(lo: np.ndarray, hi: np.ndarray, open_: np.ndarray, ends=None) -> np.ndarray:
        out = np.zeros(open_.shape, np.int8)
        for c, one in enumerate(tests):
            mine = open_[:, c]
            if mine.all():
                out[:, c] = one(lo, hi)
            elif mine.any():
                out[mine, c] = one(lo[mine], hi[mine])
        return out

    return test


def pave(grid: Grid, test: BoxTest, on_level: Callable[[int, int], None] | None = None) -> Paving:
    """Pave the root box of `grid` down to its depth with `test`."""
    start = np.zeros((1, grid.dim), dtype=np.int64)
    return _descend(grid, test, 0, start, [], [], [], on_level)


def pave_many(grid: Grid, tests: MultiTest, count: int) -> list[Paving]:
    """Pave the root box once for `count` box tests evaluated together (a `MultiTest`, whose tests
    share work: the modes of one space). A box is tested where any test still leaves it open and
    counts for those tests only, so paving c equals `pave(grid, test c)`: the same trees, the same
    undetermined cells in the same order, the same evaluations per level."""
    start = np.zeros((1, grid.dim), dtype=np.int64)
    return _descend_many(grid, tests, count, 0, start)


def refine(inside: Tree, outside: Tree, test: BoxTest, depth: int,
           on_level: Callable[[int, int], None] | None = None, band: Tree | None = None) -> Paving:
    """Deepen a saved paving to `depth`, testing only the children of its undetermined cells.

    The result equals a fresh `pave` at `depth`; its evaluation count is the fresh count minus the
    evaluations of the original paving. `band` holds the saved band cells, if the test has any.
    """
    grid = inside.grid
    band = Tree.empty(grid) if band is None else band
    if outside.grid != grid or band.grid != grid:
        raise ValueError("the trees of the paving have different grids")
    if depth < grid.depth:
        raise ValueError(f"cannot refine a depth-{grid.depth} paving to the smaller depth {depth}")
    open_cells = undetermined_cells(inside, outside, band)
    deeper = grid.with_depth(depth)
    per_level = [0] * (grid.depth + 1)
    if depth == grid.depth:
        return Paving(deeper, inside, outside, open_cells, tuple(per_level), band)
    return _descend(
        deeper, test, grid.depth + 1, children(open_cells),
        [(inside.level, inside.code)], [(outside.level, outside.code)], per_level, on_level,
        [(band.level, band.code)] if len(band) else [],
    )


def deepen(grid: Grid, test: BoxTest, cells: np.ndarray, extra: int) -> Paving:
    """Pave the depth-D cells `cells` (undetermined ones, typically) `extra` levels deeper.

    The result lives on the grid of depth D + extra and holds only what the new boxes decided:
    a local refinement, e.g. to settle whether two pieces of a region connect.
    """
    deeper = grid.with_depth(grid.depth + extra)
    if extra <= 0 or len(cells) == 0:
        return Paving(deeper, Tree.empty(deeper), Tree.empty(deeper), np.zeros((0, grid.dim), np.int64),
                      (0,) * (deeper.depth + 1))
    return _descend(deeper, test, grid.depth + 1, children(cells), [], [], [0] * (grid.depth + 1), None)


def deepen_many(grid: Grid, tests: MultiTest, cells: list[np.ndarray], extra: int) -> list[Paving]:
    """`deepen(grid, test c, cells[c], extra)` for each c, from one descent over the cells of all
    (`tests`: a `MultiTest` of the tests, a column each, as `pave_many`'s): a box is tested once
    where several lists hold it (the deeper band of classes of one sheet). Each list in Morton
    order (a paving's undetermined cells, or a subset of them in order), so that its own cells,
    children of the union in Morton order, come in the order `deepen` gives them: the same
    pavings. Lists out of that order are deepened one at a time."""
    codes = [interleave(c, grid.depth) if len(c) else np.zeros(0, np.int64) for c in cells]
    if any(np.any(c[1:] <= c[:-1]) for c in codes):
        return [deepen(grid, _column(tests, c, len(cells)), cell, extra) for c, cell in enumerate(cells)]
    deeper = grid.with_depth(grid.depth + extra)
    union, first = np.unique(np.concatenate(codes), return_index=True)
    if extra <= 0 or len(union) == 0:
        return [deepen(grid, None, cell, extra) for cell in cells]
    member = np.column_stack([np.isin(union, c, assume_unique=True) for c in codes])
    coords = np.concatenate(cells)[first]
    per_level = [[0] * (grid.depth + 1) for _ in cells]
    open_ = np.repeat(member, 1 << grid.dim, axis=0)
    return _descend_many(deeper, tests, len(cells), grid.depth + 1, children(coords), per_level=per_level, open_=open_)


def _column(tests: MultiTest, c: int, count: int) -> BoxTest:
    """Column c of a multi-test as a box test (given the boxes' ends)."""
    def test(lo, hi, ends=None):
        open_ = np.zeros((len(lo), count), bool)
        open_[:, c] = True
        return tests(lo, hi, open_, ends)[:, c]
    return test


def undetermined_cells(inside: Tree, outside: Tree, band: Tree | None = None) -> np.ndarray:
    """Depth-D coordinates of the cells certified neither inside nor outside (nor in the band)."""
    grid = inside.grid
    decided = inside.union(outside)
    if len(inside.intersection(outside)) or (band is not None and len(band.intersection(decided))):
        raise ValueError("the inside and outside trees overlap: not a paving pair")
    gaps = (decided if band is None else decided.union(band)).complement()
    span = grid.depth - gaps.level
    total = int(np.sum(np.int64(1) << (grid.dim * span))) if len(gaps) else 0
    if total > MAX_REFINE_CELLS:
        raise ValueError(f"{total} undetermined cells: the trees do not look like a paving pair")
    # expand merged gap leaves back to depth-D cells
    coords = gaps.coords
    cells = [coords[gaps.level == grid.depth]]
    for s in unique(span[span > 0]):
        block = coords[span == s]
        for _ in range(int(s)):
            block = children(block)
        cells.append(block)
    coords = np.concatenate(cells) if cells else np.zeros((0, grid.dim), np.int64)
    return coords.reshape(-1, grid.dim).astype(np.int64)


def _descend(grid, test, level, coords, inside_parts, outside_parts, per_level, on_level, band_parts=()) -> Paving:
    parts = {INSIDE: list(inside_parts), OUTSIDE: list(outside_parts), BAND: list(band_parts)}
    paving, = _descend_many(grid, single(test), 1, level, coords, [parts], [list(per_level)], on_level)
    return paving


def _descend_many(grid, tests, count, level, coords, parts=None, per_level=None, on_level=None, open_=None) -> list[Paving]:
    """Breadth-first descent for `count` tests at once: `open_[:, c]`, the boxes still open for test c
    (given: the first boxes' columns, else all open). The boxes' Morton codes follow them down (a
    child's is its parent's and its child index)."""
    parts = parts or [{INSIDE: [], OUTSIDE: [], BAND: []} for _ in range(count)]
    per_level = per_level or [[] for _ in range(count)]
    undetermined = [np.zeros((0, grid.dim), dtype=np.int64)] * count
    if open_ is None:
        open_ = np.ones((len(coords), count), dtype=bool)
    codes = interleave(coords, level)
    while True:
        if on_level is not None:
            on_level(level, len(coords))
        status = _classify_many(grid, level, coords, open_, tests)
        status[~open_] = 127  # read only where open
        answers = (INSIDE, OUTSIDE, BAND) if (status == BAND).any() else (INSIDE, OUTSIDE)  # (bands: rare)
        for c in range(count):
            per_level[c].append(int(np.count_nonzero(open_[:, c])))
            answer = status[:, c]
            for value in answers:
                sel = codes[answer == value]
                if len(sel):
                    parts[c][value].append((level, sel))
        still = status == UNDETERMINED
        if level == grid.depth or not still.any():
            if level == grid.depth:
                undetermined = [np.compress(still[:, c], coords, axis=0) for c in range(count)]
            del coords, codes, open_, status, still, answer  # the last level's boxes: free them before the trees
            break
        any_open = _any_per_row(still)
        # (np.compress: rows of 2-D arrays at a third of boolean indexing's cost, the same rows)
        coords = children(np.compress(any_open, coords, axis=0))
        codes = child_codes(codes[any_open], grid.dim)
        open_ = np.repeat(np.compress(any_open, still, axis=0), 1 << grid.dim, axis=0)
        level += 1
    out = []
    for c in range(count):
        done = per_level[c] + [0] * (grid.depth + 1 - len(per_level[c]))
        trees = {value: _tree(grid, kept) for value, kept in parts[c].items()}
        parts[c] = None  # each paving's parts freed once its trees are built
        out.append(Paving(grid, trees[INSIDE], trees[OUTSIDE], undetermined[c], tuple(done), trees[BAND]))
    return out


def _any_per_row(mask: np.ndarray) -> np.ndarray:
    """mask.any(axis=1) of a C-contiguous boolean array (n, k): for k of 1, 2, 4 or 8, each row read
    as one unsigned integer (a fraction of the reduction's cost)."""
    k = mask.shape[1]
    if k in (1, 2, 4, 8) and mask.flags.c_contiguous:
        return mask.view(f"u{k}").ravel() != 0
    return mask.any(axis=1)


def _tree(grid: Grid, parts) -> Tree:
    """The tree of the cells found, given as (level, Morton codes) parts."""
    if not parts:
        return Tree.empty(grid)
    levels = [lev for lev, _ in parts]
    if (all(np.ndim(lev) == 0 for lev in levels) and len(set(levels)) == len(levels)
            and all(np.all(code[1:] > code[:-1]) for _, code in parts)):  # a descent's: one sorted part a level
        return Tree(grid, *_canonical_leaves(grid, parts), canonical=True)
    # saved trees' leaves (`refine`), cells in any order (`deepen`): canonicalised by Tree
    level = np.concatenate([np.broadcast_to(np.asarray(lev, np.int64), len(code)) for lev, code in parts])
    return Tree(grid, level, np.concatenate([code for _, code in parts]))


def _canonical_leaves(grid: Grid, parts) -> tuple[np.ndarray, np.ndarray]:
    """The canonical leaves (`paving.tree`) of the cells a descent decided, given as one part
    (level, sorted Morton codes) per level: from the deepest level up, every complete group of 2^dim
    sibling cells becomes its parent, a cell of the level above (which the descent split, so
    disjoint from that level's own cells); then the leaves in Morton preorder. The same leaves as
    Tree's general canonicalisation, without its sorts of every cell by finest index."""
    dim, group = grid.dim, 1 << grid.dim
    found = dict(parts)
    levels, codes = [], []
    merged = np.zeros(0, np.int64)
    for level in range(max(found), -1, -1):
        here = found.get(level)
        if here is None:
            here = merged
        elif len(merged):
            here = np.sort(np.concatenate([here, merged]), kind="stable")  # (two sorted runs: merged)
        if level and len(here) >= group:
            first = np.flatnonzero((here[:1 - group] & (group - 1)) == 0)  # a child 0 with room for its siblings
            first = first[here[first + group - 1] == here[first] + group - 1]  # ... and all of them found
            merged = here[first] >> dim
            if len(first):
                member = np.zeros(len(here), bool)
                for k in range(group):
                    member[first + k] = True
                here = here[~member]
        else:
            merged = np.zeros(0, np.int64)
        if len(here):
            levels.append(np.full(len(here), level, np.int64))
            codes.append(here)
    level, code = np.concatenate(levels), np.concatenate(codes)
    order = np.argsort(finest_key(code, level, dim, grid.depth), kind="stable")  # (sorted runs: merged)
    return level[order], code[order]
