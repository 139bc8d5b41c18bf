"""The 2-RPR: its YAML schema, spaces, box tests, exact workspace area and aspect model.

```yaml
name: rpr2-demo
type: rpr2
base: {d: 8}                       # A1 = (0, 0), A2 = (d, 0)
legs: {rho_min: 3, rho_max: 15}    # the range of both prismatic legs
```
Workspace: the square of half-side rho_max about (d/2, 0), which holds both annuli's
intersection. Joint space: the box [rho_min, rho_max]^2 of leg lengths.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping

import numpy as np

from fivebar_cli.io import schema
from fivebar_cli.mechanisms.base import Axis, Mechanism, Space, describe_fields, description_numbers
from fivebar_cli.mechanisms.rpr2 import boxtests, kinematics
from fivebar_cli.numerics import annuli as ring
from fivebar_cli.numerics.verdict import verdict
from fivebar_cli.paving.engine import stacked


@dataclass(frozen=True)
class Rpr2(Mechanism):
    """Two prismatic legs of lengths in [rho_min, rho_max] from A1 = (0, 0) and A2 = (d, 0) to P."""

    name: str
    d: float
    rho_min: float
    rho_max: float

    kind = "rpr2"

    @classmethod
    def parse(cls, data: Mapping, source: str = "<config>") -> "Rpr2":
        schema.check_keys(data, {"name", "type", "base", "legs"}, {"name", "type", "base", "legs"}, source)
        name = schema.name_field(data, source)
        base = schema.mapping(data, "base", source)
        schema.check_keys(base, {"d"}, {"d"}, source, "base.")
        d = schema.number(base["d"], source, "base.d", positive=True)
        legs = schema.mapping(data, "legs", source)
        schema.check_keys(legs, {"rho_min", "rho_max"}, {"rho_min", "rho_max"}, source, "legs.")
        rho_min = schema.number(legs["rho_min"], source, "legs.rho_min", nonnegative=True)
        rho_max = schema.number(legs["rho_max"], source, "legs.rho_max", positive=True)
        if rho_min >= rho_max:
            raise schema.ConfigError(source, "legs", f"rho_min ({rho_min!r}) must be smaller than rho_max ({rho_max!r})")
        if 2.0 * rho_max < d:
            raise schema.ConfigError(source, "legs.rho_max", f"the legs cannot meet: 2 rho_max = {2 * rho_max!r} < d = {d!r}")
        return cls(name=name, d=d, rho_min=rho_min, rho_max=rho_max)

    @classmethod
    def from_description(cls, fields: Mapping[str, str], name: str, source: str) -> "Rpr2":
        v = description_numbers(fields, ("d", "rho_min", "rho_max"), source)
        return cls.parse({"name": name, "type": cls.kind, "base": {"d": v["d"]},
                          "legs": {"rho_min": v["rho_min"], "rho_max": v["rho_max"]}}, source)

    def describe(self) -> str:
        return describe_fields(self.kind, {"d": self.d, "rho_min": self.rho_min, "rho_max": self.rho_max})

    def spaces(self) -> dict[str, Space]:
        half, mid = self.rho_max, 0.5 * self.d
        return {
            "jointspace": Space("jointspace", "assemblable", (
                Axis("rho1", self.rho_min, self.rho_max, label=r"$\rho_1$"),
                Axis("rho2", self.rho_min, self.rho_max, label=r"$\rho_2$"),
            )),
            "workspace": Space("workspace", "reachable", (Axis("x", mid - half, mid + half), Axis("y", -half, half))),
        }

    def box_test(self, space: str, procedure: str = "exact", region: str | None = None):
        if region not in (None, self.spaces()[space].region):
            raise KeyError(region)
        tests = {"jointspace": boxtests.joint_space_test, "workspace": boxtests.workspace_test}
        return tests[space](self)

    def exact_measure(self, space: str, region: str | None = None) -> float | None:
        """Workspace: the intersection of two annuli (exact, by arcs); joint space: the part of the
        box [rho_min, rho_max]^2 between the lines |rho1 - rho2| = d and rho1 + rho2 = d."""
        if space == "workspace":
            return ring.area(boxtests.annuli(self))
        return joint_area(self.d, self.rho_min, self.rho_max)

    def aspect_model(self) -> "Rpr2Modes":
        return Rpr2Modes(self)


def joint_area(d: float, lo: float, hi: float) -> float:
    """Area of {(r1, r2) in [lo, hi]^2 : |r1 - r2| <= d <= r1 + r2}: the square minus three
    corner triangles (each the part of the square beyond one line, a right isosceles triangle)."""
    side = hi - lo

    def corner(reach: float) -> float:  # the part of the square within `reach` (L1) of a corner
        reach = min(max(reach, 0.0), 2 * side)
        if reach <= side:
            return 0.5 * reach * reach
        return side * side - 0.5 * (2 * side - reach) ** 2

    return side * side - corner(d - 2 * lo) - 2 * corner(side - d)


@dataclass(frozen=True)
class Rpr2Modes:
    """The 2-RPR's `AspectModel`: one working mode (++), assembly mode = side of the base line."""

    m: Rpr2
    working_modes = ((1, 1),)
    assembly_modes = (1, -1)
    serial_names = ("rho1", "rho2")

    @property
    def length_scale(self) -> float:
        return kinematics.scale(self.m)

    def workspace_test(self, working):
        return boxtests.working_workspace_test(self.m)

    def jointspace_test(self, assembly):
        return boxtests.assembly_joint_test(self.m)

    def workspace_tests(self, workings):
        return stacked([self.workspace_test(w) for w in workings])

    def jointspace_tests(self, assemblies):
        return stacked([self.jointspace_test(a) for a in assemblies])

    def assembly_signs(self, working, points):
        _, _, ok = kinematics.ikp(self.m, points[:, 0], points[:, 1])
        return np.where(ok, np.sign(points[:, 1]), 0).astype(np.int8)

    def working_signs(self, assembly, points):
        _, ok = kinematics.dkp(self.m, points[:, 0], points[:, 1], assembly)
        return np.where(ok[:, None], 1, 0).astype(np.int8) * np.ones((1, 2), np.int8)

    def ikp(self, points, working):
        rho1, rho2, ok = kinematics.ikp(self.m, points[:, 0], points[:, 1])
        return np.column_stack([np.where(ok, rho1, np.nan), np.where(ok, rho2, np.nan)]), ok

    def dkp(self, points, assembly):
        return kinematics.dkp(self.m, points[:, 0], points[:, 1], assembly)

    def mode_values(self, joints, poses):
        return np.column_stack(kinematics.mode_values(self.m, joints[:, 0], joints[:, 1], poses))

    def workspace_signs(self, working, lo, hi, ends=None):  # (`ends`: unused by these tests of boxes)
        status = boxtests.workspace_test(self.m)(lo, hi)
        _, eta = boxtests.margins(self.m)
        side = verdict(lo[:, 1] - eta > 0, hi[:, 1] + eta < 0)
        return status != -1, side[:, None]

    def jointspace_signs(self, assembly, lo, hi, ends=None):
        _, outside = boxtests._triangle(self.m, lo, hi, strict=False)
        return ~outside, boxtests.leg_signs(self.m, lo, hi)

    def serial_band_signs(self, assembly, lo, hi, ends=None):
        inside, _ = boxtests._triangle(self.m, lo, hi, strict=True)
        return inside, boxtests.leg_signs(self.m, lo, hi)

    def jointspace_band_signs(self, assembly, lo, hi, ends=None):
        _, outside = boxtests._triangle(self.m, lo, hi, strict=False)
        inside, _ = boxtests._triangle(self.m, lo, hi, strict=True)
        return ~outside, boxtests.leg_signs(self.m, lo, hi), inside  # the leg signs once
