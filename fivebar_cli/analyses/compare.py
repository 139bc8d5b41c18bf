"""Two trees compared as sets: what `fivebar diff` reports."""

from __future__ import annotations

from dataclasses import dataclass

from fivebar_cli.io.qtfile import QtFile
from fivebar_cli.paving.tree import Tree


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
        return len(self.only_a) == 0 and len(self.only_b) == 0

    def report(self, name_a: str, name_b: str) -> list[str]:
        """The lines `fivebar diff` prints."""
        if self.equal:
            lines = [f"same set: {len(self.a)} cells, area {self.a.area:.10g}"]
        else:
            lines = [
                f"{name_a}: {len(self.a)} cells, area {self.a.area:.10g}",
                f"{name_b}: {len(self.b)} cells, area {self.b.area:.10g}",
                f"only in A: {len(self.only_a)} cells, area {self.only_a.area:.10g}",
                f"only in B: {len(self.only_b)} cells, area {self.only_b.area:.10g}",
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
