"""Exact robust and possible membership of five-bar points over a box of link lengths (written from
the geometry with numpy only; nothing from fivebar_cli).

`bounds` is ((lo, hi) for L0 .. L4); A1 = (0, 0), A2 = (L0, 0), cranks L1, L2, couplers L3, L4.

- Workspace: P is valid for lengths L when |L1 - L3| <= |P| <= L1 + L3 and |L2 - L4| <= |P - A2| <=
  L2 + L4. The legs share no length but A2 moves along the segment S = [l0, u0] x {0}: P is valid for
  every L (robust) when |P| lies in [max |L1 - L3|, l1 + l3] (the worst radii, at corners of the
  length box) and |P - a| in [max |L2 - L4|, l2 + l4] for every a of S (the nearest and the farthest
  point of S); for some L (possible) when |P| lies in [min |L1 - L3|, u1 + u3] and some a of S has
  |P - a| in [min |L2 - L4|, u2 + u4] (|P - a| sweeps [nearest, farthest] as a runs along S).
- Joint space: d = |B1B2| with B1 = L1 u(th1), B2 = (L0, 0) + L2 u(th2) is the norm of a vector
  affine in (L0, L1, L2): over the length box it sweeps [zmin, zmax], zmax at a corner (convexity),
  zmin the distance from the origin to a zonotope (its edges and faces, `zonotope_min`). Valid for
  lengths L when |L3 - L4| <= d <= L3 + L4; robust when [zmin, zmax] lies in [max |L3 - L4|, l3 + l4];
  possible when it meets [min |L3 - L4|, u3 + u4].
"""

from __future__ import annotations

import itertools

import numpy as np


def _radii(b_crank, b_coupler):
    """(robust inner, robust outer, possible inner, possible outer) radii of a leg's annulus."""
    (l1, u1), (l3, u3) = b_crank, b_coupler
    possible_in = 0.0 if max(l1, l3) <= min(u1, u3) else min(abs(l1 - u3), abs(l3 - u1))
    return max(abs(u1 - l3), abs(l1 - u3)), l1 + l3, possible_in, u1 + u3


def _segment_distances(bounds, x, y):
    l0, u0 = bounds[0]
    near = np.hypot(x - np.clip(x, l0, u0), y)
    far = np.maximum(np.hypot(x - l0, y), np.hypot(x - u0, y))
    return near, far


def robust_work(bounds, x, y):
    r_in, r_out, _, _ = _radii(bounds[1], bounds[3])
    q_in, q_out, _, _ = _radii(bounds[2], bounds[4])
    m1 = np.hypot(x, y)
    near, far = _segment_distances(bounds, x, y)
    return (m1 >= r_in) & (m1 <= r_out) & (m1 > 0) & (near >= q_in) & (far <= q_out) & (near > 0)


def possible_work(bounds, x, y):
    _, _, r_in, r_out = _radii(bounds[1], bounds[3])
    _, _, q_in, q_out = _radii(bounds[2], bounds[4])
    m1 = np.hypot(x, y)
    near, far = _segment_distances(bounds, x, y)
    return (m1 >= r_in) & (m1 <= r_out) & (near <= q_out) & (far >= q_in)


def zonotope_min(c, W, D):
    """min over |d_k| <= D_k of |c + W d|; c = (cx, cy), W = three columns (wx, wy), D (3,); the
    coordinates are arrays of n points (or scalars), kept apart for speed."""
    cx, cy = c
    best = np.full(np.broadcast(cx, cy).shape, np.inf)
    for k in range(3):  # the 12 edges: one free coefficient, the others at +-D
        others = [j for j in range(3) if j != k]
        wx, wy = W[k]
        for s in itertools.product((-1, 1), repeat=2):
            steps = [s[t] * D[j] for t, j in enumerate(others)]
            px = cx + sum(f * W[j][0] for f, j in zip(steps, others))
            py = cy + sum(f * W[j][1] for f, j in zip(steps, others))
            with np.errstate(divide="ignore", invalid="ignore"):
                t = np.clip(np.nan_to_num(-(px * wx + py * wy) / (wx * wx + wy * wy)), -D[k], D[k])
            best = np.minimum(best, np.hypot(px + t * wx, py + t * wy))
    for k in range(3):  # the origin inside a 2-D face (the zonotope is flat in the plane)
        (a00, a10), (a01, a11) = (W[j] for j in range(3) if j != k)
        others = [j for j in range(3) if j != k]
        for s in (-1, 1):
            px, py = cx + s * D[k] * W[k][0], cy + s * D[k] * W[k][1]
            det = a00 * a11 - a01 * a10
            with np.errstate(divide="ignore", invalid="ignore"):
                d0 = (-px * a11 + py * a01) / det
                d1 = (-py * a00 + px * a10) / det
            inside = (np.abs(d0) <= D[others[0]]) & (np.abs(d1) <= D[others[1]])
            best = np.where(inside, 0.0, best)
    return best


def crank_distance_range(bounds, th1, th2):
    """(zmin, zmax): the range of |B1B2| over the length box at each (th1, th2)."""
    th1, th2 = np.ravel(th1), np.ravel(th2)
    mid = [0.5 * (lo + hi) for lo, hi in bounds]
    half = np.array([0.5 * (hi - lo) for lo, hi in bounds[:3]])
    c1, s1, c2, s2 = np.cos(th1), np.sin(th1), np.cos(th2), np.sin(th2)
    c = (mid[0] + mid[2] * c2 - mid[1] * c1, mid[2] * s2 - mid[1] * s1)
    W = [(1.0, 0.0), (-c1, -s1), (c2, s2)]  # the columns: d/dL0, d/dL1, d/dL2 of B2 - B1
    zmax = np.max([np.hypot(c[0] + sum(s[k] * half[k] * W[k][0] for k in range(3)),
                            c[1] + sum(s[k] * half[k] * W[k][1] for k in range(3)))
                   for s in itertools.product((-1, 1), repeat=3)], axis=0)
    return zonotope_min(c, W, half), zmax


def robust_joint(bounds, th1, th2):
    zmin, zmax = crank_distance_range(bounds, th1, th2)
    r_in, r_out, _, _ = _radii(bounds[3], bounds[4])
    return (zmax <= r_out) & (zmin >= r_in) & (zmin > 0)


def possible_joint(bounds, th1, th2):
    zmin, zmax = crank_distance_range(bounds, th1, th2)
    _, _, p_in, p_out = _radii(bounds[3], bounds[4])
    return (zmin <= p_out) & (zmax >= p_in)


def length_vectors(bounds, rng, extra: int = 16) -> np.ndarray:
    """The 32 corners of the length box and `extra` random length vectors inside it."""
    lo, hi = np.array(bounds).T
    corners = np.array(list(itertools.product(*bounds)))
    return np.vstack([corners, lo + (hi - lo) * rng.random((extra, 5))])


def valid_work(L, x, y):
    """Valid pose for one length vector."""
    L0, L1, L2, L3, L4 = L
    m1, m2 = np.hypot(x, y), np.hypot(x - L0, y)
    return (m1 >= abs(L1 - L3)) & (m1 <= L1 + L3) & (m2 >= abs(L2 - L4)) & (m2 <= L2 + L4)


def valid_joint(L, th1, th2):
    """Assemblable joint values for one length vector."""
    L0, L1, L2, L3, L4 = L
    d = np.hypot(L0 + L2 * np.cos(th2) - L1 * np.cos(th1), L2 * np.sin(th2) - L1 * np.sin(th1))
    return (d >= abs(L3 - L4)) & (d <= L3 + L4)
