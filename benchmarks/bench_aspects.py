"""Aspect analysis speed: the full `fivebar aspects` pipeline without plots (six mode pavings,
component labelling, cross-space linking with fragment refinement, crossings), per depth.

    python benchmarks/bench_aspects.py [--depths 10,12,14] [--configs m1,m2]

Prints total seconds, the part spent in component labelling alone, peak memory, and counts.
"""

from __future__ import annotations

import argparse
import time
import tracemalloc
from pathlib import Path

from fivebar_cli.analyses.aspects import analyse_aspects
from fivebar_cli.mechanisms.registry import load_config

CONFIGS = Path(__file__).resolve().parents[1] / "configs"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--depths", default="10,12,14")
    parser.add_argument("--configs", default="m1,m2")
    args = parser.parse_args()
    print(f"{'mech':4s} {'d':>2s} {'total s':>8s} {'paving s':>8s} {'labels s':>8s} {'linking s':>9s} "
          f"{'crossing s':>10s} {'peak MiB':>8s} {'evaluations':>11s} {'leaves':>8s} {'aspects':>7s} {'fragments':>9s}")
    for name in args.configs.split(","):
        m = load_config(CONFIGS / f"{name}.yaml")
        analyse_aspects(m, 6)  # warm-up
        for depth in (int(d) for d in args.depths.split(",")):
            t0 = time.perf_counter()
            result = analyse_aspects(m, depth)
            total = time.perf_counter() - t0
            tracemalloc.start()  # memory from a second run: tracemalloc slows allocation-heavy code
            analyse_aspects(m, depth)
            peak = tracemalloc.get_traced_memory()[1] / 2**20
            tracemalloc.stop()
            t = result.timings
            leaves = sum(len(r.tree) for r in result.regions)
            print(f"{m.name:4s} {depth:2d} {total:8.3f} {t['paving']:8.3f} {t['components']:8.3f} "
                  f"{t['linking']:9.3f} {t['crossings']:10.3f} {peak:8.1f} {result.evaluations:11d} {leaves:8d} "
                  f"{len(result.aspects):7d} {result.fragments_resolved:9d}")


if __name__ == "__main__":
    main()
