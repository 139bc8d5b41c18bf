"""Certified box tests of a five-bar's limits and obstacles (`constraints.py`), and every five-bar
test combined with them.

Per box of either space and per mode (a working mode in the workspace, an assembly mode in the
joint space, where each configuration is one point), `ranges` bounds what the constraints are
about over the box's existing configurations: the five limited angles and the boxes the four link
ends range over. Then `status` is 1 when every constraint holds at every configuration of the box,
-1 when at each one some constraint fails, 0 otherwise. With interval lengths every range also
covers every length vector: 1 then means for every length vector, -1 for none.

The ranges, exact where cheap:
- workspace (P in the box): alpha_i, the direction of P - A_i, and |P - A_i| have exact ranges;
  the triangle angles beta_i (at A_i) and gamma_i (at P) of the leg triangle A_i B_i P are exact
  functions of |P - A_i|. th1 = alpha1 - su beta1, th3 = alpha1 + su gamma1 (as the IKP and the
  mode tests); the elbow B1 = su (pi - angle at B1) is an exact function of |P - A1| (and B2 of
  |P - A2|); P = th4 - th3. B1 lies in the crank's box (th1's arc) and in the coupler's (P minus
  L3 along th3's arc): their intersection.
- joint space: th1, th2 are the box; |B1B2| has its exact range (interval lengths: the robust
  bounds), the coupler triangle's angles and the direction of B2 - B1 follow (the mode tests'
  `coupler_triangle`); P = sa (angle at P), an exact function of |B1B2|; B1 = B2 - th4 ... as above.
- actuated limits narrower than a turn are the joint space's root box (`FiveBar.spaces`), so the
  joint-space tests leave them out; in the workspace they are tested like the passive angles.
- obstacles: each link's ends range over two boxes; `numerics/obstacles.py` bounds the signed
  distance of every segment between them.

Margins: angle ranges widen by ANGLE_MARGIN (1e-8 rad) before deciding, on top of the length
margins (DELTA_REL, ETA_REL of the mode tests) the angles are computed from; obstacle distances by
ETA_REL times the scale of the mechanism and its obstacles.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fivebar_cli.mechanisms.constraint_tests import (  # noqa: F401 (arc_status, restricted: the five-bar's names too)
    arc_box, arc_status, constraint_status, included_angle_range, meet, paved_empty, plus, restricted,
)
from fivebar_cli.mechanisms.constraint_tests import empty_problem as shared_empty_problem
from fivebar_cli.mechanisms.fivebar import modes, robust, robust_modes
from fivebar_cli.mechanisms.fivebar.boxtests import ETA_REL, AngleTables, joint_space_test
from fivebar_cli.mechanisms.fivebar.constraints import LINKS
from fivebar_cli.mechanisms.fivebar.kinematics import scale
from fivebar_cli.numerics.ranges import direction_range, triangle_angle_range
from fivebar_cli.numerics.verdict import verdict

EMPTY_DEPTH = 6  # `empty_problem` paves the joint space this deep to find constraints that leave nothing


# ---------------------------------------------------------------- ranges


def _triangle(s, adjacent, opposite):
    """Range of the angle between a side s (range) and the side `adjacent` of a triangle whose third
    side is `opposite` (lengths as (lo, hi) bounds): exact for exact lengths."""
    if adjacent[0] == adjacent[1] and opposite[0] == opposite[1]:
        return triangle_angle_range(s[0], s[1], adjacent[0], opposite[0])
    return robust.triangle_angle_range3(s[0], s[1], adjacent, opposite)


@dataclass(frozen=True)
class Ranges:
    """Over boxes in one mode: `angles[name]` = (lo, hi) radians of each limited angle the space
    does not handle itself (only those the constraints limit), `ends[name]` = (lo corner, hi corner)
    of A1, A2, B1, B2, P (None without obstacles)."""

    angles: dict
    ends: dict | None


def _ends(m, p, b1, b2):
    """The link ends' boxes: A1, A2 (A2 on [l0, u0] x {0}), B1, B2, P."""
    n = len(p[0])
    l0, u0 = m.bounds[0]
    zeros = np.zeros((n, 2))
    a2 = (np.column_stack([np.full(n, l0), np.zeros(n)]), np.column_stack([np.full(n, u0), np.zeros(n)]))
    return {"A1": (zeros, zeros), "A2": a2, "B1": b1, "B2": b2, "P": p}


def workspace_legs(m, lo: np.ndarray, hi: np.ndarray) -> dict:
    """What `workspace_ranges` needs over boxes of P that no working mode changes (computed once for
    all of `space_test`'s modes): the ranges of |P - A_i| (s1, s2), of the directions of P - A_i
    (a1, a2), and of the triangles' angles at A_i (beta1, beta2), at P (gamma1, gamma2) and at B_i
    (at_B1, at_B2: only with that limit)."""
    bounds, limited = m.bounds, {lim.name for lim in m.constraints.limits}
    delta, _ = robust.margins(m)
    (d1, d2) = robust.leg_ranges(m, lo, hi)
    _, _, p1_in, p1_out = robust.radii(m, 1, 3)
    _, _, p2_in, p2_out = robust.radii(m, 2, 4)
    s1 = modes._valid_lengths(*d1, p1_in, p1_out, delta)
    s2 = modes._valid_lengths(*d2, p2_in, p2_out, delta)
    wlo, whi = robust.widened(m, lo, hi)
    legs = {"a1": direction_range(lo[:, 0], hi[:, 0], lo[:, 1], hi[:, 1]),
            "a2": direction_range(wlo[:, 0], whi[:, 0], wlo[:, 1], whi[:, 1]),
            "beta1": _triangle(s1, bounds[1], bounds[3]), "beta2": _triangle(s2, bounds[2], bounds[4]),
            "gamma1": _triangle(s1, bounds[3], bounds[1]), "gamma2": _triangle(s2, bounds[4], bounds[2])}
    for name, s, crank, coupler in (("B1", s1, bounds[1], bounds[3]), ("B2", s2, bounds[2], bounds[4])):
        if name in limited:  # pi - the angle at B_i, an exact function of |P - A_i|
            legs[f"at_{name}"] = included_angle_range(s, crank, coupler)
    return legs


def workspace_ranges(m, working, lo: np.ndarray, hi: np.ndarray, legs: dict | None = None) -> Ranges:
    """The ranges over boxes of P in a working mode (module docstring), from `workspace_legs`
    (computed here unless given)."""
    su, sv = working
    bounds, limited = m.bounds, {lim.name for lim in m.constraints.limits}
    legs = workspace_legs(m, lo, hi) if legs is None else legs
    a1, a2 = legs["a1"], legs["a2"]
    th1 = plus(a1, -su, legs["beta1"])  # alpha1 - su beta1
    th2 = plus(a2, -sv, legs["beta2"])
    th3 = plus(a1, su, legs["gamma1"])  # alpha1 + su gamma1
    th4 = plus(a2, sv, legs["gamma2"])
    angles = {"theta1": th1, "theta2": th2, "P": (th4[0] - th3[1], th4[1] - th3[0])}
    for name, sign in (("B1", su), ("B2", sv)):
        if name in limited:  # sign (pi - the angle at B_i)
            angles[name] = plus((np.full(len(lo), np.pi * sign),) * 2, -sign, legs[f"at_{name}"])
    if not m.constraints.obstacles:
        return Ranges(angles, None)
    coupler1, coupler2 = arc_box(*th3, bounds[3]), arc_box(*th4, bounds[4])
    b1 = meet(arc_box(*th1, bounds[1]), (lo - coupler1[1], hi - coupler1[0]))
    crank2 = arc_box(*th2, bounds[2])
    b2 = meet((crank2[0] + [bounds[0][0], 0.0], crank2[1] + [bounds[0][1], 0.0]), (lo - coupler2[1], hi - coupler2[0]))
    return Ranges(angles, _ends(m, (lo, hi), b1, b2))


def jointspace_legs(m, lo: np.ndarray, hi: np.ndarray) -> dict:
    """What `jointspace_ranges` needs over boxes of (th1, th2) that no assembly mode changes: the
    angle tables, the coupler triangle, the range of the angle at P (at_p) and, with obstacles, the
    boxes of B1 and B2."""
    bounds = m.bounds
    tables = AngleTables.of(lo, hi)
    tri = (robust_modes.coupler_triangle if m.is_interval else modes.coupler_triangle)(m, lo, hi, tables)
    legs = {"tri": tri, "at_p": included_angle_range(tri.d, bounds[3], bounds[4])}
    if m.constraints.obstacles:
        trig = tables.box_trig
        legs["b1"] = arc_box(lo[:, 0], hi[:, 0], bounds[1], trig[0])
        crank2 = arc_box(lo[:, 1], hi[:, 1], bounds[2], trig[1])
        legs["b2"] = (crank2[0] + [bounds[0][0], 0.0], crank2[1] + [bounds[0][1], 0.0])
    return legs


def jointspace_ranges(m, assembly: int, lo: np.ndarray, hi: np.ndarray, legs: dict | None = None) -> Ranges:
    """The ranges over boxes of (th1, th2) in an assembly mode (module docstring); the actuated
    angles are the box itself (left to the root box). `legs`: `jointspace_legs` (computed here
    unless given)."""
    bounds = m.bounds
    legs = jointspace_legs(m, lo, hi) if legs is None else legs
    tri, at_p = legs["tri"], legs["at_p"]
    th3, th4 = modes.coupler_directions(assembly, tri.b, tri.a, tri.e)
    angles = {"B1": (th3[0] - hi[:, 0], th3[1] - lo[:, 0]), "B2": (th4[0] - hi[:, 1], th4[1] - lo[:, 1]),
              "P": at_p if assembly > 0 else (-at_p[1], -at_p[0])}
    if not m.constraints.obstacles:
        return Ranges(angles, None)
    b1, b2 = legs["b1"], legs["b2"]
    via1, via2 = arc_box(*th3, bounds[3]), arc_box(*th4, bounds[4])
    p = meet((b1[0] + via1[0], b1[1] + via1[1]), (b2[0] + via2[0], b2[1] + via2[1]))
    return Ranges(angles, _ends(m, p, b1, b2))


LINK_ENDS = {"A1B1": ("A1", "B1"), "B1P": ("B1", "P"), "A2B2": ("A2", "B2"), "B2P": ("B2", "P")}
assert tuple(LINK_ENDS) == LINKS


def obstacle_margin(m) -> float:
    """The margin on obstacle distances: ETA_REL times the size of the mechanism and its obstacles."""
    return ETA_REL * (scale(m) + sum(b[1] - b[0] for b in m.bounds) + m.constraints.extent())


def status(m, ranges: Ranges) -> np.ndarray:
    """1 / -1 / 0 per box: every constraint holds at every configuration / at each some constraint
    fails / cannot tell (module docstring)."""
    links = [(ranges.ends[a], ranges.ends[b]) for a, b in LINK_ENDS.values()] if ranges.ends else []
    return constraint_status(m.constraints, ranges.angles, links, obstacle_margin(m))


def workspace_status(m, working, lo, hi, legs: dict | None = None) -> np.ndarray:
    return status(m, workspace_ranges(m, working, lo, hi, legs))


def jointspace_status(m, assembly, lo, hi, legs: dict | None = None) -> np.ndarray:
    return status(m, jointspace_ranges(m, assembly, lo, hi, legs))


# ---------------------------------------------------------------- combined with the existing tests


def space_test(m, space: str, base):
    """The `workspace` / `jointspace` test with the constraints: a point is valid when some mode
    (a working mode in the workspace, an assembly mode in the joint space) reaches or assembles
    it within the constraints. 1 needs one mode whose constraints hold on the whole box."""
    keys = modes.WORKING_MODES if space == "workspace" else modes.ASSEMBLY_MODES
    of, shared = (workspace_status, workspace_legs) if space == "workspace" else (jointspace_status, jointspace_legs)

    def test(lo, hi):
        def combined(mask):  # (what no mode changes, computed once for all of them)
            lo_, hi_ = lo[mask], hi[mask]
            legs = shared(m, lo_, hi_)
            s = np.stack([of(m, key, lo_, hi_, legs) for key in keys])
            return verdict(np.any(s == 1, axis=0), np.all(s == -1, axis=0))

        return restricted(base(lo, hi), combined)

    return test


@dataclass(frozen=True)
class ConstrainedModes(modes.FiveBarModes):
    """The `AspectModel` of a five-bar with limits or obstacles: every mode test and classifier of
    the lengths' model (`base`: exact or interval lengths) restricted to the constraints. A black
    cell is non-singular, in its modes and within every constraint; a cell the constraints fail
    everywhere is certified out of every mode set, so constraint boundaries separate aspects as
    singularities do. Kinematics (IKP, DKP, mode values) are the nominal ones, as before."""

    base: modes.FiveBarModes = None

    def workspace_test(self, working):
        base = self.base.workspace_test(working)
        return lambda lo, hi: restricted(base(lo, hi), lambda k: workspace_status(self.m, working, lo[k], hi[k]))

    def jointspace_test(self, assembly):
        base = self.base.jointspace_test(assembly)
        return lambda lo, hi: restricted(base(lo, hi), lambda k: jointspace_status(self.m, assembly, lo[k], hi[k]))

    def workspace_tests(self, workings):
        return _restricted_columns(self.base.workspace_tests(workings), workings,
                                   lambda w, lo, hi: workspace_status(self.m, w, lo, hi))

    def jointspace_tests(self, assemblies):
        return _restricted_columns(self.base.jointspace_tests(assemblies), assemblies,
                                   lambda a, lo, hi: jointspace_status(self.m, a, lo, hi))

    def parallel_free_test(self, assembly):
        base = self.base.parallel_free_test(assembly)
        return lambda lo, hi: restricted(base(lo, hi), lambda k: jointspace_status(self.m, assembly, lo[k], hi[k]))

    def serial_band_signs(self, assembly, lo, hi, ends=None):
        """Band cells must also be within every constraint (a crossing is a motion)."""
        strict, signs = self.base.serial_band_signs(assembly, lo, hi, ends=ends)
        return self._within(assembly, lo, hi, strict), signs

    def _within(self, assembly, lo, hi, strict):
        """`strict` where the boxes are also certified within every constraint."""
        ok = strict.copy()
        if ok.any():
            ok[ok] = jointspace_status(self.m, assembly, lo[ok], hi[ok]) == 1
        return ok

    def workspace_signs(self, working, lo, hi, ends=None):
        possible, sign = self.base.workspace_signs(working, lo, hi, ends=ends)
        return _possible(possible, lambda k: workspace_status(self.m, working, lo[k], hi[k])), sign

    def jointspace_signs(self, assembly, lo, hi, ends=None):
        possible, signs = self.base.jointspace_signs(assembly, lo, hi, ends=ends)
        return _possible(possible, lambda k: jointspace_status(self.m, assembly, lo[k], hi[k])), signs

    def jointspace_band_signs(self, assembly, lo, hi, ends=None):
        """As `jointspace_signs` and `serial_band_signs`, with the constraints evaluated once on the
        boxes either needs (`_possible`, `_within`)."""
        possible, signs, strict = self.base.jointspace_band_signs(assembly, lo, hi, ends=ends)
        status = np.zeros(len(lo), np.int8)
        needed = possible | strict
        if needed.any():
            status[needed] = jointspace_status(self.m, assembly, lo[needed], hi[needed])
        return possible & (status != -1), signs, strict & (status == 1)


def _restricted_columns(base, modes_, status):
    """A multi-test's columns each restricted to the constraints in its mode (`restricted`),
    evaluated on the boxes still open for that column only."""

    def test(lo, hi, open_, ends=None):
        out = base(lo, hi, open_, ends)
        for c, mode in enumerate(modes_):
            rows = np.flatnonzero(open_[:, c])
            if len(rows):
                out[rows, c] = restricted(out[rows, c], lambda k: status(mode, lo[rows[k]], hi[rows[k]]))
        return out

    return test


def _possible(possible: np.ndarray, constraint) -> np.ndarray:
    """`possible` (may hold a valid point) without the boxes where the constraints fail everywhere."""
    out = possible.copy()
    if out.any():
        out[out] = constraint(out) != -1
    return out


# ---------------------------------------------------------------- constraints that leave nothing


def leaves_nothing(m, depth: int = EMPTY_DEPTH) -> bool:
    """Whether the joint space is certified empty under the constraints: every cell of a paving
    `depth` deep is certified outside."""
    space = m.spaces()["jointspace"]
    base = (robust.joint_space_test if m.is_interval else joint_space_test)(m)
    return paved_empty(space.grid(depth), space_test(m, "jointspace", base))


def empty_problem(m) -> tuple[str, str] | None:
    """(field, message) when the constraints are certified to leave no configuration, naming the
    constraint that alone empties it (or all of them together), else None."""
    return shared_empty_problem(m, leaves_nothing, "five-bar")
