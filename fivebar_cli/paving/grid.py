"""The geometry shared by a paving and all its trees: root box, maximum depth, periodic axes."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

MAX_INDEX_BITS = 52  # dim * depth: Morton indices stay exact in float64 and int64


@dataclass(frozen=True)
class Grid:
    """The geometry shared by a paving and all its trees: root box, maximum depth, periodic axes."""

    root: tuple[tuple[float, float], ...]
    depth: int
    periodic: tuple[bool, ...]

    def __post_init__(self) -> None:
        if len(self.periodic) != len(self.root):
            raise ValueError("periodic needs one flag per axis")
        if self.depth < 0 or self.dim * self.depth > MAX_INDEX_BITS:
            raise ValueError(f"depth {self.depth} out of range 0..{MAX_INDEX_BITS // self.dim}")
        for lo, hi in self.root:
            if not (np.isfinite(lo) and np.isfinite(hi) and lo < hi):
                raise ValueError(f"bad root interval [{lo}, {hi}]")

    @property
    def dim(self) -> int:
        return len(self.root)

    @property
    def lo(self) -> np.ndarray:
        return np.array([r[0] for r in self.root])

    @property
    def size(self) -> np.ndarray:
        return np.array([r[1] - r[0] for r in self.root])

    def with_depth(self, depth: int) -> "Grid":
        return Grid(self.root, depth, self.periodic)

    def cell_volume(self, level) -> np.ndarray:
        """Area (volume) of a cell at `level` (array-friendly, exact for dyadic levels)."""
        return float(np.prod(self.size)) * np.ldexp(1.0, -self.dim * np.asarray(level, dtype=np.int64))

    def boxes(self, level: int, coords: np.ndarray, pad: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
        """Bounds (lo, hi), shape (m, dim), of the cells `coords` at `level`, widened by `pad`."""
        return boxes_of(self.axis_ends(level, coords, pad))

    def axis_ends(self, level: int, coords: np.ndarray, pad: float = 0.0) -> tuple["AxisEnds", ...]:
        """The bounds of the cells `coords` at `level`, widened by `pad`, per axis (`AxisEnds`):
        tables over the span of the cells' coordinates along the axis, when it is no longer than
        twice their number (the cells a paving tests at one level lie along curves: about one
        distinct coordinate in six), else one entry per cell."""
        width = np.ldexp(self.size, -level)
        root = self.lo
        ends = []
        for k in range(self.dim):
            c = coords[:, k]
            first = int(c.min()) if len(c) else 0
            span = int(c.max()) - first + 1 if len(c) else 0
            cells, index = (np.arange(first, first + span, dtype=np.int64), c - first) if span <= 2 * len(c) else (c, None)
            ends.append(AxisEnds(root[k] + cells * width[k] - pad, root[k] + (cells + 1) * width[k] + pad, index))
        return tuple(ends)

    def cells_of_points(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Depth-D cell coordinates of points and a mask of the points inside the root box.

        Periodic axes are wrapped into the root first. Axis by axis, in place in one array of
        contiguous columns (the coordinates come in it)."""
        points = np.atleast_2d(np.asarray(points, dtype=float))
        lo, size = self.lo, self.size
        rel = np.empty(points.shape, order="F")
        inside = np.ones(len(points), bool)
        below = np.empty(len(points), bool)
        for axis, wrap in enumerate(self.periodic):
            r = rel[:, axis]
            np.subtract(points[:, axis], lo[axis], out=r)
            r /= size[axis]
            if wrap:
                _unit_mod(r, out=r)
            inside &= np.greater_equal(r, 0, out=below)
            inside &= np.less_equal(r, 1, out=below)
        if not inside.all():
            rel[~inside] = 0
        n = 1 << self.depth
        rel *= n
        np.floor(rel, out=rel)
        np.clip(rel, 0, n - 1, out=rel)
        return rel.astype(np.int64), inside


def _unit_mod(x: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
    """np.mod(x, 1.0), the same floats (numpy's float remainder is fmod, plus the divisor where
    fmod is negative) at a fifth of its cost; `out`: an array to write into (x itself may be)."""
    out = np.fmod(x, 1.0, out=out)
    np.add(out, 1.0, out=out, where=out < 0)
    return out


@dataclass(frozen=True)
class AxisEnds:
    """The bounds of boxes along one axis as tables and an index: box i spans
    [low[index[i]], high[index[i]]] (`index` None: one entry per box). The boxes of one level
    share their ends, so a value of an axis's interval alone (a cosine, the range of a sinusoid)
    is computed once per entry and gathered (`per_box`), at a fraction of the cost."""

    low: np.ndarray
    high: np.ndarray
    index: np.ndarray | None = None

    @classmethod
    def of_boxes(cls, lo: np.ndarray, hi: np.ndarray) -> tuple["AxisEnds", ...]:
        """The ends of boxes (lo, hi), shape (m, dim), one entry per box."""
        return tuple(cls(lo[:, k], hi[:, k]) for k in range(lo.shape[1]))

    @property
    def shared(self) -> bool:
        """Whether the boxes share entries (a table shorter than the boxes): what depends on this
        axis alone then costs less computed once per entry and gathered (`per_box`)."""
        return self.index is not None and len(self.low) < len(self.index)

    def rows(self, rows: np.ndarray) -> "AxisEnds":
        """The ends of the boxes `rows` (indices) only: the same tables, the rows of the index
        (or of the per-box ends)."""
        if self.index is None:
            return AxisEnds(self.low[rows], self.high[rows])
        return AxisEnds(self.low, self.high, self.index[rows])

    def per_box(self, table):
        """A table's values (an array over the entries, or tuples of them) for each box."""
        if self.index is None:
            return table
        if isinstance(table, tuple):
            return tuple(self.per_box(t) for t in table)
        return np.take(table, self.index, axis=0)  # (table[self.index], faster)


def boxes_of(ends: tuple[AxisEnds, ...]) -> tuple[np.ndarray, np.ndarray]:
    """Bounds (lo, hi), shape (m, dim), of the boxes whose ends per axis are `ends`."""
    return (np.column_stack([e.per_box(e.low) for e in ends]), np.column_stack([e.per_box(e.high) for e in ends]))
