"""`fivebar dkp` (and its 3-RPR name `fivebar rpr3 dkp`): every pose with given joint values, certified."""

from __future__ import annotations

import click

from fivebar_cli.api.poses import dkp as fb_dkp
from fivebar_cli.cli.numbers import NUMBER
from fivebar_cli.cli.options import common_options, option_errors, prepare_out, report, save_files, wrote
from fivebar_cli.cli.poses import CONFIG, load_pose_kind, pose_budget_option, pose_depth_option


def run_dkp(config_path, joints, option: str, depth: int, budget: int, out, no_plot: bool, quiet: bool) -> None:
    """What `fivebar dkp` and `fivebar rpr3 dkp` do (`option`: how the joints were given)."""
    from fivebar_cli.api.pose_space import joint_poses

    m = load_pose_kind(config_path, poses=True, depth=depth)
    with option_errors(joints=option, legs=option):
        solved = joint_poses(m, joints, option[2:])  # bad joints are named before the output folder
        folder = prepare_out(out, m.name)
        found = fb_dkp(m, joints, depth, budget=budget, folder=folder, source=str(config_path), what=option[2:],
                       solved=solved)
    for line in found.notes:
        report(quiet, line)
    wrote(quiet, save_files(found, folder, no_plot))


@click.command("dkp", short_help="Every pose with given leg lengths (assembly modes), certified.")
@click.argument("config_path", metavar="CONFIG", type=CONFIG)
@click.option("--legs", type=(float, float, float), required=True, metavar="R1 R2 R3", help="The leg lengths.")
@pose_depth_option
@pose_budget_option
@common_options
@option_errors()
def dkp(config_path, legs, depth, budget, out, no_plot, quiet):
    """Every pose (assembly mode) of a 3-RPR with the given leg lengths, certified.

    Branch and prune over the space of poses (x, y, phi) with the Krawczyk test: each pose is in
    a small box proven to hold exactly one solution, every other box is proven to hold none, so
    the number of assembly modes is certified (boxes left undecided, near a singular pose, are
    reported as such). Each pose comes with its sign of det J and its aspect (the aspects at
    --depth: read from -o when an `aspects` run saved them there, else computed). Writes dkp.csv
    (x,y,phi_deg,det_sign,aspect,certified; rows in the order the modes are numbered: det J > 0
    first, then by phi) and dkp.png (the robot in each mode). Exit 2 when the legs are outside
    their ranges or give no pose. The same as `fivebar dkp CONFIG --joints R1 R2 R3`.

    \b
    Example:
      fivebar rpr3 dkp configs/rpr3-caro.yaml --legs 14.98 15.38 12 --depth 6 -o out/caro
    """
    run_dkp(config_path, legs, "--legs", depth, budget, out, no_plot, quiet)


@click.command("dkp", short_help="Every pose with given joint values (assembly modes), certified.")
@click.argument("config_path", metavar="CONFIG", type=CONFIG)
@click.option("--joints", type=(NUMBER, NUMBER, NUMBER), required=True, metavar="J1 J2 J3",
              help="The joint values: leg lengths (3-RPR), actuated angles in degrees (3-RRR).")
@pose_depth_option
@pose_budget_option
@common_options
@option_errors()
def joints_dkp(config_path, joints, depth, budget, out, no_plot, quiet):
    """Every pose (assembly mode) with the given joint values, certified, for a kind whose aspects
    live in a space of poses (x, y, phi): a 3-RPR's leg lengths (as `fivebar rpr3 dkp --legs`), a
    3-RRR's actuated angles theta1, theta2, theta3 in degrees (up to six poses).

    Branch and prune over the space of poses with the Krawczyk test: each pose is in a small box
    proven to hold exactly one solution, every other box is proven to hold none, so the number of
    assembly modes is certified (boxes left undecided, near a singular pose, are reported as
    such). Each pose comes with its class (a 3-RPR: the sign of det J; a 3-RRR: its working mode,
    which the joints decide, and the sign of det A) and its aspect (the aspects at --depth: read
    from -o when an `aspects` run saved them there, else computed). Writes dkp.csv (the pose
    columns x,y,phi_deg, the class columns, aspect, certified; rows in the order the modes are
    numbered: by class, then by phi) and dkp.png (the robot in each mode). Exit 2 when the joints
    are outside their ranges or give no pose. A 3-RRR with `working_mode:` set counts only the
    poses in that working mode.

    \b
    Examples:
      fivebar dkp configs/rrr3-symmetric.yaml --joints -35 -150 -155 --depth 2 --budget 0 -o out/rrr3-symmetric
      fivebar dkp configs/rpr3-caro.yaml --joints 14.98 15.38 12 --depth 6 -o out/caro
    """
    run_dkp(config_path, joints, "--joints", depth, budget, out, no_plot, quiet)
