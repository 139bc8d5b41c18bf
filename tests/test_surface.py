"""The boundary surface of an octree's cells (paving/surface.py) on random octrees: closed, oriented
outwards, conforming (no vertex inside another triangle's edge) and enclosing exactly the cells'
volume, counted voxel by voxel (the trees merge voxels into larger cells, so faces meet smaller ones).
"""

from __future__ import annotations

import numpy as np
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from fivebar_cli.paving.grid import Grid
from fivebar_cli.paving.surface import boundary_mesh
from fivebar_cli.paving.tree import Tree

DEPTH = 3


@st.composite
def voxel_sets(draw):
    """A random set of depth-3 voxels, made of random blocks so that the tree has cells of every size."""
    full = np.zeros((8, 8, 8), bool)
    for _ in range(draw(st.integers(1, 6))):
        size = 1 << draw(st.integers(0, 2))
        x, y, z = (draw(st.integers(0, 8 // size - 1)) * size for _ in range(3))
        full[x:x + size, y:y + size, z:z + size] = draw(st.booleans()) or not full.any()
    assume(full.any())  # an aspect is never empty
    return full


@settings(max_examples=40, deadline=None)
@given(voxel_sets())
def test_random_octree_surfaces_are_closed_oriented_conforming_and_exact(full):
    grid = Grid(((0.0, 1.0),) * 3, DEPTH, (False,) * 3)
    tree = Tree.from_cells(grid, DEPTH, np.argwhere(full))
    vertices, triangles = boundary_mesh(tree)
    t = vertices[triangles]
    enclosed = np.einsum("ij,ij->i", t[:, 0], np.cross(t[:, 1], t[:, 2])).sum() / 6.0  # divergence theorem
    assert enclosed == full.sum()  # lattice units: one voxel is 1, exactly (half-integers, small sums)
    directed = np.concatenate([triangles[:, [0, 1]], triangles[:, [1, 2]], triangles[:, [2, 0]]])
    keys, back = directed[:, 0] * len(vertices) + directed[:, 1], directed[:, 1] * len(vertices) + directed[:, 0]
    assert np.array_equal(np.sort(keys), np.sort(back))  # closed and oriented: each edge walked both ways
    edges = np.unique(np.sort(directed, axis=1), axis=0)
    p, q = vertices[edges[:, 0]], vertices[edges[:, 1]]
    d = vertices[None, :, :] - p[:, None, :]
    along = np.einsum("evk,ek->ev", d, q - p) / np.einsum("ek,ek->e", q - p, q - p)[:, None]
    off = np.linalg.norm(d - along[:, :, None] * (q - p)[:, None, :], axis=2)
    assert not np.any((off < 1e-12) & (along > 1e-12) & (along < 1 - 1e-12))  # no T-junction
    assert np.all(np.linalg.norm(np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]), axis=1) > 0)  # no flat triangle
