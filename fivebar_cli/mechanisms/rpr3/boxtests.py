"""Certified box tests of the 3-RPR over boxes of poses (x, y, phi), phi in degrees.

With q_i = R(phi) P_i (platform point i relative to the platform origin, in the fixed frame) and
the leg vector e_i = (x, y) + q_i - B_i:

- **reachable**: rho_min_i <= |e_i| <= rho_max_i for the three legs. For a box, |e_i| is the
  distance from a point X of the rectangle [x] x [y] to the point C_i(phi) = B_i - q_i, which runs
  along an arc of radius |P_i| about B_i: the exact range of the distance between a rectangle and
  an arc (the minimum at an arc end, an arc point where the arc crosses or faces a side, or a
  corner facing the arc; the maximum at a corner and an arc end or the arc point opposite it).
  Distances are moved out by ETA_REL x scale and arc ends by ANGLE_TOL before deciding, far above
  their rounding. A box is outside when one leg is out of range at all of its poses.
- **det J**, sign convention: J is the 3x3 matrix whose row i is (e_ix, e_iy, q_i x e_i), with
  a x b = a_x b_y - a_y b_x, so that J (x', y', phi') = (rho_1 rho_1', rho_2 rho_2', rho_3 rho_3')
  with phi' in rad/s. Its sign over a box is certified with outward-rounded interval arithmetic
  (`numerics/interval.py`): the natural enclosure intersected with the mean-value form
  det(mid) + grad(box) . (box - mid), whose excess shrinks quadratically with the box.

A region test returns 1 when every pose of the box is in the region, -1 when none is, 0 otherwise:
reachable; "singularity-free det J > 0" (reachable and det J > 0: outside when unreachable or
det J < 0 on the whole box); "singularity-free det J < 0" likewise.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from fivebar_cli.numerics import interval as iv
from fivebar_cli.numerics.interval import Interval
from fivebar_cli.numerics.platform import ETA_REL, D2R, Platform, leg_groups, legs_apart  # noqa: F401 (ETA_REL: the margin, as before)
from fivebar_cli.numerics.verdict import verdict

REACHABLE = "reachable"  # the regions a box test decides (the `region:` of the .qt files)
PLUS = "singularity-free det J > 0"
MINUS = "singularity-free det J < 0"

_D2R = Interval(D2R * (1.0 - 4e-16), D2R * (1.0 + 4e-16))  # encloses pi / 180


@dataclass(frozen=True)
class Geometry(Platform):
    """The numbers the tests use (`numerics.platform.Platform`: base B, platform P, |P_i| and
    its angle, the shift of phi, the fixed phi, the margin) and the leg limits, as arrays."""

    rho_min: np.ndarray
    rho_max: np.ndarray

    @classmethod
    def of(cls, m) -> "Geometry":
        rho_min, rho_max = (np.array(v, float) for v in m.leg_limits())
        return cls(**Platform.fields(m.base, m.platform, m.phi_range, rho_max.max()), rho_min=rho_min, rho_max=rho_max)


# ---------------------------------------------------------------- reachability


def leg_distance_ranges(g: Geometry, lo: np.ndarray, hi: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
    """Exact (min, max) of each leg length over boxes (m, 3), before margins."""
    return g.distance_ranges(lo, hi)


def reach_status(g: Geometry, lo: np.ndarray, hi: np.ndarray, ends=None) -> np.ndarray:
    """1: every pose of each box has its three legs in range; -1: no pose has; 0: cannot tell
    (`ends`: the boxes' ends as tables, `grid.AxisEnds`, when the caller has them)."""
    def decide(i, near, far):
        near, far = np.maximum(near - g.eta, 0.0), far + g.eta
        a, b = g.rho_min[i], g.rho_max[i]
        return (near >= a) & (far <= b), (far < a) | (near > b)

    return g.legs_verdict(lo, hi, decide, ends)


# ---------------------------------------------------------------- det J


def _minors(a, b):
    """The 2x2 minors of the columns a, b that `_det3` takes with the entries of its third column."""
    return a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]


def _det3(a, b, c, minors=None):
    """det of the 3x3 matrix with columns a, b, c (lists of three row entries); `minors` of a, b
    when the caller has them (the same values: several determinants share the columns e_x, e_y)."""
    m = _minors(a, b) if minors is None else minors
    return c[0] * m[0] + c[1] * m[1] + c[2] * m[2]


ONE_PASS = 2048  # up to this many boxes the three legs are evaluated as one (3, n) pass; beyond, leg by leg


def _columns(g: Geometry, x: Interval, y: Interval, phi_deg: Interval, index=(None, None, None)):
    """Interval columns of J and the pieces its derivatives need: e_x, e_y, q x e, q_x, q_y, u, v,
    each a list of the three legs' intervals (`_leg_passes`)."""
    return legs_apart(_leg_passes(g, x, y, phi_deg, index), 7)


def _leg_passes(g: Geometry, x: Interval, y: Interval, phi_deg: Interval, index=(None, None, None)) -> list[tuple]:
    """e_x, e_y, q x e, q_x, q_y, u, v with the legs on a first axis ((k, n) Intervals), in the
    passes of `platform.leg_groups` (the legs' constants are (k, 1) columns). `index`: per axis,
    None (x, y, phi_deg hold each box's interval) or each box's entry in the axis's distinct
    intervals (`_axes`): what depends on one axis alone (u, v; q_x, q_y) is computed once per
    entry and gathered, the same bounds."""
    ix, iy, ip = index
    ph = (phi_deg - g.shift) * _D2R
    out = []
    for first, stop in leg_groups(len(x.lo) if ix is None else len(ix), ONE_PASS):
        legs = slice(first, stop)
        radius, angle = (v[legs] for v in _leg_constants(g))
        base = np.asarray(g.base, float)[legs]
        c, s = iv.cos_sin(ph + angle)
        qx, qy = _gather(radius * c, ip), _gather(radius * s, ip)
        u, v = _gather(x - base[:, :1], ix), _gather(y - base[:, 1:], iy)
        out.append((u + qx, v + qy, qx * v - qy * u, qx, qy, u, v))
    return out


def _gather(a: Interval, index) -> Interval:
    """Each box's interval from the entries `a` (last axis) of `index` (None: `a` has them)."""
    return a if index is None else a.take(index)


def _axes(g: Geometry, lo: np.ndarray, hi: np.ndarray, ends) -> tuple[list[Interval], list]:
    """The intervals of the axes x, y, phi of boxes (m, 2 or 3) and their index (`_leg_passes`): per
    axis the paving's table of its distinct intervals (`ends`, `grid.AxisEnds`) when shorter than
    the boxes, else each box's interval (index None); boxes of (x, y) share the fixed phi (one entry)."""
    n = len(lo)
    fixed = lo.shape[1] == 2
    lo, hi = g.poses(lo), g.poses(hi)
    axes, index = [Interval(lo[:, k], hi[:, k]) for k in range(3)], [None] * 3
    for k, e in enumerate(ends or ()):
        if e.shared:
            axes[k], index[k] = Interval(e.low, e.high), e.index
    if fixed:
        axes[2], index[2] = Interval(np.full(1, g.phi), np.full(1, g.phi)), np.zeros(n, np.intp)
    return axes, index


def _leg_constants(g: Geometry) -> tuple[Interval, Interval]:
    """|P_i| and the angle of P_i (within 1e-15) as (3, 1) Intervals, each computed from the leg's
    two floats alone (once per geometry: a frozen dataclass's cache, not a field)."""
    cache = g.__dict__.setdefault("_leg_constant_cache", {})
    if not cache:
        radii = [iv.hypot(px, py) for px, py in g.platform]
        a = np.array([[math.atan2(py, px)] for px, py in g.platform])
        cache["radius"] = Interval(np.array([[r.lo] for r in radii], float), np.array([[r.hi] for r in radii], float))
        cache["angle"] = Interval(a - 1e-15, a + 1e-15)
    return cache["radius"], cache["angle"]


def det_enclosure(g: Geometry, lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Certified bounds of det J over boxes (m, 3): natural enclosure and mean-value form intersected."""
    return _det_bounds(g, lo, hi, everywhere=True)


def det_sign(g: Geometry, lo: np.ndarray, hi: np.ndarray, ends=None) -> np.ndarray:
    """+1 / -1 where det J is certified positive / negative on the whole box, else 0 (`ends`: the
    boxes' ends as tables, `grid.AxisEnds`, when the caller has them)."""
    dlo, dhi = _det_bounds(g, lo, hi, everywhere=False, ends=ends)
    return verdict(dlo > 0, dhi < 0)


def _det_bounds(g: Geometry, lo: np.ndarray, hi: np.ndarray, everywhere: bool, ends=None) -> tuple[np.ndarray, np.ndarray]:
    """`det_enclosure`, or (not `everywhere`) with the mean-value form only on the boxes whose
    natural enclosure has no sign: elsewhere it cannot change the sign (both forms enclose det J)
    and it costs most of the work. Every operation is elementwise: the same values on those boxes,
    and the same values whether an axis comes as a table (`_axes`) or box by box."""
    axes, index = _axes(g, np.asarray(lo, float), np.asarray(hi, float), ends)
    columns = _columns(g, *axes, index)
    minors = _minors(*columns[:2])
    natural = _det3(*columns[:3], minors)
    if everywhere:
        mean = _mean_value(g, axes, index, columns, minors)
        return np.maximum(natural.lo, mean.lo), np.minimum(natural.hi, mean.hi)
    d_lo, d_hi = natural.lo.copy(), natural.hi.copy()
    at = np.flatnonzero(~((d_lo > 0) | (d_hi < 0)))
    if len(at):
        pick = lambda items: [v[at] for v in items]  # noqa: E731
        axes = [a if i is not None else a[at] for a, i in zip(axes, index)]
        index = [i if i is None else i[at] for i in index]
        mean = _mean_value(g, axes, index, [pick(c) for c in columns], pick(minors))
        d_lo[at], d_hi[at] = np.maximum(d_lo[at], mean.lo), np.minimum(d_hi[at], mean.hi)
    return d_lo, d_hi


def _mean_value(g: Geometry, axes, index, columns, minors) -> Interval:
    """The mean-value form det(mid) + grad(box) . (box - mid) of det J, given the boxes' axes and
    their index (`_axes`), the box's columns and the minors of e_x, e_y."""
    ex, ey, mm, qx, qy, u, v = columns
    mid = [0.5 * (a.lo + a.hi) for a in axes]
    point = _det3(*_columns(g, *(Interval.point(m) for m in mid), index)[:3])
    offset = [_gather(a - m, i) for a, m, i in zip(axes, mid, index)]  # box - mid
    one = [Interval.point(1.0)] * 3
    minus_qy = [-q for q in qy]
    gx = _det3(one, ey, mm) + _det3(ex, ey, minus_qy, minors)
    gy = _det3(ex, one, mm) + _det3(ex, ey, qx, minors)
    dm = [-(qx[i] * u[i] + qy[i] * v[i]) for i in range(3)]
    gp = (_det3(minus_qy, ey, mm) + _det3(ex, qx, mm) + _det3(ex, ey, dm, minors)) * _D2R
    return point + gx * offset[0] + gy * offset[1] + gp * offset[2]


def _legs_and_arms(m, poses: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Leg vectors e_i and arms q_i = R(phi) P_i, each (m, 3, 2), at poses (m, 3) in floating point."""
    g = Geometry.of(m) if not isinstance(m, Geometry) else m
    return g.legs_and_arms(poses)


def det_j(m, poses: np.ndarray) -> np.ndarray:
    """det J at poses (m, 3) in floating point (for reports; certified signs come from the box tests)."""
    e, q = _legs_and_arms(m, poses)
    moment = q[..., 0] * e[..., 1] - q[..., 1] * e[..., 0]
    return np.linalg.det(np.concatenate([e, moment[..., None]], -1))


def leg_lengths(m, poses: np.ndarray) -> np.ndarray:
    """Leg lengths (m, 3) at poses (m, 3) in floating point."""
    e, _ = _legs_and_arms(m, poses)
    return np.hypot(e[..., 0], e[..., 1])


# ---------------------------------------------------------------- region tests


def region_test(m, region: str):
    """The box test of one region of the workspace (see the module docstring)."""
    g = Geometry.of(m)
    if region == REACHABLE:
        return lambda lo, hi, ends=None: reach_status(g, lo, hi, ends)
    want = _want(region)

    def test(lo: np.ndarray, hi: np.ndarray, ends=None) -> np.ndarray:
        return _status(*_reach_and_sign(g, lo, hi, ends), want)

    return test


def region_tests(m, regions):
    """The box tests of several regions PLUS / MINUS at once (a `paving.engine.MultiTest`: statuses
    (n, len(regions)), column c that of `region_test(m, regions[c])`), sharing the reach test and
    det J's sign: the pavings of both signs test the same boxes down to where they part."""
    g = Geometry.of(m)
    wants = [_want(region) for region in regions]

    def test(lo: np.ndarray, hi: np.ndarray, open_=None, ends=None) -> np.ndarray:
        reach, sign = _reach_and_sign(g, lo, hi, ends)
        return np.column_stack([_status(reach, sign, want) for want in wants])

    return test


def _want(region: str) -> int:
    """The sign of det J of a singularity-free region (KeyError for another region)."""
    if region not in (PLUS, MINUS):
        raise KeyError(region)
    return 1 if region == PLUS else -1


def _reach_and_sign(g: Geometry, lo: np.ndarray, hi: np.ndarray, ends) -> tuple[np.ndarray, np.ndarray]:
    """`reach_status` of boxes, and `det_sign` where some pose may be reachable (0 elsewhere)."""
    reach = reach_status(g, lo, hi, ends)
    sign = np.zeros(len(lo), dtype=np.int8)
    some = np.flatnonzero(reach != -1)
    if len(some):
        sign[some] = det_sign(g, lo[some], hi[some], ends and tuple(e.rows(some) for e in ends))
    return reach, sign


def _status(reach: np.ndarray, sign: np.ndarray, want: int) -> np.ndarray:
    """A singularity-free region's status from the boxes' reach and sign of det J (the two cases
    exclude each other: `verdict`'s order does not matter)."""
    return verdict((reach == 1) & (sign == want), (reach == -1) | (sign == -want))
