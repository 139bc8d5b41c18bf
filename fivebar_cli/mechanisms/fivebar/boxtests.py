"""Exact box tests of the five-bar's joint space and workspace.

The tests compute exact ranges (extrema of sinusoids, distances from a point to a box, the exact
emptiness test of a box against the intersection of two annuli), then widen them by a safety
margin `DELTA_REL * scale^2` (scale = sum of lengths), far above the few-ulp rounding of the float
evaluation, before deciding; boxes are already widened by the paving for their own rounding.
Box tests return 1 (every point valid), -1 (no point valid), 0 (cannot tell).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from fivebar_cli.mechanisms.fivebar.kinematics import scale
from fivebar_cli.numerics import annuli as ring
from fivebar_cli.numerics.ranges import ANGLE_TOL, angle_inside, axis_distance2, circle_intersections, sinusoid_range
from fivebar_cli.numerics.verdict import verdict
from fivebar_cli.paving.grid import AxisEnds

DELTA_REL = 1e-12  # safety margin on squared lengths, relative to the squared scale
ETA_REL = 1e-9  # safety margin on lengths along box edges, relative to the scale
ANCHOR_TOL_REL = 1e-9  # anchors within this (times scale^2) of the workspace are kept


# ---------------------------------------------------------------- joint space


@dataclass(frozen=True)
class AngleTables:
    """Boxes of joint angles (th1, th2), per axis: the ends of the boxes as tables (`grid.AxisEnds`:
    the cells of one level share their ends) with their cos and sin. What depends on one angle's
    interval alone is computed once per table entry and gathered per box (`along`)."""

    ends: tuple
    trig: tuple  # per axis: (cos, sin) of its table's low ends, then of its high ends

    @classmethod
    def of(cls, lo: np.ndarray, hi: np.ndarray, ends=None) -> "AngleTables":
        """The tables of boxes (lo, hi): `ends` when the caller has them, else one entry per box."""
        ends = ends if ends is not None else AxisEnds.of_boxes(lo, hi)
        return cls(ends, tuple((np.cos(e.low), np.sin(e.low), np.cos(e.high), np.sin(e.high)) for e in ends))

    @cached_property
    def box_trig(self) -> tuple[tuple, tuple]:
        """(cos, sin) of both ends of both angles per box: ((c, s, c, s) of th1, (c, s, c, s) of th2)."""
        return tuple(e.per_box(t) for e, t in zip(self.ends, self.trig))

    def along(self, axis: int, fn):
        """fn(lo, hi, trig) of the intervals of one axis (an array or a tuple of arrays), per box."""
        e = self.ends[axis]
        return e.per_box(fn(e.low, e.high, self.trig[axis]))


def crank_distance2_range(m, lo: np.ndarray, hi: np.ndarray, angles: AngleTables | None = None):
    """Exact range of |B1B2|^2 over boxes [th1] x [th2] (`angles`: their tables, if at hand).

    d^2 = K - 2 L0 L1 cos th1 + 2 L0 L2 cos th2 - 2 L1 L2 cos(th1 - th2) is smooth, so its extrema
    over a box lie on the edges (sinusoids in one angle: exact) or at interior critical points:
    where B1B2 is normal to both crank circles, i.e. B1, B2 on the line A1A2 (th1, th2 in {0, pi}),
    or where B1 = B2 (d = 0).
    """
    L0, L1, L2 = m.L0, m.L1, m.L2
    k0 = L0 * L0 + L1 * L1 + L2 * L2
    angles = angles if angles is not None else AngleTables.of(lo, hi)
    t1, t2 = angles.box_trig
    fmin = fmax = None
    # an edge th_i = const is a sinusoid a cos t + b sin t in the other angle t, whose coefficients
    # and phase atan2(b, a) depend on the edge's angle alone: the phases come per table entry; the
    # other angle's intervals, widened by angle_inside's tolerance, per table entry too
    edges = ((0, k0, -2 * L0 * L1, 2 * L0 * L2, -2 * L1 * L2, t2),  # th1 = const
             (1, k0, 2 * L0 * L2, -2 * L0 * L1, -2 * L1 * L2, t1))  # th2 = const
    for axis, k, kc, a0, a1, t_trig in edges:
        own, table, other = angles.box_trig[axis], angles.trig[axis], angles.ends[1 - axis]
        t_lo, t_hi = other.per_box((other.low - ANGLE_TOL, other.high + ANGLE_TOL))
        for cos_, sin_, cos_table, sin_table in ((own[0], own[1], table[0], table[1]), (own[2], own[3], table[2], table[3])):
            base = k + kc * cos_
            phase = angles.ends[axis].per_box(np.arctan2(a1 * sin_table, a0 + a1 * cos_table))
            bot, top = sinusoid_range(a0 + a1 * cos_, a1 * sin_, t_lo, t_hi, t_trig, phase, tol=0.0)
            bot += base
            top += base
            if fmin is None:  # (min(inf, x) is x: the first edge's range as it is)
                fmin, fmax = bot, top
            else:
                np.minimum(fmin, bot, out=fmin)
                np.maximum(fmax, top, out=fmax)
    holds = [{}, {}]  # per axis: angle -> whether each table entry's interval holds it
    for th1, th2, value in _crank_critical_points(m):
        in1, in2 = _holds(angles, holds, 0, th1), _holds(angles, holds, 1, th2)
        if in1.any() and in2.any():  # (deep levels: rarely; the boxes that hold it updated alone)
            rows = np.flatnonzero(angles.ends[0].per_box(in1) & angles.ends[1].per_box(in2))
            fmin[rows] = np.minimum(fmin[rows], value)
            fmax[rows] = np.maximum(fmax[rows], value)
    return fmin, fmax


def _holds(angles: AngleTables, memo: list[dict], axis: int, angle: float) -> np.ndarray:
    """Whether each table entry's interval of `axis` holds `angle` (memoised per angle)."""
    if angle not in memo[axis]:
        e = angles.ends[axis]
        memo[axis][angle] = angle_inside(angle, e.low, e.high)
    return memo[axis][angle]


def _crank_critical_points(m) -> list[tuple[float, float, float]]:
    """Interior critical points (th1, th2, d^2) of the crank distance."""
    points = []
    for th1 in (0.0, np.pi):
        for th2 in (0.0, np.pi):
            x = m.L1 * np.cos(th1) - m.L0 - m.L2 * np.cos(th2)
            points.append((th1, th2, x * x))
    for q in circle_intersections((0.0, 0.0), m.L1, (m.L0, 0.0), m.L2):  # B1 = B2
        points.append((float(np.arctan2(q[1], q[0])), float(np.arctan2(q[1], q[0] - m.L0)), 0.0))
    return points


def joint_space_test(m):
    """Box test of the joint space (th1, th2): |L3 - L4| <= |B1B2| <= L3 + L4 and B1 != B2.

    Exact: the box is connected, so |B1B2| takes every value between its exact extrema.
    """

    def test(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        return assembly_status(m, *crank_distance2_range(m, lo, hi))

    return test


def assembly_status(m, dmin: np.ndarray, dmax: np.ndarray) -> np.ndarray:
    """1 / -1 / 0 from the exact range of |B1B2|^2, widened by the safety margin."""
    lo2, hi2 = (m.L3 - m.L4) ** 2, (m.L3 + m.L4) ** 2
    delta = DELTA_REL * scale(m) ** 2
    dmin, dmax = dmin - delta, dmax + delta
    inside = (dmin >= lo2) & (dmax <= hi2) & (dmin > 0)
    outside = (dmax < lo2) | (dmin > hi2)
    return verdict(inside, outside)


# ---------------------------------------------------------------- workspace


def annuli(m) -> list[tuple[float, float, float]]:
    """Workspace constraints as annuli (centre x, inner radius, outer radius); centres on y = 0."""
    return [(0.0, abs(m.L1 - m.L3), m.L1 + m.L3), (m.L0, abs(m.L2 - m.L4), m.L2 + m.L4)]


def workspace_test(m):
    """Box test of the workspace: P in both annuli |L_i - L_j| <= |P - A_i| <= L_i + L_j, P != A_i.

    Exact in both directions (`numerics/annuli.py`).
    """
    anchors = workspace_anchors(m)

    def test(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        return reach_status(m, lo, hi, leg_distance2_ranges(m, lo, hi), anchors)

    return test


def workspace_anchors(m) -> list[tuple[float, float]]:
    return ring.anchors(annuli(m), ANCHOR_TOL_REL * scale(m) ** 2)


def leg_distance2_ranges(m, lo: np.ndarray, hi: np.ndarray, ends=None) -> list[tuple[np.ndarray, np.ndarray]]:
    """Exact ranges of |P - A1|^2 and |P - A2|^2 over boxes (`ring.distance2_ranges`'s floats).
    `ends`: the boxes' ends as tables (`grid.AxisEnds`), if at hand: a squared distance from a
    point of y = 0 to a box is a part of its x interval plus a part of its y interval, each
    computed per table entry (the y part once, the same for both legs) and gathered."""
    if ends is None:
        return ring.distance2_ranges(annuli(m), lo, hi)
    x, y = ends
    near_y, far_y = y.per_box(axis_distance2(0.0, y.low, y.high))
    out = []
    for cx, _, _ in annuli(m):
        near_x, far_x = x.per_box(axis_distance2(cx, x.low, x.high))
        out.append((near_x + near_y, far_x + far_y))
    return out


def reach_status(m, lo: np.ndarray, hi: np.ndarray, ranges, anchors) -> np.ndarray:
    """1 / -1 / 0 of the workspace test from the leg distance ranges."""
    s = scale(m)
    return ring.reach_status(annuli(m), lo, hi, ranges, anchors, DELTA_REL * s * s, ETA_REL * s)


def workspace_area(m) -> float:
    """Exact area of the workspace: the intersection of two annuli, by Green's theorem on its arcs."""
    return ring.area(annuli(m))
