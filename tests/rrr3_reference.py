"""An independent 3-RRR reference for the tests (numpy, scipy.ndimage and shapely; nothing from
fivebar_cli), written from the definitions of issue 23 / docs/formats.md:

the pose (x, y, phi in degrees) puts the platform point C_i at (x, y) + R(phi) c_i; leg i has its
elbow B_i = A_i + l1_i (cos theta_i, sin theta_i) with |C_i - B_i| = l2_i; its working-mode sign
is the sign of (B_i - A_i) x (C_i - B_i); A has rows (e_i, (R c_i) x e_i), e_i = C_i - B_i.

The elbow is found by angles (law of cosines), not by the projection formula the code uses: with
d = C_i - A_i, (B - A) x (C - A) = l1 |d| sin(angle from B - A to d), so the sign + puts B - A
clockwise from d: theta = atan2(d) - acos((l1^2 + |d|^2 - l2^2) / (2 l1 |d|)).
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage


def platform_points(platform, poses) -> np.ndarray:
    """C_i (m, 3, 2) and the arms R(phi) c_i (m, 3, 2)."""
    poses = np.atleast_2d(np.asarray(poses, float))
    a = np.radians(poses[:, 2])
    c, s = np.cos(a)[:, None], np.sin(a)[:, None]
    p = np.asarray(platform, float)
    arms = np.stack([c * p[:, 0] - s * p[:, 1], s * p[:, 0] + c * p[:, 1]], -1)
    return poses[:, None, :2] + arms, arms


def valid(base, platform, l1, l2, poses) -> np.ndarray:
    """Every leg strictly inside its annulus |l1 - l2| < |C_i - A_i| < l1 + l2."""
    pts, _ = platform_points(platform, poses)
    rho = np.linalg.norm(pts - np.asarray(base, float)[None], axis=-1)
    l1, l2 = np.asarray(l1, float), np.asarray(l2, float)
    return np.all((rho > np.abs(l1 - l2)) & (rho < l1 + l2), axis=1)


def joint_angles(base, platform, l1, l2, poses, signs) -> np.ndarray:
    """theta_i in radians (m, 3) in working mode `signs` (NaN where a leg cannot reach)."""
    pts, _ = platform_points(platform, poses)
    d = pts - np.asarray(base, float)[None]
    rho = np.linalg.norm(d, axis=-1)
    l1, l2 = np.asarray(l1, float), np.asarray(l2, float)
    with np.errstate(invalid="ignore", divide="ignore"):
        opening = np.arccos((l1 ** 2 + rho ** 2 - l2 ** 2) / (2 * l1 * rho))
    return np.arctan2(d[..., 1], d[..., 0]) - np.asarray(signs, float) * opening


def det_a(base, platform, l1, l2, poses, signs) -> np.ndarray:
    """det A (m,) in working mode `signs`."""
    pts, arms = platform_points(platform, poses)
    t = joint_angles(base, platform, l1, l2, poses, signs)
    elbows = np.asarray(base, float)[None] + np.asarray(l1, float)[:, None] * np.stack([np.cos(t), np.sin(t)], -1)
    e = pts - elbows
    moment = arms[..., 0] * e[..., 1] - arms[..., 1] * e[..., 0]
    with np.errstate(invalid="ignore"):
        return np.linalg.det(np.concatenate([e, moment[..., None]], -1))


def mode_signs(base, platform, l1, poses, theta_deg) -> np.ndarray:
    """The signs of (B_i - A_i) x (C_i - B_i) (m, 3) of poses with actuated angles theta (degrees)."""
    pts, _ = platform_points(platform, poses)
    t = np.radians(np.asarray(theta_deg, float))
    u = np.asarray(l1, float)[:, None] * np.stack([np.cos(t), np.sin(t)], -1)
    e = pts - np.asarray(base, float)[None] - u
    return np.sign(u[..., 0] * e[..., 1] - u[..., 1] * e[..., 0])


def _crossings(base, platform, l1, l2, theta_deg, phi_deg: np.ndarray):
    """The two crossings X (n, 2, 2) of the first two circles (centres B_i - R(phi) c_i, radii
    l2_i; NaN where they do not cross) and the third circle's centre (n, 2)."""
    t = np.radians(np.asarray(theta_deg, float))
    elbows = np.asarray(base, float) + np.asarray(l1, float)[:, None] * np.column_stack([np.cos(t), np.sin(t)])
    zero = np.zeros((len(phi_deg), 1))
    _, arms = platform_points(platform, np.column_stack([zero, zero, phi_deg]))
    centres = elbows[None] - arms  # (n, 3, 2)
    r = np.asarray(l2, float)
    v = centres[:, 1] - centres[:, 0]
    dist = np.linalg.norm(v, axis=-1)
    along = (dist ** 2 + r[0] ** 2 - r[1] ** 2) / (2 * dist)
    with np.errstate(invalid="ignore"):
        across = np.sqrt(r[0] ** 2 - along ** 2)
    unit = v / dist[:, None]
    perp = np.stack([-unit[:, 1], unit[:, 0]], -1)
    x = [centres[:, 0] + along[:, None] * unit + s * across[:, None] * perp for s in (1.0, -1.0)]
    return np.stack(x, 1), centres[:, 2]


def assembly_residual(base, platform, l1, l2, theta_deg, phi_deg: np.ndarray) -> np.ndarray:
    """For actuated angles theta, over orientations phi (n,): for each of the two crossings X of the
    first two circles, |X - D_3| - l2_3 (n, 2); NaN where the circles do not cross. The robot
    assembles at phi where a column is 0."""
    x, third = _crossings(base, platform, l1, l2, theta_deg, phi_deg)
    return np.linalg.norm(x - third[:, None], axis=-1) - float(np.asarray(l2, float)[2])


def assembly_poses(base, platform, l1, l2, theta_deg, phi_range, n: int = 20001) -> np.ndarray:
    """The poses (k, 3) with actuated angles theta: each sign change of a residual on an n-point
    grid of phi_range, refined by bisection (the crossing point X at that phi)."""
    def residual(phi, k):
        return assembly_residual(base, platform, l1, l2, theta_deg, np.atleast_1d(phi))[:, k]

    phi = np.linspace(phi_range[0], phi_range[1], n)
    res = assembly_residual(base, platform, l1, l2, theta_deg, phi)
    poses = []
    for k in range(2):
        a, b = res[:-1, k], res[1:, k]
        for j in np.flatnonzero(np.isfinite(a) & np.isfinite(b) & (np.sign(a) != np.sign(b))):
            lo, hi = phi[j], phi[j + 1]
            for _ in range(60):
                mid = 0.5 * (lo + hi)
                if np.sign(residual(mid, k)[0]) == np.sign(res[j, k]):
                    lo = mid
                else:
                    hi = mid
            x, _ = _crossings(base, platform, l1, l2, theta_deg, np.array([lo]))
            poses.append([*x[0, k], lo])
    return np.array(poses).reshape(-1, 3)


def assembles(base, platform, l1, l2, theta_deg, phi_range, n: int = 4001) -> bool | None:
    """True: some branch changes sign between two orientations of an n-point grid of phi_range (the
    circles crossing all along): the robot assembles; False: every residual is far from 0 (more
    than the most the residual can move between grid points); None: cannot tell."""
    phi = np.linspace(phi_range[0], phi_range[1], n)
    res = assembly_residual(base, platform, l1, l2, theta_deg, phi)
    for k in range(2):
        a, b = res[:-1, k], res[1:, k]
        if np.any(np.isfinite(a) & np.isfinite(b) & (np.sign(a) * np.sign(b) <= 0)):
            return True
    step = np.radians(phi[1] - phi[0])
    reach = np.abs(np.asarray(platform, float)).sum(axis=1).max() + np.max(l2)
    slack = 50.0 * step * reach  # a generous bound of how far a residual moves between two grid points
    finite = res[np.isfinite(res)]
    if finite.size == 0 or np.min(np.abs(finite)) > slack:
        return False
    return None


def aspect_count_2d(base, platform, l1, l2, phi: float, signs, root, n: int, min_fraction: float = 2e-4) -> int:
    """Aspects of working mode `signs` at orientation phi seen on an n x n grid of cell centres of
    root ((xlo, xhi), (ylo, yhi)): 8-connected components of the valid centres of each sign of
    det A (not within a relative 1e-9 of 0), of at least min_fraction of the grid's centres."""
    xs = [lo + (np.arange(n) + 0.5) / n * (hi - lo) for lo, hi in root]
    grid = np.stack(np.meshgrid(*xs, indexing="ij"), -1).reshape(-1, 2)
    poses = np.column_stack([grid, np.full(len(grid), phi)])
    ok = valid(base, platform, l1, l2, poses)
    d = np.where(ok, det_a(base, platform, l1, l2, poses, signs), 0.0)
    scale = float(np.max(np.abs(d))) or 1.0
    total = 0
    for sign in (1, -1):
        labels, _ = ndimage.label((ok & (sign * d > 1e-9 * scale)).reshape(n, n), structure=np.ones((3, 3), bool))
        sizes = np.bincount(labels.ravel())[1:]
        total += int(np.count_nonzero(sizes >= min_fraction * n * n))
    return total


def aspect_count_3d(base, platform, l1, l2, signs, root, n: int, min_fraction: float = 1e-4) -> int:
    """Aspects of working mode `signs` over (x, y, phi) seen on an n^3 grid of cell centres of root
    ((xlo, xhi), (ylo, yhi), (phi1, phi2)), phi not periodic: 26-connected components of the valid
    centres of each sign of det A, of at least min_fraction of the grid's centres."""
    axes = [lo + (np.arange(n) + 0.5) / n * (hi - lo) for lo, hi in root]
    poses = np.stack(np.meshgrid(*axes, indexing="ij"), -1).reshape(-1, 3)
    ok = valid(base, platform, l1, l2, poses)
    d = np.where(ok, det_a(base, platform, l1, l2, poses, signs), 0.0)
    scale = float(np.max(np.abs(d))) or 1.0
    total = 0
    for sign in (1, -1):
        labels, _ = ndimage.label((ok & (sign * d > 1e-9 * scale)).reshape(n, n, n), structure=np.ones((3, 3, 3), bool))
        sizes = np.bincount(labels.ravel())[1:]
        total += int(np.count_nonzero(sizes >= min_fraction * n ** 3))
    return total


def disc(cx: float, cy: float, r: float, n: int):
    """A regular n-gon about (cx, cy) with the disc's area (its radius r (2 pi / (n sin(2 pi / n)))^(1/2)):
    its boundary stays within r (2 pi / n)^2 / 4 of the circle, crossing it twice per side."""
    from shapely.geometry import Polygon

    t = 2 * np.pi * np.arange(n) / n
    rr = r * np.sqrt(2 * np.pi / (n * np.sin(2 * np.pi / n)))
    return Polygon(np.column_stack([cx + rr * np.cos(t), cy + rr * np.sin(t)]))


def annuli_area(base, platform, l1, l2, phi: float, n: int = 1 << 15) -> float:
    """The area reachable at orientation phi as shapely polygons: the intersection of the three
    annuli about A_i - R(phi) c_i, each circle an n-gon of its area (`disc`)."""
    _, arms = platform_points(platform, [[0.0, 0.0, phi]])
    region = None
    for i in range(3):
        cx, cy = np.asarray(base[i], float) - arms[0, i]
        ring = disc(cx, cy, l1[i] + l2[i], n)
        inner = abs(l1[i] - l2[i])
        if inner > 0:
            ring = ring.difference(disc(cx, cy, inner, n))
        region = ring if region is None else region.intersection(ring)
    return float(region.area)
