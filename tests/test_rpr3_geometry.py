"""3-RPR closed forms checked against independent computations.

The Jacobian is built from first principles (platform points in the paper's moving frame, legs
B_i P_i), never from the workspace-circle centres; areas are checked against shapely polygons and
Monte Carlo; rho_max auto against a dense scan of the singularity circle.
"""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from shapely.geometry import Point

from fivebar_cli.mechanisms.rpr3 import closed_form as rpr3

EQUI = (2 / 3**0.25, 1 / 3**0.25, 3**0.25)
BASES = {"acute": (1.8, 1.2, 1.11), "equilateral": EQUI, "obtuse": (1.8, 2.2, 1.11)}


def paper_frame(t1, t2, t3, k):
    """Platform points P'_i and the centroid p in the moving frame (paper, section 2)."""
    t4, t5, t6 = k * t1, k * t2, k * t3
    return np.array([[0, 0], [t4, 0], [t5, t6]], float), np.array([(t4 + t5) / 3, t6 / 3])


def jacobian_det(t1, t2, t3, k, x, y, phi):
    """det of the 3x3 matrix of rows (e_i, (P_i - X) x e_i), e_i = P_i - B_i: the direct-kinematics
    Jacobian of rho_i rho_i' = e_i . (X' + phi' J (P_i - X))."""
    base = np.array([[0, 0], [t1, 0], [t2, t3]], float)
    pts, p = paper_frame(t1, t2, t3, k)
    rot = np.array([[math.cos(phi), -math.sin(phi)], [math.sin(phi), math.cos(phi)]])
    arm = (pts - p) @ rot.T  # P_i - X
    e = np.array([x, y]) + arm - base
    m = np.stack([e[:, 0], e[:, 1], arm[:, 0] * e[:, 1] - arm[:, 1] * e[:, 0]], 1)
    return np.linalg.det(m), np.prod(np.linalg.norm(m, axis=1))


def paper_centres(t1, t2, t3, k, phi):
    """Centres of the workspace circles, eq. (3) of the paper, written out."""
    (_, _), (t4, _), (t5, t6) = paper_frame(t1, t2, t3, k)[0]
    xp, yp = (t4 + t5) / 3, t6 / 3
    c, s = math.cos(phi), math.sin(phi)
    return np.array([
        [xp * c - yp * s, xp * s + yp * c],
        [xp * c - yp * s - t4 * c + t1, xp * s + yp * c - t4 * s],
        [xp * c - yp * s - t5 * c + t6 * s + t2, xp * s + yp * c - t5 * s - t6 * c + t3],
    ])


def circumradius(t1, t2, t3):
    a, b, c = t1, math.hypot(t2, t3), math.hypot(t2 - t1, t3)
    return a * b * c / (2 * abs(t1 * t3))  # abc / (4 * area)


designs = st.tuples(
    st.floats(0.5, 2.0), st.floats(-2.0, 3.0), st.floats(0.3, 2.0).flatmap(lambda v: st.sampled_from([v, -v])),
    st.floats(0.1, 1.5), st.floats(0.05, math.pi - 0.05),
)


@settings(max_examples=40, deadline=None)
@given(designs)
def test_centres_and_singularity_circle(design):
    t1, t2, t3, k, phi = design
    c = rpr3.workspace_centres(t1, t2, t3, k, phi)
    assert np.allclose(c, paper_centres(t1, t2, t3, k, phi), atol=1e-12)
    o, r = rpr3.singularity_circle(t1, t2, t3, k, phi)
    assert np.allclose(np.hypot(*(c - o).T), r, rtol=1e-12)  # the circumcircle of C1 C2 C3
    assert r == pytest.approx(circumradius(t1, t2, t3) * math.sqrt(1 + k * k - 2 * k * math.cos(phi)), rel=1e-12)


@settings(max_examples=30, deadline=None)
@given(designs, st.floats(0, 2 * math.pi))
def test_jacobian_vanishes_exactly_on_the_singularity_circle(design, theta):
    t1, t2, t3, k, phi = design
    (ox, oy), r = rpr3.singularity_circle(t1, t2, t3, k, phi)
    det, scale = jacobian_det(t1, t2, t3, k, ox + r * math.cos(theta), oy + r * math.sin(theta), phi)
    assert abs(det) <= 1e-11 * scale
    # det is a multiple of |X - o|^2 - R^2 (with a non-zero factor): it vanishes nowhere else
    rng = np.random.default_rng(int(theta * 1e6))
    pts = np.array([ox, oy]) + rng.normal(scale=2 * r, size=(6, 2))
    ratios = [jacobian_det(t1, t2, t3, k, x, y, phi)[0] / (np.hypot(x - ox, y - oy) ** 2 - r * r) for x, y in pts]
    assert abs(ratios[0]) > 1e-6
    assert np.allclose(ratios, ratios[0], rtol=1e-7)


def test_whole_plane_singular_at_phi_0_and_180():
    rng = np.random.default_rng(3)
    for phi in (0.0, math.pi):
        for x, y in rng.normal(size=(5, 2)):
            det, scale = jacobian_det(1.8, 1.2, 1.11, 0.6, x, y, phi)
            assert abs(det) <= 1e-12 * scale
    det, scale = jacobian_det(1.8, 1.2, 1.11, 0.6, 0.3, 0.4, 0.5)
    assert abs(det) > 1e-3 * scale


@pytest.mark.parametrize("k", [0.3, 0.6, 1.0, 1.4])
def test_radius_increases_on_zero_pi(k):
    phi = np.linspace(1e-3, math.pi - 1e-3, 2001)
    for base in BASES.values():
        r = rpr3.singularity_circle(*base, k, phi)[1]
        assert np.all(np.diff(r) > 0)
        assert np.allclose(r, circumradius(*base) * np.sqrt(1 + k * k - 2 * k * np.cos(phi)), rtol=1e-12)
        assert np.all(r > 0)


def test_platform_pose_matches_the_legs():
    t1, t2, t3, k, phi, x, y = 1.8, 2.2, 1.11, 0.6, 0.7, 0.9, 0.4
    p = rpr3.platform_points(t1, t2, t3, k, phi, x, y)
    base = np.array([[0, 0], [t1, 0], [t2, t3]])
    c = rpr3.workspace_centres(t1, t2, t3, k, phi)
    assert np.allclose(np.hypot(*(p - base).T), np.hypot(*(np.array([x, y]) - c).T))  # leg i: |X - C_i|
    assert np.allclose(p.mean(0), [x, y])  # the tracked point is the centroid
    sides = lambda q: np.hypot(*(q - np.roll(q, 1, axis=0)).T)  # noqa: E731
    assert np.allclose(sides(p), k * sides(base))


# ---------------------------------------------------------------- rho_max auto


def brute_rho_max(t1, t2, t3, k, phi, rho, n=400001):
    """min over sampled circle points at distance >= rho from every C_i of the largest distance."""
    (ox, oy), r = rpr3.singularity_circle(t1, t2, t3, k, phi)
    th = np.linspace(0, 2 * math.pi, n)
    px, py = ox + r * np.cos(th), oy + r * np.sin(th)
    d = [np.hypot(px - cx, py - cy) for cx, cy in rpr3.workspace_centres(t1, t2, t3, k, phi)]  # one per centre
    ok = np.minimum(np.minimum(d[0], d[1]), d[2]) >= rho
    far = np.maximum(np.maximum(d[0], d[1]), d[2])
    return (far[ok].min() if ok.any() else np.inf), r


@settings(max_examples=25, deadline=None)
@given(designs, st.floats(0.0, 1.3))
def test_rho_max_auto_against_a_scan_of_the_circle(design, fraction):
    t1, t2, t3, k, phi = design
    r = float(rpr3.singularity_circle(t1, t2, t3, k, phi)[1])
    rho = fraction * r
    ours = float(rpr3.rho_max_auto(t1, t2, t3, k, phi, rho))
    scan, r = brute_rho_max(t1, t2, t3, k, phi, rho)
    if math.isinf(ours):
        assert math.isinf(scan)
        assert rho >= float(rpr3.rho_min_limit(t1, t2, t3, k, phi)) * (1 - 1e-9)
    else:
        assert ours <= scan + 1e-12  # no sampled circle point lies in all three annuli below ours
        assert scan - ours < 2e-4 * r  # and the scan gets there (up to its resolution)


def test_rho_min_limit_is_where_rho_max_auto_becomes_infinite():
    for base in BASES.values():
        for phi in (0.3, 1.2, 2.8):
            lim = float(rpr3.rho_min_limit(*base, 0.6, phi))
            assert np.isfinite(rpr3.rho_max_auto(*base, 0.6, phi, lim * (1 - 1e-9)))
            assert np.isinf(rpr3.rho_max_auto(*base, 0.6, phi, lim * (1 + 1e-9)))


def test_rho_max_auto_equilateral_closed_form():
    # equilateral: the binding point is at chord rho from C3; the far centres are 120 deg + delta away
    phi, rho = math.radians(100), 0.2
    r = float(rpr3.singularity_circle(*EQUI, 0.6, phi)[1])
    delta = 2 * math.asin(rho / (2 * r))
    assert float(rpr3.rho_max_auto(*EQUI, 0.6, phi, rho)) == pytest.approx(
        2 * r * math.sin((2 * math.pi / 3 + delta) / 2), rel=1e-14)


@settings(max_examples=25, deadline=None)
@given(designs, st.floats(0.0, 1.5), st.floats(0.05, 1.0))
def test_rho_max_range_is_the_minimum_over_the_range(design, fraction, width):
    t1, t2, t3, k, phi1 = design
    phi2 = phi1 + width * (math.pi - 0.01 - phi1)
    rho = fraction * float(rpr3.singularity_circle(t1, t2, t3, k, phi1)[1])
    ours = float(rpr3.rho_max_range(t1, t2, t3, k, phi1, phi2, rho))
    phis = np.linspace(phi1, phi2, 4001)
    scan = rpr3.rho_max_auto(t1, t2, t3, k, phis, rho)
    assert ours <= scan.min() * (1 + 1e-12)  # safe at every sampled orientation
    if np.isfinite(scan.min()):
        i = int(np.argmin(scan))  # and attained: refine around the best sample
        fine = rpr3.rho_max_auto(t1, t2, t3, k, np.linspace(phis[max(i - 1, 0)], phis[min(i + 1, 4000)], 20001), rho)
        assert min(scan.min(), fine.min()) - ours <= 1e-6 * scan.min()


def test_rho_max_range_can_be_below_the_first_orientation():
    # non-monotone case: a bisector point of the obtuse base becomes admissible inside the range
    t1, t2, t3, k, rho = 1.8, 2.2, 1.11, 0.6, 0.69
    p1, p2 = math.radians(40), math.radians(60)
    first = float(rpr3.rho_max_auto(t1, t2, t3, k, p1, rho))
    ours = float(rpr3.rho_max_range(t1, t2, t3, k, p1, p2, rho))
    assert ours < first - 0.1
    scan = rpr3.rho_max_auto(t1, t2, t3, k, np.linspace(p1, p2, 20001), rho)
    assert scan.min() >= ours and scan.min() - ours < 1e-3
    # the paper's setup is monotone: the range value is the one at phi1
    for rho in (0.2, 0.412168, 0.656267):
        assert rpr3.rho_max_range(*EQUI, 0.6, math.radians(100), math.radians(165), rho) == rpr3.rho_max_auto(
            *EQUI, 0.6, math.radians(100), rho)


# ---------------------------------------------------------------- areas


def shapely_w(t1, t2, t3, k, phi, rho_min, rho_max, quad_segs=2048):
    (ox, oy), r = rpr3.singularity_circle(t1, t2, t3, k, phi)
    region = Point(ox, oy).buffer(r, quad_segs=quad_segs)
    for cx, cy in rpr3.workspace_centres(t1, t2, t3, k, phi):
        region = region.intersection(Point(cx, cy).buffer(rho_max, quad_segs=quad_segs))
        if rho_min > 0:
            region = region.difference(Point(cx, cy).buffer(rho_min, quad_segs=quad_segs))
    return region.area


@pytest.mark.parametrize("name", sorted(BASES))
@pytest.mark.parametrize("phi_deg,rho_min", [(10, 0.2), (45, 0.2), (45, 0.6), (100, 0.233276), (165, 0.4)])
def test_area_against_shapely(name, phi_deg, rho_min):
    base, phi = BASES[name], math.radians(phi_deg)
    rho_max = float(rpr3.rho_max_auto(*base, 0.6, phi, rho_min))
    exact = float(rpr3.area(*base, 0.6, phi, rho_min, rho_max))
    assert exact == pytest.approx(shapely_w(*base, 0.6, phi, rho_min, rho_max), abs=1e-5)
    # with a smaller, explicit rho_max too
    exact = float(rpr3.area(*base, 0.6, phi, rho_min, 0.9 * rho_max))
    assert exact == pytest.approx(shapely_w(*base, 0.6, phi, rho_min, 0.9 * rho_max), abs=1e-5)


def test_area_against_monte_carlo_and_jacobian_sign():
    rng = np.random.default_rng(11)
    phi, rho_min = math.radians(100), 0.233276
    rho_max = float(rpr3.rho_max_auto(*EQUI, 0.6, phi, rho_min))
    (ox, oy), r = rpr3.singularity_circle(*EQUI, 0.6, phi)
    c = rpr3.workspace_centres(*EQUI, 0.6, phi)
    n = 400_000
    pts = np.array([ox, oy]) + rng.uniform(-r, r, (n, 2))
    d = np.hypot(pts[:, None, 0] - c[:, 0], pts[:, None, 1] - c[:, 1])
    inside = (np.hypot(pts[:, 0] - ox, pts[:, 1] - oy) <= r) & np.all((d >= rho_min) & (d <= rho_max), axis=1)
    p = inside.mean()
    estimate, sigma = p * 4 * r * r, math.sqrt(p * (1 - p) / n) * 4 * r * r
    assert abs(estimate - float(rpr3.area(*EQUI, 0.6, phi, rho_min, rho_max))) < 4 * sigma
    # W is singularity-free: the Jacobian determinant keeps one sign over it
    signs = {np.sign(jacobian_det(*EQUI, 0.6, x, y, phi)[0]) for x, y in pts[inside][:200]}
    assert len(signs) == 1


def test_boundary_of_figure_2_style_region():
    # at rho_max auto the singularity circle only touches the annuli: it is not on the boundary
    phi, rho_min = math.radians(45), 0.2
    rho_max = float(rpr3.rho_max_auto(*EQUI, 0.6, phi, rho_min))
    arcs_ = rpr3.boundary(*EQUI, 0.6, phi, rho_min, rho_max)
    assert sum(a.length for a in arcs_ if a.circle == 0) < 1e-6
    assert sum(a.green() for a in arcs_) == pytest.approx(float(rpr3.area(*EQUI, 0.6, phi, rho_min, rho_max)))
    # with rho_max past the limit the circle does bound W
    arcs_ = rpr3.boundary(*EQUI, 0.6, phi, rho_min, rho_max + 0.2)
    assert sum(a.length for a in arcs_ if a.circle == 0) > 0.1
