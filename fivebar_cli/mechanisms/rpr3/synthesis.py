"""Synthesis of the leg range over an orientation range (Jiang & Gosselin, section 4, Table 1).

For a minimal leg length rho_min, rho_max is the largest value keeping the singularity circle out
of the three annuli at every orientation of the range (`closed_form.rho_max_range`); the six cases
choose rho_min by six objectives: given, the optimum at phi1, at phi2, the largest mean area A_a,
A1 = A2, the smallest fluctuation dA_a. Angles in radians.

Cases 5 and 6 are searched only where W is not empty (at both ends for case 5, at every sampled
orientation for case 6): an empty W trivially has A1 = A2 = 0 and no fluctuation. A case whose
objective says nothing (a zero-width range, no equal areas, an optimum where W vanishes) carries
a `note`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from fivebar_cli.mechanisms.rpr3.closed_form import (
    area, centre_scale, optimal_rho_min, rho_max_range, rho_min_limit, singularity_circle,
)
from fivebar_cli.numerics.optimize import brent_min

OBJECTIVES = {  # case -> (short name for files, description)
    1: ("given", "given rho_min"),
    2: ("max_A1", "max A(phi1)"),
    3: ("max_A2", "max A(phi2)"),
    4: ("max_A_a", "max A_a"),
    5: ("equal_A1_A2", "min |A1 - A2|"),
    6: ("min_dA_a", "min dA_a"),
}


@dataclass(frozen=True)
class MeanArea:
    """Trapezoid mean A_a of A(phi) on [phi1, phi2], n steps, and dA_a = mean |A_i - A_a| over the n + 1 samples."""

    mean: float
    fluctuation: float
    n: int
    phis: np.ndarray = field(repr=False)
    areas: np.ndarray = field(repr=False)


def mean_area(t1, t2, t3, k, phi1, phi2, rho_min, rho_max, n0: int = 25, rtol: float = 1e-6) -> MeanArea:
    """A_a by the trapezoid rule on n equal steps, n doubled from n0 until two estimates differ by
    less than rtol (relative) or 1e-9 of the area of the largest singularity disc (absolute: W lies
    in that disc, and a W vanishing at one end of the range has no relative accuracy to reach);
    dA_a is then the mean of |A_i - A_a| over the n + 1 samples. A zero-width range gives n = 0."""
    if phi1 == phi2:
        a = np.atleast_1d(np.asarray(area(t1, t2, t3, k, phi1, rho_min, rho_max), float))
        return MeanArea(float(a[0]), 0.0, 0, np.array([phi1]), a)
    atol = 1e-9 * disc_area(t1, t2, t3, k, phi1, phi2)
    n = n0
    phis = np.linspace(phi1, phi2, n + 1)
    a = area(t1, t2, t3, k, phis, rho_min, rho_max)
    est = _trapezoid_mean(a)
    while True:
        if n > 1 << 20:
            raise ArithmeticError(f"mean area did not converge with n = {n}")
        mids = 0.5 * (phis[:-1] + phis[1:])
        merged, phis2 = np.empty(2 * n + 1), np.empty(2 * n + 1)
        merged[0::2], merged[1::2] = a, area(t1, t2, t3, k, mids, rho_min, rho_max)
        phis2[0::2], phis2[1::2] = phis, mids
        new, a, phis, n = _trapezoid_mean(merged), merged, phis2, 2 * n
        if abs(new - est) <= rtol * abs(new) + atol:  # an empty W (area 0) has converged
            return MeanArea(float(new), float(np.mean(np.abs(a - new))), n, phis, a)
        est = new


def disc_area(t1, t2, t3, k, phi1, phi2) -> float:
    """Area of the larger singularity disc at the ends of the range: W lies in it (a scale for tolerances)."""
    radius = max(float(singularity_circle(t1, t2, t3, k, p)[1]) for p in (phi1, phi2))
    return float(np.pi * radius * radius)


EMPTY = 1e-12  # relative to disc_area: a smaller W is rounding noise, i.e. empty


def _trapezoid_mean(a):
    n = a.shape[-1] - 1
    return (a[..., 1:-1].sum(-1) + 0.5 * (a[..., 0] + a[..., -1])) / n


@dataclass(frozen=True)
class Case:
    """One row of Table 1: a minimal leg length, the rho_max safe over the range, and the areas."""

    number: int
    objective: str
    rho_min: float
    rho_max: float
    a1: float
    a2: float
    mean: float
    fluctuation: float
    n: int
    note: str = ""  # why the objective did not choose this rho_min (degenerate), if it did not

    @property
    def diff_rounded(self) -> float:
        """|A1 - A2| as printed in the paper: the difference of A1 and A2 rounded to 6 decimals."""
        return abs(round(self.a1, 6) - round(self.a2, 6))


def evaluate_case(t1, t2, t3, k, phi1, phi2, rho_min, number=0, objective="", note="") -> Case:
    """All Table-1 quantities for one rho_min (rho_max from rho_max_range)."""
    rho_max = float(rho_max_range(t1, t2, t3, k, phi1, phi2, rho_min))
    a1, a2 = (float(area(t1, t2, t3, k, p, rho_min, rho_max)) for p in (phi1, phi2))
    m = mean_area(t1, t2, t3, k, phi1, phi2, rho_min, rho_max)
    empty = [name for name, a in (("phi1", a1), ("phi2", a2)) if a <= EMPTY * disc_area(t1, t2, t3, k, phi1, phi2)]
    if empty and not note:
        note = f"W is empty at {' and '.join(empty)}"
    return Case(number, objective, float(rho_min), rho_max, a1, a2, m.mean, m.fluctuation, m.n, note)


def synthesize(t1, t2, t3, k, phi1, phi2, rho_min, grid: int = 17, xtol: float = 1e-10) -> list[Case]:
    """The six cases of section 4.1: given rho_min, optimum at phi1, at phi2, max A_a, A1 = A2,
    min dA_a; rho_min is searched in [0, rho_min_limit at the smaller singularity circle)."""
    pw = phi1 if centre_scale(k, phi1) <= centre_scale(k, phi2) else phi2  # the smaller singularity circle
    lim = float(rho_min_limit(t1, t2, t3, k, pw)) * (1.0 - 1e-9)

    def rmax(rho):
        return rho_max_range(t1, t2, t3, k, phi1, phi2, rho)

    def minimise(f, xs, fs):  # a grid scan brackets the best point, Brent's method refines it
        i = int(np.argmin(fs))
        x, fx = brent_min(f, xs[max(i - 1, 0)], xs[min(i + 1, len(xs) - 1)], xtol)
        return x if fx <= fs[i] else float(xs[i])

    means: dict[float, MeanArea] = {}  # cases 4 and 6 scan the same grid

    def mean(rho):
        rho = float(rho)
        if rho not in means:
            means[rho] = mean_area(t1, t2, t3, k, phi1, phi2, rho, rmax(rho))
        return means[rho]

    def ends(rho):
        r = rmax(rho)
        return float(area(t1, t2, t3, k, phi1, rho, r)), float(area(t1, t2, t3, k, phi2, rho, r))

    tiny = EMPTY * disc_area(t1, t2, t3, k, phi1, phi2)
    rho = {1: float(rho_min)}
    rho[2] = float(optimal_rho_min(t1, t2, t3, k, phi1, 33, xtol)[0])
    rho[3] = float(optimal_rho_min(t1, t2, t3, k, phi2, 33, xtol)[0])
    xs = np.linspace(0.0, lim, grid)
    rho[4] = minimise(lambda r: -mean(r).mean, xs, [-mean(x).mean for x in xs])
    notes = {}
    if phi1 == phi2:
        rho[5] = rho[6] = rho[4]
        notes[5] = "degenerate: phi1 = phi2, so A1 = A2 for every rho_min (rho_min of case 4)"
        notes[6] = "degenerate: phi1 = phi2, so dA_a = 0 for every rho_min (rho_min of case 4)"
    else:
        rho[5], notes[5] = _equal_areas(ends, np.linspace(0.0, lim, 4 * grid), rho[4], xtol, tiny)
        rho[6], notes[6] = _least_fluctuation(mean, minimise, xs, rho[4], tiny)
    return [evaluate_case(t1, t2, t3, k, phi1, phi2, rho[i], i, OBJECTIVES[i][1], notes.get(i, ""))
            for i in range(1, 7)]


def _equal_areas(ends, xs, fallback: float, xtol: float, tiny: float) -> tuple[float, str]:
    """Case 5: a rho_min with A1 = A2 and W non-empty at both ends (the one with the largest W).

    Roots of A1 - A2 are bracketed by sign changes on the grid `xs`, among grid points where W is
    non-empty at both ends, and refined by Brent's method on |A1 - A2|. Without a root, the
    smallest |A1 - A2| over those points, with a note."""
    a = np.array([ends(x) for x in xs])
    ok = (a[:, 0] > tiny) & (a[:, 1] > tiny)
    if not ok.any():
        return fallback, "degenerate: W is empty at phi1 or phi2 for every rho_min (rho_min of case 4)"
    d = a[:, 0] - a[:, 1]

    def gap(rho):
        a1, a2 = ends(rho)
        return abs(a1 - a2) if a1 > tiny and a2 > tiny else np.inf

    best, best_area = None, -1.0
    for i in np.flatnonzero(ok[:-1] & ok[1:] & (d[:-1] * d[1:] <= 0)):
        x, _ = brent_min(gap, xs[i], xs[i + 1], xtol)
        if min(ends(x)) > best_area:
            best, best_area = x, min(ends(x))
    if best is not None:
        return float(best), ""
    i = int(np.argmin(np.where(ok, np.abs(d), np.inf)))
    x, fx = brent_min(gap, xs[max(i - 1, 0)], xs[min(i + 1, len(xs) - 1)], xtol)
    x = x if fx <= abs(d[i]) else float(xs[i])
    return x, f"no rho_min gives A1 = A2 with W non-empty at both ends: closest |A1 - A2| = {gap(x):.6g}"


def _least_fluctuation(mean, minimise, xs, fallback: float, tiny: float) -> tuple[float, str]:
    """Case 6: the smallest dA_a among rho_min where W is non-empty at every sampled orientation."""
    means = [mean(x) for x in xs]
    ok = np.array([m.areas.min() > tiny for m in means])
    if not ok.any():
        return fallback, "degenerate: W is empty somewhere in the range for every rho_min (rho_min of case 4)"

    def fluctuation(rho):
        m = mean(rho)
        return m.fluctuation if m.areas.min() > tiny else np.inf

    fs = np.where(ok, [m.fluctuation for m in means], np.inf)
    i = int(np.argmin(fs))
    x = minimise(fluctuation, xs, fs)
    if i == len(xs) - 1 or not ok[i + 1]:
        return x, ("degenerate: dA_a only decreases as W shrinks towards empty; this is the edge of the "
                   "rho_min range where W is non-empty")
    return x, ""
