"""The paper's Table 1 for any mechanism: evaluation counts K = n / 2^(dim d) of the paving against
the dense discretization, with our exact tests and, where the kind has one, the paper's procedure.

For the five-bar, the paper's printed whole percents are its procedure's K rounded to one decimal
with the decimal then dropped (8.97% -> "9", 25.91% -> "25"): `printed_form` reproduces all 24 of
them from our counts of the paper's procedure. The table compares quadtrees: spaces of other
dimensions (a 3-RPR's (x, y, phi) octree) are left out (`planar_spaces`).
"""

from __future__ import annotations

import math

from fivebar_cli.analyses.spaces import k_ratio, pave_space
from fivebar_cli.mechanisms.base import Mechanism

HEADER = (
    "space", "mechanism", "depth", "discretization", "evaluations", "K",
    "paper_procedure_evaluations", "paper_procedure_K", "paper_procedure_percent",
    "paper_printed_percent", "saving_vs_paper",
)


def printed_form(k: float) -> int:
    """How the five-bar paper prints a ratio: percent to one decimal, decimal dropped."""
    return math.floor(round(100.0 * k, 1))


def planar_spaces(m: Mechanism) -> list[str]:
    """The spaces of `m` that are paved by quadtrees (the ones the table compares)."""
    return [name for name, s in m.spaces().items() if s.dim == 2]


def row_count(mechanisms: list[Mechanism], depths: list[int]) -> int:
    """How many rows (and progress steps) `kratio_rows` makes."""
    return sum(len(planar_spaces(m)) for m in mechanisms) * len(depths)


def kratio_rows(mechanisms: list[Mechanism], depths: list[int], advance=lambda n=1: None) -> list[dict]:
    """One row per (space, mechanism, depth), spaces in the order the kinds declare them."""
    spaces = list(dict.fromkeys(s for m in mechanisms for s in planar_spaces(m)))
    rows = []
    for space in spaces:
        for m in mechanisms:
            if space not in planar_spaces(m):
                continue
            dim = m.spaces()[space].dim
            for depth in depths:
                ours = pave_space(m, space, depth, "exact").evaluations
                row = {"space": space, "mechanism": m.name, "depth": depth, "discretization": 2 ** (dim * depth),
                       "evaluations": ours, "K": k_ratio(ours, dim, depth)}
                row.update(_paper_columns(m, space, depth, ours))
                advance(1)
                rows.append(row)
    return rows


def _paper_columns(m: Mechanism, space: str, depth: int, ours: int) -> dict:
    """The paper's procedure's count, its K as printed, the printed K and our saving ('' if none)."""
    if "paper" not in m.procedures:
        return {k: "" for k in HEADER[6:]}
    paper = pave_space(m, space, depth, "paper").evaluations
    dim = m.spaces()[space].dim
    printed = m.printed_k_percent(space, depth)
    return {
        "paper_procedure_evaluations": paper, "paper_procedure_K": k_ratio(paper, dim, depth),
        "paper_procedure_percent": printed_form(k_ratio(paper, dim, depth)),
        "paper_printed_percent": "" if printed is None else printed,
        "saving_vs_paper": 1.0 - ours / paper,
    }
