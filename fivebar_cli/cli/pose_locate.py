"""`fivebar locate` for a kind whose aspects live in one space of poses: the aspect and class of a
pose, or of every pose of given joint values (reached through `cli/dispatch.py`)."""

from __future__ import annotations

import click

from fivebar_cli.analyses.pose_aspect_files import joint_columns, pose_columns
from fivebar_cli.analyses.pose_aspects import aspect_at, sheet_classes, sheet_of
from fivebar_cli.analyses.pose_paths import check_pose, wrap_pose
from fivebar_cli.cli.numbers import NUMBER
from fivebar_cli.cli.options import option_errors, reuse_options
from fivebar_cli.cli.poses import (
    CONFIG, aspects_for, check_joints, class_values, joints_options, load_pose_kind, numbers, pose_budget_option,
    pose_depth_option, sheets_chosen, solve_joints, working_mode_option,
)
from fivebar_cli.io.files import csv_text
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
            check_pose(m, wrap_pose(space, value), f"pose ({numbers(value)})", str(config_path))
        else:
            check_joints(m, value, f"--{kind}")
    aspects, source = aspects_for(m, output_dir(out, m.name), depth, budget)
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
            violates = "; ".join(model.violated_constraints(pose[None, :], sheet)[0]) if m.constraints else ""
            rows.append({"input": k, "location": f"{kind} {' '.join(f'{v:g}' for v in value)}", "pose": pose,
                         "joints": joints_at[0], "cls": cls, "sheet": sheet, "aspect": aspect, "violates": violates})
    fields = [k for k, _ in model.classes[0].fields]
    if as_csv:
        violates = ("violates",) if m.constraints else ()
        header = ("input", "location", *pose_columns(m), *joint_columns(m), *fields, "aspect", "aspect_certified",
                  *violates)
        table = [(r["input"], r["location"], *r["pose"], *r["joints"], *class_values(model, r["cls"], r["sheet"]),
                  r["aspect"].number if r["aspect"] else "",
                  ("true" if r["aspect"].certified else "false") if r["aspect"] else "",
                  *((r["violates"],) if violates else ())) for r in rows]
        click.echo(csv_text(header, table), nl=False)
        return
    click.echo(f"{m.name}: aspects at depth {depth} {source}")
    names = [a.name for a in space.axes]
    for k, (kind, value) in enumerate(locations, start=1):
        mine = [r for r in rows if r["input"] == k]
        what = f"{kind} ({numbers(value)})"
        if kind != "pose":
            what += f": {len(mine)} poses" + (" (certified)" if not notes[k] else notes[k])
        click.echo(f"location {k}: {what}")
        for r in mine:
            sheet = model.sheets[r["sheet"]].label
            why = f"violates the {r['violates']}" if r["violates"] else "on or near a singularity (no certified sign)"
            label = model.classes[r["cls"]].label if r["cls"] >= 0 else (f"{sheet}: " if sheet else "") + why
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
