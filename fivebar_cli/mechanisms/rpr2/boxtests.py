"""Exact box tests of the 2-RPR's workspace and joint space, and the mode-restricted tests.

Workspace: P in the two annuli rho_min <= |P - A_i| <= rho_max, the exact test of
`numerics/annuli.py`. Joint space (rho1, rho2): the triangle A1 A2 P closes when
|rho1 - rho2| <= d <= rho1 + rho2; these are linear, so their extrema over a box are at corners.
Margins: squared lengths by DELTA_REL * scale^2, lengths by ETA_REL * scale.
"""

from __future__ import annotations

import numpy as np

from fivebar_cli.mechanisms.rpr2.kinematics import scale
from fivebar_cli.numerics import annuli as ring
from fivebar_cli.numerics.verdict import verdict

DELTA_REL = 1e-12
ETA_REL = 1e-9


def margins(m) -> tuple[float, float]:
    s = scale(m)
    return DELTA_REL * s * s, ETA_REL * s


def annuli(m) -> list[tuple[float, float, float]]:
    return [(0.0, m.rho_min, m.rho_max), (m.d, m.rho_min, m.rho_max)]


def workspace_test(m):
    """1: every P of the box has both legs within their limits (and not of length 0); -1: none."""
    rings = annuli(m)
    delta, eta = margins(m)
    anchors = ring.anchors(rings, 1e3 * delta)

    def test(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        return ring.reach_status(rings, lo, hi, ring.distance2_ranges(rings, lo, hi), anchors, delta, eta)

    return test


def _triangle(m, lo: np.ndarray, hi: np.ndarray, strict: bool) -> tuple[np.ndarray, np.ndarray]:
    """(every point closes the triangle [strictly], no point closes it) over boxes of (rho1, rho2)."""
    _, eta = margins(m)
    d = m.d
    if strict:
        inside = (lo[:, 0] + lo[:, 1] - eta > d) & (hi[:, 0] - lo[:, 1] + eta < d) & (hi[:, 1] - lo[:, 0] + eta < d)
    else:
        inside = (lo[:, 0] + lo[:, 1] - eta >= d) & (hi[:, 0] - lo[:, 1] + eta <= d) & (hi[:, 1] - lo[:, 0] + eta <= d)
    outside = (hi[:, 0] + hi[:, 1] + eta < d) | (lo[:, 0] - hi[:, 1] - eta > d) | (lo[:, 1] - hi[:, 0] - eta > d)
    return inside, outside


def joint_space_test(m):
    """1: every (rho1, rho2) of the box assembles (the legs are the root box); -1: none does."""

    def test(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        inside, outside = _triangle(m, lo, hi, strict=False)
        return verdict(inside, outside)

    return test


def assembly_joint_test(m):
    """Joint space, one assembly mode: black when every point assembles off the parallel
    singularity (strict triangle inequalities); both modes have the same black cells."""

    def test(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        inside, outside = _triangle(m, lo, hi, strict=True)
        return verdict(inside, outside)

    return test


def working_workspace_test(m):
    """Workspace, the one working mode: black when every P is reachable and off the base line."""
    reach = workspace_test(m)
    _, eta = margins(m)

    def test(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        status = reach(lo, hi)
        off_line = (lo[:, 1] - eta > 0) | (hi[:, 1] + eta < 0)
        return verdict((status == 1) & off_line, status == -1)

    return test


def leg_signs(m, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Signs of B11 = rho1 and B22 = rho2 over boxes (0 where a box reaches length 0)."""
    _, eta = margins(m)
    return np.where(lo - eta > 0, 1, 0).astype(np.int8)
