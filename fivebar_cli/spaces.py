"""Five-bar spaces as pavings: grid and test per space, .qt headers, and the run summary.

This is the glue between the kinematics (`fivebar.py`), the paving engine and the files, kept out
of the CLI so that scripts and tests can call it directly.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from fivebar_cli import fivebar
from fivebar_cli.config import FiveBar, parse_fivebar
from fivebar_cli.errors import InputError
from fivebar_cli.paving import Paving, pave, refine
from fivebar_cli.qtfile import QtFile, write_qt
from fivebar_cli.quadtree import Grid

REGION = {"jointspace": "assemblable", "workspace": "reachable"}
SUMMARY_HEADER = (
    "space", "name", "procedure", "depth", "evaluations", "K", "inside_area", "undetermined_area",
    "outside_area", "inside_cells", "outside_cells", "undetermined_cells", "exact_area",
)


def grid(m: FiveBar, space: str, depth: int) -> Grid:
    periodic = space == "jointspace"
    return Grid(fivebar.space_root(m, space), depth, (periodic, periodic))


def pave_space(m: FiveBar, space: str, depth: int, procedure: str = "exact", on_level=None) -> Paving:
    """Certified paving of the joint space or workspace of `m`."""
    return pave(grid(m, space, depth), fivebar.space_test(m, space, procedure), on_level)


def qt_fields(m: FiveBar, space: str, colour: str, procedure: str, evaluations: int, region: str | None = None) -> dict:
    """Header fields of a .qt file; `mechanism`, `procedure` and `evaluations` let `refine` resume."""
    return {
        "name": m.name,
        "space": space,
        "region": region or REGION[space],
        "colour": colour,
        "mechanism": m.describe(),
        "procedure": procedure,
        "evaluations": evaluations,
    }


def paving_paths(out: Path, space: str) -> tuple[Path, Path]:
    return out / f"{space}.qt", out / f"{space}.complement.qt"


def write_paving(out: Path, m: FiveBar, space: str, paving: Paving, procedure: str, evaluations: int) -> list[Path]:
    """Write `<space>.qt` (certified inside) and `<space>.complement.qt` (certified outside).

    `evaluations` counts every box tested to reach this paving (with those of a refined run).
    """
    inside_path, outside_path = paving_paths(out, space)
    n = evaluations
    return [
        write_qt(inside_path, paving.inside, **qt_fields(m, space, "inside", procedure, n)),
        write_qt(outside_path, paving.outside, **qt_fields(m, space, "outside", procedure, n)),
    ]


def summary_row(m: FiveBar, space: str, procedure: str, paving: Paving, evaluations: int) -> tuple:
    """One CSV row; `exact_area` is the closed-form workspace area (none is known for the joint space)."""
    depth = paving.grid.depth
    return (
        space, m.name, procedure, depth, evaluations, evaluations / 4.0**depth,
        paving.inside.area, paving.undetermined_area, paving.outside.area,
        len(paving.inside), len(paving.outside), len(paving.undetermined),
        fivebar.workspace_area(m) if space == "workspace" else "",
    )


@dataclass(frozen=True)
class SavedPaving:
    """A pair of .qt files read back, with what is needed to resume the paving."""

    mechanism: FiveBar
    space: str
    procedure: str
    evaluations: int
    inside: QtFile
    outside: QtFile
    source: str = ""


def sibling_paths(path: Path) -> tuple[Path, Path]:
    """(inside, complement) paths of the pair a `.qt` or `.complement.qt` file belongs to."""
    name = path.name
    if name.endswith(".complement.qt"):
        return path.with_name(name[: -len(".complement.qt")] + ".qt"), path
    if name.endswith(".qt"):
        return path, path.with_name(name[: -len(".qt")] + ".complement.qt")
    raise InputError(str(path), "", "expected a .qt file")


def mechanism_from_fields(qt: QtFile, source: str) -> FiveBar:
    """Rebuild the five-bar from a `# mechanism: fivebar L0=... L4=...` header line."""
    text = qt.get("mechanism")
    if not text:
        raise InputError(source, "mechanism", "missing header line '# mechanism: fivebar L0=... L4=...'")
    kind, *items = text.split()
    if kind != "fivebar":
        raise InputError(source, "mechanism", f"unsupported mechanism {kind!r}")
    lengths = {}
    for item in items:
        key, sep, value = item.partition("=")
        try:
            lengths[key] = float(value)
        except ValueError:
            raise InputError(source, "mechanism", f"bad length {item!r}") from None
    return parse_fivebar({"name": qt.get("name", "unnamed") or "unnamed", "type": "fivebar", "lengths": lengths}, source)


def refine_saved(saved: SavedPaving, depth: int, on_level=None) -> Paving:
    """Deepen a saved paving, testing only its undetermined cells."""
    test = fivebar.space_test(saved.mechanism, saved.space, saved.procedure)
    try:
        return refine(saved.inside.tree, saved.outside.tree, test, depth, on_level)
    except ValueError as exc:  # the two trees do not form a paving (overlap, gaps above the depth)
        raise InputError(saved.source, "", f"{exc}") from None


def load_saved(path: str | Path) -> SavedPaving:
    """Read a paving pair from either of its files and check that the two files belong together."""
    from fivebar_cli.qtfile import read_qt

    inside_path, outside_path = sibling_paths(Path(path))
    inside, outside = read_qt(inside_path), read_qt(outside_path)
    for qt, colour, p in ((inside, "inside", inside_path), (outside, "outside", outside_path)):
        if qt.get("colour", colour) != colour:
            raise InputError(str(p), "colour", f"expected '{colour}', got {qt.get('colour')!r}")
    for key in ("mechanism", "space", "region", "procedure", "evaluations"):
        if inside.get(key) != outside.get(key):
            raise InputError(str(outside_path), key, f"does not match {inside_path.name} "
                             f"({outside.get(key)!r} vs {inside.get(key)!r})")
    if inside.tree.grid != outside.tree.grid:
        raise InputError(str(outside_path), "root/depth/periodic", f"does not match {inside_path.name}")
    source = str(inside_path)
    mechanism = mechanism_from_fields(inside, source)
    space = inside.get("space")
    if space not in fivebar.SPACES or inside.get("region") != REGION[space]:
        raise InputError(source, "space", f"cannot resume a paving of space {space!r}, region {inside.get('region')!r}")
    procedure = inside.get("procedure", "exact")
    if procedure not in fivebar.PROCEDURES:
        raise InputError(source, "procedure", f"unknown procedure {procedure!r}")
    expected = grid(mechanism, space, inside.tree.grid.depth)
    if expected != inside.tree.grid:
        raise InputError(source, "root", "the root box does not match the mechanism's "
                         f"{space} root {expected.root}")
    try:
        evaluations = int(inside.get("evaluations", "0"))
    except ValueError:
        raise InputError(source, "evaluations", f"expected an integer, got {inside.get('evaluations')!r}") from None
    pair = f"{inside_path} + {outside_path.name}"
    return SavedPaving(mechanism, space, procedure, evaluations, inside, outside, pair)
