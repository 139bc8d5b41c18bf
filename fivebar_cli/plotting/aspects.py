"""Figures of generalized aspects: the parallel aspects in the workspace, one panel per working
mode (the paper's figures 7, 8), with each aspect's largest certified circle and square, and the
serial aspects in the joint space (figures 9, 10)."""

from __future__ import annotations

import math

import numpy as np

from fivebar_cli.analyses.aspects import signs_text
from fivebar_cli.paving.tree import Tree
from fivebar_cli.plotting import pyplot
from fivebar_cli.plotting.trees import BLACK, PALE, draw_layers


def _aspect_colour(number: int):
    import matplotlib

    return matplotlib.colormaps["tab10"]((number - 1) % 10)[:3]


def _label_aspects(ax, aspects, space: str) -> None:
    for a in aspects:
        tree = a.workspace if space == "workspace" else a.jointspace
        if not len(tree):  # an aspect too thin for cells in this space at this depth
            continue
        x, y = tree.centres()[int(np.argmin(tree.level))]
        ax.annotate(str(a.number), (x, y), ha="center", va="center", fontsize=9, fontweight="bold",
                    color="white", bbox={"boxstyle": "circle,pad=0.2", "fc": "0.15", "ec": "none", "alpha": 0.8})


def _draw_shapes(ax, aspects) -> None:
    """Each aspect's largest certified circle (dashed) and axis-aligned square (solid)."""
    from matplotlib.patches import Circle, Rectangle

    for a in aspects:
        if a.circle is not None:
            ax.add_patch(Circle((a.circle.x, a.circle.y), a.circle.r, fill=False, ec="white", lw=0.9, ls="--"))
        if a.square is not None:
            half = 0.5 * a.square.side
            ax.add_patch(Rectangle((a.square.x - half, a.square.y - half), a.square.side, a.square.side,
                                   fill=False, ec="white", lw=0.9))


def _aspect_panel(ax, analysis, region, aspects, space: str, title: str) -> None:
    layers = [(region.paving.outside, PALE), (region.paving.undetermined_tree(), BLACK)]
    layers += [(a.workspace if space == "workspace" else a.jointspace, _aspect_colour(a.number)) for a in aspects]
    marks = analysis.mechanism.marks(space)
    draw_layers(ax, layers, analysis.mechanism.spaces()[space].axes, outline=[], marks=marks)
    if space == "workspace":
        _draw_shapes(ax, aspects)
    _label_aspects(ax, aspects, space)
    ax.set_title(title, fontsize=9)


def draw_aspects(ax, m, aspects, space: str = "workspace") -> None:
    """Aspects as (number, tree) on the caller's axes, each in its colour with its number (the
    library's `Aspects.plot`); a 3-D space is shown by its slice at the middle of the last axis."""
    from fivebar_cli.plotting.trees import slice_layers

    s = m.spaces()[space]
    layers, axes = slice_layers([(tree, _aspect_colour(number)) for number, tree in aspects], s)
    if not layers:
        layers = [(Tree.empty(s.grid(0)), PALE)]
        layers, axes = slice_layers(layers, s)
    draw_layers(ax, layers, axes, outline=[])
    if s.dim == 2:
        for number, tree in aspects:
            if len(tree):
                x, y = tree.centres()[int(np.argmin(tree.level))]
                ax.annotate(str(number), (x, y), ha="center", va="center", fontsize=9, color="white",
                            bbox={"boxstyle": "circle,pad=0.2", "fc": "0.15", "ec": "none", "alpha": 0.8})


LEGEND_ROW = 0.17  # inches per legend row (7 pt)


def _legend_rows(aspects, shapes: bool) -> int:
    return math.ceil((len(aspects) + 2 + 2 * shapes) / 3)


def _room(aspects, shapes: bool, fits: int) -> float:
    """Extra height (inches) for a legend of more rows than the figure leaves room for (`fits`):
    mechanisms with limits or obstacles can have many aspects."""
    return max(0, _legend_rows(aspects, shapes) - fits) * LEGEND_ROW


def _aspect_legend(fig, aspects, shapes: bool = False) -> None:
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    handles = [Patch(facecolor=_aspect_colour(a.number), label=f"aspect {a.number}: working mode "
                     f"{signs_text(a.working)}, det A {signs_text(a.assembly)}") for a in aspects]
    handles += [Patch(facecolor=PALE, label="complement (certified outside)"),
                Patch(facecolor=BLACK, label="undetermined (singularities)")]
    if shapes:
        handles += [Line2D([], [], color="0.4", ls="--", label="largest certified circle"),
                    Line2D([], [], color="0.4", label="largest certified square")]
    fig.legend(handles=handles, loc="lower center", ncol=3, fontsize=7, frameon=False)


def figure_aspects_workspace(analysis):
    """Paper figures 7 and 8: the parallel aspects, one panel per working mode."""
    plt = pyplot()
    modes = analysis.model.working_modes
    cols = math.ceil(math.sqrt(len(modes)))
    rows = math.ceil(len(modes) / cols)
    room = _room(analysis.aspects, True, 5)
    height = 5.4 * rows + 0.6 + room
    fig, axes = plt.subplots(rows, cols, figsize=(5 * cols, height), dpi=130, squeeze=False)
    signs = ", ".join(analysis.model.serial_names)
    for ax, wm in zip(axes.ravel(), modes):
        region = analysis.region("workspace", wm)
        mine = [a for a in analysis.aspects if a.working == wm]
        _aspect_panel(ax, analysis, region, mine, "workspace", f"working mode {signs_text(wm)} (signs of {signs})")
    fig.suptitle(f"{analysis.mechanism.name}: parallel aspects in the workspace, depth {analysis.depth}")
    _aspect_legend(fig, analysis.aspects, shapes=True)
    fig.tight_layout(rect=(0, 0.08 + room / height * 0.92 if room else 0.08, 1, 0.97), h_pad=2.0)
    return fig


def figure_aspects_jointspace(analysis, assembly: int):
    """Paper figures 9 and 10: the serial aspects in the joint space for one sign of det A."""
    plt = pyplot()
    mine = [a for a in analysis.aspects if a.assembly == assembly]
    room = _room(mine, False, 4)
    fig, ax = plt.subplots(figsize=(6.8, 7.4 + room), dpi=150)
    region = analysis.region("jointspace", assembly)
    _aspect_panel(ax, analysis, region, mine, "jointspace",
                  f"{analysis.mechanism.name}: serial aspects, det A {'>' if assembly > 0 else '<'} 0, "
                  f"depth {analysis.depth}")
    _aspect_legend(fig, mine)
    fig.tight_layout(rect=(0, 0.1 + room / (7.4 + room) * 0.9 if room else 0.1, 1, 1))
    return fig
