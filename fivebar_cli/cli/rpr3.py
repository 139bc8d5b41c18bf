"""`fivebar rpr3 area | sweep | synthesize`: the closed forms of a platform similar to the base
(Jiang & Gosselin), each one call of `fivebar_cli.api.rpr3`; `pave` and `verify` are in
`rpr3_octree.py` (attached to the group in `main.py`)."""

from __future__ import annotations

from pathlib import Path

import click

from fivebar_cli.api import rpr3 as api
from fivebar_cli.cli.numbers import NUMBER
from fivebar_cli.cli.options import (
    CONFIG, common_options, data_on_stdout, option_errors, prepare_out, progress, report, save_files, wrote,
)
from fivebar_cli.io.layout import AREA_CSV


@click.group()
def rpr3() -> None:
    """3-RPR: closed forms for a platform similar to the base (area, sweep, synthesize),
    certified octrees of any 3-RPR in (x, y, phi) (pave, verify) and its assembly modes (dkp).

    \b
    Examples (each also in its command's help):
      fivebar rpr3 area configs/rpr3-equilateral.yaml -o out/equilateral
      fivebar rpr3 sweep configs/rpr3-acute.yaml configs/rpr3-equilateral.yaml configs/rpr3-obtuse.yaml --over phi
      fivebar rpr3 synthesize configs/rpr3-table1.yaml
      fivebar rpr3 pave configs/rpr3-general.yaml --depth 5 -o out/general
      fivebar rpr3 verify configs/rpr3-verify/table1-legs-1-1.5.yaml
      fivebar rpr3 dkp configs/rpr3-caro.yaml --legs 14.98 15.38 12 --depth 6 -o out/caro
    """



# ---------------------------------------------------------------- area


@rpr3.command("area", short_help="Exact area of the singularity-free workspace (figures 2, 9).")
@click.argument("config", type=CONFIG)
@common_options(single=AREA_CSV)
@option_errors()
def area_cmd(config: Path, out: Path | None, no_plot: bool, quiet: bool) -> None:
    """Exact area of the singularity-free workspace W at phi (or at both ends of phi_range).

    W is the part inside the singularity circle of the intersection of the three annuli
    rho_min <= |X - C_i| <= rho_max. Writes area.csv (phi_deg,rho_min,rho_max,area) and
    singularity-free-workspace.png (the construction of the paper's figures 2 and 9).

    \b
    Examples:
      fivebar rpr3 area configs/rpr3-equilateral.yaml -o out/equilateral
      fivebar rpr3 area configs/rpr3-equilateral.yaml -o -          # area.csv on standard output
    """
    mech = api.similar(config)
    stdout = data_on_stdout(out)
    folder = None if stdout else prepare_out(out, mech.name)
    study = api.area(mech)
    for line in study.notes:
        report(quiet, line)
    if stdout:
        click.echo(study.csv(), nl=False)
        return
    wrote(quiet, save_files(study, folder, no_plot))


# ---------------------------------------------------------------- sweeps


@rpr3.command("sweep", short_help="Area swept over phi, rho_min or t2 (figures 3-8).")
@click.argument("configs", nargs=-1, required=True, type=CONFIG, metavar="CONFIG...")
@click.option("--over", type=click.Choice(["phi", "rho_min", "t2"]), required=True,
              help="phi: figures 3, 4, 6, 7; rho_min: figure 5 (at the config's phi); t2: figure 8.")
@click.option("--range", "span", type=(NUMBER, NUMBER), default=None, metavar="LO HI",
              help="Swept interval [default: phi 0.5 179.5; rho_min 0 up to where rho_max auto is finite; "
                   "t2 -5 t1+5].")
@click.option("--steps", type=click.IntRange(2, api.MAX_STEPS), default=None,
              help="Number of samples [default: phi 359, rho_min 201, t2 233].")
@click.option("--angles", default=None,
              help="Orientations (degrees) of the t2 sweep, comma separated [default: 30,60,90,120,150].")
@common_options(single="the table (area-vs-phi.csv, area-vs-rho-min.csv or area-vs-t2.csv)",
                default="outputs/<config name>/, outputs/<name1>+<name2>+.../ for several")
@option_errors()
def sweep_cmd(configs, over, span, steps, angles, out, no_plot, quiet) -> None:
    """Area of W swept over phi, rho_min or the base shape t2, for one or more bases on one figure.

    Every sample is a design of its own (rho_max auto at that orientation). Several CONFIGs are
    overlaid (the paper compares the acute, equilateral and obtuse bases); the default output
    folder is then outputs/<name1>+<name2>+.../.

    \b
    Examples:
      fivebar rpr3 sweep configs/rpr3-acute.yaml configs/rpr3-equilateral.yaml configs/rpr3-obtuse.yaml --over phi
      fivebar rpr3 sweep configs/rpr3-equilateral.yaml --over rho_min --range 0 0.7
      fivebar rpr3 sweep configs/rpr3-equilateral.yaml --over t2 --angles 30,90,150 --steps 21
      fivebar rpr3 sweep configs/rpr3-equilateral.yaml --over rho_min -o - > area-vs-rho-min.csv
    """
    mechs = [api.similar(c) for c in configs]
    with option_errors(span="--range", angles="--angles"):
        api.check_span(span)
    stdout = data_on_stdout(out)
    folder = None if stdout else prepare_out(out, "+".join(dict.fromkeys(m.name for m in mechs)))
    with option_errors(span="--range", angles="--angles", over="--over"):
        with progress(quiet or over == "rho_min", len(mechs), f"sweeping {over}") as advance:
            study = api.sweep(mechs, over, span, steps, angles, advance)
    for line in study.notes:
        report(quiet, line)
    if stdout:
        click.echo(study.csv(), nl=False)
        return
    wrote(quiet, save_files(study, folder, no_plot))


# ---------------------------------------------------------------- synthesis


@rpr3.command("synthesize", short_help="Leg range for an orientation range (Table 1, figure 10).")
@click.argument("config", type=CONFIG)
@common_options
@option_errors()
def synthesize_cmd(config: Path, out: Path | None, no_plot: bool, quiet: bool) -> None:
    """Leg-length range for a singularity-free workspace over phi_range (section 4, Table 1).

    Six choices of rho_min: the config's, the optimum at phi1, at phi2, the maximal mean area A_a,
    A1 = A2, the minimal fluctuation dA_a; rho_max is, for each, the largest value keeping W
    singularity-free at every orientation of the range (closed form). Writes
    synthesis.csv, table1-comparison.csv (our values beside the paper's, for the paper's setup),
    area-vs-phi-cases.png (figure 10) and singularity-free-workspace-case2.png (figure 9).

    \b
    Example:
      fivebar rpr3 synthesize configs/rpr3-table1.yaml
    """
    mech = api.similar(config)
    study = api.synthesize(mech)
    for line in study.notes[:study.printed]:
        report(quiet, line)
    folder = prepare_out(out, mech.name)
    for line in study.notes[study.printed:]:
        report(quiet, line)
    wrote(quiet, save_files(study, folder, no_plot))
