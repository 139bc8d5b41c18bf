"""`fivebar refine | diff`: a saved paving deepened (testing only its undetermined cells), and two
`.qt` files compared as sets."""

from __future__ import annotations

from pathlib import Path

import click

from fivebar_cli.analyses import spaces
from fivebar_cli.api.calls import refine as deepen
from fivebar_cli.api.trees import compare as fb_compare
from fivebar_cli.cli.options import (
    NamedPath, as_flags, common_options, depth_option, option_errors, progress, refuse_stdout, report, save_files,
    wrote,
)
from fivebar_cli.errors import InputError
from fivebar_cli.io.files import check_writable_dir
from fivebar_cli.io.layout import PAVE_SET, band_path, sibling_paths
from fivebar_cli.io.outputs import read_runs

QT_FILE = NamedPath(path_type=Path, dir_okay=False)


@click.command(short_help="Deepen a saved paving, testing only undetermined cells.")
@click.argument("tree_path", metavar="TREE.qt", type=QT_FILE)
@depth_option(default=12, octrees=True)
@common_options(default="the folder of TREE.qt, in place")
@option_errors()
def refine(tree_path, depth, out, no_plot, quiet):
    """Deepen a saved paving, testing only its undetermined cells.

    TREE.qt may be either file of a pair (X.qt and X.complement.qt, as written by `jointspace`,
    `workspace` and `rpr3 pave`); the mechanism, region and box test are read from their headers.
    The deeper pair replaces the old one in place (same file names, in the folder of TREE.qt),
    unless --out names another folder. A pair of `rpr3 pave` is refined with the two other pairs
    of its run, and volumes.csv is rewritten, so the folder holds one run at one depth. The result
    equals a fresh run at the new depth, with fewer evaluations.

    \b
    Example:
      fivebar workspace configs/m1.yaml --depth 10 -o out/m1
      fivebar refine out/m1/workspace.qt --depth 12
    """
    refuse_stdout(out, "a .qt pair, its summary and figures")
    saved = spaces.load_saved(tree_path)
    old_depth = saved.inside.tree.grid.depth
    inside, outside = sibling_paths(tree_path)
    source = inside.parent
    folder = check_writable_dir(out if out is not None else source)
    runs = read_runs(source)
    pair = [inside, outside] + ([band_path(source, saved.stem)] if saved.band else [])
    if runs.set_of(inside) == PAVE_SET:
        return _refine_pave_set(source, folder, saved.mechanism, old_depth, depth, no_plot, quiet)
    # (the depth is checked by the library: not below the saved one, an octree's limit for 3 axes)
    with progress(quiet, max(depth - old_depth, 0), f"refine to depth {depth}") as advance:
        paving = deepen(saved, depth, advance=advance)
    problem = runs.one_run(pair)
    if problem is not None:  # after the pair's own checks (a corrupted file is named more precisely by them)
        raise InputError(str(tree_path), "", f"not of one complete run with {pair[1 if tree_path == inside else 0].name}"
                         f": {problem}")
    total, new = paving.evaluations, paving.evaluations - saved.evaluations
    m, space = saved.mechanism, saved.space
    paths = save_files(paving, folder, no_plot, command=f"fivebar refine {saved.stem}.qt")
    what = space if saved.region is None else f"{space} ({saved.region})"
    report(quiet, f"{m.name} {what}: refined depth {old_depth} -> {depth} with {new} evaluations "
           f"({saved.evaluations} saved by not retesting; a fresh run needs {total})")
    report(quiet, "  " + paving.summary(new))
    wrote(quiet, paths)


def _refine_pave_set(source: Path, folder: Path, m, old_depth: int, depth: int, no_plot: bool, quiet: bool) -> None:
    """Refine the three pairs of an `rpr3 pave` run together and rewrite its volumes and figures."""
    from fivebar_cli.api.rpr3 import refine_pave_set

    with progress(quiet, 3 * max(depth - old_depth, 0), f"refine to depth {depth}") as advance:
        result, saved_total = refine_pave_set(source, m, old_depth, depth, advance=advance)
    report(quiet, f"{m.name}: the three pavings of its rpr3 pave run refined together, depth {old_depth} -> {depth} "
                  f"({saved_total} evaluations saved by not retesting)")
    paths = save_files(result, folder, no_plot)
    for line in result.notes:
        report(quiet, line)
    wrote(quiet, paths)


@click.command(short_help="Compare two .qt files as sets (exit 0 same, 1 different).")
@click.argument("a_path", metavar="A.qt", type=QT_FILE)
@click.argument("b_path", metavar="B.qt", type=QT_FILE)
@click.option("--sets-only", is_flag=True,
              help="Compare the cells alone: equal sets exit 0 even when colour, mechanism, space or region differ.")
@click.option("--quiet", "-q", is_flag=True, help="Print nothing; only the exit status tells.")
@option_errors()
def diff(a_path, b_path, sets_only, quiet):
    """Compare two quadtree files: exit 0 when they hold the same set of cells and claim the same
    thing about it, 1 when not, 2 on bad input.

    Prints the cells and the area in A but not in B, and in B but not in A, and the header lines
    that differ. Equal sets still differ (exit 1) when the headers colour, mechanism, space or
    region differ: a tree and its complement, or the same cells for two mechanisms, claim
    different things; --sets-only compares the cells alone. Trees of different depths are
    compared on the finer grid; their root boxes must agree.

    \b
    Examples:
      fivebar workspace configs/m1.yaml --depth 10 -o out/m1 --no-plot
      fivebar diff tests/golden/M1/workspace.qt out/m1/workspace.qt
    """
    result = fb_compare(a_path, b_path, sets_only=sets_only)
    if not quiet:
        for line in result.notes:
            click.echo(as_flags(line))
    if result.exit_code:
        raise click.exceptions.Exit(result.exit_code)
