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
        width = np.ldexp(self.size, -level)
        lo = self.lo + coords * width
        hi = self.lo + (coords + 1) * width
        return lo - pad, hi + pad

    def cells_of_points(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Depth-D cell coordinates of points and a mask of the points inside the root box.

        Periodic axes are wrapped into the root first.
        """
        points = np.atleast_2d(np.asarray(points, dtype=float))
        rel = (points - self.lo) / self.size
        for axis, wrap in enumerate(self.periodic):
            if wrap:
                rel[:, axis] = np.mod(rel[:, axis], 1.0)
        inside = np.all((rel >= 0) & (rel <= 1), axis=1)
        n = 1 << self.depth
        coords = np.clip(np.floor(np.where(inside[:, None], rel, 0) * n), 0, n - 1).astype(np.int64)
        return coords, inside
