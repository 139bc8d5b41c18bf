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
_MERGE_TOL = 1e-9  # relative to the smallest radius: arcs meeting within it are one arc; shorter ones are points
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
    alpha, beta, ok = _cut_alpha_beta(x1, y1, r1, x2, y2, r2)
    ang = np.stack([alpha - beta, alpha + beta], -1)
    return np.where(ok[..., None], ang, np.nan), ok


def _cut_alpha_beta(x1, y1, r1, x2, y2, r2):
    """Intersections of circle 1 with circle 2 as angles alpha -+ beta on circle 1, and a validity mask.

    Written so that nothing cancels when one circle is much larger than the other (a nearly
    straight singularity circle): the distances a1, a2 from each centre to the foot of the common
    chord use (d - r)(d + r), and the half-chord is taken on the side of the smaller circle. Two
    nearly coincident circles of nearly equal radii (d much smaller than r) would cancel there
    instead: r1^2 - r2^2 is then taken as (r1 - r2)(r1 + r2) (`_coincident_foot`).
    """
    dx, dy = x2 - x1, y2 - y1
    d = np.hypot(dx, dy)
    scale = np.maximum(np.maximum(r1, r2), d)
    tol = _CUT_TOL * scale
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        sum_r = r1 + r2
        ok = (d > _SAME_TOL * scale) & (d <= sum_r + tol) & (d >= np.abs(r1 - r2) - tol)
        a1 = ((d - r2) * (d + r2) + r1 * r1) / (2.0 * d)
        a2 = ((d - r1) * (d + r1) + r2 * r2) / (2.0 * d)
        close = d < 1e-2 * sum_r  # the pairs `_coincident_foot` may regroup (few): those alone
        if np.any(close):
            a1, a2 = np.array(a1), np.array(a2)  # (writable, also from 0-d inputs)
            dc, r1c, r2c = (np.broadcast_to(v, close.shape)[close] for v in (d, r1, r2))
            a1[close] = _coincident_foot(dc, r1c, r2c, a1[close])
            a2[close] = _coincident_foot(dc, r2c, r1c, a2[close])
        h2 = np.where(r1 <= r2, (r1 - a1) * (r1 + a1), (r2 - a2) * (r2 + a2))
        h = np.sqrt(np.maximum(h2, 0.0))
        h = np.where(h < _SNAP * np.minimum(r1, r2), 0.0, h)  # rounding noise near tangency: one point
        alpha = np.arctan2(dy, dx)
        beta = np.arctan2(h, a1)
    return alpha, beta, ok


def _coincident_foot(d, r1, r2, foot):
    """`foot`, the distance from centre 1 to the foot of the common chord, (d^2 - r2^2 + r1^2) / (2 d)
    grouped as (d - r2)(d + r2) + r1^2, regrouped as d^2 + (r1 - r2)(r1 + r2) where that grouping's
    rounding is a million times smaller: nearly coincident circles of nearly equal radii, where the
    first loses digits as r^2 / d^2 (a cut 1e-5 rad off for d = 1e-12 r); every other cut keeps its
    bits. Only circles with d < 1e-2 (r1 + r2) can be regrouped, the caller's cheap test: beyond it,
    1e-6 size <= 1e-6 (d + r1 + r2)^2 < 0.011 d^2."""
    size = np.abs(d - r2) * (d + r2) + r1 * r1  # the first grouping's rounding, in units of eps
    better = d * d + np.abs(r1 - r2) * (r1 + r2) < 1e-6 * size
    return np.where(better, (d * d + (r1 - r2) * (r1 + r2)) / (2.0 * d), foot)


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
    """For M circles: the indices of the other circles of each one, and j <= m."""
    others = np.array([[i for i in range(m) if i != j] for j in range(m)], int).reshape(m, max(m - 1, 0))
    jj, mm = np.meshgrid(np.arange(m), np.arange(m), indexing="ij")
    return others, jj <= mm


def _arcs(centres, radii, sides):
    """Elementary arcs of a flat batch of regions (N, M) and whether each is on the boundary.

    Returns start, end (N, M, K) angles on circle j (end >= start), keep (N, M, K) bool and the
    Green's-theorem contribution of each arc (N, M, K), zero where not kept.

    The work is laid out batch-last, (pair or arc axes..., N): every broadcast then repeats whole
    rows of N regions, so numpy's inner loops run over N contiguous numbers instead of over the
    M - 1 other circles or the K arcs of one circle (per-loop overhead was most of the time).
    Each number is the same expression of the same operands as in a batch-first layout, the
    sort sorts the same lanes and the maximum over constraints runs in the same order; start, end
    and keep are returned as (N, M, K) views, and Green's terms are scattered into an (N, M, K)
    array, so what callers read and sum is unchanged.
    """
    n, m = radii.shape
    x, y, r, s = centres[..., 0], centres[..., 1], radii, sides
    trivial = ((s < 0) & (r == 0)) | ((s > 0) & np.isinf(r))
    empty = np.any(((s > 0) & (r == 0)) | ((s < 0) & np.isinf(r)), axis=1)
    active = ~trivial & np.isfinite(r) & (r > 0)
    xt, yt, rt, st, at_ = (np.ascontiguousarray(v.T) for v in (x, y, r, s, active))  # (M, N)

    # Cut angles of circle j by the other circles o != j: (j, o, 2, N) -> (j, N, 2M - 2) ordered,
    # inf last -> (K, j, N). A circle does not cut itself: only pairs of distinct circles.
    others, first_index = _indices(m)
    kk = max(2 * (m - 1), 1)
    if m == 1:
        ang, count = np.full((1, 1, n), np.inf), np.zeros((1, n), int)
    else:
        alpha, beta, ok = _cut_alpha_beta(xt[:, None], yt[:, None], rt[:, None], xt[others], yt[others], rt[others])
        ok &= at_[:, None] & at_[others]
        ang = np.stack([alpha - beta, alpha + beta], 2)
        ang = np.where(ang < 0.0, ang + TWO_PI, ang)  # alpha +- beta lies in (-2 pi, 2 pi)
        ang = np.where(ok[:, :, None], ang, np.inf).reshape(m, kk, n)
        ang = np.ascontiguousarray(np.sort(ang.transpose(0, 2, 1), axis=-1).transpose(2, 0, 1))
        count = np.sum(ok, axis=1) * 2  # (M, N)
    k = np.arange(kk)[:, None, None]
    last = np.maximum(count, 1)
    start = np.where(count == 0, 0.0, ang)  # a circle without cuts is one whole arc
    wrap = k + 1 >= last
    end = np.where(wrap, start[:1] + TWO_PI, np.roll(start, -1, axis=0))  # the next cut, or the first + 2 pi
    valid = (k < last) & at_
    start = np.where(valid, start, 0.0)
    end = np.where(valid, end, 0.0)
    mid = 0.5 * (start + end)[valid]  # only the valid arcs' midpoints (some 40 %) are tested: the rest is
    ux, uy = np.ones(valid.shape), np.zeros(valid.shape)  # not kept, so any finite direction will do there
    ux[valid], uy[valid] = np.cos(mid), np.sin(mid)

    # Midpoint p = c_j + r_j u against constraint i: (|p - c_i|^2 - r_i^2) s_i <= 0, expanded as
    # A_ji + B_ji . u with A = (|c_j - c_i|^2 + r_j^2 - r_i^2) s_i and B = 2 r_j (c_j - c_i) s_i,
    # stored (i, j, N). Trivial constraints give -inf (always satisfied). An arc satisfies its own
    # circle; of two identical circles with the same side only the first one carries the boundary.
    # (Against a huge circle of radius R the rounding of A is ~R^2 eps: a misplaced midpoint would
    # have to be within ~R eps of it.)
    with np.errstate(invalid="ignore", over="ignore"):
        dx = xt[None, :, :] - xt[:, None, :]
        dy = yt[None, :, :] - yt[:, None, :]
        rj, ri, si = rt[None, :, :], rt[:, None, :], st[:, None, :]
        coef_a = (dx * dx + dy * dy + rj * rj - ri * ri) * si
        coef_bx = 2.0 * rj * dx * si
        coef_by = 2.0 * rj * dy * si
        tol = _SAME_TOL * (np.abs(xt) + np.abs(yt) + rt)[None, :, :]
        same = (np.abs(dx) <= tol) & (np.abs(dy) <= tol) & (np.abs(rj - ri) <= tol)
        first = (st[None, :, :] != si) | first_index.T[:, :, None]
        coef_a = np.where(same, np.where(first, -np.inf, np.inf), coef_a)
        coef_bx = np.where(same, 0.0, coef_bx)
        coef_by = np.where(same, 0.0, coef_by)
        worst = np.full(ux.shape, -np.inf)
        t = np.empty(ux.shape)
        for i in range(m):
            np.multiply(coef_bx[i], ux, out=t)
            t += coef_by[i] * uy
            t += coef_a[i]
            np.maximum(worst, t, out=worst)
    keep = (valid & (worst <= 0.0) & ~empty).transpose(2, 1, 0)
    start, end, ux, uy = (v.transpose(2, 1, 0) for v in (start, end, ux, uy))

    # Green, as chord plus circular segment: 1/2 s_j [P_s x P_e + r^2 (theta - sin theta)], theta = e - s,
    # with P_s x P_e = 2 r sin(h) (c . u + r cos h), h = theta / 2. Unlike r^2 theta + 2 r sin(h) c . u,
    # nothing large cancels for a huge circle with a short arc (a nearly collinear base): there
    # theta is known to its rounding only, and r^2 theta is huge. Only the kept arcs (a tenth of
    # them, typically) are measured: the same expression, element by element, zero elsewhere.
    at = np.nonzero(keep)
    row = at[:2]
    rr = np.where(active, r, 0.0)[row]
    theta = end[at] - start[at]
    half = 0.5 * theta
    ch, sh = np.cos(half), np.sin(half)
    seg = np.where(theta < 0.05, theta_minus_sin(theta), theta - 2.0 * sh * ch)
    green = np.zeros(keep.shape)
    green[at] = 0.5 * s[row] * (2.0 * rr * sh * (x[row] * ux[at] + y[row] * uy[at] + rr * ch) + rr * rr * seg)
    return start, end, keep, green


def theta_minus_sin(t):
    """t - sin t without cancellation for small t (a series below 0.05; its next term is < 1e-17 t^3)."""
    t = np.asarray(t, float)
    t2 = t * t
    series = t * t2 / 6.0 * (1.0 - t2 / 20.0 * (1.0 - t2 / 42.0 * (1.0 - t2 / 72.0)))
    return np.where(t < 0.05, series, t - np.sin(t))


def _green(x, y, r, side, start, end):
    """1/2 integral of (x dy - y dx) along an arc (traversed ccw for side +1, cw for side -1)."""
    return 0.5 * side * (
        r * r * (end - start) + r * x * (np.sin(end) - np.sin(start)) - r * y * (np.cos(end) - np.cos(start))
    )


def _origin(centres, radii, sides):
    """Working origin of each region (N, 1, 2): the centre of its smallest constraining circle.

    Green's theorem is translation invariant; working near the region keeps the coordinates small.
    """
    active = np.isfinite(radii) & (radii > 0)
    i = np.argmin(np.where(active, radii, np.inf), axis=1)
    return np.take_along_axis(centres, i[:, None, None], axis=1)


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
        out[sl] = np.sum(_arcs(cc - _origin(cc, rr, ss), rr, ss)[3], axis=(1, 2))
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
    """Boundary of one region as maximal arcs: elementary arcs of one circle that meet end to
    start (also across angle 0) are merged and arcs of negligible length (tangency points) dropped,
    so that the list is a property of the region, not of where its circles happen to be cut."""
    centres, radii, sides = _prepare(centres, radii, sides)
    if centres.ndim != 2:
        raise ValueError("boundary_arcs takes one region: centres (M, 2)")
    start, end, keep, _ = _arcs(centres[None], radii[None], sides[None])
    active = np.isfinite(radii) & (radii > 0)
    tol = _MERGE_TOL * (float(radii[active].min()) if active.any() else 1.0)  # a length
    arcs = []
    for j in range(len(radii)):
        pieces = sorted((float(a), float(b)) for a, b in zip(start[0, j][keep[0, j]], end[0, j][keep[0, j]]))
        r = float(radii[j])
        for a, b in _merge_pieces(pieces, tol / r if r > 0 else 0.0):
            if r * (b - a) > tol:
                arcs.append(Arc(j, (float(centres[j, 0]), float(centres[j, 1])), r, a, b, int(sides[j])))
    return arcs


def _merge_pieces(pieces: list[tuple[float, float]], gap: float) -> list[tuple[float, float]]:
    """Sorted angle intervals of one circle merged where they meet (within `gap` radians), the
    last one joined to the first across 2 pi."""
    merged: list[list[float]] = []
    for a, b in pieces:
        if merged and a - merged[-1][1] <= gap:
            merged[-1][1] = max(merged[-1][1], b)
        else:
            merged.append([a, b])
    if len(merged) > 1 and merged[0][0] + TWO_PI - merged[-1][1] <= gap:
        last = merged.pop()
        merged[0] = [last[0], merged[0][1] + TWO_PI]
    for piece in merged:
        if piece[1] - piece[0] >= TWO_PI - gap:
            piece[1] = piece[0] + TWO_PI
    return [(a, b) for a, b in merged]


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
