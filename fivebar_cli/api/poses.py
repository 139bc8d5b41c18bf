"""The API calls of the kinds whose aspects live in a space of poses (3-RPR, 3-RRR): `verify`
(`fivebar verify`), a certificate that no valid pose is singular, or a singular pose."""

from __future__ import annotations

from dataclasses import dataclass

from fivebar_cli.analyses.limits import MAX_VERIFY_DEPTH
from fivebar_cli.api.calls import _mechanism, check_depth, source_name
from fivebar_cli.api.studies import Report
from fivebar_cli.errors import InputError
from fivebar_cli.mechanisms.base import article


@dataclass(frozen=True, repr=False)
class Verified(Report):
    """verify's report, with the command's exit status (0 certified, 1 singular pose, 3 undecided)."""

    exit_code: int = 0


def verify(mech, depth: int = 14, *, working_mode: str | None = None) -> Report:
    """Can the robot reach a singular pose: a 3-RPR over its orientation range (det J = 0, legs in
    their ranges), a 3-RRR in a working mode (det A = 0 with every leg strictly inside its annulus)?

    Per working mode (`working_mode` only, e.g. '+-+', or every one), the space of poses is
    subdivided until every box is certified invalid or of one non-zero sign ('certified
    singularity-free'), or a wholly valid box holds both signs (bisected to a 'singular pose
    found'), or to `depth` ('undecided').

    Returns
    -------
    Report
        One row of verify.csv per working mode; `notes`, the lines `fivebar verify` prints;
        `exit_code`, the command's exit status (0 certified, 1 a singular pose, 3 undecided);
        `save(folder, figures=True)` writes verify.csv and, with a singular pose,
        counterexample.csv and counterexample.png.

    Examples
    --------
    >>> import fivebar_cli as fb
    >>> v = fb.verify("rpr3-verify/table1-legs-1-1.5", 10)
    >>> [r["status"] for r in v.rows()], v.exit_code
    (['certified singularity-free'], 0)
    """
    from fivebar_cli.analyses.pose_aspect_files import joint_columns, pose_columns
    from fivebar_cli.analyses.pose_aspects import working_sheets
    from fivebar_cli.analyses.pose_verify import EXIT, SINGULAR, UNDECIDED, verify as run
    from fivebar_cli.io.layout import COUNTEREXAMPLE_CSV, COUNTEREXAMPLE_PNG, VERIFY_CSV, VERIFY_FILES

    m = _mechanism(mech)
    model = m.pose_aspect_model()
    if model is None:
        raise InputError(source_name(mech), "type", f"{article(m.kind)} has no space of poses to verify")
    sheets = working_sheets(m, working_mode)
    check_depth(depth, MAX_VERIFY_DEPTH)
    fields = [k for k, _ in model.sheets[0].fields]
    rows, singular, statuses, notes = [], [], [], []
    for sheet in sheets:
        result = run(m, depth, sheet)
        label = model.sheets[sheet].label
        statuses.append(result.status)
        rows.append((m.name, *(v for _, v in model.sheets[sheet].fields), result.status, result.exit_code,
                     result.depth, result.max_depth, result.evaluations, result.undecided_volume, result.root_volume))
        notes.append(f"{m.name}: {label + ': ' if label else ''}" + result.headline())
        if result.status == SINGULAR:
            pose = result.pose
            singular.append((sheet, pose))
            notes.append("  singular pose: " + ", ".join(f"{a} = {v:.12g}" for a, v in zip(pose_columns(m), pose.pose))
                         + ", " + ", ".join(f"{a} = {v:.12g}" for a, v in zip(joint_columns(m), pose.joints))
                         + f", {model.singularity_name} = {pose.value:.3g}")
        if result.status == UNDECIDED:
            notes.append("  " + result.undecided_line())
    header = ("name", *fields, "status", "exit", "depth", "max_depth", "evaluations", "undecided_volume", "root_volume")
    tables, drawings = (), ()
    if singular:
        tables = ((COUNTEREXAMPLE_CSV, [*fields, *pose_columns(m), *joint_columns(m), model.singularity_name],
                   [(*(v for _, v in model.sheets[s].fields), *p.pose, *p.joints, p.value) for s, p in singular]),)

        def figure():
            import numpy as np

            from fivebar_cli.analyses.pose_aspects import sheet_classes
            from fivebar_cli.plotting.pose_aspects import figure_assembly_modes

            poses = np.array([p.pose for _, p in singular])
            classes = np.array([sheet_classes(model, s)[0] for s, _ in singular])
            labels = [f"{model.sheets[s].label or m.name}: {model.singularity_name} = {p.value:.2g}"
                      for s, p in singular]
            return figure_assembly_modes(model, poses, labels, f"{m.name}: valid singular poses", classes)

        drawings = ((COUNTEREXAMPLE_PNG, figure),)
    exit_code = EXIT[SINGULAR] if SINGULAR in statuses else EXIT[UNDECIDED] if UNDECIDED in statuses else 0
    # a counterexample of an earlier run is removed when none is found (the set owns it)
    return Verified(f"Verify {m.name}, depth {depth}", header, tuple(rows), tuple(notes),
                    (f"{m.kind}-verify", VERIFY_FILES, "fivebar verify", VERIFY_CSV), drawings, tables, exit_code)

