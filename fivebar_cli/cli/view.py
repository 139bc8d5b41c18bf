"""`fivebar view`: one self-contained HTML page to explore trees, octrees and aspects in a browser."""

from __future__ import annotations

from pathlib import Path

import click

from fivebar_cli.cli.options import STDOUT, NamedPath, data_on_stdout, option_errors, plural, report, wrote
from fivebar_cli.io.layout import VIEW_HTML, view_page


@click.command(short_help="One self-contained HTML page to explore the trees in a browser.")
@click.argument("paths", metavar="PATH...", nargs=-1, required=True, type=NamedPath(path_type=Path))
@click.option("--out", "-o", "out", type=NamedPath(dir_okay=False, path_type=Path), default=None,
              help=f"The HTML file to write [default: {VIEW_HTML} in the first folder given, or beside the first .qt "
                   "file]; - writes the page to standard output.")
@click.option("--quiet", "-q", is_flag=True, help="Print nothing but errors.")
@option_errors()
def view(paths, out, quiet):
    """Write one HTML page that shows trees in any browser, offline: zoom, pan, hover a cell to
    read it, toggle layers.

    PATH is a .qt file (its .complement.qt partner comes along when present; their undetermined
    cells are shown too) or an output folder of workspace, jointspace, aspects, refine or rpr3
    pave (its *.qt and aspects/*.qt, with aspects.csv, aspects-adjacency.csv and path.csv when
    present; a `tolerance` run writes tables, not trees). Only files of complete runs are shown:
    those of an interrupted run, or of a run partly replaced by another, are left out with a
    warning. Aspects are shown in both spaces side by side with linked highlighting and the
    crossings graph; octrees as a slice with a slider over the third axis and a rotatable 3-D
    view; periodic axes (the five-bar joint space) wrap around as a torus. Everything is in the
    one file: data, script and style; nothing is loaded from the network.

    \b
    Examples:
      fivebar aspects configs/m1.yaml --depth 8 -o out/m1 --no-plot
      fivebar view out/m1                         # writes out/m1/view.html
      fivebar workspace configs/m1.yaml --depth 8 -o out/m1 --no-plot
      fivebar view out/m1/workspace.qt -o m1-workspace.html
      fivebar view out/m1 -o - > page.html
    """
    import warnings

    from fivebar_cli.analyses.view import gather  # imported here: other commands start without them
    from fivebar_cli.errors import FivebarWarning
    from fivebar_cli.webpage.page import render_page, write_page

    stdout = out is not None and str(out) == STDOUT and data_on_stdout(out)
    page = out if out is not None else view_page(paths[0])
    data = gather(paths)
    for line in data.ignored_summary():
        warnings.warn(FivebarWarning(line))
    if stdout:
        click.echo(render_page(data), nl=False)
    else:
        path = write_page(page, data)
    report(quiet, f"{data.title.removeprefix('fivebar view: ')}: {plural(len(data.trees), 'tree')}, "
                  f"{plural(data.leaves, 'black leaf', 'black leaves')}, {plural(len(data.sections), 'section')}")
    if not stdout:
        wrote(quiet, [path])
