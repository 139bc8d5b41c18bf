"""Manufacturing tolerances: the cost of robust pavings and robust aspects against nominal ones,
and how tight the robust pavings are.

    python benchmarks/bench_tolerance.py [--depth 14] [--aspect-depth 10] [--tolerances 0.01,0.05,0.1]

Per mechanism, space and tolerance: seconds of the robust paving and of the nominal one at the same
depth (best of three) and their ratio, evaluations, peak memory; the robust area against the exact
robust area (tests/reference_robust.py, on a 1500^2 grid, about 0.1 % accurate). Then robust
aspects per tolerance: seconds, count, certified. No interval library ships a five-bar with
interval lengths to compare against; the nominal paving is the baseline.
"""

from __future__ import annotations

import argparse
import sys
import time
import tracemalloc
from pathlib import Path

import numpy as np

from fivebar_cli.analyses.aspects import analyse_aspects
from fivebar_cli.mechanisms.registry import load_config
from fivebar_cli.paving.engine import pave

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))
from reference_robust import robust_joint, robust_work  # noqa: E402

REFERENCE = {"workspace": robust_work, "jointspace": robust_joint}


def best_of(n: int, run) -> tuple[float, object]:
    times, result = [], None
    for _ in range(n):
        t0 = time.perf_counter()
        result = run()
        times.append(time.perf_counter() - t0)
    return min(times), result


def exact_robust_area(m, space: str, n: int = 1500) -> float:
    root = np.array(m.spaces()[space].root)
    t = [(np.arange(n) + 0.5) / n * (hi - lo) + lo for lo, hi in root]
    parts = []
    for row in np.array_split(np.arange(n), 10):  # rows in chunks: the zonotope distance is memory-hungry
        x, y = np.meshgrid(t[0][row], t[1], indexing="ij")
        parts.append(REFERENCE[space](m.bounds, x.ravel(), y.ravel()))
    inside = np.concatenate(parts)
    return float(inside.mean() * np.prod(root[:, 1] - root[:, 0]))


def pavings(names, depth: int, tolerances) -> None:
    print(f"paving at depth {depth}: robust vs nominal")
    print(f"{'mech':4s} {'space':10s} {'T':>5s} {'robust s':>8s} {'nominal s':>9s} {'ratio':>5s} {'evaluations':>11s} "
          f"{'peak MiB':>8s} {'robust area':>11s} {'exact robust':>12s} {'tight %':>7s}")
    for name in names:
        m = load_config(ROOT / "configs" / f"{name}.yaml")
        for space in ("workspace", "jointspace"):
            nominal_s, _ = best_of(3, lambda: pave(m.spaces()[space].grid(depth), m.box_test(space)))
            for tol in tolerances:
                mt = m.widened(tol)
                grid, test = mt.spaces()[space].grid(depth), mt.box_test(space)
                seconds, paving = best_of(3, lambda: pave(grid, test))
                tracemalloc.start()
                pave(grid, test)
                peak = tracemalloc.get_traced_memory()[1] / 2**20
                tracemalloc.stop()
                exact = exact_robust_area(mt, space)
                print(f"{m.name:4s} {space:10s} {tol:5g} {seconds:8.3f} {nominal_s:9.3f} {seconds / nominal_s:5.2f} "
                      f"{paving.evaluations:11d} {peak:8.1f} {paving.inside.area:11.5f} {exact:12.5f} "
                      f"{100 * paving.inside.area / exact:7.2f}", flush=True)


def aspects(names, depth: int, tolerances) -> None:
    print(f"robust aspects at depth {depth}")
    print(f"{'mech':4s} {'T':>5s} {'seconds':>8s} {'aspects':>7s} {'certified':>9s} {'evaluations':>11s}")
    for name in names:
        m = load_config(ROOT / "configs" / f"{name}.yaml")
        for tol in (0.0, *tolerances):
            mt = m.widened(tol)
            seconds, a = best_of(1 if tol else 3, lambda: analyse_aspects(mt, depth))
            bounds = "" if a.certified else f" [{a.lower}-{a.upper}]"
            print(f"{m.name:4s} {tol:5g} {seconds:8.3f} {len(a.aspects):7d} {str(a.certified):>9s}{bounds} "
                  f"{a.evaluations:11d}", flush=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--depth", type=int, default=14)
    parser.add_argument("--aspect-depth", type=int, default=10)
    parser.add_argument("--tolerances", default="0.01,0.05,0.1")
    parser.add_argument("--configs", default="m1,m2")
    args = parser.parse_args()
    tolerances = [float(t) for t in args.tolerances.split(",")]
    names = args.configs.split(",")
    pavings(names, args.depth, tolerances)
    aspects(["m1"], args.aspect_depth, tolerances)


if __name__ == "__main__":
    main()
