"""Generalized aspects of a 2-DOF mechanism (Chablat 2010, sections 2.2, 3.3, 3.5, 3.6), with a
certificate for their count, for every kind whose model declares an `AspectModel`
(mechanisms/base.py).

1. Regions. Workspace: one paving per working mode (black = reachable and non-singular in that
   working mode); joint space: one paving per assembly mode (black = assembles, non-singular).
   The other modes (det A's sign, resp. the working mode) are constant on a black cell.
2. Mode sets. For every full mode and space, the set S of its non-singular configurations has an
   inner approximation (the black cells with these modes) and an outer one (adding every
   undetermined cell not certified to miss S); its outer components, refined locally until each
   holds exactly one black component, are its pieces (`pieces.py`).
3. Linking. A generalized aspect is one component of S seen in both spaces: the map between
   them is a homeomorphism on non-singular configurations of fixed modes. A sample point of a
   piece's black cells, sent through the IKP (workspace) or DKP (joint space), is a point of S in
   the other space, so it lies in one of that space's pieces of the same modes: the two pieces
   hold the same aspect. Groups of linked pieces are the aspects.
4. Certificate. An aspect is certified when it holds exactly one piece in each space, each with at
   most one black component (one with black cells); the count is certified when every aspect is
   and no piece is left undecided. It then equals the number of components of S in each mode,
   except for components lying wholly inside the undetermined cells of a piece that already holds
   one (docs/formats.md, "What a certified aspect count means").
5. Crossings (`crossings.py`): aspects joined across one serial singularity.
6. The largest disc and axis-aligned square in each aspect's workspace cells (`inscribed.py`),
   with, when they run on workers, the texts of the aspect's files (`aspect_texts.py`).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field, replace

import numpy as np

from fivebar_cli.analyses.aspect_texts import aspect_texts, signs_text
from fivebar_cli.analyses.crossings import Band, Crossing, find_crossings, serial_bands
from fivebar_cli.analyses.inscribed import Disc, Square, largest_shapes
from fivebar_cli.analyses.jobs import Texts, Workers
from fivebar_cli.analyses.pieces import SPLIT_EXTRA, SPLIT_STEP, Budget, ModeSet
from fivebar_cli.analyses.pieces import undetermined_pairs as _undetermined_pairs
from fivebar_cli.errors import FivebarError, param
from fivebar_cli.mechanisms.base import AspectModel, Mechanism, plural
from fivebar_cli.paving.engine import Paving, on_cells, pave_many
from fivebar_cli.paving.arrays import unique, unique_pairs
from fivebar_cli.paving.grid import MAX_INDEX_BITS, Grid
from fivebar_cli.paving.morton import finest_order
from fivebar_cli.paving.tree import Tree, finest_indices, union_find

SMALL_PIECE = 64  # pieces with at most this many black leaves are sampled densely when linking
DENSE = 4  # samples per axis and leaf for small pieces
LINK_STRIDE = 16  # into a mode set of one anchor, one sample in this many is mapped first (`_pairs_of`)
DEFAULT_BUDGET = 1 << 21  # box evaluations local refinement may spend in one analysis (about a second)


@dataclass
class Region:
    """One mode paving: the workspace in a working mode, or the joint space in an assembly mode.

    `free[k]` holds the signs the paving leaves free (det A's sign in the workspace, the working
    signs in the joint space) on black leaf k.
    """

    space: str
    working: tuple[int, ...] | None
    assembly: int | None
    paving: Paving
    model: AspectModel
    free: np.ndarray
    # what the mode sets are built from (`pieces.ModeSet`), then dropped (None):
    black_labels: np.ndarray = None  # corner-connected components of the black leaves (one sign each)
    und_possible: np.ndarray = None  # per undetermined cell: may hold a valid point
    und_signs: np.ndarray = None  # per undetermined cell: the free signs, 0 where not constant
    und_pairs: list = None  # per direction: (undetermined cells, neighbours), black leaves numbered first
    bands: list[Band] = field(default_factory=list)  # cells crossed by one serial singularity (`crossings.py`)

    @property
    def tree(self) -> Tree:
        return self.paving.inside

    @property
    def test(self):
        """The paving's box test, made from the model when asked: a closure is not kept, so that a
        region (an `Aspects` holding it) pickles."""
        return _mode_test(self.model, self.space, self.working, self.assembly)

    def title(self) -> str:
        if self.space == "workspace":
            return f"workspace, working mode {signs_text(self.working)}"
        return f"joint space, assembly mode {signs_text(self.assembly)}"

    def modes_with(self, free) -> tuple[int, ...]:
        """The full modes (*working, assembly) of configurations with these free signs."""
        free = tuple(int(v) for v in free)
        return (*self.working, *free) if self.space == "workspace" else (*free, self.assembly)

    def free_signs(self, points: np.ndarray) -> np.ndarray:
        """The free signs at points of the region's space, shape (n, k) (0 where invalid)."""
        if self.space == "workspace":
            return np.asarray(self.model.assembly_signs(self.working, points), np.int8).reshape(-1, 1)
        return np.asarray(self.model.working_signs(self.assembly, points), np.int8)

    def signs(self, lo: np.ndarray, hi: np.ndarray, ends=None):
        """Per box: (may hold a valid point, free signs constant over its valid points or 0);
        `ends`: the boxes' ends as tables (`grid.AxisEnds`), if at hand."""
        if self.space == "workspace":
            return self.model.workspace_signs(self.working, lo, hi, ends=ends)
        return self.model.jointspace_signs(self.assembly, lo, hi, ends=ends)


@dataclass(frozen=True)
class Aspect:
    number: int
    working: tuple[int, ...]
    assembly: int
    workspace: Tree
    jointspace: Tree
    pose: tuple[float, float]
    joints: tuple[float, float]
    certified: bool = True
    circle: Disc | None = None  # the largest disc in the workspace cells (None: no workspace cells)
    square: Square | None = None  # the largest axis-aligned square in them


@dataclass
class AspectAnalysis:
    mechanism: Mechanism
    model: AspectModel
    depth: int
    regions: list[Region]
    aspects: list[Aspect]
    crossings: list[Crossing]
    lower: int = 0  # a certified lower bound on the number of aspects
    upper: int = 0  # the count if every undecided piece were an aspect of its own
    undecided: int = 0  # outer components whose anchors or emptiness the budget left undecided
    empty_undecided: int = 0  # of them, those without anchors (each may hide an aspect)
    merged: int = 0  # components of the pavings' black cells proved to belong to another one
    refinement_evaluations: int = 0
    timings: dict = field(default_factory=dict)
    # per aspect, its files' texts (`aspect_texts`), made in its task with its shapes when these
    # ran on workers (`aspect_files.write_aspects` writes them); None: made when written
    texts: list | None = None

    @property
    def certified(self) -> bool:
        return self.undecided == 0 and all(a.certified for a in self.aspects)

    @property
    def undecided_pieces(self) -> int:
        """Reported aspects not certified, and outer components that may hide one."""
        return sum(not a.certified for a in self.aspects) + self.empty_undecided

    def headline(self) -> str:
        """One line: the certified count, or the bounds and what is left undecided."""
        name, depth = self.mechanism.name, self.depth
        what = "robust generalized aspect" if self.mechanism.is_interval else "generalized aspect"
        if self.certified:
            return (f"{name}: {plural(len(self.aspects), what)} at depth {depth} (certified; "
                    f"{self.evaluations} box evaluations, {self.refinement_evaluations} in local refinement)")
        return (f"{name}: between {self.lower} and {plural(self.upper, what)}, not certified at depth "
                f"{depth}: {plural(self.undecided_pieces, 'piece')} undecided (raise " + param("depth") + " or "
                + param("budget") + ")")

    @property
    def evaluations(self) -> int:
        return sum(r.paving.evaluations for r in self.regions) + self.refinement_evaluations

    def region(self, space: str, key) -> Region:
        for r in self.regions:
            if r.space == space and (r.working if space == "workspace" else r.assembly) == key:
                return r
        raise KeyError((space, key))


# ---------------------------------------------------------------- analysis


def region_count(m: Mechanism) -> int:
    """How many mode pavings `analyse_aspects` makes (for a progress bar: one step each, plus one)."""
    model = m.aspect_model()
    return len(model.working_modes) + len(model.assembly_modes)


def analyse_aspects(m: Mechanism, depth: int, advance=lambda n=1: None, budget: int = DEFAULT_BUDGET,
                    shapes: bool = True, jobs: int | None = 1) -> AspectAnalysis:
    """Pave the mode regions, find the mode sets' anchors and outer components, link and join the
    anchors into generalized aspects, certify the count, find the crossings; with `shapes`, the
    largest disc and square of each aspect's workspace (what `aspects.csv` reports). The spaces'
    pavings, the mode regions (each started once its space is paved) and the shapes are tasks run
    on `jobs` processes (`analyses.jobs.Workers`, one pool for them all); the certificate and the
    numbering run here, between them. On workers, each aspect's task makes its files' texts too
    (`texts`): one round of tasks, not a second pool when the files are written."""
    model = m.aspect_model()
    if model is None:
        raise FivebarError(f"a {m.kind} has no working and assembly modes: no aspects to find")
    timings = {"paving": 0.0, "outer": 0.0}
    with Workers(jobs, region_count(m) + 2) as pool:
        regions, sets, linked = _regions(m, model, depth, pool, timings, advance)
        t0 = time.perf_counter()
        count = _Count(model, sets, Budget(budget), depth, linked)
        timings["certificate"] = time.perf_counter() - t0
        t0 = time.perf_counter()
        aspects, leaf_aspect = _number_aspects(model, regions, sets, count)
        bounds = (count.lower, count.upper, count.undecided, count.empty_undecided, count.merged, count.budget.spent)
        del sets, count  # what the certificate alone needed: dropped before the shapes' tasks
        # the aspects' tasks start now on workers (the aspects alone travel), the crossings meanwhile
        texts = shapes and pool.n > 1
        found = pool.map(_aspect_task, [(m, a, depth, texts) for a in aspects],
                         cost=lambda task: len(task[1].workspace) + texts * len(task[1].jointspace)) if shapes else None
        crossings = find_crossings(model, regions, aspects, leaf_aspect)
        timings["crossings"] = time.perf_counter() - t0
        t0 = time.perf_counter()
        if shapes:
            found = list(found)
            aspects = [replace(a, circle=circle, square=square) for a, ((circle, square), _) in zip(aspects, found)]
        timings["inscribed"] = time.perf_counter() - t0
    advance(1)
    return AspectAnalysis(m, model, depth, regions, aspects, crossings, *bounds, timings,
                          [made for _, made in found] if texts else None)


def _aspect_task(task: tuple) -> tuple[tuple[Disc | None, Square | None], Texts | None]:
    """One aspect's largest disc and square in its workspace cells, and with `texts` its files'
    texts (`aspect_texts`, as `Texts`; the circle and square are not in them)."""
    m, aspect, depth, texts = task
    return largest_shapes(aspect.workspace), Texts(aspect_texts(m, aspect, depth)) if texts else None


def _regions(m: Mechanism, model: AspectModel, depth: int, pool: Workers, timings: dict, advance):
    """The mode regions and their mode sets: one paving pass per space for all its modes (their
    tests share work), then each mode region's data and mode sets, as tasks of similar sizes
    started as soon as their space is paved (the other space's paving may still run). With
    workers, the certificate's links (`link_pairs`) of the sets taken so far are found here while
    the last regions' tasks run: (regions, sets, the links found, by (set, set of the other space))."""
    spaces = [pool.submit(_space_task, (m, space, depth)) for space in ("workspace", "jointspace")]
    links = pool.n > 1  # the certificate's link samples in the workers (their memory is no concern then)
    region_tasks = [[], []]
    for k in pool.completed(spaces):
        keys, pavings, seconds = spaces[k].get()
        # (a region's task reads no outside tree: none travels to a worker)
        region_tasks[k] = [(paving, pool.submit(_region_task, (m, *key, replace(paving, outside=Tree.empty(paving.grid))
                                                                 if links else paving, links)))
                           for key, paving in zip(keys, pavings)]
        timings["paving"] += seconds
    regions, sets, linked = [], [], {}
    for paving, task in region_tasks[0] + region_tasks[1]:
        region, region_sets, seconds = task.get()
        region.paving = paving  # (not sent back: the caller has it)
        region.model = model
        regions.append(region)
        sets += region_sets
        if links:  # (with the link samples the workers found)
            for k in range(len(sets) - len(region_sets), len(sets)):
                for j in _linked_to(sets, k):
                    if j < k:
                        linked[(k, j)] = link_pairs(sets[j], *sets[k].links)
                        linked[(j, k)] = link_pairs(sets[k], *sets[j].links)
        timings["outer"] += seconds
        advance(1)
    return regions, sets, linked


def _free_modes(model: AspectModel, region: Region) -> list[tuple[int, ...]]:
    """The values of the signs a region leaves free: det A's sign, or every working mode."""
    if region.space == "workspace":
        return [(am,) for am in model.assembly_modes]
    return [tuple(wm) for wm in model.working_modes]


def _mode_test(model: AspectModel, space: str, working, assembly):
    return model.workspace_test(working) if space == "workspace" else model.jointspace_test(assembly)


def _space_task(task: tuple) -> tuple[list, list[Paving], float]:
    """The mode pavings of one space in one pass, in a worker: (the regions' keys (space, working,
    assembly), their pavings, seconds)."""
    m, space, depth = task
    model = m.aspect_model()
    t0 = time.perf_counter()
    if space == "workspace":
        keys = [(space, wm, None) for wm in model.working_modes]
        tests = model.workspace_tests(model.working_modes)
    else:
        keys = [(space, None, am) for am in model.assembly_modes]
        tests = model.jointspace_tests(model.assembly_modes)
    pavings = pave_many(m.spaces()[space].grid(depth), tests, len(keys))
    return keys, pavings, time.perf_counter() - t0


def _region_task(task: tuple) -> tuple[Region, list[ModeSet], float]:
    """One mode region's data and mode sets, in a worker: (the region without its model and its
    paving, which the caller has; its mode sets, with `links`, the certificate's link samples
    (`link_points`); seconds)."""
    m, space, working, assembly, paving, links = task
    model = m.aspect_model()
    t0 = time.perf_counter()
    region = _region(model, space, working, assembly, paving)
    region_sets = [ModeSet(region, free) for free in _free_modes(model, region)]
    if links:
        other = m.spaces()["jointspace" if space == "workspace" else "workspace"].grid(paving.grid.depth)
        for s in region_sets:
            s.links = link_points(model, s, other)
    # what only the mode sets need, dropped once they are built (most of a region's memory)
    region.und_pairs = region.black_labels = region.und_possible = region.und_signs = None
    region.model = region.paving = None
    return region, region_sets, time.perf_counter() - t0


def _region(model: AspectModel, space: str, working, assembly, paving: Paving) -> Region:
    """A mode paving with what the certificate needs of it: free signs, black components,
    undetermined cells' signs and neighbours."""
    region = Region(space, working, assembly, paving, model, np.zeros((0, 0), np.int8))
    # two closed black cells of different signs cannot touch (a shared point would have both), so
    # the components of all black leaves are the anchors of every mode set at once, and the free
    # signs are constant on each: read at the centre of its largest leaf, not of every leaf
    inside = paving.inside
    index = inside.search_index()  # one search index of the black leaves for all their neighbour searches
    region.black_labels, count = inside.components(corners=True, index=index)
    first = _largest_leaf(inside.level, region.black_labels, count)
    signs = region.free_signs(inside.subset(first).centres())
    if np.any(signs == 0):
        raise FivebarError(f"internal error: a black cell of the {region.title()} has a vanishing mode sign")
    region.free = signs[region.black_labels]
    band_signs = None
    if space == "jointspace":  # one classification for the free signs and the serial bands
        region.und_possible, region.und_signs, strict = on_cells(
            lambda lo, hi, ends: model.jointspace_band_signs(assembly, lo, hi, ends=ends), paving.grid,
            paving.undetermined, ends=True)
        band_signs = strict, region.und_signs
    else:
        region.und_possible, region.und_signs = on_cells(region.signs, paving.grid, paving.undetermined, ends=True)
    region.und_pairs = _undetermined_pairs(paving, index)
    region.bands = serial_bands(model, region, band_signs, index)
    return region


def _largest_leaf(level: np.ndarray, labels: np.ndarray, count: int) -> np.ndarray:
    """Per label 0 .. count - 1: its first leaf (in Morton order) of the lowest level: the least
    key level * n + leaf of its leaves, in one pass (`np.minimum.at`)."""
    n = len(level)
    key = level.astype(np.int64) * n
    key += np.arange(n)
    best = np.full(count, np.iinfo(np.int64).max)
    np.minimum.at(best, labels, key)
    return best % max(n, 1)


# ---------------------------------------------------------------- the certificate


class _Count:
    """Anchors of every mode set joined into groups (one group: one component of S), and what is
    proved about the groups: which are certified, lower and upper bounds on the count.

    1. Links: a sample of an anchor's black cells mapped into the other space (IKP / DKP) that
       lands in a black cell of an anchor of the same modes: both anchors hold that configuration,
       so they are one component (rigorous).
    2. Joins: anchors of one outer component joined by black cells found by local refinement.
    3. Partners: a group with no anchor in one space takes the outer component its images land in.
    4. Empty outer components (no anchor, no partner) must vanish under refinement; outer
       components still holding several groups must split under refinement (`pieces.py`); one
       that also holds a partner group is never taken as separated (`strangers`).

    With mode sets of one space only (`pose_aspects.py`: aspects over a space of poses) there is
    nothing to link: steps 2 and 4 alone make the certificate, and a group is certified by its one
    outer component in that space.
    """

    def __init__(self, model: AspectModel, sets: list[ModeSet], budget: Budget, depth: int, linked: dict | None = None,
                 deepen_many=None):
        """`deepen_many(pairs, extra)`: when given, the deeper pavings of outer components (set,
        outer) that `ModeSet._deeper` would make, made at once (sharing their box tests); the
        first round of the empty outer components' `vanish` is taken from it."""
        self.model, self.sets, self.budget = model, sets, budget
        self.offset = np.cumsum([0] + [s.n_anchors for s in sets])
        total = int(self.offset[-1])
        self.edges_i, self.edges_j = [], []
        self._roots, self._roots_for = None, None  # the roots, and how many edges they hold
        self._link(linked or {})
        self._join()
        self.partner = self._partners()
        self.undecided = self.empty_undecided = 0
        limit = min(depth + SPLIT_EXTRA, MAX_INDEX_BITS // max((s.grid.dim for s in sets), default=2))
        self.split_ok = {}
        ready = self._first_rounds(deepen_many, limit)
        for k, s in enumerate(sets):
            local_roots = self.roots[self.offset[k]:self.offset[k + 1]]
            for o in range(s.n_outer):
                anchors = s.anchors_in(o)
                held = unique(local_roots[anchors])
                if len(held) > 1:
                    self.split_ok[(k, o)] = (not self.strangers(k, o, held)
                                             and self._separate(s, o, anchors, local_roots, limit))
                    self.undecided += not self.split_ok[(k, o)]
                elif len(held) == 0 and (k, o) not in self.partner_of and not s.vanish(o, budget, limit,
                                                                                      ready.pop((k, o), None)):
                    self.undecided += 1
                    self.empty_undecided += 1
        self.merged = total - len(unique(self.roots)) if total else 0
        self.lower, self.upper = self._bounds()

    def _first_rounds(self, deepen_many, limit: int) -> dict:
        """The first round of `vanish` of every outer component that will be asked to vanish (no
        anchor, no partner), from `deepen_many` at once, when the budget pays for all of them now
        and the depth limit allows a round ({} otherwise: each vanish paves its own). The budget
        is still taken round by round as `vanish` goes (`ModeSet._deeper`): the same answers."""
        pairs = [(k, o) for k, s in enumerate(self.sets) for o in range(s.n_outer)
                 if not len(s.anchors_in(o)) and (k, o) not in self.partner_of]
        if deepen_many is None or not pairs or any(self.sets[k].grid.depth + SPLIT_STEP > limit for k, _ in pairs):
            return {}
        cells = sum(int(np.count_nonzero(~self.sets[k].outer_cells(o).black)) for k, o in pairs)
        dim = max(self.sets[k].grid.dim for k, _ in pairs)
        return deepen_many(pairs, SPLIT_STEP) if self.budget.allows(cells, SPLIT_STEP, dim) else {}

    def strangers(self, k: int, o: int, held) -> set:
        """Partner groups in outer component o of set k that hold no anchor there. Separating the
        anchored groups says nothing about them (one may be the same aspect as an anchored group),
        so such a component is never counted as separated."""
        return self.partner_of.get((k, o), set()) - {int(g) for g in held}

    def _separate(self, s: ModeSet, o: int, anchors: np.ndarray, roots: np.ndarray, limit: int) -> bool:
        """Separate the groups of anchors sharing an outer component: each group but the biggest
        isolated locally, or else the whole outer component split by refinement."""
        groups = roots[anchors]
        size = {g: s.anchor_size[anchors[groups == g]].sum() for g in unique(groups)}
        biggest = max(size, key=lambda g: (size[g], -g))
        if all(s.isolate(o, anchors[groups == g], roots, self.budget) for g in size if g != biggest):
            return True
        return s.split(o, roots, self.budget, limit)

    @property
    def roots(self) -> np.ndarray:
        """Union-find root of every anchor: the edges added since the last call joined to the
        roots found before (each edge is joined once)."""
        done = self._roots_for  # None: not computed yet
        if done != len(self.edges_i):
            i = np.array(self.edges_i[done or 0:], np.int64)
            j = np.array(self.edges_j[done or 0:], np.int64)
            self._roots = union_find(int(self.offset[-1]), i, j, self._roots)
            self._roots_for = len(self.edges_i)
        return self._roots

    def _link(self, linked: dict) -> None:
        """The links' edges, set by set: those found already (`linked`, by (set, other set)), or
        from the set's link samples (`link_points`: found in the region's task when it ran in a
        worker, else now). Links only join anchors: those between two sets whose anchors are all
        one group already (often a set of one anchor, once the links into it are in) would join
        nothing, and are not looked for (the groups are the same: `roots`)."""
        for k, s in enumerate(self.sets):
            others = _linked_to(self.sets, k)  # none when the aspects live in one space
            if not others:
                continue
            links = s.links
            s.links = None
            for j in others:
                pairs = linked.get((k, j))
                if pairs is None and self._joined(k, j):
                    continue
                if pairs is None:
                    pairs = link_pairs(self.sets[j], *links) if links is not None else _pairs_of(self.model, s, self.sets[j])
                self.edges_i += (self.offset[k] + pairs[:, 0]).tolist()
                self.edges_j += (self.offset[j] + pairs[:, 1]).tolist()

    def _joined(self, k: int, j: int) -> bool:
        """Whether every anchor of sets k and j is in one group already."""
        roots = self.roots
        held = np.concatenate([roots[self.offset[k]:self.offset[k + 1]], roots[self.offset[j]:self.offset[j + 1]]])
        return len(held) > 0 and bool(np.all(held == held[0]))

    def _join(self) -> None:
        """Join the anchors of each outer component by local refinement, as long as it joins."""
        for k, s in enumerate(self.sets):
            for o in range(s.n_outer):
                anchors = s.anchors_in(o)
                while self.budget.left > 0:
                    roots = self.roots[self.offset[k]:self.offset[k + 1]]
                    if len(unique(roots[anchors])) < 2:
                        break
                    new = [(a, b) for a, b in s.join(o, roots, self.budget) if roots[a] != roots[b]]
                    if not new:
                        break
                    self.edges_i += [self.offset[k] + a for a, _ in new]
                    self.edges_j += [self.offset[k] + b for _, b in new]

    def _partners(self) -> dict:
        """For every group with no anchor in a mode set of the other space: the outer components
        of that set its images land in. Also `partner_of[(set, outer)]`: the groups landing there."""
        roots = self.roots
        partner: dict = {}
        self.partner_of: dict = {}
        for k, s in enumerate(self.sets):
            groups_here = roots[self.offset[k]:self.offset[k + 1]]
            for j in _linked_to(self.sets, k):
                t = self.sets[j]
                missing = unique(groups_here[~np.isin(groups_here, roots[self.offset[j]:self.offset[j + 1]])])
                if not len(missing):
                    continue
                points, owners = link_samples(s)
                keep = np.isin(groups_here[owners], missing)
                points, groups = points[keep], groups_here[owners[keep]]
                images, ok = _images(self.model, s, points)
                located = np.full(len(points), -1, np.int64)
                if ok.any():
                    cells = t.cells
                    order = finest_order(cells.code, cells.level, cells.grid.dim, cells.grid.depth)
                    leaf = cells.tree().locate(images[ok])
                    located[np.flatnonzero(ok)] = np.where(leaf >= 0, order[np.maximum(leaf, 0)], -1)
                for g in missing:
                    outers = set(t.outer[located[(groups == g) & (located >= 0)]].tolist())
                    partner[(int(g), j)] = outers
                    for o in outers:
                        self.partner_of.setdefault((j, o), set()).add(int(g))
        return partner

    def group_outers(self, g: int) -> dict:
        """Per space: the set of (mode set, outer component) pairs holding group g."""
        out = {s.space: set() for s in self.sets}
        roots = self.roots
        for k, s in enumerate(self.sets):
            local = np.flatnonzero(roots[self.offset[k]:self.offset[k + 1]] == g)
            out[s.space] |= {(k, int(o)) for o in unique(s.anchor_outer[local])}
            for (gg, j), outers in self.partner.items():
                if gg == g and j == k:
                    out[s.space] |= {(k, o) for o in outers}
        return out

    def owners(self, k: int, o: int) -> set:
        s = self.sets[k]
        roots = self.roots[self.offset[k]:self.offset[k + 1]]
        return set(unique(roots[s.anchors_in(o)]).tolist()) | self.partner_of.get((k, o), set())

    def certified(self, g: int) -> bool:
        outers = self.group_outers(g)
        for space in outers:
            if len(outers[space]) != 1:
                return False
            (k, o), = outers[space]
            if self.owners(k, o) != {g} and not self.split_ok.get((k, o), False):
                return False
        return True

    def _bounds(self) -> tuple[int, int]:
        """Groups sharing an outer component may be one aspect: the lower bound counts clusters
        of groups joined by shared outer components, the upper bound counts groups, plus the
        undecided outer components without an anchor."""
        groups = unique(self.roots)
        index = {int(g): i for i, g in enumerate(groups)}
        ei, ej = [], []
        for k, s in enumerate(self.sets):
            for o in range(s.n_outer):
                held = sorted(self.owners(k, o))
                if len(held) > 1 and not self.split_ok.get((k, o), False):
                    ei += [index[held[0]]] * (len(held) - 1)
                    ej += [index[h] for h in held[1:]]
        clusters = len(unique(union_find(len(groups), np.array(ei, np.int64), np.array(ej, np.int64))))
        split_failed = sum(1 for v in self.split_ok.values() if not v)
        return clusters, len(groups) + (self.undecided - split_failed)


def _linked_to(sets: list[ModeSet], k: int) -> list[int]:
    """The mode sets a set's links go to: those of the same modes in the other space."""
    s = sets[k]
    return [j for j, t in enumerate(sets) if t.space != s.space and t.modes == s.modes]


def link_pairs(t: ModeSet, owners: np.ndarray, index: np.ndarray) -> np.ndarray:
    """The links from a mode set's samples (`link_points`: their anchors `owners` and the Morton
    indices of their images) into mode set t of the other space: the distinct pairs (anchor of
    the samples' set, anchor of t) where an image lies in a black cell of t's anchor, (n, 2)."""
    leaf = t.region.tree.locate_finest(index)
    hit = leaf >= 0
    target = np.full(len(index), -1, np.int64)
    target[hit] = t.anchor_of_leaf[leaf[hit]]
    good = target >= 0
    return unique_pairs(owners[good], target[good])


def link_samples(s: ModeSet) -> tuple[np.ndarray, np.ndarray]:
    """Sample points of every anchor's black cells of a mode set (centres; a DENSE x DENSE grid in
    the leaves of small anchors) and the anchor each comes from. The centres are built axis by
    axis into one array with contiguous columns (the IKP / DKP read columns: `Tree.centres`)."""
    tree = s.region.tree
    mine, owner = s.black_leaves, s.leaf_anchors
    small = s.anchor_size[owner] <= SMALL_PIECE
    dense = None  # (most sets: no small anchor, no copies)
    if small.any():
        lo, hi = tree.bounds(mine[small])
        g = (np.arange(DENSE) + 0.5) / DENSE
        grid_pts = np.stack(np.meshgrid(g, g), -1).reshape(-1, 2)
        dense = (lo[:, None, :] + grid_pts[None] * (hi - lo)[:, None, :]).reshape(-1, 2)
        mine, owner = mine[~small], np.concatenate([owner[~small], np.repeat(owner[small], DENSE * DENSE)])
    points = np.empty((len(mine) + (0 if dense is None else len(dense)), tree.grid.dim), order="F")
    tree.centres(mine, out=points[:len(mine)])
    if dense is not None:
        points[len(mine):] = dense
    return points, owner


def _images(model: AspectModel, s: ModeSet, points: np.ndarray):
    """The points of a mode set's space mapped into the other space (IKP / DKP), and which exist."""
    *working, assembly = s.modes
    if s.space == "workspace":
        return model.ikp(points, tuple(working))
    return model.dkp(points, assembly)


def link_points(model: AspectModel, s: ModeSet, other: Grid) -> tuple[np.ndarray, np.ndarray]:
    """What the certificate's links need of a mode set: its anchors' samples (`link_samples`) by
    anchor, and the depth-D Morton index of each sample's image in the other space's grid (-1
    where there is none). Computed in the region's task when that runs in a worker (the main
    process then only looks the indices up), else by the certificate (`_pairs_of`)."""
    points, owners = link_samples(s)
    return owners, _image_indices(model, s, points, other)


def _pairs_of(model: AspectModel, s: ModeSet, t: ModeSet) -> np.ndarray:
    """`link_pairs(t, *link_points(model, s, t.grid))`, with fewer images when t has one anchor:
    a sample then adds a pair only for an anchor of s that has none yet, so the samples of a
    sparse stride are mapped first, and the others only for the anchors left without a pair
    (the same pairs: those skipped are among the first ones)."""
    points, owners = link_samples(s)
    if t.n_anchors != 1 or len(points) < 4 * LINK_STRIDE:
        return link_pairs(t, owners, _image_indices(model, s, points, t.grid))
    first = np.zeros(len(points), bool)
    first[::LINK_STRIDE] = True
    found = link_pairs(t, owners[first], _image_indices(model, s, points[first], t.grid))
    rest = ~first & ~np.isin(owners, found[:, 0])
    more = link_pairs(t, owners[rest], _image_indices(model, s, points[rest], t.grid))
    return unique_pairs(np.concatenate([found[:, 0], more[:, 0]]), np.concatenate([found[:, 1], more[:, 1]]))


def _image_indices(model: AspectModel, s: ModeSet, points: np.ndarray, other: Grid) -> np.ndarray:
    """The depth-D Morton index in the other space's grid of each point's image (-1: none)."""
    index = np.full(len(points), -1, np.int64)
    if len(points):
        images, ok = _images(model, s, points)
        if ok.all():
            index = finest_indices(other, images)
        else:
            index[ok] = finest_indices(other, images[ok])
    return index


def _number_aspects(model: AspectModel, regions: list[Region], sets: list[ModeSet], count: _Count):
    """Aspects (groups of anchors) ordered by assembly mode (+ first), working mode (++, +-, -+,
    --), then the position of their first joint-space cell; and, per region, the aspect number of
    each black leaf of its paving."""
    roots = count.roots
    leaves = {}  # group -> {space: (region, leaf indices)}
    for k, s in enumerate(sets):
        local = roots[count.offset[k]:count.offset[k + 1]]
        mine = s.black_leaves  # with their anchors `s.leaf_anchors` (a byte or two each)
        for g in unique(local).tolist():  # (a few groups)
            part = mine[np.isin(s.leaf_anchors, np.flatnonzero(local == g))]
            region, idx = leaves.setdefault(g, {}).get(s.space, (s.region, np.zeros(0, np.int64)))
            leaves[g][s.space] = (region, np.concatenate([idx, part]))
    keys = []
    for g, per_space in leaves.items():
        trees = {}
        for space in ("workspace", "jointspace"):
            if space in per_space:
                region, idx = per_space[space]
                trees[space] = region.tree.subset(np.sort(idx, kind="stable"))
            else:
                trees[space] = Tree.empty(next(r for r in regions if r.space == space).paving.grid)
        k = next(k for k, s in enumerate(sets) if np.any(roots[count.offset[k]:count.offset[k + 1]] == g))
        *working, sa = sets[k].modes
        first = (0, int(trees["jointspace"].start[0])) if len(trees["jointspace"]) else (1, int(trees["workspace"].start[0]))
        keys.append(((-sa, *(-w for w in working), first), g, trees, tuple(working), sa))
    keys.sort(key=lambda item: item[0])
    leaf_aspect = {id(r): np.full(len(r.tree), -1, np.int64) for r in regions}
    aspects = []
    for number, (_, g, trees, working, sa) in enumerate(keys, start=1):
        for space, (region, idx) in leaves[g].items():
            leaf_aspect[id(region)][idx] = number
        pose, joints = _representative(model, working, sa, trees["workspace"], trees["jointspace"])
        aspects.append(Aspect(number, working, sa, trees["workspace"], trees["jointspace"], pose, joints,
                              count.certified(g)))
    return aspects, leaf_aspect


def _representative(model: AspectModel, working, assembly: int, ws: Tree, js: Tree):
    """A configuration inside the aspect: the centre of its largest workspace cell whose IKP image
    lies in the aspect's joint-space cells (or, for an aspect too thin for workspace cells, the
    centre of its largest joint-space cell and its DKP image)."""
    if not len(ws):
        joints = js.centres()[int(np.argmin(js.level))][None, :]
        pose, _ = model.dkp(joints, assembly)
        return (float(pose[0, 0]), float(pose[0, 1])), (float(joints[0, 0]), float(joints[0, 1]))
    order = np.argsort(ws.level.astype(np.uint8), kind="stable")  # (levels in a byte: a radix sort, the same order)
    first = None
    for a, b in _doubling(len(order)):  # the largest cells first: the first one inside is near the start
        lo, hi = ws.bounds(order[a:b])
        centres = 0.5 * (lo + hi)
        joints, ok = model.ikp(centres, working)
        inside = ok.copy()
        inside[ok] = js.locate(joints[ok]) >= 0
        if first is None:  # none inside at all: the largest cell
            first = centres[0], joints[0]
        if inside.any():
            k = int(np.argmax(inside))
            first = centres[k], joints[k]
            break
    (x, y), (t1, t2) = first
    return (float(x), float(y)), (float(t1), float(t2))


def _doubling(n: int, size: int = 64):
    """Slices [a, b) covering range(n) in order, each twice the one before."""
    a = 0
    while a < n:
        yield a, min(a + size, n)
        a, size = a + size, 2 * size
