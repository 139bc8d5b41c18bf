"""`fivebar tolerance`: the sensitivity of a five-bar's workspace, joint space and aspects to
manufacturing tolerances on its link lengths."""

from __future__ import annotations

import click

from fivebar_cli.api import studies
from fivebar_cli.api.studies import MAX_TOLERANCES
from fivebar_cli.cli.options import (
    CONFIG, common_options, data_on_stdout, depth_option, jobs_option, option_errors, prepare_out, progress, report,
    save_files, wrote,
)
from fivebar_cli.io.layout import TOLERANCE_CSV


def _parse_tolerances(ctx, param, text: str) -> list[float]:
    """Click callback: '0,0.01,0.05' -> sorted distinct tolerances (finite, >= 0)."""
    try:
        values = sorted({float(v) for v in text.split(",") if v.strip()})
    except ValueError:
        raise click.BadParameter(f"{text!r}: expected numbers separated by commas, like 0,0.01,0.05") from None
    if not values or any(not (v >= 0 and v < float("inf")) for v in values):
        raise click.BadParameter(f"{text!r}: tolerances must be finite numbers >= 0")
    if len(values) > MAX_TOLERANCES:
        raise click.BadParameter(f"{text!r}: at most {MAX_TOLERANCES} tolerances")
    return values


@click.command(short_help="Robust and possible regions for a range of length tolerances.")
@click.argument("config_path", metavar="CONFIG", type=CONFIG)
@click.option("--tolerances", default="0,0.01,0.02,0.05,0.1", show_default=True, callback=_parse_tolerances,
              help="Tolerances T: every link length becomes [L - T, L + T].")
@depth_option()
@jobs_option
@common_options(single=TOLERANCE_CSV)
@option_errors()
def tolerance(config_path, tolerances, depth, jobs, out, no_plot, quiet):
    """How manufacturing tolerances shrink a five-bar's workspace, joint space and aspects.

    For each tolerance T every link length becomes [L - T, L + T] (from the nominal lengths, the
    midpoints of the config's intervals). A cell is robust when every point of it is valid for
    every length vector, impossible when valid for none; between lies the uncertain band. Writes
    tolerance.csv (tolerance,region,robust_area,possible_area,nominal_area; region is workspace,
    jointspace or aspect-NN for each nominal aspect), tolerance-bands.png (robust and possible
    bands over the nominal workspace and joint space) and tolerance-aspects.png (robust area
    against tolerance per aspect), and reports which aspects shrink, split or vanish.

    The folder holds tables and figures, no trees (`fivebar view` shows the trees of `workspace
    --tolerance T`, `jointspace --tolerance T` and `aspects --tolerance T` runs).

    \b
    Examples:
      fivebar tolerance configs/m1.yaml --tolerances 0,0.02,0.05 --depth 7 -o out/m1
      fivebar tolerance configs/m2.yaml --tolerances 0,0.01 --depth 6 -o - > m2-tolerance.csv
      fivebar tolerance configs/m1.yaml --tolerances 0,0.05 --depth 6 --jobs 2 -o out/m1-tolerance-jobs --no-plot
    """
    m, tolerances = studies.tolerance_mechanism(config_path, tolerances)
    stdout = data_on_stdout(out)
    folder = None if stdout else prepare_out(out, m.name)
    with progress(quiet, 3 * len(tolerances), f"tolerances, depth {depth}") as advance:
        study = studies.tolerance(m, tolerances, depth, jobs=jobs, advance=advance)
    if stdout:
        click.echo(study.csv(), nl=False)
        paths = []
    else:
        paths = save_files(study, folder, no_plot)
    for line in study.notes:
        report(quiet, line)
    wrote(quiet, paths)
