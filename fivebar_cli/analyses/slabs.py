"""The union of integer boxes as rectangles of vertical slabs, and the rectangles the shortest
polyline between two points crosses (the corridor step of `channel.py`).

Cut at every box edge, the union is, in each slab, a set of disjoint closed intervals: rectangles.
Rectangles of consecutive slabs whose intervals overlap with positive length are neighbours (boxes
touching at a corner only are not joined: no float path passes through one exact point). Without
holes this graph is a tree: the rectangles from one point to another are unique, and string
pulling through the edges they share gives the shortest polyline. With holes the sequence is the
one of the shortest polyline in the visibility graph of the two points and the reflex corners
(Dijkstra; visibility tested slab by slab in floating point, which only steers the search: the
motion is proven afterwards, exactly). Also the graph searches `channel.py` uses (CSR, A*).
"""

from __future__ import annotations

import heapq

import numpy as np


def csr(count: int, i: np.ndarray, j: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Directed pairs (i, j) as CSR over `count` nodes: node k's are targets[first[k]:first[k + 1]],
    sorted."""
    pairs = np.unique(np.column_stack([i, j]).astype(np.int64), axis=0).reshape(-1, 2)
    return np.searchsorted(pairs[:, 0], np.arange(count + 1)), pairs[:, 1]


def astar(first: np.ndarray, targets: np.ndarray, centre: np.ndarray, start: int, end: int, delta) -> list[int] | None:
    """A* from node `start` to node `end` of a graph in CSR form, by the distances between node
    centres (`delta` maps centre differences, e.g. to the torus's short way); ties break by node
    order, so the result depends on the start's component alone. None when no path joins them."""
    guess = _lengths(delta(centre - centre[end])).tolist()
    best = {start: 0.0}
    parent = {start: -1}
    heap = [(guess[start], 0.0, start)]
    done = set()
    while heap:
        _, g, node = heapq.heappop(heap)
        if node in done:
            continue
        done.add(node)
        if node == end:
            break
        near = targets[first[node]:first[node + 1]]
        steps = _lengths(delta(centre[near] - centre[node]))
        for other, step in zip(near.tolist(), steps.tolist()):
            cost = g + step
            if other not in done and cost < best.get(other, np.inf):
                best[other] = cost
                parent[other] = node
                heapq.heappush(heap, (cost + guess[other], cost, other))
    if end not in done:
        return None
    path = [end]
    while parent[path[-1]] >= 0:
        path.append(parent[path[-1]])
    return path[::-1]


def _lengths(d: np.ndarray) -> np.ndarray:
    """Euclidean lengths of the rows of `d` (hypot in the plane, as the 2-D paths always measured)."""
    return np.hypot(*d.T) if d.shape[1] == 2 else np.linalg.norm(d, axis=1)


class Slabs:
    """The union of integer boxes (a corridor, in lattice units) cut into vertical slabs at every
    box edge: in each slab it is a set of disjoint closed intervals (touching ones merged), i.e.
    rectangles, ordered by slab then y. Rectangles of consecutive slabs whose intervals overlap
    with positive length are neighbours (cells touching at a corner only are not joined)."""

    EPS = 1e-9  # lattice units: slack of the float visibility test (only steers the search)

    def __init__(self, lo: np.ndarray, hi: np.ndarray):
        xs = np.unique(np.concatenate([lo[:, 0], hi[:, 0]]))
        first = np.searchsorted(xs, lo[:, 0])
        span = np.searchsorted(xs, hi[:, 0]) - first
        box = np.repeat(np.arange(len(lo)), span)
        slab = first[box] + np.arange(int(span.sum())) - np.repeat(np.cumsum(span) - span, span)
        y0, y1 = lo[box, 1], hi[box, 1]
        self.base, self.width = int(y0.min()), int(y1.max() - y0.min()) + 1
        order = np.lexsort((y0, slab))
        slab, y0, y1 = slab[order], y0[order], y1[order]
        top = np.maximum.accumulate(slab * self.width + (y1 - self.base)) - slab * self.width + self.base
        new = np.ones(len(slab), bool)
        new[1:] = (slab[1:] != slab[:-1]) | (y0[1:] > top[:-1])  # a gap: a new rectangle
        starts = np.flatnonzero(new)
        self.xs, self.slab = xs, slab[starts]
        self.lo = np.column_stack([xs[self.slab], y0[starts]])
        self.hi = np.column_stack([xs[self.slab + 1], np.maximum.reduceat(y1, starts)])
        self.key_lo = self.slab * self.width + (self.lo[:, 1] - self.base)
        self.first, self.targets = self._graph()

    def _graph(self) -> tuple[np.ndarray, np.ndarray]:
        """Neighbours in CSR form. Keys slab * width + y increase with both ends of the intervals,
        so the rectangles of the previous slab overlapping [a, b] are one range of indices."""
        key_hi = self.slab * self.width + (self.hi[:, 1] - self.base)
        left = (self.slab - 1) * self.width - self.base
        lo_index = np.searchsorted(key_hi, left + self.lo[:, 1], side="right")  # first with top > a
        hi_index = np.searchsorted(self.key_lo, left + self.hi[:, 1], side="left")  # first with bottom >= b
        count = np.maximum(hi_index - lo_index, 0)
        i = np.repeat(np.arange(len(self.slab)), count)
        j = np.repeat(lo_index, count) + np.arange(int(count.sum())) - np.repeat(np.cumsum(count) - count, count)
        return csr(len(self.slab), np.concatenate([i, j]), np.concatenate([j, i]))

    def rect_at(self, slab: np.ndarray, y0: np.ndarray, y1: np.ndarray) -> np.ndarray:
        """Per query, the rectangle of that slab holding [y0, y1] (within EPS), or -1."""
        slab = np.asarray(slab, np.int64)
        key = slab * self.width + (np.asarray(y0, float) + self.EPS - self.base)
        k = np.searchsorted(self.key_lo, key, side="right") - 1
        safe = np.clip(k, 0, len(self.slab) - 1)
        ok = (k >= 0) & (self.slab[safe] == slab) & (self.hi[safe, 1] >= np.asarray(y1, float) - self.EPS)
        return np.where(ok, safe, -1)

    def holder(self, p: np.ndarray) -> int | None:
        """A rectangle holding the point (lattice units)."""
        for i in {int(np.searchsorted(self.xs, p[0], side="right")) - 1, int(np.searchsorted(self.xs, p[0])) - 1}:
            if 0 <= i < len(self.xs) - 1:
                k = int(self.rect_at(np.array([i]), np.array([p[1]]), np.array([p[1]]))[0])
                if k >= 0:
                    return k
        return None

    def holes(self, rect: int) -> int:
        """Holes of the connected set of rectangles holding `rect` (independent cycles of the
        graph: two rectangles of one slab both joined to the next slab enclose a gap)."""
        reached = np.zeros(len(self.slab), bool)
        reached[rect] = True
        frontier = np.array([rect])
        while len(frontier):
            count = self.first[frontier + 1] - self.first[frontier]
            at = np.repeat(self.first[frontier] - np.cumsum(count) + count, count) + np.arange(int(count.sum()))
            nxt = np.unique(self.targets[at])
            frontier = nxt[~reached[nxt]]
            reached[frontier] = True
        edges = int(np.diff(self.first)[reached].sum()) // 2
        return edges - int(reached.sum()) + 1

    def sight(self, p: np.ndarray, q: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Whether each segment p[k] -> q[k] (lattice units) lies in the rectangles, crossing slab
        edges only where neighbours overlap with positive length; also, per (segment, slab) row,
        the segment and the rectangle (in order of x; a vertical segment has one row)."""
        x0, x1 = np.minimum(p[:, 0], q[:, 0]), np.maximum(p[:, 0], q[:, 0])
        i0 = np.searchsorted(self.xs, x0, side="right") - 1
        i1 = np.searchsorted(self.xs, x1, side="left") - 1
        vertical = x0 == x1
        i1 = np.where(vertical, i0, i1)
        count = np.maximum(i1 - i0 + 1, 0)
        inside = (x0 >= self.xs[0]) & (x1 <= self.xs[-1])
        count[~inside] = 0
        seg = np.repeat(np.arange(len(p)), count)
        slab = i0[seg] + np.arange(int(count.sum())) - np.repeat(np.cumsum(count) - count, count)
        dx = (q - p)[seg]
        safe_dx = np.where(dx[:, 0] == 0, 1.0, dx[:, 0])
        slope = dx[:, 1] / safe_dx
        right = self.xs[np.minimum(slab + 1, len(self.xs) - 1)]
        xa, xb = np.maximum(self.xs[slab], x0[seg]), np.minimum(right, x1[seg])
        ya, yb = p[seg, 1] + (xa - p[seg, 0]) * slope, p[seg, 1] + (xb - p[seg, 0]) * slope
        flat = vertical[seg]
        ya, yb = np.where(flat, p[seg, 1], ya), np.where(flat, q[seg, 1], yb)
        rect = self.rect_at(slab, np.minimum(ya, yb), np.maximum(ya, yb))
        if flat.any():  # a vertical segment on a slab edge may lie in the slab on its left
            left = flat & (rect < 0) & (slab > 0) & (self.xs[np.maximum(slab, 0)] == x0[seg])
            rect[left] = self.rect_at(slab[left] - 1, np.minimum(ya, yb)[left], np.maximum(ya, yb)[left])
        good = np.ones(len(p), bool) & (count > 0)
        np.logical_and.at(good, seg, rect >= 0)
        nxt = np.flatnonzero((seg[1:] == seg[:-1]) & (rect[1:] >= 0) & (rect[:-1] >= 0))
        a, b = rect[nxt], rect[nxt + 1]
        overlap = np.minimum(self.hi[a, 1], self.hi[b, 1]) - np.maximum(self.lo[a, 1], self.lo[b, 1])
        np.logical_and.at(good, seg[nxt], overlap > 0)
        return good, seg, rect

    def route(self, start: np.ndarray, end: np.ndarray, scale: np.ndarray, bound: float,
              corners_limit: int = 400) -> list[int] | None:
        """The rectangles from the start's to the end's (lattice units) that the shortest polyline
        crosses: the unique sequence when the connected set has no hole; with holes, the one of the
        shortest polyline in the visibility graph of the start, the end and the reflex corners a
        polyline no longer than `bound` (space units, `scale` per lattice step) can reach, when
        there are at most `corners_limit` of them, else A* on the rectangles' centres."""
        a, b = self.holder(start), self.holder(end)
        if a is None or b is None:
            return None
        centre = 0.5 * (self.lo + self.hi) * scale
        if self.holes(a):
            corners = self._reflex_corners()
            reach = (np.hypot(*((corners - start) * scale).T) + np.hypot(*((corners - end) * scale).T))
            corners = corners[reach <= bound * (1 + 1e-9)]
            if len(corners) <= corners_limit:
                polyline = self._visible_path(np.vstack([start, end, corners]), scale)
                if polyline is not None:
                    rects = self._rects_along(polyline)
                    if rects and self._is_chain(rects):
                        return rects
        return astar(self.first, self.targets, centre, a, b, lambda d: d)

    def _reflex_corners(self) -> np.ndarray:
        """Rectangle corners with exactly three of their four quadrants in the union."""
        corners = np.unique(np.vstack([self.lo, self.hi, np.column_stack([self.lo[:, 0], self.hi[:, 1]]),
                                       np.column_stack([self.hi[:, 0], self.lo[:, 1]])]), axis=0).astype(float)
        free = np.zeros(len(corners), np.int64)
        for dx in (-0.5, 0.5):
            for dy in (-0.5, 0.5):
                x, y = corners[:, 0] + dx, corners[:, 1] + dy
                slab = np.searchsorted(self.xs, x, side="right") - 1
                ok = (slab >= 0) & (slab < len(self.xs) - 1)
                hit = np.full(len(x), -1)
                hit[ok] = self.rect_at(slab[ok], y[ok], y[ok])
                free += hit >= 0
        return corners[free == 3]

    def _visible_path(self, nodes: np.ndarray, scale: np.ndarray) -> np.ndarray | None:
        """Dijkstra from node 0 to node 1 on the visibility graph of the nodes (lattice units)."""
        n = len(nodes)
        i, j = np.triu_indices(n, 1)
        weight = np.full((n, n), np.inf)
        for chunk in range(0, len(i), 20000):
            ii, jj = i[chunk:chunk + 20000], j[chunk:chunk + 20000]
            good, _, _ = self.sight(nodes[ii], nodes[jj])
            w = np.hypot(*((nodes[jj] - nodes[ii]) * scale).T)
            weight[ii[good], jj[good]] = w[good]
            weight[jj[good], ii[good]] = w[good]
        dist, parent, done = np.full(n, np.inf), np.full(n, -1), np.zeros(n, bool)
        dist[0] = 0.0
        while True:
            k = int(np.argmin(np.where(done, np.inf, dist)))
            if done[k] or not np.isfinite(dist[k]):
                return None
            if k == 1:
                break
            done[k] = True
            better = dist[k] + weight[k] < dist
            dist[better], parent[better] = dist[k] + weight[k][better], k
        path = [1]
        while path[-1] != 0:
            path.append(int(parent[path[-1]]))
        return nodes[path[::-1]]

    def _rects_along(self, polyline: np.ndarray) -> list[int] | None:
        """The rectangles a polyline crosses, in order (None when a segment leaves them)."""
        out: list[int] = []
        for p, q in zip(polyline, polyline[1:]):
            good, seg, rect = self.sight(p[None, :], q[None, :])
            if not good[0]:
                return None
            rect = rect.tolist() if p[0] <= q[0] else rect[::-1].tolist()
            out += [r for r in rect if not out or r != out[-1]]
        return out

    def _is_chain(self, rects: list[int]) -> bool:
        for a, b in zip(rects, rects[1:]):
            if b not in self.targets[self.first[a]:self.first[a + 1]]:
                return False
        return True
