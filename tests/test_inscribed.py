"""The largest certified circle and axis-aligned square of each aspect (issue 12, item 2).

References computed here, independently of fivebar_cli/analyses/inscribed.py: the aspect's cells
are rasterised at their depth (exactly: every cell is a union of pixels), and the grid optimum is
the best centre among the pixel centres, with its radius measured exactly
against the pixels outside the aspect (scipy's Euclidean distance transform only shortlists the
candidates; the chessboard transform is exact for squares). Ours must be at least 95 % of it, and
at most the grid optimum plus the pixel half-diagonal (the true optimum is no larger). Every disc
and square is also sampled, inside and on its boundary, against the reference kinematics: every
point is reachable in the aspect's working mode with det A of the aspect's sign.
"""

from __future__ import annotations

import bisect
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from reference_kinematics import ref_ikp
from scipy import ndimage

from fivebar_cli.analyses.aspects import analyse_aspects
from fivebar_cli.analyses.inscribed import largest_disc, largest_shapes, largest_square
from fivebar_cli.mechanisms.fivebar.model import FiveBar
from fivebar_cli.paving.grid import Grid
from fivebar_cli.paving.tree import Tree

M1 = FiveBar("M1", 9.0, 8.0, 5.0, 5.0, 8.0)
M2 = FiveBar("M2", 2.55, 2.3, 2.3, 2.3, 2.3)
DEPTH = 10
RATIOS: dict = {}


@pytest.fixture(scope="module", params=[M1, M2], ids=["M1", "M2"])
def analysis(request):
    return analyse_aspects(request.param, DEPTH)


def raster(tree: Tree, level: int) -> tuple[np.ndarray, np.ndarray]:
    """Pixels at `level` (indexed [x, y]) in the tree's cells, over the cells' bounding box with a
    border of one outside pixel; and the integer coordinates of the first pixel."""
    span = 1 << (level - tree.level)
    lo = tree.coords * span[:, None]
    first = lo.min(axis=0) - 1
    size = (lo + span[:, None]).max(axis=0) + 1 - first
    image = np.zeros(tuple(size), bool)
    for (x, y), s in zip((lo - first).tolist(), span.tolist()):
        image[x:x + s, y:y + s] = True
    return image, first


def grid_optimum(tree: Tree, metric: str) -> tuple[float, float]:
    """(best radius or half side over the pixel centres, pixel size), pixels of the finest cells."""
    level = tree.grid.depth
    padded, first = raster(tree, level)  # the border (and anything outside the root) is outside
    pixel = tree.grid.size[0] / (1 << level)
    origin = tree.grid.lo + first * pixel
    if metric == "linf":
        cb = ndimage.distance_transform_cdt(padded, metric="chessboard")
        return float((cb.max() - 0.5) * pixel), pixel
    # shortlist: the distance to the box of the nearest outside pixel centre (scipy's transform)
    # is an upper bound; measure the best candidates exactly against every outside pixel box
    # next to the aspect, until no candidate's bound can beat the best exact value
    _, (nx, ny) = ndimage.distance_transform_edt(padded, return_indices=True)
    ix, iy = np.nonzero(padded)
    centres = origin + (np.column_stack([ix, iy]) + 0.5) * pixel
    near_lo = origin + np.column_stack([nx[ix, iy], ny[ix, iy]]) * pixel
    gap = np.maximum(np.maximum(near_lo - centres, centres - near_lo - pixel), 0.0)
    upper = np.hypot(gap[:, 0], gap[:, 1])
    order = np.argsort(upper)[::-1]
    border = ~padded & ndimage.binary_dilation(padded, structure=np.ones((3, 3)))
    bx, by = np.nonzero(border)
    lo = origin + np.column_stack([bx, by]) * pixel
    hi = lo + pixel
    best = 0.0
    for start in range(0, order.size, 64):
        chunk = order[start:start + 64]
        if upper[chunk[0]] <= best:
            break
        c = centres[chunk]
        reach = upper[chunk].max()
        keep = np.all((hi >= c.min(axis=0) - reach) & (lo <= c.max(axis=0) + reach), axis=1)
        gap = np.maximum(np.maximum(lo[keep][None] - c[:, None], c[:, None] - hi[keep][None]), 0.0)
        r = np.hypot(gap[..., 0], gap[..., 1]).min(axis=1)
        best = max(best, float(r.max()))
    return best, pixel


def test_circles_and_squares_against_the_grid_optimum(analysis):
    """Aspects of det A > 0 against the grid optimum; those of det A < 0 are their mirror images
    (y -> -y), with the same radius and side."""
    plus = [a for a in analysis.aspects if a.assembly > 0]
    minus = [a for a in analysis.aspects if a.assembly < 0]
    assert sorted((a.circle.r, a.square.side) for a in plus) == sorted((a.circle.r, a.square.side) for a in minus)
    for a in plus:
        if not len(a.workspace):
            continue
        for metric, found in (("l2", a.circle.r), ("linf", 0.5 * a.square.side)):
            best, pixel = grid_optimum(a.workspace, metric)
            slack = pixel * (math.sqrt(0.5) if metric == "l2" else 0.5)
            assert found >= 0.95 * best, (analysis.mechanism.name, a.number, metric, found, best)
            assert found <= best + slack + 1e-12, (analysis.mechanism.name, a.number, metric, found, best)
            RATIOS[(analysis.mechanism.name, a.number, metric)] = found / best


def sample_disc(x, y, r, n=4000, rng=np.random.default_rng(1)):
    rho = r * np.sqrt(rng.random(n))
    phi = rng.random(n) * 2 * np.pi
    ring = np.linspace(0, 2 * np.pi, 720, endpoint=False)
    return np.concatenate([np.column_stack([x + rho * np.cos(phi), y + rho * np.sin(phi)]),
                           np.column_stack([x + r * np.cos(ring), y + r * np.sin(ring)])])


def sample_square(x, y, side, n=4000, rng=np.random.default_rng(2)):
    h = 0.5 * side
    inner = np.column_stack([x, y]) + rng.uniform(-h, h, (n, 2))
    t = np.linspace(-h, h, 200)
    edges = np.concatenate([np.column_stack([x + t, np.full_like(t, y - h)]), np.column_stack([x + t, np.full_like(t, y + h)]),
                            np.column_stack([np.full_like(t, x - h), y + t]), np.column_stack([np.full_like(t, x + h), y + t])])
    return np.concatenate([inner, edges])


def closed_member(tree: Tree, pts: np.ndarray, tol: float = 1e-9) -> np.ndarray:
    """Points in the closed cells: the cell of the point, or of the point moved by tol (a point
    on an edge belongs to the cells on both sides)."""
    out = np.zeros(len(pts), bool)
    for dx in (-tol, 0.0, tol):
        for dy in (-tol, 0.0, tol):
            out |= tree.locate(pts + [dx, dy]) >= 0
    return out


def test_every_point_of_the_discs_and_squares_is_in_the_aspect(analysis):
    m = analysis.mechanism
    for a in analysis.aspects:
        if a.circle is None:
            continue
        for pts in (sample_disc(a.circle.x, a.circle.y, a.circle.r), sample_square(a.square.x, a.square.y, a.square.side)):
            assert closed_member(a.workspace, pts).all()
            *_, u, v, t, ok = ref_ikp(m, pts[:, 0], pts[:, 1], a.working)
            assert ok.all()
            assert np.all(np.sign(u) == a.working[0]) and np.all(np.sign(v) == a.working[1])
            assert np.all(np.sign(t) == a.assembly)


def test_the_csv_numbers_are_what_was_certified(analysis):
    """10 significant digits at most: the values in aspects.csv are exactly the certified ones."""
    for a in analysis.aspects:
        if a.circle is None:
            continue
        for v in (a.circle.x, a.circle.y, a.circle.r, a.square.x, a.square.y, a.square.side):
            assert float("%.10g" % v) == v


def test_report_ratios():
    """Print the ratios to the grid optimum (seen with pytest -s); they are also asserted above."""
    if RATIOS:
        worst = min(RATIOS.values())
        assert worst >= 0.95
        print("\nworst ratio to the grid optimum:", worst)


# ---------------------------------------------------------------- shapes with known answers


def test_known_answers():
    grid = Grid(((0.0, 8.0), (0.0, 8.0)), 3, (False, False))
    full = Tree.full(grid)
    d, s = largest_disc(full), largest_square(full)
    assert d.r == pytest.approx(4.0, rel=1e-9) and d.r <= 4.0 and s.side == pytest.approx(8.0, rel=1e-9)
    # an L of arms 3 wide: squares of side 3; the largest disc sits in the corner, touching the
    # root's two edges and the inner corner (3, 3): centre (c, c) with c = sqrt(2) (3 - c)
    ell = Tree.from_cells(grid, 3, np.array([(x, y) for x in range(8) for y in range(8) if x < 3 or y < 3]))
    d, s = largest_disc(ell), largest_square(ell)
    assert 0.99 * 3.0 <= s.side <= 3.0
    best = 3 * math.sqrt(2) / (1 + math.sqrt(2))
    assert 0.99 * best <= d.r <= best
    assert largest_disc(Tree.empty(grid)) is None and largest_square(Tree.empty(grid)) is None
    assert largest_shapes(Tree.empty(grid)) == (None, None)


@settings(max_examples=15, deadline=None)
@given(seed=st.integers(0, 10 ** 6))
def test_random_cell_sets(seed):
    """Random sets of cells of several sizes: the disc and square lie in the cells, and reach 95 %
    of the grid optimum."""
    rng = np.random.default_rng(seed)
    grid = Grid(((-3.0, 5.0), (-1.0, 7.0)), 5, (False, False))
    coords = np.argwhere(rng.random((16, 16)) < 0.75)
    tree = Tree.from_cells(grid, 4, coords)
    if not len(tree):
        return
    d, s = largest_disc(tree), largest_square(tree)
    assert largest_shapes(tree) == (d, s)  # one complement for both: the same shapes
    assert closed_member(tree, sample_disc(d.x, d.y, d.r, 1500), tol=1e-12).all()
    assert closed_member(tree, sample_square(s.x, s.y, s.side, 1500), tol=1e-12).all()
    for metric, found in (("l2", d.r), ("linf", 0.5 * s.side)):
        best, _ = grid_optimum(tree, metric)
        assert found >= 0.95 * best


def _one_pass_distance(obstacles, metric: str, centres: np.ndarray, bounds: np.ndarray) -> np.ndarray:
    """The reference for `_Obstacles.distance`: the distance to the root's outside, then every
    complement cell whose extent reaches within the bound (as the search uses it), each centre on
    its own, no span or group."""
    out = np.min(np.concatenate([centres - obstacles.root_lo, obstacles.root_hi - centres], axis=1), axis=1)
    b = np.minimum(bounds, out)
    for k, ((cx, cy), bk) in enumerate(zip(centres, b)):
        x0, x1, y0, y1 = obstacles.x0, obstacles.x1, obstacles.y0, obstacles.y1
        near = (y0 <= cy + bk) & (y1 >= cy - bk) & (x1 >= cx - bk) & (x0 <= cx + bk)
        gx = np.maximum(np.maximum(x0[near] - cx, cx - x1[near]), 0.0)
        gy = np.maximum(np.maximum(y0[near] - cy, cy - y1[near]), 0.0)
        d = np.hypot(gx, gy) if metric == "l2" else np.maximum(gx, gy)
        out[k] = min(out[k], d.min()) if len(d) else out[k]
    return out


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 10 ** 6))
def test_bucketed_distance_is_the_one_pass_distance(seed):
    """Centres close to one another and far apart, with bounds above the true distance, with and
    without hints (any cell, or none): the very floats of a pass over every cell; the nearest cell
    given is at that distance; `near` finds the cells a pass over every cell finds."""
    _check_bucketed_distance(seed, 9)


def _check_bucketed_distance(seed: int, depth: int):
    from fivebar_cli.analyses.inscribed import _cell_distance, _Obstacles

    rng = np.random.default_rng(seed)
    grid = Grid(((-1.5, 2.25), (-3.0, 0.5)), depth, (False, False))
    level = int(rng.integers(3, 10))
    n = 1 << level
    tree = Tree.from_cells(grid, level, np.argwhere(rng.random((n, n)) < rng.uniform(0.5, 0.98)))
    if not len(tree):
        return
    obstacles = _Obstacles(tree)
    inside = tree.centres()
    base = inside[rng.integers(0, len(inside), 3)]
    centres = np.concatenate([base, base[:1] + rng.normal(0, 0.02, (12, 2)), inside[rng.integers(0, len(inside), 5)]])
    cells = len(obstacles.x0)
    for metric in ("l2", "linf"):
        truth = _one_pass_distance(obstacles, metric, centres, np.full(len(centres), np.inf))
        bounds = truth * rng.uniform(1.01, 3.0, len(centres))
        assert np.array_equal(obstacles.distance(metric, centres, bounds), truth)
        assert np.array_equal(obstacles.distance(metric, centres), truth)
        hint = rng.integers(-1, cells, len(centres)) if cells else None
        f, near = obstacles.nearest(metric, centres, bounds, hint)
        assert np.array_equal(f, truth)
        of_cell = near >= 0
        k = near[of_cell]
        d = _cell_distance(metric, centres[of_cell, 0], centres[of_cell, 1],
                           obstacles.x0[k], obstacles.x1[k], obstacles.y0[k], obstacles.y1[k])
        assert np.array_equal(d, truth[of_cell])
        leaf_centres = tree.centres()
        beside = obstacles.beside(tree.start, leaf_centres, metric)
        if cells:  # the nearer of the complement cells just before and just after each leaf in Morton order
            starts, leaf_starts = obstacles.cells.start.tolist(), tree.start.tolist()
            for k in rng.integers(0, len(tree), 20).tolist():
                after = bisect.bisect_left(starts, leaf_starts[k])
                pair = [j for j in (after - 1, after) if 0 <= j < cells]
                d = _cell_distance(metric, leaf_centres[k, 0], leaf_centres[k, 1], obstacles.x0[pair],
                                   obstacles.x1[pair], obstacles.y0[pair], obstacles.y1[pair])
                assert beside[k] in pair and d[pair.index(beside[k])] == d.min()
        c, radius = centres[0], float(truth[0]) * 1.5
        everyone = _cell_distance(metric, c[0], c[1], obstacles.x0, obstacles.x1, obstacles.y0, obstacles.y1)
        assert np.array_equal(obstacles.near(metric, tuple(c), radius), np.flatnonzero(everyone <= radius))


@settings(max_examples=15, deadline=None)
@given(seed=st.integers(0, 10 ** 6))
def test_bucketed_distance_on_a_deep_grid(seed):
    """`test_bucketed_distance_is_the_one_pass_distance` on a grid of depth `DEEP` (its finer
    buckets, and more cells looked at for every centre)."""
    from fivebar_cli.analyses.inscribed import DEEP, LEVELS, _Obstacles

    grid = Grid(((-1.5, 2.25), (-3.0, 0.5)), DEEP, (False, False))
    assert _Obstacles(Tree.from_cells(grid, 1, [[0, 0]])).bucket_level == LEVELS[True][1] > LEVELS[False][1]
    _check_bucketed_distance(seed, DEEP)


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 10 ** 6), depth=st.integers(1, 16))
def test_obstacle_bounds_are_the_trees_bounds(seed, depth):
    """The complement cells' bounds, made axis by axis from a table of widths (`_axis_bounds`):
    the very floats of `Tree.bounds` (cell_bounds: a width per cell), on a root box whose sides
    are not powers of two, for leaves of every level."""
    from fivebar_cli.analyses.inscribed import _Obstacles

    rng = np.random.default_rng(seed)
    grid = Grid(((-1.3, 2.7), (0.1, 0.45)), depth, (False, False))
    level = int(rng.integers(1, min(depth, 7) + 1))  # (the complement's leaves: every level up to it)
    n = 1 << level
    tree = Tree.from_cells(grid, level, np.argwhere(rng.random((n, n)) < rng.uniform(0.05, 0.95)))
    if not len(tree):
        return
    obstacles = _Obstacles(tree)
    lo, hi = obstacles.cells.bounds()
    for got, want in ((obstacles.x0, lo[:, 0]), (obstacles.y0, lo[:, 1]), (obstacles.x1, hi[:, 0]), (obstacles.y1, hi[:, 1])):
        assert got.dtype == np.float64 and np.array_equal(got, want)
