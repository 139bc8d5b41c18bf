"""The paper's Table 1: evaluation counts K = n / 4^d of the quadtree against discretization.

For each space, mechanism and depth: our tight tests, the paper's own procedure, and the value
printed in the paper. The printed whole percents are the paper procedure's K rounded to one
decimal with the decimal then dropped (8.97% -> "9", 25.91% -> "25"): `printed_form` reproduces
all 24 of them from our counts of the paper's procedure.
"""

from __future__ import annotations

import math

from fivebar_cli.config import FiveBar
from fivebar_cli.spaces import pave_space

PAPER_DEPTHS = (5, 6, 7, 8, 9, 10)
M1_LENGTHS = (9.0, 8.0, 5.0, 5.0, 8.0)
M2_LENGTHS = (2.55, 2.3, 2.3, 2.3, 2.3)
PAPER_TABLE1 = {  # Chablat (2010), Table 1, in percent, depths 5..10
    ("jointspace", M1_LENGTHS): (99, 73, 40, 22, 13, 9),
    ("jointspace", M2_LENGTHS): (111, 83, 40, 18, 8, 4),
    ("workspace", M1_LENGTHS): (72, 45, 25, 13, 7, 3),
    ("workspace", M2_LENGTHS): (65, 37, 19, 10, 5, 2),
}
HEADER = (
    "space", "mechanism", "depth", "discretization", "evaluations", "K",
    "paper_procedure_evaluations", "paper_procedure_K", "paper_procedure_percent",
    "paper_printed_percent", "saving_vs_paper",
)


def printed_form(k: float) -> int:
    """How the paper prints a ratio: percent to one decimal, decimal dropped."""
    return math.floor(round(100.0 * k, 1))


def printed_percent(m: FiveBar, space: str, depth: int) -> int | None:
    """The paper's printed K (percent) for this mechanism (recognised by its lengths), if any."""
    key = (space, tuple(m.lengths.values()))
    if key in PAPER_TABLE1 and depth in PAPER_DEPTHS:
        return PAPER_TABLE1[key][PAPER_DEPTHS.index(depth)]
    return None


def kratio_rows(mechanisms: list[FiveBar], depths: list[int], advance=lambda n=1: None) -> list[dict]:
    """One row per (space, mechanism, depth), in that order."""
    rows = []
    for space in ("jointspace", "workspace"):
        for m in mechanisms:
            for depth in depths:
                ours = pave_space(m, space, depth, "exact").evaluations
                paper = pave_space(m, space, depth, "paper").evaluations
                advance(1)
                grid_n = 4**depth
                printed = printed_percent(m, space, depth)
                rows.append({
                    "space": space, "mechanism": m.name, "depth": depth, "discretization": grid_n,
                    "evaluations": ours, "K": ours / grid_n,
                    "paper_procedure_evaluations": paper, "paper_procedure_K": paper / grid_n,
                    "paper_procedure_percent": printed_form(paper / grid_n),
                    "paper_printed_percent": "" if printed is None else printed,
                    "saving_vs_paper": 1.0 - ours / paper,
                })
    return rows
