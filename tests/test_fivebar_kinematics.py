"""Point kinematics of the five-bar (fivebar_cli.fivebar): DKP, IKP, mode signs, point tests."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from conftest import M1, M2, MECHS, crank_points, mechanism, singular_b1_eq_b2, valid_joint, valid_work
from fivebar_cli.mechanisms.fivebar import kinematics as kin

ANGLE = st.floats(-math.pi, math.pi, allow_nan=False)


def cross(a, b):
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def wrap(a):
    return (np.asarray(a) + np.pi) % (2 * np.pi) - np.pi


def angle_error(a, b):
    return np.abs(wrap(np.asarray(a) - np.asarray(b)))


def test_configs_hold_the_paper_mechanisms():
    """configs/m1.yaml and m2.yaml describe the paper's M1 and M2 (section 3)."""
    assert mechanism("M1") == M1
    assert mechanism("M2") == M2


# ---------------------------------------------------------------- DKP


@pytest.mark.parametrize("name", ["M1", "M2"])
def test_dkp_closure_and_assembly_sign(name):
    m = MECHS[name]
    rng = np.random.default_rng(1)
    th1, th2 = rng.uniform(-np.pi, np.pi, (2, 20000))
    b1, b2 = crank_points(m, th1, th2)
    d = np.hypot(*(b2 - b1).T)
    assemblable = (d > 0) & (d <= m.L3 + m.L4) & (d >= abs(m.L3 - m.L4))
    assert 0.2 < assemblable.mean() < 0.9
    for assembly in (1, -1):
        p, ok = kin.dkp(m, th1, th2, assembly)
        assert np.array_equal(ok, assemblable)
        assert np.all(np.isnan(p[~ok]))
        p, b1o, b2o = p[ok], b1[ok], b2[ok]
        np.testing.assert_allclose(np.hypot(*(p - b1o).T), m.L3, rtol=0, atol=1e-9)
        np.testing.assert_allclose(np.hypot(*(p - b2o).T), m.L4, rtol=0, atol=1e-9)
        t = cross(p - b1o, p - b2o)  # det A (paper eq. 3), computed here
        clear = np.abs(t) > 1e-6
        assert np.all(np.sign(t[clear]) == assembly)
        # mode_values gives the same t
        _, _, t2 = kin.mode_values(m, th1[ok], th2[ok], p)
        np.testing.assert_allclose(t2, t, rtol=1e-12, atol=1e-12)
    # the two solutions are mirror images across the line B1B2
    pp, _ = kin.dkp(m, th1, th2, 1)
    pm, _ = kin.dkp(m, th1, th2, -1)
    sel = assemblable
    u = (b2 - b1)[sel] / d[sel, None]
    rel_p, rel_m = pp[sel] - b1[sel], pm[sel] - b1[sel]
    np.testing.assert_allclose(np.sum(rel_p * u, axis=1), np.sum(rel_m * u, axis=1), atol=1e-9)
    np.testing.assert_allclose(cross(u, rel_p), -cross(u, rel_m), atol=1e-9)


def test_dkp_hand_example_m2():
    """th1 = th2 = pi/2: B1 = (0, 2.3), B2 = (2.55, 2.3); P on x = 1.275 above (+) or below (-) B1B2."""
    h = math.sqrt(2.3**2 - 1.275**2)
    p, ok = kin.dkp(M2, np.pi / 2, np.pi / 2, 1)
    assert ok and np.allclose(p, [1.275, 2.3 + h], atol=1e-12)
    p, ok = kin.dkp(M2, np.pi / 2, np.pi / 2, -1)
    assert ok and np.allclose(p, [1.275, 2.3 - h], atol=1e-12)


def test_dkp_rejects_unassemblable_configurations():
    # M1: |B1B2| must lie in [|L3 - L4|, L3 + L4] = [3, 13]
    # th1 = pi, th2 = 0: B1 = (-8, 0), B2 = (14, 0), |B1B2| = 22 > 13
    p, ok = kin.dkp(M1, np.pi, 0.0, 1)
    assert not ok and np.all(np.isnan(p))
    # th1 = 0, th2 = pi: B1 = (8, 0), B2 = (4, 0), |B1B2| = 4: fine; th2 chosen so that B2 is near B1
    p, ok = kin.dkp(M1, 0.0, np.pi, 1)
    assert ok
    # |B1B2| < 3: B2 the point of its circle nearest to B1 = 8 e^{0.3 i}: |B1B2| = 5 - |A2B1| = 2.27
    th1 = 0.3
    b1 = np.array([8 * math.cos(th1), 8 * math.sin(th1)])
    v = b1 - np.array([9.0, 0.0])
    th2 = math.atan2(v[1], v[0])
    b2 = np.array([9.0, 0.0]) + 5 * v / np.linalg.norm(v)
    assert 2.2 < np.linalg.norm(b2 - b1) < 2.3
    p, ok = kin.dkp(M1, th1, th2, 1)
    assert not ok and np.all(np.isnan(p))
    p, ok = kin.dkp(M1, th1, th2 + 0.8, 1)  # turning the crank away opens the gap past 3
    b2 = np.array([9.0 + 5 * math.cos(th2 + 0.8), 5 * math.sin(th2 + 0.8)])
    assert np.linalg.norm(b2 - b1) > 3 and ok
    # M2: B1 = B2 cannot be solved (P turns freely)
    for th1, th2 in singular_b1_eq_b2(M2):
        p, ok = kin.dkp(M2, th1, th2, 1)
        b1, b2 = crank_points(M2, th1, th2)
        d = float(np.hypot(*(b2 - b1)))
        assert d < 1e-12
        assert bool(ok) == (d > 0)  # exactly B1 = B2 has no solution; rounding may leave d > 0
        p, ok = kin.dkp(M2, th1 + 1e-3, th2, 1)  # next to it the mechanism assembles
        assert ok


# ---------------------------------------------------------------- IKP


@pytest.mark.parametrize("name", ["M1", "M2"])
def test_ikp_closure_and_working_modes(name):
    m = MECHS[name]
    rng = np.random.default_rng(2)
    R = m.L1 + m.L3
    x, y = rng.uniform(-R, R, (2, 20000))
    reach = valid_work(m, x, y)
    assert 0.1 < reach.mean() < 0.9
    for su in (1, -1):
        for sv in (1, -1):
            th1, th2, ok = kin.ikp(m, x, y, (su, sv))
            assert np.array_equal(ok, reach)
            assert np.all(np.isnan(th1[~ok])) and np.all(np.isnan(th2[~ok]))
            assert np.all(np.abs(th1[ok]) <= np.pi) and np.all(np.abs(th2[ok]) <= np.pi)
            b1, b2 = crank_points(m, th1[ok], th2[ok])
            p = np.stack([x[ok], y[ok]], axis=1)
            np.testing.assert_allclose(np.hypot(*(p - b1).T), m.L3, atol=1e-9)
            np.testing.assert_allclose(np.hypot(*(p - b2).T), m.L4, atol=1e-9)
            # working-mode signs, computed here: u = (b1 - a1) x (p - b1), v = (b2 - a2) x (p - b2)
            u = cross(b1, p - b1)
            v = cross(b2 - np.array([m.L0, 0.0]), p - b2)
            clear_u, clear_v = np.abs(u) > 1e-6, np.abs(v) > 1e-6
            assert np.all(np.sign(u[clear_u]) == su)
            assert np.all(np.sign(v[clear_v]) == sv)
            mu, mv, _ = kin.mode_values(m, th1[ok], th2[ok], p)
            np.testing.assert_allclose(mu, u, atol=1e-12)
            np.testing.assert_allclose(mv, v, atol=1e-12)


@settings(max_examples=200, deadline=None)
@given(st.sampled_from(["M1", "M2"]), ANGLE, ANGLE, st.sampled_from([1, -1]))
def test_dkp_then_ikp_gives_back_the_angles(name, th1, th2, assembly):
    m = MECHS[name]
    p, ok = kin.dkp(m, th1, th2, assembly)
    if not ok:
        assert not valid_joint(m, th1, th2)
        return
    assert valid_joint(m, th1, th2)
    u, v, t = kin.mode_values(m, th1, th2, p)
    s = kin.scale(m) ** 2
    if abs(t) > 1e-6 * s:
        assert np.sign(t) == assembly
    if min(abs(u), abs(v)) < 1e-6 * s:
        return  # serial singularity: the working mode is ambiguous
    working = (int(np.sign(u)), int(np.sign(v)))
    r1, r2, ok2 = kin.ikp(m, p[0], p[1], working)
    assert ok2
    assert angle_error(r1, th1) < 1e-7 and angle_error(r2, th2) < 1e-7
    # and the DKP of the recovered angles in the same assembly mode gives back P
    if abs(t) > 1e-6 * s:
        q, _ = kin.dkp(m, r1, r2, assembly)
        assert np.allclose(q, p, atol=1e-7)


@settings(max_examples=200, deadline=None)
@given(st.sampled_from(["M1", "M2"]), st.floats(0, 1), st.floats(-math.pi, math.pi), st.sampled_from([1, -1]),
       st.sampled_from([1, -1]))
def test_ikp_then_dkp_gives_back_the_point(name, radius_frac, angle, su, sv):
    m = MECHS[name]
    r_lo, r_hi = abs(m.L1 - m.L3), m.L1 + m.L3
    r = r_lo + (r_hi - r_lo) * radius_frac
    x, y = r * math.cos(angle), r * math.sin(angle)
    th1, th2, ok = kin.ikp(m, x, y, (su, sv))
    assert bool(ok) == bool(valid_work(m, x, y))
    if not ok:
        return
    p = np.array([x, y])
    u, v, t = kin.mode_values(m, th1, th2, p)
    s = kin.scale(m) ** 2
    if abs(u) > 1e-6 * s:
        assert np.sign(u) == su
    if abs(v) > 1e-6 * s:
        assert np.sign(v) == sv
    if abs(t) > 1e-6 * s:
        q, okq = kin.dkp(m, th1, th2, int(np.sign(t)))
        assert okq and np.allclose(q, p, atol=1e-7)


# ---------------------------------------------------------------- mode conventions


@settings(max_examples=100, deadline=None)
@given(ANGLE, ANGLE, st.floats(-20, 20), st.floats(-20, 20), st.sampled_from(["M1", "M2"]))
def test_mode_values_are_the_design_cross_products(th1, th2, px, py, name):
    m = MECHS[name]
    b1 = np.array([m.L1 * math.cos(th1), m.L1 * math.sin(th1)])
    b2 = np.array([m.L0 + m.L2 * math.cos(th2), m.L2 * math.sin(th2)])
    p = np.array([px, py])
    u, v, t = kin.mode_values(m, th1, th2, p)
    a1, a2 = np.zeros(2), np.array([m.L0, 0.0])
    assert u == pytest.approx(float(cross(b1 - a1, p - b1)), abs=1e-9)
    assert v == pytest.approx(float(cross(b2 - a2, p - b2)), abs=1e-9)
    assert t == pytest.approx(float(cross(p - b1, p - b2)), abs=1e-9)


def test_b11_is_l1_l3_sin_th3_minus_th1():
    """docs/formats.md: B11 = L1 L3 sin(th3 - th1), B22 = L2 L4 sin(th4 - th2): the signs of u and v."""
    rng = np.random.default_rng(4)
    for m in (M1, M2):
        th1, th2 = rng.uniform(-np.pi, np.pi, (2, 5000))
        p, ok = kin.dkp(m, th1, th2, 1)
        th1, th2, p = th1[ok], th2[ok], p[ok]
        b1, b2 = crank_points(m, th1, th2)
        th3 = np.arctan2(*(p - b1).T[::-1])
        th4 = np.arctan2(*(p - b2).T[::-1])
        u, v, _ = kin.mode_values(m, th1, th2, p)
        np.testing.assert_allclose(u, m.L1 * m.L3 * np.sin(th3 - th1), atol=1e-9)
        np.testing.assert_allclose(v, m.L2 * m.L4 * np.sin(th4 - th2), atol=1e-9)


def test_mode_sign_hand_examples():
    # th1 = 0: B1 = (L1, 0); P straight above B1 -> u = L1 * L3 > 0 (elbow turning left)
    m = M1
    p = np.array([m.L1, m.L3])
    u, _, _ = kin.mode_values(m, 0.0, 0.0, p)
    assert u == pytest.approx(m.L1 * m.L3)
    # th2 = pi/2: B2 = (L0, L2); P to the right of B2 -> v = (0, L2) x (L4, 0) = -L2 L4 < 0
    p = np.array([m.L0 + m.L4, m.L2])
    _, v, _ = kin.mode_values(m, 0.0, np.pi / 2, p)
    assert v == pytest.approx(-m.L2 * m.L4)
    # assembly: P left of B1 -> B2 gives t > 0
    _, _, t = kin.mode_values(M2, np.pi / 2, np.pi / 2, np.array([1.275, 4.0]))
    assert t > 0


# ---------------------------------------------------------------- point tests


@pytest.mark.parametrize("name", ["M1", "M2"])
def test_point_tests_against_independent_geometry(name):
    m = MECHS[name]
    rng = np.random.default_rng(7)
    th = rng.uniform(-4, 4, (50000, 2))
    assert np.array_equal(kin.in_joint_space(m, th[:, 0], th[:, 1]), valid_joint(m, th[:, 0], th[:, 1]))
    R = m.L1 + m.L3
    xy = rng.uniform(-R, R, (50000, 2))
    assert np.array_equal(kin.in_workspace(m, xy[:, 0], xy[:, 1]), valid_work(m, xy[:, 0], xy[:, 1]))
    # scalars work too
    assert bool(kin.in_workspace(m, 0.5 * m.L0, 0.5)) == bool(valid_work(m, 0.5 * m.L0, 0.5))


def test_point_tests_exclude_the_singular_points():
    assert not kin.in_workspace(M2, 0.0, 0.0)  # P = A1 with L1 = L3
    assert not kin.in_workspace(M2, M2.L0, 0.0)  # P = A2 with L2 = L4
    assert kin.in_workspace(M2, 1e-9, 0.0) and kin.in_workspace(M2, M2.L0 - 1e-9, 1e-9)
    assert kin.in_workspace(M1, 3.0, 0.0) and not kin.in_workspace(M1, 2.999, 0.0)  # hole of radius 3
    assert kin.in_workspace(M1, -4.0, 0.0) and not kin.in_workspace(M1, -4.001, 0.0)  # |P - A2| <= 13
    for th1, th2 in singular_b1_eq_b2(M2):
        for d1, d2 in ((1e-7, 0), (0, 1e-7), (-1e-7, 1e-7)):
            assert kin.in_joint_space(M2, th1 + d1, th2 + d2)


def test_workspace_is_the_image_of_the_joint_space():
    """Every DKP solution of an assemblable configuration is in the workspace."""
    rng = np.random.default_rng(8)
    for m in (M1, M2):
        th1, th2 = rng.uniform(-np.pi, np.pi, (2, 20000))
        for a in (1, -1):
            p, ok = kin.dkp(m, th1, th2, a)
            p = p[ok]
            r1 = np.hypot(*p.T)
            r2 = np.hypot(p[:, 0] - m.L0, p[:, 1])
            assert np.all(r1 <= m.L1 + m.L3 + 1e-9) and np.all(r1 >= abs(m.L1 - m.L3) - 1e-9)
            assert np.all(r2 <= m.L2 + m.L4 + 1e-9) and np.all(r2 >= abs(m.L2 - m.L4) - 1e-9)


def test_space_roots_follow_the_paper():
    assert M1.spaces()["jointspace"].root == ((-np.pi, np.pi), (-np.pi, np.pi))
    assert M1.spaces()["workspace"].root == ((-13.0, 13.0), (-13.0, 13.0))
    assert M2.spaces()["workspace"].root == ((-4.6, 4.6), (-4.6, 4.6))
