"""`fivebar path`: a certified singularity-free motion between two configurations."""

from __future__ import annotations

import click

from fivebar_cli.api.calls import check_serial
from fivebar_cli.api.calls import path as fb_path
from fivebar_cli.cli.numbers import JOINT, NUMBER, check_joints
from fivebar_cli.cli.options import (
    CONFIG, MAX_ASPECT_DEPTH, common_options, depth_option, load_with_aspects, option_errors, prepare_out, report,
    save_files, wrote,
)

WORKING_MODES = ["++", "+-", "-+", "--"]


def _record_order(ctx, param, value):
    """Click processes options in the order they first appear on the command line: remember it, so
    that `--pose A --joints B` starts at A and `--joints B --pose A` starts at B."""
    if value:
        ctx.meta.setdefault("path_order", []).append(param.name)
    return value


@click.command(short_help="A certified singularity-free motion between two configurations.")
@click.argument("config_path", metavar="CONFIG", type=CONFIG)
@click.option("--joints", "joints", type=(JOINT, JOINT), multiple=True, metavar="TH1 TH2", callback=_record_order,
              help="An endpoint by its joint values (radians, or degrees with the suffix deg: 30deg); its "
                   "assembly mode is --assembly-mode (or that of a --pose endpoint).")
@click.option("--pose", "poses", type=(NUMBER, NUMBER), multiple=True, metavar="X Y", callback=_record_order,
              help="An endpoint by the position of P, in the working mode of --working-mode.")
@click.option("--working-mode", "working_modes", type=click.Choice(WORKING_MODES), multiple=True,
              help="Working mode of the --pose endpoints: once for all, or once per --pose in order (needed "
                   "when several working modes reach a pose).")
@click.option("--assembly-mode", type=click.Choice(["+", "-"]), default=None,
              help="Assembly mode (sign of det A) of the --joints endpoints.")
@click.option("--allow-serial", is_flag=True,
              help="Allow crossing serial singularities (changing working mode), never parallel ones.")
@depth_option(limit=MAX_ASPECT_DEPTH)
@common_options
@option_errors()
def path(config_path, joints, poses, working_modes, assembly_mode, allow_serial, depth, out, no_plot, quiet):
    """A certified singularity-free motion between two configurations.

    Give two endpoints, --joints or --pose, in the order of the motion. Without --allow-serial
    the motion stays in one generalized aspect (no serial and no parallel singularity); with it,
    it may change working mode across serial singularities but never crosses a parallel one.
    The motion is a polyline in the joint space whose every straight segment is proven, in exact
    arithmetic, to lie in certified cells at --depth; it is the straight segment when that lies in
    the cells, else the shortest polyline through them found by string pulling. Angles are in
    radians, or in degrees with the suffix deg (--joints 30deg -45deg). Rows are in [-pi, pi);
    each segment goes the short way round on each angle. Writes
    path.csv (theta1,theta2,x,y per waypoint; the first and last rows are the requested
    configurations) and path.png. Reuses the aspect trees an `aspects` run wrote into -o for
    the same mechanism and depth. Exit status 1, with the reason, when no motion is found at this
    depth: "no" when none exists (proven), "not decided at depth D" (with what to try) otherwise.

    \b
    Examples:
      fivebar path configs/m1.yaml --joints -0.1 -2.06 --joints 0.88 1.47 --assembly-mode +
      fivebar path configs/m1.yaml --joints -5deg -120deg --joints 50deg 85deg --assembly-mode +
      fivebar path configs/m1.yaml --pose 4 5 --pose 6 8 --working-mode ++
      fivebar path configs/m1.yaml --joints 0.1 0.7 --joints -0.5 -3.1 --assembly-mode + --allow-serial
    """
    order = click.get_current_context().meta.get("path_order", [])
    values = {"joints": list(joints), "poses": list(poses)}
    if len(joints) + len(poses) != 2:
        raise click.UsageError("give exactly two endpoints (--joints TH1 TH2 or --pose X Y, twice in all)")
    if working_modes and not poses:  # (taken without a word before)
        raise click.UsageError("--working-mode is that of a --pose endpoint: joints decide their own working mode")
    if working_modes and len(working_modes) not in (1, len(poses)):
        raise click.UsageError(f"give --working-mode once, or once per --pose ({len(poses)})")
    pose_modes = list(working_modes) * len(poses) if len(working_modes) == 1 else list(working_modes) or [None] * len(poses)
    ends = [{"pose": value, "working_mode": pose_modes[k]} if name == "poses" else {"joints": value}
            for name in order for k, value in enumerate(values[name])]
    m = load_with_aspects(config_path)
    check_joints(m, joints, config_path)
    check_serial(m, allow_serial, config_path)
    folder = prepare_out(out, m.name)
    motion = fb_path(m, *ends, depth=depth, allow_serial=allow_serial, assembly_mode=assembly_mode, folder=folder,
                     source=str(config_path))
    paths = save_files(motion, folder, no_plot)
    for line in motion.notes:
        report(quiet, line)
    wrote(quiet, paths)
