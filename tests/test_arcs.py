"""Regions bounded by circular arcs: intersections, boundary arcs and exact areas.

Areas are checked against closed forms and, for random configurations, against shapely polygons
(each circle a 4096-gon, so the polygon area is within ~1e-6 relative of the true one).
"""

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from shapely.geometry import Point, box

from conftest import lens_area
from fivebar_cli.numerics import arcs


def shapely_area(centres, radii, sides, quad_segs=1024):
    """Area of the region by polygon clipping (independent of arcs.py)."""
    region = box(-50, -50, 50, 50)
    for (x, y), r, s in zip(centres, radii, sides):
        disc = Point(x, y).buffer(r, quad_segs=quad_segs)
        region = region.intersection(disc) if s > 0 else region.difference(disc)
    return region.area


# ---------------------------------------------------------------- intersections


def test_intersection_points_lie_on_both_circles():
    rng = np.random.default_rng(1)
    c1, c2 = rng.uniform(-1, 1, (500, 2)), rng.uniform(-1, 1, (500, 2))
    r1, r2 = rng.uniform(0.1, 1.5, 500), rng.uniform(0.1, 1.5, 500)
    pts, ok = arcs.circle_intersections(c1, r1, c2, r2)
    d = np.hypot(*(c2 - c1).T)
    assert np.array_equal(ok, (d < r1 + r2) & (d > np.abs(r1 - r2)))  # no random pair is tangent
    for c, r in ((c1, r1), (c2, r2)):
        dist = np.hypot(pts[..., 0] - c[:, None, 0], pts[..., 1] - c[:, None, 1])
        assert np.allclose(dist[ok], r[ok, None], atol=1e-12)


def test_tangent_circles_meet_once_and_separate_circles_never():
    pts, ok = arcs.circle_intersections([0, 0], 1.0, [3, 0], 2.0)  # external tangency at (1, 0)
    assert ok and np.allclose(pts, [[1, 0], [1, 0]])
    pts, ok = arcs.circle_intersections([0, 0], 0.3, [0.1, 0], 0.2)  # internal tangency at (0.3, 0)
    assert ok and np.allclose(pts, [[0.3, 0], [0.3, 0]], atol=1e-12)
    for c2, r2 in (([3, 0], 1.0), ([0.1, 0], 0.5), ([0, 0], 1.0), ([0, 0], 0.5)):  # apart, inside, same, concentric
        assert not arcs.circle_intersections([0, 0], 1.0, c2, r2)[1]


# ---------------------------------------------------------------- areas: closed forms


def test_disc_annulus_and_lens_closed_forms():
    assert arcs.area([[0.3, -2]], [1.7], [1]) == pytest.approx(math.pi * 1.7**2, rel=1e-14)
    assert arcs.area([[0, 0], [0.2, 0.1]], [2.0, 0.5], [1, -1]) == pytest.approx(math.pi * (4 - 0.25), rel=1e-14)
    for d in (0.0, 0.3, 0.9, 1.4, 1.79, 2.5):
        got = arcs.area([[0, 0], [d, 0]], [1.0, 0.8], [1, 1])
        assert got == pytest.approx(lens_area(1.0, 0.8, d), abs=1e-13)
        # the disc minus the other disc is the disc minus the lens
        got = arcs.area([[0, 0], [d, 0]], [1.0, 0.8], [1, -1])
        assert got == pytest.approx(math.pi - lens_area(1.0, 0.8, d), abs=1e-13)


def test_tangencies_and_identical_circles():
    # internally tangent hole: exact annulus-like area despite the tangency
    assert arcs.area([[0, 0], [0.1, 0]], [0.3, 0.2], [1, -1]) == pytest.approx(math.pi * 0.05, abs=1e-15)
    # externally tangent discs: a single point in common
    assert arcs.area([[0, 0], [2, 0]], [1.0, 1.0], [1, 1]) == pytest.approx(0.0, abs=1e-15)
    # the same disc twice counts once; a disc and its own complement leave only the circle
    assert arcs.area([[0, 0], [0, 0]], [1.0, 1.0], [1, 1]) == pytest.approx(math.pi, rel=1e-14)
    assert arcs.area([[0, 0], [0, 0]], [1.0, 1.0], [1, -1]) == pytest.approx(0.0, abs=1e-15)


def test_trivial_empty_and_unbounded_regions():
    assert arcs.area([[0, 0], [5, 5]], [1.0, 0.0], [1, -1]) == pytest.approx(math.pi)  # empty hole
    assert arcs.area([[0, 0], [5, 5]], [1.0, np.inf], [1, 1]) == pytest.approx(math.pi)  # everything
    assert arcs.area([[0, 0], [5, 5]], [1.0, 0.0], [1, 1]) == 0.0  # a point
    assert arcs.area([[0, 0]], [1.0], [-1]) == np.inf  # outside a disc: unbounded
    with pytest.raises(ValueError):
        arcs.area([[0, 0]], [-1.0], [1])


def test_batch_equals_one_by_one():
    rng = np.random.default_rng(7)
    c, r = rng.uniform(-1, 1, (1200, 5, 2)), rng.uniform(0.2, 1.8, (1200, 5))
    sides = np.array([1, 1, -1, 1, -1])
    batch = arcs.area(c, r, sides)  # several internal chunks
    single = [float(arcs.area(c[i], r[i], sides)) for i in range(0, 1200, 97)]
    assert np.array_equal(batch[::97], single)
    assert batch.reshape(30, 40).shape == arcs.area(c.reshape(30, 40, 5, 2), r.reshape(30, 40, 5), sides).shape


# ---------------------------------------------------------------- random configurations vs shapely


circle = st.tuples(
    st.floats(-1, 1, allow_nan=False), st.floats(-1, 1, allow_nan=False), st.floats(0.1, 1.5, allow_nan=False),
    st.sampled_from([1, -1]),
)


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.lists(circle, min_size=1, max_size=5))
def test_area_matches_shapely(circles):
    circles[0] = circles[0][:3] + (1,)  # bounded: at least one disc
    centres = [(x, y) for x, y, _, _ in circles]
    radii = [r for _, _, r, _ in circles]
    sides = [s for *_, s in circles]
    exact = float(arcs.area(centres, radii, sides))
    assert exact == pytest.approx(shapely_area(centres, radii, sides), abs=2e-5)


@settings(max_examples=40, deadline=None)
@given(st.lists(circle, min_size=2, max_size=5))
def test_boundary_arcs_close_up_and_carry_the_area(circles):
    circles[0] = circles[0][:3] + (1,)
    centres = np.array([(x, y) for x, y, _, _ in circles])
    radii = np.array([r for _, _, r, _ in circles])
    sides = np.array([s for *_, s in circles])
    boundary = arcs.boundary_arcs(centres, radii, sides)
    exact = float(arcs.area(centres, radii, sides))
    # boundary_arcs drops the arcs shorter than _MERGE_TOL * the smallest radius (points), at most
    # 2 (M - 1) pieces per circle, each carrying at most length * (r + |c|) / 2 of Green's sum
    # (two nearly coincident circles leave such slivers' ends: found by hypothesis, 3e-11)
    dropped = len(radii) * (len(radii) - 1) * arcs._MERGE_TOL * radii.min() * np.max(radii + np.hypot(*centres.T))
    assert sum(a.green() for a in boundary) == pytest.approx(exact, abs=1e-12 + dropped)
    for loop in arcs.loops(boundary):  # every loop closes: each tail meets the next head
        for a, b in zip(loop, loop[1:] + loop[:1]):
            assert np.linalg.norm(a.tail - b.head) < 1e-6
    # each arc is boundary: just left of its midpoint is inside, just right is outside
    for a in boundary:
        if a.length < 1e-3:
            continue
        mid = 0.5 * (a.start + a.end)
        normal = np.array([math.cos(mid), math.sin(mid)])  # outward from the arc's circle
        p = np.array(a.centre) + a.radius * normal
        inward = -normal * a.side
        near = [p + 1e-7 * inward, p - 1e-7 * inward]
        inside = arcs.contains(near, centres, radii, sides)
        if not np.any(np.abs(np.hypot(*(centres - p).T) - radii)[np.arange(len(radii)) != a.circle] < 1e-6):
            assert inside[0] and not inside[1]


def test_polygon_of_the_loops_has_the_area():
    centres, radii, sides = [[0, 0], [1, 0], [0.5, 0.8], [0.5, 0.3]], [1.0, 1.0, 1.0, 0.2], [1, 1, 1, -1]
    exact = float(arcs.area(centres, radii, sides))
    total = 0.0
    for poly in arcs.polygon(arcs.boundary_arcs(centres, radii, sides), points_per_radian=2000):
        x, y = poly[:, 0], poly[:, 1]
        total += 0.5 * np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y)  # shoelace, signed
    assert total == pytest.approx(exact, rel=1e-6)
    assert exact == pytest.approx(shapely_area(centres, radii, sides), abs=2e-5)


@pytest.mark.parametrize("gap", [1e-13, 1e-12, 1e-9, 1e-6, 1e-3])
def test_nearly_coincident_circles_cut_where_they_meet(gap):
    """Two equal discs whose centres are `gap` * r apart: the lens's area is the closed form
    2 r^2 acos(d / 2r) - (d / 2) sqrt(4 r^2 - d^2), and the arcs meet (the cut points were 1e-5 rad
    off at gap 1e-12 while r^2 - r^2 was left to cancel against d^2)."""
    r, angle = 0.25, 0.7
    d = gap * r
    centres = [(0.3, -0.2), (0.3 + d * math.cos(angle), -0.2 + d * math.sin(angle))]
    lens = 2 * r * r * math.acos(d / (2 * r)) - 0.5 * d * math.sqrt(4 * r * r - d * d)
    assert float(arcs.area(centres, [r, r], [1, 1])) == pytest.approx(lens, rel=1e-13)
    boundary = arcs.boundary_arcs(centres, [r, r], [1, 1])
    assert len(boundary) == 2
    for a, b in zip(boundary, boundary[::-1]):
        assert np.linalg.norm(a.tail - b.head) < 1e-12
