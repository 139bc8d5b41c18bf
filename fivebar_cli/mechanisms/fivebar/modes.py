"""Five-bar working and assembly modes: mode-restricted box tests, and the `AspectModel` the
generalized-aspect analysis uses.

Workspace, one working mode (sign B11, sign B22): black when every P of the box is reachable and
non-singular in that mode; joint space, one assembly mode (sign det A): black when every
(th1, th2) assembles, non-singular. The other modes are constant on a black cell and read at one
point of it. The sign ranges come from exact ranges of the angles involved (`numerics/ranges.py`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fivebar_cli.mechanisms.fivebar.boxtests import (
    DELTA_REL, AngleTables, annuli, assembly_status, crank_distance2_range, leg_distance2_ranges, reach_status,
    workspace_anchors,
)
from fivebar_cli.mechanisms.fivebar.kinematics import cranks, dkp, ikp, mode_values, scale
from fivebar_cli.numerics.ranges import direction_range, sin_sign, sinusoid_range, triangle_angle_range
from fivebar_cli.numerics.verdict import verdict
from fivebar_cli.paving.grid import AxisEnds

WORKING_MODES = ((1, 1), (1, -1), (-1, 1), (-1, -1))
ASSEMBLY_MODES = (1, -1)


def _strict(dmin, dmax, inner: float, outer: float, delta: float) -> np.ndarray:
    """Squared distance strictly inside (inner^2, outer^2) and positive on the whole box, with margin."""
    return (dmin - delta > inner * inner) & (dmax + delta < outer * outer) & (dmin - delta > 0)


def _valid_lengths(dmin, dmax, inner: float, outer: float, delta: float):
    """Length range of the valid part, from a squared-distance range widened by the margin."""
    lo = np.sqrt(np.maximum(dmin - delta, 0.0))
    hi = np.sqrt(np.maximum(dmax + delta, 0.0))
    return np.clip(lo, inner, outer), np.clip(hi, inner, outer)


def working_mode_workspace_test(m, working: tuple[int, int]):
    """Box test in the workspace for one working mode (sign u, sign v).

    1: every P of the box is reachable, non-singular (no serial: strictly inside both annuli;
    no parallel: det A != 0) in this working mode; -1: no P of the box is reachable; 0 otherwise.
    The sign of det A is constant on a black cell; `workspace_assembly_sign` reads it.
    """
    tests = working_mode_workspace_tests(m, (working,))
    return lambda lo, hi: tests(lo, hi)[:, 0]


def working_mode_workspace_tests(m, workings):
    """The box tests of several working modes at once (a `paving.engine.MultiTest`: statuses
    (n, len(workings))), sharing the reach test and the legs' direction and angle ranges. Only a
    box strictly inside both annuli can be black: the signs are taken for those boxes only."""
    classify = workspace_modes_classifier(m, workings)

    def test(lo: np.ndarray, hi: np.ndarray, open_=None, ends=None) -> np.ndarray:
        status, strict, d = classify.reach(lo, hi, ends)
        out = np.repeat(np.where(status == -1, -1, 0).astype(np.int8)[:, None], len(workings), axis=1)
        rows = np.flatnonzero(strict)  # (strict implies reachable: status 1)
        if len(rows):
            ends = AxisEnds.of_boxes(lo, hi) if ends is None else ends
            signs = classify.signs(tuple(e.rows(rows) for e in ends), [(dmin[rows], dmax[rows]) for dmin, dmax in d])
            out[rows] = signs != 0
        return out

    return test


def workspace_mode_classifier(m, working: tuple[int, int]):
    """Per box, for one working mode: (reach status 1/-1/0, strictly inside both annuli, sign of
    det A over the reachable points of the box, 0 where it is not constant).

    With alpha_i the direction of P - A_i and gamma_i the angle at P in triangle A_i B_i P,
    the legs' directions are th3 = alpha1 + su gamma1 and th4 = alpha2 + sv gamma2, and
    sign det A = sign sin(th4 - th3): its range is the sum of four exact ranges.
    """
    classify = workspace_modes_classifier(m, (working,))

    def one(lo: np.ndarray, hi: np.ndarray, ends=None):
        status, strict, signs = classify(lo, hi, ends)
        return status, strict, signs[:, 0]

    return one


def workspace_modes_classifier(m, workings):
    """`workspace_mode_classifier` of several working modes at once: the sign of det A per mode,
    shape (n, len(workings)); the ranges of alpha_i and gamma_i are computed once. Its parts:
    `reach(lo, hi, ends=None)` -> (status, strict, the legs' squared-distance ranges) and
    `signs(ends, ranges)` -> the signs (`ends`: the boxes' ends per axis, `grid.AxisEnds`); the
    whole, `classify(lo, hi, ends=None)`, takes the ends as tables when the caller has them."""
    (c1, r1, big1), (c2, r2, big2) = annuli(m)
    delta = DELTA_REL * scale(m) ** 2
    anchors = workspace_anchors(m)

    def reach(lo: np.ndarray, hi: np.ndarray, ends=None):
        d1, d2 = leg_distance2_ranges(m, lo, hi, ends)
        status = reach_status(m, lo, hi, (d1, d2), anchors)
        strict = _strict(*d1, r1, big1, delta) & _strict(*d2, r2, big2, delta)
        return status, strict, (d1, d2)

    def signs(ends, d) -> np.ndarray:
        leg1 = _leg_angle_ranges(m, ends, d[0], c1, r1, big1, m.L3, m.L1, delta)
        leg2 = _leg_angle_ranges(m, ends, d[1], c2, r2, big2, m.L4, m.L2, delta)
        out = np.empty((len(d[0][0]), len(workings)), np.int8)
        for k, (su, sv) in enumerate(workings):
            theta, theta4 = leg_branch(*leg1, su), leg_branch(*leg2, sv)
            out[:, k] = sin_sign(theta4[0] - theta[1], theta4[1] - theta[0])
        return out

    def classify(lo: np.ndarray, hi: np.ndarray, ends=None):
        status, strict, d = reach(lo, hi, ends)
        return status, strict, signs(AxisEnds.of_boxes(lo, hi) if ends is None else ends, d)

    classify.reach, classify.signs = reach, signs
    return classify


def _leg_angle_ranges(m, ends, d2range, cx, inner, outer, coupler, crank, delta):
    """Ranges over boxes (their `ends` per axis) of alpha_i (the direction of P - A_i) and gamma_i
    (the angle at P of the triangle A_i B_i P)."""
    x, y = ends
    alpha = direction_range(*x.per_box((x.low - cx, x.high - cx)), y.per_box(y.low), y.per_box(y.high))
    m_lo, m_hi = _valid_lengths(*d2range, inner, outer, delta)
    return alpha, triangle_angle_range(m_lo, m_hi, coupler, crank)


def leg_branch(alpha, gamma, s):
    """Range of the direction of P - B_i, alpha_i + s gamma_i, in the branch of sign s."""
    (a_lo, a_hi), (g_lo, g_hi) = alpha, gamma
    return (a_lo + g_lo, a_hi + g_hi) if s > 0 else (a_lo - g_hi, a_hi - g_lo)


def workspace_assembly_sign(m, working: tuple[int, int], points: np.ndarray) -> np.ndarray:
    """Sign of det A at points of the workspace in a working mode (0 where unreachable)."""
    th1, th2, ok = ikp(m, points[:, 0], points[:, 1], working)
    _, _, t = mode_values(m, np.nan_to_num(th1), np.nan_to_num(th2), points)
    return np.where(ok, np.sign(t), 0).astype(np.int8)


def assembly_mode_joint_test(m, assembly: int):
    """Box test in the joint space for one assembly mode (sign of det A).

    1: every (th1, th2) of the box assembles, non-singular (|L3-L4| < |B1B2| < L3+L4 strictly,
    B1 != B2, B11 != 0, B22 != 0); -1: no point of the box assembles; 0 otherwise. The working
    mode is constant on a black cell; `joint_working_mode` reads it.

    With beta the direction of B2 - B1 and alpha, delta the angles of triangle B1 B2 P at B1 and
    B2: th3 = beta + sa alpha, th4 = beta + pi - sa delta; sign B11 = sign sin(th3 - th1),
    sign B22 = sign sin(th4 - th2). The range of beta comes from the exact ranges of the two
    components of B2 - B1 (each a sum of independent sinusoids).
    """
    tests = assembly_mode_joint_tests(m, (assembly,))
    return lambda lo, hi: tests(lo, hi)[:, 0]


def assembly_mode_joint_tests(m, assemblies):
    """The tests of several assembly modes at once (a `paving.engine.MultiTest`), sharing the
    coupler triangle's ranges. (The triangle's angles and the signs are taken for every box, not
    only for those free of parallel singularity, the only ones that can be black: at deep levels
    86% of them, and gathering them costs what it saves.)"""

    def test(lo: np.ndarray, hi: np.ndarray, open_=None, ends=None) -> np.ndarray:
        status, strict, u, v = joint_modes_classes(m, assemblies, lo, hi, ends)
        out = (strict[:, None] & (u != 0) & (v != 0)).view(np.int8)  # black: 1, else 0
        out[status == -1] = -1
        return out

    return test


def parallel_free_joint_test(m):
    """Box test in the joint space: 1 when every (th1, th2) of the box assembles with det A != 0
    (|L3-L4| < |B1B2| < L3+L4 strictly, so B1 != B2), -1 when none assembles, 0 otherwise.

    det A vanishes exactly where B1, P, B2 are aligned, i.e. where |B1B2| reaches L3 + L4 or
    |L3 - L4|: the set is the same for both assembly modes (each DKP branch is then smooth and
    non-singular), and B11, B22 may vanish in it (serial singularities are allowed). The motions
    of `fivebar path --allow-serial` stay in it.
    """
    r, big = abs(m.L3 - m.L4), m.L3 + m.L4
    delta = DELTA_REL * scale(m) ** 2

    def test(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        dmin, dmax = crank_distance2_range(m, lo, hi)
        status = assembly_status(m, dmin, dmax)
        strict = _strict(dmin, dmax, r, big, delta)
        return verdict(strict, status == -1)

    return test


def joint_mode_classes(m, assembly: int, lo: np.ndarray, hi: np.ndarray, ends=None):
    """Per box: (assembly status 1/-1/0, certified free of parallel singularity, sign B11, sign B22).

    A sign is 0 where it is not constant on the box; the signs are meaningful where the box is
    free of parallel singularities. `aspects.py` uses the pieces to find the boxes that only a
    serial singularity crosses. `ends`: the boxes' ends as tables (`grid.AxisEnds`), if at hand.
    """
    status, strict, u, v = joint_modes_classes(m, (assembly,), lo, hi, ends)
    return status, strict, u[:, 0], v[:, 0]


def joint_modes_classes(m, assemblies, lo: np.ndarray, hi: np.ndarray, ends=None):
    """`joint_mode_classes` of several assembly modes at once: signs of shape (n, len(assemblies));
    `ends`: the boxes' ends as tables (`grid.AxisEnds`), if at hand."""
    r, big = abs(m.L3 - m.L4), m.L3 + m.L4
    delta = DELTA_REL * scale(m) ** 2
    tri = coupler_triangle(m, lo, hi, AngleTables.of(lo, hi, ends))
    status = assembly_status(m, tri.dmin, tri.dmax)
    strict = _strict(tri.dmin, tri.dmax, r, big, delta)
    u, v = serial_signs_of(assemblies, lo, hi, tri)
    return status, strict, u, v


def serial_signs_of(assemblies, lo, hi, tri) -> tuple[np.ndarray, np.ndarray]:
    """`serial_signs` of several assembly modes from one coupler triangle: (n, k) arrays."""
    u = np.empty((len(lo), len(assemblies)), np.int8)
    v = np.empty_like(u)
    for k, sa in enumerate(assemblies):
        u[:, k], v[:, k] = serial_signs(sa, lo, hi, tri.b, tri.a, tri.e)
    return u, v


@dataclass(frozen=True)
class CouplerTriangle:
    """Ranges over boxes of (th1, th2) of the coupler triangle B1 B2 P: |B1B2|^2 (`dmin`, `dmax`),
    the valid |B1B2| (`d`), its angles at B1 (`a`) and B2 (`e`), the direction of B2 - B1 (`b`)."""

    dmin: np.ndarray
    dmax: np.ndarray
    d: tuple
    a: tuple
    e: tuple
    b: tuple


def coupler_triangle(m, lo, hi, angles: AngleTables) -> CouplerTriangle:
    """The coupler triangle's exact ranges (exact lengths), widened by the safety margin."""
    r, big = abs(m.L3 - m.L4), m.L3 + m.L4
    delta = DELTA_REL * scale(m) ** 2
    dmin, dmax = crank_distance2_range(m, lo, hi, angles)
    d_lo, d_hi = _valid_lengths(dmin, dmax, r, big, delta)
    d_lo = np.maximum(d_lo, np.sqrt(delta))  # beta is undefined at B1 = B2; `strict` excludes it
    a = triangle_angle_range(d_lo, d_hi, m.L3, m.L4)
    e = triangle_angle_range(d_lo, d_hi, m.L4, m.L3)
    return CouplerTriangle(dmin, dmax, (d_lo, d_hi), a, e, _crank_direction_range(m, angles))


def coupler_directions(assembly: int, b, a, e):
    """Ranges of th3 and th4 (the directions of P - B1 and P - B2) from the ranges of the direction
    b of B2 - B1 and of the coupler triangle's angles a (at B1) and e (at B2): in this assembly
    mode th3 = b + a, th4 = b + pi - e (b - a, b + pi + e in the other)."""
    (b_lo, b_hi), (a_lo, a_hi), (e_lo, e_hi) = b, a, e
    if assembly > 0:
        return (b_lo + a_lo, b_hi + a_hi), (b_lo + np.pi - e_hi, b_hi + np.pi - e_lo)
    return (b_lo - a_hi, b_hi - a_lo), (b_lo + np.pi + e_lo, b_hi + np.pi + e_hi)


def serial_signs(assembly: int, lo, hi, b, a, e):
    """Signs of B11 and B22 over boxes of (th1, th2) (0 where not constant): those of sin(th3 - th1)
    and sin(th4 - th2), th3 and th4 from `coupler_directions`."""
    t3, t4 = coupler_directions(assembly, b, a, e)
    return sin_sign(t3[0] - hi[:, 0], t3[1] - lo[:, 0]), sin_sign(t4[0] - hi[:, 1], t4[1] - lo[:, 1])


def _crank_direction_range(m, angles: AngleTables):
    """Range of the direction of B2 - B1 over boxes of (th1, th2), from the exact ranges of its
    components L0 + L2 cos th2 - L1 cos th1 and L2 sin th2 - L1 sin th1 (each a sum of ranges of
    one angle: computed per table entry)."""
    x, y = angles.ends
    c1_lo, c1_hi, s1_lo, s1_hi = _cos_sin_range(x.low, x.high, angles.trig[0])
    c2_lo, c2_hi, s2_lo, s2_hi = _cos_sin_range(y.low, y.high, angles.trig[1])
    # each term per table entry, then gathered: (L0 + L2 cos th2) - L1 cos th1, as written per box
    th2_part = y.per_box((m.L0 + m.L2 * c2_lo, m.L0 + m.L2 * c2_hi, m.L2 * s2_lo, m.L2 * s2_hi))
    th1_part = x.per_box((m.L1 * c1_hi, m.L1 * c1_lo, m.L1 * s1_hi, m.L1 * s1_lo))
    return direction_range(*(a - b for a, b in zip(th2_part, th1_part)))


def _cos_sin_range(lo, hi, trig):
    """The exact ranges of cos and of sin over [lo, hi]: (cos min, cos max, sin min, sin max)."""
    return (*sinusoid_range(1.0, 0.0, lo, hi, trig), *sinusoid_range(0.0, 1.0, lo, hi, trig))


def joint_working_mode(m, assembly: int, points: np.ndarray) -> np.ndarray:
    """Working-mode signs (u, v), shape (n, 2), at joint-space points in an assembly mode (0 if none)."""
    b = cranks(m, points[:, 0], points[:, 1])
    p, ok = dkp(m, points[:, 0], points[:, 1], assembly, b)
    u, v, _ = mode_values(m, points[:, 0], points[:, 1], np.nan_to_num(p), b)
    return np.where(ok[:, None], np.sign(np.stack([u, v], axis=1)), 0).astype(np.int8)


@dataclass(frozen=True)
class FiveBarModes:
    """The five-bar's `AspectModel` (mechanisms/base.py)."""

    m: object  # the FiveBar
    working_modes = WORKING_MODES
    assembly_modes = ASSEMBLY_MODES
    serial_names = ("B11", "B22")
    # the box tests and classifiers of exact lengths; RobustFiveBarModes swaps in those of interval lengths
    _workspace_test = staticmethod(working_mode_workspace_test)
    _jointspace_test = staticmethod(assembly_mode_joint_test)
    _workspace_tests = staticmethod(working_mode_workspace_tests)
    _jointspace_tests = staticmethod(assembly_mode_joint_tests)
    _parallel_free_test = staticmethod(parallel_free_joint_test)
    _joint_classes = staticmethod(joint_mode_classes)
    _workspace_classifier = staticmethod(workspace_mode_classifier)

    @property
    def length_scale(self) -> float:
        return scale(self.m)

    def workspace_test(self, working):
        return self._workspace_test(self.m, working)

    def jointspace_test(self, assembly):
        return self._jointspace_test(self.m, assembly)

    def workspace_tests(self, workings):
        return self._workspace_tests(self.m, workings)

    def jointspace_tests(self, assemblies):
        return self._jointspace_tests(self.m, assemblies)

    def parallel_free_test(self, assembly):
        """Joint-space boxes assemblable in `assembly` with det A != 0 (serial singularities allowed)."""
        return self._parallel_free_test(self.m)

    def assembly_signs(self, working, points):
        return workspace_assembly_sign(self.m, working, points)

    def working_signs(self, assembly, points):
        return joint_working_mode(self.m, assembly, points)

    def ikp(self, points, working):
        th1, th2, ok = ikp(self.m, points[:, 0], points[:, 1], working)
        return np.column_stack([th1, th2]), ok

    def dkp(self, points, assembly):
        return dkp(self.m, points[:, 0], points[:, 1], assembly)

    def mode_values(self, joints, poses):
        return np.column_stack(mode_values(self.m, joints[:, 0], joints[:, 1], poses))

    def serial_band_signs(self, assembly, lo, hi, ends=None):
        _, strict, u, v = self._joint_classes(self.m, assembly, lo, hi, ends=ends)
        return strict, np.column_stack([u, v])

    def workspace_signs(self, working, lo, hi, ends=None):
        status, _, sign = self._workspace_classifier(self.m, working)(lo, hi, ends)
        return status != -1, sign[:, None]

    def jointspace_signs(self, assembly, lo, hi, ends=None):
        status, _, u, v = self._joint_classes(self.m, assembly, lo, hi, ends=ends)
        return status != -1, np.column_stack([u, v])

    def jointspace_band_signs(self, assembly, lo, hi, ends=None):
        """`jointspace_signs` and `serial_band_signs` of the same boxes from one classification:
        (may hold an assemblable point, working signs, certified free of parallel singularity)."""
        status, strict, u, v = self._joint_classes(self.m, assembly, lo, hi, ends=ends)
        return status != -1, np.column_stack([u, v]), strict
