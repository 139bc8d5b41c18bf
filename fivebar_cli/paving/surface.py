"""The boundary of the union of an octree's cells, as a closed, conforming triangle mesh in integer
lattice coordinates (depth-D cell units), for surface files (`io/mesh.py`).

1. Faces: for every leaf and each of the 6 directions, the same-size cell across the face is
   full (inside the set: no face), empty (the whole face is boundary) or partly covered (the face
   is split into the faces of the leaf's 4 children on that side, and each is looked at again),
   level by level down to depth D. Cells across the root box's side are empty: periodic axes are
   not wrapped, so the surface closes on the seam and encloses the cells' volume in the chart.
2. Orientation: each face is a quad whose corners turn counter-clockwise seen from outside, so
   its normal points out of the set.
3. Conforming: a face next to smaller faces has their corners on its edges (T-junctions); every
   face is cut into a fan of triangles from its centre through its corners and every vertex on its
   edges, in order, so that every edge of the mesh is shared by triangles on both sides (all faces
   alike: one rule, built for all faces at once).

Integer coordinates keep it exact: the enclosed volume (divergence theorem) is the cells' volume.
"""

from __future__ import annotations

import numpy as np

from fivebar_cli.paving.morton import deinterleave, step
from fivebar_cli.paving.tree import Tree

BITS = 21  # lattice coordinates of one axis fit in this many bits (depth <= 17 octrees, doubled for centres)


def _covered(tree: Tree, level: np.ndarray, code: np.ndarray) -> np.ndarray:
    """How much of each cell (level, code) the tree covers: 1 all, 0 none, 0.5 part."""
    grid = tree.grid
    shift = grid.dim * (grid.depth - level)
    start = code << shift
    end = start + (np.int64(1) << shift)
    out = np.zeros(len(level))
    if not len(tree) or not len(level):
        return out
    tree_start, tree_end = tree.start, tree.end
    leaf = np.searchsorted(tree_start, start, side="right") - 1
    inside = leaf >= 0
    inside[inside] &= tree_end[leaf[inside]] >= end[inside]
    sizes = np.concatenate([[0], np.cumsum(tree_end - tree_start)])
    a, b = np.searchsorted(tree_start, start), np.searchsorted(tree_start, end)
    some = (sizes[b] - sizes[a]) > 0
    out[some] = 0.5
    out[inside] = 1.0
    return out


def boundary_faces(tree: Tree) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Boundary faces of an octree's cells: (level, coords at that level, axis, side) per face;
    side +1: the face on the cell's high side along `axis`."""
    grid = tree.grid
    if grid.dim != 3:
        raise ValueError("surfaces are for octrees")
    out = []
    for axis in range(3):
        for side in (-1, 1):
            level, code = tree.level.copy(), tree.code.copy()
            while len(level):
                across, wrapped = step(code, level, 3, axis, side)
                cover = np.where(wrapped, 0.0, _covered(tree, level, across))
                empty = cover == 0.0
                out.append((level[empty], code[empty], np.full(int(empty.sum()), axis), np.full(int(empty.sum()), side)))
                part = cover == 0.5
                # the children on this side: bit `axis` of the child index is 1 on the high side
                kids = np.array([k for k in range(8) if ((k >> axis) & 1) == (side > 0)], np.int64)
                level = np.repeat(level[part] + 1, len(kids))
                code = ((code[part][:, None] << 3) | kids[None, :]).ravel()
    level = np.concatenate([o[0] for o in out])
    code = np.concatenate([o[1] for o in out])
    return level, deinterleave(code, level, 3), np.concatenate([o[2] for o in out]), np.concatenate([o[3] for o in out])


def boundary_mesh(tree: Tree) -> tuple[np.ndarray, np.ndarray]:
    """(vertices (v, 3) in depth-D lattice units, as floats: face centres are half-integers;
    triangles (t, 3) of vertex indices, counter-clockwise seen from outside)."""
    level, coords, axis, side = boundary_faces(tree)
    depth = tree.grid.depth
    size = np.int64(1) << (depth - level)
    lo = coords * size[:, None]
    b, c = (axis + 1) % 3, (axis + 2) % 3
    n = len(level)
    # quad corners (2 x lattice units, so centres are integers), turning from +b to +c: normal +axis
    corners = np.zeros((n, 4, 3), np.int64)
    rows = np.arange(n)
    for k, (db, dc) in enumerate(((0, 0), (1, 0), (1, 1), (0, 1))):
        corners[rows, k, axis] = lo[rows, axis] + (side > 0) * size
        corners[rows, k, b] = lo[rows, b] + db * size
        corners[rows, k, c] = lo[rows, c] + dc * size
    corners = np.where(side[:, None, None] > 0, corners, corners[:, ::-1])
    corners *= 2
    keys, index = np.unique(_key(corners.reshape(-1, 3), (0, 1, 2)), return_inverse=True)
    vertices = (keys[:, None] >> np.array([2 * BITS, BITS, 0])) & ((1 << BITS) - 1)  # sorted by (x, y, z)
    index = index.reshape(n, 4)
    first, count, forward, order = _edge_vertices(vertices, corners)
    # each face's ring: corner 0, the vertices inside edge 0, corner 1, ... (segments of 1 + count)
    seg = (1 + count).ravel()
    seg_start = np.cumsum(seg) - seg
    segment = np.repeat(np.arange(len(seg)), seg)
    at = np.arange(seg.sum()) - seg_start[segment] - 1  # -1: the corner, else the k-th inside vertex
    face, k = segment // 4, segment % 4
    inside = np.where(forward[face, k], at, count[face, k] - 1 - at)
    ring = np.where(at < 0, index[face, k], order[first[face, k] + np.maximum(inside, 0)])
    ring_len = seg.reshape(n, 4).sum(axis=1)
    after = np.arange(len(ring)) + 1
    after[np.cumsum(ring_len) - 1] = np.cumsum(ring_len) - ring_len  # each ring closes on its first vertex
    triangles = np.column_stack([len(vertices) + face, ring, ring[after]])
    vertices = np.concatenate([vertices, corners.sum(axis=1) // 4])
    return vertices.astype(float) / 2.0, triangles.astype(np.int64)


def _key(points: np.ndarray, axes: tuple[int, int, int]) -> np.ndarray:
    """Lattice points (non-negative, under 2**BITS) as one int64 each, ordered as the tuples of
    their coordinates along `axes`."""
    a, b, c = axes
    return (points[:, a] << (2 * BITS)) | (points[:, b] << BITS) | points[:, c]


def _edge_vertices(vertices: np.ndarray, corners: np.ndarray):
    """The mesh vertices strictly inside each face's edge k (corner k to corner k + 1), as
    (first, count, forward, order): they are order[first : first + count], sorted along the edge,
    to be read backwards where `forward` is False (the edge runs down its axis); (n, 4) arrays."""
    n = len(corners)
    first, count = np.zeros((n, 4), np.int64), np.zeros((n, 4), np.int64)
    forward = np.ones((n, 4), bool)
    sorted_keys, orders = [], []
    for e in range(3):  # vertices sorted by (the two other coordinates, the coordinate along e)
        key = _key(vertices, ((e + 1) % 3, (e + 2) % 3, e))
        order = np.argsort(key, kind="stable")
        sorted_keys.append(key[order])
        orders.append(order)
    for k in range(4):
        p, q = corners[:, k], corners[:, (k + 1) % 4]
        e = np.argmax(p != q, axis=1)
        for axis in range(3):
            sel = np.flatnonzero(e == axis)
            if not len(sel):
                continue
            o1, o2 = (axis + 1) % 3, (axis + 2) % 3
            base = (p[sel, o1] << (2 * BITS)) | (p[sel, o2] << BITS)
            a, b = np.minimum(p[sel, axis], q[sel, axis]), np.maximum(p[sel, axis], q[sel, axis])
            lo = np.searchsorted(sorted_keys[axis], base | (a + 1))
            first[sel, k] = lo + axis * len(vertices)  # into the three orders laid end to end
            count[sel, k] = np.searchsorted(sorted_keys[axis], base | b) - lo
            forward[sel, k] = q[sel, axis] > p[sel, axis]
    return first, count, forward, np.concatenate(orders)
