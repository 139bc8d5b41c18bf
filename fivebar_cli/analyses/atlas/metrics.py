"""The metrics of one five-bar design: one row of `atlas.csv`, a pure function of its lengths.

Every metric is one `Metric` in `METRICS`: a column name, a function of the `Design` (which
computes the aspect analysis once, on first use, and shares it), and the value written for a
design that cannot be assembled (whose analysis is skipped). Adding a metric is one line there;
`robust=True` marks one of every length widened by the tolerance (a column only when it is > 0).
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from functools import cached_property
from typing import Callable

from fivebar_cli.analyses.aspects import AspectAnalysis, analyse_aspects
from fivebar_cli.analyses.spaces import pave_space
from fivebar_cli.mechanisms.fivebar.constraints import NO_CONSTRAINTS, Constraints
from fivebar_cli.mechanisms.fivebar.model import LENGTHS, FiveBar

TRUE, FALSE = "true", "false"


def assemblable(L0: float, L1: float, L2: float, L3: float, L4: float) -> bool:
    """Whether the loop closes for some joint angles, in closed form and exactly (in rationals).

    |B1B2| takes every value of [max(0, L0 - L1 - L2, |L1 - L2| - L0), L0 + L1 + L2]; the couplers
    close the loop when it lies in [|L3 - L4|, L3 + L4]. The two intervals must meet.
    """
    L0, L1, L2, L3, L4 = (Fraction(v) for v in (L0, L1, L2, L3, L4))
    near, far = max(Fraction(0), L0 - L1 - L2, abs(L1 - L2) - L0), L0 + L1 + L2
    return near <= L3 + L4 and abs(L3 - L4) <= far


@dataclass
class Design:
    """One design: its lengths, the depth of its analyses, its tolerance (0: exact lengths)."""

    lengths: tuple[float, ...]
    depth: int
    tolerance: float = 0.0
    constraints: Constraints = NO_CONSTRAINTS  # the spec's limits and obstacles

    @cached_property
    def mechanism(self) -> FiveBar:
        return FiveBar("design", *self.lengths, constraints=self.constraints)

    @cached_property
    def analysis(self) -> AspectAnalysis:
        """The generalized aspects, as `fivebar aspects` computes them (default budget)."""
        return analyse_aspects(self.mechanism, self.depth)

    @cached_property
    def widened(self) -> FiveBar:
        """Every length widened to [L - T, L + T] (as `--tolerance T`)."""
        return self.mechanism.widened(self.tolerance)

    @cached_property
    def robust(self) -> AspectAnalysis:
        """The robust aspects, as `fivebar aspects --tolerance T` computes them."""
        return analyse_aspects(self.widened, self.depth)


@dataclass(frozen=True)
class Metric:
    name: str
    compute: Callable[[Design], object]  # a CSV cell: int, float or text
    unassemblable: object = ""  # the cell of a design that cannot be assembled
    robust: bool = False  # of the lengths widened by the tolerance: a column only when it is > 0


def _flag(value: bool) -> str:
    return TRUE if value else FALSE


def _largest(analysis: AspectAnalysis) -> float:
    return max((a.workspace.area for a in analysis.aspects), default=0.0)


def _circle_r(analysis: AspectAnalysis) -> float:
    """The radius of the largest certified disc inside one aspect's workspace (`circle_r` of
    `aspects.csv`, largest over the aspects); 0 when no aspect has workspace cells."""
    return max((a.circle.r for a in analysis.aspects if a.circle is not None), default=0.0)


def _workspace_area(d: Design) -> float:
    """The exact workspace area; with limits or obstacles (no closed form) the certified area
    (`inside_area` of `fivebar workspace`)."""
    exact = d.mechanism.exact_measure("workspace")
    return exact if exact is not None else pave_space(d.mechanism, "workspace", d.depth).inside.area


def _robust_workspace_area(d: Design) -> float:
    """The certified robust workspace area (`inside_area` of `fivebar workspace --tolerance T`)."""
    return pave_space(d.widened, "workspace", d.depth).inside.area


# A design that cannot be assembled has no robust configuration either (its nominal lengths lie in
# the length box): 0 robust aspects, certified by the closed form, robust area 0.
METRICS: tuple[Metric, ...] = (
    Metric("assemblable", lambda d: TRUE, FALSE),
    Metric("aspects", lambda d: len(d.analysis.aspects), 0),
    Metric("certified", lambda d: _flag(d.analysis.certified), TRUE),
    Metric("workspace_area", _workspace_area, 0.0),
    Metric("largest_aspect_area", lambda d: _largest(d.analysis), 0.0),
    Metric("circle_r", lambda d: _circle_r(d.analysis), 0.0),
    Metric("robust_aspects", lambda d: len(d.robust.aspects), 0, robust=True),
    Metric("robust_certified", lambda d: _flag(d.robust.certified), TRUE, robust=True),
    Metric("robust_workspace_area", _robust_workspace_area, 0.0, robust=True),
    Metric("robust_largest_aspect_area", lambda d: _largest(d.robust), 0.0, robust=True),
    Metric("robust_circle_r", lambda d: _circle_r(d.robust), 0.0, robust=True),
)


def metrics(tolerance: float = 0.0) -> tuple[Metric, ...]:
    """The metrics computed at this tolerance, in column order."""
    return tuple(m for m in METRICS if tolerance > 0 or not m.robust)


def columns(tolerance: float = 0.0) -> tuple[str, ...]:
    """The header of `atlas.csv`: the five lengths, then the metrics."""
    return (*LENGTHS, *(m.name for m in metrics(tolerance)))


def row(lengths: tuple[float, ...], depth: int, tolerance: float = 0.0,
        constraints: Constraints = NO_CONSTRAINTS) -> tuple:
    """One row of `atlas.csv`: the lengths, then every metric of the design (with the constraints)."""
    chosen = metrics(tolerance)
    if not assemblable(*lengths):
        return (*lengths, *(m.unassemblable for m in chosen))
    design = Design(tuple(lengths), depth, tolerance, constraints)
    return (*lengths, *(m.compute(design) for m in chosen))
