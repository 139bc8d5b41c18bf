"""Regions bounded by circular arcs: intersections of closed discs and closed disc complements.

A region is a list of circles (centre, radius) and one side per circle: +1 keeps the closed disc,
-1 keeps the closed outside. Its boundary is found as in Gosselin & Guillot (1991): cut every
circle at its intersections with the others, order the cut points along the circle, and keep an
elementary arc when its midpoint satisfies every other constraint. The exact area then follows
from Green's theorem, A = 1/2 sum over boundary arcs of the integral of (x dy - y dx), disc arcs
run counter-clockwise and complement arcs clockwise (region on the left); no ordering of the arcs
into loops is needed for the area.

Everything is vectorised over leading batch axes: thousands of regions cost one numpy pass.
A circle of radius 0 with side -1 or of radius inf with side +1 constrains nothing and is ignored.
Identical circles are handled: with the same side only the first is used, with opposite sides the
region is a circle (area 0). Near-tangent circles get a (double) cut point, so no arc midpoint can
land on a tangency.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

TWO_PI = 2.0 * math.pi
_CUT_TOL = 1e-9  # relative: circles this close to tangency still get a cut point (harmless extra cut)
_SNAP = 1e-7  # relative half-chord below which a cut is a tangency (lens area < 1e-20 r^2 ignored)
_SAME_TOL = 1e-14  # relative: circles this close are the same circle
_CHUNK = 512  # regions per numpy pass (keeps the working arrays in cache)


# ---------------------------------------------------------------- intersections


def circle_intersections(c1, r1, c2, r2):
    """Intersection points of circles (c1, r1) and (c2, r2), broadcast over leading axes.

    Returns (points, ok): points (..., 2, 2) (a tangency gives the same point twice), ok (...) bool.
    """
    c1, c2 = np.asarray(c1, float), np.asarray(c2, float)
    r1, r2 = np.asarray(r1, float), np.asarray(r2, float)
    ang, ok = _cut_angles_pair(c1[..., 0], c1[..., 1], r1, c2[..., 0], c2[..., 1], r2)
    pts = np.stack([c1[..., None, 0] + r1[..., None] * np.cos(ang), c1[..., None, 1] + r1[..., None] * np.sin(ang)], -1)
    return pts, ok


def _cut_angles_pair(x1, y1, r1, x2, y2, r2):
    """Angles on circle 1 of its intersections with circle 2: (..., 2) and a validity mask (...)."""
    dx, dy = x2 - x1, y2 - y1
    d = np.hypot(dx, dy)
    scale = np.maximum(np.maximum(r1, r2), d)
    tol = _CUT_TOL * scale
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        ok = (d > _SAME_TOL * scale) & (d <= r1 + r2 + tol) & (d >= np.abs(r1 - r2) - tol)
        a = (d * d + r1 * r1 - r2 * r2) / (2.0 * d)
        h = np.sqrt(np.maximum(r1 * r1 - a * a, 0.0))
        h = np.where(h < _SNAP * r1, 0.0, h)  # rounding noise near tangency: snap to one point
        alpha = np.arctan2(dy, dx)
        beta = np.arctan2(h, a)
    ang = np.stack([alpha - beta, alpha + beta], -1)
    return np.where(ok[..., None], ang, np.nan), ok


# ---------------------------------------------------------------- elementary arcs


def _prepare(centres, radii, sides):
    centres = np.asarray(centres, float)
    radii = np.asarray(radii, float)
    sides = np.asarray(sides, int)
    m = sides.shape[-1]
    batch = np.broadcast_shapes(centres.shape[:-2], radii.shape[:-1], sides.shape[:-1])
    centres = np.broadcast_to(centres, batch + (m, 2))
    radii = np.broadcast_to(radii, batch + (m,))
    sides = np.broadcast_to(sides, batch + (m,))
    if not (np.all(radii >= 0) and np.all(np.isfinite(centres))):  # NaN radii fail ">= 0" too
        raise ValueError("radii must be >= 0 (or inf) and centres finite")
    return centres, radii, sides


@lru_cache(maxsize=None)
def _indices(m: int):
    """For M circles: row and column indices of the other circles of each one, and j <= m."""
    others = np.array([[i for i in range(m) if i != j] for j in range(m)], int).reshape(m, max(m - 1, 0))
    jj, mm = np.meshgrid(np.arange(m), np.arange(m), indexing="ij")
    return np.arange(m)[:, None], others, jj <= mm


def _arcs(centres, radii, sides):
    """Elementary arcs of a flat batch of regions (N, M) and whether each is on the boundary.

    Returns start, end (N, M, K) angles on circle j (end >= start), keep (N, M, K) bool and the
    Green's-theorem contribution of each arc (N, M, K), zero where not kept.
    """
    n, m = radii.shape
    x, y, r, s = centres[..., 0], centres[..., 1], radii, sides
    trivial = ((s < 0) & (r == 0)) | ((s > 0) & np.isinf(r))
    empty = np.any(((s > 0) & (r == 0)) | ((s < 0) & np.isinf(r)), axis=1)
    active = ~trivial & np.isfinite(r) & (r > 0)

    # Cut angles of circle j by the other circles: (N, j, m, 2) -> (N, j, 2M - 2), ordered, inf last.
    ang, ok = _cut_angles_pair(x[:, :, None], y[:, :, None], r[:, :, None], x[:, None, :], y[:, None, :], r[:, None, :])
    ok &= active[:, :, None] & active[:, None, :]
    ang = np.where(ang < 0.0, ang + TWO_PI, ang)  # alpha +- beta lies in (-2 pi, 2 pi)
    rows, others, first_index = _indices(m)
    ang = np.where(ok[..., None], ang, np.inf)[:, rows, others].reshape(n, m, 2 * (m - 1))
    ang = np.sort(ang, axis=-1)
    count = np.sum(ok, axis=-1) * 2  # (N, M)
    k = np.arange(max(2 * (m - 1), 1))
    if m == 1:
        ang = np.full((n, 1, 1), np.inf)
    last = np.maximum(count, 1)[..., None]
    start = np.where(count[..., None] == 0, 0.0, ang)  # a circle without cuts is one whole arc
    wrap = k + 1 >= last
    end = np.take_along_axis(start, np.broadcast_to(np.where(wrap, 0, k + 1), start.shape), axis=-1)
    end = np.where(wrap, end + TWO_PI, end)
    valid = (k < last) & active[..., None]
    start = np.where(valid, start, 0.0)
    end = np.where(valid, end, 0.0)
    mid = 0.5 * (start + end)
    ux, uy = np.cos(mid), np.sin(mid)

    # Midpoint p = c_j + r_j u against constraint m: (|p - c_m|^2 - r_m^2) s_m <= 0, expanded as
    # A_jm + B_jm . u with A = (|c_j - c_m|^2 + r_j^2 - r_m^2) s_m and B = 2 r_j (c_j - c_m) s_m.
    # Trivial constraints give -inf (always satisfied). An arc satisfies its own circle; of two
    # identical circles with the same side only the first one carries the boundary.
    with np.errstate(invalid="ignore", over="ignore"):
        dx = x[:, :, None] - x[:, None, :]
        dy = y[:, :, None] - y[:, None, :]
        rj, rm, sm = r[:, :, None], r[:, None, :], s[:, None, :]
        coef_a = (dx * dx + dy * dy + rj * rj - rm * rm) * sm
        coef_bx = 2.0 * rj * dx * sm
        coef_by = 2.0 * rj * dy * sm
        tol = _SAME_TOL * (np.abs(x) + np.abs(y) + r)[:, :, None]
        same = (np.abs(dx) <= tol) & (np.abs(dy) <= tol) & (np.abs(rj - rm) <= tol)
        first = (s[:, :, None] != sm) | first_index
        coef_a = np.where(same, np.where(first, -np.inf, np.inf), coef_a)
        coef_bx = np.where(same, 0.0, coef_bx)
        coef_by = np.where(same, 0.0, coef_by)
        worst = np.full(ux.shape, -np.inf)
        for i in range(m):
            t = coef_bx[:, :, i, None] * ux
            t += coef_by[:, :, i, None] * uy
            t += coef_a[:, :, i, None]
            np.maximum(worst, t, out=worst)
    keep = valid & (worst <= 0.0) & ~empty[:, None, None]

    # Green: 1/2 s_j [r^2 (e - s) + r x (sin e - sin s) - r y (cos e - cos s)], with the half-angle
    # identities sin e - sin s = 2 cos(mid) sin(h), cos e - cos s = -2 sin(mid) sin(h), h = (e - s)/2.
    rr = np.where(active, r, 0.0)[..., None]
    g = 0.5 * s[..., None] * (
        rr * rr * (end - start) + 2.0 * rr * np.sin(0.5 * (end - start)) * (x[..., None] * ux + y[..., None] * uy)
    )
    return start, end, keep, np.where(keep, g, 0.0)


def _green(x, y, r, side, start, end):
    """1/2 integral of (x dy - y dx) along an arc (traversed ccw for side +1, cw for side -1)."""
    return 0.5 * side * (
        r * r * (end - start) + r * x * (np.sin(end) - np.sin(start)) - r * y * (np.cos(end) - np.cos(start))
    )


def area(centres, radii, sides):
    """Exact area of the region(s): centres (..., M, 2), radii (..., M), sides (..., M) of +1 / -1.

    A region with no finite disc constraint is unbounded: its area is inf (0 if it is empty).
    """
    centres, radii, sides = _prepare(centres, radii, sides)
    batch, m = radii.shape[:-1], radii.shape[-1]
    c = centres.reshape(-1, m, 2)
    r = radii.reshape(-1, m)
    s = sides.reshape(-1, m)
    out = np.empty(len(r))
    for lo in range(0, len(r), _CHUNK):
        sl = slice(lo, lo + _CHUNK)
        cc, rr, ss = c[sl], r[sl], s[sl]
        # Green's theorem is translation invariant: work about the first centre, for accuracy.
        out[sl] = np.sum(_arcs(cc - cc[:, :1, :], rr, ss)[3], axis=(1, 2))
    bounded = np.any((s > 0) & np.isfinite(r), axis=-1)  # else the region is unbounded (or empty)
    return np.where(bounded, np.maximum(out, 0.0), np.where(out < 0, np.inf, 0.0)).reshape(batch)


# ---------------------------------------------------------------- one region: arcs, loops, membership


@dataclass(frozen=True)
class Arc:
    """A boundary arc of circle `circle` from angle `start` to `end` (end > start, radians).

    The region lies on the left when the arc is traversed in its direction: counter-clockwise for
    side +1 (disc), clockwise for side -1 (outside of a disc).
    """

    circle: int
    centre: tuple[float, float]
    radius: float
    start: float
    end: float
    side: int

    def points(self, n: int = 64) -> np.ndarray:
        """(n, 2) points along the arc in its traversal direction."""
        t = np.linspace(self.start, self.end, n)
        if self.side < 0:
            t = t[::-1]
        return np.column_stack([self.centre[0] + self.radius * np.cos(t), self.centre[1] + self.radius * np.sin(t)])

    @property
    def head(self) -> np.ndarray:
        return self.points(2)[0]

    @property
    def tail(self) -> np.ndarray:
        return self.points(2)[-1]

    @property
    def length(self) -> float:
        return self.radius * (self.end - self.start)

    def green(self) -> float:
        """This arc's share of the area (Green's theorem)."""
        return float(_green(self.centre[0], self.centre[1], self.radius, self.side, self.start, self.end))


def boundary_arcs(centres, radii, sides) -> list[Arc]:
    """Boundary of one region as elementary arcs (zero-length arcs at tangencies dropped)."""
    centres, radii, sides = _prepare(centres, radii, sides)
    if centres.ndim != 2:
        raise ValueError("boundary_arcs takes one region: centres (M, 2)")
    start, end, keep, _ = _arcs(centres[None], radii[None], sides[None])
    arcs = []
    for j, kk in zip(*np.nonzero(keep[0])):
        a, b = float(start[0, j, kk]), float(end[0, j, kk])
        if b - a > 1e-15:
            arcs.append(Arc(int(j), (float(centres[j, 0]), float(centres[j, 1])), float(radii[j]), a, b, int(sides[j])))
    return arcs


def loops(arcs: list[Arc], tol: float = 1e-7) -> list[list[Arc]]:
    """Chain boundary arcs into closed loops (each arc's tail meets the next arc's head).

    Arcs shorter than `tol` (relative) are dropped: they come from nearly coincident cut points.
    """
    scale = max([1.0] + [abs(a.centre[0]) + abs(a.centre[1]) + a.radius for a in arcs])
    todo = [a for a in arcs if a.length > tol * scale]
    out = []
    while todo:
        loop = [todo.pop(0)]
        while todo and not _closed(loop, tol * scale):
            gaps = [float(np.linalg.norm(a.head - loop[-1].tail)) for a in todo]
            i = int(np.argmin(gaps))
            if gaps[i] > 1e3 * tol * scale:
                break
            loop.append(todo.pop(i))
        out.append(loop)
    return out


def _closed(loop: list[Arc], tol: float) -> bool:
    if len(loop) == 1:
        return loop[0].end - loop[0].start > TWO_PI - 1e-12
    return float(np.linalg.norm(loop[-1].tail - loop[0].head)) <= tol


def contains(points, centres, radii, sides) -> np.ndarray:
    """Whether each point (..., 2) lies in the region (closed): one region, M circles."""
    p = np.asarray(points, float)[..., None, :]
    c, r, s = np.asarray(centres, float), np.asarray(radii, float), np.asarray(sides)
    d = np.hypot(p[..., 0] - c[:, 0], p[..., 1] - c[:, 1])
    return np.all(np.where(s > 0, d <= r, d >= r), axis=-1)


def polygon(arcs: list[Arc], points_per_radian: float = 64.0) -> list[np.ndarray]:
    """Each boundary loop as a closed (n, 2) polyline, for drawing."""
    out = []
    for loop in loops(arcs):
        pts = [a.points(max(2, int(math.ceil((a.end - a.start) * points_per_radian)) + 1)) for a in loop]
        out.append(np.vstack(pts))
    return out
