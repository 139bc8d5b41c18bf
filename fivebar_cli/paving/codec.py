"""The B/W/G preorder body of a tree, both ways, vectorised (no Python recursion per node).

G: grey (2^dim children follow), B: black (the cell belongs to the set), W: white (it does not).
"""

from __future__ import annotations

import numpy as np

from fivebar_cli.paving.morton import trailing_zeros


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
    0): no node is looked up, one merge of two sorted arrays."""
    grid = tree.grid
    dim, depth = grid.dim, grid.depth
    if len(tree) == 0:
        return "W"
    if tree.level[0] == 0:
        return "B"
    white = tree.complement()
    start = np.concatenate([tree.start, white.start])
    order = np.argsort(start, kind="stable")  # a merge of two sorted runs
    start = start[order]
    black = order < len(tree)  # which leaves, in Morton order, are black
    runs = np.concatenate([tree.level, white.level])[order]
    del order, white
    # a G per grey ancestor starting where the leaf starts (down from the highest level at which
    # its start is aligned), then the leaf's letter
    runs -= np.maximum(depth - trailing_zeros(start, dim * depth) // dim, 0)
    runs += 1
    leaf_at = np.cumsum(runs) - 1
    letters = np.full(int(leaf_at[-1]) + 1, ord("G"), np.uint8)
    letters[leaf_at] = np.where(black, ord("B"), ord("W"))
    return letters.tobytes().decode("ascii")


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
