"""`fivebar aspects` for a kind whose aspects live in one space of poses (the 3-RPR and the 3-RRR
over (x, y, phi); reached through `cli/dispatch.py`)."""

from __future__ import annotations

import click

from fivebar_cli.api.calls import aspects as fb_aspects
from fivebar_cli.cli.options import (
    as_flags, common_options, jobs_option, option_errors, prepare_out, progress, report, save_files, wrote,
)
from fivebar_cli.cli.poses import CONFIG, load_pose_kind, pose_budget_option, pose_depth_option


@click.command("aspects", short_help="Generalized aspects over a space of poses, with a certified count.")
@click.argument("config_path", metavar="CONFIG", type=CONFIG)
@pose_depth_option
@pose_budget_option
@jobs_option
@common_options
@option_errors()
def pose_aspects(config_path, depth, budget, jobs, out, no_plot, quiet):
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
      fivebar aspects configs/rpr3-caro.yaml --depth 5 --jobs 2 -o out/caro-jobs --no-plot
    """
    m = load_pose_kind(config_path, depth=depth)
    folder = prepare_out(out, m.name)
    with progress(quiet, len(m.pose_aspect_model().classes) + 1, f"aspects depth {depth}") as advance:
        result = fb_aspects(m, depth, budget=budget, advance=advance, jobs=jobs)
    paths = save_files(result, folder, no_plot, spelled=as_flags)
    report(quiet, result.headline)
    for line in result.lines():
        report(quiet, line)
    if not result.aspects:
        report(quiet, f"  no aspect has certified cells at depth {depth}: a deeper paving finds thin ones "
                      f"(try --depth {depth + 1})")
    wrote(quiet, paths)
