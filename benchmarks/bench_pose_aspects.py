"""Aspects over (x, y, phi), assembly modes and motions of a 3-RPR (issue 19): seconds, boxes tested
and peak memory per depth, and a comparison of certified counts with a dense-grid count.

    python benchmarks/bench_pose_aspects.py [--depths 5,6,7,8] [--random 20 --random-depths 6,7]

Rows, each in a fresh interpreter (so the peak is the run's own): the aspects of Caro's example
(configs/rpr3-caro.yaml: the cuspidal robot, legs [10, 32], a full turn) and of the general
example over [0, 60] degrees per depth (total seconds, of which paving, certificate and the probe
one level deeper; boxes tested; tracemalloc peak of a second run and max RSS); `rpr3 dkp` of the ALIAS example
and of the cuspidal legs (14.98, 15.38, 12); the certified path between two of the cuspidal
assembly modes. With --random N: N random robots (seeded, half of them over a full turn) at each
depth, the share of certified counts and how many disagree with the dense grid of
tests/reference_pose_aspects.py when it is stable (64^3 and 96^3).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
CARO, GENERAL = REPO / "configs" / "rpr3-caro.yaml", REPO / "configs" / "rpr3-general.yaml"

ROW = r"""
import json, resource, sys, time, tracemalloc
kind, config, arg = sys.argv[1], sys.argv[2], sys.argv[3]
from fivebar_cli.mechanisms.registry import load_config
m = load_config(config)


def run():
    if kind == "aspects":
        from fivebar_cli.analyses.pose_aspects import analyse_pose_aspects
        a = analyse_pose_aspects(m, int(arg))
        return {"what": a.headline().split(": ", 1)[1].split(" (")[0], "evaluations": a.evaluations,
                "refine": a.refinement_evaluations, **{k: round(v, 3) for k, v in a.timings.items()}}
    from fivebar_cli.analyses.dkp import solve
    model = m.pose_aspect_model()
    if kind == "dkp":
        r = solve(model, m.spaces()["workspace"], [float(v) for v in arg.split(",")])
        return {"what": f"{len(r.solutions)} poses, certified {r.certified}", "evaluations": r.evaluations}
    from fivebar_cli.analyses.pose_paths import find_motion
    depth, i, j = (int(v) for v in arg.split(","))
    modes = solve(model, m.spaces()["workspace"], [14.98, 15.38, 12.0]).solutions
    p = find_motion(m, depth, modes[i - 1].pose, modes[j - 1].pose, ("a", "b"), "bench")
    return {"what": f"{len(p.poses)} waypoints, {p.motion.checked_cells} cells checked exactly", "evaluations": 0}


t0 = time.perf_counter()
out = run()
out["seconds"] = time.perf_counter() - t0
tracemalloc.start()  # memory from a second run: tracemalloc slows allocation-heavy code
run()
out["peak"] = tracemalloc.get_traced_memory()[1] / 2**20
out["rss"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
print(json.dumps(out))
"""


def row(kind: str, config: Path, arg: str) -> dict:
    env = dict(os.environ, PYTHONPATH=str(REPO))
    text = subprocess.run([sys.executable, "-c", ROW, kind, str(config), arg], capture_output=True, text=True,
                          env=env, check=True).stdout
    return json.loads(text.strip().splitlines()[-1])


def random_robots(n: int, depths: list[int]) -> None:
    sys.path.insert(0, str(REPO / "tests"))
    import time

    from reference_pose_aspects import stable_count
    from test_pose_aspects import random_robot

    from fivebar_cli.analyses.pose_aspects import analyse_pose_aspects

    print(f"{n} random 3-RPRs (tests/test_pose_aspects.py random_robot, seeds 0..{n // 2 - 1}, full turn and not)")
    results = {d: [] for d in depths}
    disagree, changed, unknown = 0, 0, 0
    for seed in range(n // 2):
        for full in (True, False):
            m = random_robot(seed, full)
            reference = stable_count(m.base, m.platform, m.rho_min, m.rho_max, m.spaces()["workspace"].root, full)
            unknown += reference is None
            counts = set()
            for d in depths:
                t0 = time.perf_counter()
                a = analyse_pose_aspects(m, d)
                results[d].append((a.certified, time.perf_counter() - t0))
                if a.certified:
                    counts.add(len(a.aspects))
                    disagree += reference is not None and len(a.aspects) != reference
            changed += len(counts) > 1
    for d in depths:
        certified = sum(c for c, _ in results[d])
        seconds = [s for _, s in results[d]]
        print(f"  depth {d}: {certified} of {len(results[d])} certified, mean {np.mean(seconds):.2f} s, "
              f"max {np.max(seconds):.2f} s")
    print(f"  certified counts that differ from the stable grid count: {disagree}; grid not stable: {unknown}; "
          f"robots with two different certified counts: {changed}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--depths", default="5,6,7,8")
    parser.add_argument("--random", type=int, default=0)
    parser.add_argument("--random-depths", default="6,7")
    args = parser.parse_args()
    print(f"3-RPR aspects over (x, y, phi), assembly modes, motions (x86_64, {os.cpu_count()} cores, "
          f"load average {os.getloadavg()[0]:.1f}); every row in a fresh interpreter")
    print(f"{'case':38s} {'seconds':>8s} {'paving':>7s} {'certif':>7s} {'probe':>7s} {'boxes':>9s} "
          f"{'peak MiB':>8s} {'RSS MiB':>8s}  result")
    for name, config in (("Caro's example (full turn)", CARO), ("general example [0, 60] deg", GENERAL)):
        for depth in (int(d) for d in args.depths.split(",")):
            r = row("aspects", config, str(depth))
            print(f"{name + ', aspects, depth ' + str(depth):38s} {r['seconds']:8.2f} {r['paving']:7.2f} "
                  f"{r['certificate']:7.2f} {r['probe']:7.2f} {r['evaluations']:9d} {r['peak']:8.1f} "
                  f"{r['rss']:8.1f}  {r['what']}")
    for name, config, arg in (("dkp, ALIAS example", None, "7.0710678118654755,5.0990195135927845,5"),
                              ("dkp, legs (14.98, 15.38, 12)", CARO, "14.98,15.38,12")):
        if config is None:
            config = Path(os.environ.get("TMPDIR", "/tmp")) / "bench-alias.yaml"
            config.write_text("name: alias\ntype: rpr3\nbase: {B1: [0, 0], B2: [10, 0], B3: [3, 10]}\n"
                              "platform: {P1: [0, 0], P2: [4, 0], P3: [2, 2]}\nlegs: {rho_min: 1, rho_max: 12}\n"
                              "phi_range: [-180, 180]\n")
        r = row("dkp", config, arg)
        print(f"{name:38s} {r['seconds']:8.3f} {'':7s} {'':7s} {'':7s} {r['evaluations']:9d} {r['peak']:8.1f} "
              f"{r['rss']:8.1f}  {r['what']}")
    for depth in (6, 7):  # the dkp that finds the modes included
        r = row("path", CARO, f"{depth},1,2")
        print(f"{'path, modes 1 to 2, depth ' + str(depth):38s} {r['seconds']:8.3f} {'':7s} {'':7s} {'':7s} "
              f"{'':9s} {r['peak']:8.1f} {r['rss']:8.1f}  {r['what']}")
    if args.random:
        random_robots(args.random, [int(d) for d in args.random_depths.split(",")])


if __name__ == "__main__":
    main()
