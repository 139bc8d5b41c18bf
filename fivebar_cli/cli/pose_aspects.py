"""`fivebar aspects | locate | path` for a kind whose aspects live in one space of poses (the
3-RPR and the 3-RRR over (x, y, phi); reached through `cli/dispatch.py`), and `fivebar dkp` (with
its 3-RPR name `fivebar rpr3 dkp`): every pose with given joint values, certified.

Joint values are given with `--joints` in the units of the kind's joint axes (leg lengths for a
3-RPR, which also takes `--legs`; actuated angles in degrees for a 3-RRR). A kind whose pose does
not decide its class (a 3-RRR: a pose is reached in eight working modes) takes `--working-mode`
to choose the sheet of a `--pose`; the joints of a `--joints` location decide it themselves."""

from __future__ import annotations

from pathlib import Path

import click
import numpy as np

from fivebar_cli.analyses.aspect_files import aspect_set
from fivebar_cli.analyses.dkp import DkpResult, solve
from fivebar_cli.analyses.pose_aspect_files import (
    joint_columns, load_pose_aspects, pose_columns, write_pose_aspects,
)
from fivebar_cli.analyses.pose_aspects import (
    DEFAULT_BUDGET, analyse_pose_aspects, aspect_at, sheet_classes, sheet_of,
)
from fivebar_cli.analyses.pose_paths import check_pose, find_motion, wrap_pose
from fivebar_cli.cli.options import MAX_ASPECT_DEPTH, NUMBER, common_options, figure, prepare_out, progress, report, wrote
from fivebar_cli.io.files import csv_text, write_csv, write_text
from fivebar_cli.io.layout import DKP_CSV, DKP_FILES, DKP_PNG, PATH_CSV, PATH_FILES, PATH_PNG, output_dir
from fivebar_cli.io.outputs import output_set
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


def _budget_option(func):
    return click.option(
        "--budget", type=click.IntRange(0, None), default=DEFAULT_BUDGET, show_default=True,
        help="Box evaluations that local refinement below --depth may spend to join or separate pieces.",
    )(func)


def _depth_option(func):
    return click.option("--depth", "-d", type=click.IntRange(0, MAX_PLANE_DEPTH), default=DEFAULT_POSE_DEPTH,
                        show_default=True, help=f"Depth of the trees (cells are root/2^d wide; 0..{MAX_POSE_DEPTH} for "
                                                f"an octree, 0..{MAX_PLANE_DEPTH} for a single orientation).")(func)


def _numbers(values) -> str:
    return ", ".join(f"{v:g}" for v in values)


def _joints_options(func):
    """`--joints J1 J2 J3` (any kind, the joint axes' units) and its 3-RPR spelling `--legs R1 R2 R3`."""
    func = click.option("--legs", "legs", type=(NUMBER, NUMBER, NUMBER), multiple=True, metavar="R1 R2 R3",
                        help="A 3-RPR's leg lengths (the same as --joints). Repeatable.")(func)
    return click.option("--joints", "joints", type=(NUMBER, NUMBER, NUMBER), multiple=True, metavar="J1 J2 J3",
                        help="Joint values: leg lengths (3-RPR), actuated angles in degrees (3-RRR). Repeatable.")(func)


def _working_mode_option(func):
    return click.option("--working-mode", "working_mode", default=None, metavar="W",
                        help="A kind whose pose does not decide its class (3-RRR): the working mode of the "
                             "--pose locations, e.g. +-+ [default: every working mode].")(func)


def sheets_chosen(m: Mechanism, working_mode: str | None) -> list[int]:
    """The sheets a --pose is taken in: the one of --working-mode, else all of them (exit 2 when
    the kind has no such working mode)."""
    model = m.pose_aspect_model()
    if working_mode is None:
        return list(range(len(model.sheets)))
    found = [k for k, sheet in enumerate(model.sheets) if dict(sheet.fields).get("working_mode") == working_mode]
    if not found:
        modes = [dict(sheet.fields).get("working_mode") for sheet in model.sheets]
        known = ", ".join(mode for mode in modes if mode) or "none: its pose decides its class"
        raise click.BadParameter(f"{working_mode!r} is not a working mode of this {m.kind} (its working modes: "
                                 f"{known})", param_hint="--working-mode")
    return found


def class_values(model, cls: int, sheet: int) -> list[str]:
    """The class's field values for a CSV row; for no certified class, the sheet's fields and '0'."""
    if cls >= 0:
        return [v for _, v in model.classes[cls].fields]
    known = dict(model.sheets[sheet].fields)
    return [known.get(k, "0") for k, _ in model.classes[0].fields]


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
@common_options
def pose_aspects(config_path, depth, budget, out, no_plot, quiet):
    """Generalized aspects of a 3-RPR over (x, y, phi): the connected components of the poses with
    every leg in its range and det J > 0, and of those with det J < 0; of a 3-RRR, per working mode,
    of the poses with every leg strictly inside its annulus and det A > 0, resp. < 0.

    Paves the space of poses once per class (sign of det J; working mode and sign of det A: an
    octree, phi wrapping around when the orientation range is a full turn, e.g. phi_range:
    [-180, 180]; a quadtree of (x, y) for a single orientation, phi: X), takes the components of
    the certified cells (touching at a face, edge or corner), and certifies the count: inner and
    outer approximations, locally refined below --depth within --budget. Prints "N generalized
    aspects (certified)" or the bounds of an uncertified count. Writes aspects.csv
    (aspect,det_sign,volume,cells,x,y,phi_deg,rho1,rho2,rho3,certified for a 3-RPR: a pose inside
    each aspect and its joints; aspect,working_mode,det_sign,...,theta1_deg,theta2_deg,theta3_deg,
    certified for a 3-RRR), aspects/aspect-NN.workspace.qt (each aspect's tree),
    aspects/aspect-NN.workspace.ply (an octree's cells as a closed surface, phi scaled as the
    header says), aspects-slices.png (slices of each aspect at four orientations) and
    aspects-map.png (every aspect in its colour, one panel per working mode, at one orientation;
    undetermined cells dark: the singularity curves and the workspace boundary).

    \b
    Examples:
      fivebar aspects configs/rpr3-caro.yaml --depth 6 -o out/caro
      fivebar aspects configs/rrr3-symmetric-phi0.yaml --depth 6 --no-plot -o out/rrr3-phi0
    """
    m = load_pose_kind(config_path, depth=depth)
    model = m.pose_aspect_model()
    folder = prepare_out(out, m.name)
    with progress(quiet, len(model.classes) + 1, f"aspects depth {depth}") as advance:
        analysis = analyse_pose_aspects(m, depth, advance, budget)
    with aspect_set(folder):
        paths = write_pose_aspects(folder, analysis)
        if not no_plot:
            from fivebar_cli.plotting.pose_aspects import figure_aspect_map, figure_aspect_slices

            paths.append(figure(lambda: figure_aspect_slices(analysis), folder / "aspects-slices.png"))
            paths.append(figure(lambda: figure_aspect_map(analysis), folder / "aspects-map.png"))
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
                      f"(try --depth {depth + 1})")
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


def run_dkp(config_path, joints, option: str, depth: int, budget: int, out, no_plot: bool, quiet: bool) -> None:
    """What `fivebar dkp` and `fivebar rpr3 dkp` do (`option`: how the joints were given)."""
    m = load_pose_kind(config_path, poses=True, depth=depth)
    model = m.pose_aspect_model()
    result = solve_joints(m, joints, str(config_path), option)
    folder = prepare_out(out, m.name)
    aspects, source = _aspects_for(m, folder, depth, budget)
    rows = dkp_rows(m, result, aspects)
    n = len(result.solutions)
    what = "legs" if option == "--legs" else "joints"
    if result.certified:
        report(quiet, f"{m.name}: {n} assembly modes for {what} ({_numbers(joints)}) (certified: every other box of "
                      f"poses holds none; {result.evaluations} boxes tested)")
    else:
        report(quiet, f"{m.name}: {n} certified assembly modes for {what} ({_numbers(joints)}), not decided: "
                      f"{len(result.undecided_lo)} boxes of poses left near singular poses (written with certified "
                      "false)")
    names = [a.name for a in m.spaces()[model.space].axes]
    for k, s in enumerate(result.solutions, start=1):
        where = f"aspect {rows[k - 1][-2]}" if rows[k - 1][-2] != "" else f"in no certified cell at depth {depth}"
        label = model.classes[s.cls].label if s.cls >= 0 else "sign not certified"
        report(quiet, f"  mode {k}: " + ", ".join(f"{a} = {v:.10g}" for a, v in zip(names, s.pose))
               + f", {label}, {where}")
    report(quiet, f"  aspects at depth {depth} {source}")
    with output_set(folder, "dkp", DKP_FILES, "fivebar rpr3 dkp" if option == "--legs" else "fivebar dkp"):
        paths = [write_csv(folder / DKP_CSV, dkp_header(m), rows)]
        if not no_plot and n:
            from fivebar_cli.plotting.pose_aspects import figure_assembly_modes

            labels = [f"mode {k}: {model.classes[s.cls].label if s.cls >= 0 else '?'}" for k, s in
                      enumerate(result.solutions, start=1)]
            title = f"{m.name}: the {n} assembly modes of {what} ({_numbers(joints)})"
            poses = np.array([s.pose for s in result.solutions])
            classes = np.array([max(s.cls, 0) for s in result.solutions])
            paths.append(figure(lambda: figure_assembly_modes(model, poses, labels, title, classes), folder / DKP_PNG))
    wrote(quiet, paths)


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
@_depth_option
@_budget_option
@common_options
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


# ---------------------------------------------------------------- locate


@click.command("locate", short_help="Aspect and class of a pose, or of every pose of given joints.")
@click.argument("config_path", metavar="CONFIG", type=CONFIG)
@click.option("--pose", "poses", type=(NUMBER, NUMBER, NUMBER), multiple=True, metavar="X Y PHI",
              help="A pose (phi in degrees). Repeatable.")
@_joints_options
@_working_mode_option
@_depth_option
@_budget_option
@click.option("--out", "-o", "out", type=click.Path(file_okay=False, path_type=Path), default=None,
              help="Folder of an earlier `aspects` run to reuse when it holds this mechanism at this depth "
                   "[default: outputs/<config name>/]; otherwise the aspects are computed (nothing is written).")
@click.option("--csv", "as_csv", is_flag=True, help="Print the poses as CSV.")
def pose_locate(config_path, poses, joints, legs, working_mode, depth, budget, out, as_csv):
    """Which aspect and which class (the sign of det J of a 3-RPR; the working mode and sign of
    det A of a 3-RRR) a pose has; with --joints (--legs for a 3-RPR), every pose of those joint
    values (its assembly modes) and theirs. A 3-RRR pose is located in every working mode, or in
    the one of --working-mode. With two or more locations, says which can be joined without
    crossing a singularity (they share an aspect).

    \b
    Examples:
      fivebar locate configs/rpr3-caro.yaml --pose -5.4962 -13.9353 -2.7121 --depth 6 -o out/caro
      fivebar locate configs/rpr3-caro.yaml --legs 14.98 15.38 12 --depth 6 -o out/caro
      fivebar locate configs/rrr3-symmetric.yaml --pose 5 2.887 10 --working-mode +-+ --depth 2 --budget 0 -o out/rrr3-symmetric
    """
    joint_sets = [("legs", tuple(r)) for r in legs] + [("joints", tuple(j)) for j in joints]
    if not poses and not joint_sets:
        raise click.UsageError("give at least one --pose X Y PHI or --joints J1 J2 J3 (--legs R1 R2 R3)")
    m = load_pose_kind(config_path, poses=True, depth=depth)
    model = m.pose_aspect_model()
    space = m.spaces()[model.space]
    sheets = sheets_chosen(m, working_mode)
    locations = [("pose", tuple(p)) for p in poses] + joint_sets
    for kind, value in locations:  # exit 2 for bad input before anything is computed
        if kind == "pose":
            check_pose(m, wrap_pose(space, value), f"pose ({_numbers(value)})", str(config_path))
        else:
            check_joints(m, value, f"--{kind}")
    aspects, source = _aspects_for(m, output_dir(out, m.name), depth, budget)
    rows, notes = [], {}
    for k, (kind, value) in enumerate(locations, start=1):
        if kind == "pose":
            found = [(wrap_pose(space, value), sheet, None) for sheet in sheets]
        else:
            result = solve_joints(m, value, str(config_path), f"--{kind}")
            found = [(s.pose, sheet_of(model, s.cls) if s.cls >= 0 else 0, s.cls) for s in result.solutions]
            notes[k] = "" if result.certified else f", {len(result.undecided_lo)} boxes of poses not decided"
        for pose, sheet, known in found:
            cls, aspect = aspect_at(aspects, model, pose, sheet)
            if known is not None and cls != known:  # the joints decided: a certified class elsewhere, or none
                cls, aspect = known, None if known < 0 else aspect
            joints_at, _ = model.ikp(pose[None, :], cls if cls >= 0 else sheet_classes(model, sheet)[0])
            rows.append({"input": k, "location": f"{kind} {' '.join(f'{v:g}' for v in value)}", "pose": pose,
                         "joints": joints_at[0], "cls": cls, "sheet": sheet, "aspect": aspect})
    fields = [k for k, _ in model.classes[0].fields]
    if as_csv:
        header = ("input", "location", *pose_columns(m), *joint_columns(m), *fields, "aspect", "aspect_certified")
        table = [(r["input"], r["location"], *r["pose"], *r["joints"], *class_values(model, r["cls"], r["sheet"]),
                  r["aspect"].number if r["aspect"] else "",
                  ("true" if r["aspect"].certified else "false") if r["aspect"] else "") for r in rows]
        click.echo(csv_text(header, table), nl=False)
        return
    click.echo(f"{m.name}: aspects at depth {depth} {source}")
    names = [a.name for a in space.axes]
    for k, (kind, value) in enumerate(locations, start=1):
        mine = [r for r in rows if r["input"] == k]
        what = f"{kind} ({_numbers(value)})"
        if kind != "pose":
            what += f": {len(mine)} poses" + (" (certified)" if not notes[k] else notes[k])
        click.echo(f"location {k}: {what}")
        for r in mine:
            sheet = model.sheets[r["sheet"]].label
            label = (model.classes[r["cls"]].label if r["cls"] >= 0 else
                     (f"{sheet}: " if sheet else "") + "on or near a singularity (no certified sign)")
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
@_working_mode_option
@_depth_option
@common_options
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
    model = m.pose_aspect_model()
    space = m.spaces()[model.space]
    if legs is not None:
        result = solve_joints(m, legs, str(config_path), option)
        count = len(result.solutions)
        for mode in modes:
            if not 1 <= mode <= count:
                raise click.BadParameter(f"mode {mode} is out of range: {option[2:]} ({_numbers(legs)}) have {count} "
                                         "assembly modes" + ("" if result.certified else " certified"),
                                         param_hint="--modes")
        ends = [result.solutions[k - 1].pose for k in modes]
        sheets = tuple(sheet_of(model, result.solutions[k - 1].cls) if result.solutions[k - 1].cls >= 0 else 0
                       for k in modes)
        labels = tuple(f"assembly mode {k}" for k in modes)
    else:
        chosen = sheets_chosen(m, working_mode)
        if len(chosen) > 1:
            raise click.BadParameter(f"a {m.kind} pose is reached in {len(chosen)} working modes: say which one "
                                     "(e.g. --working-mode " + dict(model.sheets[0].fields)["working_mode"] + ")",
                                     param_hint="--working-mode")
        ends = [wrap_pose(space, p) for p in poses]
        sheets = (chosen[0], chosen[0])
        labels = tuple(f"pose ({_numbers(p)})" for p in poses)
    folder = output_dir(out, m.name)
    saved = load_pose_aspects(folder, m, depth) if folder.is_dir() else None
    motion = find_motion(m, depth, ends[0], ends[1], labels, str(config_path), saved, sheets)
    folder = prepare_out(out, m.name)
    names = [*pose_columns(m), *joint_columns(m)]
    rows = [[_exact(v) for v in row] for row in path_rows(motion)]
    with output_set(folder, "path", PATH_FILES, "fivebar path"):
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
