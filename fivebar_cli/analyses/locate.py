"""Which aspect a configuration lies in, and whether a singularity-free motion joins two: the one
decision `locate` and `path` share.

A configuration lies in an aspect when its joint values are in the aspect's joint-space cells or
its pose in the aspect's workspace cells (either proves it: every point of those cells is a
non-singular configuration of the aspect, and the cells of one aspect are proven to lie in one
component of the non-singular configurations of its modes). On or near a singularity (a mode
value below `SINGULAR_TOL * scale^2`) it is in none.

`decide` answers, for two configurations:
- **no**, only when that is proven: their modes differ by a sign that does not vanish (det A, or,
  without serial crossings, B11 or B22 changes sign along every motion between them), or they lie
  in two different aspects that are both certified (the certificate separates them; with joint
  limits or obstacles, a motion within them would cross a singularity or a constraint's boundary);
- **yes**, only when that is proven: one aspect holds both (with interval lengths: one connected
  set of a robust aspect's cells in one space, so that the motion is singularity-free for every
  length vector);
- otherwise **not decided** at this depth, with the reason and what to try.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from fivebar_cli.analyses.aspects import Aspect
from fivebar_cli.analyses.channel import containing_leaves
from fivebar_cli.errors import param
from fivebar_cli.mechanisms.base import AspectModel, Mechanism, Space

SINGULAR_TOL = 1e-9  # |B11|, |B22| or |det A| below this times scale^2 is a singularity
SAME_TOL = 1e-9  # two configurations closer than this times the scale are one
SPACES = ("jointspace", "workspace")

YES, NO, UNDECIDED = "yes", "no", "not decided"


@dataclass(frozen=True)
class Configuration:
    """One configuration: joint values, pose and mode signs ('0' where a sign vanishes, on or near
    a singularity), and for a mechanism with limits or obstacles the ones it violates (by a
    floating-point check); `label` names it in messages."""

    label: str
    joints: np.ndarray
    pose: np.ndarray
    working: str
    assembly: str
    violates: str = ""  # the joint limits and obstacles it violates ('P limit; obstacle 1'), if any

    def point(self, space: str) -> np.ndarray:
        return self.joints if space == "jointspace" else self.pose


@dataclass(frozen=True)
class Verdict:
    """Whether a singularity-free motion joins two configurations: `answer` is YES, NO or UNDECIDED
    (at `depth`), `reason` says why, `advice` what to try (undecided only), `aspect` the aspect
    holding both (yes)."""

    answer: str
    reason: str
    depth: int
    advice: str = ""
    aspect: int | None = None

    def text(self) -> str:
        """The reason (with the advice in parentheses), or for a verdict left open 'not decided at
        depth D: <reason>; <advice>'."""
        if self.answer == UNDECIDED:
            return f"not decided at depth {self.depth}: " + self.reason + ("; " + self.advice if self.advice else "")
        return self.reason + (" (" + self.advice + ")" if self.advice else "")

    def line(self) -> str:
        """'yes: <reason>', 'no: <reason>' or 'not decided at depth D: <reason>; <advice>'."""
        return self.text() if self.answer == UNDECIDED else f"{self.answer}: " + self.text()


def deeper(depth: int, max_depth: int | None) -> str:
    """What to try when cells at this depth are too coarse."""
    if max_depth is not None and depth + 2 > max_depth:
        return param("depth", max_depth) + " is the deepest"
    return "try " + param("depth", depth + 2)


# ---------------------------------------------------------------- configurations


def configurations(m: Mechanism, point, space: str, label: str = "") -> list[Configuration]:
    """Every configuration at a pose (workspace) or joint values (joint space): the requested
    values exactly, the others computed. On a singularity two branches coincide (a stretched leg
    has one elbow): such a configuration is listed once, with the sign that vanishes written 0."""
    model, joint_space = m.aspect_model(), m.spaces()["jointspace"]
    point = np.asarray(point, float)
    if space == "workspace":
        candidates = [(point, joints[0]) for joints, ok in (model.ikp(point[None, :], wm) for wm in model.working_modes)
                      if ok[0]]
    else:
        candidates = [(pose[0], point) for pose, ok in (model.dkp(point[None, :], am) for am in model.assembly_modes)
                      if ok[0]]
    seen: list[np.ndarray] = []
    out = []
    for pose, joints in candidates:
        key = np.concatenate([pose, _joint_key(joint_space, joints)])
        if any(np.allclose(key, other, rtol=0, atol=SAME_TOL * model.length_scale) for other in seen):
            continue
        seen.append(key)
        values = model.mode_values(joints[None, :], pose[None, :])[0]
        tol = SINGULAR_TOL * model.length_scale ** 2
        signs = ["0" if abs(x) <= tol else ("+" if x > 0 else "-") for x in values]
        out.append(Configuration(label, np.asarray(joints, float), np.asarray(pose, float),
                                 "".join(signs[:-1]), signs[-1]))
    if out and m.constraints:
        labels = m.violated_constraints(np.array([c.joints for c in out]), np.array([c.pose for c in out]))
        out = [replace(c, violates="; ".join(names)) for c, names in zip(out, labels)]
    return out


def singularities(model: AspectModel, c: Configuration) -> list[str]:
    """The singularities a configuration is on or near: 'serial (B11 = 0)', 'parallel (det A = 0)'."""
    out = [f"serial ({name} = 0)" for name, s in zip(model.serial_names, c.working) if s == "0"]
    return out + ["parallel (det A = 0)"] if c.assembly == "0" else out


def locate_configurations(m: Mechanism, aspects: list[Aspect], points: np.ndarray, space: str) -> list[dict]:
    """Every configuration at the given poses (workspace) or joint values (joint space), as rows
    (`row`), numbered by the point's index."""
    points = np.atleast_2d(np.asarray(points, float))
    return [row(m, c, aspect_of(aspects, c), k) for k, point in enumerate(points) for c in configurations(m, point, space)]


def row(m: Mechanism, c: Configuration, aspect: Aspect | None, index: int) -> dict:
    """A configuration as a row of `locate --csv`: its pose, its joint values (periodic ones
    wrapped into the root interval), its modes, the aspect holding it (None when on or near a
    singularity or in no certified cell at this depth), whether that aspect is certified; with
    limits or obstacles, the ones it violates (`violates`)."""
    joint_space = m.spaces()["jointspace"]
    axes = [a.name for a in joint_space.axes]
    joints = _wrap(joint_space, c.joints)
    out = {
        "input": index, "x": float(c.pose[0]), "y": float(c.pose[1]),
        axes[0]: float(joints[0]), axes[1]: float(joints[1]),
        "working_mode": c.working, "assembly_mode": c.assembly,
        "aspect": None if aspect is None else aspect.number,
        "singular": "; ".join(singularities(m.aspect_model(), c)),
        "aspect_certified": None if aspect is None else aspect.certified,
    }
    return {**out, "violates": c.violates} if m.constraints else out


def _joint_key(space: Space, joints: np.ndarray) -> np.ndarray:
    """Joint values as a point to compare: periodic axes through (cos, sin)."""
    parts = []
    for axis, value in zip(space.axes, joints):
        parts += [np.cos(value), np.sin(value)] if axis.periodic else [value]
    return np.array(parts)


def _wrap(space: Space, joints: np.ndarray) -> np.ndarray:
    """Periodic joint values wrapped into the root interval: [lo, lo + period)."""
    out = joints.astype(float).copy()
    for i, axis in enumerate(space.axes):
        if axis.periodic:
            period = axis.hi - axis.lo
            out[i] = (out[i] - axis.lo) % period + axis.lo
    return out


# ---------------------------------------------------------------- where a configuration lies


def _signs_of(a: Aspect) -> tuple[str, str]:
    text = "".join("+" if s > 0 else "-" for s in a.working)
    return text, "+" if a.assembly > 0 else "-"


def holders(aspects: list[Aspect], c: Configuration) -> list[tuple[Aspect, str, list[int]]]:
    """(aspect, space, leaves) for every aspect of the configuration's modes and every space whose
    cells of that aspect hold it (joint values in the joint-space cells, the pose in the workspace
    cells), with the leaves holding it. A configuration that violates a limit or an obstacle is in
    no aspect."""
    out = []
    if c.violates:
        return out
    for a in aspects:
        if _signs_of(a) != (c.working, c.assembly):
            continue
        for space in SPACES:
            tree = a.jointspace if space == "jointspace" else a.workspace
            leaves = containing_leaves(tree, c.point(space)) if len(tree) else []
            if leaves:
                out.append((a, space, leaves))
    return out


def aspect_of(aspects: list[Aspect], c: Configuration) -> Aspect | None:
    """The aspect holding the configuration, or None (no aspect's certified cells hold it)."""
    held = holders(aspects, c)
    return held[0][0] if held else None


class Pieces:
    """The connected sets of each aspect's cells in each space (corner contact joins: the point two
    closed cells share is in both), computed once per tree."""

    def __init__(self):
        self._labels: dict[int, np.ndarray] = {}

    def of(self, a: Aspect, space: str, leaves: list[int]) -> set[tuple[int, str, int]]:
        tree = a.jointspace if space == "jointspace" else a.workspace
        if id(tree) not in self._labels:
            self._labels[id(tree)] = (tree, tree.components(corners=True)[0])
        labels = self._labels[id(tree)][1]
        return {(a.number, space, int(labels[k])) for k in leaves}


# ---------------------------------------------------------------- the decision


def mode_verdict(model: AspectModel, c1: Configuration, c2: Configuration, depth: int,
                 allow_serial: bool = False, offer_serial: bool = False) -> Verdict | None:
    """What the modes alone decide: NO when a sign that vanishes at neither differs (det A, or B11
    or B22 without serial crossings: that sign changes along every motion between them); not
    decided when one lies on or near a singularity the motion may not cross; else None.
    `allow_serial`: serial crossings are allowed; `offer_serial`: the command could allow them (the
    advice then names `allow_serial`)."""
    if "0" not in (c1.assembly, c2.assembly) and c1.assembly != c2.assembly:
        return Verdict(NO, f"different assembly modes ({c1.assembly} for {c1.label}, {c2.assembly} for {c2.label}): "
                           "every motion between them crosses a parallel singularity (det A = 0)", depth)
    if not allow_serial and any("0" not in (a, b) and a != b for a, b in zip(c1.working, c2.working)):
        return Verdict(NO, f"different working modes ({c1.working} for {c1.label}, {c2.working} for {c2.label}): "
                           "every motion between them crosses a serial singularity", depth,
                       advice=param("allow_serial", True) + " allows that" if offer_serial else "")
    for c in (c1, c2):
        if c.violates:
            return Verdict(UNDECIDED, f"{c.label} violates the {c.violates} (by a floating-point check): it is in "
                                      "no aspect", depth)
        if c.assembly == "0":
            return Verdict(UNDECIDED, f"{c.label} is on or near a parallel singularity (det A = 0): no certified "
                                      "cell holds it", depth)
        if "0" in c.working and not allow_serial:
            names = " and ".join(n for n, s in zip(model.serial_names, c.working) if s == "0")
            return Verdict(UNDECIDED, f"{c.label} is on or near a serial singularity ({names} = 0): it is in no "
                                      "aspect's certified cells", depth,
                           param("allow_serial", True) + " allows motions across serial singularities"
                           if offer_serial else "")
    return None


def decide(model: AspectModel, aspects: list[Aspect], c1: Configuration, c2: Configuration, depth: int,
           robust: bool = False, max_depth: int | None = None, pieces: Pieces | None = None,
           offer_serial: bool = False, constrained: bool = False) -> Verdict:
    """Whether a singularity-free motion (no serial and no parallel singularity) joins two
    configurations, given the aspects at `depth` (module docstring). With `robust` (interval
    lengths) the configurations are the nominal robot's and a yes means a motion that is
    singularity-free for every length vector; with `constrained` (limits or obstacles) the motion
    also keeps within them, and two aspects apart may be parted by a constraint's boundary."""
    verdict = mode_verdict(model, c1, c2, depth, offer_serial=offer_serial)
    if verdict is not None:
        return verdict
    held = [holders(aspects, c) for c in (c1, c2)]
    for c, h in zip((c1, c2), held):
        if not h:
            return Verdict(UNDECIDED, f"{c.label} lies in no certified cell (too close to a "
                                      "singularity for cells this size)", depth, deeper(depth, max_depth))
    shared = {a.number for a, _, _ in held[0]} & {a.number for a, _, _ in held[1]}
    if shared:
        number = min(shared)
        if not robust:
            return Verdict(YES, f"both lie in aspect {number}", depth, aspect=number)
        pieces = pieces or Pieces()
        sets = [set().union(*(pieces.of(a, space, leaves) for a, space, leaves in h if a.number == number))
                for h in held]
        if sets[0] & sets[1]:
            return Verdict(YES, f"both lie in one connected set of robust aspect {number}'s cells", depth,
                           aspect=number)
        return Verdict(UNDECIDED, f"both lie in robust aspect {number}, but in no connected set of its cells in one "
                                  "space", depth, deeper(depth, max_depth))
    a, b = held[0][0][0], held[1][0][0]
    where = f"{c1.label} is in {'robust ' if robust else ''}aspect {a.number}, {c2.label} in aspect {b.number}"
    if robust:
        return Verdict(UNDECIDED, f"{where}: robust aspects apart do not prove that every motion crosses a "
                                  "singularity (the nominal robot may move between them)", depth,
                       "ask again without the tolerance for the nominal robot's answer")
    if a.certified and b.certified:
        crossed = "a singularity or a limit's or an obstacle's boundary" if constrained else "a singularity"
        return Verdict(NO, f"{where}, both certified: every motion between them crosses {crossed}", depth)
    return Verdict(UNDECIDED, f"{where}, not both certified: they may be one aspect", depth,
                   deeper(depth, max_depth))


def overall(verdicts: list[Verdict]) -> str:
    """For two locations, over the pairs of their configurations: YES when a motion joins one pair,
    NO when every pair is proven apart (and there is a pair), else UNDECIDED."""
    answers = {v.answer for v in verdicts}
    if YES in answers:
        return YES
    return NO if answers == {NO} else UNDECIDED
