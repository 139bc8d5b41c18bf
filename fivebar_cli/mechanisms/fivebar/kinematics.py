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
    `cranks(m, th1, th2)` when the caller has them. Computed coordinate by coordinate in place
    (p's coordinates are its last axis, a view of one array per coordinate).
    """
    b1, b2 = crank_points if crank_points is not None else cranks(m, th1, th2)
    (b1x, b1y), (b2x, b2y) = np.moveaxis(b1, -1, 0), np.moveaxis(b2, -1, 0)
    dx, dy = np.asarray(b2x - b1x), np.asarray(b2y - b1y)
    d = np.hypot(dx, dy)
    ok = np.asarray((d > 0) & (d <= m.L3 + m.L4) & (d >= abs(m.L3 - m.L4)))
    alpha = _cosine(d, m.L3, m.L4)
    if not ok.all():
        np.copyto(alpha, 0.0, where=~ok)
    np.clip(alpha, -1.0, 1.0, out=alpha)
    np.arccos(alpha, out=alpha)
    alpha *= assembly
    angle = np.arctan2(dy, dx, out=dx)  # beta (dx is not needed any more)
    angle += alpha
    p = np.empty((2, *ok.shape))
    np.cos(angle, out=p[0, ...])
    np.sin(angle, out=p[1, ...])
    p *= m.L3
    p[0, ...] += b1x
    p[1, ...] += b1y
    if not ok.all():
        np.copyto(p, np.nan, where=~ok)
    return np.moveaxis(p, 0, -1), ok


def ikp(m, x, y, working: tuple[int, int]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Inverse kinematics: (th1, th2, ok) for the working mode (sign u, sign v).

    u = L1 M1 sin(alpha1 - th1) with alpha1 the direction of A1P, so sign u = +1 is th1 = alpha1 - beta1.
    """
    x, y = np.asarray(x, float), np.asarray(y, float)
    su, sv = working
    x2 = np.asarray(x - m.L0)
    m1, m2 = np.hypot(x, y), np.hypot(x2, y)
    ok = np.asarray((m1 > 0) & (m2 > 0))
    angles = []
    for to_a, dist, side, leg, sign in ((x, m1, m.L1, m.L3, su), (x2, m2, m.L2, m.L4, sv)):
        c = _cosine(dist, side, leg)
        ok &= (c >= -1) & (c <= 1)  # (|c| <= 1, NaN excluded)
        angles.append((to_a, c, sign))
    out = []
    for to_a, c, sign in angles:
        if not ok.all():
            np.copyto(c, 0.0, where=~ok)
        np.arccos(c, out=c)
        c *= sign
        th = np.asarray(np.arctan2(y, to_a))
        th -= c
        th = np.asarray(wrap_angle(th, out=th))  # (a new 0-d array for a scalar)
        if not ok.all():
            np.copyto(th, np.nan, where=~ok)
        out.append(th)
    return out[0], out[1], ok


def _cosine(side: np.ndarray, adjacent: float, opposite: float) -> np.ndarray:
    """(adjacent^2 + side^2 - opposite^2) / (2 adjacent side), the cosine of the triangle's angle
    between `side` and `adjacent` (NaN or infinite where side = 0), as a new array."""
    with np.errstate(divide="ignore", invalid="ignore"):
        c = np.asarray(side * side)
        c += adjacent**2
        c -= opposite**2
        c /= side * (2.0 * adjacent)
    return c


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
