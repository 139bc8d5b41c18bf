"""Two trees compared as sets and as claims: what `fivebar diff` reports.

Equal sets of cells are not equal trees when the headers say the cells mean different things: a
tree and its complement, the same cells for two mechanisms, spaces or regions (`MEANING`).
"""

from __future__ import annotations

from dataclasses import dataclass

from fivebar_cli.errors import param
from fivebar_cli.io.qtfile import QtFile
from fivebar_cli.mechanisms.base import plural
from fivebar_cli.paving.tree import Tree

MEANING = ("colour", "mechanism", "space", "region")  # header keys that say what a black cell claims


@dataclass(frozen=True)
class TreeDiff:
    """The cells only in A, only in B, and the header keys whose values differ."""

    a: Tree
    b: Tree
    only_a: Tree
    only_b: Tree
    headers: tuple[tuple[str, str, str], ...]  # (key, value in A, value in B)

    @property
    def equal(self) -> bool:
        """The same set of cells."""
        return len(self.only_a) == 0 and len(self.only_b) == 0

    @property
    def meaning(self) -> tuple[tuple[str, str, str], ...]:
        """The differing headers that change what a black cell claims (`MEANING`)."""
        return tuple(h for h in self.headers if h[0] in MEANING)

    def same(self, sets_only: bool = False) -> bool:
        """Equal sets, and (unless `sets_only`) the same claim about them."""
        return self.equal and (sets_only or not self.meaning)

    def report(self, name_a: str, name_b: str, sets_only: bool = False) -> list[str]:
        """The lines `fivebar diff` prints."""
        if self.equal:
            lines = [f"same set: {plural(len(self.a), 'cell')}, area {self.a.area:.10g}"]
            if self.meaning and not sets_only:
                keys = ", ".join(k for k, _, _ in self.meaning)
                lines.append(f"but the trees do not claim the same thing: their {keys} differ "
                             "(" + param("sets_only", True) + " compares the cells alone)")
        else:
            lines = [
                f"{name_a}: {plural(len(self.a), 'cell')}, area {self.a.area:.10g}",
                f"{name_b}: {plural(len(self.b), 'cell')}, area {self.b.area:.10g}",
                f"only in A: {plural(len(self.only_a), 'cell')}, area {self.only_a.area:.10g}",
                f"only in B: {plural(len(self.only_b), 'cell')}, area {self.only_b.area:.10g}",
            ]
            for label, t in (("A", self.only_a), ("B", self.only_b)):
                if len(t):
                    lo, hi = t.bounds()
                    box = " x ".join(f"[{l:.6g}, {h:.6g}]" for l, h in zip(lo.min(0), hi.max(0)))
                    lines.append(f"  only in {label} lies within {box}")
        return lines + [f"header {k}: {va!r} vs {vb!r}" for k, va, vb in self.headers]


def compare(a: QtFile, b: QtFile) -> TreeDiff:
    """Compare two trees on the same root box (any depths: the finer grid is used).

    Raises ValueError when the root boxes or periodic axes differ."""
    ga, gb = a.tree.grid, b.tree.grid
    if ga.root != gb.root or ga.periodic != gb.periodic:
        raise ValueError(f"root box or periodic axes differ: {ga.root} vs {gb.root}")
    headers = tuple((k, a.get(k), b.get(k)) for k in sorted(set(a.fields) | set(b.fields)) if a.get(k) != b.get(k))
    return TreeDiff(a.tree, b.tree, a.tree - b.tree, b.tree - a.tree, headers)
