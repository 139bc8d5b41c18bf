"""Generalized aspects of a 2-DOF mechanism (Chablat 2010, sections 2.2, 3.3, 3.5, 3.6), for
every kind whose model declares an `AspectModel` (mechanisms/base.py).

1. Regions. Workspace: one paving per working mode (black = reachable and non-singular in that
   working mode), whose black cells split by the sign of det A. Joint space: one paving per
   assembly mode (black = assembles, non-singular), split by the working mode. Serial and
   parallel singularities stay undetermined, so they separate the regions.
2. Components of each paving (face-connected, torus-aware in the joint space).
3. Linking. A sample point of a workspace component, sent through the IKP of its working mode,
   that lands in a black cell of a joint-space component of the same modes proves that both
   belong to one generalized aspect (they share a non-singular configuration, and each is
   connected); the DKP does the same from the joint space. Groups of linked components are
   the generalized aspects: their workspace part is the parallel aspect, their joint-space part
   the serial aspect.
4. Fragments. Near tangencies of singular curves a region is a thin wedge, and a quadtree can
   hold a few black cells of it cut off from the rest by undetermined cells. Such a fragment has
   no partner in the other space; a local refinement of the undetermined cells around it (a few
   levels deeper) connects it, with certified black cells, to the component it belongs to. A
   component that still has no partner is reported as an error, never dropped silently.
5. Crossings (`crossings.py`): aspects joined across one serial singularity.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from fivebar_cli.analyses.crossings import Crossing, find_crossings
from fivebar_cli.errors import FivebarError
from fivebar_cli.mechanisms.base import AspectModel, Mechanism
from fivebar_cli.paving.engine import Paving, deepen, pave
from fivebar_cli.paving.tree import Tree, union_find

SMALL_COMPONENT = 64  # components with at most this many leaves are sampled densely when linking
DENSE = 4  # samples per axis and leaf for small components
REFINE_STEPS = ((2, 4), (4, 16), (8, 32), (10, 64))  # fragment refinement: (extra levels, radius in cells)


class AspectError(FivebarError):
    """Components that cannot be matched one-to-one between the two spaces (exit status 1)."""


def signs_text(signs) -> str:
    """(+1, -1) -> '+-'; a vanishing sign is '0'."""
    return "".join({1: "+", -1: "-", 0: "0"}[int(np.sign(s))] for s in np.atleast_1d(signs))


@dataclass
class Region:
    """One mode paving with its components; `modes[c]` = (working signs..., sign det A) of component c."""

    space: str
    working: tuple[int, ...] | None
    assembly: int | None
    paving: Paving
    test: object
    labels: np.ndarray
    count: int
    modes: np.ndarray
    offset: int = 0

    @property
    def tree(self) -> Tree:
        return self.paving.inside

    def title(self) -> str:
        if self.space == "workspace":
            return f"workspace, working mode {signs_text(self.working)}"
        return f"joint space, assembly mode {signs_text(self.assembly)}"


@dataclass(frozen=True)
class Aspect:
    number: int
    working: tuple[int, ...]
    assembly: int
    workspace: Tree
    jointspace: Tree
    pose: tuple[float, float]
    joints: tuple[float, float]


@dataclass
class AspectAnalysis:
    mechanism: Mechanism
    model: AspectModel
    depth: int
    regions: list[Region]
    aspects: list[Aspect]
    crossings: list[Crossing]
    fragments_resolved: int = 0
    timings: dict = field(default_factory=dict)

    @property
    def evaluations(self) -> int:
        return sum(r.paving.evaluations for r in self.regions)

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


def analyse_aspects(m: Mechanism, depth: int, advance=lambda n=1: None) -> AspectAnalysis:
    """Pave the mode regions, label, link and number the generalized aspects, find crossings."""
    model = m.aspect_model()
    if model is None:
        raise FivebarError(f"a {m.kind} has no working and assembly modes: no aspects to find")
    timings = {"paving": 0.0, "components": 0.0}
    regions = []
    for wm in model.working_modes:
        regions.append(_region(m, model, "workspace", wm, None, depth, timings))
        advance(1)
    for am in model.assembly_modes:
        regions.append(_region(m, model, "jointspace", None, am, depth, timings))
        advance(1)
    offset = 0
    for r in regions:
        r.offset, offset = offset, offset + r.count
    t0 = time.perf_counter()
    edges = _links(model, regions)
    roots, resolved = _resolve_fragments(regions, offset, edges)
    timings["linking"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    aspects, node_aspect = _number_aspects(model, regions, roots)
    crossings = find_crossings(model, regions, aspects, node_aspect)
    timings["crossings"] = time.perf_counter() - t0
    advance(1)
    return AspectAnalysis(m, model, depth, regions, aspects, crossings, resolved, timings)


def _region(m: Mechanism, model: AspectModel, space: str, working, assembly, depth: int, timings: dict) -> Region:
    t0 = time.perf_counter()
    if space == "workspace":
        test = model.workspace_test(working)
    else:
        test = model.jointspace_test(assembly)
    paving = pave(m.spaces()[space].grid(depth), test)
    t1 = time.perf_counter()
    labels, count = paving.inside.components()
    timings["paving"] += t1 - t0
    timings["components"] += time.perf_counter() - t1
    centres = paving.inside.centres()
    if space == "workspace":
        leaf_modes = np.column_stack([
            np.broadcast_to(np.array(working, np.int8), (len(centres), len(working))),
            model.assembly_signs(working, centres),
        ])
    else:
        leaf_modes = np.column_stack([
            model.working_signs(assembly, centres), np.full(len(centres), assembly, np.int8),
        ])
    modes = np.zeros((count, leaf_modes.shape[1]), dtype=np.int8)
    modes[labels] = leaf_modes
    if np.any(modes[labels] != leaf_modes) or np.any(leaf_modes == 0):
        raise FivebarError(f"internal error: the modes are not constant on a component of the {space} paving")
    return Region(space, working, assembly, paving, test, labels, count, modes)


def _samples(region: Region, nodes: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Sample points of the black leaves (centres; a DENSE x DENSE grid in small components)."""
    tree, labels = region.tree, region.labels
    sizes = np.bincount(labels, minlength=region.count)
    keep = np.ones(len(tree), bool) if nodes is None else np.isin(labels, nodes - region.offset)
    lo, hi = tree.bounds()
    small = keep & (sizes[labels] <= SMALL_COMPONENT)
    big = keep & ~small
    g = (np.arange(DENSE) + 0.5) / DENSE
    grid_pts = np.stack(np.meshgrid(g, g), -1).reshape(-1, 2)
    dense = (lo[small, None, :] + grid_pts[None] * (hi - lo)[small, None, :]).reshape(-1, 2)
    points = np.concatenate([0.5 * (lo[big] + hi[big]), dense])
    owners = np.concatenate([labels[big], np.repeat(labels[small], DENSE * DENSE)])
    return points, owners


def _links(model: AspectModel, regions: list[Region], nodes: np.ndarray | None = None) -> list[tuple[np.ndarray, np.ndarray]]:
    """Edges (node, node) between components of the two spaces that share a configuration."""
    edges = []
    for src in regions:
        points, owners = _samples(src, nodes)
        if not len(points):
            continue
        modes = src.modes[owners]
        if src.space == "workspace":
            images, ok = model.ikp(points, src.working)
        else:
            images, ok = model.dkp(points, src.assembly)
        for dst in regions:
            if dst.space == src.space:
                continue
            if dst.space == "jointspace":
                sel = ok & (modes[:, -1] == dst.assembly)
            else:
                sel = ok & np.all(modes[:, :-1] == np.array(dst.working), axis=1)
            leaf = dst.tree.locate(images[sel])
            hit = leaf >= 0
            a = src.offset + owners[sel][hit]
            b = dst.offset + dst.labels[leaf[hit]]
            if np.any(dst.modes[b - dst.offset] != src.modes[a - src.offset]):
                raise FivebarError("internal error: linked components have different modes")
            edges.append((a, b))
    return edges


def _groups(total: int, edges) -> np.ndarray:
    i = np.concatenate([e[0] for e in edges]) if edges else np.zeros(0, np.int64)
    j = np.concatenate([e[1] for e in edges]) if edges else np.zeros(0, np.int64)
    return union_find(total, i.astype(np.int64), j.astype(np.int64))


def _fragment_nodes(regions: list[Region], roots: np.ndarray) -> np.ndarray:
    """Nodes whose group lacks components of the other space."""
    is_ws = np.concatenate([np.full(r.count, r.space == "workspace") for r in regions])
    has_ws = np.zeros(len(roots), bool)
    has_js = np.zeros(len(roots), bool)
    np.logical_or.at(has_ws, roots, is_ws)
    np.logical_or.at(has_js, roots, ~is_ws)
    return np.flatnonzero(~(has_ws[roots] & has_js[roots]))


def _resolve_fragments(regions: list[Region], total: int, edges) -> tuple[np.ndarray, int]:
    """Group the components; attach fragments by local refinement; raise if any stay unmatched."""
    roots = _groups(total, edges)
    fragments = _fragment_nodes(regions, roots)
    initial = len(fragments)
    for extra, radius in REFINE_STEPS:
        if not len(fragments):
            break
        for region in regions:
            mine = fragments[(fragments >= region.offset) & (fragments < region.offset + region.count)]
            if len(mine):
                edges.append(_attach_locally(region, mine, extra, radius))
        roots = _groups(total, edges)
        fragments = _fragment_nodes(regions, roots)
    if len(fragments):
        raise AspectError(_unmatched_message(regions, fragments))
    return roots, initial


def _attach_locally(region: Region, nodes: np.ndarray, extra: int, radius: int):
    """Same-space edges found by paving the undetermined cells near `nodes` `extra` levels deeper.

    Only a window around the fragments is examined: the black leaves within 2 * radius cells
    and the new black cells of the refinement. Connectivity inside the window is connectivity.
    """
    paving, tree = region.paving, region.tree
    grid = paving.grid
    frag = np.isin(region.labels, nodes - region.offset)
    f_lo, f_hi = _integer_boxes(grid, tree.coords[frag], tree.level[frag])
    cells = paving.undetermined
    near = cells[_near(grid, f_lo, f_hi, cells, cells + 1, radius)]
    window = _near(grid, f_lo, f_hi, *_integer_boxes(grid, tree.coords, tree.level), 2 * radius)
    local = deepen(grid, region.test, near, extra)
    sub = tree.subset(window)
    merged = sub.with_depth(local.grid.depth) | local.inside
    labels, _ = merged.components()
    owner = labels[merged.locate(sub.centres())]
    # components of the depth-D paving that share a component of the refined window are connected
    comp = region.labels[window]
    order = np.argsort(owner, kind="stable")
    first = np.r_[True, owner[order][1:] != owner[order][:-1]]
    head = np.maximum.accumulate(np.where(first, np.arange(len(order)), 0))
    return region.offset + comp[order], region.offset + comp[order][head]


def _integer_boxes(grid, coords: np.ndarray, level: np.ndarray):
    """Leaves as half-open boxes of depth-D cell indices."""
    shift = (grid.depth - level)[:, None]
    return coords << shift, (coords + 1) << shift


def _near(grid, a_lo, a_hi, b_lo, b_hi, radius: int) -> np.ndarray:
    """Mask of the boxes b within `radius` cells (Chebyshev) of some box a (periodic axes wrap)."""
    keep = np.zeros(len(b_lo), bool)
    if not len(a_lo) or not len(b_lo):
        return keep
    n = np.int64(1) << grid.depth
    a_lo, a_hi = a_lo - radius, a_hi + radius
    step = max(1, (1 << 22) // len(b_lo))  # bound the (a x b) comparison matrices
    for s in range(0, len(a_lo), step):
        near = np.ones((min(step, len(a_lo) - s), len(b_lo)), bool)
        for axis in range(grid.dim):
            a0, a1 = a_lo[s:s + step, axis, None], a_hi[s:s + step, axis, None]
            b0, b1 = b_lo[None, :, axis], b_hi[None, :, axis]
            if grid.periodic[axis]:
                near &= ((a1 - a0 >= n) | (np.mod(b0 - a0, n) < a1 - a0) | (np.mod(a0 - b0, n) < b1 - b0))
            else:
                near &= (b0 < a1) & (a0 < b1)
        keep |= near.any(axis=0)
    return keep


def _unmatched_message(regions: list[Region], nodes: np.ndarray) -> str:
    parts = []
    for node in nodes[:5]:
        region = next(r for r in regions if r.offset <= node < r.offset + r.count)
        sub = region.tree.subset(region.labels == node - region.offset)
        centre = sub.centres().mean(axis=0)
        parts.append(f"{region.title()} near ({centre[0]:.4g}, {centre[1]:.4g}), area {sub.area:.3g}")
    more = f" and {len(nodes) - 5} more" if len(nodes) > 5 else ""
    return (f"{len(nodes)} component(s) have no counterpart in the other space at depth "
            f"{regions[0].paving.grid.depth}: " + "; ".join(parts) + more + " (try a larger --depth)")


# ---------------------------------------------------------------- numbering


def _number_aspects(model: AspectModel, regions: list[Region], roots: np.ndarray):
    """Aspects ordered by assembly mode (+ first), working mode (++, +-, -+, --), then position."""
    node_region = np.concatenate([np.full(r.count, k) for k, r in enumerate(regions)])
    node_local = np.concatenate([np.arange(r.count) for r in regions])
    node_modes = np.concatenate([r.modes for r in regions])
    groups = np.unique(roots)
    keys = []
    for g in groups:
        members = np.flatnonzero(roots == g)
        *working, sa = (int(v) for v in node_modes[members[0]])
        js = [n for n in members if regions[node_region[n]].space == "jointspace"]
        region = regions[node_region[js[0]]]
        first = min(int(region.tree.start[region.labels == node_local[n]].min()) for n in js)
        keys.append((-sa, *(-w for w in working), first, g))
    keys.sort()
    node_aspect = np.full(len(roots), -1)
    aspects = []
    for number, key in enumerate(keys, start=1):
        g = key[-1]
        members = np.flatnonzero(roots == g)
        node_aspect[members] = number
        *working, sa = (int(v) for v in node_modes[members[0]])
        trees = {}
        for space in ("workspace", "jointspace"):
            mine = [n for n in members if regions[node_region[n]].space == space]
            region = regions[node_region[mine[0]]]
            trees[space] = region.tree.subset(np.isin(region.labels, node_local[mine]))
        pose, joints = _representative(model, tuple(working), trees["workspace"], trees["jointspace"])
        aspects.append(Aspect(number, tuple(working), sa, trees["workspace"], trees["jointspace"], pose, joints))
    return aspects, node_aspect


def _representative(model: AspectModel, working, ws: Tree, js: Tree):
    """A configuration inside the aspect: the centre of its largest workspace cell whose IKP image
    lies in the aspect's joint-space cells."""
    order = np.argsort(ws.level, kind="stable")
    centres = ws.centres()[order]
    joints, ok = model.ikp(centres, working)
    inside = ok.copy()
    inside[ok] = js.locate(joints[ok]) >= 0
    k = int(np.argmax(inside)) if inside.any() else 0
    return (float(centres[k, 0]), float(centres[k, 1])), (float(joints[k, 0]), float(joints[k, 1]))


