"""The five-bar: A1 = (0, 0), A2 = (L0, 0), cranks L1, L2 at A1, A2, couplers L3, L4 meeting at P.

Its YAML schema (docs/formats.md), its two spaces (the joint space (th1, th2), a torus, and the
workspace (x, y)), a box test per space and procedure (`exact`: ours; `paper`: the paper's
interval procedure), the exact workspace area and the aspect model.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping, Sequence

import numpy as np

from fivebar_cli.io import schema
from fivebar_cli.mechanisms.base import Axis, Mechanism, Space, describe_fields, description_numbers
from fivebar_cli.mechanisms.fivebar import boxtests, paper
from fivebar_cli.mechanisms.fivebar.modes import FiveBarModes

LENGTHS = ("L0", "L1", "L2", "L3", "L4")


def _num(x: float) -> str:
    return f"{x:.12g}"


def assembles(lengths: Mapping[str, float] | Sequence[float]) -> str | None:
    """None when the loop closes on a set of positive area, else the violated inequality (one line).

    |B1B2| ranges over [max(0, L0 - L1 - L2, |L1 - L2| - L0), L0 + L1 + L2] (two points on
    circles of radii L1, L2 whose centres are L0 apart), and the loop closes exactly where it lies
    in [|L3 - L4|, L3 + L4]; when the two ranges only touch, the loop closes in flat, singular
    configurations only. Used by `FiveBar.parse`, and by sweeps that build designs directly.
    """
    L0, L1, L2, L3, L4 = (float(lengths[k]) for k in LENGTHS) if isinstance(lengths, Mapping) else map(float, lengths)
    far, inner, outer = L0 + L1 + L2, abs(L3 - L4), L3 + L4
    checks = (  # (left name, left value, right name, right value): the loop needs left < right
        ("|L3 - L4|", inner, "L0 + L1 + L2", far),
        ("L0", L0, "L1 + L2 + L3 + L4", L1 + L2 + outer),
        ("|L1 - L2|", abs(L1 - L2), "L0 + L3 + L4", L0 + outer),
    )
    for left, a, right, b in checks:
        if a > b:
            return f"{left} = {_num(a)} > {right} = {_num(b)}: the loop never closes"
        if a == b:
            return f"{left} = {right} = {_num(a)}: the loop closes only in flat, singular configurations"
    return None


@dataclass(frozen=True)
class FiveBar(Mechanism):
    """Five-bar with A1 = (0, 0), A2 = (L0, 0), crank lengths L1, L2 and coupler lengths L3, L4."""

    name: str
    L0: float
    L1: float
    L2: float
    L3: float
    L4: float

    kind = "fivebar"
    procedures = ("exact", "paper")

    @property
    def lengths(self) -> dict[str, float]:
        return {k: getattr(self, k) for k in LENGTHS}

    @classmethod
    def parse(cls, data: Mapping, source: str = "<config>") -> "FiveBar":
        schema.check_keys(data, {"name", "type", "lengths"}, {"name", "type", "lengths"}, source)
        name = schema.name_field(data, source)
        lengths = schema.mapping(data, "lengths", source)
        schema.check_keys(lengths, set(LENGTHS), set(LENGTHS), source, "lengths.")
        values = {k: schema.number(lengths[k], source, f"lengths.{k}", positive=True) for k in LENGTHS}
        problem = assembles(values)
        if problem is not None:
            raise schema.ConfigError(source, "lengths", problem)
        return cls(name=name, **values)

    @classmethod
    def from_description(cls, fields: Mapping[str, str], name: str, source: str) -> "FiveBar":
        lengths = description_numbers(fields, LENGTHS, source)
        return cls.parse({"name": name, "type": cls.kind, "lengths": lengths}, source)

    def describe(self) -> str:
        """One-line, round-trippable description (used in .qt headers)."""
        return describe_fields(self.kind, self.lengths)

    def spaces(self) -> dict[str, Space]:
        """Joint space: the torus [-pi, pi]^2; workspace: [-(L1+L3), L1+L3]^2, as in the paper."""
        reach = self.L1 + self.L3
        return {
            "jointspace": Space("jointspace", "assemblable", (
                Axis("theta1", -np.pi, np.pi, "rad", periodic=True, label=r"$\theta_1$"),
                Axis("theta2", -np.pi, np.pi, "rad", periodic=True, label=r"$\theta_2$"),
            )),
            "workspace": Space("workspace", "reachable", (Axis("x", -reach, reach), Axis("y", -reach, reach))),
        }

    def box_test(self, space: str, procedure: str = "exact"):
        tests = {
            ("jointspace", "exact"): boxtests.joint_space_test,
            ("workspace", "exact"): boxtests.workspace_test,
            ("jointspace", "paper"): paper.paper_joint_space_test,
            ("workspace", "paper"): paper.paper_workspace_test,
        }
        return tests[space, procedure](self)

    def exact_measure(self, space: str) -> float | None:
        """The workspace is the intersection of two annuli: its area is exact (arcs, Green)."""
        return boxtests.workspace_area(self) if space == "workspace" else None

    def printed_k_percent(self, space: str, depth: int) -> int | None:
        """The paper's Table 1, for M1 and M2 (recognised by their lengths)."""
        return paper.printed_percent(self, space, depth)

    def aspect_model(self) -> FiveBarModes:
        return FiveBarModes(self)
