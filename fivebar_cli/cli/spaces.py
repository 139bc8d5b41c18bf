"""`fivebar jointspace | workspace`: the certified paving of a space, one call of the API."""

from __future__ import annotations

from pathlib import Path

import click

from fivebar_cli.api.calls import load, pave
from fivebar_cli.api.values import check_geojson
from fivebar_cli.cli.options import (
    CONFIG, common_options, depth_option, offscreen, option_errors, prepare_out, progress, report, tolerance_option,
    with_tolerance, wrote,
)
from fivebar_cli.errors import InputError
from fivebar_cli.io.layout import paving_files
from fivebar_cli.io.outputs import output_set
from fivebar_cli.mechanisms.base import article


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


def _space_options(func):
    """The argument and options both space commands take, applied innermost first as a stack of
    decorators is (so --help lists them config, --depth, --procedure, ... as before)."""
    for decorate in (option_errors(), common_options, _geojson_option, tolerance_option, _procedure_option,
                     depth_option(octrees=True), click.argument("config_path", metavar="CONFIG", type=CONFIG)):
        func = decorate(func)
    return func


def _space_command(space: str, config_path: Path, depth: int, procedure: str, tolerance: float, out, no_plot: bool,
                   quiet: bool, geojson: bool = False) -> None:
    m = with_tolerance(load(config_path, space=space), tolerance, config_path)
    if procedure not in m.procedures:
        raise InputError(str(config_path), "--procedure", f"{article(m.kind)} has no {procedure!r} procedure "
                         f"(it has: {', '.join(m.procedures)})")
    check_geojson(m, space, geojson, str(config_path))  # (before anything is computed)
    folder = prepare_out(out, m.name)
    with progress(quiet, depth + 1, f"{space} depth {depth}") as advance:
        paving = pave(m, space, depth, procedure=procedure, advance=advance)
    if not no_plot:
        offscreen()
    with output_set(folder, space, paving_files(space), f"fivebar {space}"):
        paths = paving.write(folder, figures=not no_plot, geojson=geojson)
    report(quiet, paving.summary())
    wrote(quiet, paths)


@click.command(short_help="Certified joint space of a mechanism (figs. 3, 4).")
@_space_options
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
@_space_options
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
