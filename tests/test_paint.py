"""The raster of the figures (plotting.trees.paint) against the blend it stands for, written here
pixel by pixel: white, then each layer's coverage (the fraction of the pixel its cells cover)
blended in its colour, in order. Layers overlap and have cells finer than a pixel, so both the
whole-pixel shortcut and the blended pixels are exercised; the image must be the same to the bit
(the PNGs of the commands depend on it): the blend's colours as `as_drawn` stores them, float32
values that matplotlib draws to the very bytes of the float64 blend (checked here on Agg)."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from conftest import cells_of
from fivebar_cli.paving.grid import Grid
from fivebar_cli.paving.tree import Tree
from fivebar_cli.plotting.trees import as_drawn, paint

GRID = Grid(((0.0, 1.0), (0.0, 1.0)), 6, (False, False))


def random_tree(rng: np.random.Generator) -> Tree:
    """A random set of cells at levels 2 to 6 (disjoint: drawn at the finest level, merged)."""
    level = int(rng.integers(2, 7))
    arr = rng.random((1 << level, 1 << level)) < rng.uniform(0.05, 0.7)
    fine = np.repeat(np.repeat(arr, 1 << (6 - level), 0), 1 << (6 - level), 1)
    fine &= rng.random(fine.shape) < rng.uniform(0.5, 1.0)  # some pixels only partly covered
    return Tree.from_cells(GRID, 6, cells_of(fine))


def reference(layers, level: int) -> np.ndarray:
    n = 1 << level
    image = np.ones((n, n, 3))
    for tree, colour in layers:
        cover = np.zeros((n, n))
        centres = tree.centres()
        area = 0.25 ** (tree.level - level).clip(0)  # a cell finer than a pixel covers this much of it
        for (x, y), lev, a in zip(centres, tree.level, area):
            i, j = int(x * n), int(y * n)
            if lev >= level:
                cover[j, i] += a
            else:
                span = n >> lev
                i0, j0 = i - i % span, j - j % span
                cover[j0:j0 + span, i0:i0 + span] = 1.0
        for j in range(n):
            for i in range(n):
                c = min(cover[j, i], 1.0)
                if c > 0:
                    image[j, i] = image[j, i] * (1 - c) + np.asarray(colour) * c
    return image


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), layers=st.integers(0, 4), level=st.integers(2, 5))
def test_paint_is_the_layer_by_layer_blend_to_the_bit(seed, layers, level):
    rng = np.random.default_rng(seed)
    stack = [(random_tree(rng), tuple(rng.random(3))) for _ in range(layers)]
    image = paint(stack, level)
    assert image.dtype == np.float32 and (image[..., 3] == 1).all()  # opaque
    assert np.array_equal(image[..., :3], as_drawn(reference(stack, level)))


def test_a_layer_covering_a_pixel_wholly_replaces_what_was_under_it():
    full, red, blue = Tree.full(GRID), (1.0, 0.0, 0.0), (0.0, 0.0, 1.0)
    half = Tree.from_cells(GRID, 1, np.array([[0, 0], [1, 0]]))  # the lower half
    image = paint([(full, red), (half, blue)], 3)
    assert (image[:4, :, :3] == blue).all() and (image[4:, :, :3] == red).all()  # 0 and 1 exactly


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), level=st.integers(0, 6))
def test_covered_pixels_are_those_the_coarse_leaves_fill(seed, level):
    """`covered`: the pixels filled by leaves at most `level` deep, counted here leaf by leaf;
    for a tree no deeper than `level` exactly the pixels of coverage 1."""
    tree = random_tree(np.random.default_rng(seed))
    n = 1 << level
    expect = np.zeros((n, n), bool)
    for lev, (x, y) in zip(tree.level, tree.coords):
        if lev <= level:
            span = 1 << (level - lev)
            expect[y * span:(y + 1) * span, x * span:(x + 1) * span] = True
    assert np.array_equal(tree.covered(level), expect)
    if tree.level.max(initial=0) <= level:  # an empty tree too: no pixel covered, none of coverage 1
        assert np.array_equal(tree.covered(level), tree.coverage(level) == 1)


def drawn_bytes(image: np.ndarray) -> bytes:
    """The pixels matplotlib's Agg draws for `image` as the figures show a raster (nearest, scaled
    by a non-integer factor, here on a tiny figure)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(1.3, 1.1), dpi=97)
    FigureCanvasAgg(fig)
    ax = fig.add_axes((0.1, 0.1, 0.8, 0.8))
    ax.imshow(image, origin="lower", extent=(0, 1, 0, 1), interpolation="nearest")
    fig.canvas.draw()
    return bytes(fig.canvas.buffer_rgba())


def test_as_drawn_colours_draw_to_the_bytes_of_the_float64_ones():
    """Every byte k survives matplotlib's float32 round trip (k / 255, times 255, truncated), and a
    float64 image, its colours near every byte boundary and blends of random coverage included,
    draws to the same pixels as its float32 `as_drawn` stand-in (an image half as large)."""
    k = np.arange(256, dtype=np.uint8)
    assert np.array_equal((np.divide(k, 255, dtype=np.float32) * np.float32(255)).astype(np.uint8), k)
    rng = np.random.default_rng(7)
    near = (k[:, None] + np.array([-1e-12, 0, 1e-12, 0.5, 1 - 1e-9])).ravel() / 255  # around each x * 255 = k
    values = np.concatenate([np.clip(near, 0, 1), rng.random(64 * 64 * 3 - near.size)])
    image = np.ones((64, 64, 4))
    image[..., :3] = rng.permutation(values).reshape(64, 64, 3)
    stored = as_drawn(image)
    assert stored.dtype == np.float32
    assert drawn_bytes(stored) == drawn_bytes(image)
