"""The singularity-free configurations of one working and assembly mode, in one space: inner and
outer approximations, their components, and local refinement that joins or separates them.

S is the set of non-singular configurations with given modes, seen in one space (an open set).
The *inner* approximation is the black cells of the mode paving that carry these modes (every
point in S); the *outer* one adds every undetermined cell not certified to miss S (the box test
may hold a valid point and the signs that are constant on the box do not contradict the modes).
Cells are closed, so two cells touching at a corner share a point: components are taken with
corner contact, on the torus where the space wraps. Then:

- the black cells of one inner component (an *anchor*) lie in one component of S (the points
  they share are in S);
- every component of S lies in one component of the outer set (S is inside it and connected), so
  anchors in different outer components lie in different components of S.

Anchors of one outer component may be one component of S or several. Local refinement decides:
paving the undetermined cells near an anchor a few levels deeper can find black cells that join it
to another (`join`), and paving all undetermined cells of the outer component deeper can split it
into parts that separate the anchors (`split`). Near a pinch (two singular curves tangent) a thin
tail of S shows detached black cells at every depth; they never need deciding: only the anchors
(the paving's own black components) do.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fivebar_cli.paving.engine import Paving, deepen
from fivebar_cli.paving.grid import MAX_INDEX_BITS, Grid
from fivebar_cli.paving.morton import deinterleave, finest_key, finest_order, interleave
from fivebar_cli.paving.arrays import dense_rank, index_type, label_type, rows_equal, unique
from fivebar_cli.paving.tree import Tree, root_labels, union_find_blocks

# (extra levels, window radius in cells) to join anchors; None: the whole outer component
JOIN_STEPS = ((2, 4), (2, 16), (4, 16), (2, 64), (4, 64), (6, 32), (2, 256), (2, None), (4, None))
SPLIT_STEP = 2  # levels added per round when separating anchors
SPLIT_EXTRA = 12  # separation goes at most this many levels below the paving's depth


@dataclass
class Budget:
    """Box evaluations that local refinement may still spend (shared by a whole analysis)."""

    left: int
    spent: int = 0

    def take(self, n: int) -> None:
        self.left -= n
        self.spent += n

    def allows(self, cells: int, extra: int, dim: int) -> bool:
        """Whether paving `cells` cells `extra` levels deeper can fit: at most 2^dim + 4^dim + ...
        evaluations per cell."""
        return cells * sum((1 << dim) ** k for k in range(1, extra + 1)) <= self.left


@dataclass(frozen=True)
class CellSet:
    """Disjoint cells of a grid: black (in S) or undetermined (may meet S); `leaf` is the index of
    the paving's black leaf a black cell is (-1 for cells found by refinement and undetermined ones)."""

    grid: Grid
    level: np.ndarray
    code: np.ndarray
    black: np.ndarray
    leaf: np.ndarray

    def select(self, mask: np.ndarray) -> "CellSet":
        return CellSet(self.grid, self.level[mask], self.code[mask], self.black[mask], self.leaf[mask])

    def tree(self, mask: np.ndarray | None = None) -> Tree:
        """The selected cells as a tree (their own leaves, sorted, not merged)."""
        level, code = (self.level, self.code) if mask is None else (self.level[mask], self.code[mask])
        return _sorted_tree(self.grid, level, code)[0]

    def undetermined_coords(self) -> np.ndarray:
        """Integer coordinates of the undetermined cells (all at the grid's depth)."""
        und = ~self.black
        return deinterleave(self.code[und], self.level[und], self.grid.dim)


def _sorted_tree(grid, level: np.ndarray, code: np.ndarray) -> tuple[Tree, np.ndarray]:
    """Cells as a tree (their own leaves, sorted, not merged) and the order that sorts them."""
    order = finest_order(code, level, grid.dim, grid.depth)
    return Tree(grid, level[order], code[order], canonical=True), order


def components(cells: CellSet, mask: np.ndarray | None = None) -> tuple[np.ndarray, int]:
    """Corner-connected components of the selected cells, labels in the cells' own order."""
    level = cells.level if mask is None else cells.level[mask]
    code = cells.code if mask is None else cells.code[mask]
    if len(level) == 0:
        return np.zeros(0, np.int64), 0
    tree, order = _sorted_tree(cells.grid, level, code)
    labels, count = tree.components(corners=True)
    out = np.empty_like(labels)
    out[order] = labels
    return out, count


def components_with_black(cells: CellSet) -> tuple[tuple[np.ndarray, int], tuple[np.ndarray, int]]:
    """(`components(cells)`, `components` of its black cells `cells.select(cells.black)`), from one
    neighbour search (`Tree.components_within`): the same labels as each alone."""
    if len(cells.level) == 0:
        return (np.zeros(0, np.int64), 0), (np.zeros(0, np.int64), 0)
    tree, order = _sorted_tree(cells.grid, cells.level, cells.code)
    black = cells.black[order]
    (labels, count), (black_labels, black_count) = tree.components_within(black, corners=True)
    out = np.empty_like(labels)
    out[order] = labels
    place = np.empty(len(order), np.int64)
    place[order] = np.cumsum(black) - 1  # each cell's index among the black cells, in the tree's order
    return (out, count), (black_labels[place[cells.black]], black_count)


class ModeSet:
    """One mode set S of one space: its cells, anchors and outer components.

    `anchor_of_leaf[k]` is the anchor of black leaf k of the region's paving (-1 when the leaf has
    other modes); `anchor_outer[a]` is the outer component holding anchor a.
    """

    def __init__(self, region, secondary: tuple[int, ...]):
        self.region = region
        self.space = region.space
        self.secondary = np.array(secondary, np.int8)  # the signs the region's paving leaves free, fixed here
        self.modes = region.modes_with(secondary)
        paving = region.paving
        grid = paving.grid
        # a set's arrays per cell stay through the analysis: the black leaves and undetermined
        # cells it holds as bits, anchors and outer components (a few) in the smallest type
        black = rows_equal(region.free, self.secondary)
        mine = np.flatnonzero(black)
        fits = region.und_possible & _allow(region.und_signs, self.secondary)
        self.grid, self._black, self._fits = grid, np.packbits(black), np.packbits(fits)
        self._leaves, self._cells = len(paving.inside), len(paving.undetermined)
        anchors = dense_rank(region.black_labels[mine])
        self.n_anchors = int(anchors.max()) + 1 if len(anchors) else 0
        anchors = anchors.astype(label_type(self.n_anchors))
        self.leaf_anchors = anchors  # the anchor of each of the set's black leaves (`black_leaves`)
        outer, self.n_outer = self._outer_components(mine, fits, anchors)
        self.outer = outer.astype(label_type(self.n_outer))
        self.anchor_outer = np.zeros(self.n_anchors, np.int64)
        self.anchor_outer[anchors] = self.outer[:len(mine)]  # (the set's black cells come first)
        self.anchor_size = np.bincount(anchors, minlength=self.n_anchors)
        self.links = None  # the certificate's link samples, when a worker found them (`aspects.link_points`)

    @property
    def black_leaves(self) -> np.ndarray:
        """Indices of the region's black leaves that are the set's (sorted)."""
        return np.flatnonzero(np.unpackbits(self._black, count=self._leaves).view(bool))  # (10x faster than of uint8)

    @property
    def anchor_of_leaf(self) -> np.ndarray:
        """The anchor of each black leaf of the region's paving (-1 when the leaf has other modes),
        int32, built when asked: kept for every mode set of a region, these arrays of all its
        leaves were a third of the sets' memory."""
        out = np.full(self._leaves, -1, np.int32)
        out[self.black_leaves] = self.leaf_anchors
        return out

    @property
    def cells(self) -> CellSet:
        """The set's cells: its black leaves, then its undetermined cells. Built when asked (for
        refinement, partners): kept for every mode set through a whole analysis, they would be
        most of its memory."""
        mine, _, und = self._parts()
        return self._cell_set(mine, und)

    def _parts(self, part: np.ndarray | None = None):
        """The set's black leaves, their anchors and its undetermined cells' coordinates (`cells`
        in pieces), or those of the mask `part` over its cells only."""
        mine, anchors = self.black_leaves, self.leaf_anchors
        und = np.flatnonzero(np.unpackbits(self._fits, count=self._cells).view(bool))
        if part is not None:
            mine, anchors, und = mine[part[:len(mine)]], anchors[part[:len(mine)]], und[part[len(mine):]]
        return mine, anchors, self.region.paving.undetermined[und]

    def _cell_set(self, mine: np.ndarray, und: np.ndarray) -> CellSet:
        """Black leaves `mine` of the region's paving, then undetermined cells `und` (coordinates)."""
        inside, depth = self.region.paving.inside, self.grid.depth
        level = np.concatenate([inside.level[mine], np.full(len(und), depth, np.int64)])
        code = np.concatenate([inside.code[mine], _codes(und, depth)])
        black = np.concatenate([np.ones(len(mine), bool), np.zeros(len(und), bool)])
        return CellSet(self.grid, level, code, black, np.concatenate([mine, np.full(len(und), -1, np.int64)]))

    def _boxes(self, mine: np.ndarray, und: np.ndarray):
        """The integer boxes (`_integer_boxes`) of `_cell_set(mine, und)`'s cells, the undetermined
        cells' straight from their coordinates (not interleaved, then deinterleaved)."""
        inside = self.region.paving.inside
        lo, hi = _integer_boxes(self.grid, inside.level[mine], inside.code[mine])
        und = und.astype(np.int64, copy=False)
        return np.concatenate([lo, und]), np.concatenate([hi, und + 1])

    def _outer_components(self, mine: np.ndarray, fits: np.ndarray, anchors: np.ndarray) -> tuple[np.ndarray, int]:
        """Components of the outer set (black leaves `mine`, undetermined cells `fits`), from the
        region's pairs of touching cells: nodes are the anchors, then the undetermined cells."""
        n_black = len(self.region.tree)
        und = np.flatnonzero(fits)
        small = index_type(n_black + len(fits))
        node = np.full(n_black + len(fits), -1, small)
        node[mine] = anchors
        node[n_black + und] = np.arange(self.n_anchors, self.n_anchors + len(und), dtype=small)
        node_und = node[n_black:]

        def edges():  # the region's pairs within the set, a direction at a time (`union_find_blocks`)
            for u, n in self.region.und_pairs:  # (gathers by int32 indices cost 2x a cast and a gather)
                a, b = node_und[u.astype(np.intp)], node[n.astype(np.intp)]
                keep = (a | b) >= 0  # both ends in the set: neither is -1 (the sign bit clear in both)
                yield a[keep], b[keep]

        labels, count = root_labels(union_find_blocks(self.n_anchors + len(und), edges()))
        return np.concatenate([labels[anchors], labels[self.n_anchors:]]), count

    def compatible(self, grid: Grid, coords: np.ndarray) -> np.ndarray:
        """Undetermined cells that may meet S: not certified empty, no sign against S's."""
        if len(coords) == 0:
            return np.zeros(0, bool)
        lo, hi = grid.boxes(grid.depth, coords)
        possible, signs = self.region.signs(lo, hi)
        return possible & _allow(signs, self.secondary)

    def outer_cells(self, o: int) -> CellSet:
        mine, _, und = self._parts(self.outer == o)
        return self._cell_set(mine, und)

    def anchors_in(self, o: int) -> np.ndarray:
        return np.flatnonzero(self.anchor_outer == o)

    # -- refinement

    def _deeper(self, cells: CellSet, extra: int, budget: Budget, local: Paving | None = None) -> CellSet | None:
        """`cells` with their undetermined cells paved `extra` levels deeper: new black cells join
        the black ones, new undetermined cells that may meet S replace the old ones. None when the
        budget cannot pay for it. `local`: that paving (`deepen` of the undetermined cells), when
        made beforehand (with other sets', `engine.deepen_many`)."""
        if not budget.allows(int(np.count_nonzero(~cells.black)), extra, cells.grid.dim):
            return None
        if local is None:
            local = deepen(cells.grid, self.region.test, cells.undetermined_coords(), extra)
        budget.take(local.evaluations)
        deeper = local.grid
        new_black = local.inside
        if len(new_black):  # black cells of other modes are outside S
            new_black = new_black.subset(rows_equal(self.region.free_signs(new_black.centres()), self.secondary))
        new_und = local.undetermined[self.compatible(deeper, local.undetermined)]
        old = cells.select(cells.black)
        level = np.concatenate([old.level, new_black.level, np.full(len(new_und), deeper.depth, np.int64)])
        code = np.concatenate([old.code, new_black.code, _codes(new_und, deeper.depth)])
        black = np.concatenate([np.ones(len(old.level) + len(new_black), bool), np.zeros(len(new_und), bool)])
        leaf = np.concatenate([old.leaf, np.full(len(new_black) + len(new_und), -1, np.int64)])
        return CellSet(deeper, level, code, black, leaf)

    def join(self, o: int, roots: np.ndarray, budget: Budget) -> list[tuple[int, int]]:
        """Pairs of anchors of outer component `o` proved to be one component of S, by paving the
        undetermined cells near all but the largest group of anchors deeper (growing windows).

        `roots[a]` groups anchors already known to be one component.
        """
        anchors = self.anchors_in(o)
        groups = roots[anchors]
        sizes = {g: self.anchor_size[anchors[groups == g]].sum() for g in unique(groups)}
        biggest = max(sizes, key=lambda g: (sizes[g], -g))
        small = anchors[groups != biggest]
        # the outer component's cells as pieces: its black leaves and their integer boxes, its
        # undetermined cells (their boxes: [und, und + 1)); windows of black leaves, near cells of
        # undetermined ones, each `_near` over its own kind only (the masks per box are the same)
        mine, cell_anchor, und = self._parts(self.outer == o)
        grid, inside = self.grid, self.region.paving.inside
        b_lo, b_hi = _integer_boxes(grid, inside.level[mine], inside.code[mine])
        u_lo = und.astype(np.int64, copy=False)
        u_hi = u_lo + 1
        targets = np.isin(cell_anchor, small)
        t_lo, t_hi = b_lo[targets], b_hi[targets]
        found = []
        for extra, radius in JOIN_STEPS:
            if budget.left <= 0 or grid.depth + extra > MAX_INDEX_BITS // grid.dim:
                break
            if radius is None:
                near, window = np.ones(len(und), bool), np.ones(len(mine), bool)
            else:
                near = _near(grid, t_lo, t_hi, u_lo, u_hi, radius)
                window = _near(grid, t_lo, t_hi, b_lo, b_hi, 2 * radius)
            if not near.any():
                break
            local = self._deeper(self._cell_set(mine[window], und[near]), extra, budget)
            if local is None:
                continue
            labels, _ = components(local, local.black)
            # the window's anchors, located by their cells' first depth index in the refined set
            old = self._cell_set(mine[window], und[:0])  # (the window's cells are black)
            old_anchor = cell_anchor[window]
            black_local = local.select(local.black)
            where = _position(black_local, old.level, old.code)
            owner = labels[where]
            pairs = [(a, b) for a, b in _same_label_pairs(owner, old_anchor) if roots[a] != roots[b]]
            found += pairs
            if pairs:
                break
        return found

    def isolate(self, o: int, group: np.ndarray, roots: np.ndarray, budget: Budget) -> bool:
        """Whether a group of anchors of outer component `o` is separated from everything else in
        it, by a local argument: pave the undetermined cells of a window around the group deeper
        (growing windows); if the group's part of the refined window touches no outer cell outside
        the window (the ring: outer cells touching a window cell), no outer path leaves the window
        from it, so it is a whole outer component and holds no other group's anchor, unless the
        refined part itself holds one."""
        mine, cell_anchor, und = self._parts(self.outer == o)
        cells, (cell_lo, cell_hi) = self._cell_set(mine, und), self._boxes(mine, und)
        grid = cells.grid
        anchor_of_leaf = self.anchor_of_leaf
        members = np.isin(cell_anchor, group)  # (the group's anchors are in o; black cells first)
        g_lo, g_hi = cell_lo[:len(members)][members], cell_hi[:len(members)][members]
        for extra, radius in JOIN_STEPS:
            if radius is None or budget.left <= 0 or grid.depth + extra > MAX_INDEX_BITS // grid.dim:
                return False
            window = _near(grid, g_lo, g_hi, cell_lo, cell_hi, radius)
            if not window[~cells.black].any():
                continue
            ring = _touching(cells, window)
            local = self._deeper(cells.select(window), extra, budget)
            if local is None:
                return False
            outside = cells.select(ring)
            both = _concat(local, CellSet(local.grid, outside.level, outside.code, outside.black, outside.leaf))
            labels, _ = components(both)
            in_group = (both.leaf >= 0) & np.isin(anchor_of_leaf[np.maximum(both.leaf, 0)], group)
            part = np.isin(labels, unique(labels[in_group]))
            if part[len(local.level):].any():
                continue  # the group's part reaches the ring: try a larger window
            held = both.leaf[part & (both.leaf >= 0)]
            if np.isin(roots[anchor_of_leaf[held]], roots[group]).all():  # (every root held is the group's)
                return True
        return False

    def split(self, o: int, roots: np.ndarray, budget: Budget, limit: int) -> bool:
        """Whether the anchors of outer component `o` that are not known to be one component of S
        (`roots[a]`) can be separated: its undetermined cells are paved deeper, round after round,
        until no part of the outer set holds two of them. A part holding none of them but black
        cells is a component of S of its own: the outer component stays undecided then, as it does
        when the budget or the depth limit ends the search first."""
        cells, anchor_of_leaf = self.outer_cells(o), self.anchor_of_leaf
        while budget.left > 0 and cells.grid.depth + SPLIT_STEP <= limit:
            old = cells.select(cells.leaf >= 0)  # the paving's leaves
            cells = self._deeper(cells, SPLIT_STEP, budget)
            if cells is None:
                return False
            outer, count = components(cells)
            anchor_roots = roots[anchor_of_leaf[old.leaf]]
            part_of_old = outer[_position(cells, old.level, old.code)]
            separated = True
            for k in range(count):
                held = unique(anchor_roots[part_of_old == k])
                if len(held) > 1:
                    separated = False
                elif len(held) == 0 and np.any(cells.black[outer == k]):
                    return False
            if separated:
                return True
        return False

    def hidden_parts(self, o: int, extra: int, budget: Budget, limit: int,
                     local: Paving | None = None) -> tuple[int, int]:
        """What outer component `o` hides below the paving's depth: its undetermined cells are
        paved `extra` levels deeper and the new black cells that touch no black cell joined to
        the paving's leaves (islands) are joined to them by local refinement (growing windows
        paved two levels deeper still). Returns (found, open): the islands left whose part of the
        deeper outer set holds none of the paving's leaves are components of S of their own that
        the paving's black cells missed (found, proven); an island left in a part with the
        paving's leaves may be one (open), as may a part without black cells that does not vanish
        under refinement. `local`: the deepening of `outer_cells(o)`'s undetermined cells, when
        made beforehand (`_deeper`)."""
        cells = self.outer_cells(o)
        old = cells.select(cells.leaf >= 0)
        deeper = self._deeper(cells, extra, budget, local)
        if deeper is None:
            return 0, 1
        black = deeper.select(deeper.black)
        (parts, n_parts), (labels, count) = components_with_black(deeper)
        joined = np.isin(np.arange(count), labels[_position(black, old.level, old.code)])
        for island in np.flatnonzero(~joined):
            joined[island] = self._joins(deeper, black, labels, joined, island, budget)
        anchored = np.zeros(n_parts, bool)
        anchored[parts[_position(deeper, old.level, old.code)]] = True
        island_cells = np.flatnonzero(deeper.black)[~joined[labels]]
        found = len(unique(parts[island_cells][~anchored[parts[island_cells]]]))
        opened = int(np.any(anchored[parts[island_cells]]))
        with_black = np.zeros(n_parts, bool)
        with_black[parts[deeper.black]] = True
        for k in np.flatnonzero(~anchored & ~with_black):
            opened += not self.vanishes(deeper.select(parts == k), budget, limit)
        return found, opened

    def _joins(self, cells: CellSet, black: CellSet, labels: np.ndarray, joined: np.ndarray, island: int,
               budget: Budget) -> bool:
        """Whether black cells found by paving a window of `cells` around one island of `black`
        (labels: its components; joined: those holding or joined to the paving's leaves) two
        levels deeper join the island to a joined component."""
        grid = cells.grid
        own = black.select(labels == island)
        i_lo, i_hi = _integer_boxes(grid, own.level, own.code)
        c_lo, c_hi = _integer_boxes(grid, cells.level, cells.code)
        for radius in (4, 16):
            if grid.depth + 2 > MAX_INDEX_BITS // grid.dim or budget.left <= 0:
                return False
            window = _near(grid, i_lo, i_hi, c_lo, c_hi, radius)
            local = self._deeper(cells.select(window), 2, budget)
            if local is None:
                return False
            lb = local.select(local.black)
            comp, _ = components(lb)
            wb = cells.select(window & cells.black)  # the window's black cells, kept in `local`
            where = _position(lb, wb.level, wb.code)
            mine = np.isin(_position(black, wb.level, wb.code), np.flatnonzero(labels == island))
            good = joined[labels[_position(black, wb.level, wb.code)]]
            if np.intersect1d(comp[where[mine]], comp[where[good]]).size:
                return True
        return False

    def vanish(self, o: int, budget: Budget, limit: int, first: Paving | None = None) -> bool:
        """Whether outer component `o`, which holds no black cell, is proved to miss S: paved
        deeper until no cell of it may meet S (True), or a black cell shows a component of S in it,
        or the budget or the depth limit ends the search (False). `first`: the first round's
        paving, when made beforehand (`_deeper`)."""
        return self.vanishes(self.outer_cells(o), budget, limit, first)

    def vanishes(self, cells: CellSet, budget: Budget, limit: int, first: Paving | None = None) -> bool:
        """`vanish` for any cells without black ones (a part of the outer set, e.g. found deeper)."""
        while budget.left > 0 and cells.grid.depth + SPLIT_STEP <= limit:
            cells = self._deeper(cells, SPLIT_STEP, budget, first)
            first = None
            if cells is None or cells.black.any():
                return False
            if len(cells.level) == 0:
                return True
        return False


def undetermined_pairs(paving: Paving, index=None) -> list[tuple[np.ndarray, np.ndarray]]:
    """Every (undetermined cell u, neighbour n) touching at a point, a pair of undetermined cells
    once (n's index above u's); n < len(black leaves) is a black leaf, else the undetermined cell
    n - len(black leaves); as arrays (u, n), one block per direction (`union_find_blocks` joins
    them faster a block at a time). Undetermined cells are the smallest cells, so looking up their
    neighbours (among themselves, then among the black leaves) finds every pair; a pair of
    undetermined cells is looked up in half the directions (`Tree.neighbour_pairs`'s `once`), so
    the blocks come in the order of `once`. int32 when the indices fit: these pairs are most of a region's memory (about 7 per undetermined cell).
    `index`: the black leaves' `Tree.search_index()`, when at hand."""
    grid, inside, und = paving.grid, paving.inside, paving.undetermined
    n_black = len(inside)
    small = index_type(n_black + len(und))
    code = interleave(und, grid.depth) if len(und) else np.zeros(0, np.int64)
    order = None  # the cells' Morton order, when they are not in it already (a paving's are)
    if np.any(code[1:] < code[:-1]):
        order = np.argsort(code, kind="stable").astype(small)
        code = code[order]
    cells = Tree(grid, np.full(len(code), grid.depth, np.int64), code, canonical=True)
    del code
    blocks = []
    # a pair of undetermined cells is looked up from one side only (`once`: they share a level)
    for i, j in cells.neighbour_pairs(inside, corners=True, itself=True, once=True, other_index=index):
        u, n = i.astype(small), j.astype(small)
        if order is not None:
            u = order[i]
            und_n = n >= n_black
            n[und_n] = n_black + order[n[und_n] - n_black]
        swap = np.flatnonzero((n >= n_black) & (n - n_black < u))  # the lower index first
        u[swap], n[swap] = n[swap] - n_black, u[swap] + n_black
        blocks.append((u, n))
    return blocks


def _allow(signs: np.ndarray, values: np.ndarray) -> np.ndarray:
    """Rows of signs that do not contradict `values`: every sign 0 (undecided) or equal."""
    out = np.ones(len(signs), bool)
    for c in range(signs.shape[1]):
        out &= (signs[:, c] == 0) | (signs[:, c] == values[c])
    return out


def _touching(cells: CellSet, inside: np.ndarray) -> np.ndarray:
    """Mask of the cells not in `inside` that touch (share a point with) a cell in it."""
    tree = cells.tree()
    order = finest_order(cells.code, cells.level, cells.grid.dim, cells.grid.depth)
    rank = np.empty_like(order)
    rank[order] = np.arange(len(order))
    i, j = tree.adjacency(corners=True)
    inside_sorted = inside[order]
    out_sorted = np.zeros(len(order), bool)
    out_sorted[j[inside_sorted[i] & ~inside_sorted[j]]] = True
    out_sorted[i[inside_sorted[j] & ~inside_sorted[i]]] = True
    return out_sorted[rank]


def _concat(a: CellSet, b: CellSet) -> CellSet:
    """Two disjoint cell sets of one grid as one."""
    return CellSet(a.grid, np.concatenate([a.level, b.level]), np.concatenate([a.code, b.code]),
                   np.concatenate([a.black, b.black]), np.concatenate([a.leaf, b.leaf]))


def _codes(coords: np.ndarray, level: int) -> np.ndarray:
    return interleave(coords, level).astype(np.int64) if len(coords) else np.zeros(0, np.int64)


def _integer_boxes(grid: Grid, level: np.ndarray, code: np.ndarray):
    """Cells as half-open boxes of depth-D cell indices."""
    coords = deinterleave(code, level, grid.dim)
    shift = (grid.depth - level)[:, None]
    return coords << shift, (coords + 1) << shift


def _near(grid: Grid, a_lo, a_hi, b_lo, b_hi, radius: int) -> np.ndarray:
    """Mask of the boxes b within about `radius` cells (Chebyshev) of some box a, periodic axes
    wrapping: boxes are hashed into blocks of side >= radius, and b is near when a block it overlaps
    is within one block of a block some a overlaps (a superset of the exact answer: a window).
    The marked blocks are kept as sorted flat indices, so memory follows the boxes, not the
    (2^depth / radius)^dim blocks of the grid (an octree at depth 12 has 2^30 blocks of 4 cells)."""
    keep = np.zeros(len(b_lo), bool)
    if not len(a_lo) or not len(b_lo):
        return keep
    k = max(int(radius - 1).bit_length(), 0)
    n = (1 << grid.depth) >> k if grid.depth >= k else 1
    n = max(n, 1)
    shape = (n,) * grid.dim
    blocks = list(_enumerate(a_lo, a_hi, k, n, pad=1, periodic=grid.periodic))
    marked = unique(np.concatenate([np.ravel_multi_index(idx, shape) for idx in blocks]))
    # only the boxes b that reach into the marked blocks' bounding range along every axis can
    # overlap one of them (a window is small: most boxes b leave here, by a few comparisons)
    candidate = np.ones(len(b_lo), bool)
    for axis in range(grid.dim):
        first = min(int(idx[axis].min()) for idx in blocks)
        last = max(int(idx[axis].max()) for idx in blocks)
        candidate &= b_lo[:, axis] < ((last + 1) << k)
        candidate &= b_hi[:, axis] > (first << k)
    candidate = np.flatnonzero(candidate)
    b_lo, b_hi = b_lo[candidate], b_hi[candidate]
    lo_blk, hi_blk = _block_span(b_lo, b_hi, k, n)
    # every run of blocks along the last axis a box b overlaps (one per index of the other axes):
    # a marked flat index between the run's ends makes b near (flat indices are in C order)
    head_lo, head_hi = lo_blk[:, :-1], hi_blk[:, :-1]
    runs = np.prod(head_hi - head_lo + 1, axis=1)
    owner = np.repeat(np.arange(len(b_lo)), runs)
    offset = np.arange(int(runs.sum())) - np.repeat(np.cumsum(runs) - runs, runs)
    base = np.zeros(len(owner), np.int64)
    for axis in range(grid.dim - 1):
        width = head_hi[owner, axis] - head_lo[owner, axis] + 1
        base = base * n + head_lo[owner, axis] + offset % width
        offset = offset // width
    first = np.searchsorted(marked, base * n + lo_blk[owner, -1])
    last = np.searchsorted(marked, base * n + hi_blk[owner, -1], side="right")
    keep[candidate[owner[first < last]]] = True
    return keep


def _block_span(lo, hi, k: int, n: int):
    """First and last block index per axis of half-open integer boxes."""
    return np.minimum(lo >> k, n - 1), np.minimum((hi - 1) >> k, n - 1)


def _enumerate(a_lo, a_hi, k: int, n: int, pad: int, periodic):
    """Index tuples of every block within `pad` blocks of each box (wrapping periodic axes)."""
    lo_blk, hi_blk = _block_span(a_lo, a_hi, k, n)
    lo_blk, hi_blk = lo_blk - pad, hi_blk + pad
    counts = np.prod(hi_blk - lo_blk + 1, axis=1)
    owner = np.repeat(np.arange(len(lo_blk)), counts)
    offset = np.arange(counts.sum()) - np.repeat(np.cumsum(counts) - counts, counts)
    index = []
    for axis in range(lo_blk.shape[1]):
        width = hi_blk[owner, axis] - lo_blk[owner, axis] + 1
        along = lo_blk[owner, axis] + offset % width
        offset = offset // width
        index.append(np.mod(along, n) if periodic[axis] else np.clip(along, 0, n - 1))
    yield tuple(index)


def _position(cells: CellSet, level: np.ndarray, code: np.ndarray) -> np.ndarray:
    """Index in `cells` of each of the given cells (which are among them, with the same level)."""
    dim, depth = cells.grid.dim, cells.grid.depth
    keys = finest_key(cells.code, cells.level, dim, depth)
    order = np.argsort(keys, kind="stable")
    return order[np.searchsorted(keys[order], finest_key(code, level, dim, depth))]


def _same_label_pairs(labels: np.ndarray, anchors: np.ndarray) -> list[tuple[int, int]]:
    """(a, b) pairs of distinct anchors whose cells share a label."""
    pairs = []
    first: dict[int, int] = {}
    for lab, a in zip(labels.tolist(), anchors.tolist()):
        if lab in first and first[lab] != a:
            pairs.append((first[lab], a))
        first.setdefault(lab, a)
    return pairs
