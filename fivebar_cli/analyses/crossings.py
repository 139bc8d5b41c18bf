"""Crossings: which generalized aspects of one assembly mode touch across one serial singularity.

Undetermined joint-space cells certified free of parallel singularities and of every serial
singularity but one (B22 != 0, say) are crossed only by that one (B11 = 0); a face-connected band
of them touching two aspects is a motion between these aspects that changes the working mode once
(one sign of the diagonal of B).
"""

from __future__ import annotations

import numpy as np

from dataclasses import dataclass

from fivebar_cli.mechanisms.base import AspectModel, plural
from fivebar_cli.paving.arrays import index_type, label_type, unique_pairs
from fivebar_cli.paving.engine import on_cells
from fivebar_cli.paving.tree import Tree, root_labels, union_find_blocks


@dataclass(frozen=True)
class Crossing:
    """Aspects `a` < `b` (same assembly mode) joined across the serial singularity `singularity`."""

    a: int
    b: int
    assembly: int
    singularity: str  # the name of the serial singularity crossed, e.g. "B11"
    band_cells: int


@dataclass(frozen=True)
class Band:
    """The undetermined cells of a joint-space region crossed by one serial singularity only (the
    working sign `changing` vanishes, the others are certified), as face-connected components:
    `size[c]` leaves of the band's quadtree in component c (its cells, a complete 2 x 2 group of
    siblings counted once: the `band_cells` of docs/formats.md); (`label`, `leaf`): the components
    and the region's black leaves they touch (distinct pairs)."""

    changing: int
    size: np.ndarray
    label: np.ndarray
    leaf: np.ndarray


def serial_bands(model: AspectModel, region, band_signs=None, index=None) -> list[Band]:
    """The bands of one joint-space mode region (`aspects.Region`), one per serial singularity that
    has some: what `find_crossings` needs of the region, computed with it (in its worker).
    `band_signs`: the undetermined cells' `serial_band_signs`, `index`: the black leaves'
    `Tree.search_index()`, when already at hand."""
    if region.space != "jointspace" or not len(region.paving.undetermined):
        return []
    grid, cells = region.paving.grid, region.paving.undetermined
    strict, signs = band_signs or on_cells(
        lambda lo, hi, ends: model.serial_band_signs(region.assembly, lo, hi, ends=ends), grid, cells, ends=True)
    bands = []
    for changing in range(len(model.serial_names)):  # the one sign that changes across the band
        others = np.delete(signs, changing, axis=1)
        band = strict & (signs[:, changing] == 0) & np.all(others != 0, axis=1)
        if not band.any():
            continue
        band_tree = Tree.from_cells(grid, grid.depth, cells[band])
        labels, count, i, j = _band_pairs(band_tree, region.tree, index)
        touched = unique_pairs(labels[i], j)  # kept through the analysis: in the smallest types
        bands.append(Band(changing, np.bincount(labels, minlength=count), touched[:, 0].astype(label_type(count)),
                          touched[:, 1].astype(index_type(len(region.tree)))))
    return bands


def _band_pairs(band: Tree, black: Tree, index=None):
    """The band's face-connected components (`Tree.components`: labels, count) and its pairs
    (band leaf, black leaf) sharing a face (`band.adjacency(black)`), from one neighbour search of
    both: a cell across a band leaf that lies in the band lies in no black leaf (they are
    disjoint), so only the others are looked up among the black leaves (`index`: theirs, when
    at hand)."""
    n_black, across = len(black), []
    small = index_type(max(len(band), n_black))

    def own():  # the band's own pairs, a direction at a time; its pairs with the black leaves kept
        for i, j in band.neighbour_pairs(black, itself=True, other_index=index):
            mine = j >= n_black
            other = np.flatnonzero(~mine)  # kept until the labels are known: in the smallest type
            across.append((i[other].astype(small), j[other].astype(small)))
            yield i[mine], j[mine] - n_black

    labels, count = root_labels(union_find_blocks(len(band), own()))
    return labels, count, np.concatenate([i for i, _ in across]), np.concatenate([j for _, j in across])


def find_crossings(model: AspectModel, regions, aspects, leaf_aspect: dict) -> list[Crossing]:
    """Aspect pairs joined by a band of cells crossed by one serial singularity only (`regions`:
    the mode regions of `aspects.py`, each with its `bands` (`serial_bands`);
    `leaf_aspect[id(region)]`: the aspect of each black leaf)."""
    modes = {a.number: (*a.working, a.assembly) for a in aspects}
    found: dict[tuple, int] = {}
    for region in regions:
        for band in region.bands:
            changing, name, size = band.changing, model.serial_names[band.changing], band.size
            numbers = leaf_aspect[id(region)][band.leaf]
            keep = numbers > 0
            touched = unique_pairs(band.label[keep], numbers[keep])
            if not len(touched):
                continue
            starts = np.flatnonzero(np.r_[True, touched[1:, 0] != touched[:-1, 0]])
            for comp_rows in np.split(touched, starts[1:]):
                numbers = comp_rows[:, 1]
                for x in numbers:
                    for y in numbers[numbers > x]:
                        mx, my = modes[int(x)], modes[int(y)]
                        if mx[changing] != my[changing] and _same_but(mx, my, changing):
                            key = (int(x), int(y), region.assembly, name)
                            found[key] = found.get(key, 0) + int(size[comp_rows[0, 0]])
    return [Crossing(a, b, am, name, n) for (a, b, am, name), n in sorted(found.items())]


def _same_but(a, b, k: int) -> bool:
    """Whether two mode vectors agree everywhere except (possibly) at working sign k."""
    return all(x == y for i, (x, y) in enumerate(zip(a, b)) if i != k)


def adjacency_matrix(aspects, crossings: list[Crossing], assembly: int) -> tuple[list[int], np.ndarray]:
    """Aspect numbers of an assembly mode and their crossing adjacency (boolean matrix)."""
    numbers = [a.number for a in aspects if a.assembly == assembly]
    index = {n: k for k, n in enumerate(numbers)}
    adj = np.zeros((len(numbers), len(numbers)), bool)
    for c in crossings:
        if c.assembly == assembly:
            adj[index[c.a], index[c.b]] = adj[index[c.b], index[c.a]] = True
    return numbers, adj


def is_complete_bipartite_2_3(aspects, crossings: list[Crossing], assembly: int) -> bool:
    """Whether the crossing graph of an assembly mode is K_{2,3}: five aspects, two of which each
    touch the other three, and no other pair touches (the paper's claim, section 3.6)."""
    numbers, adj = adjacency_matrix(aspects, crossings, assembly)
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


def paper_claim_verdict(aspects, crossings: list[Crossing], assembly: int) -> str:
    """The five-bar paper's claim of section 3.6 for one assembly mode: 'holds', 'does NOT hold',
    or why it cannot be compared."""
    count = sum(a.assembly == assembly for a in aspects)
    if count != 5:
        return f"not comparable ({plural(count, 'aspect')}, the paper has 5)"
    return "holds" if is_complete_bipartite_2_3(aspects, crossings, assembly) else "does NOT hold"


def crossing_pattern(aspects, crossings: list[Crossing], assembly: int) -> str:
    """Whether the crossing graph of an assembly mode has the K_{2,3} pattern of the paper's M1 and
    M2, for mechanisms the paper's claim is not about."""
    numbers, adj = adjacency_matrix(aspects, crossings, assembly)
    edges = int(adj.sum()) // 2
    shape = f"{plural(len(numbers), 'aspect')}, {plural(edges, 'crossing pair')}"
    if is_complete_bipartite_2_3(aspects, crossings, assembly):
        return f"K_{{2,3}} ({shape}), like the paper's M1 and M2"
    return f"not K_{{2,3}} ({shape})"
