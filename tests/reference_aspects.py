"""An independent dense-grid count of a five-bar's generalized aspects (written from the geometry,
with numpy and scipy.ndimage only; nothing from fivebar_cli).

Both spaces are sampled on an n x n grid of cell centres. A centre is kept for a mode when the
configuration there is non-singular with that working mode (signs of B11, B22) and assembly
mode (sign of det A). Kept centres are labelled per mode with 8-connectivity (on the torus in the
joint space); then every kept centre is mapped into the other space (DKP / IKP) and the labels it
lands on are merged. The groups that hold centres of both spaces are the aspects; grid islands of
a thin sliver usually merge through the other space, where the sliver is thick.

A grid sees nothing thinner than a cell: near a pinch (two singular curves tangent) a sliver
thinner than a cell in both spaces leaves islands of a pixel or two that match each other. Groups
are therefore counted only with at least `MIN_PIXELS` * (n / 512)^2 kept centres (a real aspect
grows with the grid, an island does not), and the count is only trusted when it is the same at
two resolutions (`stable_count`).
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage

WORKING = ((1, 1), (1, -1), (-1, 1), (-1, -1))
ASSEMBLY = (1, -1)
EIGHT = np.ones((3, 3), bool)
MIN_PIXELS = 12  # at n = 512; scaled with the number of cells


class JointGeometry:
    """What both assembly modes share at joint values: the cranks' ends B1, B2 and the triangle
    B1 B2 P (reachable, and the angles that place P)."""

    def __init__(self, L, th1, th2):
        L0, L1, L2, L3, L4 = L
        self.L = L
        self.b1 = L1 * np.cos(th1), L1 * np.sin(th1)
        self.b2 = L0 + L2 * np.cos(th2), L2 * np.sin(th2)
        dx, dy = self.b2[0] - self.b1[0], self.b2[1] - self.b1[1]
        dist = np.hypot(dx, dy)
        self.ok = (dist < L3 + L4) & (dist > abs(L3 - L4))
        c = np.clip((dist**2 + L3**2 - L4**2) / (2 * L3 * np.where(dist > 0, dist, 1.0)), -1, 1)
        self.toward, self.spread = _unit(dx, dy, dist), (c, np.sqrt(1 - c * c))  # cos and sin of both angles

    def modes(self, assembly):
        """(valid and non-singular, sign B11, sign B22, P) for one assembly mode: P at the angle
        toward + assembly * spread from B1 (cos and sin by the sum formulas: no trigonometry)."""
        L0, L3 = self.L[0], self.L[3]
        (b1x, b1y), (b2x, b2y) = self.b1, self.b2
        cos, sin = _turned(self.toward, self.spread, assembly)
        px, py = b1x + L3 * cos, b1y + L3 * sin
        u = np.sign(b1x * (py - b1y) - b1y * (px - b1x))
        v = np.sign((b2x - L0) * (py - b2y) - b2y * (px - b2x))
        return self.ok & (u != 0) & (v != 0), u, v, np.stack([px, py], -1)


class WorkGeometry:
    """What the four working modes share at poses: reachability, and each crank's angle for either
    sign of its leg (a working mode takes one per leg)."""

    def __init__(self, L, x, y):
        L0, L1, L2, L3, L4 = L
        self.L, self.x, self.y = L, x, y
        m1, m2 = np.hypot(x, y), np.hypot(x - L0, y)
        self.ok = (m1 > abs(L1 - L3)) & (m1 < L1 + L3) & (m2 > abs(L2 - L4)) & (m2 < L2 + L4)
        c1 = np.clip((L1**2 + m1**2 - L3**2) / (2 * L1 * np.maximum(m1, 1e-300)), -1, 1)
        c2 = np.clip((L2**2 + m2**2 - L4**2) / (2 * L2 * np.maximum(m2, 1e-300)), -1, 1)
        self.toward = np.arctan2(y, x), np.arctan2(y, x - L0)
        self.spread = np.arccos(c1), np.arccos(c2)
        # cos and sin of both angles, for the cranks' ends by the sum formulas (no trigonometry)
        self._unit = _unit(x, y, m1), _unit(x - L0, y, m2)
        self._cos_sin = (c1, np.sqrt(1 - c1 * c1)), (c2, np.sqrt(1 - c2 * c2))
        self._cranks = {}

    def crank(self, leg: int, sign: int):
        """(theta, Bx, By) of crank `leg` (0 or 1) when its leg's working-mode sign is `sign`."""
        if (leg, sign) not in self._cranks:
            L0, L1, L2 = self.L[:3]
            th = self.toward[leg] - sign * self.spread[leg]
            cos, sin = _turned(self._unit[leg], self._cos_sin[leg], -sign)
            self._cranks[leg, sign] = ((th, L1 * cos, L1 * sin) if leg == 0 else (th, L0 + L2 * cos, L2 * sin))
        return self._cranks[leg, sign]

    def modes(self, working):
        """(valid and non-singular, sign det A, th1, th2) for one working mode."""
        x, y = self.x, self.y
        th1, b1x, b1y = self.crank(0, working[0])
        th2, b2x, b2y = self.crank(1, working[1])
        t = np.sign((x - b1x) * (y - b2y) - (y - b1y) * (x - b2x))
        return self.ok & (t != 0), t, th1, th2


def _unit(dx, dy, length):
    """cos and sin of the direction (dx, dy) of length `length` (arctan2's (1, 0) at the origin)."""
    zero = length == 0
    scale = 1 / np.where(zero, 1.0, length)
    return np.where(zero, 1.0, dx * scale), dy * scale


def _turned(direction, turn, sign):
    """cos and sin of a + sign * b, from (cos a, sin a) and (cos b, sin b)."""
    (ca, sa), (cb, sb) = direction, turn
    return ca * cb - sign * sa * sb, sa * cb + sign * ca * sb


def joint_modes(L, th1, th2, assembly):
    """(valid and non-singular, sign B11, sign B22, P) at joint values, for one assembly mode."""
    return JointGeometry(L, th1, th2).modes(assembly)


def work_modes(L, x, y, working):
    """(valid and non-singular, sign det A, th1, th2) at poses, for one working mode."""
    return WorkGeometry(L, x, y).modes(working)


def _label(mask: np.ndarray, torus: bool) -> np.ndarray:
    """8-connected labels (0: not kept), with the opposite edges glued on the torus."""
    labels, n = ndimage.label(mask, structure=EIGHT)
    if not torus or n == 0:
        return labels
    pairs = [np.stack([labels[0, :], labels[-1, :]], 1), np.stack([labels[:, 0], labels[:, -1]], 1)]
    for shift in (-1, 1):  # diagonal contacts across the seams
        pairs.append(np.stack([labels[0, :], np.roll(labels[-1, :], shift)], 1))
        pairs.append(np.stack([labels[:, 0], np.roll(labels[:, -1], shift)], 1))
    pairs = np.concatenate(pairs)
    pairs = pairs[(pairs[:, 0] > 0) & (pairs[:, 1] > 0)]
    return _merge(labels, n, pairs)


def _merge(labels: np.ndarray, n: int, pairs: np.ndarray) -> np.ndarray:
    parent = np.arange(n + 1)

    def find(a):
        while parent[a] != a:
            parent[a] = parent[parent[a]]
            a = parent[a]
        return a

    keys = np.unique(pairs[:, 0].astype(np.int64) * (n + 1) + pairs[:, 1])
    for a, b in zip((keys // (n + 1)).tolist(), (keys % (n + 1)).tolist()):
        ra, rb = find(a), find(b)
        if ra != rb:
            parent[max(ra, rb)] = min(ra, rb)
    roots = np.array([find(k) for k in range(n + 1)])
    return roots[labels]


def count(L, n: int = 1024) -> int:
    """The number of generalized aspects seen on n x n grids of both spaces."""
    L = tuple(float(v) for v in L)
    t = (np.arange(n) + 0.5) / n * 2 * np.pi - np.pi
    th1, th2 = t[:, None], t[None, :]  # the grid by broadcasting: what depends on one axis is computed on n values
    reach = L[1] + L[3]
    s = (np.arange(n) + 0.5) / n * 2 * reach - reach
    x, y = s[:, None], s[None, :]
    joint, joints, poses = {}, JointGeometry(L, th1, th2), WorkGeometry(L, x, y)
    for am in ASSEMBLY:
        ok, u, v, p = joints.modes(am)
        for wm in WORKING:
            joint[wm, am] = (_label(ok & (u == wm[0]) & (v == wm[1]), True), p)
    work = {}
    for wm in WORKING:
        ok, sign, a1, a2 = poses.modes(wm)
        for am in ASSEMBLY:
            work[wm, am] = (_label(ok & (sign == am), False), a1, a2)
    total = 0
    for key in joint:
        jl, p = joint[key]
        wl, a1, a2 = work[key]
        kept = wl > 0  # workspace -> joint
        i1 = np.floor((a1[kept] + np.pi) / (2 * np.pi) * n).astype(np.int64) % n
        i2 = np.floor((a2[kept] + np.pi) / (2 * np.pi) * n).astype(np.int64) % n
        total += linked_groups(jl, p, wl, jl[i1, i2], reach, n)
    return total


def linked_groups(jl, p, wl, back, reach: float, n: int) -> int:
    """The groups of one mode: joint-space labels `jl` (P at each centre: `p`) and workspace labels
    `wl` merged where a kept centre maps into a labelled cell of the other space (`back`: the joint
    label each kept workspace centre maps to, 0 for none); those with centres in both spaces and at
    least MIN_PIXELS (scaled) of them."""
    nj, nw = int(jl.max()), int(wl.max())
    kept = jl > 0  # joint -> workspace
    joint_kept, work_kept, p_kept = jl[kept], wl[wl > 0], p[kept]
    ix = np.floor((p_kept[:, 0] + reach) / (2 * reach) * n).astype(np.int64)
    iy = np.floor((p_kept[:, 1] + reach) / (2 * reach) * n).astype(np.int64)
    inside = (ix >= 0) & (ix < n) & (iy >= 0) & (iy < n)
    target = np.zeros(len(ix), np.int64)
    target[inside] = wl[ix[inside], iy[inside]]
    hit = target > 0
    pairs = [np.stack([joint_kept[hit], nj + target[hit]], 1)]
    hit = back > 0
    pairs.append(np.stack([back[hit], nj + work_kept[hit]], 1))
    groups = _merge(np.arange(nj + nw + 1), nj + nw, np.concatenate(pairs))
    size_j = np.bincount(groups[joint_kept], minlength=len(groups))
    size_w = np.bincount(groups[nj + work_kept], minlength=len(groups))
    big = (size_j > 0) & (size_w > 0) & (size_j + size_w >= MIN_PIXELS * (n / 512) ** 2)
    return int(np.count_nonzero(big))


def stable_count(L, sizes=(512, 1024)) -> int | None:
    """The count when two resolutions agree, else None (the grids cannot tell)."""
    counts = {count(L, n) for n in sizes}
    return counts.pop() if len(counts) == 1 else None
