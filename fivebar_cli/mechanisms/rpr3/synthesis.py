"""Synthesis of the leg range over an orientation range (Jiang & Gosselin, section 4, Table 1).

For a minimal leg length rho_min, rho_max is the largest value keeping the singularity circle out
of the three annuli at every orientation of the range (`closed_form.rho_max_range`); the six cases
choose rho_min by six objectives: given, the optimum at phi1, at phi2, the largest mean area A_a,
A1 = A2, the smallest fluctuation dA_a. Angles in radians.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from fivebar_cli.mechanisms.rpr3.closed_form import area, centre_scale, optimal_rho_min, rho_max_range, rho_min_limit
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
    less than rtol (relative); dA_a is then the mean of |A_i - A_a| over the n + 1 samples."""
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
        if abs(new - est) <= rtol * abs(new):  # '<=': an empty W (area 0) has converged
            return MeanArea(float(new), float(np.mean(np.abs(a - new))), n, phis, a)
        est = new


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

    @property
    def diff_rounded(self) -> float:
        """|A1 - A2| as printed in the paper: the difference of A1 and A2 rounded to 6 decimals."""
        return abs(round(self.a1, 6) - round(self.a2, 6))


def evaluate_case(t1, t2, t3, k, phi1, phi2, rho_min, number=0, objective="") -> Case:
    """All Table-1 quantities for one rho_min (rho_max from rho_max_range)."""
    rho_max = float(rho_max_range(t1, t2, t3, k, phi1, phi2, rho_min))
    a1, a2 = (float(area(t1, t2, t3, k, p, rho_min, rho_max)) for p in (phi1, phi2))
    m = mean_area(t1, t2, t3, k, phi1, phi2, rho_min, rho_max)
    return Case(number, objective, float(rho_min), rho_max, a1, a2, m.mean, m.fluctuation, m.n)


def synthesize(t1, t2, t3, k, phi1, phi2, rho_min, grid: int = 17, xtol: float = 1e-10) -> list[Case]:
    """The six cases of section 4.1: given rho_min, optimum at phi1, at phi2, max A_a, A1 = A2,
    min dA_a; rho_min is searched in [0, rho_min_limit at the smaller singularity circle)."""
    pw = phi1 if centre_scale(k, phi1) <= centre_scale(k, phi2) else phi2  # the smaller singularity circle
    lim = float(rho_min_limit(t1, t2, t3, k, pw)) * (1.0 - 1e-9)

    def rmax(rho):
        return rho_max_range(t1, t2, t3, k, phi1, phi2, rho)

    def minimise(f, n):  # a grid scan brackets the best point, Brent's method refines it
        xs = np.linspace(0.0, lim, n)
        fs = [f(x) for x in xs]
        i = int(np.argmin(fs))
        x, fx = brent_min(f, xs[max(i - 1, 0)], xs[min(i + 1, n - 1)], xtol)
        return x if fx <= fs[i] else float(xs[i])

    def mean(rho):
        return mean_area(t1, t2, t3, k, phi1, phi2, rho, rmax(rho))

    def gap(rho):
        r = rmax(rho)
        return abs(float(area(t1, t2, t3, k, phi1, rho, r)) - float(area(t1, t2, t3, k, phi2, rho, r)))

    rho = {1: float(rho_min)}
    rho[2] = float(optimal_rho_min(t1, t2, t3, k, phi1, 33, xtol)[0])
    rho[3] = float(optimal_rho_min(t1, t2, t3, k, phi2, 33, xtol)[0])
    rho[4] = minimise(lambda r: -mean(r).mean, grid)
    rho[5] = minimise(gap, 4 * grid)
    rho[6] = minimise(lambda r: mean(r).fluctuation, grid)
    return [evaluate_case(t1, t2, t3, k, phi1, phi2, rho[i], i, OBJECTIVES[i][1]) for i in range(1, 7)]
