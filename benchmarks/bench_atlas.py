"""Atlas throughput: designs per second in this process, on a plain `multiprocessing` pool (the peer)
and on a local Dask cluster, at depths 8 and 10; start-up, peak memory, the scheduler's overhead per task.

    python benchmarks/bench_atlas.py [--depths 8,10] [--steps 6] [--workers 2] [--repeat 2]

The designs are the README's example grid (L0 = 1, L2 = 0.7, L4 = 1.1; L1 and L3 swept over
[0.4, 1.6], `--steps` values each), run through the real engine (`run_plan`: parts written, then
atlas.csv) into a temporary folder; every engine must write the same bytes. Rates count from the
first batch submitted to atlas.csv written; "start s" is the time to start the pool or cluster
(the Dask row "+ start-up" adds it to the run). Each figure is the best of `--repeat` alternated
runs (the machine may be shared). Peak RSS: of this process (in process) or of the busiest worker
process. The overhead per task is the time per empty task, submitted by the thousand, workers idle.
"""

from __future__ import annotations

import argparse
import multiprocessing
import os
import resource
import tempfile
import time
from pathlib import Path

from fivebar_cli.analyses.atlas.cluster import local_cluster
from fivebar_cli.analyses.atlas.engine import batch_text, in_process, plan_atlas, run_plan
from fivebar_cli.analyses.atlas.spec import AtlasSpec, sweep_values


def empty(spec, index: int) -> str:
    return ""


def peak_mib() -> float:
    """The peak resident size of the calling process."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def _pool_batch(args) -> tuple[int, str, float]:
    spec, index = args
    return index, batch_text(spec, index), peak_mib()


class PoolRunner:
    """The peer: a `multiprocessing` pool (spawned, as Dask's workers) taking batches one at a time."""

    def __init__(self, pool):
        self.pool, self.peak = pool, 0.0

    def __call__(self, task, spec, indices):
        for index, text, peak in self.pool.imap_unordered(_pool_batch, [(spec, i) for i in indices], chunksize=1):
            self.peak = max(self.peak, peak)
            yield index, text


def timed(spec: AtlasSpec, folder: Path, runner) -> tuple[float, bytes]:
    t0 = time.perf_counter()
    path = run_plan(plan_atlas(spec, folder), runner)
    return time.perf_counter() - t0, path.read_bytes()


def measure(spec: AtlasSpec, workers: int, repeat: int) -> dict:
    """Per engine: best seconds, start-up seconds, peak RSS (MiB); and whether all bytes agree."""
    best: dict = {}
    outputs = set()

    def keep(engine: str, seconds: float, start: float, rss: float) -> None:
        if seconds < best.get(engine, (float("inf"),))[0]:
            best[engine] = (seconds, start, rss)

    for _ in range(repeat):
        with tempfile.TemporaryDirectory() as tmp:
            seconds, data = timed(spec, Path(tmp) / "local", in_process)
            keep("in process", seconds, 0.0, peak_mib())
            outputs.add(data)
            t0 = time.perf_counter()
            with multiprocessing.get_context("spawn").Pool(workers) as pool:
                start = time.perf_counter() - t0
                runner = PoolRunner(pool)
                seconds, data = timed(spec, Path(tmp) / "pool", runner)
            keep(f"multiprocessing.Pool({workers})", seconds, start, runner.peak)
            outputs.add(data)
            t0 = time.perf_counter()
            with local_cluster(workers) as runner:
                start = time.perf_counter() - t0
                seconds, data = timed(spec, Path(tmp) / "dask", runner)
                rss = max(runner.client.run(peak_mib).values())
            keep(f"Dask LocalCluster({workers})", seconds, start, rss)
            outputs.add(data)
    dask = best[f"Dask LocalCluster({workers})"]
    best["  + start-up"] = (dask[0] + dask[1], dask[1], dask[2])
    return {"best": best, "same": len(outputs) == 1}


def task_overhead(workers: int, tasks: int = 2000) -> float:
    spec = AtlasSpec("empty", ((1.0,),) * 5)
    with local_cluster(workers) as runner:
        list(runner(empty, spec, list(range(100))))  # warm-up
        t0 = time.perf_counter()
        for _ in runner(empty, spec, list(range(100, 100 + tasks))):
            pass
        return (time.perf_counter() - t0) / tasks


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--depths", default="8,10")
    parser.add_argument("--steps", type=int, default=6)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--repeat", type=int, default=2, help="Alternated runs of each; the best is reported.")
    args = parser.parse_args()
    values = sweep_values(0.4, 1.6, args.steps)
    n = args.steps**2
    print(f"{n} designs (batches of 1): L0 = 1, L2 = 0.7, L4 = 1.1, L1 and L3 in [0.4, 1.6] ({args.steps} steps "
          f"each); {os.cpu_count()} cores, load average {os.getloadavg()[0]:.1f} at start; best of {args.repeat}")
    print(f"{'depth':>5s}  {'engine':26s} {'designs/s':>9s} {'seconds':>8s} {'speed-up':>8s} {'start s':>7s} "
          f"{'peak RSS MiB':>12s}")
    for depth in (int(d) for d in args.depths.split(",")):
        spec = AtlasSpec("bench", ((1.0,), values, (0.7,), values, (1.1,)), depth)
        r = measure(spec, args.workers, args.repeat)
        base = r["best"]["in process"][0]
        for engine, (seconds, start, rss) in r["best"].items():
            print(f"{depth:5d}  {engine:26s} {n / seconds:9.2f} {seconds:8.1f} {base / seconds:7.2f}x {start:7.1f} "
                  f"{rss:12.0f}")
        print(f"{'':5s}  same atlas.csv bytes from every engine: {r['same']}", flush=True)
    per_task = task_overhead(args.workers)
    print(f"scheduler overhead per task: {per_task * 1e3:.2f} ms (2000 empty tasks, {args.workers} workers); "
          f"at 100 designs per task and 0.5 s per design: {per_task / 50:.1e} of the run")
    print(f"load average at end {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
