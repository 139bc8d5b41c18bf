"""Five-bar point kinematics: crank positions, DKP, IKP and the mode values whose signs are the
working and assembly modes.

Geometry (docs/formats.md): A1 = (0, 0), A2 = (L0, 0), B1 = A1 + L1 (cos th1, sin th1),
B2 = A2 + L2 (cos th2, sin th2), |P - B1| = L3, |P - B2| = L4. `m` is any object with
attributes L0 .. L4 (a `FiveBar`).

Modes, all from cross products (z components):
  assembly mode  t = (p - b1) x (p - b2)      (sign of det A; > 0 when P is left of B1 -> B2)
  working mode   u = (b1 - a1) x (p - b1),  v = (b2 - a2) x (p - b2)   (signs of B11, B22)
Serial singularities: u = 0 or v = 0 (a leg stretched or folded); parallel: t = 0 (B1, P, B2
aligned, including B1 = B2 when L3 = L4).
"""

from __future__ import annotations

import numpy as np

from fivebar_cli.numerics.ranges import wrap_angle


def scale(m) -> float:
    return m.L0 + m.L1 + m.L2 + m.L3 + m.L4


def cranks(m, th1, th2) -> tuple[np.ndarray, np.ndarray]:
    """Positions of B1 and B2 (arrays of shape (..., 2))."""
    th1, th2 = np.asarray(th1, float), np.asarray(th2, float)
    b1 = np.stack([m.L1 * np.cos(th1), m.L1 * np.sin(th1)], axis=-1)
    b2 = np.stack([m.L0 + m.L2 * np.cos(th2), m.L2 * np.sin(th2)], axis=-1)
    return b1, b2


def dkp(m, th1, th2, assembly: int, crank_points=None) -> tuple[np.ndarray, np.ndarray]:
    """Direct kinematics: P for the assembly mode `assembly` (+1: det A > 0, -1: det A < 0).

    Returns (p, ok) where ok is False where the mechanism cannot be assembled
    (|B1B2| > L3 + L4, |B1B2| < |L3 - L4|, or B1 = B2) and p is NaN there. `crank_points`:
    `cranks(m, th1, th2)` when the caller has them.
    """
    b1, b2 = crank_points if crank_points is not None else cranks(m, th1, th2)
    diff = b2 - b1
    d = np.hypot(diff[..., 0], diff[..., 1])
    beta = np.arctan2(diff[..., 1], diff[..., 0])
    with np.errstate(divide="ignore", invalid="ignore"):
        c = (d * d + m.L3**2 - m.L4**2) / (2.0 * m.L3 * d)
    ok = (d > 0) & (d <= m.L3 + m.L4) & (d >= abs(m.L3 - m.L4))
    alpha = np.arccos(np.clip(np.where(ok, c, 0.0), -1.0, 1.0))
    angle = beta + assembly * alpha
    p = b1 + m.L3 * np.stack([np.cos(angle), np.sin(angle)], axis=-1)
    return np.where(ok[..., None], p, np.nan), ok


def ikp(m, x, y, working: tuple[int, int]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Inverse kinematics: (th1, th2, ok) for the working mode (sign u, sign v).

    u = L1 M1 sin(alpha1 - th1) with alpha1 the direction of A1P, so sign u = +1 is th1 = alpha1 - beta1.
    """
    x, y = np.asarray(x, float), np.asarray(y, float)
    su, sv = working
    m1 = np.hypot(x, y)
    m2 = np.hypot(x - m.L0, y)
    with np.errstate(divide="ignore", invalid="ignore"):
        c1 = (m.L1**2 + m1 * m1 - m.L3**2) / (2.0 * m.L1 * m1)
        c2 = (m.L2**2 + m2 * m2 - m.L4**2) / (2.0 * m.L2 * m2)
    ok = (m1 > 0) & (m2 > 0) & (np.abs(c1) <= 1) & (np.abs(c2) <= 1)
    th1 = np.arctan2(y, x) - su * np.arccos(np.clip(np.where(ok, c1, 0.0), -1, 1))
    th2 = np.arctan2(y, x - m.L0) - sv * np.arccos(np.clip(np.where(ok, c2, 0.0), -1, 1))
    return np.where(ok, wrap_angle(th1), np.nan), np.where(ok, wrap_angle(th2), np.nan), ok


def mode_values(m, th1, th2, p, crank_points=None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(u, v, t): the cross products whose signs are the working modes and the assembly mode
    (`crank_points`: `cranks(m, th1, th2)` when the caller has them)."""
    b1, b2 = crank_points if crank_points is not None else cranks(m, th1, th2)
    a2 = np.array([m.L0, 0.0])
    cross = lambda a, b: a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]  # noqa: E731
    return cross(b1, p - b1), cross(b2 - a2, p - b2), cross(p - b1, p - b2)


def in_joint_space(m, th1, th2) -> np.ndarray:
    """Point test: the mechanism can be assembled with finitely many solutions (B1 != B2)."""
    b1, b2 = cranks(m, th1, th2)
    d = np.hypot(b2[..., 0] - b1[..., 0], b2[..., 1] - b1[..., 1])
    return (d > 0) & (d <= m.L3 + m.L4) & (d >= abs(m.L3 - m.L4))


def in_workspace(m, x, y) -> np.ndarray:
    """Point test: P is reachable by both legs with finitely many solutions (P != A_i)."""
    m1, m2 = np.hypot(x, y), np.hypot(np.asarray(x) - m.L0, y)
    leg1 = (m1 > 0) & (m1 >= abs(m.L1 - m.L3)) & (m1 <= m.L1 + m.L3)
    leg2 = (m2 > 0) & (m2 >= abs(m.L2 - m.L4)) & (m2 <= m.L2 + m.L4)
    return leg1 & leg2
