"""Soundness of the five-bar box tests beyond M1 and M2 (issue 9, item 5).

- Random mechanisms (hypothesis), including lengths where L0 + L1 + L2 or |L0 - L1 - L2| falls just
  past L3 + L4 or |L3 - L4| (the crank distance then only just reaches, or just misses, a limit),
  with boxes around the points where exactness is hard: the interior critical points of |B1B2|
  (B1, B2 on the line A1A2; B1 = B2), the workspace anchors, random places. Every box a test
  decides is sampled, the special points inside it included, against the reference geometry of
  conftest.py.
- Exact arithmetic: workspace boxes whose far or near corner lies a few ulps beyond a circle; the
  decision is checked with fractions.Fraction (the squared distances of the box's extreme points
  are exact rationals). Float sampling cannot see a box 1e-14 outside |P| = L1 + L3; this can.
"""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from conftest import box_samples, unchecked_fivebar, valid_joint, valid_work
from reference_kinematics import ref_dkp, ref_ikp
from fivebar_cli.mechanisms.fivebar import modes
from fivebar_cli.mechanisms.fivebar.model import FiveBar

SETTINGS = settings(max_examples=80, deadline=None, suppress_health_check=[HealthCheck.too_slow])
ULP = 2.0**-52


@st.composite
def mechanisms(draw):
    """Random five-bars; half of them with L0 tuned so that a crank-distance extreme lands within a
    relative 1e-15 .. 1e-6 of L3 + L4 or |L3 - L4|, on either side."""
    l1, l2, l3, l4 = (draw(st.floats(0.3, 3.0)) for _ in range(4))
    if draw(st.booleans()):
        target = draw(st.sampled_from([l3 + l4, abs(l3 - l4)]))
        eps = draw(st.sampled_from([-1, 1])) * 10.0 ** draw(st.floats(-15, -6)) * target
        # the extremes of |B1B2| on the axis are |L0 +- L1 +- L2|
        l0 = abs(draw(st.sampled_from([target + eps - l1 - l2, target + eps + l1 + l2, target + eps + l1 - l2,
                                        target + eps - l1 + l2])))
        if l0 < 0.05:
            l0 = draw(st.floats(0.3, 3.0))
    else:
        l0 = draw(st.floats(0.1, 3.0))
    return unchecked_fivebar("random", l0, l1, l2, l3, l4)  # also designs a file would refuse (flat, never closing)


def special_joint_points(m: FiveBar) -> np.ndarray:
    """The interior critical points of |B1B2|: (0 or pi, 0 or pi), and B1 = B2 when the cranks meet."""
    pts = [(a, b) for a in (0.0, math.pi, -math.pi) for b in (0.0, math.pi, -math.pi)]
    d = m.L0
    if abs(m.L1 - m.L2) <= d <= m.L1 + m.L2:
        x = (d * d + m.L1**2 - m.L2**2) / (2 * d)
        h = math.sqrt(max(m.L1**2 - x * x, 0.0))
        for s in (1, -1):
            pts.append((math.atan2(s * h, x), math.atan2(s * h, x - d)))
    return np.array(pts)


def special_work_points(m: FiveBar) -> np.ndarray:
    """The extreme points of the four workspace circles on the x axis, and the circles' crossings."""
    circles = [(0.0, m.L1 + m.L3), (0.0, abs(m.L1 - m.L3)), (m.L0, m.L2 + m.L4), (m.L0, abs(m.L2 - m.L4))]
    pts = [(c + s * r, 0.0) for c, r in circles for s in (1, -1)]
    for i, (c1, r1) in enumerate(circles):
        for c2, r2 in circles[i + 1:]:
            d = abs(c2 - c1)
            if d > 0 and abs(r1 - r2) <= d <= r1 + r2:
                x = (d * d + r1 * r1 - r2 * r2) / (2 * d)
                h = math.sqrt(max(r1 * r1 - x * x, 0.0))
                pts += [(c1 + x * np.sign(c2 - c1), h), (c1 + x * np.sign(c2 - c1), -h)]
    return np.array(pts)


def boxes_around(points: np.ndarray, rng, n: int, scale: float) -> tuple[np.ndarray, np.ndarray]:
    centres = points[rng.integers(0, len(points), n)]
    widths = scale * 10.0 ** rng.uniform(-9, 0, (n, 2))
    lo = centres - widths * rng.random((n, 2))
    return lo, lo + widths


def samples(lo, hi, rng, points: np.ndarray) -> np.ndarray:
    """(boxes, k, 2): a 7 x 7 grid with corners and edges, random points, and every special point
    that lies inside the box (elsewhere replaced by the box centre)."""
    grid = box_samples(lo, hi, rng, 7, 24)
    inside = np.all((points[None] >= lo[:, None]) & (points[None] <= hi[:, None]), axis=2)
    special = np.where(inside[..., None], points[None], 0.5 * (lo + hi)[:, None, :])
    return np.concatenate([grid, special], axis=1)


def assert_sound(status, valid, lo, hi, what: str) -> None:
    wrong_in = (status == 1) & ~valid.all(axis=1)
    wrong_out = (status == -1) & valid.any(axis=1)
    assert not wrong_in.any(), f"{what}: box {lo[wrong_in][0]}..{hi[wrong_in][0]} is black but holds an invalid point"
    assert not wrong_out.any(), f"{what}: box {lo[wrong_out][0]}..{hi[wrong_out][0]} is outside but holds a valid point"


@SETTINGS
@given(m=mechanisms(), seed=st.integers(0, 2**32 - 1))
def test_joint_space_test_is_sound_on_random_mechanisms(m, seed):
    rng = np.random.default_rng(seed)
    points = special_joint_points(m)
    lo, hi = boxes_around(np.concatenate([points, rng.uniform(-math.pi, math.pi, (8, 2))]), rng, 96, 2 * math.pi)
    pts = samples(lo, hi, rng, points)
    status = m.box_test("jointspace")(lo, hi)
    assert_sound(status, valid_joint(m, pts[..., 0], pts[..., 1]), lo, hi, f"joint space of {m}")


@SETTINGS
@given(m=mechanisms(), seed=st.integers(0, 2**32 - 1))
def test_workspace_test_is_sound_on_random_mechanisms(m, seed):
    rng = np.random.default_rng(seed)
    points = special_work_points(m)
    reach = m.L1 + m.L3
    lo, hi = boxes_around(np.concatenate([points, rng.uniform(-reach, reach, (8, 2))]), rng, 96, 2 * reach)
    pts = samples(lo, hi, rng, points)
    status = m.box_test("workspace")(lo, hi)
    assert_sound(status, valid_work(m, pts[..., 0], pts[..., 1]), lo, hi, f"workspace of {m}")


@SETTINGS
@given(m=mechanisms(), seed=st.integers(0, 2**32 - 1), am=st.sampled_from([1, -1]))
def test_assembly_mode_test_is_sound_on_random_mechanisms(m, seed, am):
    """Black: every point assembles in mode `am`, off every singularity; outside: none assembles."""
    rng = np.random.default_rng(seed)
    points = special_joint_points(m)
    lo, hi = boxes_around(np.concatenate([points, rng.uniform(-math.pi, math.pi, (8, 2))]), rng, 96, 2 * math.pi)
    pts = samples(lo, hi, rng, points)
    status = modes.assembly_mode_joint_test(m, am)(lo, hi)
    _, _, u, v, t, ok = ref_dkp(m, pts[..., 0], pts[..., 1], am)
    tol = 1e-9 * (m.L0 + m.L1 + m.L2 + m.L3 + m.L4) ** 2
    regular = ok & (np.abs(u) > tol) & (np.abs(v) > tol) & (np.abs(t) > tol)
    black = status == 1
    assert not (black & ~regular.all(axis=1)).any(), f"assembly {am} of {m}: a black box holds a singular point"
    signs = np.sign(np.stack([u, v], -1))
    same = np.all(signs == signs[:, :1], axis=(1, 2))
    assert same[black].all(), f"assembly {am} of {m}: the working mode changes inside a black box"
    assert not ((status == -1) & ok.any(axis=1)).any(), f"assembly {am} of {m}: an outside box assembles"


@SETTINGS
@given(m=mechanisms(), seed=st.integers(0, 2**32 - 1), wm=st.sampled_from([(1, 1), (1, -1), (-1, 1), (-1, -1)]))
def test_working_mode_test_is_sound_on_random_mechanisms(m, seed, wm):
    rng = np.random.default_rng(seed)
    points = special_work_points(m)
    reach = m.L1 + m.L3
    lo, hi = boxes_around(np.concatenate([points, rng.uniform(-reach, reach, (8, 2))]), rng, 96, 2 * reach)
    pts = samples(lo, hi, rng, points)
    status = modes.working_mode_workspace_test(m, wm)(lo, hi)
    _, _, u, v, t, ok = ref_ikp(m, pts[..., 0], pts[..., 1], wm)
    tol = 1e-9 * (m.L0 + m.L1 + m.L2 + m.L3 + m.L4) ** 2
    black = status == 1
    regular = ok & (np.abs(u) > tol) & (np.abs(v) > tol) & (np.abs(t) > tol)
    assert not (black & ~regular.all(axis=1)).any(), f"working mode {wm} of {m}: a black box holds a singular point"
    assert np.all(np.sign(t) == np.sign(t[:, :1]), axis=1)[black].all()
    assert not ((status == -1) & ok.any(axis=1)).any(), f"working mode {wm} of {m}: an outside box is reachable"


# ---------------------------------------------------------------- exact decisions near the circles


def exact_extremes(cx: float, lo, hi) -> tuple[Fraction, Fraction]:
    """Exact min and max of |P - (cx, 0)|^2 over a box with float bounds (rationals)."""
    c = Fraction(cx)
    x0, x1, y0, y1 = (Fraction(float(v)) for v in (lo[0], hi[0], lo[1], hi[1]))
    nx = min(max(c, x0), x1) - c
    ny = min(max(Fraction(0), y0), y1)
    fx = max(abs(x0 - c), abs(x1 - c))
    fy = max(abs(y0), abs(y1))
    return nx * nx + ny * ny, fx * fx + fy * fy


def boxes_at_circles(m: FiveBar, rng, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Boxes with one corner a few ulps inside or outside one of the workspace circles."""
    circles = [(0.0, m.L1 + m.L3), (0.0, abs(m.L1 - m.L3)), (m.L0, m.L2 + m.L4), (m.L0, abs(m.L2 - m.L4))]
    lo, hi = np.empty((n, 2)), np.empty((n, 2))
    for k in range(n):
        cx, r = circles[rng.integers(0, 4)]
        angle = rng.uniform(-math.pi, math.pi)
        radius = r * (1 + rng.integers(-8, 9) * ULP)
        corner = np.array([cx + radius * math.cos(angle), radius * math.sin(angle)])
        towards = -np.sign([math.cos(angle), math.sin(angle)]) * rng.choice([1, -1])  # into or out of the disc
        width = (m.L1 + m.L3) * 10.0 ** rng.uniform(-12, -3, 2)
        other = corner + towards * width
        lo[k], hi[k] = np.minimum(corner, other), np.maximum(corner, other)
    return lo, hi


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(m=mechanisms(), seed=st.integers(0, 2**32 - 1))
def test_workspace_decisions_are_exact_near_the_circles(m, seed):
    """A black box must lie in both closed annuli exactly; a box declared outside must have an
    exactly outside nearest or farthest point for one annulus (the boxes are tiny, at one circle)."""
    rng = np.random.default_rng(seed)
    lo, hi = boxes_at_circles(m, rng, 48)
    status = m.box_test("workspace")(lo, hi)
    annuli = [(0.0, abs(m.L1 - m.L3), m.L1 + m.L3), (m.L0, abs(m.L2 - m.L4), m.L2 + m.L4)]
    for k in np.flatnonzero(status != 0):
        ext = [exact_extremes(cx, lo[k], hi[k]) for cx, _, _ in annuli]
        inside = all(dmin >= Fraction(r) ** 2 and dmax <= Fraction(big) ** 2 and dmin > 0
                     for (dmin, dmax), (_, r, big) in zip(ext, annuli))
        if status[k] == 1:
            assert inside, f"{m}: box {lo[k]}..{hi[k]} certified inside, exactly it is not"
        else:
            misses = any(dmax < Fraction(r) ** 2 or dmin > Fraction(big) ** 2 for (dmin, dmax), (_, r, big) in zip(ext, annuli))
            corners = [(lo[k][0], lo[k][1]), (lo[k][0], hi[k][1]), (hi[k][0], lo[k][1]), (hi[k][0], hi[k][1])]
            exact_in = [all(Fraction(r) ** 2 <= (Fraction(x) - Fraction(cx)) ** 2 + Fraction(y) ** 2 <= Fraction(big) ** 2
                            for cx, r, big in annuli) for x, y in corners]
            assert misses or not any(exact_in), f"{m}: box {lo[k]}..{hi[k]} certified outside holds a valid corner"


def test_m1_box_just_outside_the_outer_circle_is_not_certified():
    """The issue's case: a box 2.6e-14 outside |P| = 13 must not be black for M1."""
    m = FiveBar("M1", 9.0, 8.0, 5.0, 5.0, 8.0)
    angle = 1.0
    far = 13.0 + 2.6e-14
    corner = np.array([far * math.cos(angle), far * math.sin(angle)])
    lo, hi = corner - 1e-3, corner
    assert exact_extremes(0.0, lo, hi)[1] > 169
    assert m.box_test("workspace")(lo[None], hi[None])[0] != 1
