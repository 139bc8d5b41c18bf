"""The 3-RPR studies of Jiang & Gosselin (closed forms, similar base and platform): the exact area of
the singularity-free workspace (`area`), its sweeps over phi, rho_min or t2 (`sweep`), the leg-range
synthesis of Table 1 (`synthesize`); and for any 3-RPR the certified check `verify`.

Each returns a `Report` (`rows()`, `plot(ax)`) whose `notes` are the lines `fivebar rpr3 ...`
prints and whose `save(folder, figures=False)` writes the command's files."""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass, field

import numpy as np

from fivebar_cli.analyses.limits import check_count
from fivebar_cli.api.values import Drawing, Report, Table, Verified
from fivebar_cli.errors import InputError, param
from fivebar_cli.io.layout import (
    AREA_CSV, AREA_FILES, COUNTEREXAMPLE_CSV, COUNTEREXAMPLE_PNG, SYNTHESIS_CSV, SYNTHESIS_FILES, TABLE1_CSV, VERIFY_CSV,
    VERIFY_FILES,
)
from fivebar_cli.mechanisms.base import is_choice

AREA_HEADER = ("phi_deg", "rho_min", "rho_max", "area")
SYNTHESIS_HEADER = ("case", "objective", "rho_min", "rho_max", "A1", "A2", "abs_A1_A2", "A_a", "dA_a", "n")
VERIFY_HEADER = ("name", "status", "exit", "depth", "max_depth", "evaluations", "undecided_volume", "root_volume")
COUNTEREXAMPLE_HEADER = ("x", "y", "phi_deg", "rho1", "rho2", "rho3", "det_j")
DEFAULT_ANGLES = (30.0, 60.0, 90.0, 120.0, 150.0)
MAX_STEPS = 20001  # samples of a sweep (each a design of its own)


def similar(mech):
    """The similar-form design of a 3-RPR (a path, a mapping, an example's name or an `Rpr3`), for
    the closed forms (InputError naming the field when it is not of that form)."""
    from fivebar_cli.api.calls import load, source_name
    from fivebar_cli.mechanisms.rpr3.model import SimilarDesign

    if isinstance(mech, SimilarDesign):
        return mech
    return load(mech, kind="rpr3").closed_form(source_name(mech))


def check_phis(values, field: str) -> None:
    """Orientations (degrees) must be finite and avoid the multiples of 180, where the whole plane
    is singular (InputError on `field`)."""
    from fivebar_cli.mechanisms.rpr3.model import reaches_singular_orientation

    if not all(math.isfinite(v) for v in values):
        raise InputError("", field, "orientations must be finite numbers")
    if reaches_singular_orientation(min(values), max(values)):
        raise InputError("", field, "orientations must not reach a multiple of 180 degrees (singular everywhere)")


# ---------------------------------------------------------------- area


def area(mech) -> Report:
    """Exact area of the singularity-free workspace W at phi (or at both ends of phi_range): one row
    per orientation, with rho_max auto when the config says so (figure 2).

    Examples
    --------
    >>> import fivebar_cli as fb
    >>> round(fb.rpr3.area("rpr3-equilateral").rows()[0]["area"], 6) > 0
    True
    """
    from fivebar_cli.mechanisms.rpr3 import closed_form as geo
    from fivebar_cli.mechanisms.rpr3.model import to_radians
    from fivebar_cli.plotting.rpr3 import construction

    m = similar(mech)
    t = m.design
    _, rho_max, auto = m.leg_range()
    phis = sorted(set(m.phi_range))
    notes = [f"{m.name}: base t = ({m.t1:g}, {m.t2:g}, {m.t3:g}), k = {m.k:g}"]
    if auto:
        notes.append("  rho_max auto = inf: every point of the singularity circle is within rho_min of some C_i"
                     if math.isinf(rho_max) else f"  rho_max auto = {rho_max:.9g} (largest singularity-free value)")
    elif rho_max > m.rho_max_limit():
        notes.append(f"  note: rho_max {rho_max:g} exceeds the singularity-free limit {m.rho_max_limit():.9g}: "
                     "the annuli reach the singularity circle, which then bounds W")
    rows = []
    for phi_deg in phis:
        phi = to_radians(phi_deg, m.phi_range[0])
        (cx, cy), radius = (np.asarray(v).tolist() for v in geo.singularity_circle(*t, phi))
        a = float(geo.area(*t, phi, m.rho_min, rho_max))
        arcs_ = geo.boundary(*t, phi, m.rho_min, rho_max)
        on = sorted({geo.CIRCLE_NAMES[a_.circle] for a_ in arcs_})
        rows.append((phi_deg, m.rho_min, rho_max, a))
        notes.append(f"  phi = {phi_deg:g} deg: singularity circle centre ({cx:.6f}, {cy:.6f}), radius {radius:.6f}")
        notes.append(f"    area of W = {a:.9f}, boundary: {len(arcs_)} arcs on {', '.join(on) if on else '-'}")

    title = f"{m.name}: singularity-free workspace, k = {m.k:g}, phi = {', '.join(f'{p:g}' for p in phis)} deg"
    construction_figure = Drawing(construction, (m, phis, m.rho_min, rho_max, title))
    return Report(f"Area {m.name}", AREA_HEADER, tuple(rows), tuple(notes),
                  ("rpr3-area", AREA_FILES, "fivebar rpr3 area", AREA_CSV), ((AREA_FILES[1], construction_figure),))


# ---------------------------------------------------------------- sweeps


def sweep(mechs, over: str, span=None, steps: int | None = None, angles=None, advance=None) -> Report:
    """Area of W swept over `over` ("phi", "rho_min" or "t2") for one or more bases (a design per
    sample, rho_max auto): `span` (lo, hi) and `steps` default to the paper's ranges; `angles` are
    the orientations (degrees) of the t2 sweep (None: 30, 60, 90, 120 and 150), of no other.

    Examples
    --------
    >>> import fivebar_cli as fb
    >>> s = fb.rpr3.sweep(["rpr3-equilateral"], "rho_min", steps=11)
    >>> len(s)
    11
    """
    from fivebar_cli.io.layout import sweep_files

    if not is_choice(over, ("phi", "rho_min", "t2")):
        raise InputError("", param("over"), f"expected phi, rho_min or t2, got {over!r}")
    ms = [similar(m) for m in ([mechs] if not isinstance(mechs, (list, tuple)) else mechs)]
    if not ms:  # (as the command needs one CONFIG at least)
        raise InputError("", param("mechs"), "give at least one 3-RPR")
    span = check_span(span)
    steps = check_count(steps, "steps", 2, MAX_STEPS, none="None: the paper's")
    if angles is not None and over != "t2":  # (taken without a word before)
        raise InputError("", param("angles"), "only the sweep over t2 (" + param("over", "t2")
                         + f") takes orientations; this one is over {over}")
    run = {"phi": _sweep_phi, "rho_min": _sweep_rho_min, "t2": _sweep_t2}[over]
    header, rows, notes, drawings = run(ms, span, steps, angles, advance or (lambda n=1: None))
    files = sweep_files(over)
    return Report(f"Sweep over {over}", tuple(header), tuple(rows), tuple(notes),
                  (f"rpr3-sweep-{over}", files, f"fivebar rpr3 sweep --over {over}", files[0]), tuple(zip(files[1:], drawings)))


def check_span(span) -> tuple[float, float] | None:
    """A swept interval (lo, hi), as two floats: finite, at most 1e6 in magnitude, lo < hi
    (InputError on `span`); None (the paper's) stays None. Any pair of numbers is one: a tuple, a
    list, a numpy array (whose truth value a default `span or ...` could not take)."""
    if span is None:
        return None
    if (isinstance(span, (str, bytes)) or not hasattr(span, "__len__") or len(span) != 2
            or not all(isinstance(v, numbers.Real) for v in span)):
        raise InputError("", param("span"), f"expected (LO, HI), two numbers, got {span!r}")
    if not all(abs(v) <= 1e6 for v in span):
        raise InputError("", param("span"), f"LO and HI must be at most 1e6 in magnitude, got {span[0]:g} {span[1]:g}")
    if not span[0] < span[1]:
        raise InputError("", param("span"), f"LO must be smaller than HI, got {span[0]:g} {span[1]:g}")
    return float(span[0]), float(span[1])


def _sweep_phi(mechs, span, steps, angles, advance):
    from fivebar_cli.mechanisms.rpr3 import sweeps
    from fivebar_cli.plotting.rpr3 import lines

    lo, hi = span or (0.5, 179.5)
    check_phis((lo, hi), param("span"))
    phis_deg = np.linspace(lo, hi, steps or 359)
    rows, curves, notes = [], [], []
    for m in mechs:
        d = sweeps.sweep_phi(*m.design, m.rho_min, np.radians(phis_deg))
        curves.append((m.name, d))
        rows += [(m.name, p, *vals) for p, *vals in zip(phis_deg, d["rho_min"], d["rho_max"], d["area"],
                                                      d["rho_min_opt"], d["rho_max_opt"], d["area_opt"])]
        advance(1)
        best = int(np.argmax(d["area"]))
        notes.append(f"{m.name}: rho_min = {m.rho_min:g}: largest area {d['area'][best]:.6f} at phi = "
                     f"{phis_deg[best]:g} deg; optimal rho_min {d['rho_min_opt'].min():.6f} .. "
                     f"{d['rho_min_opt'].max():.6f}")
    header = ["config", "phi_deg", "rho_min", "rho_max", "area", "rho_min_opt", "rho_max_opt", "area_opt"]
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
        return Drawing(lines, ([(n, phis_deg[sel], d[key][sel]) for n, d in curves], "phi (degrees)",
                                         ylabel, title))

    return header, rows, notes, [drawing(*f) for f in figs]


def _sweep_rho_min(mechs, span, steps, angles, advance):
    from fivebar_cli.mechanisms.rpr3 import closed_form as geo
    from fivebar_cli.mechanisms.rpr3 import sweeps
    from fivebar_cli.mechanisms.rpr3.model import to_radians
    from fivebar_cli.plotting.rpr3 import lines

    limits = [float(geo.rho_min_limit(*m.design, to_radians(m.phi))) for m in mechs]
    lo, hi = span or (0.0, max(limits))
    if lo < 0:
        raise InputError("", param("span"), f"rho_min must not be negative, got {lo:g}")
    rhos = np.linspace(lo, hi, steps or 201)
    rows, series, marks, notes = [], [], [], []
    for m in mechs:
        phi = to_radians(m.phi)
        d = sweeps.sweep_rho_min(*m.design, phi, rhos)
        rows += [(m.name, m.phi, *vals) for vals in zip(d["rho_min"], d["rho_max"], d["area"])]
        series.append((f"{m.name} (phi = {m.phi:g})", rhos, d["area"]))
        r_opt, a_opt, _ = (float(v) for v in geo.optimal_rho_min(*m.design, phi))
        marks.append((f"{r_opt:.4f}", r_opt, a_opt))
        notes.append(f"{m.name}: phi = {m.phi:g} deg: optimal rho_min = {r_opt:.6f}, area {a_opt:.6f}")
    phis = ", ".join(sorted({f"{m.phi:g}" for m in mechs}))
    title = f"Area of W vs rho_min (phi = {phis} deg) [fig. 5]"

    return ["config", "phi_deg", "rho_min", "rho_max", "area"], rows, notes, [
        Drawing(lines, (series, "rho_min", "area of W", title, marks))]


def _sweep_t2(mechs, span, steps, angles, advance):
    from fivebar_cli.mechanisms.rpr3 import sweeps
    from fivebar_cli.plotting.rpr3 import lines

    try:
        angles = DEFAULT_ANGLES if angles is None else angles
        phis_deg = [float(a) for a in (angles.split(",") if isinstance(angles, str) else angles)
                    if not isinstance(a, str) or a.strip()]
    except ValueError:
        raise InputError("", param("angles"), f"expected comma-separated degrees, got {angles!r}") from None
    if not phis_deg:
        raise InputError("", param("angles"), "no orientation given")
    for p in phis_deg:
        check_phis((p,), param("angles"))
    rows, series, notes = [], [], []
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
            notes.append(f"{m.name}: phi = {p:g} deg: largest area {d['area'][i][best]:.6f} at t2 = "
                         f"{t2s[best]:.6g} (t1 / 2 = {m.t1 / 2:.6g})")
        advance(1)
    header = ["config", "phi_deg", "t1", "t2", "t3", "rho_min", "rho_max", "area", "rho_min_opt", "rho_max_opt",
              "area_opt"]
    rho = ", ".join(sorted({f"{m.rho_min:g}" for m in mechs}))
    title = f"Area of W vs t2, t1 and t3 fixed (rho_min = {rho}) [fig. 8]"

    return header, rows, notes, [Drawing(lines, (series, "t2", "area of W", title))]


# ---------------------------------------------------------------- synthesis


def synthesize(mech) -> Report:
    """Leg-length range keeping W singularity-free over phi_range (section 4, Table 1): six cases
    of rho_min, each with the largest rho_max, the areas at both ends, the mean area and its
    fluctuation; the notes end with the recommended leg range (section 4.2). `comparison` rows
    (ours beside the paper's) are in `.comparison` for the paper's own setup.

    Examples
    --------
    >>> import fivebar_cli as fb
    >>> [r["case"] for r in fb.rpr3.synthesize("rpr3-table1").rows()]  # doctest: +SKIP
    [1, 2, 3, 4, 5, 6]
    """
    from fivebar_cli.mechanisms.rpr3 import paper
    from fivebar_cli.mechanisms.rpr3.synthesis import OBJECTIVES, synthesize as cases_of

    m = similar(mech)
    t = m.design
    p1, p2 = m.phi_range
    r1, r2 = m.radians
    before = [f"note: legs.rho_max = {m.rho_max:g} is not used: the synthesis computes rho_max"] if m.rho_max is not None else []
    cases = cases_of(*t, r1, r2, m.rho_min)
    notes = before + [f"{m.name}: k = {m.k:g}, base t = ({m.t1:g}, {m.t2:g}, {m.t3:g}), phi in [{p1:g}, {p2:g}] deg"]
    columns = ("rho_min", "rho_max", "A1", "A2", "|A1-A2|", "A_a", "dA_a")
    notes.append(f"case  {'objective':<16} " + " ".join(f"{c:<10}" for c in columns) + " n")
    for c in cases:
        notes.append(f"{c.number:<5} {c.objective:<16} {c.rho_min:<10.6f} {c.rho_max:<10.6f} {c.a1:<10.6f} "
                     f"{c.a2:<10.6f} {c.diff_rounded:<10.6f} {c.mean:<10.6f} {c.fluctuation:<10.6f} {c.n}")
    rows = tuple((c.number, OBJECTIVES[c.number][0], c.rho_min, c.rho_max, c.a1, c.a2, c.diff_rounded, c.mean,
                  c.fluctuation, c.n) for c in cases)
    if paper.is_paper_table1(*t, p1, p2, m.rho_min):
        comparison, worst = paper.table1_comparison(cases)
        comparison = Table("Table 1 comparison", tuple(paper.COMPARISON_HEADER), tuple(map(tuple, comparison)))
        notes.append(f"Table 1 at the paper's rho_min: largest difference from the printed cells {worst:.2e}")
    else:
        comparison = None
        notes.append("(not the paper's Table-1 setup: no comparison with the printed values)")
    notes += [f"  case {c.number}: {c.note}" for c in cases if c.note]
    best, flat = cases[3], cases[4]
    notes.append(f"Recommended leg range (section 4.2): [{best.rho_min:.6f}, {best.rho_max:.6f}] for the largest "
                 f"mean area (case 4),")
    if flat.note:
        notes.append(f"  (case 5 is not a recommendation here: {flat.note}); any leg range inside keeps W "
                     f"singularity-free for phi in [{p1:g}, {p2:g}] deg.")
    else:
        notes.append(f"  [{flat.rho_min:.6f}, {flat.rho_max:.6f}] for equal areas at phi1 and phi2 (case 5); any "
                     f"leg range inside keeps W singularity-free for phi in [{p1:g}, {p2:g}] deg.")
    return Synthesis(f"Synthesis {m.name}", SYNTHESIS_HEADER, rows, tuple(notes),
                     ("rpr3-synthesize", SYNTHESIS_FILES, "fivebar rpr3 synthesize", SYNTHESIS_CSV),
                     _synthesis_drawings(m, cases), _csv_of(TABLE1_CSV, comparison), comparison, len(before))


def _csv_of(file: str, table: Table | None) -> tuple:
    """A table as the `tables` of a `Report` (none for None): another CSV of its output set."""
    return () if table is None else ((file, table.columns, table.data),)


@dataclass(frozen=True, repr=False)
class Synthesis(Report):
    """The synthesis table, with the paper's comparison (None off its setup); the first `printed`
    notes are about the config (said before anything is written)."""

    comparison: Table | None = None
    printed: int = 0


def _synthesis_drawings(m, cases) -> tuple:
    """Figures 10 (area against phi, six cases) and 9 (W at both ends of the range, case 2)."""
    from fivebar_cli.mechanisms.rpr3 import closed_form as geo
    from fivebar_cli.plotting.rpr3 import construction, lines

    t = m.design
    p1, p2 = m.phi_range

    phis_deg = np.linspace(p1, p2, 131)
    series = [(f"case {c.number}: rho_min = {c.rho_min:.6f}", phis_deg,
               geo.area(*t, np.radians(phis_deg), c.rho_min, c.rho_max)) for c in cases]
    cases_figure = Drawing(lines, (series, "phi (degrees)", "area of W",
                                             f"{m.name}: area of W vs phi, six cases [fig. 10]"))
    c2 = cases[1]
    title = f"{m.name}: W at phi1 = {p1:g} and phi2 = {p2:g} deg, rho_min optimal at phi1 ({c2.rho_min:.6f}) [fig. 9]"
    case2_figure = Drawing(construction, (m, [p1, p2], c2.rho_min, c2.rho_max, title))
    return tuple(zip(SYNTHESIS_FILES[2:], (cases_figure, case2_figure)))


# ---------------------------------------------------------------- octrees


@dataclass(frozen=True, repr=False)
class PaveSet:
    """The three certified pavings of `rpr3 pave` by region (`reachable`, `singularity-free det J > 0`,
    `< 0`; `Paving`s), their volumes (the row of volumes.csv) and the lines the command prints."""

    mechanism: object
    depth: int
    pavings: dict
    volumes: dict
    notes: tuple[str, ...] = ()

    def __repr__(self) -> str:
        v = self.volumes
        return (f"<PaveSet {self.mechanism.name}, depth {self.depth}: reachable {v['reachable']:.6g}, det J > 0 "
                f"{v['det_positive']:.6g}, det J < 0 {v['det_negative']:.6g}>")

    def rows(self) -> list[dict]:
        return [dict(self.volumes)]

    def save(self, folder, figures: bool = False) -> list:
        """The files of `rpr3 pave` as one output set: the three pairs and summaries, volumes.csv and
        (with `figures`) workspace.png and singularity-free.png."""
        from fivebar_cli.analyses import spaces
        from fivebar_cli.io.files import user_path, write_csv
        from fivebar_cli.io.layout import PAVE_SET, VOLUMES_CSV, pave_files, region_stem
        from fivebar_cli.io.outputs import output_set
        from fivebar_cli.mechanisms.rpr3 import volumes
        from fivebar_cli.mechanisms.rpr3.model import REACHABLE

        folder, m = user_path(folder, "folder"), self.mechanism
        paths = []
        with output_set(folder, PAVE_SET, pave_files(), "fivebar rpr3 pave"):
            for region, p in self.pavings.items():
                own = None if region == REACHABLE else region
                paths += spaces.write_paving(folder, m, "workspace", p.paving, "exact", p.evaluations, own,
                                             region_stem("workspace", own))
            paths.append(write_csv(folder / VOLUMES_CSV, volumes.HEADER, [tuple(self.volumes.values())]))
            if figures:
                paths += self._figures(folder)
        return paths

    def _figures(self, folder) -> list:
        from fivebar_cli.io.layout import SINGULARITY_FREE_PNG, paving_figure
        from fivebar_cli.mechanisms.rpr3.model import REACHABLE
        from fivebar_cli.plotting.rpr3 import figure_singularity_free
        from fivebar_cli.plotting.saving import draw_and_save
        from fivebar_cli.plotting.trees import figure_paving

        m, space = self.mechanism, self.mechanism.spaces()["workspace"]
        reach = self.pavings[REACHABLE].paving
        plus, minus = (self.pavings[r].inside for r in m.regions("workspace")[1:])
        title = f"{m.name}: singularity-free workspace by sign of det J, depth {self.depth}"
        return [draw_and_save(lambda: figure_paving(m.name, space, reach.inside, reach.outside,
                                                    reach.undetermined_tree(), False),
                                     folder / paving_figure("workspace")),
                draw_and_save(lambda: figure_singularity_free(title, space, plus, minus, reach.outside,
                                                              m.phi_range, m.closed_form_or_none()),
                              folder / SINGULARITY_FREE_PNG)]


def pave(mech, depth: int = 7, advance=None, jobs: int | None = 1) -> PaveSet:
    """Certified octree over (x, y, phi) of a 3-RPR's workspace and of its two singularity-free
    parts (any geometry), with their volumes (exact ones too for a similar platform); the three
    pavings on `jobs` processes (None: one per core), the same result for any. `advance(n=1)`:
    told of each level of each paving (3 * (depth + 1) steps at most).

    Examples
    --------
    >>> import fivebar_cli as fb
    >>> s = fb.rpr3.pave("rpr3-general", 3)
    >>> sorted(s.pavings) == sorted(s.mechanism.regions("workspace"))
    True
    """
    from fivebar_cli.analyses.limits import check_paving_depth
    from fivebar_cli.analyses.spaces import pave_regions
    from fivebar_cli.api.calls import per_level
    from fivebar_cli.api.values import Paving

    depth = check_paving_depth(depth, 3)
    m = bounded(mech)
    whole = m.spaces()["workspace"].region
    pavings = {r: Paving(m, "workspace", depth, "exact", None if r == whole else r, p, p.evaluations)
               for r, p in pave_regions(m, "workspace", depth, on_level=per_level(advance), jobs=jobs).items()}
    return pave_set(m, pavings)


def pave_set(m, pavings: dict, saved: int | None = None) -> PaveSet:
    """The pave set of these pavings (by region), its volumes row and report lines."""
    from fivebar_cli.mechanisms.rpr3 import volumes
    from fivebar_cli.mechanisms.rpr3.model import REACHABLE

    space = m.spaces()["workspace"]
    depth = pavings[REACHABLE].depth
    v = volumes.volumes(m, {r: p.paving for r, p in pavings.items()})
    v["evaluations"] = sum(p.evaluations for p in pavings.values())
    unit = "area" if space.dim == 2 else "volume (x y deg)"
    notes = [f"{m.name}: workspace {'quadtree' if space.dim == 2 else 'octree'} depth {depth}, "
             f"{v['evaluations']} evaluations; {unit}:",
             f"  reachable {v['reachable']:.8g}, unreachable {v['unreachable']:.8g}, "
             f"undetermined {v['undetermined']:.4g} (root {v['root']:.8g})",
             f"  singularity-free det J > 0: {v['det_positive']:.8g}, det J < 0: {v['det_negative']:.8g}, "
             f"singular or undetermined: {v['singular_or_undetermined']:.4g}"]
    if v["exact_reachable"] != "":
        notes.append(f"  closed form: reachable {v['exact_reachable']:.8g}, det J > 0 {v['exact_det_positive']:.8g}, "
                     f"det J < 0 {v['exact_det_negative']:.8g}")
    return PaveSet(m, depth, pavings, v, tuple(notes))


def refine_pave_set(source, m, old_depth: int, depth: int, advance=None) -> tuple[PaveSet, int]:
    """The three pairs of an `rpr3 pave` run in folder `source` deepened together to `depth`, and
    the evaluations saved by not retesting; `advance(n=1)` told of each new level of each pair."""
    from pathlib import Path

    from fivebar_cli.analyses import spaces
    from fivebar_cli.analyses.limits import check_paving_depth
    from fivebar_cli.api.calls import per_level
    from fivebar_cli.api.values import Paving
    from fivebar_cli.io.layout import paving_paths, region_stem
    from fivebar_cli.mechanisms.rpr3.model import REACHABLE

    depth = check_paving_depth(depth, 3)
    if depth < old_depth:
        raise InputError(str(source), param("depth"), f"{depth} is below the saved depth {old_depth}")
    pavings, saved_total = {}, 0
    for region in m.regions("workspace"):
        path = paving_paths(Path(source), region_stem("workspace", None if region == REACHABLE else region))[0]
        saved = spaces.load_saved(path)
        if saved.mechanism != m or saved.inside.tree.grid.depth != old_depth:
            raise InputError(str(path), "mechanism", "does not belong to the same rpr3 pave run")
        p = spaces.refine_saved(saved, depth, per_level(advance))
        pavings[region] = Paving(m, "workspace", depth, saved.procedure, saved.region, p, saved.evaluations + p.evaluations)
        saved_total += saved.evaluations
    return pave_set(m, pavings), saved_total


# ---------------------------------------------------------------- verify


def bounded(mech):
    """A 3-RPR whose legs are bounded (a workspace to pave or verify); InputError otherwise."""
    from fivebar_cli.api.calls import load, source_name

    m = load(mech, kind="rpr3")
    m.check_bounded(source_name(mech))
    return m


def verify(mech, depth: int = 14, advance=None) -> Report:
    """Can the robot reach a singular pose over its orientation range and leg ranges? One row of
    `verify.csv`: `status` is 'certified singularity-free', 'singular pose found' (the pose in
    `.result.pose`, its row in `counterexample`) or 'undecided' at `depth`. `advance(n=1)`: told
    of each level searched (depth + 1 steps at most).

    Examples
    --------
    >>> import fivebar_cli as fb
    >>> fb.rpr3.verify("rpr3-verify/table1-legs-1-1.5").rows()[0]["status"]
    'certified singularity-free'
    """
    from fivebar_cli.analyses.limits import MAX_VERIFY_DEPTH, check_depth
    from fivebar_cli.analyses.pose_verify import SINGULAR, UNDECIDED, verify as run
    from fivebar_cli.api.calls import per_level
    from fivebar_cli.plotting.rpr3 import figure_pose

    depth = check_depth(depth, MAX_VERIFY_DEPTH)
    m = bounded(mech)
    result = run(m, depth, on_level=per_level(advance))
    a, b = m.leg_limits()
    legs = ", ".join(f"[{lo:.8g}, {hi:.8g}]" for lo, hi in zip(a, b))
    p1, p2 = m.phi_range
    notes = [f"{m.name}: legs {legs}, phi in [{p1:g}, {p2:g}] deg",
             "  " + result.headline()]
    pose, counterexample, drawings = result.pose, None, ()
    if result.status == SINGULAR:
        x, y, phi = (*pose.pose, m.phi_range[0])[:3]  # one orientation: the pose is (x, y)
        notes.append(f"  singular pose: x = {x:.12g}, y = {y:.12g}, phi = {phi:.12g} deg, legs "
                     f"{', '.join(f'{v:.12g}' for v in pose.joints)}, {pose.value_text('det J')}")
        counterexample = Table("Singular pose", COUNTEREXAMPLE_HEADER, ((x, y, phi, *pose.joints, pose.value),))
        drawings = ((COUNTEREXAMPLE_PNG, Drawing(figure_pose, (
            m, (x, y, phi), pose.joints, f"{m.name}: a reachable singular pose ({pose.value_text('det J')})"))),)
    if result.status == UNDECIDED:
        notes.append("  " + result.undecided_line())
    row = (m.name, result.status, result.exit_code, result.depth, result.max_depth, result.evaluations,
           result.undecided_volume, result.root_volume)
    # a counterexample of an earlier run is removed when none is found (the set owns it)
    return Verification(f"Verify {m.name}", VERIFY_HEADER, (row,), tuple(notes),
                        ("rpr3-verify", VERIFY_FILES, "fivebar rpr3 verify", VERIFY_CSV), drawings,
                        _csv_of(COUNTEREXAMPLE_CSV, counterexample), result.exit_code, result, counterexample)


@dataclass(frozen=True, repr=False)
class Verification(Verified):
    """`verify`'s row and exit status (a `Verified`, as `fb.verify`'s), with the library's result
    (`status`, `pose`) and the singular pose as a one-row table (None when none is found)."""

    result: object = field(default=None, compare=False)
    counterexample: Table | None = None

    @property
    def status(self) -> str:
        return self.result.status
