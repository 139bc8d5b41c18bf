"""An independent reference for the shortest polyline inside a union of closed boxes.

shapely builds the union of the boxes (a polygon, maybe with holes) and tells which straight
segments it covers; the shortest polyline from one point to another in a polygon bends only at
its reflex vertices, so Dijkstra (scipy) on the visibility graph of the two points and those
vertices gives its length. Cells that touch only at a corner are not joined there (the union is
shrunk by a hair), as in fivebar's chains of cells sharing edges. Quadratic in the vertices: for
tests and benchmarks. Nothing here is shared with `fivebar_cli/analyses/channel.py`.
"""

from __future__ import annotations

from itertools import product

import numpy as np

PINCH = 1e-7  # the union is shrunk by this many lattice steps, which parts cells touching at a corner
HAIR = 1e-4  # lattice steps: a point this far from the union is outside it whatever the rounding


def _reflex_vertices(union) -> np.ndarray:
    """Vertices where the polygon's interior angle exceeds 180 degrees (rings oriented so that the
    interior is on the left: a right turn is reflex)."""
    import shapely
    from shapely.geometry.polygon import orient

    out = []
    for part in shapely.get_parts(union):
        part = orient(part, sign=1.0)
        for ring in [part.exterior, *part.interiors]:
            v = np.asarray(ring.coords)[:-1]
            prev, nxt = np.roll(v, 1, axis=0), np.roll(v, -1, axis=0)
            turn = (v - prev)[:, 0] * (nxt - v)[:, 1] - (v - prev)[:, 1] * (nxt - v)[:, 0]
            out.append(v[turn < 0])
    return np.concatenate(out) if out else np.zeros((0, 2))


def _maybe_covered(union, a: np.ndarray, b: np.ndarray, hair: float) -> np.ndarray:
    """False for segments a-b that the union certainly does not cover: a point sampled on them lies
    outside the union grown by `hair` (far more than the rounding of the sample), so a point of the
    segment lies outside the union. Only a cheap first pass: shapely.covers decides the rest."""
    import shapely

    grown = union.buffer(hair)
    shapely.prepare(grown)
    keep = np.ones(len(a), bool)
    for t in (0.5, 0.25, 0.75, 0.125, 0.375, 0.625, 0.875):
        idx = np.flatnonzero(keep)
        p = a[idx] + t * (b[idx] - a[idx])
        keep[idx] = shapely.intersects_xy(grown, p[:, 0], p[:, 1])
    return keep


def shortest_through_boxes(lo: np.ndarray, hi: np.ndarray, start, ends, bound: float | None = None,
                           scale=(1.0, 1.0)) -> float:
    """The length of the shortest polyline from `start` to the nearest of `ends` (several copies of
    one point on a torus) that stays in the union of the closed boxes (lo, hi); inf when none.
    The boxes are integer (lattice) boxes, so that shapely's union is exact; `scale` maps lattice
    units to the space's (per axis), applied to the union and the points before measuring. With
    `bound` (an upper bound on the answer), only boxes and vertices that a polyline that short
    could reach are kept (|p - start| + |p - end| <= bound), which changes nothing."""
    import shapely
    import shapely.affinity
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import dijkstra

    scale = np.asarray(scale, float)
    start = np.asarray(start, float) * scale
    ends = np.atleast_2d(np.asarray(ends, float)) * scale
    union_lo, union_hi = np.asarray(lo, np.int64), np.asarray(hi, np.int64)
    lo, hi = union_lo * scale, union_hi * scale
    if bound is not None:
        def dist(p):
            return np.hypot(*np.maximum(np.maximum(lo - p, p - hi), 0).T)

        keep = np.min([dist(start) + dist(e) for e in ends], axis=0) <= bound * (1 + 1e-9) + 1e-12
        union_lo, union_hi = union_lo[keep], union_hi[keep]
    if not len(union_lo):
        return float("inf")
    union = shapely.union_all(shapely.box(union_lo[:, 0], union_lo[:, 1], union_hi[:, 0], union_hi[:, 1]))
    union = shapely.affinity.scale(union, scale[0], scale[1], origin=(0, 0))
    # cells touching only at a corner do not join: no float path passes through one exact point
    union = union.buffer(-PINCH * float(scale.min()), join_style="mitre")
    shapely.prepare(union)
    corners = _reflex_vertices(union)
    if bound is not None and len(corners):
        reach = np.hypot(*(corners - start).T) + np.min([np.hypot(*(corners - e).T) for e in ends], axis=0)
        corners = corners[reach <= bound * (1 + 1e-9) + 1e-12]
    nodes = np.concatenate([start[None], ends, corners])
    i, j = np.triu_indices(len(nodes), 1)
    ok = _maybe_covered(union, nodes[i], nodes[j], HAIR * float(scale.min()))
    ok[ok] = shapely.covers(union, shapely.linestrings(np.stack([nodes[i[ok]], nodes[j[ok]]], axis=1)))
    i, j = i[ok], j[ok]
    w = np.hypot(*(nodes[i] - nodes[j]).T)
    graph = coo_matrix((np.concatenate([w, w]) + 0.0, (np.concatenate([i, j]), np.concatenate([j, i]))),
                       shape=(len(nodes), len(nodes))).tocsr()
    dist = dijkstra(graph, indices=0)
    return float(np.min(dist[1:1 + len(ends)]))


def shortest_through_tree(tree, start, end, bound: float | None = None) -> float:
    """`shortest_through_boxes` on the leaves of a 2-D tree (lattice boxes computed here from the
    leaves' levels and coordinates), points in the space's units; on a periodic axis over the
    copies of the cells and of the end that a polyline of length `bound` can reach (the points
    wrapped into the root first): 3 x 3 without a bound, more for a motion that winds round the
    torus more than once (found by hypothesis: a motion going two periods the other way round)."""
    grid = tree.grid
    n = 1 << grid.depth
    span = (1 << (grid.depth - tree.level))[:, None]
    lo, hi = tree.coords * span, tree.coords * span + span
    turns = [1 if bound is None else int(bound // size) + 1 for size in grid.size]
    copies = [np.array(c) for c in product(*[range(-k, k + 1) if p else (0,) for p, k in zip(grid.periodic, turns)])]
    scale = grid.size / n

    def to(p):
        p = np.asarray(p, float) - grid.lo
        return np.where(grid.periodic, p % grid.size, p) / scale

    return shortest_through_boxes(np.concatenate([lo + c * n for c in copies]),
                                  np.concatenate([hi + c * n for c in copies]),
                                  to(start), [to(end) + c * n for c in copies], bound, scale)
