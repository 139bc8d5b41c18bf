"""The 2-RPR through the new door (issue 8, item 3): certified, sound box tests and the CLI.

Two prismatic legs from A1 = (0, 0) and A2 = (d, 0) meet at P, leg lengths in [rho_min, rho_max].
Every reference here is written from the geometry, not from the code under test:

- workspace membership: rho_min <= |P - A_i| <= rho_max (and P != A_i), by distances;
- joint-space membership: the triangle A1 A2 P closes, |rho1 - rho2| <= d <= rho1 + rho2 (strict
  inequalities off the parallel singularity, where P leaves the base line);
- workspace area: V = (D1 \\ h1) n (D2 \\ h2) for the outer discs D_i and the holes h_i, so by
  inclusion-exclusion |V| = |D1 n D2| - |h1 n D2| - |D1 n h2| + |h1 n h2|, four lenses
  (`lens_area` of conftest);
- joint-space area: the square [rho_min, rho_max]^2 clipped by the three half-planes of the
  triangle inequality (Sutherland-Hodgman), then the shoelace formula.

Soundness: every box a test calls 1 holds only valid points, every box called -1 only invalid ones,
checked on sample points of the box (a grid with its corners and edges, the box's points nearest to
the centres, the crossings of the boundary curves with its edges and points just beside them, the
vertices of the region clipped into it), for random mechanisms and boxes (hypothesis) and for
every leaf of the pavings; dense points, on and beside the boundary curves, must not fall in a
certified cell of the wrong colour.
"""

from __future__ import annotations

import csv
import io
import math
import signal

import numpy as np
import pytest
from click.testing import CliRunner
from conftest import CONFIGS, leaf_bounds, lens_area, ref_decode
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from fivebar_cli.analyses.aspects import analyse_aspects
from fivebar_cli.analyses.locate import locate_configurations
from fivebar_cli.analyses.spaces import pave_space
from fivebar_cli.cli import cli, main
from fivebar_cli.mechanisms.registry import from_description, load_config
from fivebar_cli.mechanisms.rpr2.model import Rpr2

RPR2_YAML = CONFIGS / "rpr2.yaml"
D, RHO_MIN, RHO_MAX = 8.0, 3.0, 15.0
DEMO = Rpr2("rpr2-demo", D, RHO_MIN, RHO_MAX)
SUMMARY = ["space", "name", "procedure", "depth", "evaluations", "K", "inside_area", "undetermined_area",
           "outside_area", "inside_cells", "outside_cells", "undetermined_cells", "exact_area"]
ASPECTS_HEADER = ("aspect,working_mode,assembly_mode,workspace_area,jointspace_area,workspace_cells,"
                  "jointspace_cells,x,y,rho1,rho2,certified,circle_x,circle_y,circle_r,square_x,square_y,square_side")
HYP = settings(max_examples=50, deadline=None, suppress_health_check=[HealthCheck.too_slow])


# ---------------------------------------------------------------- reference geometry (independent)


def legs_ok(m, rho):
    return (rho > 0) & (rho >= m.rho_min) & (rho <= m.rho_max)


def ref_work(m, x, y):
    """P = (x, y) is reachable: both distances to the base points are leg lengths."""
    return legs_ok(m, np.hypot(x, y)) & legs_ok(m, np.hypot(x - m.d, y))


def ref_joint(m, r1, r2, strict=False):
    """(rho1, rho2) assembles: within the limits and the triangle A1 A2 P closes (strictly: P off
    the base line)."""
    ok = legs_ok(m, r1) & legs_ok(m, r2)
    if strict:
        return ok & (np.abs(r1 - r2) < m.d) & (r1 + r2 > m.d)
    return ok & (np.abs(r1 - r2) <= m.d) & (r1 + r2 >= m.d)


def ref_work_area(m) -> float:
    big, small, d = m.rho_max, m.rho_min, m.d
    return lens_area(big, big, d) - 2 * lens_area(small, big, d) + lens_area(small, small, d)


def _clip(poly, a, b, c):
    """Sutherland-Hodgman: the part of a convex polygon where a x + b y <= c."""
    out = []
    for i, p in enumerate(poly):
        q = poly[(i + 1) % len(poly)]
        fp, fq = a * p[0] + b * p[1] - c, a * q[0] + b * q[1] - c
        if fp <= 0:
            out.append(p)
        if (fp < 0 < fq) or (fq < 0 < fp):
            t = fp / (fp - fq)
            out.append((p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])))
    return out


def joint_polygon(m):
    lo, hi, d = m.rho_min, m.rho_max, m.d
    poly = [(lo, lo), (hi, lo), (hi, hi), (lo, hi)]
    for a, b, c in ((-1, -1, -d), (1, -1, d), (-1, 1, d)):  # r1 + r2 >= d, r1 - r2 <= d, r2 - r1 <= d
        poly = _clip(poly, a, b, c)
    return poly


def ref_joint_area(m) -> float:
    poly = joint_polygon(m)
    return 0.5 * abs(sum(p[0] * q[1] - q[0] * p[1] for p, q in zip(poly, poly[1:] + poly[:1])))


def circles(m):
    return [(cx, r) for cx in (0.0, m.d) for r in (m.rho_min, m.rho_max)]


def work_vertices(m) -> np.ndarray:
    """Points every component of V inside a box brings with it: circle-circle crossings, the
    x-extremes of the circles, the base points."""
    pts = [(0.0, 0.0), (m.d, 0.0), (0.5 * m.d, 0.0)]
    for cx, r in circles(m):
        pts += [(cx - r, 0.0), (cx + r, 0.0)]
    for ra in (m.rho_min, m.rho_max):
        for rb in (m.rho_min, m.rho_max):
            x = (ra * ra - rb * rb + m.d * m.d) / (2 * m.d)
            h2 = ra * ra - x * x
            if h2 >= 0:
                pts += [(x, math.sqrt(h2)), (x, -math.sqrt(h2))]
    return np.array(pts)


def scale(m) -> float:
    return m.d + 2 * m.rho_max


# ---------------------------------------------------------------- sample points of boxes


def grid_points(lo, hi, k):
    """k x k points of each box, corners and edges included: shape (m, k*k, 2)."""
    t = np.linspace(0.0, 1.0, k)
    tx, ty = np.repeat(t, k), np.tile(t, k)
    x = lo[:, None, 0] * (1 - tx) + hi[:, None, 0] * tx
    y = lo[:, None, 1] * (1 - ty) + hi[:, None, 1] * ty
    return np.stack([x, y], axis=-1)


def _beside(values, width, m, offsets):
    """The values, and (with offsets) the values moved by +-1e-6 box widths and +-1e-9 scale."""
    if not offsets:
        return list(values)
    shifts = [0.0, -1e-6 * width, 1e-6 * width, -1e-9 * scale(m), 1e-9 * scale(m)]
    return [v + o for v in values for o in shifts]


def work_points(m, lo, hi, k=7, offsets=True):
    """Sample points of workspace boxes (m, n, 2): grid, points nearest to A1 and A2, crossings of
    the four circles with the edges (and just beside them), V's vertices clipped into the box."""
    lx, ly, hx, hy = lo[:, 0], lo[:, 1], hi[:, 0], hi[:, 1]
    pts = [np.clip(0.0, lx, hx), np.clip(0.0, ly, hy), np.clip(m.d, lx, hx), np.clip(0.0, ly, hy)]
    pts = [np.stack(pts[:2], -1), np.stack(pts[2:], -1)]
    w = hi - lo
    for cx, r in circles(m):
        for y0 in (ly, hy):
            h = np.sqrt(np.maximum(r * r - y0 * y0, 0.0))
            for x in _beside((cx - h, cx + h), w[:, 0], m, offsets):
                pts.append(np.stack([x, y0], -1))
        for x0 in (lx, hx):
            h = np.sqrt(np.maximum(r * r - (x0 - cx) ** 2, 0.0))
            for y in _beside((-h, h), w[:, 1], m, offsets):
                pts.append(np.stack([x0, y], -1))
    for v in work_vertices(m):
        pts.append(np.broadcast_to(v, lo.shape))
    extra = np.stack(pts, axis=1)
    allp = np.concatenate([grid_points(lo, hi, k), extra], axis=1)
    return np.clip(allp, lo[:, None, :], hi[:, None, :])


def joint_points(m, lo, hi, k=7, offsets=True):
    """Sample points of joint-space boxes: grid, crossings of the three lines of the triangle
    inequality with the edges (and beside them), the vertices of the joint-space polygon."""
    d = m.d
    lx, ly, hx, hy = lo[:, 0], lo[:, 1], hi[:, 0], hi[:, 1]
    w = hi - lo
    pts = []
    for x0 in (lx, hx):  # r2 on the lines r1 + r2 = d, r1 - r2 = d, r2 - r1 = d
        for y in _beside((d - x0, x0 - d, x0 + d), w[:, 1], m, offsets):
            pts.append(np.stack([x0, y], -1))
    for y0 in (ly, hy):
        for x in _beside((d - y0, y0 + d, y0 - d), w[:, 0], m, offsets):
            pts.append(np.stack([x, y0], -1))
    for v in joint_polygon(m) + [(0.5 * d, 0.5 * d)]:
        pts.append(np.broadcast_to(np.array(v, float), lo.shape))
    allp = np.concatenate([grid_points(lo, hi, k), np.stack(pts, axis=1)], axis=1)
    return np.clip(allp, lo[:, None, :], hi[:, None, :])


def assert_sound(status, pts, valid, what):
    """Boxes called 1 hold only valid sample points, boxes called -1 only invalid ones."""
    ok = valid(pts[..., 0], pts[..., 1])
    bad_in = np.flatnonzero((status == 1) & ~ok.all(axis=1))
    bad_out = np.flatnonzero((status == -1) & ok.any(axis=1))
    assert bad_in.size == 0, f"{what}: {bad_in.size} box(es) called 1 hold invalid points, e.g. #{bad_in[0]}"
    assert bad_out.size == 0, f"{what}: {bad_out.size} box(es) called -1 hold valid points, e.g. #{bad_out[0]}"


# ---------------------------------------------------------------- random mechanisms and boxes


def make_mechanism(d, grow, frac):
    rho_max = 0.5 * d * (1.0 + grow)  # 2 rho_max >= d (grow = 0: the legs only just meet)
    return Rpr2.parse({"name": "h", "type": "rpr2", "base": {"d": d},
                       "legs": {"rho_min": rho_max * frac, "rho_max": rho_max}})


mechanisms = st.builds(
    make_mechanism,
    d=st.floats(0.25, 40.0),
    grow=st.one_of(st.just(0.0), st.floats(0.0, 4.0)),
    frac=st.one_of(st.just(0.0), st.floats(0.0, 0.97)),
)


def random_boxes(rng, root_lo, root_hi, special_pts, xs, ys, n):
    """Boxes of four families: anywhere (widths over 6 decades), around special points (tiny to
    middling), snapped to special coordinates (edges on circle tangents, lines, vertices),
    anchored at a special coordinate with a random width."""
    size = root_hi - root_lo
    span_lo, span_hi = root_lo - 0.1 * size, root_hi + 0.1 * size
    k = n // 4
    c = rng.uniform(span_lo, span_hi, (k, 2))
    w = size * 10.0 ** rng.uniform(-6, 0, (k, 2))
    boxes = [(c - w / 2, c + w / 2)]
    p = special_pts[rng.integers(len(special_pts), size=k)]
    w = size * 10.0 ** rng.uniform(-10, -1, (k, 2))
    c = p + w * rng.normal(0, 1, (k, 2))
    boxes.append((c - w / 2 * rng.uniform(0, 2, (k, 2)), c + w / 2 * rng.uniform(0, 2, (k, 2))))
    a = np.stack([rng.choice(xs, k), rng.choice(ys, k)], -1)
    b = np.stack([rng.choice(xs, k), rng.choice(ys, k)], -1)
    boxes.append((np.minimum(a, b), np.maximum(a, b)))
    a = np.stack([rng.choice(xs, k), rng.choice(ys, k)], -1)
    w = size * 10.0 ** rng.uniform(-9, -0.5, (k, 2)) * rng.choice([-1, 1], (k, 2))
    boxes.append((np.minimum(a, a + w), np.maximum(a, a + w)))
    lo = np.concatenate([b[0] for b in boxes])
    hi = np.concatenate([b[1] for b in boxes])
    return lo, hi


def work_boxes(m, rng, n=240):
    root = np.array(m.spaces()["workspace"].root)
    verts = work_vertices(m)
    t = rng.uniform(0, 2 * np.pi, 40)
    on_circles = np.concatenate([np.stack([cx + r * np.cos(t), r * np.sin(t)], -1) for cx, r in circles(m)])
    special = np.concatenate([verts, on_circles])
    xs = np.unique(np.concatenate([verts[:, 0], root[0]]))
    ys = np.unique(np.concatenate([verts[:, 1], [-m.rho_max, m.rho_max, -m.rho_min, m.rho_min], root[1]]))
    return random_boxes(rng, root[:, 0], root[:, 1], special, xs, ys, n)


def joint_boxes(m, rng, n=240):
    root = np.array(m.spaces()["jointspace"].root)
    lo_r, hi_r = root[:, 0], root[:, 1]
    d = m.d
    special = np.array(joint_polygon(m) + [(0.5 * d, 0.5 * d), (lo_r[0], lo_r[1]), (hi_r[0], hi_r[1])])
    coords = np.array([m.rho_min, m.rho_max, d - m.rho_min, d - m.rho_max, m.rho_min + d, m.rho_max - d, 0.5 * d])
    coords = np.clip(coords, m.rho_min, m.rho_max)
    lo, hi = random_boxes(rng, lo_r, hi_r, special, coords, coords, n)
    lo, hi = np.clip(lo, lo_r, hi_r), np.clip(hi, lo_r, hi_r)  # the legs' limits are the root box
    return lo, hi


@HYP
@given(m=mechanisms, seed=st.integers(0, 2**32 - 1))
def test_workspace_box_tests_are_sound_for_random_mechanisms_and_boxes(m, seed):
    lo, hi = work_boxes(m, np.random.default_rng(seed))
    pts = work_points(m, lo, hi)
    status = m.box_test("workspace")(lo, hi)
    assert status.dtype == np.int8 and set(np.unique(status)) <= {-1, 0, 1}
    assert_sound(status, pts, lambda x, y: ref_work(m, x, y), f"workspace of {m}")
    # the working mode ++ (aspects): black when reachable and off the base line y = 0
    status = m.aspect_model().workspace_test((1, 1))(lo, hi)
    assert_sound(status, pts, lambda x, y: ref_work(m, x, y) & (y != 0), f"working-mode workspace of {m}")


@HYP
@given(m=mechanisms, seed=st.integers(0, 2**32 - 1))
def test_joint_box_tests_are_sound_for_random_mechanisms_and_boxes(m, seed):
    lo, hi = joint_boxes(m, np.random.default_rng(seed))
    pts = joint_points(m, lo, hi)
    status = m.box_test("jointspace")(lo, hi)
    assert_sound(status, pts, lambda a, b: ref_joint(m, a, b), f"joint space of {m}")
    modes = m.aspect_model()
    for am in modes.assembly_modes:  # black: assembles off the parallel singularity
        status = modes.jointspace_test(am)(lo, hi)
        ok = ref_joint(m, pts[..., 0], pts[..., 1], strict=True)
        assert not ((status == 1) & ~ok.all(axis=1)).any()
        assert not ((status == -1) & ref_joint(m, pts[..., 0], pts[..., 1]).any(axis=1)).any()
        free, signs = modes.serial_band_signs(am, lo, hi)
        assert not (free & ~ok.all(axis=1)).any()
        positive = (pts > 0).all(axis=1)  # a leg sign +1 only where every sampled length is > 0
        assert not ((signs == 1) & ~positive).any()


def test_box_tests_decide_most_small_boxes():
    """Soundness alone is met by a test that always says 0: the tests must also decide."""
    rng = np.random.default_rng(7)
    for space, points, valid in (("workspace", work_points, ref_work), ("jointspace", joint_points, ref_joint)):
        root = np.array(DEMO.spaces()[space].root)
        c = rng.uniform(root[:, 0], root[:, 1], (4000, 2))
        lo, hi = c - 0.01, c + 0.01
        status = DEMO.box_test(space)(lo, hi)
        pts = points(DEMO, lo, hi, offsets=False)
        ok = valid(DEMO, pts[..., 0], pts[..., 1])
        decidable = ok.all(axis=1) | ~ok.any(axis=1)  # boxes the boundary does not visibly cross
        assert (status[decidable] == 0).mean() < 0.01
        assert (status == 1).sum() > 1000 and (status == -1).sum() > 500


@settings(max_examples=50, deadline=None)
@given(m=mechanisms)
def test_exact_measures_description_and_roots(m):
    # abs: the lens formula loses about sqrt(eps) R^2 to cancellation when two circles nearly touch
    assert m.exact_measure("workspace") == pytest.approx(ref_work_area(m), rel=1e-9, abs=1e-7 * m.rho_max ** 2)
    assert m.exact_measure("jointspace") == pytest.approx(ref_joint_area(m), rel=1e-9, abs=1e-9 * m.rho_max ** 2)
    again = from_description(m.describe(), m.name, "<test>")
    assert again == m and again.describe() == m.describe()
    # the workspace root holds V: x in [d - rho_max, rho_max], |y| <= rho_max
    (x0, x1), (y0, y1) = m.spaces()["workspace"].root
    assert x0 <= m.d - m.rho_max and m.rho_max <= x1 and y0 <= -m.rho_max and m.rho_max <= y1
    assert m.spaces()["jointspace"].root == ((m.rho_min, m.rho_max), (m.rho_min, m.rho_max))


@settings(max_examples=50, deadline=None)
@given(m=mechanisms, seed=st.integers(0, 2**32 - 1))
def test_aspect_model_kinematics_match_the_geometry(m, seed):
    rng = np.random.default_rng(seed)
    model = m.aspect_model()
    poses = rng.uniform(-m.rho_max, m.rho_max, (300, 2)) + [0.5 * m.d, 0]
    joints, ok = model.ikp(poses, (1, 1))
    assert np.array_equal(ok, ref_work(m, poses[:, 0], poses[:, 1]))
    expected = np.column_stack([np.hypot(*poses[ok].T), np.hypot(poses[ok, 0] - m.d, poses[ok, 1])])
    assert np.allclose(joints[ok], expected)
    assert np.array_equal(model.assembly_signs((1, 1), poses), np.where(ok, np.sign(poses[:, 1]), 0))
    rho = rng.uniform(m.rho_min, m.rho_max, (300, 2))
    for am in (1, -1):
        p, ok = model.dkp(rho, am)
        assert np.array_equal(ok, ref_joint(m, rho[:, 0], rho[:, 1]))
        p = p[ok]
        tol = 1e-6 * scale(m)
        assert np.allclose(np.hypot(p[:, 0], p[:, 1]), rho[ok, 0], atol=tol)
        assert np.allclose(np.hypot(p[:, 0] - m.d, p[:, 1]), rho[ok, 1], atol=tol)
        assert np.all(am * p[:, 1] >= 0)
        assert np.array_equal(model.working_signs(am, rho), np.where(ok[:, None], 1, 0) * np.ones((1, 2)))


# ---------------------------------------------------------------- the demo: closed forms


def test_demo_config_and_closed_forms():
    m = load_config(RPR2_YAML)
    assert m == DEMO and m.kind == "rpr2"
    # the number: a lens of two discs of radius 15 at distance 8 minus two holes of radius 3
    assert ref_work_area(m) == pytest.approx(lens_area(15, 15, 8) - 2 * math.pi * 9, rel=1e-12)
    assert ref_work_area(m) == pytest.approx(413.185, abs=1e-3)
    # the square of side 12 minus the corners r1 + r2 < 8 (legs 2) and |r1 - r2| > 8 (legs 4, twice)
    assert ref_joint_area(m) == pytest.approx(144 - 2 - 8 - 8, rel=1e-12)
    # a Monte Carlo estimate agrees with both (independent of the polygon and lens formulas)
    rng = np.random.default_rng(1)
    p = rng.uniform([-11, -15], [19, 15], (400_000, 2))
    assert ref_work(m, p[:, 0], p[:, 1]).mean() * 900 == pytest.approx(ref_work_area(m), rel=0.01)
    r = rng.uniform(3, 15, (400_000, 2))
    assert ref_joint(m, r[:, 0], r[:, 1]).mean() * 144 == pytest.approx(ref_joint_area(m), rel=0.01)


# ---------------------------------------------------------------- pavings: dense sampling


def paint(tree, n):
    """Depth-D boolean grid of a tree's leaves (bounds from the Morton codes, decoded in conftest)."""
    lo, hi = leaf_bounds(tree)
    root = np.array(tree.grid.root, float)
    w = (root[:, 1] - root[:, 0]) / n
    i0 = np.rint((lo - root[:, 0]) / w).astype(int)
    i1 = np.rint((hi - root[:, 0]) / w).astype(int)
    arr = np.zeros((n, n), dtype=bool)
    for (a, b), (c, e) in zip(i0, i1):
        assert not arr[a:c, b:e].any(), "overlapping leaves"
        arr[a:c, b:e] = True
    return arr


def touches(arr, root, pts, tol=1e-9):
    """Whether each point lies in a closed black cell (within tol cell widths); points outside the
    root box touch nothing."""
    n = arr.shape[0]
    root = np.array(root, float)
    u = (pts - root[:, 0]) / ((root[:, 1] - root[:, 0]) / n)
    inroot = ((u >= -tol) & (u <= n + tol)).all(axis=1)
    hit = np.zeros(len(pts), dtype=bool)
    for dx in (-tol, tol):
        for dy in (-tol, tol):
            i = np.clip(np.floor(u[:, 0] + dx).astype(int), 0, n - 1)
            j = np.clip(np.floor(u[:, 1] + dy).astype(int), 0, n - 1)
            hit |= arr[i, j]
    return hit & inroot


def boundary_points(m, space, count=3000):
    """Points on the boundary curves of a space's set, and beside them (normal offsets of 1e-9,
    1e-6 and 1e-3 times the scale, both sides)."""
    s = scale(m)
    offsets = [0.0] + [sgn * f * s for f in (1e-9, 1e-6, 1e-3) for sgn in (-1, 1)]
    t = np.linspace(0, 2 * np.pi, count, endpoint=False) + 0.01
    out = []
    if space == "workspace":
        for cx, r in circles(m):
            for o in offsets:
                out.append(np.stack([cx + (r + o) * np.cos(t), (r + o) * np.sin(t)], -1))
    else:
        lo, hi, d = m.rho_min, m.rho_max, m.d
        u = np.linspace(lo, hi, count)
        n = np.sqrt(0.5)
        for o in offsets:  # r1 + r2 = d, r1 - r2 = d, r2 - r1 = d, shifted along their normals
            out.append(np.stack([u + o * n, d - u + o * n], -1))
            out.append(np.stack([u + o * n, u - d - o * n], -1))
            out.append(np.stack([u - o * n, u + d + o * n], -1))
    return np.concatenate(out)


def check_paving(m, space, depth, uniform=100_000, boundary=3000, seed=0):
    paving = pave_space(m, space, depth)
    sp = m.spaces()[space]
    valid = (lambda x, y: ref_work(m, x, y)) if space == "workspace" else (lambda a, b: ref_joint(m, a, b))
    points = work_points if space == "workspace" else joint_points
    root = np.array(sp.root)
    for tree, expect in ((paving.inside, True), (paving.outside, False)):
        lo, hi = leaf_bounds(tree)
        assert np.allclose(lo, tree.bounds()[0]) and np.allclose(hi, tree.bounds()[1])
        if len(lo):  # the exact cells lie in the root box; their float bounds may stick out by an ulp
            pts = np.clip(points(m, lo, hi, k=4, offsets=False), root[:, 0], root[:, 1])
            ok = valid(pts[..., 0], pts[..., 1])
            colour = "black" if expect else "white"
            assert (ok.all() if expect else not ok.any()), f"{space} depth {depth}: a {colour} leaf is wrong"
    n = 1 << depth
    black, white = paint(paving.inside, n), paint(paving.outside, n)
    assert not (black & white).any()
    assert n * n - black.sum() - white.sum() == len(paving.undetermined)
    rng = np.random.default_rng(seed)
    pts = np.concatenate([rng.uniform(root[:, 0], root[:, 1], (uniform, 2)), boundary_points(m, space, boundary)])
    ok = valid(pts[:, 0], pts[:, 1])
    in_black, in_white = touches(black, sp.root, pts), touches(white, sp.root, pts)
    assert not (in_black & ~ok).any(), f"{space} depth {depth}: invalid point in a black cell"
    assert not (in_white & ok).any(), f"{space} depth {depth}: valid point in a white cell"
    return paving


@pytest.mark.parametrize("depth", [6, 8, 10])
@pytest.mark.parametrize("space", ["workspace", "jointspace"])
def test_demo_pavings_are_sound_and_bracket_the_exact_area(space, depth):
    paving = check_paving(DEMO, space, depth)
    exact = ref_work_area(DEMO) if space == "workspace" else ref_joint_area(DEMO)
    assert paving.inside.area <= exact <= paving.inside.area + paving.undetermined_area
    root_area = math.prod(b - a for a, b in DEMO.spaces()[space].root)
    assert paving.inside.area + paving.undetermined_area + paving.outside.area == pytest.approx(root_area, rel=1e-12)
    if depth == 10:  # the "must hold": within 1 % of the exact area at depth 10
        assert paving.inside.area >= 0.99 * exact


@settings(max_examples=12, deadline=None)
@given(m=mechanisms, seed=st.integers(0, 2**32 - 1))
def test_random_pavings_are_sound(m, seed):
    for space in ("workspace", "jointspace"):
        paving = check_paving(m, space, 6, uniform=10_000, boundary=500, seed=seed)
        exact = ref_work_area(m) if space == "workspace" else ref_joint_area(m)
        tol = 1e-7 * m.rho_max ** 2  # the reference's lens areas take acos near 1: errors of order sqrt(eps)
        assert paving.inside.area <= exact + tol and exact <= paving.inside.area + paving.undetermined_area + tol


# ---------------------------------------------------------------- aspects (library)


@pytest.fixture(scope="module")
def analysis():
    return analyse_aspects(DEMO, 10)


def test_two_aspects_one_per_side_of_the_base_line(analysis):
    aspects = analysis.aspects
    assert [a.number for a in aspects] == [1, 2]
    assert [a.working for a in aspects] == [(1, 1), (1, 1)]
    assert [a.assembly for a in aspects] == [1, -1]
    assert analysis.crossings == []
    exact_w, exact_j = ref_work_area(DEMO), ref_joint_area(DEMO)
    for a in aspects:
        lo, hi = leaf_bounds(a.workspace)
        assert (lo[:, 1] > 0).all() if a.assembly == 1 else (hi[:, 1] < 0).all()
        pts = work_points(DEMO, lo, hi, k=4, offsets=False)
        assert ref_work(DEMO, pts[..., 0], pts[..., 1]).all()
        assert (np.sign(pts[..., 1]) == a.assembly).all()
        # the half of V on one side has area exact/2 (V is symmetric, the line has no area)
        assert 0.98 * exact_w / 2 <= a.workspace.area <= exact_w / 2
        lo, hi = leaf_bounds(a.jointspace)
        pts = joint_points(DEMO, lo, hi, k=4, offsets=False)
        assert ref_joint(DEMO, pts[..., 0], pts[..., 1], strict=True).all()
        assert 0.99 * exact_j <= a.jointspace.area <= exact_j
        (x, y), (r1, r2) = a.pose, a.joints
        assert np.sign(y) == a.assembly
        assert (r1, r2) == pytest.approx((math.hypot(x, y), math.hypot(x - D, y)), rel=1e-12)
    assert aspects[0].jointspace == aspects[1].jointspace  # both assemblies: the same strict triangle


def test_locate_random_configurations(analysis):
    rng = np.random.default_rng(3)
    poses = rng.uniform([-11, -15], [19, 15], (300, 2))
    r1, r2 = np.hypot(poses[:, 0], poses[:, 1]), np.hypot(poses[:, 0] - D, poses[:, 1])
    # clear of every boundary by a few cells in both spaces (near the base line outside A1 A2,
    # |rho1 - rho2| tends to d: the joint point is then near the joint-space boundary)
    margins = np.abs(np.stack([r1 - RHO_MIN, r1 - RHO_MAX, r2 - RHO_MIN, r2 - RHO_MAX, poses[:, 1],
                               np.abs(r1 - r2) - D, r1 + r2 - D]))
    clear = margins.min(axis=0) > 0.1
    assert clear.sum() > 100
    found = locate_configurations(DEMO, analysis.aspects, poses, "workspace")
    by_input = {}
    for c in found:
        by_input.setdefault(c["input"], []).append(c)
    valid = ref_work(DEMO, poses[:, 0], poses[:, 1])
    assert set(by_input) == set(np.flatnonzero(valid).tolist())
    for k, confs in by_input.items():
        (c,) = confs
        assert (c["rho1"], c["rho2"]) == pytest.approx((r1[k], r2[k]), rel=1e-12)
        assert c["working_mode"] == "++" and c["assembly_mode"] == "+-"[int(poses[k, 1] < 0)]
        if clear[k]:
            assert c["aspect"] == (1 if poses[k, 1] > 0 else 2)
        else:
            assert c["aspect"] in (None, 1 if poses[k, 1] > 0 else 2)
    joints = rng.uniform(RHO_MIN, RHO_MAX, (200, 2))
    found = locate_configurations(DEMO, analysis.aspects, joints, "jointspace")
    strict = ref_joint(DEMO, joints[:, 0], joints[:, 1], strict=True)
    counts = np.bincount([c["input"] for c in found], minlength=len(joints))
    assert np.array_equal(counts, np.where(strict, 2, ref_joint(DEMO, joints[:, 0], joints[:, 1]).astype(int)))
    a, b = joints[:, 0], joints[:, 1]
    height = np.sqrt(np.maximum(a * a - ((a * a - b * b + D * D) / (2 * D)) ** 2, 0))  # |y| of P
    margins = np.abs(np.stack([a - RHO_MIN, a - RHO_MAX, b - RHO_MIN, b - RHO_MAX, np.abs(a - b) - D, a + b - D,
                               height]))
    clear = margins.min(axis=0) > 0.1
    assert clear.sum() > 100
    for c in found:
        k = c["input"]
        assert math.hypot(c["x"], c["y"]) == pytest.approx(joints[k, 0], rel=1e-9)
        assert math.hypot(c["x"] - D, c["y"]) == pytest.approx(joints[k, 1], rel=1e-9)
        assert abs(c["y"]) == pytest.approx(height[k], rel=1e-9, abs=1e-9)
        expected = 1 if c["y"] > 0 else 2
        assert c["aspect"] == expected if clear[k] else c["aspect"] in (None, expected)


# ---------------------------------------------------------------- the CLI


def invoke(*args, code=0):
    result = CliRunner().invoke(cli, [str(a) for a in args], catch_exceptions=False)
    assert result.exit_code == code, result.output
    return result


def read_rows(path):
    with open(path, newline="") as fh:
        rows = list(csv.reader(fh))
    return rows[0], rows[1:]


def inside_area(path):
    header, rows = read_rows(path)
    return float(dict(zip(header, rows[0]))["inside_area"])


def read_qt_text(path):
    """Header fields and the decoded cells of a .qt file (decoded with conftest's ref_decode)."""
    header, body = {}, []
    for line in path.read_text().splitlines():
        if line.startswith("#"):
            key, _, value = line[1:].strip().partition(": ")
            header[key] = value
        else:
            body.append(line.strip())
    depth = int(header["depth"])
    return header, ref_decode("".join(body), depth, 2)


def cell_points(grid, root):
    """Corners and centres of the cells of a boolean grid: (m, 5, 2)."""
    n = grid.shape[0]
    root = np.array(root, float)
    w = (root[:, 1] - root[:, 0]) / n
    lo = root[:, 0] + np.argwhere(grid) * w
    hi = lo + w
    return np.concatenate([grid_points(lo, hi, 2), ((lo + hi) / 2)[:, None, :]], axis=1)


DEPTH = 8


@pytest.fixture(scope="module")
def out(tmp_path_factory):
    """workspace, jointspace and aspects of the demo at depth 8 into one folder (no figures)."""
    folder = tmp_path_factory.mktemp("rpr2")
    for command in ("workspace", "jointspace", "aspects"):
        invoke(command, RPR2_YAML, "--depth", DEPTH, "-o", folder, "--no-plot", "-q")
    return folder


def test_cli_writes_the_same_files_as_for_the_five_bar(out):
    names = sorted(p.relative_to(out).as_posix() for p in out.rglob("*") if p.is_file())
    assert names == sorted([
        "workspace.qt", "workspace.complement.qt", "workspace.csv",
        "jointspace.qt", "jointspace.complement.qt", "jointspace.csv",
        "aspects.csv", "aspects-adjacency.csv",
        "aspects/aspect-01.workspace.qt", "aspects/aspect-01.jointspace.qt", "aspects/aspect-01.workspace.geojson",
        "aspects/aspect-02.workspace.qt", "aspects/aspect-02.jointspace.qt", "aspects/aspect-02.workspace.geojson",
        ".fivebar/workspace.json", ".fivebar/jointspace.json", ".fivebar/aspects.json",  # the runs' manifests
    ])


@pytest.mark.parametrize("space", ["workspace", "jointspace"])
def test_cli_space_files(out, space):
    header, rows = read_rows(out / f"{space}.csv")
    assert header == SUMMARY and len(rows) == 1
    row = dict(zip(header, rows[0]))
    exact = ref_work_area(DEMO) if space == "workspace" else ref_joint_area(DEMO)
    assert (row["space"], row["name"], row["procedure"], row["depth"]) == (space, "rpr2-demo", "exact", str(DEPTH))
    assert float(row["exact_area"]) == pytest.approx(exact, rel=1e-9)
    inside, undet, outside = (float(row[k]) for k in ("inside_area", "undetermined_area", "outside_area"))
    assert inside <= exact <= inside + undet
    root = ((-11.0, 19.0), (-15.0, 15.0)) if space == "workspace" else ((3.0, 15.0), (3.0, 15.0))
    assert inside + undet + outside == pytest.approx(math.prod(b - a for a, b in root), rel=1e-9)
    assert float(row["K"]) == pytest.approx(int(row["evaluations"]) / 4 ** DEPTH, rel=1e-9)
    valid = (lambda x, y: ref_work(DEMO, x, y)) if space == "workspace" else (lambda a, b: ref_joint(DEMO, a, b))
    for name, colour, expect in ((f"{space}.qt", "inside", True), (f"{space}.complement.qt", "outside", False)):
        fields, grid = read_qt_text(out / name)
        assert fields["mechanism"] == "rpr2 d=8.0 rho_min=3.0 rho_max=15.0"
        assert (fields["space"], fields["colour"], fields["depth"]) == (space, colour, str(DEPTH))
        assert fields["root"] == " ".join(str(v) for r in root for v in r)
        pts = cell_points(grid, root)
        ok = valid(pts[..., 0], pts[..., 1])
        assert ok.all() if expect else not ok.any()
        assert grid.sum() * math.prod(b - a for a, b in root) / 4 ** DEPTH == pytest.approx(
            float(row["inside_area" if expect else "outside_area"]), rel=1e-9)


def test_cli_aspects_files(out):
    text = (out / "aspects.csv").read_text()
    assert text.splitlines()[0] == ASPECTS_HEADER
    rows = list(csv.DictReader(io.StringIO(text)))
    assert [(r["aspect"], r["working_mode"], r["assembly_mode"]) for r in rows] == [("1", "++", "+"), ("2", "++", "-")]
    assert [r["certified"] for r in rows] == ["true", "true"]
    assert (out / "aspects-adjacency.csv").read_text().strip().count("\n") == 0  # only its header
    assert (out / "aspects-adjacency.csv").read_text().startswith("aspect_a,aspect_b,")
    for r, sign in zip(rows, (1, -1)):
        x, y, r1, r2 = (float(r[k]) for k in ("x", "y", "rho1", "rho2"))
        assert np.sign(y) == sign
        assert (r1, r2) == pytest.approx((math.hypot(x, y), math.hypot(x - D, y)), rel=1e-9)
        assert 0.95 * ref_work_area(DEMO) / 2 <= float(r["workspace_area"]) <= ref_work_area(DEMO) / 2
        assert 0.99 * ref_joint_area(DEMO) <= float(r["jointspace_area"]) <= ref_joint_area(DEMO)
        fields, ws = read_qt_text(out / "aspects" / f"aspect-0{r['aspect']}.workspace.qt")
        assert (fields["working_mode"], fields["assembly_mode"]) == ("++", r["assembly_mode"])
        pts = cell_points(ws, ((-11.0, 19.0), (-15.0, 15.0)))
        assert ref_work(DEMO, pts[..., 0], pts[..., 1]).all() and (np.sign(pts[..., 1]) == sign).all()
        assert ws.sum() * 900 / 4 ** DEPTH == pytest.approx(float(r["workspace_area"]), rel=1e-9)
        _, js = read_qt_text(out / "aspects" / f"aspect-0{r['aspect']}.jointspace.qt")
        pts = cell_points(js, ((3.0, 15.0), (3.0, 15.0)))
        assert ref_joint(DEMO, pts[..., 0], pts[..., 1], strict=True).all()
        assert js.sum() * 144 / 4 ** DEPTH == pytest.approx(float(r["jointspace_area"]), rel=1e-9)
        n = 1 << DEPTH  # the representative lies in its aspect's cells
        assert ws[int((x + 11) / 30 * n), int((y + 15) / 30 * n)]
        assert js[int((r1 - 3) / 12 * n), int((r2 - 3) / 12 * n)]


def test_cli_locate(out):
    result = invoke("locate", RPR2_YAML, "--pose", 4, 5, "--pose", 4, 0, "--joints", 6, 7, "--joints", 5, 3,
                    "--depth", DEPTH, "-o", out, "--csv")
    rows = list(csv.DictReader(io.StringIO(result.stdout)))
    assert [r["input"] for r in rows] == ["1", "2", "3", "3", "4"]
    pose, singular, up, down, flat = rows
    # rho1 + rho2 = d: P = (5, 0) on the base line, both assemblies are one configuration
    assert (float(flat["x"]), float(flat["y"])) == pytest.approx((5, 0), abs=1e-9)
    assert flat["assembly_mode"] == "0" and flat["aspect"] == "" and "parallel" in flat["singular"]
    assert (pose["working_mode"], pose["assembly_mode"], pose["aspect"], pose["singular"]) == ("++", "+", "1", "")
    assert (float(pose["rho1"]), float(pose["rho2"])) == pytest.approx((math.hypot(4, 5), math.hypot(4 - D, 5)))
    assert singular["assembly_mode"] == "0" and singular["aspect"] == "" and "parallel" in singular["singular"]
    assert (float(singular["rho1"]), float(singular["rho2"])) == pytest.approx((4, 4))
    for row, sign, aspect in ((up, 1, "1"), (down, -1, "2")):
        x, y = float(row["x"]), float(row["y"])
        assert np.sign(y) == sign and row["aspect"] == aspect and row["assembly_mode"] == "+-"[int(sign < 0)]
        assert (math.hypot(x, y), math.hypot(x - D, y)) == pytest.approx((6, 7), rel=1e-9)
        assert (float(row["rho1"]), float(row["rho2"])) == (6.0, 7.0)


def test_cli_figures(tmp_path):
    invoke("aspects", RPR2_YAML, "--depth", 5, "-o", tmp_path, "-q")
    for name in ("aspects-workspace.png", "aspects-jointspace-assembly+.png", "aspects-jointspace-assembly-.png"):
        assert (tmp_path / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize("space", ["workspace", "jointspace"])
def test_cli_refine_equals_a_fresh_run_and_diff(out, tmp_path, space):
    shallow, deep = tmp_path / "d6", tmp_path / "refined"
    invoke(space, RPR2_YAML, "--depth", 6, "-o", shallow, "--no-plot", "-q")
    invoke("refine", shallow / f"{space}.qt", "--depth", DEPTH, "-o", deep, "--no-plot", "-q")
    for name in (f"{space}.qt", f"{space}.complement.qt", f"{space}.csv"):
        assert (deep / name).read_bytes() == (out / name).read_bytes(), name
    invoke("diff", deep / f"{space}.qt", out / f"{space}.qt", "-q", code=0)
    result = invoke("diff", shallow / f"{space}.qt", out / f"{space}.qt", code=1)
    area6, area8 = (inside_area(folder / f"{space}.csv") for folder in (shallow, out))
    lines = result.output.splitlines()
    assert any(line.startswith("only in A: 0 cells, area 0") for line in lines)  # black cells stay black
    (only_b,) = [line for line in lines if line.startswith("only in B:")]
    assert float(only_b.rsplit("area ", 1)[1]) == pytest.approx(area8 - area6, rel=1e-6)
    assert area8 > area6


def test_cli_kratio(tmp_path):
    invoke("kratio", RPR2_YAML, "--depths", "4-6", "-o", tmp_path, "--no-plot", "-q")
    header, rows = read_rows(tmp_path / "kratio.csv")
    assert header[:6] == ["space", "mechanism", "depth", "discretization", "evaluations", "K"]
    assert sorted((r[0], int(r[2])) for r in rows) == [(s, k) for s in ("jointspace", "workspace") for k in (4, 5, 6)]
    for r in rows:
        cells = dict(zip(header, r))
        depth = int(cells["depth"])
        assert cells["mechanism"] == "rpr2-demo" and int(cells["discretization"]) == 4 ** depth
        assert int(cells["evaluations"]) == pave_space(DEMO, cells["space"], depth).evaluations
        assert float(cells["K"]) == pytest.approx(int(cells["evaluations"]) / 4 ** depth, rel=1e-9)
        assert all(v == "" for k, v in cells.items() if "paper" in k)  # no paper numbers for a 2-RPR
        assert 1 <= int(cells["evaluations"]) <= sum(4 ** k for k in range(depth + 1))


# ---------------------------------------------------------------- bad configs


GOOD = {"base": "base: {d: 8}\n", "legs": "legs: {rho_min: 3, rho_max: 15}\n"}
BAD = {
    "rho_min = rho_max": ({"legs": "legs: {rho_min: 15, rho_max: 15}\n"}, "legs"),
    "rho_min > rho_max": ({"legs": "legs: {rho_min: 16, rho_max: 15}\n"}, "legs"),
    "2 rho_max < d": ({"legs": "legs: {rho_min: 1, rho_max: 3.99}\n"}, "legs.rho_max"),
    "negative rho_min": ({"legs": "legs: {rho_min: -1, rho_max: 15}\n"}, "legs.rho_min"),
    "unknown leg key": ({"legs": "legs: {rho_min: 3, rho_max: 15, rho_mid: 9}\n"}, "legs.rho_mid"),
    "unknown key": ({"extra": "colour: red\n"}, "colour"),
    "missing base.d": ({"base": "base: {}\n"}, "base.d"),
    "missing base": ({"base": ""}, "base"),
    "unknown base key": ({"base": "base: {d: 8, e: 1}\n"}, "base.e"),
    "zero d": ({"base": "base: {d: 0}\n"}, "base.d"),
}


def run_main(argv):
    old = signal.getsignal(signal.SIGINT)
    try:
        with pytest.raises(SystemExit) as exc:
            main([str(a) for a in argv])
    finally:
        signal.signal(signal.SIGINT, old)
    return exc.value.code


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_config_is_one_line_and_exit_2(tmp_path, capsys, case):
    parts, field = BAD[case]
    text = "# a broken 2-RPR\nname: bad\ntype: rpr2\n" + "".join({**GOOD, **parts}.values())
    path = tmp_path / "bad.yaml"
    path.write_text(text)
    command = ["workspace", "jointspace", "aspects"][sorted(BAD).index(case) % 3]
    assert run_main([command, path, "--depth", 3, "-o", tmp_path / "out", "--no-plot", "-q"]) == 2
    err = capsys.readouterr().err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in err
    assert f"{path}: {field}:" in lines[0]
    assert not (tmp_path / "out").exists()


def test_good_config_runs_through_main(tmp_path, capsys):
    assert run_main(["workspace", RPR2_YAML, "--depth", 4, "-o", tmp_path, "--no-plot", "-q"]) == 0
    assert capsys.readouterr().err == "" and (tmp_path / "workspace.qt").exists()
