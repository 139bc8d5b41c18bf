"""Obstacles (discs, simple polygons) against segments: pointwise distances, and certified bounds
on the signed distance of a whole family of segments, vectorised over families.

The signed distance sd(x) of a point is its distance to the obstacle outside it and minus its
distance to the boundary inside it; sd of a segment is its minimum over the segment's points, so a
segment keeps a clearance c from the obstacle exactly when sd > c (for c >= 0).

A *family* of segments is given by two boxes (centre, half-widths per axis), one per endpoint: every
segment [b1, b2] with b1 in R1 and b2 in R2. Bounds on sd over the family (`Disc.bounds`,
`Polygon.bounds`):

- lower: every segment lies in the convex hull H of R1 and R2, and for any unit vector n,
  min over H of n.x minus max over the obstacle of n.y is at most the distance between them
  (their separation along n). The minimum of n.x over a box is n.centre - |n_x| h_x - |n_y| h_y,
  so H needs no construction. Directions: from the obstacle's nearest point to the segment of the
  two centres (exact for that segment, so the bound converges as the boxes shrink), and, for a
  polygon edge, its normal. A polygon whose every edge is separated from H holds H entirely or
  misses it; one point decides which.
- upper: the point at parameter t of every segment of the family lies in the box
  (1 - t) R1 + t R2; sd is 1-Lipschitz, so its maximum over that box is at most sd(centre) + |h|
  (for a disc, the exact farthest corner). Witness parameters t: the nearest point of the centres'
  segment to the disc's centre; for a polygon the ends, the feet of its vertices and the middles
  between consecutive crossings of its edges (one lies deepest inside whenever the segment enters).

Callers widen the comparisons by their margins; these are float evaluations of exact bounds.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction

import numpy as np


def _cross(ax, ay, bx, by):
    return ax * by - ay * bx


def point_segment(px, py, ax, ay, bx, by):
    """(distance, parameter t in [0, 1] of the nearest point) from points to segments (broadcast)."""
    dx, dy = bx - ax, by - ay
    length2 = dx * dx + dy * dy
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.where(length2 > 0, ((px - ax) * dx + (py - ay) * dy) / length2, 0.0)
    t = np.clip(np.nan_to_num(t), 0.0, 1.0)
    return np.hypot(ax + t * dx - px, ay + t * dy - py), t


def segments_cross(ax, ay, bx, by, cx, cy, dx, dy):
    """Whether the closed segments [a, b] and [c, d] meet (broadcast; float orientation signs)."""
    o1 = _cross(bx - ax, by - ay, cx - ax, cy - ay)
    o2 = _cross(bx - ax, by - ay, dx - ax, dy - ay)
    o3 = _cross(dx - cx, dy - cy, ax - cx, ay - cy)
    o4 = _cross(dx - cx, dy - cy, bx - cx, by - cy)
    proper = (o1 * o2 <= 0) & (o3 * o4 <= 0)
    collinear = (o1 == 0) & (o2 == 0)
    overlap_x = np.maximum(np.minimum(ax, bx), np.minimum(cx, dx)) <= np.minimum(np.maximum(ax, bx), np.maximum(cx, dx))
    overlap_y = np.maximum(np.minimum(ay, by), np.minimum(cy, dy)) <= np.minimum(np.maximum(ay, by), np.maximum(cy, dy))
    overlap = overlap_x & overlap_y
    return np.where(collinear, overlap, proper)


def _box_min_dot(nx, ny, cx, cy, hx, hy):
    """min over the box (centre c, half-widths h) of n . x."""
    return nx * cx + ny * cy - np.abs(nx) * hx - np.abs(ny) * hy


def _unit(x, y, fx, fy):
    """(x, y) normalised, (fx, fy) where it vanishes."""
    norm = np.hypot(x, y)
    ok = norm > 0
    safe = np.where(ok, norm, 1.0)
    return np.where(ok, x / safe, fx), np.where(ok, y / safe, fy)


def _normal(c1, c2):
    """A unit normal of the segments between the centres (x axis for a point)."""
    nx, ny = _unit(-(c2[..., 1] - c1[..., 1]), c2[..., 0] - c1[..., 0], 1.0, 0.0)
    return nx, ny


@dataclass(frozen=True)
class Disc:
    """The closed disc of centre (x, y) and radius r >= 0."""

    centre: tuple[float, float]
    radius: float

    kind = "disc"

    def extent(self) -> float:
        return max(abs(self.centre[0]), abs(self.centre[1])) + self.radius

    def point_distance(self, x, y):
        """Signed distance of points."""
        return np.hypot(np.asarray(x, float) - self.centre[0], np.asarray(y, float) - self.centre[1]) - self.radius

    def segment_distance(self, a, b):
        """Distance from segments [a, b] ((n, 2) arrays) to the disc (0 where they meet)."""
        d, _ = point_segment(self.centre[0], self.centre[1], a[:, 0], a[:, 1], b[:, 0], b[:, 1])
        return np.maximum(d - self.radius, 0.0)

    def bounds(self, c1, h1, c2, h2, enough: float = np.inf):
        """(lower, upper) bounds on the signed distance of every segment of the families ((m, 2)
        centres and half-widths of the endpoints' boxes), see the module docstring (`enough`: as
        `Polygon.bounds`; the disc's upper bound is cheap and always given)."""
        cx, cy = self.centre
        d, t = point_segment(cx, cy, c1[:, 0], c1[:, 1], c2[:, 0], c2[:, 1])
        qx, qy = c1[:, 0] + t * (c2[:, 0] - c1[:, 0]), c1[:, 1] + t * (c2[:, 1] - c1[:, 1])
        fx, fy = _normal(c1, c2)
        nx, ny = _unit(qx - cx, qy - cy, fx, fy)
        reach = np.minimum(_box_min_dot(nx, ny, c1[:, 0], c1[:, 1], h1[:, 0], h1[:, 1]),
                           _box_min_dot(nx, ny, c2[:, 0], c2[:, 1], h2[:, 0], h2[:, 1]))
        lower = reach - (nx * cx + ny * cy) - self.radius
        wx = (1 - t) * h1[:, 0] + t * h2[:, 0]
        wy = (1 - t) * h1[:, 1] + t * h2[:, 1]
        upper = np.hypot(np.abs(qx - cx) + wx, np.abs(qy - cy) + wy) - self.radius
        return lower, upper


@dataclass(frozen=True)
class Polygon:
    """A simple polygon (either orientation), closed (boundary included)."""

    vertices: tuple[tuple[float, float], ...]

    kind = "polygon"

    @property
    def _edges(self):
        v = np.asarray(self.vertices, float)
        w = np.roll(v, -1, axis=0)
        return v[:, 0], v[:, 1], w[:, 0], w[:, 1]

    def extent(self) -> float:
        return float(np.max(np.abs(np.asarray(self.vertices, float))))

    def contains(self, x, y):
        """Even-odd rule: whether points (broadcast against the edges: pass (..., 1) arrays) lie inside."""
        ax, ay, bx, by = self._edges
        straddle = (ay > y) != (by > y)
        with np.errstate(divide="ignore", invalid="ignore"):
            at = ax + (y - ay) * (bx - ax) / (by - ay)
        return (np.count_nonzero(straddle & (x < at), axis=-1) % 2) == 1

    def boundary_distance(self, x, y):
        """Distance of points ((..., 1) arrays) to the boundary."""
        ax, ay, bx, by = self._edges
        d, _ = point_segment(x, y, ax, ay, bx, by)
        return np.min(d, axis=-1)

    def point_distance(self, x, y):
        """Signed distance of points."""
        x, y = np.asarray(x, float)[..., None], np.asarray(y, float)[..., None]
        d = self.boundary_distance(x, y)
        return np.where(self.contains(x, y), -d, d)

    def segment_distance(self, a, b):
        """Distance from segments [a, b] ((n, 2) arrays) to the polygon (0 where they meet)."""
        ax, ay, bx, by = self._edges
        sx, sy, tx, ty = (a[:, 0:1], a[:, 1:2], b[:, 0:1], b[:, 1:2])
        meets = np.any(segments_cross(sx, sy, tx, ty, ax, ay, bx, by), axis=1) | self.contains(sx, sy)
        d = np.minimum.reduce([point_segment(sx, sy, ax, ay, bx, by)[0], point_segment(tx, ty, ax, ay, bx, by)[0],
                               point_segment(ax, ay, sx, sy, tx, ty)[0], point_segment(bx, by, sx, sy, tx, ty)[0]])
        return np.where(meets, 0.0, np.min(d, axis=1))

    def bounds(self, c1, h1, c2, h2, enough: float = np.inf):
        """(lower, upper) bounds on the signed distance of every segment of the families, see the
        module docstring (lower is -inf where the hull may meet the polygon, or lies inside it).
        Families whose bounding box lies farther than `enough` from the polygon's get that
        distance (a lower bound: they are outside) and no more; the upper bound is only worked out
        where lower <= `enough` (elsewhere +inf)."""
        v = np.asarray(self.vertices, float)
        box_lo, box_hi = np.minimum(c1 - h1, c2 - h2), np.maximum(c1 + h1, c2 + h2)
        gap = np.maximum(np.maximum(v.min(axis=0) - box_hi, box_lo - v.max(axis=0)), 0.0)
        lower, upper = np.hypot(gap[:, 0], gap[:, 1]), np.full(len(c1), np.inf)
        near = lower <= enough
        if near.any():
            lower[near], upper[near] = self._near_bounds(c1[near], h1[near], c2[near], h2[near], enough)
        return lower, upper

    def _near_bounds(self, c1, h1, c2, h2, enough: float):
        """`bounds` for families near the polygon: separation along the best directions, witnesses."""
        ax, ay, bx, by = self._edges  # (n,)
        sx, sy, tx, ty = c1[:, 0:1], c1[:, 1:2], c2[:, 0:1], c2[:, 1:2]  # (m, 1)
        # nearest points between the centres' segment and each edge: the best of four projections,
        # as vectors from the edge to the segment, shape (m, n)
        cands = []
        for px, py in ((sx, sy), (tx, ty)):  # an end of the segment against the edge
            d, t = point_segment(px, py, ax, ay, bx, by)
            cands.append((d, px - (ax + t * (bx - ax)), py - (ay + t * (by - ay))))
        for px, py in ((ax, ay), (bx, by)):  # an end of the edge against the segment
            d, t = point_segment(px, py, sx, sy, tx, ty)
            cands.append((d, sx + t * (tx - sx) - px, sy + t * (ty - sy) - py))
        best = np.argmin(np.stack([c[0] for c in cands]), axis=0)
        dirx = np.choose(best, [c[1] for c in cands])
        diry = np.choose(best, [c[2] for c in cands])
        enx, eny = _unit(-(by - ay), bx - ax, 1.0, 0.0)  # edge normals (n,)
        gap = np.full(dirx.shape, -np.inf)
        for nx, ny in (_unit(dirx, diry, enx + 0 * dirx, eny + 0 * diry), (enx + 0 * dirx, eny + 0 * diry)):
            hull_lo = np.minimum(_box_min_dot(nx, ny, c1[:, 0:1], c1[:, 1:2], h1[:, 0:1], h1[:, 1:2]),
                                 _box_min_dot(nx, ny, c2[:, 0:1], c2[:, 1:2], h2[:, 0:1], h2[:, 1:2]))
            hull_hi = -np.minimum(_box_min_dot(-nx, -ny, c1[:, 0:1], c1[:, 1:2], h1[:, 0:1], h1[:, 1:2]),
                                  _box_min_dot(-nx, -ny, c2[:, 0:1], c2[:, 1:2], h2[:, 0:1], h2[:, 1:2]))
            edge_lo = np.minimum(nx * ax + ny * ay, nx * bx + ny * by)
            edge_hi = np.maximum(nx * ax + ny * ay, nx * bx + ny * by)
            gap = np.maximum(gap, np.maximum(hull_lo - edge_hi, edge_lo - hull_hi))
        separation = np.min(gap, axis=1)
        inside = self.contains(sx, sy)
        lower = np.where(separation > 0, np.where(inside, -np.inf, separation), -np.inf)
        upper = np.where((separation > 0) & inside, -separation, np.inf)
        todo = (lower <= enough) & ~((separation > 0) & inside)
        if todo.any():
            upper[todo] = self._witness_upper(c1[todo], h1[todo], c2[todo], h2[todo])
        return lower, upper

    def _witness_upper(self, c1, h1, c2, h2):
        """min over witness parameters t of sd(centre of (1-t) R1 + t R2) + |its half-widths|."""
        ax, ay, bx, by = self._edges
        sx, sy, tx, ty = c1[:, 0:1], c1[:, 1:2], c2[:, 0:1], c2[:, 1:2]
        _, feet = point_segment(ax, ay, sx, sy, tx, ty)  # (m, n)
        ux, uy = tx - sx, ty - sy
        ex, ey = bx - ax, by - ay
        den = _cross(ux, uy, ex, ey)
        with np.errstate(divide="ignore", invalid="ignore"):
            s = _cross(ax - sx, ay - sy, ex, ey) / den  # along the centres' segment
            r = _cross(ax - sx, ay - sy, ux, uy) / den  # along the edge
        crossing = np.where((den != 0) & (s >= 0) & (s <= 1) & (r >= 0) & (r <= 1), s, np.nan)
        ends = np.column_stack([np.zeros(len(c1)), np.ones(len(c1))])
        stops = np.sort(np.concatenate([ends, crossing], axis=1), axis=1)  # NaN last
        middles = 0.5 * (stops[:, :-1] + stops[:, 1:])
        t = np.concatenate([ends, feet, middles], axis=1)  # (m, k)
        valid = ~np.isnan(t)
        t = np.where(valid, t, 0.0)
        px, py = sx + t * ux, sy + t * uy
        wx = (1 - t) * h1[:, 0:1] + t * h2[:, 0:1]
        wy = (1 - t) * h1[:, 1:2] + t * h2[:, 1:2]
        bound = self.point_distance(px, py) + np.hypot(wx, wy)
        return np.min(np.where(valid, bound, np.inf), axis=1)


# ---------------------------------------------------------------- exact checks of a polygon


def polygon_problem(vertices) -> str | None:
    """Why the vertices do not make a simple polygon of positive area (exact rational arithmetic),
    or None."""
    v = [(Fraction(x), Fraction(y)) for x, y in vertices]
    n = len(v)
    if n < 3:
        return f"a polygon needs at least 3 vertices, got {n}"
    for i in range(n):
        if v[i] == v[(i + 1) % n]:
            return f"vertices {i} and {(i + 1) % n} coincide (a degenerate edge)"
    area2 = sum(v[i][0] * v[(i + 1) % n][1] - v[(i + 1) % n][0] * v[i][1] for i in range(n))
    if area2 == 0:
        return "the polygon has zero area (degenerate)"

    def orient(a, b, c):
        s = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
        return (s > 0) - (s < 0)

    def on(a, b, c):  # c on segment [a, b], given collinear
        return min(a[0], b[0]) <= c[0] <= max(a[0], b[0]) and min(a[1], b[1]) <= c[1] <= max(a[1], b[1])

    def meet(a, b, c, d):
        o1, o2, o3, o4 = orient(a, b, c), orient(a, b, d), orient(c, d, a), orient(c, d, b)
        if o1 != o2 and o3 != o4:
            return True
        return ((o1 == 0 and on(a, b, c)) or (o2 == 0 and on(a, b, d)) or (o3 == 0 and on(c, d, a))
                or (o4 == 0 and on(c, d, b)))

    for i in range(n):
        a, b = v[i], v[(i + 1) % n]
        for j in range(i + 1, n):
            c, d = v[j], v[(j + 1) % n]
            if j == i + 1 or (i == 0 and j == n - 1):  # neighbours share a vertex: they must not fold back
                shared, p, q = (b, a, d) if j == i + 1 else (a, b, c)
                if orient(p, shared, q) == 0 and (q[0] - shared[0]) * (p[0] - shared[0]) + \
                        (q[1] - shared[1]) * (p[1] - shared[1]) > 0:
                    return f"edges {i} and {j} overlap (the polygon folds back on itself)"
                continue
            if meet(a, b, c, d):
                return f"edges {i} and {j} intersect (the polygon is not simple)"
    return None
