"""The B/W/G preorder body of a tree, both ways, vectorised (no Python recursion per node).

G: grey (2^dim children follow), B: black (the cell belongs to the set), W: white (it does not).
"""

from __future__ import annotations

import numpy as np

from fivebar_cli.paving.morton import floor_log2, trailing_zeros


class BodyError(ValueError):
    """A malformed B/W/G body; `position` is the 0-based index of the offending letter."""

    def __init__(self, position: int, message: str):
        self.position = position
        super().__init__(message)


def encode(tree) -> str:
    """The preorder body of a tree. Its leaves are the black leaves and the white ones (the
    complement's canonical leaves: the maximal cells without black, whose parents hold black); in
    Morton order, each leaf follows a G for every grey ancestor that starts where it starts (the
    levels above it at which its first depth-D index is aligned, the root excepted when it is not
    0): no node is looked up, nothing sorted. The white leaves are the gaps between the black runs
    cut greedily into aligned blocks (`_white_leaves`), block i of gap g placed after the black
    leaves and white blocks before it."""
    grid = tree.grid
    dim, depth = grid.dim, grid.depth
    if len(tree) == 0:
        return "W"
    if tree.level[0] == 0:
        return "B"
    level = tree.level
    start = tree.start
    end = start + (np.int64(1) << (dim * (depth - level)))
    # the black runs (leaves touching end to start) and the gaps before each run and after the last
    first = np.ones(len(start), bool)
    first[1:] = start[1:] != end[:-1]
    run_first = np.flatnonzero(first)  # the first leaf of each run
    last = np.r_[run_first[1:] - 1, len(start) - 1]
    a = np.concatenate([[0], end[last]])  # gap g: [a, b), before run g (g = runs: after the last)
    b = np.concatenate([start[run_first], [np.int64(1) << (dim * depth)]])
    open_ = np.flatnonzero(a < b)
    white_gap, white_grey, nth = _white_leaves(open_, a[open_], b[open_], dim, depth)
    per_gap = np.bincount(white_gap, minlength=len(run_first) + 1)
    white_before = np.cumsum(per_gap) - per_gap  # white blocks in the gaps before gap g
    black_before = np.r_[run_first, len(start)]  # black leaves before gap g
    at_black = np.arange(len(start)) + np.cumsum(per_gap)[np.cumsum(first) - 1]
    at_white = black_before[white_gap] + white_before[white_gap] + nth
    # a G per grey ancestor starting where the leaf starts (down from the highest level at which
    # its start is aligned), then the leaf's letter
    runs = np.empty(len(start) + len(white_gap), np.int64)
    runs[at_black] = level - np.maximum(depth - trailing_zeros(start, dim * depth) // dim, 0)
    runs[at_white] = white_grey
    runs += 1
    leaf_at = np.cumsum(runs) - 1
    letters = np.full(int(leaf_at[-1]) + 1, ord("G"), np.uint8)
    letters[leaf_at[at_black]] = ord("B")
    letters[leaf_at[at_white]] = ord("W")
    return letters.tobytes().decode("ascii")


def _white_leaves(gap: np.ndarray, a: np.ndarray, b: np.ndarray, dim: int, depth: int):
    """The non-empty gaps [a, b) (numbered `gap`) cut greedily into aligned blocks, as
    `morton.aligned_blocks` cuts them (from the left, the largest block that starts there and
    fits), round after round: each block's gap, its grey count (the G's before it: the levels
    above it at which its start is aligned, from the alignment the cut reads anyway) and its rank
    in its gap (its round), in rounds. (np.compress: numpy's boolean indexing is slower.)"""
    gaps, greys, sizes = [gap[:0]], [gap[:0]], []
    while len(a):
        aligned = np.minimum(trailing_zeros(a, dim * depth) // dim, depth)  # the start's alignment
        span = np.minimum(aligned, floor_log2(b - a) // dim)  # the block: 2^(dim * span) indices
        gaps.append(gap)
        greys.append(aligned - span)
        sizes.append(len(a))
        a = a + (np.int64(1) << (dim * span))
        more = a < b
        a, b, gap = np.compress(more, a), np.compress(more, b), np.compress(more, gap)
    return np.concatenate(gaps), np.concatenate(greys), np.repeat(np.arange(len(sizes)), sizes)


def decode(grid, body: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Levels, codes and black mask of every node of a preorder body (vectorised).

    With e = k-1 for G and -1 for a leaf, the prefix sum S counts nodes still owed; a well-formed
    body has S >= 0 before its last letter and S = -1 at the end. The subtree of a grey node at i
    ends at the first t >= i with S[t] = S[i-1] - 1, which gives every node's depth; the nodes of a
    level, in body order, are the children of the grey nodes of the level above, k at a time.
    """
    dim, depth, k = grid.dim, grid.depth, 1 << grid.dim
    letters = np.frombuffer(body.encode("ascii", errors="replace"), dtype=np.uint8)
    n = letters.size
    if n == 0:
        raise BodyError(0, "empty tree body")
    bad = np.flatnonzero((letters != ord("G")) & (letters != ord("B")) & (letters != ord("W")))
    if bad.size:
        raise BodyError(int(bad[0]), f"unexpected character {body[bad[0]]!r} (expected B, W or G)")
    grey = letters == ord("G")
    s = np.cumsum(np.where(grey, k - 1, -1))
    done = np.flatnonzero(s < 0)
    if done.size == 0:
        raise BodyError(n, f"truncated tree body: {int(s[-1]) + 1} more node(s) expected")
    if done[0] != n - 1:
        raise BodyError(int(done[0]) + 1, "extra letters after the end of the tree")
    prev = np.concatenate([[0], s[:-1]])
    g = np.flatnonzero(grey)
    order = np.lexsort((np.arange(n), s))
    key_sorted = s[order] * (n + 1) + order
    pos = np.searchsorted(key_sorted, (prev[g] - 1) * (n + 1) + g)
    end = order[pos]
    delta = np.zeros(n + 1, dtype=np.int64)
    np.add.at(delta, g + 1, 1)
    np.add.at(delta, end + 1, -1)
    level = np.cumsum(delta)[:n]
    too_deep = np.flatnonzero(grey & (level >= depth))
    if too_deep.size:
        raise BodyError(int(too_deep[0]), f"grey node at level {int(level[too_deep[0]])}: the tree is deeper than its depth {depth}")
    code = np.zeros(n, dtype=np.int64)
    by_level = np.argsort(level, kind="stable")
    counts = np.bincount(level, minlength=1)
    bounds = np.concatenate([[0], np.cumsum(counts)])
    for lev in range(1, counts.size):
        nodes = by_level[bounds[lev]:bounds[lev + 1]]
        parents = by_level[bounds[lev - 1]:bounds[lev]]
        parents = parents[grey[parents]]
        rank = np.arange(nodes.size)
        code[nodes] = (code[parents[rank // k]] << dim) | (rank % k)
    return level, code, letters == ord("B")
