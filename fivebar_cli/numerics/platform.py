"""A planar platform on three legs, over boxes of poses (x, y, phi): exact distance ranges and a root box.

Platform point i sits at c_i in the platform frame, so at (x, y) + R(phi) c_i in the fixed frame,
and leg i joins it to the base point A_i: the leg spans the distance |X - C_i(phi)| between the
platform origin X = (x, y) and the point C_i(phi) = A_i - R(phi) c_i, which runs along an arc of
radius |c_i| about A_i as phi sweeps an interval. Kinds with such a platform (the 3-RPR, the 3-RRR)
decide reachability from the exact range of that distance over a box, and take their root box from
the arcs' bounding boxes widened by each leg's longest reach.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from fivebar_cli.numerics import interval as iv
from fivebar_cli.numerics.interval import Interval
from fivebar_cli.numerics.ranges import angle_inside
from fivebar_cli.numerics.verdict import verdict

_HALF_PI = 0.5 * math.pi
ETA_REL = 1e-9  # distances: margin relative to the scale of the mechanism
ANGLE_TOL = 1e-9  # radians added to each end of an arc (covers the rounding of degrees -> radians)
D2R = math.pi / 180.0


@dataclass(frozen=True)
class Platform:
    """The numbers of a platform on three legs, as arrays: base points A (3, 2), platform points c
    (3, 2) in the platform frame, |c_i| and the angle of c_i, the multiple of 360 degrees
    subtracted from phi before taking radians, the fixed phi of a single-orientation space, and
    the margin `eta` (ETA_REL x the scale: |A| + |c| + the longest reach)."""

    base: np.ndarray
    platform: np.ndarray
    radius: np.ndarray
    angle: np.ndarray
    shift: float
    phi: float
    eta: float

    @staticmethod
    def fields(base, platform, phi_range, reach: float) -> dict:
        """The field values of a platform whose legs reach at most `reach`."""
        base, platform = np.array(base, float), np.array(platform, float)
        radius = np.hypot(platform[:, 0], platform[:, 1])
        scale = float(np.abs(base).max() + radius.max() + reach)
        return dict(base=base, platform=platform, radius=radius, angle=np.arctan2(platform[:, 1], platform[:, 0]),
                    shift=360.0 * math.floor(phi_range[0] / 360.0), phi=float(phi_range[0]), eta=ETA_REL * scale)

    def poses(self, a: np.ndarray) -> np.ndarray:
        """(m, 3) poses or box bounds from (m, 2) ones of a single-orientation space."""
        a = np.asarray(a, float)
        return a if a.shape[1] == 3 else np.column_stack([a, np.full(len(a), self.phi)])

    def distance_ranges(self, lo: np.ndarray, hi: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
        """Exact (min, max) of each |C_i - A_i| over boxes of poses (m, 3), before margins."""
        turns, index = self._turns(lo, hi)
        return [self._distance_range(i, lo, hi, turns, index) for i in range(3)]

    def _turns(self, lo: np.ndarray, hi: np.ndarray, ends=None, fixed: bool = False) -> tuple[tuple[np.ndarray, np.ndarray], np.ndarray | None]:
        """The orientation ranges in radians (phi - shift), the part every leg's arc shares, and
        their index: of the single orientation (`fixed`: boxes of (x, y)) or the paving's table of
        the boxes' orientations (`ends`, `grid.AxisEnds`) when shorter than the boxes, each box's
        entry; else each box's range, None."""
        if fixed:
            turn = (np.full(1, self.phi) - self.shift) * D2R
            return (turn, turn), np.zeros(len(lo), np.intp)
        phi = ends[2] if ends is not None and len(ends) == 3 else None
        if phi is not None and phi.shared:
            return ((phi.low - self.shift) * D2R, (phi.high - self.shift) * D2R), phi.index
        return ((lo[:, 2] - self.shift) * D2R, (hi[:, 2] - self.shift) * D2R), None

    def _distance_range(self, i: int, lo, hi, turns, index) -> tuple[np.ndarray, np.ndarray]:
        start = self.angle[i] + math.pi  # A_i - C_i + (x, y) = -R(phi) c_i
        cx, cy = self.base[i]
        return rect_arc_distance(lo[:, 0], hi[:, 0], lo[:, 1], hi[:, 1], cx, cy, self.radius[i],
                                 turns[0] + start - ANGLE_TOL, turns[1] + start + ANGLE_TOL, index)

    def legs_verdict(self, lo: np.ndarray, hi: np.ndarray, decide, ends=None) -> np.ndarray:
        """1 / -1 / 0 over boxes of poses (m, 2 or 3): every leg inside / some leg outside / cannot
        tell, from `decide(i, near, far)` -> (inside, outside) of leg i given its distance ranges.
        A box found outside is not measured for the next legs (the verdict is -1 whatever they give).
        `ends`: the boxes' ends as tables (`grid.AxisEnds`), when the caller has them (`_turns`)."""
        fixed = np.shape(lo)[1] == 2
        lo, hi = self.poses(lo), self.poses(hi)
        turns, index = self._turns(lo, hi, ends, fixed)
        inside = np.ones(len(lo), dtype=bool)
        outside = np.zeros(len(lo), dtype=bool)
        for i in range(3):
            if i and outside.any():
                at = np.flatnonzero(~outside)
                rows = (turns, index[at]) if index is not None else ((turns[0][at], turns[1][at]), None)
                ins, out = decide(i, *self._distance_range(i, lo[at], hi[at], *rows))
                inside[at] &= ins
                outside[at] |= out
            else:
                ins, out = decide(i, *self._distance_range(i, lo, hi, turns, index))
                inside &= ins
                outside |= out
        return verdict(inside, outside)

    def legs_and_arms(self, poses: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """C_i - A_i and R(phi) c_i, each (m, 3, 2), at poses (m, 2 or 3), in floating point."""
        poses = self.poses(poses)
        phi = (poses[:, 2] - self.shift) * D2R
        c, s = np.cos(phi), np.sin(phi)
        q = np.stack([np.stack([c * px - s * py, s * px + c * py], -1) for px, py in self.platform], -2)
        return poses[:, None, :2] + q - np.asarray(self.base, float)[None], q


def leg_groups(boxes: int, one_pass: int) -> list[tuple[int, int]]:
    """The legs' passes (first, stop) over `boxes` boxes: the three legs in one pass up to
    `one_pass` boxes (a third of the numpy calls: interval arithmetic on small arrays costs its
    calls), leg by leg beyond (arrays that stay in cache). Either way each bound is the operation
    a leg-by-leg evaluation makes, so the grouping changes no number."""
    return [(0, 3)] if boxes <= one_pass else [(0, 1), (1, 2), (2, 3)]


def legs_apart(passes, count: int) -> list[list[Interval]]:
    """The first `count` quantities of `passes` ((k, n) Intervals covering legs 0, 1, 2 in order)
    as lists of the three legs' (n,) Intervals (views, the same bounds)."""
    return [[Interval._of(lo, hi) for part in passes for lo, hi in zip(part[q].lo, part[q].hi)] for q in range(count)]


def leg_enclosure(passes, lengths: np.ndarray, d2r: Interval):
    """Enclosures of F_i = |e_i|^2 - L_i^2 (L: `lengths` (3,)) and of its Jacobian rows
    2 (e_ix, e_iy, (q_i x e_i) d2r) over boxes, from `passes` of (e_x, e_y, q x e, ...) as (k, n)
    Intervals covering legs 0, 1, 2 in order (all three in one pass, or one leg a pass): the same
    bounds either way, laid out (f_lo, f_hi) (n, leg) and (j_lo, j_hi) (n, leg, column)."""
    f_lo, f_hi, j_lo, j_hi, first = [], [], [], [], 0
    for ex, ey, mm, *_ in passes:
        stop = first + len(ex.lo)
        f = iv.sqr(ex) + iv.sqr(ey) - iv.sqr(Interval.point(np.asarray(lengths[first:stop], float)[:, None]))
        row = [ex * 2.0, ey * 2.0, mm * (d2r * 2.0)]
        f_lo.append(f.lo)
        f_hi.append(f.hi)
        j_lo.append(np.stack([v.lo for v in row], -1))
        j_hi.append(np.stack([v.hi for v in row], -1))
        first = stop
    return (*(np.ascontiguousarray(np.concatenate(v).T) for v in (f_lo, f_hi)),
            *(np.ascontiguousarray(np.concatenate(v).transpose(1, 0, 2)) for v in (j_lo, j_hi)))


def _box_distance(px, py, xlo, xhi, ylo, yhi):
    """Distance from points to rectangles (exact up to rounding)."""
    dx = np.maximum(np.maximum(xlo - px, px - xhi), 0.0)
    dy = np.maximum(np.maximum(ylo - py, py - yhi), 0.0)
    return np.hypot(dx, dy)


def _nearer(near, at, px, py, xlo, xhi, ylo, yhi):
    """near[at] lowered to the distance from the points (px, py) (over `at`) to those rectangles."""
    if len(at):
        near[at] = np.minimum(near[at], _box_distance(px, py, xlo[at], xhi[at], ylo[at], yhi[at]))


def _farthest_corner(px, py, xlo, xhi, ylo, yhi):
    """Largest distance from points to the corners of rectangles: hypot(px - x, py - y), maximised
    over the four corners, with the same value as taking it at every corner.

    hypot at the corner farthest in x and in y; where that corner's lead over another corner is
    below 1e-12 of its square (but not a tie of |x - px| or |y - py|, whose corners have equal
    values), at every corner: a larger lead cannot be reversed by hypot's rounding (under one ulp)."""
    ax, bx = np.abs(xlo - px), np.abs(xhi - px)
    ay, by = np.abs(ylo - py), np.abs(yhi - py)
    big_x, small_x = np.maximum(ax, bx), np.minimum(ax, bx)
    big_y, small_y = np.maximum(ay, by), np.minimum(ay, by)
    far = np.hypot(big_x, big_y)
    lead_x = (big_x - small_x) * (big_x + small_x)
    lead_y = (big_y - small_y) * (big_y + small_y)
    close = 1e-12 * (big_x * big_x + big_y * big_y)
    redo = np.flatnonzero(((lead_x > 0) & (lead_x <= close)) | ((lead_y > 0) & (lead_y <= close)))
    if len(redo):
        far[redo] = np.maximum(np.maximum(np.hypot(ax[redo], ay[redo]), np.hypot(ax[redo], by[redo])),
                               np.maximum(np.hypot(bx[redo], ay[redo]), np.hypot(bx[redo], by[redo])))
    return far


def rect_arc_distance(xlo, xhi, ylo, yhi, cx, cy, r, t_lo, t_hi, index=None):
    """Range of |X - C| for X in the rectangles and C on the arcs c + r (cos t, sin t), t in [t_lo, t_hi]:
    the minimum at an arc end, an arc point where the arc crosses or faces a side, or a corner
    facing the arc; the maximum at a corner and an arc end or the arc point opposite it.

    Each candidate that lies on the arc of only some boxes (a corner's nearest or farthest arc
    point, a radius along an axis, a crossing of a side) is measured on those boxes alone.
    `index`: t_lo, t_hi hold distinct arcs and box j has arc index[j]: what depends on the arc
    alone (its ends, the axis directions it holds) is computed once per arc and gathered."""
    per_box = (lambda v: v) if index is None else (lambda v: np.take(v, index))
    ends = [(per_box(cx + r * np.cos(t)), per_box(cy + r * np.sin(t))) for t in (t_lo, t_hi)]
    axes = [per_box(angle_inside(k * _HALF_PI, t_lo, t_hi, 0.0)) for k in range(4)]
    t_lo, t_hi = per_box(t_lo), per_box(t_hi)
    # farthest: an arc end and a corner, or a corner and the arc point opposite it
    far = np.maximum(*(_farthest_corner(ex, ey, xlo, xhi, ylo, yhi) for ex, ey in ends))
    near = np.minimum(*(_box_distance(ex, ey, xlo, xhi, ylo, yhi) for ex, ey in ends))
    # nearest: an arc end, a corner facing the arc, an arc point facing a side (radius along an
    # axis), or a crossing of a side
    for px in (xlo, xhi):
        for py in (ylo, yhi):
            wx, wy = px - cx, py - cy
            psi = np.arctan2(wy, wx)
            faces = angle_inside(psi, t_lo, t_hi, 0.0)
            psi += math.pi
            opposite = angle_inside(psi, t_lo, t_hi, 0.0)
            at = np.flatnonzero(faces | opposite)
            if len(at):
                rho = np.hypot(wx[at], wy[at])
                near[at] = np.minimum(near[at], np.where(faces[at], np.abs(rho - r), np.inf))
                far[at] = np.maximum(far[at], np.where(opposite[at], rho + r, 0.0))
    for k in range(4):
        t = k * _HALF_PI
        _nearer(near, np.flatnonzero(axes[k]), cx + r * math.cos(t), cy + r * math.sin(t), xlo, xhi, ylo, yhi)
    # crossings of the horizontal sides (y = y0), then of the vertical ones (x = x0)
    for horizontal, sides, c_across, c_along in ((True, (ylo, yhi), cy, cx), (False, (xlo, xhi), cx, cy)):
        for side in sides:
            d = side - c_across
            at = np.flatnonzero(np.abs(d) <= r)
            d = d[at]
            half = np.sqrt(r * r - d * d)
            for sign in (-1.0, 1.0):
                along = sign * half
                ok = angle_inside(np.arctan2(d, along) if horizontal else np.arctan2(along, d), t_lo[at], t_hi[at], 0.0)
                px, py = c_along + along[ok], side[at[ok]]
                _nearer(near, at[ok], *((px, py) if horizontal else (py, px)), xlo, xhi, ylo, yhi)
    return near, far


def root_box(base, platform, reach, phi_range) -> tuple[tuple[float, float], tuple[float, float]] | None:
    """An (x, y) box holding every pose whose legs are within `reach` (the longest length of each
    leg) over the orientation range (degrees), or None when the legs never meet.

    The intersection over the legs of each arc's bounding box widened by its reach, padded for
    rounding and rounded outward to a dyadic step (so that libm differences in the last bit do not
    move it). Angles are taken after subtracting the multiple of 360 degrees below phi1.
    """
    turn = 360.0 * math.floor(phi_range[0] / 360.0)
    a1, a2 = (math.radians(p - turn) for p in phi_range)
    boxes = []
    for (bx, by), (px, py), rmax in zip(base, platform, reach):
        r = math.hypot(px, py)
        start = math.atan2(py, px) + math.pi
        xs, ys = arc_extent(start + a1, start + a2)
        boxes.append((bx + r * xs[0] - rmax, bx + r * xs[1] + rmax, by + r * ys[0] - rmax, by + r * ys[1] + rmax))
    xlo, xhi = max(b[0] for b in boxes), min(b[1] for b in boxes)
    ylo, yhi = max(b[2] for b in boxes), min(b[3] for b in boxes)
    if not (xlo < xhi and ylo < yhi):
        return None
    scale = max(abs(v) for b in boxes for v in b) + max(reach)
    pad = 1e-9 * scale
    step = 2.0 ** (math.floor(math.log2(max(xhi - xlo, yhi - ylo))) - 10)
    return tuple((math.floor((lo - pad) / step) * step, math.ceil((hi + pad) / step) * step)
                 for lo, hi in ((xlo, xhi), (ylo, yhi)))


def arc_extent(t1: float, t2: float) -> tuple[tuple[float, float], tuple[float, float]]:
    """Ranges of cos t and sin t over [t1, t2] (radians), from the ends and the extrema inside."""
    c = [math.cos(t1), math.cos(t2)]
    s = [math.sin(t1), math.sin(t2)]
    for k in range(math.ceil(t1 / (0.5 * math.pi)), math.floor(t2 / (0.5 * math.pi)) + 1):
        c.append(math.cos(k * 0.5 * math.pi))
        s.append(math.sin(k * 0.5 * math.pi))
    return (min(c), max(c)), (min(s), max(s))
