"""An independent 3-RPR reference for the tests: leg lengths and det J from the geometry.

Written from the definitions in docs/rpr3.md, not from fivebar_cli: the pose (x, y, phi) puts the
platform frame's origin at (x, y) turned by phi degrees; leg i joins B_i to the platform joint
A_i = (x, y) + R(phi) P_i; J has rows (e_i, q_i x e_i) with e_i = A_i - B_i, q_i = R(phi) P_i.
Also: the similar form's platform (P_i = k (B_i - g)), and the concurrency of the leg lines
(det J = 0 exactly when the three lines meet in a point or are parallel).
"""

from __future__ import annotations

import numpy as np


def similar_geometry(t1: float, t2: float, t3: float, k: float) -> tuple[np.ndarray, np.ndarray]:
    """Base and platform points of Jiang & Gosselin's similar form (platform frame at its centroid)."""
    base = np.array([[0.0, 0.0], [t1, 0.0], [t2, t3]])
    return base, k * (base - base.mean(axis=0))


def rotations(phi_deg) -> np.ndarray:
    a = np.radians(np.asarray(phi_deg, float))
    c, s = np.cos(a), np.sin(a)
    return np.stack([np.stack([c, -s], -1), np.stack([s, c], -1)], -2)  # (..., 2, 2)


def arms(platform, poses) -> np.ndarray:
    """q_i = R(phi) P_i, shape (m, 3, 2): the matrix product written out, its sums started from 0.0
    as numpy's einsum does (a zero arm is +0.0); einsum took half the time of an aspect count on a
    96^3 grid."""
    r = rotations(np.asarray(poses)[:, 2])[:, None]  # (m, 1, 2, 2)
    p = np.asarray(platform, float)[None, :, None]  # (1, 3, 1, 2)
    return 0.0 + r[..., 0] * p[..., 0] + r[..., 1] * p[..., 1]


def leg_vectors(base, platform, poses, q=None) -> np.ndarray:
    """e_i = (x, y) + q_i - B_i, shape (m, 3, 2) (`q`: the arms, when already known)."""
    poses = np.asarray(poses, float)
    return poses[:, None, :2] + (arms(platform, poses) if q is None else q) - np.asarray(base, float)[None]


def legs(base, platform, poses, q=None) -> np.ndarray:
    """Leg lengths (m, 3) (`q`: the arms, when already known)."""
    return np.linalg.norm(leg_vectors(base, platform, poses, q), axis=-1)


def det_j(base, platform, poses, q=None) -> np.ndarray:
    """det J (m,) with rows (e_x, e_y, q_x e_y - q_y e_x) (`q`: the arms, when already known)."""
    q = arms(platform, poses) if q is None else q
    e = leg_vectors(base, platform, poses, q)
    rows = np.concatenate([e, (q[..., 0] * e[..., 1] - q[..., 1] * e[..., 0])[..., None]], -1)
    return np.linalg.det(rows)


def leg_lines_gap(base, platform, pose) -> float:
    """How far the three leg lines are from meeting in one point: the distance from the meeting
    point of lines 1 and 2 to line 3, over the size of the mechanism (0 at a singularity)."""
    base = np.asarray(base, float)
    e = leg_vectors(base, platform, np.asarray(pose, float)[None])[0]
    # B_1 + s e_1 = B_2 + t e_2
    s, _ = np.linalg.solve(np.column_stack([e[0], -e[1]]), base[1] - base[0])
    meet = base[0] + s * e[0]
    d3 = e[2] / np.linalg.norm(e[2])
    w = meet - base[2]
    return abs(w[0] * d3[1] - w[1] * d3[0]) / max(np.abs(base).max(), np.abs(e).max())
