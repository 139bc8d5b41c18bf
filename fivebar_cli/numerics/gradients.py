"""First-order forward differentiation on outward-rounded intervals, for mean-value forms.

A `Dual` holds an enclosure of a function's value over a box and of each partial derivative over
the same box (`numerics/interval.py` arithmetic, so both are sound). By the mean-value theorem,
for f differentiable on the (convex) box X and its centre m,

    f(X) is within f(m) + sum_k df/dx_k(X) (X_k - m_k),

whose excess over the true range shrinks with the square of the box width, where the natural
enclosure's shrinks only linearly: near a zero of f this is what decides its sign. A function is
written once with `+ - *`, `sqr`, `sqrt`, `sin`, `cos` of this module and evaluated on `Dual`s
(value and gradient over the box) or on plain `Interval`s (the value at the centre).
A zero partial derivative is stored as None, so constants and untouched variables cost nothing.
"""

from __future__ import annotations

import numpy as np

from fivebar_cli.numerics import interval as iv
from fivebar_cli.numerics.interval import Interval

__all__ = ["Dual", "cos", "cos_sin", "mean_value", "negate_where", "sin", "sqr", "sqrt", "variables"]


def _add(a, b):
    if a is None:
        return b
    return a if b is None else a + b


def _scale(g, c):
    return None if g is None else g * c


class Dual:
    """An interval value and interval partial derivatives (None: zero), over a box."""

    __slots__ = ("v", "g")
    __array_ufunc__ = None  # numpy defers: ndarray * Dual -> Dual.__rmul__

    def __init__(self, v: Interval, g: tuple):
        self.v, self.g = v, g

    def _lift(self, other) -> "Dual":
        if isinstance(other, Dual):
            return other
        value = other if isinstance(other, Interval) else Interval.point(other)
        return Dual(value, (None,) * len(self.g))

    def __neg__(self) -> "Dual":
        return Dual(-self.v, tuple(None if g is None else -g for g in self.g))

    def __add__(self, other) -> "Dual":
        b = self._lift(other)
        return Dual(self.v + b.v, tuple(_add(p, q) for p, q in zip(self.g, b.g)))

    __radd__ = __add__

    def __sub__(self, other) -> "Dual":
        return self + (-self._lift(other))

    def __rsub__(self, other) -> "Dual":
        return self._lift(other) + (-self)

    def __mul__(self, other) -> "Dual":
        b = self._lift(other)
        return Dual(self.v * b.v, tuple(_add(_scale(p, b.v), _scale(q, self.v)) for p, q in zip(self.g, b.g)))

    __rmul__ = __mul__

    def __getitem__(self, idx) -> "Dual":
        """The value and partial derivatives at `idx` (a derivative still of a smaller shape, a
        constant of the variables, is first broadcast to the value's)."""
        shape = self.v.shape
        return Dual(self.v[idx], tuple(None if g is None else _broadcast(g, shape)[idx] for g in self.g))


def _broadcast(a: Interval, shape) -> Interval:
    return a if a.shape == shape else Interval(np.broadcast_to(a.lo, shape), np.broadcast_to(a.hi, shape))


def negate_where(a, mask):
    """-a where `mask` (broadcast), a elsewhere: exact, as negation is (Intervals or Duals)."""
    if isinstance(a, Dual):
        return Dual(negate_where(a.v, mask), tuple(None if g is None else negate_where(g, mask) for g in a.g))
    return Interval(np.where(mask, -a.hi, a.lo), np.where(mask, -a.lo, a.hi))


def _chain(a: Dual, value: Interval, slope: Interval) -> Dual:
    return Dual(value, tuple(_scale(g, slope) for g in a.g))


def sqr(a):
    """x^2 (the exact range for an interval)."""
    if isinstance(a, Dual):
        return _chain(a, iv.sqr(a.v), a.v * 2.0)
    return iv.sqr(a)


def sqrt(a):
    """sqrt x on x >= 0; its derivative 1 / (2 sqrt x) is unbounded where the value reaches 0."""
    if isinstance(a, Dual):
        root = iv.sqrt(a.v)
        return _chain(a, root, 0.5 / root)
    return iv.sqrt(a)


def sin(a):
    if isinstance(a, Dual):
        c, s = iv.cos_sin(a.v)
        return _chain(a, s, c)
    return iv.sin(a)


def cos(a):
    if isinstance(a, Dual):
        c, s = iv.cos_sin(a.v)
        return _chain(a, c, -s)
    return iv.cos(a)


def cos_sin(a):
    """(cos a, sin a), sharing their work (`interval.cos_sin`)."""
    if isinstance(a, Dual):
        c, s = iv.cos_sin(a.v)
        return _chain(a, c, -s), _chain(a, s, c)
    return iv.cos_sin(a)


def variables(lo: np.ndarray, hi: np.ndarray) -> list[Dual]:
    """The coordinates of boxes (m, d) as `Dual`s: each its interval and a unit gradient."""
    d = lo.shape[1]
    one = Interval.point(1.0)
    return [Dual(Interval(lo[:, k], hi[:, k]), tuple(one if j == k else None for j in range(d))) for k in range(d)]


def mean_value(f, lo: np.ndarray, hi: np.ndarray, *fixed):
    """Certified bounds (lo, hi) of f over boxes (m, d): its natural enclosure intersected with the
    mean-value form at the centre. `f` takes the d coordinates (Duals or Intervals), then `fixed`
    (arguments passed as they are), and returns one value, or a tuple of values (then a list of
    bounds). The caller makes sure f is differentiable on every box."""
    mid = 0.5 * (lo + hi)
    over = f(*variables(lo, hi), *fixed)
    at = f(*(Interval.point(mid[:, k]) for k in range(lo.shape[1])), *fixed)
    single = isinstance(over, Dual)
    out = []
    for value, centre in zip((over,) if single else over, (at,) if single else at):
        total = centre
        for k, g in enumerate(value.g):
            if g is not None:
                total = total + g * (Interval(lo[:, k], hi[:, k]) - Interval.point(mid[:, k]))
        with np.errstate(invalid="ignore"):
            low, high = np.maximum(value.v.lo, total.lo), np.minimum(value.v.hi, total.hi)
        out.append((np.where(np.isnan(low), value.v.lo, low), np.where(np.isnan(high), value.v.hi, high)))
    return out[0] if single else out
