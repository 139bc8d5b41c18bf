"""Is one sheet of a kind's configurations free of singularities over its space of poses? A
certified yes or no, for any kind with a `PoseAspectModel` (the 3-RPR over its orientation range;
a 3-RRR in one working mode).

Breadth-first over the space of poses, level by level up to a maximum depth, every box is decided
as soon as possible, from the model's validity test in the sheet (`valid_test`: with a 3-RRR's
limits and obstacles, those of its working mode) and the class it certifies on the box in the
sheet (`classes_of_boxes`):

- **free**: no pose of the box is valid, or one class (one sign of det J, of det A) is certified on it;
- **singular**: every pose of the box is valid and two of its corners or its centre are certified
  in different classes; the sign that tells the classes apart is continuous on the valid poses and
  the box convex, so the segment between the two holds a valid singular pose, found by bisection
  until the class is no longer certified (the model's `singularity` at rounding level);
- **open** otherwise: split into its 2^dim children.

The answer: singularity-free when no box is left open (exit 0), singular as soon as one singular
box is found (exit 1, with the pose), undecided when boxes are still open at the maximum depth
(exit 3, with their volume).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fivebar_cli.analyses.pose_aspects import pose_model
from fivebar_cli.errors import param
from fivebar_cli.mechanisms.base import Mechanism
from fivebar_cli.paving.engine import CHUNK, box_pad, children

FREE, SINGULAR, UNDECIDED = "certified singularity-free", "singular pose found", "undecided"
EXIT = {FREE: 0, SINGULAR: 1, UNDECIDED: 3}
MAX_BOXES = 1 << 23  # boxes of one level: beyond, the open set is a surface, not a few curves (stop: undecided)


@dataclass(frozen=True)
class SingularPose:
    """A valid pose (the space's coordinates) where the model's singularity value is at rounding
    level, with its joints (in the sheet's class) and that value (det J, det A)."""

    pose: tuple[float, ...]
    joints: tuple[float, ...]
    value: float

    def value_text(self, name: str) -> str:
        """`det J = 0 to rounding (-1.1e-15)`: what is claimed is that the value's sign cannot be
        certified here; its computed digits are rounding noise, which differs between machines'
        math libraries (so they are shown, but never as the claim)."""
        return f"{name} = 0 to rounding ({self.value:.2g})"


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
    pose: SingularPose | None = None
    note: str = ""

    @property
    def exit_code(self) -> int:
        return EXIT[self.status]

    @property
    def evaluations(self) -> int:
        return int(sum(self.per_level))

    def headline(self) -> str:
        """'free (depth 6 of 14, 1234 boxes tested)': the verdict line of every `verify`."""
        return f"{self.status} (depth {self.depth} of {self.max_depth}, {self.evaluations} boxes tested)"

    def undecided_line(self) -> str:
        """What an undecided verdict left open and what to try (the parameter as data: `param`)."""
        return (f"undecided volume {self.undecided_volume:.6g} of {self.root_volume:.6g} at depth {self.depth}: "
                + (self.note or "raise " + param("depth")))


def verify(m: Mechanism, max_depth: int, sheet: int = 0, on_level=None) -> VerifyResult:
    """Prove that every valid pose of `m` has a certified class in `sheet` (no singularity), or
    find a valid singular pose."""
    model = pose_model(m)
    grid = m.spaces()[model.space].grid(max_depth)
    valid_test = model.valid_test(sheet)
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
            valid = valid_test(lo, hi)
            cls = np.full(len(lo), -1, np.int64)
            some = np.flatnonzero(valid != -1)
            if len(some):
                cls[some] = model.classes_of_boxes(lo[some], hi[some], sheet)
            undecided = (valid != -1) & (cls < 0)
            full = np.flatnonzero(undecided & (valid == 1))
            if len(full):
                pose = _singular_pose(model, sheet, lo[full], hi[full])
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


def _point_classes(model, sheet: int, points: np.ndarray) -> np.ndarray:
    return model.classes_of_boxes(points, points, sheet)


def _singular_pose(model, sheet: int, lo: np.ndarray, hi: np.ndarray) -> SingularPose | None:
    """In the first of these wholly valid boxes where two sample points are certified in different
    classes, the pose where bisection between them ends (the first point of the box's lowest class
    present, and the first point of another class)."""
    pts = _sample_points(lo, hi)
    n, k, dim = pts.shape
    cls = _point_classes(model, sheet, pts.reshape(-1, dim)).reshape(n, k)
    low = np.where(cls >= 0, cls, np.iinfo(np.int64).max).min(axis=1)
    both = np.flatnonzero((cls >= 0).any(1) & ((cls >= 0) & (cls != low[:, None])).any(1))
    if len(both) == 0:
        return None
    b = both[0]
    first = pts[b, np.argmax(cls[b] == low[b])]
    other = pts[b, np.argmax((cls[b] >= 0) & (cls[b] != low[b]))]
    pose = bisect(model, sheet, int(low[b]), first, other)
    if not model.valid(pose[None], sheet)[0]:  # the box is certified valid
        raise ArithmeticError(f"the singular pose {pose} found in a valid box is not valid")
    joints, _ = model.ikp(pose[None], int(low[b]))
    return SingularPose(tuple(float(v) for v in pose), tuple(float(v) for v in joints[0]),
                        float(model.singularity(pose[None], int(low[b]))[0]))


def bisect(model, sheet: int, k: int, inside: np.ndarray, outside: np.ndarray, steps: int = 200) -> np.ndarray:
    """A pose on the segment [inside, outside] (class k at `inside`, another at `outside`) where the
    class is no longer certified, or where the segment cannot be halved further in floating point:
    then whichever end has the smaller |singularity value|."""
    for _ in range(steps):
        mid = 0.5 * (inside + outside)
        if np.array_equal(mid, inside) or np.array_equal(mid, outside):
            break
        c = _point_classes(model, sheet, mid[None])[0]
        if c < 0:
            return mid
        if c == k:
            inside = mid
        else:
            outside = mid
    a, b = (abs(float(model.singularity(p[None], k)[0])) for p in (inside, outside))
    return inside if a <= b else outside
