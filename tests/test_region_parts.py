"""The parts of the aspects' region work that take shortcuts (issue 22), against what they replace:
free signs read once per black component against every leaf's own, union-find a block of edges
at a time against scipy's components, refinement windows against a brute force over blocks, the
certificate's link samples against a point-by-point location."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from fivebar_cli.analyses.aspects import DENSE, SMALL_PIECE, _free_modes, _largest_leaf, _region, _space_task, link_points, link_samples
from fivebar_cli.analyses.pieces import ModeSet, _integer_boxes, _near
from fivebar_cli.mechanisms.fivebar.model import FiveBar
from fivebar_cli.paving.grid import Grid
from fivebar_cli.paving.tree import union_find, union_find_blocks


def random_design(seed: int) -> FiveBar:
    rng = np.random.default_rng(2200 + seed)
    return FiveBar(f"random-{seed}", float(rng.uniform(0.2, 2)), *(float(v) for v in rng.uniform(0.5, 2, 4)))


@pytest.fixture(scope="module")
def regions(m1):
    """The mode regions of M1 and of three random five-bars at depth 7, with their mode sets."""
    out = []
    for m in (m1, *(random_design(seed) for seed in range(3))):
        model = m.aspect_model()
        for space in ("workspace", "jointspace"):
            keys, pavings, _ = _space_task((m, space, 7))
            for key, paving in zip(keys, pavings):
                region = _region(model, *key, paving)
                out.append((m, region, [ModeSet(region, free) for free in _free_modes(model, region)]))
    return out


def test_free_signs_per_component_are_every_leafs_own(regions):
    """region.free (read at one leaf of each black component) equals the signs at every black
    leaf's centre, and a component never holds two sign vectors."""
    leaves = 0
    for _, region, _ in regions:
        tree = region.tree
        if not len(tree):
            continue
        own = region.free_signs(tree.centres())
        assert np.array_equal(region.free, own), region.title()
        leaves += len(tree)
    assert leaves > 10000


def test_largest_leaf_of_each_label():
    rng = np.random.default_rng(5)
    for _ in range(20):
        n = int(rng.integers(1, 300))
        count = int(rng.integers(1, 12))
        labels = np.sort(rng.integers(0, count, n))
        labels = np.unique(labels, return_inverse=True)[1]  # every label present
        count = int(labels.max()) + 1
        level = rng.integers(0, 9, n)
        got = _largest_leaf(level, labels, count)
        for c in range(count):
            mine = np.flatnonzero(labels == c)
            assert got[c] == mine[np.argmin(level[mine])]  # (argmin: the first of the lowest level)


def test_union_find_blocks_against_scipy():
    rng = np.random.default_rng(7)
    for _ in range(30):
        n = int(rng.integers(1, 400))
        m = int(rng.integers(0, 2 * n))
        i, j = rng.integers(0, n, m), rng.integers(0, n, m)
        count, labels = connected_components(coo_matrix((np.ones(m), (i, j)), shape=(n, n)), directed=False)
        smallest = np.full(count, n)
        np.minimum.at(smallest, labels, np.arange(n))
        cuts = np.sort(rng.integers(0, m + 1, int(rng.integers(0, 6))))
        blocks = [(i[a:b], j[a:b]) for a, b in zip([0, *cuts], [*cuts, m])]
        got = union_find_blocks(n, blocks)
        assert np.array_equal(got, smallest[labels])
        assert np.array_equal(union_find(n, i, j), smallest[labels])


def _near_reference(grid: Grid, a_lo, a_hi, b_lo, b_hi, radius: int) -> np.ndarray:
    """_near's definition, box by box: the blocks (side 2^k >= radius) b overlaps against those
    within one block of a block some a overlaps (wrapping on periodic axes, clipped elsewhere)."""
    k = max(int(radius - 1).bit_length(), 0)
    n = max((1 << grid.depth) >> k, 1)

    def span(lo, hi):
        return [range(min(lo[d] >> k, n - 1), min((hi[d] - 1) >> k, n - 1) + 1) for d in range(grid.dim)]

    marked = set()
    for lo, hi in zip(a_lo, a_hi):
        ranges = [range(r.start - 1, r.stop + 1) for r in span(lo, hi)]
        for x in ranges[0]:
            for y in ranges[1]:
                marked.add(tuple(v % n if grid.periodic[d] else min(max(v, 0), n - 1) for d, v in enumerate((x, y))))
    return np.array([any((x, y) in marked for x in sx for y in sy) for sx, sy in (span(lo, hi) for lo, hi in zip(b_lo, b_hi))], bool)


@pytest.mark.parametrize("periodic", [(False, False), (True, False), (True, True)])
def test_near_against_blocks_one_by_one(periodic):
    rng = np.random.default_rng(11)
    grid = Grid(((0.0, 1.0), (0.0, 1.0)), 6, periodic)

    def boxes(count):
        level = rng.integers(2, 7, count)
        coords = (rng.random((count, 2)) * (1 << level)[:, None]).astype(np.int64)
        shift = (6 - level)[:, None]
        return coords << shift, (coords + 1) << shift

    for radius in (1, 3, 4, 16):
        for _ in range(6):
            a_lo, a_hi = boxes(int(rng.integers(1, 4)))
            b_lo, b_hi = boxes(200)
            got = _near(grid, a_lo, a_hi, b_lo, b_hi, radius)
            assert np.array_equal(got, _near_reference(grid, a_lo, a_hi, b_lo, b_hi, radius))


def test_link_points_are_the_images_located_one_by_one(regions):
    """link_points: per sample of a mode set's anchors, its anchor and the depth-D index of its
    image in the other space's grid, which locates the same leaf as the image itself."""
    checked = 0
    for m, region, sets in regions[:6]:  # M1's regions
        model = m.aspect_model()
        other_space = "jointspace" if region.space == "workspace" else "workspace"
        other_keys, other_pavings, _ = _space_task((m, other_space, 7))
        for s in sets:
            points, owners = link_samples(s)
            got_owners, index = link_points(model, s, other_pavings[0].grid)
            assert np.array_equal(got_owners, owners)
            *working, assembly = s.modes
            images, ok = model.ikp(points, tuple(working)) if s.space == "workspace" else model.dkp(points, assembly)
            for paving in other_pavings:
                tree = paving.inside
                expected = np.full(len(points), -1)
                expected[ok] = tree.locate(images[ok])
                assert np.array_equal(tree.locate_finest(index), expected)
                checked += int(np.count_nonzero(expected >= 0))
            # every sample lies in its anchor's leaves
            leaf = region.tree.locate(points)
            assert np.array_equal(s.anchor_of_leaf[leaf], owners)
    assert checked > 1000


def test_link_samples_are_the_leaves_centres(regions):
    """link_samples (centres built axis by axis from integer coordinates): bit for bit the centres
    0.5 (lo + hi) of Tree.bounds of the large anchors' leaves, then a DENSE x DENSE grid in the
    small anchors' leaves, with the anchor of each."""
    sizes = set()
    for _, region, sets in regions:
        for s in sets:
            points, owners = link_samples(s)
            mine, anchor = s.black_leaves, s.leaf_anchors
            small = s.anchor_size[anchor] <= SMALL_PIECE
            lo, hi = region.tree.bounds(mine)
            g = (np.arange(DENSE) + 0.5) / DENSE
            offsets = np.stack(np.meshgrid(g, g), -1).reshape(-1, 2)
            dense = (lo[small, None, :] + offsets[None] * (hi - lo)[small, None, :]).reshape(-1, 2)
            expected = np.concatenate([0.5 * (lo[~small] + hi[~small]), dense])
            assert points.shape == expected.shape and points.tobytes() == expected.tobytes()  # (bit for bit)
            assert np.array_equal(owners, np.concatenate([anchor[~small], np.repeat(anchor[small], DENSE * DENSE)]))
            sizes |= {bool(small.any()), bool((~small).any())}
    assert sizes == {True, False}  # both kinds of anchors were sampled


def test_cells_of_a_part_are_the_selected_cells_with_their_boxes(regions):
    """ModeSet._parts(part) and _cell_set (a part's cells built from it alone) and _boxes (the
    undetermined cells' boxes from their coordinates): the same cells as `cells.select(part)`,
    their integer boxes as `_integer_boxes` of their codes, each black cell's anchor as
    `anchor_of_leaf`."""
    rng = np.random.default_rng(7)
    checked = 0
    for _, region, sets in regions[:10]:
        for s in sets:
            cells = s.cells
            for part in (s.outer == 0, rng.random(len(cells.level)) < 0.3):
                mine, anchors, und = s._parts(part)
                got, (lo, hi) = s._cell_set(mine, und), s._boxes(mine, und)
                want = cells.select(part)
                for field in ("level", "code", "black", "leaf"):
                    assert np.array_equal(getattr(got, field), getattr(want, field)), field
                want_lo, want_hi = _integer_boxes(s.grid, want.level, want.code)
                assert np.array_equal(lo, want_lo) and np.array_equal(hi, want_hi)
                assert np.array_equal(anchors, s.anchor_of_leaf[want.leaf[want.black]])
                checked += len(want.level)
    assert checked > 1000


@pytest.mark.parametrize("stride", [16, 61])
def test_pairs_of_a_set_are_the_links_of_all_its_samples(regions, stride, monkeypatch):
    """_pairs_of (into a set of one anchor: a sparse stride of samples mapped first, the others
    only for the anchors left without a pair): the same pairs as link_pairs of every sample's
    image (`link_points`), on M1 and random five-bars; the wider stride leaves many anchors
    without a sample in the first pass."""
    from fivebar_cli.analyses import aspects
    from fivebar_cli.analyses.aspects import _linked_to, _pairs_of, link_pairs
    monkeypatch.setattr(aspects, "LINK_STRIDE", stride)
    by_model: dict = {}
    for m, _, sets in regions:
        by_model.setdefault(m.name, (m, []))[1].extend(sets)
    pruned = 0
    for m, sets in by_model.values():
        model = m.aspect_model()
        for k, s in enumerate(sets):
            for j in _linked_to(sets, k):
                t = sets[j]
                want = link_pairs(t, *link_points(model, s, t.grid))
                got = _pairs_of(model, s, t)
                assert got.dtype == want.dtype and np.array_equal(got, want)
                pruned += t.n_anchors == 1 and len(link_samples(s)[0]) >= 4 * stride and len(want) > 0
    assert pruned >= 3


def test_links_skipped_between_joined_sets_leave_the_groups_of_every_link(regions):
    """`_Count._link` does not look for the links of two sets whose anchors are one group
    already: its groups equal those of every link (`_pairs_of` of every pair of linked sets,
    joined by a plain union-find), on M1 and random five-bars; and it does skip some."""
    from fivebar_cli.analyses.aspects import _Count, _linked_to, _pairs_of

    skipped = 0
    for m in {id(m): m for m, _, _ in regions}.values():
        model = m.aspect_model()
        sets = [s for mm, _, region_sets in regions if mm is m for s in region_sets]
        count = _Count.__new__(_Count)
        count.model, count.sets = model, sets
        count.offset = np.cumsum([0] + [s.n_anchors for s in sets])
        count.edges_i, count.edges_j, count._roots, count._roots_for = [], [], None, None
        calls = []
        original = count._joined
        count._joined = lambda k, j: calls.append(original(k, j)) or calls[-1]
        count._link({})
        skipped += sum(calls)
        i, j = [], []
        for k, s in enumerate(sets):
            for t in _linked_to(sets, k):
                pairs = _pairs_of(model, s, sets[t])
                i += (count.offset[k] + pairs[:, 0]).tolist()
                j += (count.offset[t] + pairs[:, 1]).tolist()
        every = union_find(int(count.offset[-1]), np.array(i, np.int64), np.array(j, np.int64))
        assert np.array_equal(count.roots, every)
    assert skipped > 0
