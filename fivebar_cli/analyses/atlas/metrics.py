"""The metrics of one five-bar design: one row of `atlas.csv`, a pure function of its lengths.

Every metric is one `Metric` in `METRICS`: a column name, a function of the `Design` (which
computes the aspect analysis once, on first use, and shares it), and the value written for a
design that cannot be assembled (whose analysis is skipped). Adding a metric is one line there;
`robust=True` marks one that needs interval lengths (computed only when the tolerance is > 0).
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from functools import cached_property
from typing import Callable

from fivebar_cli.analyses.aspects import AspectAnalysis, analyse_aspects
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

    @cached_property
    def mechanism(self) -> FiveBar:
        return FiveBar("design", *self.lengths)

    @cached_property
    def analysis(self) -> AspectAnalysis:
        """The generalized aspects, as `fivebar aspects` computes them (default budget)."""
        return analyse_aspects(self.mechanism, self.depth)


@dataclass(frozen=True)
class Metric:
    name: str
    compute: Callable[[Design], object]  # a CSV cell: int, float or text
    unassemblable: object = ""  # the cell of a design that cannot be assembled
    robust: bool = False  # needs interval lengths: a column only when the tolerance is > 0


def _flag(value: bool) -> str:
    return TRUE if value else FALSE


def _largest_aspect_area(d: Design) -> float:
    return max((a.workspace.area for a in d.analysis.aspects), default=0.0)


METRICS: tuple[Metric, ...] = (
    Metric("assemblable", lambda d: TRUE, FALSE),
    Metric("aspects", lambda d: len(d.analysis.aspects), 0),
    Metric("certified", lambda d: _flag(d.analysis.certified), TRUE),
    Metric("workspace_area", lambda d: d.mechanism.exact_measure("workspace"), 0.0),
    Metric("largest_aspect_area", _largest_aspect_area, 0.0),
)


def metrics(tolerance: float = 0.0) -> tuple[Metric, ...]:
    """The metrics computed at this tolerance, in column order."""
    return tuple(m for m in METRICS if tolerance > 0 or not m.robust)


def columns(tolerance: float = 0.0) -> tuple[str, ...]:
    """The header of `atlas.csv`: the five lengths, then the metrics."""
    return (*LENGTHS, *(m.name for m in metrics(tolerance)))


def row(lengths: tuple[float, ...], depth: int, tolerance: float = 0.0) -> tuple:
    """One row of `atlas.csv`: the lengths, then every metric of the design."""
    chosen = metrics(tolerance)
    if not assemblable(*lengths):
        return (*lengths, *(m.unassemblable for m in chosen))
    design = Design(tuple(lengths), depth, tolerance)
    return (*lengths, *(m.compute(design) for m in chosen))
