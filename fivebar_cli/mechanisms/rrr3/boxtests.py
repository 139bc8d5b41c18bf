"""Certified box tests of the 3-RRR over boxes of poses (x, y, phi), phi in degrees.

Leg i: the actuated joint at A_i, the elbow B_i = A_i + l1_i (cos theta_i, sin theta_i), the
platform point C_i = (x, y) + q_i with q_i = R(phi) c_i, and |C_i - B_i| = l2_i. With
d_i = C_i - A_i and rho_i = |d_i|:

- **valid** (reachable, serial-singularity free): |l1_i - l2_i| < rho_i < l1_i + l2_i for every
  leg, strictly (on the annulus' circles the leg is stretched or folded: a serial singularity).
  rho_i is the distance from (x, y) to A_i - q_i, which runs along an arc as phi sweeps a box:
  its exact range over a box (`numerics/platform.py`), moved out by ETA_REL x scale, decides.
- **working mode** s = (s_1, s_2, s_3): s_i is the sign of (B_i - A_i) x (C_i - B_i), with
  a x b = a_x b_y - a_y b_x. On a valid pose each sign picks one elbow: with
  P_i = rho_i^2 - l1_i^2 + l2_i^2 and Q_i = (rho_i^2 - (l1_i - l2_i)^2) ((l1_i + l2_i)^2 - rho_i^2) > 0,
  the distal link is e_i = C_i - B_i = (P_i d_i + s_i sqrt(Q_i) d_i^perp) / (2 rho_i^2),
  d^perp = (-d_y, d_x), and B_i = C_i - e_i.
- **det A**: A is the 3x3 matrix whose row i is (e_i, q_i x e_i) (the distal lines: det A = 0 when
  they are concurrent or parallel, a parallel singularity). Scaling row i by 2 rho_i^2 > 0 keeps
  the sign: rows (P d_x - s sqrt(Q) d_y, P d_y + s sqrt(Q) d_x, P (q x d) + s sqrt(Q) (q . d)),
  polynomials in the pose but for one square root each. Its sign over a box is certified with
  outward-rounded intervals: the natural enclosure, and where that is not enough and every pose
  of the box is valid (so the function is differentiable on it), the mean-value form
  (`numerics/gradients.py`), whose excess shrinks quadratically with the box.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np

from fivebar_cli.numerics import gradients as gr
from fivebar_cli.numerics import interval as iv
from fivebar_cli.numerics.interval import Interval
from fivebar_cli.numerics.platform import D2R, ETA_REL, Platform, leg_groups  # noqa: F401 (ETA_REL: the margin)
from fivebar_cli.numerics.verdict import verdict

_D2R = Interval(D2R * (1.0 - 4e-16), D2R * (1.0 + 4e-16))  # encloses pi / 180
WORKING_MODES = tuple("".join(s) for s in itertools.product("+-", repeat=3))  # +++, ++-, ..., ---


def signs_of(mode: str) -> tuple[int, int, int]:
    """'+-+' -> (1, -1, 1)."""
    return tuple(1 if c == "+" else -1 for c in mode)


@dataclass(frozen=True)
class Geometry(Platform):
    """The numbers the tests use (`numerics.platform.Platform`: base A, platform c, |c_i| and its
    angle, the shift of phi, the fixed phi, the margin), the link lengths l1, l2 (3,) and the
    annuli radii |l1 - l2| and l1 + l2, and outward-rounded constants for the intervals."""

    l1: np.ndarray
    l2: np.ndarray
    inner: np.ndarray
    outer: np.ndarray

    @classmethod
    def of(cls, m) -> "Geometry":
        l1, l2 = np.array(m.proximal, float), np.array(m.distal, float)
        return cls(**Platform.fields(m.base, m.platform, m.phi_range, float((l1 + l2).max())),
                   l1=l1, l2=l2, inner=np.abs(l1 - l2), outer=l1 + l2)

    def constants(self, i: int) -> tuple[Interval, Interval, Interval, Interval, Interval]:
        """Leg i's |c_i| and angle of c_i, l2^2 - l1^2, (l1 - l2)^2 and (l1 + l2)^2, as intervals
        (computed once per geometry: every det A evaluation takes them, on small sets of boxes)."""
        cache = self.__dict__.setdefault("_constant_cache", {})  # not a field: a frozen dataclass's cache
        if i not in cache:
            cache[i] = self._constants(i)
        return cache[i]

    def leg_constants(self, first: int = 0, stop: int = 3) -> tuple[Interval, ...]:
        """`constants` of legs first..stop-1 stacked as (k, 1) Intervals (the same bounds), and the
        base A of those legs as two (k, 1) arrays: det A evaluates several legs in one pass."""
        cache = self.__dict__.setdefault("_constant_cache", {})
        if (first, stop) not in cache:
            per_leg = list(zip(*(self.constants(i) for i in range(first, stop))))
            stacked = [Interval(np.array([c.lo for c in cs])[:, None], np.array([c.hi for c in cs])[:, None])
                       for cs in per_leg]
            base = self.base[first:stop].astype(float)
            cache[first, stop] = (*stacked, base[:, :1], base[:, 1:])
        return cache[first, stop]

    def _constants(self, i: int) -> tuple[Interval, Interval, Interval, Interval, Interval]:
        l1, l2 = Interval.point(self.l1[i]), Interval.point(self.l2[i])
        px, py = self.platform[i]
        a = math.atan2(py, px)
        return (iv.hypot(px, py), Interval(a - 1e-15, a + 1e-15), iv.sqr(l2) - iv.sqr(l1), iv.sqr(l1 - l2),
                iv.sqr(l1 + l2))


# ---------------------------------------------------------------- validity


def valid_status(g: Geometry, lo: np.ndarray, hi: np.ndarray, ends=None) -> np.ndarray:
    """1: every pose of each box has every leg strictly inside its annulus; -1: no pose has; 0: cannot tell
    (`ends`: the boxes' ends as tables, `grid.AxisEnds`, when the caller has them)."""
    def decide(i, near, far):
        near, far = near - g.eta, far + g.eta
        a, b = g.inner[i], g.outer[i]
        return (near > a) & (far < b), (far < a) | (near > b)

    return g.legs_verdict(lo, hi, decide, ends)


# ---------------------------------------------------------------- det A


def _det3(a, b, c):
    """det of the 3x3 matrix with rows a, b, c (each three entries; the first operand of every
    product is the row entry, so that Dual rows take Interval factors)."""
    return (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
            + a[2] * (b[0] * c[1] - b[1] * c[0]))


ONE_PASS = 8192  # up to this many boxes the three legs are evaluated as one (3, m) pass; beyond, leg by leg


def _det_a(g: Geometry, signs, x, y, phi, index=None):
    """det A, rows scaled by 2 rho_i^2 (module docstring), at (x, y, phi in degrees) given as
    Intervals or `gradients.Dual`s (x first in every sum, so that a Dual absorbs the constants),
    the legs in the passes of `platform.leg_groups`. `index`: phi (an Interval) holds distinct
    orientations and box j has phi[index[j]] (`_rows`)."""
    boxes = max(np.size((v.v if isinstance(v, gr.Dual) else v).lo) for v in (x, y, phi))
    boxes = boxes if index is None else len(index)
    rows = []
    for first, stop in leg_groups(boxes, ONE_PASS):
        columns = _rows(g, signs[first:stop], x, y, phi, first, stop, index)
        rows += [[column[k] for column in columns] for k in range(stop - first)]
    return _det3(*rows)


def _rows(g: Geometry, signs, x, y, phi, first: int, stop: int, index=None):
    """The three entries of the scaled rows of legs first..stop-1, each with those legs on its
    first axis. `index` (`_det_a`): q_x, q_y, which depend on phi alone, are computed once per
    orientation and gathered, the same bounds."""
    radius, angle, l21, inner2, outer2, base_x, base_y = g.leg_constants(first, stop)
    t = (phi - g.shift) * _D2R + angle
    c, s = gr.cos_sin(t)
    qx, qy = c * radius, s * radius
    if index is not None:
        qx, qy = qx.take(index), qy.take(index)
    dx = x - base_x + qx
    dy = y - base_y + qy
    rho2 = gr.sqr(dx) + gr.sqr(dy)
    p = rho2 + l21
    root = gr.negate_where(gr.sqrt(-((rho2 - inner2) * (rho2 - outer2))), np.array(signs)[:, None] < 0)
    cross = dy * qx - dx * qy
    dot = dx * qx + dy * qy
    return p * dx - root * dy, p * dy + root * dx, p * cross + root * dot


def _orientations(g: Geometry, lo: np.ndarray, hi: np.ndarray, ends) -> tuple[Interval, np.ndarray | None]:
    """The boxes' orientations for `_det_a`: the single orientation of a space of (x, y) boxes (one
    entry, which every box shares by broadcasting), the paving's table of them (`ends`,
    `grid.AxisEnds`) when shorter than the boxes with each box's entry, else each box's (None)."""
    if lo.shape[1] == 2:
        return Interval(np.full(1, g.phi), np.full(1, g.phi)), None
    phi = ends[2] if ends is not None else None
    if phi is not None and phi.shared:
        return Interval(phi.low, phi.high), phi.index
    return Interval(lo[:, 2], hi[:, 2]), None


def det_enclosure(g: Geometry, signs, lo: np.ndarray, hi: np.ndarray, valid: np.ndarray | None = None, ends=None):
    """Certified bounds of det A (rows scaled) in working mode `signs` over boxes (m, 2 or 3): the
    natural enclosure, tightened by the mean-value form on the boxes where it includes 0 and
    `valid` (every pose valid: the function is differentiable there) is set (`ends`: the boxes'
    ends as tables, `grid.AxisEnds`, when the caller has them: the same bounds)."""
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    box = [Interval(lo[:, k], hi[:, k]) for k in range(2)]
    natural = _det_a(g, signs, *box, *_orientations(g, lo, hi, ends))
    d_lo, d_hi = natural.lo.copy(), natural.hi.copy()
    if valid is not None:
        redo = np.flatnonzero(valid & (d_lo <= 0) & (d_hi >= 0))
        if len(redo):
            if lo.shape[1] == 3:
                f = lambda x, y, p: _det_a(g, signs, x, y, p)  # noqa: E731
            else:
                fixed = Interval.point(g.phi)
                f = lambda x, y: _det_a(g, signs, x, y, fixed)  # noqa: E731
            m_lo, m_hi = gr.mean_value(f, lo[redo], hi[redo])
            d_lo[redo], d_hi[redo] = np.maximum(d_lo[redo], m_lo), np.minimum(d_hi[redo], m_hi)
    return d_lo, d_hi


def det_sign(g: Geometry, signs, lo: np.ndarray, hi: np.ndarray, valid: np.ndarray | None = None,
             ends=None) -> np.ndarray:
    """+1 / -1 where det A (working mode `signs`) is certified positive / negative at every valid
    pose of the box, else 0 (`valid`, `ends` as in `det_enclosure`)."""
    d_lo, d_hi = det_enclosure(g, signs, lo, hi, valid, ends)
    return verdict(d_lo > 0, d_hi < 0)


def class_status(g: Geometry, signs, want: int, lo: np.ndarray, hi: np.ndarray, ends=None) -> np.ndarray:
    """1: every pose of each box is valid with det A of sign `want` in working mode `signs`;
    -1: no pose of the box is (invalid everywhere, or det A of the other sign); 0: cannot tell
    (`ends`: the boxes' ends as tables, `grid.AxisEnds`, when the caller has them)."""
    return class_statuses(g, (tuple(signs),), (want,), lo, hi, ends)[:, 0]


def class_statuses(g: Geometry, signs, wants, lo: np.ndarray, hi: np.ndarray, ends=None,
                   open_: np.ndarray | None = None) -> np.ndarray:
    """`class_status` of working mode `signs[c]` and sign `wants[c]` for each column c (statuses
    (n, len(wants))), sharing the validity test (of every working mode) and det A's sign (of one);
    `open_` (n, len(wants)): where a column is read (`paving.engine.MultiTest`), so that a working
    mode's det A is taken on the boxes open in its columns only (None: on every box)."""
    valid = valid_status(g, lo, hi, ends)
    some = valid != -1
    out = np.empty((len(lo), len(wants)), np.int8)
    for mode in dict.fromkeys(signs):
        columns = [c for c, s in enumerate(signs) if s == mode]
        rows = np.flatnonzero(some if open_ is None else some & open_[:, columns].any(axis=1))
        sign = np.zeros(len(lo), dtype=np.int8)
        if len(rows):
            sign[rows] = det_sign(g, mode, lo[rows], hi[rows], valid[rows] == 1, ends and tuple(e.rows(rows) for e in ends))
        for c in columns:
            out[:, c] = verdict((valid == 1) & (sign == wants[c]), (valid == -1) | (sign == -wants[c]))
    return out


# ---------------------------------------------------------------- floating point (reports, IKP, figures)


def elbows(g: Geometry, poses: np.ndarray, signs) -> np.ndarray:
    """B_i (m, 3, 2) of poses in working mode `signs` (NaN where a leg cannot reach)."""
    d, q = g.legs_and_arms(poses)
    rho2 = np.sum(d * d, axis=-1)
    p = rho2 - g.l1 ** 2 + g.l2 ** 2
    with np.errstate(invalid="ignore", divide="ignore"):
        root = np.sqrt((rho2 - g.inner ** 2) * (g.outer ** 2 - rho2)) * np.asarray(signs, float)
        perp = np.stack([-d[..., 1], d[..., 0]], -1)
        e = (p[..., None] * d + root[..., None] * perp) / (2.0 * rho2[..., None])
    return g.base[None] + d - e


def joint_angles(g: Geometry, poses: np.ndarray, signs) -> np.ndarray:
    """theta_i in degrees (m, 3), in [-180, 180), of poses in working mode `signs` (NaN: no elbow)."""
    u = elbows(g, poses, signs) - g.base[None]
    theta = np.degrees(np.arctan2(u[..., 1], u[..., 0]))
    return np.where(theta >= 180.0, theta - 360.0, theta)


def det_a(g: Geometry, poses: np.ndarray, signs) -> np.ndarray:
    """det A (unscaled rows (e_i, q_i x e_i)) at poses in working mode `signs`, in floating point."""
    d, q = g.legs_and_arms(poses)
    e = d - (elbows(g, poses, signs) - g.base[None])
    moment = q[..., 0] * e[..., 1] - q[..., 1] * e[..., 0]
    return np.linalg.det(np.concatenate([e, moment[..., None]], -1))
