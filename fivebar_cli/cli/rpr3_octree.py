"""`fivebar rpr3 pave | verify`: certified octrees of any 3-RPR in (x, y, phi), each one call of
`fivebar_cli.api.rpr3` (commands of the `rpr3` group, attached in `main.py`)."""

from __future__ import annotations

from pathlib import Path

import click

from fivebar_cli.api import rpr3 as api
from fivebar_cli.analyses.limits import MAX_OCTREE_DEPTH, MAX_VERIFY_DEPTH
from fivebar_cli.cli.options import (
    CONFIG, common_options, jobs_option, option_errors, prepare_out, progress, report, save_files, wrote,
)



@click.command("pave", short_help="Certified octree of the workspace and its singularity-free parts.")
@click.argument("config", type=CONFIG)
@click.option("--depth", "-d", type=click.IntRange(0, MAX_OCTREE_DEPTH), default=7, show_default=True,
              help=f"Depth d of the octree (cells are root/2^d wide; 0..{MAX_OCTREE_DEPTH}).")
@jobs_option
@common_options
@option_errors()
def pave_cmd(config: Path, depth: int, jobs: int | None, out: Path | None, no_plot: bool, quiet: bool) -> None:
    """Certified octree over (x, y, phi) of the workspace and of its singularity-free parts.

    Any 3-RPR: base and platform points (or the similar form), one leg range or one per leg,
    an orientation range (a single phi gives the quadtree of (x, y) at that phi). Three pavings,
    each a .qt pair (black cells certified in, complement cells certified out) and a summary CSV:
    workspace (every pose has its three legs in range), singularity-free.plus and
    singularity-free.minus (every pose reachable and det J > 0, resp. < 0; sign convention in
    docs/rpr3.md). Also volumes.csv (reachable, unreachable, undetermined, each sign, the
    singular-or-undetermined band; exact volumes for a similar platform) and the figures
    workspace.png and singularity-free.png (slices at a few phi, with the closed-form singularity
    circle for a similar platform). `fivebar refine` deepens any of the pairs.

    \b
    Examples:
      fivebar rpr3 pave configs/rpr3-general.yaml --depth 5 -o out/general
      fivebar rpr3 pave configs/rpr3-general.yaml --depth 5 --jobs 2 -o out/general-jobs --no-plot
    """
    mech = api.bounded(config)
    folder = prepare_out(out, mech.name)
    regions = mech.regions("workspace")
    with progress(quiet, len(regions) * (depth + 1), f"octree depth {depth}") as advance:
        result = api.pave(mech, depth, advance=advance, jobs=jobs)
    paths = save_files(result, folder, no_plot)
    for line in result.notes:
        report(quiet, line)
    wrote(quiet, paths)


@click.command("verify", short_help="Prove a design singularity-free, or find a reachable singular pose.")
@click.argument("config", type=CONFIG)
@click.option("--depth", "-d", type=click.IntRange(0, MAX_VERIFY_DEPTH), default=14, show_default=True,
              help="Maximum depth of the subdivision (it stops as soon as it has decided).")
@common_options
@option_errors()
def verify_cmd(config: Path, depth: int, out: Path | None, no_plot: bool, quiet: bool) -> None:
    """Can the robot reach a singular pose over its orientation range and leg ranges?

    Subdivides (x, y, phi) until every box is certified unreachable or of one non-zero sign of
    det J (then: exit 0, "certified singularity-free"), or until a box whose poses are all
    reachable holds both signs of det J (exit 1: bisection to a pose with |det J| at rounding
    level, printed and written to counterexample.csv: x,y,phi_deg,rho1,rho2,rho3,det_j). Exit 3:
    undecided at --depth (the volume left open is printed; raise --depth, or the design touches
    a singularity, e.g. rho_max exactly at the closed-form limit). Writes verify.csv (the verdict)
    and, with a singular pose, counterexample.png (the robot at that pose, its leg lines meeting);
    a counterexample of an earlier run in the same folder is removed when none is found.

    \b
    Examples:
      fivebar rpr3 verify configs/rpr3-verify/table1-legs-1-1.5.yaml
      fivebar rpr3 verify configs/rpr3-verify/obtuse-phi1-rule.yaml     # exit 1: a singular pose is found
    """
    mech = api.bounded(config)
    folder = prepare_out(out, mech.name)
    study = api.verify(mech, depth)
    for line in study.notes:
        report(quiet, line)
    wrote(quiet, save_files(study, folder, no_plot))
    if study.exit_code:
        raise click.exceptions.Exit(study.exit_code)
