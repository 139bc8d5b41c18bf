"""Morton (Z-order) codes of integer cell coordinates, vectorised with lookup tables.

Bit j of a child index is the high half along axis j, so the Morton order of the cells of a level
is the preorder of the tree: (x low, y low), (x high, y low), (x low, y high), (x high, y high),
then phi low before phi high for octrees.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np


@lru_cache(maxsize=None)
def _spread_table(dim: int, bits: int) -> np.ndarray:
    """table[c] = the `bits` low bits of c spread to every dim-th bit position."""
    c = np.arange(1 << bits, dtype=np.int64)
    out = np.zeros_like(c)
    for b in range(bits):
        out |= ((c >> b) & 1) << (b * dim)
    return out


@lru_cache(maxsize=None)
def _compact_table(dim: int, bits: int) -> np.ndarray:
    """table[v, axis] = the bits of axis `axis` gathered from a (bits * dim)-bit Morton chunk v."""
    v = np.arange(1 << (bits * dim), dtype=np.int64)
    out = np.zeros((v.size, dim), dtype=np.int64)
    for b in range(bits):
        for axis in range(dim):
            out[:, axis] |= ((v >> (b * dim + axis)) & 1) << b
    return out


def _chunk(dim: int) -> int:
    return 16 // dim  # coordinate bits per table lookup (tables of 2^16 entries at most)


def interleave(coords: np.ndarray, level: int | np.ndarray) -> np.ndarray:
    """Morton codes of integer cell coordinates, shape (m, dim) -> (m,), bit j of a child index = axis j."""
    coords = np.asarray(coords, dtype=np.int64)
    m, dim = coords.shape
    bits = int(np.max(level)) if np.size(level) else 0
    step = _chunk(dim)
    table = _spread_table(dim, step)
    code = np.zeros(m, dtype=np.int64)
    for k in range(0, bits, step):
        for axis in range(dim):
            code |= table[(coords[:, axis] >> k) & ((1 << step) - 1)] << (k * dim + axis)
    return code


def deinterleave(code: np.ndarray, level: int | np.ndarray, dim: int) -> np.ndarray:
    """Inverse of `interleave`: Morton codes -> integer coordinates, shape (m, dim)."""
    code = np.asarray(code, dtype=np.int64)
    bits = int(np.max(level)) if np.size(level) else 0
    step = _chunk(dim)
    table = _compact_table(dim, step)
    coords = np.zeros((code.size, dim), dtype=np.int64)
    for k in range(0, bits, step):
        coords |= table[(code >> (k * dim)) & ((1 << (step * dim)) - 1)] << k
    return coords


def finest_key(code: np.ndarray, level: np.ndarray | int, dim: int, depth: int) -> np.ndarray:
    """The first finest-level (depth) Morton index of each cell: cells at mixed levels in Z-order."""
    return code << (dim * (depth - level))


def finest_order(code: np.ndarray, level: np.ndarray | int, dim: int, depth: int) -> np.ndarray:
    """The permutation that sorts cells at mixed levels by `finest_key` (stable: ties keep order)."""
    return np.argsort(finest_key(code, level, dim, depth), kind="stable")


def floor_log2(x: np.ndarray) -> np.ndarray:
    """floor(log2(x)) for positive integers below 2**53 (exact through frexp)."""
    return np.frexp(x.astype(np.float64))[1].astype(np.int64) - 1


def trailing_zeros(x: np.ndarray, cap: int) -> np.ndarray:
    """Number of trailing zero bits of non-negative int64 values (x == 0 gives `cap`)."""
    low = x & -x
    return np.where(x == 0, cap, floor_log2(np.where(x == 0, 1, low)))


def axis_mask(dim: int, axis: int) -> int:
    """The bits of a Morton code that belong to one axis (every dim-th bit from bit `axis`)."""
    return sum(1 << b for b in range(axis, 63, dim))


def step(code: np.ndarray, level: np.ndarray, dim: int, axis: int, delta: int) -> tuple[np.ndarray, np.ndarray]:
    """Morton codes of the cells one step (delta = +1 or -1) along `axis` from cells at `level`,
    by dilated-integer arithmetic (no decoding), and whether the step wrapped around the root."""
    mask = np.int64(axis_mask(dim, axis)) & ((np.int64(1) << (dim * level)) - 1)
    along = code & mask
    if delta > 0:
        moved = ((along | ~mask) + 1) & mask
        wrapped = along == mask
    else:
        moved = (along - 1) & mask
        wrapped = along == 0
    return (code & ~mask) | moved, wrapped
