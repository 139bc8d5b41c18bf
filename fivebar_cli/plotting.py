"""Matplotlib figures of five-bar results (imported lazily: only commands that plot load matplotlib).

Trees are drawn as rasters (coverage of each pixel, so millions of cells cost nothing) with the
outlines of the leaves on top when they are few enough to be seen, like the paper's figures.
"""

from __future__ import annotations

import numpy as np

from fivebar_cli.quadtree import Tree

MAX_RASTER_LEVEL = 10
MAX_OUTLINES = 12000
WHITE = np.array([1.0, 1.0, 1.0])


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _paint(layers: list[tuple[Tree, tuple[float, float, float]]], level: int) -> np.ndarray:
    """RGB image: white, with each tree's coverage blended in its colour."""
    n = 1 << level
    image = np.tile(WHITE, (n, n, 1))
    for tree, colour in layers:
        cover = np.clip(tree.coverage(level), 0, 1)[..., None]
        image = image * (1 - cover) + np.asarray(colour) * cover
    return image


def _outlines(ax, trees: list[Tree]) -> None:
    from matplotlib.collections import LineCollection

    for tree in trees:
        if 0 < len(tree) <= MAX_OUTLINES:
            lo, hi = tree.bounds()
            x0, y0, x1, y1 = lo[:, 0], lo[:, 1], hi[:, 0], hi[:, 1]
            segs = np.stack(
                [np.stack([x0, y0, x1, y0], 1), np.stack([x1, y0, x1, y1], 1),
                 np.stack([x1, y1, x0, y1], 1), np.stack([x0, y1, x0, y0], 1)], 1
            ).reshape(-1, 2, 2)
            ax.add_collection(LineCollection(segs, colors="0.55", linewidths=0.15))


def _axes_labels(ax, space: str) -> None:
    if space == "jointspace":
        ax.set_xlabel(r"$\theta_1$ (rad)")
        ax.set_ylabel(r"$\theta_2$ (rad)")
    else:
        ax.set_xlabel("x")
        ax.set_ylabel("y")


def figure_layers(layers, space: str, title: str, legend: list[tuple[str, tuple]], outline: list[Tree]):
    """A figure of coloured trees on the root box of their grid."""
    plt = _pyplot()
    grid = layers[0][0].grid
    level = min(grid.depth, MAX_RASTER_LEVEL)
    (x0, x1), (y0, y1) = grid.root
    fig, ax = plt.subplots(figsize=(6.4, 6.0), dpi=150)
    ax.imshow(_paint(layers, level), origin="lower", extent=(x0, x1, y0, y1), interpolation="nearest")
    _outlines(ax, outline)
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)
    ax.set_aspect("equal")
    _axes_labels(ax, space)
    ax.set_title(title, fontsize=10)
    if legend:
        from matplotlib.patches import Patch

        ax.legend(handles=[Patch(facecolor=c, edgecolor="0.3", label=t) for t, c in legend],
                  loc="upper right", fontsize=7, framealpha=0.9)
    fig.tight_layout()
    return fig


def figure_paving(name: str, space: str, inside: Tree, outside: Tree, undetermined: Tree, complement: bool):
    """Paper figures 3 and 6 (certified inside in black) or 4 (complementary space in black)."""
    black, red, pale = (0.0, 0.0, 0.0), (0.85, 0.15, 0.1), (0.88, 0.88, 0.88)
    shown, other = (outside, inside) if complement else (inside, outside)
    what = "complementary " if complement else ""
    label = {"jointspace": "joint space", "workspace": "workspace"}[space]
    title = (f"{name}: {what}{label}, depth {inside.grid.depth} "
             f"(black area {shown.area:.6g}, undetermined {undetermined.area:.3g})")
    legend = [
        ("certified outside" if complement else "certified inside", black),
        ("undetermined at maximum depth", red),
    ]
    layers = [(shown, black), (undetermined, red)]
    if not complement:
        legend.append(("certified outside", pale))
        layers.insert(0, (other, pale))
    return figure_layers(layers, space, title, legend, outline=[shown])


def figure_kratio(rows: list[dict]):
    """K = n / 4^d against depth: our tests, the paper's procedure and the paper's printed values."""
    plt = _pyplot()
    fig, axes = plt.subplots(1, 2, figsize=(10, 4.2), dpi=150, sharey=True)
    for ax, space in zip(axes, ("jointspace", "workspace")):
        for mech in sorted({r["mechanism"] for r in rows}):
            sel = [r for r in rows if r["space"] == space and r["mechanism"] == mech]
            if not sel:
                continue
            d = [r["depth"] for r in sel]
            line, = ax.semilogy(d, [r["K"] for r in sel], "o-", label=f"{mech}: tight tests")
            ax.semilogy(d, [r["paper_procedure_K"] for r in sel], "s--", color=line.get_color(),
                        alpha=0.7, label=f"{mech}: paper's procedure")
            printed = [(r["depth"], r["paper_printed_percent"] / 100) for r in sel if r["paper_printed_percent"] != ""]
            if printed:
                ax.semilogy(*zip(*printed), "x", color="k", markersize=7)
        ax.set_title({"jointspace": "Joint space", "workspace": "Workspace"}[space])
        ax.set_xlabel("depth d")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    axes[0].set_ylabel(r"$K = n / 4^d$  (x: paper's Table 1)")
    fig.tight_layout()
    return fig


def _aspect_colour(number: int):
    import matplotlib

    return matplotlib.colormaps["tab10"]((number - 1) % 10)[:3]


def _label_aspects(ax, aspects, space: str) -> None:
    for a in aspects:
        tree = a.workspace if space == "workspace" else a.jointspace
        x, y = tree.centres()[int(np.argmin(tree.level))]
        ax.annotate(str(a.number), (x, y), ha="center", va="center", fontsize=9, fontweight="bold",
                    color="white", bbox={"boxstyle": "circle,pad=0.2", "fc": "0.15", "ec": "none", "alpha": 0.8})


def _aspect_panel(ax, region, aspects, space: str, title: str) -> None:
    grid = region.paving.grid
    level = min(grid.depth, MAX_RASTER_LEVEL)
    pale, black = (0.88, 0.88, 0.88), (0.0, 0.0, 0.0)
    layers = [(region.paving.outside, pale), (region.paving.undetermined_tree(), black)]
    layers += [(a.workspace if space == "workspace" else a.jointspace, _aspect_colour(a.number)) for a in aspects]
    (x0, x1), (y0, y1) = grid.root
    ax.imshow(_paint(layers, level), origin="lower", extent=(x0, x1, y0, y1), interpolation="nearest")
    _label_aspects(ax, aspects, space)
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)
    ax.set_aspect("equal")
    _axes_labels(ax, space)
    ax.set_title(title, fontsize=9)


def _aspect_legend(fig, aspects) -> None:
    from matplotlib.patches import Patch

    from fivebar_cli.aspects import signs_text

    handles = [Patch(facecolor=_aspect_colour(a.number), label=f"aspect {a.number}: working mode "
                     f"{signs_text(a.working)}, det A {signs_text(a.assembly)}") for a in aspects]
    handles += [Patch(facecolor=(0.88, 0.88, 0.88), label="complement (certified outside)"),
                Patch(facecolor=(0.0, 0.0, 0.0), label="undetermined (singularities)")]
    fig.legend(handles=handles, loc="lower center", ncol=3, fontsize=7, frameon=False)


def figure_aspects_workspace(analysis):
    """Paper figures 7 and 8: the parallel aspects, one panel per working mode."""
    from fivebar_cli.aspects import WORKING_MODES, signs_text

    plt = _pyplot()
    fig, axes = plt.subplots(2, 2, figsize=(10, 10.8), dpi=130)
    for ax, wm in zip(axes.ravel(), WORKING_MODES):
        region = analysis.region("workspace", wm)
        mine = [a for a in analysis.aspects if a.working == wm]
        _aspect_panel(ax, region, mine, "workspace", f"working mode {signs_text(wm)} (signs of B11, B22)")
    fig.suptitle(f"{analysis.mechanism.name}: parallel aspects in the workspace, depth {analysis.depth}")
    _aspect_legend(fig, analysis.aspects)
    fig.tight_layout(rect=(0, 0.07, 1, 0.97), h_pad=2.0)
    return fig


def figure_aspects_jointspace(analysis, assembly: int):
    """Paper figures 9 and 10: the serial aspects in the joint space for one sign of det A."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(6.8, 7.4), dpi=150)
    region = analysis.region("jointspace", assembly)
    mine = [a for a in analysis.aspects if a.assembly == assembly]
    _aspect_panel(ax, region, mine, "jointspace",
                  f"{analysis.mechanism.name}: serial aspects, det A {'>' if assembly > 0 else '<'} 0, "
                  f"depth {analysis.depth}")
    _aspect_legend(fig, mine)
    fig.tight_layout(rect=(0, 0.1, 1, 1))
    return fig
