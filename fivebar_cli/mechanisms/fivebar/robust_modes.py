"""Mode-restricted box tests of a five-bar with interval lengths: the cells of robust aspects.

A box is black for a working mode (workspace) or an assembly mode (joint space) when every point
of it is reachable, non-singular and in that mode for every length vector of the length box; -1
when no point is reachable for any; BAND when every point of it is out of reach for some length
vector (so none is robust; `robust.py`'s band tests). Elsewhere 0: such boxes are split.

The cells a singular curve sweeps as the lengths vary stay 0 at every depth: they bound the robust
aspects from outside, as undetermined cells do in the nominal analysis.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fivebar_cli.mechanisms.fivebar import modes, robust
from fivebar_cli.mechanisms.fivebar.boxtests import AngleTables
from fivebar_cli.numerics.ranges import direction_range, sin_sign
from fivebar_cli.numerics.verdict import verdict
from fivebar_cli.paving.engine import BAND


def _clip(d2range, r_in, r_out, delta):
    lo = np.sqrt(np.maximum(d2range[0] - delta, 0.0))
    hi = np.sqrt(np.maximum(d2range[1] + delta, 0.0))
    return np.clip(lo, r_in, r_out), np.clip(hi, r_in, r_out)


def workspace_mode_classifier(m, working: tuple[int, int]):
    """Per box, for one working mode: (status 1/-1/0 of reach, strictly inside both annuli for every
    L, sign of det A over the box and every L where the configuration exists, 0 if not constant)."""
    classify = workspace_modes_classifier(m, (working,))

    def one(lo, hi, ends=None):  # (the interval lengths' ranges are per box: `ends` unused)
        status, strict, signs = classify(lo, hi)
        return status, strict, signs[:, 0]

    return one


def workspace_modes_classifier(m, workings):
    """`workspace_mode_classifier` of several working modes at once: the sign of det A per mode,
    shape (n, len(workings)); the legs' ranges are computed once."""
    delta, _ = robust.margins(m)

    def classify(lo, hi):
        reach, impossible, strict = robust.workspace_classes(m, lo, hi)
        d1, d2 = robust.leg_ranges(m, lo, hi)
        _, _, p1_in, p1_out = robust.radii(m, 1, 3)
        _, _, p2_in, p2_out = robust.radii(m, 2, 4)
        a1 = direction_range(lo[:, 0], hi[:, 0], lo[:, 1], hi[:, 1])
        wlo, whi = robust.widened(m, lo, hi)
        a2 = direction_range(wlo[:, 0], whi[:, 0], wlo[:, 1], whi[:, 1])
        g1 = robust.triangle_angle_range3(*_clip(d1, p1_in, p1_out, delta), m.bounds[3], m.bounds[1])
        g2 = robust.triangle_angle_range3(*_clip(d2, p2_in, p2_out, delta), m.bounds[4], m.bounds[2])
        signs = np.empty((len(lo), len(workings)), np.int8)
        for k, (su, sv) in enumerate(workings):
            t3, t4 = modes.leg_branch(a1, g1, su), modes.leg_branch(a2, g2, sv)
            signs[:, k] = sin_sign(t4[0] - t3[1], t4[1] - t3[0])
        status = verdict(reach, impossible)
        return status, strict, signs

    return classify


def working_mode_workspace_test(m, working):
    """Black when every P of the box is reachable, non-singular and in this working mode for every L."""
    tests = working_mode_workspace_tests(m, (working,))
    return lambda lo, hi: tests(lo, hi)[:, 0]


def working_mode_workspace_tests(m, workings):
    """The tests of several working modes at once (a `paving.engine.MultiTest`)."""
    classify = workspace_modes_classifier(m, workings)

    def test(lo, hi, open_=None, ends=None):
        status, strict, signs = classify(lo, hi)
        out = robust.workspace_band(m, lo, hi, possible_too=False)  # no point robust: none in a robust aspect
        black = strict[:, None] & (signs != 0)
        return np.where(status[:, None] == -1, -1, np.where(black, 1, np.where(out[:, None], BAND, 0))).astype(np.int8)

    return test


def joint_mode_classes(m, assembly: int, lo, hi, with_band: bool = False, ends=None):
    """Per box: (status 1/-1/0, free of parallel singularity for every L, sign B11, sign B22 over
    the box and every L where it assembles, 0 where not constant); with `with_band` also whether
    no point assembles robustly. `ends`: the boxes' ends as tables (`grid.AxisEnds`), if at hand."""
    status, strict, u, v, *band = joint_modes_classes(m, (assembly,), lo, hi, with_band, ends)
    return (status, strict, u[:, 0], v[:, 0], *band)


def joint_modes_classes(m, assemblies, lo, hi, with_band: bool = False, ends=None):
    """`joint_mode_classes` of several assembly modes at once: signs of shape (n, len(assemblies));
    `ends`: the boxes' ends as tables (`grid.AxisEnds`), if at hand."""
    angles = AngleTables.of(lo, hi, ends)
    bounds = robust.crank_distance_bounds(m, lo, hi, angles)
    reach, impossible = robust.joint_status(m, bounds["low"], bounds["high"])
    strict, _ = robust.joint_status(m, bounds["low"], bounds["high"], strict=True)
    tri = coupler_triangle(m, lo, hi, angles, bounds)
    u, v = modes.serial_signs_of(assemblies, lo, hi, tri)
    status = verdict(reach, impossible)
    if with_band:
        return status, strict, u, v, robust.joint_band(m, bounds, possible_too=False)
    return status, strict, u, v


def coupler_triangle(m, lo, hi, angles: AngleTables, bounds=None) -> modes.CouplerTriangle:
    """The coupler triangle's ranges over the boxes and every length vector (`modes.CouplerTriangle`;
    `dmin`, `dmax` are those of the nominal |B1B2|^2, `d` the valid |B1B2| of every length vector)."""
    bounds = bounds if bounds is not None else robust.crank_distance_bounds(m, lo, hi, angles)
    (l3, u3), (l4, u4) = m.bounds[3], m.bounds[4]
    p_in = 0.0 if max(l3, l4) <= min(u3, u4) else min(abs(l3 - u4), abs(l4 - u3))
    _, eta = robust.margins(m)
    d_lo = np.maximum(np.clip(bounds["low"] - eta, p_in, u3 + u4), eta)  # beta is undefined at d = 0
    d_hi = np.clip(bounds["high"] + eta, p_in, u3 + u4)
    a = robust.triangle_angle_range3(d_lo, d_hi, m.bounds[3], m.bounds[4])
    e = robust.triangle_angle_range3(d_lo, d_hi, m.bounds[4], m.bounds[3])
    b = robust.crank_direction_range(m, angles)
    return modes.CouplerTriangle(bounds["dmin"] ** 2, bounds["dmax"] ** 2, (d_lo, d_hi), a, e, b)


def assembly_mode_joint_test(m, assembly: int):
    """Black when every (th1, th2) of the box assembles in this mode, non-singular, for every L."""
    tests = assembly_mode_joint_tests(m, (assembly,))
    return lambda lo, hi: tests(lo, hi)[:, 0]


def assembly_mode_joint_tests(m, assemblies):
    """The tests of several assembly modes at once (a `paving.engine.MultiTest`)."""

    def test(lo, hi, open_=None, ends=None):
        status, strict, u, v, out = joint_modes_classes(m, assemblies, lo, hi, with_band=True, ends=ends)
        black = strict[:, None] & (u != 0) & (v != 0)
        return np.where(status[:, None] == -1, -1, np.where(black, 1, np.where(out[:, None], BAND, 0))).astype(np.int8)

    return test


def parallel_free_joint_test(m):
    """Black when every (th1, th2) of the box assembles with det A != 0 for every L (|B1B2|
    strictly inside the robust range, serial singularities allowed); -1 when none assembles for
    any L. The cells of `fivebar path --allow-serial` with interval lengths."""

    def test(lo, hi):
        b = robust.crank_distance_bounds(m, lo, hi)
        black, impossible = robust.joint_status(m, b["low"], b["high"], strict=True)
        return verdict(black, impossible)

    return test


@dataclass(frozen=True)
class RobustFiveBarModes(modes.FiveBarModes):
    """The `AspectModel` of a five-bar with interval lengths: black cells are non-singular with their
    modes for every length vector (this module); samples are mapped between the spaces with the
    nominal kinematics (the nominal lengths are in the length box)."""

    _workspace_test = staticmethod(working_mode_workspace_test)
    _jointspace_test = staticmethod(assembly_mode_joint_test)
    _workspace_tests = staticmethod(working_mode_workspace_tests)
    _jointspace_tests = staticmethod(assembly_mode_joint_tests)
    _parallel_free_test = staticmethod(parallel_free_joint_test)
    _joint_classes = staticmethod(joint_mode_classes)
    _workspace_classifier = staticmethod(workspace_mode_classifier)
