"""Exact ranges of elementary functions over boxes, vectorised over arrays of boxes.

Box tests are only as tight as the ranges they decide from; these are exact (the true minimum and
maximum over the box, up to float rounding), not interval-arithmetic enclosures: extrema of a
sinusoid over an angle interval, the direction of a vector over a box of vectors, the angle of a
triangle with one side of variable length, the distance from a point to a box. Callers add the
safety margins that cover rounding before they decide anything.
"""

from __future__ import annotations

import numpy as np

TWO_PI = 2.0 * np.pi
ANGLE_TOL = 1e-12  # an extremum of a sinusoid counts as inside an interval within this tolerance
ANGLE_MARGIN = 1e-8  # radians: covers the rounding of atan2 / arccos where a sign of sin is decided


def angle_inside(angle, lo, hi, tol: float = ANGLE_TOL) -> np.ndarray:
    """Whether some angle + 2 k pi lies in [lo - tol, hi + tol] (elementwise)."""
    if tol:  # (tol 0: lo - 0 and hi + 0 are lo and hi, compared alike; not copied)
        lo, hi = lo - tol, hi + tol
    k = np.subtract(lo, angle)
    if k.ndim == 0:
        return angle + np.ceil(k / TWO_PI) * TWO_PI <= hi
    k /= TWO_PI  # in place, the same operations in the same order: a hot path of the box tests
    np.ceil(k, out=k)
    k *= TWO_PI
    k += angle
    return k <= hi


def sinusoid_range(a, b, lo, hi, trig=None, psi=None, tol: float = ANGLE_TOL) -> tuple[np.ndarray, np.ndarray]:
    """Exact range of a cos t + b sin t for t in [lo, hi] (elementwise, any width).

    `trig` = (cos lo, sin lo, cos hi, sin hi) and `psi` = arctan2(b, a) (where the maximum lies)
    when the caller has them already. The amplitude hypot(a, b) is taken only where an extremum
    lies inside (few boxes when a, b are arrays). `tol`: `angle_inside`'s tolerance (a caller
    with `trig` may pass lo - tol, hi + tol, widened once for several sinusoids, and 0).
    """
    c_lo, s_lo, c_hi, s_hi = trig if trig is not None else (np.cos(lo), np.sin(lo), np.cos(hi), np.sin(hi))
    psi = np.arctan2(b, a) if psi is None else psi
    f_lo = a * c_lo + b * s_lo
    f_hi = a * c_hi + b * s_hi
    top = np.maximum(f_lo, f_hi)
    bottom = np.minimum(f_lo, f_hi)
    up, down = angle_inside(psi, lo, hi, tol), angle_inside(psi + np.pi, lo, hi, tol)
    if np.ndim(a) == 0 and np.ndim(b) == 0:
        amp = np.hypot(a, b)
        return np.where(down, -amp, bottom), np.where(up, amp, top)
    a, b = np.broadcast_to(a, np.shape(top)), np.broadcast_to(b, np.shape(top))
    top[up] = np.hypot(a[up], b[up])
    bottom[down] = -np.hypot(a[down], b[down])
    return bottom, top


def cos_sin_ranges(lo, hi, trig=None):
    """Exact ranges ((cos min, cos max), (sin min, sin max)) over [lo, hi], from their values at
    the ends (`trig` = (cos lo, sin lo, cos hi, sin hi) when the caller has them)."""
    c_lo, s_lo, c_hi, s_hi = trig if trig is not None else (np.cos(lo), np.sin(lo), np.cos(hi), np.sin(hi))
    cmin, cmax = np.minimum(c_lo, c_hi), np.maximum(c_lo, c_hi)
    smin, smax = np.minimum(s_lo, s_hi), np.maximum(s_lo, s_hi)
    return ((np.where(angle_inside(np.pi, lo, hi), -1.0, cmin), np.where(angle_inside(0.0, lo, hi), 1.0, cmax)),
            (np.where(angle_inside(-0.5 * np.pi, lo, hi), -1.0, smin),
             np.where(angle_inside(0.5 * np.pi, lo, hi), 1.0, smax)))


def direction_range(xlo, xhi, ylo, yhi) -> tuple[np.ndarray, np.ndarray]:
    """Exact range of the direction atan2(y, x) over boxes of vectors (width 2 pi if a box holds 0).

    A box not containing the origin is seen under an angle below pi, spanned by its corners;
    angles are unwrapped around the direction of the box centre.
    """
    centre = np.arctan2(0.5 * (ylo + yhi), 0.5 * (xlo + xhi))
    lo = hi = None
    for x in (xlo, xhi):
        for y in (ylo, yhi):
            off = _centred(np.arctan2(y, x), centre)
            lo, hi = (off, off.copy()) if lo is None else (np.minimum(lo, off, out=lo), np.maximum(hi, off, out=hi))
    origin = (xlo <= 0) & (xhi >= 0) & (ylo <= 0) & (yhi >= 0)
    lo += centre
    hi += centre
    if origin.any():
        lo[origin] = (centre - np.pi)[origin]
        hi[origin] = (centre + np.pi)[origin]
    return lo, hi


def _centred(angle: np.ndarray, centre: np.ndarray) -> np.ndarray:
    """(angle - centre + pi) % 2 pi - pi, in place in `angle` (a temporary), for angle and centre
    in [-pi, pi] (atan2's): `wrap_angle`'s floats, its remainder taken without fmod (below)."""
    angle -= centre
    angle += np.pi  # in [-pi, 3 pi]: fmod(x, 2 pi) is x - 2 pi (exact) from 2 pi on, else x
    if angle.size and not (angle.min() >= 0 and angle.max() < TWO_PI):  # (often none: no box
        high = angle >= TWO_PI  # across the branch cut; two reductions cost less than the corrections)
        angle += (angle < 0) * TWO_PI  # (x + 0 turns -0 into +0: the same -pi below)
        angle -= high * TWO_PI
    angle -= np.pi
    return angle


def wrap_angle(angle, out=None) -> np.ndarray:
    """(angle + pi) % 2 pi - pi, the same floats (numpy's float remainder is fmod, plus the divisor
    where fmod is negative; +0 where it is 0, which - pi makes the same) at a fifth of its cost;
    `out`: an array to write into (`angle` itself, when it is a temporary)."""
    if np.ndim(angle) == 0:
        return (angle + np.pi) % TWO_PI - np.pi
    out = np.add(angle, np.pi, out=out)
    np.fmod(out, TWO_PI, out=out)
    np.add(out, TWO_PI, out=out, where=out < 0)
    out -= np.pi
    return out


def triangle_angle_range(side_lo, side_hi, adjacent: float, opposite: float):
    """Range of the angle between a side of variable length s in [side_lo, side_hi] and the side
    `adjacent` of a triangle whose third side is `opposite`: arccos((s^2 + a^2 - o^2) / (2 a s)).

    The cosine (s^2 + c) / (2 a s), c = a^2 - o^2, has its only minimum at s = sqrt(c) when c > 0.
    Only lengths where the triangle closes are meaningful; the caller clips s to them.
    """
    c = adjacent * adjacent - opposite * opposite

    def cosine(s):
        with np.errstate(divide="ignore", invalid="ignore"):
            return (s * s + c) / (2.0 * adjacent * s)

    ends = [cosine(side_lo), cosine(side_hi)]
    cmin, cmax = np.minimum(*ends), np.maximum(*ends)
    if c > 0:
        star = np.sqrt(c)
        inside = (side_lo <= star) & (star <= side_hi)
        cmin = np.where(inside, np.minimum(cmin, cosine(star)), cmin)
    # clipped to [-1, 1], a NaN (no triangle) as the widest end: fmax / fmin skip NaNs
    cmin = np.minimum(np.fmax(cmin, -1.0), 1.0)
    cmax = np.maximum(np.fmin(cmax, 1.0), -1.0)
    return np.arccos(cmax), np.arccos(cmin)


def sin_sign(lo, hi, margin: float = ANGLE_MARGIN) -> np.ndarray:
    """+1 / -1 where sin is positive / negative on all of [lo - margin, hi + margin], else 0."""
    lo, hi = lo - margin, hi + margin
    k = np.floor(lo / np.pi)
    inside = (lo > k * np.pi) & (hi < (k + 1) * np.pi)
    half = k * 0.5  # k is a whole number where inside: odd where half is not (exact, unlike np.mod's cost)
    odd = np.floor(half) != half
    return (inside & ~odd).view(np.int8) - (inside & odd).view(np.int8)


def point_box_distance2(cx: float, cy: float, lo: np.ndarray, hi: np.ndarray):
    """Exact range of the squared distance from (cx, cy) to the points of each box (2-D)."""
    (near_x, far_x), (near_y, far_y) = axis_distance2(cx, lo[:, 0], hi[:, 0]), axis_distance2(cy, lo[:, 1], hi[:, 1])
    return near_x + near_y, far_x + far_y


def axis_distance2(c: float, lo: np.ndarray, hi: np.ndarray):
    """The squares of the nearest and farthest offsets from c of the intervals [lo, hi] (one axis's
    part of a squared distance from a point to boxes)."""
    near = np.clip(c, lo, hi) - c
    far = np.maximum(np.abs(lo - c), np.abs(hi - c))
    return near * near, far * far


def circle_intersections(c1, r1: float, c2, r2: float) -> list[tuple[float, float]]:
    """Exact intersection points of two circles (tangent circles give one point, r = 0 is a point).

    Unlike `arcs.circle_intersections`, nothing is snapped: box tests use these points as the
    anchors and critical points of exact ranges.
    """
    (x1, y1), (x2, y2) = c1, c2
    dx, dy = x2 - x1, y2 - y1
    d = float(np.hypot(dx, dy))
    if d == 0 or d > r1 + r2 or d < abs(r1 - r2):
        return []
    a = (d * d + r1 * r1 - r2 * r2) / (2 * d)
    h = float(np.sqrt(max(r1 * r1 - a * a, 0.0)))
    mx, my = x1 + a * dx / d, y1 + a * dy / d
    pts = {(mx - h * dy / d, my + h * dx / d), (mx + h * dy / d, my - h * dx / d)}
    return sorted(pts)
