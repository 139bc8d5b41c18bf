"""The API calls of the kinds whose aspects live in a space of poses (3-RPR, 3-RRR): `dkp`
(`fivebar dkp`), every pose with given joint values, certified; `verify` (`fivebar verify`), a
certificate that no valid pose is singular, or a singular pose; and what `locate` and `path` over
poses share with them: the mechanism checked (`pose_mechanism`), joint values solved into their
assembly modes (`joint_poses`), the aspects reused from a folder or computed (`pose_aspects_for`)."""

from __future__ import annotations

from dataclasses import dataclass

from pathlib import Path

from fivebar_cli.analyses.limits import MAX_PLANE_DEPTH, MAX_POSE_DEPTH, MAX_VERIFY_DEPTH
from fivebar_cli.api.calls import _mechanism, check_depth, source_name
from fivebar_cli.api.studies import Report
from fivebar_cli.errors import InputError, param
from fivebar_cli.mechanisms.base import Mechanism, article

DEFAULT_POSE_DEPTH = 7


def numbers(values) -> str:
    """Values as messages list them: '14.98, 15.38, 12'."""
    return ", ".join(f"{v:g}" for v in values)


def pose_mechanism(mech, *, poses: bool = False, depth: int | None = None, source: str | None = None) -> Mechanism:
    """A mechanism with a pose-space aspect model, checked: an orientation range of at most one
    turn; with `poses`, a space of poses with the three axes (x, y, phi) that poses and joint
    values need; with `depth`, one its trees can be paved to (at most `MAX_POSE_DEPTH` for an
    octree, `MAX_PLANE_DEPTH` for a single orientation). InputError naming the field otherwise."""
    m = _mechanism(mech)
    source = source or source_name(mech)
    model = m.pose_aspect_model()
    if model is None:
        raise InputError(source, "legs.rho_max", f"this {m.kind} has no bounded space of poses to pave (give rho_max)")
    space = m.spaces()[model.space]
    for axis in space.axes:
        if axis.unit == "deg" and axis.hi - axis.lo > 360.0:
            raise InputError(source, "phi_range", f"[{axis.lo:g}, {axis.hi:g}] is wider than a full turn: aspects "
                             "need at most one turn (a full turn is [phi1, phi1 + 360], e.g. [-180, 180])")
    if poses and space.dim != 3:
        raise InputError(source, "phi", f"a single orientation: the poses (x, y, phi) of locate, path and dkp need "
                         f"an orientation range (phi_range), the space here has {space.dim} axes")
    if depth is not None:
        check_depth(depth, MAX_PLANE_DEPTH)
        if space.dim > 2 and depth > MAX_POSE_DEPTH:
            raise InputError("", param("depth"), f"{depth} is too deep for an octree of poses (at most "
                             f"{MAX_POSE_DEPTH}: about 4x the time and memory per level; up to {MAX_PLANE_DEPTH} "
                             "for a single orientation)")
    return m


def check_joints(m: Mechanism, joints, field: str = "joints") -> None:
    """Joint values in their ranges (InputError on `field`, `joints` or `legs`, otherwise)."""
    for axis, value in zip(m.pose_aspect_model().joint_axes, joints):
        if not axis.periodic and not axis.lo <= value <= axis.hi:
            raise InputError("", param(field), f"{axis.name} = {value:g} is outside its range [{axis.lo:g}, {axis.hi:g}]")


def joint_poses(m: Mechanism, joints, field: str = "joints"):
    """Every pose with these joint values (`analyses.dkp.DkpResult`); InputError on `field` for
    values out of their ranges or that give no pose at all (certified)."""
    from fivebar_cli.analyses.dkp import solve

    model = m.pose_aspect_model()
    if len(joints) != len(model.joint_axes):
        raise InputError("", param(field), f"expected {len(model.joint_axes)} joint values, got {len(joints)}")
    check_joints(m, joints, field)
    result = solve(model, m.spaces()[model.space], [float(j) for j in joints])
    if not result.solutions and result.certified:
        raise InputError("", param(field), f"({numbers(joints)}) give no pose within the space of poses (certified: "
                         "every box of poses is proven to hold none)")
    return result


def pose_aspects_for(m: Mechanism, folder, depth: int, budget: int | None = None, advance=None):
    """(aspects, where): the aspects an `aspects` run saved in `folder` for this mechanism and
    depth ('read from FOLDER'), or computed ('computed'); the library's `PoseAspect`s."""
    from fivebar_cli.analyses.aspects import DEFAULT_BUDGET
    from fivebar_cli.analyses.pose_aspect_files import load_pose_aspects
    from fivebar_cli.analyses.pose_aspects import analyse_pose_aspects

    folder = Path(folder) if folder is not None else None
    saved = load_pose_aspects(folder, m, depth) if folder is not None and folder.is_dir() else None
    if saved is not None:
        return saved, f"read from {folder}"
    budget = DEFAULT_BUDGET if budget is None else budget
    return analyse_pose_aspects(m, depth, advance or (lambda n=1: None), budget).aspects, "computed"


def class_values(model, cls: int, sheet: int) -> list[str]:
    """The class's field values for a CSV row; for no certified class, the sheet's fields and '0'."""
    if cls >= 0:
        return [v for _, v in model.classes[cls].fields]
    known = dict(model.sheets[sheet].fields)
    return [known.get(k, "0") for k, _ in model.classes[0].fields]


# ---------------------------------------------------------------- dkp


def dkp(mech, joints, depth: int = DEFAULT_POSE_DEPTH, *, budget: int | None = None, folder=None,
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
    depth : int
        Depth of the aspects' trees (at most 9 for an octree).
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
    depth = aspects.depth if aspects is not None else depth
    m = pose_mechanism(mech, poses=True, depth=depth, source=source)
    model = m.pose_aspect_model()
    result = solved if solved is not None else joint_poses(m, joints, "legs" if what == "legs" else "joints")
    aspects, where = ((aspects.analysis.aspects, "given") if aspects is not None else
                      pose_aspects_for(m, folder, depth, budget))
    fields = [k for k, _ in model.classes[0].fields]
    rows = []
    for s in result.solutions:
        aspect = _solution_aspect(model, aspects, s)
        rows.append((*s.pose, *(class_values(model, s.cls, 0) if s.cls >= 0 else ("0",) * len(fields)),
                     aspect.number if aspect is not None else "", "true"))
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
        def figure():
            import numpy as np

            from fivebar_cli.plotting.pose_aspects import figure_assembly_modes

            labels = [f"mode {k}: {model.classes[s.cls].label if s.cls >= 0 else '?'}"
                      for k, s in enumerate(result.solutions, start=1)]
            title = f"{m.name}: the {n} assembly modes of {what} ({numbers(joints)})"
            poses = np.array([s.pose for s in result.solutions])
            classes = np.array([max(s.cls, 0) for s in result.solutions])
            return figure_assembly_modes(model, poses, labels, title, classes)

        drawings = ((DKP_PNG, figure),)
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



# ---------------------------------------------------------------- path over poses (`fb.path`)


def pose_path(m: Mechanism, start, goal, depth: int, working_mode: str | None, joints, legs, folder, source: str):
    """`fb.path` of a 3-RPR or 3-RRR: between two poses (in `working_mode`), or between assembly
    modes `start` and `goal` of `joints` (`legs`)."""
    import numpy as np

    from fivebar_cli.analyses.pose_aspect_files import joint_columns, load_pose_aspects, pose_columns
    from fivebar_cli.analyses.pose_aspects import motion_sheet, sheet_of
    from fivebar_cli.analyses.pose_paths import find_motion, wrap_pose
    from fivebar_cli.api.values import Path_

    m = pose_mechanism(m, poses=True, depth=depth, source=source)
    model = m.pose_aspect_model()
    space = m.spaces()[model.space]
    if joints is not None and legs is not None:
        raise InputError(source, param("legs"), "give joints or legs, not both")
    values, field = (legs, "legs") if legs is not None else (joints, "joints")
    if values is not None:
        result = joint_poses(m, values, field)
        count = len(result.solutions)
        for name, mode in (("start", start), ("goal", goal)):
            if isinstance(mode, bool) or not isinstance(mode, (int, np.integer)) or not 1 <= mode <= count:
                raise InputError("", param(name), f"mode {mode} is out of range: {field} ({numbers(values)}) have "
                                 f"{count} assembly modes" + ("" if result.certified else " certified"))
        chosen = [result.solutions[k - 1] for k in (start, goal)]
        ends = [s.pose for s in chosen]
        sheets = tuple(sheet_of(model, s.cls) if s.cls >= 0 else 0 for s in chosen)
        labels = (f"assembly mode {start}", f"assembly mode {goal}")
    else:
        sheet = motion_sheet(m, working_mode)
        ends = [wrap_pose(space, np.asarray(p, float)) for p in (start, goal)]
        sheets = (sheet, sheet)
        labels = tuple(f"pose ({numbers(p)})" for p in (start, goal))
    saved = load_pose_aspects(Path(folder), m, depth) if folder is not None and Path(folder).is_dir() else None
    motion = find_motion(m, depth, ends[0], ends[1], labels, source, saved, sheets)
    where = (f"aspect {motion.aspect.number}, {'certified' if motion.aspect.certified else 'not certified'}"
             if motion.aspect is not None else "one generalized aspect")
    notes = [f"{m.name}: singularity-free motion in {where}: {model.classes[motion.cls].label}, depth {depth}",
             f"  from {labels[0]} to {labels[1]}: {len(motion.poses)} waypoints, length {motion.length:.6g} "
             f"({', '.join(a.name for a in space.axes)}); every segment lies in the certified cells "
             f"({motion.motion.checked_cells} cells, checked in exact arithmetic)"]
    if saved is not None:
        notes.append(f"  aspect trees read from {folder}")
    return Path_(m, depth, (*pose_columns(m), *joint_columns(m)), np.hstack([motion.poses, motion.joints]),
                 motion.length, motion, tuple(notes), Path(folder) if saved is not None else None, labels)


# ---------------------------------------------------------------- locate over poses (`fb.locate`)


def locate_poses(m: Mechanism, pose, legs, joints, depth: int, aspects, working_mode: str | None, budget,
                 folder, source: str, advance):
    """`fb.locate` of a 3-RPR or 3-RRR: every pose (in every working mode or in `working_mode`)
    and every pose of each joint values (`legs`, `joints`), with its class and aspect; the rows,
    the CSV and the lines of `fivebar locate`. Bad input is named before any aspect is computed."""
    from fivebar_cli.analyses.pose_aspect_files import joint_columns, pose_columns
    from fivebar_cli.analyses.pose_aspects import aspect_at, sheet_classes, sheet_of, working_sheets
    from fivebar_cli.analyses.pose_paths import check_pose, wrap_pose
    from fivebar_cli.api.locations import Location, _points

    depth = aspects.depth if aspects is not None else depth
    m = pose_mechanism(m, poses=True, depth=depth, source=source)
    model = m.pose_aspect_model()
    space = m.spaces()[model.space]
    sheets = working_sheets(m, working_mode)
    locations = [(kind, p) for kind, value in (("pose", pose), ("legs", legs), ("joints", joints))
                 for p in _points(value)]
    if not locations:
        raise InputError(source, param("pose"), "give pose, joints or legs (or several)")
    for kind, value in locations:  # bad input named before anything is computed
        if kind == "pose":
            check_pose(m, wrap_pose(space, value), f"pose ({numbers(value)})", source)
        else:
            check_joints(m, value, kind)
    if aspects is not None:
        found, where = aspects.analysis.aspects, "given"
    else:
        found, where = pose_aspects_for(m, folder, depth, budget, advance)
    rows, undecided = [], {}
    for k, (kind, value) in enumerate(locations, start=1):
        if kind == "pose":
            here = [(wrap_pose(space, value), sheet, None) for sheet in sheets]
        else:
            result = joint_poses(m, value, kind)
            here = [(s.pose, sheet_of(model, s.cls) if s.cls >= 0 else 0, s.cls) for s in result.solutions]
            undecided[k] = "" if result.certified else f", {len(result.undecided_lo)} boxes of poses not decided"
        for at, sheet, known in here:
            cls, aspect = aspect_at(found, model, at, sheet)
            if known is not None and cls != known:  # the joints decided: a certified class elsewhere, or none
                cls, aspect = known, None if known < 0 else aspect
            legs_at, _ = model.ikp(at[None, :], cls if cls >= 0 else sheet_classes(model, sheet)[0])
            violates = "; ".join(model.violated_constraints(at[None, :], sheet)[0]) if m.constraints else ""
            rows.append({"input": k, "location": f"{kind} {' '.join(f'{v:g}' for v in value)}", "pose": at,
                         "joints": legs_at[0], "cls": cls, "sheet": sheet, "aspect": aspect, "violates": violates})
    fields = [k for k, _ in model.classes[0].fields]
    extra = ("violates",) if m.constraints else ()
    columns = ("input", "location", *pose_columns(m), *joint_columns(m), *fields, "aspect", "aspect_certified", *extra)
    cells = tuple((r["input"], r["location"], *r["pose"], *r["joints"], *class_values(model, r["cls"], r["sheet"]),
                   r["aspect"].number if r["aspect"] else "",
                   ("true" if r["aspect"].certified else "false") if r["aspect"] else "",
                   *((r["violates"],) if extra else ())) for r in rows)
    notes = _locate_lines(m, depth, where, locations, rows, undecided)
    values = tuple({"input": r["input"], "location": r["location"], "pose": tuple(map(float, r["pose"])),
                    "joints": tuple(map(float, r["joints"])), "sheet": dict(model.sheets[r["sheet"]].fields),
                    "class": dict(model.classes[r["cls"]].fields) if r["cls"] >= 0 else None,
                    "aspect": r["aspect"].number if r["aspect"] else None,
                    "aspect_certified": bool(r["aspect"].certified) if r["aspect"] else None,
                    "violates": r["violates"]} for r in rows)
    return Location(m, depth, values, columns, tuple(locations), tuple(found), where, (working_mode, None), cells,
                    tuple(notes))


def _locate_lines(m: Mechanism, depth: int, where: str, locations, rows, undecided) -> list[str]:
    """What `fivebar locate` prints over poses: each location's poses, their class and aspect; with
    two or more locations, which pairs share an aspect."""
    model = m.pose_aspect_model()
    names = [a.name for a in m.spaces()[model.space].axes]
    out = [f"{m.name}: aspects at depth {depth} {where}"]
    for k, (kind, value) in enumerate(locations, start=1):
        mine = [r for r in rows if r["input"] == k]
        what = f"{kind} ({numbers(value)})"
        if kind != "pose":
            what += f": {len(mine)} poses" + (" (certified)" if not undecided[k] else undecided[k])
        out.append(f"location {k}: {what}")
        for r in mine:
            sheet = model.sheets[r["sheet"]].label
            why = f"violates the {r['violates']}" if r["violates"] else "on or near a singularity (no certified sign)"
            label = model.classes[r["cls"]].label if r["cls"] >= 0 else (f"{sheet}: " if sheet else "") + why
            a = r["aspect"]
            place = (f"aspect {a.number}" + ("" if a.certified else " (not certified at this depth)") if a else
                     "in no certified cell at this depth" if r["cls"] >= 0 else "in no aspect")
            out.append("  " + ", ".join(f"{n} = {v:.6g}" for n, v in zip(names, r["pose"])) + ", "
                       + ", ".join(f"{ax.name} = {v:.6g}" for ax, v in zip(model.joint_axes, r["joints"]))
                       + f": {label} -> {place}")
    if len(locations) >= 2:
        out.append("singularity-free motions between locations:")
        held = {k: {r["aspect"].number for r in rows if r["input"] == k and r["aspect"]}
                for k in range(1, len(locations) + 1)}
        for i in range(1, len(locations) + 1):
            for j in range(i + 1, len(locations) + 1):
                shared = sorted(held[i] & held[j])
                out.append(f"  {i} -> {j}: " + (f"yes, within aspect(s) {', '.join(map(str, shared))}" if shared else
                                               "no aspect holds a pose of both at this depth"))
    return out
