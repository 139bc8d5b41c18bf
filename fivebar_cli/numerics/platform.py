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

from fivebar_cli.numerics.ranges import angle_inside

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
        out = []
        for i in range(3):
            cx, cy = self.base[i]
            r = self.radius[i]
            start = self.angle[i] + math.pi  # A_i - C_i + (x, y) = -R(phi) c_i
            t_lo = (lo[:, 2] - self.shift) * D2R + start - ANGLE_TOL
            t_hi = (hi[:, 2] - self.shift) * D2R + start + ANGLE_TOL
            out.append(rect_arc_distance(lo[:, 0], hi[:, 0], lo[:, 1], hi[:, 1], cx, cy, r, t_lo, t_hi))
        return out

    def legs_and_arms(self, poses: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """C_i - A_i and R(phi) c_i, each (m, 3, 2), at poses (m, 2 or 3), in floating point."""
        poses = self.poses(poses)
        phi = (poses[:, 2] - self.shift) * D2R
        c, s = np.cos(phi), np.sin(phi)
        q = np.stack([np.stack([c * px - s * py, s * px + c * py], -1) for px, py in self.platform], -2)
        return poses[:, None, :2] + q - np.asarray(self.base, float)[None], q


def _box_distance(px, py, xlo, xhi, ylo, yhi):
    """Distance from points to rectangles (exact up to rounding)."""
    dx = np.maximum(np.maximum(xlo - px, px - xhi), 0.0)
    dy = np.maximum(np.maximum(ylo - py, py - yhi), 0.0)
    return np.hypot(dx, dy)


def rect_arc_distance(xlo, xhi, ylo, yhi, cx, cy, r, t_lo, t_hi):
    """Range of |X - C| for X in the rectangles and C on the arcs c + r (cos t, sin t), t in [t_lo, t_hi]:
    the minimum at an arc end, an arc point where the arc crosses or faces a side, or a corner
    facing the arc; the maximum at a corner and an arc end or the arc point opposite it."""
    inf = np.inf
    ends = [(cx + r * np.cos(t), cy + r * np.sin(t)) for t in (t_lo, t_hi)]
    # farthest: a corner and the arc point opposite it, or an arc end
    far = np.zeros_like(xlo)
    near = np.full_like(xlo, inf)
    for px in (xlo, xhi):
        for py in (ylo, yhi):
            wx, wy = px - cx, py - cy
            rho, psi = np.hypot(wx, wy), np.arctan2(wy, wx)
            tip = np.where(angle_inside(psi + math.pi, t_lo, t_hi, 0.0), rho + r, 0.0)
            far = np.maximum(far, np.maximum(tip, np.maximum(*(np.hypot(px - ex, py - ey) for ex, ey in ends))))
            near = np.minimum(near, np.where(angle_inside(psi, t_lo, t_hi, 0.0), np.abs(rho - r), inf))
    # nearest: an arc end, an arc point facing a side (radius along an axis), or a crossing of a side
    candidates = list(ends)
    for k in range(4):
        t = k * _HALF_PI
        ok = angle_inside(t, t_lo, t_hi, 0.0)
        candidates.append((np.where(ok, cx + r * math.cos(t), np.nan), np.where(ok, cy + r * math.sin(t), np.nan)))
    with np.errstate(invalid="ignore"):
        for y0 in (ylo, yhi):  # horizontal sides
            dy = y0 - cy
            half = np.sqrt(r * r - dy * dy)
            for sx in (-1.0, 1.0):
                ok = angle_inside(np.arctan2(dy, sx * half), t_lo, t_hi, 0.0) & (np.abs(dy) <= r)
                candidates.append((np.where(ok, cx + sx * half, np.nan), np.where(ok, y0, np.nan)))
        for x0 in (xlo, xhi):  # vertical sides
            dx = x0 - cx
            half = np.sqrt(r * r - dx * dx)
            for sy in (-1.0, 1.0):
                ok = angle_inside(np.arctan2(sy * half, dx), t_lo, t_hi, 0.0) & (np.abs(dx) <= r)
                candidates.append((np.where(ok, x0, np.nan), np.where(ok, cy + sy * half, np.nan)))
    for px, py in candidates:
        d = _box_distance(px, py, xlo, xhi, ylo, yhi)
        near = np.minimum(near, np.where(np.isnan(d), inf, d))
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
