"""Generalized aspects that live in one space of poses, with a certificate for their count, for
every kind whose model declares a `PoseAspectModel` (mechanisms/base.py): the 3-RPR over
(x, y, phi), a 3-RRR per working mode, any dimension, with periodic axes.

1. Regions: the space is paved once per sign class (the class's box test: black = valid and
   non-singular in that class, so singularities stay undetermined and separate the aspects);
   the classes (all of them on one worker, a sheet's on several) are paved together when the
   model tests them at once (the same pavings, their shared work done once).
2. Mode sets: each class's set S has an inner approximation (its black cells) and an outer one
   (adding every undetermined cell: the class test could not exclude it); cells touching at a
   corner share a point, so components are taken with corner contact, wrapping periodic axes
   (`pieces.ModeSet`, with no sign left free).
3. Certificate (`aspects._Count` on the mode sets of one space: nothing to link across spaces):
   the black components (anchors) of one outer component are joined by black cells found by
   local refinement, or separated by refinement; an outer component without anchor must vanish.
4. Probe: the undetermined cells of every outer component holding an anchor are paved one level
   deeper (PROBE_LEVELS). New black cells touching no black cell joined to the anchors (islands)
   must join them by local refinement; an island left in a part of the deeper outer set without
   anchor is a component of S that the depth-D black cells missed (an aspect thinner than a
   cell, hidden in the band of another one): proven, both bounds count it; an island left in the
   anchors' part may be one (the upper bound counts it), as may a part without black cells that
   does not vanish under refinement. Either way the count is not certified at this depth; a
   deeper run sees the aspect's cells.
   An aspect is certified when its anchors lie in one outer component that holds no other
   aspect (or was proven to split) and whose probe found nothing; the count is certified when
   every aspect is and no outer component is left undecided. The same words, "N generalized
   aspects (certified)" or "between L and U ...", as the five-bar's two-space certificate, with
   the same caveat (docs/formats.md): an aspect hidden in the band even one level deeper is not
   excluded.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from fivebar_cli.analyses.aspects import DEFAULT_BUDGET, AspectAnalysis, _Count
from fivebar_cli.analyses.jobs import run_tasks, workers
from fivebar_cli.analyses.pieces import SPLIT_EXTRA, Budget, ModeSet, undetermined_pairs
from fivebar_cli.errors import InputError, param
from fivebar_cli.mechanisms.base import Mechanism, PoseAspectModel, SignClass, article, is_choice
from fivebar_cli.paving.engine import Paving, deepen_many, pave, pave_many
from fivebar_cli.paving.grid import MAX_INDEX_BITS
from fivebar_cli.paving.tree import Tree

__all__ = ["DEFAULT_BUDGET", "ClassRegion", "PoseAspect", "PoseAspectAnalysis", "analyse_pose_aspects",
           "aspect_at", "pose_model", "sheet_classes", "sheet_of", "working_sheets", "motion_sheet"]


PROBE_LEVELS = 1  # the band of every outer component holding an aspect is paved this much deeper


def pose_model(m: Mechanism, source: str = "") -> PoseAspectModel:
    """The kind's pose-space aspect model; when it has none, `m.no_pose_space`'s InputError (on
    `type` for a kind whose configurations are not poses, a five-bar or a 2-RPR; on `legs.rho_max`
    for a 3-RPR whose legs leave its space of poses unbounded)."""
    model = m.pose_aspect_model()
    if model is None:
        raise m.no_pose_space(source)
    return model


@dataclass
class ClassRegion:
    """The paving of one sign class, seen by `pieces.ModeSet` as a region that leaves no sign free:
    every undetermined cell may meet the class's set (the class test already says -1 for the
    cells it can exclude)."""

    space: str
    index: int
    paving: Paving
    model: PoseAspectModel
    black_labels: np.ndarray = None
    und_pairs: list = None

    @property
    def tree(self) -> Tree:
        return self.paving.inside

    @property
    def test(self):
        """The class's box test, made from the model when asked: a closure is not kept, so that a
        region (an `Aspects` holding it) pickles."""
        return self.model.class_test(self.index)

    @property
    def free(self) -> np.ndarray:
        return np.zeros((len(self.paving.inside), 0), np.int8)

    @property
    def und_possible(self) -> np.ndarray:
        return np.ones(len(self.paving.undetermined), bool)

    @property
    def und_signs(self) -> np.ndarray:
        return np.zeros((len(self.paving.undetermined), 0), np.int8)

    def title(self) -> str:
        return f"{self.space}, {self.model.classes[self.index].label}"

    def modes_with(self, free) -> tuple[int, ...]:
        return (self.index,)

    def free_signs(self, points: np.ndarray) -> np.ndarray:
        return np.zeros((len(points), 0), np.int8)

    def signs(self, lo: np.ndarray, hi: np.ndarray):
        return np.ones(len(lo), bool), np.zeros((len(lo), 0), np.int8)


@dataclass(frozen=True)
class PoseAspect:
    """One aspect: its class, its certified cells, a pose inside it and that pose's joints."""

    number: int
    cls: int
    signs: SignClass
    tree: Tree
    pose: tuple[float, ...]
    joints: tuple[float, ...]
    certified: bool = True

    @property
    def volume(self) -> float:
        return self.tree.area


class PoseAspectAnalysis(AspectAnalysis):
    """`AspectAnalysis` of aspects in one space: `regions` are `ClassRegion`s, `aspects` are
    `PoseAspect`s, there are no crossings; the count's fields and headline are the five-bar's
    (with "N ..., not certified" when the bounds meet: aspects found by the probe only)."""

    def headline(self) -> str:
        if self.certified or self.lower != self.upper:
            return super().headline()
        return (f"{self.mechanism.name}: {self.lower} generalized aspects, not certified at depth {self.depth}: "
                f"{self.lower - len(self.aspects)} of them thinner than its cells, found one level deeper "
                "(raise " + param("depth") + ")")


def analyse_pose_aspects(m: Mechanism, depth: int, advance=lambda n=1: None,
                         budget: int = DEFAULT_BUDGET, jobs: int | None = 1) -> PoseAspectAnalysis:
    """Pave every sign class (one task each, on `jobs` processes: `analyses.jobs`), find the
    anchors and outer components, join and separate them under the budget, number the aspects
    (class order, then Morton order of their first cell)."""
    model = pose_model(m)
    space = m.spaces()[model.space]
    timings = {"paving": 0.0}
    regions = []
    for found, seconds in run_tasks(_class_task, [(m, depth, ks) for ks in _class_groups(model, jobs)], jobs):
        for region in found:
            region.model = model
            regions.append(region)
            advance(1)
        timings["paving"] += seconds
    t0 = time.perf_counter()
    sets = [ModeSet(region, ()) for region in regions]
    count = _Count(model, sets, Budget(budget), depth, deepen_many=lambda pairs, extra: _deeper_pavings(model, sets, pairs, extra))
    timings["certificate"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    probe = Budget(1 << 62)  # part of the analysis at this depth, not of the refinement budget
    limit = min(depth + SPLIT_EXTRA, MAX_INDEX_BITS // space.dim)
    found = opened = 0  # aspects the probe proved, and parts it left that may hide one
    hiding = set()  # (set, outer component) where it found either
    probed = [(k, o) for k, s in enumerate(sets) for o in range(s.n_outer)
              if len(s.anchors_in(o)) and depth + PROBE_LEVELS <= limit]
    pavings = _deeper_pavings(model, sets, probed, PROBE_LEVELS)
    for k, o in probed:
        black, still = sets[k].hidden_parts(o, PROBE_LEVELS, probe, limit, pavings.pop((k, o), None))
        if black or still:
            found, opened = found + black, opened + still
            hiding.add((k, o))
    timings["probe"] = time.perf_counter() - t0

    def certified(g: int) -> bool:
        return count.certified(g) and not (count.group_outers(g)[model.space] & hiding)

    aspects = _number_aspects(model, sets, count, certified)
    advance(1)
    return PoseAspectAnalysis(m, model, depth, regions, aspects, [], count.lower + found,
                              count.upper + found + opened, count.undecided + len(hiding),
                              count.empty_undecided + found + opened, count.merged,
                              count.budget.spent + probe.spent, timings)


def _tests_at_once(model: PoseAspectModel) -> bool:
    """Whether the model has the optional `class_tests` of `PoseAspectModel` (a member the
    protocol leaves out: a third-party kind's model may not have it)."""
    return hasattr(model, "class_tests")


def _deeper_pavings(model: PoseAspectModel, sets: list[ModeSet], pairs: list[tuple[int, int]], extra: int) -> dict:
    """The undetermined cells of the outer components `pairs` ((set, outer)) paved `extra` levels
    deeper, all together when the model tests its classes at once (`engine.deepen_many` with
    `class_tests`: the classes' bands overlap, a shared box is tested once, and the tests share
    work across classes): {(set, outer): the paving `ModeSet._deeper` would make} (the probe's,
    the first round of an empty component's `vanish`); without `class_tests`, left to `_deeper`."""
    if len(pairs) < 2 or not _tests_at_once(model):
        return {}
    cells = [sets[k].outer_cells(o).undetermined_coords() for k, o in pairs]
    tests = model.class_tests(tuple(sets[k].region.index for k, _ in pairs))
    return dict(zip(pairs, deepen_many(sets[pairs[0][0]].grid, tests, cells, extra)))


def _class_groups(model: PoseAspectModel, jobs: int | None) -> list[tuple[int, ...]]:
    """The class tasks: on one worker, every class in one task when the model tests them at once
    (their pavings share their tests' work, `class_regions`: a 3-RRR's validity test is every
    working mode's); else the classes of each sheet together when that leaves a task for every
    worker, else one class a task."""
    processes = workers(jobs, len(model.classes))
    if processes == 1 and _tests_at_once(model):
        return [tuple(range(len(model.classes)))]
    groups = [tuple(sheet_classes(model, s)) for s in range(len(model.sheets))]
    if sorted(k for ks in groups for k in ks) != list(range(len(model.classes))) or len(groups) < processes:
        return [(k,) for k in range(len(model.classes))]
    return groups


def _class_task(task: tuple) -> tuple[list[ClassRegion], float]:
    """The regions of some classes, in a worker: (regions without their model, seconds)."""
    m, depth, ks = task
    t0 = time.perf_counter()
    model = pose_model(m)
    regions = class_regions(model, m.spaces()[model.space].grid(depth), ks)
    for region in regions:
        region.model = None
    return regions, time.perf_counter() - t0


def class_regions(model: PoseAspectModel, grid, ks) -> list[ClassRegion]:
    """`class_region` of each class of `ks`; paved together (`engine.pave_many`: the same pavings)
    when the model tests them at once (its optional `class_tests(ks)`, a `MultiTest` sharing the
    classes' work: the boxes of one level are mostly open in all of them)."""
    if len(ks) == 1 or not _tests_at_once(model):
        return [class_region(model, grid, k) for k in ks]
    return [_region(model, k, paving) for k, paving in zip(ks, pave_many(grid, model.class_tests(ks), len(ks)))]


def class_region(model: PoseAspectModel, grid, k: int) -> ClassRegion:
    """The paving of class k with its black components and undetermined neighbour pairs."""
    return _region(model, k, pave(grid, model.class_test(k)))


def _region(model: PoseAspectModel, k: int, paving: Paving) -> ClassRegion:
    """Class k's region of its paving: its black components and undetermined neighbour pairs."""
    region = ClassRegion(model.space, k, paving, model)
    # two closed black cells of one class touching at a point are in one aspect: corner contact
    region.black_labels, _ = paving.inside.components(corners=True)
    region.und_pairs = undetermined_pairs(paving)
    return region


def _number_aspects(model: PoseAspectModel, sets: list[ModeSet], count: _Count, certified) -> list[PoseAspect]:
    """Groups of anchors -> aspects, numbered by class, then by the Morton order of their first
    cell; each with a pose inside (the centre of its largest cell, first in Morton order)."""
    roots = count.roots
    found = []
    for k, s in enumerate(sets):
        local = roots[count.offset[k]:count.offset[k + 1]]
        for g in np.unique(local):
            leaves = np.flatnonzero(np.isin(s.anchor_of_leaf, np.flatnonzero(local == g)))
            tree = s.region.tree.subset(leaves)
            found.append(((s.region.index, int(tree.start[0])), int(g), s.region.index, tree))
    found.sort(key=lambda item: item[0])
    aspects = []
    for number, (_, g, cls, tree) in enumerate(found, start=1):
        biggest = int(np.argmin(tree.level))
        pose = tree.centres()[biggest]
        joints, _ = model.ikp(pose[None, :], cls)
        aspects.append(PoseAspect(number, cls, model.classes[cls], tree, tuple(float(v) for v in pose),
                                  tuple(float(v) for v in joints[0]), certified(g)))
    return aspects


def sheet_classes(model: PoseAspectModel, sheet: int) -> list[int]:
    """The classes of one sheet: those carrying the sheet's fields."""
    fields = set(model.sheets[sheet].fields)
    return [k for k, c in enumerate(model.classes) if fields <= set(c.fields)]


def sheet_of(model: PoseAspectModel, k: int) -> int:
    """The sheet of class k."""
    return next(s for s in range(len(model.sheets)) if k in sheet_classes(model, s))


def working_sheets(m: Mechanism, working_mode: str | None) -> list[int]:
    """The sheets a pose is taken in: the one of `working_mode` (a 3-RRR's '+-+'), else all of them
    (InputError on `working_mode` when the kind has no such working mode)."""
    model = pose_model(m)
    if working_mode is None:
        return list(range(len(model.sheets)))
    modes = [dict(sheet.fields).get("working_mode") for sheet in model.sheets]
    if not is_choice(working_mode, modes):
        known = ", ".join(mode for mode in modes if mode) or "none: its pose decides its class"
        raise InputError("", param("working_mode"), f"{working_mode!r} is not a working mode of this {m.kind} (its "
                         f"working modes: {known})")
    return [k for k, mode in enumerate(modes) if mode == working_mode]


def motion_sheet(m: Mechanism, working_mode: str | None) -> int:
    """The one sheet a motion between two poses runs in: `working_sheets`' only one (InputError on
    `working_mode` when the kind has several and none is given)."""
    chosen = working_sheets(m, working_mode)
    if len(chosen) > 1:
        first = dict(pose_model(m).sheets[0].fields)["working_mode"]
        raise InputError("", param("working_mode"), f"{article(m.kind)} pose is reached in {len(chosen)} working modes: say "
                         "which one (e.g. " + param("working_mode", first) + ")")
    return chosen[0]


def aspect_at(aspects: list[PoseAspect], model: PoseAspectModel, pose: np.ndarray,
              sheet: int = 0) -> tuple[int, PoseAspect | None]:
    """(class, aspect) of a pose in a sheet: the class certified at that point (-1: on or near a
    singularity, or not a valid pose) and the aspect whose cells hold it (None: in no certified cell)."""
    pose = np.asarray(pose, float)[None, :]
    if not model.valid(pose, sheet)[0]:
        return -1, None
    cls = int(model.classes_of_boxes(pose, pose, sheet)[0])
    if cls < 0:
        return -1, None
    for a in aspects:
        if a.cls == cls and a.tree.locate(pose)[0] >= 0:
            return cls, a
    return cls, None
