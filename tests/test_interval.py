"""Property tests for fivebar_cli.numerics.interval against independent exact references.

Soundness: every enclosure contains the exact range, checked with fractions.Fraction (exact for
+ - * /) and mpmath at >= 60 significant digits (sqrt, sin, cos, hypot; plus mpmath.iv for the
sin/cos ranges). Tightness: bounds lie within a few ulps of the exact range, so that a stub
returning [-inf, inf] or [-1, 1] fails.
"""
import math
import operator
import pickle
import sys
from fractions import Fraction as F

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st
from mpmath import iv, mp

from fivebar_cli.numerics.interval import Interval, cos, hull, hypot, sin, sqr, sqrt

# 100 examples of up to 10 intervals each (about 550 intervals per property); an example costs ~7 ms,
# most of it drawing the nested strategies
SETTINGS = settings(max_examples=100, deadline=None)
INF = math.inf
EPS53 = 2.0**-53
MAX = sys.float_info.max


def down(x, n=1):
    for _ in range(n):
        x = math.nextafter(x, -INF)
    return float(x)


def up(x, n=1):
    for _ in range(n):
        x = math.nextafter(x, INF)
    return float(x)


def bounds(res, i):
    """Bounds of element i as Python floats (exact comparisons with Fraction and mpf)."""
    return float(res.lo[i]), float(res.hi[i])


def nearest(q):
    """Round an exact Fraction / mpf to the nearest float (+-inf on overflow)."""
    try:
        return float(q)
    except OverflowError:
        return INF if q > 0 else -INF


def near_lo(r, e, n=2):
    """Lower bound r is at most n ulps below the exact value e (clipped to the finite range;
    one more subnormal step in the lowest binades, where 2**-1074 is the whole ulp)."""
    return r >= down(min(nearest(e), MAX), n) - 2.0**-1074


def near_hi(r, e, n=2):
    return r <= up(max(nearest(e), -MAX), n) + 2.0**-1074


def dps_for(*xs):
    """Enough decimal digits to resolve x / pi for the largest |x| (argument reduction)."""
    return 60 + max(0, int(math.log10(max([abs(x) for x in xs] + [1.0]))))


# ---------------------------------------------------------------- strategies

@st.composite
def near_half_pi_multiple(draw):
    """Floats within 3 ulps of k pi / 2: the extrema of sin and cos, and their zeros."""
    k = draw(st.one_of(st.integers(-20, 20), st.integers(-10**6, 10**6),
                       st.integers(-10**16, 10**16)))
    with mp.workdps(80):
        x = float(k * mp.pi / 2)
    j = draw(st.integers(-3, 3))
    return down(x, -j) if j < 0 else up(x, j)


bound = st.one_of(
    st.floats(-10, 10),
    st.floats(-1e6, 1e6),
    st.floats(allow_nan=False, allow_infinity=False),          # includes 1e308 and subnormals
    st.floats(-1e-300, 1e-300),
    st.sampled_from([0.0, -0.0, 1.0, -1.0, 5e-324, 1e300, -1e300, math.pi, -math.pi]),
    near_half_pi_multiple(),
)
width = st.one_of(st.just(0.0), st.floats(0, 1e-12), st.floats(0, 7),
                  st.floats(6.2831, 6.2833), st.floats(0, 1e3))


@st.composite
def interval(draw, bounds=bound):
    """(lo, hi) with lo <= hi: two independent bounds, or a bound plus a width."""
    x = draw(bounds)
    if draw(st.booleans()):
        y = draw(bounds)
        return (min(x, y), max(x, y))
    y = x + draw(width)
    return (x, y) if math.isfinite(y) else (x, x)


def arrays(draw_list):
    lo, hi = zip(*draw_list)
    return Interval(np.array(lo), np.array(hi))


interval_lists = st.lists(interval(), min_size=1, max_size=10)
pair_lists = st.lists(st.tuples(interval(), interval()), min_size=1, max_size=10)
moderate = st.one_of(st.floats(-10, 10), st.floats(-1e6, 1e6),
                     near_half_pi_multiple().filter(lambda x: abs(x) < 1e6))
moderate_lists = st.lists(interval(moderate), min_size=1, max_size=10)


# ---------------------------------------------------------------- + - * / with exact fractions

def check_exact_binary(res, a, b, op, ulps=2):
    """Contains the exact range of op over the corners; within `ulps` of it."""
    for i, (ia, ib) in enumerate(zip(a, b)):
        vals = [op(F(x), F(y)) for x in ia for y in ib]
        emin, emax = min(vals), max(vals)
        lo, hi = bounds(res, i)
        assert lo <= emin and emax <= hi, (ia, ib, lo, hi)
        assert near_lo(lo, emin, ulps) and near_hi(hi, emax, ulps), (ia, ib, lo, hi)


@SETTINGS
@given(pair_lists)
def test_add_sub_mul_enclose_exact_range(pairs):
    a, b = [p[0] for p in pairs], [p[1] for p in pairs]
    A, B = arrays(a), arrays(b)
    check_exact_binary(A + B, a, b, operator.add)
    check_exact_binary(A - B, a, b, operator.sub)
    check_exact_binary(A * B, a, b, operator.mul)


@SETTINGS
@given(pair_lists)
def test_division_encloses_exact_range(pairs):
    a, b = [p[0] for p in pairs], [p[1] for p in pairs]
    res = arrays(a) / arrays(b)
    for i, (ia, ib) in enumerate(zip(a, b)):
        if ib[0] <= 0 <= ib[1]:
            assert res.lo[i] == -INF and res.hi[i] == INF
        else:
            check_exact_binary(res[i:i + 1], [ia], [ib], operator.truediv)


def test_division_by_interval_containing_zero():
    a = Interval([1.0, -1.0, 0.0, 1.0], [2.0, 1.0, 0.0, 2.0])
    b = Interval([-1.0, 0.0, -0.0, 0.5], [1.0, 3.0, 0.0, 4.0])
    res = a / b
    assert list(res.lo[:3]) == [-INF] * 3 and list(res.hi[:3]) == [INF] * 3
    assert down(0.25, 2) <= res.lo[3] <= 0.25 and 4.0 <= res.hi[3] <= up(4.0, 2)
    assert (1.0 / Interval(-1.0, 1.0)).lo == -INF


def test_negation_and_reflected_operators():
    a = Interval([1.0, -2.0], [3.0, 0.5])
    assert np.array_equal((-a).lo, [-3.0, -0.5]) and np.array_equal((-a).hi, [-1.0, 2.0])
    for left, right in [(2.0 + a, a + 2.0), (2.0 * a, a * 2.0),
                        (np.float64(2.0) * a, a * Interval.point(2.0)),
                        (np.array([2.0, 3.0]) * a, a * Interval.point([2.0, 3.0])),
                        (5.0 - a, Interval.point(5.0) - a), (1.0 / a, Interval.point(1.0) / a)]:
        assert isinstance(left, Interval)
        assert np.array_equal(left.lo, right.lo) and np.array_equal(left.hi, right.hi)
    res = 5.0 - a
    assert res.lo[0] <= 2.0 <= 4.0 <= res.hi[0] and res.hi[0] <= up(4.0)


def test_vectorised_equals_elementwise_and_broadcasts():
    rng = np.random.default_rng(0)
    lo = rng.uniform(-5, 5, (3, 1))
    A = Interval(lo, lo + rng.uniform(0, 2, (3, 1)))
    lo = rng.uniform(-5, 5, 4)
    B = Interval(lo, lo + rng.uniform(0, 8, 4))
    for f in [operator.add, operator.sub, operator.mul, operator.truediv, hypot, hull]:
        res = f(A, B)
        assert res.shape == (3, 4)
        for i in range(3):
            for j in range(4):
                one = f(A[i, 0], B[j])
                assert res.lo[i, j] == one.lo and res.hi[i, j] == one.hi
    for f in [sqr, sqrt, sin, cos]:
        res = f(B)
        for j in range(4):
            assert res.lo[j] == f(B[j]).lo and res.hi[j] == f(B[j]).hi
    assert (A + 1.0).shape == (3, 1) and Interval(0.0, np.ones(5)).shape == (5,)


# ---------------------------------------------------------------- sqr, sqrt

@SETTINGS
@given(interval_lists)
def test_sqr_exact_range(ivs):
    res = sqr(arrays(ivs))
    for i, (lo, hi) in enumerate(ivs):
        vals = [F(lo) ** 2, F(hi) ** 2] + ([F(0)] if lo < 0 < hi else [])
        emin, emax = min(vals), max(vals)
        rlo, rhi = bounds(res, i)
        assert rlo <= emin and emax <= rhi
        assert rlo >= 0.0 and near_lo(rlo, emin) and near_hi(rhi, emax)


def test_sqr_is_tighter_than_self_product():
    a = Interval(-2.0, 3.0)
    assert sqr(a).lo == 0.0 and (a * a).lo < -5.9


@SETTINGS
@given(interval_lists)
def test_sqrt_encloses_and_is_tight(ivs):
    res = sqrt(arrays(ivs))
    with mp.workdps(60):
        for i, (lo, hi) in enumerate(ivs):
            if hi < 0:
                assert np.isnan(res.lo[i]) and np.isnan(res.hi[i])
                continue
            emin, emax = mp.sqrt(max(lo, 0.0)), mp.sqrt(hi)
            rlo, rhi = bounds(res, i)
            assert rlo <= emin and emax <= rhi
            assert near_lo(rlo, emin) and near_hi(rhi, emax)


def test_nan_marks_empty_and_propagates():
    e = sqrt(Interval(-2.0, -1.0))
    for r in [e + 1.0, e * 2.0, 2.0 / e, sqr(e), sin(e), hypot(e, 1.0)]:
        assert np.isnan(r.lo) and np.isnan(r.hi)


# ---------------------------------------------------------------- sin, cos

TRIG = [(sin, mp.sin, 0.5), (cos, mp.cos, 0.0)]   # extrema at (k + shift) pi, max for even k


def trig_tol(e):
    """Allowed excess over the exact sin/cos bound e: the margin (4 * 2**-52 |e|, i.e. 4 to 8
    ulps, plus 4 * 2**-53) and libm's error."""
    return 10 * math.ulp(float(e)) + 5 * EPS53


def exact_trig_range(mf, shift, lo, hi):
    """Exact range (mpf) from the endpoint values and every extremum (k + shift) pi inside."""
    L, H = mp.mpf(lo), mp.mpf(hi)
    if H - L >= 2 * mp.pi:
        return mp.mpf(-1), mp.mpf(1)
    vals = [mf(L), mf(H)]
    k = mp.ceil(L / mp.pi - shift)
    while (k + shift) * mp.pi <= H:
        vals.append(mp.mpf((-1) ** int(k % 2)))
        k += 1
    return min(vals), max(vals)


def check_trig(ivs, tight):
    A = arrays(ivs)
    for f, mf, shift in TRIG:
        res = f(A)
        for i, (lo, hi) in enumerate(ivs):
            rlo, rhi = bounds(res, i)
            assert -1.0 <= rlo <= rhi <= 1.0
            with mp.workdps(dps_for(lo, hi)):
                emin, emax = exact_trig_range(mf, shift, lo, hi)
                interior = [lo + t * (hi - lo) for t in (0.25, 0.5, 0.75)]
                assert all(rlo <= mf(x) <= rhi for x in interior if lo <= x <= hi)
                assert rlo <= emin and emax <= rhi, (f.__name__, lo, hi, rlo, rhi)
                if tight:
                    assert rlo >= emin - trig_tol(emin) and rhi <= emax + trig_tol(emax)


@SETTINGS
@given(interval_lists)
def test_sin_cos_enclose_exact_range(ivs):
    check_trig(ivs, tight=False)


@SETTINGS
@given(moderate_lists)
def test_sin_cos_tight_for_moderate_arguments(ivs):
    check_trig(ivs, tight=True)


@SETTINGS
@given(moderate_lists)
def test_sin_cos_agree_with_mpmath_iv(ivs):
    A = arrays(ivs)
    old_dps, iv.dps = iv.dps, 60
    try:
        with mp.workdps(60):
            for f, ivf in [(sin, iv.sin), (cos, iv.cos)]:
                res = f(A)
                for i, (lo, hi) in enumerate(ivs):
                    ref = ivf(iv.mpf([lo, hi]))
                    emin, emax = mp.mpf(ref.a), mp.mpf(ref.b)
                    rlo, rhi = bounds(res, i)
                    assert rlo <= emin and emax <= rhi
                    assert rlo >= emin - trig_tol(emin) and rhi <= emax + trig_tol(emax)
    finally:
        iv.dps = old_dps


@settings(max_examples=150, deadline=None)  # three intervals an example
@given(near_half_pi_multiple(), near_half_pi_multiple(), st.integers(0, 3))
def test_sin_cos_extrema_at_interval_ends(x, y, n):
    """Endpoints within ulps of k pi / 2 (extrema or zeros), narrow or not."""
    check_trig([(x, up(x, n)), (down(y, n), y), (min(x, y), max(x, y))], tight=False)


@pytest.mark.parametrize("lo, hi", [
    (-2.579709441420336e+16, -2.5797094414203356e+16),    # found by search: sin
    (1.6686449003976872e+16, 1.6686449003976874e+16),
    (3.0472370255050292e+16, 3.0472370255050296e+16),     # cos
    (2.9362371246364252e+16, 2.9362371246364256e+16)])
def test_sin_cos_extremum_missed_by_float_quotient(lo, hi):
    """Width 2 or 4 < 2 pi with an extremum inside that float(x / pi) puts outside: only the
    rounding-error margin on the extremum search keeps the result sound."""
    check_trig([(lo, hi)], tight=False)


def test_sin_cos_known_extrema():
    half_pi = math.pi / 2                       # float pi/2 lies just below the true pi/2
    assert sin(Interval(half_pi, 2.0)).hi == 1.0 and sin(Interval(1.0, half_pi)).hi == 1.0
    assert sin(Interval(1.0, 2.0)).hi == 1.0 and sin(Interval(1.0, 1.5)).hi < 0.9975
    assert cos(Interval(3.0, 3.2)).lo == -1.0 and cos(Interval(-0.1, 0.1)).hi == 1.0
    assert cos(Interval(0.1, 3.0)).hi < 0.996 and cos(Interval(0.1, 3.0)).lo > -0.99
    assert sin(Interval(4.0, 5.0)).lo == -1.0 and sin(Interval(4.0, 4.5)).lo > -0.98


@pytest.mark.parametrize("lo, hi", [(0.0, 2 * math.pi), (-1e300, 1e300), (1e300, up(1e300)),
                                    (-INF, 0.0), (0.0, INF), (-INF, INF), (3.0, 10.0)])
def test_sin_cos_wide_unbounded_and_huge(lo, hi):
    for f in (sin, cos):
        res = f(Interval(lo, hi))
        assert res.lo == -1.0 and res.hi == 1.0


def test_sin_cos_degenerate_huge_argument_is_narrow():
    with mp.workdps(400):
        exact = mp.sin(mp.mpf(1e300))
    res = sin(Interval.point(1e300))
    assert float(res.lo) <= exact <= float(res.hi) and res.width < 1e-14


# ---------------------------------------------------------------- hypot

@SETTINGS
@given(pair_lists)
def test_hypot_exact_range(pairs):
    a, b = [p[0] for p in pairs], [p[1] for p in pairs]
    res = hypot(arrays(a), arrays(b))
    with mp.workdps(60):
        for i, (ia, ib) in enumerate(pairs):
            xs = list(ia) + ([0.0] if ia[0] < 0 < ia[1] else [])
            ys = list(ib) + ([0.0] if ib[0] < 0 < ib[1] else [])
            vals = [mp.sqrt(mp.mpf(x) ** 2 + mp.mpf(y) ** 2) for x in xs for y in ys]
            emin, emax = min(vals), max(vals)
            rlo, rhi = bounds(res, i)
            assert rlo <= emin and emax <= rhi, (ia, ib)
            tol = lambda e: 10 * math.ulp(float(e)) + 2 * math.ulp(0.0)   # margin: 4..8 ulps
            assert rlo >= emin - tol(emin) and rhi <= nearest(emax + tol(emax))


def test_hypot_straddling_zero_and_scalars():
    res = hypot(Interval(-3.0, 1.0), Interval(-0.5, 2.0))
    assert res.lo == 0.0 and 3.6 < math.sqrt(13.0) <= res.hi < 3.6056
    res = hypot(Interval(3.0, 3.0), 4.0)
    assert res.lo <= 5.0 <= res.hi and res.width < 1e-14
    assert hypot(Interval(1e300, 1e300), 1e300).hi < INF
    res = hypot(Interval(1.3e308, 1.3e308), 1.3e308)             # exact 1.84e308 > MAX
    assert 1.79e308 < res.lo <= MAX and res.hi == INF


# ---------------------------------------------------------------- small API

@SETTINGS
@given(interval_lists, st.floats(0, 1e3))
def test_width_mid_inflate_contains(ivs, eps):
    A = arrays(ivs)
    w, m, big = A.width, A.mid, A.inflate(eps)
    assert A.contains(m).all()
    for i, (lo, hi) in enumerate(ivs):
        exact, mi, (blo, bhi) = F(hi) - F(lo), float(m[i]), bounds(big, i)
        assert exact <= float(w[i]) and near_hi(float(w[i]), exact)
        assert lo <= mi <= hi
        assert abs(F(mi) - (F(lo) + F(hi)) / 2) <= F(math.ulp(max(abs(lo), abs(hi))))
        assert blo <= F(lo) - F(eps) and F(hi) + F(eps) <= bhi
        assert near_lo(blo, F(lo) - F(eps)) and near_hi(bhi, F(hi) + F(eps))


def test_contains_point_hull_getitem_immutable():
    assert Interval(1e308, 1.5e308).mid == 1.25e308 and Interval(-INF, INF).contains(0.0)
    a = Interval([0.0, 2.0], [1.0, 3.0])
    assert list(a.contains(1.0)) == [True, False] and list(a.contains(np.array([2.0, 2.0]))) == \
        [False, True]
    p = Interval.point([1.5, -2.0])
    assert np.array_equal(p.lo, p.hi) and p.lo.dtype == np.float64 and p.shape == (2,)
    h = hull(a, 5.0)
    assert np.array_equal(h.lo, [0.0, 2.0]) and np.array_equal(h.hi, [5.0, 5.0])
    h = hull(a[0], a[1])
    assert h.lo == 0.0 and h.hi == 3.0 and a[1:].shape == (1,)
    with pytest.raises(AttributeError):
        a.lo = np.zeros(2)
    b = pickle.loads(pickle.dumps(a))
    assert np.array_equal(b.lo, a.lo) and np.array_equal(b.hi, a.hi)
    assert Interval(1, 2).lo.dtype == np.float64


def test_overflow_and_infinite_bounds_stay_sound():
    big = Interval(1e308, 1e308)
    assert (big + big).hi == INF and 1.79e308 < (big + big).lo <= MAX     # exact: 2e308
    assert (big * -2.0).lo == -INF
    r = Interval(0.0, 1.0) * Interval(1.0, INF)           # 0 * inf must not poison the hull
    assert r.lo <= 0.0 and r.hi == INF
    r = Interval(0.0, 0.0) * Interval(-INF, INF)
    assert r.lo <= 0.0 <= r.hi and np.isfinite(r.lo) and np.isfinite(r.hi)
    r = Interval(1.0, INF) / Interval(1.0, INF)
    assert r.lo <= 0.0 and r.hi == INF
    tiny = Interval(1e-200, 1e-200)
    r = tiny * tiny                                         # underflows to 0: must straddle 1e-400
    assert r.lo <= 0.0 < r.hi
