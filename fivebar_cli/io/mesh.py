"""Octrees as closed surface meshes in PLY files (binary little-endian), for ParaView, MeshLab and
Blender: the outer faces of the tree's black cells (`paving/surface.py`), as triangles.

Coordinates: an axis in the length unit (x, y) is written as is; an axis in another unit (phi in
degrees) is scaled by `axis_scales`: its root width is mapped onto the largest root width of the
length axes, so that the box is about as tall as it is wide; the factor is in the header
(`comment scale phi 0.178125: z = phi (deg) x 0.178125`). The enclosed volume is then the
cells' volume times the product of the scales.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from fivebar_cli.io.files import atomic_write
from fivebar_cli.paving.surface import boundary_mesh
from fivebar_cli.paving.tree import Tree


def axis_scales(axes) -> np.ndarray:
    """Per axis: 1 for axes in the first axis's unit, else the factor that gives it the largest
    width of those axes (a degree axis becomes as long as the widest length axis)."""
    unit = axes[0].unit
    widest = max(a.hi - a.lo for a in axes if a.unit == unit)
    return np.array([1.0 if a.unit == unit else widest / (a.hi - a.lo) for a in axes])


def mesh_of(tree: Tree, scales: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(vertices (v, 3) in the space's units times `scales`, triangles (t, 3))."""
    lattice, triangles = boundary_mesh(tree)
    grid = tree.grid
    vertices = (grid.lo + lattice * (grid.size / float(1 << grid.depth))) * scales
    return vertices, triangles


def ply_bytes(vertices: np.ndarray, triangles: np.ndarray, comments: list[str]) -> bytes:
    """A binary little-endian PLY: double x, y, z per vertex; faces as uchar 3 + three int32."""
    head = ["ply", "format binary_little_endian 1.0", *(f"comment {c}" for c in comments),
            f"element vertex {len(vertices)}", "property double x", "property double y", "property double z",
            f"element face {len(triangles)}", "property list uchar int vertex_indices", "end_header"]
    faces = np.zeros(len(triangles), dtype=[("n", "u1"), ("v", "<i4", (3,))])
    faces["n"], faces["v"] = 3, triangles
    return ("\n".join(head) + "\n").encode("ascii") + np.ascontiguousarray(vertices, "<f8").tobytes() + faces.tobytes()


def write_ply(path: str | Path, tree: Tree, axes, comments: list[str] = ()) -> Path:
    """Atomically write an octree's boundary surface (axes: the space's `Axis` objects)."""
    scales = axis_scales(axes)
    vertices, triangles = mesh_of(tree, scales)
    notes = list(comments) + [f"axes {' '.join(a.name for a in axes)}"]
    notes += [f"scale {a.name} {s!r}: {'xyz'[k]} = {a.name} ({a.unit}) x {s!r}"
              for k, (a, s) in enumerate(zip(axes, scales)) if s != 1.0]
    data = ply_bytes(vertices, triangles, notes)

    return atomic_write(path, lambda tmp: tmp.write_bytes(data))
