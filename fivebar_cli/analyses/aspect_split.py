"""What limits and obstacles cost: each generalized aspect of a constrained five-bar, the
unconstrained aspect it comes from (`aspects-split.csv`), and one line saying it.

A constrained aspect is a connected set of non-singular configurations of fixed modes, so it lies
in exactly one unconstrained aspect of the same modes. Its black cells passed the same mode test
as the unconstrained paving's (and the constraints' test), on the same grid, so each lies inside a
black cell of the unconstrained paving of its mode, which belongs to one unconstrained aspect:
locating the cells' centres there names it (in the workspace; in the joint space for an aspect too
thin for workspace cells). An actuated limit narrower than a turn gives the joint space another root,
so there the cells are not nested: when no centre lies in a black cell of its modes, the
unconstrained aspect whose black cells overlap its own names it (an overlap is a configuration of
both). Should two unconstrained aspects hold its cells (possible only when the unconstrained count
is not certified), the one holding most is named and the row is not certified.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from fivebar_cli.analyses.aspects import Aspect, AspectAnalysis, signs_text
from fivebar_cli.errors import FivebarError
from fivebar_cli.io.files import write_csv
from fivebar_cli.io.layout import SPLIT_CSV
from fivebar_cli.paving.tree import Tree

HEADER = (
    "constrained_aspect", "unconstrained_aspect", "working_mode", "assembly_mode", "parts",
    "workspace_area", "unconstrained_workspace_area", "workspace_kept",
    "jointspace_area", "unconstrained_jointspace_area", "jointspace_kept", "certified",
)


@dataclass(frozen=True)
class SplitRow:
    """One constrained aspect (None: an unconstrained aspect the constraints leave nothing of) and
    the unconstrained aspect it lies in; `parts`: how many constrained aspects that one holds."""

    constrained: Aspect | None
    unconstrained: Aspect
    parts: int
    certified: bool

    def cells(self) -> tuple:
        c, u = self.constrained, self.unconstrained
        ws = c.workspace.area if c is not None else 0.0
        js = c.jointspace.area if c is not None else 0.0
        return ("" if c is None else c.number, u.number, signs_text(u.working), signs_text(u.assembly), self.parts,
                ws, u.workspace.area, _share(ws, u.workspace.area), js, u.jointspace.area,
                _share(js, u.jointspace.area), "true" if self.certified else "false")


def _share(part: float, whole: float):
    return part / whole if whole > 0 else ""


def _home(a: Aspect, free: AspectAnalysis) -> tuple[Aspect | None, bool]:
    """The unconstrained aspect holding most of `a`'s cells, and whether it holds all of them: by
    the cells' centres, or, when no centre lies in a black cell of its modes, by the joint-space
    cells that overlap (`_overlapping`)."""
    same = [f for f in free.aspects if (f.working, f.assembly) == (a.working, a.assembly)]
    space = "workspace" if len(a.workspace) else "jointspace"
    centres = getattr(a, space).centres()
    hits = [int(np.count_nonzero(getattr(f, space).locate(centres) >= 0)) if len(centres) else 0 for f in same]
    total = len(centres)
    if same and max(hits) == 0:  # (a joint space cut by an actuated limit: another grid, see the docstring)
        hits, total = [_overlapping(a.jointspace, f.jointspace) for f in same], len(a.jointspace)
    if not same or max(hits) == 0:
        return None, False
    best = int(np.argmax(hits))
    return same[best], hits[best] == total


def _overlapping(a: Tree, b: Tree) -> int:
    """How many of `a`'s leaves overlap a leaf of `b` (boxes sharing an open set; on `b`'s periodic
    axes, shifted by a period either way too). Two black cells of one mode that overlap share a
    configuration, so the aspects holding them are one: the test of last resort when the cells of
    `a` and `b` are not nested, their grids' roots being different (a joint space cut by an actuated
    limit narrower than a turn, against the whole torus)."""
    if not len(a) or not len(b):
        return 0
    alo, ahi = a.bounds()
    blo, bhi = b.bounds()
    shifts = [np.zeros(b.grid.dim)]
    for axis, periodic in enumerate(b.grid.periodic):
        if periodic:
            period = np.zeros(b.grid.dim)
            period[axis] = b.grid.root[axis][1] - b.grid.root[axis][0]
            shifts = [s + k * period for s in shifts for k in (-1, 0, 1)]
    found = np.zeros(len(alo), bool)
    chunk = max(1, (1 << 22) // len(blo))  # (leaves of a) x (leaves of b) booleans at a time
    for shift in shifts:
        for k in range(0, len(alo), chunk):
            lo, hi = (alo[k:k + chunk] + shift)[:, None, :], (ahi[k:k + chunk] + shift)[:, None, :]
            found[k:k + chunk] |= np.all((blo[None] < hi) & (bhi[None] > lo), axis=2).any(axis=1)
    return int(np.count_nonzero(found))


def split_rows(constrained: AspectAnalysis, free: AspectAnalysis) -> list[SplitRow]:
    """Every constrained aspect with its unconstrained aspect, then the unconstrained aspects that
    hold none (`constrained` None)."""
    homes = [(a, *_home(a, free)) for a in constrained.aspects]
    for a, home, _ in homes:
        if home is None:  # its cells are black cells of the unconstrained pavings (module docstring)
            raise FivebarError(f"internal error: constrained aspect {a.number} lies in no unconstrained aspect")
    parts: dict[int, int] = {}
    for _, home, _ in homes:
        parts[home.number] = parts.get(home.number, 0) + 1
    rows = [SplitRow(a, home, parts[home.number], a.certified and home.certified and whole)
            for a, home, whole in homes]
    rows += [SplitRow(None, f, 0, f.certified and constrained.certified) for f in free.aspects if f.number not in parts]
    return rows


def write_split(folder: Path, rows: list[SplitRow] | None) -> list[Path]:
    """Write `aspects-split.csv`, or, for a run without constraints (None), remove one an earlier
    run left, so the folder holds one run's set."""
    path = folder / SPLIT_CSV
    if rows is None:
        path.unlink(missing_ok=True)
        return []
    return [write_csv(path, HEADER, [r.cells() for r in rows])]


def cost_text(rows: list[SplitRow], free: AspectAnalysis) -> str:
    """One line: how the unconstrained aspects fare and the share of their workspace area kept."""
    per = {f.number: sum(1 for r in rows if r.constrained is not None and r.unconstrained.number == f.number)
           for f in free.aspects}
    split = [n for n in per.values() if n > 1]
    whole = sum(1 for n in per.values() if n == 1)
    lost = sum(1 for n in per.values() if n == 0)
    kept = sum(r.constrained.workspace.area for r in rows if r.constrained is not None)
    total = sum(f.workspace.area for f in free.aspects)
    share = f"; {kept / total:.0%} of their workspace area kept" if total > 0 else ""
    parts = f" (into {', '.join(map(str, split))} parts)" if split else ""
    return (f"constraints: the {len(free.aspects)} unconstrained aspects give {sum(per.values())}: "
            f"{len(split)} split{parts}, {whole} whole (shrunk or not), {lost} lost{share}")
