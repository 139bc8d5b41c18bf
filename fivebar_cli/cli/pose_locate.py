"""`fivebar locate` for a kind whose aspects live in one space of poses: the aspect and class of a
pose, or of every pose of given joint values (reached through `cli/dispatch.py`)."""

from __future__ import annotations

import click

from fivebar_cli.api.locations import locate as fb_locate
from fivebar_cli.cli.numbers import NUMBER
from fivebar_cli.cli.options import option_errors, reuse_options
from fivebar_cli.cli.poses import (
    CONFIG, joints_options, load_pose_kind, pose_budget_option, pose_depth_option, working_mode_option,
)
from fivebar_cli.io.layout import output_dir


@click.command("locate", short_help="Aspect and class of a pose, or of every pose of given joints.")
@click.argument("config_path", metavar="CONFIG", type=CONFIG)
@click.option("--pose", "poses", type=(NUMBER, NUMBER, NUMBER), multiple=True, metavar="X Y PHI",
              help="A pose (phi in degrees). Repeatable.")
@joints_options
@working_mode_option
@pose_depth_option
@pose_budget_option
@reuse_options("poses")
@option_errors()
def pose_locate(config_path, poses, joints, legs, working_mode, depth, budget, out, as_csv):
    """Which aspect and which class (the sign of det J of a 3-RPR; the working mode and sign of
    det A of a 3-RRR) a pose has; with --joints (--legs for a 3-RPR), every pose of those joint
    values (its assembly modes) and theirs. A 3-RRR pose is located in every working mode, or in
    the one of --working-mode. With two or more locations, says which can be joined without
    crossing a singularity (they share an aspect). With joint limits or obstacles (a 3-RRR), a
    pose that violates one in a working mode is in no aspect there: the report says which, and
    --csv adds a violates column.

    \b
    Examples:
      fivebar locate configs/rpr3-caro.yaml --pose -5.4962 -13.9353 -2.7121 --depth 6 -o out/caro
      fivebar locate configs/rpr3-caro.yaml --legs 14.98 15.38 12 --depth 6 -o out/caro
      fivebar locate configs/rrr3-symmetric.yaml --pose 5 2.887 10 --working-mode +-+ --depth 2 --budget 0 -o out/rrr3-symmetric
    """
    if not poses and not joints and not legs:
        raise click.UsageError("give at least one --pose X Y PHI or --joints J1 J2 J3 (--legs R1 R2 R3)")
    m = load_pose_kind(config_path, poses=True, depth=depth)
    with option_errors(working_mode="--working-mode", joints="--joints", legs="--legs"):
        found = fb_locate(m, pose=list(poses) or None, legs=list(legs) or None, joints=list(joints) or None,
                          depth=depth, working_mode=working_mode, budget=budget, folder=output_dir(out, m.name),
                          source=str(config_path))
    if as_csv:
        click.echo(found.csv(), nl=False)
        return
    for line in found.lines():
        click.echo(line)
