"""Joint limits and obstacles: what they cost the aspect analysis, and how tight their tests are
against a naive interval-arithmetic version of the same tests.

    python benchmarks/bench_constraints.py [--depth 10] [--depths 8,10] [--repeat 3]

1. Aspects of M1 at --depth without constraints and with the peer's two (P in [-90, 90] deg; the
   disc of radius 1 at (4.5, 0)) and the README's example (every limit, a disc and a square):
   seconds (best of --repeat), box evaluations, peak memory, the count and whether it is certified;
   the ratio to the unconstrained run (the issue's target: within 3x).
2. The same mode pavings (workspace, working mode ++; joint space, assembly mode +) restricted by
   our constraint tests and by a naive version: the link ends and P computed in outward-rounded
   interval arithmetic (`numerics/interval.py`: B_i from the crank angles or the circle
   intersection, P by the DKP formula), the P limit as the sign of (B1 - P) . (B2 - P), a link's
   distance to the disc through the interval nearest point. Evaluations to reach the depth, the
   undetermined area left (the tighter the test, the less), seconds.
"""

from __future__ import annotations

import argparse
import tracemalloc
from dataclasses import replace
from pathlib import Path

import numpy as np

from fivebar_cli.analyses.aspects import analyse_aspects
from fivebar_cli.mechanisms.fivebar import constrained
from fivebar_cli.mechanisms.fivebar.constraints import Constraints, Limit
from fivebar_cli.mechanisms.registry import load_config
from fivebar_cli.numerics.interval import Interval, cos, sin, sqr, sqrt
from fivebar_cli.numerics.obstacles import Disc
from fivebar_cli.paving.engine import pave
from bench_tolerance import best_of  # noqa: E402 (benchmarks/ is on the path when run as a script)

ROOT = Path(__file__).resolve().parents[1]
CONFIGS = ("m1", "m1-passive-limit", "m1-obstacle", "m1-limited")


def aspects(depth: int, repeat: int) -> None:
    print(f"aspects at depth {depth} (best of {repeat})")
    print(f"{'config':18s} {'seconds':>8s} {'ratio':>5s} {'evaluations':>11s} {'peak MiB':>8s} {'aspects':>7s} "
          f"{'certified':>9s}")
    base = None
    for name in CONFIGS:
        m = load_config(ROOT / "configs" / f"{name}.yaml")
        seconds, a = best_of(repeat, lambda: analyse_aspects(m, depth))
        tracemalloc.start()
        analyse_aspects(m, depth)
        peak = tracemalloc.get_traced_memory()[1] / 2**20
        tracemalloc.stop()
        base = base or seconds
        print(f"{name:18s} {seconds:8.2f} {seconds / base:5.2f} {a.evaluations:11d} {peak:8.1f} {len(a.aspects):7d} "
              f"{str(a.certified).lower():>9s}", flush=True)


# ---------------------------------------------------------------- the naive interval version


def _box(lo, hi, k):
    return Interval(lo[:, k], hi[:, k])


def _decide(holds: Interval, threshold: float):
    """1 where holds > threshold everywhere, -1 where holds < threshold everywhere."""
    return np.where(holds.lo > threshold, 1, np.where(holds.hi < threshold, -1, 0))


def _link_clear(e1, e2, length2: float, disc: Disc):
    """Naive status of a link against the disc: the squared distance from the centre to the link's
    nearest point, in interval arithmetic."""
    cx, cy = disc.centre
    dx, dy = e2[0] - e1[0], e2[1] - e1[1]
    t = ((cx - e1[0]) * dx + (cy - e1[1]) * dy) / length2
    t = Interval(np.clip(t.lo, 0, 1), np.clip(t.hi, 0, 1))
    qx, qy = e1[0] + t * dx - cx, e1[1] + t * dy - cy
    return _decide(sqr(qx) + sqr(qy), disc.radius ** 2)


def _naive_status(m, b1, b2, p) -> np.ndarray:
    """Naive status from interval link ends: -1 if some constraint fails everywhere, 1 if all hold."""
    n = len(p[0].lo)
    a1, a2 = (Interval.point(np.zeros(n)), Interval.point(np.zeros(n))), (Interval.point(np.full(n, m.L0)),
                                                                           Interval.point(np.zeros(n)))
    parts = []
    for lim in m.constraints.limits:  # the peer's limit only: P in [-90, 90] is (B1 - P) . (B2 - P) >= 0
        assert (lim.name, lim.lo, lim.hi) == ("P", -90, 90)
        parts.append(_decide((b1[0] - p[0]) * (b2[0] - p[0]) + (b1[1] - p[1]) * (b2[1] - p[1]), 0.0))
    for disc in m.constraints.obstacles:
        for e1, e2, length in ((a1, b1, m.L1), (b1, p, m.L3), (a2, b2, m.L2), (b2, p, m.L4)):
            parts.append(_link_clear(e1, e2, length * length, disc))
    s = np.stack(parts)
    return np.where((s == -1).any(axis=0), -1, np.where((s == 1).all(axis=0), 1, 0)).astype(np.int8)


def naive_joint(m, assembly: int, lo, hi) -> np.ndarray:
    t1, t2 = _box(lo, hi, 0), _box(lo, hi, 1)
    b1 = (m.L1 * cos(t1), m.L1 * sin(t1))
    b2 = (m.L0 + m.L2 * cos(t2), m.L2 * sin(t2))
    dx, dy = b2[0] - b1[0], b2[1] - b1[1]
    d2 = sqr(dx) + sqr(dy)
    d = sqrt(d2)
    a = (d2 + (m.L3 ** 2 - m.L4 ** 2)) / (2.0 * d)
    h = sqrt(m.L3 ** 2 - sqr(a))
    p = (b1[0] + (a * dx - assembly * h * dy) / d, b1[1] + (a * dy + assembly * h * dx) / d)
    return _naive_status(m, b1, b2, p)


def naive_work(m, working, lo, hi) -> np.ndarray:
    x, y = _box(lo, hi, 0), _box(lo, hi, 1)

    def elbow(cx: float, crank: float, coupler: float, s_sign: int):  # the circle-intersection formula
        ux = x - cx
        s2 = sqr(ux) + sqr(y)
        s = sqrt(s2)
        a = (crank ** 2 - coupler ** 2 + s2) / (2.0 * s)
        h = sqrt(crank ** 2 - sqr(a))
        return (cx + (a * ux + s_sign * h * y) / s, (a * y - s_sign * h * ux) / s)

    b1 = elbow(0.0, m.L1, m.L3, working[0])
    b2 = elbow(m.L0, m.L2, m.L4, working[1])
    return _naive_status(m, b1, b2, (x, y))


def tightness(depths, repeat: int) -> None:
    print("\nconstraint tests: ours against naive interval arithmetic (same mode tests, same paving)")
    print(f"{'case':10s} {'space':10s} {'depth':>5s} {'version':8s} {'evaluations':>11s} {'undetermined':>12s} "
          f"{'inside':>9s} {'seconds':>7s}")
    m1 = load_config(ROOT / "configs" / "m1.yaml")
    cases = {"P limit": Constraints((Limit("P", -90, 90),)), "disc": Constraints((), (Disc((4.5, 0.0), 1.0),))}
    for case, c in cases.items():
        m = replace(m1, constraints=c)
        model = m.aspect_model().base
        for space, key in (("workspace", (1, 1)), ("jointspace", 1)):
            base = model.workspace_test(key) if space == "workspace" else model.jointspace_test(key)
            ours = constrained.workspace_status if space == "workspace" else constrained.jointspace_status
            naive = naive_work if space == "workspace" else naive_joint
            for depth in depths:
                for version, status in (("ours", ours), ("naive", naive)):
                    def test(lo, hi, status=status):
                        return constrained.restricted(base(lo, hi), lambda k: status(m, key, lo[k], hi[k]))

                    with np.errstate(all="ignore"):
                        seconds, p = best_of(repeat, lambda: pave(m.spaces()[space].grid(depth), test))
                    print(f"{case:10s} {space:10s} {depth:5d} {version:8s} {p.evaluations:11d} "
                          f"{p.undetermined_area:12.5f} {p.inside.area:9.4f} {seconds:7.2f}", flush=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--depth", type=int, default=10)
    parser.add_argument("--depths", default="8,10")
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    aspects(args.depth, args.repeat)
    tightness([int(d) for d in args.depths.split(",")], args.repeat)


if __name__ == "__main__":
    main()
