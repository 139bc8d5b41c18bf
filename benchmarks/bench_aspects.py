"""Aspect analysis speed and certification: the full `fivebar aspects` pipeline without plots (mode
pavings, outer approximations, links, local refinement, crossings), per depth.

    python benchmarks/bench_aspects.py [--depths 10,12,14] [--configs m1,m2]
    python benchmarks/bench_aspects.py --random 200 --depths 8,10,12     # random five-bars

Named configs: total seconds, the part spent on the certificate (outer sets, links, refinement),
peak memory, counts, and the box evaluations local refinement added. Random five-bars (L0 in
[0.2, 2], the other lengths in [0.5, 2], seeded): the share of certified counts per depth, seconds,
refinement evaluations, and whether any design got two different certified counts.
"""

from __future__ import annotations

import argparse
import time
import tracemalloc
from pathlib import Path

import numpy as np

from fivebar_cli.analyses.aspects import analyse_aspects
from fivebar_cli.mechanisms.fivebar.model import FiveBar
from fivebar_cli.mechanisms.registry import load_config

CONFIGS = Path(__file__).resolve().parents[1] / "configs"


def named(configs: list[str], depths: list[int]) -> None:
    print(f"{'mech':4s} {'d':>2s} {'total s':>8s} {'paving s':>8s} {'certif s':>8s} {'crossing s':>10s} "
          f"{'peak MiB':>8s} {'evaluations':>11s} {'refine ev':>9s} {'aspects':>7s} {'certified':>9s}")
    for name in configs:
        m = load_config(CONFIGS / f"{name}.yaml")
        analyse_aspects(m, 6)  # warm-up
        for depth in depths:
            t0 = time.perf_counter()
            result = analyse_aspects(m, depth)
            total = time.perf_counter() - t0
            tracemalloc.start()  # memory from a second run: tracemalloc slows allocation-heavy code
            analyse_aspects(m, depth)
            peak = tracemalloc.get_traced_memory()[1] / 2**20
            tracemalloc.stop()
            t = result.timings
            print(f"{m.name:4s} {depth:2d} {total:8.3f} {t['paving']:8.3f} {t['outer'] + t['certificate']:8.3f} "
                  f"{t['crossings']:10.3f} {peak:8.1f} {result.evaluations:11d} {result.refinement_evaluations:9d} "
                  f"{len(result.aspects):7d} {str(result.certified):>9s}")


def random_designs(n: int, depths: list[int], seed: int) -> None:
    rng = np.random.default_rng(seed)
    designs = [(float(rng.uniform(0.2, 2)), *(float(v) for v in rng.uniform(0.5, 2, 4))) for _ in range(n)]
    counts: list[dict] = [{} for _ in designs]
    print(f"{n} random five-bars (seed {seed})")
    print(f"{'d':>2s} {'certified':>10s} {'mean s':>7s} {'max s':>7s} {'mean refine ev':>14s} {'max refine ev':>13s}")
    for depth in depths:
        seconds, extra, certified = [], [], 0
        for k, lengths in enumerate(designs):
            t0 = time.perf_counter()
            a = analyse_aspects(FiveBar("random", *lengths), depth)
            seconds.append(time.perf_counter() - t0)
            extra.append(a.refinement_evaluations)
            if a.certified:
                certified += 1
                counts[k][depth] = len(a.aspects)
        print(f"{depth:2d} {certified / n:10.1%} {np.mean(seconds):7.2f} {np.max(seconds):7.2f} "
              f"{np.mean(extra):14.0f} {np.max(extra):13d}")
    changed = sum(len(set(c.values())) > 1 for c in counts)
    print(f"designs whose certified count changes with depth: {changed}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--depths", default=None)
    parser.add_argument("--configs", default="m1,m2")
    parser.add_argument("--random", type=int, default=0, help="Random five-bars to analyse instead of configs.")
    parser.add_argument("--seed", type=int, default=7)
    args = parser.parse_args()
    if args.random:
        random_designs(args.random, [int(d) for d in (args.depths or "8,10,12").split(",")], args.seed)
    else:
        named(args.configs.split(","), [int(d) for d in (args.depths or "10,12,14").split(",")])


if __name__ == "__main__":
    main()
