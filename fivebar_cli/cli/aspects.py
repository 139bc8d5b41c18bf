"""`fivebar aspects`: generalized aspects, their matching and crossings (one call of the API)."""

from __future__ import annotations

import click

from fivebar_cli.analyses.aspects import region_count
from fivebar_cli.api.calls import aspects as find_aspects
from fivebar_cli.api.calls import comparisons
from fivebar_cli.cli.options import (
    CONFIG, MAX_ASPECT_DEPTH, budget_option, common_options, depth_option, jobs_option, load_with_aspects,
    option_errors, prepare_out, progress, report, save_files, tolerance_option, wrote,
)


@click.command(short_help="Generalized aspects, their matching and crossings (figs. 7-10).")
@click.argument("config_path", metavar="CONFIG", type=CONFIG)
@depth_option(limit=MAX_ASPECT_DEPTH)
@budget_option
@tolerance_option
@jobs_option
@common_options
@option_errors()
def aspects(config_path, depth, budget, tolerance, jobs, out, no_plot, quiet):
    """Generalized aspects: the singularity-free regions of each working and assembly mode.

    Paves the workspace once per working mode and the joint space once per assembly mode,
    labels the connected regions (the five-bar's joint space is a torus), matches each parallel
    aspect (workspace) to its serial aspect (joint space), certifies the count (inner and outer
    approximations of every mode, locally refined below --depth within --budget), and finds
    which aspects touch across a serial singularity. Prints "N generalized aspects (certified)"
    or the bounds of an uncertified count. Writes aspects.csv (with a `certified` column),
    aspects-adjacency.csv, aspects/aspect-NN.workspace.qt and aspect-NN.jointspace.qt, the
    workspace region of each aspect as GeoJSON (aspect-NN.workspace.geojson), and the figures
    aspects-workspace.png (paper figs. 7, 8, with each aspect's largest certified circle and
    square) and aspects-jointspace-assembly+.png / -.png (figs. 9, 10); aspect files of an
    earlier run that this one does not have are removed. aspects.csv also gives the largest
    circle and axis-aligned square inside each aspect's certified workspace cells.

    With interval lengths (in the config, or --tolerance T) the aspects are robust: a
    configuration belongs to one when, for every length vector in the box, it is reachable,
    non-singular and in the aspect's modes. The nominal aspects are then computed too and the
    report says which of them shrink, split or vanish.

    With joint limits or obstacles in the config (limits:, obstacles:, clearance:) an aspect's
    configurations also respect every limit and keep every link clear of every obstacle; the
    constraints' boundaries separate aspects like singularities. The five-bar without its
    constraints is analysed too: aspects-split.csv says which unconstrained aspect each one comes
    from, and the report what the constraints cost.

    \b
    Examples:
      fivebar aspects configs/m1.yaml --depth 10 -o out/m1
      fivebar aspects configs/m1.yaml --depth 8 --tolerance 0.05 -o out/m1-tol --no-plot
      fivebar aspects configs/m1-obstacle.yaml --depth 9 -o out/m1-obstacle --no-plot
      fivebar aspects configs/m1.yaml --depth 9 --jobs 2 --no-plot -o out/m1-jobs
    """
    m = load_with_aspects(config_path, tolerance)
    folder = prepare_out(out, m.name)
    robust = m.is_interval
    with progress(quiet, region_count(m) * comparisons(m) + 1, f"aspects depth {depth}") as advance:
        result = find_aspects(m, depth, budget=budget, compare=True, advance=advance, jobs=jobs)
    paths = save_files(result, folder, no_plot, jobs=jobs)
    report(quiet, result.headline)
    for line in result.lines():
        report(quiet, line)
    if not result.aspects:
        report(quiet, f"  {_no_aspect_hint(depth, robust)}")
    for line in result.comparisons():
        report(quiet, line)
    wrote(quiet, paths)


def _no_aspect_hint(depth: int, robust: bool = False) -> str:
    """Why no aspect is listed. The (nominal) mechanism assembles (an empty joint space is refused
    when the file is read), so its non-singular configurations fill open sets: deeper cells find
    them. Robust aspects may not exist at all: the tolerance can leave none."""
    text = f"no {'robust ' if robust else ''}aspect has certified cells at depth {depth}"
    if robust:
        return (f"{text}: the tolerance may leave no configuration non-singular for every length vector "
                f"(a deeper paving can only find thin ones; the nominal aspects' fates follow)")
    if depth + 2 <= MAX_ASPECT_DEPTH:
        return f"{text}: a deeper paving finds them (try --depth {max(depth + 2, 8)})"
    return f"{text} (the maximum depth): the singularity-free regions are thinner than the cells"
