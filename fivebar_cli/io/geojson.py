"""GeoJSON (RFC 7946) of 2-D trees: the union of the black cells as a (Multi)Polygon with holes,
for CAD and GIS tools.

The outline (`paving/outline.py`: minimal boundary rings on the depth-D lattice, exact integers,
traced from the cells with the set on their left) gives one polygon per face of the set (cells
joined through edges; faces touching at a corner stay separate polygons, so the result is valid):
its counter-clockwise ring and its clockwise holes. They are normalized, oriented as RFC 7946 asks
(exterior rings counter-clockwise, holes clockwise) and only then mapped to the space's
coordinates. These are the polygons shapely's polygonizer finds from the boundary segments (the
tests compare the bytes), without its cost, which grew faster than the boundary. Coordinates are in
the space's own units (not longitude and latitude). The text is deterministic: keys sorted, floats
in their shortest exact form, no `-0.0`. shapely is imported only here, inside the functions that
need it.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from fivebar_cli.io.files import write_text
from fivebar_cli.paving.grid import Grid
from fivebar_cli.paving.outline import boundary_rings, lattice_to_space
from fivebar_cli.paving.tree import Tree


def tree_geometry(tree: Tree):
    """The union of the tree's cells as a shapely MultiPolygon, in the space's coordinates."""
    import shapely

    points, ring, ring_leaf = boundary_rings(tree)
    if not len(points):
        return shapely.MultiPolygon()
    # a face is a set of cells joined through edges (not corners, not across a periodic seam): its
    # exterior ring runs counter-clockwise, its holes clockwise
    flat = Tree(Grid(tree.grid.root, tree.grid.depth, (False,) * tree.grid.dim), tree.level, tree.code, canonical=True)
    face = flat.components()[0][ring_leaf]
    x, y = points[:, 0].astype(float), points[:, 1].astype(float)
    x_next, y_next = _next_in_ring(x, ring), _next_in_ring(y, ring)
    twice_area = np.bincount(ring, x * y_next - x_next * y)
    order = np.lexsort((twice_area < 0, face))  # per face: its exterior, then its holes
    rank = np.empty_like(order)
    rank[order] = np.arange(len(order))
    by_ring = np.argsort(rank[ring], kind="stable")
    rings = shapely.linearrings(points[by_ring].astype(float), indices=rank[ring][by_ring])
    _, polygon = np.unique(face[order], return_inverse=True)
    kept = shapely.normalize(shapely.MultiPolygon(list(shapely.polygons(rings, indices=polygon))))
    kept = shapely.orient_polygons(kept, exterior_cw=False)
    return shapely.transform(kept, lambda xy: lattice_to_space(tree, xy))


def _next_in_ring(v: np.ndarray, ring: np.ndarray) -> np.ndarray:
    """Each ring point's successor's value (rings are contiguous runs, closed)."""
    out = np.roll(v, -1)
    last = np.flatnonzero(np.r_[ring[1:] != ring[:-1], True])
    first = np.r_[0, last[:-1] + 1]
    out[last] = v[first]
    return out


def geometry_json(geometry) -> dict:
    """GeoJSON geometry of a shapely (Multi)Polygon: a Polygon when it has one part."""
    import shapely

    def ring(r) -> list:
        return (shapely.get_coordinates(r) + 0.0).tolist()  # + 0.0: no -0.0

    def polygon(p) -> list:
        return [ring(p.exterior)] + [ring(h) for h in p.interiors]

    parts = list(shapely.get_parts(geometry)) if not geometry.is_empty else []
    if len(parts) == 1:
        return {"type": "Polygon", "coordinates": polygon(parts[0])}
    return {"type": "MultiPolygon", "coordinates": [polygon(p) for p in parts]}


def feature(tree: Tree, properties: dict) -> dict:
    return {"type": "Feature", "properties": dict(properties), "geometry": geometry_json(tree_geometry(tree))}


def geojson_text(features: list[dict]) -> str:
    """A FeatureCollection as deterministic text (sorted keys, one line, final newline)."""
    return json.dumps({"type": "FeatureCollection", "features": features}, sort_keys=True,
                      separators=(",", ":"), allow_nan=False) + "\n"


def write_geojson(path: str | Path, tree: Tree, properties: dict) -> Path:
    """Atomically write one tree as a FeatureCollection of one Feature."""
    return write_text(path, geojson_text([feature(tree, properties)]))
