"""`fivebar aspects | locate | path` for a kind whose aspects live in one space of poses (the
3-RPR over (x, y, phi); reached through `cli/dispatch.py`), and `fivebar rpr3 dkp`: every pose
with given leg lengths, certified."""

from __future__ import annotations

from pathlib import Path

import click
import numpy as np

from fivebar_cli.analyses.aspect_files import aspect_set
from fivebar_cli.analyses.dkp import DkpResult, solve
from fivebar_cli.analyses.pose_aspect_files import (
    joint_columns, load_pose_aspects, pose_columns, write_pose_aspects,
)
from fivebar_cli.analyses.pose_aspects import DEFAULT_BUDGET, analyse_pose_aspects, aspect_at
from fivebar_cli.analyses.pose_paths import check_pose, find_motion, wrap_pose
from fivebar_cli.cli.options import common_options, figure, jobs_option, prepare_out, progress, report, wrote
from fivebar_cli.io.files import csv_text, write_csv, write_text
from fivebar_cli.io.layout import DKP_CSV, DKP_FILES, DKP_PNG, PATH_CSV, PATH_FILES, PATH_PNG, output_dir
from fivebar_cli.io.outputs import output_set
from fivebar_cli.io.schema import ConfigError
from fivebar_cli.mechanisms.base import Mechanism
from fivebar_cli.mechanisms.registry import load_config

MAX_POSE_DEPTH = 9  # octree aspects: about 4x the time and memory per level (depth 8: 40 s, 0.7 GiB; 9: ~3 GiB)
DEFAULT_POSE_DEPTH = 7
CONFIG = click.Path(path_type=Path, dir_okay=False)


def load_pose_kind(config_path, poses: bool = False) -> Mechanism:
    """A mechanism with a pose-space aspect model; with `poses`, one whose space of poses has the
    three axes (x, y, phi) that --pose and --legs need. One line naming the field otherwise."""
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
    return m


def _budget_option(func):
    return click.option(
        "--budget", type=click.IntRange(0, None), default=DEFAULT_BUDGET, show_default=True,
        help="Box evaluations that local refinement below --depth may spend to join or separate pieces.",
    )(func)


def _depth_option(func):
    return click.option("--depth", "-d", type=click.IntRange(0, MAX_POSE_DEPTH), default=DEFAULT_POSE_DEPTH,
                        show_default=True, help=f"Depth of the trees (cells are root/2^d wide; 0..{MAX_POSE_DEPTH}).")(func)


def _numbers(values) -> str:
    return ", ".join(f"{v:g}" for v in values)


def _aspects_for(m: Mechanism, folder: Path | None, depth: int, budget: int):
    """(aspects, source): the trees an `aspects` run saved in the folder for this mechanism and
    depth, or computed ones."""
    saved = load_pose_aspects(folder, m, depth) if folder is not None and folder.is_dir() else None
    if saved is not None:
        return saved, f"read from {folder}"
    return analyse_pose_aspects(m, depth, budget=budget).aspects, "computed"


# ---------------------------------------------------------------- aspects


@click.command("aspects", short_help="Generalized aspects over a space of poses, with a certified count.")
@click.argument("config_path", metavar="CONFIG", type=CONFIG)
@_depth_option
@_budget_option
@jobs_option
@common_options
def pose_aspects(config_path, depth, budget, jobs, out, no_plot, quiet):
    """Generalized aspects of a 3-RPR over (x, y, phi): the connected components of the poses with
    every leg in its range and det J > 0, and of those with det J < 0.

    Paves the space of poses once per sign of det J (an octree; phi wraps around when the
    orientation range is a full turn, e.g. phi_range: [-180, 180]), takes the components of the
    certified cells (touching at a face, edge or corner), and certifies the count: inner and
    outer approximations, locally refined below --depth within --budget. Prints "N generalized
    aspects (certified)" or the bounds of an uncertified count. Writes aspects.csv
    (aspect,det_sign,volume,cells,x,y,phi_deg,rho1,rho2,rho3,certified: a pose inside each aspect
    and its leg lengths), aspects/aspect-NN.workspace.qt (each aspect's octree),
    aspects/aspect-NN.workspace.ply (its cells' closed surface, phi scaled as the header says) and
    aspects-slices.png (slices of each aspect at four orientations).

    \b
    Examples:
      fivebar aspects configs/rpr3-caro.yaml --depth 6 -o out/caro
      fivebar aspects configs/rpr3-caro.yaml --depth 5 --jobs 2 -o out/caro-jobs --no-plot
    """
    m = load_pose_kind(config_path)
    model = m.pose_aspect_model()
    folder = prepare_out(out, m.name)
    with progress(quiet, len(model.classes) + 1, f"aspects depth {depth}") as advance:
        analysis = analyse_pose_aspects(m, depth, advance, budget, jobs)
    with aspect_set(folder):
        paths = write_pose_aspects(folder, analysis)
        if not no_plot:
            from fivebar_cli.plotting.pose_aspects import figure_aspect_slices

            paths.append(figure(lambda: figure_aspect_slices(analysis), folder / "aspects-slices.png"))
    space = m.spaces()[model.space]
    unit = ("area" if space.dim == 2 else "volume") + " (" + " x ".join(a.unit or "length" for a in space.axes) + ")"
    report(quiet, analysis.headline())
    for a in analysis.aspects:
        report(quiet, f"  aspect {a.number:2d}: {a.signs.label}, {unit} {a.volume:.6g}, {len(a.tree)} cells, "
               f"({', '.join(ax.name for ax in space.axes)}) = ({_numbers(a.pose)}), "
               f"({', '.join(ax.name for ax in model.joint_axes)}) = ({_numbers(a.joints)})"
               + ("" if a.certified else " (not certified)"))
    if not analysis.aspects:
        report(quiet, f"  no aspect has certified cells at depth {depth}: a deeper paving finds thin ones "
                      f"(try --depth {min(depth + 1, MAX_POSE_DEPTH)})")
    wrote(quiet, paths)


# ---------------------------------------------------------------- dkp


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
        raise click.BadParameter(f"({_numbers(joints)}) give no pose within the space of poses (certified: every "
                                 "box of poses is proven to hold none)", param_hint=option)
    return result


def dkp_rows(m: Mechanism, result: DkpResult, aspects) -> list[tuple]:
    """dkp.csv rows: every certified pose with its class's fields, its aspect (empty: in no
    certified cell at that depth) and `true`; then every undecided box (its centre) with `false`."""
    model = m.pose_aspect_model()
    rows = []
    for s in result.solutions:
        fields = tuple(v for _, v in model.classes[s.cls].fields) if s.cls >= 0 else ("0",) * len(model.classes[0].fields)
        _, aspect = aspect_at(aspects, model, s.pose) if aspects is not None else (None, None)
        rows.append((*s.pose, *fields, aspect.number if aspect is not None else "", "true"))
    for lo, hi in zip(result.undecided_lo, result.undecided_hi):
        rows.append((*(0.5 * (lo + hi)), *("",) * len(model.classes[0].fields), "", "false"))
    return rows


def dkp_header(m: Mechanism) -> tuple[str, ...]:
    model = m.pose_aspect_model()
    return (*pose_columns(m), *(k for k, _ in model.classes[0].fields), "aspect", "certified")


@click.command("dkp", short_help="Every pose with given leg lengths (assembly modes), certified.")
@click.argument("config_path", metavar="CONFIG", type=CONFIG)
@click.option("--legs", type=(float, float, float), required=True, metavar="R1 R2 R3", help="The leg lengths.")
@_depth_option
@_budget_option
@common_options
def dkp(config_path, legs, depth, budget, out, no_plot, quiet):
    """Every pose (assembly mode) of a 3-RPR with the given leg lengths, certified.

    Branch and prune over the space of poses (x, y, phi) with the Krawczyk test: each pose is in
    a small box proven to hold exactly one solution, every other box is proven to hold none, so
    the number of assembly modes is certified (boxes left undecided, near a singular pose, are
    reported as such). Each pose comes with its sign of det J and its aspect (the aspects at
    --depth: read from -o when an `aspects` run saved them there, else computed). Writes dkp.csv
    (x,y,phi_deg,det_sign,aspect,certified; rows in the order the modes are numbered: det J > 0
    first, then by phi) and dkp.png (the robot in each mode). Exit 2 when the legs are outside
    their ranges or give no pose.

    \b
    Example:
      fivebar rpr3 dkp configs/rpr3-caro.yaml --legs 14.98 15.38 12 --depth 6 -o out/caro
    """
    m = load_pose_kind(config_path, poses=True)
    model = m.pose_aspect_model()
    result = solve_joints(m, legs, str(config_path))
    folder = prepare_out(out, m.name)
    aspects, source = _aspects_for(m, folder, depth, budget)
    rows = dkp_rows(m, result, aspects)
    n = len(result.solutions)
    if result.certified:
        report(quiet, f"{m.name}: {n} assembly modes for legs ({_numbers(legs)}) (certified: every other box of "
                      f"poses holds none; {result.evaluations} boxes tested)")
    else:
        report(quiet, f"{m.name}: {n} certified assembly modes for legs ({_numbers(legs)}), not decided: "
                      f"{len(result.undecided_lo)} boxes of poses left near singular poses (written with certified "
                      "false)")
    names = [a.name for a in m.spaces()[model.space].axes]
    for k, s in enumerate(result.solutions, start=1):
        where = f"aspect {rows[k - 1][-2]}" if rows[k - 1][-2] != "" else f"in no certified cell at depth {depth}"
        label = model.classes[s.cls].label if s.cls >= 0 else "sign not certified"
        report(quiet, f"  mode {k}: " + ", ".join(f"{a} = {v:.10g}" for a, v in zip(names, s.pose))
               + f", {label}, {where}")
    report(quiet, f"  aspects at depth {depth} {source}")
    with output_set(folder, "dkp", DKP_FILES, "fivebar rpr3 dkp"):
        paths = [write_csv(folder / DKP_CSV, dkp_header(m), rows)]
        if not no_plot and n:
            from fivebar_cli.plotting.pose_aspects import figure_assembly_modes

            labels = [f"mode {k}: {model.classes[s.cls].label if s.cls >= 0 else '?'}" for k, s in
                      enumerate(result.solutions, start=1)]
            title = f"{m.name}: the {n} assembly modes of legs ({_numbers(legs)})"
            poses = np.array([s.pose for s in result.solutions])
            paths.append(figure(lambda: figure_assembly_modes(model, poses, labels, title), folder / DKP_PNG))
    wrote(quiet, paths)


# ---------------------------------------------------------------- locate


@click.command("locate", short_help="Aspect and sign of det J of a pose, or of every pose of given legs.")
@click.argument("config_path", metavar="CONFIG", type=CONFIG)
@click.option("--pose", "poses", type=(float, float, float), multiple=True, metavar="X Y PHI",
              help="A pose (phi in degrees). Repeatable.")
@click.option("--legs", "legs", type=(float, float, float), multiple=True, metavar="R1 R2 R3",
              help="Leg lengths: every pose with them (certified, as `rpr3 dkp`). Repeatable.")
@_depth_option
@_budget_option
@click.option("--out", "-o", "out", type=click.Path(file_okay=False, path_type=Path), default=None,
              help="Folder of an earlier `aspects` run to reuse when it holds this mechanism at this depth "
                   "[default: outputs/<config name>/]; otherwise the aspects are computed (nothing is written).")
@click.option("--csv", "as_csv", is_flag=True, help="Print the poses as CSV.")
def pose_locate(config_path, poses, legs, depth, budget, out, as_csv):
    """Which aspect and which sign of det J a 3-RPR pose has; with --legs, every pose of those
    leg lengths (its assembly modes) and theirs. With two or more locations, says which can be
    joined without crossing a singularity (they share an aspect).

    \b
    Examples:
      fivebar locate configs/rpr3-caro.yaml --pose -5.4962 -13.9353 -2.7121 --depth 6 -o out/caro
      fivebar locate configs/rpr3-caro.yaml --legs 14.98 15.38 12 --depth 6 -o out/caro
    """
    if not poses and not legs:
        raise click.UsageError("give at least one --pose X Y PHI or --legs R1 R2 R3")
    m = load_pose_kind(config_path, poses=True)
    model = m.pose_aspect_model()
    space = m.spaces()[model.space]
    locations = [("pose", tuple(p)) for p in poses] + [("legs", tuple(r)) for r in legs]
    for kind, value in locations:  # exit 2 for bad input before anything is computed
        if kind == "pose":
            check_pose(m, wrap_pose(space, value), f"pose ({_numbers(value)})", str(config_path))
        else:
            check_joints(m, value)
    aspects, source = _aspects_for(m, output_dir(out, m.name), depth, budget)
    rows, notes = [], {}
    for k, (kind, value) in enumerate(locations, start=1):
        if kind == "pose":
            found = [wrap_pose(space, value)]
        else:
            result = solve_joints(m, value, str(config_path))
            found = [s.pose for s in result.solutions]
            notes[k] = "" if result.certified else f", {len(result.undecided_lo)} boxes of poses not decided"
        for pose in found:
            cls, aspect = aspect_at(aspects, model, pose)
            joints, _ = model.ikp(pose[None, :], max(cls, 0))
            rows.append({"input": k, "location": f"{kind} {' '.join(f'{v:g}' for v in value)}", "pose": pose,
                         "joints": joints[0], "cls": cls, "aspect": aspect})
    fields = [k for k, _ in model.classes[0].fields]
    if as_csv:
        header = ("input", "location", *pose_columns(m), *joint_columns(m), *fields, "aspect", "aspect_certified")
        table = [(r["input"], r["location"], *r["pose"], *r["joints"],
                  *([v for _, v in model.classes[r["cls"]].fields] if r["cls"] >= 0 else ["0"] * len(fields)),
                  r["aspect"].number if r["aspect"] else "",
                  ("true" if r["aspect"].certified else "false") if r["aspect"] else "") for r in rows]
        click.echo(csv_text(header, table), nl=False)
        return
    click.echo(f"{m.name}: aspects at depth {depth} {source}")
    names = [a.name for a in space.axes]
    for k, (kind, value) in enumerate(locations, start=1):
        mine = [r for r in rows if r["input"] == k]
        what = f"{kind} ({_numbers(value)})"
        if kind == "legs":
            what += f": {len(mine)} poses" + (" (certified)" if not notes[k] else notes[k])
        click.echo(f"location {k}: {what}")
        for r in mine:
            label = model.classes[r["cls"]].label if r["cls"] >= 0 else "on or near a singularity (no certified sign)"
            a = r["aspect"]
            where = (f"aspect {a.number}" + ("" if a.certified else " (not certified at this depth)") if a else
                     "in no certified cell at this depth" if r["cls"] >= 0 else "in no aspect")
            click.echo("  " + ", ".join(f"{n} = {v:.6g}" for n, v in zip(names, r["pose"])) + ", "
                       + ", ".join(f"{ax.name} = {v:.6g}" for ax, v in zip(model.joint_axes, r["joints"]))
                       + f": {label} -> {where}")
    if len(locations) >= 2:
        click.echo("singularity-free motions between locations:")
        held = {k: {r["aspect"].number for r in rows if r["input"] == k and r["aspect"]} for k in
                range(1, len(locations) + 1)}
        for i in range(1, len(locations) + 1):
            for j in range(i + 1, len(locations) + 1):
                shared = sorted(held[i] & held[j])
                click.echo(f"  {i} -> {j}: " + (f"yes, within aspect(s) {', '.join(map(str, shared))}" if shared else
                                               "no aspect holds a pose of both at this depth"))


# ---------------------------------------------------------------- path


def path_rows(result) -> list[tuple]:
    return [(*p, *j) for p, j in zip(result.poses, result.joints)]


def _exact(value: float) -> str:
    v = float(value)
    return "0" if v == 0 else repr(v)


@click.command("path", short_help="A certified singularity-free motion between two poses of a 3-RPR.")
@click.argument("config_path", metavar="CONFIG", type=CONFIG)
@click.option("--pose", "poses", type=(float, float, float), multiple=True, metavar="X Y PHI",
              help="An endpoint (phi in degrees); twice, in the order of the motion.")
@click.option("--legs", type=(float, float, float), default=None, metavar="R1 R2 R3",
              help="Leg lengths whose assembly modes --modes I J are the endpoints.")
@click.option("--modes", type=(int, int), default=None, metavar="I J",
              help="With --legs: from assembly mode I to mode J (numbered as in dkp.csv).")
@_depth_option
@common_options
def pose_path(config_path, poses, legs, modes, depth, out, no_plot, quiet):
    """A certified singularity-free motion of a 3-RPR between two poses, or between two assembly
    modes of the same leg lengths (a non-singular change of assembly mode, for a cuspidal robot).

    The motion is a polyline in (x, y, phi) through certified cells of one sign of det J (every
    pose in them has its legs in range and det J of that sign), each segment proven in exact
    arithmetic to lie in the cells; so both ends are in one aspect. Writes path.csv
    (x,y,phi_deg,rho1,rho2,rho3 per waypoint; the first and last rows are the endpoints, phi
    wrapped into a full turn's range, each step the short way round) and path.png (the robot along
    the motion, the legs against the path parameter). Exit 1 with the reason when no motion
    exists (different signs of det J, different certified aspects) or none is found at --depth
    ("not decided at depth D"); exit 2 for a pose outside the ranges, legs that give no pose,
    modes out of range.

    \b
    Examples:
      fivebar path configs/rpr3-caro.yaml --legs 14.98 15.38 12 --modes 1 2 --depth 6 -o out/caro
      fivebar path configs/rpr3-caro.yaml --pose -5.4962 -13.9353 -2.7121 --pose 8 -9 -5.6 --depth 6 -o out/caro
    """
    if legs is None and modes is not None:
        raise click.UsageError("--modes needs --legs R1 R2 R3")
    if legs is not None and (modes is None or poses):
        raise click.UsageError("give --legs R1 R2 R3 with --modes I J, or two --pose X Y PHI")
    if legs is None and len(poses) != 2:
        raise click.UsageError("give exactly two endpoints: --pose X Y PHI twice (or --legs with --modes)")
    m = load_pose_kind(config_path, poses=True)
    model = m.pose_aspect_model()
    space = m.spaces()[model.space]
    if legs is not None:
        result = solve_joints(m, legs, str(config_path))
        count = len(result.solutions)
        for mode in modes:
            if not 1 <= mode <= count:
                raise click.BadParameter(f"mode {mode} is out of range: legs ({_numbers(legs)}) have {count} "
                                         "assembly modes" + ("" if result.certified else " certified"),
                                         param_hint="--modes")
        ends = [result.solutions[k - 1].pose for k in modes]
        labels = tuple(f"assembly mode {k}" for k in modes)
    else:
        ends = [wrap_pose(space, p) for p in poses]
        labels = tuple(f"pose ({_numbers(p)})" for p in poses)
    folder = output_dir(out, m.name)
    saved = load_pose_aspects(folder, m, depth) if folder.is_dir() else None
    motion = find_motion(m, depth, ends[0], ends[1], labels, str(config_path), saved)
    folder = prepare_out(out, m.name)
    names = [*pose_columns(m), *joint_columns(m)]
    rows = [[_exact(v) for v in row] for row in path_rows(motion)]
    with output_set(folder, "path", PATH_FILES, "fivebar rpr3 path"):
        paths = [write_text(folder / PATH_CSV, csv_text(names, rows))]
        if not no_plot:
            from fivebar_cli.plotting.pose_aspects import figure_motion

            title = (f"{m.name}: a certified singularity-free motion, {model.classes[motion.cls].label}, "
                     f"{labels[0]} to {labels[1]}, depth {depth}")
            paths.append(figure(lambda: figure_motion(model, space, motion.motion.unwrapped(), motion.cls, title,
                                                      labels[0], labels[1]), folder / PATH_PNG))
    where = (f"aspect {motion.aspect.number}, {'certified' if motion.aspect.certified else 'not certified'}"
             if motion.aspect is not None else "one generalized aspect")
    report(quiet, f"{m.name}: singularity-free motion in {where}: {model.classes[motion.cls].label}, depth {depth}")
    report(quiet, f"  from {labels[0]} to {labels[1]}: {len(motion.poses)} waypoints, length {motion.length:.6g} "
                  f"({', '.join(a.name for a in space.axes)}); every segment lies in the certified cells "
                  f"({motion.motion.checked_cells} cells, checked in exact arithmetic)")
    if saved is not None:
        report(quiet, f"  aspect trees read from {folder}")
    wrote(quiet, paths)
