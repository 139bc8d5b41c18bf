"""Quadtrees and octrees (fivebar_cli.paving.tree) against independent references written here:
a recursive B/W/G encoder over boolean grids, numpy boolean set algebra, Morton decoding by bits,
brute-force point location and a breadth-first flood fill (face contact only, periodic wrap)."""

from __future__ import annotations

from contextlib import contextmanager

import numpy as np
import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from conftest import (
    cells_of,
    flood_fill,
    leaf_coords,
    leaf_index_grid,
    morton_coords,
    ref_decode,
    ref_encode,
    tree_to_bool,
    upsample,
)
from fivebar_cli.paving.grid import Grid
from fivebar_cli.paving import tree as tree_module
from fivebar_cli.paving.tree import BodyError, Tree

SETTINGS = settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
DYADIC_ROOT = ((-13.0, 13.0), (-13.0, 13.0))  # 26^2 / 4^D is exact: areas compare with ==
ODD_ROOT = ((-1.5, 2.25), (-3.0, 0.5))


# ---------------------------------------------------------------- random sets


def blocky(rng: np.random.Generator, depth: int, dim: int, p_split: float, p_black: float) -> np.ndarray:
    """A random set made of dyadic blocks of all sizes (so merges and greys both occur)."""
    n = 1 << depth
    arr = np.zeros((n,) * dim, dtype=bool)

    def rec(origin, size):
        if size == 1 or rng.random() > p_split:
            if rng.random() < p_black:
                arr[tuple(slice(o, o + size) for o in origin)] = True
            return
        h = size // 2
        for k in range(1 << dim):
            rec(tuple(o + h * ((k >> j) & 1) for j, o in enumerate(origin)), h)

    rec((0,) * dim, n)
    return arr


@st.composite
def grids(draw, dim: int = 2, max_depth: int = 5, min_depth: int = 0):
    """(depth, boolean grid of shape (2^depth,)*dim indexed [x, y, (z)])."""
    depth = draw(st.integers(min_depth, max_depth))
    kind = draw(st.sampled_from(["blocky", "noise", "empty", "full", "single", "blocky"]))
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    n = 1 << depth
    if kind == "blocky":
        arr = blocky(rng, depth, dim, draw(st.floats(0.3, 0.95)), draw(st.floats(0.2, 0.8)))
    elif kind == "noise":
        arr = rng.random((n,) * dim) < draw(st.floats(0.0, 1.0))
    elif kind == "empty":
        arr = np.zeros((n,) * dim, dtype=bool)
    elif kind == "full":
        arr = np.ones((n,) * dim, dtype=bool)
    else:
        arr = np.zeros((n,) * dim, dtype=bool)
        arr[tuple(rng.integers(0, n, size=dim))] = True
    return depth, arr


def make_tree(arr: np.ndarray, depth: int, root=DYADIC_ROOT, periodic=None) -> Tree:
    dim = arr.ndim
    if len(root) != dim:
        root = tuple((-1.0, 1.0) for _ in range(dim))
    periodic = periodic if periodic is not None else (False,) * dim
    return Tree.from_cells(Grid(root, depth, periodic), depth, cells_of(arr))


def ref_leaves(arr: np.ndarray) -> tuple[list[int], list[tuple[int, ...]]]:
    """Maximal black blocks (the canonical leaves) of a boolean grid, found recursively."""
    dim, levels, coords = arr.ndim, [], []

    def rec(block, level, coord):
        if block.all():
            levels.append(level)
            coords.append(coord)
        elif block.any():
            h = block.shape[0] // 2
            for k in range(1 << dim):
                idx = tuple(slice(h, None) if (k >> j) & 1 else slice(0, h) for j in range(dim))
                rec(block[idx], level + 1, tuple(2 * c + ((k >> j) & 1) for j, c in enumerate(coord)))

    rec(arr, 0, (0,) * dim)
    return levels, coords


def assert_canonical(tree: Tree) -> None:
    """Leaves sorted in preorder, disjoint, within the depth, and no 2^dim black siblings."""
    dim, depth = tree.grid.dim, tree.grid.depth
    lev, code = tree.level.tolist(), tree.code.tolist()
    assert all(0 <= l <= depth for l in lev)
    starts = [c << (dim * (depth - l)) for l, c in zip(lev, code)]
    ends = [s + (1 << (dim * (depth - l))) for s, l in zip(starts, lev)]
    assert starts == sorted(starts)
    assert all(e <= s for e, s in zip(ends[:-1], starts[1:]))
    siblings: dict[tuple[int, int], int] = {}
    for l, c in zip(lev, code):
        if l > 0:
            siblings[l, c >> dim] = siblings.get((l, c >> dim), 0) + 1
    assert max(siblings.values(), default=0) < (1 << dim), "2^dim black siblings were not merged"


# ---------------------------------------------------------------- B/W/G codec


def test_bwg_child_order_is_the_design_order():
    g1 = Grid(((0.0, 1.0), (0.0, 1.0)), 1, (False, False))
    # (x low, y low), (x high, y low), (x low, y high), (x high, y high)
    assert Tree.from_cells(g1, 1, np.array([[1, 0]])).to_bwg() == "GWBWW"
    assert Tree.from_cells(g1, 1, np.array([[0, 1]])).to_bwg() == "GWWBW"
    assert Tree.from_cells(g1, 1, np.array([[1, 1], [0, 0]])).to_bwg() == "GBWWB"
    g2 = g1.with_depth(2)
    assert Tree.from_cells(g2, 2, np.array([[1, 0]])).to_bwg() == "GGWBWWWWW"
    assert Tree.from_cells(g2, 2, np.array([[3, 3]])).to_bwg() == "GWWWGWWWB"
    g3 = Grid(((0.0, 1.0),) * 3, 1, (False,) * 3)
    assert Tree.from_cells(g3, 1, np.array([[0, 0, 1]])).to_bwg() == "GWWWWBWWW"  # phi high after phi low
    assert Tree.empty(g2).to_bwg() == "W"
    assert Tree.full(g2).to_bwg() == "B"


@SETTINGS
@given(grids(dim=2, max_depth=6))
@example((0, np.zeros((1, 1), dtype=bool)))
@example((0, np.ones((1, 1), dtype=bool)))
@example((3, np.zeros((8, 8), dtype=bool)))
@example((3, np.ones((8, 8), dtype=bool)))
@example((3, np.eye(8, dtype=bool)))
def test_bwg_round_trip_quadtree(case):
    depth, arr = case
    tree = make_tree(arr, depth)
    body = tree.to_bwg()
    assert body == ref_encode(arr)
    assert np.array_equal(tree_to_bool(tree), arr)
    back = Tree.from_bwg(tree.grid, body)
    assert back == tree
    assert np.array_equal(ref_decode(body, depth, 2), arr)
    assert_canonical(tree)


def test_bwg_single_cell_at_every_depth():
    for depth in range(0, 8):
        n = 1 << depth
        for x, y in ((0, 0), (n - 1, 0), (0, n - 1), (n - 1, n - 1), (n // 3, n // 2)):
            arr = np.zeros((n, n), dtype=bool)
            arr[x, y] = True
            tree = make_tree(arr, depth)
            assert tree.to_bwg() == ref_encode(arr)
            assert len(tree) == 1 and tree.level[0] == depth
            assert morton_coords(int(tree.code[0]), depth, 2) == (x, y)
            assert Tree.from_bwg(tree.grid, tree.to_bwg()) == tree


@pytest.mark.parametrize("dim, depth", [(2, 6), (3, 3)])
def test_bwg_of_sparse_and_dense_sets(dim, depth):
    """The encoder cuts the gaps between black runs into white blocks itself: sets with long gaps
    (a few black cells) and many short ones (a few white cells), against the recursive encoder."""
    rng = np.random.default_rng(22)
    for density in (0.002, 0.02, 0.2, 0.8, 0.98, 0.998):
        arr = rng.random((1 << depth,) * dim) < density
        assert make_tree(arr, depth).to_bwg() == ref_encode(arr)


@settings(max_examples=40, deadline=None)
@given(dim=st.integers(2, 3), depth=st.integers(1, 8), seed=st.integers(0, 10 ** 6), count=st.integers(1, 30))
def test_white_leaves_are_the_greedy_cut(dim, depth, seed, count):
    """codec._white_leaves (each block's gap, grey count and rank, in rounds) against
    morton.aligned_blocks round by round, the grey count from the block's start and level: the
    levels above it at which the start is aligned."""
    from fivebar_cli.paving.codec import _white_leaves
    from fivebar_cli.paving.morton import aligned_blocks

    rng = np.random.default_rng(seed)
    ends = np.unique(rng.integers(0, (1 << (dim * depth)) + 1, 2 * count))  # disjoint gaps [a, b), a < b
    a, b = ends[0:len(ends) - 1:2], ends[1::2]
    keep = np.flatnonzero(rng.random(len(a)) < 0.8)  # (their numbers need not run 0, 1, ...)
    gap, grey, nth = _white_leaves(keep, a[keep], b[keep], dim, depth)
    want_gap, want_grey, want_nth, numbers = [], [], [], keep
    for i, (start, span, more) in enumerate(aligned_blocks(a[keep], b[keep], dim, depth)):
        aligned = [next(k for k in range(depth, -1, -1) if int(s) % (1 << (dim * k)) == 0) for s in start]
        want_gap += numbers.tolist()
        want_grey += [al - int(sp) for al, sp in zip(aligned, span)]
        want_nth += [i] * len(start)
        numbers = numbers[more]
    assert gap.tolist() == want_gap and grey.tolist() == want_grey and nth.tolist() == want_nth


@settings(max_examples=30, deadline=None)
@given(grids(dim=3, max_depth=4))
def test_bwg_round_trip_octree(case):
    depth, arr = case
    tree = make_tree(arr, depth)
    body = tree.to_bwg()
    assert body == ref_encode(arr)
    assert np.array_equal(tree_to_bool(tree), arr)
    assert Tree.from_bwg(tree.grid, body) == tree
    assert_canonical(tree)


# ---------------------------------------------------------------- canonical form


def test_four_black_siblings_merge_into_their_parent():
    grid = Grid(DYADIC_ROOT, 3, (False, False))
    kids = np.array([[2, 4], [3, 4], [2, 5], [3, 5]])
    tree = Tree.from_cells(grid, 3, kids)
    assert tree == Tree.from_cells(grid, 2, np.array([[1, 2]]))
    assert tree.level.tolist() == [2] and len(tree) == 1
    # three of them stay three leaves
    assert len(Tree.from_cells(grid, 3, kids[:3])) == 3
    # all cells of the grid merge up to the root
    n = 8
    all_cells = np.array([[x, y] for x in range(n) for y in range(n)])
    assert Tree.from_cells(grid, 3, all_cells) == Tree.full(grid)
    assert Tree.from_cells(grid, 3, all_cells).level.tolist() == [0]


@SETTINGS
@given(grids(dim=2, max_depth=6))
def test_tree_from_cells_equals_tree_from_merged_cells(case):
    depth, arr = case
    grid = Grid(DYADIC_ROOT, depth, (False, False))
    levels, coords = ref_leaves(arr)
    merged = Tree.from_cells(grid, np.array(levels, dtype=np.int64), np.array(coords, dtype=np.int64).reshape(-1, 2))
    fine = Tree.from_cells(grid, depth, cells_of(arr))
    assert merged == fine
    assert sorted(zip(fine.level.tolist(), map(tuple, fine.coords.tolist()))) == sorted(zip(levels, coords))
    # a shuffled, partially split input gives the same canonical tree
    rng = np.random.default_rng(depth)
    order = rng.permutation(len(fine)) if len(fine) else np.zeros(0, int)
    assert Tree(grid, fine.level[order], fine.code[order]) == fine


def test_overlapping_or_too_deep_cells_are_rejected():
    grid = Grid(DYADIC_ROOT, 2, (False, False))
    with pytest.raises(ValueError):
        Tree.from_cells(grid, np.array([1, 2]), np.array([[0, 0], [1, 1]]))  # (1,1)@2 lies in (0,0)@1
    with pytest.raises(ValueError):
        Tree.from_cells(grid, 3, np.array([[0, 0]]))


def test_grid_validation():
    with pytest.raises(ValueError):
        Grid(((1.0, 1.0), (0.0, 1.0)), 3, (False, False))
    with pytest.raises(ValueError):
        Grid(((0.0, float("inf")), (0.0, 1.0)), 3, (False, False))
    with pytest.raises(ValueError):
        Grid(((0.0, 1.0), (0.0, 1.0)), -1, (False, False))
    with pytest.raises(ValueError):
        Grid(((0.0, 1.0), (0.0, 1.0)), 27, (False, False))  # 2 * 27 > 52 index bits
    with pytest.raises(ValueError):
        Grid(((0.0, 1.0), (0.0, 1.0)), 3, (False,))
    Grid(((0.0, 1.0), (0.0, 1.0)), 26, (False, False))
    Grid(((0.0, 1.0),) * 3, 17, (False,) * 3)


# ---------------------------------------------------------------- set operations


@SETTINGS
@given(grids(dim=2, max_depth=5), grids(dim=2, max_depth=5), st.sampled_from([(False, False), (True, True), (False, True)]))
def test_set_operations_against_boolean_grids(a, b, periodic):
    da, A = a
    db, B = b
    D = max(da, db)
    ta, tb = make_tree(A, da, periodic=periodic), make_tree(B, db, periodic=periodic)
    ua, ub = upsample(A, D - da), upsample(B, D - db)
    cell = 26.0 * 26.0 / 4**D
    for result, ref in (
        (ta | tb, ua | ub),
        (ta & tb, ua & ub),
        (ta - tb, ua & ~ub),
        (tb - ta, ub & ~ua),
        (ta ^ tb, ua ^ ub),
        (ta.union(tb), ua | ub),
        (ta.intersection(tb), ua & ub),
        (ta.difference(tb), ua & ~ub),
        (ta.symmetric_difference(tb), ua ^ ub),
    ):
        assert result.grid.depth == D and result.grid.root == DYADIC_ROOT and result.grid.periodic == periodic
        assert np.array_equal(tree_to_bool(result), ref)
        assert_canonical(result)
        assert result.area == ref.sum() * cell
    comp = ta.complement()
    assert comp.grid == ta.grid
    assert np.array_equal(tree_to_bool(comp), ~A)
    assert_canonical(comp)
    assert comp.area + ta.area == 26.0 * 26.0


def test_set_operations_need_the_same_root():
    a = Tree.full(Grid(DYADIC_ROOT, 3, (False, False)))
    other_root = Tree.full(Grid(((-13.0, 13.0), (-13.0, 13.5)), 3, (False, False)))
    other_wrap = Tree.full(Grid(DYADIC_ROOT, 3, (True, True)))
    for b in (other_root, other_wrap):
        with pytest.raises(ValueError):
            a | b
        with pytest.raises(ValueError):
            a - b


def test_with_depth_keeps_the_set():
    rng = np.random.default_rng(5)
    arr = blocky(rng, 3, 2, 0.8, 0.5)
    tree = make_tree(arr, 3)
    deeper = tree.with_depth(5)
    assert deeper.grid.depth == 5
    assert np.array_equal(tree_to_bool(deeper), upsample(arr, 2))
    assert deeper.area == tree.area
    if tree.level.max(initial=0) > 1:
        with pytest.raises(ValueError):
            tree.with_depth(1)


# ---------------------------------------------------------------- area


@SETTINGS
@given(grids(dim=2, max_depth=7))
def test_area_is_exact(case):
    depth, arr = case
    tree = make_tree(arr, depth)
    assert tree.area == arr.sum() * (26.0 * 26.0 / 4**depth)  # dyadic: exact in floating point
    odd = make_tree(arr, depth, root=ODD_ROOT)
    assert odd.area == pytest.approx(arr.sum() * 3.75 * 3.5 / 4**depth, rel=1e-14, abs=0)


def test_octree_volume_is_exact():
    rng = np.random.default_rng(3)
    arr = blocky(rng, 4, 3, 0.8, 0.5)
    tree = Tree.from_cells(Grid(((0.0, 2.0), (-1.0, 1.0), (4.0, 8.0)), 4, (False,) * 3), 4, cells_of(arr))
    assert tree.area == arr.sum() * (2.0 * 2.0 * 4.0 / 8**4)


# ---------------------------------------------------------------- point location


@SETTINGS
@given(grids(dim=2, max_depth=6), st.integers(0, 2**32 - 1), st.sampled_from([(False, False), (True, False), (True, True)]))
def test_locate_against_brute_force(case, seed, periodic):
    depth, arr = case
    tree = make_tree(arr, depth, root=ODD_ROOT, periodic=periodic)
    rng = np.random.default_rng(seed)
    lo = np.array([ODD_ROOT[0][0], ODD_ROOT[1][0]])
    size = np.array([3.75, 3.5])
    n = 1 << depth
    pts = lo + rng.random((500, 2)) * size
    rel = (pts - lo) / size * n
    frac = rel - np.floor(rel)
    pts = pts[(np.min(frac, axis=1) > 1e-6) & (np.max(frac, axis=1) < 1 - 1e-6)]  # off the cell edges
    cell = np.floor((pts - lo) / size * n).astype(int)
    expected = arr[cell[:, 0], cell[:, 1]]
    found = tree.locate(pts)
    assert np.array_equal(found >= 0, expected)
    owner = leaf_index_grid(tree)
    assert np.array_equal(found[expected], owner[cell[expected, 0], cell[expected, 1]])
    # leaf bounds, computed here from the Morton code, contain the point
    for p, leaf in zip(pts[expected], found[expected]):
        lev = int(tree.level[leaf])
        c = np.array(morton_coords(int(tree.code[leaf]), lev, 2))
        w = size / (1 << lev)
        assert np.all(lo + c * w <= p) and np.all(p <= lo + (c + 1) * w)
    # shifting by whole periods on the periodic axes changes nothing; elsewhere the point leaves the root
    for axis in range(2):
        shifted = pts.copy()
        shifted[:, axis] += size[axis] * rng.choice([-2, -1, 1, 3], size=len(pts))
        got = tree.locate(shifted)
        if periodic[axis]:
            assert np.array_equal(got, found)
        else:
            assert np.all(got == -1)


def test_locate_on_the_root_boundary():
    grid = Grid(((0.0, 1.0), (0.0, 1.0)), 2, (False, False))
    full = Tree.full(grid)
    assert full.locate(np.array([[0.0, 0.0], [1.0, 1.0], [1.0, 0.5]])).tolist() == [0, 0, 0]
    assert full.locate(np.array([[1.0 + 1e-9, 0.5], [-1e-9, 0.5], [np.nan, 0.5]])).tolist() == [-1, -1, -1]
    assert Tree.empty(grid).locate(np.array([[0.5, 0.5]])).tolist() == [-1]


# ---------------------------------------------------------------- connected components


def assert_components_match(tree: Tree, arr: np.ndarray, periodic) -> int:
    labels, count = tree.components()
    ref, ref_count = flood_fill(arr, periodic)
    assert count == ref_count
    owner = leaf_index_grid(tree)
    cells = arr.nonzero()
    pairs = set(zip(ref[cells].tolist(), labels[owner[cells]].tolist()))
    assert len(pairs) == ref_count  # the two partitions are the same (a bijection of labels)
    # labels are numbered in Morton order of each component's first leaf
    first_seen = []
    for lab in labels.tolist():
        if lab not in first_seen:
            first_seen.append(lab)
    assert first_seen == list(range(count))
    parts = tree.split_components()
    assert len(parts) == count
    if parts:
        union = parts[0]
        for p in parts[1:]:
            assert len(union & p) == 0
            union = union | p
        assert union == tree
    return count


@settings(max_examples=80, deadline=None)
@given(grids(dim=2, max_depth=6), st.sampled_from([(False, False), (True, True), (True, False), (False, True)]))
def test_components_against_flood_fill(case, periodic):
    depth, arr = case
    tree = make_tree(arr, depth, periodic=periodic)
    assert_components_match(tree, arr, periodic)


def test_components_checkerboard_cells_are_all_separate():
    for depth in (1, 3, 4):
        n = 1 << depth
        x, y = np.indices((n, n))
        arr = (x + y) % 2 == 0
        for periodic in ((False, False), (True, True)):
            tree = make_tree(arr, depth, periodic=periodic)
            assert assert_components_match(tree, arr, periodic) == n * n // 2


def test_components_corner_contact_does_not_connect():
    arr = np.zeros((4, 4), dtype=bool)
    arr[0, 0] = arr[1, 1] = True
    assert assert_components_match(make_tree(arr, 2), arr, (False, False)) == 2
    # a big leaf and a small one meeting at a corner
    arr = np.zeros((4, 4), dtype=bool)
    arr[0:2, 0:2] = True
    arr[2, 2] = True
    tree = make_tree(arr, 2)
    assert sorted(tree.level.tolist()) == [1, 2]
    assert assert_components_match(tree, arr, (False, False)) == 2
    # the same pair touching along a face is one component
    arr[2, 2] = False
    arr[2, 1] = True
    assert assert_components_match(make_tree(arr, 2), arr, (False, False)) == 1
    # diagonal cells in opposite corners touch only through the wrapped corner
    arr = np.zeros((8, 8), dtype=bool)
    arr[0, 0] = arr[7, 7] = True
    assert assert_components_match(make_tree(arr, 3, periodic=(True, True)), arr, (True, True)) == 2


def test_components_band_across_the_periodic_boundary():
    arr = np.zeros((8, 8), dtype=bool)
    arr[0, :] = True  # x = 0 column and x = 7 column: one band through x = +-pi
    arr[7, :] = True
    assert assert_components_match(make_tree(arr, 3, periodic=(True, True)), arr, (True, True)) == 1
    assert assert_components_match(make_tree(arr, 3, periodic=(True, False)), arr, (True, False)) == 1
    assert assert_components_match(make_tree(arr, 3, periodic=(False, True)), arr, (False, True)) == 2
    assert assert_components_match(make_tree(arr, 3), arr, (False, False)) == 2
    # a single cell pair across the y boundary, different leaf sizes
    arr = np.zeros((8, 8), dtype=bool)
    arr[4:8, 4:8] = True
    arr[5, 0] = True
    assert assert_components_match(make_tree(arr, 3, periodic=(False, True)), arr, (False, True)) == 1
    assert assert_components_match(make_tree(arr, 3, periodic=(True, False)), arr, (True, False)) == 2


def test_components_full_and_empty():
    for depth in (0, 1, 3):
        for periodic in ((False, False), (True, True)):
            grid = Grid(DYADIC_ROOT, depth, periodic)
            assert Tree.full(grid).components()[1] == 1
            assert Tree.empty(grid).components()[1] == 0
    # half the torus: one leaf at level 1 is its own neighbour's neighbour, still one component
    grid = Grid(DYADIC_ROOT, 1, (True, True))
    tree = Tree.from_cells(grid, 1, np.array([[0, 0], [1, 1]]))
    assert tree.components()[1] == 2
    tree = Tree.from_cells(grid, 1, np.array([[0, 0], [1, 0]]))
    assert tree.components()[1] == 1


@settings(max_examples=30, deadline=None)
@given(grids(dim=3, max_depth=4), st.sampled_from([(False, False, False), (False, False, True), (True, True, True)]))
def test_octree_components_against_flood_fill(case, periodic):
    depth, arr = case
    tree = make_tree(arr, depth, periodic=periodic)
    assert_components_match(tree, arr, periodic)


def test_octree_band_across_the_phi_boundary():
    arr = np.zeros((4, 4, 4), dtype=bool)
    arr[1, 1, 0] = arr[1, 1, 3] = True
    arr[2, 2, 1] = True  # touches neither (edge contact with nothing, corner at most)
    assert assert_components_match(make_tree(arr, 2, periodic=(False, False, True)), arr, (False, False, True)) == 2
    assert assert_components_match(make_tree(arr, 2), arr, (False, False, False)) == 3


# ---------------------------------------------------------------- coverage rasters


@SETTINGS
@given(grids(dim=2, max_depth=5))
def test_coverage_against_boolean_grids(case):
    depth, arr = case
    tree = make_tree(arr, depth)
    for level in range(0, depth + 3):
        img = tree.coverage(level)
        n = 1 << level
        assert img.shape == (n, n)
        if level >= depth:
            ref = upsample(arr, level - depth).astype(float)
        else:
            k = 1 << (depth - level)
            ref = arr.reshape(n, k, n, k).mean(axis=(1, 3))
        np.testing.assert_allclose(img, ref.T, rtol=0, atol=1e-12)  # raster is indexed [y, x]


def test_coverage_is_for_quadtrees_only():
    with pytest.raises(ValueError):
        Tree.full(Grid(((0.0, 1.0),) * 3, 2, (False,) * 3)).coverage(2)


# ---------------------------------------------------------------- malformed bodies


@pytest.mark.parametrize(
    "depth, body, position, words",
    [
        (2, "", 0, "empty"),
        (2, "G", 1, "truncated"),
        (2, "GBWB", 4, "truncated"),
        (2, "GGBBB", 5, "truncated"),
        (2, "BW", 1, "extra"),
        (2, "GBBBWB", 5, "extra"),
        (2, "GBWWBGWWWW", 5, "extra"),
        (2, "GBXBW", 2, "unexpected character"),
        (2, "gBWBW", 0, "unexpected character"),
        (2, "GB BW", 2, "unexpected character"),
        (2, "GBW\u00e9W", 3, "unexpected character"),
        (1, "GGBBBBBBB", 1, "deeper"),
        (0, "GBBBB", 0, "deeper"),
        (2, "GWGWWGBBBBWWW", 5, "deeper"),  # grey at level 1 is fine, at level 2 (position 5) not
    ],
)
def test_malformed_bodies_raise_body_error_with_position(depth, body, position, words):
    grid = Grid(DYADIC_ROOT, depth, (False, False))
    with pytest.raises(BodyError) as err:
        Tree.from_bwg(grid, body)
    assert err.value.position == position
    assert words in str(err.value)


def test_well_formed_bodies_at_the_depth_limit_parse():
    grid = Grid(DYADIC_ROOT, 1, (False, False))
    assert np.array_equal(tree_to_bool(Tree.from_bwg(grid, "GBWWB")), np.array([[True, False], [False, True]]))
    grid3 = Grid(((0.0, 1.0),) * 3, 1, (False,) * 3)
    with pytest.raises(BodyError) as err:
        Tree.from_bwg(grid3, "GBBBB")  # an octree grey node has eight children
    assert err.value.position == 5
    # non-canonical bodies (four black siblings) are accepted and canonicalised
    assert Tree.from_bwg(grid, "GBBBB") == Tree.full(grid)


# ---------------------------------------------------------------- neighbour pairs


def brute_pairs(tree: Tree, target: Tree, offset, itself: bool) -> list[tuple[int, int]]:
    """(i, j) for each leaf i of `tree` whose same-size cell one step along `offset` (wrapping on
    periodic axes) lies inside leaf j of `target`, in order of i: read off a depth-D grid of leaf
    indices (the definition of `Tree.adjacency`), level by level: the block of depth-D cells under
    each cell of that level holds one leaf j when its smallest and largest index are that j."""
    grid, dim, depth = tree.grid, tree.grid.dim, tree.grid.depth
    owner = leaf_index_grid(target)
    level, coords = np.asarray(tree.level, dtype=np.int64), leaf_coords(tree) + np.asarray(offset)
    found_i, found_j = [], []
    for lev in np.unique(level).tolist():
        n, s = 1 << lev, 1 << (depth - lev)
        i = np.flatnonzero(level == lev)
        c = coords[i]
        keep = np.all([grid.periodic[a] | ((c[:, a] >= 0) & (c[:, a] < n)) for a in range(dim)], axis=0)
        i, c = i[keep], c[keep] % n
        blocks = owner.reshape(sum(((n, s) for _ in range(dim)), ()))
        inner = tuple(range(1, 2 * dim, 2))
        low, high = blocks.min(axis=inner)[tuple(c.T)], blocks.max(axis=inner)[tuple(c.T)]
        ok = (low >= 0) & (low == high) & ~(itself & (low == i))
        found_i.append(i[ok])
        found_j.append(low[ok])
    i, j = np.concatenate([np.zeros(0, np.int64), *found_i]), np.concatenate([np.zeros(0, np.int64), *found_j])
    order = np.argsort(i, kind="stable")
    return list(zip(i[order].tolist(), j[order].tolist()))


@contextmanager
def window(near: int):
    """Neighbour searches with windows of `near` leaves (tree.NEAR) for a while."""
    old = tree_module.NEAR
    tree_module.NEAR = near
    try:
        yield
    finally:
        tree_module.NEAR = old


def random_tree(rng, grid: Grid, depth: int) -> Tree:
    arr = blocky(rng, depth, grid.dim, rng.uniform(0.4, 0.95), rng.uniform(0.2, 0.8))
    return Tree.from_cells(grid, depth, cells_of(arr))


@pytest.mark.parametrize("near", [1, 3, 16])  # tiny windows: most searches fall back to the binary search
@settings(max_examples=25, deadline=None)
@given(st.integers(0, 2**32 - 1), st.sampled_from([2, 3]), st.booleans())
def test_neighbour_pairs_against_a_leaf_by_leaf_reference(near, seed, dim, corners):
    """Tree.neighbour_pairs, direction by direction, equals the definition: within a tree, against
    another tree, and against another tree and itself (`itself`: other's leaves numbered first)."""
    with window(near):
        check_neighbour_pairs(np.random.default_rng(seed), dim, corners)


def check_neighbour_pairs(rng, dim: int, corners: bool) -> None:
    depth = int(rng.integers(0, 6 if dim == 2 else 4))
    grid = Grid(tuple((-1.0, 1.0) for _ in range(dim)), depth, tuple(bool(b) for b in rng.integers(0, 2, dim)))
    a = random_tree(rng, grid, depth)
    b = random_tree(rng, grid, depth) - a  # disjoint from a: a and b are one set of cells
    offsets = tree_module._offsets(dim, corners)
    for offset, (i, j) in zip(offsets, a.neighbour_pairs(corners=corners)):
        assert list(zip(i.tolist(), j.tolist())) == brute_pairs(a, a, offset, True)
    for offset, (i, j) in zip(offsets, a.neighbour_pairs(b, corners=corners)):
        assert list(zip(i.tolist(), j.tolist())) == brute_pairs(a, b, offset, False)
    for offset, (i, j) in zip(offsets, a.neighbour_pairs(b, corners=corners, itself=True)):
        expected = sorted(brute_pairs(a, b, offset, False) + [(x, len(b) + y) for x, y in brute_pairs(a, a, offset, True)])
        assert list(zip(i.tolist(), j.tolist())) == expected
    i, j = a.adjacency(corners=corners)
    assert sorted(zip(i.tolist(), j.tolist())) == sorted(p for o in offsets for p in brute_pairs(a, a, o, True))
    # `once`: a's cells as leaves of one level, their own pairs looked up in half the directions
    index = np.concatenate([np.zeros(0, np.int64)] + [np.arange(s, e) for s, e in zip(a.start.tolist(), a.end.tolist())])
    cells = Tree(grid, np.full(len(index), depth), index, canonical=True)
    forward = [o for o in offsets if o[np.flatnonzero(o)[0]] > 0]
    assert len(forward) == len(offsets) // 2
    for other, shift in ((b, len(b)), (None, 0)):
        blocks = list(cells.neighbour_pairs(other, corners=corners, itself=other is not None, once=True))
        assert len(blocks) == len(offsets)
        for n, offset in enumerate(forward):
            own = [(x, shift + y) for x, y in brute_pairs(cells, cells, offset, True)]
            across = brute_pairs(cells, b, offset, False) if other is not None else []
            back = brute_pairs(cells, b, -offset, False) if other is not None else []
            i, j = blocks[2 * n]
            assert list(zip(i.tolist(), j.tolist())) == sorted(across + own)
            i, j = blocks[2 * n + 1]
            assert list(zip(i.tolist(), j.tolist())) == back
            # the opposite direction's own pairs are those found, reversed
            assert sorted((y - shift, x) for x, y in own) == brute_pairs(cells, cells, -offset, True)


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 4), st.sampled_from([-1, 0, 1]))
def test_search_near_equals_a_binary_search(seed, near, sign):
    """_search_near (the leaf holding each query, from the NEAR leaves around the querying one)
    equals np.searchsorted for queries at any distance on the side `sign` says (both when 0)."""
    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 200))
    start = np.unique(rng.integers(0, 10 * n, n))
    padded = np.concatenate([np.full(near, -1), start, np.full(near, np.iinfo(np.int64).max)])
    step = rng.geometric(0.3, len(start)) * rng.choice([1, 5, 50], len(start))
    side = sign if sign else rng.choice([-1, 1], len(start))
    first = np.maximum(start + np.where(side > 0, step, -step), 0)
    for s in (0, len(start) // 3):
        chunk = first[s:]
        with window(near):
            got = tree_module._search_near(padded, start, chunk, s, sign)
        assert np.array_equal(got, np.searchsorted(start, chunk, side="right") - 1)


@pytest.mark.parametrize("dim, deepest", [(1, 52), (2, 26), (3, 17), (4, 13)])
def test_morton_codes_bit_by_bit(dim, deepest):
    """interleave / deinterleave (magic-mask dilation) against the bit-by-bit definition, at mixed
    levels from 0 to the deepest a grid allows, the first and last cells of each level included."""
    from fivebar_cli.paving.morton import deinterleave, interleave

    rng = np.random.default_rng(dim)
    level = np.concatenate([np.arange(deepest + 1), np.arange(deepest + 1), rng.integers(0, deepest + 1, 300)])
    coords = rng.integers(0, 1 << 62, (len(level), dim)) >> (62 - level[:, None])
    coords[: deepest + 1] = 0
    coords[deepest + 1: 2 * deepest + 2] = (1 << level[deepest + 1: 2 * deepest + 2, None]) - 1
    code = interleave(coords, level)
    want = [sum(((int(c[j]) >> b) & 1) << (b * dim + j) for b in range(int(lev)) for j in range(dim))
            for c, lev in zip(coords, level)]
    assert code.tolist() == want
    assert [morton_coords(int(k), int(lev), dim) for k, lev in zip(code, level)] == [tuple(c) for c in coords.tolist()]
    assert deinterleave(code, level, dim).tolist() == coords.tolist()
    for lev in (0, 1, deepest):  # one level for every cell, as the engine and the trees call them
        same = coords >> (level[:, None] - np.minimum(level, lev)[:, None])
        assert deinterleave(interleave(same, lev), lev, dim).tolist() == same.tolist()


def test_trailing_zeros_and_floor_log2_against_python_ints():
    """morton.floor_log2 / trailing_zeros (float64 exponent bits) against int.bit_length, for every
    cap a grid allows (0..52), at 0, powers of two, their neighbours and random values below 2^cap."""
    from fivebar_cli.paving.morton import floor_log2, trailing_zeros

    rng = np.random.default_rng(7)
    for cap in range(53):
        top = 1 << cap
        x = np.unique(np.concatenate([[0, top - 1], [1 << b for b in range(cap)], [(1 << b) + 1 for b in range(cap)],
                                      [(1 << b) - 1 for b in range(1, cap + 1)],
                                      rng.integers(0, top, 50) if cap else []]).astype(np.int64))
        x = x[x < top]
        want = [cap if v == 0 else (v & -v).bit_length() - 1 for v in x.tolist()]
        assert trailing_zeros(x, cap).tolist() == want
        positive = x[x > 0]
        assert floor_log2(positive).tolist() == [v.bit_length() - 1 for v in positive.tolist()]
