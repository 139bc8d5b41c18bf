"""Every pose with given joint values (the direct kinematic problem), certified: branch and prune
over the space of poses with the Krawczyk test, for any kind with a `PoseAspectModel`.

The equations F(pose) = 0 come from the model (`dkp_system`: F and its Jacobian in floating
point, and outward-rounded enclosures of both over boxes). Breadth-first from the root box of the
pose space, every box X of a level is, in one vectorised pass:

- **empty** when F's enclosure over X (the natural one, or the mean-value form F(m) + J(X)(X - m))
  excludes 0 in some component, or when the Krawczyk image K(X) = m - Y F(m) + (I - Y J(X))(X - m)
  (Y: the inverse of the Jacobian at the centre m) misses X: every zero in X lies in K(X);
- **a solution** when K(X') lies in the interior of X', the box X widened by a quarter of its
  width on every side: then X' holds exactly one zero (Krawczyk, Moore), and K(X') encloses it
  (tightened by a few more Krawczyk steps). The widening lets a zero on a face or corner of the
  dyadic boxes (such as phi = 0) be proven from a box that holds it inside;
- split into its 2^d halves otherwise, down to `max_depth`; the boxes left then are **not
  decided** (reported, never dropped: near a singular pose F's Jacobian is nearly singular).

Solutions found from several boxes are merged when the enclosure of one lies in the widened box of
another (that box holds one zero only, so they are the same); enclosures that are disjoint are
distinct zeros. A zero whose enclosure lies outside the root box (the orientation range of a
3-RPR) is not counted; one whose enclosure straddles the root's boundary is not decided. On a
periodic axis enclosures are compared modulo the period. The count is certified when no box is
left undecided: the root box then holds exactly these solutions. Each solution's class is
certified over its box: by the system when the joints decide the sheet (a 3-RRR's working mode;
a solution in a working mode the model leaves out is not counted), else by the model.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fivebar_cli.mechanisms.base import PoseAspectModel, PoseSystem, Space
from fivebar_cli.numerics.interval import Interval

MAX_DEPTH = 44  # bisections of every axis: the root's width / 2^44 is near the rounding of its bounds
MAX_BOXES = 1 << 20  # boxes of one level: beyond, the search stops with those boxes undecided
WIDEN = 0.25  # the Krawczyk test of a box is run on the box widened by this fraction of its width
TIGHTEN = 6  # Krawczyk steps that tighten a solution's enclosure


@dataclass(frozen=True)
class Solution:
    """One zero: a floating-point pose inside `lo`..`hi`, a box proven to hold it and no other;
    `cls` is the sign class certified over that box (-1: not certified)."""

    pose: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    cls: int


@dataclass(frozen=True)
class DkpResult:
    joints: np.ndarray
    solutions: list[Solution]  # in class order, then by the last axis, then the first ones
    undecided_lo: np.ndarray  # (k, d) boxes left undecided
    undecided_hi: np.ndarray
    evaluations: int
    depth: int  # the deepest level searched

    @property
    def certified(self) -> bool:
        return len(self.undecided_lo) == 0


# ---------------------------------------------------------------- interval linear algebra


def krawczyk(system: PoseSystem, lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """K(X) over boxes (n, d): (lo, hi, ok); ok is False where Y cannot be formed (a singular or
    non-finite Jacobian at the centre: K is then the whole space).

    Component i of K is m_i - sum_a Y_ia F_a(m) + sum_b (delta_ib - sum_a Y_ia J_ab(X)) (X_b - m_b),
    summed in that order; every component i (and every coefficient i, b) is one column of an
    (n, d) (or (n, d, d)) interval array, so the sums take d steps, not d^2 or d^3 small ones."""
    n, d = lo.shape
    m = np.minimum(np.maximum(0.5 * lo + 0.5 * hi, lo), hi)
    with np.errstate(all="ignore"):
        jm = system.jacobian(m)
        ok = np.all(np.isfinite(jm), axis=(1, 2)) & (np.abs(np.linalg.det(np.where(np.isfinite(jm), jm, 0.0))) > 0)
        y = np.zeros_like(jm)
        if ok.any():
            y[ok] = np.linalg.inv(jm[ok])
        ok &= np.all(np.isfinite(y), axis=(1, 2))
    y = np.where(ok[:, None, None], y, 0.0)
    f_lo, f_hi, _, _ = system.enclosure(m, m)
    _, _, j_lo, j_hi = system.enclosure(lo, hi)
    fm = Interval(f_lo, f_hi)
    dx = Interval(lo, hi) - Interval.point(m)
    jac = Interval(j_lo, j_hi)
    value = Interval.point(m)
    for a in range(d):
        value = value - y[:, :, a] * fm[:, a, None]
    coefficient = Interval.point(np.eye(d))
    for a in range(d):
        coefficient = coefficient - y[:, :, a, None] * jac[:, a, None, :]
    for b in range(d):
        value = value + coefficient[:, :, b] * dx[:, b, None]
    k_lo, k_hi = value.lo.copy(), value.hi.copy()
    bad = ~ok | np.any(~np.isfinite(k_lo) | ~np.isfinite(k_hi), axis=1)
    k_lo[bad], k_hi[bad] = -np.inf, np.inf
    return k_lo, k_hi, ~bad


def excludes_zero(system: PoseSystem, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Boxes on which some component of F is certified non-zero (natural or mean-value enclosure;
    the mean-value form F_i(m) + sum_b J_ib(X) (X_b - m_b) of every i at once, as in `krawczyk`)."""
    m = np.minimum(np.maximum(0.5 * lo + 0.5 * hi, lo), hi)
    f_lo, f_hi, j_lo, j_hi = system.enclosure(lo, hi)
    out = np.any((f_lo > 0) | (f_hi < 0), axis=1)
    fm_lo, fm_hi, _, _ = system.enclosure(m, m)
    dx = Interval(lo, hi) - Interval.point(m)
    jac = Interval(j_lo, j_hi)
    value = Interval(fm_lo, fm_hi)
    for b in range(lo.shape[1]):
        value = value + jac[:, :, b] * dx[:, b, None]
    return out | np.any((value.lo > 0) | (value.hi < 0), axis=1)


# ---------------------------------------------------------------- the search


def solve(model: PoseAspectModel, space: Space, joints, max_depth: int = MAX_DEPTH,
          max_boxes: int = MAX_BOXES) -> DkpResult:
    """Every pose of `space`'s root box with these joint values, certified (see the module)."""
    joints = np.asarray(joints, float)
    system = model.dkp_system(joints)
    root = np.array(space.root, float)
    periodic = np.array([a.periodic for a in space.axes])
    lo, hi = root[None, :, 0].copy(), root[None, :, 1].copy()
    found: list[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]] = []  # (S lo, S hi, X' lo, X' hi)
    undecided = []
    evaluations, level = 0, 0
    while len(lo):
        evaluations += len(lo)
        status, s_lo, s_hi, w_lo, w_hi = _classify(system, lo, hi)
        for k in np.flatnonzero(status == 1):
            found.append((s_lo[k], s_hi[k], w_lo[k], w_hi[k]))
        open_ = status == 0
        if level >= max_depth or np.count_nonzero(open_) << lo.shape[1] > max_boxes:
            undecided.append((lo[open_], hi[open_]))
            break
        lo, hi = _halves(lo[open_], hi[open_])
        level += 1
    solutions, left = _distinct(model, system, found, root, periodic)
    boxes = undecided + left
    empty = np.zeros((0, root.shape[0]))
    und_lo = np.concatenate([empty] + [b[0] for b in boxes])
    und_hi = np.concatenate([empty] + [b[1] for b in boxes])
    return DkpResult(joints, solutions, und_lo, und_hi, evaluations, level)


def _classify(system: PoseSystem, lo: np.ndarray, hi: np.ndarray):
    """Per box: status (-1 empty, 1 a solution in the widened box, 0 split), the solution's
    enclosure and the widened box."""
    n, d = lo.shape
    status = np.zeros(n, np.int8)
    s_lo, s_hi = np.full((n, d), np.nan), np.full((n, d), np.nan)
    empty = excludes_zero(system, lo, hi)
    rest = np.flatnonzero(~empty)
    if len(rest):
        k_lo, k_hi, _ = krawczyk(system, lo[rest], hi[rest])
        empty[rest] |= np.any((k_lo > hi[rest]) | (k_hi < lo[rest]), axis=1)
    status[empty] = -1
    width = hi - lo
    w_lo, w_hi = lo - WIDEN * width, hi + WIDEN * width
    rest = np.flatnonzero(~empty)
    if len(rest):
        k_lo, k_hi, ok = krawczyk(system, w_lo[rest], w_hi[rest])
        inside = ok & np.all((k_lo > w_lo[rest]) & (k_hi < w_hi[rest]), axis=1)
        proven = rest[inside]
        status[proven] = 1
        s_lo[proven], s_hi[proven] = _tighten(system, k_lo[inside], k_hi[inside])
    return status, s_lo, s_hi, w_lo, w_hi


def _tighten(system: PoseSystem, lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A few Krawczyk steps X <- K(X) /\\ X: each keeps the zero X holds, and the boxes shrink
    quadratically while the Jacobian is well conditioned."""
    for _ in range(TIGHTEN):
        k_lo, k_hi, ok = krawczyk(system, lo, hi)
        k_lo, k_hi = np.maximum(k_lo, lo), np.minimum(k_hi, hi)
        keep = ok[:, None] & (k_lo <= k_hi)
        lo, hi = np.where(keep, k_lo, lo), np.where(keep, k_hi, hi)
    return lo, hi


def _halves(lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The 2^d children of each box, cut at the (float) centre: they cover the box exactly."""
    n, d = lo.shape
    mid = np.minimum(np.maximum(0.5 * lo + 0.5 * hi, lo), hi)
    bits = (np.arange(1 << d)[:, None] >> np.arange(d)[None, :]) & 1  # child order as the trees'
    c_lo = np.where(bits[None] == 1, mid[:, None, :], lo[:, None, :])
    c_hi = np.where(bits[None] == 1, hi[:, None, :], mid[:, None, :])
    return c_lo.reshape(-1, d), c_hi.reshape(-1, d)


def _distinct(model: PoseAspectModel, system: PoseSystem, found, root: np.ndarray, periodic: np.ndarray):
    """The distinct solutions among the proven boxes, inside the root box; and the boxes that
    could not be settled (an enclosure across the root's boundary, or overlapping enclosures of
    boxes that do not hold each other's)."""
    period = root[:, 1] - root[:, 0]
    entries, left = [], []
    for s_lo, s_hi, w_lo, w_hi in found:
        turns = np.where(periodic, np.floor((0.5 * (s_lo + s_hi) - root[:, 0]) / period), 0.0)
        shift = turns * period
        s_lo, s_hi, w_lo, w_hi = s_lo - shift, s_hi - shift, w_lo - shift, w_hi - shift
        inside = np.all(periodic | ((s_lo >= root[:, 0]) & (s_hi <= root[:, 1])))
        outside = np.any(~periodic & ((s_hi < root[:, 0]) | (s_lo > root[:, 1])))
        if outside:
            continue
        if not inside:
            left.append((s_lo[None], s_hi[None]))
            continue
        entries.append((s_lo, s_hi, w_lo, w_hi))
    parent = list(range(len(entries)))

    def find(a):
        while parent[a] != a:
            a = parent[a]
        return a

    for i in range(len(entries)):
        for j in range(i + 1, len(entries)):
            for shift in _shifts(periodic, period):
                a, b = entries[i], entries[j]
                if np.any((a[1] < b[0] + shift) | (b[1] + shift < a[0])):
                    continue  # disjoint enclosures: distinct zeros
                if _holds(b[2] + shift, b[3] + shift, a[0], a[1]) or _holds(a[2], a[3], b[0] + shift, b[1] + shift):
                    parent[find(j)] = find(i)
                else:
                    left.append((np.minimum(a[0], b[0] + shift)[None], np.maximum(a[1], b[1] + shift)[None]))
    classes = system.classes_of_boxes  # the joints may decide the sheet
    groups: dict[int, list[int]] = {}
    for i in range(len(entries)):
        groups.setdefault(find(i), []).append(i)
    solutions = []
    for members in groups.values():
        s_lo, s_hi, _, _ = min((entries[i] for i in members), key=lambda e: float(np.sum(e[1] - e[0])))
        cls = int(classes(s_lo[None], s_hi[None])[0])
        if cls < -1:
            continue  # certified in none of the model's classes: not one of its configurations
        solutions.append(Solution(_polish(system, s_lo, s_hi), s_lo, s_hi, cls))
    solutions.sort(key=lambda s: (s.cls if s.cls >= 0 else len(model.classes), *s.pose[::-1]))
    return solutions, left


def _shifts(periodic: np.ndarray, period: np.ndarray) -> list[np.ndarray]:
    """Whole-period offsets to compare enclosures across the seam of each periodic axis."""
    out = [np.zeros(len(period))]
    for axis in np.flatnonzero(periodic):
        out += [o + sign * period[axis] * (np.arange(len(period)) == axis) for o in list(out) for sign in (-1, 1)]
    return out


def _holds(lo: np.ndarray, hi: np.ndarray, in_lo: np.ndarray, in_hi: np.ndarray) -> bool:
    return bool(np.all((lo <= in_lo) & (in_hi <= hi)))


def _polish(system: PoseSystem, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """A floating-point pose in the enclosure: Newton's method from its centre, kept only while it
    stays inside (the enclosure is the proof; this is the number to report)."""
    x = 0.5 * (lo + hi)
    for _ in range(8):
        with np.errstate(all="ignore"):
            try:
                step = np.linalg.solve(system.jacobian(x[None])[0], system.values(x[None])[0])
            except np.linalg.LinAlgError:
                break
        nxt = x - step
        if not (np.all(np.isfinite(nxt)) and np.all((nxt >= lo) & (nxt <= hi))) or np.array_equal(nxt, x):
            break
        x = nxt
    return x
