"""GeoJSON (RFC 7946) of 2-D trees: the union of the black cells as a (Multi)Polygon with holes,
for CAD and GIS tools.

The outline (`paving/outline.py`: boundary segments on the depth-D lattice, exact integers) is
polygonized with shapely, the faces inside the set are kept (faces touching at a corner stay
separate polygons, so the result is valid), normalized, oriented as RFC 7946 asks (exterior
rings counter-clockwise, holes clockwise) and only then mapped to the space's coordinates.
Coordinates are in the space's own units (not longitude and latitude). The text is deterministic:
keys sorted, floats in their shortest exact form, no `-0.0`. shapely is imported only here, inside
the functions that need it.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from fivebar_cli.io.files import write_text
from fivebar_cli.paving.outline import boundary_segments, lattice_to_space
from fivebar_cli.paving.tree import Tree


def tree_geometry(tree: Tree):
    """The union of the tree's cells as a shapely MultiPolygon, in the space's coordinates."""
    import shapely

    segments = boundary_segments(tree)
    if not len(segments):
        return shapely.MultiPolygon()
    lines = shapely.linestrings(segments.reshape(-1, 2, 2).astype(float))
    faces = shapely.get_parts(shapely.polygonize(lines))
    inside = np.zeros(len(faces), bool)
    if len(faces):
        probe = shapely.get_coordinates(shapely.point_on_surface(faces))
        cells = np.floor(probe) + 0.5  # the lattice cell holding the probe: wholly in one face
        inside = tree.locate(lattice_to_space(tree, cells)) >= 0
    kept = shapely.normalize(shapely.MultiPolygon(list(faces[inside])))
    kept = shapely.orient_polygons(kept, exterior_cw=False)
    return shapely.transform(kept, lambda xy: lattice_to_space(tree, xy))


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
