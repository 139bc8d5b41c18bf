"""What the API's calls over a space of poses (3-RPR, 3-RRR) share, below their entry points
(`dkp`, `verify`: api/poses.py; `locate`: api/locations.py; `path`, `aspects`: api/calls.py): the
mechanism checked (`pose_mechanism`), joint values checked and solved into their assembly modes
(`joint_poses`), the aspects reused from a folder or computed (`pose_aspects_for`), and `path`'s
motion between two poses or two assembly modes (`pose_path`). It imports no other call module."""

from __future__ import annotations

from pathlib import Path

from fivebar_cli.analyses.limits import MAX_PLANE_DEPTH, MAX_POSE_DEPTH, check_count, check_depth
from fivebar_cli.api.values import finite_points
from fivebar_cli.errors import InputError, param
from fivebar_cli.io.files import user_path
from fivebar_cli.mechanisms.base import Mechanism, article

DEFAULT_POSE_DEPTH = 7


def numbers(values) -> str:
    """Values as messages list them: '14.98, 15.38, 12'."""
    return ", ".join(f"{v:g}" for v in values)


def pose_mechanism(m: Mechanism, *, poses: bool = False, depth: int | None = None, source: str = "") -> Mechanism:
    """A mechanism with a pose-space aspect model, checked: an orientation range of at most one
    turn; with `poses`, a space of poses with the three axes (x, y, phi) that poses and joint
    values need; with `depth`, one its trees can be paved to (at most `MAX_POSE_DEPTH` for an
    octree, `MAX_PLANE_DEPTH` for a single orientation). InputError naming the field otherwise."""
    from fivebar_cli.analyses.pose_aspects import pose_model

    source = source or m.name
    model = pose_model(m, source)
    space = m.spaces()[model.space]
    for axis in space.axes:
        if axis.unit == "deg" and axis.hi - axis.lo > 360.0:
            raise InputError(source, "phi_range", f"[{axis.lo:g}, {axis.hi:g}] is wider than a full turn: aspects "
                             "need at most one turn (a full turn is [phi1, phi1 + 360], e.g. [-180, 180])")
    if poses and space.dim != 3:
        raise InputError(source, "phi", f"a single orientation: the poses (x, y, phi) of locate, path and dkp need "
                         f"an orientation range (phi_range), the space here has {space.dim} axes")
    if depth is not None:
        pose_depth(m, depth)
    return m


def pose_depth(m: Mechanism, depth) -> int:
    """`depth` for the trees of the space of poses of `m` (a mechanism `pose_mechanism` took), as
    the Python int the calls go on with: at most `MAX_POSE_DEPTH` for an octree, `MAX_PLANE_DEPTH`
    for a single orientation (InputError naming `depth` otherwise)."""
    depth = check_depth(depth, MAX_PLANE_DEPTH)
    if m.spaces()[m.pose_aspect_model().space].dim > 2 and depth > MAX_POSE_DEPTH:
        raise InputError("", param("depth"), f"{depth} is too deep for an octree of poses (at most "
                         f"{MAX_POSE_DEPTH}: about 4x the time and memory per level; up to {MAX_PLANE_DEPTH} "
                         "for a single orientation)")
    return depth


def check_joints(m: Mechanism, joints, field: str = "joints") -> None:
    """Joint values in their ranges (InputError on `field`, `joints` or `legs`, otherwise)."""
    for axis, value in zip(m.pose_aspect_model().joint_axes, joints):
        if not axis.periodic and not axis.lo <= value <= axis.hi:
            raise InputError("", param(field), f"{axis.name} = {value:g} is outside its range [{axis.lo:g}, {axis.hi:g}]")


def joint_poses(m: Mechanism, joints, field: str = "joints"):
    """Every pose with these joint values (`analyses.dkp.DkpResult`); InputError on `field` for
    values out of their ranges or that give no pose at all (certified), or for `legs` of a kind
    whose joints are angles (a 3-RRR's: legs are lengths, a 3-RPR's)."""
    from fivebar_cli.analyses.dkp import solve

    model = m.pose_aspect_model()
    names = ", ".join(axis.name for axis in model.joint_axes)
    if field == "legs" and any(axis.unit == "deg" for axis in model.joint_axes):
        raise InputError("", param("legs"), f"{article(m.kind)}'s joints are angles ({names}), not legs: give "
                         + param("joints"))
    values = finite_points(joints, len(model.joint_axes))
    if values is None:
        raise InputError("", param(field), f"expected ({names}), finite numbers, got {joints!r}")
    check_joints(m, values[0], field)
    result = solve(model, m.spaces()[model.space], [float(j) for j in values[0]])
    if not result.solutions and result.certified:
        raise InputError("", param(field), f"({numbers(joints)}) give no pose within the space of poses (certified: "
                         "every box of poses is proven to hold none)")
    return result


def saved_pose_aspects(m: Mechanism, folder, depth: int):
    """The aspects an `aspects` run saved in `folder` for this mechanism and depth (None: no
    folder, or none saved there for them)."""
    from fivebar_cli.analyses.pose_aspect_files import load_pose_aspects

    if folder is None:
        return None
    folder = user_path(folder, "folder")
    return load_pose_aspects(folder, m, depth) if folder.is_dir() else None


def pose_aspects_for(m: Mechanism, folder, depth: int, budget: int | None = None, advance=None):
    """(aspects, where): the aspects an `aspects` run saved in `folder` for this mechanism and
    depth ('read from FOLDER'), or computed ('computed'); the library's `PoseAspect`s."""
    from fivebar_cli.analyses.aspects import DEFAULT_BUDGET
    from fivebar_cli.analyses.pose_aspects import analyse_pose_aspects

    saved = saved_pose_aspects(m, folder, depth)
    if saved is not None:
        return saved, f"read from {folder}"
    budget = check_count(budget, "budget", 0, none=f"None: {DEFAULT_BUDGET:,}")
    budget = DEFAULT_BUDGET if budget is None else budget
    return analyse_pose_aspects(m, depth, advance or (lambda n=1: None), budget).aspects, "computed"


def class_values(model, cls: int, sheet: int) -> list[str]:
    """The class's field values for a CSV row; for no certified class, the sheet's fields and '0'."""
    if cls >= 0:
        return [v for _, v in model.classes[cls].fields]
    known = dict(model.sheets[sheet].fields)
    return [known.get(k, "0") for k, _ in model.classes[0].fields]


# ---------------------------------------------------------------- a motion over poses (`fb.path`)


def pose_path(m: Mechanism, start, goal, depth: int, working_mode: str | None, joints, legs, folder, source: str):
    """`fb.path` of a 3-RPR or 3-RRR: between two poses (in `working_mode`), or between assembly
    modes `start` and `goal` of `joints` (`legs`)."""
    import numpy as np

    from fivebar_cli.analyses.pose_aspect_files import joint_columns, pose_columns
    from fivebar_cli.analyses.pose_aspects import motion_sheet, sheet_of
    from fivebar_cli.analyses.pose_paths import find_motion, wrap_pose
    from fivebar_cli.api.values import Path as Motion, motion_where

    m = pose_mechanism(m, poses=True, source=source)
    depth = pose_depth(m, depth)
    model = m.pose_aspect_model()
    space = m.spaces()[model.space]
    if joints is not None and legs is not None:
        raise InputError(source, param("legs"), "give joints or legs, not both")
    values, field = (legs, "legs") if legs is not None else (joints, "joints")
    if values is not None and working_mode is not None:  # (it was ignored: the poses' classes decide)
        raise InputError(source, param("working_mode"), "is that of a motion between two poses: the assembly modes "
                         f"of {field} are poses of their own classes (their working modes)")
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
        ends = [wrap_pose(space, _pose(p, which, space, source)) for p, which in ((start, "start"), (goal, "goal"))]
        sheets = (sheet, sheet)
        labels = tuple(f"pose ({numbers(p)})" for p in (start, goal))
    saved = saved_pose_aspects(m, folder, depth)
    motion = find_motion(m, depth, ends[0], ends[1], labels, source, saved, sheets)
    notes = [f"{m.name}: singularity-free motion in {motion_where(motion.aspect)}: {model.classes[motion.cls].label}, depth {depth}",
             f"  from {labels[0]} to {labels[1]}: {len(motion.poses)} waypoints, length {motion.length:.6g} "
             f"({', '.join(a.name for a in space.axes)}); every segment lies in the certified cells "
             f"({motion.motion.checked_cells} cells, checked in exact arithmetic)"]
    if saved is not None:
        notes.append(f"  aspect trees read from {folder}")
    return Motion(m, depth, (*pose_columns(m), *joint_columns(m)), np.hstack([motion.poses, motion.joints]),
                  motion.length, motion, tuple(notes), Path(folder) if saved is not None else None, labels)


def _pose(p, which: str, space, source: str):
    """`path`'s endpoint `p` as a pose of `space` (finite numbers, one per axis); InputError naming
    `which` (start or goal) else."""
    pose = finite_points(p, len(space.axes))
    if pose is None:
        axes = ", ".join(a.name for a in space.axes)
        raise InputError(str(source), param(which), f"expected a pose ({axes}), got {p!r}")
    return pose[0]
