"""The paper's own interval procedures (Chablat 2010, sections 3.2-3.4), as a baseline for Table 1.

They use plain interval arithmetic (`numerics/interval.py`, outward rounded), so they are sound but loose
(the det A check uses arccos/atan2 ranges without outward rounding: it can only withhold a 1, and
the property certified, "can be assembled", rests on the outward-rounded |B1B2| and C(alpha));
the tight tests of `boxtests.py` certify the same sets with fewer evaluations. Implemented as
printed, with the corrections listed in the README where the print is a typo (no sqrt in C(alpha),
atan2 for beta). With these choices every K of the paper's Table 1 is reproduced after truncation
to a whole percent (`analyses/kratio.printed_form`, and the README):

- joint space (DKP, 3.2 + 3.3): L = |B1B2| by interval arithmetic; -1 only if L > L3 + L4 (the
  print has no test for |B1B2| < |L3 - L4|); 1 if L > 0, C(alpha) = (L^2 + L3^2 - L4^2) / (2 L3 L)
  lies in [-1, 1], and det A = (b1 - p) x (b2 - p) of the solution P = B1 + L3 e^{i(beta + alpha)}
  excludes 0 ("the algorithm cannot define valid boxes where det(A) is equal to zero"); else 0.
- workspace (IKP, 3.4): M_i = |A_i P|; -1 if M_i > L_i + L_j or M_i < |L_i - L_j| on the whole
  box; 1 if all the strict inequalities of the print hold and C(beta_i) lies in [-1, 1]; else 0.
"""

from __future__ import annotations

import numpy as np

from fivebar_cli.numerics.interval import Interval, cos, hypot, sin, sqr
from fivebar_cli.numerics.ranges import direction_range
from fivebar_cli.numerics.verdict import verdict


# ---------------------------------------------------------------- Table 1 as printed

PAPER_DEPTHS = (5, 6, 7, 8, 9, 10)
M1_LENGTHS = (9.0, 8.0, 5.0, 5.0, 8.0)
M2_LENGTHS = (2.55, 2.3, 2.3, 2.3, 2.3)
PAPER_TABLE1 = {  # Chablat (2010), Table 1, in percent, depths 5..10
    ("jointspace", M1_LENGTHS): (99, 73, 40, 22, 13, 9),
    ("jointspace", M2_LENGTHS): (111, 83, 40, 18, 8, 4),
    ("workspace", M1_LENGTHS): (72, 45, 25, 13, 7, 3),
    ("workspace", M2_LENGTHS): (65, 37, 19, 10, 5, 2),
}


def is_paper_mechanism(m) -> bool:
    """Whether a five-bar is the paper's M1 or M2 (recognised by its lengths)."""
    return tuple(m.lengths.values()) in (M1_LENGTHS, M2_LENGTHS)


def printed_percent(m, space: str, depth: int) -> int | None:
    """The paper's printed K (percent) for this mechanism (recognised by its lengths), if any."""
    key = (space, tuple(m.lengths.values()))
    if key in PAPER_TABLE1 and depth in PAPER_DEPTHS:
        return PAPER_TABLE1[key][PAPER_DEPTHS.index(depth)]
    return None


# ---------------------------------------------------------------- the procedures


def _acos(c: Interval) -> Interval:
    """arccos of an interval clipped to [-1, 1] (decreasing, so the bounds swap)."""
    return Interval(np.arccos(np.clip(c.hi, -1, 1)), np.arccos(np.clip(c.lo, -1, 1)))


def paper_joint_space_test(m):
    """The DKP procedure of section 3.2 with the det A check of section 3.3."""

    def test(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        th1, th2 = Interval(lo[:, 0], hi[:, 0]), Interval(lo[:, 1], hi[:, 1])
        b1x, b1y = m.L1 * cos(th1), m.L1 * sin(th1)
        b2x, b2y = m.L0 + m.L2 * cos(th2), m.L2 * sin(th2)
        dx, dy = b2x - b1x, b2y - b1y
        dist = hypot(dx, dy)
        outside = dist.lo > m.L3 + m.L4
        with np.errstate(divide="ignore", invalid="ignore"):
            c = (sqr(dist) + (m.L3**2 - m.L4**2)) / (2 * m.L3 * dist)
        inside = (dist.lo > 0) & (c.lo >= -1) & (c.hi <= 1)
        angle = Interval(*direction_range(dx.lo, dx.hi, dy.lo, dy.hi)) + _acos(c)
        px, py = b1x + m.L3 * cos(angle), b1y + m.L3 * sin(angle)
        det = (b1x - px) * (b2y - py) - (b1y - py) * (b2x - px)
        inside &= (det.lo > 0) | (det.hi < 0)
        return verdict(inside & ~outside, outside)

    return test


def paper_workspace_test(m):
    """The IKP procedure of section 3.4."""
    r1, big1 = abs(m.L1 - m.L3), m.L1 + m.L3
    r2, big2 = abs(m.L2 - m.L4), m.L2 + m.L4

    def test(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        x, y = Interval(lo[:, 0], hi[:, 0]), Interval(lo[:, 1], hi[:, 1])
        m1, m2 = hypot(x, y), hypot(x - m.L0, y)
        outside = (m1.lo > big1) | (m2.lo > big2) | (m1.hi < r1) | (m2.hi < r2)
        inside = (m1.lo > 0) & (m2.lo > 0) & (m1.lo > r1) & (m2.lo > r2) & (m1.hi < big1) & (m2.hi < big2)
        with np.errstate(divide="ignore", invalid="ignore"):
            c1 = (m.L1**2 + sqr(m1) - m.L3**2) / (2 * m1 * m.L1)
            c2 = (m.L2**2 + sqr(m2) - m.L4**2) / (2 * m2 * m.L2)
        inside &= (c1.lo >= -1) & (c1.hi <= 1) & (c2.lo >= -1) & (c2.hi <= 1)
        return verdict(inside & ~outside, outside)

    return test
