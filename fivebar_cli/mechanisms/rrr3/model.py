"""The 3-RRR: model, YAML schema, spaces and regions.

```yaml
name: rrr3-symmetric
type: rrr3
base: {A1: [0, 0], A2: [10, 0], A3: [5, 8.66]}                  # actuated joints, fixed frame
platform: {C1: [-1, -0.577], C2: [1, -0.577], C3: [0, 1.155]}   # platform frame
legs: {proximal: 5, distal: 5}                                 # or lists of three
phi_range: [-30, 30]                                            # degrees; or phi: 0; a full turn: [a, a + 360]
working_mode: "+++"                                             # optional: one of the 8 elbow-sign modes
limits: {theta1: [-120, 120], B1: [10, 170]}                    # optional: theta1..3, B1..3, degrees
obstacles: [{disc: {centre: [5, 3], radius: 0.5}}]              # optional: no link or platform edge may touch
clearance: 0.0                                                  # optional
```

The pose (x, y, phi) puts the platform frame's origin at (x, y), turned by phi (degrees in files,
headers and trees); leg i: B_i = A_i + l1_i (cos theta_i, sin theta_i), |C_i - B_i| = l2_i. The
workspace is paved in (x, y, phi) (an octree; phi periodic over a full turn) or, for one
orientation, in (x, y) (a quadtree, with the exact area of the intersection of the three annuli
|l1_i - l2_i| <= |X - (A_i - R(phi) c_i)| <= l1_i + l2_i); the joint space is the 3-torus of the
actuated angles (theta1, theta2, theta3) in degrees (an actuated limit of less than a turn makes
its axis that interval). Conventions and box tests: `boxtests.py`; limits and obstacles:
`constraints.py` (with them, every test holds only where a working mode's constraints hold).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Mapping

import numpy as np

from fivebar_cli.io import schema
from fivebar_cli.mechanisms.base import (
    Axis, Mechanism, Space, description_numbers, legs_word_value, pair_word, values_word, word_values,
)
from fivebar_cli.mechanisms import constraints as shared_constraints
from fivebar_cli.mechanisms.constraints import NO_CONSTRAINTS, Constraints
from fivebar_cli.mechanisms.rrr3 import boxtests, constraints
from fivebar_cli.mechanisms.rrr3.boxtests import WORKING_MODES, signs_of  # noqa: F401 (the model's names too)
from fivebar_cli.mechanisms.rrr3 import jointspace
from fivebar_cli.numerics import platform as platform_geometry

REACHABLE = "reachable"  # the workspace's own region: every pose of a black cell is reachable
ASSEMBLABLE = "assemblable"  # the joint space's: every joint triple of a black cell assembles

Point = tuple[float, float]
Legs = tuple[float, float, float]


def sign_region(mode: str, det_sign: str) -> str:
    """The region of poses valid in working mode `mode` with det A of sign '+' or '-'."""
    return f"singularity-free {mode} det A {'>' if det_sign == '+' else '<'} 0"


@dataclass(frozen=True)
class Rrr3(Mechanism):
    """3-RRR: base and platform points, proximal and distal lengths per leg, orientation range
    (degrees; phi1 == phi2 for a single orientation), and optionally one working mode."""

    name: str
    base: tuple[Point, Point, Point]
    platform: tuple[Point, Point, Point]
    proximal: Legs
    distal: Legs
    phi_range: tuple[float, float]
    working_mode: str | None = None
    constraints: Constraints = NO_CONSTRAINTS  # joint limits and obstacles (constraints.py)

    kind = "rrr3"
    has_poses = True  # Mechanism's capability: a space of poses (x, y, phi)

    @property
    def full_turn(self) -> bool:
        """Whether phi2 - phi1 = 360 degrees exactly: phi is then periodic."""
        return self.phi_range[1] - self.phi_range[0] == 360.0

    @property
    def working_modes(self) -> tuple[str, ...]:
        """The working modes analysed: the one given, else all eight."""
        return (self.working_mode,) if self.working_mode else WORKING_MODES

    # -- protocol

    @classmethod
    def parse(cls, data: Mapping, source: str = "<config>", check_empty: bool = True) -> "Rrr3":
        """The model of a mapping; optional `limits`, `obstacles`, `clearance` (constraints.py) must
        keep clear of the base joints and, with `check_empty`, not be certified to leave nothing (a
        small paving: `.qt` headers, which describe a mechanism a run already took, skip it)."""
        return _parse(cls, data, source, check_empty)

    @classmethod
    def from_description(cls, fields: Mapping[str, str], name: str, source: str) -> "Rrr3":
        fields = dict(fields)
        limited = {k: fields.pop(k) for k in list(fields) if k in constraints.LIMIT_NAMES or k == "clearance"
                   or (k.startswith("obstacle") and k[8:].isdigit())}
        words = {key: fields.pop(key, None) for key in ("A1", "A2", "A3", "C1", "C2", "C3", "proximal", "distal")}
        mode = fields.pop("working_mode", None)
        v = description_numbers(fields, ("phi1", "phi2"), source)
        data: dict = {"name": name, "type": cls.kind,
                      "base": {f"A{i}": word_values(words[f"A{i}"], (2,), f"A{i}", source) for i in (1, 2, 3)},
                      "platform": {f"C{i}": word_values(words[f"C{i}"], (2,), f"C{i}", source) for i in (1, 2, 3)},
                      "legs": {k: legs_word_value(words[k], k, source) for k in ("proximal", "distal")}}
        data.update({"phi": v["phi1"]} if v["phi1"] == v["phi2"] else {"phi_range": [v["phi1"], v["phi2"]]})
        if mode is not None:
            data["working_mode"] = mode
        return cls.parse({**data, **constraints.description_data(limited, source)}, source, check_empty=False)

    def describe(self) -> str:
        text = self.kind + "".join(f" A{i + 1}={pair_word(p)}" for i, p in enumerate(self.base))
        text += "".join(f" C{i + 1}={pair_word(p)}" for i, p in enumerate(self.platform))
        text += f" proximal={values_word(self.proximal)} distal={values_word(self.distal)}"
        text += f" phi1={float(self.phi_range[0])!r} phi2={float(self.phi_range[1])!r}"
        text += f" working_mode={self.working_mode}" if self.working_mode else ""
        return text + self.constraints.words()

    def spaces(self) -> dict[str, Space]:
        """The workspace (x, y, phi[deg]; (x, y) for one orientation) on a root box holding every
        reachable pose, and, over an orientation range, the joint space: the 3-torus of the
        actuated angles in degrees (at one orientation the angles that assemble form a surface)."""
        (xlo, xhi), (ylo, yhi) = workspace_root(self)
        axes = (Axis("x", xlo, xhi), Axis("y", ylo, yhi))
        phi1, phi2 = self.phi_range
        spaces = {}
        if phi1 < phi2:
            axes += (Axis("phi", phi1, phi2, "deg", periodic=self.full_turn, label=r"$\varphi$"),)
            spaces["jointspace"] = Space("jointspace", ASSEMBLABLE, jointspace.joint_axes(self.constraints))
        return {"workspace": Space("workspace", REACHABLE, axes), **spaces}

    def regions(self, space: str) -> tuple[str, ...]:
        """The workspace: reachable, and per working mode and sign of det A the valid poses of that
        mode and sign (singularity-free); the joint space: assemblable."""
        if space == "jointspace":
            return (ASSEMBLABLE,)
        return (REACHABLE, *(sign_region(w, s) for w in self.working_modes for s in "+-"))

    def box_test(self, space: str, procedure: str = "exact", region: str | None = None):
        if space not in self.spaces() or procedure != "exact":
            raise KeyError((space, procedure))
        if space == "jointspace":
            if region not in (None, ASSEMBLABLE):
                raise KeyError(region)
            return jointspace.assembly_test(self)
        g = boxtests.Geometry.of(self)
        if region in (None, REACHABLE):
            return self._constrained(lambda lo, hi, ends=None: boxtests.valid_status(g, lo, hi, ends), self.working_modes)
        for w in self.working_modes:
            for s in "+-":
                if region == sign_region(w, s):
                    signs, want = signs_of(w), 1 if s == "+" else -1
                    return self._constrained(lambda lo, hi, ends=None: boxtests.class_status(g, signs, want, lo, hi, ends), (w,))
        raise KeyError(region)

    def _constrained(self, test, modes):
        """`test` restricted to the constraints of the working modes `modes` (some mode's)."""
        if not self.constraints:
            return test
        return constraints.constrained_test(test, boxtests.Geometry.of(self), self.constraints, modes)

    def exact_measure(self, space: str, region: str | None = None) -> float | None:
        """One orientation: the area of the intersection of the three annuli (exact, by arcs)."""
        if (space != "workspace" or region not in (None, REACHABLE) or self.phi_range[0] != self.phi_range[1]
                or self.constraints):
            return None
        return reachable_area(self, self.phi_range[0])

    def pose_aspect_model(self):
        """Aspects over (x, y, phi) (or (x, y)) by working mode and sign of det A (`rrr3/aspects.py`)."""
        from fivebar_cli.mechanisms.rrr3.aspects import Rrr3PoseAspects

        return Rrr3PoseAspects(self)

    def unconstrained(self) -> "Rrr3":
        """The 3-RRR without its joint limits and obstacles."""
        return replace(self, constraints=NO_CONSTRAINTS)

    def marks(self, space: str) -> list[dict]:
        """Obstacles (workspace) and actuated limits (joint space, degrees) for figures and `fivebar view`."""
        if space == "workspace":
            return shared_constraints.obstacle_marks(self.constraints)
        if space == "jointspace":
            return shared_constraints.limit_marks(self.constraints, constraints.ACTUATED, degrees=True)
        return []


def annuli(m: Rrr3, phi_deg: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The reachable set at one orientation as circles for `numerics.arcs`: per leg, the disc of
    radius l1 + l2 and the outside of the circle of radius |l1 - l2| about A_i - R(phi) c_i."""
    phi = math.radians(phi_deg - 360.0 * math.floor(phi_deg / 360.0))
    c, s = math.cos(phi), math.sin(phi)
    centres, radii, sides = [], [], []
    for (ax, ay), (px, py), l1, l2 in zip(m.base, m.platform, m.proximal, m.distal):
        centre = (ax - (c * px - s * py), ay - (s * px + c * py))
        centres += [centre, centre]
        radii += [l1 + l2, abs(l1 - l2)]
        sides += [1, -1]
    return np.array(centres), np.array(radii), np.array(sides)


def reachable_area(m: Rrr3, phi_deg: float) -> float:
    """Exact area of the poses reachable at one orientation (Green's theorem on the boundary arcs)."""
    from fivebar_cli.numerics import arcs

    return float(arcs.area(*annuli(m, phi_deg)))


def workspace_root(m: Rrr3) -> tuple[tuple[float, float], tuple[float, float]] | None:
    """An (x, y) box holding every reachable pose over the orientation range (None: the legs never
    meet): each C_i - R(phi) c_i runs along an arc about A_i, widened by l1_i + l2_i."""
    reach = tuple(a + b for a, b in zip(m.proximal, m.distal))
    return platform_geometry.root_box(m.base, m.platform, reach, m.phi_range)


# ---------------------------------------------------------------- YAML


def _parse(cls, data: Mapping, source: str, check_empty: bool = True) -> Rrr3:
    schema.check_keys(data, {"name", "type", "base", "platform", "legs", "phi", "phi_range", "working_mode",
                             *shared_constraints.KEYS}, {"name", "type", "base", "platform", "legs"}, source)
    name = schema.name_field(data, source)
    points = {}
    for key, letter in (("base", "A"), ("platform", "C")):
        given = schema.mapping(data, key, source)
        names = {f"{letter}{i}" for i in (1, 2, 3)}
        schema.check_keys(given, names, names, source, f"{key}.")
        points[key] = tuple(schema.point(given[f"{letter}{i}"], source, f"{key}.{letter}{i}") for i in (1, 2, 3))
        schema.distinct_points(points[key], source, key, letter)
    legs = schema.mapping(data, "legs", source)
    schema.check_keys(legs, {"proximal", "distal"}, {"proximal", "distal"}, source, "legs.")
    proximal, distal = (_leg_values(legs[k], source, f"legs.{k}") for k in ("proximal", "distal"))
    phi_range, _ = schema.orientations(data, source)
    mode = data.get("working_mode")
    if mode is not None and mode not in WORKING_MODES:
        raise schema.ConfigError(source, "working_mode", f"expected one of {', '.join(WORKING_MODES)} (the sign of "
                                 f"(B_i - A_i) x (C_i - B_i) per leg, quoted), got {schema.short(mode)}")
    m = cls(name=name, base=points["base"], platform=points["platform"], proximal=proximal, distal=distal,
            phi_range=phi_range, working_mode=mode)
    if workspace_root(m) is None:
        raise schema.ConfigError(source, "legs", "the three legs can never reach a common pose (no point is within "
                                 "l1 + l2 of all three over the orientation range)")
    m = replace(m, constraints=constraints.parse(data, source))
    if not m.constraints:
        return m
    problem = constraints.base_problem(m.constraints, m.base)
    if problem is None and check_empty:
        problem = constraints.empty_problem(m)
    if problem is not None:
        raise schema.ConfigError(source, *problem)
    return m


def _leg_values(value, source: str, field: str) -> Legs:
    """A positive length for all three legs, or a list of three."""
    if isinstance(value, list):
        if len(value) != 3:
            raise schema.ConfigError(source, field, f"expected a number or a list of three, got {len(value)} values")
        return tuple(schema.number(v, source, f"{field}[{i}]", positive=True) for i, v in enumerate(value))
    v = schema.number(value, source, field, positive=True)
    return (v, v, v)
