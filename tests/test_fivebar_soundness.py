"""Soundness of the certified pavings (the core of "certified") and their areas.

Black cells must hold only valid points and complementary cells only invalid ones, for M1 and M2,
both spaces, both procedures ("exact" and the paper's), at depths 6..10: checked with many points
(uniform, on cell corners and edges, just inside the edges, and around the true boundary curves),
with the point tests in_joint_space / in_workspace (themselves checked against the geometry
in conftest). The box tests are also checked directly on random boxes (hypothesis). Areas converge
to independent values: the lens formula for the workspace, a closed-form sinusoid integrated
numerically for the joint space.
"""

from __future__ import annotations

import functools
import math
import zlib

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from shapely.geometry import Point

from conftest import (
    M1,
    M2,
    MECHS,
    box_samples,
    jointspace_area_numeric,
    jointspace_boundary_points,
    leaf_bounds,
    lens_area,
    singular_b1_eq_b2,
    tree_to_bool,
    valid_joint,
    valid_work,
    workspace_area_closed_form,
    workspace_boundary_points,
)
from fivebar_cli.analyses import spaces
from fivebar_cli.mechanisms.fivebar import kinematics as kin

CASES = [(n, s, p) for n in ("M1", "M2") for s in ("jointspace", "workspace") for p in ("exact", "paper")]
DEPTHS = range(6, 11)


@functools.lru_cache(maxsize=None)
def cached_paving(name: str, space: str, depth: int, procedure: str = "exact"):
    """The certified paving, computed once for the module: several tests read the same pavings."""
    return spaces.pave_space(MECHS[name], space, depth, procedure)


def point_valid(m, space, pts: np.ndarray) -> np.ndarray:
    """The library's point test, cross-checked against the geometry written in conftest."""
    if space == "jointspace":
        got = kin.in_joint_space(m, pts[:, 0], pts[:, 1])
        ref = valid_joint(m, pts[:, 0], pts[:, 1])
    else:
        got = kin.in_workspace(m, pts[:, 0], pts[:, 1])
        ref = valid_work(m, pts[:, 0], pts[:, 1])
    assert np.array_equal(got, ref)
    return got


def cell_points(tree, rng: np.random.Generator, uniform: int = 6) -> np.ndarray:
    """Points of the closed leaves: uniform, corners, edge midpoints, on and just inside the edges."""
    lo, hi = leaf_bounds(tree)
    if len(lo) == 0:
        return np.zeros((0, 2))
    w = hi - lo
    parts = [lo + rng.random((uniform, len(lo), 2)) * w]
    for fx in (0.0, 0.5, 1.0):
        for fy in (0.0, 0.5, 1.0):
            parts.append((lo + np.array([fx, fy]) * w)[None])
    for eps in (1e-12, 1e-9, 1e-6, 1e-3):  # just inside each edge, at a random place along it
        t = rng.random((4, len(lo)))
        parts.append(np.stack([lo[:, 0] + eps * w[:, 0], lo[:, 1] + t[0] * w[:, 1]], axis=-1)[None])
        parts.append(np.stack([hi[:, 0] - eps * w[:, 0], lo[:, 1] + t[1] * w[:, 1]], axis=-1)[None])
        parts.append(np.stack([lo[:, 0] + t[2] * w[:, 0], lo[:, 1] + eps * w[:, 1]], axis=-1)[None])
        parts.append(np.stack([lo[:, 0] + t[3] * w[:, 0], hi[:, 1] - eps * w[:, 1]], axis=-1)[None])
    t = rng.random((2, len(lo)))  # exactly on the edges
    parts.append(np.stack([lo[:, 0], lo[:, 1] + t[0] * w[:, 1]], axis=-1)[None])
    parts.append(np.stack([lo[:, 0] + t[1] * w[:, 0], hi[:, 1]], axis=-1)[None])
    return np.concatenate([p.reshape(-1, 2) for p in parts])


def boundary_points(m, space, rng, n: int = 4000) -> np.ndarray:
    base = jointspace_boundary_points(m, n) if space == "jointspace" else workspace_boundary_points(m, n)
    scale = 2 * np.pi if space == "jointspace" else 2 * (m.L1 + m.L3)
    parts = [base]
    for eps in (1e-13, 1e-10, 1e-7, 1e-4, 1e-2):
        direction = rng.normal(size=base.shape)
        direction /= np.linalg.norm(direction, axis=1, keepdims=True)
        parts.append(base + eps * scale * direction)
    return np.concatenate(parts)


def special_points(m, space) -> list[tuple[float, float]]:
    if space == "jointspace":
        return singular_b1_eq_b2(m)
    return [(0.0, 0.0), (m.L0, 0.0)]


def assert_sound(m, space, paving, rng) -> tuple[int, int]:
    black = cell_points(paving.inside, rng)
    white = cell_points(paving.outside, rng)
    bad_black = black[~point_valid(m, space, black)]
    bad_white = white[point_valid(m, space, white)]
    assert len(bad_black) == 0, f"{len(bad_black)} invalid points in black cells, e.g. {bad_black[:3].tolist()}"
    assert len(bad_white) == 0, f"{len(bad_white)} valid points in complement cells, e.g. {bad_white[:3].tolist()}"
    near = boundary_points(m, space, rng)
    valid = point_valid(m, space, near)
    assert valid.any() and not valid.all()
    in_black = paving.inside.locate(near) >= 0
    in_white = paving.outside.locate(near) >= 0
    assert not np.any(in_black & in_white)
    assert np.all(valid[in_black]), f"invalid boundary points in black cells: {near[in_black & ~valid][:3].tolist()}"
    assert not np.any(valid[in_white]), f"valid boundary points in complement cells: {near[in_white & valid][:3].tolist()}"
    return len(black), len(white)


# ---------------------------------------------------------------- cells against points


@pytest.mark.parametrize("name, space, procedure", CASES)
def test_certified_cells_hold_no_wrong_point(name, space, procedure):
    m = MECHS[name]
    rng = np.random.default_rng(zlib.crc32(f"{name} {space} {procedure}".encode()))  # stable across runs
    total_black = total_white = 0
    for depth in DEPTHS:
        paving = cached_paving(name, space, depth, procedure)
        assert len(paving.inside) > 0 and len(paving.outside) > 0
        b, w = assert_sound(m, space, paving, rng)
        total_black += b
        total_white += w
    assert total_black > 10_000 and total_white > 10_000


@pytest.mark.parametrize("name, space, procedure", CASES)
def test_black_and_complement_cells_never_touch(name, space, procedure):
    """A point shared by a closed black cell and a closed complement cell would be both valid and
    invalid: a sound paving keeps them apart (no face, edge or corner contact; across +-pi in the
    joint space, which is a torus)."""
    depth = 8
    paving = cached_paving(name, space, depth, procedure)
    black, white = tree_to_bool(paving.inside), tree_to_bool(paving.outside)
    assert black.any() and white.any() and not (black & white).any()
    periodic = space == "jointspace"
    for dx in (-1, 0, 1):
        for dy in (-1, 0, 1):
            if periodic:
                moved = np.roll(black, (dx, dy), axis=(0, 1))
            else:
                moved = np.zeros_like(black)
                n = black.shape[0]
                moved[max(dx, 0):n + min(dx, 0), max(dy, 0):n + min(dy, 0)] = \
                    black[max(-dx, 0):n + min(-dx, 0), max(-dy, 0):n + min(-dy, 0)]
            assert not (moved & white).any(), f"a black cell touches a complement cell (offset {dx}, {dy})"


# ---------------------------------------------------------------- singular points


@pytest.mark.parametrize("procedure", ["exact", "paper"])
@pytest.mark.parametrize("space", ["jointspace", "workspace"])
def test_m2_singular_points_stay_undetermined_at_every_depth(space, procedure):
    """B1 = B2 (joint space) and P = A1, P = A2 (workspace) of M2: inside the space's closure,
    assemblable or reachable all around, but singular: never certified at depths 1..12."""
    m = M2
    pavings = {depth: cached_paving("M2", space, depth, procedure) for depth in range(1, 13)}
    for sx, sy in special_points(m, space):
        around = np.array([[sx + dx, sy + dy] for dx in (-1e-7, 0, 1e-7) for dy in (-1e-7, 0, 1e-7)
                           if (dx, dy) != (0, 0)])
        assert np.all(point_valid(m, space, around))  # valid all around the singular point
        if space == "jointspace":
            b1, b2 = kin.cranks(m, sx, sy)
            assert np.hypot(*(b2 - b1)) < 1e-12 <= m.L3 + m.L4  # B1 = B2: |B1B2| = 0 <= L3 + L4
        probes = np.array([[sx, sy]] + [[sx + dx, sy + dy] for dx in (-1e-12, 1e-12) for dy in (-1e-12, 1e-12)])
        for depth, paving in pavings.items():
            assert np.all(paving.inside.locate(probes) < 0), f"depth {depth}: singular point in a black cell"
            assert np.all(paving.outside.locate(probes) < 0), f"depth {depth}: singular point in a complement cell"
            coords, ok = paving.grid.cells_of_points(probes)
            assert ok.all()
            und = set(map(tuple, paving.undetermined.tolist()))
            assert all(tuple(c) in und for c in coords.tolist())


def test_a1_is_a_grid_corner_in_the_m2_workspace():
    """P = A1 = (0, 0) is the common corner of four cells at every depth: all four stay undetermined."""
    for depth in (1, 4, 9, 12):
        paving = cached_paving("M2", "workspace", depth)
        n = 1 << depth
        und = set(map(tuple, paving.undetermined.tolist()))
        assert {(n // 2 - 1, n // 2 - 1), (n // 2, n // 2 - 1), (n // 2 - 1, n // 2), (n // 2, n // 2)} <= und


# ---------------------------------------------------------------- box tests on random boxes


def random_boxes(m, space, rng, n, kind, log_width):
    (x0, x1), (y0, y1) = m.spaces()[space].root
    size = x1 - x0
    if kind == "uniform":
        margin = 0.3 * size
        centres = rng.uniform([x0 - margin, y0 - margin], [x1 + margin, y1 + margin], (n, 2))
    elif kind == "boundary":
        pts = jointspace_boundary_points(m, 512) if space == "jointspace" else workspace_boundary_points(m, 512)
        centres = pts[rng.integers(0, len(pts), n)]
    else:
        pts = np.array(special_points(m, space) + special_points(m, "workspace" if space == "jointspace" else space))
        centres = pts[rng.integers(0, len(pts), n)]
    widths = size * 10.0 ** rng.uniform(log_width - 1.5, log_width, (n, 2))
    lo = centres - widths * rng.random((n, 2))
    return lo, lo + widths


def check_boxes(m, space, procedure, lo, hi, rng) -> np.ndarray:
    status = m.box_test(space, procedure)(lo, hi)
    assert status.dtype == np.int8 and set(np.unique(status).tolist()) <= {-1, 0, 1}
    pts = box_samples(lo, hi, rng, 9, 40)
    valid = point_valid(m, space, pts.reshape(-1, 2)).reshape(pts.shape[:2])
    wrong_in = (status == 1) & ~valid.all(axis=1)
    wrong_out = (status == -1) & valid.any(axis=1)
    assert not wrong_in.any(), f"box {lo[wrong_in][0]}..{hi[wrong_in][0]} declared valid holds an invalid point"
    assert not wrong_out.any(), f"box {lo[wrong_out][0]}..{hi[wrong_out][0]} declared invalid holds a valid point"
    return status


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.sampled_from(CASES), st.integers(0, 2**32 - 1), st.sampled_from(["uniform", "boundary", "special"]),
       st.floats(-8.0, 0.3))
def test_box_tests_are_sound_on_random_boxes(case, seed, kind, log_width):
    name, space, procedure = case
    m = MECHS[name]
    rng = np.random.default_rng(seed)
    lo, hi = random_boxes(m, space, rng, 64, kind, log_width)
    check_boxes(m, space, procedure, lo, hi, rng)


@pytest.mark.parametrize("name, space, procedure", CASES)
def test_box_tests_decide_many_random_boxes_soundly(name, space, procedure):
    """A large deterministic batch, so that many boxes really are decided (1 or -1) and checked."""
    m = MECHS[name]
    rng = np.random.default_rng(11)
    decided = {1: 0, -1: 0}
    for kind in ("uniform", "boundary", "special"):
        for log_width in (-6.0, -3.0, -1.5, -0.5):
            lo, hi = random_boxes(m, space, rng, 400, kind, log_width)
            status = check_boxes(m, space, procedure, lo, hi, rng)
            decided[1] += int(np.sum(status == 1))
            decided[-1] += int(np.sum(status == -1))
    assert decided[1] > 100 and decided[-1] > 100


@pytest.mark.parametrize("procedure", ["exact", "paper"])
@pytest.mark.parametrize("space", ["jointspace", "workspace"])
def test_boxes_around_a_singular_point_are_undetermined(space, procedure):
    """A box holding B1 = B2 (or A1, A2 for the M2 workspace) holds an invalid point and valid ones."""
    m = M2
    rng = np.random.default_rng(5)
    test = m.box_test(space, procedure)
    for sx, sy in special_points(m, space):
        w = 10.0 ** rng.uniform(-9, 0, (500, 2))
        a = rng.uniform(0.05, 0.95, (500, 2))
        lo = np.array([sx, sy]) - a * w
        status = test(lo, lo + w)
        assert np.all(status == 0)
    if space == "workspace":  # A1 and A2 are exact floats: the degenerate box at them is invalid
        for sx, sy in special_points(m, space):
            box = np.array([[sx, sy]])
            assert test(box, box)[0] != 1


# ---------------------------------------------------------------- areas


def test_closed_form_workspace_areas():
    """Lens formula against shapely polygons (fine circles) and the disc inclusions it relies on."""
    q = 4096
    for m in (M1, M2):
        R1, R2 = m.L1 + m.L3, m.L2 + m.L4
        r1, r2 = abs(m.L1 - m.L3), abs(m.L2 - m.L4)
        region = Point(0, 0).buffer(R1, quad_segs=q).intersection(Point(m.L0, 0).buffer(R2, quad_segs=q))
        if r1 > 0:
            region = region.difference(Point(0, 0).buffer(r1, quad_segs=q))
        if r2 > 0:
            region = region.difference(Point(m.L0, 0).buffer(r2, quad_segs=q))
        assert workspace_area_closed_form(m) == pytest.approx(region.area, rel=2e-7)
    # lens limits
    assert lens_area(1.0, 1.0, 2.0) == 0.0
    assert lens_area(1.0, 3.0, 0.5) == pytest.approx(math.pi)
    assert lens_area(2.0, 2.0, 1e-9) == pytest.approx(4 * math.pi)
    # M1: lens of two discs of radius 13 at distance 9 minus two discs of radius 3
    assert workspace_area_closed_form(M1) == pytest.approx(lens_area(13, 13, 9) - 2 * math.pi * 9)
    assert workspace_area_closed_form(M2) == pytest.approx(lens_area(4.6, 4.6, 2.55))


def test_jointspace_area_reference_against_monte_carlo():
    rng = np.random.default_rng(9)
    n = 1_000_000
    for m in (M1, M2):
        th = rng.uniform(-np.pi, np.pi, (n, 2))
        frac = valid_joint(m, th[:, 0], th[:, 1]).mean()
        estimate = frac * (2 * np.pi) ** 2
        sigma = math.sqrt(frac * (1 - frac) / n) * (2 * np.pi) ** 2
        reference = jointspace_area_numeric(m)
        assert abs(estimate - reference) < 5 * sigma
        assert abs(jointspace_area_numeric(m, 100_000) - reference) < 2e-6  # the quadrature has converged


@pytest.mark.parametrize("name", ["M1", "M2"])
@pytest.mark.parametrize("space", ["workspace", "jointspace"])
def test_certified_area_converges_from_below(name, space):
    m = MECHS[name]
    exact_area = workspace_area_closed_form(m) if space == "workspace" else jointspace_area_numeric(m)
    tol = 1e-9 * exact_area  # far below the gaps (>= 1e-2 at depth 12)
    previous_inside, previous_gap, previous_und = -1.0, math.inf, math.inf
    for depth in range(6, 13):
        p = cached_paving(name, space, depth)
        inside, und = p.inside.area, p.undetermined_area
        assert inside < exact_area - tol, f"depth {depth}: certified area {inside} above the true {exact_area}"
        assert inside + und > exact_area + tol, f"depth {depth}: inside + undetermined {inside + und} below the true area"
        assert inside > previous_inside  # grows with depth
        gap = exact_area - inside
        assert gap < 0.6 * previous_gap  # and closes geometrically (about halves per level)
        assert und < 0.6 * previous_und
        previous_inside, previous_gap, previous_und = inside, gap, und
    assert previous_gap < 0.002 * exact_area  # depth 12: within 0.2 %


@pytest.mark.parametrize("name", ["M1", "M2"])
@pytest.mark.parametrize("space", ["workspace", "jointspace"])
def test_paper_procedure_areas_bound_the_true_area(name, space):
    m = MECHS[name]
    exact_area = workspace_area_closed_form(m) if space == "workspace" else jointspace_area_numeric(m)
    for depth in DEPTHS:
        p = cached_paving(name, space, depth, "paper")
        q = cached_paving(name, space, depth, "exact")
        assert p.inside.area < exact_area < p.inside.area + p.undetermined_area
        # the exact tests certify at least as much, on both sides
        assert len(p.inside - q.inside) == 0 and len(p.outside - q.outside) == 0
