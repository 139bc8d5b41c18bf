"""The atlas figure: heat maps of the metrics over the two fastest swept lengths, one row of panels
per value of the other swept lengths (facets, at most MAX_FACETS evenly chosen); line plots when
one length is swept; robust panels too when the atlas has a tolerance. Grey: cannot be assembled;
x: aspect count (robust count, for the robust panels) not certified."""

from __future__ import annotations

import itertools

import numpy as np

from fivebar_cli.mechanisms.fivebar.model import LENGTHS
from fivebar_cli.plotting import pyplot

# (column, title, the column certifying it); the robust ones are drawn when atlas.csv has them
PANELS = (("aspects", "generalized aspects", "certified"), ("workspace_area", "workspace area", "certified"),
          ("largest_aspect_area", "largest aspect: workspace area", "certified"),
          ("circle_r", "largest singularity-free circle: radius", "certified"),
          ("robust_aspects", "robust aspects", "robust_certified"),
          ("robust_workspace_area", "robust workspace area", "robust_certified"))
MAX_FACETS = 6


def _edges(values: np.ndarray) -> np.ndarray:
    mid = (values[1:] + values[:-1]) / 2
    return np.concatenate([[2 * values[0] - mid[0]], mid, [2 * values[-1] - mid[-1]]])


def _panels(table: dict) -> tuple:
    return tuple(p for p in PANELS if p[0] in table)


def _grids(spec, table: dict) -> dict:
    """Each column of the table as an array over the swept lengths only (fixed axes dropped)."""
    keep = tuple(len(v) for v in spec.grid if len(v) > 1)
    out = {}
    for name in ("assemblable", "certified", "robust_certified"):
        if name in table:
            out[name] = (np.array(table[name]) == "true").reshape(keep)
    for name, _, _ in _panels(table):
        out[name] = np.array([float(v) for v in table[name]]).reshape(keep)
        out[name][~out["assemblable"]] = np.nan
    return out


def _title(spec) -> str:
    fixed = ", ".join(f"{k} = {v[0]:g}" for k, v in zip(LENGTHS, spec.grid) if len(v) == 1)
    robust = f", tolerance {spec.tolerance:g}" if spec.tolerance > 0 else ""
    return f"{spec.name}: depth {spec.depth}{robust}" + (f"; {fixed}" if fixed else "")


def figure_atlas(spec, table: dict):
    """The figure of an atlas (`table`: atlas.csv as columns of text), or None when nothing is swept."""
    swept = [k for k, v in enumerate(spec.grid) if len(v) > 1]
    if not swept:
        return None
    data, panels = _grids(spec, table), _panels(table)
    if len(swept) == 1:
        return _lines(spec, swept[0], data, panels)
    return _heat_maps(spec, swept, data, panels)


def _lines(spec, axis: int, data: dict, panels: tuple):
    plt = pyplot()
    x = np.array(spec.grid[axis])
    fig, axes = plt.subplots(1, len(panels), figsize=(4.2 * len(panels), 3.6), dpi=120, squeeze=False)
    for ax, (name, label, certificate) in zip(axes[0], panels):
        ax.plot(x, data[name], ".-", color="C0", lw=1)
        bad = ~data[certificate] & data["assemblable"]
        if bad.any():
            ax.plot(x[bad], data[name][bad], "x", color="C3", label="count not certified")
            ax.legend(fontsize=7)
        for value in x[~data["assemblable"]]:
            ax.axvline(value, color="0.7", lw=2)
        ax.set_xlabel(LENGTHS[axis])
        ax.set_title(label, fontsize=9)
        ax.grid(True, alpha=0.3)
    fig.suptitle(_title(spec) + "; grey: cannot be assembled", fontsize=9)
    fig.tight_layout()
    return fig


def _facets(spec, outer: list[int]) -> list[tuple[int, ...]]:
    combos = list(itertools.product(*(range(len(spec.grid[k])) for k in outer)))
    if len(combos) <= MAX_FACETS:
        return combos
    return [combos[i] for i in np.unique(np.linspace(0, len(combos) - 1, MAX_FACETS).round().astype(int))]


def _heat_maps(spec, swept: list[int], data: dict, panels: tuple):
    plt = pyplot()
    from matplotlib.colors import BoundaryNorm

    outer, (kx, ky) = swept[:-2], swept[-2:]
    facets = _facets(spec, outer)
    x, y = np.array(spec.grid[kx]), np.array(spec.grid[ky])
    ex, ey = _edges(x), _edges(y)
    counts = np.concatenate([data[n][np.isfinite(data[n])] for n, _, _ in panels if n.endswith("aspects")])
    levels = np.arange(counts.min() if counts.size else 0, (counts.max() if counts.size else 0) + 2) - 0.5
    cmap_counts = plt.get_cmap("viridis", max(1, len(levels) - 1))
    fig, axes = plt.subplots(len(facets), len(panels), figsize=(4.4 * len(panels), 3.6 * len(facets) + 0.4),
                             dpi=120, squeeze=False)
    marker = max(4.0, 400.0 / max(len(x), len(y)))
    for row, facet in zip(axes, facets):
        where = f"{', '.join(f'{LENGTHS[k]} = {spec.grid[k][i]:g}' for k, i in zip(outer, facet))}: " if outer else ""
        for ax, (name, label, certificate) in zip(row, panels):
            values = data[name][facet]  # (len(x), len(y))
            ax.set_facecolor("0.8")
            if name.endswith("aspects"):
                mesh = ax.pcolormesh(ex, ey, values.T, cmap=cmap_counts, norm=BoundaryNorm(levels, cmap_counts.N))
                bar = fig.colorbar(mesh, ax=ax)
                bar.set_ticks(levels[:-1] + 0.5)
                bar.set_ticklabels([f"{v:.0f}" for v in levels[:-1] + 0.5])
            else:
                mesh = ax.pcolormesh(ex, ey, values.T, cmap="magma")
                fig.colorbar(mesh, ax=ax)
            bad = ~data[certificate][facet] & data["assemblable"][facet]
            if bad.any():
                gx, gy = np.meshgrid(x, y, indexing="ij")
                ax.scatter(gx[bad], gy[bad], marker="x", s=marker, color="red", linewidths=0.8)
            ax.set_xlabel(LENGTHS[kx])
            ax.set_ylabel(LENGTHS[ky])
            ax.set_title(where + label, fontsize=9)
    shown = f" ({len(facets)} of {np.prod([len(spec.grid[k]) for k in outer])} facets)" if outer else ""
    fig.suptitle(_title(spec) + f"{shown}; grey: cannot be assembled; x: count not certified", fontsize=9)
    fig.tight_layout()
    return fig
