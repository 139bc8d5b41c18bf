"""The 3-RPR's aspects in one space of poses (x, y, phi): the `PoseAspectModel` of `Rpr3`.

The classes are the two signs of det J (`boxtests.py`: row i of J is (e_i, q_i x e_i)): an
aspect is a connected component of the reachable poses (every leg in its range) with det J > 0,
or with det J < 0. The class tests are the octree regions `singularity-free det J > 0 | < 0`.
The joints are the leg lengths rho1, rho2, rho3; the direct kinematic problem is the system
|e_i(pose)|^2 - rho_i^2 = 0, with phi in degrees as in the trees.
"""

from __future__ import annotations

import math

import numpy as np

from fivebar_cli.mechanisms.base import Axis, SignClass
from fivebar_cli.mechanisms.rpr3 import boxtests
from fivebar_cli.mechanisms.rpr3.boxtests import MINUS, PLUS, Geometry
from fivebar_cli.numerics.interval import Interval
from fivebar_cli.numerics.platform import leg_enclosure

CLASSES = (SignClass((("det_sign", "+"),)), SignClass((("det_sign", "-"),)))
REGIONS = (PLUS, MINUS)  # the class tests, in the order of CLASSES


class Rpr3PoseAspects:
    """`PoseAspectModel` of a 3-RPR with bounded legs (mechanisms/base.py)."""

    space = "workspace"
    classes = CLASSES
    sheets = (SignClass(()),)  # a pose has one class
    singularity_name = "det_j"

    def __init__(self, m):
        self.m = m
        self.g = Geometry.of(m)
        self.joint_axes = tuple(Axis(f"rho{i + 1}", float(a), float(b))
                                for i, (a, b) in enumerate(zip(self.g.rho_min, self.g.rho_max)))
        self.length_scale = self.g.eta / boxtests.ETA_REL

    def class_test(self, k: int):
        return boxtests.region_test(self.m, REGIONS[k])

    def class_tests(self, ks):
        return boxtests.region_tests(self.m, [REGIONS[k] for k in ks])

    def valid_test(self, sheet: int | None = None):
        return boxtests.region_test(self.m, boxtests.REACHABLE)

    def classes_of_boxes(self, lo: np.ndarray, hi: np.ndarray, sheet: int = 0) -> np.ndarray:
        return _det_classes(self.g, lo, hi)

    def valid(self, poses: np.ndarray, sheet: int | None = None) -> np.ndarray:
        legs = boxtests.leg_lengths(self.g, np.atleast_2d(poses))
        return np.all((legs >= self.g.rho_min) & (legs <= self.g.rho_max), axis=1)

    def ikp(self, poses: np.ndarray, k: int = 0) -> tuple[np.ndarray, np.ndarray]:
        poses = np.atleast_2d(np.asarray(poses, float))
        return boxtests.leg_lengths(self.g, poses), np.ones(len(poses), bool)

    def singularity(self, poses: np.ndarray, k: int = 0) -> np.ndarray:
        """det J, floating point (0 on a singularity)."""
        return boxtests.det_j(self.g, np.atleast_2d(np.asarray(poses, float)))

    def dkp_system(self, joints: np.ndarray) -> "LegSystem":
        return LegSystem(self.g, np.asarray(joints, float))

    def sketch(self, poses: np.ndarray, classes=0) -> dict[str, np.ndarray]:
        poses = self.g.poses(np.atleast_2d(np.asarray(poses, float)))
        e, q = boxtests._legs_and_arms(self.g, poses)
        platform = poses[:, None, :2] + q
        base = np.asarray(self.g.base, float)
        links = np.stack([np.broadcast_to(base, platform.shape), platform], axis=2)
        return {"base": base, "platform": platform, "links": links}


class LegSystem:
    """|e_i(x, y, phi)|^2 - rho_i^2 = 0 (i = 1, 2, 3), phi in degrees: the poses with leg lengths
    rho (`PoseSystem`). The Jacobian's rows are 2 (e_ix, e_iy, (q_i x e_i) pi / 180): twice J's
    rows with phi in degrees, so it is singular exactly where det J = 0."""

    def __init__(self, g: Geometry, rho: np.ndarray):
        self.g, self.rho = g, rho

    def values(self, poses: np.ndarray) -> np.ndarray:
        e, _ = boxtests._legs_and_arms(self.g, np.atleast_2d(poses))
        return np.sum(e * e, axis=-1) - self.rho ** 2

    def jacobian(self, poses: np.ndarray) -> np.ndarray:
        e, q = boxtests._legs_and_arms(self.g, np.atleast_2d(poses))
        moment = q[..., 0] * e[..., 1] - q[..., 1] * e[..., 0]
        return 2.0 * np.concatenate([e, (moment * (math.pi / 180.0))[..., None]], axis=-1)

    def classes_of_boxes(self, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        return _det_classes(self.g, lo, hi)  # the sign of det J, whatever the legs

    def enclosure(self, lo: np.ndarray, hi: np.ndarray):
        """F and J over boxes (`platform.leg_enclosure` of the legs' passes, `boxtests._leg_passes`)."""
        lo, hi = self.g.poses(lo), self.g.poses(hi)
        box = [Interval(lo[:, k], hi[:, k]) for k in range(3)]
        return leg_enclosure(boxtests._leg_passes(self.g, *box), self.rho, boxtests._D2R)


def _det_classes(g: Geometry, lo, hi) -> np.ndarray:
    """Class 0 (det J > 0) or 1 (det J < 0) certified over each box of poses, -1 where not."""
    sign = boxtests.det_sign(g, np.asarray(lo, float), np.asarray(hi, float))
    return np.where(sign > 0, 0, np.where(sign < 0, 1, -1)).astype(np.int64)
