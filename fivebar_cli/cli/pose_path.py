"""`fivebar path` for a kind whose aspects live in one space of poses: a certified singularity-free
motion between two poses, or two assembly modes of the same joints (reached through `cli/dispatch.py`)."""

from __future__ import annotations

import click

from fivebar_cli.api.calls import path as fb_path
from fivebar_cli.cli.numbers import NUMBER
from fivebar_cli.cli.options import common_options, option_errors, prepare_out, report, save_files, wrote
from fivebar_cli.cli.poses import CONFIG, load_pose_kind, pose_depth_option, working_mode_option
from fivebar_cli.io.layout import output_dir


@click.command("path", short_help="A certified singularity-free motion between two poses (3-RPR, 3-RRR).")
@click.argument("config_path", metavar="CONFIG", type=CONFIG)
@click.option("--pose", "poses", type=(NUMBER, NUMBER, NUMBER), multiple=True, metavar="X Y PHI",
              help="An endpoint (phi in degrees); twice, in the order of the motion.")
@click.option("--legs", type=(NUMBER, NUMBER, NUMBER), default=None, metavar="R1 R2 R3",
              help="A 3-RPR's leg lengths whose assembly modes --modes I J are the endpoints (as --joints).")
@click.option("--joints", type=(NUMBER, NUMBER, NUMBER), default=None, metavar="J1 J2 J3",
              help="Joint values whose assembly modes --modes I J are the endpoints (3-RRR: degrees).")
@click.option("--modes", type=(int, int), default=None, metavar="I J",
              help="With --joints (--legs): from assembly mode I to mode J (numbered as in dkp.csv).")
@working_mode_option
@pose_depth_option
@common_options
@option_errors()
def pose_path(config_path, poses, legs, joints, modes, working_mode, depth, out, no_plot, quiet):
    """A certified singularity-free motion of a 3-RPR or a 3-RRR between two poses, or between two
    assembly modes of the same joint values (a non-singular change of assembly mode, for a cuspidal
    robot). A 3-RRR's poses are taken in the working mode of --working-mode (required with --pose).

    The motion is a polyline in (x, y, phi) through certified cells of one class (every pose in
    them valid, with one sign of det J; one working mode and one sign of det A), each segment
    proven in exact arithmetic to lie in the cells; so both ends are in one aspect. Writes path.csv
    (x,y,phi_deg and the joints, rho1,rho2,rho3 or theta1_deg,theta2_deg,theta3_deg, per waypoint;
    the first and last rows are the endpoints, phi wrapped into a full turn's range, each step the
    short way round) and path.png (the robot along the motion, the joints against the path
    parameter). Exit 1 with the reason when no motion exists (different classes, different
    certified aspects) or none is found at --depth ("not decided at depth D"); exit 2 for a pose
    outside the ranges, joints that give no pose, modes out of range.

    \b
    Examples:
      fivebar path configs/rpr3-caro.yaml --legs 14.98 15.38 12 --modes 1 2 --depth 6 -o out/caro
      fivebar path configs/rpr3-caro.yaml --pose -5.4962 -13.9353 -2.7121 --pose 8 -9 -5.6 --depth 6 -o out/caro
    """
    if legs is not None and joints is not None:
        raise click.UsageError("give --joints or --legs, not both")
    option = "--legs" if legs is not None else "--joints"
    legs = legs if legs is not None else joints
    if legs is None and modes is not None:
        raise click.UsageError("--modes needs --legs R1 R2 R3 or --joints J1 J2 J3")
    if legs is not None and (modes is None or poses):
        raise click.UsageError(f"give {option} with --modes I J, or two --pose X Y PHI")
    if legs is None and len(poses) != 2:
        raise click.UsageError("give exactly two endpoints: --pose X Y PHI twice (or --joints with --modes)")
    m = load_pose_kind(config_path, poses=True, depth=depth)
    ends, given = (modes, {option[2:]: legs}) if legs is not None else (poses, {})
    with option_errors(working_mode="--working-mode", joints=option, legs=option, start="--modes", goal="--modes"):
        motion = fb_path(m, *ends, depth=depth, working_mode=working_mode, **given, folder=output_dir(out, m.name),
                         source=str(config_path))
    folder = prepare_out(out, m.name)
    paths = save_files(motion, folder, no_plot)
    for line in motion.notes:
        report(quiet, line)
    wrote(quiet, paths)
