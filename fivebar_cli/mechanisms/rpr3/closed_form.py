"""3-RPR with similar base and platform: closed forms, singularity-free workspace, synthesis.

Base B1 = (0, 0), B2 = (t1, 0), B3 = (t2, t3); platform points P'_i = k B_i in the moving frame;
the tracked point X is the platform centroid; phi is the platform orientation (radians here,
degrees only at the command line). With complex numbers b_i = B_i and g the base centroid:

    leg i:  |X - C_i| = rho_i   with   C_i = g + (b_i - g) z,   z = 1 - k exp(i phi),

so the workspace-circle centres form the base scaled by |z| and turned by arg z about g.
The singularity locus of X (legs concurrent) is the circumcircle of C_1 C_2 C_3 (checked in the
tests against the 3x3 Jacobian): centre o = g + (o_B - g) z, radius R = R_B sqrt(1 + k^2 - 2k cos phi),
o_B and R_B being the base's circumcentre and circumradius. R grows on (0, pi) since
d(R^2)/dphi = 2 k R_B^2 sin phi. At phi = 0 or pi the base and the platform are homothetic, the
legs always meet at the homothety centre, and the whole plane is singular.

The singularity-free workspace W is the part inside the singularity circle of the intersection
of the annuli rho_min <= |X - C_i| <= rho_max; its area is exact (arcs.area).
All functions broadcast over their array arguments.
"""

from __future__ import annotations

import math

import numpy as np

from fivebar_cli.numerics import arcs
from fivebar_cli.numerics.optimize import scan_min

# Circles of the region W, in this order: singularity circle, three rho_max circles, three rho_min.
SIDES = np.array([1, 1, 1, 1, -1, -1, -1])
CIRCLE_NAMES = ("singularity", "rho_max 1", "rho_max 2", "rho_max 3", "rho_min 1", "rho_min 2", "rho_min 3")


# ---------------------------------------------------------------- closed forms


def _complex(t1, t2, t3):
    """Base points b (..., 3) as complex numbers and the centroid g (...)."""
    t1, t2, t3 = np.broadcast_arrays(*(np.asarray(v, float) for v in (t1, t2, t3)))
    b = np.stack([np.zeros_like(t1), t1 + 0j, t2 + 1j * t3], -1)
    return b, b.mean(-1)


def _z(k, phi):
    return 1.0 - np.asarray(k, float) * np.exp(1j * np.asarray(phi, float))


def centre_scale(k, phi):
    """|1 - k exp(i phi)|: the factor by which the workspace-circle centres scale the base."""
    return np.abs(_z(k, phi))


def _xy(z):
    return np.stack([z.real, z.imag], -1)


def _circle_frame(t1, t2, t3, k, phi):
    """Singularity-circle centre o (complex), radius R and the centres C_i (..., 3) as complex numbers."""
    b, g = _complex(t1, t2, t3)
    t1, t2, t3 = (np.asarray(v, float) for v in (t1, t2, t3))
    o_b = 0.5 * t1 + 1j * (t2 * t2 + t3 * t3 - t1 * t2) / (2.0 * t3)  # base circumcentre (|o_b - B1| = R_B)
    z = _z(k, phi)
    return g + (o_b - g) * z, np.abs(o_b) * np.abs(z), g[..., None] + (b - g[..., None]) * z[..., None]


def workspace_centres(t1, t2, t3, k, phi):
    """Centres C_i (..., 3, 2) of the workspace circles |X - C_i| = rho_i at orientation phi."""
    return _xy(_circle_frame(t1, t2, t3, k, phi)[2])


def singularity_circle(t1, t2, t3, k, phi):
    """Centre (..., 2) and radius (...) of the singularity circle of the platform centroid."""
    o, r, _ = _circle_frame(t1, t2, t3, k, phi)
    return _xy(o), r


def platform_points(t1, t2, t3, k, phi, x, y):
    """Platform attachment points P_i (..., 3, 2) for centroid (x, y) and orientation phi."""
    b, g = _complex(t1, t2, t3)
    turn = np.asarray(k, float) * np.exp(1j * np.asarray(phi, float))
    return _xy((np.asarray(x) + 1j * np.asarray(y))[..., None] + turn[..., None] * (b - g[..., None]))


def _bisector_points(o, r, c):
    """The six circle points equidistant from two C_i (the perpendicular bisectors pass through o)."""
    out = []
    for i, j in ((0, 1), (1, 2), (2, 0)):
        u = 1j * (c[..., j] - c[..., i]) / np.abs(c[..., j] - c[..., i])
        out += [o + r * u, o - r * u]
    return np.stack(out, -1)


def rho_max_auto(t1, t2, t3, k, phi, rho_min):
    """Largest rho_max for which no point of the singularity circle lies in all three annuli.

    That is min over circle points X with min_i |X - C_i| >= rho_min of max_i |X - C_i| (inf when
    no circle point is that far from all three C_i). On the circle, each |X - C_i| is concave
    between its zeros, so the minimum of the max is at a point equidistant from two C_i (on the
    perpendicular bisector, through the centre) or at an end of the allowed set (distance rho_min
    from some C_i): twelve closed-form candidates.
    """
    return _rho_max_auto(*_circle_frame(t1, t2, t3, k, phi), rho_min)


def _rho_max_auto(o, r, c, rho_min):
    """`rho_max_auto` given the circle frame (o, R, C_i) of the design and orientation."""
    rho = np.asarray(rho_min, float)
    shape = np.broadcast_shapes(r.shape, rho.shape)
    o, r, rho = (np.broadcast_to(v, shape) for v in (o, r, rho))
    c = np.broadcast_to(c, shape + (3,))
    cand = [_bisector_points(o, r, c)]
    reach = rho <= 2.0 * r
    delta = 2.0 * np.arcsin(np.minimum(rho / (2.0 * r), 1.0))
    for i in range(3):  # at distance rho_min from C_i
        for sign in (1.0, -1.0):
            cand.append(np.where(reach, o + (c[..., i] - o) * np.exp(1j * sign * delta), np.nan)[..., None])
    d = np.abs(np.concatenate(cand, -1)[..., None] - c[..., None, :])  # (..., 12, 3)
    with np.errstate(invalid="ignore"):
        feasible = np.all(d >= (rho - 1e-12 * r)[..., None, None], axis=-1)
    return np.where(feasible, d.max(-1), np.inf).min(-1)


def rho_max_range(t1, t2, t3, k, phi1, phi2, rho_min):
    """Largest rho_max keeping the singularity circle out of the three annuli for every phi in
    [phi1, phi2] (a range without multiples of pi), in closed form.

    The configuration at phi is the base scaled by s = |1 - k exp(i phi)| (monotone on the range),
    and every candidate of rho_max_auto has a value that grows with s once it is feasible. So the
    minimum over the range is rho_max_auto at the smallest circle (phi1 on (0, pi), the paper's
    rule), unless a bisector point becomes feasible (its distance to the nearest C_i reaches
    rho_min) inside the range: it then enters with value rho_min * (max distance / min distance).
    """
    s1, s2 = np.abs(_z(k, phi1)), np.abs(_z(k, phi2))
    p_lo = np.where(s1 <= s2, phi1, phi2)
    growth = np.maximum(s1, s2) / np.minimum(s1, s2)
    base = rho_max_auto(t1, t2, t3, k, p_lo, rho_min)
    o, r, c = _circle_frame(t1, t2, t3, k, p_lo)
    d = np.abs(_bisector_points(o, r, c)[..., None] - c[..., None, :])  # (..., 6, 3) at the smallest circle
    near, far = d.min(-1), d.max(-1)
    rho = np.asarray(rho_min, float)[..., None]
    with np.errstate(divide="ignore", invalid="ignore"):
        scale = rho / near  # growth at which the point becomes feasible
        late = (scale > 1.0) & (scale <= np.asarray(growth)[..., None] * (1 + 1e-12))
        entering = np.where(late, rho * far / near, np.inf).min(-1)
    return np.minimum(base, entering)


def rho_min_limit(t1, t2, t3, k, phi):
    """Largest rho_min for which rho_max_auto is finite: 2 R sin(gap / 4), gap = largest arc between C_i."""
    o, r, c = _circle_frame(t1, t2, t3, k, phi)
    th = np.sort(np.angle(c - o[..., None]), axis=-1)
    gaps = np.diff(np.concatenate([th, th[..., :1] + 2 * math.pi], -1), axis=-1)
    return 2.0 * r * np.sin(gaps.max(-1) / 4.0)


def region(t1, t2, t3, k, phi, rho_min, rho_max):
    """Circles of W: centres (..., 7, 2), radii (..., 7); sides are SIDES. rho_max may be inf."""
    return _region(*_circle_frame(t1, t2, t3, k, phi), rho_min, rho_max)


def _region(o, r, c, rho_min, rho_max):
    """`region` given the circle frame (o, R, C_i) of the design and orientation."""
    rmin, rmax = np.asarray(rho_min, float), np.asarray(rho_max, float)
    shape = np.broadcast_shapes(r.shape, rmin.shape, rmax.shape)
    centres = np.broadcast_to(np.concatenate([o[..., None], c, c], -1), shape + (7,))
    radii = np.empty(shape + (7,))
    radii[..., 0], radii[..., 1:4], radii[..., 4:] = r, rmax[..., None], rmin[..., None]
    return _xy(centres), radii


def area(t1, t2, t3, k, phi, rho_min, rho_max):
    """Exact area of the singularity-free workspace W (broadcast over all arguments)."""
    centres, radii = region(t1, t2, t3, k, phi, rho_min, rho_max)
    return arcs.area(centres, radii, SIDES)


def area_auto(t1, t2, t3, k, phi, rho_min):
    """Area of W with rho_max = rho_max_auto at the same orientation (a design for that phi); the
    circle frame, which both take, computed once."""
    frame = _circle_frame(t1, t2, t3, k, phi)
    return arcs.area(*_region(*frame, rho_min, _rho_max_auto(*frame, rho_min)), SIDES)


def boundary(t1, t2, t3, k, phi, rho_min, rho_max) -> list[arcs.Arc]:
    """Boundary arcs of W for one design and orientation (Arc.circle indexes CIRCLE_NAMES)."""
    centres, radii = region(t1, t2, t3, k, phi, rho_min, rho_max)
    return arcs.boundary_arcs(centres, radii, SIDES)


def optimal_rho_min(t1, t2, t3, k, phi, grid: int = 33, xtol: float = 1e-10):
    """rho_min maximising the area of W at phi (rho_max auto at phi): (rho_min, area, rho_max)."""
    t1, t2, t3, k, phi = np.broadcast_arrays(*(np.asarray(v, float) for v in (t1, t2, t3, k, phi)))
    lim = rho_min_limit(t1, t2, t3, k, phi) * (1.0 - 1e-9)

    def neg_area(rho):
        extra = rho.ndim - t1.ndim
        args = [v.reshape(v.shape + (1,) * extra) for v in (t1, t2, t3, k, phi)]
        return -area_auto(*args, rho)

    rho, neg = scan_min(neg_area, np.zeros_like(lim), lim, grid, xtol)
    return rho, -neg, rho_max_auto(t1, t2, t3, k, phi, rho)
