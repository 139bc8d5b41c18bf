"""The 3-RRR's aspects in one space of poses: the `PoseAspectModel` of `Rrr3`.

A configuration is a pose and a working mode (the elbow signs, which the IKP chooses), so the
classes are working mode x sign of det A (16, or 2 with `working_mode:` set), grouped in one sheet
per working mode: a pose has a class in each sheet. An aspect is a connected component of the
valid poses (every leg strictly inside its annulus: no serial singularity) of one working mode
with det A of one sign (no parallel singularity). The joints are the actuated angles theta1..3 in
degrees (a 3-torus, or an interval per actuated limit); the direct kinematic problem is
|C_i(pose) - B_i(theta_i)|^2 - l2_i^2 = 0.

Joint limits and obstacles (`constraints.py`) hold per working mode: a class's black cells satisfy
its mode's constraints at every pose, and a box where they fail everywhere is outside the class,
so a constraint boundary separates aspects as a singularity does. A pose is valid in a sheet when
its legs reach it and the sheet's constraints hold (in any sheet: in some working mode). A DKP
solution certified to violate a constraint is not a configuration and is left out, as a working
mode the model leaves out is.
"""

from __future__ import annotations

import numpy as np

from fivebar_cli.mechanisms.base import SignClass
from fivebar_cli.mechanisms.rrr3 import boxtests, constraints
from fivebar_cli.mechanisms.rrr3.boxtests import D2R, Geometry, _D2R, signs_of
from fivebar_cli.mechanisms.rrr3.jointspace import joint_axes
from fivebar_cli.numerics import interval as iv
from fivebar_cli.numerics.interval import Interval
from fivebar_cli.numerics.platform import leg_enclosure, leg_groups, legs_apart
from fivebar_cli.paving.engine import stacked

OUTSIDE = -2  # a DKP solution certified in a working mode the model leaves out (`working_mode:` set)


class Rrr3PoseAspects:
    """`PoseAspectModel` of a 3-RRR (mechanisms/base.py), with one sheet per working mode."""

    space = "workspace"
    singularity_name = "det_a"

    def __init__(self, m):
        self.m = m
        self.g = Geometry.of(m)
        self.modes = m.working_modes
        self.sheets = tuple(SignClass((("working_mode", w),)) for w in self.modes)
        self.classes = tuple(SignClass((("working_mode", w), ("det_sign", s))) for w in self.modes for s in "+-")
        self.joint_axes = joint_axes(m.constraints)
        self.length_scale = self.g.eta / boxtests.ETA_REL

    def _signs(self, k: int) -> tuple[int, int, int]:
        return signs_of(self.modes[k // 2])

    def _modes(self, sheet: int | None) -> tuple[str, ...]:
        return self.modes if sheet is None else (self.modes[sheet],)

    def _constrained(self, test, modes):
        if not self.m.constraints:
            return test
        return constraints.constrained_test(test, self.g, self.m.constraints, modes)

    def class_test(self, k: int):
        signs, want = self._signs(k), 1 if k % 2 == 0 else -1
        return self._constrained(lambda lo, hi, ends=None: boxtests.class_status(self.g, signs, want, lo, hi, ends),
                                 self._modes(k // 2))

    def class_tests(self, ks):
        """The tests of classes `ks` at once (`boxtests.class_statuses`: the validity test shared
        by all, det A by the classes of one working mode), each as `class_test`; with
        constraints, each on its own."""
        if self.m.constraints:
            return stacked([self.class_test(k) for k in ks])
        signs, wants = [self._signs(k) for k in ks], [1 if k % 2 == 0 else -1 for k in ks]
        return lambda lo, hi, open_=None, ends=None: boxtests.class_statuses(self.g, signs, wants, lo, hi, ends, open_)

    def valid_test(self, sheet: int | None = None):
        return self._constrained(lambda lo, hi, ends=None: boxtests.valid_status(self.g, lo, hi, ends), self._modes(sheet))

    def classes_of_boxes(self, lo: np.ndarray, hi: np.ndarray, sheet: int = 0) -> np.ndarray:
        lo, hi = np.asarray(lo, float), np.asarray(hi, float)
        valid = boxtests.valid_status(self.g, lo, hi) == 1
        sign = boxtests.det_sign(self.g, signs_of(self.modes[sheet]), lo, hi, valid)
        return np.where(sign > 0, 2 * sheet, np.where(sign < 0, 2 * sheet + 1, -1)).astype(np.int64)

    def valid(self, poses: np.ndarray, sheet: int | None = None) -> np.ndarray:
        poses = np.atleast_2d(np.asarray(poses, float))
        d, _ = self.g.legs_and_arms(poses)
        rho = np.hypot(d[..., 0], d[..., 1])
        reach = np.all((rho > self.g.inner) & (rho < self.g.outer), axis=1)
        if not self.m.constraints:
            return reach
        return reach & np.any([constraints.satisfied(self.m, poses, w) for w in self._modes(sheet)], axis=0)

    def violated_constraints(self, poses: np.ndarray, sheet: int) -> list[list[str]]:
        """Per pose, the labels of the constraints it violates in `sheet`'s working mode."""
        labels = self.m.constraints.labels()
        return [[labels[j] for j in np.flatnonzero(row)]
                for row in constraints.violated(self.m, poses, self.modes[sheet])]

    def ikp(self, poses: np.ndarray, k: int = 0) -> tuple[np.ndarray, np.ndarray]:
        poses = np.atleast_2d(np.asarray(poses, float))
        theta = boxtests.joint_angles(self.g, poses, self._signs(k))
        return theta, np.all(np.isfinite(theta), axis=1)

    def singularity(self, poses: np.ndarray, k: int = 0) -> np.ndarray:
        """det A in class k's working mode, floating point (0 on a parallel singularity)."""
        return boxtests.det_a(self.g, np.atleast_2d(np.asarray(poses, float)), self._signs(k))

    def dkp_system(self, joints: np.ndarray) -> "DistalSystem":
        return DistalSystem(self, np.asarray(joints, float))

    def sketch(self, poses: np.ndarray, classes=0) -> dict[str, np.ndarray]:
        """Base triangle, platform triangles, and the proximal and distal links of each pose in its
        class's working mode (`classes`: one class, or one per pose)."""
        poses = self.g.poses(np.atleast_2d(np.asarray(poses, float)))
        classes = np.broadcast_to(np.asarray(classes), (len(poses),))
        d, _ = self.g.legs_and_arms(poses)
        platform = self.g.base[None] + d
        elbows = np.empty_like(platform)
        for k in np.unique(classes):
            at = classes == k
            elbows[at] = boxtests.elbows(self.g, poses[at], self._signs(max(int(k), 0)))
        base = np.broadcast_to(self.g.base, platform.shape)
        links = np.concatenate([np.stack([base, elbows], 2), np.stack([elbows, platform], 2)], axis=1)
        return {"base": self.g.base, "platform": platform, "links": links}


class DistalSystem:
    """|e_i(x, y, phi)|^2 - l2_i^2 = 0 with e_i = C_i(pose) - B_i(theta_i) (phi, theta in degrees):
    the poses with actuated angles theta (`PoseSystem`). The Jacobian's rows are
    2 (e_ix, e_iy, (q_i x e_i) pi / 180): twice A's rows, phi in degrees, so it is singular exactly
    where det A = 0. Its solutions' class follows from the joints: the working mode is the sign of
    (B_i - A_i) x e_i, certified with det A's sign over each solution's box."""

    def __init__(self, model: Rrr3PoseAspects, theta: np.ndarray):
        self.model, self.g, self.theta = model, model.g, theta
        t = np.radians(theta)
        self.elbows = self.g.base + self.g.l1[:, None] * np.column_stack([np.cos(t), np.sin(t)])
        arm = [Interval.point(theta[i]) * _D2R for i in range(3)]
        self.arm = [(iv.cos(a) * float(self.g.l1[i]), iv.sin(a) * float(self.g.l1[i])) for i, a in enumerate(arm)]
        # the same arms as (3, 1) columns, for the legs' passes
        self.arm_columns = tuple(Interval(np.array([[float(a[k].lo)] for a in self.arm]),
                                          np.array([[float(a[k].hi)] for a in self.arm])) for k in range(2))

    def _distal(self, poses: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        d, q = self.g.legs_and_arms(np.atleast_2d(poses))
        return d + self.g.base[None] - self.elbows[None], q

    def values(self, poses: np.ndarray) -> np.ndarray:
        e, _ = self._distal(poses)
        return np.sum(e * e, axis=-1) - self.g.l2 ** 2

    def jacobian(self, poses: np.ndarray) -> np.ndarray:
        e, q = self._distal(poses)
        moment = q[..., 0] * e[..., 1] - q[..., 1] * e[..., 0]
        return 2.0 * np.concatenate([e, (moment * D2R)[..., None]], axis=-1)

    def _columns(self, lo: np.ndarray, hi: np.ndarray):
        """Interval e_x, e_y, q x e over boxes of poses, each a list of the three legs' intervals
        (`_leg_passes`)."""
        return legs_apart(self._leg_passes(lo, hi), 3)

    def _leg_passes(self, lo: np.ndarray, hi: np.ndarray) -> list[tuple]:
        """e_x, e_y, q x e with the legs on a first axis ((k, n) Intervals), in the passes of
        `platform.leg_groups` with det A's `boxtests.ONE_PASS` (the legs' constants, arms
        u_i = B_i - A_i and bases are (k, 1) columns)."""
        lo, hi = self.g.poses(lo), self.g.poses(hi)
        x, y, phi = (Interval(lo[:, k], hi[:, k]) for k in range(3))
        t0 = (phi - self.g.shift) * _D2R
        out = []
        for first, stop in leg_groups(len(lo), boxtests.ONE_PASS):
            radius, angle, *_, base_x, base_y = self.g.leg_constants(first, stop)
            c, s = iv.cos_sin(t0 + angle)
            qx, qy = c * radius, s * radius
            ux, uy = (Interval(a.lo[first:stop], a.hi[first:stop]) for a in self.arm_columns)
            ex = x + qx - ux - base_x
            ey = y + qy - uy - base_y
            out.append((ex, ey, qx * ey - qy * ex))
        return out

    def enclosure(self, lo: np.ndarray, hi: np.ndarray):
        """F and J over boxes (`platform.leg_enclosure` of the legs' passes, `_leg_passes`)."""
        return leg_enclosure(self._leg_passes(lo, hi), self.g.l2, _D2R)

    def classes_of_boxes(self, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        """The class certified over each box of poses with these joints; -1 where a sign (or, with
        constraints, whether they hold) is not certified, OUTSIDE where the working mode is one the
        model leaves out or a constraint is certified violated."""
        ex, ey, mm = self._columns(lo, hi)
        signs = []
        for i in range(3):
            ux, uy = self.arm[i]
            cross = ux * ey[i] - uy * ex[i]
            signs.append(np.where(cross.lo > 0, 1, np.where(cross.hi < 0, -1, 0)))
        det = boxtests._det3(*([ex[i], ey[i], mm[i]] for i in range(3)))
        det_sign = np.where(det.lo > 0, 0, np.where(det.hi < 0, 1, -1))
        out = np.full(len(det_sign), -1, np.int64)
        for k, (s1, s2, s3) in enumerate(zip(*signs)):
            if 0 in (s1, s2, s3) or det_sign[k] < 0:
                continue
            mode = "".join("+" if s > 0 else "-" for s in (s1, s2, s3))
            out[k] = 2 * self.model.modes.index(mode) + det_sign[k] if mode in self.model.modes else OUTSIDE
        c = self.model.m.constraints
        for sheet in np.unique(out[out >= 0] // 2) if c else ():  # a certified violation: not a configuration
            at = np.flatnonzero((out >= 0) & (out // 2 == sheet))
            held = constraints.mode_status(self.g, c, signs_of(self.model.modes[sheet]), lo[at], hi[at])
            out[at] = np.where(held == -1, OUTSIDE, np.where(held == 1, out[at], -1))
        return out
