"""The five-bar's mode box tests compute the very floats they computed before they were made faster
(issue 22: ranges of one axis per table entry, remainders and parities without np.mod, amplitudes
only where an extremum lies inside): every verdict and every range bit for bit equal to the frozen
code of `reference_boxtests.py`, on random mechanisms, on the cells of random levels (with their
ends as tables, as the paving engine hands them) and on arbitrary boxes."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fivebar_cli.mechanisms.fivebar import modes
from fivebar_cli.mechanisms.fivebar.boxtests import (
    DELTA_REL, ETA_REL, AngleTables, annuli, leg_distance2_ranges, reach_status, workspace_anchors,
)
from fivebar_cli.mechanisms.fivebar.model import FiveBar, assembles
from fivebar_cli.numerics import ranges
from fivebar_cli.paving.engine import box_pad
from fivebar_cli.paving.grid import boxes_of
from tests import reference_boxtests as ref


def same(a, b) -> bool:
    """Bit for bit: the same dtype, shape and bytes."""
    a, b = np.asarray(a), np.asarray(b)
    return a.dtype == b.dtype and a.shape == b.shape and a.tobytes() == b.tobytes()


def level_cells(m, space: str, rng, n: int = 1500):
    """(lo, hi, ends) of n cells of a random level of `space`, clustered as a paving's are (or not)."""
    level = int(rng.integers(1, 21))
    grid = m.spaces()[space].grid(level)
    spread = int(rng.choice([1, 40, 1 << level]))
    centre = rng.integers(0, 1 << level, 2)
    coords = np.clip(centre + rng.integers(-spread, spread + 1, (n, 2)), 0, (1 << level) - 1)
    ends = grid.axis_ends(level, coords, box_pad(grid))
    lo, hi = boxes_of(ends)
    return lo, hi, ends


def loose_boxes(span: float, rng, n: int = 1500):
    """Boxes anywhere in [-span, span]^2, of widths from 2 span down to 1e-12 span (some empty)."""
    lo = rng.uniform(-span, span, (n, 2))
    width = span * np.ldexp(1.0, -rng.integers(-1, 40, (n, 1))) * rng.uniform(0, 1, (n, 2))
    width[: n // 20] = 0.0
    return lo, lo + width


def special_joint_boxes(m):
    """Boxes whose ends are the critical angles (0, pi, where B1 = B2), and boxes wider than a turn."""
    angles = sorted({a for t1, t2, _ in ref.crank_critical_points(m) for a in (t1, t2)} | {-np.pi, np.pi / 2})
    ends = np.array([(a, b) for a in angles for b in angles])
    lo = np.concatenate([ends, ends - 1e-3, ends - 1e-13, np.full((3, 2), -np.pi)])
    hi = np.concatenate([ends + 1e-3, ends, ends + 1e-13, np.array([[np.pi, np.pi], [7.0, 0.1], [-np.pi, 20.0]])])
    return lo, hi


mechanisms = (st.tuples(st.lists(st.floats(0.5, 10.0), min_size=5, max_size=5), st.booleans())
              .map(lambda t: t[0][:3] + [t[0][3]] * 2 if t[1] else t[0])  # equal couplers: |L3 - L4| = 0
              .filter(lambda lengths: assembles(lengths) is None)
              .map(lambda lengths: FiveBar("random", *lengths)))


def check_joint(m, lo, hi, ends=None):
    assemblies = modes.ASSEMBLY_MODES
    want = ref.joint_classes(m, assemblies, lo, hi)
    got = modes.joint_modes_classes(m, assemblies, lo, hi, ends)
    for g, w in zip(got, want[:4]):
        assert same(g, w)
    tri = modes.coupler_triangle(m, lo, hi, AngleTables.of(lo, hi, ends))
    ranges_got = (tri.dmin, tri.dmax, *tri.d, *tri.a, *tri.e, *tri.b)
    assert all(same(g, w) for g, w in zip(ranges_got, want[4], strict=True))
    open_ = np.ones((len(lo), 2), bool)
    want = ref.joint_tests(m, assemblies, lo, hi)
    assert same(modes.assembly_mode_joint_tests(m, assemblies)(lo, hi, open_, ends), want)
    open_ = np.random.default_rng(len(lo)).random((len(lo), 2)) < 0.6  # a column is read where open only
    got = modes.assembly_mode_joint_tests(m, assemblies)(lo, hi, open_, ends)
    assert same(got[open_], want[open_])


def reach_margins(m):
    scale = m.L0 + m.L1 + m.L2 + m.L3 + m.L4
    return DELTA_REL * scale * scale, ETA_REL * scale


def boundary_boxes(m, rng, n: int = 1500):
    """Boxes of every size around points of the workspace's four circles and of their crossings
    (V's vertices and anchors), where the reach test cannot decide from the distance ranges alone."""
    points = [(cx + rad * np.cos(t), rad * np.sin(t)) for cx, r, big_r in annuli(m) for rad in (r, big_r)
              for t in rng.uniform(-np.pi, np.pi, 40)] + workspace_anchors(m)
    centre = np.array(points)[rng.integers(0, len(points), n)]
    half = (m.L0 + m.L1 + m.L2 + m.L3 + m.L4) * np.ldexp(1.0, -rng.integers(0, 45, (n, 1))) * rng.uniform(0, 1, (n, 2))
    shift = rng.uniform(-1, 1, (n, 2)) * half
    return centre + shift - half, centre + shift + half


def check_workspace(m, lo, hi, ends=None):
    workings = modes.WORKING_MODES
    anchors = workspace_anchors(m)

    def reach(lo_, hi_, d):
        return reach_status(m, lo_, hi_, d, anchors)

    if ends is not None:  # the legs' distance ranges from the ends' tables: point_box_distance2's floats
        got = leg_distance2_ranges(m, lo, hi, ends)
        want = [ranges.point_box_distance2(cx, 0.0, lo, hi) for cx, _, _ in annuli(m)]
        assert all(same(g, w) for g, w in zip(np.concatenate(got), np.concatenate(want), strict=True))
    frozen = ref.reach_status(annuli(m), lo, hi, leg_distance2_ranges(m, lo, hi), anchors, *reach_margins(m))
    assert same(reach_status(m, lo, hi, leg_distance2_ranges(m, lo, hi), anchors), frozen)
    want = ref.workspace_classes(m, workings, lo, hi, reach)
    for tables in (None, ends) if ends is not None else (None,):  # (the regions' classifier takes the tables too)
        got = modes.workspace_modes_classifier(m, workings)(lo, hi, tables)
        assert all(same(g, w) for g, w in zip(got, want, strict=True))
    open_ = np.ones((len(lo), 4), bool)
    assert same(modes.working_mode_workspace_tests(m, workings)(lo, hi, open_, ends),
                ref.workspace_tests(m, workings, lo, hi, reach))


@settings(max_examples=30, deadline=None)
@given(mechanisms, st.integers(0, 2**32 - 1))
def test_joint_space_classes_are_bit_identical(m, seed):
    rng = np.random.default_rng(seed)
    lo, hi, ends = level_cells(m, "jointspace", rng)
    check_joint(m, lo, hi, ends)
    check_joint(m, *loose_boxes(np.pi, rng))
    check_joint(m, *special_joint_boxes(m))


@settings(max_examples=30, deadline=None)
@given(mechanisms, st.integers(0, 2**32 - 1))
def test_workspace_classes_are_bit_identical(m, seed):
    rng = np.random.default_rng(seed)
    lo, hi, ends = level_cells(m, "workspace", rng)
    check_workspace(m, lo, hi, ends)
    scale = m.L0 + m.L1 + m.L2 + m.L3 + m.L4
    check_workspace(m, *loose_boxes(scale, rng))
    check_workspace(m, *boundary_boxes(m, rng))


def test_cells_of_a_level_are_tables_when_they_cluster():
    """The engine's cells (clustered) come as tables with an index; scattered ones one entry per cell;
    either way the bounds are those of `Grid.boxes`'s formula."""
    m = FiveBar("m1", 9, 8, 5, 5, 8)
    grid = m.spaces()["jointspace"].grid(12)
    coords = np.array([[5, 7], [6, 7], [5, 9], [1000, 7]])
    (x, y) = grid.axis_ends(12, coords[:3], 1e-15)
    assert x.index.tolist() == [0, 1, 0] and len(x.low) == 2 and y.index.tolist() == [0, 0, 2] and len(y.low) == 3
    (x, _) = grid.axis_ends(12, coords, 1e-15)
    assert x.index is None and len(x.low) == 4
    width = np.ldexp(np.array([2 * np.pi, 2 * np.pi]), -12)
    lo, hi = grid.boxes(12, coords, 1e-15)
    assert same(lo, grid.lo + coords * width - 1e-15) and same(hi, grid.lo + (coords + 1) * width + 1e-15)


EDGES = np.array([0.0, -0.0, np.pi, -np.pi, 2 * np.pi, 0.5 * np.pi, 1e-300, -1e-300, 1e300, np.inf, -np.inf, np.nan])


@pytest.fixture(scope="module")
def intervals():
    rng = np.random.default_rng(22)
    n = 20000
    lo = np.concatenate([EDGES, np.repeat(EDGES, 3) - np.tile([0, 1e-13, 1], len(EDGES)), rng.uniform(-30, 30, n)])
    width = np.concatenate([np.zeros(len(EDGES)), np.tile([0, 1e-13, 1], len(EDGES)),
                            rng.exponential(1, n) * rng.choice([0, 1e-12, 1e-6, 1, 10], n)])
    return lo, lo + width


def test_range_functions_are_bit_identical(intervals):
    lo, hi = intervals
    with np.errstate(all="ignore"):
        assert same(ranges.sin_sign(lo, hi), ref.sin_sign(lo, hi))
        for angle in (0.0, np.pi, -0.5 * np.pi, 1.234):
            assert same(ranges.angle_inside(angle, lo, hi), ref.angle_inside(angle, lo, hi))
        a, b = np.cos(3 * lo), np.sin(5 * lo) * 2
        assert all(same(g, w) for g, w in zip(ranges.sinusoid_range(a, b, lo, hi), ref.sinusoid_range(a, b, lo, hi)))
        for a, b in ((1.0, 0.0), (0.0, 1.0), (-2.0, 0.5)):
            assert all(same(g, w) for g, w in zip(ranges.sinusoid_range(a, b, lo, hi), ref.sinusoid_range(a, b, lo, hi)))
        for adjacent, opposite in ((5.0, 8.0), (8.0, 5.0), (3.0, 3.0), (1e-3, 7.0)):  # c < 0, > 0, 0
            got = ranges.triangle_angle_range(np.abs(lo), np.abs(hi), adjacent, opposite)
            assert all(same(g, w) for g, w in zip(got, ref.triangle_angle_range(np.abs(lo), np.abs(hi), adjacent, opposite)))
            got = ranges.triangle_angle_range(lo, hi, adjacent, opposite)  # (negative, zero, NaN, inf sides too)
            assert all(same(g, w) for g, w in zip(got, ref.triangle_angle_range(lo, hi, adjacent, opposite)))
        n = len(lo) // 2
        x0, x1, y0, y1 = lo[:n], hi[:n], lo[n:2 * n], hi[n:2 * n]
        got, want = ranges.direction_range(x0, x1, y0, y1), ref.direction_range(x0, x1, y0, y1)
        assert all(same(g, w) for g, w in zip(got, want))


def test_angle_wrapping_is_bit_identical(intervals):
    """The wrap to [-pi, pi) of the IKP's angles and the periodic axes' wrap of points to cells."""
    lo, hi = intervals
    with np.errstate(all="ignore"):
        values = np.concatenate([lo, hi, lo * 1e6, -lo, np.pi * np.arange(-6, 7), np.nextafter(np.pi * np.arange(-6, 7), 0)])
        assert same(ranges.wrap_angle(values), ref.wrap_angle(values))
        assert same(ranges.wrap_angle(values[5]), ref.wrap_angle(values[5]))
        m = FiveBar("m1", 9, 8, 5, 5, 8)
        grid = m.spaces()["jointspace"].grid(14)
        points = np.column_stack([values, values[::-1]])
        assert all(same(g, w) for g, w in zip(grid.cells_of_points(points), ref.cells_of_points(grid, points), strict=True))


def test_centred_corner_angles_are_bit_identical():
    """direction_range's offsets of atan2 angles from the centre's, wrapped without fmod: the frozen
    wrap's floats over all of [-pi, pi]^2, at its ends, signed zeros, and differences near +-2 pi."""
    from fivebar_cli.numerics.ranges import _centred

    rng = np.random.default_rng(6)
    pi = np.pi
    special = np.array([pi, -pi, 0.0, -0.0, np.nextafter(pi, 0), np.nextafter(-pi, 0), pi / 2, -pi / 2, 1e-300,
                        -1e-300, 2e-16, np.nan])
    a = np.concatenate([rng.uniform(-pi, pi, 20000), np.repeat(special, len(special)), np.full(500, pi), np.full(500, -pi)])
    c = np.concatenate([rng.uniform(-pi, pi, 20000), np.tile(special, len(special)),
                        -pi + rng.uniform(0, 1e-12, 500), pi - rng.uniform(0, 1e-12, 500)])
    with np.errstate(invalid="ignore"):
        assert same(_centred(a.copy(), c), ref.wrap_angle(a - c))
    near = c[:20000] + rng.uniform(-1, 1, 20000) * rng.choice([1e-9, 1e-3, 1.0, 3.14], 20000)
    near = np.clip(near, -pi, pi)  # offsets within +-pi only: no remainder corrections needed
    assert same(_centred(near.copy(), c[:20000]), ref.wrap_angle(near - c[:20000]))
    assert _centred(np.zeros(0), np.zeros(0)).shape == (0,)


def test_ikp_and_dkp_are_bit_identical():
    """The IKP and DKP computed in place, coordinate by coordinate (the certificate's links map every
    black leaf's centre through them), against the frozen code: random five-bars (and one with
    equal links, where B1 = B2 happens), points and angles of every shape, on the edges too (P at
    A1 or A2, B1 = B2, scalars, broadcast operands)."""
    from fivebar_cli.mechanisms.fivebar import kinematics as kin
    rng = np.random.default_rng(22)
    designs = [FiveBar("m1", 9, 8, 5, 5, 8), FiveBar("equal", 1, 1, 1, 1, 1)]
    designs += [FiveBar(f"r{k}", *(float(v) for v in rng.uniform(0.2, 3, 5))) for k in range(8)]
    for m in designs:
        for shape in [(), (400,), (6, 7)]:
            th1, th2 = rng.uniform(-4, 4, shape), rng.uniform(-4, 4, shape)
            x, y = (rng.uniform(-1, 1, shape) * kin.scale(m) for _ in range(2))
            if shape == (400,):
                th2[100:300] = _crank_angles_at(m, th1[100:300], m.L3 + m.L4, np.arange(200) % 41 - 20)
                th2[300:] = _crank_angles_at(m, th1[300:], abs(m.L3 - m.L4), np.arange(100) % 41 - 20)
                th1[:4] = th2[:4] = 0.0  # (B1 = B2 for the equal links)
                x[4:6], y[4:6] = (0.0, m.L0), 0.0  # P at A1, at A2
            for assembly in (1, -1):
                assert all(same(g, w) for g, w in zip(kin.dkp(m, th1, th2, assembly), ref.dkp(m, th1, th2, assembly), strict=True))
                assert all(same(g, w) for g, w in zip(kin.dkp(m, th1, 0.5, assembly), ref.dkp(m, th1, 0.5, assembly), strict=True))
                crank_points = kin.cranks(m, th1, th2)
                assert all(same(g, w) for g, w in zip(kin.dkp(m, th1, th2, assembly, crank_points),
                                                      ref.dkp(m, th1, th2, assembly), strict=True))
            for working in [(1, 1), (1, -1), (-1, 1), (-1, -1)]:
                assert all(same(g, w) for g, w in zip(kin.ikp(m, x, y, working), ref.ikp(m, x, y, working), strict=True))
                assert all(same(g, w) for g, w in zip(kin.ikp(m, x, -0.25, working), ref.ikp(m, x, -0.25, working), strict=True))


def _crank_angles_at(m, th1, distance: float, ulps: np.ndarray) -> np.ndarray:
    """Angles th2 (a few ulps off) where |B1B2| = distance, the ends of the DKP's domain, where the
    cosine of the coupler's angle rounds to just above 1 (NaN where no such angle exists)."""
    wx, wy = m.L0 - m.L1 * np.cos(th1), -m.L1 * np.sin(th1)  # A2 - B1
    w = np.hypot(wx, wy)
    k = (distance**2 - w * w - m.L2**2) / (2 * m.L2 * w)
    with np.errstate(invalid="ignore"):
        th2 = np.arctan2(wy, wx) + np.arccos(k)
    return th2 * (1 + ulps * 2.0**-52)
