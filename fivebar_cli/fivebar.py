"""Five-bar kinematics: point DKP/IKP, mode signs, and box tests for the joint space and workspace.

Geometry (DESIGN.md): A1 = (0, 0), A2 = (L0, 0), B1 = A1 + L1 (cos th1, sin th1),
B2 = A2 + L2 (cos th2, sin th2), |P - B1| = L3, |P - B2| = L4.

Modes, all from cross products (z components):
  assembly mode  t = (p - b1) x (p - b2)      (sign of det A; > 0 when P is left of B1 -> B2)
  working mode   u = (b1 - a1) x (p - b1),  v = (b2 - a2) x (p - b2)   (signs of B11, B22)
Serial singularities: u = 0 or v = 0 (a leg stretched or folded); parallel: t = 0 (B1, P, B2
aligned, including B1 = B2 when L3 = L4).

Box tests return 1 (every point valid), -1 (no point valid), 0 (cannot tell). The tight tests
compute exact ranges (extrema of sinusoids, distances from a point to a box, and the exact
emptiness test of a box against the intersection of two annuli), then widen them by a safety
margin `DELTA_REL * scale^2` (scale = sum of lengths), far above the few-ulp rounding of the
float evaluation, before deciding; boxes are already widened by the paving for their own rounding.
"""

from __future__ import annotations

import numpy as np

from fivebar_cli.config import FiveBar

TWO_PI = 2.0 * np.pi
DELTA_REL = 1e-12  # safety margin on squared lengths, relative to the squared scale
ETA_REL = 1e-9  # safety margin on lengths along box edges, relative to the scale
ANGLE_TOL = 1e-12  # extremum of a sinusoid taken as inside an interval within this tolerance


def scale(m: FiveBar) -> float:
    return m.L0 + m.L1 + m.L2 + m.L3 + m.L4


# ---------------------------------------------------------------- point kinematics


def cranks(m: FiveBar, th1, th2) -> tuple[np.ndarray, np.ndarray]:
    """Positions of B1 and B2 (arrays of shape (..., 2))."""
    th1, th2 = np.asarray(th1, float), np.asarray(th2, float)
    b1 = np.stack([m.L1 * np.cos(th1), m.L1 * np.sin(th1)], axis=-1)
    b2 = np.stack([m.L0 + m.L2 * np.cos(th2), m.L2 * np.sin(th2)], axis=-1)
    return b1, b2


def dkp(m: FiveBar, th1, th2, assembly: int) -> tuple[np.ndarray, np.ndarray]:
    """Direct kinematics: P for the assembly mode `assembly` (+1: det A > 0, -1: det A < 0).

    Returns (p, ok) where ok is False where the mechanism cannot be assembled
    (|B1B2| > L3 + L4, |B1B2| < |L3 - L4|, or B1 = B2) and p is NaN there.
    """
    b1, b2 = cranks(m, th1, th2)
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


def ikp(m: FiveBar, x, y, working: tuple[int, int]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Inverse kinematics: (th1, th2, ok) for the working mode (sign u, sign v).

    u = L1 M1 sin(alpha1 - th1) with alpha1 the direction of A1P, so sign u = +1 is th1 = alpha1 - beta1.
    """
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
    wrap = lambda a: np.where(ok, (a + np.pi) % TWO_PI - np.pi, np.nan)  # noqa: E731
    return wrap(th1), wrap(th2), ok


def mode_values(m: FiveBar, th1, th2, p) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(u, v, t): the cross products whose signs are the working modes and the assembly mode."""
    b1, b2 = cranks(m, th1, th2)
    a2 = np.array([m.L0, 0.0])
    cross = lambda a, b: a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]  # noqa: E731
    return cross(b1, p - b1), cross(b2 - a2, p - b2), cross(p - b1, p - b2)


def in_joint_space(m: FiveBar, th1, th2) -> np.ndarray:
    """Point test: the mechanism can be assembled with finitely many solutions (B1 != B2)."""
    b1, b2 = cranks(m, th1, th2)
    d = np.hypot(b2[..., 0] - b1[..., 0], b2[..., 1] - b1[..., 1])
    return (d > 0) & (d <= m.L3 + m.L4) & (d >= abs(m.L3 - m.L4))


def in_workspace(m: FiveBar, x, y) -> np.ndarray:
    """Point test: P is reachable by both legs with finitely many solutions (P != A_i)."""
    m1, m2 = np.hypot(x, y), np.hypot(np.asarray(x) - m.L0, y)
    leg1 = (m1 > 0) & (m1 >= abs(m.L1 - m.L3)) & (m1 <= m.L1 + m.L3)
    leg2 = (m2 > 0) & (m2 >= abs(m.L2 - m.L4)) & (m2 <= m.L2 + m.L4)
    return leg1 & leg2


# ---------------------------------------------------------------- exact ranges


def angle_inside(angle, lo, hi, tol: float = ANGLE_TOL) -> np.ndarray:
    """Whether some angle + 2 k pi lies in [lo - tol, hi + tol] (elementwise)."""
    k = np.ceil((lo - tol - angle) / TWO_PI)
    return angle + k * TWO_PI <= hi + tol


def sinusoid_range(a, b, lo, hi, trig=None) -> tuple[np.ndarray, np.ndarray]:
    """Exact range of a cos t + b sin t for t in [lo, hi] (elementwise, any width).

    `trig` = (cos lo, sin lo, cos hi, sin hi) when the caller has them already.
    """
    c_lo, s_lo, c_hi, s_hi = trig if trig is not None else (np.cos(lo), np.sin(lo), np.cos(hi), np.sin(hi))
    amp = np.hypot(a, b)
    psi = np.arctan2(b, a)
    f_lo = a * c_lo + b * s_lo
    f_hi = a * c_hi + b * s_hi
    top = np.where(angle_inside(psi, lo, hi), amp, np.maximum(f_lo, f_hi))
    bottom = np.where(angle_inside(psi + np.pi, lo, hi), -amp, np.minimum(f_lo, f_hi))
    return bottom, top


def box_trig(lo: np.ndarray, hi: np.ndarray) -> tuple[tuple, tuple]:
    """(cos, sin) of both ends of both angles of boxes: ((c, s, c, s) of th1, (c, s, c, s) of th2)."""
    return tuple((np.cos(lo[:, k]), np.sin(lo[:, k]), np.cos(hi[:, k]), np.sin(hi[:, k])) for k in (0, 1))


def crank_distance2_range(m: FiveBar, lo: np.ndarray, hi: np.ndarray, trig=None) -> tuple[np.ndarray, np.ndarray]:
    """Exact range of |B1B2|^2 over boxes [th1] x [th2].

    d^2 = K - 2 L0 L1 cos th1 + 2 L0 L2 cos th2 - 2 L1 L2 cos(th1 - th2) is smooth, so its extrema
    over a box lie on the edges (sinusoids in one angle: exact) or at interior critical points:
    where B1B2 is normal to both crank circles, i.e. B1, B2 on the line A1A2 (th1, th2 in {0, pi}),
    or where B1 = B2 (d = 0).
    """
    L0, L1, L2 = m.L0, m.L1, m.L2
    k0 = L0 * L0 + L1 * L1 + L2 * L2
    u0, v0, u1, v1 = lo[:, 0], lo[:, 1], hi[:, 0], hi[:, 1]
    t1, t2 = trig if trig is not None else box_trig(lo, hi)
    fmin = np.full(len(lo), np.inf)
    fmax = np.full(len(lo), -np.inf)
    for cu, su in ((t1[0], t1[1]), (t1[2], t1[3])):  # edges th1 = const: sinusoid in th2
        base = k0 - 2 * L0 * L1 * cu
        bot, top = sinusoid_range(2 * L0 * L2 - 2 * L1 * L2 * cu, -2 * L1 * L2 * su, v0, v1, t2)
        fmin, fmax = np.minimum(fmin, base + bot), np.maximum(fmax, base + top)
    for cv, sv in ((t2[0], t2[1]), (t2[2], t2[3])):  # edges th2 = const: sinusoid in th1
        base = k0 + 2 * L0 * L2 * cv
        bot, top = sinusoid_range(-2 * L0 * L1 - 2 * L1 * L2 * cv, -2 * L1 * L2 * sv, u0, u1, t1)
        fmin, fmax = np.minimum(fmin, base + bot), np.maximum(fmax, base + top)
    for th1, th2, value in _crank_critical_points(m):
        inside = angle_inside(th1, u0, u1) & angle_inside(th2, v0, v1)
        fmin = np.where(inside, np.minimum(fmin, value), fmin)
        fmax = np.where(inside, np.maximum(fmax, value), fmax)
    return fmin, fmax


def _crank_critical_points(m: FiveBar) -> list[tuple[float, float, float]]:
    """Interior critical points (th1, th2, d^2) of the crank distance."""
    points = []
    for th1 in (0.0, np.pi):
        for th2 in (0.0, np.pi):
            x = m.L1 * np.cos(th1) - m.L0 - m.L2 * np.cos(th2)
            points.append((th1, th2, x * x))
    for q in circle_intersections((0.0, 0.0), m.L1, (m.L0, 0.0), m.L2):  # B1 = B2
        points.append((float(np.arctan2(q[1], q[0])), float(np.arctan2(q[1], q[0] - m.L0)), 0.0))
    return points


def circle_intersections(c1, r1: float, c2, r2: float) -> list[tuple[float, float]]:
    """Intersection points of two circles (tangent circles give one point, r = 0 is a point)."""
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


# ---------------------------------------------------------------- tight box tests


def joint_space_test(m: FiveBar):
    """Box test of the joint space (th1, th2): |L3 - L4| <= |B1B2| <= L3 + L4 and B1 != B2.

    Exact: the box is connected, so |B1B2| takes every value between its exact extrema.
    """

    def test(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        return assembly_status(m, *crank_distance2_range(m, lo, hi))

    return test


def assembly_status(m: FiveBar, dmin: np.ndarray, dmax: np.ndarray) -> np.ndarray:
    """1 / -1 / 0 from the exact range of |B1B2|^2, widened by the safety margin."""
    lo2, hi2 = (m.L3 - m.L4) ** 2, (m.L3 + m.L4) ** 2
    delta = DELTA_REL * scale(m) ** 2
    dmin, dmax = dmin - delta, dmax + delta
    inside = (dmin >= lo2) & (dmax <= hi2) & (dmin > 0)
    outside = (dmax < lo2) | (dmin > hi2)
    return np.where(inside, 1, np.where(outside, -1, 0)).astype(np.int8)


def _annuli(m: FiveBar) -> list[tuple[float, float, float]]:
    """Workspace constraints as annuli (centre x, inner radius, outer radius); centres on y = 0."""
    return [(0.0, abs(m.L1 - m.L3), m.L1 + m.L3), (m.L0, abs(m.L2 - m.L4), m.L2 + m.L4)]


def workspace_area(m: FiveBar) -> float:
    """Exact area of the workspace: the intersection of the two annuli, by Green's theorem on its arcs."""
    from fivebar_cli import arcs

    centres, radii, sides = [], [], []
    for cx, r, big_r in _annuli(m):
        centres += [(cx, 0.0), (cx, 0.0)]
        radii += [big_r, r]
        sides += [1, -1]
    return float(arcs.area(np.array(centres), np.array(radii), np.array(sides)))


def point_box_distance2(cx: float, cy: float, lo: np.ndarray, hi: np.ndarray):
    """Exact range of the squared distance from (cx, cy) to the points of each box."""
    nx = np.clip(cx, lo[:, 0], hi[:, 0]) - cx
    ny = np.clip(cy, lo[:, 1], hi[:, 1]) - cy
    fx = np.maximum(np.abs(lo[:, 0] - cx), np.abs(hi[:, 0] - cx))
    fy = np.maximum(np.abs(lo[:, 1] - cy), np.abs(hi[:, 1] - cy))
    return nx * nx + ny * ny, fx * fx + fy * fy


def workspace_test(m: FiveBar):
    """Box test of the workspace: P in both annuli |L_i - L_j| <= |P - A_i| <= L_i + L_j, P != A_i.

    Exact in both directions: 'inside' from exact point-to-box distances; 'outside' when no point
    of the box lies in the intersection V of the two annuli. A box meets V iff an edge of the box
    meets V (each annulus cuts an edge in at most two intervals, intersected exactly) or a whole
    component of V lies inside the box, in which case it contains the leftmost point of that
    component: a vertex of V or the leftmost or rightmost point of one of the circles.
    """
    anchors = _workspace_anchors(m)

    def test(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        return reach_status(m, lo, hi, leg_distance2_ranges(m, lo, hi), anchors)

    return test


def leg_distance2_ranges(m: FiveBar, lo: np.ndarray, hi: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
    """Exact ranges of |P - A1|^2 and |P - A2|^2 over boxes."""
    return [point_box_distance2(cx, 0.0, lo, hi) for cx, _, _ in _annuli(m)]


def reach_status(m: FiveBar, lo: np.ndarray, hi: np.ndarray, ranges, anchors) -> np.ndarray:
    """1 / -1 / 0 of the workspace test from the leg distance ranges (see `workspace_test`)."""
    annuli = _annuli(m)
    s = scale(m)
    delta, eta = DELTA_REL * s * s, ETA_REL * s
    inside = np.ones(len(lo), dtype=bool)
    outside = np.zeros(len(lo), dtype=bool)
    for (dmin, dmax), (_, r, big_r) in zip(ranges, annuli):
        inside &= (dmin - delta >= r * r) & (dmax + delta <= big_r * big_r) & (dmin - delta > 0)
        outside |= (dmax + delta < r * r) | (dmin - delta > big_r * big_r)
    maybe = ~outside & ~inside
    if maybe.any():
        idx = np.flatnonzero(maybe)
        meets = _box_meets_annuli(annuli, lo[idx], hi[idx], delta, eta)
        for px, py in anchors:
            meets |= (
                (lo[idx, 0] - eta <= px) & (px <= hi[idx, 0] + eta)
                & (lo[idx, 1] - eta <= py) & (py <= hi[idx, 1] + eta)
            )
        outside[idx[~meets]] = True
    return np.where(inside, 1, np.where(outside, -1, 0)).astype(np.int8)


def _box_meets_annuli(annuli, lo, hi, delta, eta) -> np.ndarray:
    """Whether some point of the boundary of each box lies in every annulus (widened by the margins)."""
    meets = np.zeros(len(lo), dtype=bool)
    edges = []
    for y in (lo[:, 1], hi[:, 1]):  # horizontal edges: t = x, offset from each centre = y
        edges.append((lo[:, 0], hi[:, 0], [(cx, y) for cx, _, _ in annuli]))
    for x in (lo[:, 0], hi[:, 0]):  # vertical edges: t = y, centres at t = 0, offset = x - cx
        edges.append((lo[:, 1], hi[:, 1], [(0.0, x - cx) for cx, _, _ in annuli]))
    for t0, t1, placed in edges:
        pieces = []  # per annulus: the two allowed t-intervals [c - outer, c - inner], [c + inner, c + outer]
        for (c, w), (_, r, big_r) in zip(placed, annuli):
            reach2 = big_r * big_r + delta - w * w
            outer = np.sqrt(np.maximum(reach2, 0.0)) + eta
            inner = np.sqrt(np.maximum(r * r - delta - w * w, 0.0)) - eta
            outer = np.where(reach2 >= 0, outer, -np.inf)  # empty when the edge line misses the disc
            pieces.append(((c - outer, c - inner), (c + inner, c + outer)))
        (a_minus, a_plus), (b_minus, b_plus) = pieces
        for a in (a_minus, a_plus):
            for b in (b_minus, b_plus):
                left = np.maximum(np.maximum(t0, a[0]), b[0])
                right = np.minimum(np.minimum(t1, a[1]), b[1])
                meets |= left <= right
    return meets


def _workspace_anchors(m: FiveBar) -> list[tuple[float, float]]:
    """Points of V that every component of V lying inside a box must bring into it."""
    annuli = _annuli(m)
    circles = [((cx, 0.0), rad) for cx, r, big_r in annuli for rad in (r, big_r)]
    points = [(c[0] + sgn * rad, 0.0) for c, rad in circles for sgn in (-1, 1)]
    for i, (c1, r1) in enumerate(circles):
        for c2, r2 in circles[i + 1:]:
            points += circle_intersections(c1, r1, c2, r2)
    tol = 1e-9 * scale(m) ** 2
    keep = []
    for px, py in points:
        d2 = [(px - cx) ** 2 + py**2 for cx, _, _ in annuli]
        if all(r * r - tol <= d <= big_r * big_r + tol for d, (_, r, big_r) in zip(d2, annuli)):
            keep.append((px, py))
    return sorted(set(keep))


# ---------------------------------------------------------------- the two spaces


SPACES = ("jointspace", "workspace")
PROCEDURES = ("exact", "paper")


def space_root(m: FiveBar, space: str) -> tuple[tuple[float, float], ...]:
    """Root box: [-pi, pi]^2 (a torus) for the joint space, [-(L1+L3), L1+L3]^2 for the workspace."""
    if space == "jointspace":
        return ((-np.pi, np.pi), (-np.pi, np.pi))
    reach = m.L1 + m.L3
    return ((-reach, reach), (-reach, reach))


def space_test(m: FiveBar, space: str, procedure: str = "exact"):
    """The box test of a space: our exact one, or the paper's interval procedure."""
    from fivebar_cli import fivebar_paper

    tests = {
        ("jointspace", "exact"): joint_space_test,
        ("workspace", "exact"): workspace_test,
        ("jointspace", "paper"): fivebar_paper.paper_joint_space_test,
        ("workspace", "paper"): fivebar_paper.paper_workspace_test,
    }
    return tests[space, procedure](m)


# ---------------------------------------------------------------- mode-restricted box tests

ANGLE_MARGIN = 1e-8  # radians: covers rounding of atan2/arccos where the tests use them (see below)


def direction_range(xlo, xhi, ylo, yhi) -> tuple[np.ndarray, np.ndarray]:
    """Exact range of the direction atan2(y, x) over boxes of vectors (width 2 pi if a box holds 0).

    A box not containing the origin is seen under an angle below pi, spanned by its corners;
    angles are unwrapped around the direction of the box centre.
    """
    centre = np.arctan2(0.5 * (ylo + yhi), 0.5 * (xlo + xhi))
    lo = np.full(np.shape(xlo), np.inf)
    hi = np.full(np.shape(xlo), -np.inf)
    for x in (xlo, xhi):
        for y in (ylo, yhi):
            off = (np.arctan2(y, x) - centre + np.pi) % TWO_PI - np.pi
            lo, hi = np.minimum(lo, off), np.maximum(hi, off)
    origin = (xlo <= 0) & (xhi >= 0) & (ylo <= 0) & (yhi >= 0)
    return np.where(origin, centre - np.pi, centre + lo), np.where(origin, centre + np.pi, centre + hi)


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
    cmin = np.where(np.isnan(cmin), -1.0, cmin)
    cmax = np.where(np.isnan(cmax), 1.0, cmax)
    return np.arccos(np.clip(cmax, -1, 1)), np.arccos(np.clip(cmin, -1, 1))


def sin_sign(lo, hi, margin: float = ANGLE_MARGIN) -> np.ndarray:
    """+1 / -1 where sin is positive / negative on all of [lo - margin, hi + margin], else 0."""
    lo, hi = lo - margin, hi + margin
    k = np.floor(lo / np.pi)
    inside = (lo > k * np.pi) & (hi < (k + 1) * np.pi)
    even = np.mod(k, 2) == 0
    return np.where(inside, np.where(even, 1, -1), 0).astype(np.int8)


def _strict(dmin, dmax, inner: float, outer: float, delta: float) -> np.ndarray:
    """Squared distance strictly inside (inner^2, outer^2) and positive on the whole box, with margin."""
    return (dmin - delta > inner * inner) & (dmax + delta < outer * outer) & (dmin - delta > 0)


def _valid_lengths(dmin, dmax, inner: float, outer: float, delta: float):
    """Length range of the valid part, from a squared-distance range widened by the margin."""
    lo = np.sqrt(np.maximum(dmin - delta, 0.0))
    hi = np.sqrt(np.maximum(dmax + delta, 0.0))
    return np.clip(lo, inner, outer), np.clip(hi, inner, outer)


def working_mode_workspace_test(m: FiveBar, working: tuple[int, int]):
    """Box test in the workspace for one working mode (sign u, sign v).

    1: every P of the box is reachable, non-singular (no serial: strictly inside both annuli;
    no parallel: det A != 0) in this working mode; -1: no P of the box is reachable; 0 otherwise.
    The sign of det A is constant on a black cell; `workspace_assembly_sign` reads it.

    With alpha_i the direction of P - A_i and gamma_i the angle at P in triangle A_i B_i P,
    the legs' directions are th3 = alpha1 + su gamma1 and th4 = alpha2 + sv gamma2, and
    sign det A = sign sin(th4 - th3): its range is the sum of four exact ranges.
    """
    su, sv = working
    (c1, r1, big1), (c2, r2, big2) = _annuli(m)
    delta = DELTA_REL * scale(m) ** 2
    anchors = _workspace_anchors(m)

    def test(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        d1, d2 = leg_distance2_ranges(m, lo, hi)
        status = reach_status(m, lo, hi, (d1, d2), anchors)
        strict = _strict(*d1, r1, big1, delta) & _strict(*d2, r2, big2, delta)
        theta = _leg_direction_range(m, lo, hi, d1, c1, r1, big1, m.L3, m.L1, su, delta)
        theta4 = _leg_direction_range(m, lo, hi, d2, c2, r2, big2, m.L4, m.L2, sv, delta)
        sign = sin_sign(theta4[0] - theta[1], theta4[1] - theta[0])
        black = strict & (sign != 0)
        return np.where(status == -1, -1, np.where(black, 1, 0)).astype(np.int8)

    return test


def _leg_direction_range(m, lo, hi, d2range, cx, inner, outer, coupler, crank, s, delta):
    """Range of the direction of P - B_i over boxes: alpha_i + s gamma_i."""
    a_lo, a_hi = direction_range(lo[:, 0] - cx, hi[:, 0] - cx, lo[:, 1], hi[:, 1])
    m_lo, m_hi = _valid_lengths(*d2range, inner, outer, delta)
    g_lo, g_hi = triangle_angle_range(m_lo, m_hi, coupler, crank)
    return (a_lo + g_lo, a_hi + g_hi) if s > 0 else (a_lo - g_hi, a_hi - g_lo)


def workspace_assembly_sign(m: FiveBar, working: tuple[int, int], points: np.ndarray) -> np.ndarray:
    """Sign of det A at points of the workspace in a working mode (0 where unreachable)."""
    th1, th2, ok = ikp(m, points[:, 0], points[:, 1], working)
    _, _, t = mode_values(m, np.nan_to_num(th1), np.nan_to_num(th2), points)
    return np.where(ok, np.sign(t), 0).astype(np.int8)


def assembly_mode_joint_test(m: FiveBar, assembly: int):
    """Box test in the joint space for one assembly mode (sign of det A).

    1: every (th1, th2) of the box assembles, non-singular (|L3-L4| < |B1B2| < L3+L4 strictly,
    B1 != B2, B11 != 0, B22 != 0); -1: no point of the box assembles; 0 otherwise. The working
    mode is constant on a black cell; `joint_working_mode` reads it.

    With beta the direction of B2 - B1 and alpha, delta the angles of triangle B1 B2 P at B1 and
    B2: th3 = beta + sa alpha, th4 = beta + pi - sa delta; sign B11 = sign sin(th3 - th1),
    sign B22 = sign sin(th4 - th2). The range of beta comes from the exact ranges of the two
    components of B2 - B1 (each a sum of independent sinusoids).
    """

    def test(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        status, strict, u, v = joint_mode_classes(m, assembly, lo, hi)
        black = strict & (u != 0) & (v != 0)
        return np.where(status == -1, -1, np.where(black, 1, 0)).astype(np.int8)

    return test


def joint_mode_classes(m: FiveBar, assembly: int, lo: np.ndarray, hi: np.ndarray):
    """Per box: (assembly status 1/-1/0, certified free of parallel singularity, sign B11, sign B22).

    A sign is 0 where it is not constant on the box; the signs are meaningful where the box is
    free of parallel singularities. `aspects.py` uses the pieces to find the boxes that only a
    serial singularity crosses.
    """
    sa = assembly
    r, big = abs(m.L3 - m.L4), m.L3 + m.L4
    delta = DELTA_REL * scale(m) ** 2
    trig = box_trig(lo, hi)
    dmin, dmax = crank_distance2_range(m, lo, hi, trig)
    status = assembly_status(m, dmin, dmax)
    strict = _strict(dmin, dmax, r, big, delta)
    d_lo, d_hi = _valid_lengths(dmin, dmax, r, big, delta)
    d_lo = np.maximum(d_lo, np.sqrt(delta))  # beta is undefined at B1 = B2; `strict` excludes it
    a_lo, a_hi = triangle_angle_range(d_lo, d_hi, m.L3, m.L4)
    e_lo, e_hi = triangle_angle_range(d_lo, d_hi, m.L4, m.L3)
    b_lo, b_hi = _crank_direction_range(m, lo, hi, trig)
    if sa > 0:
        t3 = (b_lo + a_lo, b_hi + a_hi)
        t4 = (b_lo + np.pi - e_hi, b_hi + np.pi - e_lo)
    else:
        t3 = (b_lo - a_hi, b_hi - a_lo)
        t4 = (b_lo + np.pi + e_lo, b_hi + np.pi + e_hi)
    u = sin_sign(t3[0] - hi[:, 0], t3[1] - lo[:, 0])
    v = sin_sign(t4[0] - hi[:, 1], t4[1] - lo[:, 1])
    return status, strict, u, v


def _crank_direction_range(m: FiveBar, lo, hi, trig):
    """Range of the direction of B2 - B1 over boxes of (th1, th2), from the exact ranges of its
    components L0 + L2 cos th2 - L1 cos th1 and L2 sin th2 - L1 sin th1."""
    ones, zeros = np.ones(len(lo)), np.zeros(len(lo))
    c1 = sinusoid_range(ones, zeros, lo[:, 0], hi[:, 0], trig[0])
    s1 = sinusoid_range(zeros, ones, lo[:, 0], hi[:, 0], trig[0])
    c2 = sinusoid_range(ones, zeros, lo[:, 1], hi[:, 1], trig[1])
    s2 = sinusoid_range(zeros, ones, lo[:, 1], hi[:, 1], trig[1])
    x_lo, x_hi = m.L0 + m.L2 * c2[0] - m.L1 * c1[1], m.L0 + m.L2 * c2[1] - m.L1 * c1[0]
    y_lo, y_hi = m.L2 * s2[0] - m.L1 * s1[1], m.L2 * s2[1] - m.L1 * s1[0]
    return direction_range(x_lo, x_hi, y_lo, y_hi)


def joint_working_mode(m: FiveBar, assembly: int, points: np.ndarray) -> np.ndarray:
    """Working-mode signs (u, v), shape (n, 2), at joint-space points in an assembly mode (0 if none)."""
    p, ok = dkp(m, points[:, 0], points[:, 1], assembly)
    u, v, _ = mode_values(m, points[:, 0], points[:, 1], np.nan_to_num(p))
    return np.where(ok[:, None], np.sign(np.stack([u, v], axis=1)), 0).astype(np.int8)
