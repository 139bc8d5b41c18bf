"""Array helpers the hot paths share: distinct values, pairs and ranks by a sort or a table.

`unique`: the sorted distinct values of an array by one sort. numpy 2.3+ answers a plain
`np.unique(a)` with a hash table and then sorts it: on this machine 15-20x slower than a sort for
int64 arrays of 10^5 and more (4 M values: 4.3 s against 0.25 s), the same values.
"""

from __future__ import annotations

import numpy as np


def unique(a: np.ndarray) -> np.ndarray:
    """np.unique(a) for a 1-D array (the sorted distinct values), by a sort."""
    s = np.sort(np.ravel(a), kind="stable")  # radix or run-merging sort: the input is often sorted runs
    if s.size < 2:
        return s
    keep = np.empty(s.size, bool)
    keep[0] = True
    np.not_equal(s[1:], s[:-1], out=keep[1:])
    return s[keep]


def index_type(n: int):
    """int32 for indices below n when they fit (half the memory, and the memory traffic, of
    int64), else int64."""
    return np.int32 if n < np.iinfo(np.int32).max else np.int64


def label_type(n: int):
    """The smallest signed integer type that holds the labels 0 .. n - 1 and -1: per-cell labels of
    a few components (outer components, anchors) in a byte or two, not four or eight."""
    for t in (np.int8, np.int16, np.int32):
        if n <= np.iinfo(t).max:
            return t
    return np.int64


def rows_equal(a: np.ndarray, row: np.ndarray) -> np.ndarray:
    """np.all(a == row, axis=1) for a 2-D array of a few columns, column by column (numpy's
    reduction along a short last axis is about 20x slower than these comparisons)."""
    out = np.ones(len(a), bool)
    for c in range(a.shape[1]):
        out &= a[:, c] == row[c]
    return out


def dense_rank(values: np.ndarray) -> np.ndarray:
    """np.unique(values, return_inverse=True)[1] for non-negative integers (labels): each value's
    rank among the distinct values, by a table as long as the largest value, without a sort."""
    if not len(values):
        return np.zeros(0, np.int64)
    present = np.zeros(int(values.max()) + 1, bool)
    present[values] = True
    return (np.cumsum(present) - 1)[values]


def unique_pairs(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """np.unique(np.column_stack([a, b]), axis=0) for non-negative integers: the distinct pairs in
    lexicographic order, (n, 2), as keys of one sort."""
    if not len(a):
        return np.zeros((0, 2), np.int64)
    n = np.int64(b.max()) + 1
    keys = unique(a.astype(np.int64) * n + b)
    return np.column_stack([keys // n, keys % n])
