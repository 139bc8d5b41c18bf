"""Paving speed: evaluations, seconds and peak memory for both spaces of M1 and M2, against a plain
dense-grid classification at the same resolution (the paper's "discretization").

    python benchmarks/bench_paving.py [--depths 10,12,14,16] [--grid-max 14]

The dense grid tests the centre of every one of the 4^d cells with the point kinematics (in
chunks, vectorised). Above --grid-max it is timed on 1/16 of the rows and scaled by 16
(marked "~" as an extrapolation), because 4^16 points take minutes.
"""

from __future__ import annotations

import argparse
import os
import platform
import time
import tracemalloc
from pathlib import Path

import numpy as np

from fivebar_cli.analyses.spaces import pave_space
from fivebar_cli.mechanisms.fivebar import kinematics
from fivebar_cli.mechanisms.registry import load_config

CONFIGS = Path(__file__).resolve().parents[1] / "configs"


def cpu_model() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "cpu"


def measured(func):
    """(result, seconds, peak MiB of the numpy/Python heap): timed alone, then re-run under tracemalloc."""
    t0 = time.perf_counter()
    result = func()
    seconds = time.perf_counter() - t0
    tracemalloc.start()
    func()
    peak = tracemalloc.get_traced_memory()[1] / 2**20
    tracemalloc.stop()
    return result, seconds, peak


def dense_grid(m, space: str, depth: int, fraction_rows: int = 1) -> tuple[int, float]:
    """Classify cell centres of the 2^d x 2^d grid (rows 0 .. n/fraction_rows); returns (valid, seconds)."""
    g = m.spaces()[space].grid(depth)
    n = 1 << depth
    (x0, x1), (y0, y1) = g.root
    xs = x0 + (np.arange(n) + 0.5) * (x1 - x0) / n
    rows = n // fraction_rows
    per_chunk = max(1, (1 << 22) // n)
    point_test = kinematics.in_joint_space if space == "jointspace" else kinematics.in_workspace
    valid = 0
    t0 = time.perf_counter()
    for r in range(0, rows, per_chunk):
        ys = y0 + (np.arange(r, min(rows, r + per_chunk)) + 0.5) * (y1 - y0) / n
        gx, gy = np.meshgrid(xs, ys)
        valid += int(np.count_nonzero(point_test(m, gx.ravel(), gy.ravel())))
    return valid, time.perf_counter() - t0


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--depths", default="10,12,14,16")
    parser.add_argument("--grid-max", type=int, default=14, help="largest depth with a full dense grid")
    args = parser.parse_args()
    depths = [int(d) for d in args.depths.split(",")]
    print(f"machine: {platform.machine()}, {cpu_model()}, {os.cpu_count()} cores, python {platform.python_version()}, "
          f"numpy {np.__version__}")
    print(f"{'mech':4s} {'space':10s} {'d':>2s} {'evaluations':>11s} {'pave s':>8s} {'peak MiB':>8s} "
          f"{'grid points':>13s} {'grid s':>8s} {'grid/pave':>9s}")
    for name in ("m1", "m2"):
        m = load_config(CONFIGS / f"{name}.yaml")
        for space in ("jointspace", "workspace"):
            pave_space(m, space, 6)  # warm-up (imports, caches)
            for depth in depths:
                paving, seconds, peak = measured(lambda: pave_space(m, space, depth))
                fraction = 1 if depth <= args.grid_max else 16
                _, grid_seconds = dense_grid(m, space, depth, fraction)
                grid_seconds *= fraction
                mark = "~" if fraction > 1 else " "
                print(f"{m.name:4s} {space:10s} {depth:2d} {paving.evaluations:11d} {seconds:8.3f} {peak:8.1f} "
                      f"{4**depth:13d} {mark}{grid_seconds:7.2f} {grid_seconds / seconds:9.0f}x")


if __name__ == "__main__":
    main()
