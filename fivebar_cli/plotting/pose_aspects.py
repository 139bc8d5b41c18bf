"""Figures of aspects in a space of poses, assembly modes and motions, for any kind with a
`PoseAspectModel` (drawn from its `sketch`): slices of each aspect, the mechanism in each
assembly mode, and a motion (the mechanism drawn along it, the joints against the path parameter).
"""

from __future__ import annotations

import numpy as np

from fivebar_cli.plotting import pyplot
from fivebar_cli.plotting.trees import PALE, draw_layers

SLICES = 4  # columns of the slice figure: centres of equal parts of the last axis
MAX_ROWS = 6  # aspects drawn (one row each); the others are named in the title
UNDETERMINED = (0.25, 0.25, 0.25)  # the cells a class test left undetermined, in the aspect map
SNAPSHOTS = 9  # poses of the mechanism drawn along a motion


def _colour(number: int):
    import matplotlib

    return matplotlib.colormaps["tab10"]((number - 1) % 10)[:3]


def figure_aspect_slices(analysis, headline: str | None = None):
    """One row per aspect (the first MAX_ROWS), one column per slice along the last axis of a 3-D
    space (one panel for a 2-D space): the aspect's cells in its colour over the other aspects'
    in grey; obstacles in blue. The title starts with `headline` (the analysis's by default)."""
    plt = pyplot()
    space = analysis.mechanism.spaces()[analysis.model.space]
    shown = analysis.aspects[:MAX_ROWS]
    if space.dim == 2:
        values = [None]
    else:
        last = space.axes[-1]
        values = [last.lo + (k + 0.5) * (last.hi - last.lo) / SLICES for k in range(SLICES)]
    rows = max(len(shown), 1)
    fig, panels = plt.subplots(rows, len(values), figsize=(2.9 * len(values) + 0.6, 2.9 * rows + 0.8), dpi=110,
                               squeeze=False)
    for r, a in enumerate(shown):
        for c, value in enumerate(values):
            ax = panels[r, c]
            cut = (lambda t: t) if value is None else (lambda t: t.slice(space.dim - 1, value))
            layers = [(cut(b.tree), PALE) for b in analysis.aspects if b.number != a.number]
            layers.append((cut(a.tree), _colour(a.number)))
            draw_layers(ax, layers, space.axes[:2], outline=[], marks=analysis.mechanism.marks(space.name))
            where = "" if value is None else f", {space.axes[-1].name} = {value:.4g} {space.axes[-1].unit}".rstrip()
            ax.set_title(f"aspect {a.number} ({a.signs.label}){where}", fontsize=8)
            ax.tick_params(labelsize=7)
    for ax in panels.ravel()[len(shown) * len(values):]:
        ax.axis("off")
    more = f"; aspects {shown[-1].number + 1}..{analysis.aspects[-1].number} not drawn" \
        if len(analysis.aspects) > len(shown) else ""
    fig.suptitle(f"{headline or analysis.headline()}{more}", fontsize=9)
    fig.tight_layout()
    return fig


def figure_aspect_map(analysis, headline: str | None = None):
    """One panel per sheet (a 3-RRR's working mode; one panel for a 3-RPR): every aspect of the
    sheet in its own colour, the cells its classes left undetermined in dark grey (the singularity
    curves and the workspace's boundary), at one orientation (the middle of the range for a 3-D
    space); obstacles in blue. The title starts with `headline` (the analysis's by default)."""
    from fivebar_cli.analyses.pose_aspects import sheet_classes

    plt = pyplot()
    model = analysis.model
    space = analysis.mechanism.spaces()[model.space]
    value = None if space.dim == 2 else 0.5 * (space.axes[-1].lo + space.axes[-1].hi)
    cut = (lambda t: t) if value is None else (lambda t: t.slice(space.dim - 1, value))
    n = len(model.sheets)
    columns = min(n, 4)
    rows = (n + columns - 1) // columns
    fig, panels = plt.subplots(rows, columns, figsize=(3.3 * columns + 0.4, 3.3 * rows + 0.8), dpi=110, squeeze=False)
    for sheet, ax in enumerate(panels.ravel()):
        if sheet >= n:
            ax.axis("off")
            continue
        classes = sheet_classes(model, sheet)
        layers = [(cut(analysis.regions[k].paving.undetermined_tree()), UNDETERMINED) for k in classes]
        mine = [a for a in analysis.aspects if a.cls in classes]
        layers += [(cut(a.tree), _colour(j + 1)) for j, a in enumerate(mine)]
        draw_layers(ax, layers, space.axes[:2], outline=[], marks=analysis.mechanism.marks(space.name))
        label = model.sheets[sheet].label
        ax.set_title(f"{label + ': ' if label else ''}{len(mine)} aspects "
                     f"({', '.join(str(a.number) for a in mine) or '-'})", fontsize=8)
        ax.tick_params(labelsize=7)
    where = "" if value is None else f", {space.axes[-1].name} = {value:.4g} {space.axes[-1].unit}".rstrip()
    fig.suptitle(f"{headline or analysis.headline()}{where}; dark: undetermined (singularities, boundary)", fontsize=9)
    fig.tight_layout()
    return fig


def _draw_mechanism(ax, sketch: dict, k: int, colour, alpha: float = 1.0, links: bool = True) -> None:
    platform = sketch["platform"][k]
    ax.fill(platform[:, 0], platform[:, 1], facecolor=colour, edgecolor="k", alpha=alpha, lw=0.8)
    if links:
        for a, b in sketch["links"][k]:
            ax.plot(*zip(a, b), color="k", lw=1.2, alpha=max(alpha, 0.4))


def _draw_base(ax, sketch: dict) -> None:
    base = sketch["base"]
    ax.fill(base[:, 0], base[:, 1], facecolor="0.85", edgecolor="k", lw=1.2)


def figure_assembly_modes(model, poses: np.ndarray, labels: list[str], title: str, classes=0):
    """The mechanism in each of its assembly modes (in its class: one, or one per pose), one panel each."""
    plt = pyplot()
    n = max(len(poses), 1)
    columns = min(n, 3)
    rows = (n + columns - 1) // columns
    fig, panels = plt.subplots(rows, columns, figsize=(3.4 * columns, 3.4 * rows + 0.5), dpi=110, squeeze=False)
    sketch = model.sketch(np.asarray(poses, float).reshape(len(poses), -1), classes) if len(poses) else None
    if sketch is not None:
        points = np.concatenate([sketch["base"].reshape(-1, 2), sketch["platform"].reshape(-1, 2),
                                 sketch["links"].reshape(-1, 2)])
        lo, hi = points.min(0), points.max(0)
        pad = 0.08 * float(np.max(hi - lo))
    for k, ax in enumerate(panels.ravel()):
        if sketch is None or k >= len(poses):
            ax.axis("off")
            continue
        _draw_base(ax, sketch)
        _draw_mechanism(ax, sketch, k, "tab:olive", 0.7)
        ax.set_xlim(lo[0] - pad, hi[0] + pad)
        ax.set_ylim(lo[1] - pad, hi[1] + pad)
        ax.set_aspect("equal")
        ax.set_title(labels[k], fontsize=8)
        ax.tick_params(labelsize=7)
    fig.suptitle(title, fontsize=9)
    fig.tight_layout()
    return fig


def path_parameter(points: np.ndarray, scales: np.ndarray) -> np.ndarray:
    """Arc length of a polyline (axes multiplied by `scales`), from 0 to 1."""
    step = np.linalg.norm(np.diff(points * scales, axis=0), axis=1)
    s = np.concatenate([[0.0], np.cumsum(step)])
    return s / s[-1] if s[-1] > 0 else s


def dense(points: np.ndarray, per_segment: int = 40) -> np.ndarray:
    """Points along every segment of a polyline (for drawing)."""
    t = np.linspace(0.0, 1.0, per_segment, endpoint=False)[:, None]
    inner = [a + t * (b - a) for a, b in zip(points[:-1], points[1:])]
    return np.concatenate(inner + [points[-1:]])


def figure_motion(model, space, unwrapped: np.ndarray, cls: int, title: str, start_label: str, end_label: str):
    """Left: the mechanism drawn along the motion (its platform at SNAPSHOTS poses, from purple to
    yellow; the links at both ends), the path of the platform origin. Right: every joint against the path parameter (arc
    length with the axes scaled as in the surface meshes), with its range."""
    from fivebar_cli.io.mesh import axis_scales

    plt = pyplot()
    fig, (left, right) = plt.subplots(1, 2, figsize=(12.5, 5.6), dpi=110)
    samples = dense(unwrapped)
    scales = axis_scales(space.axes)
    s = path_parameter(samples, scales)
    sketch = model.sketch(samples, cls)
    _draw_base(left, sketch)
    import matplotlib

    cmap = matplotlib.colormaps["viridis"]
    picks = np.unique(np.searchsorted(s, np.linspace(0.0, 1.0, SNAPSHOTS)).clip(0, len(s) - 1))
    for j, k in enumerate(picks):
        _draw_mechanism(left, sketch, k, cmap(j / max(len(picks) - 1, 1)), 0.55, links=k in (picks[0], picks[-1]))
    left.plot(samples[:, 0], samples[:, 1], color="tab:red", lw=1.2, label="platform origin")
    left.plot(*unwrapped[0, :2], "o", color=cmap(0.0), ms=7, mec="k", label=start_label)
    left.plot(*unwrapped[-1, :2], "s", color=cmap(1.0), ms=7, mec="k", label=end_label)
    left.set_aspect("equal")
    left.set_xlabel(space.axes[0].title)
    left.set_ylabel(space.axes[1].title)
    left.legend(loc="best", fontsize=7)
    left.set_title("the mechanism along the motion (purple: start, yellow: end)", fontsize=9)
    joints, _ = model.ikp(samples, cls)
    for i, axis in enumerate(model.joint_axes):
        right.plot(s, joints[:, i], lw=1.4, label=axis.name)
    for bound in sorted({b for a in model.joint_axes if not a.periodic for b in (a.lo, a.hi)}):
        right.axhline(bound, color="0.4", ls=":", lw=0.9)
    right.set_xlabel("path parameter (arc length, 0 to 1)")
    right.set_ylabel("joints" + (f" ({model.joint_axes[0].unit})" if model.joint_axes[0].unit else ""))
    right.legend(loc="best", fontsize=8)
    right.grid(alpha=0.3)
    right.set_title("joints along the motion (dotted: their ranges)", fontsize=9)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    return fig
