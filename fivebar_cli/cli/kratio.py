"""`fivebar kratio`: the paper's Table 1, evaluations K = n / 2^(dim d) at several depths."""

from __future__ import annotations

import click

from fivebar_cli.api import studies
from fivebar_cli.api.studies import MAX_DEPTH
from fivebar_cli.cli.options import (
    CONFIG, common_options, data_on_stdout, option_errors, progress, report, save_files, wrote,
)
from fivebar_cli.io.files import check_writable_dir
from fivebar_cli.io.layout import DEFAULT_ROOT, KRATIO_CSV


def _parse_depths(ctx, param, text: str) -> list[int]:
    """Click callback: '5-10' or '5,8,10' -> sorted depths."""
    depths: set[int] = set()
    try:
        for part in text.split(","):
            lo, sep, hi = part.strip().partition("-")
            first, last = int(lo), int(hi) if sep else int(lo)
            if not 0 <= first <= last <= MAX_DEPTH:
                raise click.BadParameter(f"{text!r}: depths must lie in 0..{MAX_DEPTH}, ranges ascending")
            depths.update(range(first, last + 1))
    except ValueError:
        raise click.BadParameter(f"{text!r}: expected a range like 5-10 or a list like 5,8,10") from None
    return sorted(depths)


@click.command(short_help="The paper's Table 1: evaluation counts K = n / 4^d.")
@click.argument("config_paths", metavar="CONFIG...", type=CONFIG, nargs=-1, required=True)
@click.option("--depths", default="5-10", show_default=True, callback=_parse_depths,
              help="Depths: a range 5-10 or a list 5,8,10.")
@common_options(single=KRATIO_CSV, default="outputs/")
@option_errors()
def kratio(config_paths, depths, out, no_plot, quiet):
    """The paper's Table 1: evaluations K = n / 4^d, ours against the paper's procedure.

    For each space, mechanism and depth: our tight tests, the paper's interval procedure (for a
    five-bar) and, for M1 and M2, the K printed in the paper. Writes kratio.csv and kratio.png
    into --out (default: outputs/, not outputs/<name>/: the table compares mechanisms).

    \b
    Examples:
      fivebar kratio configs/m1.yaml configs/m2.yaml --depths 5-10 -o out
      fivebar kratio configs/m1.yaml --depths 5,8 -o -             # kratio.csv on standard output
    """
    mechanisms = [studies.kratio_mechanism(p) for p in config_paths]
    stdout = data_on_stdout(out)
    folder = None if stdout else check_writable_dir(out if out is not None else DEFAULT_ROOT)
    with progress(quiet, studies.kratio_steps(mechanisms, depths), "Table 1") as advance:
        table = studies.kratio(mechanisms, depths, advance=advance)
    paths = []
    if stdout:
        click.echo(table.csv(), nl=False)
    else:
        paths = save_files(table, folder, no_plot)
    for line in table.notes:
        report(quiet, line)
    wrote(quiet, paths)
