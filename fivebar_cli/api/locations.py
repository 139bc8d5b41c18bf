"""`locate` of the public API (`fivebar locate`): every configuration at poses or joint values, its
modes and the aspect holding it; for a five-bar or 2-RPR with several locations, whether a
singularity-free motion joins each pair (`analyses.locate.decide`, the answer `path` shares)."""

from __future__ import annotations

from dataclasses import dataclass, field, replace

from fivebar_cli.analyses.limits import MAX_ASPECT_DEPTH, check_depth
from fivebar_cli.api.calls import (
    _mechanism, check_aspects, check_modes, depth_or_default, source_name, widened, with_aspects,
)
from fivebar_cli.api.pose_space import (
    class_values, joint_poses, numbers, pose_aspects_for, pose_depth, pose_mechanism,
)
from fivebar_cli.api.values import Aspects, finite_points
from fivebar_cli.errors import InputError, param
from fivebar_cli.io.files import user_path
from fivebar_cli.mechanisms.base import Mechanism, article, plural


@dataclass(frozen=True, repr=False)
class Location:
    """Every configuration at one or more poses or joint values, with its modes and its aspect (the
    rows of `fivebar locate --csv`: `csv()`); `lines()`, what `fivebar locate` prints (five-bar,
    2-RPR: with two or more locations, whether a singularity-free motion joins each pair)."""

    mechanism: Mechanism
    depth: int
    configurations: tuple[dict, ...]
    columns: tuple[str, ...] = ()
    located: tuple = field(default=(), compare=False)  # per location: (kind, value, ((configuration, row), ...))
    aspects: tuple = field(default=(), compare=False)  # the library's aspects the rows name
    where: str = ""  # where the aspects come from: 'computed' or 'read from FOLDER'
    wanted: tuple = (None, None)  # the working and assembly modes kept (None: any)
    cells: tuple = field(default=(), compare=False)  # over poses: the CSV's cells, one tuple per row
    notes: tuple = field(default=(), compare=False)  # over poses: the report's lines

    def rows(self) -> list[dict]:
        return [dict(c) for c in self.configurations]

    def __repr__(self) -> str:
        aspects = ", ".join(str(c["aspect"]) for c in self.configurations if c.get("aspect") is not None)
        return (f"<Location {self.mechanism.name}, depth {self.depth}: "
                f"{plural(len(self.configurations), 'configuration')}" + (f" in aspects {aspects}" if aspects else "")
                + ">")

    def csv(self) -> str:
        """The rows as `fivebar locate --csv` prints them (booleans true/false, None empty)."""
        from fivebar_cli.io.files import csv_text

        if self.mechanism.pose_aspect_model() is not None:
            return csv_text(self.columns, self.cells)
        cell = {None: "", True: "true", False: "false"}
        return csv_text(self.columns, [[cell.get(r[k], r[k]) if r[k] is None or isinstance(r[k], bool) else r[k]
                                        for k in self.columns] for r in self.configurations])

    def lines(self) -> list[str]:
        """What `fivebar locate` prints: the aspects, each location's configurations and where each
        lies, then (two or more locations) the answer for each pair, as `analyses.locate.decide`
        gives it (computed here: it may pave more finely). Parameters named as data (`errors.Text`)."""
        from fivebar_cli.analyses.locate import Pieces, decide

        if self.mechanism.pose_aspect_model() is not None:
            return list(self.notes)
        m, depth, (working_mode, assembly_mode) = self.mechanism, self.depth, self.wanted
        names = [a.name for a in m.spaces()["jointspace"].axes]
        out = [f"{m.name}: {_aspect_count(self.aspects, m.is_interval)} at depth {depth} {self.where} "
               f"({_certified_count(self.aspects)})"]
        wanted = "".join(f" in {what} {mode}" for what, mode in (("working mode", working_mode),
                                                                 ("assembly mode", assembly_mode)) if mode)
        for k, (kind, value, rows) in enumerate(self.located, start=1):
            count = plural(len(rows), 'configuration') if rows else "no configuration"
            reason = "" if rows or wanted else ": unreachable or cannot assemble"
            out.append(f"location {k}: {kind} ({value[0]:g}, {value[1]:g}): {count}{wanted} "
                       f"(floating-point kinematics, not certified{reason})")
            for c, r in rows:
                out.append(f"  working mode {r['working_mode']}, assembly mode {r['assembly_mode']}: "
                           f"x = {r['x']:.6g}, y = {r['y']:.6g}, {names[0]} = {r[names[0]]:.6g}, "
                           f"{names[1]} = {r[names[1]]:.6g} -> " + _where(r, depth))
        if len(self.located) < 2:
            return out
        out.append("singularity-free motions between locations:")
        pieces, model = Pieces(), m.aspect_model()
        for i in range(len(self.located)):
            for j in range(i + 1, len(self.located)):
                empty = next((k for k in (i, j) if not self.located[k][2]), None)
                if empty is not None:
                    out.append(f"  {i + 1} -> {j + 1}: not decided: location {empty + 1} has no configuration"
                               f"{wanted} (floating-point kinematics): there is nothing to join")
                    continue
                pairs = [(a, b, decide(model, list(self.aspects), a, b, depth, m.is_interval, MAX_ASPECT_DEPTH,
                                       pieces, constrained=bool(m.constraints)))
                         for a, _ in self.located[i][2] for b, _ in self.located[j][2]]
                if len(pairs) == 1:
                    out.append(f"  {i + 1} -> {j + 1}: " + pairs[0][2].line())
                    continue
                out += _pairs_lines(i + 1, j + 1, pairs, model, depth)
        return out


def _pairs_lines(i: int, j: int, pairs, model, depth: int) -> list[str]:
    """Two locations with several configurations: the answer over every pair of them, then the
    verdict of each pair that the modes alone do not settle."""
    from fivebar_cli.analyses.locate import NO, UNDECIDED, mode_verdict, overall

    answer = overall([v for _, _, v in pairs])
    said = answer if answer != UNDECIDED else f"{answer} at depth {depth}"
    head = f"  {i} -> {j}: {said}, over the {len(pairs)} pairs"
    apart = [v.answer == NO and mode_verdict(model, a, b, depth) is not None for a, b, v in pairs]
    if all(apart):
        return [f"{head}: every pair has different modes, so every motion between them crosses a singularity"]
    out = [f"{head} of their configurations:"]
    for (a, b, v), settled in zip(pairs, apart):
        if not settled:
            modes = f"working mode {a.working}, det A {a.assembly}"
            if (a.working, a.assembly) != (b.working, b.assembly):
                modes += f" -> working mode {b.working}, det A {b.assembly}"
            out.append(f"    {modes}: " + v.line())
    if any(apart):
        out.append(f"    the other {plural(sum(apart), 'pair')}: no: different modes")
    return out


def _aspect_count(aspects, robust: bool) -> str:
    return plural(len(aspects), "robust aspect" if robust else "aspect")


def _certified_count(aspects) -> str:
    """How many of the aspects are certified, in words."""
    good = sum(a.certified for a in aspects)
    if not aspects:
        return "none has certified cells at this depth"
    if good == len(aspects):
        return "certified" if good == 1 else "all certified"
    return "not certified" if len(aspects) == 1 else ("none certified" if good == 0 else f"{good} certified, "
                                                      f"{len(aspects) - good} not certified")


def _where(row: dict, depth: int) -> str:
    """Where a configuration lies: its aspect, the constraint it violates, the singularity it is on or
    near, or no cell."""
    from fivebar_cli.analyses.locate import deeper

    if row.get("violates"):
        return f"violates the {row['violates']} (in no aspect)"
    if row["aspect"] is not None:
        return f"aspect {row['aspect']} ({'certified' if row['aspect_certified'] else 'not certified at this depth'})"
    if row["singular"]:
        return f"on or near a singularity: {row['singular']}"
    return (f"in no certified cell at depth {depth} (too close to a singularity for cells this size: "
            + deeper(depth, MAX_ASPECT_DEPTH) + ")")


def _points(value, which: str, axes, source: str) -> list[tuple[float, ...]]:
    """One point or several [(...), ...] as a list of tuples of finite numbers, one per axis of
    `axes` (None: none); InputError naming `which` (pose, joints or legs) else."""
    if value is None:
        return []
    a = finite_points(value, len(axes), many=True)
    if a is None:
        names = ", ".join(axis.name for axis in axes)
        raise InputError(str(source), param(which), f"expected ({names}) or a list of them, got {value!r}")
    return [tuple(map(float, p)) for p in a]


def locate(mech, *, pose=None, joints=None, depth: int | None = None, aspects: Aspects | None = None,
           working_mode: str | None = None, assembly_mode: str | None = None, budget: int | None = None,
           folder=None, source: str | None = None, advance=None, legs=None,
           tolerance: float | None = None) -> Location:
    """Every configuration at a pose (x, y) or at joint values, with its modes and the aspect holding
    it at `depth`.

    Five-bar and 2-RPR: `pose` and `joints` may each be one point or a list of them (the locations,
    poses first, as `fivebar locate --pose ... --joints ...`); only the configurations of
    `working_mode` and `assembly_mode` are kept when given. The aspects are `aspects` when given
    (their depth is the call's: another `depth` is refused), else those an `aspects` run wrote into
    `folder` for this mechanism at `depth` (None: 10, or 7 over poses), else computed
    (with `budget`; `advance` as for `aspects`). `lines()` gives the command's report, with the
    answer for each pair of locations; `csv()` its `--csv` output. `source`: how messages name the
    mechanism (default: its file, or its name). `tolerance`: the lengths widened by it, as
    `fb.load(..., tolerance=)`: the configurations are the nominal robot's, the aspects robust.

    Over a space of poses (3-RPR, 3-RRR), each `pose` (x, y, phi_deg) is located in every working
    mode (a 3-RRR's pose does not decide it) or in `working_mode` only ('+-+', as `fivebar locate
    --working-mode`), each `joints` (`legs`: a 3-RPR's leg lengths, so named in the rows) at every
    pose they give (`dkp`): one row per pose and working mode, with `input` (the location's
    number), `location`, `pose`, `joints`, `sheet` (its fields: {} for a 3-RPR), `class` (None on
    or near a singularity), `aspect`, `aspect_certified` and `violates` (a constraint, or '').
    `lines()` is `fivebar locate`'s report (with two or more locations, which share an aspect);
    `depth` at most 9 for an octree.

    Examples
    --------
    >>> import fivebar_cli as fb
    >>> [(r["working_mode"], r["aspect"]) for r in fb.locate(fb.load("rpr2"), pose=(0, 8), depth=6).rows()]
    [('++', 1)]
    """
    source = source or source_name(mech)
    m = with_aspects(widened(_mechanism(mech), tolerance, source), source)
    check_aspects(aspects, m, source, depth)
    depth = aspects.depth if aspects is not None else depth_or_default(m, depth)
    if m.pose_aspect_model() is not None:
        if assembly_mode is not None:  # (taken without a word before)
            raise InputError(source, param("assembly_mode"), f"{article(m.kind)}'s pose decides its class (an "
                             "assembly mode): every configuration at the locations is given, with its class")
        return locate_poses(m, pose, legs, joints, depth, aspects, working_mode, budget, folder, source, advance)
    depth = check_depth(depth, MAX_ASPECT_DEPTH)
    if legs is not None:
        raise InputError(source, param("legs"), f"{article(m.kind)} has no legs to give: give joints")
    check_modes(m, source, (working_mode,), assembly_mode)
    spaces = m.spaces()
    places = ([("pose", p) for p in _points(pose, "pose", spaces["workspace"].axes, source)]
              + [("joints", j) for j in _points(joints, "joints", spaces["jointspace"].axes, source)])
    if not places:
        raise InputError(source, param("pose"), "give pose or joints (or both)")
    from fivebar_cli.analyses.aspect_files import load_aspects
    from fivebar_cli.analyses.locate import aspect_of, configurations, row

    saved = load_aspects(user_path(folder, "folder"), m, depth) if folder is not None and aspects is None else None
    if aspects is not None:
        found, where = aspects.analysis.aspects, "given"
    elif saved is not None:
        found, where = saved, f"read from {folder}"
    else:
        from fivebar_cli.api.calls import aspects as compute

        found, where = compute(m, depth, budget=budget, shapes=False, advance=advance).analysis.aspects, "computed"
    located = []
    for k, (kind, value) in enumerate(places, start=1):
        here = [c for c in configurations(m, value, "workspace" if kind == "pose" else "jointspace")
                if (not working_mode or c.working == working_mode) and (not assembly_mode or c.assembly == assembly_mode)]
        located.append((kind, value, tuple((replace(c, label=f"location {k}"),
                                            {**row(m, c, aspect_of(found, c), k),
                                             "location": f"{kind} {value[0]:g} {value[1]:g}"}) for c in here)))
    names = [a.name for a in m.spaces()["jointspace"].axes]
    columns = ("input", "location", "x", "y", *names, "working_mode", "assembly_mode", "aspect", "singular",
               "aspect_certified", *(("violates",) if m.constraints else ()))
    rows = tuple(r for _, _, here in located for _, r in here)
    return Location(m, depth, rows, columns, tuple(located), tuple(found), where, (working_mode, assembly_mode))


# ---------------------------------------------------------------- over a space of poses


def locate_poses(m: Mechanism, pose, legs, joints, depth: int, aspects, working_mode: str | None, budget,
                 folder, source: str, advance):
    """`fb.locate` of a 3-RPR or 3-RRR: every pose (in every working mode or in `working_mode`)
    and every pose of each joint values (`legs`, `joints`), with its class and aspect; the rows,
    the CSV and the lines of `fivebar locate`. Bad input is named before any aspect is computed."""
    from fivebar_cli.analyses.pose_aspect_files import joint_columns, pose_columns
    from fivebar_cli.analyses.pose_aspects import aspect_at, sheet_classes, sheet_of, working_sheets
    from fivebar_cli.analyses.pose_paths import check_pose, wrap_pose

    m = pose_mechanism(m, poses=True, source=source)
    depth = pose_depth(m, depth)  # (the aspects' when given: `locate` decided it)
    model = m.pose_aspect_model()
    space = m.spaces()[model.space]
    sheets = working_sheets(m, working_mode)
    locations = [(kind, p) for kind, value in (("pose", pose), ("legs", legs), ("joints", joints))
                 for p in _points(value, kind, space.axes if kind == "pose" else model.joint_axes, source)]
    if not locations:
        raise InputError(source, param("pose"), "give pose, joints or legs (or several)")
    solved = {}  # joint values' poses, solved first: bad input is named before any aspect is computed
    for k, (kind, value) in enumerate(locations, start=1):
        if kind == "pose":
            check_pose(m, wrap_pose(space, value), f"pose ({numbers(value)})", source)
        else:
            solved[k] = joint_poses(m, value, kind)
    if aspects is not None:
        found, where = aspects.analysis.aspects, "given"
    else:
        found, where = pose_aspects_for(m, folder, depth, budget, advance)
    rows, undecided = [], {}
    for k, (kind, value) in enumerate(locations, start=1):
        if kind == "pose":
            here = [(wrap_pose(space, value), sheet, None) for sheet in sheets]
        else:
            result = solved[k]
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
