"""1-D minimisers for many problems at once: golden section (vectorised), Brent, grid scan + golden.

Written here rather than taken from SciPy: the synthesis needs a vectorised golden section over
thousands of independent problems (one per orientation) and a plain Brent for scalar objectives.
"""

from __future__ import annotations

import math

import numpy as np

INVPHI = (math.sqrt(5.0) - 1.0) / 2.0


def golden_min(f, lo, hi, xtol: float = 1e-10):
    """Minimise f on [lo, hi] by golden-section search, for many independent problems at once.

    f maps an array of abscissae (the shape of lo/hi) to values; it is called once per step.
    Finds the minimum of a unimodal f to within xtol; returns (x, f(x)).
    """
    lo, hi = (np.array(v, float) for v in np.broadcast_arrays(lo, hi))
    width = float(np.max(hi - lo, initial=0.0))
    steps = math.ceil(math.log(xtol / width) / math.log(INVPHI)) if width > xtol else 0
    c, d = hi - INVPHI * (hi - lo), lo + INVPHI * (hi - lo)
    fc, fd = f(c), f(d)
    for _ in range(steps):
        left = fc <= fd  # the minimum is in [lo, d]
        hi, lo = np.where(left, d, hi), np.where(left, lo, c)
        x = np.where(left, hi - INVPHI * (hi - lo), lo + INVPHI * (hi - lo))
        fx = f(x)
        c, d, fc, fd = (
            np.where(left, x, d),
            np.where(left, c, x),
            np.where(left, fx, fd),
            np.where(left, fc, fx),
        )
    better = fc <= fd
    return np.where(better, c, d), np.where(better, fc, fd)


def brent_min(f, a: float, b: float, xtol: float = 1e-9, maxiter: int = 200) -> tuple[float, float]:
    """Minimise a scalar f on [a, b] by Brent's method: parabolic steps through the three best
    points when they behave, golden-section steps otherwise (fewer evaluations than pure golden
    section on smooth objectives, still safe on kinks). Returns (x, f(x))."""
    gold = 1.0 - INVPHI
    x = w = v = a + gold * (b - a)
    fx = fw = fv = float(f(x))
    d = e = 0.0
    for _ in range(maxiter):
        mid = 0.5 * (a + b)
        tol1 = 0.5 * xtol + 1e-15 * abs(x)
        if abs(x - mid) <= 2.0 * tol1 - 0.5 * (b - a):
            break
        golden = True
        if abs(e) > tol1:  # try a parabola through x, w, v
            r = (x - w) * (fx - fv)
            q = (x - v) * (fx - fw)
            p = (x - v) * q - (x - w) * r
            q = 2.0 * (q - r)
            p, q = (-p, q) if q > 0 else (p, -q)
            if abs(p) < abs(0.5 * q * e) and q * (a - x) < p < q * (b - x):
                e, d = d, p / q
                golden = False
                if (x + d) - a < 2.0 * tol1 or b - (x + d) < 2.0 * tol1:
                    d = math.copysign(tol1, mid - x)
        if golden:
            e = (a - x) if x >= mid else (b - x)
            d = gold * e
        u = x + (d if abs(d) >= tol1 else math.copysign(tol1, d))
        fu = float(f(u))
        if fu <= fx:
            a, b = (x, b) if u >= x else (a, x)
            v, fv, w, fw, x, fx = w, fw, x, fx, u, fu
        else:
            a, b = (a, u) if u >= x else (u, b)
            if fu <= fw or w == x:
                v, fv, w, fw = w, fw, u, fu
            elif fu <= fv or v in (x, w):
                v, fv = u, fu
    return x, fx


def scan_min(f, lo, hi, grid: int = 33, xtol: float = 1e-10):
    """Global-ish minimum on [lo, hi]: a grid scan brackets the best point, golden section refines.

    Problems are vectorised along the shape of lo/hi; f is called with that shape (plus a trailing
    grid axis for the scan).
    """
    lo, hi = (np.array(v, float) for v in np.broadcast_arrays(lo, hi))
    s = np.linspace(0.0, 1.0, grid)
    xs = lo[..., None] + (hi - lo)[..., None] * s
    fs = f(xs)
    i = np.argmin(fs, axis=-1)
    a = np.take_along_axis(xs, np.maximum(i - 1, 0)[..., None], -1)[..., 0]
    b = np.take_along_axis(xs, np.minimum(i + 1, grid - 1)[..., None], -1)[..., 0]
    x, fx = golden_min(f, a, b, xtol)
    xg = np.take_along_axis(xs, i[..., None], -1)[..., 0]
    fg = np.take_along_axis(fs, i[..., None], -1)[..., 0]
    better = fx <= fg
    return np.where(better, x, xg), np.where(better, fx, fg)
