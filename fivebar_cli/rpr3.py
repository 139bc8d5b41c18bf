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
from dataclasses import dataclass, field

import numpy as np

from fivebar_cli import arcs

# Circles of the region W, in this order: singularity circle, three rho_max circles, three rho_min.
SIDES = np.array([1, 1, 1, 1, -1, -1, -1])
CIRCLE_NAMES = ("singularity", "rho_max 1", "rho_max 2", "rho_max 3", "rho_min 1", "rho_min 2", "rho_min 3")

# Table 1 of Jiang & Gosselin (k = 0.6, equilateral base of unit area, phi in [100, 165] degrees),
# as printed: case -> (rho_min, rho_max, A1, A2, |A1 - A2|, A_a, dA_a).
PAPER_TABLE1 = {
    1: (0.2, 1.995261, 2.887449, 1.523389, 1.364060, 2.088205, 0.368054),
    2: (0.233276, 2.009044, 2.894137, 1.589744, 1.304393, 2.146203, 0.354989),
    3: (0.295636, 2.033677, 2.871123, 1.711608, 1.159515, 2.234786, 0.314177),
    4: (0.412168, 2.075469, 2.709505, 1.927286, 0.782219, 2.308779, 0.207856),
    5: (0.647965, 2.142531, 1.957423, 1.957423, 0.0, 2.012230, 0.024850),
    6: (0.656267, 2.144448, 1.921667, 1.947769, 0.026102, 1.992113, 0.024325),
}
PAPER_SETUP = (2.0 / 3**0.25, 1.0 / 3**0.25, 3**0.25, 0.6, 100.0, 165.0, 0.2)  # t1, t2, t3, k, phi1, phi2, rho_min
OBJECTIVES = {  # case -> (short name for files, description)
    1: ("given", "given rho_min"),
    2: ("max_A1", "max A(phi1)"),
    3: ("max_A2", "max A(phi2)"),
    4: ("max_A_a", "max A_a"),
    5: ("equal_A1_A2", "min |A1 - A2|"),
    6: ("min_dA_a", "min dA_a"),
}


# ---------------------------------------------------------------- closed forms


def _complex(t1, t2, t3):
    """Base points b (..., 3) as complex numbers and the centroid g (...)."""
    t1, t2, t3 = np.broadcast_arrays(*(np.asarray(v, float) for v in (t1, t2, t3)))
    b = np.stack([np.zeros_like(t1), t1 + 0j, t2 + 1j * t3], -1)
    return b, b.mean(-1)


def _z(k, phi):
    return 1.0 - np.asarray(k, float) * np.exp(1j * np.asarray(phi, float))


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
    o, r, c = _circle_frame(t1, t2, t3, k, phi)
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
    o, r, c = _circle_frame(t1, t2, t3, k, phi)
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
    """Area of W with rho_max = rho_max_auto at the same orientation (a design for that phi)."""
    return area(t1, t2, t3, k, phi, rho_min, rho_max_auto(t1, t2, t3, k, phi, rho_min))


def boundary(t1, t2, t3, k, phi, rho_min, rho_max) -> list[arcs.Arc]:
    """Boundary arcs of W for one design and orientation (Arc.circle indexes CIRCLE_NAMES)."""
    centres, radii = region(t1, t2, t3, k, phi, rho_min, rho_max)
    return arcs.boundary_arcs(centres, radii, SIDES)


# ---------------------------------------------------------------- 1-D optimisation


INVPHI = (math.sqrt(5.0) - 1.0) / 2.0


def golden_min(f, lo, hi, xtol: float = 1e-10):
    """Minimise f on [lo, hi] by golden-section search, for many independent problems at once.

    f maps an array of abscissae (the shape of lo/hi) to values; it is called once per step.
    Finds the minimum of a unimodal f to within xtol; returns (x, f(x)).
    """
    lo, hi = (np.array(v, float) for v in np.broadcast_arrays(lo, hi))
    width = float(np.max(hi - lo, initial=0.0))
    steps = math.ceil(math.log(xtol / width) / math.log(INVPHI)) if width > xtol else 0
    c, d = hi - INVPHI * (hi - lo), lo + INVPHI * (hi - lo)
    fc, fd = f(c), f(d)
    for _ in range(steps):
        left = fc <= fd  # the minimum is in [lo, d]
        hi, lo = np.where(left, d, hi), np.where(left, lo, c)
        x = np.where(left, hi - INVPHI * (hi - lo), lo + INVPHI * (hi - lo))
        fx = f(x)
        c, d, fc, fd = (
            np.where(left, x, d),
            np.where(left, c, x),
            np.where(left, fx, fd),
            np.where(left, fc, fx),
        )
    better = fc <= fd
    return np.where(better, c, d), np.where(better, fc, fd)


def brent_min(f, a: float, b: float, xtol: float = 1e-9, maxiter: int = 200) -> tuple[float, float]:
    """Minimise a scalar f on [a, b] by Brent's method: parabolic steps through the three best
    points when they behave, golden-section steps otherwise (fewer evaluations than pure golden
    section on smooth objectives, still safe on kinks). Returns (x, f(x))."""
    gold = 1.0 - INVPHI
    x = w = v = a + gold * (b - a)
    fx = fw = fv = float(f(x))
    d = e = 0.0
    for _ in range(maxiter):
        mid = 0.5 * (a + b)
        tol1 = 0.5 * xtol + 1e-15 * abs(x)
        if abs(x - mid) <= 2.0 * tol1 - 0.5 * (b - a):
            break
        golden = True
        if abs(e) > tol1:  # try a parabola through x, w, v
            r = (x - w) * (fx - fv)
            q = (x - v) * (fx - fw)
            p = (x - v) * q - (x - w) * r
            q = 2.0 * (q - r)
            p, q = (-p, q) if q > 0 else (p, -q)
            if abs(p) < abs(0.5 * q * e) and q * (a - x) < p < q * (b - x):
                e, d = d, p / q
                golden = False
                if (x + d) - a < 2.0 * tol1 or b - (x + d) < 2.0 * tol1:
                    d = math.copysign(tol1, mid - x)
        if golden:
            e = (a - x) if x >= mid else (b - x)
            d = gold * e
        u = x + (d if abs(d) >= tol1 else math.copysign(tol1, d))
        fu = float(f(u))
        if fu <= fx:
            a, b = (x, b) if u >= x else (a, x)
            v, fv, w, fw, x, fx = w, fw, x, fx, u, fu
        else:
            a, b = (a, u) if u >= x else (u, b)
            if fu <= fw or w == x:
                v, fv, w, fw = w, fw, u, fu
            elif fu <= fv or v in (x, w):
                v, fv = u, fu
    return x, fx


def scan_min(f, lo, hi, grid: int = 33, xtol: float = 1e-10):
    """Global-ish minimum on [lo, hi]: a grid scan brackets the best point, golden section refines.

    Problems are vectorised along the shape of lo/hi; f is called with that shape (plus a trailing
    grid axis for the scan).
    """
    lo, hi = (np.array(v, float) for v in np.broadcast_arrays(lo, hi))
    s = np.linspace(0.0, 1.0, grid)
    xs = lo[..., None] + (hi - lo)[..., None] * s
    fs = f(xs)
    i = np.argmin(fs, axis=-1)
    a = np.take_along_axis(xs, np.maximum(i - 1, 0)[..., None], -1)[..., 0]
    b = np.take_along_axis(xs, np.minimum(i + 1, grid - 1)[..., None], -1)[..., 0]
    x, fx = golden_min(f, a, b, xtol)
    xg = np.take_along_axis(xs, i[..., None], -1)[..., 0]
    fg = np.take_along_axis(fs, i[..., None], -1)[..., 0]
    better = fx <= fg
    return np.where(better, x, xg), np.where(better, fx, fg)


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


# ---------------------------------------------------------------- synthesis over an orientation range


@dataclass(frozen=True)
class MeanArea:
    """Trapezoid mean A_a of A(phi) on [phi1, phi2], n steps, and dA_a = mean |A_i - A_a| over the n + 1 samples."""

    mean: float
    fluctuation: float
    n: int
    phis: np.ndarray = field(repr=False)
    areas: np.ndarray = field(repr=False)


def mean_area(t1, t2, t3, k, phi1, phi2, rho_min, rho_max, n0: int = 25, rtol: float = 1e-6) -> MeanArea:
    """A_a by the trapezoid rule on n equal steps, n doubled from n0 until two estimates differ by
    less than rtol (relative); dA_a is then the mean of |A_i - A_a| over the n + 1 samples."""
    n = n0
    phis = np.linspace(phi1, phi2, n + 1)
    a = area(t1, t2, t3, k, phis, rho_min, rho_max)
    est = _trapezoid_mean(a)
    while True:
        if n > 1 << 20:
            raise ArithmeticError(f"mean area did not converge with n = {n}")
        mids = 0.5 * (phis[:-1] + phis[1:])
        merged, phis2 = np.empty(2 * n + 1), np.empty(2 * n + 1)
        merged[0::2], merged[1::2] = a, area(t1, t2, t3, k, mids, rho_min, rho_max)
        phis2[0::2], phis2[1::2] = phis, mids
        new, a, phis, n = _trapezoid_mean(merged), merged, phis2, 2 * n
        if abs(new - est) <= rtol * abs(new):  # '<=': an empty W (area 0) has converged
            return MeanArea(float(new), float(np.mean(np.abs(a - new))), n, phis, a)
        est = new


def _trapezoid_mean(a):
    n = a.shape[-1] - 1
    return (a[..., 1:-1].sum(-1) + 0.5 * (a[..., 0] + a[..., -1])) / n


@dataclass(frozen=True)
class Case:
    """One row of Table 1: a minimal leg length, the rho_max safe over the range, and the areas."""

    number: int
    objective: str
    rho_min: float
    rho_max: float
    a1: float
    a2: float
    mean: float
    fluctuation: float
    n: int

    @property
    def diff_rounded(self) -> float:
        """|A1 - A2| as printed in the paper: the difference of A1 and A2 rounded to 6 decimals."""
        return abs(round(self.a1, 6) - round(self.a2, 6))


def evaluate_case(t1, t2, t3, k, phi1, phi2, rho_min, number=0, objective="") -> Case:
    """All Table-1 quantities for one rho_min (rho_max from rho_max_range)."""
    rho_max = float(rho_max_range(t1, t2, t3, k, phi1, phi2, rho_min))
    a1, a2 = (float(area(t1, t2, t3, k, p, rho_min, rho_max)) for p in (phi1, phi2))
    m = mean_area(t1, t2, t3, k, phi1, phi2, rho_min, rho_max)
    return Case(number, objective, float(rho_min), rho_max, a1, a2, m.mean, m.fluctuation, m.n)


def is_paper_table1(t1, t2, t3, k, phi1_deg, phi2_deg, rho_min, tol: float = 1e-6) -> bool:
    """Whether a design is the setup of the paper's Table 1 (to compare with the printed values)."""
    return all(abs(a - b) <= tol for a, b in zip((t1, t2, t3, k, phi1_deg, phi2_deg, rho_min), PAPER_SETUP))


def table1_at_paper_rho_min() -> list[Case]:
    """Our Table 1 evaluated at the paper's printed rho_min of each case."""
    t1, t2, t3, k, p1, p2, _ = PAPER_SETUP
    return [
        evaluate_case(t1, t2, t3, k, math.radians(p1), math.radians(p2), row[0], i, OBJECTIVES[i][1])
        for i, row in PAPER_TABLE1.items()
    ]


def synthesize(t1, t2, t3, k, phi1, phi2, rho_min, grid: int = 17, xtol: float = 1e-10) -> list[Case]:
    """The six cases of section 4.1: given rho_min, optimum at phi1, at phi2, max A_a, A1 = A2,
    min dA_a; rho_min is searched in [0, rho_min_limit at the smaller singularity circle)."""
    pw = phi1 if abs(_z(k, phi1)) <= abs(_z(k, phi2)) else phi2  # the smaller singularity circle
    lim = float(rho_min_limit(t1, t2, t3, k, pw)) * (1.0 - 1e-9)

    def rmax(rho):
        return rho_max_range(t1, t2, t3, k, phi1, phi2, rho)

    def minimise(f, n):  # a grid scan brackets the best point, Brent's method refines it
        xs = np.linspace(0.0, lim, n)
        fs = [f(x) for x in xs]
        i = int(np.argmin(fs))
        x, fx = brent_min(f, xs[max(i - 1, 0)], xs[min(i + 1, n - 1)], xtol)
        return x if fx <= fs[i] else float(xs[i])

    def mean(rho):
        return mean_area(t1, t2, t3, k, phi1, phi2, rho, rmax(rho))

    def gap(rho):
        r = rmax(rho)
        return abs(float(area(t1, t2, t3, k, phi1, rho, r)) - float(area(t1, t2, t3, k, phi2, rho, r)))

    rho = {1: float(rho_min)}
    rho[2] = float(optimal_rho_min(t1, t2, t3, k, phi1, 33, xtol)[0])
    rho[3] = float(optimal_rho_min(t1, t2, t3, k, phi2, 33, xtol)[0])
    rho[4] = minimise(lambda r: -mean(r).mean, grid)
    rho[5] = minimise(gap, 4 * grid)
    rho[6] = minimise(lambda r: mean(r).fluctuation, grid)
    return [evaluate_case(t1, t2, t3, k, phi1, phi2, rho[i], i, OBJECTIVES[i][1]) for i in range(1, 7)]


# ---------------------------------------------------------------- sweeps (figures 3-8)


def sweep_phi(t1, t2, t3, k, rho_min, phis) -> dict:
    """Figures 3, 4, 6, 7: area vs phi at a fixed rho_min and at the optimal rho_min of each phi.

    Each phi is a design of its own: rho_max is rho_max_auto at that phi.
    """
    phis = np.asarray(phis, float)
    rho_max = rho_max_auto(t1, t2, t3, k, phis, rho_min)
    rho_opt, area_opt, rho_max_opt = optimal_rho_min(t1, t2, t3, k, phis)
    return {
        "phi": phis,
        "rho_min": np.full(phis.shape, float(rho_min)),
        "rho_max": rho_max,
        "area": area(t1, t2, t3, k, phis, rho_min, rho_max),
        "rho_min_opt": rho_opt,
        "rho_max_opt": rho_max_opt,
        "area_opt": area_opt,
    }


def sweep_rho_min(t1, t2, t3, k, phi, rhos) -> dict:
    """Figure 5: area vs rho_min at one orientation (rho_max auto, inf past rho_min_limit)."""
    rhos = np.asarray(rhos, float)
    rho_max = rho_max_auto(t1, t2, t3, k, phi, rhos)
    return {"rho_min": rhos, "rho_max": rho_max, "area": area(t1, t2, t3, k, phi, rhos, rho_max)}


def sweep_t2(t1, t3, k, rho_min, phis, t2s) -> dict:
    """Figure 8: area vs t2 with t1 and t3 fixed (so the base area stays t1 t3 / 2), for each phi,
    at a fixed rho_min and at the optimal rho_min. Arrays are (len(phis), len(t2s))."""
    phi, t2 = np.meshgrid(np.asarray(phis, float), np.asarray(t2s, float), indexing="ij")
    rho_max = rho_max_auto(t1, t2, t3, k, phi, rho_min)
    rho_opt, area_opt, rho_max_opt = optimal_rho_min(t1, t2, t3, k, phi)
    return {
        "phi": phi,
        "t2": t2,
        "rho_min": np.full(phi.shape, float(rho_min)),
        "rho_max": rho_max,
        "area": area(t1, t2, t3, k, phi, rho_min, rho_max),
        "rho_min_opt": rho_opt,
        "rho_max_opt": rho_max_opt,
        "area_opt": area_opt,
    }
