"""`fivebar verify`: is a kind whose aspects live in a space of poses free of singularities over
its orientation range (a 3-RPR), in a working mode (a 3-RRR)? A certified yes or a singular pose."""

from __future__ import annotations

import click

from fivebar_cli.analyses.limits import MAX_VERIFY_DEPTH
from fivebar_cli.api.poses import verify as fb_verify
from fivebar_cli.cli.options import common_options, option_errors, prepare_out, report, save_files, wrote
from fivebar_cli.cli.poses import CONFIG, load_pose_kind, sheets_chosen


@click.command("verify", short_help="Prove a design singularity-free, or find a valid singular pose.")
@click.argument("config_path", metavar="CONFIG", type=CONFIG)
@click.option("--working-mode", "working_mode", default=None, metavar="W",
              help="A 3-RRR's working mode to verify, e.g. +-+ [default: every working mode of the config].")
@click.option("--depth", "-d", type=click.IntRange(0, MAX_VERIFY_DEPTH), default=14, show_default=True,
              help="Maximum depth of the subdivision (it stops as soon as it has decided).")
@common_options
@option_errors()
def verify_cmd(config_path, working_mode, depth, out, no_plot, quiet):
    """Can the robot reach a singular pose over its orientation range: a 3-RPR (det J = 0, legs
    in their ranges; as `fivebar rpr3 verify`), a 3-RRR in a working mode (det A = 0, a parallel
    singularity, with every leg strictly inside its annulus)?

    Per working mode (one for a 3-RPR), subdivides the space of poses until every box is
    certified invalid or of one non-zero sign (then "certified singularity-free"), or until a
    wholly valid box holds both signs (bisection to a pose where the sign is no longer certified:
    "singular pose found", written to counterexample.csv: the class's fields, the pose x,y,phi_deg,
    the joints and det_j or det_a), or undecided at --depth (the volume left open is printed).
    Writes verify.csv (name, the working mode for a 3-RRR, status, exit, depth, max_depth,
    evaluations, undecided_volume, root_volume: one row per working mode) and, with a singular
    pose, counterexample.png (the robot there). Exit 0 when every working mode is certified
    singularity-free, 1 when a singular pose is found, 3 when undecided.

    \b
    Examples:
      fivebar verify configs/rrr3-symmetric.yaml --working-mode +-+ -o out/rrr3-verify     # exit 1: a singular pose is found
      fivebar verify configs/rpr3-verify/table1-legs-1-1.5.yaml -o out/rpr3-verify
    """
    m = load_pose_kind(config_path)
    sheets_chosen(m, working_mode)
    folder = prepare_out(out, m.name)
    checked = fb_verify(m, depth, working_mode=working_mode)
    paths = save_files(checked, folder, no_plot)
    for line in checked.notes:
        report(quiet, line)
    wrote(quiet, paths)
    if checked.exit_code:
        raise click.exceptions.Exit(checked.exit_code)
