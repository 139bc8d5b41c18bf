"""The paving engine (fivebar_cli.paving.engine) against an independent recursive paving written here
(the paper's procedure Q(B, d, P), section 2.5), with exact synthetic box tests; and `refine`
against fresh pavings of the five-bar spaces."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from conftest import M1, M2, tree_to_bool
from fivebar_cli.analyses import spaces
from fivebar_cli.paving.engine import box_pad, pave, refine, undetermined_cells
from fivebar_cli.paving.grid import Grid, boxes_of
from fivebar_cli.paving.tree import Tree


# ---------------------------------------------------------------- synthetic box tests


def ball_test(centre, radius):
    """Exact test of the closed ball |p - c| <= r on axis-aligned boxes (any dimension)."""
    c = np.asarray(centre, float)
    r2 = radius * radius

    def test(lo, hi):
        near = np.clip(c, lo, hi) - c
        far = np.maximum(np.abs(lo - c), np.abs(hi - c))
        dn, df = np.sum(near * near, axis=1), np.sum(far * far, axis=1)
        return np.where(df <= r2, 1, np.where(dn > r2, -1, 0)).astype(np.int8)

    return test


def annulus_test(centre, r_in, r_out):
    """Exact test of the closed annulus r_in <= |p - c| <= r_out (2-D)."""
    c = np.asarray(centre, float)

    def test(lo, hi):
        near = np.clip(c, lo, hi) - c
        far = np.maximum(np.abs(lo - c), np.abs(hi - c))
        dn, df = np.sum(near * near, axis=1), np.sum(far * far, axis=1)
        inside = (dn >= r_in**2) & (df <= r_out**2)
        outside = (df < r_in**2) | (dn > r_out**2)
        return np.where(inside, 1, np.where(outside, -1, 0)).astype(np.int8)

    return test


def ref_pave(grid: Grid, test):
    """Depth-first recursive paving, one box at a time (paper, section 2.5)."""
    dim, depth = grid.dim, grid.depth
    lo0, size = grid.lo, grid.size
    pad = box_pad(grid)
    found = {1: [], -1: []}
    undetermined = []
    evaluations = [0] * (depth + 1)
    zeros_above = [0]

    def rec(level, coords):
        width = size / 2.0**level
        c = np.asarray(coords, float)
        lo, hi = lo0 + c * width - pad, lo0 + (c + 1) * width + pad
        evaluations[level] += 1
        status = int(test(lo[None, :], hi[None, :])[0])
        if status != 0:
            found[status].append((level, coords))
        elif level == depth:
            undetermined.append(coords)
        else:
            zeros_above[0] += 1
            for k in range(1 << dim):
                rec(level + 1, tuple(2 * x + ((k >> j) & 1) for j, x in enumerate(coords)))

    rec(0, (0,) * dim)
    return found[1], found[-1], undetermined, evaluations, zeros_above[0]


def raster(cells, depth, dim):
    n = 1 << depth
    arr = np.zeros((n,) * dim, dtype=bool)
    for level, c in cells:
        s = 1 << (depth - level)
        arr[tuple(slice(x * s, (x + 1) * s) for x in c)] = True
    return arr


def check_against_reference(grid, test):
    paving = pave(grid, test)
    ins, outs, und, evals, zeros_above = ref_pave(grid, test)
    dim, depth = grid.dim, grid.depth
    # n = 1 + 2^dim * (undetermined boxes above the maximum depth), level by level as well
    assert paving.evaluations == sum(evals) == 1 + (1 << dim) * zeros_above
    assert list(paving.per_level) == evals
    assert np.array_equal(tree_to_bool(paving.inside), raster(ins, depth, dim))
    assert np.array_equal(tree_to_bool(paving.outside), raster(outs, depth, dim))
    assert sorted(map(tuple, paving.undetermined.tolist())) == sorted(und)
    return paving


# ---------------------------------------------------------------- counts against the reference


@pytest.mark.parametrize("depth", [0, 1, 2, 5, 7])
def test_disc_paving_matches_the_recursive_reference(depth):
    grid = Grid(((-1.0, 1.0), (-1.0, 1.0)), depth, (False, False))
    check_against_reference(grid, ball_test((0.3, -0.17), 0.61))
    check_against_reference(grid, annulus_test((0.1, 0.05), 0.2, 0.9))


@settings(max_examples=25, deadline=None)
@given(
    st.floats(-1.5, 1.5), st.floats(-1.5, 1.5), st.floats(0.01, 2.5), st.integers(0, 6),
    st.tuples(st.floats(-3, 0), st.floats(0.5, 3), st.floats(-3, 0), st.floats(0.5, 3)),
)
def test_random_disc_pavings_match_the_reference(cx, cy, r, depth, root):
    grid = Grid(((root[0], root[1]), (root[2], root[3])), depth, (False, False))
    paving = check_against_reference(grid, ball_test((cx, cy), r))
    # soundness of the exact disc test, checked at the leaf corners computed here
    lo, size = grid.lo, grid.size
    for tree, want in ((paving.inside, True), (paving.outside, False)):
        for lev, c in zip(tree.level.tolist(), tree.coords.tolist()):
            w = size / 2.0**lev
            for corner in ((0, 0), (1, 0), (0, 1), (1, 1), (0.5, 0.5)):
                p = lo + (np.array(c) + np.array(corner)) * w
                inside = (p[0] - cx) ** 2 + (p[1] - cy) ** 2 <= r * r
                assert inside == want or abs(np.hypot(p[0] - cx, p[1] - cy) - r) < 1e-12


@pytest.mark.parametrize("depth", [0, 1, 3, 4])
def test_octree_ball_paving_matches_the_reference(depth):
    grid = Grid(((-1.0, 1.0), (-1.0, 1.0), (0.0, 2.0)), depth, (False, False, False))
    check_against_reference(grid, ball_test((0.2, -0.1, 0.9), 0.7))


def test_constant_tests():
    grid = Grid(((0.0, 1.0), (0.0, 1.0)), 4, (False, False))
    const = lambda v: (lambda lo, hi: np.full(len(lo), v, dtype=np.int8))  # noqa: E731
    p = pave(grid, const(1))
    assert p.evaluations == 1 and p.inside == Tree.full(grid) and len(p.outside) == 0 and len(p.undetermined) == 0
    p = pave(grid, const(-1))
    assert p.evaluations == 1 and p.outside == Tree.full(grid) and len(p.inside) == 0
    p = pave(grid, const(0))
    assert p.per_level == tuple(4**k for k in range(5))
    assert p.evaluations == sum(4**k for k in range(5)) == 1 + 4 * sum(4**k for k in range(4))
    assert len(p.undetermined) == 4**4 and len(p.inside) == len(p.outside) == 0
    assert sorted(map(tuple, p.undetermined.tolist())) == [(x, y) for x in range(16) for y in range(16)]
    grid3 = Grid(((0.0, 1.0),) * 3, 3, (False,) * 3)
    assert pave(grid3, const(0)).evaluations == 1 + 8 + 64 + 512


# ---------------------------------------------------------------- partition of the root


@pytest.mark.parametrize("name", ["M1", "M2"])
@pytest.mark.parametrize("space", ["jointspace", "workspace"])
@pytest.mark.parametrize("procedure", ["exact", "paper"])
def test_inside_outside_undetermined_partition_the_root(name, space, procedure):
    m = {"M1": M1, "M2": M2}[name]
    for depth in (3, 7, 9):
        p = spaces.pave_space(m, space, depth, procedure)
        und = p.undetermined_tree()
        assert len(p.inside & p.outside) == 0
        assert len(p.inside & und) == 0
        assert len(p.outside & und) == 0
        assert (p.inside | p.outside | und) == Tree.full(p.grid)
        root_area = float(np.prod(p.grid.size))
        assert p.inside.area + p.outside.area + p.undetermined_area == pytest.approx(root_area, rel=1e-14)
        assert p.undetermined_area == pytest.approx(len(p.undetermined) * root_area / 4**depth, rel=1e-14)
        # the undetermined cells are exactly the gaps between the two trees
        assert sorted(map(tuple, undetermined_cells(p.inside, p.outside).tolist())) == sorted(
            map(tuple, p.undetermined.tolist()))
        # evaluations: root plus four per undetermined box above the maximum depth
        assert p.per_level[0] == 1
        for level in range(depth):
            tested_next = p.per_level[level + 1]
            assert tested_next % 4 == 0
        assert p.evaluations == 1 + sum(p.per_level[1:])


# ---------------------------------------------------------------- refine


REFINE_PAIRS = [(0, 4), (3, 7), (5, 8), (6, 6), (2, 9), (7, 10)]


@pytest.mark.parametrize("name", ["M1", "M2"])
@pytest.mark.parametrize("space", ["jointspace", "workspace"])
def test_refine_equals_a_fresh_paving(name, space):
    m = {"M1": M1, "M2": M2}[name]
    test = m.box_test(space, "exact")
    for d1, d2 in REFINE_PAIRS:
        old = spaces.pave_space(m, space, d1)
        new = refine(old.inside, old.outside, test, d2)
        fresh = spaces.pave_space(m, space, d2)
        assert new.grid == fresh.grid
        assert new.inside == fresh.inside
        assert new.outside == fresh.outside
        assert sorted(map(tuple, new.undetermined.tolist())) == sorted(map(tuple, fresh.undetermined.tolist()))
        assert new.evaluations + old.evaluations == fresh.evaluations
        assert new.per_level[: d1 + 1] == (0,) * (d1 + 1)
        assert new.per_level[d1 + 1:] == fresh.per_level[d1 + 1:]


def test_refine_with_the_paper_procedure_and_twice_in_a_row():
    test = M1.box_test("workspace", "paper")
    a = spaces.pave_space(M1, "workspace", 4, "paper")
    b = refine(a.inside, a.outside, test, 6)
    c = refine(b.inside, b.outside, test, 9)
    fresh = spaces.pave_space(M1, "workspace", 9, "paper")
    assert c.inside == fresh.inside and c.outside == fresh.outside
    assert a.evaluations + b.evaluations + c.evaluations == fresh.evaluations


def test_refine_of_a_disc_paving_matches_the_reference():
    test = ball_test((0.3, -0.17), 0.61)
    grid = Grid(((-1.0, 1.0), (-1.0, 1.0)), 3, (False, False))
    old = pave(grid, test)
    new = refine(old.inside, old.outside, test, 7)
    ins, outs, und, evals, _ = ref_pave(grid.with_depth(7), test)
    assert np.array_equal(tree_to_bool(new.inside), raster(ins, 7, 2))
    assert np.array_equal(tree_to_bool(new.outside), raster(outs, 7, 2))
    assert new.evaluations == sum(evals[4:]) and old.evaluations == sum(evals[:4])


def test_refine_with_nothing_or_everything_undetermined():
    grid = Grid(((0.0, 1.0), (0.0, 1.0)), 2, (False, False))
    const = lambda v: (lambda lo, hi: np.full(len(lo), v, dtype=np.int8))  # noqa: E731
    done = pave(grid, const(1))
    again = refine(done.inside, done.outside, const(1), 6)
    assert again.evaluations == 0 and again.inside == Tree.full(grid.with_depth(6)) and len(again.undetermined) == 0
    # all 16 depth-2 cells open: the gap tree is one root leaf, expanded back to 16 cells
    open_ = pave(grid, const(0))
    assert len(undetermined_cells(open_.inside, open_.outside)) == 16
    deeper = refine(open_.inside, open_.outside, const(0), 4)
    assert deeper.per_level == (0, 0, 0, 4**3, 4**4)
    assert open_.evaluations + deeper.evaluations == pave(grid.with_depth(4), const(0)).evaluations
    # refining to the same depth tests nothing and keeps the pair
    same = refine(open_.inside, open_.outside, const(1), 2)
    assert same.evaluations == 0 and len(same.undetermined) == 16


def test_refine_rejects_bad_input():
    test = ball_test((0.0, 0.0), 0.5)
    grid = Grid(((-1.0, 1.0), (-1.0, 1.0)), 4, (False, False))
    p = pave(grid, test)
    with pytest.raises(ValueError):
        refine(p.inside, p.outside, test, 3)  # shallower
    with pytest.raises(ValueError):
        refine(p.inside, p.inside, test, 6)  # overlapping pair
    other = Tree.empty(grid.with_depth(5))
    with pytest.raises(ValueError):
        refine(p.inside, other, test, 6)


# ---------------------------------------------------------------- rounding pad


def test_every_tested_box_contains_its_exact_dyadic_cell():
    """The computed cell bounds are widened by box_pad: checked in exact rational arithmetic."""
    root = ((-np.pi, np.pi), (-13.0 / 3.0, 7.1))
    grid = Grid(root, 9, (False, False))
    pad = box_pad(grid)
    assert 0 < pad < 1e-13
    seen = []

    def recording(lo, hi):
        seen.append((lo.copy(), hi.copy()))
        return np.zeros(len(lo), dtype=np.int8)  # everything undetermined: every cell is tested

    pave(grid.with_depth(6), recording)
    rng = np.random.default_rng(0)
    checked = 0
    for level, (lo, hi) in enumerate(seen):
        n = 1 << level
        # boxes of a level are tested in child order; recover their coordinates from the bounds
        w = grid.size / n
        coords = np.rint((0.5 * (lo + hi) - grid.lo) / w - 0.5).astype(int)
        assert np.all((coords >= 0) & (coords < n))
        for i in rng.choice(len(lo), size=min(len(lo), 60), replace=False):
            for axis in range(2):
                a, b = (Fraction(v) for v in root[axis])
                exact_lo = a + (b - a) * Fraction(int(coords[i, axis]), n)
                exact_hi = a + (b - a) * Fraction(int(coords[i, axis]) + 1, n)
                assert Fraction(lo[i, axis]) <= exact_lo
                assert Fraction(hi[i, axis]) >= exact_hi
                checked += 1
    assert checked > 500


def test_chunked_box_functions_equal_one_call():
    """`engine.chunked` (box functions evaluated CHUNK boxes at a time) gives what one call gives,
    for a single array and for a tuple of arrays, across several chunks."""
    from fivebar_cli.paving.engine import CHUNK, chunked, on_cells

    rng = np.random.default_rng(3)
    lo = rng.uniform(-1, 1, (2 * CHUNK + 17, 2))
    hi = lo + rng.uniform(0, 1, lo.shape)

    def fn(a, b):
        return (a.sum(axis=1) > 0), np.column_stack([b[:, 0] - a[:, 1], np.sign(a[:, 0])]).astype(np.int8)

    whole, parts = fn(lo, hi), chunked(fn, lo, hi)
    assert all(np.array_equal(w, p) for w, p in zip(whole, parts))
    assert np.array_equal(chunked(lambda a, b: fn(a, b)[0], lo, hi), whole[0])
    grid = Grid(((-1.0, 3.0), (0.0, 2.0)), 9, (False, False))
    cells = rng.integers(0, 1 << 9, (2 * CHUNK + 5, 2))
    assert all(np.array_equal(w, p) for w, p in zip(fn(*grid.boxes(9, cells)), on_cells(fn, grid, cells)))
    seen = []  # with ends=True, fn is also handed the same boxes' ends as tables, chunk by chunk

    def with_ends(a, b, ends):
        seen.append(len(a))
        assert all(np.array_equal(x, y) for x, y in zip(boxes_of(ends), (a, b)))
        return fn(a, b)

    assert all(np.array_equal(w, p) for w, p in zip(fn(*grid.boxes(9, cells)), on_cells(with_ends, grid, cells, ends=True)))
    assert seen == [CHUNK, CHUNK, 5]


@settings(max_examples=60, deadline=None)
@given(st.lists(st.integers(-(1 << 62), 1 << 62), max_size=40), st.integers(0, 3))
def test_unique_by_sort_equals_numpys(values, repeat):
    from fivebar_cli.paving.arrays import unique

    a = np.array(values * (repeat + 1), np.int64)
    got = unique(a)
    assert got.dtype == a.dtype and np.array_equal(got, np.array(sorted(set(values)), np.int64))


def _same_paving(a, b) -> bool:
    return (a.inside == b.inside and a.outside == b.outside and a.band == b.band and a.per_level == b.per_level
            and np.array_equal(a.undetermined, b.undetermined))


@settings(max_examples=25, deadline=None)
@given(st.lists(st.tuples(st.floats(-0.8, 0.8), st.floats(-0.8, 0.8), st.floats(0.05, 0.9)), min_size=1, max_size=4),
       st.integers(2, 7))
def test_pave_many_equals_one_paving_per_test(discs, depth):
    """One pass for several tests gives each test's own paving: the same trees, undetermined cells
    in the same order, the same evaluations per level (a box counts only where its test is open)."""
    from fivebar_cli.paving.engine import pave_many, stacked

    grid = Grid(((-1.0, 1.0), (-1.0, 1.0)), depth, (False, False))
    tests = [ball_test((x, y), r) for x, y, r in discs]
    for one, many in zip([pave(grid, t) for t in tests], pave_many(grid, stacked(tests), len(tests))):
        assert _same_paving(one, many)


@settings(max_examples=25, deadline=None)
@given(st.lists(st.tuples(st.floats(-0.8, 0.8), st.floats(-0.8, 0.8), st.floats(0.05, 0.9)), min_size=1, max_size=4),
       st.integers(2, 5), st.integers(0, 3), st.integers(0, 2**32 - 1))
def test_deepen_many_equals_one_deepening_per_test(discs, depth, extra, seed):
    """Deepening several lists of cells (overlapping, empty, one out of Morton order) in one
    descent gives each list its own `deepen`: the same trees, cells, order and evaluations."""
    from fivebar_cli.paving.engine import deepen, deepen_many, stacked

    grid = Grid(((-1.0, 1.0), (-1.0, 1.0)), depth, (False, False))
    tests = [ball_test((x, y), r) for x, y, r in discs]
    rng = np.random.default_rng(seed)
    cells = []
    for k in range(len(tests)):
        und = pave(grid, tests[k]).undetermined
        cells.append(und[rng.random(len(und)) < 0.7] if k % 2 else und)
    cases = [cells]
    if len(cells[0]) > 1:
        cases.append([cells[0][::-1]] + cells[1:])  # out of order: one list at a time
    for case in cases:
        many = deepen_many(grid, stacked(tests), case, extra)
        assert [_same_paving(deepen(grid, t, c, extra), p) for t, c, p in zip(tests, case, many)] == [True] * len(tests)


def test_pave_many_of_five_bar_modes_equals_the_single_mode_pavings():
    """The five-bar's multi-tests (exact and interval lengths, with and without constraints) pave
    every mode as its own test does."""
    from conftest import CONFIGS
    from fivebar_cli.mechanisms.registry import load_config
    from fivebar_cli.paving.engine import pave_many

    m1 = load_config(CONFIGS / "m1.yaml")
    for m in (m1, load_config(CONFIGS / "m1-obstacle.yaml"), m1.widened(0.05)):
        model = m.aspect_model()
        for space, keys, many, one in (
                ("workspace", model.working_modes, model.workspace_tests, model.workspace_test),
                ("jointspace", model.assembly_modes, model.jointspace_tests, model.jointspace_test)):
            grid = m.spaces()[space].grid(6)
            pavings = pave_many(grid, many(keys), len(keys))
            assert [_same_paving(p, pave(grid, one(k))) for p, k in zip(pavings, keys)] == [True] * len(keys)
            assert sum(len(p.inside) for p in pavings) > 0


@settings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(st.integers(0, 40), st.integers(0, 40)), max_size=60))
def test_ranks_and_pairs_equal_numpys_unique(pairs):
    from fivebar_cli.paving.arrays import dense_rank, unique_pairs

    a = np.array([p[0] for p in pairs], np.int64)
    b = np.array([p[1] for p in pairs], np.int64)
    assert np.array_equal(dense_rank(a), np.unique(a, return_inverse=True)[1].reshape(-1))
    assert np.array_equal(unique_pairs(a, b), np.unique(np.column_stack([a, b]), axis=0).reshape(-1, 2))


@settings(max_examples=60, deadline=None)
@given(st.integers(1, 30), st.lists(st.tuples(st.integers(0, 29), st.integers(0, 29)), max_size=40))
def test_root_labels_number_components_by_their_smallest_element(n, edges):
    from fivebar_cli.paving.tree import root_labels, union_find

    i = np.array([min(e[0], n - 1) for e in edges], np.int64)
    j = np.array([min(e[1], n - 1) for e in edges], np.int64)
    labels, count = root_labels(union_find(n, i, j))
    # reference: flood fill, components numbered in order of their smallest element
    adj = {k: set() for k in range(n)}
    for x, y in zip(i.tolist(), j.tolist()):
        adj[x].add(y)
        adj[y].add(x)
    ref, seen = [-1] * n, 0
    for k in range(n):
        if ref[k] < 0:
            stack, ref[k] = [k], seen
            while stack:
                for y in adj[stack.pop()]:
                    if ref[y] < 0:
                        ref[y] = seen
                        stack.append(y)
            seen += 1
    assert labels.tolist() == ref and count == seen


@pytest.mark.parametrize("seed", range(4))
def test_union_find_against_scipy_on_large_graphs_edge_batch_by_edge_batch(seed):
    """union_find on a few thousand nodes (long chains: a path in shuffled order, and random
    edges), its edges given at once or in batches through `parent`, against scipy's components:
    the same partition, each node's root the smallest node of its component."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    from fivebar_cli.paving.tree import union_find

    rng = np.random.default_rng(seed)
    n = 5000
    path = rng.permutation(n - 1)[: int(0.9 * (n - 1))]  # most of the path 0-1-2-...: long chains
    extra = rng.integers(0, n, (n // 2, 2))
    i = np.concatenate([path, extra[:, 0]])
    j = np.concatenate([path + 1, extra[:, 1]])
    order = rng.permutation(len(i))
    i, j = i[order], j[order]
    _, ref = connected_components(coo_matrix((np.ones(len(i)), (i, j)), shape=(n, n)), directed=False)
    smallest = np.full(ref.max() + 1, n)
    np.minimum.at(smallest, ref, np.arange(n))
    root = union_find(n, i, j)
    assert root.dtype == np.int64 and np.array_equal(root, smallest[ref])
    batched = None
    for part in np.array_split(np.arange(len(i)), 5):
        batched = union_find(n, i[part], j[part], batched)
    assert np.array_equal(batched, smallest[ref])


def test_array_helpers_types_and_rows():
    from fivebar_cli.paving.arrays import index_type, label_type, rows_equal

    assert [label_type(n) for n in (1, 127, 128, 32767, 32768, 2**31 - 1, 2**31)] == [
        np.int8, np.int8, np.int16, np.int16, np.int32, np.int32, np.int64]
    assert index_type(10) == np.int32 and index_type(2**31) == np.int64
    rng = np.random.default_rng(0)
    signs = rng.choice(np.array([-1, 0, 1], np.int8), (500, 3))
    for row in ([1, -1, 1], [0, 0, 0], [-1, 1, 0]):
        assert np.array_equal(rows_equal(signs, np.array(row, np.int8)), np.all(signs == row, axis=1))
    assert rows_equal(np.zeros((0, 2), np.int8), np.zeros(2, np.int8)).shape == (0,)


def test_any_per_row_is_numpys_any():
    """Rows read as one unsigned integer (k = 1, 2, 4, 8) or reduced (other k, strided views):
    numpy's any(axis=1) on random masks, sparse and dense."""
    from fivebar_cli.paving.engine import _any_per_row

    rng = np.random.default_rng(7)
    for k in range(1, 10):
        for p in (0.0, 0.05, 0.5):
            mask = rng.random((257, k)) < p
            assert np.array_equal(_any_per_row(mask), mask.any(axis=1))
            view = (rng.random((257, 2 * k)) < p)[:, ::2]  # not contiguous
            assert np.array_equal(_any_per_row(view), view.any(axis=1))


@pytest.mark.parametrize("dim", [2, 3])
def test_descent_trees_equal_the_general_canonical_form(dim):
    """The leaves a descent builds level by level (`engine._tree`: complete sibling groups merged
    from the deepest level up) equal Tree's canonicalisation of the same cells, on random descents
    where each open cell is decided (full, often: whole sibling groups), left or split; and cells
    given in any order fall back to Tree's."""
    from fivebar_cli.paving.engine import _tree, children
    from fivebar_cli.paving.morton import interleave

    rng = np.random.default_rng(dim)
    grid = Grid(((0.0, 1.0),) * dim, 6, (False,) * dim)
    for trial in range(30):
        p_full = rng.choice([0.2, 0.6, 0.95])
        coords, parts = np.zeros((1, dim), np.int64), []
        for level in range(grid.depth + 1):
            fate = rng.random(len(coords))
            full = fate < p_full * (level > 0)
            codes = interleave(coords, level)
            if full.any():
                parts.append((level, codes[full]))
            split = fate > 0.5 + 0.4 * p_full
            coords = children(coords[split & ~full])
            if not len(coords):
                break
        built = _tree(grid, parts)
        level = np.concatenate([np.full(len(c), lev) for lev, c in parts]) if parts else np.zeros(0)
        code = np.concatenate([c for _, c in parts]) if parts else np.zeros(0)
        assert built == Tree(grid, level, code)
        shuffled = [(lev, rng.permutation(c)) for lev, c in parts]  # not a descent's order: Tree's way
        assert _tree(grid, shuffled) == built
