"""The five-bar: A1 = (0, 0), A2 = (L0, 0), cranks L1, L2 at A1, A2, couplers L3, L4 meeting at P.

Its YAML schema (docs/formats.md), its two spaces (the joint space (th1, th2), a torus, and the
workspace (x, y)), a box test per space and procedure (`exact`: ours; `paper`: the paper's
interval procedure), the exact workspace area and the aspect model.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Mapping, Sequence

import numpy as np

from fivebar_cli.errors import param
from fivebar_cli.io import schema
from fivebar_cli.mechanisms.base import Axis, Mechanism, Space, describe_fields
from fivebar_cli.mechanisms.fivebar import boxtests, constraints
from fivebar_cli.mechanisms.fivebar.constraints import NO_CONSTRAINTS, Constraints
from fivebar_cli.mechanisms.fivebar.modes import FiveBarModes

# the tests of interval lengths (robust, robust_modes), of limits and obstacles (constrained) and
# the paper's procedure (paper) are imported where a five-bar needs them: not by every analysis

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
    """Five-bar with A1 = (0, 0), A2 = (L0, 0), crank lengths L1, L2 and coupler lengths L3, L4.

    Lengths may be intervals (manufacturing tolerances): `bounds` then holds (lo, hi) per length
    and L0 .. L4 are the nominal lengths, the midpoints. Box tests are then robust (1: valid for
    every length vector) or impossible (-1: for none); a zero-width interval is a plain length.
    """

    name: str
    L0: float
    L1: float
    L2: float
    L3: float
    L4: float
    bounds: tuple[tuple[float, float], ...] | None = None
    constraints: Constraints = NO_CONSTRAINTS  # joint limits and obstacles (constraints.py)

    kind = "fivebar"

    @property
    def procedures(self) -> tuple[str, ...]:
        """`exact`, and the paper's procedure, which knows no joint limits or obstacles."""
        return ("exact",) if self.constraints else ("exact", "paper")

    def __post_init__(self) -> None:
        if self.bounds is None:
            object.__setattr__(self, "bounds", tuple((v, v) for v in self.lengths.values()))
        super().__post_init__()  # validated as a YAML file is (Mechanism.check_model)

    @property
    def lengths(self) -> dict[str, float]:
        return {k: getattr(self, k) for k in LENGTHS}

    widens = True  # Mechanism's capability: interval lengths (`widened`)
    crosses_serial = True  # Mechanism's capability: motions across serial singularities

    @property
    def is_interval(self) -> bool:
        """Whether some length is an interval of positive width."""
        return any(lo < hi for lo, hi in self.bounds)

    def nominal(self) -> "FiveBar":
        """The same five-bar with its nominal lengths."""
        return replace(self, bounds=None)

    def unconstrained(self) -> "FiveBar":
        """The same five-bar without its limits and obstacles."""
        return replace(self, constraints=NO_CONSTRAINTS)

    @classmethod
    def with_bounds(cls, name: str, bounds, constraints: Constraints = NO_CONSTRAINTS) -> "FiveBar":
        """A five-bar from (lo, hi) per length; nominal lengths are the midpoints."""
        mids = [lo if lo == hi else 0.5 * (lo + hi) for lo, hi in bounds]
        return cls(name, *mids, bounds=tuple((float(lo), float(hi)) for lo, hi in bounds), constraints=constraints)

    def widened(self, tolerance: float, source: str = param("tolerance")) -> "FiveBar":
        """Every length widened by `tolerance` on both sides (ConfigError when a length would reach 0)."""
        if not (math.isfinite(tolerance) and tolerance >= 0):
            raise schema.ConfigError(source, param("tolerance"), f"must be a finite number >= 0, got {tolerance!r}")
        if tolerance == 0:
            return self
        for key, (lo, _) in zip(LENGTHS, self.bounds):
            if lo - tolerance <= 0:
                raise schema.ConfigError(source, param("tolerance"), f"{tolerance!r} would make {key} reach "
                                         f"{lo - tolerance!r}: lengths must stay positive")
        return FiveBar.with_bounds(self.name, [(lo - tolerance, hi + tolerance) for lo, hi in self.bounds],
                                   self.constraints)

    @classmethod
    def parse(cls, data: Mapping, source: str = "<config>", check_empty: bool = True) -> "FiveBar":
        """Lengths are positive numbers or intervals `[lo, hi]` with 0 < lo <= hi; the (nominal)
        five-bar must close on a set of positive area (`assembles`), else a ConfigError. Optional
        `limits`, `obstacles`, `clearance` (constraints.py) must keep clear of A1 and A2 and, with
        `check_empty`, not be certified to leave nothing (a small paving: `.qt` headers, which
        describe a mechanism a run already took, skip it)."""
        schema.check_keys(data, {"name", "type", "lengths", *constraints.KEYS}, {"name", "type", "lengths"}, source)
        name = schema.name_field(data, source)
        lengths = schema.mapping(data, "lengths", source)
        schema.check_keys(lengths, set(LENGTHS), set(LENGTHS), source, "lengths.")
        bounds = [_length(lengths[k], source, f"lengths.{k}") for k in LENGTHS]
        m = cls(name, *(lo for lo, _ in bounds)) if all(lo == hi for lo, hi in bounds) else cls.with_bounds(name, bounds)
        problem = assembles(m.lengths)  # interval lengths: the nominal five-bar must close
        if problem is not None:
            nominal = "nominal lengths: " if m.is_interval else ""
            raise schema.ConfigError(source, "lengths", nominal + problem)
        limits = constraints.parse(data, source)
        if limits:
            m = replace(m, constraints=limits)
            problem = constraints.base_problem(limits, (m.L0, 0.0))
            if problem is None and check_empty:
                from fivebar_cli.mechanisms.fivebar import constrained

                problem = constrained.empty_problem(m)
            if problem is not None:
                raise schema.ConfigError(source, *problem)
        elif "clearance" in data:
            m = replace(m, constraints=limits)
        return m

    @classmethod
    def from_description(cls, fields: Mapping[str, str], name: str, source: str) -> "FiveBar":
        data = constraints.description_data({k: v for k, v in fields.items() if k not in LENGTHS}, source)
        lengths = {}
        for key in LENGTHS:
            if key not in fields:
                raise schema.ConfigError(source, "mechanism", f"missing {key}= in the mechanism description")
            text = fields[key]
            try:
                if text.startswith("[") and text.endswith("]"):
                    lengths[key] = [float(v) for v in text[1:-1].split(",")]
                else:
                    lengths[key] = float(text)
            except ValueError:
                raise schema.ConfigError(source, "mechanism", f"bad value {key}={text!r}") from None
        return cls.parse({"name": name, "type": cls.kind, "lengths": lengths, **data}, source, check_empty=False)

    def describe(self) -> str:
        """One-line, round-trippable description (used in .qt headers): lengths as `L0=9.0`, or
        `L0=[8.95,9.05]` for an interval."""
        if not self.is_interval:
            return describe_fields(self.kind, self.lengths) + self.constraints.words()
        return self.kind + "".join(f" {k}={lo!r}" if lo == hi else f" {k}=[{lo!r},{hi!r}]"
                                   for k, (lo, hi) in zip(LENGTHS, self.bounds)) + self.constraints.words()

    def spaces(self) -> dict[str, Space]:
        """Joint space: the torus [-pi, pi]^2; workspace: [-(L1+L3), L1+L3]^2, as in the paper (with
        interval lengths the largest L1 + L3, so that the root holds every possible point). An
        actuated limit of less than a turn makes its axis that interval (rounded inward), not periodic."""
        reach = self.bounds[1][1] + self.bounds[3][1]
        return {
            "jointspace": Space("jointspace", "assemblable", (
                self._joint_axis("theta1", r"$\theta_1$"), self._joint_axis("theta2", r"$\theta_2$"))),
            "workspace": Space("workspace", "reachable", (Axis("x", -reach, reach), Axis("y", -reach, reach))),
        }

    def _joint_axis(self, name: str, label: str) -> Axis:
        limit = self.constraints.limit(name)
        if limit is None or limit.full_turn:
            return Axis(name, -np.pi, np.pi, "rad", periodic=True, label=label)
        lo, hi = limit.radians  # within 2 ulp of the true angles: 4 ulp inward holds only allowed angles
        return Axis(name, lo + 4 * abs(float(np.spacing(lo))), hi - 4 * abs(float(np.spacing(hi))), "rad", label=label)

    def box_test(self, space: str, procedure: str = "exact", region: str | None = None):
        if region not in (None, self.spaces()[space].region):
            raise KeyError(region)
        if self.constraints:
            if procedure != "exact":
                raise schema.ConfigError(self.name, param("procedure"), "the paper's procedure has no joint limits or "
                                         "obstacles (use " + param("procedure", "exact") + ")")
            from fivebar_cli.mechanisms.fivebar import constrained

            return constrained.space_test(self, space, self.unconstrained().box_test(space))
        if self.is_interval:
            if procedure != "exact":
                raise schema.ConfigError(self.name, param("procedure"), "the paper's procedure has no interval version")
            from fivebar_cli.mechanisms.fivebar import robust

            return {"jointspace": robust.joint_space_test, "workspace": robust.workspace_test}[space](self)
        from fivebar_cli.mechanisms.fivebar import paper

        tests = {
            ("jointspace", "exact"): boxtests.joint_space_test,
            ("workspace", "exact"): boxtests.workspace_test,
            ("jointspace", "paper"): paper.paper_joint_space_test,
            ("workspace", "paper"): paper.paper_workspace_test,
        }
        return tests[space, procedure](self)

    def exact_measure(self, space: str, region: str | None = None) -> float | None:
        """The workspace is the intersection of two annuli: its area is exact (arcs, Green); with
        interval lengths, that of the nominal five-bar. No closed form is known for the joint space
        (`jointspace_area` integrates one numerically)."""
        if self.constraints:
            return None
        return boxtests.workspace_area(self) if space == "workspace" and region is None else None

    def printed_k_percent(self, space: str, depth: int) -> int | None:
        """The paper's Table 1, for M1 and M2 (recognised by their lengths)."""
        from fivebar_cli.mechanisms.fivebar import paper

        return None if self.constraints else paper.printed_percent(self, space, depth)

    def aspect_model(self) -> FiveBarModes:
        """Working and assembly modes; with interval lengths the aspects are robust (their cells
        are non-singular with their modes for every length vector), matched through the nominal
        kinematics."""
        if self.is_interval:
            from fivebar_cli.mechanisms.fivebar.robust_modes import RobustFiveBarModes

            base = RobustFiveBarModes(self)
        else:
            base = FiveBarModes(self)
        if not self.constraints:
            return base
        from fivebar_cli.mechanisms.fivebar import constrained

        return constrained.ConstrainedModes(self, base)

    def violated_constraints(self, joints, poses) -> list[list[str]]:
        """Per configuration (joint values and poses, (n, 2) each), the constraints it violates."""
        return constraints.violated_labels(self, joints, poses)

    def marks(self, space: str) -> list[dict]:
        """Obstacles (workspace) and actuated limits (joint space) for figures and `fivebar view`."""
        return constraints.marks(self.constraints, space)


def _length(value, source: str, field: str) -> tuple[float, float]:
    """A length: a positive number, or `[lo, hi]` with 0 < lo <= hi."""
    if isinstance(value, list):
        if len(value) != 2:
            raise schema.ConfigError(source, field, f"expected a number or an interval [lo, hi], got {schema.short(value)}")
        lo = schema.number(value[0], source, f"{field}[0]", positive=True)
        hi = schema.number(value[1], source, f"{field}[1]", positive=True)
        if lo > hi:
            raise schema.ConfigError(source, field, f"the interval [{lo!r}, {hi!r}] has lo > hi")
        return lo, hi
    v = schema.number(value, source, field, positive=True)
    return v, v
