"""Five-bar point kinematics written from the geometry alone (circle intersections and cross
products), independent of fivebar_cli, for the tests of the mode-restricted pavings and aspects."""

from __future__ import annotations

import numpy as np

from fivebar_cli.mechanisms.fivebar.model import FiveBar


def _cross(ax, ay, bx, by):
    return ax * by - ay * bx


def _circle_point(cx, cy, r, qx, qy, rq, side):
    """The intersection of circle (c, r) and circle (q, rq) left (side=+1) or right (-1) of c -> q.

    Returns (x, y, h, d): the point, its distance h from the line c q and d = |q - c|.
    """
    dx, dy = qx - cx, qy - cy
    d = np.hypot(dx, dy)
    with np.errstate(divide="ignore", invalid="ignore"):
        a = (r * r - rq * rq + d * d) / (2 * d)
        h = np.sqrt(r * r - a * a)
        ex, ey = dx / d, dy / d
    return cx + a * ex - side * h * ey, cy + a * ey + side * h * ex, h, d


def ref_ikp(m: FiveBar, x, y, working):
    """(th1, th2, u, v, t, ok) of the configuration of working mode `working` reaching P = (x, y).

    B1 lies on the circle (A1, L1) and the circle (P, L3). With B1 on the side s of the line A1 -> P,
    u = (b1 - a1) x (p - b1) = -s h |P - A1|, so sign u = su needs s = -su (same for leg 2).
    """
    x, y = np.asarray(x, float), np.asarray(y, float)
    su, sv = working
    b1x, b1y, _, d1 = _circle_point(0.0, 0.0, m.L1, x, y, m.L3, -su)
    b2x, b2y, _, d2 = _circle_point(m.L0, 0.0, m.L2, x, y, m.L4, -sv)
    ok = ((d1 > 0) & (d1 <= m.L1 + m.L3) & (d1 >= abs(m.L1 - m.L3))
          & (d2 > 0) & (d2 <= m.L2 + m.L4) & (d2 >= abs(m.L2 - m.L4)))
    u = _cross(b1x, b1y, x - b1x, y - b1y)
    v = _cross(b2x - m.L0, b2y, x - b2x, y - b2y)
    t = _cross(x - b1x, y - b1y, x - b2x, y - b2y)
    return np.arctan2(b1y, b1x), np.arctan2(b2y, b2x - m.L0), u, v, t, ok


def ref_dkp(m: FiveBar, th1, th2, assembly):
    """(x, y, u, v, t, ok) of the assembly `assembly` at joints (th1, th2).

    P lies on the circles (B1, L3) and (B2, L4); on the side s of B1 -> B2, t = (p - b1) x (p - b2)
    = s h |B1B2|, so sign t = assembly needs s = assembly.
    """
    th1, th2 = np.asarray(th1, float), np.asarray(th2, float)
    b1x, b1y = m.L1 * np.cos(th1), m.L1 * np.sin(th1)
    b2x, b2y = m.L0 + m.L2 * np.cos(th2), m.L2 * np.sin(th2)
    x, y, _, d = _circle_point(b1x, b1y, m.L3, b2x, b2y, m.L4, assembly)
    ok = (d > 0) & (d <= m.L3 + m.L4) & (d >= abs(m.L3 - m.L4))
    u = _cross(b1x, b1y, x - b1x, y - b1y)
    v = _cross(b2x - m.L0, b2y, x - b2x, y - b2y)
    t = _cross(x - b1x, y - b1y, x - b2x, y - b2y)
    return x, y, u, v, t, ok


def ref_reachable(m: FiveBar, x, y):
    r1, r2 = np.hypot(x, y), np.hypot(np.asarray(x) - m.L0, y)
    return ((r1 > 0) & (r1 >= abs(m.L1 - m.L3)) & (r1 <= m.L1 + m.L3)
            & (r2 > 0) & (r2 >= abs(m.L2 - m.L4)) & (r2 <= m.L2 + m.L4))
