"""Generalized aspects of the five-bar (Chablat 2010, sections 2.2, 3.3, 3.5, 3.6; issue 3).

What is checked, for M1 and M2:
- the paper's count: ten aspects, five per assembly mode, stable from depth 8 to 12;
- every sampled point of an aspect has the aspect's modes and is non-singular, and the IKP / DKP
  images of its points never land in another aspect of the same region (and, for a large majority,
  land in its own serial / parallel aspect);
- the assembly-mode regions of a working mode fill the workspace (closed-form lens area) as the
  depth grows;
- an independent labelling: a dense grid over the joint-space torus / the workspace, classified
  by point kinematics written here, labelled by a run-based union-find written here (4-connected,
  torus wrap in the joint space): five regions per assembly mode whose working modes, areas and
  adjacencies across one serial singularity agree with the aspects and crossings;
- the crossing graph of each assembly mode is K_{2,3} (the paper's statement in 3.6), each crossing
  changes exactly one sign, named after it;
- the symmetries of the geometry (mirror in the base line; leg swap for M2);
- deterministic, documented numbering; locate_configurations;
- Tree.components against the independent labelling on large rasters (plane and torus).
"""

from __future__ import annotations

import functools
import inspect
import math
from collections import Counter

import numpy as np
import pytest
from reference_kinematics import ref_dkp, ref_ikp

from conftest import M1, M2, MECHS, workspace_area_closed_form
from fivebar_cli.analyses import aspect_files, crossings, spaces
from fivebar_cli.analyses import aspects as asp
from fivebar_cli.analyses.locate import locate_configurations
from fivebar_cli.mechanisms.fivebar import modes
from fivebar_cli.paving.engine import pave
from fivebar_cli.paving.grid import Grid

NAMES = ["M1", "M2"]
DEPTH = 10
TWO_PI = 2 * math.pi
WM_ORDER = [(1, 1), (1, -1), (-1, 1), (-1, -1)]  # documented numbering order
GRID_N = 512  # pixels per axis of the independent grids
MIN_PIXELS = 64  # grid components below this (1/4096 of the root box) are discretisation noise


# ---------------------------------------------------------------- independent point kinematics


def sign_text(signs) -> str:
    return "".join("+" if s > 0 else "-" for s in signs)


# ---------------------------------------------------------------- independent labelling


def label_runs(cls: np.ndarray, wrap: bool) -> np.ndarray:
    """4-connected components of the pixels of equal non-zero class of `cls` (indexed [row, col]),
    wrapping both axes when `wrap`. Horizontal runs of one class are united with the runs of the
    same class that overlap them in the next row (a plain union-find over runs). Returns a label
    per pixel (-1 for class 0); labels are arbitrary integers."""
    ny, nx = cls.shape
    flat = cls.ravel()
    cuts = np.union1d(np.flatnonzero(flat[1:] != flat[:-1]) + 1, np.arange(0, ny * nx, nx))
    starts = cuts
    ends = np.append(cuts[1:], ny * nx)
    kind = flat[starts]
    keep = np.flatnonzero(kind != 0)
    s, e, k = starts[keep], ends[keep], kind[keep]
    row = s // nx
    parent = list(range(len(s)))

    def find(a):
        while parent[a] != a:
            parent[a] = parent[parent[a]]
            a = parent[a]
        return a

    def unite(i_arr, j_arr):
        for i, j in zip(i_arr.tolist(), j_arr.tolist()):
            ri, rj = find(i), find(j)
            if ri != rj:
                parent[max(ri, rj)] = min(ri, rj)

    def vertical(sel, prev_row):
        """Pairs (run j in `sel`, run q in row `prev_row`) overlapping in columns, same class."""
        js = sel
        base = prev_row * nx
        col_s, col_e = s[js] - row[js] * nx, e[js] - row[js] * nx
        q0 = np.searchsorted(e, base + col_s, side="right")
        q1 = np.searchsorted(s, base + col_e, side="left")
        cnt = np.maximum(q1 - q0, 0)
        jj = np.repeat(js, cnt)
        qq = np.repeat(q0, cnt) + (np.arange(cnt.sum()) - np.repeat(np.cumsum(cnt) - cnt, cnt))
        same = k[jj] == k[qq]
        return jj[same], qq[same]

    later = np.flatnonzero(row > 0)
    unite(*vertical(later, row[later] - 1))
    if wrap:
        first = np.flatnonzero(row == 0)
        unite(*vertical(first, np.full(len(first), ny - 1)))
        # a run ending at the last column continues into the run starting at column 0 of its row
        left = np.flatnonzero(s - row * nx == 0)
        right = np.flatnonzero(e - row * nx == nx)
        lr = {int(row[i]): i for i in left}
        pairs = [(lr[int(row[j])], j) for j in right if int(row[j]) in lr and k[lr[int(row[j])]] == k[j]]
        if pairs:
            unite(np.array([p[0] for p in pairs]), np.array([p[1] for p in pairs]))
    roots = np.array([find(i) for i in range(len(s))], dtype=np.int64)
    run_label = np.full(len(starts), -1, dtype=np.int64)
    run_label[keep] = roots
    return np.repeat(run_label, ends - starts).reshape(ny, nx)


def big_components(cls, labels, min_pixels=MIN_PIXELS):
    """{label: (class, pixels)} of the components with at least `min_pixels` pixels."""
    keys, first, counts = np.unique(labels.ravel(), return_index=True, return_counts=True)
    out = {}
    for key, f, c in zip(keys.tolist(), first.tolist(), counts.tolist()):
        if key >= 0 and c >= min_pixels:
            out[key] = (int(cls.ravel()[f]), c)
    return out


WM_OF_CODE = {1: (1, 1), 2: (1, -1), 3: (-1, 1), 4: (-1, -1)}
CODE_OF_WM = {v: k for k, v in WM_OF_CODE.items()}


def cached(f):
    """lru_cache keyed on the arguments with the defaults filled in: f(x) and f(x, default) are one
    entry, not two computations of the same grid or analysis."""
    signature, compute = inspect.signature(f), functools.lru_cache(maxsize=None)(f)

    @functools.wraps(f)
    def call(*args, **kwargs):
        bound = signature.bind(*args, **kwargs)
        bound.apply_defaults()
        return compute(*bound.args)
    return call


def _centres(n, lo, hi):
    return lo + (np.arange(n) + 0.5) * (hi - lo) / n


@cached
def joint_grid(name: str, am: int, tol: float = 1e-6):
    """Classes of the pixel centres of the joint-space torus in assembly mode `am`: working-mode
    code 1..4, 0 where the mechanism cannot be assembled or is within tol * (L1+L3)^2 of a
    singularity. Returns (cls, labels, big, u, v) with cls[row = th2, col = th1]."""
    m = MECHS[name]
    g = _centres(GRID_N, -math.pi, math.pi)
    th1, th2 = np.meshgrid(g, g)
    _, _, u, v, t, ok = ref_dkp(m, th1, th2, am)
    eps = tol * (m.L1 + m.L3) ** 2
    good = ok & (np.abs(u) > eps) & (np.abs(v) > eps) & (np.abs(t) > eps)
    code = np.where(u > 0, np.where(v > 0, 1, 2), np.where(v > 0, 3, 4))
    cls = np.where(good, code, 0).astype(np.int8)
    labels = label_runs(cls, wrap=True)
    return cls, labels, big_components(cls, labels)


@cached
def work_grid(name: str, wm: tuple, tol: float = 1e-6):
    """Classes of the pixel centres of the workspace root box for working mode `wm`: 1 for
    det A > 0, 2 for det A < 0, 0 where unreachable or near a singularity. cls[row = y, col = x]."""
    m = MECHS[name]
    r = m.L1 + m.L3
    g = _centres(GRID_N, -r, r)
    x, y = np.meshgrid(g, g)
    _, _, u, v, t, ok = ref_ikp(m, x, y, wm)
    eps = tol * r * r
    good = ok & (np.abs(u) > eps) & (np.abs(v) > eps) & (np.abs(t) > eps)
    cls = np.where(good, np.where(t > 0, 1, 2), 0).astype(np.int8)
    labels = label_runs(cls, wrap=False)
    return cls, labels, big_components(cls, labels)


def grid_aspects(name: str, tol: float = 1e-6):
    """Multisets of working modes of the big grid components, per assembly mode, in both spaces."""
    joint = {am: Counter(WM_OF_CODE[c] for c, _ in joint_grid(name, am, tol)[2].values()) for am in (1, -1)}
    work = {1: Counter(), -1: Counter()}
    for wm in WM_ORDER:
        for c, _ in work_grid(name, wm, tol)[2].values():
            work[1 if c == 1 else -1][wm] += 1
    return joint, work


# ---------------------------------------------------------------- cached analyses


@cached
def analysis(name: str, depth: int = DEPTH) -> asp.AspectAnalysis:
    return asp.analyse_aspects(MECHS[name], depth, shapes=False)  # the shapes: test_inscribed.py


def aspect_samples(tree, n, rng):
    """n points uniform over the area of a tree (leaves drawn by area, then uniform inside)."""
    lo, hi = tree.bounds()
    w = np.prod(hi - lo, axis=1)
    idx = rng.choice(len(lo), size=n, p=w / w.sum())
    return lo[idx] + rng.random((n, 2)) * (hi - lo)[idx]


# ---------------------------------------------------------------- counts and numbering


@pytest.mark.parametrize("name", NAMES)
def test_ten_aspects_five_per_assembly_mode(name):
    """Section 3.6 and figures 7-10: five aspects for det A > 0 (and, by the mirror symmetry in the
    base line, five for det A < 0), the same number for both mechanisms."""
    a = analysis(name)
    assert len(a.aspects) == 10
    assert Counter(x.assembly for x in a.aspects) == {1: 5, -1: 5}
    assert [x.number for x in a.aspects] == list(range(1, 11))
    for x in a.aspects:
        assert x.working in WM_ORDER and x.assembly in (1, -1)
        assert len(x.workspace) > 0 and len(x.jointspace) > 0


@pytest.mark.parametrize("name", NAMES)
def test_numbering_follows_documented_order(name):
    """Assembly mode + first, then working mode ++, +-, -+, --."""
    keys = [(-x.assembly, WM_ORDER.index(x.working)) for x in analysis(name).aspects]
    assert keys == sorted(keys)


@pytest.mark.parametrize("name", NAMES)
def test_aspect_count_is_stable_from_depth_8_to_12(name):
    joint, _ = grid_aspects(name)
    for depth in range(8, 13):
        a = analysis(name, depth)
        assert len(a.aspects) == 10, depth
        for am in (1, -1):
            mine = Counter(x.working for x in a.aspects if x.assembly == am)
            assert sum(mine.values()) == 5, (depth, am)
            assert mine == joint[am], (depth, am)


def test_numbering_is_deterministic():
    again = asp.analyse_aspects(M1, DEPTH, shapes=False)
    first = analysis("M1")
    assert aspect_files.aspect_rows(again) == aspect_files.aspect_rows(first)
    assert aspect_files.crossing_rows(again) == aspect_files.crossing_rows(first)
    for a, b in zip(again.aspects, first.aspects):
        assert a.workspace == b.workspace and a.jointspace == b.jointspace


@pytest.mark.parametrize("name", NAMES)
def test_no_component_is_dropped_silently(name):
    """Issue 3, item 3: a component without a counterpart is an error, never dropped. So at any
    depth, either AspectError is raised, or every black cell of every mode region belongs to an
    aspect of that region's modes (at small depths the coarse pavings may miss whole aspects in
    both spaces, which is not an error)."""
    m = MECHS[name]
    for depth in range(3, 11):
        try:
            a = analysis(name, depth) if depth >= 8 else asp.analyse_aspects(m, depth, shapes=False)
        except asp.AspectError as exc:
            assert "counterpart" in str(exc)
            continue
        for region in a.regions:
            if region.space == "workspace":
                trees = [x.workspace for x in a.aspects if x.working == region.working]
            else:
                trees = [x.jointspace for x in a.aspects if x.assembly == region.assembly]
            union = region.tree.subset(np.zeros(len(region.tree), bool))
            for t in trees:
                assert (union & t).area == 0  # aspects of one region are disjoint
                union = union | t
            assert union == region.tree, (depth, region.title())


# ---------------------------------------------------------------- sampled soundness and matching


@pytest.mark.parametrize("name", NAMES)
def test_points_of_parallel_aspects_have_the_aspect_modes(name):
    m = MECHS[name]
    rng = np.random.default_rng(10)
    for a in analysis(name).aspects:
        lo, hi = a.workspace.bounds()
        corners = np.concatenate([lo, hi, np.stack([lo[:, 0], hi[:, 1]], 1), np.stack([hi[:, 0], lo[:, 1]], 1)])
        pts = np.concatenate([aspect_samples(a.workspace, 3000, rng), corners])
        _, _, u, v, t, ok = ref_ikp(m, pts[:, 0], pts[:, 1], a.working)
        assert ok.all(), a.number
        assert np.all(np.sign(u) == a.working[0]) and np.all(np.sign(v) == a.working[1]), a.number
        assert np.all(np.sign(t) == a.assembly), a.number


@pytest.mark.parametrize("name", NAMES)
def test_points_of_serial_aspects_have_the_aspect_modes(name):
    m = MECHS[name]
    rng = np.random.default_rng(11)
    for a in analysis(name).aspects:
        lo, hi = a.jointspace.bounds()
        corners = np.concatenate([lo, hi, np.stack([lo[:, 0], hi[:, 1]], 1), np.stack([hi[:, 0], lo[:, 1]], 1)])
        pts = np.concatenate([aspect_samples(a.jointspace, 3000, rng), corners])
        _, _, u, v, t, ok = ref_dkp(m, pts[:, 0], pts[:, 1], a.assembly)
        assert ok.all(), a.number
        assert np.all(np.sign(t) == a.assembly), a.number
        assert np.all(np.sign(u) == a.working[0]) and np.all(np.sign(v) == a.working[1]), a.number


def _ikp_hits(name, depth, rng, n=3000):
    """Per aspect: (fraction of IKP images of uniform samples in its own serial aspect, images in
    another aspect of its assembly mode, images in the certified outside of the joint space)."""
    m, a = MECHS[name], analysis(name, depth)
    out = []
    for x in a.aspects:
        pts = aspect_samples(x.workspace, n, rng)
        th1, th2, _, _, _, ok = ref_ikp(m, pts[:, 0], pts[:, 1], x.working)
        assert ok.all()
        img = np.column_stack([th1, th2])
        own = x.jointspace.locate(img) >= 0
        other = np.zeros(n, bool)
        for y in a.aspects:
            if y.assembly == x.assembly and y.number != x.number:
                other |= y.jointspace.locate(img) >= 0
        outside = a.region("jointspace", x.assembly).paving.outside.locate(img) >= 0
        out.append((x, own.mean(), int(other.sum()), int(outside.sum())))
    return out


def _dkp_hits(name, depth, rng, n=3000):
    m, a = MECHS[name], analysis(name, depth)
    out = []
    for x in a.aspects:
        q = aspect_samples(x.jointspace, n, rng)
        px, py, _, _, _, ok = ref_dkp(m, q[:, 0], q[:, 1], x.assembly)
        assert ok.all()
        img = np.column_stack([px, py])
        own = x.workspace.locate(img) >= 0
        other = np.zeros(n, bool)
        for y in a.aspects:
            if y.working == x.working and y.number != x.number:
                other |= y.workspace.locate(img) >= 0
        outside = a.region("workspace", x.working).paving.outside.locate(img) >= 0
        out.append((x, own.mean(), int(other.sum()), int(outside.sum())))
    return out


def _pooled(hits):
    w = np.array([x.workspace.area for x, *_ in hits])
    f = np.array([h[1] for h in hits])
    return float((w * f).sum() / w.sum())


@pytest.mark.parametrize("name", NAMES)
def test_ikp_images_of_a_parallel_aspect_lie_in_its_serial_aspect(name):
    """The IKP image of a point of an aspect never lies in another aspect of the same assembly
    mode nor outside the joint space; it lies in the aspect's own joint-space cells unless it is
    near the boundary (then in undetermined cells): a large majority of uniform samples."""
    hits = _ikp_hits(name, DEPTH, np.random.default_rng(12))
    for x, frac, other, outside in hits:
        assert other == 0, f"aspect {x.number}: {other} IKP images in another aspect"
        assert outside == 0, f"aspect {x.number}: {outside} IKP images in the certified outside"
        assert frac > 0.6, (x.number, frac)
    assert _pooled(hits) > 0.9


@pytest.mark.parametrize("name", NAMES)
def test_dkp_images_of_a_serial_aspect_lie_in_its_parallel_aspect(name):
    hits = _dkp_hits(name, DEPTH, np.random.default_rng(13))
    for x, frac, other, outside in hits:
        assert other == 0, f"aspect {x.number}: {other} DKP images in another aspect"
        assert outside == 0, f"aspect {x.number}: {outside} DKP images in the certified outside"
        assert frac > 0.5, (x.number, frac)
    assert _pooled(hits) > 0.85


@pytest.mark.parametrize("name", NAMES)
def test_images_land_in_their_own_aspect_more_often_as_depth_grows(name):
    """The misses are the undetermined band along the boundary, which narrows with depth."""
    ikp = [_pooled(_ikp_hits(name, d, np.random.default_rng(14), 1500)) for d in (8, 10, 12)]
    dkp = [_pooled(_dkp_hits(name, d, np.random.default_rng(15), 1500)) for d in (8, 10, 12)]
    assert ikp[0] < ikp[1] < ikp[2] and ikp[2] > 0.95
    assert dkp[0] < dkp[1] < dkp[2] and dkp[2] > 0.93


@pytest.mark.parametrize("name", NAMES)
def test_representative_configuration_is_inside_its_aspect(name):
    m = MECHS[name]
    for x in analysis(name).aspects:
        (px, py), (t1, t2) = x.pose, x.joints
        th1, th2, u, v, t, ok = ref_ikp(m, px, py, x.working)
        assert ok and np.sign(t) == x.assembly
        assert abs(math.remainder(float(th1) - t1, TWO_PI)) < 1e-9
        assert abs(math.remainder(float(th2) - t2, TWO_PI)) < 1e-9
        assert x.workspace.locate(np.array([[px, py]]))[0] >= 0
        assert x.jointspace.locate(np.array([[t1, t2]]))[0] >= 0


# ---------------------------------------------------------------- areas


@pytest.mark.parametrize("name", NAMES)
def test_assembly_mode_regions_fill_the_workspace_as_depth_grows(name):
    """Per working mode, the two assembly-mode regions (sums of parallel aspects) cover at most
    the certified workspace, itself inside the exact workspace (lens minus holes), and the gap
    shrinks with the depth: the singular curves have zero area."""
    m = MECHS[name]
    exact = workspace_area_closed_form(m)
    gaps = {wm: [] for wm in WM_ORDER}
    for depth in (8, 10, 12):
        a = analysis(name, depth)
        certified = spaces.pave_space(m, "workspace", depth).inside.area
        assert certified <= exact
        for wm in WM_ORDER:
            plus = sum(x.workspace.area for x in a.aspects if x.working == wm and x.assembly == 1)
            minus = sum(x.workspace.area for x in a.aspects if x.working == wm and x.assembly == -1)
            assert plus > 0 and minus > 0
            assert plus + minus <= certified
            gaps[wm].append((certified - plus - minus, exact - plus - minus))
    for wm, g in gaps.items():
        assert g[0][0] > g[1][0] > g[2][0] >= 0, (wm, g)
        assert g[0][1] > g[1][1] > g[2][1] > 0, (wm, g)
        assert g[2][1] < 0.01 * exact, (wm, g)


@pytest.mark.parametrize("name", NAMES)
def test_serial_aspects_fill_the_joint_space_twice(name):
    """Each assembly mode's serial aspects cover (almost) the whole joint space: the joint space
    is covered once per assembly mode. Reference: the grid fraction of assemblable joints."""
    m = MECHS[name]
    g = _centres(1024, -math.pi, math.pi)
    th1, th2 = np.meshgrid(g, g)
    d = np.hypot(m.L0 + m.L2 * np.cos(th2) - m.L1 * np.cos(th1), m.L2 * np.sin(th2) - m.L1 * np.sin(th1))
    area = np.mean((d > 0) & (d <= m.L3 + m.L4) & (d >= abs(m.L3 - m.L4))) * TWO_PI ** 2
    for am in (1, -1):
        total = sum(x.jointspace.area for x in analysis(name).aspects if x.assembly == am)
        assert 0.9 * area < total < 1.005 * area


# ---------------------------------------------------------------- independent grid


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("tol", [1e-6, 1e-3])
def test_grid_has_five_serial_regions_per_assembly_mode(name, tol):
    joint, _ = grid_aspects(name, tol)
    a = analysis(name)
    for am in (1, -1):
        assert sum(joint[am].values()) == 5, (am, joint[am])
        assert joint[am] == Counter(x.working for x in a.aspects if x.assembly == am)


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("tol", [1e-6, 1e-3])
def test_grid_has_five_parallel_regions_per_assembly_mode(name, tol):
    _, work = grid_aspects(name, tol)
    a = analysis(name)
    for am in (1, -1):
        assert sum(work[am].values()) == 5, (am, work[am])
        assert work[am] == Counter(x.working for x in a.aspects if x.assembly == am)


def _grid_match(name, space):
    """{aspect number: grid label} by majority vote of the aspect's leaf centres, and the share."""
    a = analysis(name)
    m = MECHS[name]
    out = {}
    for x in a.aspects:
        if space == "jointspace":
            cls, labels, big = joint_grid(name, x.assembly)
            lo, hi = -math.pi, math.pi
            tree = x.jointspace
        else:
            cls, labels, big = work_grid(name, x.working)
            lo, hi = -(m.L1 + m.L3), m.L1 + m.L3
            tree = x.workspace
        c = tree.centres()
        ix = np.clip(np.floor((c - lo) / (hi - lo) * GRID_N).astype(int), 0, GRID_N - 1)
        lab = labels[ix[:, 1], ix[:, 0]]
        lab = lab[np.isin(lab, list(big))]
        values, counts = np.unique(lab, return_counts=True)
        best = int(values[np.argmax(counts)])
        out[x.number] = (best, counts.max() / counts.sum(), big[best])
    return out


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("space", ["jointspace", "workspace"])
def test_aspects_match_grid_regions_one_to_one(name, space):
    """Each aspect lies in one grid region (its leaf centres vote), different aspects of a region
    family in different grid regions, with the same modes and a comparable area: the certified
    aspect is inside the region, so its area is at most the grid area (plus discretisation)."""
    a = analysis(name)
    m = MECHS[name]
    match = _grid_match(name, space)
    pixel = (TWO_PI / GRID_N) ** 2 if space == "jointspace" else (2 * (m.L1 + m.L3) / GRID_N) ** 2
    families = {}
    for x in a.aspects:
        label, share, (cls, pixels) = match[x.number]
        assert share > 0.995, (x.number, share)
        if space == "jointspace":
            assert WM_OF_CODE[cls] == x.working
            family = x.assembly
        else:
            assert cls == (1 if x.assembly == 1 else 2)
            family = x.working
        families.setdefault(family, []).append(label)
        area = x.jointspace.area if space == "jointspace" else x.workspace.area
        assert 0.8 * pixels * pixel < area < 1.03 * pixels * pixel, (x.number, area, pixels * pixel)
    for family, labels in families.items():
        assert len(set(labels)) == len(labels), family  # one-to-one
    # and every big grid region is some aspect
    if space == "jointspace":
        for am in (1, -1):
            assert set(families[am]) == set(joint_grid(name, am)[2])
    else:
        for wm in WM_ORDER:
            assert set(families[wm]) == set(work_grid(name, wm)[2])


@pytest.mark.parametrize("name", NAMES)
def test_crossings_match_grid_adjacency_across_one_serial_singularity(name):
    """Two grid regions of one assembly mode whose pixels touch across a change of exactly one
    working-mode sign are joined by a motion crossing that serial singularity once; the pairs
    (and the singularity crossed) are exactly the analysis' crossings."""
    a = analysis(name)
    match = _grid_match(name, "jointspace")
    expected = set()
    for am in (1, -1):
        cls, labels, big = joint_grid(name, am)
        aspect_of = {match[x.number][0]: x.number for x in a.aspects if x.assembly == am}
        count = Counter()
        for axis in (0, 1):
            l2, c2 = np.roll(labels, -1, axis=axis), np.roll(cls, -1, axis=axis)
            sel = np.isin(labels, list(big)) & np.isin(l2, list(big)) & (labels != l2)
            for la, lb, ca, cb in zip(labels[sel], l2[sel], cls[sel], c2[sel]):
                wa, wb = WM_OF_CODE[int(ca)], WM_OF_CODE[int(cb)]
                changed = [k for k in (0, 1) if wa[k] != wb[k]]
                if len(changed) == 1:
                    pair = tuple(sorted((aspect_of[int(la)], aspect_of[int(lb)])))
                    count[pair + (am, "B11" if changed[0] == 0 else "B22")] += 1
        expected |= {key for key, n in count.items() if n >= 3}
    got = {(c.a, c.b, c.assembly, c.singularity) for c in a.crossings}
    assert got == expected


# ---------------------------------------------------------------- crossings


@pytest.mark.parametrize("name", NAMES)
def test_crossings_change_exactly_one_sign(name):
    a = analysis(name)
    by_number = {x.number: x for x in a.aspects}
    assert a.crossings
    for c in a.crossings:
        x, y = by_number[c.a], by_number[c.b]
        assert c.a < c.b
        assert x.assembly == y.assembly == c.assembly
        changed = [k for k in (0, 1) if x.working[k] != y.working[k]]
        assert len(changed) == 1
        assert c.singularity == ("B11" if changed[0] == 0 else "B22")
        assert c.band_cells > 0
    rows = aspect_files.crossing_rows(a)
    assert [(r[0], r[1]) for r in rows] == [(c.a, c.b) for c in a.crossings]
    for r in rows:
        assert r[4] == sign_text(by_number[r[0]].working) and r[5] == sign_text(by_number[r[1]].working)


@pytest.mark.parametrize("name", NAMES)
def test_crossing_graph_is_complete_bipartite_two_three(name):
    """Section 3.6: no motion changing the working mode once joins aspects 1 and 4, nor any two
    of 2, 3, 5 (the paper's numbering): the crossing graph of an assembly mode is K_{2,3} with
    parts {1, 4} and {2, 3, 5}. Checked here by two-colouring the graph."""
    a = analysis(name)
    for am in (1, -1):
        nodes = [x.number for x in a.aspects if x.assembly == am]
        edges = {(c.a, c.b) for c in a.crossings if c.assembly == am}
        assert len(edges) == 6
        colour = {nodes[0]: 0}
        stack = [nodes[0]]
        while stack:
            n = stack.pop()
            for p, q in edges:
                for u, w in ((p, q), (q, p)):
                    if u == n:
                        if w in colour:
                            assert colour[w] != colour[n], "odd cycle: not bipartite"
                        else:
                            colour[w] = 1 - colour[n]
                            stack.append(w)
        assert set(colour) == set(nodes), "the crossing graph is not connected"
        part0 = [n for n in nodes if colour[n] == 0]
        part1 = [n for n in nodes if colour[n] == 1]
        assert sorted((len(part0), len(part1))) == [2, 3]
        complete = {tuple(sorted((p, q))) for p in part0 for q in part1}
        assert edges == complete
        # the two-aspect side: working modes ++ and -- (each edge changes one sign)
        small = part0 if len(part0) == 2 else part1
        assert sorted(sign_text(x.working) for x in a.aspects if x.number in small) in (["++", "--"], ["+-", "-+"])
        assert crossings.is_complete_bipartite_2_3(a.aspects, a.crossings, am)
        numbers, adj = crossings.adjacency_matrix(a.aspects, a.crossings, am)
        assert numbers == nodes
        assert adj.sum() == 12 and np.array_equal(adj, adj.T)


# ---------------------------------------------------------------- symmetries of the geometry


def _leaf_set(tree, transform):
    out = set()
    for lev, (cx, cy) in zip(tree.level.tolist(), tree.coords.tolist()):
        out.add((lev,) + transform(lev, cx, cy))
    return out


def _sym_diff_area(sa, sb, cell_area0):
    return sum(cell_area0 * 4.0 ** -lev for lev, *_ in sa ^ sb)


@pytest.mark.parametrize("name", NAMES)
def test_mirror_in_the_base_line_maps_aspects_to_aspects(name):
    """Reflecting the mechanism in the line A1A2 (y -> -y, th -> -th) negates u, v and t: the aspect
    of modes (su, sv, sa) maps onto the aspect of modes (-su, -sv, -sa), in both spaces."""
    a = analysis(name)
    m = MECHS[name]
    ws0 = (2 * (m.L1 + m.L3)) ** 2
    js0 = TWO_PI ** 2
    ident = lambda lev, x, y: (x, y)  # noqa: E731
    flip_y = lambda lev, x, y: (x, (1 << lev) - 1 - y)  # noqa: E731
    flip_both = lambda lev, x, y: ((1 << lev) - 1 - x, (1 << lev) - 1 - y)  # noqa: E731
    partner_of = {}
    for x in a.aspects:
        partners = [y for y in a.aspects if y.working == (-x.working[0], -x.working[1]) and y.assembly == -x.assembly]
        best = min(partners, key=lambda y: _sym_diff_area(_leaf_set(x.workspace, flip_y), _leaf_set(y.workspace, ident), ws0))
        assert _sym_diff_area(_leaf_set(x.workspace, flip_y), _leaf_set(best.workspace, ident), ws0) <= 1e-3 * x.workspace.area
        assert _sym_diff_area(_leaf_set(x.jointspace, flip_both), _leaf_set(best.jointspace, ident), js0) <= 1e-3 * x.jointspace.area
        partner_of[x.number] = best.number
    assert sorted(partner_of.values()) == list(range(1, 11))
    assert all(partner_of[partner_of[k]] == k for k in partner_of)


def test_m2_leg_swap_maps_aspects_to_aspects():
    """M2 has L1 = L2 and L3 = L4: the reflection x -> L0 - x swaps the legs, (th1, th2) ->
    (pi - th2, pi - th1), and maps modes (su, sv, sa) to (-sv, -su, sa). The joint-space root is
    invariant (cell k -> n/2 - 1 - k mod n, axes swapped); the workspace root is not, so there
    only the areas are compared."""
    a = analysis("M2")
    ident = lambda lev, x, y: (x, y)  # noqa: E731

    def swap(lev, x, y):
        n = 1 << lev
        return ((n // 2 - 1 - y) % n, (n // 2 - 1 - x) % n) if lev >= 1 else (x, y)

    js0 = TWO_PI ** 2
    seen = []
    for x in a.aspects:
        image = _leaf_set(x.jointspace, swap)
        modes = ((-x.working[1], -x.working[0]), x.assembly)
        partners = [y for y in a.aspects if (y.working, y.assembly) == modes]
        best = min(partners, key=lambda y: _sym_diff_area(image, _leaf_set(y.jointspace, ident), js0))
        assert _sym_diff_area(image, _leaf_set(best.jointspace, ident), js0) <= 1e-3 * x.jointspace.area
        assert best.workspace.area == pytest.approx(x.workspace.area, rel=0.02)
        seen.append(best.number)
    assert sorted(seen) == list(range(1, 11))


# ---------------------------------------------------------------- locate_configurations


@pytest.mark.parametrize("name", NAMES)
def test_locate_reports_the_aspect_of_its_representative(name):
    a = analysis(name)
    for x in a.aspects:
        rows = locate_configurations(a.mechanism, a.aspects, np.array([x.pose]), "workspace")
        mine = [r for r in rows if r["working_mode"] == sign_text(x.working)]
        assert len(mine) == 1
        assert mine[0]["aspect"] == x.number and mine[0]["assembly_mode"] == sign_text([x.assembly])
        assert mine[0]["singular"] == ""
        rows = locate_configurations(a.mechanism, a.aspects, np.array([x.joints]), "jointspace")
        mine = [r for r in rows if r["assembly_mode"] == sign_text([x.assembly])]
        assert len(mine) == 1
        assert mine[0]["aspect"] == x.number and mine[0]["working_mode"] == sign_text(x.working)
        assert mine[0]["x"] == pytest.approx(x.pose[0], abs=1e-9) and mine[0]["y"] == pytest.approx(x.pose[1], abs=1e-9)


@pytest.mark.parametrize("name", NAMES)
def test_locate_random_poses_agrees_with_independent_grid(name):
    """For random poses, every configuration placed in an aspect has that aspect's modes (by the
    reference IKP) and lies in the grid region matched to that aspect; and a pose whose every
    configuration is well inside a grid region gets an aspect for each of them."""
    m = MECHS[name]
    a = analysis(name)
    by_number = {x.number: x for x in a.aspects}
    match = _grid_match(name, "workspace")
    rng = np.random.default_rng(16)
    r = m.L1 + m.L3
    pts = rng.uniform(-r, r, (300, 2))
    rows = locate_configurations(a.mechanism, a.aspects, pts, "workspace")
    placed = 0
    for row in rows:
        k = row["aspect"]
        wm = tuple(1 if c == "+" else -1 for c in row["working_mode"])
        p = pts[row["input"]]
        th1, th2, u, v, t, ok = ref_ikp(m, p[0], p[1], wm)
        assert ok
        if k is None:
            continue
        placed += 1
        x = by_number[k]
        assert x.working == wm and x.assembly == int(np.sign(t))
        cls, labels, _ = work_grid(name, wm)
        ix = np.clip(np.floor((p + r) / (2 * r) * GRID_N).astype(int), 0, GRID_N - 1)
        lab = labels[ix[1], ix[0]]
        if lab >= 0:
            assert lab == match[k][0]
    reachable = sum(bool(ref_ikp(m, p[0], p[1], (1, 1))[5]) for p in pts)
    assert placed > 0.9 * 4 * reachable


def test_locate_joints_wrap_around_the_torus():
    """Joint values are angles: th and th + 2 k pi are the same configuration, same aspect."""
    a = analysis("M1")
    for x in a.aspects:
        base = locate_configurations(a.mechanism, a.aspects, np.array([x.joints]), "jointspace")
        shifted = locate_configurations(a.mechanism, a.aspects, np.array([x.joints]) + [TWO_PI, -2 * TWO_PI], "jointspace")
        assert [r["aspect"] for r in base] == [r["aspect"] for r in shifted]
        assert x.number in [r["aspect"] for r in shifted]


def test_locate_outside_the_workspace_gives_no_configuration():
    a = analysis("M1")
    # beyond both outer circles; in the hole |P - A1| < |L1 - L3| = 3; the point A1 itself
    for pose in ([30.0, 0.0], [0.0, 20.0], [1.0, 1.0], [0.0, 0.0]):
        assert locate_configurations(a.mechanism, a.aspects, np.array([pose]), "workspace") == []
    # joints that cannot be assembled: th1 = pi, th2 = 0 gives |B1B2| = 22 > L3 + L4
    assert locate_configurations(a.mechanism, a.aspects, np.array([[math.pi, 0.0]]), "jointspace") == []


def test_locate_on_a_serial_singularity_reports_no_aspect():
    """P on the outer circle |P - A1| = L1 + L3 = 13 at 60 degrees, inside the workspace
    (|P - A2| is about 11.5, in [3, 13]): leg 1 is stretched, B11 = 0 for every configuration."""
    a = analysis("M1")
    p = 13.0 * np.array([math.cos(math.pi / 3), math.sin(math.pi / 3)])
    assert 3 < math.hypot(p[0] - 9, p[1]) < 13
    rows = locate_configurations(a.mechanism, a.aspects, p[None, :], "workspace")
    assert rows
    for row in rows:
        assert row["aspect"] is None
        assert "B11" in row["singular"]


def test_locate_lists_each_configuration_once_on_a_serial_singularity():
    """P on the outer circle of leg 1: B1 is unique (leg 1 stretched), so P has two configurations
    (one per branch of leg 2), not four; each should be listed once."""
    a = analysis("M1")
    p = 13.0 * np.array([math.cos(math.pi / 3), math.sin(math.pi / 3)])
    rows = locate_configurations(a.mechanism, a.aspects, p[None, :], "workspace")
    joints = [(round(r["theta1"], 9), round(r["theta2"], 9)) for r in rows]
    assert len(set(joints)) == 2
    assert len(joints) == len(set(joints))
    assert all(r["working_mode"][0] == "0" and "B11 = 0" in r["singular"] and r["aspect"] is None for r in rows)


def test_locate_on_a_parallel_singularity_reports_no_aspect():
    """B1, P, B2 aligned with |B1B2| = L3 + L4 (the boundary of the joint space): at th1 = 1.0
    solve |B1B2| = 13 for th2; the configuration with these joints reports no aspect."""
    m = M1
    a = analysis("M1")
    th1 = 1.0
    b1 = np.array([m.L1 * math.cos(th1), m.L1 * math.sin(th1)])
    w = np.array([m.L0, 0.0]) - b1  # B2 - B1 = w + L2 e^{i th2}; |.|^2 = |w|^2 + L2^2 + 2 L2 w.e
    q = ((m.L3 + m.L4) ** 2 - w @ w - m.L2 ** 2) / (2 * m.L2 * math.hypot(*w))
    th2 = math.atan2(w[1], w[0]) + math.acos(q)
    b2 = np.array([m.L0 + m.L2 * math.cos(th2), m.L2 * math.sin(th2)])
    assert np.hypot(*(b2 - b1)) == pytest.approx(13.0)
    p = b1 + m.L3 * (b2 - b1) / np.hypot(*(b2 - b1))
    rows = locate_configurations(a.mechanism, a.aspects, p[None, :], "workspace")
    aligned = [r for r in rows if abs(math.remainder(r["theta1"] - th1, TWO_PI)) < 1e-5
               and abs(math.remainder(r["theta2"] - th2, TWO_PI)) < 1e-5]
    assert aligned
    for r in aligned:
        assert r["aspect"] is None


def test_locate_m2_with_coincident_cranks_reports_no_aspect():
    """M2 (L3 = L4) with B1 = B2: P turns freely around B1 (section 3.1), an isolated parallel
    singularity; whatever assembly is reported there, it belongs to no aspect."""
    m = M2
    a = analysis("M2")
    x0 = (m.L0 ** 2 + m.L1 ** 2 - m.L2 ** 2) / (2 * m.L0)
    h = math.sqrt(m.L1 ** 2 - x0 * x0)
    for s in (1, -1):
        joints = np.array([[math.atan2(s * h, x0), math.atan2(s * h, x0 - m.L0)]])
        for row in locate_configurations(a.mechanism, a.aspects, joints, "jointspace"):
            assert row["aspect"] is None
        # nearby joints (off the point) do belong to aspects
        near = locate_configurations(a.mechanism, a.aspects, joints + 0.3, "jointspace")
        assert any(r["aspect"] is not None for r in near)


# ---------------------------------------------------------------- components at scale


def _leaf_pixel_labels(tree, labels_img):
    """Raster label under the first pixel of every leaf (depth-D pixel coordinates)."""
    shift = tree.grid.depth - tree.level
    xy = tree.coords << shift[:, None]
    return labels_img[xy[:, 1], xy[:, 0]]


def test_components_of_a_depth_12_paving_agree_with_raster_labelling():
    """Tree.components on the black tree of M1's workspace paving for working mode +- at depth 12
    (three aspects, plus the thin fragments near tangencies) against the independent labelling of
    the depth-12 raster (4096 x 4096, 4-connected: corner contact does not connect)."""
    m = M1
    r = m.L1 + m.L3
    grid = Grid(((-r, r), (-r, r)), 12, (False, False))
    tree = pave(grid, modes.working_mode_workspace_test(m, (1, -1))).inside
    assert len(tree) > 20000
    labels, count = tree.components()
    raster = tree.coverage(12) == 1.0
    mine = label_runs(raster.astype(np.int8), wrap=False)
    assert count == len(np.unique(mine[mine >= 0]))
    pixel_label = _leaf_pixel_labels(tree, mine)
    assert np.all(pixel_label >= 0)
    pairs = set(zip(labels.tolist(), pixel_label.tolist()))
    assert len(pairs) == count  # a bijection between the two labellings
    assert count >= 3


def test_components_honour_the_torus_wrap():
    """On the joint-space torus a region crossing th = +-pi is one region: Tree.components on the
    black tree of M1's assembly-mode + paving (depth 10) agrees with the labelling with wrap, and
    the wrap matters (without it there are more components)."""
    m = M1
    grid = Grid(((-math.pi, math.pi), (-math.pi, math.pi)), 10, (True, True))
    tree = pave(grid, modes.assembly_mode_joint_test(m, 1)).inside
    labels, count = tree.components()
    raster = (tree.coverage(10) == 1.0).astype(np.int8)
    wrapped = label_runs(raster, wrap=True)
    flat = label_runs(raster, wrap=False)
    n_wrapped = len(np.unique(wrapped[wrapped >= 0]))
    assert count == n_wrapped
    assert len(np.unique(flat[flat >= 0])) > n_wrapped
    pairs = set(zip(labels.tolist(), _leaf_pixel_labels(tree, wrapped).tolist()))
    assert len(pairs) == count
    # the region family of the whole joint space: the same, with the reachable-joints paving
    js = spaces.pave_space(m, "jointspace", 10).inside
    labels, count = js.components()
    raster = (js.coverage(10) == 1.0).astype(np.int8)
    wrapped = label_runs(raster, wrap=True)
    assert count == len(np.unique(wrapped[wrapped >= 0]))
    assert len(set(zip(labels.tolist(), _leaf_pixel_labels(js, wrapped).tolist()))) == count


def test_label_runs_reference_on_small_cases():
    """The reference labelling itself: wrap, corner contact, classes."""
    img = np.zeros((6, 6), np.int8)
    img[0, 0] = img[0, 5] = 1  # joined through the x wrap only
    img[5, 2] = img[0, 2] = 1  # joined through the y wrap only
    img[2, 2] = img[3, 3] = 1  # corner contact: two components
    img[4, 0] = 1
    img[4, 1] = 2  # different class: not joined
    lab = label_runs(img, wrap=True)
    assert lab[0, 0] == lab[0, 5] and lab[5, 2] == lab[0, 2]
    assert lab[2, 2] != lab[3, 3] and lab[4, 0] != lab[4, 1]
    assert len(np.unique(lab[lab >= 0])) == 6
    lab = label_runs(img, wrap=False)
    assert lab[0, 0] != lab[0, 5] and lab[5, 2] != lab[0, 2]
    assert len(np.unique(lab[lab >= 0])) == 8
