"""`fivebar locate`: which aspect a configuration lies in, and whether two can be joined without
a singularity (the answer `path` shares: `analyses.locate.decide`)."""

from __future__ import annotations

from dataclasses import replace

import click

from fivebar_cli.analyses.aspect_files import load_aspects
from fivebar_cli.analyses.aspects import analyse_aspects
from fivebar_cli.analyses.locate import (
    NO, UNDECIDED, Pieces, aspect_of, configurations, decide, deeper, mode_verdict, overall, row,
)
from fivebar_cli.cli.numbers import JOINT, NUMBER, check_joints
from fivebar_cli.cli.options import (
    CONFIG, MAX_ASPECT_DEPTH, as_flags, budget_option, depth_option, load_with_aspects, option_errors, reuse_options,
    tolerance_option,
)
from fivebar_cli.io.files import csv_text
from fivebar_cli.io.layout import output_dir
from fivebar_cli.mechanisms.base import plural


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
    folder = output_dir(out, m.name)
    saved = load_aspects(folder, m, depth)
    found = saved if saved is not None else analyse_aspects(m, depth, budget=budget, shapes=False).aspects
    model, robust = m.aspect_model(), m.is_interval
    names = [a.name for a in m.spaces()["jointspace"].axes]
    locations = [("pose", tuple(p)) for p in poses] + [("joints", tuple(j)) for j in joints]
    kept = []  # per location: (configuration, its row)
    for k, (kind, value) in enumerate(locations, start=1):
        found_here = [c for c in configurations(m, value, "workspace" if kind == "pose" else "jointspace")
                      if (not working_mode or c.working == working_mode)
                      and (not assembly_mode or c.assembly == assembly_mode)]
        kept.append([(replace(c, label=f"location {k}"), {**row(m, c, aspect_of(found, c), k),
                                                           "location": f"{kind} {value[0]:g} {value[1]:g}"})
                     for c in found_here])
    if as_csv:
        keys = ("input", "location", "x", "y", *names, "working_mode", "assembly_mode", "aspect", "singular",
                "aspect_certified", *(("violates",) if m.constraints else ()))
        cell = {None: "", True: "true", False: "false"}
        click.echo(csv_text(keys, [[cell.get(r[k], r[k]) if r[k] is None or isinstance(r[k], bool) else r[k]
                                    for k in keys] for rows in kept for _, r in rows]), nl=False)
        return
    source = f"read from {folder}" if saved is not None else "computed"
    click.echo(f"{m.name}: {_aspect_count(found, robust)} at depth {depth} {source} ({_certified_count(found)})")
    wanted = "".join(f" in {what} {mode}" for what, mode in (("working mode", working_mode),
                                                             ("assembly mode", assembly_mode)) if mode)
    for k, ((kind, value), rows) in enumerate(zip(locations, kept), start=1):
        count = plural(len(rows), 'configuration') if rows else "no configuration"
        reason = "" if rows or wanted else ": unreachable or cannot assemble"
        click.echo(f"location {k}: {kind} ({value[0]:g}, {value[1]:g}): {count}{wanted} "
                   f"(floating-point kinematics, not certified{reason})")
        for c, r in rows:
            click.echo(f"  working mode {r['working_mode']}, assembly mode {r['assembly_mode']}: "
                       f"x = {r['x']:.6g}, y = {r['y']:.6g}, {names[0]} = {r[names[0]]:.6g}, "
                       f"{names[1]} = {r[names[1]]:.6g} -> {_where(r, depth)}")
    if len(locations) < 2:
        return
    click.echo("singularity-free motions between locations:")
    pieces = Pieces()
    for i in range(len(locations)):
        for j in range(i + 1, len(locations)):
            empty = next((k for k in (i, j) if not kept[k]), None)
            if empty is not None:
                click.echo(f"  {i + 1} -> {j + 1}: not decided: location {empty + 1} has no configuration{wanted} "
                           "(floating-point kinematics): there is nothing to join")
                continue
            pairs = [(a, b, decide(model, found, a, b, depth, robust, MAX_ASPECT_DEPTH, pieces,
                                   constrained=bool(m.constraints)))
                     for a, _ in kept[i] for b, _ in kept[j]]
            if len(pairs) == 1:
                click.echo(f"  {i + 1} -> {j + 1}: {as_flags(pairs[0][2].line())}")
                continue
            _pairs_report(i + 1, j + 1, pairs, model, depth)


def _pairs_report(i: int, j: int, pairs, model, depth: int) -> None:
    """Two locations with several configurations: the answer over every pair of them, then the
    verdict of each pair that the modes alone do not settle."""
    answer = overall([v for _, _, v in pairs])
    said = answer if answer != UNDECIDED else f"{answer} at depth {depth}"
    head = f"  {i} -> {j}: {said}, over the {len(pairs)} pairs"
    apart = [v.answer == NO and mode_verdict(model, a, b, depth) is not None for a, b, v in pairs]
    if all(apart):
        click.echo(f"{head}: every pair has different modes, so every motion between them crosses a singularity")
        return
    click.echo(f"{head} of their configurations:")
    for (a, b, v), settled in zip(pairs, apart):
        if not settled:
            modes = f"working mode {a.working}, det A {a.assembly}"
            if (a.working, a.assembly) != (b.working, b.assembly):
                modes += f" -> working mode {b.working}, det A {b.assembly}"
            click.echo(f"    {modes}: {as_flags(v.line())}")
    if any(apart):
        click.echo(f"    the other {plural(sum(apart), 'pair')}: no: different modes")


def _aspect_count(aspects, robust: bool) -> str:
    word = "robust aspect" if robust else "aspect"
    return plural(len(aspects), word)


def _certified_count(aspects) -> str:
    """How many of the aspects are certified, in words."""
    good = sum(a.certified for a in aspects)
    if not aspects:
        return "none has certified cells at this depth"
    if good == len(aspects):
        return "certified" if good == 1 else "all certified"
    return "not certified" if len(aspects) == 1 else ("none certified" if good == 0 else f"{good} certified, "
                                                      f"{len(aspects) - good} not certified")


def _where(row: dict, depth: int) -> str:
    """Where a configuration lies: its aspect, the constraint it violates, the singularity it is on or
    near, or no cell."""
    if row.get("violates"):
        return f"violates the {row['violates']} (in no aspect)"
    if row["aspect"] is not None:
        return f"aspect {row['aspect']} ({'certified' if row['aspect_certified'] else 'not certified at this depth'})"
    if row["singular"]:
        return f"on or near a singularity: {row['singular']}"
    return (f"in no certified cell at depth {depth} (too close to a singularity for cells this size: "
            f"{as_flags(deeper(depth, MAX_ASPECT_DEPTH))})")
