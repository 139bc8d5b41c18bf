"""The five-bar studies of the public API: the sensitivity to manufacturing tolerances (`tolerance`,
`fivebar tolerance`) and the paper's Table 1 of evaluation counts (`kratio`, `fivebar kratio`).

Each returns a `Report`: an immutable table (`columns`, `rows()` as the CSV's dicts) with the lines
the command prints (`notes`) and `save(folder, figures=True)`, which writes the command's files
(the same bytes, as one output set)."""

from __future__ import annotations

import math
import numbers
import os
from collections.abc import Mapping

from fivebar_cli.analyses.limits import MAX_DEPTH, check_depth
from fivebar_cli.api.calls import load, source_name
from fivebar_cli.api.values import Drawing, Report
from fivebar_cli.errors import InputError, param
from fivebar_cli.mechanisms.base import Mechanism, article, plural

MAX_TOLERANCES = 50  # a study paves both spaces and analyses the aspects once per tolerance
DEFAULT_TOLERANCES = (0.0, 0.01, 0.02, 0.05, 0.1)
DEFAULT_DEPTHS = tuple(range(5, 11))


# ---------------------------------------------------------------- tolerance


def tolerance_mechanism(mech, tolerances) -> tuple[Mechanism, list[float]]:
    """The five-bar of a tolerance study and its tolerances (`tolerance_values`), checked: every
    tolerance a finite number >= 0 (at most `MAX_TOLERANCES` of them) that keeps every length
    positive (InputError naming `tolerances`, or the length reaching 0, with the mechanism's source)."""
    m = load(mech, kind="fivebar")
    values = tolerance_values(tolerances, source_name(mech))
    for t in values:
        m.nominal().widened(t, source_name(mech))  # every tolerance keeps the lengths positive
    return m, values


def tolerance_values(tolerances, source: str = "") -> list[float]:
    """The tolerances sorted, each once: 1 to `MAX_TOLERANCES` finite numbers >= 0 (InputError
    naming `tolerances` otherwise: a str or a bool is no number, as for `tolerance`)."""
    from fivebar_cli.io.schema import is_number

    items = None if isinstance(tolerances, (str, bytes)) or not hasattr(tolerances, "__iter__") else list(tolerances)
    if items is None or not all(is_number(t) for t in items):
        raise InputError(source, param("tolerances"), f"expected a sequence of numbers, got {tolerances!r}")
    values = sorted({float(t) for t in items})
    if not 1 <= len(values) <= MAX_TOLERANCES:
        raise InputError(source, param("tolerances"), f"give 1 to {MAX_TOLERANCES} tolerances, got {len(values)}")
    if not all(math.isfinite(t) and t >= 0 for t in values):
        raise InputError(source, param("tolerances"), f"must be finite numbers >= 0, got {values!r}")
    return values


def tolerance(mech, tolerances=DEFAULT_TOLERANCES, depth: int = 10, *, jobs: int | None = 1,
              advance=None) -> Report:
    """How manufacturing tolerances shrink a five-bar's workspace, joint space and aspects.

    For each tolerance T (sorted, each once) every link length becomes [L - T, L + T] around the
    nominal lengths: the robust area (valid for every length vector) and the possible one (valid
    for some) of both spaces beside the nominal area, and for each nominal aspect the area of the
    robust aspects it still holds (rows `aspect-NN`, no possible area: '').

    Parameters
    ----------
    mech : Mechanism, str, Path or Mapping
        A five-bar (what `load` takes).
    tolerances : sequence of float
        The tolerances T, finite and >= 0 (0: the nominal five-bar); at most 50.
    depth : int
        Depth of every paving.
    jobs : int or None
        Worker processes for the independent pavings (None: one per core); the same result for any.
    advance : callable, optional
        `advance(n=1)`, told of each step: 3 per tolerance (its two spaces, its aspects).

    Returns
    -------
    Report
        The rows of tolerance.csv (`tolerance`, `region`, `robust_area`, `possible_area`,
        `nominal_area`), the report's lines in `notes`; `save(folder)` writes tolerance.csv,
        tolerance-bands.png and tolerance-aspects.png.

    Examples
    --------
    >>> import fivebar_cli as fb
    >>> t = fb.tolerance("m1", [0, 0.05], 6)
    >>> [(r["tolerance"], r["region"]) for r in t.rows()][:2]
    [(0.0, 'workspace'), (0.0, 'jointspace')]
    """
    from fivebar_cli.analyses.tolerance import HEADER, fate_text, tolerance_study
    from fivebar_cli.io.layout import TOLERANCE_ASPECTS_PNG, TOLERANCE_BANDS_PNG, TOLERANCE_CSV, TOLERANCE_FILES

    m, tolerances = tolerance_mechanism(mech, tolerances)
    depth = check_depth(depth, MAX_DEPTH)
    study = tolerance_study(m, tolerances, depth, advance or (lambda n=1: None), jobs)
    nominal = study.nominal
    count = (f"{plural(len(nominal.aspects), 'nominal generalized aspect')}, certified" if nominal.certified else
             f"between {nominal.lower} and {plural(nominal.upper, 'nominal generalized aspect')}, not certified at "
             f"this depth: the aspect rows cover only those with certified cells")
    notes = [f"{m.name}: tolerance study at depth {depth} ({count})",
             f"  {'T':>8s} {'space':10s} {'robust':>12s} {'possible':>12s} {'nominal':>12s}"]
    notes += [f"  {r.tolerance:8g} {r.region:10s} {r.robust_area:12.6g} {r.possible_area:12.6g} {r.nominal_area:12.6g}"
              for r in study.rows if not r.region.startswith("aspect")]
    for tol in tolerances:
        if not study.robust[tol].certified:
            notes.append(f"  T = {tol:g}: " + study.robust[tol].headline())
        changed = [f for f in study.fates[tol] if f.verdict != "keeps its area"]
        if changed:
            notes.append(f"  T = {tol:g}: " + "; ".join(f"aspect {f.number} {fate_text(f)}" for f in changed))

    from fivebar_cli.plotting.tolerance import figure_aspect_areas, figure_bands

    bands, aspect_areas = Drawing(figure_bands, (study,)), Drawing(figure_aspect_areas, (study,))
    return Report(f"Tolerance {m.name}, depth {depth}", HEADER, tuple(r.cells() for r in study.rows), tuple(notes),
                  ("tolerance", TOLERANCE_FILES, "fivebar tolerance", TOLERANCE_CSV),
                  ((TOLERANCE_BANDS_PNG, bands), (TOLERANCE_ASPECTS_PNG, aspect_areas)))


# ---------------------------------------------------------------- kratio


def kratio_mechanism(mech) -> Mechanism:
    """A mechanism of Table 1, checked to have a 2-D space to pave (InputError on its `type`)."""
    from fivebar_cli.analyses.kratio import planar_spaces

    m = load(mech)
    if not planar_spaces(m):
        raise InputError(source_name(mech), "type", f"{article(m.kind)} has no 2-D space to pave (the table "
                         "compares quadtrees)")
    return m


def kratio_steps(mechanisms: list[Mechanism], depths) -> int:
    """How many rows (and steps of `advance`) `kratio` makes."""
    from fivebar_cli.analyses.kratio import row_count

    return row_count(mechanisms, sorted(set(depths)))


def kratio(mechs, depths=DEFAULT_DEPTHS, *, advance=None) -> Report:
    """The paper's Table 1: evaluations K = n / 4^d of our tests and of the paper's procedure.

    One row per (space, mechanism, depth), spaces in the order the kinds declare them: our tight
    tests' evaluations and K, and for a five-bar the paper's interval procedure, its K as the
    paper prints it and, for M1 and M2, the K printed in the paper ('' where there is none).

    Parameters
    ----------
    mechs : sequence of (Mechanism, str, Path or Mapping), or one of them
        Mechanisms with a 2-D space (five-bar, 2-RPR).
    depths : int or sequence of int
        Depths in 0..20.
    advance : callable, optional
        `advance(n=1)`, told of each row done.

    Returns
    -------
    Report
        The rows of kratio.csv; `notes` the lines `fivebar kratio` prints; `save(folder)` writes
        kratio.csv and kratio.png.

    Examples
    --------
    >>> import fivebar_cli as fb
    >>> k = fb.kratio(["m1"], [5])
    >>> [(r["space"], r["evaluations"], r["paper_printed_percent"]) for r in k.rows()]
    [('jointspace', 485, 99), ('workspace', 485, 72)]
    """
    from fivebar_cli.analyses.kratio import HEADER, kratio_rows
    from fivebar_cli.io.layout import KRATIO_CSV, KRATIO_FILES, KRATIO_PNG

    if isinstance(mechs, (str, os.PathLike, Mechanism, Mapping)):
        mechs = [mechs]
    elif not hasattr(mechs, "__iter__"):
        raise InputError("", param("mechs"), f"expected a mechanism or a sequence of them, got {mechs!r}")
    ms = [kratio_mechanism(m) for m in mechs]
    if not ms:
        raise InputError("", param("mechs"), "give at least one mechanism")
    # one depth, as one mechanism; a str is no sequence of depths (its characters were read as depths)
    if isinstance(depths, (str, bytes)) or not (isinstance(depths, numbers.Integral) or hasattr(depths, "__iter__")):
        raise InputError("", param("depths"), f"expected a depth or a sequence of depths, got {depths!r}")
    depths = [depths] if isinstance(depths, numbers.Integral) else list(depths)
    if not depths:
        raise InputError("", param("depths"), "give at least one depth")
    depths = [check_depth(d, MAX_DEPTH, "depths") for d in depths]
    rows = kratio_rows(ms, sorted(set(depths)), advance or (lambda n=1: None))
    notes = []
    for r in rows:
        printed = f"{r['paper_printed_percent']}%" if r["paper_printed_percent"] != "" else "-"
        notes.append(f"{r['space']:10s} {r['mechanism']:6s} d={r['depth']:2d}  ours {r['evaluations']:8d} "
                     f"(K {r['K']:.2%})  paper's procedure {_cell(r['paper_procedure_evaluations'], '8d')} "
                     f"(K {_cell(r['paper_procedure_K'], '.2%')}, printed {printed})  "
                     f"saving {_cell(r['saving_vs_paper'], '.0%')}")

    from fivebar_cli.plotting.kratio import figure_kratio

    figure = Drawing(figure_kratio, (rows,))
    return Report(f"Table 1 of {', '.join(m.name for m in ms)}", HEADER, tuple(tuple(r[k] for k in HEADER) for r in rows),
                  tuple(notes), ("kratio", KRATIO_FILES, "fivebar kratio", KRATIO_CSV), ((KRATIO_PNG, figure),))


def _cell(value, fmt: str) -> str:
    return "-" if value == "" else format(value, fmt)
