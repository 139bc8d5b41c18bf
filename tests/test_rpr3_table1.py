"""Section 4 of Jiang & Gosselin: Table 1, the optimisers of cases 2-6 and the mean-area procedure."""

import math

import numpy as np
import pytest

from fivebar_cli.mechanisms.rpr3 import closed_form as rpr3
from fivebar_cli.mechanisms.rpr3 import paper as rpr3_paper
from fivebar_cli.mechanisms.rpr3 import synthesis
from fivebar_cli.numerics import optimize

T1, T2, T3, K, P1, P2, RHO1 = rpr3_paper.PAPER_SETUP
PHI1, PHI2 = math.radians(P1), math.radians(P2)
DESIGN = (T1, T2, T3, K)
COLUMNS = ("rho_max", "A1", "A2", "|A1 - A2|", "A_a", "dA_a")


def test_paper_setup_is_the_equilateral_unit_area_base():
    assert T1 * T3 / 2 == pytest.approx(1.0, rel=1e-15)
    assert math.hypot(T2, T3) == pytest.approx(T1, rel=1e-15)
    assert math.hypot(T2 - T1, T3) == pytest.approx(T1, rel=1e-15)


@pytest.mark.parametrize("case", sorted(rpr3_paper.PAPER_TABLE1))
def test_table1_cells_at_the_paper_rho_min(case):
    printed = rpr3_paper.PAPER_TABLE1[case]
    c = synthesis.evaluate_case(*DESIGN, PHI1, PHI2, printed[0], case)
    ours = (c.rho_max, c.a1, c.a2, c.diff_rounded, c.mean, c.fluctuation)
    for name, got, want in zip(COLUMNS, ours, printed[1:]):
        assert abs(got - want) <= 1.5e-6, f"case {case}, {name}: ours {got:.9f}, paper {want}"


@pytest.fixture(scope="module")
def cases():
    return synthesis.synthesize(*DESIGN, PHI1, PHI2, RHO1)


@pytest.mark.parametrize("case", [4, 5, 6])
def test_optimisers_find_the_printed_rho_min(cases, case):
    assert abs(cases[case - 1].rho_min - rpr3_paper.PAPER_TABLE1[case][0]) <= 1e-6


def test_optimisers_are_optimal(cases):
    rmax = lambda rho: rpr3.rho_max_range(*DESIGN, PHI1, PHI2, rho)  # noqa: E731
    mean = lambda rho: synthesis.mean_area(*DESIGN, PHI1, PHI2, rho, rmax(rho))  # noqa: E731
    h = 1e-4
    # case 2 / 3: the area at phi1 / phi2 (rho_max auto there) is locally maximal, and no grid value beats it
    for case, phi in ((2, PHI1), (3, PHI2)):
        rho = cases[case - 1].rho_min
        grid = np.linspace(0.0, float(rpr3.rho_min_limit(*DESIGN, phi)) * 0.999, 400)
        best = float(rpr3.area_auto(*DESIGN, phi, rho))
        assert best >= rpr3.area_auto(*DESIGN, phi, grid).max()
        assert best >= max(float(rpr3.area_auto(*DESIGN, phi, rho + dr)) for dr in (-h, h))
        # the paper's value is within 2e-5 (its optimiser stopped early: the area differs by < 1e-8)
        assert abs(rho - rpr3_paper.PAPER_TABLE1[case][0]) < 2e-5
        assert best - float(rpr3.area_auto(*DESIGN, phi, rpr3_paper.PAPER_TABLE1[case][0])) < 1e-8
    c4, c5, c6 = cases[3:6]
    assert c4.mean >= max(mean(c4.rho_min - h).mean, mean(c4.rho_min + h).mean)
    assert c4.mean >= max(c.mean for c in cases)
    assert abs(c5.a1 - c5.a2) < 1e-9
    assert c6.fluctuation <= min(mean(c6.rho_min - h).fluctuation, mean(c6.rho_min + h).fluctuation)
    assert c6.fluctuation <= min(c.fluctuation for c in cases)
    # the paper's remark: the curve of case 5 stays above that of case 6 over the whole range
    phis = np.linspace(PHI1, PHI2, 131)
    assert np.all(rpr3.area(*DESIGN, phis, c5.rho_min, c5.rho_max) > rpr3.area(*DESIGN, phis, c6.rho_min, c6.rho_max))


def test_mean_area_procedure():
    rho = 0.3
    rmax = float(rpr3.rho_max_range(*DESIGN, PHI1, PHI2, rho))
    m = synthesis.mean_area(*DESIGN, PHI1, PHI2, rho, rmax)
    steps = m.n // 25
    assert m.n % 25 == 0 and steps & (steps - 1) == 0 and m.n >= 50  # 25 doubled
    assert len(m.phis) == m.n + 1 and np.allclose(np.diff(m.phis), (PHI2 - PHI1) / m.n)

    def trapezoid(n):
        a = rpr3.area(*DESIGN, np.linspace(PHI1, PHI2, n + 1), rho, rmax)
        return (a.sum() - (a[0] + a[-1]) / 2) / n

    assert m.mean == pytest.approx(trapezoid(m.n), rel=1e-14)
    assert abs(trapezoid(m.n) - trapezoid(m.n // 2)) < 1e-6 * m.mean  # stopped at the first small change
    if m.n > 50:
        assert abs(trapezoid(m.n // 2) - trapezoid(m.n // 4)) >= 1e-6 * trapezoid(m.n // 2)
    assert m.fluctuation == pytest.approx(np.mean(np.abs(m.areas - m.mean)), rel=1e-14)
    # and the trapezoid mean is close to the integral (Simpson on a fine grid)
    n = 4096
    a = rpr3.area(*DESIGN, np.linspace(PHI1, PHI2, n + 1), rho, rmax)
    simpson = (a[0] + a[-1] + 4 * a[1:-1:2].sum() + 2 * a[2:-1:2].sum()) / (3 * n)
    assert m.mean == pytest.approx(simpson, rel=1e-5)


def test_golden_section_many_problems_at_once():
    targets = np.array([0.1, 0.37, 0.5, 0.93])
    calls = []

    def f(x):
        calls.append(np.shape(x))
        return (x - targets) ** 2 + np.abs(x - targets)  # a kink at the minimum too

    x, fx = optimize.golden_min(f, np.zeros(4), np.ones(4), xtol=1e-10)
    assert np.allclose(x, targets, atol=1e-9)
    assert all(shape == (4,) for shape in calls)
    x, _ = optimize.scan_min(lambda v: np.cos(3 * v) + 0.1 * v, 0.0, 6.0, grid=33)  # two local minima
    assert float(x) == pytest.approx(_argmin_ref(), abs=1e-7)


def test_brent_on_smooth_and_kinked_functions():
    calls = []

    def smooth(x):
        calls.append(x)
        return math.exp(x) - 3 * x  # minimum at log 3

    x, fx = optimize.brent_min(smooth, 0.0, 3.0, xtol=1e-10)
    # a smooth minimum is located to ~sqrt(machine epsilon): f changes by < 1 ulp closer in
    assert x == pytest.approx(math.log(3), abs=2e-8) and fx == pytest.approx(3 - 3 * math.log(3), abs=1e-15)
    assert len(calls) < 20  # parabolic steps: far fewer than golden section's ~50
    x, _ = optimize.brent_min(lambda v: abs(v - 0.123456789) + 0.01 * v * v, -1.0, 2.0, xtol=1e-11)
    assert x == pytest.approx(0.123456789, abs=1e-10)


def _argmin_ref():
    """Global minimiser of cos(3v) + 0.1 v on [0, 6] by a fine scan plus Newton."""
    v = np.linspace(0, 6, 600001)
    x = v[np.argmin(np.cos(3 * v) + 0.1 * v)]
    for _ in range(20):
        x -= (-3 * math.sin(3 * x) + 0.1) / (-9 * math.cos(3 * x))
    return x
