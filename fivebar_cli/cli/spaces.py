"""`fivebar jointspace | workspace | refine | diff`: certified pavings of a space, deepened, compared."""

from __future__ import annotations

from pathlib import Path

import click

from fivebar_cli.analyses import spaces
from fivebar_cli.analyses.compare import compare
from fivebar_cli.cli.options import (
    CONFIG, common_options, depth_option, figure, offscreen, prepare_out, progress, refuse_stdout, report,
    tolerance_option, with_tolerance, wrote,
)
from fivebar_cli.errors import InputError
from fivebar_cli.io.files import check_writable_dir
from fivebar_cli.io.layout import PAVE_SET, band_path, geojson_path, paving_files, sibling_paths
from fivebar_cli.io.outputs import output_set, read_runs
from fivebar_cli.io.qtfile import read_qt
from fivebar_cli.mechanisms.base import article
from fivebar_cli.mechanisms.registry import load_config

QT_FILE = click.Path(path_type=Path, dir_okay=False)


def _procedure_option(func):
    return click.option(
        "--procedure", type=click.Choice(["exact", "paper"]), default="exact", show_default=True,
        help="Box test: our exact-range tests, or the paper's interval procedure (five-bar baseline).",
    )(func)


def _geojson_option(func):
    return click.option(
        "--geojson", is_flag=True,
        help="Also write <space>.geojson: the certified inside region (robust with --tolerance) as a "
             "(Multi)Polygon with holes (the joint space in its [-pi, pi]^2 chart).",
    )(func)


def _space_command(space: str, config_path: Path, depth: int, procedure: str, tolerance: float, out, no_plot: bool,
                   quiet: bool, geojson: bool = False) -> None:
    m = with_tolerance(load_config(config_path, space=space), tolerance, config_path)
    if procedure not in m.procedures:
        raise InputError(str(config_path), "--procedure", f"{article(m.kind)} has no {procedure!r} procedure "
                         f"(it has: {', '.join(m.procedures)})")
    if geojson and m.spaces()[space].dim != 2:
        raise InputError(str(config_path), "--geojson", f"GeoJSON is for 2-D spaces; the {space} of {article(m.kind)} "
                         f"has {m.spaces()[space].dim} axes")
    folder = prepare_out(out, m.name)
    with progress(quiet, depth + 1, f"{space} depth {depth}") as advance:
        paving = spaces.pave_space(m, space, depth, procedure, on_level=lambda level, n: advance(1))
    with output_set(folder, space, paving_files(space), f"fivebar {space}"):
        paths = _write(folder, m, space, paving, procedure, paving.evaluations, no_plot)
        if geojson:
            from fivebar_cli.io.geojson import write_geojson

            properties = {"name": m.name, "space": space, "region": m.spaces()[space].region, "depth": depth,
                          "procedure": procedure, "area": paving.inside.area}
            paths.append(write_geojson(geojson_path(folder, space), paving.inside, properties))
    report(quiet, _summary(m, space, paving, procedure))
    wrote(quiet, paths)


def _summary(m, space: str, paving, procedure: str) -> str:
    dim, depth = paving.grid.dim, paving.grid.depth
    head = (f"{m.name} {space}, depth {depth} ({procedure} tests): {paving.evaluations} evaluations "
            f"(K = {spaces.k_ratio(paving.evaluations, dim, depth):.4%}), ")
    if spaces.has_band(m):
        possible = float(paving.grid.size.prod()) - paving.outside.area
        exact = m.exact_measure(space)
        return head + (f"robust area {paving.inside.area:.10g}, possible area {possible:.10g} "
                       f"(uncertain band {paving.band.area:.4g}, undetermined {paving.undetermined_area:.4g})"
                       + (f", nominal exact area {exact:.10g}" if exact is not None else ""))
    return head + (f"certified inside {'area' if dim == 2 else 'volume'} {paving.inside.area:.10g}, "
                   f"undetermined {paving.undetermined_area:.4g}")


def _write(folder: Path, m, space: str, paving, procedure: str, evaluations: int, no_plot: bool,
           region: str | None = None, stem: str | None = None) -> list[Path]:
    """The .qt pair, the summary CSV and (unless --no-plot) the figures of a paving (of a region)."""
    stem = stem or space
    paths = spaces.write_paving(folder, m, space, paving, procedure, evaluations, region, stem)
    if not no_plot:
        from fivebar_cli.plotting.trees import figure_paving

        und = paving.undetermined_tree()
        s = m.spaces()[space]
        for complement, suffix in ((False, ""), (True, ".complement")):
            marks = getattr(m, "marks", lambda name: [])(space)
            paths.append(figure(lambda: figure_paving(m.name, s, paving.inside, paving.outside, und, complement,
                                                      paving.band, region, marks), folder / f"{stem}{suffix}.png"))
    return paths


@click.command(short_help="Certified joint space of a mechanism (figs. 3, 4).")
@click.argument("config_path", metavar="CONFIG", type=CONFIG)
@depth_option()
@_procedure_option
@tolerance_option
@_geojson_option
@common_options
def jointspace(config_path, depth, procedure, tolerance, geojson, out, no_plot, quiet):
    """Certified joint space of a mechanism: (th1, th2) on the torus [-pi, pi]^2 for a five-bar
    (an actuated limit narrower than a turn makes its axis that interval), the leg lengths
    (rho1, rho2) for a 2-RPR. With joint limits or obstacles, black cells hold only configurations
    within them.

    Black cells can be assembled at every point (five-bar: |L3-L4| <= |B1B2| <= L3+L4,
    B1 != B2); complement cells at no point. Writes jointspace.qt, jointspace.complement.qt,
    jointspace.csv and the figures jointspace.png (paper fig. 3) and jointspace.complement.png
    (fig. 4); with --geojson, jointspace.geojson (the black cells as polygons).

    \b
    Example:
      fivebar jointspace configs/m1.yaml --depth 10 -o out/m1
    """
    _space_command("jointspace", config_path, depth, procedure, tolerance, out, no_plot, quiet, geojson)


@click.command(short_help="Certified workspace (x, y) of a mechanism (fig. 6).")
@click.argument("config_path", metavar="CONFIG", type=CONFIG)
@depth_option()
@_procedure_option
@tolerance_option
@_geojson_option
@common_options
def workspace(config_path, depth, procedure, tolerance, geojson, out, no_plot, quiet):
    """Certified workspace (x, y) of a mechanism, on the root box [-(L1+L3), L1+L3]^2 for a five-bar.

    Black cells are reachable at every point; complement cells at no point. Writes workspace.qt,
    workspace.complement.qt, workspace.csv and the figures workspace.png (paper fig. 6) and
    workspace.complement.png; with --geojson, workspace.geojson (the black cells as polygons,
    for CAD and GIS tools).

    \b
    Example:
      fivebar workspace configs/m2.yaml --depth 12 -o out/m2
    """
    _space_command("workspace", config_path, depth, procedure, tolerance, out, no_plot, quiet, geojson)


@click.command(short_help="Deepen a saved paving, testing only undetermined cells.")
@click.argument("tree_path", metavar="TREE.qt", type=QT_FILE)
@depth_option(default=12)
@common_options(default="the folder of TREE.qt, in place")
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
    if depth < old_depth:
        raise InputError(str(tree_path), "--depth", f"{depth} is below the saved depth {old_depth}")
    inside, outside = sibling_paths(tree_path)
    source = inside.parent
    folder = check_writable_dir(out if out is not None else source)
    runs = read_runs(source)
    pair = [inside, outside] + ([band_path(source, saved.stem)] if saved.band else [])
    if runs.set_of(inside) == PAVE_SET:
        return _refine_pave_set(source, folder, saved.mechanism, old_depth, depth, no_plot, quiet)
    with progress(quiet, depth - old_depth, f"refine to depth {depth}") as advance:
        paving = spaces.refine_saved(saved, depth, on_level=lambda level, n: advance(1))
    problem = runs.one_run(pair)
    if problem is not None:  # after the pair's own checks (a corrupted file is named more precisely by them)
        raise InputError(str(tree_path), "", f"not of one complete run with {pair[1 if tree_path == inside else 0].name}"
                         f": {problem}")
    total = saved.evaluations + paving.evaluations
    m, space = saved.mechanism, saved.space
    with output_set(folder, saved.stem, paving_files(saved.stem), f"fivebar refine {saved.stem}.qt"):
        paths = _write(folder, m, space, paving, saved.procedure, total, no_plot, saved.region, saved.stem)
    what = space if saved.region is None else f"{space} ({saved.region})"
    report(quiet, f"{m.name} {what}: refined depth {old_depth} -> {depth} with {paving.evaluations} evaluations "
           f"({saved.evaluations} saved by not retesting; a fresh run needs {total})")
    report(quiet, "  " + _summary(m, space, paving, saved.procedure))
    wrote(quiet, paths)


def _refine_pave_set(source: Path, folder: Path, m, old_depth: int, depth: int, no_plot: bool, quiet: bool) -> None:
    """Refine the three pairs of an `rpr3 pave` run together and rewrite its volumes and figures."""
    from fivebar_cli.api.rpr3 import refine_pave_set

    with progress(quiet, 3 * (depth - old_depth), f"refine to depth {depth}") as advance:
        result, saved_total = refine_pave_set(source, m, old_depth, depth, on_level=lambda level, n: advance(1))
    report(quiet, f"{m.name}: the three pavings of its rpr3 pave run refined together, depth {old_depth} -> {depth} "
                  f"({saved_total} evaluations saved by not retesting)")
    if not no_plot:
        offscreen()
    paths = result.save(folder, figures=not no_plot)
    for line in result.notes:
        report(quiet, line)
    wrote(quiet, paths)


@click.command(short_help="Compare two .qt files as sets (exit 0 same, 1 different).")
@click.argument("a_path", metavar="A.qt", type=QT_FILE)
@click.argument("b_path", metavar="B.qt", type=QT_FILE)
@click.option("--sets-only", is_flag=True,
              help="Compare the cells alone: equal sets exit 0 even when colour, mechanism, space or region differ.")
@click.option("--quiet", "-q", is_flag=True, help="Print nothing; only the exit status tells.")
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
    a, b = read_qt(a_path), read_qt(b_path)
    try:
        result = compare(a, b)
    except ValueError as exc:
        raise InputError(str(b_path), "root", f"{exc} (A is {a_path})") from None
    if not quiet:
        for line in result.report(str(a_path), str(b_path), sets_only):
            click.echo(line)
    if not result.same(sets_only):
        raise click.exceptions.Exit(1)
