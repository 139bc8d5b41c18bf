"""Figures for the 3-RPR (matplotlib, imported lazily, Agg backend): the construction of the
singularity-free workspace (the paper's figures 2 and 9) and line plots (figures 3-8 and 10)."""

from __future__ import annotations

import math

import numpy as np

from fivebar_cli.mechanisms.rpr3 import closed_form as rpr3
from fivebar_cli.mechanisms.rpr3.model import to_radians
from fivebar_cli.numerics import arcs
from fivebar_cli.plotting import pyplot

_COLOURS = ("tab:blue", "tab:red", "tab:green", "tab:orange", "tab:purple", "tab:brown")
_HATCHES = ("///", "xxx")


def _inner_point(loops_xy: list[np.ndarray], centres, radii) -> np.ndarray | None:
    """A point well inside the region (grid point farthest from the boundary), for the platform."""
    if not loops_xy:
        return None
    pts = np.vstack(loops_xy)
    lo, hi = pts.min(0), pts.max(0)
    gx, gy = np.meshgrid(np.linspace(lo[0], hi[0], 41), np.linspace(lo[1], hi[1], 41))
    grid = np.column_stack([gx.ravel(), gy.ravel()])
    grid = grid[arcs.contains(grid, centres, radii, rpr3.SIDES)]
    if len(grid) == 0:
        return None
    depth = np.min(np.hypot(grid[:, None, 0] - pts[None, ::4, 0], grid[:, None, 1] - pts[None, ::4, 1]), axis=1)
    return grid[int(np.argmax(depth))]


def _finish_plane(fig, ax, title: str):
    """Equal axes x, y, title, legend and grid of a figure in the plane; the figure."""
    ax.set_aspect("equal")
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    ax.set_title(title, fontsize=10)
    ax.legend(loc="upper left", fontsize=7, framealpha=0.85)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    return fig


def construction(mech, phis_deg, rho_min: float, rho_max: float, title: str):
    """Base, platform, workspace circles, singularity circle and the hatched region W at each phi
    (one phi: figure 2; two: figure 9, with the second region cross-hatched)."""
    plt = pyplot()
    from matplotlib.patches import Circle, PathPatch
    from matplotlib.path import Path as MPath

    t = mech.design
    fig, ax = plt.subplots(figsize=(7.5, 7.5), dpi=110)
    base = np.array([[0.0, 0.0], [mech.t1, 0.0], [mech.t2, mech.t3]])
    ax.fill(base[:, 0], base[:, 1], facecolor="0.85", edgecolor="k", lw=1.5, zorder=1, label="base")
    for i, p in enumerate(base):
        ax.annotate(f"B{i + 1}", p, textcoords="offset points", xytext=(-12, -12), fontsize=9)
    platform_drawn = False
    for n, phi_deg in enumerate(phis_deg):
        phi = to_radians(phi_deg, mech.phi_range[0])
        col = _COLOURS[n % len(_COLOURS)]
        centres, radii = rpr3.region(*t, phi, rho_min, rho_max)
        ax.add_patch(Circle(centres[0], radii[0], fill=False, ec=col, lw=2.0,
                            label=f"singularity circle, phi = {phi_deg:g}"))
        for i in range(3):
            c = centres[1 + i]
            ax.plot(*c, "o", color=col, ms=4)
            ax.annotate(f"C{i + 1}", c, textcoords="offset points", xytext=(4, 4), fontsize=9, color=col)
            if math.isfinite(radii[1 + i]):
                ax.add_patch(Circle(c, radii[1 + i], fill=False, ec=col, lw=0.7, ls="--", alpha=0.7))
            if radii[4 + i] > 0:
                ax.add_patch(Circle(c, radii[4 + i], fill=False, ec=col, lw=0.7, ls=":", alpha=0.9))
        boundary = arcs.boundary_arcs(centres, radii, rpr3.SIDES)
        loops_xy = arcs.polygon(boundary)
        a = float(arcs.area(centres, radii, rpr3.SIDES))
        if loops_xy:
            verts = np.vstack([np.vstack([lp, lp[:1]]) for lp in loops_xy])
            codes = np.concatenate(
                [[MPath.MOVETO] + [MPath.LINETO] * (len(lp) - 1) + [MPath.CLOSEPOLY] for lp in loops_xy]
            )
            ax.add_patch(
                PathPatch(MPath(verts, codes), facecolor="none", edgecolor=col, hatch=_HATCHES[n % 2], lw=1.5,
                          label=f"W at phi = {phi_deg:g}: area {a:.6f}")
            )
        if not platform_drawn:
            x = _inner_point(loops_xy, centres, radii)
            if x is not None:
                p = rpr3.platform_points(*t, phi, x[0], x[1])
                ax.fill(p[:, 0], p[:, 1], facecolor="tab:olive", edgecolor="k", alpha=0.6, zorder=3,
                        label=f"platform at phi = {phi_deg:g}")
                for i in range(3):
                    ax.plot([base[i, 0], p[i, 0]], [base[i, 1], p[i, 1]], "k-", lw=1.2, zorder=2)
                ax.plot(*x, "k+", ms=8, zorder=4)
                platform_drawn = True
    ax.plot([], [], "k--", lw=0.7, label=f"rho_max = {rho_max:.6g} circles")
    ax.plot([], [], "k:", lw=0.7, label=f"rho_min = {rho_min:.6g} circles")
    ax.autoscale_view()
    return _finish_plane(fig, ax, title)


def lines(series, xlabel: str, ylabel: str, title: str, marks=None):
    """A line plot: series is a list of (label, x, y) or (label, x, y, group); curves of one group
    share a line style and are coloured in turn. marks: optional (label, x, y) points."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(7.0, 4.8), dpi=110)
    groups: dict = {}
    for label, x, y, *group in series:
        members = groups.setdefault(tuple(group), [])
        style = ("-", "--", ":", "-.")[(len(groups) - 1) % 4]
        ax.plot(x, y, color=_COLOURS[len(members) % len(_COLOURS)], ls=style, lw=1.4, label=label)
        members.append(label)
    for label, x, y in marks or []:
        ax.plot([x], [y], "ko", ms=4)
        ax.annotate(label, (x, y), textcoords="offset points", xytext=(4, 4), fontsize=8)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title, fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    return fig


def close(fig) -> None:
    pyplot().close(fig)


# ---------------------------------------------------------------- octrees of the general 3-RPR

PLUS_COLOUR, MINUS_COLOUR = (0.16, 0.42, 0.78), (0.93, 0.55, 0.13)
SLICES = 4


def figure_singularity_free(title: str, space, plus, minus, unreachable, phi_range, design=None):
    """Constant-orientation slices of the sign trees (the 2-D quadtree of each slice): det J > 0 in
    blue, det J < 0 in orange, certified unreachable in grey, the singular-or-undetermined band in
    red; for a similar platform (`design`), the closed-form singularity circle at each slice's phi.
    A single-orientation space (phi_range[0]) is one panel."""
    from matplotlib.patches import Circle, Patch

    from fivebar_cli.paving.tree import Tree
    from fivebar_cli.plotting.trees import PALE, RED, draw_layers

    plt = pyplot()
    if space.dim == 2:
        values, shape = [None], (1, 1)
    else:
        last = space.axes[-1]
        values = [last.lo + (k + 0.5) * (last.hi - last.lo) / SLICES for k in range(SLICES)]
        shape = (2, SLICES // 2)
    fig, panels = plt.subplots(*shape, figsize=(6.4, 6.0) if space.dim == 2 else (10, 10), dpi=120, squeeze=False)
    for ax, value in zip(panels.ravel(), values):
        trees = [t if value is None else t.slice(2, value) for t in (unreachable, plus, minus)]
        band = Tree.full(trees[0].grid) - (trees[0] | trees[1] | trees[2])
        layers = [(trees[0], PALE), (trees[1], PLUS_COLOUR), (trees[2], MINUS_COLOUR), (band, RED)]
        draw_layers(ax, layers, space.axes[:2], outline=[])
        phi = phi_range[0] if value is None else value
        if design is not None:
            (cx, cy), radius = rpr3.singularity_circle(*design.design, to_radians(phi, phi_range[0]))
            ax.add_patch(Circle((float(cx), float(cy)), float(radius), fill=False, ec="k", lw=1.0, ls="--"))
        ax.set_title(f"phi = {phi:.4g} deg", fontsize=9)
    handles = [Patch(facecolor=c, edgecolor="0.3", label=t) for t, c in (
        ("det J > 0, reachable", PLUS_COLOUR), ("det J < 0, reachable", MINUS_COLOUR),
        ("certified unreachable", PALE), ("singular or undetermined", RED))]
    if design is not None:
        from matplotlib.lines import Line2D

        handles.append(Line2D([], [], color="k", ls="--", lw=1.0, label="singularity circle (closed form)"))
    panels.ravel()[0].legend(handles=handles, loc="upper right", fontsize=7, framealpha=0.9)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    return fig


def figure_pose(mech, pose, legs, title: str):
    """A pose (x, y, phi in degrees) of a 3-RPR with its leg lengths: base, platform, legs, and the
    leg lines extended (at a singular pose they meet in one point, or are parallel)."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(6.4, 6.0), dpi=120)
    base = np.array(mech.base, float)
    x, y, phi_deg = pose
    phi = math.radians(phi_deg)
    rot = np.array([[math.cos(phi), -math.sin(phi)], [math.sin(phi), math.cos(phi)]])
    joints = np.array([x, y]) + np.array(mech.platform, float) @ rot.T
    ax.fill(base[:, 0], base[:, 1], facecolor="0.85", edgecolor="k", lw=1.5, label="base")
    ax.fill(joints[:, 0], joints[:, 1], facecolor="tab:olive", edgecolor="k", alpha=0.6, label="platform")
    span = float(np.ptp(np.vstack([base, joints]), axis=0).max()) or 1.0
    for i in range(3):
        ax.plot(*zip(base[i], joints[i]), "k-", lw=2.0)
        d = (joints[i] - base[i]) / (np.linalg.norm(joints[i] - base[i]) or 1.0)
        ax.plot(*zip(base[i] - 2 * span * d, base[i] + 3 * span * d), ls="--", lw=0.7, color=_COLOURS[i],
                label=f"leg {i + 1} line ({legs[i]:.6g})")
        ax.annotate(f"B{i + 1}", base[i], textcoords="offset points", xytext=(-12, -12), fontsize=9)
    ax.plot([x], [y], "k+", ms=9, label=f"platform origin, phi = {phi_deg:.6g} deg")
    pts = np.vstack([base, joints])
    lo, hi = pts.min(0) - 0.6 * span, pts.max(0) + 0.6 * span
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    return _finish_plane(fig, ax, title)
