"""2-RPR point kinematics. Legs rho_i = |P - A_i| with A1 = (0, 0), A2 = (d, 0).

Differentiating rho_i^2 = |P - A_i|^2 gives A dP = B drho with A = [(P - A1)^T; (P - A2)^T] and
B = diag(rho1, rho2): the working mode (signs of B's diagonal) is always ++ where the legs are
not of zero length, and det A = (P - A1) x (P - A2) = d y, so the assembly mode is the side of
the base line and the parallel singularities are the points of that line. `m` is any object with
attributes d, rho_min, rho_max (an `Rpr2`).
"""

from __future__ import annotations

import numpy as np


def scale(m) -> float:
    return m.d + 2.0 * m.rho_max


def in_limits(m, rho) -> np.ndarray:
    return (rho >= m.rho_min) & (rho <= m.rho_max) & (rho > 0)


def ikp(m, x, y) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(rho1, rho2, ok): the unique leg lengths of P, and where they are within the limits."""
    x, y = np.asarray(x, float), np.asarray(y, float)
    rho1, rho2 = np.hypot(x, y), np.hypot(x - m.d, y)
    return rho1, rho2, in_limits(m, rho1) & in_limits(m, rho2)


def dkp(m, rho1, rho2, assembly: int) -> tuple[np.ndarray, np.ndarray]:
    """(P, ok): the point at distances rho1, rho2 from A1, A2 on the side `assembly` of the base
    line (+1: y >= 0); ok where the legs are within their limits and the triangle closes."""
    rho1, rho2 = np.asarray(rho1, float), np.asarray(rho2, float)
    x = (rho1 * rho1 - rho2 * rho2 + m.d * m.d) / (2.0 * m.d)
    h2 = rho1 * rho1 - x * x
    ok = in_limits(m, rho1) & in_limits(m, rho2) & (np.abs(rho1 - rho2) <= m.d) & (rho1 + rho2 >= m.d)
    y = assembly * np.sqrt(np.maximum(h2, 0.0))
    p = np.stack([x, y], axis=-1)
    return np.where(ok[..., None], p, np.nan), ok


def mode_values(m, rho1, rho2, p) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(B11, B22, det A) = (rho1, rho2, d y)."""
    return np.asarray(rho1, float), np.asarray(rho2, float), m.d * np.asarray(p, float)[..., 1]
