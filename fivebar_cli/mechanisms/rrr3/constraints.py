"""A 3-RRR's joint limits and obstacles (the shared YAML keys of `mechanisms/constraints.py`):
which constraints a configuration violates, and their certified status over boxes of poses.

Six angles can be limited (degrees in files, radians here), each a signed angle
atan2(u x v, u . v) in (-180, 180]:

    theta1..3  actuated at A_i: from the x axis to A_i -> B_i (the joint-space axes)
    B1..3      passive elbow:   from A_i -> B_i to B_i -> C_i

A configuration collides when one of its links, the segments A_iB_i and B_iC_i, or an edge of the
platform, C1C2, C2C3, C3C1, comes within `clearance` of an obstacle (the platform is a body that
moves in the same plane as the legs).

A configuration is a pose and a working mode (the elbows), so the constraints are tested per
working mode. Over a box of poses, in working mode s (d_i = C_i - A_i, rho_i = |d_i|):
- rho_i has its exact range (`Platform.distance_ranges`), clipped to the annulus where the leg
  exists; the direction alpha_i of d_i ranges over the directions of the box holding every d_i
  (the box of (x, y) plus the arc of R(phi) c_i);
- the leg triangle A_i B_i C_i has the angles beta_i at A_i and gamma_i at C_i, exact functions of
  rho_i: theta_i = alpha_i - s_i beta_i, the direction of B_i -> C_i is alpha_i + s_i gamma_i, and
  the elbow angle s_i (pi - the angle at B_i) is an exact function of rho_i;
- B_i lies in the box of A_i plus l1_i along theta_i's arc and in the box of C_i minus l2_i along
  the distal direction's arc: their intersection; the links' ends range over these boxes and C_i's.
`constraint_tests.constraint_status` decides from them, with ANGLE_MARGIN on angles and the margin
`obstacle_margin` on distances; positions are widened by the geometry's `eta` before.
"""

from __future__ import annotations

import math

import numpy as np

from fivebar_cli.mechanisms import constraints as shared
from fivebar_cli.mechanisms.constraint_tests import (
    arc_box, constraint_status, included_angle_range, meet, paved_empty, plus, restricted,
)
from fivebar_cli.mechanisms.constraint_tests import empty_problem as shared_empty_problem
from fivebar_cli.mechanisms.constraints import Constraints
from fivebar_cli.mechanisms.rrr3.boxtests import ETA_REL, Geometry, elbows, signs_of
from fivebar_cli.numerics.platform import ANGLE_TOL, D2R
from fivebar_cli.numerics.ranges import cos_sin_ranges, direction_range, triangle_angle_range

ACTUATED = ("theta1", "theta2", "theta3")
LIMIT_NAMES = (*ACTUATED, "B1", "B2", "B3")
EMPTY_BITS = 12  # `empty_problem` paves the workspace to about 2^EMPTY_BITS cells


def parse(data, source: str) -> Constraints:
    """`limits`, `obstacles` and `clearance` of a 3-RRR's mapping (all optional)."""
    return shared.parse(data, source, LIMIT_NAMES)


def description_data(fields, source: str) -> dict:
    """The YAML mapping of a description's constraint words."""
    return shared.description_data(fields, source, LIMIT_NAMES)


def base_problem(c: Constraints, base) -> tuple[str, str] | None:
    """(field, message) when an obstacle comes within the clearance of a base joint A_i (every
    configuration then collides: the proximal link there always touches it), else None."""
    return shared.base_problem(c, {f"A{i}": p for i, p in enumerate(base, start=1)}, "proximal link")


def obstacle_margin(g: Geometry, c: Constraints) -> float:
    """The margin on obstacle distances: ETA_REL times the size of the mechanism and its obstacles."""
    return g.eta + ETA_REL * c.extent()


# ---------------------------------------------------------------- configurations (floating point)


def configurations(g: Geometry, poses: np.ndarray, signs):
    """The limited angles (radians, by name) and the links ((start, end) arrays (n, 2)) of poses
    (n, 2 or 3) in working mode `signs` (NaN where a leg cannot reach)."""
    d, _ = g.legs_and_arms(poses)
    b = elbows(g, poses, signs)
    c = g.base[None] + d
    u, e = b - g.base[None], c - b
    angles = {f"theta{i + 1}": np.arctan2(u[:, i, 1], u[:, i, 0]) for i in range(3)}
    cross = u[..., 0] * e[..., 1] - u[..., 1] * e[..., 0]
    dot = np.sum(u * e, axis=-1)
    angles.update({f"B{i + 1}": np.arctan2(cross[:, i], dot[:, i]) for i in range(3)})
    a = np.broadcast_to(g.base[None], b.shape)
    links = [(a[:, i], b[:, i]) for i in range(3)] + [(b[:, i], c[:, i]) for i in range(3)]
    links += [(c[:, i], c[:, (i + 1) % 3]) for i in range(3)]
    return angles, links


def violated(m, poses: np.ndarray, mode: str) -> np.ndarray:
    """(n, k) booleans: pose i in working mode `mode` violates constraint j (`labels()` order)."""
    g = Geometry.of(m)
    angles, links = configurations(g, np.atleast_2d(np.asarray(poses, float)), signs_of(mode))
    return shared.violated(m.constraints, angles, links if m.constraints.obstacles else ())


def satisfied(m, poses: np.ndarray, mode: str) -> np.ndarray:
    """Whether poses in working mode `mode` satisfy every constraint (floating point)."""
    return ~np.any(violated(m, poses, mode), axis=1)


# ---------------------------------------------------------------- certified statuses over boxes of poses


def leg_ranges(g: Geometry, c: Constraints, lo: np.ndarray, hi: np.ndarray) -> list[dict]:
    """What `ranges` needs of each leg over boxes of poses that no working mode changes (computed once
    for all the modes of `modes_status`): the range of |C_i - A_i| (rho), the direction range of
    C_i - A_i (alpha) and the box of C_i (c_box), and the triangle's angle ranges at A_i (at_a), at
    B_i (at_b: with a B_i limit) and at C_i (at_c: with obstacles)."""
    lo, hi = g.poses(lo), g.poses(hi)
    eta = g.eta
    limited = {lim.name for lim in c.limits}
    legs = []
    for i, (near, far) in enumerate(g.distance_ranges(lo, hi)):
        l1, l2 = float(g.l1[i]), float(g.l2[i])
        rho = (np.clip(near - eta, g.inner[i], g.outer[i]), np.clip(far + eta, g.inner[i], g.outer[i]))
        t_lo = (lo[:, 2] - g.shift) * D2R + g.angle[i] - ANGLE_TOL
        t_hi = (hi[:, 2] - g.shift) * D2R + g.angle[i] + ANGLE_TOL
        (qx, qy) = (np.multiply(g.radius[i], r) for r in cos_sin_ranges(t_lo, t_hi))
        d_lo = np.column_stack([lo[:, 0] + qx[0] - g.base[i, 0], lo[:, 1] + qy[0] - g.base[i, 1]]) - eta
        d_hi = np.column_stack([hi[:, 0] + qx[1] - g.base[i, 0], hi[:, 1] + qy[1] - g.base[i, 1]]) + eta
        leg = {"alpha": direction_range(d_lo[:, 0], d_hi[:, 0], d_lo[:, 1], d_hi[:, 1]),
               "at_a": triangle_angle_range(*rho, l1, l2)}
        if f"B{i + 1}" in limited:  # pi - the angle at B_i, an exact function of rho_i
            leg["at_b"] = included_angle_range(rho, (l1, l1), (l2, l2))
        if c.obstacles:
            leg["at_c"] = triangle_angle_range(*rho, l2, l1)
            leg["c_box"] = (d_lo + g.base[i], d_hi + g.base[i])
        legs.append(leg)
    return legs


def ranges(g: Geometry, c: Constraints, signs, lo: np.ndarray, hi: np.ndarray, legs: list[dict] | None = None):
    """(angles, links): the ranges (radians) of the limited angles and the (lo corner, hi corner)
    boxes of each link's ends over boxes of poses in working mode `signs` (module docstring), from
    `leg_ranges` (computed here unless given)."""
    legs = leg_ranges(g, c, lo, hi) if legs is None else legs
    n, eta = len(lo), g.eta
    limited = {lim.name for lim in c.limits}
    angles, ends = {}, []
    for i, leg in enumerate(legs):
        l1, l2, s = float(g.l1[i]), float(g.l2[i]), signs[i]
        theta = plus(leg["alpha"], -s, leg["at_a"])
        angles[f"theta{i + 1}"] = theta
        if f"B{i + 1}" in limited:  # s (pi - the angle at B_i)
            angles[f"B{i + 1}"] = plus((np.full(n, math.pi * s),) * 2, -s, leg["at_b"])
        if c.obstacles:
            distal = plus(leg["alpha"], s, leg["at_c"])
            c_box = leg["c_box"]
            proximal, back = arc_box(*theta, (l1, l1)), arc_box(*distal, (l2, l2))
            b_box = meet((proximal[0] + g.base[i] - eta, proximal[1] + g.base[i] + eta),
                         (c_box[0] - back[1] - eta, c_box[1] - back[0] + eta))
            ends.append(((np.tile(g.base[i], (n, 1)),) * 2, b_box, c_box))
    links = [(a, b) for a, b, _ in ends] + [(b, c_) for _, b, c_ in ends]
    links += [(ends[i][2], ends[(i + 1) % 3][2]) for i in range(3)] if ends else []
    return {k: v for k, v in angles.items() if k in limited}, links


def mode_status(g: Geometry, c: Constraints, signs, lo: np.ndarray, hi: np.ndarray,
                legs: list[dict] | None = None) -> np.ndarray:
    """1 / -1 / 0 per box of poses: in working mode `signs`, every constraint holds at every
    configuration of the box / at each one some constraint fails / cannot tell (`legs`: as `ranges`)."""
    angles, links = ranges(g, c, signs, lo, hi, legs)
    if not angles and not links:
        return np.ones(len(lo), np.int8)
    return constraint_status(c, angles, links, obstacle_margin(g, c))


def modes_status(g: Geometry, c: Constraints, modes, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """The status of "some working mode of `modes` satisfies every constraint": 1 when one mode's
    constraints hold on the whole box, -1 when every mode's fail everywhere. The legs' ranges that
    no mode changes are computed once for them all."""
    legs = leg_ranges(g, c, lo, hi)
    s = np.stack([mode_status(g, c, signs_of(w), lo, hi, legs) for w in modes])
    return np.where(np.any(s == 1, axis=0), 1, np.where(np.all(s == -1, axis=0), -1, 0)).astype(np.int8)


def constrained_test(base, g: Geometry, c: Constraints, modes):
    """A box test `base` restricted to the constraints of the working modes `modes` (one: that
    mode's; several: some mode's), evaluated only where `base` is not -1."""
    return lambda lo, hi: restricted(base(lo, hi), lambda k: modes_status(g, c, modes, lo[k], hi[k]))


# ---------------------------------------------------------------- constraints that leave nothing


def leaves_nothing(m) -> bool:
    """Whether the workspace is certified empty under the constraints: every cell of a paving of
    about 2^EMPTY_BITS cells is certified outside."""
    space = m.spaces()["workspace"]
    return paved_empty(space.grid(EMPTY_BITS // space.dim), m.box_test("workspace"))


def empty_problem(m) -> tuple[str, str] | None:
    """(field, message) when the constraints are certified to leave no configuration, naming the
    constraint that alone empties it (or all of them together), else None."""
    return shared_empty_problem(m, leaves_nothing, "3-RRR")
