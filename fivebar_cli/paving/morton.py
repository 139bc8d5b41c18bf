"""Morton (Z-order) codes of integer cell coordinates, vectorised with bit dilation (magic masks).

Bit j of a child index is the high half along axis j, so the Morton order of the cells of a level
is the preorder of the tree: (x low, y low), (x high, y low), (x low, y high), (x high, y high),
then phi low before phi high for octrees.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np


@lru_cache(maxsize=None)
def _dilation(dim: int, bits: int) -> tuple[tuple[int, int], ...]:
    """How the `bits` low bits of a coordinate sit in a Morton code, as the classic magic-mask bit
    dilation (for any dim): (shift, mask) per stage, from groups of one bit (every dim-th bit,
    shift 0) to groups of 2, 4, ... bits, each group of 2g bits made of two of g bits, the upper one
    shifted by g (dim - 1); the last stage holds the `bits` bits together."""
    stages, g = [(0, sum(1 << (i * dim) for i in range(bits)))], 1
    while g < bits:
        mask = sum(((1 << 2 * g) - 1) << (i * 2 * g * dim) for i in range(-(-bits // (2 * g))))
        stages.append((g * (dim - 1), mask & ((1 << (bits * dim)) - 1)))
        g *= 2
    return tuple(stages)


def _bits(level) -> int:
    return int(np.max(level)) if np.size(level) else 0


def interleave(coords: np.ndarray, level: int | np.ndarray) -> np.ndarray:
    """Morton codes of integer cell coordinates, shape (m, dim) -> (m,), bit j of a child index = axis j."""
    coords = np.asarray(coords, dtype=np.int64)
    m, dim = coords.shape
    stages = _dilation(dim, _bits(level))
    code = np.zeros(m, dtype=np.int64)
    for axis in range(dim):
        x = coords[:, axis] & stages[-1][1]
        for (shift, _), (_, mask) in zip(stages[:0:-1], stages[-2::-1]):  # groups halved, spread apart
            x |= x << shift
            x &= mask
        if axis:
            x <<= axis
        code |= x
    return code


def deinterleave(code: np.ndarray, level: int | np.ndarray, dim: int) -> np.ndarray:
    """Inverse of `interleave`: Morton codes -> integer coordinates, shape (m, dim)."""
    code = np.asarray(code, dtype=np.int64)
    stages = _dilation(dim, _bits(level))
    coords = np.empty((code.size, dim), dtype=np.int64)
    shifted = np.empty_like(code)
    for axis in range(dim):
        x = code >> axis if axis else code.copy()
        x &= stages[0][1]
        for shift, mask in stages[1:]:  # groups of one bit, two, four... gathered to the low end
            np.right_shift(x, shift, out=shifted)
            x |= shifted
            x &= mask
        coords[:, axis] = x
    return coords


def finest_key(code: np.ndarray, level: np.ndarray | int, dim: int, depth: int) -> np.ndarray:
    """The first finest-level (depth) Morton index of each cell: cells at mixed levels in Z-order."""
    return code << (dim * (depth - level))


def finest_order(code: np.ndarray, level: np.ndarray | int, dim: int, depth: int) -> np.ndarray:
    """The permutation that sorts cells at mixed levels by `finest_key` (stable: ties keep order)."""
    return np.argsort(finest_key(code, level, dim, depth), kind="stable")


def floor_log2(x: np.ndarray) -> np.ndarray:
    """floor(log2(x)) for positive integers below 2**53: the exponent bits of their (exact)
    float64 values."""
    out = np.asarray(x).astype(np.float64).view(np.int64)
    out >>= 52
    out -= 1023
    return out


def trailing_zeros(x: np.ndarray, cap: int) -> np.ndarray:
    """Number of trailing zero bits of int64 values in [0, 2**cap), cap <= 52 (x == 0 gives
    `cap`): the lowest set bit of x | 2**cap, by `floor_log2`."""
    low = x | (np.int64(1) << cap)
    low &= -low
    return floor_log2(low)


def aligned_blocks(a: np.ndarray, b: np.ndarray, dim: int, depth: int):
    """The greedy cut of non-empty intervals [a, b) of depth-D indices into aligned blocks (cells):
    from the left, the largest block that starts at the current position and fits. Round after
    round, yields (starts, spans, more): the next block of every interval not yet cut whole (its
    level is depth - span) and which of them have more blocks after it (a caller keeping values
    per interval filters them with `more`)."""
    while a.size:
        span = np.minimum(trailing_zeros(a, dim * depth) // dim, floor_log2(b - a) // dim)
        span = np.minimum(span, depth)
        after = a + (np.int64(1) << (dim * span))
        more = after < b
        yield a, span, more
        a, b = after[more], b[more]


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
