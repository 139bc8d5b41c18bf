"""Where a 3-RRR can be assembled: a certified box test over the 3-torus of actuated angles.

For actuated angles theta the elbows B_i = A_i + l1_i (cos theta_i, sin theta_i) are fixed, and at
an orientation phi the platform origin X must lie on the three circles of centres
D_i = B_i - R(phi) c_i and radii l2_i. With v = D_2 - D_1, dd = |v|^2, the first two circles
cross where K = (dd - (l2_1 - l2_2)^2) ((l2_1 + l2_2)^2 - dd) >= 0, at

    X_s = D_1 + (P v + s sqrt(K) v^perp) / (2 dd),   P = dd + l2_1^2 - l2_2^2,  s = +1 or -1,

and the third passes through X_s when G_s = |W_s|^2 - (2 dd l2_3)^2 = 0, W_s = 2 dd (D_1 - D_3) +
P v + s sqrt(K) v^perp (G_s has the sign of |X_s - D_3|^2 - l2_3^2 where dd > 0). The robot
assembles at theta when some G_s vanishes with phi in the orientation range: a question in one
variable. For a box Theta of actuated angles, a branch and prune over pieces of the orientation
range decides, every enclosure (outward-rounded intervals) taken over the piece and Theta:

- a piece is **excluded** when the two circles never cross on it (K < 0), or neither G_s can vanish;
- the box is **assemblable** (1) when on some piece the circles always cross (K > 0, dd > 0) and a
  G_s takes certified opposite signs at the piece's two ends, for every theta of the box: X_s is
  then continuous along the piece and G_s vanishes in between (intermediate values);
- it is **not assemblable** (-1) when every piece is excluded;
- otherwise undetermined (0), once the pieces are a few levels narrower than the box, or when
  more pieces than a few per assembly mode are left (a box too wide for its enclosures to tell):
  near the joint space's boundary, where two assembly modes meet (det A = 0), neither can be proven.

Each of the three pairings of legs (first two circles, third leg) is tried: a piece is excluded
when one pairing excludes it, proven when one pairing proves it.
"""

from __future__ import annotations

import math

import numpy as np

from fivebar_cli.mechanisms.base import Axis
from fivebar_cli.mechanisms.rrr3.boxtests import D2R, Geometry
from fivebar_cli.mechanisms.rrr3.constraints import ACTUATED
from fivebar_cli.numerics import gradients as gr
from fivebar_cli.numerics import interval as iv
from fivebar_cli.numerics.interval import Interval

EXTRA_LEVELS = 2  # pieces are split until 2^EXTRA_LEVELS times narrower than the box (in radians)
MAX_LEVELS = 40
MAX_PIECES = 1 << 18  # pieces alive in one call: beyond, the boxes left are undetermined
MAX_PER_BOX = 24  # pieces alive for one box (a few per assembly mode): beyond, it is left undetermined


JOINT_AXES = tuple(Axis(f"theta{i}", -180.0, 180.0, "deg", periodic=True, label=rf"$\theta_{i}$") for i in (1, 2, 3))


def joint_axes(constraints) -> tuple[Axis, ...]:
    """The joint-space axes under the actuated limits: a limit of less than a turn makes its axis
    that interval (rounded inward by 4 ulp, so that the paving's widened boxes stay within it)."""
    axes = []
    for axis in JOINT_AXES:
        limit = constraints.limit(axis.name) if constraints else None
        if limit is None or limit.full_turn:
            axes.append(axis)
        else:
            lo, hi = limit.lo + 4 * abs(float(np.spacing(limit.lo))), limit.hi - 4 * abs(float(np.spacing(limit.hi)))
            axes.append(Axis(axis.name, lo, hi, "deg", label=axis.label))
    return tuple(axes)
ORDERS = ((0, 1, 2), (1, 2, 0), (2, 0, 1))  # (first circle, second circle, third leg): each pairing


def elbows(g: Geometry, t1, t2, t3) -> list[tuple]:
    """B_i = A_i + l1_i (cos t_i, sin t_i) for actuated angles in radians (Intervals or Duals)."""
    return [(gr.cos(t) * float(g.l1[i]) + float(g.base[i, 0]), gr.sin(t) * float(g.l1[i]) + float(g.base[i, 1]))
            for i, t in enumerate((t1, t2, t3))]


def branch_values(g: Geometry, elbow: list[tuple], phi, order=(0, 1, 2)):
    """(K, dd, G_+, G_-) of the module docstring for elbows B_i (Intervals or `gradients.Dual`s)
    and the orientation phi (radians, an Interval), with the legs taken in `order` (the first two
    circles, then the third leg)."""
    centres = []
    for i, (bx, by) in enumerate(elbow):
        radius, angle, *_ = g.constants(i)
        s = phi + angle
        centres.append((bx - iv.cos(s) * radius, by - iv.sin(s) * radius))
    (x1, y1), (x2, y2), (x3, y3) = (centres[i] for i in order)
    r1, r2, r3 = (Interval.point(g.l2[i]) for i in order)
    vx, vy = x2 - x1, y2 - y1
    dd = gr.sqr(vx) + gr.sqr(vy)
    k = -((dd - iv.sqr(r1 - r2)) * (dd - iv.sqr(r1 + r2)))
    p = dd + (iv.sqr(r1) - iv.sqr(r2))
    root = gr.sqrt(k)
    ux = (x1 - x3) * dd * 2.0 + p * vx
    uy = (y1 - y3) * dd * 2.0 + p * vy
    far = gr.sqr(dd * r3 * 2.0)
    plus = gr.sqr(ux - root * vy) + gr.sqr(uy + root * vx) - far
    minus = gr.sqr(ux + root * vy) + gr.sqr(uy - root * vx) - far
    return k, dd, plus, minus


def _sign_change(a: Interval | tuple, b: Interval | tuple) -> np.ndarray:
    """Certified opposite signs of two enclosures (Intervals or (lo, hi) pairs)."""
    (a_lo, a_hi), (b_lo, b_hi) = ((v.lo, v.hi) if isinstance(v, Interval) else v for v in (a, b))
    return ((a_lo > 0) & (b_hi < 0)) | ((a_hi < 0) & (b_lo > 0))


def _end_signs(g: Geometry, lo: np.ndarray, hi: np.ndarray, phi: np.ndarray, order) -> list:
    """Enclosures of G_+ and G_- at the orientations `phi` (points) over boxes of angles (radians),
    by mean-value forms (every G_s is differentiable there: the caller checked K > 0, dd > 0)."""
    return gr.mean_value(lambda a, b, c, f: branch_values(g, elbows(g, a, b, c), f, order)[2:], lo, hi,
                         Interval.point(phi))


def assembly_status(g: Geometry, phi_range: tuple[float, float], lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """1: every triple of actuated angles of each box (degrees) assembles with phi in the range;
    -1: none does; 0: cannot tell (module docstring)."""
    n = len(lo)
    status = np.zeros(n, np.int8)
    if n == 0:
        return status
    p1, p2 = (math.radians(p - g.shift) for p in phi_range)
    width = float(np.max(hi - lo)) * D2R
    levels = min(MAX_LEVELS, max(0, math.ceil(math.log2(max(p2 - p1, width) / width))) + EXTRA_LEVELS)
    rad_lo, rad_hi = np.radians(lo), np.radians(hi)
    centre = 0.5 * (rad_lo + rad_hi)
    owner, given_up = np.arange(n), np.zeros(n, bool)
    f_lo, f_hi = np.full(n, p1), np.full(n, p2)
    for level in range(levels + 1):
        over = elbows(g, *(Interval(rad_lo[owner, i], rad_hi[owner, i]) for i in range(3)))
        at = elbows(g, *(Interval.point(centre[owner, i]) for i in range(3)))
        keep = np.ones(len(owner), bool)
        for order in ORDERS:
            k, dd, plus, minus = branch_values(g, over, Interval(f_lo, f_hi), order)
            keep &= (k.hi >= 0) & (_holds_zero(plus) | _holds_zero(minus))
            rows = np.flatnonzero((k.lo > 0) & (dd.lo > 0) & keep & (status[owner] == 0))
            if len(rows):  # a sign change at the box's centre first (cheap), then over the whole box
                mid = [(bx[rows], by[rows]) for bx, by in at]
                ends = [branch_values(g, mid, Interval.point(f[rows]), order)[2:] for f in (f_lo, f_hi)]
                rows = rows[_sign_change(ends[0][0], ends[1][0]) | _sign_change(ends[0][1], ends[1][1])]
            if len(rows):
                box = owner[rows]
                ends = [_end_signs(g, rad_lo[box], rad_hi[box], f[rows], order) for f in (f_lo, f_hi)]
                proven = _sign_change(ends[0][0], ends[1][0]) | _sign_change(ends[0][1], ends[1][1])
                status[box[proven]] = 1
        left = np.zeros(n, bool)
        left[owner[keep]] = True
        status[~left & ~given_up & (status == 0)] = -1
        given_up |= np.bincount(owner[keep], minlength=n) > MAX_PER_BOX  # too many pieces: left undetermined
        keep &= (status[owner] == 0) & ~given_up[owner]
        if not keep.any() or level == levels or 2 * np.count_nonzero(keep) > MAX_PIECES:
            break
        mid = 0.5 * (f_lo[keep] + f_hi[keep])
        owner = np.repeat(owner[keep], 2)
        f_lo = np.column_stack([f_lo[keep], mid]).ravel()
        f_hi = np.column_stack([mid, f_hi[keep]]).ravel()
    return status


def _holds_zero(a: Interval) -> np.ndarray:
    return ~((a.lo > 0) | (a.hi < 0))


def assembly_test(m):
    """The joint space's box test (`assembly_status` over the whole orientation range). The actuated
    limits are the root box (`joint_axes`); passive limits and obstacles are not decided here: a
    box that assembles is then left undetermined (0), never claimed inside."""
    g = Geometry.of(m)
    c = m.constraints
    if c.obstacles or any(lim.name not in ACTUATED and not lim.full_turn for lim in c.limits):
        return lambda lo, hi: np.minimum(assembly_status(g, m.phi_range, lo, hi), 0).astype(np.int8)
    return lambda lo, hi: assembly_status(g, m.phi_range, lo, hi)

