"""Manufacturing tolerances: what every robot built within tolerance reaches, and how the nominal
aspects fare (the sensitivity study the five-bar paper leaves as future work).

With every link length widened to [L - T, L + T], a cell is *robust* when every point of it is
valid for every length vector and *impossible* when valid for none (mechanisms/fivebar/robust.py).
The study reports, per tolerance, the robust and the possible (root minus impossible) areas of the
workspace and of the joint space beside the nominal ones, and for every nominal aspect the area of
the robust aspects it still holds.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fivebar_cli.analyses.aspects import AspectAnalysis, analyse_aspects
from fivebar_cli.analyses.jobs import run_tasks
from fivebar_cli.mechanisms.base import Mechanism
from fivebar_cli.paving.engine import pave

HEADER = ("tolerance", "region", "robust_area", "possible_area", "nominal_area")
QUADRATURE = 1 << 20  # points of the joint-space area quadrature


@dataclass(frozen=True)
class Fate:
    """What a tolerance does to nominal aspect `number`: `robust` lists the robust aspects inside it."""

    number: int
    robust: tuple[int, ...]
    nominal_area: float
    robust_area: float

    @property
    def verdict(self) -> str:
        if not self.robust:
            return "vanishes"
        if len(self.robust) > 1:
            return "splits"
        return "shrinks" if self.robust_area < self.nominal_area else "keeps its area"


def aspect_fates(nominal: AspectAnalysis, robust: AspectAnalysis) -> list[Fate]:
    """For each nominal aspect, the robust aspects of the same modes whose cells lie in it (their
    cells are non-singular with these modes for the nominal lengths too, so each robust aspect lies
    in exactly one nominal aspect; located here by the shared workspace or joint-space cells)."""
    fates = []
    for a in nominal.aspects:
        inside = []
        for r in robust.aspects:
            if (r.working, r.assembly) != (a.working, a.assembly):
                continue
            if _meets(r.workspace, a.workspace) or _meets(r.jointspace, a.jointspace):
                inside.append(r)
        fates.append(Fate(a.number, tuple(r.number for r in inside), a.workspace.area,
                          float(sum(r.workspace.area for r in inside))))
    return fates


def fate_text(f: Fate) -> str:
    """'vanishes', 'splits into robust aspects 3, 4', 'shrinks to 86%' or 'keeps its area'."""
    if f.verdict == "vanishes":
        return "vanishes (no robust cell at this depth)"
    if f.verdict == "splits":
        return f"splits into robust aspects {', '.join(map(str, f.robust))}"
    if f.verdict == "shrinks":
        return f"shrinks to {f.robust_area / f.nominal_area:.0%} (robust aspect {f.robust[0]})"
    return f.verdict


def _meets(cells, tree) -> bool:
    """Whether a cell centre of `cells` lies in `tree` (the trees may have different root boxes)."""
    return bool(len(cells) and len(tree) and np.any(tree.locate(cells.centres()) >= 0))


def _pave_task(task: tuple):
    m, grid, space = task
    return pave(grid, m.box_test(space))


def jointspace_area(m, n: int = QUADRATURE) -> float:
    """The nominal joint-space area: for each th1 the measure of {th2 : |L3 - L4| <= |B1B2| <= L3 + L4}
    in closed form (|B1B2|^2 = c + R cos(th2 - phi)), integrated over th1 by the midpoint rule on n
    points (the integrand is periodic; its kinks make the error about n^-1.5 relative)."""
    th1 = (np.arange(n) + 0.5) / n * 2 * np.pi - np.pi
    wx, wy = m.L0 - m.L1 * np.cos(th1), -m.L1 * np.sin(th1)
    w = np.hypot(wx, wy)
    c, r = w * w + m.L2**2, 2 * m.L2 * w
    with np.errstate(divide="ignore", invalid="ignore"):
        a = np.where(r > 0, ((m.L3 - m.L4) ** 2 - c) / r, -np.inf)
        b = np.where(r > 0, ((m.L3 + m.L4) ** 2 - c) / r, np.inf)
    measure = 2 * np.arccos(np.clip(a, -1, 1)) - 2 * np.arccos(np.clip(b, -1, 1))
    return float(np.mean(measure) * 2 * np.pi)


@dataclass(frozen=True)
class StudyRow:
    tolerance: float
    region: str
    robust_area: float
    possible_area: float | None
    nominal_area: float

    def cells(self) -> tuple:
        return (self.tolerance, self.region, self.robust_area,
                "" if self.possible_area is None else self.possible_area, self.nominal_area)


@dataclass(frozen=True)
class Study:
    """The sensitivity study: rows of `tolerance.csv`, the robust pavings, the fates of the aspects."""

    mechanism: Mechanism
    depth: int
    rows: list[StudyRow]
    pavings: dict  # (tolerance, space) -> Paving
    fates: dict  # tolerance -> list[Fate]
    nominal: AspectAnalysis
    robust: dict  # tolerance -> AspectAnalysis of the robust aspects


def tolerance_study(m: Mechanism, tolerances: list[float], depth: int, advance=lambda n=1: None,
                    jobs: int | None = 1) -> Study:
    """Robust and possible areas of both spaces and the robust area of every nominal aspect, for
    each tolerance (0: the nominal five-bar). Every tolerance is paved on the root box of the
    largest one (which holds every possible point), so the trees compare cell for cell. The
    pavings of the spaces, then those of each aspect analysis, run on `jobs` processes."""
    base = m.nominal()
    widest = base.widened(max(tolerances))
    nominal_areas = {"workspace": base.exact_measure("workspace"), "jointspace": jointspace_area(base)}
    if base.constraints:  # no closed form under limits and obstacles: the certified area
        nominal_areas = {s: pave(widest.spaces()[s].grid(depth), base.box_test(s)).inside.area for s in nominal_areas}
    spaces = ("workspace", "jointspace")
    tasks = [(base.widened(tol), widest.spaces()[space].grid(depth), space) for tol in tolerances for space in spaces]
    space_pavings = iter(run_tasks(_pave_task, tasks, jobs))
    nominal = analyse_aspects(base, depth, shapes=False, jobs=jobs)  # the study writes areas, not shapes
    rows, pavings, fates, analyses = [], {}, {}, {}
    for tol in tolerances:
        mt = base.widened(tol)
        for space in spaces:
            paving = next(space_pavings)
            pavings[tol, space] = paving
            possible = float(paving.grid.size.prod()) - paving.outside.area
            rows.append(StudyRow(tol, space, paving.inside.area, possible, nominal_areas[space]))
            advance(1)
        analyses[tol] = robust = nominal if tol == 0 else analyse_aspects(mt, depth, shapes=False, jobs=jobs)
        fates[tol] = aspect_fates(nominal, robust)
        rows += [StudyRow(tol, f"aspect-{f.number:02d}", f.robust_area, None, f.nominal_area) for f in fates[tol]]
        advance(1)
    return Study(base, depth, rows, pavings, fates, nominal, analyses)
