"""GeoJSON (RFC 7946) of 2-D trees: the union of the black cells as a (Multi)Polygon with holes,
for CAD and GIS tools.

The outline (`paving/outline.py`: minimal boundary rings on the depth-D lattice, exact integers,
traced from the cells with the set on their left) gives one polygon per face of the set (cells
joined through edges; faces touching at a corner stay separate polygons, so the result is valid):
its counter-clockwise ring and its clockwise holes. A hole belongs to the smallest exterior ring
around the cell on its left. They are normalized, oriented as RFC 7946 asks (exterior rings
counter-clockwise, holes clockwise) and only then mapped to the space's coordinates. These are the
polygons shapely's polygonizer finds from the boundary segments (the tests compare the bytes),
without its cost, which grew faster than the boundary. Coordinates are in the space's own units
(not longitude and latitude). The text is deterministic: keys sorted, floats in their shortest
exact form, no `-0.0`: the bytes `json.dumps(..., sort_keys=True, separators=(",", ":"))` gives,
written without building the nested lists (a ring's vertices lie on a few thousand lattice lines:
each coordinate's text is formatted once, the points assembled from them). shapely is imported
only here, inside the functions that need it.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from fivebar_cli.io.files import write_text
from fivebar_cli.paving.arrays import unique
from fivebar_cli.paving.morton import deinterleave
from fivebar_cli.paving.outline import boundary_rings, lattice_to_space
from fivebar_cli.paving.tree import Tree


def tree_geometry(tree: Tree):
    """The union of the tree's cells as a shapely MultiPolygon, in the space's coordinates."""
    import shapely

    return shapely.transform(_lattice_geometry(tree), lambda xy: lattice_to_space(tree, xy))


def _lattice_geometry(tree: Tree):
    """The union of the tree's cells as a normalized shapely MultiPolygon (exteriors
    counter-clockwise, holes clockwise), in depth-D lattice units."""
    import shapely

    points, ring, ring_leaf = boundary_rings(tree)
    if not len(points):
        return shapely.MultiPolygon()
    x, y = points[:, 0].astype(float), points[:, 1].astype(float)
    x_next, y_next = _next_in_ring(x, ring), _next_in_ring(y, ring)
    twice_area = np.bincount(ring, x * y_next - x_next * y)
    face = _faces(tree, points.astype(float), ring, ring_leaf, twice_area)
    order = np.lexsort((twice_area < 0, face))  # per face: its exterior, then its holes
    rank = np.empty_like(order)
    rank[order] = np.arange(len(order))
    by_ring = np.argsort(rank[ring], kind="stable")
    rings = shapely.linearrings(points[by_ring].astype(float), indices=rank[ring][by_ring])
    _, polygon = np.unique(face[order], return_inverse=True)
    kept = shapely.normalize(shapely.MultiPolygon(list(shapely.polygons(rings, indices=polygon))))
    return shapely.orient_polygons(kept, exterior_cw=False)


def _faces(tree: Tree, points: np.ndarray, ring: np.ndarray, ring_leaf: np.ndarray,
           twice_area: np.ndarray) -> np.ndarray:
    """The face of each ring (a face: cells joined through edges, not corners, not across a
    periodic seam), numbered by its exterior ring: a face has one counter-clockwise ring; a
    clockwise ring (a hole) belongs to the smallest of them around the cell on its left (a cell of
    the face; a larger exterior around it holds the whole face in one of its holes)."""
    import shapely

    exterior = np.flatnonzero(twice_area > 0)
    face = np.full(len(twice_area), -1, np.int64)
    face[exterior] = np.arange(len(exterior))
    holes = np.flatnonzero(twice_area < 0)
    if not len(holes) or len(exterior) == 1:
        face[holes] = 0
        return face
    starts = np.searchsorted(ring, np.arange(len(twice_area) + 1))
    is_exterior = np.repeat(twice_area > 0, np.diff(starts))
    shell_of_ring = np.cumsum(twice_area > 0) - 1
    shells = shapely.polygons(shapely.linearrings(points[is_exterior], indices=shell_of_ring[ring[is_exterior]]))
    leaf = ring_leaf[holes]  # (the coordinates of these leaves only, not of the whole tree)
    span = np.int64(1) << (tree.grid.depth - tree.level[leaf])
    coords = deinterleave(tree.code[leaf], tree.level[leaf], tree.grid.dim)
    centre = (coords * span[:, None]).astype(float) + 0.5 * span[:, None]
    hole, shell = shapely.STRtree(shells).query(shapely.points(centre), predicate="within")
    smallest = np.lexsort((twice_area[exterior][shell], hole))
    first = np.r_[True, hole[smallest][1:] != hole[smallest][:-1]]
    face[holes[hole[smallest][first]]] = shell[smallest][first]
    return face


def _next_in_ring(v: np.ndarray, ring: np.ndarray) -> np.ndarray:
    """Each ring point's successor's value (rings are contiguous runs, closed)."""
    out = np.roll(v, -1)
    last = np.flatnonzero(np.r_[ring[1:] != ring[:-1], True])
    first = np.r_[0, last[:-1] + 1]
    out[last] = v[first]
    return out


def _coordinates_text(tree: Tree, geometry) -> tuple[str, str]:
    """(GeoJSON geometry type, the text of its coordinates) of a lattice MultiPolygon: a Polygon
    when it has one part. Each lattice value's float text is made once (repr, as json writes it)."""
    coords, ring_offsets, polygon_offsets = _ragged(geometry)
    if not len(polygon_offsets) > 1:
        return "MultiPolygon", "[]"
    lattice = coords.astype(np.int64)
    # the points' texts, "[x," then "y],", joined as they are, but for the brackets opening each
    # ring (and polygon) before its first point and closing it after its last
    pieces = np.empty(2 * len(lattice), dtype=object)
    pieces[0::2] = _value_texts(tree, lattice[:, 0], 0)
    pieces[1::2] = _value_texts(tree, lattice[:, 1], 1)
    rings = len(ring_offsets) - 1
    first_of_polygon = np.zeros(rings, bool)
    first_of_polygon[polygon_offsets[:-1]] = True
    last_of_polygon = np.zeros(rings, bool)
    last_of_polygon[polygon_offsets[1:] - 1] = True
    first, last = 2 * ring_offsets[:-1], 2 * ring_offsets[1:] - 1
    pieces[first] = np.where(first_of_polygon, "[[", "[").astype(object) + pieces[first]
    pieces[last] = (np.array([text[:-1] for text in pieces[last]], dtype=object)  # "y]" then "]," or "]],"
                    + np.where(last_of_polygon, "]],", "],").astype(object))
    body = "".join(pieces.tolist())[:-1]  # (no comma after the last point)
    if len(polygon_offsets) == 2:
        return "Polygon", body
    return "MultiPolygon", "[" + body + "]"


def _ragged(geometry) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A MultiPolygon's coordinates, ring offsets (into them) and polygon offsets (into the rings):
    those of `shapely.to_ragged_array([geometry])`, from its parts (to_ragged_array takes
    np.unique of the geometry types, which imports numpy.ma: 7-10 ms of an aspects run)."""
    import shapely

    polygons = shapely.get_parts(geometry)
    rings, polygon_of_ring = shapely.get_rings(polygons, return_index=True)
    coords, ring_of_point = shapely.get_coordinates(rings, return_index=True)
    ring_offsets = np.r_[0, np.cumsum(np.bincount(ring_of_point, minlength=len(rings)))]
    polygon_offsets = np.r_[0, np.cumsum(np.bincount(polygon_of_ring, minlength=len(polygons)))]
    return coords, ring_offsets, polygon_offsets


_TEXTS: dict = {}  # per axis of the last grid written: (which lattice values are made, their point texts)
TABLE_DEPTH = 20  # grids up to this depth (every analysis's) keep a table of 2^depth + 1 texts an axis


def _value_texts(tree: Tree, values: np.ndarray, axis: int) -> np.ndarray:
    """The text of each lattice value along `axis` as a point writes it, "[x," or "y],": the space
    coordinate (`lattice_to_space`, `+ 0.0`: no -0.0) as json writes it (repr), each made once for
    the trees of one grid (the aspects of an analysis share most of their lattice lines), kept in
    a table by lattice value (0..2^depth: looked up, not searched); an object array. A deeper
    grid's are made for each tree."""
    if tree.grid.depth > TABLE_DEPTH:
        wanted, inverse = np.unique(values, return_inverse=True)
        return _made_texts(tree, wanted, axis)[inverse]
    key = (tree.grid, axis)
    if key not in _TEXTS:
        if len(_TEXTS) >= 2:  # another grid's
            _TEXTS.clear()
        size = (1 << tree.grid.depth) + 1
        _TEXTS[key] = (np.zeros(size, bool), np.empty(size, dtype=object))
    made, texts = _TEXTS[key]
    new = unique(values[~made[values]])
    if len(new):
        texts[new] = _made_texts(tree, new, axis)
        made[new] = True
    return texts[values]


def _made_texts(tree: Tree, values: np.ndarray, axis: int) -> np.ndarray:
    """The texts of some lattice values along `axis` (`_value_texts`), made."""
    points = np.zeros((len(values), 2), np.int64)
    points[:, axis] = values
    before, after = ("[", ",") if axis == 0 else ("", "],")
    return np.array([before + repr(v) + after for v in (lattice_to_space(tree, points)[:, axis] + 0.0).tolist()],
                    dtype=object)


def _json(value) -> str:
    return json.dumps(value, sort_keys=True, separators=(",", ":"), allow_nan=False)


def feature_text(tree: Tree, properties: dict) -> str:
    """One Feature as text: the tree's cells as its geometry, with these properties."""
    kind, coordinates = _coordinates_text(tree, _lattice_geometry(tree))
    return "".join(['{"geometry":{"coordinates":', coordinates, ',"type":', _json(kind), '},"properties":',
                    _json(dict(properties)), ',"type":"Feature"}'])  # one copy of the coordinates


def geojson_text(features: list[str]) -> str:
    """A FeatureCollection of `feature_text`s as deterministic text (sorted keys, one line, final
    newline)."""
    return "".join(['{"features":[', ",".join(features), '],"type":"FeatureCollection"}\n'])


def write_geojson(path: str | Path, tree: Tree, properties: dict) -> Path:
    """Atomically write one tree as a FeatureCollection of one Feature."""
    return write_text(path, geojson_text([feature_text(tree, properties)]))
