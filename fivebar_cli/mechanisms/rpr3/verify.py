"""Is a 3-RPR singularity-free over its orientation range and leg ranges? A certified yes or no.

Breadth-first over the workspace space (x, y, phi), level by level up to a maximum depth, every
box is decided as soon as possible:

- **free**: no pose of the box is reachable, or det J has one certified non-zero sign on it;
- **singular**: every pose of the box is reachable and det J takes both certified signs at two
  of its corners or its centre; det J is continuous and the box convex, so the segment between a
  positive and a negative pose holds a reachable singular pose, found by bisection until the
  sign of det J is no longer certified (|det J| at rounding level);
- **open** otherwise: split into its 2^dim children.

The answer: singularity-free when no box is left open (exit 0), singular as soon as one singular
box is found (exit 1, with the pose), undecided when boxes are still open at the maximum depth
(exit 3, with their volume).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fivebar_cli.mechanisms.rpr3 import boxtests
from fivebar_cli.paving.engine import CHUNK, box_pad, children

FREE, SINGULAR, UNDECIDED = "certified singularity-free", "singular pose found", "undecided"
EXIT = {FREE: 0, SINGULAR: 1, UNDECIDED: 3}
MAX_BOXES = 1 << 23  # boxes of one level: beyond, the open set is a surface, not a few curves (stop: undecided)


@dataclass(frozen=True)
class Pose:
    """A reachable pose with its leg lengths and det J (a singular pose: |det J| at rounding level)."""

    x: float
    y: float
    phi: float  # degrees
    legs: tuple[float, float, float]
    det_j: float


@dataclass(frozen=True)
class VerifyResult:
    """What `verify` found: the verdict, the depth it took, the boxes tested (per level), the
    volume still open (undecided verdict), the root volume and, when singular, the pose."""

    status: str
    depth: int
    max_depth: int
    per_level: tuple[int, ...]
    undecided_volume: float
    root_volume: float
    pose: Pose | None = None
    note: str = ""

    @property
    def exit_code(self) -> int:
        return EXIT[self.status]

    @property
    def evaluations(self) -> int:
        return int(sum(self.per_level))


def verify(m, max_depth: int, on_level=None) -> VerifyResult:
    """Prove that every reachable pose of `m` has det J != 0, or find a reachable singular pose."""
    space = m.spaces()["workspace"]
    grid = space.grid(max_depth)
    g = boxtests.Geometry.of(m)
    pad = box_pad(grid)
    coords = np.zeros((1, grid.dim), dtype=np.int64)
    per_level = []
    for level in range(max_depth + 1):
        if on_level is not None:
            on_level(level, len(coords))
        per_level.append(len(coords))
        open_ = np.zeros(len(coords), dtype=bool)
        for s in range(0, len(coords), CHUNK):
            lo, hi = grid.boxes(level, coords[s:s + CHUNK], pad)
            reach = boxtests.reach_status(g, lo, hi)
            sign = np.zeros(len(lo), dtype=np.int8)
            some = np.flatnonzero(reach != -1)
            if len(some):
                sign[some] = boxtests.det_sign(g, lo[some], hi[some])
            undecided = (reach != -1) & (sign == 0)
            full = np.flatnonzero(undecided & (reach == 1))
            if len(full):
                pose = _singular_pose(m, g, lo[full], hi[full])
                if pose is not None:
                    return VerifyResult(SINGULAR, level, max_depth, tuple(per_level), 0.0, _volume(grid, 0), pose)
            open_[s:s + CHUNK] = undecided
        left = coords[open_]
        if len(left) == 0:
            return VerifyResult(FREE, level, max_depth, tuple(per_level), 0.0, _volume(grid, 0))
        if level == max_depth or len(left) << grid.dim > MAX_BOXES:
            note = "" if level == max_depth else f"stopped: {len(left) << grid.dim} boxes at the next depth"
            return VerifyResult(UNDECIDED, level, max_depth, tuple(per_level),
                                len(left) * _volume(grid, level), _volume(grid, 0), note=note)
        coords = children(left)
    raise AssertionError("unreachable")


def _volume(grid, level: int) -> float:
    return float(grid.cell_volume(level))


def _sample_points(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """The corners and the centre of each box: (m, 2^dim + 1, dim)."""
    dim = lo.shape[1]
    k = np.arange(1 << dim)
    bits = ((k[:, None] >> np.arange(dim)[None, :]) & 1).astype(bool)
    corners = np.where(bits[None], hi[:, None, :], lo[:, None, :])
    return np.concatenate([corners, 0.5 * (lo + hi)[:, None, :]], axis=1)


def _singular_pose(m, g, lo: np.ndarray, hi: np.ndarray) -> Pose | None:
    """In the first of these fully reachable boxes where det J takes both certified signs at its
    sample points, the pose where bisection between a positive and a negative one ends."""
    pts = _sample_points(lo, hi)
    n, k, dim = pts.shape
    signs = boxtests.det_point_sign(g, pts.reshape(-1, dim)).reshape(n, k)
    both = np.flatnonzero((signs > 0).any(1) & (signs < 0).any(1))
    if len(both) == 0:
        return None
    b = both[0]
    plus, minus = pts[b, np.argmax(signs[b] > 0)], pts[b, np.argmax(signs[b] < 0)]
    pose = bisect(g, plus, minus)
    legs = boxtests.leg_lengths(g, pose[None])[0]
    if not np.all((legs >= g.rho_min) & (legs <= g.rho_max)):  # the box is certified reachable
        raise ArithmeticError(f"the singular pose {pose} found in a reachable box has a leg out of range")
    return Pose(*(float(v) for v in g.poses(pose[None])[0]), tuple(float(v) for v in legs),
                float(boxtests.det_j(g, pose[None])[0]))


def bisect(g, plus: np.ndarray, minus: np.ndarray, steps: int = 200) -> np.ndarray:
    """A pose on the segment [plus, minus] (det J > 0 at plus, < 0 at minus) where the sign of
    det J is no longer certified, or where the segment cannot be halved further in floating point."""
    for _ in range(steps):
        mid = 0.5 * (plus + minus)
        if np.array_equal(mid, plus) or np.array_equal(mid, minus):
            break
        s = boxtests.det_point_sign(g, mid[None])[0]
        if s == 0:
            return mid
        if s > 0:
            plus = mid
        else:
            minus = mid
    dp, dm = (abs(float(boxtests.det_j(g, p[None])[0])) for p in (plus, minus))
    return plus if dp <= dm else minus
