"""The boundary of the union of a 2-D tree's cells, as straight lattice segments.

Every leaf edge is cut into unit edges of the depth-D lattice; an edge shared by two cells of the
set appears twice and is interior, an edge that appears once is on the boundary. Boundary unit
edges on one lattice line are then merged into maximal straight segments, except through a vertex
where four boundary edges meet (two cells of the set touching at a corner only), so that segments
meet only at their ends (what a polygonizer needs). Integer lattice coordinates keep it exact.

`boundary_rings` traces the same boundary as closed rings: every boundary unit edge directed with
the set on its left, each edge followed by the one leaving its end point (the left turn at a pinch
point), the cycles of that permutation found by pointer doubling, rings passing a pinch point twice
cut there; a ring keeps its corners and pinch points.
"""

from __future__ import annotations

import numpy as np

from fivebar_cli.paving.morton import deinterleave, interleave
from fivebar_cli.paving.tree import Tree


def _unit_edges(tree: Tree) -> tuple[np.ndarray, np.ndarray]:
    """Boundary unit edges: horizontal ones as (x, y) for [x, x+1] x {y}, vertical ones as (x, y)
    for {x} x [y, y+1], in depth-D lattice units."""
    depth = tree.grid.depth
    span = np.int64(1) << (depth - tree.level)
    corner = tree.coords * span[:, None]
    leaf = np.repeat(np.arange(len(tree)), span)
    offset = np.arange(int(span.sum()), dtype=np.int64) - np.repeat(np.cumsum(span) - span, span)
    x0, y0, s = corner[leaf, 0], corner[leaf, 1], span[leaf]
    n = np.int64(1) << (depth + 1)  # keys: lattice values run 0..2^depth

    def once(a: np.ndarray, b: np.ndarray) -> np.ndarray:
        keys, counts = np.unique(a * n + b, return_counts=True)
        keys = keys[counts == 1]
        return np.column_stack([keys // n, keys % n])

    horizontal = once(np.concatenate([y0, y0 + s]), np.concatenate([x0 + offset] * 2))[:, ::-1]  # (x, y)
    vertical = once(np.concatenate([x0, x0 + s]), np.concatenate([y0 + offset] * 2))  # (x, y)
    return horizontal, vertical


def _merge(edges: np.ndarray, along: int, pinch: np.ndarray, n: np.int64) -> np.ndarray:
    """Unit edges on lattice lines (`along`: the axis they run along) merged into maximal segments
    (x0, y0, x1, y1), broken at pinch vertices."""
    if not len(edges):
        return np.zeros((0, 4), np.int64)
    across = 1 - along
    order = np.lexsort((edges[:, along], edges[:, across]))
    e = edges[order]
    start_key = e[:, 0] * n + e[:, 1]
    new = np.ones(len(e), bool)
    new[1:] = (e[1:, across] != e[:-1, across]) | (e[1:, along] != e[:-1, along] + 1)
    new |= np.isin(start_key, pinch)
    first = np.flatnonzero(new)
    last = np.r_[first[1:], len(e)] - 1
    lo, hi = e[first], e[last].copy()
    hi[:, along] += 1
    return np.column_stack([lo, hi])


def boundary_segments(tree: Tree) -> np.ndarray:
    """The boundary of the union of the tree's cells: segments (x0, y0, x1, y1) in depth-D lattice
    units (integers), meeting only at their ends; sorted, so the same set gives the same array."""
    if tree.grid.dim != 2:
        raise ValueError("outlines are for quadtrees")
    if not len(tree):
        return np.zeros((0, 4), np.int64)
    horizontal, vertical = _unit_edges(tree)
    n = np.int64(1) << (tree.grid.depth + 2)
    ends = np.concatenate([horizontal, horizontal + [1, 0], vertical, vertical + [0, 1]])
    keys, degree = np.unique(ends[:, 0] * n + ends[:, 1], return_counts=True)
    pinch = keys[degree > 2]
    return np.concatenate([_merge(horizontal, 0, pinch, n), _merge(vertical, 1, pinch, n)])


def lattice_to_space(tree: Tree, points: np.ndarray) -> np.ndarray:
    """Lattice coordinates (units of depth-D cells) to the space's coordinates; the same lattice
    value always gives the same float."""
    grid = tree.grid
    return grid.lo + np.asarray(points, float) * (grid.size / float(1 << grid.depth))


# directions of directed unit edges: +x, +y, -x, -y (a left turn adds 1)
_STEP = np.array([[1, 0], [0, 1], [-1, 0], [0, -1]], np.int64)


def _directed_edges(tree: Tree):
    """The boundary as maximal straight segments directed with the set on their left: start and
    end points (n, 2) and directions (0..3, `_STEP`), in depth-D lattice units.

    On each lattice line, the leaves' sides facing one way minus those facing the other way
    (`_only_one`: memory of a few words a leaf, not its unit edges)."""
    depth = tree.grid.depth
    size = depth - tree.level  # a leaf's side: 2^size lattice units
    span = np.int64(1) << size
    lo = deinterleave(tree.start, depth, 2)  # (the leaves' lower corners: their first depth-D cells)
    hi = lo + span[:, None]
    del span
    width = (np.int64(1) << depth) + 1  # positions along a line run 0..2^depth
    out = []
    for axis in (0, 1):  # sides along x (horizontal lines y = const), then along y
        other = 1 - axis
        # the low sides of the leaves (the set beyond them) and their high sides (the set before)
        sides = _only_one(lo[:, other] * width, hi[:, other] * width, lo[:, axis], size)
        for (start, end), forward in zip(sides, (axis == 0, axis == 1)):
            line, a, b = start // width, start % width, end - (start // width) * width
            first, last = (a, b) if forward else (b, a)
            p, q = np.empty((len(a), 2), np.int64), np.empty((len(a), 2), np.int64)
            p[:, axis], p[:, other], q[:, axis], q[:, other] = first, line, last, line
            d = (0 if axis == 0 else 1) if forward else (2 if axis == 0 else 3)
            out.append((p, q, np.full(len(a), d, np.int64)))
    return tuple(np.concatenate(parts) for parts in zip(*out))


_TAG = np.array([1, -1, 2, -2], np.int8)  # an end's change of state: entering a, leaving a, entering b, leaving b


def _only_one(line_a: np.ndarray, line_b: np.ndarray, start: np.ndarray, size: np.ndarray):
    """Two unions of disjoint intervals of non-negative keys below 2^53, a: [line_a + start,
    line_a + start + 2^size) and b: [line_b + start, line_b + start + 2^size) (0 <= size < 64):
    the maximal intervals of a minus b and of b minus a, sorted. Each family sorted by its starts
    (its sizes in the low bits; disjoint, so its starts are distinct, any sort gives the same
    array, and its ends come in the same order), its touching intervals joined, so that its starts
    and ends alternate in one sorted run of ends, tagged with what they change; the two runs merged
    by one sort: the state (in a) + 2 (in b) is their running sum between consecutive ends (int8:
    0..3; the ends at one key in any order). (np.compress: numpy's boolean indexing is slower.)"""
    runs = []
    for k, line in enumerate((line_a, line_b)):
        keys = line + start
        keys <<= 6
        keys |= size
        keys.sort()  # (distinct keys: numpy's quicksort, vectorised, beats its stable sort)
        first = keys >> 6
        keys &= 63
        last = np.left_shift(1, keys, out=keys)
        last += first
        del keys
        apart = last[:-1] != first[1:]  # not joined to the next interval
        first, last = np.compress(np.r_[True, apart], first), np.compress(np.r_[apart, True], last)
        events = np.empty(2 * len(first), np.int64)
        first <<= 2
        first |= 2 * k
        last <<= 2
        last |= 2 * k + 1
        events[0::2], events[1::2] = first, last
        runs.append(events)
        del first, last
    events = np.concatenate(runs)
    del runs
    events.sort(kind="stable")  # two sorted runs: merged
    state = np.cumsum(_TAG[np.bitwise_and(events, 3, dtype=np.int8, casting="unsafe")], dtype=np.int8)
    events >>= 2  # the ends' keys
    step = events[1:] > events[:-1]  # elementary intervals [events[i], events[i + 1]) of positive length
    out = []
    for wanted in (1, 2):
        i = np.flatnonzero(step & (state[:-1] == wanted))
        start, end = events[i], events[i + 1]
        new = np.ones(len(i), bool)  # merge the touching ones
        new[1:] = start[1:] != end[:-1]
        last = np.ones(len(i), bool)
        last[:-1] = new[1:]
        out.append((np.compress(new, start), np.compress(last, end)))
    return out


def boundary_rings(tree: Tree):
    """The boundary of the union of a 2-D tree's cells as closed rings of lattice points, each
    running with the set on its left (exteriors counter-clockwise, holes clockwise), minimal: no
    ring passes a point twice, so two cells of the set touching at a corner only lie in separate
    faces, as do two holes touching at a corner. Points are the corners of the boundary and the
    pinch points. Returns (points (m, 2), ring of each point (sorted), leaf bordering each ring):
    the rings a polygonizer would find from `boundary_segments`."""
    if tree.grid.dim != 2:
        raise ValueError("outlines are for quadtrees")
    if not len(tree):
        return np.zeros((0, 2), np.int64), np.zeros(0, np.int64), np.zeros(0, np.int64)
    start, end, d = _directed_edges(tree)
    n_edges = len(d)
    m = np.int64(1) << (tree.grid.depth + 2)
    start_key = start[:, 0] * m + start[:, 1]
    end_key = end[:, 0] * m + end[:, 1]
    order = np.argsort(start_key)  # (the order of equal keys, at a pinch point, changes nothing)
    sorted_keys = start_key[order]
    lo = np.searchsorted(sorted_keys, end_key, side="left")
    succ = order[lo]
    after = np.minimum(lo + 1, n_edges - 1)
    # two edges leave the end point (four boundary edges meet there, never more): take the left turn
    pinch_next = (lo + 1 < n_edges) & (sorted_keys[after] == end_key)
    second = order[after]
    left = (d + 1) % 4
    succ = np.where(pinch_next & (d[second] == left), second, succ)
    pinch = np.zeros(n_edges, bool)  # the edge starts at a pinch point
    pinch[succ[pinch_next]] = True
    # the boundary turns at every end (straight edges are merged; a ring never goes straight
    # through a pinch point): horizontal and vertical edges alternate, and every edge starts at a
    # corner or a pinch point: all kept
    ring, position = _alternating_cycles(succ, int(np.count_nonzero(d % 2 == 0)))
    length = np.bincount(ring, minlength=n_edges)  # (rings named by their least edge: in that order)
    keep = np.empty(n_edges, np.int64)  # by ring, then along it
    keep[(np.cumsum(length) - length)[ring] + position] = np.arange(n_edges)
    points, point_ring, point_pinch = start[keep], ring[keep], pinch[keep]
    first = np.r_[True, point_ring[1:] != point_ring[:-1]]  # each ring's first point
    ring_index = np.cumsum(first) - 1
    first_edge = keep[first]
    # the cell on the left of each ring's first edge, at its start: the leaf holding it
    e = first_edge
    cell = start[e] - (d[e] == 1)[:, None] * [1, 0] - (d[e] == 2)[:, None] * [1, 1] - (d[e] == 3)[:, None] * [0, 1]
    ring_leaf = np.searchsorted(tree.start, interleave(cell, tree.grid.depth), side="right") - 1
    return _split_at_repeats(points, ring_index, point_pinch, ring_leaf, m)


def _alternating_cycles(succ: np.ndarray, half: int) -> tuple[np.ndarray, np.ndarray]:
    """`_cycles` of a permutation taking [0, half) into the rest and back (the horizontal edges
    come first in `_directed_edges`), from those of its square on [0, half): half the elements,
    the same cycles' least elements (on [0, half)) and positions twice theirs (one more after)."""
    into = succ[:half]
    low, steps = _cycles(succ[into])
    ring, position = np.empty_like(succ), np.empty_like(succ)
    ring[:half], position[:half] = low, 2 * steps
    ring[into], position[into] = low, 2 * steps + 1
    return ring, position


def _cycles(succ: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The cycles of a permutation: each element's cycle (named by its smallest element) and its
    position along the cycle from there, by pointer doubling (no loop over elements): over windows
    of 2^k steps ahead, the least element and how many steps ahead it first comes."""
    n = len(succ)
    low = np.minimum(np.arange(n), succ)
    ahead = (succ < np.arange(n)).astype(np.int64)  # steps to the window's least element
    jump, span = succ[succ], 2
    while True:  # once no window lowers its minimum, that is the cycle's minimum
        next_low = low[jump]
        new_low = np.minimum(low, next_low)
        if np.array_equal(new_low, low):
            break
        ahead = np.where(low <= next_low, ahead, ahead[jump] + span)
        low, jump, span = new_low, jump[jump], 2 * span
    length = np.bincount(low, minlength=n)[low]
    return low, (length - ahead) % length


def _split_at_repeats(points, ring, pinch, ring_leaf, m):
    """Rings that pass a pinch point twice (two holes touching at a corner, or a hole touching
    its exterior) cut there into minimal rings; the others as they are."""
    key = points[:, 0] * m + points[:, 1]
    at_pinch = np.flatnonzero(pinch)
    pair = ring[at_pinch] * (m * m) + key[at_pinch]
    _, counts = np.unique(pair, return_counts=True)
    if not np.any(counts > 1):
        return points, ring, ring_leaf
    bounds = np.searchsorted(ring, np.arange(ring.max() + 2))
    pieces, leaves = [], []
    for r in range(len(bounds) - 1):  # rings are few; those to cut fewer still
        todo = [points[bounds[r]:bounds[r + 1]]]
        while todo:
            loop = todo.pop()
            k = loop[:, 0] * m + loop[:, 1]
            _, first, seen = np.unique(k, return_index=True, return_counts=True)
            if not np.any(seen > 1):
                pieces.append(loop)
                leaves.append(ring_leaf[r])
                continue
            i = int(first[np.argmax(seen > 1)])
            j = i + 1 + int(np.flatnonzero(k[i + 1:] == k[i])[0])
            todo += [loop[i:j], np.concatenate([loop[j:], loop[:i]])]
    ring_out = np.repeat(np.arange(len(pieces)), [len(p) for p in pieces])
    return np.concatenate(pieces), ring_out, np.array(leaves, np.int64)
