"""`fivebar rpr3 area | sweep | synthesize` (closed forms, similar base and platform, Jiang & Gosselin)
and `fivebar rpr3 pave | verify` (certified octrees of any 3-RPR in (x, y, phi))."""

from __future__ import annotations

import math
from pathlib import Path

import click
import numpy as np

from fivebar_cli.cli.options import (
    NUMBER, common_options, data_on_stdout, figure, jobs_option, prepare_out, progress, report, wrote,
)
from fivebar_cli.io.files import csv_text, write_csv
from fivebar_cli.io.outputs import output_set
from fivebar_cli.io.schema import ConfigError
from fivebar_cli.mechanisms.registry import load_config
from fivebar_cli.mechanisms.rpr3 import closed_form as geo
from fivebar_cli.mechanisms.rpr3 import paper, sweeps
from fivebar_cli.mechanisms.rpr3.model import SimilarDesign, reaches_singular_orientation, to_radians
from fivebar_cli.mechanisms.rpr3.synthesis import OBJECTIVES, synthesize

CONFIG = click.Path(path_type=Path)


def load_rpr3(path) -> SimilarDesign:
    """The similar-form design of a config, for the closed forms (one line naming the field if not)."""
    return load_config(path, kind="rpr3").closed_form(str(path))


def _figure(make, path: Path, paths: list) -> None:
    paths.append(figure(make, path))


def _check_phis(values, where: str) -> None:
    """Orientations (degrees) must avoid the multiples of 180, where the whole plane is singular."""
    if not all(math.isfinite(v) for v in values):
        raise click.BadParameter("orientations must be finite numbers", param_hint=where)
    if reaches_singular_orientation(min(values), max(values)):
        raise click.BadParameter("orientations must not reach a multiple of 180 degrees (singular everywhere)",
                                 param_hint=where)


@click.group()
def rpr3() -> None:
    """3-RPR: closed forms for a platform similar to the base (area, sweep, synthesize),
    certified octrees of any 3-RPR in (x, y, phi) (pave, verify) and its assembly modes (dkp).

    \b
    Examples (each also in its command's help):
      fivebar rpr3 area configs/rpr3-equilateral.yaml -o out/equilateral
      fivebar rpr3 sweep configs/rpr3-acute.yaml configs/rpr3-equilateral.yaml configs/rpr3-obtuse.yaml --over phi
      fivebar rpr3 synthesize configs/rpr3-table1.yaml
      fivebar rpr3 pave configs/rpr3-general.yaml --depth 5 -o out/general
      fivebar rpr3 verify configs/rpr3-verify/table1-legs-1-1.5.yaml
      fivebar rpr3 dkp configs/rpr3-caro.yaml --legs 14.98 15.38 12 --depth 6 -o out/caro
    """


# ---------------------------------------------------------------- area


@rpr3.command("area", short_help="Exact area of the singularity-free workspace (figures 2, 9).")
@click.argument("config", type=CONFIG)
@common_options(single="area.csv")
def area_cmd(config: Path, out: Path | None, no_plot: bool, quiet: bool) -> None:
    """Exact area of the singularity-free workspace W at phi (or at both ends of phi_range).

    W is the part inside the singularity circle of the intersection of the three annuli
    rho_min <= |X - C_i| <= rho_max. Writes area.csv (phi_deg,rho_min,rho_max,area) and
    singularity-free-workspace.png (the construction of the paper's figures 2 and 9).

    \b
    Examples:
      fivebar rpr3 area configs/rpr3-equilateral.yaml -o out/equilateral
      fivebar rpr3 area configs/rpr3-equilateral.yaml -o -          # area.csv on standard output
    """
    mech = load_rpr3(config)
    t = mech.design
    _, rho_max, auto = mech.leg_range()
    phis = sorted(set(mech.phi_range))
    stdout = data_on_stdout(out)
    folder = None if stdout else prepare_out(out, mech.name)
    report(quiet, f"{mech.name}: base t = ({mech.t1:g}, {mech.t2:g}, {mech.t3:g}), k = {mech.k:g}")
    if auto:
        if math.isinf(rho_max):
            report(quiet, "  rho_max auto = inf: every point of the singularity circle is within rho_min of some C_i")
        else:
            report(quiet, f"  rho_max auto = {rho_max:.9g} (largest singularity-free value)")
    else:
        limit = mech.rho_max_limit()
        if rho_max > limit:
            report(quiet, f"  note: rho_max {rho_max:g} exceeds the singularity-free limit {limit:.9g}: "
                          "the annuli reach the singularity circle, which then bounds W")
    rows = []
    for phi_deg in phis:
        phi = to_radians(phi_deg, mech.phi_range[0])
        (cx, cy), radius = (np.asarray(v).tolist() for v in geo.singularity_circle(*t, phi))
        a = float(geo.area(*t, phi, mech.rho_min, rho_max))
        arcs_ = geo.boundary(*t, phi, mech.rho_min, rho_max)
        on = sorted({geo.CIRCLE_NAMES[a_.circle] for a_ in arcs_})
        rows.append((phi_deg, mech.rho_min, rho_max, a))
        report(quiet, f"  phi = {phi_deg:g} deg: singularity circle centre ({cx:.6f}, {cy:.6f}), radius {radius:.6f}")
        report(quiet, f"    area of W = {a:.9f}, boundary: {len(arcs_)} arcs on {', '.join(on) if on else '-'}")
    header = ["phi_deg", "rho_min", "rho_max", "area"]
    if stdout:
        click.echo(csv_text(header, rows), nl=False)
        return
    with output_set(folder, "rpr3-area", ("area.csv", "singularity-free-workspace.png"), "fivebar rpr3 area"):
        paths = [write_csv(folder / "area.csv", header, rows)]
        if not no_plot:
            from fivebar_cli.plotting.rpr3 import construction

            title = (f"{mech.name}: singularity-free workspace, k = {mech.k:g}, "
                     f"phi = {', '.join(f'{p:g}' for p in phis)} deg")
            _figure(lambda: construction(mech, phis, mech.rho_min, rho_max, title),
                    folder / "singularity-free-workspace.png", paths)
    wrote(quiet, paths)


# ---------------------------------------------------------------- sweeps


@rpr3.command("sweep", short_help="Area swept over phi, rho_min or t2 (figures 3-8).")
@click.argument("configs", nargs=-1, required=True, type=CONFIG, metavar="CONFIG...")
@click.option("--over", type=click.Choice(["phi", "rho_min", "t2"]), required=True,
              help="phi: figures 3, 4, 6, 7; rho_min: figure 5 (at the config's phi); t2: figure 8.")
@click.option("--range", "span", type=(NUMBER, NUMBER), default=None, metavar="LO HI",
              help="Swept interval [default: phi 0.5 179.5; rho_min 0 up to where rho_max auto is finite; "
                   "t2 -5 t1+5].")
@click.option("--steps", type=click.IntRange(2, 20001), default=None,
              help="Number of samples [default: phi 359, rho_min 201, t2 233].")
@click.option("--angles", default="30,60,90,120,150", show_default=True,
              help="Orientations (degrees) of the t2 sweep, comma separated.")
@common_options(single="the table (area-vs-phi.csv, area-vs-rho-min.csv or area-vs-t2.csv)",
                default="outputs/<config name>/, outputs/<name1>+<name2>+.../ for several")
def sweep_cmd(configs, over, span, steps, angles, out, no_plot, quiet) -> None:
    """Area of W swept over phi, rho_min or the base shape t2, for one or more bases on one figure.

    Every sample is a design of its own (rho_max auto at that orientation). Several CONFIGs are
    overlaid (the paper compares the acute, equilateral and obtuse bases); the default output
    folder is then outputs/<name1>+<name2>+.../.

    \b
    Examples:
      fivebar rpr3 sweep configs/rpr3-acute.yaml configs/rpr3-equilateral.yaml configs/rpr3-obtuse.yaml --over phi
      fivebar rpr3 sweep configs/rpr3-equilateral.yaml --over rho_min --range 0 0.7
      fivebar rpr3 sweep configs/rpr3-equilateral.yaml --over t2 --angles 30,90,150 --steps 21
      fivebar rpr3 sweep configs/rpr3-equilateral.yaml --over rho_min -o - > area-vs-rho-min.csv
    """
    mechs = [load_rpr3(c) for c in configs]
    if span is not None and not all(abs(v) <= 1e6 for v in span):
        raise click.BadParameter(f"LO and HI must be at most 1e6 in magnitude, got {span[0]:g} {span[1]:g}",
                                 param_hint="--range")
    if span is not None and not span[0] < span[1]:
        raise click.BadParameter(f"LO must be smaller than HI, got {span[0]:g} {span[1]:g}", param_hint="--range")
    stdout = data_on_stdout(out)
    folder = None if stdout else prepare_out(out, "+".join(dict.fromkeys(m.name for m in mechs)))
    run, table, figures = SWEEPS[over]
    header, rows, drawings = run(mechs, span, steps, angles, quiet)
    if stdout:
        click.echo(csv_text(header, rows), nl=False)
        return
    with output_set(folder, f"rpr3-sweep-{over}", (table, *figures), f"fivebar rpr3 sweep --over {over}"):
        paths = [write_csv(folder / table, header, rows)]
        if not no_plot:
            for name, make in zip(figures, drawings):
                _figure(make, folder / name, paths)
    wrote(quiet, paths)


def _sweep_phi(mechs, span, steps, angles, quiet):
    """(header, rows, figure makers) of the sweep over phi (figures 3, 4, 6, 7)."""
    lo, hi = span or (0.5, 179.5)
    _check_phis((lo, hi), "--range")
    phis_deg = np.linspace(lo, hi, steps or 359)
    rows, curves = [], []
    with progress(quiet, len(mechs), "sweeping phi") as advance:
        for m in mechs:
            d = sweeps.sweep_phi(*m.design, m.rho_min, np.radians(phis_deg))
            curves.append((m.name, d))
            rows += [(m.name, p, *vals) for p, *vals in zip(phis_deg, d["rho_min"], d["rho_max"], d["area"],
                                                          d["rho_min_opt"], d["rho_max_opt"], d["area_opt"])]
            advance(1)
            best = int(np.argmax(d["area"]))
            report(quiet, f"{m.name}: rho_min = {m.rho_min:g}: largest area {d['area'][best]:.6f} at phi = "
                          f"{phis_deg[best]:g} deg; optimal rho_min {d['rho_min_opt'].min():.6f} .. "
                          f"{d['rho_min_opt'].max():.6f}")
    header = ["config", "phi_deg", "rho_min", "rho_max", "area", "rho_min_opt", "rho_max_opt", "area_opt"]
    from fivebar_cli.plotting.rpr3 import lines

    rho = ", ".join(sorted({f"{m.rho_min:g}" for m in mechs}))
    small = phis_deg <= lo + (hi - lo) / 6.0
    figs = [
        ("area", None, "area of W", f"Area of W vs phi (rho_min = {rho}) [fig. 3]"),
        ("area", small, "area of W", f"Area of W vs small phi (rho_min = {rho}) [fig. 4]"),
        ("area_opt", None, "area of W", "Area of W vs phi with the optimal rho_min [fig. 6]"),
        ("rho_min_opt", None, "optimal rho_min", "Optimal rho_min vs phi [fig. 7]"),
    ]

    def drawing(key, mask, ylabel, title):
        sel = slice(None) if mask is None else mask
        series = [(n, phis_deg[sel], d[key][sel]) for n, d in curves]
        return lambda: lines(series, "phi (degrees)", ylabel, title)

    return header, rows, [drawing(*f) for f in figs]


def _sweep_rho_min(mechs, span, steps, angles, quiet):
    """(header, rows, figure makers) of the sweep over rho_min (figure 5)."""
    limits = [float(geo.rho_min_limit(*m.design, to_radians(m.phi))) for m in mechs]
    lo, hi = span or (0.0, max(limits))
    if lo < 0:
        raise click.BadParameter(f"rho_min must not be negative, got {lo:g}", param_hint="--range")
    rhos = np.linspace(lo, hi, steps or 201)
    rows, series, marks = [], [], []
    for m in mechs:
        phi = to_radians(m.phi)
        d = sweeps.sweep_rho_min(*m.design, phi, rhos)
        rows += [(m.name, m.phi, *vals) for vals in zip(d["rho_min"], d["rho_max"], d["area"])]
        series.append((f"{m.name} (phi = {m.phi:g})", rhos, d["area"]))
        r_opt, a_opt, _ = (float(v) for v in geo.optimal_rho_min(*m.design, phi))
        marks.append((f"{r_opt:.4f}", r_opt, a_opt))
        report(quiet, f"{m.name}: phi = {m.phi:g} deg: optimal rho_min = {r_opt:.6f}, area {a_opt:.6f}")
    from fivebar_cli.plotting.rpr3 import lines

    phis = ", ".join(sorted({f"{m.phi:g}" for m in mechs}))
    title = f"Area of W vs rho_min (phi = {phis} deg) [fig. 5]"
    return (["config", "phi_deg", "rho_min", "rho_max", "area"], rows,
            [lambda: lines(series, "rho_min", "area of W", title, marks)])


def _sweep_t2(mechs, span, steps, angles, quiet):
    """(header, rows, figure makers) of the sweep over the base shape t2 (figure 8)."""
    try:
        phis_deg = [float(a) for a in angles.split(",") if a.strip()]
    except ValueError:
        raise click.BadParameter(f"expected comma-separated degrees, got {angles!r}", param_hint="--angles") from None
    if not phis_deg:
        raise click.BadParameter("no orientation given", param_hint="--angles")
    for p in phis_deg:
        _check_phis((p,), "--angles")
    rows, series = [], []
    with progress(quiet, len(mechs), "sweeping t2") as advance:
        for m in mechs:
            lo, hi = span or (-5.0, m.t1 + 5.0)
            t2s = np.linspace(lo, hi, steps or 233)
            d = sweeps.sweep_t2(m.t1, m.t3, m.k, m.rho_min, np.radians(phis_deg), t2s)
            for i, p in enumerate(phis_deg):
                rows += [(m.name, p, m.t1, t2, m.t3, *vals) for t2, *vals in zip(
                    t2s, d["rho_min"][i], d["rho_max"][i], d["area"][i], d["rho_min_opt"][i], d["rho_max_opt"][i],
                    d["area_opt"][i])]
                label = f"{m.name}, phi = {p:g}" if len(mechs) > 1 else f"phi = {p:g}"
                series.append((label, t2s, d["area"][i], m.name))
                best = int(np.argmax(d["area"][i]))
                report(quiet, f"{m.name}: phi = {p:g} deg: largest area {d['area'][i][best]:.6f} at t2 = "
                              f"{t2s[best]:.6g} (t1 / 2 = {m.t1 / 2:.6g})")
            advance(1)
    header = ["config", "phi_deg", "t1", "t2", "t3", "rho_min", "rho_max", "area", "rho_min_opt", "rho_max_opt",
              "area_opt"]
    from fivebar_cli.plotting.rpr3 import lines

    rho = ", ".join(sorted({f"{m.rho_min:g}" for m in mechs}))
    title = f"Area of W vs t2, t1 and t3 fixed (rho_min = {rho}) [fig. 8]"
    return header, rows, [lambda: lines(series, "t2", "area of W", title)]


# sweep -> (function, its table, its figures in the order the function draws them)
SWEEPS = {
    "phi": (_sweep_phi, "area-vs-phi.csv", ("area-vs-phi.png", "area-vs-small-phi.png",
                                            "area-vs-phi-optimal-rho-min.png", "optimal-rho-min-vs-phi.png")),
    "rho_min": (_sweep_rho_min, "area-vs-rho-min.csv", ("area-vs-rho-min.png",)),
    "t2": (_sweep_t2, "area-vs-t2.csv", ("area-vs-t2.png",)),
}


# ---------------------------------------------------------------- synthesis


@rpr3.command("synthesize", short_help="Leg range for an orientation range (Table 1, figure 10).")
@click.argument("config", type=CONFIG)
@common_options
def synthesize_cmd(config: Path, out: Path | None, no_plot: bool, quiet: bool) -> None:
    """Leg-length range for a singularity-free workspace over phi_range (section 4, Table 1).

    Six choices of rho_min: the config's, the optimum at phi1, at phi2, the maximal mean area A_a,
    A1 = A2, the minimal fluctuation dA_a; rho_max is, for each, the largest value keeping W
    singularity-free at every orientation of the range (closed form). Writes
    synthesis.csv, table1-comparison.csv (our values beside the paper's, for the paper's setup),
    area-vs-phi-cases.png (figure 10) and singularity-free-workspace-case2.png (figure 9).

    \b
    Example:
      fivebar rpr3 synthesize configs/rpr3-table1.yaml
    """
    mech = load_rpr3(config)
    t = mech.design
    p1, p2 = mech.phi_range
    r1, r2 = mech.radians
    if mech.rho_max is not None:
        report(quiet, f"note: legs.rho_max = {mech.rho_max:g} is not used: the synthesis computes rho_max")
    cases = synthesize(*t, r1, r2, mech.rho_min)
    folder = prepare_out(out, mech.name)

    report(quiet, f"{mech.name}: k = {mech.k:g}, base t = ({mech.t1:g}, {mech.t2:g}, {mech.t3:g}), "
                  f"phi in [{p1:g}, {p2:g}] deg")
    columns = ("rho_min", "rho_max", "A1", "A2", "|A1-A2|", "A_a", "dA_a")
    report(quiet, f"case  {'objective':<16} " + " ".join(f"{c:<10}" for c in columns) + " n")
    for c in cases:
        report(quiet, f"{c.number:<5} {c.objective:<16} {c.rho_min:<10.6f} {c.rho_max:<10.6f} {c.a1:<10.6f} "
                      f"{c.a2:<10.6f} {c.diff_rounded:<10.6f} {c.mean:<10.6f} {c.fluctuation:<10.6f} {c.n}")
    header = ["case", "objective", "rho_min", "rho_max", "A1", "A2", "abs_A1_A2", "A_a", "dA_a", "n"]
    rows = [(c.number, OBJECTIVES[c.number][0], c.rho_min, c.rho_max, c.a1, c.a2, c.diff_rounded, c.mean,
             c.fluctuation, c.n) for c in cases]
    files = ("synthesis.csv", "table1-comparison.csv", "area-vs-phi-cases.png", "singularity-free-workspace-case2.png")
    with output_set(folder, "rpr3-synthesize", files, "fivebar rpr3 synthesize"):
        paths = [write_csv(folder / "synthesis.csv", header, rows)]
        if paper.is_paper_table1(*t, p1, p2, mech.rho_min):
            rows, worst = paper.table1_comparison(cases)
            paths.append(write_csv(folder / "table1-comparison.csv", paper.COMPARISON_HEADER, rows))
            report(quiet, f"Table 1 at the paper's rho_min: largest difference from the printed cells {worst:.2e}")
        else:
            report(quiet, "(not the paper's Table-1 setup: no comparison with the printed values)")
        _synthesis_figures(mech, cases, folder, paths, no_plot)

    for c in cases:
        if c.note:
            report(quiet, f"  case {c.number}: {c.note}")
    best, flat = cases[3], cases[4]
    report(quiet, f"Recommended leg range (section 4.2): [{best.rho_min:.6f}, {best.rho_max:.6f}] for the largest "
                  f"mean area (case 4),")
    if flat.note:
        report(quiet, f"  (case 5 is not a recommendation here: {flat.note}); any leg range inside keeps W "
                      f"singularity-free for phi in [{p1:g}, {p2:g}] deg.")
    else:
        report(quiet, f"  [{flat.rho_min:.6f}, {flat.rho_max:.6f}] for equal areas at phi1 and phi2 (case 5); any "
                      f"leg range inside keeps W singularity-free for phi in [{p1:g}, {p2:g}] deg.")
    wrote(quiet, paths)


def _synthesis_figures(mech, cases, folder: Path, paths: list, no_plot: bool) -> None:
    """Figures 10 (area against phi, six cases) and 9 (W at both ends of the range, case 2)."""
    t = mech.design
    p1, p2 = mech.phi_range
    if not no_plot:
        from fivebar_cli.plotting.rpr3 import construction, lines

        phis_deg = np.linspace(p1, p2, 131)
        series = [(f"case {c.number}: rho_min = {c.rho_min:.6f}", phis_deg,
                   geo.area(*t, np.radians(phis_deg), c.rho_min, c.rho_max)) for c in cases]
        title = f"{mech.name}: area of W vs phi, six cases [fig. 10]"
        _figure(lambda: lines(series, "phi (degrees)", "area of W", title), folder / "area-vs-phi-cases.png", paths)
        c2 = cases[1]
        title = (f"{mech.name}: W at phi1 = {p1:g} and phi2 = {p2:g} deg, rho_min optimal at phi1 "
                 f"({c2.rho_min:.6f}) [fig. 9]")
        _figure(lambda: construction(mech, [p1, p2], c2.rho_min, c2.rho_max, title),
                folder / "singularity-free-workspace-case2.png", paths)


# ---------------------------------------------------------------- octrees: pave and verify

MAX_OCTREE_DEPTH = 12  # an octree's boundary surface has ~4^d cells: about 0.1 GiB per million
MAX_VERIFY_DEPTH = 17  # verify only splits what it cannot decide; 3 x 17 bits index an octree cell


def load_octree(path):
    """Any 3-RPR config whose legs are bounded (a workspace to pave)."""
    mech = load_config(path, kind="rpr3")
    if "workspace" not in mech.spaces():
        raise ConfigError(str(path), "legs.rho_max", "'auto' is unbounded here (every point of the singularity "
                          "circle is within rho_min of some C_i): give rho_max to pave or verify")
    return mech


@rpr3.command("pave", short_help="Certified octree of the workspace and its singularity-free parts.")
@click.argument("config", type=CONFIG)
@click.option("--depth", "-d", type=click.IntRange(0, MAX_OCTREE_DEPTH), default=7, show_default=True,
              help=f"Depth d of the octree (cells are root/2^d wide; 0..{MAX_OCTREE_DEPTH}).")
@jobs_option
@common_options
def pave_cmd(config: Path, depth: int, jobs: int | None, out: Path | None, no_plot: bool, quiet: bool) -> None:
    """Certified octree over (x, y, phi) of the workspace and of its singularity-free parts.

    Any 3-RPR: base and platform points (or the similar form), one leg range or one per leg,
    an orientation range (a single phi gives the quadtree of (x, y) at that phi). Three pavings,
    each a .qt pair (black cells certified in, complement cells certified out) and a summary CSV:
    workspace (every pose has its three legs in range), singularity-free.plus and
    singularity-free.minus (every pose reachable and det J > 0, resp. < 0; sign convention in
    docs/rpr3.md). Also volumes.csv (reachable, unreachable, undetermined, each sign, the
    singular-or-undetermined band; exact volumes for a similar platform) and the figures
    workspace.png and singularity-free.png (slices at a few phi, with the closed-form singularity
    circle for a similar platform). `fivebar refine` deepens any of the pairs.

    \b
    Examples:
      fivebar rpr3 pave configs/rpr3-general.yaml --depth 5 -o out/general
      fivebar rpr3 pave configs/rpr3-general.yaml --depth 5 --jobs 2 -o out/general-jobs --no-plot
    """
    from fivebar_cli.analyses import spaces

    mech = load_octree(config)
    folder = prepare_out(out, mech.name)
    regions = mech.regions("workspace")
    with progress(quiet, len(regions) * (depth + 1), f"octree depth {depth}") as advance:
        pavings = spaces.pave_regions(mech, "workspace", depth, on_level=lambda level, n: advance(1), jobs=jobs)
    paths = write_pave(folder, mech, pavings, {r: p.evaluations for r, p in pavings.items()}, no_plot, quiet)
    wrote(quiet, paths)


PAVE_SET = "rpr3-pave"  # the output set of `rpr3 pave` (and of `refine` of one of its pairs)


def pave_files() -> tuple[str, ...]:
    from fivebar_cli.io.layout import paving_files
    from fivebar_cli.mechanisms.rpr3.model import REGION_FILES

    return (*(f for stem in REGION_FILES.values() for f in paving_files(stem)), "volumes.csv", "singularity-free.png")


def write_pave(folder: Path, mech, pavings: dict, evaluations: dict, no_plot: bool, quiet: bool) -> list[Path]:
    """The files of `rpr3 pave` as one output set: the three pairs and summaries, volumes.csv and
    the figures; `evaluations` per region counts every box tested to reach it (with a refined run's)."""
    from fivebar_cli.analyses import spaces
    from fivebar_cli.io.outputs import output_set
    from fivebar_cli.mechanisms.rpr3 import volumes
    from fivebar_cli.mechanisms.rpr3.model import REACHABLE, REGION_FILES

    space = mech.spaces()["workspace"]
    regions = mech.regions("workspace")
    depth = pavings[REACHABLE].grid.depth
    v = volumes.volumes(mech, pavings)
    v["evaluations"] = sum(evaluations.values())
    paths = []
    with output_set(folder, PAVE_SET, pave_files(), "fivebar rpr3 pave"):
        for region, p in pavings.items():
            own = None if region == REACHABLE else region
            paths += spaces.write_paving(folder, mech, "workspace", p, "exact", evaluations[region], own,
                                         REGION_FILES[region])
        paths.append(write_csv(folder / "volumes.csv", volumes.HEADER, [tuple(v.values())]))
        if not no_plot:
            from fivebar_cli.plotting.rpr3 import figure_singularity_free
            from fivebar_cli.plotting.trees import figure_paving

            reach = pavings[REACHABLE]
            paths.append(figure(lambda: figure_paving(mech.name, space, reach.inside, reach.outside,
                                                      reach.undetermined_tree(), False), folder / "workspace.png"))
            design = mech.closed_form_or_none()
            plus, minus = (pavings[r].inside for r in regions[1:])
            title = f"{mech.name}: singularity-free workspace by sign of det J, depth {depth}"
            paths.append(figure(lambda: figure_singularity_free(title, space, plus, minus, reach.outside,
                                                                mech.phi_range, design),
                                folder / "singularity-free.png"))
    unit = "area" if space.dim == 2 else "volume (x y deg)"
    report(quiet, f"{mech.name}: workspace {'quadtree' if space.dim == 2 else 'octree'} depth {depth}, "
                  f"{v['evaluations']} evaluations; {unit}:")
    report(quiet, f"  reachable {v['reachable']:.8g}, unreachable {v['unreachable']:.8g}, "
                  f"undetermined {v['undetermined']:.4g} (root {v['root']:.8g})")
    report(quiet, f"  singularity-free det J > 0: {v['det_positive']:.8g}, det J < 0: {v['det_negative']:.8g}, "
                  f"singular or undetermined: {v['singular_or_undetermined']:.4g}")
    if v["exact_reachable"] != "":
        report(quiet, f"  closed form: reachable {v['exact_reachable']:.8g}, det J > 0 {v['exact_det_positive']:.8g}, "
                      f"det J < 0 {v['exact_det_negative']:.8g}")
    return paths


@rpr3.command("verify", short_help="Prove a design singularity-free, or find a reachable singular pose.")
@click.argument("config", type=CONFIG)
@click.option("--depth", "-d", type=click.IntRange(0, MAX_VERIFY_DEPTH), default=14, show_default=True,
              help="Maximum depth of the subdivision (it stops as soon as it has decided).")
@common_options
def verify_cmd(config: Path, depth: int, out: Path | None, no_plot: bool, quiet: bool) -> None:
    """Can the robot reach a singular pose over its orientation range and leg ranges?

    Subdivides (x, y, phi) until every box is certified unreachable or of one non-zero sign of
    det J (then: exit 0, "certified singularity-free"), or until a box whose poses are all
    reachable holds both signs of det J (exit 1: bisection to a pose with |det J| at rounding
    level, printed and written to counterexample.csv: x,y,phi_deg,rho1,rho2,rho3,det_j). Exit 3:
    undecided at --depth (the volume left open is printed; raise --depth, or the design touches
    a singularity, e.g. rho_max exactly at the closed-form limit). Writes verify.csv (the verdict)
    and, with a singular pose, counterexample.png (the robot at that pose, its leg lines meeting);
    a counterexample of an earlier run in the same folder is removed when none is found.

    \b
    Examples:
      fivebar rpr3 verify configs/rpr3-verify/table1-legs-1-1.5.yaml
      fivebar rpr3 verify configs/rpr3-verify/obtuse-phi1-rule.yaml     # exit 1: a singular pose is found
    """
    from fivebar_cli.analyses.pose_verify import SINGULAR, UNDECIDED, verify

    mech = load_octree(config)
    folder = prepare_out(out, mech.name)
    result = verify(mech, depth)
    a, b = mech.leg_limits()
    legs = ", ".join(f"[{lo:.8g}, {hi:.8g}]" for lo, hi in zip(a, b))
    p1, p2 = mech.phi_range
    report(quiet, f"{mech.name}: legs {legs}, phi in [{p1:g}, {p2:g}] deg")
    report(quiet, f"  {result.status} (depth {result.depth} of {result.max_depth}, {result.evaluations} boxes tested)")
    if result.status == SINGULAR:
        pose = result.pose
        x, y, phi = (*pose.pose, mech.phi_range[0])[:3]  # one orientation: the pose is (x, y)
        report(quiet, f"  singular pose: x = {x:.12g}, y = {y:.12g}, phi = {phi:.12g} deg, legs "
                      f"{', '.join(f'{v:.12g}' for v in pose.joints)}, det J = {pose.value:.3g}")
    if result.status == UNDECIDED:
        advice = result.note or "raise --depth"
        report(quiet, f"  undecided volume {result.undecided_volume:.6g} of {result.root_volume:.6g} at depth "
                      f"{result.depth}: {advice}")
    header = ["name", "status", "exit", "depth", "max_depth", "evaluations", "undecided_volume", "root_volume"]
    row = (mech.name, result.status, result.exit_code, result.depth, result.max_depth, result.evaluations,
           result.undecided_volume, result.root_volume)
    # a counterexample of an earlier run is removed when none is found (the set owns it)
    with output_set(folder, "rpr3-verify", ("verify.csv", "counterexample.csv", "counterexample.png"),
                    "fivebar rpr3 verify"):
        paths = [write_csv(folder / "verify.csv", header, [row])]
        if result.status == SINGULAR:
            paths.append(write_csv(folder / "counterexample.csv", ["x", "y", "phi_deg", "rho1", "rho2", "rho3", "det_j"],
                                   [(x, y, phi, *pose.joints, pose.value)]))
            if not no_plot:
                from fivebar_cli.plotting.rpr3 import figure_pose

                title = f"{mech.name}: a reachable singular pose (det J = {pose.value:.2g})"
                paths.append(figure(lambda: figure_pose(mech, (x, y, phi), pose.joints, title),
                                    folder / "counterexample.png"))
    wrote(quiet, paths)
    if result.exit_code:
        raise click.exceptions.Exit(result.exit_code)
