"""Generalized aspects of the five-bar (Chablat 2010, sections 2.2, 3.3, 3.5, 3.6).

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
5. Crossings. Undetermined joint-space cells certified free of parallel singularities and of
   one serial singularity (B22 != 0, say) are crossed only by the other one (B11 = 0); a
   face-connected band of them touching two aspects is a motion between these aspects that
   changes the working mode once (one sign of B11, B22).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from fivebar_cli import fivebar
from fivebar_cli.config import FiveBar
from fivebar_cli.errors import FivebarError
from fivebar_cli.paving import Paving, deepen, pave
from fivebar_cli.quadtree import Tree, union_find
from fivebar_cli.spaces import grid as space_grid

WORKING_MODES = ((1, 1), (1, -1), (-1, 1), (-1, -1))
ASSEMBLY_MODES = (1, -1)
SMALL_COMPONENT = 64  # components with at most this many leaves are sampled densely when linking
DENSE = 4  # samples per axis and leaf for small components
REFINE_STEPS = ((2, 4), (4, 16), (8, 32), (10, 64))  # fragment refinement: (extra levels, radius in cells)
SINGULAR_TOL = 1e-9  # `locate`: |u|, |v| or |det A| below this times scale^2 is a singularity


class AspectError(FivebarError):
    """Components that cannot be matched one-to-one between the two spaces (exit status 1)."""


def signs_text(signs) -> str:
    """(+1, -1) -> '+-'."""
    return "".join("+" if s > 0 else "-" for s in np.atleast_1d(signs))


@dataclass
class Region:
    """One mode paving with its components; `modes[c]` = (sign B11, sign B22, sign det A) of component c."""

    space: str
    working: tuple[int, int] | None
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
    working: tuple[int, int]
    assembly: int
    workspace: Tree
    jointspace: Tree
    pose: tuple[float, float]
    joints: tuple[float, float]


@dataclass(frozen=True)
class Crossing:
    """Aspects `a` < `b` (same assembly mode) joined across the serial singularity `singularity`."""

    a: int
    b: int
    assembly: int
    singularity: str  # "B11" or "B22"
    band_cells: int


@dataclass
class AspectAnalysis:
    mechanism: FiveBar
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


def analyse_aspects(m: FiveBar, depth: int, advance=lambda n=1: None) -> AspectAnalysis:
    """Pave the six mode regions, label, link and number the generalized aspects, find crossings."""
    timings = {"paving": 0.0, "components": 0.0}
    regions = []
    for wm in WORKING_MODES:
        regions.append(_region(m, "workspace", wm, None, depth, timings))
        advance(1)
    for am in ASSEMBLY_MODES:
        regions.append(_region(m, "jointspace", None, am, depth, timings))
        advance(1)
    offset = 0
    for r in regions:
        r.offset, offset = offset, offset + r.count
    t0 = time.perf_counter()
    edges = _links(m, regions)
    roots, resolved = _resolve_fragments(m, regions, offset, edges)
    timings["linking"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    aspects, node_aspect = _number_aspects(m, regions, roots)
    crossings = _crossings(m, regions, aspects, node_aspect)
    timings["crossings"] = time.perf_counter() - t0
    advance(1)
    return AspectAnalysis(m, depth, regions, aspects, crossings, resolved, timings)


def _region(m: FiveBar, space: str, working, assembly, depth: int, timings: dict) -> Region:
    t0 = time.perf_counter()
    if space == "workspace":
        test = fivebar.working_mode_workspace_test(m, working)
    else:
        test = fivebar.assembly_mode_joint_test(m, assembly)
    paving = pave(space_grid(m, space, depth), test)
    t1 = time.perf_counter()
    labels, count = paving.inside.components()
    timings["paving"] += t1 - t0
    timings["components"] += time.perf_counter() - t1
    centres = paving.inside.centres()
    if space == "workspace":
        leaf_modes = np.column_stack([
            np.broadcast_to(np.array(working, np.int8), (len(centres), 2)),
            fivebar.workspace_assembly_sign(m, working, centres),
        ])
    else:
        leaf_modes = np.column_stack([
            fivebar.joint_working_mode(m, assembly, centres), np.full(len(centres), assembly, np.int8),
        ])
    modes = np.zeros((count, 3), dtype=np.int8)
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


def _links(m: FiveBar, regions: list[Region], nodes: np.ndarray | None = None) -> list[tuple[np.ndarray, np.ndarray]]:
    """Edges (node, node) between components of the two spaces that share a configuration."""
    edges = []
    for src in regions:
        points, owners = _samples(src, nodes)
        if not len(points):
            continue
        modes = src.modes[owners]
        if src.space == "workspace":
            th1, th2, ok = fivebar.ikp(m, points[:, 0], points[:, 1], src.working)
            images = np.column_stack([th1, th2])
        else:
            images, ok = fivebar.dkp(m, points[:, 0], points[:, 1], src.assembly)
        for dst in regions:
            if dst.space == src.space:
                continue
            if dst.space == "jointspace":
                sel = ok & (modes[:, 2] == dst.assembly)
            else:
                sel = ok & (modes[:, 0] == dst.working[0]) & (modes[:, 1] == dst.working[1])
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


def _resolve_fragments(m: FiveBar, regions: list[Region], total: int, edges) -> tuple[np.ndarray, int]:
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


def _number_aspects(m: FiveBar, regions: list[Region], roots: np.ndarray):
    """Aspects ordered by assembly mode (+ first), working mode (++, +-, -+, --), then position."""
    node_region = np.concatenate([np.full(r.count, k) for k, r in enumerate(regions)])
    node_local = np.concatenate([np.arange(r.count) for r in regions])
    node_modes = np.concatenate([r.modes for r in regions])
    groups = np.unique(roots)
    keys = []
    for g in groups:
        members = np.flatnonzero(roots == g)
        su, sv, sa = node_modes[members[0]]
        js = [n for n in members if regions[node_region[n]].space == "jointspace"]
        region = regions[node_region[js[0]]]
        first = min(int(region.tree.start[region.labels == node_local[n]].min()) for n in js)
        keys.append((-sa, -su, -sv, first, g))
    keys.sort()
    node_aspect = np.full(len(roots), -1)
    aspects = []
    for number, (_, _, _, _, g) in enumerate(keys, start=1):
        members = np.flatnonzero(roots == g)
        node_aspect[members] = number
        su, sv, sa = (int(v) for v in node_modes[members[0]])
        trees = {}
        for space in ("workspace", "jointspace"):
            mine = [n for n in members if regions[node_region[n]].space == space]
            region = regions[node_region[mine[0]]]
            trees[space] = region.tree.subset(np.isin(region.labels, node_local[mine]))
        pose, joints = _representative(m, (su, sv), trees["workspace"], trees["jointspace"])
        aspects.append(Aspect(number, (su, sv), sa, trees["workspace"], trees["jointspace"], pose, joints))
    return aspects, node_aspect


def _representative(m: FiveBar, working, ws: Tree, js: Tree):
    """A configuration inside the aspect: the centre of its largest workspace cell whose IKP image
    lies in the aspect's joint-space cells."""
    order = np.argsort(ws.level, kind="stable")
    centres = ws.centres()[order]
    th1, th2, ok = fivebar.ikp(m, centres[:, 0], centres[:, 1], working)
    inside = ok.copy()
    inside[ok] = js.locate(np.column_stack([th1[ok], th2[ok]])) >= 0
    k = int(np.argmax(inside)) if inside.any() else 0
    return (float(centres[k, 0]), float(centres[k, 1])), (float(th1[k]), float(th2[k]))


# ---------------------------------------------------------------- crossings


def _crossings(m: FiveBar, regions: list[Region], aspects: list[Aspect], node_aspect: np.ndarray) -> list[Crossing]:
    """Aspect pairs joined by a band of cells crossed by one serial singularity only."""
    modes = {a.number: (a.working[0], a.working[1], a.assembly) for a in aspects}
    found: dict[tuple, int] = {}
    for region in regions:
        if region.space != "jointspace" or not len(region.paving.undetermined):
            continue
        grid, cells = region.paving.grid, region.paving.undetermined
        lo, hi = grid.boxes(grid.depth, cells)
        _, strict, u, v = fivebar.joint_mode_classes(m, region.assembly, lo, hi)
        # (name, band cells, index of the sign that changes across it)
        for name, band, changing in (("B11", strict & (u == 0) & (v != 0), 0),
                                     ("B22", strict & (v == 0) & (u != 0), 1)):
            if not band.any():
                continue
            band_tree = Tree.from_cells(grid, grid.depth, cells[band])
            labels, count = band_tree.components()
            size = np.bincount(labels, minlength=count)
            i, j = band_tree.adjacency(region.tree)
            touched = np.unique(np.column_stack([labels[i], node_aspect[region.offset + region.labels[j]]]), axis=0)
            starts = np.flatnonzero(np.r_[True, touched[1:, 0] != touched[:-1, 0]])
            for comp_rows in np.split(touched, starts[1:]):
                numbers = comp_rows[:, 1]
                for x in numbers:
                    for y in numbers[numbers > x]:
                        mx, my = modes[int(x)], modes[int(y)]
                        if mx[changing] != my[changing] and mx[1 - changing] == my[1 - changing]:
                            key = (int(x), int(y), region.assembly, name)
                            found[key] = found.get(key, 0) + int(size[comp_rows[0, 0]])
    return [Crossing(a, b, am, name, n) for (a, b, am, name), n in sorted(found.items())]


def adjacency_matrix(analysis: AspectAnalysis, assembly: int) -> tuple[list[int], np.ndarray]:
    """Aspect numbers of an assembly mode and their crossing adjacency (boolean matrix)."""
    numbers = [a.number for a in analysis.aspects if a.assembly == assembly]
    index = {n: k for k, n in enumerate(numbers)}
    adj = np.zeros((len(numbers), len(numbers)), bool)
    for c in analysis.crossings:
        if c.assembly == assembly:
            adj[index[c.a], index[c.b]] = adj[index[c.b], index[c.a]] = True
    return numbers, adj


def locate_configurations(analysis: AspectAnalysis, points: np.ndarray, space: str) -> list[dict]:
    """Every configuration at the given poses (workspace) or joint values (joint space), with its
    modes and the aspect containing it (None when on or near a singularity at this depth).

    On a singularity two branches coincide (a stretched leg has one elbow): such a configuration is
    listed once, with the sign that vanishes written 0.
    """
    m = analysis.mechanism
    out = []
    for k, point in enumerate(np.atleast_2d(points)):
        seen: list[np.ndarray] = []
        if space == "workspace":
            candidates = [(point, np.array([th1[0], th2[0]]))
                          for th1, th2, ok in (fivebar.ikp(m, point[:1], point[1:], wm) for wm in WORKING_MODES) if ok[0]]
        else:
            candidates = [(p[0], point) for p, ok in (fivebar.dkp(m, point[:1], point[1:], am) for am in ASSEMBLY_MODES)
                          if ok[0]]
        for pose, joints in candidates:
            key = np.concatenate([pose, np.cos(joints), np.sin(joints)])
            if any(np.allclose(key, other, rtol=0, atol=1e-9 * fivebar.scale(m)) for other in seen):
                continue
            seen.append(key)
            out.append(_configuration(analysis, k, pose, joints))
    return out


def _configuration(analysis: AspectAnalysis, index: int, pose: np.ndarray, joints: np.ndarray) -> dict:
    m = analysis.mechanism
    u, v, t = (float(x[0]) for x in fivebar.mode_values(m, joints[:1], joints[1:], pose[None, :]))
    tol = SINGULAR_TOL * fivebar.scale(m) ** 2
    su, sv, sa = (0 if abs(x) <= tol else int(np.sign(x)) for x in (u, v, t))
    joints = (joints + np.pi) % (2 * np.pi) - np.pi
    number = None
    for a in analysis.aspects:
        if (a.working, a.assembly) == ((su, sv), sa):
            if a.workspace.locate(pose[None, :])[0] >= 0 and a.jointspace.locate(joints[None, :])[0] >= 0:
                number = a.number
    singular = [what for value, what in ((su, "serial (B11 = 0)"), (sv, "serial (B22 = 0)"), (sa, "parallel (det A = 0)"))
                if value == 0]
    return {
        "input": index, "x": float(pose[0]), "y": float(pose[1]),
        "theta1": float(joints[0]), "theta2": float(joints[1]),
        "working_mode": "".join({1: "+", -1: "-", 0: "0"}[s] for s in (su, sv)),
        "assembly_mode": {1: "+", -1: "-", 0: "0"}[sa],
        "aspect": number, "singular": ", ".join(singular),
    }


# ---------------------------------------------------------------- tables

ASPECT_HEADER = (
    "aspect", "working_mode", "assembly_mode", "workspace_area", "jointspace_area",
    "workspace_cells", "jointspace_cells", "x", "y", "theta1", "theta2",
)
CROSSING_HEADER = (
    "aspect_a", "aspect_b", "assembly_mode", "singularity", "working_mode_a", "working_mode_b", "band_cells",
)


def aspect_rows(analysis: AspectAnalysis) -> list[tuple]:
    return [
        (a.number, signs_text(a.working), signs_text(a.assembly), a.workspace.area, a.jointspace.area,
         len(a.workspace), len(a.jointspace), *a.pose, *a.joints)
        for a in analysis.aspects
    ]


def crossing_rows(analysis: AspectAnalysis) -> list[tuple]:
    modes = {a.number: signs_text(a.working) for a in analysis.aspects}
    return [(c.a, c.b, signs_text(c.assembly), c.singularity, modes[c.a], modes[c.b], c.band_cells)
            for c in analysis.crossings]


def paper_claim_holds(analysis: AspectAnalysis, assembly: int) -> bool:
    """Chablat (2010), 3.6: for det A > 0 there are five aspects and no motion changing the working
    mode once joins aspects 1 and 4, nor any two of 2, 3, 5 -- while the other pairs are joined.
    That is: the crossing graph is complete bipartite between two aspects and the other three."""
    numbers, adj = adjacency_matrix(analysis, assembly)
    if len(numbers) != 5:
        return False
    for pair in ((i, j) for i in range(5) for j in range(i + 1, 5)):
        two = list(pair)
        three = [k for k in range(5) if k not in two]
        expected = np.zeros((5, 5), bool)
        for a in two:
            for b in three:
                expected[a, b] = expected[b, a] = True
        if np.array_equal(adj, expected):
            return True
    return False
