"""Box tests of a five-bar whose link lengths are intervals (manufacturing tolerances).

A box is *robust* (1) when every point of it is valid for every length vector of the length box,
*impossible* (-1) when no point of it is valid for any length vector, and 0 otherwise. `m` is a
`FiveBar` with interval lengths: `m.bounds[k] = (lo, hi)` for L0 .. L4 and the nominal lengths
(the midpoints) in `m.L0 .. m.L4`.

Exact where the geometry allows it, first-order exact elsewhere:

- Workspace. A1 is fixed, so |P - A1| has its exact range over the box; A2 = (L0, 0) moves along
  the segment S = [l0, u0] x {0}, so P - A2 ranges over the box widened in x by the segment: the
  exact range of |P - A2| is that of the widened box. The worst radii of an annulus over the length
  box are the corners: robust needs |L_i - L_j| <= r <= L_i + L_j for every L, i.e. r in
  [max |L_i - L_j|, l_i + l_j]; some L allows r in [min |L_i - L_j|, u_i + u_j].
- Joint space. d = |B1B2| = |v|, v = (L0 + L2 cos th2 - L1 cos th1, L2 sin th2 - L1 sin th1) is
  the norm of a vector affine in (L0, L1, L2): v = c + e with c at the nominal lengths and
  e = sum of dLk w_k (w0 = e_x, w1 = -u(th1), w2 = u(th2), |dLk| <= Dk). The norm is convex:
  |c + e| >= |c| + c^.e >= |c| - sum Dk |c^.w_k|; and sqrt(|c|^2 + 2 c.e + |e|^2) <= |c| + c^.e +
  |e|^2 / (2 |c|). So d over the length box lies in [|c| - s, |c| + s + (sum D)^2 / (2 |c|)],
  s = sum Dk |cos(beta - dir w_k)|, beta the direction of c: both bounds are exact to first order
  in the tolerances. Over the box, |c| has its exact range (the nominal test's), beta the range of
  the nominal crank direction and |cos| its exact maximum over the resulting angle intervals.
- Mode signs. The angle of a triangle with one side m and two sides given as intervals (adjacent a,
  opposite o) has its exact range: cos = (m^2 + a^2 - o^2) / (2 a m) decreases in o and has no
  critical point inside the (m, a) rectangle, so its extremes lie on its edges (`triangle_angle_range3`).

Margins: lengths widened by ETA_REL * scale (squared ones by DELTA_REL * scale^2), as in the
nominal tests, far above the rounding of these evaluations.
"""

from __future__ import annotations

import numpy as np

from fivebar_cli.mechanisms.fivebar.boxtests import DELTA_REL, ETA_REL, AngleTables, crank_distance2_range
from fivebar_cli.mechanisms.fivebar.kinematics import scale
from fivebar_cli.numerics.ranges import cos_sin_ranges, direction_range, point_box_distance2
from fivebar_cli.paving.engine import BAND

# ---------------------------------------------------------------- exact pieces


def radii(m, crank: int, coupler: int) -> tuple[float, float, float, float]:
    """Annulus radii of a leg over the length box: (robust inner, robust outer, possible inner,
    possible outer) = (max |Li - Lj|, li + lj, min |Li - Lj|, ui + uj)."""
    (l1, u1), (l3, u3) = m.bounds[crank], m.bounds[coupler]
    robust_in = max(abs(u1 - l3), abs(l1 - u3))
    possible_in = 0.0 if max(l1, l3) <= min(u1, u3) else min(abs(l1 - u3), abs(l3 - u1))
    return robust_in, l1 + l3, possible_in, u1 + u3


def widened(m, lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Boxes of P - A2 for P in the boxes and A2 = (L0, 0) on its segment (relative to the origin)."""
    l0, u0 = m.bounds[0]
    return (np.column_stack([lo[:, 0] - u0, lo[:, 1]]), np.column_stack([hi[:, 0] - l0, hi[:, 1]]))


def leg_ranges(m, lo, hi):
    """Exact ranges of |P - A1|^2 and of |P - A2|^2 over the boxes and every L0."""
    wlo, whi = widened(m, lo, hi)
    return point_box_distance2(0.0, 0.0, lo, hi), point_box_distance2(0.0, 0.0, wlo, whi)


def triangle_angle_range3(side_lo, side_hi, adjacent: tuple[float, float], opposite: tuple[float, float]):
    """Exact range of the angle between a side s in [side_lo, side_hi] and a side a in `adjacent` of
    a triangle whose third side o is in `opposite`: arccos((s^2 + a^2 - o^2) / (2 a s)).

    The cosine decreases in o; for fixed o it has no critical point inside the (s, a) rectangle (the
    gradient vanishes only for o = 0), so its extremes over it lie on the four edges: at a corner,
    or at s* = sqrt(a^2 - o^2) on an a-edge, a* = sqrt(s^2 - o^2) on an s-edge. Where the triangle
    cannot close for part of the box, the cosine is clipped to [-1, 1], as in the nominal test.
    """
    def cosine(s, a, o):
        with np.errstate(divide="ignore", invalid="ignore"):
            return (s * s + a * a - o * o) / (2.0 * a * s)

    def extremes(o):
        values = []
        for a in adjacent:
            values += [cosine(side_lo, a, o), cosine(side_hi, a, o)]
            if a * a > o * o:
                star = np.sqrt(a * a - o * o)
                values.append(np.where((side_lo <= star) & (star <= side_hi), cosine(star, a, o), np.nan))
        for s in (side_lo, side_hi):
            a_star = np.sqrt(np.maximum(s * s - o * o, 0.0))
            inside = (s * s > o * o) & (adjacent[0] <= a_star) & (a_star <= adjacent[1])
            values.append(np.where(inside, cosine(s, np.where(inside, a_star, 1.0), o), np.nan))
        return np.stack(values)

    with np.errstate(invalid="ignore"):
        cmax = np.nanmax(extremes(opposite[0]), axis=0)
        cmin = np.nanmin(extremes(opposite[1]), axis=0)
    cmin = np.where(np.isnan(cmin), -1.0, cmin)
    cmax = np.where(np.isnan(cmax), 1.0, cmax)
    return np.arccos(np.clip(cmax, -1, 1)), np.arccos(np.clip(cmin, -1, 1))


def crank_distance_bounds(m, lo, hi, angles: AngleTables | None = None, refine=None) -> dict:
    """What the tests need about d = |B1B2| over the boxes and every length vector (see the module
    docstring), with c the nominal B2 - B1, s = sum Dk |c^.w_k| and E = sum Dk:
    `dmin`, `dmax`: the exact range of |c|; `s_lo`, `s_hi`: a range of s; `low` <= d <= `high`.

    s is bounded by [0, E], then, where `refine` (a mask, default all) is set, by its value at the
    box centre give or take its variation over the box (`sharpen`)."""
    angles = angles if angles is not None else AngleTables.of(lo, hi)
    dmin2, dmax2 = crank_distance2_range(m, lo, hi, angles)
    total = sum(0.5 * (b[1] - b[0]) for b in m.bounds[:3])
    b = {"dmin": np.sqrt(np.maximum(dmin2, 0.0)), "dmax": np.sqrt(np.maximum(dmax2, 0.0)), "total": total,
         "s_lo": np.zeros(len(lo)), "s_hi": np.full(len(lo), total)}
    if refine is None or refine.any():
        sharpen(m, b, lo, hi, angles.box_trig, np.arange(len(lo)) if refine is None else np.flatnonzero(refine))
    return _finish(b)


def sharpen(m, b: dict, lo, hi, trig, idx) -> dict:
    """Replace the range of s of boxes `idx` by a tighter one, in place: s at the box centre, give
    or take how far it can move inside the box. |cos| is 1-Lipschitz in the angle, c^ turns by at
    most (L1 h1 + L2 h2) / |c|min over the box (|dc/dth_k| = L_k) and w1, w2 by h1, h2 (h: the box's
    half widths); the centre's cos and sin come from the ends' by the angle-addition formulas."""
    half = [0.5 * (v[1] - v[0]) for v in m.bounds[:3]]
    h = 0.5 * (hi[idx] - lo[idx])
    ch, sh = np.cos(h), np.sin(h)
    (c1, s1, _, _), (c2, s2, _, _) = ((t[0][idx], t[1][idx], None, None) for t in trig)
    c1, s1 = c1 * ch[:, 0] - s1 * sh[:, 0], s1 * ch[:, 0] + c1 * sh[:, 0]  # at the centre
    c2, s2 = c2 * ch[:, 1] - s2 * sh[:, 1], s2 * ch[:, 1] + c2 * sh[:, 1]
    cx, cy = m.L0 + m.L2 * c2 - m.L1 * c1, m.L2 * s2 - m.L1 * s1
    norm = np.hypot(cx, cy)
    with np.errstate(divide="ignore", invalid="ignore"):
        dots = [np.abs(cx) / norm, np.abs(cx * c1 + cy * s1) / norm, np.abs(cx * c2 + cy * s2) / norm]
        turn = (m.L1 * h[:, 0] + m.L2 * h[:, 1]) / b["dmin"][idx]
    moves = [turn, turn + h[:, 0], turn + h[:, 1]]
    ok = (norm > 0) & (b["dmin"][idx] > 0)
    s_lo = sum(k * np.where(ok, np.clip(d - mv, 0.0, 1.0), 0.0) for k, d, mv in zip(half, dots, moves))
    s_hi = sum(k * np.where(ok, np.clip(d + mv, 0.0, 1.0), 1.0) for k, d, mv in zip(half, dots, moves))
    b["s_lo"][idx] = s_lo
    b["s_hi"][idx] = s_hi
    return _finish(b)


def _finish(b: dict) -> dict:
    """`low` and `high` from |c|'s range and s's range (module docstring)."""
    dmin, dmax, total = b["dmin"], b["dmax"], b["total"]
    with np.errstate(divide="ignore", invalid="ignore"):
        second = np.where(dmin > 0, total * total / (2.0 * dmin), np.inf)
    b["low"] = np.maximum(dmin - b["s_hi"], 0.0)
    b["high"] = np.minimum(dmax + b["s_hi"] + second, dmax + total)
    return b


def crank_direction_range(m, angles: AngleTables, nominal: bool = False):
    """Range of the direction of B2 - B1 over the boxes (and every L0, L1, L2 unless `nominal`),
    from the exact ranges of its components, sums of independent products of lengths and sinusoids."""
    c1, s1 = angles.along(0, cos_sin_ranges)
    c2, s2 = angles.along(1, cos_sin_ranges)
    (l0, u0), (l1, u1), (l2, u2) = ((m.L0, m.L0), (m.L1, m.L1), (m.L2, m.L2)) if nominal else m.bounds[:3]

    def product(a, b, t):  # exact range of L * f, L in [a, b] > 0, f in t (f's sign picks the end)
        return np.minimum(a * t[0], b * t[0]), np.maximum(a * t[1], b * t[1])

    l2c, l1c, l2s, l1s = product(l2, u2, c2), product(l1, u1, c1), product(l2, u2, s2), product(l1, u1, s1)
    x_lo, x_hi = l0 + l2c[0] - l1c[1], u0 + l2c[1] - l1c[0]
    y_lo, y_hi = l2s[0] - l1s[1], l2s[1] - l1s[0]
    return direction_range(x_lo, x_hi, y_lo, y_hi)


# ---------------------------------------------------------------- the two spaces


def margins(m) -> tuple[float, float]:
    s = scale(m) + sum(b[1] - b[0] for b in m.bounds)
    return DELTA_REL * s * s, ETA_REL * s


def joint_status(m, d_lo, d_hi, strict: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """(robust, impossible) masks from the bounds of |B1B2|: robust when every point assembles for
    every L (|L3 - L4| <= d <= L3 + L4, d > 0; strictly with `strict`), impossible when none does
    for any L."""
    (l3, u3), (l4, u4) = m.bounds[3], m.bounds[4]
    robust_in = max(abs(u3 - l4), abs(l3 - u4))
    possible_in = 0.0 if max(l3, l4) <= min(u3, u4) else min(abs(l3 - u4), abs(l4 - u3))
    _, eta = margins(m)
    lo, hi = d_lo - eta, d_hi + eta
    if strict:
        robust = (lo > robust_in) & (hi < l3 + l4) & (lo > 0)
    else:
        robust = (lo >= robust_in) & (hi <= l3 + l4) & (lo > 0)
    impossible = (lo > u3 + u4) | (hi < possible_in)
    return robust, impossible


def joint_band(m, b: dict, possible_too: bool = True) -> np.ndarray:
    """Boxes certified in the uncertain band: every point fails to assemble for some length vector
    and (with `possible_too`) assembles for another.

    Not robust anywhere: max over L of d >= |c| + s > the robust outer limit l3 + l4, or min over L
    of d <= sqrt(|c|^2 - 2 |c| s + E^2) < the robust inner limit max |L3 - L4| (both from the
    module docstring's expansion, with s >= s_lo). Possible everywhere: these bounds on min and max
    over L of d lie within the possible limits [min |L3 - L4|, u3 + u4] (d takes every value between
    its min and max over the length box, which is connected)."""
    (l3, u3), (l4, u4) = m.bounds[3], m.bounds[4]
    robust_in = max(abs(u3 - l4), abs(l3 - u4))
    possible_in = 0.0 if max(l3, l4) <= min(u3, u4) else min(abs(l3 - u4), abs(l4 - u3))
    _, eta = margins(m)
    dmin, dmax, s_lo, total = b["dmin"], b["dmax"], b["s_lo"], b["total"]
    max_low = dmin + s_lo  # <= max over L of d, everywhere in the box
    g = np.maximum(dmin * dmin - 2 * dmin * s_lo, dmax * dmax - 2 * dmax * s_lo) + total * total
    min_high = np.minimum(np.sqrt(np.maximum(g, 0.0)), dmax)  # >= min over L of d, everywhere
    band = (max_low - eta > l3 + l4) | (min_high + eta < robust_in)
    if possible_too:
        band &= (min_high + eta <= u3 + u4) & (max_low - eta >= possible_in)
    return band


def joint_space_test(m):
    """Robust / impossible / band box test of the joint space."""

    def status(b):
        robust, impossible = joint_status(m, b["low"], b["high"])
        return np.where(robust, 1, np.where(impossible, -1, np.where(joint_band(m, b), BAND, 0))).astype(np.int8)

    def test(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        return status(crank_distance_bounds(m, lo, hi))

    return test


def workspace_classes(m, lo, hi):
    """Per box: (robust, impossible, strict) for the workspace: P in both annuli for every L (strictly
    inside with `strict`, the aspects' non-singular part), or for none.

    Impossible: the box misses the union over L of annulus 1 (an annulus with the possible radii)
    or that of annulus 2 (P within the possible outer radius of some point of A2's segment and
    beyond the possible inner radius from another: the widened box's exact distance range). The
    union of the intersections can be smaller than the intersection of the unions only where both
    annuli matter at once; there such boxes stay undetermined (sound, less tight)."""
    delta, _ = margins(m)
    robust = np.ones(len(lo), bool)
    strict = np.ones(len(lo), bool)
    impossible = np.zeros(len(lo), bool)
    for (dmin, dmax), (r_in, r_out, p_in, p_out) in zip(leg_ranges(m, lo, hi), (radii(m, 1, 3), radii(m, 2, 4))):
        robust &= (dmin - delta >= r_in * r_in) & (dmax + delta <= r_out * r_out) & (dmin - delta > 0)
        strict &= (dmin - delta > r_in * r_in) & (dmax + delta < r_out * r_out) & (dmin - delta > 0)
        impossible |= (dmax + delta < p_in * p_in) | (dmin - delta > p_out * p_out)
    return robust, impossible, strict


def _segment_distances(m, lo, hi):
    """Over each box: the largest distance from a point to A2's segment S = [l0, u0] x {0} (at a
    corner: the distance is convex) and a lower bound of the smallest farthest-point distance
    (the farthest point of S is an end: max(min |P - a|, min |P - b|))."""
    (l0, u0) = m.bounds[0]
    corners = [(lo[:, 0], lo[:, 1]), (lo[:, 0], hi[:, 1]), (hi[:, 0], lo[:, 1]), (hi[:, 0], hi[:, 1])]
    near_max = np.max([np.hypot(x - np.clip(x, l0, u0), y) for x, y in corners], axis=0)
    far_min = np.sqrt(np.maximum(point_box_distance2(l0, 0.0, lo, hi)[0], point_box_distance2(u0, 0.0, lo, hi)[0]))
    return near_max, far_min


def workspace_band(m, lo, hi, possible_too: bool = True) -> np.ndarray:
    """Boxes certified in the uncertain band: no point reachable for every length vector and (with
    `possible_too`) every point reachable for some. Not robust anywhere: the box misses the robust
    annulus of leg 1, or every point is farther than the robust outer radius from an end of A2's
    segment, or closer than the robust inner radius to all of it. Possible everywhere: the box lies
    in the possible annulus of leg 1 and within the possible radii of A2's segment."""
    delta, eta = margins(m)
    d1, _ = leg_ranges(m, lo, hi)
    r1_in, r1_out, p1_in, p1_out = radii(m, 1, 3)
    r2_in, r2_out, p2_in, p2_out = radii(m, 2, 4)
    near_max, far_min = _segment_distances(m, lo, hi)
    band = ((d1[1] + delta < r1_in * r1_in) | (d1[0] - delta > r1_out * r1_out)
            | (far_min - eta > r2_out) | (near_max + eta < r2_in))
    if possible_too:
        band &= (d1[0] - delta >= p1_in * p1_in) & (d1[1] + delta <= p1_out * p1_out)
        band &= (near_max + eta <= p2_out) & (far_min - eta >= p2_in)
    return band


def workspace_test(m):
    """Robust / impossible / band box test of the workspace."""

    def test(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        robust, impossible, _ = workspace_classes(m, lo, hi)
        band = workspace_band(m, lo, hi)
        return np.where(robust, 1, np.where(impossible, -1, np.where(band, BAND, 0))).astype(np.int8)

    return test
