"""Vectorised interval arithmetic on numpy float64 arrays with outward rounding.

An ``Interval`` holds two float64 arrays ``lo <= hi`` of one (broadcast) shape; every operation
works elementwise on whole arrays, so a box test runs once per paving level, not once per box.

Soundness: the result of every operation encloses the exact real range of the operation over
the input intervals, despite floating-point rounding. Assumptions and how:

* ``+ - * /`` and ``sqrt`` are correctly rounded (IEEE 754 binary64, round-to-nearest, as numpy
  does on x86-64 SSE/AVX and AArch64), so the exact result lies within one ulp of the computed
  one, and moving each bound outward by at least one ulp (``_down`` / ``_up``: 1 to 2 ulps,
  like ``np.nextafter`` but ten times cheaper) is enough. Exact results are widened too.
* ``sin``, ``cos`` and ``hypot`` are *not* correctly rounded by libm / numpy's SIMD code. We
  assume their error is below 3 ulps of the result (measured: below 0.6 ulp for numpy 2.4 on
  AVX-512, arguments up to 1e300) and widen each bound by ``MARGIN_ULPS * 2**-52 * |v|`` (4 to
  8 ulps of the value v) plus an absolute floor: ``4 * 2**-53`` for sin/cos (values in [-1, 1]:
  covers absolute errors of results near 0), the smallest subnormal for hypot. sin/cos results
  are then clipped to [-1, 1].
* Interior extrema of sin/cos (at pi/2 + k pi, resp. k pi) are located from ``x / pi`` in float
  arithmetic and included when they lie inside the interval *or within a bound on the rounding
  error of that quotient*: including too much is sound, too little is not (for |x| ~ 2e16 the
  bare quotient does miss extrema). Near an extremum the function is flat, so this costs no
  tightness; beyond |x| ~ 1e15 a non-degenerate interval degrades to [-1, 1] (a point [x, x]
  stays narrow).

Bounds may be infinite (division by an interval containing 0 gives [-inf, inf] there; ``mid``
needs finite bounds). NaN bounds mark an empty result (``sqrt`` of an interval entirely below 0)
and propagate through every operation.
"""
from __future__ import annotations

import numpy as np

MARGIN_ULPS = 4
TRIG_FLOOR = 4 * 2.0**-53          # absolute error floor for sin/cos values in [-1, 1]
_MAX = np.finfo(np.float64).max
_ULP_REL = 2.0**-52                # ulp(x) <= |x| * 2**-52 for every normal x
_TINY = 2.0**-1074                 # smallest subnormal: the ulp of every subnormal
_CLIP_CHECK = 1024                 # from this many values _down / _up look for infinities before clipping

__all__ = ["Interval", "sqr", "sqrt", "sin", "cos", "cos_sin", "hypot", "hull", "MARGIN_ULPS"]


def _down(x):
    """A float at least one ulp below x: a lower bound for any real that rounds to x.

    Same guarantee as np.nextafter(x, -inf) (one ulp of x is at most |x| * 2**-52, the smallest
    subnormal covers underflow, and subtracting at least one ulp cannot round back up to x) at
    a tenth of the cost; it moves 1 to 2 ulps. An overflowed x = +inf (a real >= MAX) gives a
    finite bound, as nextafter does.
    """
    y = np.minimum(x, _MAX) if _may_reach(x, np.inf) else x
    return _step(y, np.abs(y), np.subtract)


def _up(x):
    """A float at least one ulp above x (mirror of _down)."""
    y = np.maximum(x, -_MAX) if _may_reach(x, -np.inf) else x
    return _step(y, np.abs(y), np.add)


def _may_reach(x, end: float) -> bool:
    """False when x is a float64 array whose values are all finite on the side of `end` (+inf or
    -inf), so that clipping it to [-MAX, MAX] on that side would return its very values: on a
    large array a reduction costs a seventh of np.minimum / np.maximum with a scalar (numpy's slow
    loop for a scalar operand); a small one, or another type (which the clip makes float64), is
    clipped (True). NaN makes the reduction NaN: True."""
    if type(x) is not np.ndarray or x.size < _CLIP_CHECK or x.dtype != np.float64:
        return True
    return not (x.max() < end) if end > 0 else not (x.min() > end)


def _step(y, t, move):
    """move(y, |y| * 2**-52 + TINY), in place on t = |y|, which the caller owns (y may be the
    caller's argument: it is only read; the same operations in the same order as the expression:
    a hot path of every interval operation)."""
    if not t.ndim:
        return move(y, t * _ULP_REL + _TINY)
    t *= _ULP_REL
    t += _TINY
    return move(y, t, out=t)


def _hull_of(cands, a, b):
    """Outward-rounded hull of the four endpoint products (or quotients) of a and b.

    A NaN candidate comes from 0 * inf or inf / inf; counting it as 0 only widens the hull,
    and the other candidates still bound the range. NaN (empty) operands give NaN bounds.
    """
    def lo_hi(c):
        return (np.minimum(np.minimum(c[0], c[1]), np.minimum(c[2], c[3])),
                np.maximum(np.maximum(c[0], c[1]), np.maximum(c[2], c[3])))
    c0, c1, c2, c3 = cands
    if not np.ndim(c0):
        lo, hi = lo_hi(cands)
        nan = np.isnan(lo) or np.isnan(hi)
    else:  # in place on the candidates, which are ours: min and max are exact, so the same values
        lo = np.minimum(c0, c1)
        np.minimum(lo, np.minimum(c2, c3), out=lo)
        nan = lo.size and np.isnan(lo.min())  # a NaN candidate makes both lo and hi NaN
        if not nan:
            hi = np.maximum(c0, c1, out=c0)
            np.maximum(hi, np.maximum(c2, c3, out=c2), out=hi)
    if nan:            # rare, so off the fast path
        lo, hi = lo_hi([np.where(np.isnan(c), 0.0, c) for c in cands])
        empty = np.isnan(a.lo) | np.isnan(a.hi) | np.isnan(b.lo) | np.isnan(b.hi)
        lo, hi = np.where(empty, np.nan, lo), np.where(empty, np.nan, hi)
    return Interval._of(_down(lo), _up(hi))


def _as_interval(x) -> Interval:
    return x if isinstance(x, Interval) else Interval.point(x)


class Interval:
    """Immutable array of closed intervals [lo, hi] (float64, broadcast to one shape)."""

    __slots__ = ("lo", "hi")
    __array_ufunc__ = None          # make numpy defer: ndarray * Interval -> Interval.__rmul__

    def __init__(self, lo, hi):
        lo, hi = np.broadcast_arrays(np.asarray(lo, dtype=np.float64),
                                     np.asarray(hi, dtype=np.float64))
        object.__setattr__(self, "lo", lo)
        object.__setattr__(self, "hi", hi)

    def __setattr__(self, name, value):
        raise AttributeError("Interval is immutable")

    @staticmethod
    def _of(lo, hi) -> Interval:
        """Interval(lo, hi) without the conversions when lo and hi are float64 arrays of one shape."""
        if not (type(lo) is np.ndarray and type(hi) is np.ndarray and lo.shape == hi.shape
                and lo.dtype == hi.dtype == np.float64):
            return Interval(lo, hi)
        out = object.__new__(Interval)
        object.__setattr__(out, "lo", lo)
        object.__setattr__(out, "hi", hi)
        return out

    @staticmethod
    def point(x) -> Interval:
        """Degenerate interval [x, x] (exact: x is already a float64); its lo is its hi, which
        products recognise (two candidates instead of four: the same values)."""
        x = np.asarray(x, dtype=np.float64)
        return Interval._of(x, x)

    @property
    def shape(self):
        return self.lo.shape

    @property
    def width(self) -> np.ndarray:
        """hi - lo, rounded up (an upper bound for the exact width)."""
        with np.errstate(all="ignore"):
            return _up(self.hi - self.lo)

    @property
    def mid(self) -> np.ndarray:
        """A point inside the interval near its centre (no overflow for huge bounds)."""
        with np.errstate(all="ignore"):
            return np.minimum(np.maximum(0.5 * self.lo + 0.5 * self.hi, self.lo), self.hi)

    def contains(self, x) -> np.ndarray:
        """Boolean array: lo <= x <= hi."""
        return (self.lo <= x) & (x <= self.hi)

    def inflate(self, eps) -> Interval:
        """[lo - eps, hi + eps], rounded outward."""
        with np.errstate(all="ignore"):
            return Interval(_down(self.lo - eps), _up(self.hi + eps))

    def __getitem__(self, idx) -> Interval:
        return Interval(self.lo[idx], self.hi[idx])

    def take(self, index: np.ndarray) -> Interval:
        """The intervals at `index` along the last axis (np.take: each box's entry of a table)."""
        return Interval._of(np.take(self.lo, index, axis=-1), np.take(self.hi, index, axis=-1))

    def __reduce__(self):
        return (Interval, (self.lo, self.hi))

    def __len__(self):
        return len(self.lo)

    def __repr__(self):
        return f"Interval(lo={self.lo!r}, hi={self.hi!r})"

    def __neg__(self) -> Interval:
        return Interval._of(-self.hi, -self.lo)

    def __add__(self, other) -> Interval:
        b = _as_interval(other)
        with np.errstate(all="ignore"):
            return Interval._of(_down(self.lo + b.lo), _up(self.hi + b.hi))

    __radd__ = __add__

    def __sub__(self, other) -> Interval:
        b = _as_interval(other)
        with np.errstate(all="ignore"):
            return Interval._of(_down(self.lo - b.hi), _up(self.hi - b.lo))

    def __rsub__(self, other) -> Interval:
        return _as_interval(other) - self

    def __mul__(self, other) -> Interval:
        a, b = self, _as_interval(other)
        if a.lo is a.hi:
            a, b = b, a
        with np.errstate(all="ignore"):
            if b.lo is b.hi and a.lo.ndim:  # times a point x: the hull of lo x and hi x
                p, q = a.lo * b.lo, a.hi * b.lo
                lo = np.minimum(p, q)
                if not (lo.size and np.isnan(lo.min())):
                    return Interval._of(_down(lo), _up(np.maximum(p, q, out=p)))
            return _hull_of([a.lo * b.lo, a.lo * b.hi, a.hi * b.lo, a.hi * b.hi], a, b)

    __rmul__ = __mul__

    def __truediv__(self, other) -> Interval:
        """Quotient; [-inf, inf] wherever the divisor contains 0."""
        a, b = self, _as_interval(other)
        with np.errstate(all="ignore"):
            q = _hull_of([a.lo / b.lo, a.lo / b.hi, a.hi / b.lo, a.hi / b.hi], a, b)
        zero = (b.lo <= 0) & (b.hi >= 0)
        if not zero.any():
            return q
        return Interval(np.where(zero, -np.inf, q.lo), np.where(zero, np.inf, q.hi))

    def __rtruediv__(self, other) -> Interval:
        return _as_interval(other) / self


def _mig_mag(a: Interval):
    """Smallest and largest |x| over each interval."""
    alo, ahi = np.abs(a.lo), np.abs(a.hi)
    straddles = (a.lo < 0) & (a.hi > 0)
    return np.where(straddles, 0.0, np.minimum(alo, ahi)), np.maximum(alo, ahi)


def sqr(a) -> Interval:
    """Exact range of x**2 (lower bound 0 when the interval contains 0), tighter than a * a."""
    a = _as_interval(a)
    mig, mag = _mig_mag(a)
    with np.errstate(all="ignore"):
        return Interval(np.maximum(_down(mig * mig), 0.0), _up(mag * mag))


def sqrt(a) -> Interval:
    """Square root on the domain part x >= 0; NaN bounds where the interval is entirely < 0."""
    a = _as_interval(a)
    with np.errstate(all="ignore"):
        lo = np.maximum(_down(np.sqrt(np.maximum(a.lo, 0.0))), 0.0)
        hi = _up(np.sqrt(a.hi))
    return Interval(np.where(a.hi < 0, np.nan, lo), hi)


def _widen(v, floor):
    """Safety margin for a not correctly rounded libm result v: at least MARGIN_ULPS ulps of v
    (|v| * 2**-52 >= ulp(v); cheaper than np.spacing) plus an absolute floor."""
    return np.abs(v) * (MARGIN_ULPS * _ULP_REL) + floor


def _sinusoids(a: Interval, pairs) -> list[Interval]:
    """Range of each f (sin or cos) of `pairs` (f, shift) over a; f's extrema lie at
    x = (k + shift) pi, a maximum for even k.

    k_lo..k_hi brackets every integer k with (k + shift) pi in [lo, hi], widened by ``err``, a
    bound on the rounding error of t = x / pi - shift (float pi, division and subtraction:
    below 3.1 * 2**-52 * max(|x / pi|, 1); we take 8 of those units). x / pi and err are
    computed once for every f of the pairs.
    """
    out = []
    with np.errstate(all="ignore"):
        u_lo, u_hi = a.lo / np.pi, a.hi / np.pi
        err_lo = np.maximum(np.abs(u_lo), 1.0) * (8 * _ULP_REL)
        err_hi = np.maximum(np.abs(u_hi), 1.0) * (8 * _ULP_REL)
        proper = a.hi > a.lo                  # a point [x, x] has no interior extremum
        for f, shift in pairs:
            k_lo = np.ceil(u_lo - shift - err_lo)
            k_hi = np.floor(u_hi - shift + err_hi)
            several = proper & (k_hi > k_lo)      # also for infinite bounds (err is inf there)
            one = proper & (k_hi == k_lo)
            even = np.floor(0.5 * k_lo) * 2.0 == k_lo
            has_max = several | (one & even)
            has_min = several | (one & ~even)
            v_lo, v_hi = f(a.lo), f(a.hi)
            vmin, vmax = np.minimum(v_lo, v_hi), np.maximum(v_lo, v_hi)
            lo = np.where(has_min, -1.0, np.maximum(vmin - _widen(vmin, TRIG_FLOOR), -1.0))
            hi = np.where(has_max, 1.0, np.minimum(vmax + _widen(vmax, TRIG_FLOOR), 1.0))
            out.append(Interval(lo, hi))
    return out


def sin(a) -> Interval:
    """Exact range of sin over each interval (interior extrema at pi/2 + k pi), outward."""
    return _sinusoids(_as_interval(a), [(np.sin, 0.5)])[0]


def cos(a) -> Interval:
    """Exact range of cos over each interval (interior extrema at k pi), outward."""
    return _sinusoids(_as_interval(a), [(np.cos, 0.0)])[0]


def cos_sin(a) -> tuple[Interval, Interval]:
    """(cos(a), sin(a)), sharing the work they have in common (the same values as each alone)."""
    c, s = _sinusoids(_as_interval(a), [(np.cos, 0.0), (np.sin, 0.5)])
    return c, s


def hypot(a, b) -> Interval:
    """Exact range of sqrt(x**2 + y**2) for independent x in a, y in b (no overflow)."""
    amig, amag = _mig_mag(_as_interval(a))
    bmig, bmag = _mig_mag(_as_interval(b))
    with np.errstate(all="ignore"):
        # an overflowed lower value (inf) stands for something >= MAX: lower it to MAX first
        vlo, vhi = np.minimum(np.hypot(amig, bmig), _MAX), np.hypot(amag, bmag)
        return Interval(np.maximum(vlo - _widen(vlo, _TINY), 0.0), vhi + _widen(vhi, _TINY))


def hull(a, b) -> Interval:
    """Smallest interval containing both a and b (elementwise, broadcast)."""
    a, b = _as_interval(a), _as_interval(b)
    return Interval(np.minimum(a.lo, b.lo), np.maximum(a.hi, b.hi))
