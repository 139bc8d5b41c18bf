"""`fivebar reproduce`: every table and figure of both papers, as one list of commands."""

from __future__ import annotations

from pathlib import Path

import click

from fivebar_cli.cli.options import NamedPath, option_errors, report
from fivebar_cli.errors import FivebarError

BASES = ("{configs}/rpr3-acute.yaml", "{configs}/rpr3-equilateral.yaml", "{configs}/rpr3-obtuse.yaml")
REPRODUCTION = (  # (what, arguments[, expected exit status]); {configs} and {out} are filled in
    ("five-bar Table 1", ["kratio", "{configs}/m1.yaml", "{configs}/m2.yaml", "--depths", "5-10", "-o", "{out}"]),
    ("M1 joint space (figs. 3, 4)", ["jointspace", "{configs}/m1.yaml", "--depth", "10", "-o", "{out}/M1"]),
    ("M1 workspace (fig. 6)", ["workspace", "{configs}/m1.yaml", "--depth", "10", "-o", "{out}/M1"]),
    ("M1 aspects (figs. 7, 9)", ["aspects", "{configs}/m1.yaml", "--depth", "10", "-o", "{out}/M1"]),
    ("M1 in a browser (view.html)", ["view", "{out}/M1", "-o", "{out}/M1/view.html"]),
    ("M2 joint space (figs. 3, 4)", ["jointspace", "{configs}/m2.yaml", "--depth", "10", "-o", "{out}/M2"]),
    ("M2 workspace (fig. 6)", ["workspace", "{configs}/m2.yaml", "--depth", "10", "-o", "{out}/M2"]),
    ("M2 aspects (figs. 8, 10)", ["aspects", "{configs}/m2.yaml", "--depth", "10", "-o", "{out}/M2"]),
    ("M2 in a browser (view.html)", ["view", "{out}/M2", "-o", "{out}/M2/view.html"]),
    ("M1 with its end joint P limited to [-90, 90] deg (Caro et al. 2014: 12 aspects)",
     ["aspects", "{configs}/m1-passive-limit.yaml", "--depth", "10", "-o", "{out}/M1-passive-limit"]),
    ("M1 with P limited, in a browser (view.html)",
     ["view", "{out}/M1-passive-limit", "-o", "{out}/M1-passive-limit/view.html"]),
    ("M1 with a disc obstacle no link may touch (Caro et al. 2014: 26 aspects, a lower bound)",
     ["aspects", "{configs}/m1-obstacle.yaml", "--depth", "10", "-o", "{out}/M1-obstacle"]),
    ("M1 with the disc, in a browser (view.html)", ["view", "{out}/M1-obstacle", "-o", "{out}/M1-obstacle/view.html"]),
    ("M1 tolerances (the paper's future work)",
     ["tolerance", "{configs}/m1.yaml", "--tolerances", "0,0.01,0.02,0.05,0.1", "--depth", "9", "-o", "{out}/M1"]),
    ("M2 tolerances (the paper's future work)",
     ["tolerance", "{configs}/m2.yaml", "--tolerances", "0,0.005,0.01,0.02", "--depth", "9", "-o", "{out}/M2"]),
    ("3-RPR construction (fig. 2)", ["rpr3", "area", "{configs}/rpr3-equilateral.yaml", "-o", "{out}/rpr3-equilateral"]),
    ("3-RPR area vs phi (figs. 3, 4, 6, 7)", ["rpr3", "sweep", *BASES, "--over", "phi", "-o", "{out}/rpr3-bases"]),
    ("3-RPR area vs rho_min (fig. 5)", ["rpr3", "sweep", *BASES, "--over", "rho_min", "-o", "{out}/rpr3-bases"]),
    ("3-RPR area vs t2, t1 of the equilateral base (fig. 8)",
     ["rpr3", "sweep", "{configs}/rpr3-equilateral.yaml", "--over", "t2", "-o", "{out}/rpr3-equilateral"]),
    ("3-RPR synthesis (Table 1, figs. 9, 10)", ["rpr3", "synthesize", "{configs}/rpr3-table1.yaml", "-o", "{out}/rpr3-table1"]),
    ("3-RPR general geometry: octree of the workspace and its singularity-free parts",
     ["rpr3", "pave", "{configs}/rpr3-general.yaml", "--depth", "7", "-o", "{out}/rpr3-general"]),
    ("3-RPR octree in a browser (view.html)", ["view", "{out}/rpr3-general", "-o", "{out}/rpr3-general/view.html"]),
    *((f"3-RPR verify: {what}", ["rpr3", "verify", f"{{configs}}/rpr3-verify/{name}.yaml",
                                 "-o", f"{{out}}/rpr3-verify/{name}"], status) for what, name, status in (
        ("the paper's leg range [1, 1.5] over [100, 165] deg (certified)", "table1-legs-1-1.5", 0),
        ("obtuse base, rho_max at phi1 (a singular pose)", "obtuse-phi1-rule", 1),
        ("obtuse base, rho_max below the range minimum (certified)", "obtuse-range-minimum", 0),
        *((f"Table 1 case {case}, rho_max 0.001 below the limit (certified)", f"table1-case{case}", 0)
          for case in range(1, 7)),
    )),
    ("3-RRR symmetric at phi = 0: workspace (exact area of the three annuli)",
     ["workspace", "{configs}/rrr3-symmetric-phi0.yaml", "--depth", "8", "-o", "{out}/rrr3-symmetric-phi0"]),
    ("3-RRR symmetric at phi = 0: aspects per working mode (Caro et al. 2014's fixed-orientation experiment; "
     "between 26 and 32 at depth 7, --depth 10 certifies 32)",
     ["aspects", "{configs}/rrr3-symmetric-phi0.yaml", "--depth", "7", "-o", "{out}/rrr3-symmetric-phi0"]),
    ("3-RRR symmetric over phi in [-30, 30]: octree of the workspace",
     ["workspace", "{configs}/rrr3-symmetric.yaml", "--depth", "5", "-o", "{out}/rrr3-symmetric"]),
    ("3-RRR Gosselin-Angeles-style over phi in [-60, 60]: octree of the workspace",
     ["workspace", "{configs}/rrr3-gosselin-angeles.yaml", "--depth", "5", "-o", "{out}/rrr3-gosselin-angeles"]),
)
FIGURE_STEPS = ("view",)  # commands that only draw: skipped with --no-plot (tables and trees only)


@click.command(short_help="Regenerate every table and figure of both papers.")
@click.option("--configs", type=NamedPath(file_okay=False, path_type=Path), default=None,
              help="Folder holding m1.yaml, m2.yaml and the rpr3-*.yaml and rrr3-*.yaml cases [default: configs, or "
                   "the shipped examples (fivebar examples) when ./configs does not exist].")
@click.option("--out", "-o", type=NamedPath(file_okay=False, path_type=Path), default=Path("outputs"),
              show_default=True, help="Output folder.")
@click.option("--no-plot", is_flag=True, help="Skip the PNG figures and HTML pages (the tables and trees only).")
@click.option("--quiet", "-q", is_flag=True, help="Print nothing but errors.")
@option_errors()
def reproduce(configs, out, no_plot, quiet):
    """Regenerate every table and figure of both papers (what `make reproduce` runs).

    Runs, in order: the five-bar Table 1 (kratio), the joint space, workspace and aspects of
    M1 and M2 at depth 10 with a view.html page of each (fivebar view), the aspects of M1 with
    the two constraints of Caro et al. (2014) (P in [-90, 90] deg; a disc obstacle), their sensitivity to
    manufacturing tolerances (depth 9), the 3-RPR construction, sweeps and synthesis, the octree
    of a general 3-RPR (and its page), the `rpr3 verify` checks of the paper's designs (one of
    them must find a singular pose: exit 1 is its expected result), and the 3-RRR: the workspace
    and certified aspects of a symmetric design at one orientation, the octrees of the workspace
    of it and of a Gosselin-Angeles-style design. The .qt and CSV files are
    deterministic: the tests diff them against tests/golden/ (make golden). --no-plot skips the
    figures and the pages. `fivebar reproduce` alone writes everything into outputs/ (under a
    minute; what `make reproduce` runs); outside the repository it reads the shipped examples.

    \b
    Example:
      fivebar reproduce -o out/check --no-plot
    """
    if configs is None:
        from fivebar_cli.api.calls import examples_folder

        configs = Path("configs") if Path("configs").is_dir() else examples_folder()
    root = click.get_current_context().find_root().command
    flags = (["--no-plot"] if no_plot else []) + (["--quiet"] if quiet else [])
    for number, (what, args, *expected) in enumerate(REPRODUCTION, start=1):
        if no_plot and args[0] in FIGURE_STEPS:
            continue
        argv = [a.format(configs=configs.as_posix(), out=out.as_posix()) for a in args] + flags
        report(quiet, f"[{number}/{len(REPRODUCTION)}] {what}: fivebar {' '.join(argv)}")
        status = root.main(args=argv, prog_name="fivebar", standalone_mode=False) or 0
        if status != (expected[0] if expected else 0):
            raise FivebarError(f"reproduction step {number} ({what}) exited with status {status}, "
                               f"expected {expected[0] if expected else 0}")
