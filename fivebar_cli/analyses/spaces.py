"""A space of any mechanism as a certified paving: pave it, write it, read it back, deepen it.

The glue between the mechanism kinds (their spaces, regions and box tests), the paving engine
and the files, kept out of the CLI so that scripts and tests can call it directly. A paving is
of one region of a space: the space's own region (`<space>.qt`) unless another region the kind
declares is named; its files are `<stem>.qt`, `<stem>.complement.qt` and `<stem>.csv`, and the
`.qt` header records the region, so `refine` asks the kind for that region's box test.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from fivebar_cli.analyses.jobs import run_tasks, workers
from fivebar_cli.errors import InputError
from fivebar_cli.io.files import write_csv
from fivebar_cli.io.layout import band_path, paving_paths, sibling_paths, summary_path
from fivebar_cli.io.qtfile import QtFile, read_qt, write_qt
from fivebar_cli.mechanisms.base import Mechanism
from fivebar_cli.mechanisms.registry import from_description
from fivebar_cli.paving.engine import Paving, pave, refine

SUMMARY_HEADER = (
    "space", "name", "procedure", "depth", "evaluations", "K", "inside_area", "undetermined_area",
    "outside_area", "inside_cells", "outside_cells", "undetermined_cells", "exact_area",
)


def k_ratio(evaluations: int, dim: int, depth: int) -> float:
    """The paper's K: evaluations over the number of cells of the dense grid, 2^(dim depth)."""
    return evaluations / 2.0 ** (dim * depth)


def _test(m: Mechanism, space: str, procedure: str, region: str | None):
    """The box test of a region (the space's own region asks with the two-argument call)."""
    if region is None or region == m.spaces()[space].region:
        return m.box_test(space, procedure)
    return m.box_test(space, procedure, region)


def pave_space(m: Mechanism, space: str, depth: int, procedure: str = "exact", on_level=None,
               region: str | None = None) -> Paving:
    """Certified paving of one space (or one region of it) of `m` to `depth`."""
    return pave(m.spaces()[space].grid(depth), _test(m, space, procedure, region), on_level)


def pave_regions(m: Mechanism, space: str, depth: int, procedure: str = "exact", on_level=None,
                 jobs: int | None = 1) -> dict[str, Paving]:
    """Certified pavings of every region the kind declares for a space, by region name; one task
    per region on `jobs` processes (`analyses.jobs`; `on_level` then hears of a region's levels
    when it is done)."""
    regions = list(m.regions(space))
    if workers(jobs, len(regions)) == 1:
        return {region: pave_space(m, space, depth, procedure, on_level, region) for region in regions}
    pavings = run_tasks(_pave_task, [(m, space, depth, procedure, region) for region in regions], jobs)
    for paving in pavings:
        for level, n in enumerate(paving.per_level):
            if on_level is not None:
                on_level(level, n)
    return dict(zip(regions, pavings))


def _pave_task(task: tuple) -> Paving:
    m, space, depth, procedure, region = task
    return pave_space(m, space, depth, procedure, region=region)


def qt_fields(m: Mechanism, space: str, colour: str, procedure: str, evaluations: int,
              region: str | None = None) -> dict:
    """Header fields of a paving's .qt files; `mechanism`, `procedure` and `evaluations` let
    `refine` resume it; trees of three or more axes also name their axes and units."""
    s = m.spaces()[space]
    fields = {"name": m.name, "space": space, "region": region or s.region, "colour": colour}
    if s.dim > 2:
        fields["axes"] = s.axes_header()
    fields.update(mechanism=m.describe(), procedure=procedure, evaluations=evaluations)
    return fields


def has_band(m: Mechanism) -> bool:
    """Whether the mechanism's pavings have an uncertain band (interval parameters)."""
    return bool(m.is_interval)


def write_paving(folder: Path, m: Mechanism, space: str, paving: Paving, procedure: str,
                 evaluations: int, region: str | None = None, stem: str | None = None) -> list[Path]:
    """`<stem>.qt`, `<stem>.complement.qt`, with interval lengths `<stem>.band.qt`, and `<stem>.csv`
    (the summary row); the stem is the space's name unless given.

    `evaluations` counts every box tested to reach this paving (with those of a refined run).
    """
    stem = stem or space
    inside_path, outside_path = paving_paths(folder, stem)
    fields = {colour: qt_fields(m, space, colour, procedure, evaluations, region) for colour in ("inside", "outside")}
    paths = [
        write_qt(inside_path, paving.inside, **fields["inside"]),
        write_qt(outside_path, paving.outside, **fields["outside"]),
    ]
    if has_band(m):
        paths.append(write_qt(band_path(folder, stem), paving.band,
                              **qt_fields(m, space, "band", procedure, evaluations, region)))
    paths.append(write_csv(summary_path(folder, stem), SUMMARY_HEADER,
                           [summary_row(m, space, procedure, paving, evaluations, region)]))
    return paths


def summary_row(m: Mechanism, space: str, procedure: str, paving: Paving, evaluations: int,
                region: str | None = None) -> tuple:
    """One CSV row; `exact_area` is the closed-form measure of the set, when one is known. The band
    of an interval mechanism counts with the undetermined cells (at depth D), so that the three
    areas still sum to the root's."""
    grid = paving.grid
    own = region is None or region == m.spaces()[space].region
    exact = m.exact_measure(space) if own else m.exact_measure(space, region)
    band_cells = int(np.sum(np.left_shift(1, grid.dim * (grid.depth - np.asarray(paving.band.level, np.int64)))))
    return (
        space, m.name, procedure, grid.depth, evaluations, k_ratio(evaluations, grid.dim, grid.depth),
        paving.inside.area, paving.undetermined_area + paving.band.area, paving.outside.area,
        len(paving.inside), len(paving.outside), len(paving.undetermined) + band_cells,
        "" if exact is None else exact,
    )


@dataclass(frozen=True)
class SavedPaving:
    """A pair of .qt files read back, with what is needed to resume the paving."""

    mechanism: Mechanism
    space: str
    procedure: str
    evaluations: int
    inside: QtFile
    outside: QtFile
    source: str = ""
    region: str | None = None  # None: the space's own region
    stem: str = ""  # the file names of the pair: <stem>.qt, <stem>.complement.qt
    band: QtFile | None = None


def load_saved(path: str | Path) -> SavedPaving:
    """Read a paving pair from either of its files and check that the two files belong together."""
    inside_path, outside_path = sibling_paths(Path(path))
    _check_partner(Path(path), inside_path, outside_path)
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
    mechanism = from_description(inside.get("mechanism"), inside.get("name", "unnamed") or "unnamed", source)
    space = inside.get("space")
    spaces = mechanism.spaces()
    region = inside.get("region")
    if space not in spaces or region not in mechanism.regions(space):
        raise InputError(source, "space", f"cannot resume a paving of space {space!r}, region {region!r}")
    procedure = inside.get("procedure", "exact")
    if procedure not in mechanism.procedures:
        raise InputError(source, "procedure", f"unknown procedure {procedure!r}")
    expected = spaces[space].grid(inside.tree.grid.depth)
    if expected != inside.tree.grid:
        raise InputError(source, "root", "the root box does not match the mechanism's "
                         f"{space} root {expected.root}")
    try:
        evaluations = int(inside.get("evaluations", "0"))
    except ValueError:
        raise InputError(source, "evaluations", f"expected an integer, got {inside.get('evaluations')!r}") from None
    pair = f"{inside_path} + {outside_path.name}"
    own = None if region == spaces[space].region else region
    stem = inside_path.name[: -len(".qt")]
    band = None
    if has_band(mechanism):
        path = band_path(inside_path.parent, stem)
        band = read_qt(path)
        if band.get("mechanism") != inside.get("mechanism") or band.tree.grid != inside.tree.grid:
            raise InputError(str(path), "mechanism", f"does not match {inside_path.name}")
    return SavedPaving(mechanism, space, procedure, evaluations, inside, outside, pair, own, stem, band)


def _check_partner(given: Path, inside_path: Path, outside_path: Path) -> None:
    """InputError when the partner of the file given is missing: an aspect's tree (`aspects` writes
    one tree per aspect, no pair) is told that it is no paving; another file, which partner was
    looked for (the user named only one of the two)."""
    partner = outside_path if given == inside_path else inside_path
    if not given.is_file() or partner.is_file():
        return  # (reading them says what is wrong, if anything)
    region = read_qt(given).get("region") or ""
    if region.startswith("aspect "):
        raise InputError(str(given), "region", f"{region!r}: the tree of one aspect, not a paving pair: only a "
                         "paving (a .qt file with its .complement.qt, as workspace and jointspace write them) "
                         "is refined; to go deeper, find the aspects again at a larger depth")
    raise InputError(str(partner), "", f"no such file: a paving is refined from its pair of files "
                     f"({inside_path.name} and {outside_path.name}, side by side)")


def refine_saved(saved: SavedPaving, depth: int, on_level=None) -> Paving:
    """Deepen a saved paving, testing only its undetermined cells (with its region's box test)."""
    test = _test(saved.mechanism, saved.space, saved.procedure, saved.region)
    band = saved.band.tree if saved.band is not None else None
    try:
        return refine(saved.inside.tree, saved.outside.tree, test, depth, on_level, band)
    except ValueError as exc:  # the two trees do not form a paving (overlap, gaps above the depth)
        raise InputError(saved.source, "", f"{exc}") from None
