"""Figure of a certified motion (`fivebar path`): the polyline over its cells in the joint space
(wrapped into the chart), and its image through the DKP over the aspect in the workspace."""

from __future__ import annotations

import numpy as np

from fivebar_cli.plotting import pyplot
from fivebar_cli.plotting.trees import PALE, draw_layers

SAMPLES = 64  # points per segment for the drawn curves
CELLS, CHANNEL = (0.62, 0.78, 0.93), (0.2, 0.45, 0.75)


def dense(joints: np.ndarray) -> np.ndarray:
    """Points along every segment of the polyline (for drawing)."""
    t = np.linspace(0.0, 1.0, SAMPLES, endpoint=False)[None, :, None]
    a, b = joints[:-1, None, :], joints[1:, None, :]
    return np.concatenate([(a + t * (b - a)).reshape(-1, 2), joints[-1:]])


def wrapped(points: np.ndarray, grid) -> np.ndarray:
    """Points wrapped into the root box on periodic axes, with NaN rows where the curve jumps."""
    out = points.copy()
    for axis, wrap in enumerate(grid.periodic):
        if wrap:
            lo, size = grid.lo[axis], grid.size[axis]
            out[:, axis] = (out[:, axis] - lo) % size + lo
    jump = np.any(np.abs(np.diff(out, axis=0)) > 0.5 * grid.size, axis=1)
    return np.insert(out, np.flatnonzero(jump) + 1, np.nan, axis=0)


def figure_path(result, component, backdrop):
    """Joint space (the cells the motion may use, its component in blue, the polyline) and the
    workspace (the aspect's cells and the motion's image)."""
    plt = pyplot()
    m = result.mechanism
    spaces = m.spaces()
    fig, (left, right) = plt.subplots(1, 2, figsize=(12, 6.2), dpi=100)
    grid = result.cells.grid
    marks = m.marks
    draw_layers(left, [(result.cells, CELLS), (component, CHANNEL)], spaces["jointspace"].axes, outline=[],
                marks=marks("jointspace"))
    curve = wrapped(dense(result.unwrapped()), grid)
    left.plot(curve[:, 0], curve[:, 1], color="black", lw=1.4)
    corners = wrapped(result.unwrapped(), grid)
    left.plot(corners[:, 0], corners[:, 1], "o", color="black", ms=2.5)
    if result.allow_serial:
        _serial_curves(left, result)
    left.set_title("joint space: certified cells (blue: those joined to the start)", fontsize=9)
    assembly = 1 if result.start.assembly == "+" else -1
    image, ok = m.aspect_model().dkp(dense(result.unwrapped()), assembly)
    image = np.where(ok[:, None], image, np.nan)
    ws_grid = spaces["workspace"].grid(result.depth)
    layers = [(backdrop if backdrop is not None and len(backdrop) else _empty(ws_grid), CHANNEL)]
    draw_layers(right, layers, spaces["workspace"].axes, outline=[], marks=marks("workspace"))
    right.plot(image[:, 0], image[:, 1], color="black", lw=1.4)
    right.plot(result.poses[:, 0], result.poses[:, 1], "o", color="black", ms=2.5)
    right.set_title("workspace: the motion of P over its aspect" if not result.allow_serial
                    else "workspace: the motion of P over the certified workspace", fontsize=9)
    for ax, pts in ((left, corners[~np.isnan(corners[:, 0])]), (right, result.poses)):
        ax.plot(*pts[0], "o", color="tab:green", ms=7, label="start")
        ax.plot(*pts[-1], "s", color="tab:red", ms=7, label="end")
    right.legend(loc="upper right", fontsize=7)
    kind = "across serial singularities, never parallel ones" if result.allow_serial else "singularity-free"
    fig.suptitle(f"{m.name}: certified motion ({kind}), det A {result.start.assembly}, depth {result.depth}, "
                 f"{len(result.joints)} waypoints", fontsize=10)
    fig.patch.set_facecolor("white")
    left.set_facecolor(PALE)
    fig.tight_layout()
    return fig


def _serial_curves(ax, result, n: int = 400) -> None:
    """The serial singularities B11 = 0 and B22 = 0 of the motion's assembly mode (drawn from a
    grid of DKP samples: a picture, not a certificate)."""
    m = result.mechanism
    axes = m.spaces()["jointspace"].axes
    a, b = np.meshgrid(np.linspace(axes[0].lo, axes[0].hi, n), np.linspace(axes[1].lo, axes[1].hi, n))
    joints = np.column_stack([a.ravel(), b.ravel()])
    model = m.aspect_model()
    poses, ok = model.dkp(joints, 1 if result.start.assembly == "+" else -1)
    values = model.mode_values(joints, np.nan_to_num(poses))
    for k, style in zip(range(values.shape[1] - 1), ("-", "--")):
        field = np.where(ok, values[:, k], np.nan).reshape(n, n)
        ax.contour(a, b, field, levels=[0.0], colors="0.25", linewidths=0.7, linestyles=style)
    from matplotlib.lines import Line2D

    names = model.serial_names
    ax.legend(handles=[Line2D([], [], color="0.25", lw=0.7, ls=st, label=f"{name} = 0")
                       for name, st in zip(names, ("-", "--"))], loc="upper right", fontsize=7)


def _empty(grid):
    from fivebar_cli.paving.tree import Tree

    return Tree.empty(grid)
