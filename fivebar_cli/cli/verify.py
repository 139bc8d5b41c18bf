"""`fivebar verify`: is a kind whose aspects live in a space of poses free of singularities over
its orientation range (a 3-RPR), in a working mode (a 3-RRR)? A certified yes or a singular pose."""

from __future__ import annotations

import click

from fivebar_cli.analyses.pose_aspect_files import joint_columns, pose_columns
from fivebar_cli.analyses.pose_verify import EXIT, SINGULAR, UNDECIDED, verify
from fivebar_cli.cli.options import common_options, figure, option_errors, prepare_out, report, wrote
from fivebar_cli.cli.poses import CONFIG, load_pose_kind, sheets_chosen
from fivebar_cli.io.files import write_csv
from fivebar_cli.io.layout import COUNTEREXAMPLE_CSV, COUNTEREXAMPLE_PNG, VERIFY_CSV, VERIFY_FILES
from fivebar_cli.io.outputs import output_set

MAX_VERIFY_DEPTH = 17  # verify only splits what it cannot decide; 3 x 17 bits index an octree cell


@click.command("verify", short_help="Prove a design singularity-free, or find a valid singular pose.")
@click.argument("config_path", metavar="CONFIG", type=CONFIG)
@click.option("--working-mode", "working_mode", default=None, metavar="W",
              help="A 3-RRR's working mode to verify, e.g. +-+ [default: every working mode of the config].")
@click.option("--depth", "-d", type=click.IntRange(0, MAX_VERIFY_DEPTH), default=14, show_default=True,
              help="Maximum depth of the subdivision (it stops as soon as it has decided).")
@common_options
@option_errors()
def verify_cmd(config_path, working_mode, depth, out, no_plot, quiet):
    """Can the robot reach a singular pose over its orientation range: a 3-RPR (det J = 0, legs
    in their ranges; as `fivebar rpr3 verify`), a 3-RRR in a working mode (det A = 0, a parallel
    singularity, with every leg strictly inside its annulus)?

    Per working mode (one for a 3-RPR), subdivides the space of poses until every box is
    certified invalid or of one non-zero sign (then "certified singularity-free"), or until a
    wholly valid box holds both signs (bisection to a pose where the sign is no longer certified:
    "singular pose found", written to counterexample.csv: the class's fields, the pose x,y,phi_deg,
    the joints and det_j or det_a), or undecided at --depth (the volume left open is printed).
    Writes verify.csv (name, the working mode for a 3-RRR, status, exit, depth, max_depth,
    evaluations, undecided_volume, root_volume: one row per working mode) and, with a singular
    pose, counterexample.png (the robot there). Exit 0 when every working mode is certified
    singularity-free, 1 when a singular pose is found, 3 when undecided.

    \b
    Examples:
      fivebar verify configs/rrr3-symmetric.yaml --working-mode +-+ -o out/rrr3-verify     # exit 1: a singular pose is found
      fivebar verify configs/rpr3-verify/table1-legs-1-1.5.yaml -o out/rpr3-verify
    """
    m = load_pose_kind(config_path)
    model = m.pose_aspect_model()
    sheets = sheets_chosen(m, working_mode)
    folder = prepare_out(out, m.name)
    fields = [k for k, _ in model.sheets[0].fields]
    rows, singular, statuses = [], [], []
    for sheet in sheets:
        result = verify(m, depth, sheet)
        values = [v for _, v in model.sheets[sheet].fields]
        label = model.sheets[sheet].label
        statuses.append(result.status)
        rows.append((m.name, *values, result.status, result.exit_code, result.depth, result.max_depth,
                     result.evaluations, result.undecided_volume, result.root_volume))
        report(quiet, f"{m.name}: {label + ': ' if label else ''}" + result.headline())
        if result.status == SINGULAR:
            pose = result.pose
            singular.append((sheet, pose))
            report(quiet, "  singular pose: " + ", ".join(f"{a} = {v:.12g}" for a, v in zip(pose_columns(m), pose.pose))
                   + ", " + ", ".join(f"{a} = {v:.12g}" for a, v in zip(joint_columns(m), pose.joints))
                   + f", {model.singularity_name} = {pose.value:.3g}")
        if result.status == UNDECIDED:
            report(quiet, "  " + result.undecided_line())
    header = ["name", *fields, "status", "exit", "depth", "max_depth", "evaluations", "undecided_volume", "root_volume"]
    # a counterexample of an earlier run is removed when none is found (the set owns it)
    with output_set(folder, f"{m.kind}-verify", VERIFY_FILES, "fivebar verify"):
        paths = [write_csv(folder / VERIFY_CSV, header, rows)]
        if singular:
            paths.append(write_csv(folder / COUNTEREXAMPLE_CSV,
                                   [*fields, *pose_columns(m), *joint_columns(m), model.singularity_name],
                                   [(*(v for _, v in model.sheets[s].fields), *p.pose, *p.joints, p.value)
                                    for s, p in singular]))
            if not no_plot:
                import numpy as np

                from fivebar_cli.analyses.pose_aspects import sheet_classes
                from fivebar_cli.plotting.pose_aspects import figure_assembly_modes

                poses = np.array([p.pose for _, p in singular])
                classes = np.array([sheet_classes(model, s)[0] for s, _ in singular])
                labels = [f"{model.sheets[s].label or m.name}: {model.singularity_name} = {p.value:.2g}"
                          for s, p in singular]
                title = f"{m.name}: valid singular poses"
                paths.append(figure(lambda: figure_assembly_modes(model, poses, labels, title, classes),
                                    folder / COUNTEREXAMPLE_PNG))
    wrote(quiet, paths)
    status = 1 if SINGULAR in statuses else 3 if UNDECIDED in statuses else 0
    if status:
        raise click.exceptions.Exit(EXIT[SINGULAR] if status == 1 else EXIT[UNDECIDED])
