"""The `fivebar` command line: parse options, call one library function, write files, report.

Errors become one line on stderr and an exit status: 2 for usage and configuration problems,
1 for anything else. Set FIVEBAR_DEBUG=1 to see the traceback of an unexpected failure.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import click

from fivebar_cli import __version__
from fivebar_cli.cli_common import common_options, prepare_out, progress, report, wrote
from fivebar_cli.errors import FivebarError, InputError

MAX_DEPTH = 20  # one paving: beyond this the boundary cells alone need several GiB
MAX_ASPECT_DEPTH = 16  # aspects pave six regions and label them: about 0.2 GiB at 14, x4 per two levels

CONTEXT = {"help_option_names": ["-h", "--help"], "max_content_width": 100}


@click.group(context_settings=CONTEXT)
@click.version_option(__version__, "-V", "--version", prog_name="fivebar")
def cli() -> None:
    """Certified joint space, workspace and aspects of planar parallel robots.

    \b
    Examples:
      fivebar jointspace configs/m1.yaml --depth 10
      fivebar workspace configs/m2.yaml --depth 12 -o out/m2
      fivebar aspects configs/m1.yaml --depth 10
      fivebar locate configs/m1.yaml --pose 4 5 --pose 6 -3
      fivebar kratio configs/m1.yaml configs/m2.yaml --depths 5-10
      fivebar rpr3 synthesize configs/rpr3-table1.yaml
      fivebar reproduce
    """


CONFIG = click.Path(path_type=Path, dir_okay=False)


def _depth_option(default: int = 10, limit: int = MAX_DEPTH):
    return click.option("--depth", "-d", type=click.IntRange(0, limit), default=default, show_default=True,
                        help=f"Maximum depth d of the quadtree (cells are root/2^d wide; 0..{limit}).")


def _procedure_option(func):
    return click.option(
        "--procedure", type=click.Choice(["exact", "paper"]), default="exact", show_default=True,
        help="Box test: our exact-range tests, or the paper's interval procedure (baseline).",
    )(func)


def _space_command(space: str, m_path: Path, depth: int, procedure: str, out, no_plot: bool, quiet: bool) -> None:
    from fivebar_cli import config, spaces

    m = config.load_fivebar(m_path)
    out_dir = prepare_out(out, m.name)
    with progress(quiet, depth + 1, f"{space} depth {depth}") as advance:
        paving = spaces.pave_space(m, space, depth, procedure, on_level=lambda level, n: advance(1))
    paths = _write_space(out_dir, m, space, paving, procedure, paving.evaluations, no_plot)
    report(quiet, f"{m.name} {space}, depth {depth} ({procedure} tests): {paving.evaluations} evaluations "
           f"(K = {paving.evaluations / 4.0**depth:.4%}), certified inside area {paving.inside.area:.10g}, "
           f"undetermined {paving.undetermined_area:.4g}")
    wrote(quiet, paths)


def _write_space(out_dir: Path, m, space: str, paving, procedure: str, evaluations: int, no_plot: bool) -> list[Path]:
    """The .qt pair, the summary CSV and (unless --no-plot) the figures of a paving."""
    from fivebar_cli import spaces
    from fivebar_cli.outputs import write_csv

    paths = spaces.write_paving(out_dir, m, space, paving, procedure, evaluations)
    row = spaces.summary_row(m, space, procedure, paving, evaluations)
    paths.append(write_csv(out_dir / f"{space}.csv", spaces.SUMMARY_HEADER, [row]))
    if not no_plot:
        paths += _plot_paving(out_dir, m.name, space, paving)
    return paths


def _plot_paving(out_dir: Path, name: str, space: str, paving) -> list[Path]:
    from fivebar_cli import plotting
    from fivebar_cli.outputs import save_figure

    und = paving.undetermined_tree()
    paths = []
    for complement, suffix in ((False, ""), (True, ".complement")):
        fig = plotting.figure_paving(name, space, paving.inside, paving.outside, und, complement)
        paths.append(save_figure(fig, out_dir / f"{space}{suffix}.png"))
        fig.clf()
    return paths


@cli.command(short_help="Certified joint space (th1, th2) of a five-bar (figs. 3, 4).")
@click.argument("config_path", metavar="CONFIG", type=CONFIG)
@_depth_option()
@_procedure_option
@common_options
def jointspace(config_path, depth, procedure, out, no_plot, quiet):
    """Certified joint space (th1, th2) of a five-bar, on the torus [-pi, pi]^2.

    Black cells can be assembled (|L3-L4| <= |B1B2| <= L3+L4, B1 != B2) at every point;
    complement cells at no point. Writes jointspace.qt, jointspace.complement.qt,
    jointspace.csv and the figures jointspace.png (paper fig. 3) and
    jointspace.complement.png (fig. 4).

    \b
    Example:
      fivebar jointspace configs/m1.yaml --depth 10
    """
    _space_command("jointspace", config_path, depth, procedure, out, no_plot, quiet)


@cli.command(short_help="Certified workspace (x, y) of a five-bar (fig. 6).")
@click.argument("config_path", metavar="CONFIG", type=CONFIG)
@_depth_option()
@_procedure_option
@common_options
def workspace(config_path, depth, procedure, out, no_plot, quiet):
    """Certified workspace (x, y) of a five-bar, on the root box [-(L1+L3), L1+L3]^2.

    Black cells are reachable by both legs at every point; complement cells at no point.
    Writes workspace.qt, workspace.complement.qt, workspace.csv and the figures
    workspace.png (paper fig. 6) and workspace.complement.png.

    \b
    Example:
      fivebar workspace configs/m2.yaml --depth 12 -o out/m2
    """
    _space_command("workspace", config_path, depth, procedure, out, no_plot, quiet)


def _parse_depths(ctx, param, text: str) -> list[int]:
    """Click callback: '5-10' or '5,8,10' -> sorted depths."""
    depths: set[int] = set()
    try:
        for part in text.split(","):
            lo, sep, hi = part.strip().partition("-")
            first, last = int(lo), int(hi) if sep else int(lo)
            if not 0 <= first <= last <= MAX_DEPTH:
                raise click.BadParameter(f"{text!r}: depths must lie in 0..{MAX_DEPTH}, ranges ascending")
            depths.update(range(first, last + 1))
    except ValueError:
        raise click.BadParameter(f"{text!r}: expected a range like 5-10 or a list like 5,8,10") from None
    return sorted(depths)


@cli.command(short_help="The paper's Table 1: evaluation counts K = n / 4^d.")
@click.argument("config_paths", metavar="CONFIG...", type=CONFIG, nargs=-1, required=True)
@click.option("--depths", default="5-10", show_default=True, callback=_parse_depths,
              help="Depths: a range 5-10 or a list 5,8,10.")
@common_options
def kratio(config_paths, depths, out, no_plot, quiet):
    """The paper's Table 1: evaluations K = n / 4^d, ours against the paper's procedure.

    For each space, mechanism and depth: our tight tests, the paper's interval procedure and,
    for M1 and M2, the K printed in the paper. Writes kratio.csv and kratio.png into --out
    (default outputs/).

    \b
    Example:
      fivebar kratio configs/m1.yaml configs/m2.yaml --depths 5-10
    """
    from fivebar_cli import config, tables
    from fivebar_cli.outputs import ensure_dir, write_csv

    depth_list = depths
    mechanisms = [config.load_fivebar(p) for p in config_paths]
    out_dir = ensure_dir(out if out is not None else Path("outputs"))
    with progress(quiet, 2 * len(mechanisms) * len(depth_list), "Table 1") as advance:
        rows = tables.kratio_rows(mechanisms, depth_list, advance)
    paths = [write_csv(out_dir / "kratio.csv", tables.HEADER, [[r[k] for k in tables.HEADER] for r in rows])]
    if not no_plot:
        from fivebar_cli import plotting
        from fivebar_cli.outputs import save_figure

        paths.append(save_figure(plotting.figure_kratio(rows), out_dir / "kratio.png"))
    for r in rows:
        printed = f"{r['paper_printed_percent']}%" if r["paper_printed_percent"] != "" else "-"
        report(quiet, f"{r['space']:10s} {r['mechanism']:6s} d={r['depth']:2d}  ours {r['evaluations']:8d} "
               f"(K {r['K']:.2%})  paper's procedure {r['paper_procedure_evaluations']:8d} "
               f"(K {r['paper_procedure_K']:.2%}, printed {printed})  saving {r['saving_vs_paper']:.0%}")
    wrote(quiet, paths)


@cli.command(short_help="Deepen a saved paving, testing only undetermined cells.")
@click.argument("tree_path", metavar="TREE.qt", type=click.Path(path_type=Path, dir_okay=False))
@_depth_option(default=12)
@common_options
def refine(tree_path, depth, out, no_plot, quiet):
    """Deepen a saved paving, testing only its undetermined cells.

    TREE.qt may be either file of a pair (X.qt and X.complement.qt, as written by
    `jointspace` and `workspace`); the mechanism and box test are read from their headers.
    The deeper pair replaces the old one (or goes to --out). The result equals a fresh run at
    the new depth, with fewer evaluations.

    \b
    Example:
      fivebar workspace configs/m1.yaml --depth 10
      fivebar refine outputs/M1/workspace.qt --depth 14
    """
    from fivebar_cli import spaces
    from fivebar_cli.outputs import ensure_dir

    saved = spaces.load_saved(tree_path)
    old_depth = saved.inside.tree.grid.depth
    if depth < old_depth:
        raise InputError(str(tree_path), "--depth", f"{depth} is below the saved depth {old_depth}")
    out_dir = ensure_dir(out if out is not None else spaces.sibling_paths(tree_path)[0].parent)
    with progress(quiet, depth - old_depth, f"refine to depth {depth}") as advance:
        paving = spaces.refine_saved(saved, depth, on_level=lambda level, n: advance(1))
    total = saved.evaluations + paving.evaluations
    m, space = saved.mechanism, saved.space
    paths = _write_space(out_dir, m, space, paving, saved.procedure, total, no_plot)
    report(quiet, f"{m.name} {space}: refined depth {old_depth} -> {depth} with {paving.evaluations} evaluations "
           f"({saved.evaluations} saved by not retesting; a fresh run needs {total}), "
           f"certified inside area {paving.inside.area:.10g}, undetermined {paving.undetermined_area:.4g}")
    wrote(quiet, paths)


@cli.command(short_help="Compare two .qt files as sets (exit 0 equal, 1 different).")
@click.argument("a_path", metavar="A.qt", type=click.Path(path_type=Path, dir_okay=False))
@click.argument("b_path", metavar="B.qt", type=click.Path(path_type=Path, dir_okay=False))
@click.option("--quiet", "-q", is_flag=True, help="Print nothing; only the exit status tells.")
def diff(a_path, b_path, quiet):
    """Compare two quadtree files as sets: exit 0 when equal, 1 when not, 2 on bad input.

    Prints the cells and the area in A but not in B, and in B but not in A. Trees of different
    depths are compared on the finer grid; their root boxes must agree.

    \b
    Example:
      fivebar diff golden/workspace.qt outputs/M1/workspace.qt
    """
    from fivebar_cli.qtfile import read_qt

    a, b = read_qt(a_path), read_qt(b_path)
    ga, gb = a.tree.grid, b.tree.grid
    if ga.root != gb.root or ga.periodic != gb.periodic:
        raise InputError(str(b_path), "root", f"root box or periodic axes differ from {a_path}: "
                         f"{ga.root} vs {gb.root}")
    only_a, only_b = a.tree - b.tree, b.tree - a.tree
    equal = len(only_a) == 0 and len(only_b) == 0
    if not quiet:
        if equal:
            click.echo(f"same set: {len(a.tree)} cells, area {a.tree.area:.10g}")
        else:
            click.echo(f"{a_path}: {len(a.tree)} cells, area {a.tree.area:.10g}")
            click.echo(f"{b_path}: {len(b.tree)} cells, area {b.tree.area:.10g}")
            click.echo(f"only in A: {len(only_a)} cells, area {only_a.area:.10g}")
            click.echo(f"only in B: {len(only_b)} cells, area {only_b.area:.10g}")
            for label, t in (("A", only_a), ("B", only_b)):
                if len(t):
                    lo, hi = t.bounds()
                    bb = " x ".join(f"[{l:.6g}, {h:.6g}]" for l, h in zip(lo.min(0), hi.max(0)))
                    click.echo(f"  only in {label} lies within {bb}")
        for key in sorted(set(a.fields) | set(b.fields)):
            if a.get(key) != b.get(key) and not quiet:
                click.echo(f"header {key}: {a.get(key)!r} vs {b.get(key)!r}")
    if not equal:
        raise click.exceptions.Exit(1)


@cli.command(short_help="Generalized aspects, their matching and crossings (figs. 7-10).")
@click.argument("config_path", metavar="CONFIG", type=CONFIG)
@_depth_option(limit=MAX_ASPECT_DEPTH)
@common_options
def aspects(config_path, depth, out, no_plot, quiet):
    """Generalized aspects of a five-bar: singularity-free regions per working and assembly mode.

    Paves the workspace once per working mode and the joint space once per assembly mode,
    labels the connected regions (the joint space is a torus), matches each parallel aspect
    (workspace) to its serial aspect (joint space), and finds which aspects touch across a
    serial singularity. Writes aspects.csv, aspects-adjacency.csv, aspects/aspect-NN.workspace.qt
    and aspect-NN.jointspace.qt, and the figures aspects-workspace.png (paper figs. 7, 8) and
    aspects-jointspace-assembly+.png / -.png (figs. 9, 10).

    \b
    Example:
      fivebar aspects configs/m1.yaml --depth 10
    """
    from fivebar_cli import aspects as asp
    from fivebar_cli import config
    from fivebar_cli.outputs import write_csv
    from fivebar_cli.qtfile import write_qt

    m = config.load_fivebar(config_path)
    out_dir = prepare_out(out, m.name)
    with progress(quiet, 7, f"aspects depth {depth}") as advance:
        analysis = asp.analyse_aspects(m, depth, advance)
    paths = [
        write_csv(out_dir / "aspects.csv", asp.ASPECT_HEADER, asp.aspect_rows(analysis)),
        write_csv(out_dir / "aspects-adjacency.csv", asp.CROSSING_HEADER, asp.crossing_rows(analysis)),
    ]
    for a in analysis.aspects:
        for space, tree in (("workspace", a.workspace), ("jointspace", a.jointspace)):
            paths.append(write_qt(
                out_dir / "aspects" / f"aspect-{a.number:02d}.{space}.qt", tree, name=m.name, space=space,
                region=f"aspect {a.number}", colour="inside", mechanism=m.describe(),
                working_mode=asp.signs_text(a.working), assembly_mode=asp.signs_text(a.assembly),
            ))
    if not no_plot:
        from fivebar_cli import plotting
        from fivebar_cli.outputs import save_figure

        paths.append(save_figure(plotting.figure_aspects_workspace(analysis), out_dir / "aspects-workspace.png"))
        for am in asp.ASSEMBLY_MODES:
            fig = plotting.figure_aspects_jointspace(analysis, am)
            paths.append(save_figure(fig, out_dir / f"aspects-jointspace-assembly{asp.signs_text(am)}.png"))
    report(quiet, f"{m.name}: {len(analysis.aspects)} generalized aspects at depth {depth} "
           f"({analysis.evaluations} box evaluations; {analysis.fragments_resolved} fragments attached)")
    for row in asp.aspect_rows(analysis):
        report(quiet, f"  aspect {row[0]:2d}: working mode {row[1]}, det A {row[2]}, workspace area {row[3]:.6g}, "
               f"joint-space area {row[4]:.6g}")
    for c in analysis.crossings:
        report(quiet, f"  aspects {c.a} and {c.b} (det A {asp.signs_text(c.assembly)}) touch across {c.singularity} = 0")
    if not analysis.aspects:
        report(quiet, "  no aspect can be certified at this depth: try --depth 8 or more")
    for am in asp.ASSEMBLY_MODES:
        count = sum(a.assembly == am for a in analysis.aspects)
        if count != 5:
            verdict = f"not comparable ({count} aspects, the paper has 5)"
        else:
            verdict = "holds" if asp.paper_claim_holds(analysis, am) else "does NOT hold"
        report(quiet, f"  paper's claim on single working-mode changes (det A {asp.signs_text(am)}): {verdict}")
    wrote(quiet, paths)


def _pairs(values) -> list[tuple[float, float]]:
    return [tuple(float(v) for v in pair) for pair in values]


@cli.command(short_help="Aspect of a configuration; singularity-free motion or not.")
@click.argument("config_path", metavar="CONFIG", type=CONFIG)
@click.option("--pose", "poses", type=(float, float), multiple=True, metavar="X Y",
              help="A position of P; all its configurations (working modes) are listed. Repeatable.")
@click.option("--joints", "joints", type=(float, float), multiple=True, metavar="TH1 TH2",
              help="Actuated joint values in radians; both assembly modes are listed. Repeatable.")
@click.option("--working-mode", type=click.Choice(["++", "+-", "-+", "--"]), default=None,
              help="Keep only configurations of this working mode.")
@click.option("--assembly-mode", type=click.Choice(["+", "-"]), default=None,
              help="Keep only configurations of this assembly mode.")
@_depth_option(limit=MAX_ASPECT_DEPTH)
@click.option("--csv", "as_csv", is_flag=True, help="Print the configurations as CSV.")
def locate(config_path, poses, joints, working_mode, assembly_mode, depth, as_csv):
    """Which aspect a configuration lies in, and whether two can be joined without singularity.

    For each --pose (x, y), every configuration reaching it (up to four working modes); for
    each --joints (th1, th2), every assembly (up to two). Each is reported with its modes and
    its aspect, or as on/near a singularity. With two or more locations, configurations that
    share an aspect can be joined by a singularity-free motion; others cannot.

    \b
    Examples:
      fivebar locate configs/m1.yaml --pose 4 5
      fivebar locate configs/m1.yaml --pose 4 5 --pose 6 -3 --working-mode ++
      fivebar locate configs/m2.yaml --joints 0.1 1.4 --joints 1.5 1.2 --assembly-mode +
    """
    from fivebar_cli import aspects as asp
    from fivebar_cli import config
    from fivebar_cli.outputs import csv_text

    if not poses and not joints:
        raise click.UsageError("give at least one --pose X Y or --joints TH1 TH2")
    m = config.load_fivebar(config_path)
    analysis = asp.analyse_aspects(m, depth)
    rows = []
    locations = [("pose", p) for p in _pairs(poses)] + [("joints", j) for j in _pairs(joints)]
    for k, (kind, value) in enumerate(locations):
        space = "workspace" if kind == "pose" else "jointspace"
        for cfg in asp.locate_configurations(analysis, [value], space):
            if working_mode and cfg["working_mode"] != working_mode:
                continue
            if assembly_mode and cfg["assembly_mode"] != assembly_mode:
                continue
            cfg["input"] = k + 1
            cfg["location"] = f"{kind} {value[0]:g} {value[1]:g}"
            rows.append(cfg)
    keys = ("input", "location", "x", "y", "theta1", "theta2", "working_mode", "assembly_mode", "aspect", "singular")
    if as_csv:
        click.echo(csv_text(keys, [[("" if r[k] is None else r[k]) for k in keys] for r in rows]), nl=False)
        return
    for k, (kind, value) in enumerate(locations, start=1):
        mine = [r for r in rows if r["input"] == k]
        click.echo(f"location {k}: {kind} ({value[0]:g}, {value[1]:g}): "
                   + (f"{len(mine)} configuration(s)" if mine else "no configuration (unreachable / cannot assemble)"))
        for r in mine:
            where = f"aspect {r['aspect']}" if r["aspect"] is not None else "on or near a singularity (no certified aspect)"
            extra = f" [{r['singular']}]" if r["singular"] else ""
            click.echo(f"  working mode {r['working_mode']}, assembly mode {r['assembly_mode']}: "
                       f"x = {r['x']:.6g}, y = {r['y']:.6g}, th1 = {r['theta1']:.6g}, th2 = {r['theta2']:.6g} -> {where}{extra}")
    if len(locations) >= 2:
        click.echo("singularity-free motions between locations:")
        for i in range(1, len(locations) + 1):
            for j in range(i + 1, len(locations) + 1):
                shared = sorted({r["aspect"] for r in rows if r["input"] == i and r["aspect"] is not None}
                                & {r["aspect"] for r in rows if r["input"] == j and r["aspect"] is not None})
                if shared:
                    click.echo(f"  {i} -> {j}: yes, within aspect(s) {', '.join(map(str, shared))}")
                else:
                    click.echo(f"  {i} -> {j}: no: no aspect holds a configuration of both "
                               "(every motion between them crosses a singularity)")


BASES = ("{configs}/rpr3-acute.yaml", "{configs}/rpr3-equilateral.yaml", "{configs}/rpr3-obtuse.yaml")
REPRODUCTION = (  # (what, arguments); {configs} and {out} are filled in
    ("five-bar Table 1", ["kratio", "{configs}/m1.yaml", "{configs}/m2.yaml", "--depths", "5-10", "-o", "{out}"]),
    ("M1 joint space (figs. 3, 4)", ["jointspace", "{configs}/m1.yaml", "--depth", "10", "-o", "{out}/M1"]),
    ("M1 workspace (fig. 6)", ["workspace", "{configs}/m1.yaml", "--depth", "10", "-o", "{out}/M1"]),
    ("M1 aspects (figs. 7, 9)", ["aspects", "{configs}/m1.yaml", "--depth", "10", "-o", "{out}/M1"]),
    ("M2 joint space (figs. 3, 4)", ["jointspace", "{configs}/m2.yaml", "--depth", "10", "-o", "{out}/M2"]),
    ("M2 workspace (fig. 6)", ["workspace", "{configs}/m2.yaml", "--depth", "10", "-o", "{out}/M2"]),
    ("M2 aspects (figs. 8, 10)", ["aspects", "{configs}/m2.yaml", "--depth", "10", "-o", "{out}/M2"]),
    ("3-RPR construction (fig. 2)", ["rpr3", "area", "{configs}/rpr3-equilateral.yaml", "-o", "{out}/rpr3-equilateral"]),
    ("3-RPR area vs phi (figs. 3, 4, 6, 7)", ["rpr3", "sweep", *BASES, "--over", "phi", "-o", "{out}/rpr3-bases"]),
    ("3-RPR area vs rho_min (fig. 5)", ["rpr3", "sweep", *BASES, "--over", "rho_min", "-o", "{out}/rpr3-bases"]),
    ("3-RPR area vs t2, t1 of the equilateral base (fig. 8)",
     ["rpr3", "sweep", "{configs}/rpr3-equilateral.yaml", "--over", "t2", "-o", "{out}/rpr3-equilateral"]),
    ("3-RPR synthesis (Table 1, figs. 9, 10)", ["rpr3", "synthesize", "{configs}/rpr3-table1.yaml", "-o", "{out}/rpr3-table1"]),
)


@cli.command(short_help="Regenerate every table and figure of both papers.")
@click.option("--configs", type=click.Path(file_okay=False, path_type=Path), default=Path("configs"),
              show_default=True, help="Folder holding m1.yaml, m2.yaml and the rpr3-*.yaml cases.")
@click.option("--out", "-o", type=click.Path(file_okay=False, path_type=Path), default=Path("outputs"),
              show_default=True, help="Output folder.")
@click.option("--no-plot", is_flag=True, help="Skip the PNG figures (the tables and trees only).")
@click.option("--quiet", "-q", is_flag=True, help="Print nothing but errors.")
def reproduce(configs, out, no_plot, quiet):
    """Regenerate every table and figure of both papers (what `make reproduce` runs).

    Runs, in order: the five-bar Table 1 (kratio), the joint space, workspace and aspects of
    M1 and M2 at depth 10, and the 3-RPR construction, sweeps and synthesis. The .qt and CSV
    files are deterministic: CI can diff them against the committed outputs/.

    \b
    Example:
      fivebar reproduce                  # into outputs/
      fivebar reproduce -o /tmp/check --no-plot
    """
    flags = (["--no-plot"] if no_plot else []) + (["--quiet"] if quiet else [])
    for number, (what, args) in enumerate(REPRODUCTION, start=1):
        argv = [a.format(configs=configs.as_posix(), out=out.as_posix()) for a in args] + flags
        report(quiet, f"[{number}/{len(REPRODUCTION)}] {what}: fivebar {' '.join(argv)}")
        cli.main(args=argv, prog_name="fivebar", standalone_mode=False)


def _register_rpr3() -> None:
    from fivebar_cli.cli_rpr3 import rpr3

    cli.add_command(rpr3)


class Interrupted(FivebarError):
    """Ctrl-C. Raised from the SIGINT handler so that click does not turn it into its own Abort."""


def _on_sigint(signum, frame):
    raise Interrupted("interrupted (no output was left half-written)")


def main(argv: list[str] | None = None) -> None:
    """Entry point of the console script: run the CLI and map every error to one line."""
    import signal
    import warnings

    if signal.getsignal(signal.SIGINT) is signal.default_int_handler:
        signal.signal(signal.SIGINT, _on_sigint)
    warnings.simplefilter("ignore", RuntimeWarning)  # numpy noise must not break the one-line promise
    try:
        _register_rpr3()
        status = cli.main(args=argv, prog_name="fivebar", standalone_mode=False)
    except click.exceptions.NoArgsIsHelpError as exc:  # `fivebar rpr3` alone: show the help
        click.echo(exc.ctx.get_help() if exc.ctx else str(exc))
        sys.exit(0)
    except click.exceptions.UsageError as exc:
        prefix = exc.ctx.command_path if exc.ctx else "fivebar"
        click.echo(f"{prefix}: error: {' '.join(exc.format_message().split())}", err=True)
        sys.exit(2)
    except click.exceptions.Exit as exc:
        sys.exit(exc.exit_code)
    except click.exceptions.Abort:
        click.echo("fivebar: aborted", err=True)
        sys.exit(1)
    except FivebarError as exc:
        click.echo(f"fivebar: error: {' '.join(str(exc).split())}", err=True)
        sys.exit(exc.exit_status)
    except KeyboardInterrupt:
        click.echo("fivebar: interrupted (no output was left half-written)", err=True)
        sys.exit(1)
    except MemoryError:
        click.echo("fivebar: error: out of memory (try a smaller --depth)", err=True)
        sys.exit(1)
    except Exception as exc:  # noqa: BLE001 - the promise is: no traceback, one line, status 1
        if os.environ.get("FIVEBAR_DEBUG"):
            raise
        click.echo(f"fivebar: internal error: {type(exc).__name__}: {' '.join(str(exc).split())}", err=True)
        sys.exit(1)
    sys.exit(status if isinstance(status, int) else 0)
