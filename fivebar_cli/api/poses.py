"""The API calls of the kinds whose aspects live in a space of poses (3-RPR, 3-RRR): `dkp`
(`fivebar dkp`), every pose with given joint values, certified; `verify` (`fivebar verify`), a
certificate that no valid pose is singular, or a singular pose (what they share with `locate` and
`path` over poses: api/pose_space.py)."""

from __future__ import annotations

from fivebar_cli.analyses.limits import MAX_VERIFY_DEPTH, check_depth
from fivebar_cli.api.calls import _mechanism, check_aspects, depth_or_default, source_name
from fivebar_cli.api.pose_space import (
    joint_poses, numbers, pose_aspects_for, pose_depth, pose_mechanism,
)
from fivebar_cli.api.values import Drawing, Report, Verified
from fivebar_cli.errors import InputError, param
from fivebar_cli.mechanisms.base import is_choice

# ---------------------------------------------------------------- dkp


def dkp(mech, joints, depth: int | None = None, *, budget: int | None = None, folder=None,
        aspects=None, source: str | None = None, what: str = "joints", solved=None) -> Report:
    """Every pose (assembly mode) with the given joint values, certified: a 3-RPR's leg lengths, a
    3-RRR's actuated angles in degrees.

    Branch and prune over the space of poses with the Krawczyk test: each pose is in a small box
    proven to hold exactly one solution, every other box is proven to hold none, so the number of
    assembly modes is certified (boxes left undecided, near a singular pose, are reported as such,
    with `certified` false). Each pose comes with its class and its aspect at `depth`: those of
    `aspects` (an `Aspects` of this mechanism; its depth) when given, else read from `folder` when
    an `aspects` run saved them there, else computed with `budget`.

    Parameters
    ----------
    mech : Mechanism, str, Path or Mapping
        A 3-RPR or 3-RRR with an orientation range (what `load` takes).
    joints : sequence of 3 float
        The joint values, in their ranges.
    depth : int, optional
        Depth of the aspects' trees (at most 9 for an octree; None: 7, or the depth of `aspects`,
        when given: another depth is then refused).
    what : str
        How the notes name the joint values: 'joints', or 'legs' (a 3-RPR's, as `fivebar rpr3 dkp`,
        whose command `save` then records).
    solved : optional
        `joint_poses(mech, joints)` when the caller has already checked and solved them (the
        command line does, to name bad joints before it checks its output folder): not solved again.

    Returns
    -------
    Report
        The rows of dkp.csv (the pose, the class's fields, `aspect`, `certified`), in the order the
        modes are numbered; `notes`, the lines `fivebar dkp` prints; `save(folder, figures=True)`
        writes dkp.csv and dkp.png.

    Examples
    --------
    >>> import fivebar_cli as fb
    >>> d = fb.dkp("rpr3-caro", (14.98, 15.38, 12), 2, budget=0)
    >>> len(d), [r["det_sign"] for r in d.rows()]
    (6, ['+', '+', '+', '-', '-', '-'])
    """
    from fivebar_cli.analyses.pose_aspect_files import pose_columns
    from fivebar_cli.io.layout import DKP_CSV, DKP_FILES, DKP_PNG

    source = source or source_name(mech)
    if not is_choice(what, ("joints", "legs")):  # (it names the joint values: another word was taken as joints)
        raise InputError("", param("what"), f"expected 'joints' or 'legs', got {what!r}")
    m = _mechanism(mech)
    check_aspects(aspects, m, source, depth)
    m = pose_mechanism(m, poses=True, source=source)
    depth = aspects.depth if aspects is not None else pose_depth(m, depth_or_default(m, depth))
    model = m.pose_aspect_model()
    result = solved if solved is not None else joint_poses(m, joints, "legs" if what == "legs" else "joints")
    aspects, where = ((aspects.analysis.aspects, "given") if aspects is not None else
                      pose_aspects_for(m, folder, depth, budget))
    fields = [k for k, _ in model.classes[0].fields]
    rows = []
    for s in result.solutions:
        aspect = _solution_aspect(model, aspects, s)
        cls = (v for _, v in model.classes[s.cls].fields) if s.cls >= 0 else ("0",) * len(fields)
        rows.append((*s.pose, *cls, aspect.number if aspect is not None else "", "true"))
    for lo, hi in zip(result.undecided_lo, result.undecided_hi):
        rows.append((*(0.5 * (lo + hi)), *("",) * len(fields), "", "false"))
    n = len(result.solutions)
    if result.certified:
        notes = [f"{m.name}: {n} assembly modes for {what} ({numbers(joints)}) (certified: every other box of poses "
                 f"holds none; {result.evaluations} boxes tested)"]
    else:
        notes = [f"{m.name}: {n} certified assembly modes for {what} ({numbers(joints)}), not decided: "
                 f"{len(result.undecided_lo)} boxes of poses left near singular poses (written with certified false)"]
    names = [a.name for a in m.spaces()[model.space].axes]
    for k, s in enumerate(result.solutions, start=1):
        place = f"aspect {rows[k - 1][-2]}" if rows[k - 1][-2] != "" else f"in no certified cell at depth {depth}"
        label = model.classes[s.cls].label if s.cls >= 0 else "sign not certified"
        notes.append(f"  mode {k}: " + ", ".join(f"{a} = {v:.10g}" for a, v in zip(names, s.pose)) + f", {label}, {place}")
    notes.append(f"  aspects at depth {depth} {where}")
    drawings = ()
    if n:
        import numpy as np

        from fivebar_cli.plotting.pose_aspects import figure_assembly_modes

        labels = [f"mode {k}: {model.classes[s.cls].label if s.cls >= 0 else '?'}"
                  for k, s in enumerate(result.solutions, start=1)]
        title = f"{m.name}: the {n} assembly modes of {what} ({numbers(joints)})"
        poses = np.array([s.pose for s in result.solutions])
        classes = np.array([max(s.cls, 0) for s in result.solutions])
        drawings = ((DKP_PNG, Drawing(figure_assembly_modes, (model, poses, labels, title, classes))),)
    command = "fivebar rpr3 dkp" if what == "legs" else "fivebar dkp"
    header = (*pose_columns(m), *fields, "aspect", "certified")
    return Report(f"DKP {m.name}, {what} ({numbers(joints)})", header, tuple(rows), tuple(notes),
                  ("dkp", DKP_FILES, command, DKP_CSV), drawings)


def _solution_aspect(model, aspects, solution):
    """The aspect holding a DKP solution in its certified class (None: no certified class, or in no
    certified cell at that depth)."""
    from fivebar_cli.analyses.pose_aspects import aspect_at, sheet_of

    if aspects is None or solution.cls < 0:
        return None
    cls, aspect = aspect_at(aspects, model, solution.pose, sheet_of(model, solution.cls))
    return aspect if cls == solution.cls else None


# ---------------------------------------------------------------- verify


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
    from fivebar_cli.analyses.pose_aspects import pose_model, working_sheets
    from fivebar_cli.analyses.pose_verify import EXIT, SINGULAR, UNDECIDED, verify as run
    from fivebar_cli.io.layout import COUNTEREXAMPLE_CSV, COUNTEREXAMPLE_PNG, VERIFY_CSV, VERIFY_FILES

    m = _mechanism(mech)
    model = pose_model(m, source_name(mech))
    sheets = working_sheets(m, working_mode)
    depth = check_depth(depth, MAX_VERIFY_DEPTH)
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
                         + ", " + pose.value_text(model.singularity_name))
        if result.status == UNDECIDED:
            notes.append("  " + result.undecided_line())
    header = ("name", *fields, "status", "exit", "depth", "max_depth", "evaluations", "undecided_volume", "root_volume")
    tables, drawings = (), ()
    if singular:
        tables = ((COUNTEREXAMPLE_CSV, [*fields, *pose_columns(m), *joint_columns(m), model.singularity_name],
                   [(*(v for _, v in model.sheets[s].fields), *p.pose, *p.joints, p.value) for s, p in singular]),)
        import numpy as np

        from fivebar_cli.analyses.pose_aspects import sheet_classes
        from fivebar_cli.plotting.pose_aspects import figure_assembly_modes

        poses = np.array([p.pose for _, p in singular])
        classes = np.array([sheet_classes(model, s)[0] for s, _ in singular])
        labels = [f"{model.sheets[s].label or m.name}: {p.value_text(model.singularity_name)}" for s, p in singular]
        drawings = ((COUNTEREXAMPLE_PNG, Drawing(figure_assembly_modes,
                                                 (model, poses, labels, f"{m.name}: valid singular poses", classes))),)
    exit_code = EXIT[SINGULAR] if SINGULAR in statuses else EXIT[UNDECIDED] if UNDECIDED in statuses else 0
    # a counterexample of an earlier run is removed when none is found (the set owns it)
    return Verified(f"Verify {m.name}, depth {depth}", header, tuple(rows), tuple(notes),
                    (f"{m.kind}-verify", VERIFY_FILES, "fivebar verify", VERIFY_CSV), drawings, tables, exit_code)
