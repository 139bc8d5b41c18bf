"""Boxes against an intersection of annuli centred on the x axis: an exact test and the exact area.

The workspace of a mechanism whose legs each reach a ring of points around a base point (a
five-bar's two legs, a 2-RPR's two prismatic legs) is such an intersection V. An annulus is
(cx, inner, outer): the points at distance in [inner, outer] from (cx, 0).

The test is exact in both directions: 'inside' from exact point-to-box distances; 'outside' when no
point of the box lies in V. A box meets V iff an edge of the box meets V (each annulus cuts an edge
in at most two intervals, intersected exactly) or a whole component of V lies inside the box, in
which case it contains the leftmost point of that component: a vertex of V or the leftmost or
rightmost point of one of the circles (the *anchors*). Squared distances are widened by `delta`
and lengths along edges by `eta` before deciding, far above the float rounding of the evaluation.
"""

from __future__ import annotations

import numpy as np

from fivebar_cli.numerics.ranges import circle_intersections, point_box_distance2
from fivebar_cli.numerics.verdict import verdict

Annulus = tuple[float, float, float]  # (centre x, inner radius, outer radius); centre (cx, 0)


def distance2_ranges(annuli, lo: np.ndarray, hi: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
    """Exact ranges of the squared distance from each annulus centre to the points of each box."""
    return [point_box_distance2(cx, 0.0, lo, hi) for cx, _, _ in annuli]


def anchors(annuli, tol: float) -> list[tuple[float, float]]:
    """Points of V that every component of V lying inside a box must bring into it.

    `tol` (on squared distances) keeps the candidates that lie in V up to rounding.
    """
    circles = [((cx, 0.0), rad) for cx, r, big_r in annuli for rad in (r, big_r)]
    points = [(c[0] + sgn * rad, 0.0) for c, rad in circles for sgn in (-1, 1)]
    for i, (c1, r1) in enumerate(circles):
        for c2, r2 in circles[i + 1:]:
            points += circle_intersections(c1, r1, c2, r2)
    keep = []
    for px, py in points:
        d2 = [(px - cx) ** 2 + py**2 for cx, _, _ in annuli]
        if all(r * r - tol <= d <= big_r * big_r + tol for d, (_, r, big_r) in zip(d2, annuli)):
            keep.append((px, py))
    return sorted(set(keep))


def reach_status(annuli, lo: np.ndarray, hi: np.ndarray, ranges, anchor_points, delta: float,
                 eta: float) -> np.ndarray:
    """1 (every point of the box in V, none at a centre) / -1 (no point in V) / 0, from the
    distance ranges of `distance2_ranges` (two annuli, as `box_meets`)."""
    inside = np.ones(len(lo), dtype=bool)
    outside = np.zeros(len(lo), dtype=bool)
    in_one = np.zeros(len(lo), dtype=bool)
    for (dmin, dmax), (_, r, big_r) in zip(ranges, annuli):
        inside_this = (dmin - delta >= r * r) & (dmax + delta <= big_r * big_r) & (dmin - delta > 0)
        inside &= inside_this
        in_one |= inside_this
        outside |= (dmax + delta < r * r) | (dmin - delta > big_r * big_r)
    # a box within one annulus and not out of reach of the other meets V: its (connected) boundary
    # or, when the other ring lies inside the box, that ring's leftmost point (an anchor) meets both
    # rings; `box_meets` decides the others (the boxes crossing both rings, near V's vertices)
    idx = np.flatnonzero(~outside & ~in_one)
    if len(idx):
        lo, hi = lo[idx], hi[idx]
        meets = box_meets(annuli, lo, hi, delta, eta)
        x0, x1, y0, y1 = lo[:, 0] - eta, hi[:, 0] + eta, lo[:, 1] - eta, hi[:, 1] + eta
        for px, py in anchor_points:
            meets |= (x0 <= px) & (px <= x1) & (y0 <= py) & (py <= y1)
        outside[idx[~meets]] = True
    return verdict(inside, outside)


def box_meets(annuli, lo, hi, delta, eta) -> np.ndarray:
    """Whether some point of the boundary of each box lies in every annulus (widened by the margins).

    Written for two annuli, the case of every mechanism here.
    """
    meets = np.zeros(len(lo), dtype=bool)
    edges = []
    for y in (lo[:, 1], hi[:, 1]):  # horizontal edges: t = x, offset from each centre = y
        edges.append((lo[:, 0], hi[:, 0], [(cx, y) for cx, _, _ in annuli]))
    for x in (lo[:, 0], hi[:, 0]):  # vertical edges: t = y, centres at t = 0, offset = x - cx
        edges.append((lo[:, 1], hi[:, 1], [(0.0, x - cx) for cx, _, _ in annuli]))
    for t0, t1, placed in edges:
        pieces = []  # per annulus: the two allowed t-intervals [c - outer, c - inner], [c + inner, c + outer]
        for (c, w), (_, r, big_r) in zip(placed, annuli):
            reach2 = big_r * big_r + delta - w * w
            outer = np.sqrt(np.maximum(reach2, 0.0)) + eta
            inner = np.sqrt(np.maximum(r * r - delta - w * w, 0.0)) - eta
            outer = np.where(reach2 >= 0, outer, -np.inf)  # empty when the edge line misses the disc
            pieces.append(((c - outer, c - inner), (c + inner, c + outer)))
        (a_minus, a_plus), (b_minus, b_plus) = pieces
        for a in (a_minus, a_plus):
            for b in (b_minus, b_plus):
                left = np.maximum(np.maximum(t0, a[0]), b[0])
                right = np.minimum(np.minimum(t1, a[1]), b[1])
                meets |= left <= right
    return meets


def area(annuli) -> float:
    """Exact area of V, by Green's theorem on its boundary arcs."""
    from fivebar_cli.numerics import arcs  # (only here: not imported by the box tests)

    centres, radii, sides = [], [], []
    for cx, r, big_r in annuli:
        centres += [(cx, 0.0), (cx, 0.0)]
        radii += [big_r, r]
        sides += [1, -1]
    return float(arcs.area(np.array(centres), np.array(radii), np.array(sides)))
