"""The five-bar's mode box tests as they computed before issue 22's fourth pass (main at 3d4d870), kept
frozen: the faster code must give the same floats, hence the same verdicts, bit for bit
(`test_boxtest_identity.py`). One box per row, every range computed per box; the helpers this pass
left alone are the library's (circle intersections, point-to-box distances); the workspace's reach
test and the triangle angles are kept below as they were before the sixth pass.

Per box of (th1, th2): the exact range of |B1B2|^2 (edges and interior critical points), the coupler
triangle's angles, the direction of B2 - B1 and the signs of B11, B22 per assembly mode; per box of
the workspace: the legs' distance ranges, directions and triangle angles and the sign of det A per
working mode.
"""

from __future__ import annotations

import numpy as np

from fivebar_cli.numerics.ranges import circle_intersections, point_box_distance2

TWO_PI = 2.0 * np.pi
ANGLE_TOL = 1e-12
ANGLE_MARGIN = 1e-8
DELTA_REL = 1e-12


# ---------------------------------------------------------------- numerics/ranges.py


def angle_inside(angle, lo, hi, tol=ANGLE_TOL):
    lo, hi = lo - tol, hi + tol
    k = np.subtract(lo, angle)
    if k.ndim == 0:
        return angle + np.ceil(k / TWO_PI) * TWO_PI <= hi
    k /= TWO_PI
    np.ceil(k, out=k)
    k *= TWO_PI
    k += angle
    return k <= hi


def sinusoid_range(a, b, lo, hi, trig=None):
    c_lo, s_lo, c_hi, s_hi = trig if trig is not None else (np.cos(lo), np.sin(lo), np.cos(hi), np.sin(hi))
    amp = np.hypot(a, b)
    psi = np.arctan2(b, a)
    f_lo = a * c_lo + b * s_lo
    f_hi = a * c_hi + b * s_hi
    top = np.where(angle_inside(psi, lo, hi), amp, np.maximum(f_lo, f_hi))
    bottom = np.where(angle_inside(psi + np.pi, lo, hi), -amp, np.minimum(f_lo, f_hi))
    return bottom, top


def direction_range(xlo, xhi, ylo, yhi):
    centre = np.arctan2(0.5 * (ylo + yhi), 0.5 * (xlo + xhi))
    lo = np.full(np.shape(xlo), np.inf)
    hi = np.full(np.shape(xlo), -np.inf)
    for x in (xlo, xhi):
        for y in (ylo, yhi):
            off = (np.arctan2(y, x) - centre + np.pi) % TWO_PI - np.pi
            lo, hi = np.minimum(lo, off), np.maximum(hi, off)
    origin = (xlo <= 0) & (xhi >= 0) & (ylo <= 0) & (yhi >= 0)
    return np.where(origin, centre - np.pi, centre + lo), np.where(origin, centre + np.pi, centre + hi)


def sin_sign(lo, hi, margin=ANGLE_MARGIN):
    lo, hi = lo - margin, hi + margin
    k = np.floor(lo / np.pi)
    inside = (lo > k * np.pi) & (hi < (k + 1) * np.pi)
    even = np.mod(k, 2) == 0
    return np.where(inside, np.where(even, 1, -1), 0).astype(np.int8)


# ---------------------------------------------------------------- mechanisms/fivebar: shared


def _scale(m):
    return m.L0 + m.L1 + m.L2 + m.L3 + m.L4


def _strict(dmin, dmax, inner, outer, delta):
    return (dmin - delta > inner * inner) & (dmax + delta < outer * outer) & (dmin - delta > 0)


def _valid_lengths(dmin, dmax, inner, outer, delta):
    lo = np.sqrt(np.maximum(dmin - delta, 0.0))
    hi = np.sqrt(np.maximum(dmax + delta, 0.0))
    return np.clip(lo, inner, outer), np.clip(hi, inner, outer)


# ---------------------------------------------------------------- joint space


def crank_critical_points(m):
    points = []
    for th1 in (0.0, np.pi):
        for th2 in (0.0, np.pi):
            x = m.L1 * np.cos(th1) - m.L0 - m.L2 * np.cos(th2)
            points.append((th1, th2, x * x))
    for qx, qy in circle_intersections((0.0, 0.0), m.L1, (m.L0, 0.0), m.L2):  # B1 = B2
        points.append((float(np.arctan2(qy, qx)), float(np.arctan2(qy, qx - m.L0)), 0.0))
    return points


def crank_distance2_range(m, lo, hi):
    L0, L1, L2 = m.L0, m.L1, m.L2
    k0 = L0 * L0 + L1 * L1 + L2 * L2
    u0, v0, u1, v1 = lo[:, 0], lo[:, 1], hi[:, 0], hi[:, 1]
    t1, t2 = ((np.cos(lo[:, k]), np.sin(lo[:, k]), np.cos(hi[:, k]), np.sin(hi[:, k])) for k in (0, 1))
    fmin = np.full(len(lo), np.inf)
    fmax = np.full(len(lo), -np.inf)
    for cu, su in ((t1[0], t1[1]), (t1[2], t1[3])):
        base = k0 - 2 * L0 * L1 * cu
        bot, top = sinusoid_range(2 * L0 * L2 - 2 * L1 * L2 * cu, -2 * L1 * L2 * su, v0, v1, t2)
        fmin, fmax = np.minimum(fmin, base + bot), np.maximum(fmax, base + top)
    for cv, sv in ((t2[0], t2[1]), (t2[2], t2[3])):
        base = k0 + 2 * L0 * L2 * cv
        bot, top = sinusoid_range(-2 * L0 * L1 - 2 * L1 * L2 * cv, -2 * L1 * L2 * sv, u0, u1, t1)
        fmin, fmax = np.minimum(fmin, base + bot), np.maximum(fmax, base + top)
    for th1, th2, value in crank_critical_points(m):
        inside = angle_inside(th1, u0, u1) & angle_inside(th2, v0, v1)
        fmin = np.where(inside, np.minimum(fmin, value), fmin)
        fmax = np.where(inside, np.maximum(fmax, value), fmax)
    return fmin, fmax, (t1, t2)


def crank_direction_range(m, lo, hi, trig):
    c1 = sinusoid_range(1.0, 0.0, lo[:, 0], hi[:, 0], trig[0])
    s1 = sinusoid_range(0.0, 1.0, lo[:, 0], hi[:, 0], trig[0])
    c2 = sinusoid_range(1.0, 0.0, lo[:, 1], hi[:, 1], trig[1])
    s2 = sinusoid_range(0.0, 1.0, lo[:, 1], hi[:, 1], trig[1])
    x_lo, x_hi = m.L0 + m.L2 * c2[0] - m.L1 * c1[1], m.L0 + m.L2 * c2[1] - m.L1 * c1[0]
    y_lo, y_hi = m.L2 * s2[0] - m.L1 * s1[1], m.L2 * s2[1] - m.L1 * s1[0]
    return direction_range(x_lo, x_hi, y_lo, y_hi)


def joint_classes(m, assemblies, lo, hi):
    """(status, strict, u, v, ranges): u, v of shape (n, len(assemblies)); ranges: the coupler
    triangle's (dmin, dmax, d_lo, d_hi, a, e, b)."""
    r, big = abs(m.L3 - m.L4), m.L3 + m.L4
    delta = DELTA_REL * _scale(m) ** 2
    dmin, dmax, trig = crank_distance2_range(m, lo, hi)
    d_lo, d_hi = _valid_lengths(dmin, dmax, r, big, delta)
    d_lo = np.maximum(d_lo, np.sqrt(delta))
    a = triangle_angle_range(d_lo, d_hi, m.L3, m.L4)
    e = triangle_angle_range(d_lo, d_hi, m.L4, m.L3)
    b = crank_direction_range(m, lo, hi, trig)
    lo2, hi2 = (m.L3 - m.L4) ** 2, (m.L3 + m.L4) ** 2
    wmin, wmax = dmin - delta, dmax + delta
    inside = (wmin >= lo2) & (wmax <= hi2) & (wmin > 0)
    outside = (wmax < lo2) | (wmin > hi2)
    status = np.where(inside, 1, np.where(outside, -1, 0)).astype(np.int8)
    strict = _strict(dmin, dmax, r, big, delta)
    u = np.empty((len(lo), len(assemblies)), np.int8)
    v = np.empty_like(u)
    (b_lo, b_hi), (a_lo, a_hi), (e_lo, e_hi) = b, a, e
    for k, sa in enumerate(assemblies):
        if sa > 0:
            t3, t4 = (b_lo + a_lo, b_hi + a_hi), (b_lo + np.pi - e_hi, b_hi + np.pi - e_lo)
        else:
            t3, t4 = (b_lo - a_hi, b_hi - a_lo), (b_lo + np.pi + e_lo, b_hi + np.pi + e_hi)
        u[:, k] = sin_sign(t3[0] - hi[:, 0], t3[1] - lo[:, 0])
        v[:, k] = sin_sign(t4[0] - hi[:, 1], t4[1] - lo[:, 1])
    return status, strict, u, v, (dmin, dmax, d_lo, d_hi, *a, *e, *b)


def joint_tests(m, assemblies, lo, hi):
    status, strict, u, v, _ = joint_classes(m, assemblies, lo, hi)
    black = strict[:, None] & (u != 0) & (v != 0)
    return np.where(status[:, None] == -1, -1, np.where(black, 1, 0)).astype(np.int8)


# ---------------------------------------------------------------- workspace


def workspace_classes(m, workings, lo, hi, reach_status):
    """(status, strict, signs): signs of det A per working mode, shape (n, len(workings));
    `reach_status(lo, hi, (d1, d2))` is the library's reach test."""
    annuli = [(0.0, abs(m.L1 - m.L3), m.L1 + m.L3), (m.L0, abs(m.L2 - m.L4), m.L2 + m.L4)]
    delta = DELTA_REL * _scale(m) ** 2
    d1, d2 = (point_box_distance2(cx, 0.0, lo, hi) for cx, _, _ in annuli)
    status = reach_status(lo, hi, (d1, d2))
    (c1, r1, big1), (c2, r2, big2) = annuli
    strict = _strict(*d1, r1, big1, delta) & _strict(*d2, r2, big2, delta)
    legs = []
    for d2range, cx, inner, outer, coupler, crank in ((d1, c1, r1, big1, m.L3, m.L1), (d2, c2, r2, big2, m.L4, m.L2)):
        alpha = direction_range(lo[:, 0] - cx, hi[:, 0] - cx, lo[:, 1], hi[:, 1])
        m_lo, m_hi = _valid_lengths(*d2range, inner, outer, delta)
        legs.append((alpha, triangle_angle_range(m_lo, m_hi, coupler, crank)))
    signs = np.empty((len(lo), len(workings)), np.int8)
    for k, (su, sv) in enumerate(workings):
        th = []
        for ((a_lo, a_hi), (g_lo, g_hi)), s in zip(legs, (su, sv)):
            th.append((a_lo + g_lo, a_hi + g_hi) if s > 0 else (a_lo - g_hi, a_hi - g_lo))
        signs[:, k] = sin_sign(th[1][0] - th[0][1], th[1][1] - th[0][0])
    return status, strict, signs


def workspace_tests(m, workings, lo, hi, reach_status):
    status, strict, signs = workspace_classes(m, workings, lo, hi, reach_status)
    black = strict[:, None] & (signs != 0)
    return np.where(status[:, None] == -1, -1, np.where(black, 1, 0)).astype(np.int8)


def wrap_angle(a):
    """(kinematics.ikp's wrap of its joint angles, ranges.direction_range's of its corner offsets)"""
    return (a + np.pi) % TWO_PI - np.pi


def cells_of_points(grid, points):
    """grid.Grid.cells_of_points as it was (periodic axes wrapped with np.mod)."""
    points = np.atleast_2d(np.asarray(points, dtype=float))
    rel = (points - grid.lo) / grid.size
    for axis, wrap in enumerate(grid.periodic):
        if wrap:
            rel[:, axis] = np.mod(rel[:, axis], 1.0)
    inside = np.all((rel >= 0) & (rel <= 1), axis=1)
    n = 1 << grid.depth
    return np.clip(np.floor(np.where(inside[:, None], rel, 0) * n), 0, n - 1).astype(np.int64), inside


# ---------------------------------------------------------------- numerics/annuli.py


def reach_status(annuli, lo, hi, ranges, anchor_points, delta, eta):
    """annuli.reach_status as it was before issue 22's sixth pass: `box_meets` (the library's) and
    the anchors on every box neither inside both annuli nor out of reach."""
    from fivebar_cli.numerics.annuli import box_meets

    inside = np.ones(len(lo), dtype=bool)
    outside = np.zeros(len(lo), dtype=bool)
    for (dmin, dmax), (_, r, big_r) in zip(ranges, annuli):
        inside &= (dmin - delta >= r * r) & (dmax + delta <= big_r * big_r) & (dmin - delta > 0)
        outside |= (dmax + delta < r * r) | (dmin - delta > big_r * big_r)
    maybe = ~outside & ~inside
    if maybe.any():
        idx = np.flatnonzero(maybe)
        meets = box_meets(annuli, lo[idx], hi[idx], delta, eta)
        for px, py in anchor_points:
            meets |= ((lo[idx, 0] - eta <= px) & (px <= hi[idx, 0] + eta)
                      & (lo[idx, 1] - eta <= py) & (py <= hi[idx, 1] + eta))
        outside[idx[~meets]] = True
    return np.where(inside, 1, np.where(outside, -1, 0)).astype(np.int8)


def triangle_angle_range(side_lo, side_hi, adjacent, opposite):
    """ranges.triangle_angle_range as it was before issue 22's sixth pass (NaN ends replaced, then clipped)."""
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
    cmin = np.where(np.isnan(cmin), -1.0, cmin)
    cmax = np.where(np.isnan(cmax), 1.0, cmax)
    return np.arccos(np.clip(cmax, -1, 1)), np.arccos(np.clip(cmin, -1, 1))


# ---------------------------------------------------------------- mechanisms/fivebar/kinematics.py


def ikp(m, x, y, working):
    """kinematics.ikp as it was before the seventh pass (temporaries, np.where and np.clip)."""
    x, y = np.asarray(x, float), np.asarray(y, float)
    su, sv = working
    m1 = np.hypot(x, y)
    m2 = np.hypot(x - m.L0, y)
    with np.errstate(divide="ignore", invalid="ignore"):
        c1 = (m.L1**2 + m1 * m1 - m.L3**2) / (2.0 * m.L1 * m1)
        c2 = (m.L2**2 + m2 * m2 - m.L4**2) / (2.0 * m.L2 * m2)
    ok = (m1 > 0) & (m2 > 0) & (np.abs(c1) <= 1) & (np.abs(c2) <= 1)
    th1 = np.arctan2(y, x) - su * np.arccos(np.clip(np.where(ok, c1, 0.0), -1, 1))
    th2 = np.arctan2(y, x - m.L0) - sv * np.arccos(np.clip(np.where(ok, c2, 0.0), -1, 1))
    return np.where(ok, wrap_angle(th1), np.nan), np.where(ok, wrap_angle(th2), np.nan), ok


def dkp(m, th1, th2, assembly):
    """kinematics.dkp as it was before the seventh pass (the cranks as stacked points)."""
    th1, th2 = np.asarray(th1, float), np.asarray(th2, float)
    b1 = np.stack([m.L1 * np.cos(th1), m.L1 * np.sin(th1)], axis=-1)
    b2 = np.stack([m.L0 + m.L2 * np.cos(th2), m.L2 * np.sin(th2)], axis=-1)
    diff = b2 - b1
    d = np.hypot(diff[..., 0], diff[..., 1])
    beta = np.arctan2(diff[..., 1], diff[..., 0])
    with np.errstate(divide="ignore", invalid="ignore"):
        c = (d * d + m.L3**2 - m.L4**2) / (2.0 * m.L3 * d)
    ok = (d > 0) & (d <= m.L3 + m.L4) & (d >= abs(m.L3 - m.L4))
    alpha = np.arccos(np.clip(np.where(ok, c, 0.0), -1.0, 1.0))
    angle = beta + assembly * alpha
    p = b1 + m.L3 * np.stack([np.cos(angle), np.sin(angle)], axis=-1)
    return np.where(ok[..., None], p, np.nan), ok
