"""Soundness of the mode-restricted box tests (Chablat 2010, sections 3.3 and 3.5; issue 3, item 1).

A cell may be black only if, at every point of it, the configuration exists, is non-singular and
has the requested signs: in the workspace (one paving per working mode) the IKP of that working
mode exists with sign u, sign v as requested and det A != 0, with one sign of det A per cell; in
the joint space (one paving per assembly mode) the DKP of that assembly mode exists, sign t is the
assembly mode and u, v are non-zero with one sign per cell. A cell answered -1 holds no reachable
(workspace) / assemblable (joint space) point.

Everything is checked against the point kinematics written below from the geometry alone
(circle intersections and the cross products of section 3.1), not against the library's own
point routines: the library's ikp / dkp / mode_values / workspace_assembly_sign /
joint_working_mode are compared with them as well. The helpers direction_range,
triangle_angle_range and sin_sign are checked against brute-force sampling.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from reference_kinematics import ref_dkp, ref_ikp, ref_reachable
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from conftest import M1, M2, MECHS, workspace_area_closed_form
from fivebar_cli.mechanisms.fivebar import kinematics as kin
from fivebar_cli.mechanisms.fivebar import modes
from fivebar_cli.mechanisms.fivebar.model import FiveBar
from fivebar_cli.numerics import ranges
from fivebar_cli.paving.engine import pave
from fivebar_cli.paving.grid import Grid

WORKING_MODES = ((1, 1), (1, -1), (-1, 1), (-1, -1))
ASSEMBLY_MODES = (1, -1)
DEPTH = 9
TWO_PI = 2 * math.pi


# ---------------------------------------------------------------- independent point kinematics:
# reference_kinematics.py


def ref_assemblable(m: FiveBar, th1, th2):
    d = np.hypot(m.L0 + m.L2 * np.cos(th2) - m.L1 * np.cos(th1), m.L2 * np.sin(th2) - m.L1 * np.sin(th1))
    return (d > 0) & (d <= m.L3 + m.L4) & (d >= abs(m.L3 - m.L4))


def leaf_boxes(tree):
    """(lo, hi) of every leaf, decoded here from the Morton codes (bit b*2+j = bit b of axis j)."""
    level = np.asarray(tree.level, np.int64)
    code = np.asarray(tree.code, np.int64)
    coords = np.zeros((code.size, 2), np.int64)
    for b in range(int(level.max(initial=0))):
        for j in range(2):
            coords[:, j] |= ((code >> (2 * b + j)) & 1) << b
    root = np.array(tree.grid.root, float)
    width = (root[:, 1] - root[:, 0])[None, :] / (2.0 ** level)[:, None]
    lo = root[:, 0] + coords * width
    return lo, lo + width


def cell_samples(lo, hi, rng, uniform=6):
    """Points of each closed cell: corners, edge midpoints, centre, points 1e-9 of the width inside
    the corners, points along the edges and uniform interior points. Returns (points, owner)."""
    fr = [(0, 0), (1, 0), (0, 1), (1, 1), (0.5, 0), (0.5, 1), (0, 0.5), (1, 0.5), (0.5, 0.5)]
    e = 1e-9
    fr += [(e, e), (1 - e, e), (e, 1 - e), (1 - e, 1 - e)]
    fixed = np.array(fr, float)
    n = len(lo)
    edge = rng.random((n, 4))
    pts = [lo[:, None, :] + fixed[None] * (hi - lo)[:, None, :]]
    along = np.stack([
        np.stack([edge[:, 0], np.zeros(n)], 1), np.stack([edge[:, 1], np.ones(n)], 1),
        np.stack([np.zeros(n), edge[:, 2]], 1), np.stack([np.ones(n), edge[:, 3]], 1),
    ], 1)
    pts.append(lo[:, None, :] + along * (hi - lo)[:, None, :])
    pts.append(lo[:, None, :] + rng.random((n, uniform, 2)) * (hi - lo)[:, None, :])
    pts = np.concatenate(pts, axis=1)
    owner = np.repeat(np.arange(n), pts.shape[1])
    return pts.reshape(-1, 2), owner


def constant_per_owner(values, owner, n):
    """Whether `values` is constant on each owner group."""
    lo = np.full(n, np.inf)
    hi = np.full(n, -np.inf)
    np.minimum.at(lo, owner, values)
    np.maximum.at(hi, owner, values)
    used = np.isfinite(lo)
    return bool(np.all(lo[used] == hi[used]))


# ---------------------------------------------------------------- reference kinematics vs library


@pytest.mark.parametrize("name", ["M1", "M2"])
def test_reference_ikp_closes_the_loop(name):
    """The reference IKP itself: |B1 - A1| = L1, |P - B1| = L3, |B2 - A2| = L2, |P - B2| = L4."""
    m = MECHS[name]
    rng = np.random.default_rng(1)
    r = m.L1 + m.L3
    x, y = rng.uniform(-r, r, 20000), rng.uniform(-r, r, 20000)
    for wm in WORKING_MODES:
        th1, th2, u, v, t, ok = ref_ikp(m, x, y, wm)
        assert np.array_equal(ok, ref_reachable(m, x, y))
        b1 = m.L1 * np.stack([np.cos(th1), np.sin(th1)], 1)
        b2 = np.array([m.L0, 0]) + m.L2 * np.stack([np.cos(th2), np.sin(th2)], 1)
        p = np.stack([x, y], 1)
        s = m.L1 + m.L2 + m.L3 + m.L4
        assert np.allclose(np.hypot(*(p - b1).T)[ok], m.L3, atol=1e-9 * s)
        assert np.allclose(np.hypot(*(p - b2).T)[ok], m.L4, atol=1e-9 * s)
        assert np.all(np.sign(u[ok]) == wm[0]) and np.all(np.sign(v[ok]) == wm[1])


@pytest.mark.parametrize("name", ["M1", "M2"])
def test_library_point_kinematics_agree_with_reference(name):
    m = MECHS[name]
    rng = np.random.default_rng(2)
    r = m.L1 + m.L3
    x, y = rng.uniform(-r, r, 20000), rng.uniform(-r, r, 20000)
    for wm in WORKING_MODES:
        th1, th2, u, v, t, ok = ref_ikp(m, x, y, wm)
        l1, l2, lok = kin.ikp(m, x, y, wm)
        assert np.array_equal(lok, ok)
        wrap = lambda a: (a + math.pi) % TWO_PI - math.pi  # noqa: E731
        assert np.allclose(wrap(l1[ok] - th1[ok]), 0, atol=1e-7)
        assert np.allclose(wrap(l2[ok] - th2[ok]), 0, atol=1e-7)
        lu, lv, lt = kin.mode_values(m, l1[ok], l2[ok], np.stack([x[ok], y[ok]], 1))
        clear = (np.abs(u[ok]) > 1e-6) & (np.abs(v[ok]) > 1e-6) & (np.abs(t[ok]) > 1e-6)
        assert np.all(np.sign(lu[clear]) == wm[0]) and np.all(np.sign(lv[clear]) == wm[1])
        assert np.all(np.sign(lt[clear]) == np.sign(t[ok][clear]))
    th1, th2 = rng.uniform(-math.pi, math.pi, (2, 20000))
    for am in ASSEMBLY_MODES:
        x, y, u, v, t, ok = ref_dkp(m, th1, th2, am)
        p, lok = kin.dkp(m, th1, th2, am)
        assert np.array_equal(lok, ok)
        assert np.allclose(p[ok], np.stack([x, y], 1)[ok], atol=1e-7)
        assert np.all(np.sign(t[ok][np.abs(t[ok]) > 1e-6]) == am)


# ---------------------------------------------------------------- pavings (depth 9)


def _grid(m, space, depth):
    if space == "jointspace":
        return Grid(((-math.pi, math.pi), (-math.pi, math.pi)), depth, (True, True))
    r = m.L1 + m.L3  # the paper's root box [-(L1 + L3), L1 + L3]^2 (section 3.7)
    return Grid(((-r, r), (-r, r)), depth, (False, False))


_PAVINGS: dict = {}


def mode_paving(name, space, mode):
    key = (name, space, mode)
    if key not in _PAVINGS:
        m = MECHS[name]
        test = (modes.working_mode_workspace_test(m, mode) if space == "workspace"
                else modes.assembly_mode_joint_test(m, mode))
        _PAVINGS[key] = pave(_grid(m, space, DEPTH), test)
    return _PAVINGS[key]


@pytest.mark.parametrize("name", ["M1", "M2"])
@pytest.mark.parametrize("wm", WORKING_MODES, ids=lambda w: "".join("+" if s > 0 else "-" for s in w))
def test_working_mode_black_cells_are_sound(name, wm):
    m = MECHS[name]
    paving = mode_paving(name, "workspace", wm)
    lo, hi = leaf_boxes(paving.inside)
    assert len(lo) > 1000  # a real paving, not an empty one
    rng = np.random.default_rng([len(name), name == "M1", wm[0] + 2, wm[1] + 2])
    pts, owner = cell_samples(lo, hi, rng)
    th1, th2, u, v, t, ok = ref_ikp(m, pts[:, 0], pts[:, 1], wm)
    assert ok.all(), f"unreachable points in black cells, e.g. {pts[~ok][:3]}"
    # strictly inside both annuli: no serial singularity (a leg stretched or folded)
    r1, r2 = np.hypot(pts[:, 0], pts[:, 1]), np.hypot(pts[:, 0] - m.L0, pts[:, 1])
    assert np.all((r1 > abs(m.L1 - m.L3)) & (r1 < m.L1 + m.L3) & (r1 > 0))
    assert np.all((r2 > abs(m.L2 - m.L4)) & (r2 < m.L2 + m.L4) & (r2 > 0))
    assert np.all(np.sign(u) == wm[0]) and np.all(np.sign(v) == wm[1])
    assert np.all(t != 0)
    # one sign of det A per cell: no parallel singularity crosses a black cell
    assert constant_per_owner(np.sign(t), owner, len(lo))
    centre_t = ref_ikp(m, 0.5 * (lo[:, 0] + hi[:, 0]), 0.5 * (lo[:, 1] + hi[:, 1]), wm)[4]
    assert np.all(np.sign(t) == np.sign(centre_t)[owner])
    # the library's reading of the cell's assembly mode agrees
    lib = modes.workspace_assembly_sign(m, wm, 0.5 * (lo + hi))
    assert np.array_equal(lib, np.sign(centre_t).astype(lib.dtype))
    # and so do its IKP and mode values, at every sample
    l1, l2, lok = kin.ikp(m, pts[:, 0], pts[:, 1], wm)
    assert lok.all()
    lu, lv, lt = kin.mode_values(m, l1, l2, pts)
    assert np.all(np.sign(lu) == wm[0]) and np.all(np.sign(lv) == wm[1]) and np.all(np.sign(lt) == np.sign(t))


@pytest.mark.parametrize("name", ["M1", "M2"])
@pytest.mark.parametrize("wm", WORKING_MODES, ids=lambda w: "".join("+" if s > 0 else "-" for s in w))
def test_working_mode_white_cells_are_unreachable(name, wm):
    m = MECHS[name]
    paving = mode_paving(name, "workspace", wm)
    lo, hi = leaf_boxes(paving.outside)
    pts, _ = cell_samples(lo, hi, np.random.default_rng(5), uniform=3)
    assert not ref_reachable(m, pts[:, 0], pts[:, 1]).any()


@pytest.mark.parametrize("name", ["M1", "M2"])
@pytest.mark.parametrize("am", ASSEMBLY_MODES, ids=["+", "-"])
def test_assembly_mode_black_cells_are_sound(name, am):
    m = MECHS[name]
    paving = mode_paving(name, "jointspace", am)
    lo, hi = leaf_boxes(paving.inside)
    assert len(lo) > 1000
    rng = np.random.default_rng([len(name), name == "M1", am + 2])
    pts, owner = cell_samples(lo, hi, rng)
    x, y, u, v, t, ok = ref_dkp(m, pts[:, 0], pts[:, 1], am)
    assert ok.all(), f"points that cannot be assembled in black cells, e.g. {pts[~ok][:3]}"
    d = np.hypot(m.L0 + m.L2 * np.cos(pts[:, 1]) - m.L1 * np.cos(pts[:, 0]),
                 m.L2 * np.sin(pts[:, 1]) - m.L1 * np.sin(pts[:, 0]))
    assert np.all((d > abs(m.L3 - m.L4)) & (d < m.L3 + m.L4) & (d > 0))  # no parallel singularity
    assert np.all(np.sign(t) == am)
    assert np.all(u != 0) and np.all(v != 0)
    assert constant_per_owner(np.sign(u), owner, len(lo))
    assert constant_per_owner(np.sign(v), owner, len(lo))
    c = 0.5 * (lo + hi)
    _, _, cu, cv, _, cok = ref_dkp(m, c[:, 0], c[:, 1], am)
    assert cok.all()
    assert np.all(np.sign(u) == np.sign(cu)[owner]) and np.all(np.sign(v) == np.sign(cv)[owner])
    lib = modes.joint_working_mode(m, am, c)
    assert np.array_equal(lib, np.stack([np.sign(cu), np.sign(cv)], 1).astype(lib.dtype))
    p, lok = kin.dkp(m, pts[:, 0], pts[:, 1], am)
    assert lok.all()
    lu, lv, lt = kin.mode_values(m, pts[:, 0], pts[:, 1], p)
    assert np.all(np.sign(lt) == am) and np.all(np.sign(lu) == np.sign(u)) and np.all(np.sign(lv) == np.sign(v))


@pytest.mark.parametrize("name", ["M1", "M2"])
@pytest.mark.parametrize("am", ASSEMBLY_MODES, ids=["+", "-"])
def test_assembly_mode_white_cells_cannot_assemble(name, am):
    m = MECHS[name]
    lo, hi = leaf_boxes(mode_paving(name, "jointspace", am).outside)
    pts, _ = cell_samples(lo, hi, np.random.default_rng(6), uniform=3)
    assert not ref_assemblable(m, pts[:, 0], pts[:, 1]).any()


@pytest.mark.parametrize("name", ["M1", "M2"])
def test_mode_pavings_cover_the_space_up_to_the_singular_curves(name):
    """The four working-mode regions and the two assembly-mode regions each fill their space
    up to a band around the singular curves that narrows with depth: at depth 9 the certified
    part is most of the area of the space (workspace: lens minus holes, closed form)."""
    m = MECHS[name]
    exact = workspace_area_closed_form(m)
    for wm in WORKING_MODES:
        area = mode_paving(name, "workspace", wm).inside.area
        assert 0.95 * exact < area < exact
    for am in ASSEMBLY_MODES:
        inside = mode_paving(name, "jointspace", am).inside
        th = np.linspace(-math.pi, math.pi, 801)[:-1] + math.pi / 800
        g1, g2 = np.meshgrid(th, th)
        js_area = ref_assemblable(m, g1, g2).mean() * TWO_PI ** 2
        assert 0.93 * js_area < inside.area < 1.01 * js_area


# ---------------------------------------------------------------- random boxes (hypothesis)


def _dense(lo, hi, n=17):
    g = np.linspace(0.0, 1.0, n)
    gx, gy = np.meshgrid(g, g)
    f = np.stack([gx.ravel(), gy.ravel()], 1)
    return lo + f * (hi - lo)


def _anchors(m, space):
    if space == "workspace":
        pts = [(0.0, 0.0), (m.L0, 0.0), (m.L0 / 2, 0.0)]
        for c1, ra in (((0.0, 0.0), m.L1 + m.L3), ((0.0, 0.0), abs(m.L1 - m.L3))):
            for c2, rb in (((m.L0, 0.0), m.L2 + m.L4), ((m.L0, 0.0), abs(m.L2 - m.L4))):
                d = m.L0
                if abs(ra - rb) <= d <= ra + rb and d > 0:
                    a = (d * d + ra * ra - rb * rb) / (2 * d)
                    h = math.sqrt(max(ra * ra - a * a, 0.0))
                    pts += [(a, h), (a, -h)]
        pts += [((m.L1 + m.L3) * math.cos(q), (m.L1 + m.L3) * math.sin(q)) for q in (0.5, 1.0, -1.0)]
        return pts
    a = (m.L0 ** 2 + m.L1 ** 2 - m.L2 ** 2) / (2 * m.L0)
    h = math.sqrt(m.L1 ** 2 - a * a)
    pts = [(math.atan2(s * h, a), math.atan2(s * h, a - m.L0)) for s in (1, -1)]  # B1 = B2
    pts += [(0.0, 0.0), (math.pi, math.pi), (0.0, math.pi), (math.pi, 0.0), (-math.pi, 1.0), (1.0, -math.pi)]
    return pts


@st.composite
def boxes(draw, space):
    name = draw(st.sampled_from(["M1", "M2"]))
    m = MECHS[name]
    (x0, x1), (y0, y1) = _grid(m, space, 0).root
    if draw(st.booleans()):
        cx, cy = draw(st.sampled_from(_anchors(m, space)))
        size = x1 - x0
        cx += draw(st.floats(-0.02, 0.02)) * size
        cy += draw(st.floats(-0.02, 0.02)) * size
    else:
        cx = draw(st.floats(x0, x1))
        cy = draw(st.floats(y0, y1))
    kx, ky = draw(st.integers(3, 14)), draw(st.integers(3, 14))
    wx, wy = (x1 - x0) * 2.0 ** -kx, (y1 - y0) * 2.0 ** -ky
    lo = np.array([[max(cx - wx / 2, x0), max(cy - wy / 2, y0)]])
    hi = np.array([[min(cx + wx / 2, x1), min(cy + wy / 2, y1)]])
    assume(np.all(hi > lo))
    return m, lo, hi


@settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(box=boxes("workspace"), wm=st.sampled_from(WORKING_MODES))
def test_working_mode_test_on_random_boxes(box, wm):
    m, lo, hi = box
    status = int(modes.working_mode_workspace_test(m, wm)(lo, hi)[0])
    pts = _dense(lo[0], hi[0])
    th1, th2, u, v, t, ok = ref_ikp(m, pts[:, 0], pts[:, 1], wm)
    if status == 1:
        assert ok.all()
        assert np.all(np.sign(u) == wm[0]) and np.all(np.sign(v) == wm[1])
        assert np.all(t != 0) and len(np.unique(np.sign(t))) == 1
    elif status == -1:
        assert not ok.any()
        assert not ref_reachable(m, pts[:, 0], pts[:, 1]).any()
    else:
        assert status == 0


@settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(box=boxes("jointspace"), am=st.sampled_from(ASSEMBLY_MODES))
def test_assembly_mode_test_on_random_boxes(box, am):
    m, lo, hi = box
    status = int(modes.assembly_mode_joint_test(m, am)(lo, hi)[0])
    pts = _dense(lo[0], hi[0])
    x, y, u, v, t, ok = ref_dkp(m, pts[:, 0], pts[:, 1], am)
    if status == 1:
        assert ok.all()
        assert np.all(np.sign(t) == am)
        assert np.all(u != 0) and np.all(v != 0)
        assert len(np.unique(np.sign(u))) == 1 and len(np.unique(np.sign(v))) == 1
    elif status == -1:
        assert not ok.any()
    else:
        assert status == 0


def test_mode_tests_reach_both_verdicts_on_small_boxes():
    """The random-box properties are not vacuous: small boxes well inside get 1, far outside -1."""
    m = M1
    lo, hi = np.array([[4.8, 4.8]]), np.array([[4.9, 4.9]])  # the ++ configuration of (4.85, 4.85)
    assert modes.working_mode_workspace_test(m, (1, 1))(lo, hi)[0] == 1
    lo, hi = np.array([[12.0, 12.0]]), np.array([[12.5, 12.5]])  # |P - A1| > 13
    assert modes.working_mode_workspace_test(m, (1, 1))(lo, hi)[0] == -1
    # th1 = th2 = pi: B1 = (-8, 0), B2 = (4, 0), |B1B2| = 12 < 13, a non-degenerate triangle
    lo, hi = np.array([[3.1, 3.1]]), np.array([[3.12, 3.12]])
    assert modes.assembly_mode_joint_test(m, 1)(lo, hi)[0] == 1
    # th1 = pi, th2 = 0: |B1B2| = 22 > 13
    lo, hi = np.array([[3.1, -0.01]]), np.array([[3.12, 0.01]])
    assert modes.assembly_mode_joint_test(m, 1)(lo, hi)[0] == -1


def test_isolated_parallel_singularity_of_m2_is_never_black():
    """M2 (L3 = L4): at B1 = B2 the point P turns freely (section 3.1): every box containing the
    point must stay undetermined in both assembly modes, however small."""
    m = M2
    a = (m.L0 ** 2 + m.L1 ** 2 - m.L2 ** 2) / (2 * m.L0)
    h = math.sqrt(m.L1 ** 2 - a * a)
    for s in (1, -1):
        q = np.array([math.atan2(s * h, a), math.atan2(s * h, a - m.L0)])
        for k in range(2, 30, 3):
            w = 2.0 ** -k
            for am in ASSEMBLY_MODES:
                assert modes.assembly_mode_joint_test(m, am)(q[None] - w, q[None] + w)[0] == 0


# ---------------------------------------------------------------- helpers against brute force


def _unwrap_into(angles, lo):
    """Angles shifted by multiples of 2 pi into [lo, lo + 2 pi)."""
    return lo + np.mod(angles - lo, TWO_PI)


coord = st.floats(-10, 10, allow_nan=False)


@settings(max_examples=250, deadline=None)
@given(a=coord, b=coord, c=coord, d=coord)
def test_direction_range_against_sampled_atan2(a, b, c, d):
    xlo, xhi = min(a, b), max(a, b)
    ylo, yhi = min(c, d), max(c, d)
    assume(xhi - xlo > 1e-6 and yhi - ylo > 1e-6)
    lo, hi = ranges.direction_range(np.array([xlo]), np.array([xhi]), np.array([ylo]), np.array([yhi]))
    lo, hi = float(lo[0]), float(hi[0])
    contains_origin = xlo <= 0 <= xhi and ylo <= 0 <= yhi
    if contains_origin:
        assert hi - lo == pytest.approx(TWO_PI)
        return
    # keep away from the origin, where atan2 is ill-conditioned
    dist = math.hypot(max(xlo, 0, -xhi), max(ylo, 0, -yhi))
    assume(dist > 1e-3)
    g = np.linspace(0, 1, 65)
    gx, gy = np.meshgrid(xlo + g * (xhi - xlo), ylo + g * (yhi - ylo))
    ang = np.arctan2(gy, gx).ravel()
    rel = _unwrap_into(ang, lo - 1e-9)
    assert np.all(rel <= hi + 1e-9), "a direction of the box is outside the range"
    # exact: the extreme directions are those of corners, which are sampled
    assert rel.min() == pytest.approx(lo, abs=1e-9)
    assert rel.max() == pytest.approx(hi, abs=1e-9)
    assert hi - lo < math.pi


def test_direction_range_across_the_negative_x_axis():
    """A box straddling theta = +-pi: the range is one interval through pi, not [-pi, pi]."""
    lo, hi = ranges.direction_range(np.array([-2.0]), np.array([-1.0]), np.array([-0.5]), np.array([0.5]))
    width = 2 * math.atan2(0.5, 1.0)  # seen from the origin under 2 atan(1/2)
    assert hi[0] - lo[0] == pytest.approx(width)
    mid = 0.5 * (lo[0] + hi[0])
    assert math.cos(mid) == pytest.approx(-1.0) and abs(math.sin(mid)) < 1e-12
    # a box touching the origin sees every direction
    lo, hi = ranges.direction_range(np.array([0.0]), np.array([1.0]), np.array([-1.0]), np.array([1.0]))
    assert hi[0] - lo[0] == pytest.approx(TWO_PI)


@settings(max_examples=250, deadline=None)
@given(adj=st.floats(0.1, 10), opp=st.floats(0.1, 10), f0=st.floats(0, 1), f1=st.floats(0, 1))
def test_triangle_angle_range_against_law_of_cosines(adj, opp, f0, f1):
    smin, smax = abs(adj - opp), adj + opp
    assume(smax - smin > 1e-3)
    s_lo = smin + min(f0, f1) * (smax - smin)
    s_hi = smin + max(f0, f1) * (smax - smin)
    assume(s_lo > 1e-6)
    lo, hi = ranges.triangle_angle_range(np.array([s_lo]), np.array([s_hi]), adj, opp)
    s = np.linspace(s_lo, s_hi, 2001)
    c = adj * adj - opp * opp
    if c > 0 and s_lo <= math.sqrt(c) <= s_hi:
        s = np.append(s, math.sqrt(c))  # the interior extremum of the cosine
    cos = np.clip((s * s + c) / (2 * adj * s), -1, 1)  # c first: no cancellation when s is tiny
    # compare cosines (well conditioned; arccos near +-1 amplifies rounding to ~1e-8 rad)
    assert math.cos(hi[0]) - 1e-12 <= cos.min() and cos.max() <= math.cos(lo[0]) + 1e-12
    assert cos.max() == pytest.approx(math.cos(lo[0]), abs=1e-6)
    assert cos.min() == pytest.approx(math.cos(hi[0]), abs=1e-6)
    ang = np.arccos(cos)
    assert lo[0] - 1e-7 <= ang.min() and ang.max() <= hi[0] + 1e-7


def test_triangle_angle_range_closed_forms():
    # equilateral: the angle is pi/3 at s = adj = opp
    lo, hi = ranges.triangle_angle_range(np.array([2.0]), np.array([2.0]), 2.0, 2.0)
    assert lo[0] == pytest.approx(math.pi / 3) and hi[0] == pytest.approx(math.pi / 3)
    # right angle opposite to opp when s^2 + adj^2 = opp^2 (3-4-5)
    lo, hi = ranges.triangle_angle_range(np.array([4.0]), np.array([4.0]), 3.0, 5.0)
    assert lo[0] == pytest.approx(math.pi / 2)
    # s over the whole closing range |a - o| .. a + o with a < o: from pi (folded) to 0 (stretched)
    lo, hi = ranges.triangle_angle_range(np.array([2.0]), np.array([8.0]), 3.0, 5.0)
    assert lo[0] == pytest.approx(0.0, abs=1e-7) and hi[0] == pytest.approx(math.pi)
    # a > o: the largest angle is asin(o / a), reached at s = sqrt(a^2 - o^2) (tangent)
    lo, hi = ranges.triangle_angle_range(np.array([3.0]), np.array([13.0]), 8.0, 5.0)
    assert hi[0] == pytest.approx(math.asin(5 / 8)) and lo[0] == pytest.approx(0.0, abs=1e-7)


@settings(max_examples=300, deadline=None)
@given(lo=st.floats(-20, 20), width=st.floats(0, 7), margin=st.sampled_from([0.0, 1e-8, 1e-3]))
def test_sin_sign_against_brute_force(lo, width, margin):
    hi = lo + width
    a, b = lo - margin, hi + margin
    # stay clear of the ambiguous case where an end is within rounding of a multiple of pi
    for end in (a, b):
        assume(abs(end / math.pi - round(end / math.pi)) > 1e-9)
    got = int(ranges.sin_sign(np.array([lo]), np.array([hi]), margin)[0])
    k = math.ceil(a / math.pi)
    contains_zero = k * math.pi <= b
    if contains_zero:
        assert got == 0
    else:
        s = np.sin(np.linspace(a, b, 1001))
        expected = 1 if np.all(s > 0) else -1
        assert np.all(np.sign(s) == expected)
        assert got == expected


def test_sin_sign_examples():
    lo = np.array([0.1, 3.2, -3.0, 3.0, -0.1, 6.4, 1.0])
    hi = np.array([3.0, 6.2, -0.2, 3.3, 0.1, 9.3, 1.0])
    assert ranges.sin_sign(lo, hi).tolist() == [1, -1, -1, 0, 0, 1, 1]
    # the margin reaches across pi
    assert ranges.sin_sign(np.array([0.1]), np.array([math.pi - 1e-9]), 1e-8)[0] == 0
    assert ranges.sin_sign(np.array([0.1]), np.array([math.pi - 1e-6]), 1e-8)[0] == 1
