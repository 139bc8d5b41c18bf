"""Speed and scale of the analyses (issue 22): how time and memory grow with the depth, what
`--jobs 2` gains over `--jobs 1`, and Codac side by side in the same run.

    python benchmarks/bench_scale.py                      # M1 aspects 10-16, 3-RPR octrees 6-9
    python benchmarks/bench_scale.py --aspects 10,12,14 --octrees 6,7,8 --jobs 1,2 --repeat 3

M1 aspects: the whole `fivebar aspects configs/m1.yaml --no-plot` pipeline (mode pavings,
certificate, crossings, inscribed shapes, every file written), as the command calls the library.
3-RPR octrees: `fivebar rpr3 pave configs/rpr3-table1.yaml` (Table 1's design: the reachable set and
both signs of det J), pavings only. Every row runs in a fresh interpreter; seconds are wall time
(best of --repeat, the worker counts of a depth taking turns; with 3 runs or more, the ratio of
the medians too: a best run may be a lucky one), CPU seconds those of the best run's processes
together (user + system: what `--jobs 2` spends beyond `--jobs 1` is the work its workers
duplicate or slow down, not waiting), memory the largest max RSS of the run's processes (its
workers included); cells are the undetermined cells of the mode pavings (the boundary the work
follows); growth is the ratio to the row two depths above, per level (sqrt). Codac 2.1.2 (`pip
install codac`, a benchmark-only dependency): `sivia` of M1's workspace (the two annuli) at eps =
26/2^10 plus `connected_subsets` of the result, the peer the aspects pipeline at depth 12 is
compared with.
The machine's load average is printed: other processes on a shared machine slow every row, and
`--jobs 2` gains nothing when the second core is busy. fivebar's bytecode is compiled first (as pip
compiles an installed package), by this process, which never imports codac: every row reads it,
none compiles ~100 modules in its timed part (0.1 s of a depth-12 row, and as much per worker).
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

M1 = ROOT / "configs" / "m1.yaml"
TABLE1 = ROOT / "configs" / "rpr3-table1.yaml"


def job_aspects(depth: int, jobs: int) -> dict:
    from fivebar_cli.analyses.aspect_files import aspect_set, write_aspects
    from fivebar_cli.analyses.aspects import analyse_aspects
    from fivebar_cli.mechanisms.registry import load_config

    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        m = load_config(M1)
        analysis = analyse_aspects(m, depth, jobs=jobs)
        with aspect_set(Path(tmp)):
            write_aspects(Path(tmp), analysis, jobs)
        seconds = time.perf_counter() - t0
    cells = sum(len(r.paving.undetermined) for r in analysis.regions)
    return {"seconds": seconds, "cells": cells, "what": f"{len(analysis.aspects)} aspects, certified "
            f"{analysis.certified}, {sum(len(a.workspace) + len(a.jointspace) for a in analysis.aspects)} aspect leaves"}


def job_octree(depth: int, jobs: int) -> dict:
    from fivebar_cli.analyses.spaces import pave_regions
    from fivebar_cli.mechanisms.registry import load_config

    t0 = time.perf_counter()
    pavings = pave_regions(load_config(TABLE1), "workspace", depth, jobs=jobs)
    seconds = time.perf_counter() - t0
    boxes = sum(p.evaluations for p in pavings.values())
    return {"seconds": seconds, "cells": sum(len(p.undetermined) for p in pavings.values()), "boxes": boxes,
            "what": f"{boxes} boxes tested, {seconds / boxes * 1e6:.2f} us a box"}


def job_codac() -> dict:
    from codac_peer import import_codac

    from fivebar_cli.mechanisms.registry import load_config

    m = load_config(M1)  # before codac: it rounds upward from its import on (codac_peer.py)
    codac = import_codac()
    if codac is None:
        return {"skip": "codac not installed: pip install codac==2.1.2"}
    x = codac.VectorVar(2)
    f = codac.AnalyticFunction([x], codac.vec(codac.sqr(x[0]) + codac.sqr(x[1]),
                                              codac.sqr(x[0] - m.L0) + codac.sqr(x[1])))
    y = codac.IntervalVector([[(m.L1 - m.L3) ** 2, (m.L1 + m.L3) ** 2], [(m.L2 - m.L4) ** 2, (m.L2 + m.L4) ** 2]])
    (xlo, xhi), (ylo, yhi) = m.spaces()["workspace"].root
    t0 = time.perf_counter()
    p = codac.sivia(codac.IntervalVector([[xlo, xhi], [ylo, yhi]]), f, y, (xhi - xlo) / 2**10, False)
    subsets = p.connected_subsets(codac.PavingInOut.inner)
    return {"seconds": time.perf_counter() - t0, "cells": len(p.boxes(codac.PavingInOut.inner)),
            "what": f"{len(subsets)} connected subset(s)"}


def child(args: list[str]) -> dict:
    """One job in a fresh interpreter: its result, the max RSS (MiB) of it and its workers, and
    their CPU seconds (user + system: the work done, where `seconds` is the wait)."""
    proc = subprocess.Popen([sys.executable, __file__, "--job", *args], stdout=subprocess.PIPE, text=True, cwd=ROOT)
    out = proc.stdout.read()
    _, status, usage = os.wait4(proc.pid, 0)
    if os.waitstatus_to_exitcode(status):
        raise SystemExit(f"job {args} failed")
    result = json.loads(out)
    result["rss"] = max(usage.ru_maxrss / 1024, result.pop("workers_rss"))
    result["cpu"] = usage.ru_utime + usage.ru_stime
    return result


def best(args: list[str], repeat: int) -> dict:
    runs = [child(args) for _ in range(repeat)]
    return min(runs, key=lambda r: r.get("seconds", 0.0))


def best_of_each(kind: str, depth: int, jobs: list[int], repeat: int) -> dict:
    """The best run of each worker count, the counts taking turns (1, 2, 1, 2, ...): on a machine
    whose speed drifts from one minute to the next (a shared VM), each count meets the same
    spells, where runs of one count after the other would compare two moments."""
    runs = {j: [] for j in jobs}
    for _ in range(repeat):
        for j in jobs:
            runs[j].append(child([kind, str(depth), str(j)]))
    return {j: {**min(r, key=lambda row: row["seconds"]), "median": statistics.median(row["seconds"] for row in r)}
            for j, r in runs.items()}


def table(title: str, kind: str, depths: list[int], jobs: list[int], repeat: int) -> dict:
    print(title)
    print(f"  {'d':>2s} {'jobs':>4s} {'seconds':>8s} {'CPU s':>6s} {'max RSS MiB':>11s} {'cells':>9s} {'time/level':>10s} "
          f"{'RSS/level':>9s} {'cells/level':>11s}  what")
    out = {}
    for depth in depths:
        turns = best_of_each(kind, depth, jobs, repeat)
        for j in jobs:
            r = out[depth, j] = turns[j]
            prev = out.get((depth - 2, j)) or out.get((depth - 1, j))
            levels = 2 if (depth - 2, j) in out else 1
            growth = ("" if prev is None else
                      f"{(r['seconds'] / prev['seconds']) ** (1 / levels):10.2f} {(r['rss'] / prev['rss']) ** (1 / levels):9.2f} "
                      f"{(r['cells'] / prev['cells']) ** (1 / levels):11.2f}")
            print(f"  {depth:2d} {j:4d} {r['seconds']:8.2f} {r['cpu']:6.2f} {r['rss']:11.1f} {r['cells']:9d} "
                  f"{growth or ' ' * 32:32s}  {r['what']}", flush=True)
        if len(jobs) > 1:
            first, last = out[depth, jobs[0]], out[depth, jobs[-1]]
            medians = f", {first['median'] / last['median']:.2f}x by the medians" if repeat > 2 else ""
            print(f"     --jobs {jobs[-1]} is {first['seconds'] / last['seconds']:.2f}x faster than --jobs {jobs[0]} "
                  f"(best runs{medians})", flush=True)
    return out


def main() -> None:
    import platform

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--aspects", default="10,12,14,16", help="Depths of M1's aspects ('' for none).")
    parser.add_argument("--octrees", default="6,7,8,9", help="Depths of the 3-RPR octrees ('' for none).")
    parser.add_argument("--jobs", default="1,2", help="Worker counts compared.")
    parser.add_argument("--repeat", type=int, default=1, help="Runs per row (the best is shown).")
    args = parser.parse_args()
    import compileall

    compileall.compile_dir(ROOT / "fivebar_cli", quiet=1)  # before any codac process (README: the codac caveat)
    depths = {k: [int(d) for d in getattr(args, k).split(",") if d] for k in ("aspects", "octrees")}
    jobs = [int(j) for j in args.jobs.split(",")]
    print(f"scale benchmark ({platform.machine()}, {os.cpu_count()} cores, Python {platform.python_version()}, "
          f"load average {os.getloadavg()[0]:.1f} at the start)")
    codac = best(["codac"], args.repeat)
    if "skip" in codac:
        print(f"Codac: {codac['skip']}")
    else:
        print(f"Codac 2.1.2 sivia + connected_subsets, M1 workspace, eps 26/2^10: {codac['seconds']:.3f} s, max RSS "
              f"{codac['rss']:.1f} MiB, {codac['cells']} inner boxes, {codac['what']}")
    if depths["aspects"]:
        rows = table("M1 aspects, whole pipeline without plots (fivebar aspects configs/m1.yaml --no-plot)",
                     "aspects", depths["aspects"], jobs, args.repeat)
        if "skip" not in codac and (12, 1) in rows:
            print(f"  depth 12, --jobs 1: {rows[12, 1]['seconds'] / codac['seconds']:.2f}x Codac's time (target <= 0.5)")
    if depths["octrees"]:
        table("3-RPR octrees, Table 1's design, three regions (fivebar rpr3 pave configs/rpr3-table1.yaml)",
              "octree", depths["octrees"], jobs, args.repeat)
    print(f"load average {os.getloadavg()[0]:.1f} at the end")


if __name__ == "__main__":
    if len(sys.argv) >= 3 and sys.argv[1] == "--job":
        kind, rest = sys.argv[2], [int(v) for v in sys.argv[3:]]
        result = {"aspects": job_aspects, "octree": job_octree, "codac": job_codac}[kind](*rest)
        import resource

        result["workers_rss"] = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024  # reaped workers
        print(json.dumps(result))
    else:
        main()
