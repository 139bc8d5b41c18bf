"""What the commands over a space of poses share (`aspects`, `locate`, `path`, `dkp` and `verify` of
a 3-RPR or a 3-RRR; not a command): CONFIG loaded and checked, their options (`--depth` up to an
octree's limit, `--budget`, `--joints` and `--legs`, `--working-mode`), the working modes chosen,
the aspects reused or computed, joint values solved into their assembly modes and dkp.csv's rows.

Joint values are given with `--joints` in the units of the kind's joint axes (leg lengths for a
3-RPR, which also takes `--legs`; actuated angles in degrees for a 3-RRR). A kind whose pose does
not decide its class (a 3-RRR: a pose is reached in eight working modes) takes `--working-mode`
to choose the sheet of a `--pose`; the joints of a `--joints` location decide it themselves."""

from __future__ import annotations

from pathlib import Path

import click

from fivebar_cli.analyses.dkp import DkpResult, solve
from fivebar_cli.analyses.pose_aspect_files import load_pose_aspects, pose_columns
from fivebar_cli.analyses.pose_aspects import analyse_pose_aspects, aspect_at, sheet_of, working_sheets
from fivebar_cli.cli.numbers import NUMBER
from fivebar_cli.cli.options import MAX_ASPECT_DEPTH, budget_option, option_errors
from fivebar_cli.io.schema import ConfigError
from fivebar_cli.mechanisms.base import Mechanism
from fivebar_cli.mechanisms.registry import load_config

MAX_POSE_DEPTH = 9  # octree aspects: about 4x the time and memory per level (depth 8: 40 s, 0.7 GiB; 9: ~3 GiB)
MAX_PLANE_DEPTH = MAX_ASPECT_DEPTH  # quadtree aspects (a single orientation): as the five-bar's
DEFAULT_POSE_DEPTH = 7
CONFIG = click.Path(path_type=Path, dir_okay=False)


def load_pose_kind(config_path, poses: bool = False, depth: int | None = None) -> Mechanism:
    """A mechanism with a pose-space aspect model; with `poses`, one whose space of poses has the
    three axes (x, y, phi) that --pose and --legs need; with `depth`, one its trees can be paved to
    (at most MAX_POSE_DEPTH for an octree). One line naming the field otherwise."""
    m = load_config(config_path)
    source = str(config_path)
    model = m.pose_aspect_model()
    if model is None:
        raise ConfigError(source, "legs.rho_max", f"this {m.kind} has no bounded space of poses to pave "
                          "(give rho_max)")
    space = m.spaces()[model.space]
    for axis in space.axes:
        if axis.unit == "deg" and axis.hi - axis.lo > 360.0:
            raise ConfigError(source, "phi_range", f"[{axis.lo:g}, {axis.hi:g}] is wider than a full turn: aspects "
                              "need at most one turn (a full turn is [phi1, phi1 + 360], e.g. [-180, 180])")
    if poses and space.dim != 3:
        raise ConfigError(source, "phi", f"a single orientation: the poses (x, y, phi) of locate, path and dkp "
                          f"need an orientation range (phi_range), the space here has {space.dim} axes")
    if depth is not None and space.dim > 2 and depth > MAX_POSE_DEPTH:
        raise click.BadParameter(f"{depth} is too deep for an octree of poses (at most {MAX_POSE_DEPTH}: about 4x the "
                                 f"time and memory per level; up to {MAX_PLANE_DEPTH} for a single orientation)",
                                 param_hint="'--depth' / '-d'")
    return m


def pose_budget_option(func):
    return budget_option(func, help="Box evaluations that local refinement below --depth may spend to join or separate "
                                    "pieces.")


def pose_depth_option(func):
    return click.option("--depth", "-d", type=click.IntRange(0, MAX_PLANE_DEPTH), default=DEFAULT_POSE_DEPTH,
                        show_default=True, help=f"Depth of the trees (cells are root/2^d wide; 0..{MAX_POSE_DEPTH} for "
                                                f"an octree, 0..{MAX_PLANE_DEPTH} for a single orientation).")(func)


def numbers(values) -> str:
    return ", ".join(f"{v:g}" for v in values)


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


def class_values(model, cls: int, sheet: int) -> list[str]:
    """The class's field values for a CSV row; for no certified class, the sheet's fields and '0'."""
    if cls >= 0:
        return [v for _, v in model.classes[cls].fields]
    known = dict(model.sheets[sheet].fields)
    return [known.get(k, "0") for k, _ in model.classes[0].fields]


def aspects_for(m: Mechanism, folder: Path | None, depth: int, budget: int):
    """(aspects, source): the trees an `aspects` run saved in the folder for this mechanism and
    depth, or computed ones."""
    saved = load_pose_aspects(folder, m, depth) if folder is not None and folder.is_dir() else None
    if saved is not None:
        return saved, f"read from {folder}"
    return analyse_pose_aspects(m, depth, budget=budget).aspects, "computed"


# ---------------------------------------------------------------- joint values and their assembly modes


def check_joints(m: Mechanism, joints, option: str = "--legs") -> None:
    """Exit 2 for joint values out of their ranges."""
    for axis, value in zip(m.pose_aspect_model().joint_axes, joints):
        if not axis.periodic and not axis.lo <= value <= axis.hi:
            raise click.BadParameter(f"{axis.name} = {value:g} is outside its range [{axis.lo:g}, {axis.hi:g}]",
                                     param_hint=option)


def solve_joints(m: Mechanism, joints, source: str, option: str = "--legs") -> DkpResult:
    """Every pose with these joint values; InputError (exit 2) for values out of their ranges or
    that give no pose at all (certified)."""
    model = m.pose_aspect_model()
    check_joints(m, joints, option)
    result = solve(model, m.spaces()[model.space], joints)
    if not result.solutions and result.certified:
        raise click.BadParameter(f"({numbers(joints)}) give no pose within the space of poses (certified: every "
                                 "box of poses is proven to hold none)", param_hint=option)
    return result


def solution_aspect(model, aspects, solution):
    """The aspect holding a DKP solution in its certified class (None: no certified class, or in no
    certified cell at that depth)."""
    if aspects is None or solution.cls < 0:
        return None
    cls, aspect = aspect_at(aspects, model, solution.pose, sheet_of(model, solution.cls))
    return aspect if cls == solution.cls else None


def dkp_rows(m: Mechanism, result: DkpResult, aspects) -> list[tuple]:
    """dkp.csv rows: every certified pose with its class's fields, its aspect (empty: in no
    certified cell at that depth) and `true`; then every undecided box (its centre) with `false`."""
    model = m.pose_aspect_model()
    rows = []
    for s in result.solutions:
        fields = tuple(v for _, v in model.classes[s.cls].fields) if s.cls >= 0 else ("0",) * len(model.classes[0].fields)
        aspect = solution_aspect(model, aspects, s)
        rows.append((*s.pose, *fields, aspect.number if aspect is not None else "", "true"))
    for lo, hi in zip(result.undecided_lo, result.undecided_hi):
        rows.append((*(0.5 * (lo + hi)), *("",) * len(model.classes[0].fields), "", "false"))
    return rows


def dkp_header(m: Mechanism) -> tuple[str, ...]:
    model = m.pose_aspect_model()
    return (*pose_columns(m), *(k for k, _ in model.classes[0].fields), "aspect", "certified")
