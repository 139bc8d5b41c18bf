"""Figures of pavings in any space: 2-D trees drawn directly, 3-D trees as slices.

Trees are drawn as rasters (coverage of each pixel, so millions of cells cost nothing) with the
outlines of the leaves on top when they are few enough to be seen, like the paper's figures.
"""

from __future__ import annotations

import numpy as np

from fivebar_cli.mechanisms.base import Space
from fivebar_cli.paving.tree import Tree
from fivebar_cli.plotting import pyplot

MAX_RASTER_LEVEL = 10
MAX_OUTLINES = 12000
WHITE = np.array([1.0, 1.0, 1.0])
BLACK, RED, PALE, AMBER = (0.0, 0.0, 0.0), (0.85, 0.15, 0.1), (0.88, 0.88, 0.88), (0.98, 0.7, 0.2)
MARK = (0.1, 0.35, 0.85)  # obstacles and joint limits
SPACE_TITLES = {"jointspace": "joint space", "workspace": "workspace"}
SLICES = 4  # panels of a 3-D paving: slices at the centres of this many equal parts of the last axis


def paint(layers: list[tuple[Tree, tuple[float, float, float]]], level: int) -> np.ndarray:
    """RGBA image (opaque: matplotlib would otherwise stack an alpha channel onto an RGB one at
    every draw): white, with each tree's coverage blended in its colour, layer after layer.

    A layer covering a pixel wholly replaces its colour, so a pixel that no layer covers in part
    takes the colour of the last layer covering it (white if none): one gather. Only the pixels
    some layer covers in part (cells finer than a pixel) are blended, layer by layer (in float64),
    and each colour is stored as `as_drawn` gives it: float32, drawn to the same bytes."""
    n = 1 << level
    last = np.zeros(n * n, dtype=np.int32)  # 0: white; k: the k-th layer covers it wholly, last
    mixed = np.zeros(n * n, dtype=bool)
    covers = []  # each layer's coverage where it has cells finer than a pixel (None: whole pixels only)
    for k, (tree, _) in enumerate(layers, 1):
        if len(tree) and tree.level.max() > level:  # cells finer than a pixel
            cover = tree.coverage(level).ravel()
            last[cover >= 1] = k
            mixed |= (cover > 0) & (cover < 1)
        else:  # whole pixels only
            cover = None
            last[tree.covered(level).ravel()] = k
        covers.append(cover)
    palette = as_drawn(np.array([(*WHITE, 1.0), *((*colour, 1.0) for _, colour in layers)], dtype=float))
    image = np.take(palette, last, axis=0)  # palette[last], without fancy indexing's per-row copies (3x faster)
    blend = np.flatnonzero(mixed)
    if len(blend):
        pixels = np.tile(WHITE, (len(blend), 1))
        for (tree, colour), cover in zip(layers, covers):
            cover = tree.coverage(level).ravel() if cover is None else cover
            c = np.clip(cover[blend], 0, 1)[:, None]
            pixels = pixels * (1 - c) + np.asarray(colour) * c
        image[blend, :3] = as_drawn(pixels)
    return image.reshape(n, n, 4)


BYTE_LEVELS = np.divide(np.arange(256, dtype=np.uint8), 0xFF, dtype=np.float32)  # as matplotlib reads bytes


def as_drawn(rgba: np.ndarray) -> np.ndarray:
    """Colours in [0, 1] as float32 values that matplotlib draws to the very bytes of the float64
    ones, at half the memory it copies and resamples at each draw (a 1024 x 1024 raster: 16 MB).

    `imshow` turns a float image into bytes by clipping to [0, 1] and truncating `x * 255` after
    resampling (nearest: the values as they are); in float32 that truncation can fall one short,
    but not for the values it gives a byte image (k / 255 in float32, for every byte k), which
    are the values kept here."""
    return BYTE_LEVELS[(np.clip(rgba, 0, 1) * 255).astype(np.uint8)]


def _outlines(ax, trees: list[Tree]) -> None:
    """The leaves' edges in grey (up to 4 x MAX_OUTLINES segments). They take no part in the
    axes' limits (`autolim=False`), which the caller sets to the grid's root box anyway: matplotlib
    would otherwise measure every segment's extent, for nothing."""
    from matplotlib.collections import LineCollection

    for tree in trees:
        if 0 < len(tree) <= MAX_OUTLINES:
            lo, hi = tree.bounds()
            x0, y0, x1, y1 = lo[:, 0], lo[:, 1], hi[:, 0], hi[:, 1]
            segs = np.stack(
                [np.stack([x0, y0, x1, y0], 1), np.stack([x1, y0, x1, y1], 1),
                 np.stack([x1, y1, x0, y1], 1), np.stack([x0, y1, x0, y0], 1)], 1
            ).reshape(-1, 2, 2)
            ax.add_collection(LineCollection(segs, colors="0.55", linewidths=0.15), autolim=False)


def axes_labels(ax, axes) -> None:
    ax.set_xlabel(axes[0].title)
    ax.set_ylabel(axes[1].title)


def draw_marks(ax, marks) -> None:
    """Obstacles (disc, polygon, with a dashed clearance outline) and limit lines over a panel
    (`marks` as `FiveBar.marks(space)` gives them)."""
    from matplotlib.patches import Circle, Polygon

    style = {"ec": MARK, "fc": (*MARK, 0.25), "lw": 1.2, "hatch": "////"}
    for mark in marks:
        if mark["kind"] == "line":
            draw = ax.axvline if mark["axis"] == 0 else ax.axhline
            draw(mark["value"], color=MARK, lw=1.2, ls="--")
        elif mark["kind"] == "disc":
            ax.add_patch(Circle(mark["centre"], mark["radius"], **style))
            if mark["clearance"] > 0:
                ax.add_patch(Circle(mark["centre"], mark["radius"] + mark["clearance"], fill=False, ec=MARK,
                                    lw=0.8, ls="--"))
        else:
            ax.add_patch(Polygon(mark["points"], closed=True, **style))
            if mark["clearance"] > 0:
                from shapely.geometry import Polygon as Shape

                ring = Shape(mark["points"]).buffer(mark["clearance"]).exterior.coords
                ax.plot(*zip(*ring), color=MARK, lw=0.8, ls="--")


def draw_layers(ax, layers, axes, outline: list[Tree], marks=()) -> None:
    """Coloured 2-D trees on the root box of their grid, in one panel, with the constraints' marks."""
    grid = layers[0][0].grid
    level = min(grid.depth, MAX_RASTER_LEVEL)
    (x0, x1), (y0, y1) = grid.root
    ax.imshow(paint(layers, level), origin="lower", extent=(x0, x1, y0, y1), interpolation="nearest")
    _outlines(ax, outline)
    draw_marks(ax, marks)
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)
    ax.set_aspect("equal" if axes[0].unit == axes[1].unit else "auto")
    axes_labels(ax, axes)


def slice_layers(layers, space: Space):
    """2-D layers of a paving: the trees as they are, or a 3-D paving's slice at the middle of its
    last axis (with the axes to label)."""
    if space.dim == 2:
        return layers, space.axes
    last = space.axes[-1]
    middle = 0.5 * (last.lo + last.hi)
    return [(tree.slice(space.dim - 1, middle), colour) for tree, colour in layers], space.axes[:2]


def draw_paving(ax, m, space: Space, paving) -> None:
    """A paving on the caller's axes: inside black, undetermined red, outside grey, the uncertain
    band amber, the constraints' marks blue (the library's `Paving.plot`)."""
    layers = [(paving.band, AMBER), (paving.outside, PALE), (paving.inside, BLACK), (paving.undetermined_tree(), RED)]
    layers, axes = slice_layers(layers, space)
    draw_layers(ax, layers, axes, outline=[], marks=m.marks(space.name))


def _legend(ax, legend) -> None:
    from matplotlib.patches import Patch

    ax.legend(handles=[Patch(facecolor=c, edgecolor="0.3", label=t) for t, c in legend],
              loc="upper right", fontsize=7, framealpha=0.9)


def figure_paving(name: str, space: Space, inside: Tree, outside: Tree, undetermined: Tree, complement: bool,
                  band: Tree | None = None, region: str | None = None, marks=()):
    """Paper figures 3 and 6 (certified inside in black) or 4 (complementary space in black); a
    3-D paving as slices at a few values of its last axis. With interval lengths the uncertain band
    (valid for some lengths only) is drawn in amber; a region other than the space's own is named
    in the title; obstacles and joint limits (`marks`) are drawn in blue."""
    shown, other = (outside, inside) if complement else (inside, outside)
    what = "complementary " if complement else ""
    where = SPACE_TITLES.get(space.name, space.name) + (f" ({region})" if region else "")
    title = (f"{name}: {what}{where}, depth {inside.grid.depth} "
             f"(black {'area' if space.dim == 2 else 'volume'} {shown.area:.6g}, undetermined {undetermined.area:.3g})")
    legend = [
        ("certified outside" if complement else "certified inside", BLACK),
        ("undetermined at maximum depth", RED),
    ]
    layers = [(shown, BLACK), (undetermined, RED)]
    if not complement:
        legend.append(("certified outside", PALE))
        layers.insert(0, (other, PALE))
    if band is not None and len(band):
        legend.append(("uncertain band (valid for some lengths)", AMBER))
        layers.insert(0, (band, AMBER))
    plt = pyplot()
    if space.dim == 2:
        fig, ax = plt.subplots(figsize=(6.4, 6.0), dpi=150)
        draw_layers(ax, layers, space.axes, outline=[shown], marks=marks)
        ax.set_title(title, fontsize=10)
        if marks:
            legend.append(("obstacle" if space.name == "workspace" else "joint limit", MARK))
        _legend(ax, legend)
        fig.tight_layout()
        return fig
    last = space.axes[-1]
    values = [last.lo + (k + 0.5) * (last.hi - last.lo) / SLICES for k in range(SLICES)]
    fig, panels = plt.subplots(2, SLICES // 2, figsize=(10, 10), dpi=120)
    for ax, value in zip(panels.ravel(), values):
        sliced = [(tree.slice(space.dim - 1, value), colour) for tree, colour in layers]
        draw_layers(ax, sliced, space.axes[:2], outline=[])
        ax.set_title(f"{last.name} = {value:.4g} {last.unit}".rstrip(), fontsize=9)
    _legend(panels.ravel()[0], legend)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    return fig


