"""Shared fixtures and independent reference implementations for the issue-2 test suite.

Everything here is written from the paper and docs/formats.md, not from the code under test:
a recursive B/W/G encoder/decoder over boolean grids, Morton decoding, flood fill, the lens
area, the joint-space area by a closed-form sinusoid integrated numerically, and the five-bar
point geometry.
"""

from __future__ import annotations

import math
import os
import sys
from collections import deque
from pathlib import Path

import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[1]
CONFIGS = REPO / "configs"
M1_YAML = CONFIGS / "m1.yaml"
M2_YAML = CONFIGS / "m2.yaml"

# the suite already runs one test per core (xdist): commands run their pavings in process unless a
# test asks for workers (--jobs N)
os.environ["FIVEBAR_JOBS"] = "1"
# the suite's outputs are scratch files: written atomically as always, but not flushed to the disk
os.environ["FIVEBAR_FSYNC"] = "0"

if str(REPO) not in sys.path:  # the package is installed editable; this only helps a bare checkout
    sys.path.insert(0, str(REPO))

from fivebar_cli.mechanisms.fivebar.model import FiveBar  # noqa: E402
from fivebar_cli.mechanisms.registry import load_config  # noqa: E402


def unchecked_fivebar(name: str, *lengths: float, bounds=None) -> FiveBar:
    """A five-bar built without the model's validation (Mechanism.check_model), for the tests that
    need designs a file would refuse on purpose (a loop that never closes, or closes only flat);
    with `bounds` ((lo, hi) per length) the lengths are their midpoints, as FiveBar.with_bounds."""
    if bounds is not None:
        lengths = tuple(lo if lo == hi else 0.5 * (lo + hi) for lo, hi in bounds)
    m = object.__new__(FiveBar)
    for key, value in zip(("name", "L0", "L1", "L2", "L3", "L4"), (name, *lengths)):
        object.__setattr__(m, key, value)
    object.__setattr__(m, "bounds", tuple(bounds) if bounds is not None else tuple((v, v) for v in lengths))
    return m


def box_samples(lo: np.ndarray, hi: np.ndarray, rng, grid: int, extra: int) -> np.ndarray:
    """(boxes, grid^2 + extra, 2): a grid x grid lattice over each 2-D box, its corners and edges
    included, and `extra` random points, kept in the box: lo + 1 * (hi - lo) can round an ulp
    beyond hi, outside the box and past a joint limit the box ends at (a sample there would blame
    the box test for a point it never held)."""
    t = np.linspace(0.0, 1.0, grid)
    fx, fy = np.meshgrid(t, t, indexing="ij")
    frac = np.concatenate([np.stack([fx.ravel(), fy.ravel()], axis=1), rng.random((extra, 2))])
    return np.clip(lo[:, None, :] + frac[None] * (hi - lo)[:, None, :], lo[:, None, :], hi[:, None, :])


def load_fivebar(path) -> FiveBar:
    return load_config(path, kind="fivebar")


# ---------------------------------------------------------------- mechanisms


def mechanism(name: str) -> FiveBar:
    return load_fivebar({"M1": M1_YAML, "M2": M2_YAML}[name])


M1 = FiveBar("M1", 9.0, 8.0, 5.0, 5.0, 8.0)  # the paper's numbers (section 3)
M2 = FiveBar("M2", 2.55, 2.3, 2.3, 2.3, 2.3)
MECHS = {"M1": M1, "M2": M2}


@pytest.fixture(scope="session")
def m1() -> FiveBar:
    return M1


@pytest.fixture(scope="session")
def m2() -> FiveBar:
    return M2


# ---------------------------------------------------------------- five-bar geometry (independent)


def crank_points(m: FiveBar, th1, th2):
    th1, th2 = np.asarray(th1, float), np.asarray(th2, float)
    b1 = np.stack([m.L1 * np.cos(th1), m.L1 * np.sin(th1)], axis=-1)
    b2 = np.stack([m.L0 + m.L2 * np.cos(th2), m.L2 * np.sin(th2)], axis=-1)
    return b1, b2


def valid_joint(m: FiveBar, th1, th2) -> np.ndarray:
    """Joint-space membership computed here: |L3-L4| <= |B1B2| <= L3+L4 and B1 != B2."""
    b1, b2 = crank_points(m, th1, th2)
    diff = b2 - b1
    d = np.hypot(diff[..., 0], diff[..., 1])  # hypot: no underflow of tiny distances
    return (d > 0) & (d >= abs(m.L3 - m.L4)) & (d <= m.L3 + m.L4)


def valid_work(m: FiveBar, x, y) -> np.ndarray:
    """Workspace membership computed here: P in both annuli, P != A1, A2."""
    x, y = np.asarray(x, float), np.asarray(y, float)
    r1 = np.hypot(x, y)  # hypot: no underflow of tiny distances
    r2 = np.hypot(x - m.L0, y)
    return ((r1 > 0) & (r1 >= abs(m.L1 - m.L3)) & (r1 <= m.L1 + m.L3)
            & (r2 > 0) & (r2 >= abs(m.L2 - m.L4)) & (r2 <= m.L2 + m.L4))


def singular_b1_eq_b2(m: FiveBar) -> list[tuple[float, float]]:
    """(th1, th2) with L1 e^{i th1} = (L0, 0) + L2 e^{i th2}: the crank circles' intersections."""
    a = (m.L0**2 + m.L1**2 - m.L2**2) / (2 * m.L0)  # x of the intersection points
    h = math.sqrt(m.L1**2 - a * a)
    return [(math.atan2(s * h, a), math.atan2(s * h, a - m.L0)) for s in (1.0, -1.0)]


def lens_area(r1: float, r2: float, d: float) -> float:
    """Area of the intersection of two discs of radii r1, r2 whose centres are d apart."""
    if d >= r1 + r2:
        return 0.0
    if d <= abs(r1 - r2):
        return math.pi * min(r1, r2) ** 2
    a1 = r1 * r1 * math.acos((d * d + r1 * r1 - r2 * r2) / (2 * d * r1))
    a2 = r2 * r2 * math.acos((d * d + r2 * r2 - r1 * r1) / (2 * d * r2))
    k = math.sqrt((-d + r1 + r2) * (d + r1 - r2) * (d - r1 + r2) * (d + r1 + r2))
    return a1 + a2 - 0.5 * k


def workspace_area_closed_form(m: FiveBar) -> float:
    """Lens of the two outer discs minus the two holes (valid when each hole lies inside the other
    leg's outer disc and the holes are disjoint: checked here)."""
    R1, R2 = m.L1 + m.L3, m.L2 + m.L4
    r1, r2 = abs(m.L1 - m.L3), abs(m.L2 - m.L4)
    assert m.L0 + r1 <= R2 and m.L0 + r2 <= R1, "a hole sticks out of the other leg's disc"
    assert r1 + r2 < m.L0, "the holes overlap"
    return lens_area(R1, R2, m.L0) - math.pi * r1 * r1 - math.pi * r2 * r2


def jointspace_theta2_measure(m: FiveBar, th1: np.ndarray) -> np.ndarray:
    """For each th1, the measure of {th2 : |L3-L4| <= |B1B2| <= L3+L4}.

    B2 - B1 = w + L2 e^{i th2} with w = A2 - B1, so |B1B2|^2 = c + R cos(th2 - phi) with
    c = |w|^2 + L2^2, R = 2 L2 |w|; the measure of {s : a <= cos s <= b} is 2 acos(a) - 2 acos(b).
    """
    wx = m.L0 - m.L1 * np.cos(th1)
    wy = -m.L1 * np.sin(th1)
    w = np.hypot(wx, wy)
    c = w * w + m.L2**2
    R = 2 * m.L2 * w
    a = ((m.L3 - m.L4) ** 2 - c) / R
    b = ((m.L3 + m.L4) ** 2 - c) / R
    return 2 * np.arccos(np.clip(a, -1, 1)) - 2 * np.arccos(np.clip(b, -1, 1))


def jointspace_area_numeric(m: FiveBar, n: int = 400_000) -> float:
    """Joint-space area on the torus [-pi, pi]^2 (midpoint rule in th1, periodic integrand)."""
    th1 = (np.arange(n) + 0.5) / n * 2 * np.pi - np.pi
    return float(np.mean(jointspace_theta2_measure(m, th1)) * 2 * np.pi)


def jointspace_boundary_points(m: FiveBar, n: int) -> np.ndarray:
    """Points (th1, th2) on the boundary curves |B1B2| = L3+L4 and |B1B2| = |L3-L4| (closed form)."""
    th1 = np.linspace(-np.pi, np.pi, n, endpoint=False) + 0.1234567
    wx = m.L0 - m.L1 * np.cos(th1)
    wy = -m.L1 * np.sin(th1)
    w = np.hypot(wx, wy)
    c = w * w + m.L2**2
    R = 2 * m.L2 * w
    phi = np.arctan2(wy, wx)
    pts = []
    for target in ((m.L3 + m.L4) ** 2, (m.L3 - m.L4) ** 2):
        q = (target - c) / R
        ok = np.abs(q) <= 1
        for sgn in (1, -1):
            th2 = phi[ok] + sgn * np.arccos(q[ok])
            pts.append(np.stack([th1[ok], (th2 + np.pi) % (2 * np.pi) - np.pi], axis=1))
    return np.concatenate(pts)


def workspace_boundary_points(m: FiveBar, n: int) -> np.ndarray:
    """Points on the four workspace circles (centres A1, A2; radii L_i +- L_j)."""
    t = np.linspace(0, 2 * np.pi, n, endpoint=False) + 0.0123
    pts = []
    for cx, r in ((0.0, m.L1 + m.L3), (0.0, abs(m.L1 - m.L3)), (m.L0, m.L2 + m.L4), (m.L0, abs(m.L2 - m.L4))):
        pts.append(np.stack([cx + r * np.cos(t), r * np.sin(t)], axis=1))
    return np.concatenate(pts)


# ---------------------------------------------------------------- quadtree references


def ref_encode(cells: np.ndarray) -> str:
    """Preorder B/W/G body of a boolean grid of shape (2^D,)*dim, indexed [x, y, (z)].

    Child k is the high half along axis j when bit j of k is set (docs/formats.md order).
    """
    dim = cells.ndim
    out: list[str] = []

    def rec(block: np.ndarray) -> None:
        if block.all():
            out.append("B")
        elif not block.any():
            out.append("W")
        else:
            out.append("G")
            h = block.shape[0] // 2
            for k in range(1 << dim):
                idx = tuple(slice(h, None) if (k >> j) & 1 else slice(0, h) for j in range(dim))
                rec(block[idx])

    rec(cells)
    return "".join(out)


def ref_decode(body: str, depth: int, dim: int) -> np.ndarray:
    """Boolean grid of a well-formed preorder body (recursive, for reference)."""
    n = 1 << depth
    arr = np.zeros((n,) * dim, dtype=bool)
    pos = 0

    def rec(origin: tuple[int, ...], size: int) -> None:
        nonlocal pos
        c = body[pos]
        pos += 1
        if c == "B":
            arr[tuple(slice(o, o + size) for o in origin)] = True
        elif c == "G":
            assert size > 1
            h = size // 2
            for k in range(1 << dim):
                rec(tuple(o + h * ((k >> j) & 1) for j, o in enumerate(origin)), h)
        else:
            assert c == "W"

    rec((0,) * dim, n)
    assert pos == len(body)
    return arr


def morton_coords(code: int, level: int, dim: int) -> tuple[int, ...]:
    """Integer coordinates of the cell with Morton code `code` at `level`: bit b*dim + j of the code
    is bit b of the coordinate along axis j (the last child index is the lowest dim bits)."""
    c = [0] * dim
    for b in range(level):
        for j in range(dim):
            c[j] |= ((code >> (b * dim + j)) & 1) << b
    return tuple(c)


def leaf_coords(tree) -> np.ndarray:
    """Integer coordinates (m, dim) of every leaf at its own level: morton_coords, vectorised."""
    dim = tree.grid.dim
    level = np.asarray(tree.level, dtype=np.int64)
    code = np.asarray(tree.code, dtype=np.int64)
    coords = np.zeros((code.size, dim), dtype=np.int64)
    for b in range(int(level.max(initial=0))):
        for j in range(dim):
            coords[:, j] |= ((code >> (b * dim + j)) & 1) << b
    return coords


def leaf_index_grid(tree) -> np.ndarray:
    """Depth-D grid holding the index of the leaf covering each cell (-1: not in the tree), from the
    (level, code) leaves decoded here; no two leaves may overlap. Level by level: each level's
    leaves on a grid of that level, blown up to depth D."""
    dim, depth = tree.grid.dim, tree.grid.depth
    arr = np.full((1 << depth,) * dim, -1, dtype=np.int64)
    level, coords = np.asarray(tree.level, dtype=np.int64), leaf_coords(tree)
    for lev in np.unique(level).tolist():
        sel = np.flatnonzero(level == lev)
        small = np.full((1 << lev,) * dim, -1, dtype=np.int64)
        small[tuple(coords[sel].T)] = sel
        assert np.count_nonzero(small >= 0) == len(sel), "overlapping leaves"
        big = upsample(small, depth - lev)
        assert not np.any((big >= 0) & (arr >= 0)), "overlapping leaves"
        arr = np.where(big >= 0, big, arr)
    return arr


def tree_to_bool(tree) -> np.ndarray:
    """Boolean depth-D grid of a tree, from its (level, code) leaves decoded here."""
    return leaf_index_grid(tree) >= 0


def cells_of(arr: np.ndarray) -> np.ndarray:
    """Integer coordinates (m, dim) of the True cells of a boolean grid."""
    return np.argwhere(arr).astype(np.int64)


def upsample(arr: np.ndarray, k: int) -> np.ndarray:
    for axis in range(arr.ndim):
        arr = np.repeat(arr, 1 << k, axis=axis)
    return arr


def flood_fill(arr: np.ndarray, periodic: tuple[bool, ...]) -> tuple[np.ndarray, int]:
    """Face-connected (2*dim neighbours) components of a boolean grid, with wrap on periodic axes."""
    labels = np.full(arr.shape, -1, dtype=np.int64)
    n = arr.shape[0]
    count = 0
    for start in map(tuple, np.argwhere(arr)):
        if labels[start] >= 0:
            continue
        labels[start] = count
        queue = deque([start])
        while queue:
            cell = queue.popleft()
            for axis in range(arr.ndim):
                for step in (-1, 1):
                    nb = list(cell)
                    nb[axis] += step
                    if periodic[axis]:
                        nb[axis] %= n
                    elif not 0 <= nb[axis] < n:
                        continue
                    nb = tuple(nb)
                    if arr[nb] and labels[nb] < 0:
                        labels[nb] = count
                        queue.append(nb)
        count += 1
    return labels, count


def leaf_bounds(tree) -> tuple[np.ndarray, np.ndarray]:
    """(lo, hi) of every leaf, shape (m, dim), from the Morton codes decoded here (vectorised)."""
    level = np.asarray(tree.level, dtype=np.int64)
    coords = leaf_coords(tree)
    root = np.array(tree.grid.root, dtype=float)
    width = (root[:, 1] - root[:, 0])[None, :] / (2.0 ** level)[:, None]
    lo = root[:, 0] + coords * width
    return lo, lo + width


# 12 five-bars of `fivebar atlas` tests (test_atlas.py, test_atlas_dask.py): L0 in {0.5, 1.75, 3},
# L3 in {0.3, 0.6, 0.9, 1.2}; six cannot be assembled
ATLAS_SPEC = """name: t
type: fivebar-atlas
lengths: {L0: [0.5, 3.0, 3], L1: 0.4, L2: 0.4, L3: [0.3, 1.2, 4], L4: 0.3}
depth: 6
batch: 1
"""


@pytest.fixture(scope="module")
def spec_file(tmp_path_factory):
    """ATLAS_SPEC written to t.yaml."""
    path = tmp_path_factory.mktemp("spec") / "t.yaml"
    path.write_text(ATLAS_SPEC)
    return path
