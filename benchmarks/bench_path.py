"""`fivebar path` speed: a certified motion across aspect 1 of M1, cold (nothing saved: the one
joint-space paving the motion needs) and warm (reusing the aspect trees an `aspects` run saved
into -o), with and without the figure; also a motion that does not exist (different aspects: the
aspect analysis runs to say so). Each run is a whole `fivebar path` command, in this process
after a warm-up (imports loaded once, as in a long-lived session; a fresh process adds about
0.3 s of imports). Seconds are the best of --repeat runs; peak memory from tracemalloc (numpy and
Python heap) on one more run.

    python benchmarks/bench_path.py [--depths 10,12] [--repeat 3]
"""

from __future__ import annotations

import argparse
import tempfile
import time
import tracemalloc
from pathlib import Path

from fivebar_cli.cli import main as cli_main

CONFIG = Path(__file__).resolve().parents[1] / "configs" / "m1.yaml"
MOTION = ["--joints", "-0.09817477", "-2.06167018", "--joints", "0.88357293", "1.47262156", "--assembly-mode", "+"]
NO_MOTION = ["--joints", "-2.25801972", "-2.06167018", "--joints", "1.05537878", "2.03712649", "--assembly-mode", "+"]


def run(args: list[str]) -> int:
    try:
        cli_main([str(a) for a in args])
    except SystemExit as exc:
        return int(exc.code or 0)
    return 0


def timed(args: list[str], repeat: int) -> tuple[float, float, int]:
    best, status = float("inf"), 0
    for _ in range(repeat):
        t0 = time.perf_counter()
        status = run(args)
        best = min(best, time.perf_counter() - t0)
    tracemalloc.start()
    run(args)
    peak = tracemalloc.get_traced_memory()[1] / 2**20
    tracemalloc.stop()
    return best, peak, status


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--depths", default="12")
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        warm_up = Path(tmp) / "warm-up"
        run(["path", CONFIG, *MOTION, "--depth", 6, "-o", warm_up, "-q"])  # imports, matplotlib
        print(f"{'case':42s} {'d':>2s} {'seconds':>8s} {'peak MiB':>8s} {'exit':>4s}")
        for depth in [int(d) for d in args.depths.split(",")]:
            cold, warm = Path(tmp) / f"cold-{depth}", Path(tmp) / f"warm-{depth}"
            run(["aspects", CONFIG, "--depth", depth, "-o", warm, "-q", "--no-plot"])
            cases = (
                ("path, cold, --no-plot", cold, MOTION, ["--no-plot"]),
                ("path, cold, with path.png", cold, MOTION, []),
                ("path, saved aspect trees, --no-plot", warm, MOTION, ["--no-plot"]),
                ("path, saved aspect trees, with path.png", warm, MOTION, []),
                ("no path (different aspects), cold", cold, NO_MOTION, ["--no-plot"]),
                ("no path (different aspects), saved trees", warm, NO_MOTION, ["--no-plot"]),
            )
            for label, folder, motion, extra in cases:
                seconds, peak, status = timed(["path", CONFIG, *motion, "--depth", depth, "-o", folder, "-q", *extra],
                                              args.repeat)
                print(f"{label:42s} {depth:2d} {seconds:8.3f} {peak:8.1f} {status:4d}")


if __name__ == "__main__":
    main()
