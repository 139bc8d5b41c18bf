"""`fivebar kratio`: the paper's Table 1, evaluations K = n / 2^(dim d) at several depths."""

from __future__ import annotations

from pathlib import Path

import click

from fivebar_cli.analyses.kratio import HEADER, kratio_rows, planar_spaces, row_count
from fivebar_cli.cli.options import (
    CONFIG, MAX_DEPTH, common_options, data_on_stdout, figure, option_errors, progress, report, wrote,
)
from fivebar_cli.io.files import check_writable_dir, csv_text, write_csv
from fivebar_cli.io.layout import DEFAULT_ROOT, KRATIO_CSV, KRATIO_FILES, KRATIO_PNG
from fivebar_cli.io.outputs import output_set
from fivebar_cli.io.schema import ConfigError
from fivebar_cli.mechanisms.base import article
from fivebar_cli.mechanisms.registry import load_config


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


def _cell(value, fmt: str) -> str:
    return "-" if value == "" else format(value, fmt)


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
    mechanisms = [load_config(p) for p in config_paths]
    for path, m in zip(config_paths, mechanisms):
        if not planar_spaces(m):
            raise ConfigError(str(path), "type", f"{article(m.kind)} has no 2-D space to pave (the table compares "
                              "quadtrees)")
    stdout = data_on_stdout(out)
    folder = None if stdout else check_writable_dir(out if out is not None else DEFAULT_ROOT)
    with progress(quiet, row_count(mechanisms, depths), "Table 1") as advance:
        rows = kratio_rows(mechanisms, depths, advance)
    table = [[r[k] for k in HEADER] for r in rows]
    paths = []
    if stdout:
        click.echo(csv_text(HEADER, table), nl=False)
    else:
        with output_set(folder, "kratio", KRATIO_FILES, "fivebar kratio"):
            paths.append(write_csv(folder / KRATIO_CSV, HEADER, table))
            if not no_plot:
                from fivebar_cli.plotting.kratio import figure_kratio

                paths.append(figure(lambda: figure_kratio(rows), folder / KRATIO_PNG))
    for r in rows:
        printed = f"{r['paper_printed_percent']}%" if r["paper_printed_percent"] != "" else "-"
        report(quiet, f"{r['space']:10s} {r['mechanism']:6s} d={r['depth']:2d}  ours {r['evaluations']:8d} "
               f"(K {r['K']:.2%})  paper's procedure {_cell(r['paper_procedure_evaluations'], '8d')} "
               f"(K {_cell(r['paper_procedure_K'], '.2%')}, printed {printed})  "
               f"saving {_cell(r['saving_vs_paper'], '.0%')}")
    wrote(quiet, paths)
