"""The volumes of a paved 3-RPR workspace: certified volumes of each region and the band between
them, with the closed-form volumes where they exist (the row of `volumes.csv`)."""

from __future__ import annotations

from fivebar_cli.mechanisms.rpr3.model import MINUS, PLUS, REACHABLE, Rpr3
from fivebar_cli.paving.engine import Paving

HEADER = ("name", "depth", "evaluations", "root", "reachable", "unreachable", "undetermined", "det_positive",
          "det_negative", "singular_or_undetermined", "exact_reachable", "exact_det_positive", "exact_det_negative")


def volumes(m: Rpr3, pavings: dict[str, Paving]) -> dict:
    """One value per HEADER column (volumes in length^2 x degrees; areas for one orientation). The
    band is what is certified neither unreachable nor singularity-free of one sign; the exact
    columns are '' without a closed form."""
    reach, plus, minus = pavings[REACHABLE], pavings[PLUS], pavings[MINUS]
    root = float(reach.grid.cell_volume(0))
    band = root - reach.outside.area - plus.inside.area - minus.inside.area
    exact = [m.exact_measure("workspace", r) for r in (REACHABLE, PLUS, MINUS)]
    row = (m.name, reach.grid.depth, sum(p.evaluations for p in pavings.values()), root, reach.inside.area,
           reach.outside.area, reach.undetermined_area, plus.inside.area, minus.inside.area, band,
           *("" if e is None else e for e in exact))
    return dict(zip(HEADER, row))
