"""`fivebar atlas SPEC`: sweep a grid of five-bar designs (in-process or on Dask), resumably."""

from __future__ import annotations

import time

import click

from fivebar_cli.analyses.atlas.engine import compute_plan, in_process, plan_atlas
from fivebar_cli.api.calls import atlas_runner, atlas_spec
from fivebar_cli.analyses.atlas.cluster import check_address
from fivebar_cli.cli.numbers import Number
from fivebar_cli.cli.options import (
    CONFIG, MAX_ASPECT_DEPTH, common_options, figure, option_errors, plural, prepare_out, progress, report, wrote,
)
from fivebar_cli.io.layout import ATLAS_CSV, ATLAS_PNG
from fivebar_cli.io.outputs import output_set


@click.command(short_help="Sweep five-bar designs into an atlas of metrics (Dask, resumable).")
@click.argument("spec_path", metavar="SPEC", type=CONFIG)
@click.option("--workers", "-w", type=click.IntRange(0, 1024), default=None,
              help="Worker processes of a local Dask cluster, one thread each [default: the number of cores]; "
                   "0: run in this process, without Dask.")
@click.option("--scheduler", metavar="ADDRESS", default=None,
              help="Use the existing Dask cluster whose scheduler is at ADDRESS (tcp://HOST:PORT).")
@click.option("--depth", "-d", type=click.IntRange(0, MAX_ASPECT_DEPTH), default=None,
              help=f"Depth of every design's analyses (0..{MAX_ASPECT_DEPTH}) [default: the spec's depth].")
@click.option("--tolerance", metavar="T", type=Number(lo=0), default=None,
              help="Add robust metrics of every length widened to [L - T, L + T] (as `fivebar aspects "
                   "--tolerance T`); 0: none [default: the spec's tolerance].")
@click.option("--restart", is_flag=True, help="Discard the parts of an earlier run in OUT/atlas.parts/ and start afresh.")
@common_options(default="outputs/<spec name>/")
@option_errors()
def atlas(spec_path, workers, scheduler, depth, tolerance, restart, out, no_plot, quiet):
    """Sweep a grid of five-bar designs and tabulate, per design: whether it can be assembled,
    its number of generalized aspects and whether that count is certified (as `fivebar aspects`
    at the same depth), its workspace area (exact) and the workspace area of its largest aspect.
    With a tolerance T > 0 (the spec's `tolerance:` or --tolerance), the same for the robust
    aspects and workspace of every length widened to [L - T, L + T] (as `fivebar aspects
    --tolerance T` and `fivebar workspace --tolerance T`).

    The spec (`type: fivebar-atlas`) gives each length a number (fixed) or [from, to, steps]
    (swept); designs are in grid order, L0 slowest, L4 fastest. Batches of designs run on a
    local Dask cluster (--workers N), an existing one (--scheduler), or in this process
    (--workers 0). Each finished batch is kept in OUT/atlas.parts/ with its checksum: a rerun
    after Ctrl-C, a kill or a lost worker computes only the missing batches (and any part that
    fails its checksum). Ctrl-C stops the run at any moment, cluster start-up included: exit 130,
    one line, the parts written so far kept. Writes OUT/atlas.csv (the same bytes whatever the
    workers or scheduler) and atlas.png (heat maps over the swept lengths).

    \b
    Examples:
      fivebar atlas configs/atlas-small.yaml --workers 2 -o out/atlas
      fivebar atlas configs/atlas-small.yaml --workers 0 --no-plot

    With --tolerance 0.01, the robust columns too (several times the cost). On a cluster:
    --scheduler tcp://HOST:8786 (README, "Sweeping designs").
    """
    if workers is not None and scheduler is not None:
        raise click.UsageError("give --workers or --scheduler, not both")
    if scheduler is not None:
        scheduler = check_address(scheduler)
    spec = atlas_spec(spec_path, depth, tolerance)
    folder = prepare_out(out, spec.name)
    plan = plan_atlas(spec, folder, restart)
    robust = f", tolerance {spec.tolerance:g}" if spec.tolerance > 0 else ""
    report(quiet, f"{spec.name}: {plural(spec.size, 'design')} at depth {spec.depth}{robust}, "
           f"{plural(plan.batches, 'batch', 'batches')} of {spec.batch_size}: {plan.batches - len(plan.todo)} done "
           f"before, {len(plan.todo)} to compute")
    start = time.monotonic()
    with atlas_runner(workers, scheduler, len(plan.todo)) as runner:
        if plan.todo and runner is not in_process:
            connected = runner.workers
            report(quiet, f"  on {runner.where} ({plural(connected, 'worker')} connected"
                   + (": the batches wait for workers)" if connected == 0 else ")"))
        with progress(quiet, plan.designs_todo, "designs", unit="designs") as advance:
            compute_plan(plan, runner, advance)
    seconds = time.monotonic() - start
    with output_set(folder, "atlas", (ATLAS_CSV, ATLAS_PNG), "fivebar atlas"):
        path, table = plan.parts.assemble(folder / ATLAS_CSV)
        paths = [path]
        if not no_plot and spec.swept:
            from fivebar_cli.plotting.atlas import figure_atlas

            paths.append(figure(lambda: figure_atlas(spec, table), folder / ATLAS_PNG))
    if plan.todo:
        report(quiet, f"  computed {plural(plan.designs_todo, 'design')} in {seconds:.1f} s "
                      f"({plan.designs_todo / seconds:.3g} designs/s)")
    assemblable = table["assemblable"].count("true")
    certified = _certified(table, "certified")
    report(quiet, f"  {assemblable} can be assembled; the aspect count is certified for {certified} of them"
           + (f" (not for {assemblable - certified}: raise --depth)" if certified < assemblable else ""))
    if spec.tolerance > 0:
        report(quiet, f"  the robust aspect count (tolerance {spec.tolerance:g}) is certified for "
               f"{_certified(table, 'robust_certified')} of them")
    if not no_plot and not spec.swept:
        report(quiet, "  no figure: no length is swept")
    wrote(quiet, paths)


def _certified(table: dict, column: str) -> int:
    """Designs that can be assembled and whose count in `column` is certified."""
    return sum(a == "true" and c == "true" for a, c in zip(table["assemblable"], table[column]))
