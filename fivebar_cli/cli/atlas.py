"""`fivebar atlas SPEC`: sweep a grid of five-bar designs (in-process or on Dask), resumably."""

from __future__ import annotations

import time

import click

from fivebar_cli.analyses.atlas.cluster import check_address
from fivebar_cli.api.atlas import atlas_plan, atlas_spec
from fivebar_cli.cli.numbers import Number
from fivebar_cli.cli.options import (
    CONFIG, MAX_ASPECT_DEPTH, common_options, narrated, option_errors, plural, prepare_out, progress, report, save_files,
    wrote,
)


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
    plan = atlas_plan(spec, folder, restart=restart)
    report(quiet, plan.summary)
    start = time.monotonic()
    with narrated(quiet), progress(quiet, plan.designs_todo, "designs", unit="designs") as advance:
        result = plan.run(workers=workers, scheduler=scheduler, advance=advance)
    seconds = time.monotonic() - start
    paths = save_files(result, folder, no_plot)
    if plan.designs_todo:
        report(quiet, f"  computed {plural(plan.designs_todo, 'design')} in {seconds:.1f} s "
                      f"({plan.designs_todo / seconds:.3g} designs/s)")
    for line in result.notes:
        report(quiet, line)
    if not no_plot and not spec.swept:
        report(quiet, "  no figure: no length is swept")
    wrote(quiet, paths)
