"""The boundary of the union of a 2-D tree's cells, as straight lattice segments.

Every leaf edge is cut into unit edges of the depth-D lattice; an edge shared by two cells of the
set appears twice and is interior, an edge that appears once is on the boundary. Boundary unit
edges on one lattice line are then merged into maximal straight segments, except through a vertex
where four boundary edges meet (two cells of the set touching at a corner only), so that segments
meet only at their ends (what a polygonizer needs). Integer lattice coordinates keep it exact.
"""

from __future__ import annotations

import numpy as np

from fivebar_cli.paving.tree import Tree


def _unit_edges(tree: Tree) -> tuple[np.ndarray, np.ndarray]:
    """Boundary unit edges: horizontal ones as (x, y) for [x, x+1] x {y}, vertical ones as (x, y)
    for {x} x [y, y+1], in depth-D lattice units."""
    depth = tree.grid.depth
    span = np.int64(1) << (depth - tree.level)
    corner = tree.coords * span[:, None]
    leaf = np.repeat(np.arange(len(tree)), span)
    offset = np.arange(int(span.sum()), dtype=np.int64) - np.repeat(np.cumsum(span) - span, span)
    x0, y0, s = corner[leaf, 0], corner[leaf, 1], span[leaf]
    n = np.int64(1) << (depth + 1)  # keys: lattice values run 0..2^depth

    def once(a: np.ndarray, b: np.ndarray) -> np.ndarray:
        keys, counts = np.unique(a * n + b, return_counts=True)
        keys = keys[counts == 1]
        return np.column_stack([keys // n, keys % n])

    horizontal = once(np.concatenate([y0, y0 + s]), np.concatenate([x0 + offset] * 2))[:, ::-1]  # (x, y)
    vertical = once(np.concatenate([x0, x0 + s]), np.concatenate([y0 + offset] * 2))  # (x, y)
    return horizontal, vertical


def _merge(edges: np.ndarray, along: int, pinch: np.ndarray, n: np.int64) -> np.ndarray:
    """Unit edges on lattice lines (`along`: the axis they run along) merged into maximal segments
    (x0, y0, x1, y1), broken at pinch vertices."""
    if not len(edges):
        return np.zeros((0, 4), np.int64)
    across = 1 - along
    order = np.lexsort((edges[:, along], edges[:, across]))
    e = edges[order]
    start_key = e[:, 0] * n + e[:, 1]
    new = np.ones(len(e), bool)
    new[1:] = (e[1:, across] != e[:-1, across]) | (e[1:, along] != e[:-1, along] + 1)
    new |= np.isin(start_key, pinch)
    first = np.flatnonzero(new)
    last = np.r_[first[1:], len(e)] - 1
    lo, hi = e[first], e[last].copy()
    hi[:, along] += 1
    return np.column_stack([lo, hi])


def boundary_segments(tree: Tree) -> np.ndarray:
    """The boundary of the union of the tree's cells: segments (x0, y0, x1, y1) in depth-D lattice
    units (integers), meeting only at their ends; sorted, so the same set gives the same array."""
    if tree.grid.dim != 2:
        raise ValueError("outlines are for quadtrees")
    if not len(tree):
        return np.zeros((0, 4), np.int64)
    horizontal, vertical = _unit_edges(tree)
    n = np.int64(1) << (tree.grid.depth + 2)
    ends = np.concatenate([horizontal, horizontal + [1, 0], vertical, vertical + [0, 1]])
    keys, degree = np.unique(ends[:, 0] * n + ends[:, 1], return_counts=True)
    pinch = keys[degree > 2]
    return np.concatenate([_merge(horizontal, 0, pinch, n), _merge(vertical, 1, pinch, n)])


def lattice_to_space(tree: Tree, points: np.ndarray) -> np.ndarray:
    """Lattice coordinates (units of depth-D cells) to the space's coordinates; the same lattice
    value always gives the same float."""
    grid = tree.grid
    return grid.lo + np.asarray(points, float) * (grid.size / float(1 << grid.depth))
