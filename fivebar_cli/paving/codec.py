"""The B/W/G preorder body of a tree, both ways, vectorised (no Python recursion per node).

G: grey (2^dim children follow), B: black (the cell belongs to the set), W: white (it does not).
"""

from __future__ import annotations

import numpy as np

from fivebar_cli.paving.morton import finest_key


class BodyError(ValueError):
    """A malformed B/W/G body; `position` is the 0-based index of the offending letter."""

    def __init__(self, position: int, message: str):
        self.position = position
        super().__init__(message)


def encode(tree) -> str:
    grid = tree.grid
    dim, depth, k = grid.dim, grid.depth, 1 << grid.dim
    if len(tree) == 0:
        return "W"
    if tree.level[0] == 0:
        return "B"
    grey_level, grey_code = [], []
    start = tree.start
    for lev in range(depth):  # grey nodes: the proper ancestors of black leaves
        # leaves are in Morton order, so their ancestors at one level are sorted: dropping repeats
        # of the previous value is np.unique without its sort
        anc = start[tree.level > lev] >> (dim * (depth - lev))
        anc = anc[np.concatenate([[True], anc[1:] != anc[:-1]])] if anc.size else anc
        grey_level.append(np.full(anc.size, lev, dtype=np.int64))
        grey_code.append(anc)
    g_level, g_code = np.concatenate(grey_level), np.concatenate(grey_code)
    child_level = np.repeat(g_level + 1, k)
    child_code = (np.repeat(g_code, k) << dim) | np.tile(np.arange(k, dtype=np.int64), g_code.size)
    key_grey = finest_key(g_code, g_level, dim, depth)
    key_child = finest_key(child_code, child_level, dim, depth)
    # children that are neither grey nor black are white
    is_grey = _member(child_level, child_code, g_level, g_code, depth, dim)
    is_black = _member(child_level, child_code, tree.level, tree.code, depth, dim)
    white = ~is_grey & ~is_black
    levels = np.concatenate([g_level, tree.level, child_level[white]])
    keys = np.concatenate([key_grey, tree.start, key_child[white]])
    letters = np.concatenate(
        [np.full(g_level.size, ord("G")), np.full(len(tree), ord("B")), np.full(int(white.sum()), ord("W"))]
    ).astype(np.uint8)
    # preorder: by first finest-level index, then level (a parent before its first child); one
    # key (distinct per node) and a sort that merges the sorted runs of grey, black, white nodes
    order = np.argsort(keys * (depth + 1) + levels, kind="stable")
    return letters[order].tobytes().decode("ascii")


def _member(level, code, set_level, set_code, depth, dim) -> np.ndarray:
    """Whether each (level, code) node belongs to the node set (set_level, set_code)."""
    if set_code.size == 0:
        return np.zeros(level.size, dtype=bool)
    key = finest_key(code, level, dim, depth) * (depth + 1) + level
    set_key = np.sort(finest_key(set_code, set_level, dim, depth) * (depth + 1) + set_level, kind="stable")
    pos = np.minimum(np.searchsorted(set_key, key), set_key.size - 1)
    return set_key[pos] == key


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
