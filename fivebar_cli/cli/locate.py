"""`fivebar locate`: which aspect a configuration lies in, and whether two can be joined without
a singularity (the answer `path` shares: `analyses.locate.decide`)."""

from __future__ import annotations

import click

from fivebar_cli.api.locations import locate as locate_in
from fivebar_cli.cli.numbers import JOINT, NUMBER, check_joints
from fivebar_cli.cli.options import (
    CONFIG, MAX_ASPECT_DEPTH, as_flags, budget_option, depth_option, load_with_aspects, option_errors, reuse_options,
    tolerance_option,
)
from fivebar_cli.io.layout import output_dir


@click.command(short_help="Aspect of a configuration; singularity-free motion or not.")
@click.argument("config_path", metavar="CONFIG", type=CONFIG)
@click.option("--pose", "poses", type=(NUMBER, NUMBER), multiple=True, metavar="X Y",
              help="A position of P; all its configurations (working modes) are listed. Repeatable.")
@click.option("--joints", "joints", type=(JOINT, JOINT), multiple=True, metavar="TH1 TH2",
              help="Actuated joint values (radians for a five-bar, or degrees with the suffix deg: 30deg); every "
                   "assembly is listed. Repeatable.")
@click.option("--working-mode", type=click.Choice(["++", "+-", "-+", "--"]), default=None,
              help="Keep only configurations of this working mode.")
@click.option("--assembly-mode", type=click.Choice(["+", "-"]), default=None,
              help="Keep only configurations of this assembly mode.")
@depth_option(limit=MAX_ASPECT_DEPTH)
@budget_option
@tolerance_option
@reuse_options("configurations")
@option_errors()
def locate(config_path, poses, joints, working_mode, assembly_mode, depth, budget, tolerance, out, as_csv):
    """Which aspect a configuration lies in, and whether two can be joined without singularity.

    For each --pose (x, y), every configuration reaching it (up to four working modes); for
    each --joints, every assembly (up to two). Each is reported with its modes and its aspect
    (when the aspect's certified cells hold its joint values or its pose), or as on or near a
    singularity, or as in no certified cell at this depth. With two or more locations, each pair
    gets one answer: "yes" when one aspect holds a configuration of both (proven), "no" only when
    every motion between them is proven to cross a singularity (different modes, or two
    different certified aspects), else "not decided at depth D" with the reason and what to try.
    Angles are in radians, or in degrees with the suffix deg (--joints 30deg -45deg). The aspect
    trees that `aspects` wrote for the same mechanism and depth are reused. With interval lengths
    (or --tolerance T) the configurations are the nominal robot's and the aspects are robust: a
    "yes" is a motion singularity-free for every robot built within the tolerance. With joint
    limits or obstacles, a configuration that violates one is in no aspect and the report names
    the constraint (the `violates` column with --csv).

    \b
    Examples:
      fivebar locate configs/m1.yaml --pose 4 5
      fivebar locate configs/m1.yaml --pose 4 5 --pose 6 -3 --working-mode ++
      fivebar locate configs/m2.yaml --joints 0.1 1.4 --joints 1.5 1.2 --assembly-mode +
      fivebar locate configs/m2.yaml --joints 10deg 80deg --joints 20deg 70deg --assembly-mode +
      fivebar locate configs/m1.yaml --pose 4 5 --pose 6 -3 --tolerance 0.05
      fivebar locate configs/m1-obstacle.yaml --pose 4.5 1.5 --depth 8
    """
    if not poses and not joints:
        raise click.UsageError("give at least one --pose X Y or --joints TH1 TH2")
    m = load_with_aspects(config_path, tolerance)
    check_joints(m, joints, config_path)
    found = locate_in(m, pose=list(poses) or None, joints=list(joints) or None, depth=depth,
                      working_mode=working_mode, assembly_mode=assembly_mode, budget=budget,
                      folder=output_dir(out, m.name), source=str(config_path))
    if as_csv:
        click.echo(found.csv(), nl=False)
        return
    for line in found.lines():
        click.echo(as_flags(line))
