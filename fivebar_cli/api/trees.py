"""`compare` of the public API (`fivebar diff`): two trees compared as sets of cells and as claims
(`analyses.compare`), with what the command prints and its exit status."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from fivebar_cli.errors import InputError, param
from fivebar_cli.mechanisms.base import plural


@dataclass(frozen=True, repr=False)
class Comparison:
    """Two trees compared: `same` (equal sets and, unless `sets_only`, the same claim about them),
    `only_a` and `only_b` (the cells in one tree only, as trees), `headers` ((key, value in A,
    value in B) for each header that differs); `notes`, the lines `fivebar diff` prints, and
    `exit_code`, its exit status (0 same, 1 different)."""

    names: tuple[str, str]
    diff: object = field(compare=False)  # the library's analyses.compare.TreeDiff
    sets_only: bool = False

    @property
    def same(self) -> bool:
        return self.diff.same(self.sets_only)

    @property
    def equal(self) -> bool:
        """The same set of cells (whatever the headers claim)."""
        return self.diff.equal

    @property
    def only_a(self):
        return self.diff.only_a

    @property
    def only_b(self):
        return self.diff.only_b

    @property
    def headers(self) -> tuple[tuple[str, str, str], ...]:
        return self.diff.headers

    @property
    def exit_code(self) -> int:
        return 0 if self.same else 1

    @property
    def notes(self) -> tuple[str, ...]:
        return tuple(self.diff.report(*self.names, self.sets_only))

    def __repr__(self) -> str:
        if self.same:
            return f"<Comparison {self.names[0]} vs {self.names[1]}: same, {plural(len(self.diff.a), 'cell')}>"
        return (f"<Comparison {self.names[0]} vs {self.names[1]}: different, {plural(len(self.only_a), 'cell')} only "
                f"in A, {plural(len(self.only_b), 'cell')} only in B, {plural(len(self.headers), 'header')} differ>")


def compare(a, b, *, sets_only: bool = False) -> Comparison:
    """Compare two quadtrees (or octrees) as sets of cells and as claims.

    Equal sets still differ when the headers' colour, mechanism, space or region differ (a tree and
    its complement, the same cells for two mechanisms claim different things); `sets_only` compares
    the cells alone. Trees of different depths are compared on the finer grid.

    Parameters
    ----------
    a, b : str, Path, QtFile, Paving or Tree
        `.qt` files, what `read_qt` returns, pavings (their inside trees, with the header their
        saved `.qt` file has), or trees (`Paving.inside`: no header).

    Returns
    -------
    Comparison
        `same`, `only_a`, `only_b`, `headers`; `notes` and `exit_code` as `fivebar diff`.
        InputError (on `root`, naming B) when the root boxes or periodic axes differ.

    Examples
    --------
    >>> import fivebar_cli as fb
    >>> p = fb.pave("m1", "workspace", 5)
    >>> c = fb.compare(p.inside, p.outside)
    >>> c.same, c.exit_code, len(c.only_a) == len(p.inside)
    (False, 1, True)
    """
    from fivebar_cli.analyses.compare import compare as compare_trees

    (name_a, qa), (name_b, qb) = _tree(a, "A"), _tree(b, "B")
    try:
        diff = compare_trees(qa, qb)
    except ValueError as exc:
        raise InputError(name_b, "root", f"{exc} (A is {name_a})") from None
    return Comparison((name_a, name_b), diff, bool(sets_only))


def _tree(value, label: str):
    """(name, QtFile) of a path, a QtFile, a paving (its inside tree and the header of its saved
    `.qt` file, as text) or a bare tree."""
    from fivebar_cli.analyses.spaces import qt_fields
    from fivebar_cli.api.values import Paving
    from fivebar_cli.io.qtfile import QtFile, read_qt
    from fivebar_cli.paving.tree import Tree

    if isinstance(value, (str, Path)):
        return str(value), read_qt(value)
    if isinstance(value, QtFile):
        return label, value
    if isinstance(value, Paving):
        fields = qt_fields(value.mechanism, value.space, "inside", value.procedure, value.evaluations, value.region)
        return label, QtFile(value.inside, {k: str(v) for k, v in fields.items()})
    if isinstance(value, Tree):
        return label, QtFile(value, {})
    raise InputError("", param(label.lower()), f"expected a .qt path, a QtFile, a paving or a tree, got "
                     f"{type(value).__name__}")
