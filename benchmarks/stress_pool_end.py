"""Pools ended at random moments: every one must end, at once (`analyses.jobs.Workers`).

    python benchmarks/stress_pool_end.py                    # 300 pools, seed 1
    python benchmarks/stress_pool_end.py --pools 1000 --seed 7

Each pool of two workers gets eight tasks that sleep up to 10 ms and return a result of 80 B to
800 kB (numpy arrays, which cross through /dev/shm from 64 KiB on, or bytes, which always cross the
pipes); then, at a random moment within 20 ms, the pool's `with` ends by an error (30 %), by the
WorkerLost of a worker SIGKILLed (20 %), or after every result (50 %). A pool that has not ended
within 20 s is a hang: the threads' stacks are printed and the run stops (exit 1). Prints the pools
run, how each ended, and the seconds. multiprocessing's own `terminate()` hangs here within tens of
pools (python/cpython#96995: a queue's lock held, or a message half written, by a killed worker).
"""

from __future__ import annotations

import argparse
import collections
import os
import random
import signal
import sys
import threading
import time
import traceback
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import numpy as np  # noqa: E402

from fivebar_cli.analyses.jobs import WorkerLost, Workers  # noqa: E402


class Stop(Exception):
    """The error that ends a pool's `with`."""


def task(spec: tuple[int, float, bool]):
    size, delay, array = spec
    time.sleep(delay)
    return np.ones(size) if array else b"x" * (8 * size)


def one_pool(rng: random.Random) -> str:
    """Run one pool and end it as `rng` says: how it ended."""
    try:
        with Workers(2, 8) as pool:
            tasks = [pool.submit(task, (rng.choice([10, 5_000, 40_000, 100_000]), rng.uniform(0, 0.01),
                                        rng.random() < 0.5)) for _ in range(8)]
            time.sleep(rng.uniform(0, 0.02))
            end = rng.random()
            if end < 0.3:
                raise Stop()
            if end < 0.5:
                os.kill(rng.choice(pool._pool.processes).pid, signal.SIGKILL)
            for t in tasks:
                t.get()
        return "all results"
    except Stop:
        return "an error"
    except WorkerLost:
        return "a worker killed"


def main() -> int:
    parser = argparse.ArgumentParser(description="Pools ended at random moments: every one must end.")
    parser.add_argument("--pools", type=int, default=300)
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    rng, ended = random.Random(args.seed), collections.Counter()
    start = time.perf_counter()
    for i in range(args.pools):
        outcome = []
        runner = threading.Thread(target=lambda: outcome.append(one_pool(rng)), daemon=True)
        runner.start()
        runner.join(20)
        if runner.is_alive():
            print(f"pool {i + 1} did not end within 20 s; the threads:")
            for frame in sys._current_frames().values():
                traceback.print_stack(frame)
            return 1
        ended[outcome[0]] += 1
    print(f"{args.pools} pools (seed {args.seed}) ended, none hung, in {time.perf_counter() - start:.1f} s: "
          + ", ".join(f"{n} by {how}" for how, n in sorted(ended.items())))
    return 0


if __name__ == "__main__":
    sys.exit(main())
