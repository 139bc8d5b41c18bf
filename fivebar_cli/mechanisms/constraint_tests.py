"""Certified statuses of joint limits and obstacles over boxes, for any kind: from the ranges of
the limited angles and the boxes of the links' ends a kind computes over its boxes (the
five-bar's `fivebar/constrained.py`, the 3-RRR's `rrr3/constrained.py`), 1 where every constraint
holds at every configuration, -1 where at each one some constraint fails, 0 otherwise; and the
pieces those ranges are built of (arcs, boxes of points along arcs, their intersections).

Margins: angle ranges widen by ANGLE_MARGIN (1e-8 rad) before deciding; obstacle distances by the
kind's margin `eta` (ETA_REL times the size of the mechanism and its obstacles).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from fivebar_cli.numerics.ranges import ANGLE_MARGIN, cos_sin_ranges
from fivebar_cli.numerics.verdict import verdict
from fivebar_cli.paving.engine import INSIDE, pave

TWO_PI = 2.0 * np.pi


def arc_status(lo, hi, arc_lo: float, arc_hi: float, margin: float = ANGLE_MARGIN) -> np.ndarray:
    """1 where every angle of [lo, hi] has a turn in the closed arc [arc_lo, arc_hi], -1 where none
    has, 0 otherwise; the range is widened by `margin` first."""
    if arc_hi - arc_lo >= TWO_PI:
        return np.ones(np.shape(lo), np.int8)
    lo, hi = lo - margin, hi + margin
    k = np.ceil((hi - arc_hi) / TWO_PI)
    inside = (arc_lo + k * TWO_PI <= lo) & (hi - lo < TWO_PI)
    j = np.floor((lo - arc_hi) / TWO_PI)
    outside = (lo > arc_hi + j * TWO_PI) & (hi < arc_lo + (j + 1) * TWO_PI)
    return verdict(inside, outside)


def scaled(bounds, f):
    """Exact range of L * f for L in `bounds` (> 0) and f in the range `f`."""
    lo, hi = bounds
    return np.minimum(lo * f[0], hi * f[0]), np.maximum(lo * f[1], hi * f[1])


def arc_box(lo, hi, length, trig=None):
    """The box of the points `length` (bounds) along the directions [lo, hi]: (lo corner, hi corner)."""
    c, s = cos_sin_ranges(lo, hi, trig)
    cx, cy = scaled(length, c), scaled(length, s)
    return np.column_stack([cx[0], cy[0]]), np.column_stack([cx[1], cy[1]])


def meet(a, b):
    """The intersection of two boxes that both hold every possible point (a point box where they
    miss each other: no configuration exists there, and any answer is right)."""
    lo, hi = np.maximum(a[0], b[0]), np.minimum(a[1], b[1])
    empty = lo > hi
    mid = 0.5 * (lo + hi)
    return np.where(empty, mid, lo), np.where(empty, mid, hi)


def plus(a, s: int, g):
    """The range of a + s g (s = +1 or -1) from the ranges of a and g."""
    return (a[0] + g[0], a[1] + g[1]) if s > 0 else (a[0] - g[1], a[1] - g[0])


def included_angle_range(s, a, b):
    """Exact range of the angle between sides a and b (bounds) of a triangle whose opposite side is
    s (range): arccos((a^2 + b^2 - s^2) / (2 a b)). The cosine decreases in s; for a fixed s its
    extremes over the (a, b) rectangle lie at corners or at a* = sqrt(b^2 - s^2), b* = sqrt(a^2 - s^2)
    on the edges (no interior critical point for s > 0). Cosines are clipped to [-1, 1] where the
    triangle cannot close."""
    if a[0] == a[1] and b[0] == b[1]:  # exact lengths: monotone in s
        x, y = a[0], b[0]
        return (np.arccos(np.clip((x * x + y * y - s[0] * s[0]) / (2 * x * y), -1, 1)),
                np.arccos(np.clip((x * x + y * y - s[1] * s[1]) / (2 * x * y), -1, 1)))

    def cosines(z):
        values = []
        with np.errstate(divide="ignore", invalid="ignore"):
            for x in a:
                for y in b:
                    values.append((x * x + y * y - z * z) / (2 * x * y))
            for fixed, other in ((a, b), (b, a)):
                for x in fixed:
                    star = np.sqrt(np.maximum(x * x - z * z, 0.0))
                    inside = (x > z) & (other[0] <= star) & (star <= other[1])
                    y = np.where(inside, star, other[0])
                    values.append(np.where(inside, (x * x + y * y - z * z) / (2 * x * y), np.nan))
        return np.stack(values)

    with np.errstate(invalid="ignore"):
        cmax = np.nanmax(cosines(s[0]), axis=0)
        cmin = np.nanmin(cosines(s[1]), axis=0)
    return np.arccos(np.clip(cmax, -1, 1)), np.arccos(np.clip(cmin, -1, 1))


def constraint_status(c, angles: dict, links, eta: float) -> np.ndarray:
    """1 / -1 / 0 per box for the constraints `c`: `angles[name]` = (lo, hi) radians of each limited
    angle the kind's space does not handle itself (a limit without a range is skipped), `links` the
    (start, end) pairs of (lo corner, hi corner) boxes of each link's ends (used with obstacles)."""
    n = len(next(iter(angles.values()))[0]) if angles else len(links[0][0][0])
    all_hold = np.ones(n, bool)
    some_fails = np.zeros(n, bool)
    for lim in c.limits:
        if lim.name not in angles:
            continue
        s = arc_status(*angles[lim.name], *lim.radians)
        all_hold &= s == 1
        some_fails |= s == -1
    if c.obstacles:
        for (lo1, hi1), (lo2, hi2) in links:
            c1, h1, c2, h2 = 0.5 * (lo1 + hi1), 0.5 * (hi1 - lo1), 0.5 * (lo2 + hi2), 0.5 * (hi2 - lo2)
            for o in c.obstacles:
                lower, upper = o.bounds(c1, h1, c2, h2, enough=c.clearance + eta)
                all_hold &= lower > c.clearance + eta
                some_fails |= upper < c.clearance - eta
    return np.where(some_fails, -1, np.where(all_hold, 1, 0)).astype(np.int8)


def restricted(base: np.ndarray, constraint) -> np.ndarray:
    """A test's answers restricted to the constraints: -1 where the constraints fail everywhere,
    1 and BAND (interval lengths: nowhere robust, possibly valid everywhere) only where the
    constraints hold everywhere, else 0. `constraint(mask)` gives the constraint status of the
    boxes selected by `mask` (only those the test did not already answer -1 are evaluated)."""
    out = base.copy()
    todo = base != -1
    if todo.any():
        c = constraint(todo)
        out[todo] = np.where(c == -1, -1, np.where(c == 1, out[todo], 0))
    return out.astype(np.int8)


class _Inside(Exception):
    """A box certified inside: the paving `paved_empty` watches need not go on."""


def paved_empty(grid, test) -> bool:
    """Whether every cell of a paving of `grid` by `test` is certified outside. The paving stops at
    the first box certified inside (the answer is then no): a mechanism whose constraints leave
    room, the usual case, is told so at a fraction of a whole paving's cost."""
    def watched(lo, hi):
        status = test(lo, hi)
        if np.any(status == INSIDE):
            raise _Inside
        return status

    try:
        paving = pave(grid, watched)
    except _Inside:
        return False
    return len(paving.undetermined) == 0 and len(paving.band) == 0


def empty_problem(m, leaves_nothing, what: str) -> tuple[str, str] | None:
    """(field, message) when the constraints of `m` are certified to leave no configuration
    (`leaves_nothing(model)`: the kind's small certified paving), naming the constraint that alone
    empties it (or all of them together), else None; `what` names the kind in the message."""
    c = m.constraints
    if not c or not leaves_nothing(m):
        return None
    fields = c.fields()
    for k, label in enumerate(c.labels()):
        if leaves_nothing(replace(m, constraints=c.only(k))):
            return fields[k], f"the {label} alone leaves no configuration of this {what}"
    return "limits", f"the limits and obstacles together leave no configuration of this {what}"
