"""`fivebar tolerance`: the sensitivity of a five-bar's workspace, joint space and aspects to
manufacturing tolerances on its link lengths."""

from __future__ import annotations


import click

from fivebar_cli.analyses.tolerance import HEADER, fate_text, tolerance_study
from fivebar_cli.cli.options import (
    CONFIG, common_options, data_on_stdout, depth_option, figure, jobs_option, option_errors, plural, prepare_out,
    progress, report, wrote,
)
from fivebar_cli.io.files import csv_text, write_csv
from fivebar_cli.io.layout import TOLERANCE_ASPECTS_PNG, TOLERANCE_BANDS_PNG, TOLERANCE_CSV, TOLERANCE_FILES
from fivebar_cli.io.outputs import output_set
from fivebar_cli.mechanisms.registry import load_config

MAX_TOLERANCES = 50


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
    m = load_config(config_path, kind="fivebar")
    for t in tolerances:
        m.nominal().widened(t, str(config_path))  # every tolerance keeps the lengths positive
    stdout = data_on_stdout(out)
    folder = None if stdout else prepare_out(out, m.name)
    with progress(quiet, 3 * len(tolerances), f"tolerances, depth {depth}") as advance:
        study = tolerance_study(m, tolerances, depth, advance, jobs)
    rows = [r.cells() for r in study.rows]
    if stdout:
        click.echo(csv_text(HEADER, rows), nl=False)
        paths = []
    else:
        with output_set(folder, "tolerance", TOLERANCE_FILES, "fivebar tolerance"):
            paths = [write_csv(folder / TOLERANCE_CSV, HEADER, rows)]
            if not no_plot:
                from fivebar_cli.plotting.tolerance import figure_aspect_areas, figure_bands

                paths.append(figure(lambda: figure_bands(study), folder / TOLERANCE_BANDS_PNG))
                paths.append(figure(lambda: figure_aspect_areas(study), folder / TOLERANCE_ASPECTS_PNG))
    nominal = study.nominal
    count = (f"{plural(len(nominal.aspects), 'nominal generalized aspect')}, certified" if nominal.certified else
             f"between {nominal.lower} and {plural(nominal.upper, 'nominal generalized aspect')}, not certified at "
             f"this depth: the aspect rows cover only those with certified cells")
    report(quiet, f"{m.name}: tolerance study at depth {depth} ({count})")
    report(quiet, f"  {'T':>8s} {'space':10s} {'robust':>12s} {'possible':>12s} {'nominal':>12s}")
    for r in study.rows:
        if not r.region.startswith("aspect"):
            report(quiet, f"  {r.tolerance:8g} {r.region:10s} {r.robust_area:12.6g} {r.possible_area:12.6g} "
                          f"{r.nominal_area:12.6g}")
    for tol in tolerances:
        if not study.robust[tol].certified:
            report(quiet, f"  T = {tol:g}: " + study.robust[tol].headline())
        changed = [f for f in study.fates[tol] if f.verdict != "keeps its area"]
        if changed:
            report(quiet, f"  T = {tol:g}: " + "; ".join(f"aspect {f.number} {fate_text(f)}" for f in changed))
    wrote(quiet, paths)

