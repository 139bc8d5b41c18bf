"""An independent dense-grid count of the generalized aspects of a five-bar with joint limits and
obstacles (written from the issue's definitions with numpy and scipy.ndimage; nothing from
fivebar_cli): `reference_aspects.py`'s count, with every grid centre that violates a constraint
left out.

Constraints are evaluated here from scratch: the five angles as atan2(u x v, u . v) of the link
vectors, in a closed arc [lo, hi] when some turn of the angle lies in it; a link collides with a
disc when the distance from the centre to the segment is at most radius + clearance, with a
polygon when the segment meets it (crosses an edge or starts inside it) or comes within the
clearance of an edge. The joint-space grid covers the root box: an actuated limit of less than a
turn is the axis itself (not periodic), as the issue fixes.
"""

from __future__ import annotations

import numpy as np

import reference_aspects as ref


def _angle(u, v):
    return np.arctan2(u[..., 0] * v[..., 1] - u[..., 1] * v[..., 0], u[..., 0] * v[..., 0] + u[..., 1] * v[..., 1])


def _in_arc(angle, lo_deg, hi_deg):
    a = np.degrees(angle)
    k = np.ceil((lo_deg - a) / 360.0)
    return a + 360.0 * k <= hi_deg


def _segment_point_distance(a, b, c):
    """Distance from c to the segment [a, b] (x and y apart: no reductions over an axis of 2)."""
    (ax, ay), (bx, by), (cx, cy) = ((p[..., 0], p[..., 1]) for p in (a, b, c))
    abx, aby = bx - ax, by - ay
    t = np.clip(((cx - ax) * abx + (cy - ay) * aby) / np.maximum(abx * abx + aby * aby, 1e-300), 0, 1)
    return np.hypot(ax + t * abx - cx, ay + t * aby - cy)


def _crosses(a, b, c, d):
    def orient(p, q, r):
        return np.sign((q[..., 0] - p[..., 0]) * (r[..., 1] - p[..., 1]) - (q[..., 1] - p[..., 1]) * (r[..., 0] - p[..., 0]))
    return (orient(a, b, c) * orient(a, b, d) <= 0) & (orient(c, d, a) * orient(c, d, b) <= 0)


def _inside_polygon(p, poly):
    inside = np.zeros(p.shape[:-1], bool)
    n = len(poly)
    for i in range(n):
        (x1, y1), (x2, y2) = poly[i], poly[(i + 1) % n]
        cond = (y1 > p[..., 1]) != (y2 > p[..., 1])
        with np.errstate(divide="ignore", invalid="ignore"):
            xs = x1 + (p[..., 1] - y1) * (x2 - x1) / (y2 - y1)
        inside ^= cond & (p[..., 0] < xs)
    return inside


def collides(a, b, obstacle, clearance):
    """Whether the segments [a, b] ((..., 2) arrays) come within `clearance` of the obstacle."""
    kind, value = obstacle
    if kind == "disc":
        centre, radius = value
        return _segment_point_distance(a, b, np.broadcast_to(np.array(centre, float), a.shape)) <= radius + clearance
    poly = np.asarray(value, float)
    hit = _inside_polygon(a, poly)
    n = len(poly)
    for i in range(n):
        p, q = np.broadcast_to(poly[i], a.shape), np.broadcast_to(poly[(i + 1) % n], a.shape)
        hit |= _crosses(a, b, p, q)
        near = np.minimum.reduce([_segment_point_distance(a, b, p), _segment_point_distance(a, b, q),
                                  _segment_point_distance(p, q, a), _segment_point_distance(p, q, b)])
        hit |= near <= clearance
    return hit


def allowed(L, limits, obstacles, clearance, th1, th2, p):
    """Whether configurations (joint values, P) satisfy every limit and avoid every obstacle."""
    L0, L1, L2, L3, L4 = L
    a1 = np.zeros(th1.shape + (2,))
    a2 = np.broadcast_to(np.array([L0, 0.0]), a1.shape)
    b1 = np.stack([L1 * np.cos(th1), L1 * np.sin(th1)], -1)
    b2 = np.stack([L0 + L2 * np.cos(th2), L2 * np.sin(th2)], -1)
    x_axis = np.broadcast_to(np.array([1.0, 0.0]), a1.shape)
    angles = {"theta1": _angle(x_axis, b1 - a1), "theta2": _angle(x_axis, b2 - a2), "B1": _angle(b1 - a1, p - b1),
              "B2": _angle(b2 - a2, p - b2), "P": _angle(b1 - p, b2 - p)}
    ok = np.ones(th1.shape, bool)
    for name, (lo, hi) in limits.items():
        ok &= _in_arc(angles[name], lo, hi)
    for obstacle in obstacles:
        for s, e in ((a1, b1), (b1, p), (a2, b2), (b2, p)):
            ok &= ~collides(s, e, obstacle, clearance)
    return ok


def joint_root(limits):
    """((lo, hi), periodic) of each joint axis."""
    axes = []
    for name in ("theta1", "theta2"):
        lo, hi = limits.get(name, (-180.0, 180.0))
        full = hi - lo >= 360.0
        axes.append(((-np.pi, np.pi), True) if full else ((np.radians(lo), np.radians(hi)), False))
    return axes


def _index(angle, root, periodic, n):
    """Grid index of angles on a joint axis (outside the root: out of range)."""
    wrapped = (angle - root[0]) % (2 * np.pi) + root[0] if periodic else (angle + np.pi) % (2 * np.pi) - np.pi
    return np.floor((wrapped - root[0]) / (root[1] - root[0]) * n).astype(np.int64)


def _label(mask, periodic):
    """8-connected labels, gluing the opposite edges of periodic axes."""
    labels, n = ref.ndimage.label(mask, structure=ref.EIGHT)
    if n == 0 or not any(periodic):
        return labels
    pairs = []
    for axis, wrap in enumerate(periodic):
        if not wrap:
            continue
        first, last = (labels[0, :], labels[-1, :]) if axis == 0 else (labels[:, 0], labels[:, -1])
        along = periodic[1 - axis]  # diagonal contacts across the seam wrap only along a periodic axis
        for shift in (-1, 0, 1):
            moved = np.roll(last, shift)
            if not along and shift:
                moved = moved.copy()
                moved[0 if shift > 0 else -1] = 0
            pairs.append(np.stack([first, moved], 1))
    pairs = np.concatenate(pairs)
    pairs = pairs[(pairs[:, 0] > 0) & (pairs[:, 1] > 0)]
    return ref._merge(labels, n, pairs)


def counts(L, limits=None, obstacles=(), clearance=0.0, n: int = 1024) -> dict:
    """The number of generalized aspects seen on n x n grids, per (working mode, assembly mode)."""
    limits = dict(limits or {})
    L = tuple(float(v) for v in L)
    (r1, p1), (r2, p2) = joint_root(limits)
    t1 = r1[0] + (np.arange(n) + 0.5) / n * (r1[1] - r1[0])
    t2 = r2[0] + (np.arange(n) + 0.5) / n * (r2[1] - r2[0])
    th1, th2 = np.meshgrid(t1, t2, indexing="ij")
    reach = L[1] + L[3]
    s = (np.arange(n) + 0.5) / n * 2 * reach - reach
    x, y = np.meshgrid(s, s, indexing="ij")
    joint, joints, poses = {}, ref.JointGeometry(L, th1, th2), ref.WorkGeometry(L, x, y)
    for am in ref.ASSEMBLY:
        ok, u, v, p = joints.modes(am)
        ok &= allowed(L, limits, obstacles, clearance, th1, th2, p)
        for wm in ref.WORKING:
            joint[wm, am] = (_label(ok & (u == wm[0]) & (v == wm[1]), (p1, p2)), p)
    work = {}
    pose = np.stack([x, y], -1)
    for wm in ref.WORKING:
        ok, sign, a1, a2 = poses.modes(wm)
        ok &= allowed(L, limits, obstacles, clearance, a1, a2, pose)
        for am in ref.ASSEMBLY:
            work[wm, am] = (_label(ok & (sign == am), (False, False)), a1, a2)
    out = {}
    for key in joint:
        jl, p = joint[key]
        wl, a1, a2 = work[key]
        kept = wl > 0  # workspace -> joint, within the root box
        i1, i2 = (_index(a[kept], r, wrap, n) for a, r, wrap in ((a1, r1, p1), (a2, r2, p2)))
        inside = (i1 >= 0) & (i1 < n) & (i2 >= 0) & (i2 < n)
        back = np.zeros(len(i1), np.int64)
        back[inside] = jl[i1[inside], i2[inside]]
        out[key] = ref.linked_groups(jl, p, wl, back, reach, n)
    return out


def stable_counts(L, limits=None, obstacles=(), clearance=0.0, sizes=(512, 1024)) -> dict | None:
    """Per mode counts when two resolutions agree, else None."""
    found = [counts(L, limits, obstacles, clearance, n) for n in sizes]
    return found[0] if all(f == found[0] for f in found) else None
