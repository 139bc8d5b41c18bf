"""3-RPR benchmark: seconds and peak memory of one area evaluation, Table 1 synthesis and the sweeps.

Run from the repository root: `.venv/bin/python benchmarks/bench_rpr3.py`. Targets (issue 4):
one area evaluation < 1 ms, `synthesize` for Table 1 < 5 s, the sweeps < 30 s together.
Library timings are in-process (peak memory: tracemalloc, Python and numpy allocations); command
timings run the real `fivebar rpr3 ...` in a subprocess, figures included (peak memory: max RSS).
"""

from __future__ import annotations

import math
import os
import subprocess
import sys
import tempfile
import time
import tracemalloc
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from fivebar_cli.mechanisms.rpr3 import closed_form as rpr3  # noqa: E402
from fivebar_cli.mechanisms.rpr3.paper import PAPER_SETUP  # noqa: E402
from fivebar_cli.mechanisms.rpr3.synthesis import synthesize  # noqa: E402

BASES = [ROOT / "configs" / f"rpr3-{n}.yaml" for n in ("acute", "equilateral", "obtuse")]


def measure(fn, repeat=1):
    """Best wall time of `repeat` runs (seconds) and the tracemalloc peak of one run (MB)."""
    fn()  # warm-up: imports and caches
    best = math.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    tracemalloc.start()
    fn()
    peak = tracemalloc.get_traced_memory()[1] / 2**20
    tracemalloc.stop()
    return best, peak


def command(*args):
    """Wall time (s) and max RSS (MB) of `fivebar rpr3 ...` in a fresh interpreter."""
    t0 = time.perf_counter()
    proc = subprocess.Popen([sys.executable, "-m", "fivebar_cli", "rpr3", *map(str, args), "-q"], cwd=ROOT)
    _, status, usage = os.wait4(proc.pid, 0)
    seconds = time.perf_counter() - t0
    proc.returncode = os.waitstatus_to_exitcode(status)
    if proc.returncode:
        raise SystemExit(f"fivebar rpr3 {' '.join(map(str, args))} failed ({proc.returncode})")
    return seconds, usage.ru_maxrss / 1024


def main() -> None:
    t1, t2, t3, k, p1, p2, rho = PAPER_SETUP
    phi1, phi2 = math.radians(p1), math.radians(p2)
    rho_max = float(rpr3.rho_max_auto(t1, t2, t3, k, phi1, rho))
    print("3-RPR benchmark (best of repeats; peak memory of one run)")

    n = 1000
    s, mb = measure(lambda: [rpr3.area(t1, t2, t3, k, phi1, rho, rho_max) for _ in range(n)], 3)
    print(f"  one area evaluation (scalar call)        {1e3 * s / n:8.3f} ms   peak {mb:6.1f} MB   target < 1 ms")
    s, mb = measure(lambda: [rpr3.area_auto(t1, t2, t3, k, phi1, rho) for _ in range(n)], 3)
    print(f"  one area with rho_max auto (scalar call) {1e3 * s / n:8.3f} ms   peak {mb:6.1f} MB")
    phis = np.linspace(0.01, math.pi - 0.01, 20000)
    s, mb = measure(lambda: rpr3.area(t1, t2, t3, k, phis, rho, rho_max), 3)
    print(f"  batched area, 20000 orientations         {1e6 * s / len(phis):8.3f} us each  peak {mb:6.1f} MB")
    s, mb = measure(lambda: synthesize(t1, t2, t3, k, phi1, phi2, rho), 2)
    print(f"  Table 1 synthesis (library, 6 cases)    {s:8.3f} s    peak {mb:6.1f} MB")

    with tempfile.TemporaryDirectory() as tmp:
        s, mb = command("synthesize", ROOT / "configs" / "rpr3-table1.yaml", "-o", Path(tmp, "t1"))
        print(f"  fivebar rpr3 synthesize (Table 1, figs)  {s:8.3f} s    max RSS {mb:6.1f} MB   target < 5 s")
        total = 0.0
        for over in ("phi", "rho_min", "t2"):
            s, mb = command("sweep", *BASES, "--over", over, "-o", Path(tmp, over))
            total += s
            print(f"  fivebar rpr3 sweep 3 bases --over {over:<7}{s:8.3f} s    max RSS {mb:6.1f} MB")
        print(f"  the three sweeps together                {total:8.3f} s                      target < 30 s")


if __name__ == "__main__":
    main()
