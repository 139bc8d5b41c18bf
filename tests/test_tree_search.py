"""The neighbour searches' shortcuts (issue 22, seventh pass) against what they replace: binary
searches on 32-bit keys against int64 ones, point location of finest indices (with -1) against a
brute force, union-find whose paths are halved once a block against scipy's components on
graphs of long chains (many hooking rounds), and the once pass's second direction against the
plain adjacency."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from fivebar_cli.paving.grid import Grid
from fivebar_cli.paving.morton import interleave
from conftest import cells_of
from fivebar_cli.paving import tree as tree_module
from fivebar_cli.paving.tree import Tree, _leaf_at, _search_keys, union_find_blocks
from test_quadtree import blocky


@pytest.mark.parametrize("depth, dtype", [(16, np.uint32), (17, np.int64)])
def test_leaf_search_keys_against_int64_searchsorted(depth, dtype):
    """Keys in 32 bits exactly when the depth-D indices fit (2-D up to depth 16), and the same
    answers as an int64 search, at both ends of the index range too."""
    grid = Grid(((0.0, 1.0), (0.0, 1.0)), depth, (False, False))
    top = 1 << (2 * depth)
    rng = np.random.default_rng(depth)
    start = np.unique(np.r_[0, top - 1, rng.integers(0, top, 5000)])
    keys = _search_keys(start, grid)
    assert keys.dtype == dtype and np.array_equal(keys.astype(np.int64), start)
    query = np.r_[0, 1, top - 2, top - 1, start, start + 1, rng.integers(0, top, 5000)].astype(np.int64)
    query = query[query < top]
    assert np.array_equal(_leaf_at(keys, query), np.searchsorted(start, query, side="right") - 1)
    assert np.array_equal(_leaf_at(keys, query[:0]), np.zeros(0, np.int64))


@pytest.mark.parametrize("depth", [16, 17])
def test_locate_finest_against_brute_force(depth):
    """Each finest index's leaf by a scan of the leaves' intervals (-1 outside every leaf, and
    for the index -1 a point outside the root has)."""
    grid = Grid(((0.0, 1.0), (0.0, 1.0)), depth, (False, False))
    top = 1 << (2 * depth)
    rng = np.random.default_rng(40 + depth)
    cuts = np.unique(np.r_[0, rng.integers(0, top, 400), top])
    keep = rng.random(len(cuts) - 1) < 0.5
    tree = Tree.from_intervals(grid, cuts[:-1][keep], cuts[1:][keep])
    start, end = tree.start, tree.end
    query = np.r_[-1, 0, top - 1, start, end - 1, np.minimum(end, top - 1), rng.integers(0, top, 2000), -1]
    inside = (start[None, :] <= query[:, None]) & (query[:, None] < end[None, :])
    expected = np.where(inside.any(axis=1), inside.argmax(axis=1), -1)
    assert np.array_equal(tree.locate_finest(query), expected)
    assert np.array_equal(Tree.empty(grid).locate_finest(query), np.full(len(query), -1))


def _chains(rng, n: int, blocks: int):
    """Edges of a few long paths through a shuffled order of the nodes, cut into blocks: each
    block's hooking takes several rounds and leaves long pointer chains."""
    order = rng.permutation(n)
    breaks = np.sort(rng.choice(np.arange(1, n), size=4, replace=False))
    i, j = order[:-1], order[1:]
    keep = ~np.isin(np.arange(1, n), breaks)
    i, j = i[keep], j[keep]
    shuffle = rng.permutation(len(i))
    i, j = i[shuffle], j[shuffle]
    cuts = np.linspace(0, len(i), blocks + 1).astype(int)
    return i, j, [(i[a:b], j[a:b]) for a, b in zip(cuts[:-1], cuts[1:])]


@pytest.mark.parametrize("seed", range(4))
def test_union_find_blocks_of_chains_against_scipy(seed):
    rng = np.random.default_rng(seed)
    n = 3000
    i, j, blocks = _chains(rng, n, 1 + seed)
    count, labels = connected_components(coo_matrix((np.ones(len(i)), (i, j)), shape=(n, n)), directed=False)
    smallest = np.full(count, n)
    np.minimum.at(smallest, labels, np.arange(n))
    assert count == 5
    got = union_find_blocks(n, blocks)
    assert np.array_equal(got, smallest[labels])
    # on top of roots found already (every node its component's smallest node so far)
    half = union_find_blocks(n, blocks[:1])
    assert np.array_equal(union_find_blocks(n, blocks[1:], half), smallest[labels])


def test_once_pairs_against_adjacency():
    """The once pass (a uniform tree's own pairs once, its opposite directions looked up only
    for the cells without a neighbour of their own, among another tree's leaves): the same pairs
    as the plain adjacency of both trees, each own pair once, on random cells of a periodic and a
    bounded grid."""
    rng = np.random.default_rng(5)
    for periodic in ((False, False), (True, True), (True, False)):
        grid = Grid(((0.0, 1.0), (0.0, 1.0)), 6, periodic)
        other = Tree.from_cells(grid, 5, np.argwhere(rng.random((32, 32)) < 0.3))
        code = np.sort(interleave(np.argwhere(rng.random((64, 64)) < 0.4), 6))
        code = code[other.locate_finest(code) < 0]  # (disjoint from the other tree)
        mine = Tree(grid, np.full(len(code), 6), code, canonical=True)
        shift = len(other)

        def pairs(once: bool) -> list:
            out = []
            for i, j in mine.neighbour_pairs(other, corners=True, itself=True, once=once):
                out += [(a, b) if b < shift else (min(a, b - shift), max(a, b - shift), "own")
                        for a, b in zip(i.tolist(), j.tolist())]
            return out

        once, plain = pairs(True), pairs(False)
        own = [p for p in once if len(p) == 3]
        assert len(own) == len(set(own)) > 100 and set(own) == {p for p in plain if len(p) == 3}
        # a cell meets a larger leaf of the other tree once per direction it lies in: as often
        across = sorted(p for p in once if len(p) == 2)
        assert across == sorted(p for p in plain if len(p) == 2) and len(across) > 100


# ---- round 2 (r2tree): the uint32 window and the shared search index
@pytest.mark.parametrize("sign", [-1, 0, 1])
def test_uint32_window_equals_a_binary_search_up_to_the_last_index(sign):
    """uint32 keys (depth-16 quadtree indices): queries at any distance, the first (0) and last
    (2**32 - 1) depth-D indices included, where the paddings (0 and 2**32 - 1) equal a query."""
    top = 2**32 - 1
    rng = np.random.default_rng(7 + sign)
    for n, near in ((40, 3), (300, 16)):
        start = np.unique(np.concatenate([[0], rng.integers(0, 2**32, n), [top - 1, top]]))
        keys = start.astype(np.uint32)
        step = rng.geometric(0.2, len(start)) * rng.choice([1, 3 << 20, 1 << 30], len(start))
        side = sign if sign else rng.choice([-1, 1], len(start))
        first = np.clip(start + np.where(side > 0, step, -step), 0, top)
        first[:3], first[-3:] = 0, top  # (queries at both ends)
        expected = np.searchsorted(start, first, side="right") - 1
        old = tree_module.NEAR
        tree_module.NEAR = near
        try:
            padded = tree_module._padded(keys)
            assert padded.dtype == np.uint32
            for s in (0, len(start) // 2):
                got = tree_module._search_near(padded, keys, first[s:], s, sign)
                assert np.array_equal(got, expected[s:])
        finally:
            tree_module.NEAR = old


def test_a_shared_search_index_gives_the_same_pairs_and_components():
    """`components(index=)` and `neighbour_pairs(other_index=)` with `search_index()` built once
    equal the searches that build their own (depth-16 quadtree: uint32 keys; and a 3-D grid)."""
    rng = np.random.default_rng(3)
    for dim, depth, coarse in ((2, 16, 6), (3, 5, 5)):
        grid = Grid(tuple((-1.0, 1.0) for _ in range(dim)), depth, (False,) + (True,) * (dim - 1))
        coarse_grid = grid.with_depth(coarse)
        black = Tree.from_cells(coarse_grid, coarse, cells_of(blocky(rng, coarse, dim, 0.7, 0.5))).with_depth(depth)
        other = Tree.from_cells(coarse_grid, coarse, cells_of(blocky(rng, coarse, dim, 0.7, 0.5))).with_depth(depth) - black
        index = black.search_index()
        for corners in (False, True):
            labels, count = black.components(corners=corners)
            shared = black.components(corners=corners, index=index)
            assert count == shared[1] and np.array_equal(labels, shared[0])
            for itself in (False, True):
                own = list(other.neighbour_pairs(black, corners=corners, itself=itself))
                given = list(other.neighbour_pairs(black, corners=corners, itself=itself, other_index=index))
                assert len(own) == len(given) == len(tree_module._offsets(dim, corners))
                for (i, j), (gi, gj) in zip(own, given):
                    assert np.array_equal(i, gi) and np.array_equal(j, gj)
        assert count > 1 and len(black) > 50  # (a tree with something to find)


@pytest.mark.parametrize("dim, depth", [(2, 7), (3, 5)])
def test_centres_are_the_midpoints_of_the_bounds(dim, depth):
    """`Tree.centres` (axis by axis, of a selection, into a given array) gives bit for bit
    0.5 * (lo + hi) of `Tree.bounds`, on a grid with an offset root box."""
    rng = np.random.default_rng(dim)
    grid = Grid(((-1.3, 1.6), (0.7, 1.8), (2.0, 7.5))[:dim], depth, (False,) * dim)
    tree = Tree.from_cells(grid, depth, cells_of(blocky(rng, depth, dim, 0.7, 0.5)))
    lo, hi = tree.bounds()
    assert np.array_equal(tree.centres(), 0.5 * (lo + hi))
    pick = np.flatnonzero(rng.random(len(tree)) < 0.4)
    out = np.full((len(pick) + 3, dim), np.nan)
    tree.centres(pick, out=out[:len(pick)])
    assert np.array_equal(out[:len(pick)], 0.5 * (lo[pick] + hi[pick])) and np.isnan(out[len(pick):]).all()
