"""What the commands over a space of poses share (`aspects`, `locate`, `path`, `dkp` and `verify` of
a 3-RPR or a 3-RRR; not a command): CONFIG loaded and checked, their options (`--depth` up to an
octree's limit, `--budget`, `--joints` and `--legs`, `--working-mode`) and the working modes
chosen; the work itself is the API's (`api/poses.py`).

Joint values are given with `--joints` in the units of the kind's joint axes (leg lengths for a
3-RPR, which also takes `--legs`; actuated angles in degrees for a 3-RRR). A kind whose pose does
not decide its class (a 3-RRR: a pose is reached in eight working modes) takes `--working-mode`
to choose the sheet of a `--pose`; the joints of a `--joints` location decide it themselves."""

from __future__ import annotations

import click

from fivebar_cli.analyses.limits import MAX_PLANE_DEPTH, MAX_POSE_DEPTH
from fivebar_cli.analyses.pose_aspects import working_sheets
from fivebar_cli.api.calls import load
from fivebar_cli.api.pose_space import DEFAULT_POSE_DEPTH, pose_mechanism
from fivebar_cli.cli.numbers import NUMBER
from fivebar_cli.cli.options import CONFIG, budget_option, option_errors  # noqa: F401 - CONFIG: the pose commands
from fivebar_cli.mechanisms.base import Mechanism



def load_pose_kind(config_path, poses: bool = False, depth: int | None = None) -> Mechanism:
    """CONFIG's mechanism, checked by `api.poses.pose_mechanism` (a space of poses; with `poses`,
    one with an orientation range; with `depth`, one its trees can be paved to), a depth too deep
    named as --depth."""
    with option_errors(depth="'--depth' / '-d'"):
        return pose_mechanism(load(config_path), poses=poses, depth=depth, source=str(config_path))


def pose_budget_option(func):
    return budget_option(func, help="Box evaluations that local refinement below --depth may spend to join or separate "
                                    "pieces.")


def pose_depth_option(func):
    return click.option("--depth", "-d", type=click.IntRange(0, MAX_PLANE_DEPTH), default=DEFAULT_POSE_DEPTH,
                        show_default=True, help=f"Depth of the trees (cells are root/2^d wide; 0..{MAX_POSE_DEPTH} for "
                                                f"an octree, 0..{MAX_PLANE_DEPTH} for a single orientation).")(func)


def joints_options(func):
    """`--joints J1 J2 J3` (any kind, the joint axes' units) and its 3-RPR spelling `--legs R1 R2 R3`."""
    func = click.option("--legs", "legs", type=(NUMBER, NUMBER, NUMBER), multiple=True, metavar="R1 R2 R3",
                        help="A 3-RPR's leg lengths (the same as --joints). Repeatable.")(func)
    return click.option("--joints", "joints", type=(NUMBER, NUMBER, NUMBER), multiple=True, metavar="J1 J2 J3",
                        help="Joint values: leg lengths (3-RPR), actuated angles in degrees (3-RRR). Repeatable.")(func)


def working_mode_option(func):
    return click.option("--working-mode", "working_mode", default=None, metavar="W",
                        help="A kind whose pose does not decide its class (3-RRR): the working mode of the "
                             "--pose locations, e.g. +-+ [default: every working mode].")(func)


def sheets_chosen(m: Mechanism, working_mode: str | None) -> list[int]:
    """The sheets a --pose is taken in: the one of --working-mode, else all of them (exit 2 when
    the kind has no such working mode)."""
    with option_errors(working_mode="--working-mode"):
        return working_sheets(m, working_mode)
