"""3-RPR octrees (issue 11): `rpr3 verify` of the paper's [1, 1.5] design against Codac's sivia.

Run from the repository root: `.venv/bin/python benchmarks/bench_rpr3_octree.py`. Target: `verify`
of the paper's recommended leg range [1, 1.5] for Table 1's design over [100, 165] degrees is faster
than Codac's `sivia` computing the reachable set alone (the three squared leg lengths in
[1, 2.25]) at eps = 6/2^7 on the same box (our root box, phi in degrees). Codac 2.1.2 is a
benchmark-only dependency (`pip install codac==2.1.2`); without it its rows are skipped. A second
Codac row gives it phi in radians on the same box (the same poses), which bisects phi far less.

Also: `rpr3 pave` of Table 1's design with case 4's legs (inside volume against the exact one,
depth 6 to 8) and of the general example at depth 7. Every row runs in a fresh interpreter;
seconds are wall time (best of the repeats), memory the child's max RSS (and, for ours, the
tracemalloc peak of the Python and numpy heap).
"""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
import time
import tracemalloc
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

PAPER_DESIGN = ROOT / "configs" / "rpr3-verify" / "table1-legs-1-1.5.yaml"
GENERAL = ROOT / "configs" / "rpr3-general.yaml"
CASE4 = {"name": "case4", "type": "rpr3",
         "base": {"t1": 1.5196713713031851, "t2": 0.7598356856515925, "t3": 1.3160740129524924}, "k": 0.6,
         "legs": {"rho_min": 0.412168, "rho_max": 2.075469}, "phi_range": [100, 165]}
EPS = 6 / 2**7
REPEAT = 5


def best_of(fn, repeat: int):
    fn()  # warm-up: imports, caches
    best, value = math.inf, None
    for _ in range(repeat):
        t0 = time.perf_counter()
        value = fn()
        best = min(best, time.perf_counter() - t0)
    tracemalloc.start()
    fn()
    peak = tracemalloc.get_traced_memory()[1] / 2**20
    tracemalloc.stop()
    return best, peak, value


def job_verify() -> dict:
    from fivebar_cli.mechanisms.registry import load_config
    from fivebar_cli.analyses.pose_verify import verify

    m = load_config(PAPER_DESIGN)
    seconds, peak, r = best_of(lambda: verify(m, 14), REPEAT)
    return {"seconds": seconds, "peak": peak, "what": f"{r.status}, depth {r.depth}, {r.evaluations} boxes tested"}


def job_reachable(depth: int) -> dict:
    from fivebar_cli.analyses.spaces import pave_space
    from fivebar_cli.mechanisms.registry import load_config

    m = load_config(PAPER_DESIGN)
    seconds, peak, p = best_of(lambda: pave_space(m, "workspace", depth), 1)
    return {"seconds": seconds, "peak": peak,
            "what": f"{p.evaluations} boxes tested, {len(p.inside)} inside, {len(p.undetermined)} undetermined"}


def codac_box(radians: bool):
    from fivebar_cli.mechanisms.registry import load_config

    m = load_config(PAPER_DESIGN)
    (xlo, xhi), (ylo, yhi), (plo, phi_hi) = m.spaces()["workspace"].root
    scale = math.pi / 180 if radians else 1.0
    return m, [[xlo, xhi], [ylo, yhi], [plo * scale, phi_hi * scale]]


def job_codac(radians: bool) -> dict:
    from codac_peer import import_codac

    m, box = codac_box(radians)  # before codac: it rounds upward from its import on (codac_peer.py)
    codac = import_codac()
    if codac is None:
        return {"skip": "codac not installed: pip install codac==2.1.2"}
    x = codac.VectorVar(3)
    angle = x[2] if radians else x[2] * (math.pi / 180)
    c, s = codac.cos(angle), codac.sin(angle)
    legs = []
    for (bx, by), (px, py) in zip(m.base, m.platform):
        legs.append(codac.sqr(x[0] + px * c - py * s - bx) + codac.sqr(x[1] + px * s + py * c - by))
    f = codac.AnalyticFunction([x], codac.vec(*legs))
    lo, hi = m.leg_limits()
    y = codac.IntervalVector([[a * a, b * b] for a, b in zip(lo, hi)])
    x0 = codac.IntervalVector(box)

    t0 = time.perf_counter()  # one run: Codac's own heap is C++ (max RSS below), no warm-up needed
    p = codac.sivia(x0, f, y, EPS, False)
    seconds = time.perf_counter() - t0
    inner = len(p.boxes(codac.PavingInOut.inner))
    outer = len(p.boxes(codac.PavingInOut.outer))
    return {"seconds": seconds, "peak": None, "what": f"{inner} inner boxes, {outer - inner} boundary boxes"}


def job_case4() -> dict:
    from fivebar_cli.analyses.spaces import pave_space
    from fivebar_cli.mechanisms.rpr3.model import PLUS, Rpr3

    m = Rpr3.parse(CASE4, "<bench>")
    exact = m.exact_measure("workspace")
    rows = []
    for depth in (6, 7, 8):
        t0 = time.perf_counter()
        p = pave_space(m, "workspace", depth)
        q = pave_space(m, "workspace", depth, region=PLUS)
        rows.append((depth, time.perf_counter() - t0, p.evaluations + q.evaluations, p.inside.area / exact,
                     p.inside.area <= exact <= p.inside.area + p.undetermined_area,
                     q.inside.area <= m.exact_measure("workspace", PLUS) <= q.inside.area + q.undetermined_area))
    return {"exact": exact, "rows": rows}


def job_general() -> dict:
    from fivebar_cli.analyses.spaces import pave_space
    from fivebar_cli.mechanisms.registry import load_config

    m = load_config(GENERAL)
    t0 = time.perf_counter()
    count = sum(pave_space(m, "workspace", 7, region=r).evaluations for r in m.regions("workspace"))
    return {"seconds": time.perf_counter() - t0, "what": f"{count} boxes tested (three regions)"}


JOBS = {"verify": job_verify, "reachable7": lambda: job_reachable(7), "codac-deg": lambda: job_codac(False),
        "codac-rad": lambda: job_codac(True), "case4": job_case4, "general": job_general}


def child(name: str, script: str = __file__) -> tuple[dict, float]:
    """Run one job of a benchmark script (this one by default) in a fresh interpreter: its result
    (the JSON it prints) and max RSS (MiB)."""
    proc = subprocess.Popen([sys.executable, script, "--job", name], stdout=subprocess.PIPE, text=True, cwd=ROOT)
    out = proc.stdout.read()
    _, status, usage = os.wait4(proc.pid, 0)
    if os.waitstatus_to_exitcode(status):
        raise SystemExit(f"job {name} failed")
    return json.loads(out), usage.ru_maxrss / 1024


def main() -> None:
    import platform

    print(f"3-RPR octree benchmark ({platform.machine()}, {os.cpu_count()} cores, Python {platform.python_version()}, "
          f"load average {os.getloadavg()[0]:.1f})")
    print(f"paper's design (Table 1, k = 0.6), legs [1, 1.5], phi in [100, 165] deg; Codac eps = 6/2^7 = {EPS}")
    ours, rss = child("verify")
    print(f"  fivebar rpr3 verify (library)            {ours['seconds']:8.4f} s  peak {ours['peak']:6.1f} MiB "
          f"max RSS {rss:6.1f} MiB  {ours['what']}")
    r7, rss7 = child("reachable7")
    print(f"  our reachable octree alone, depth 7      {r7['seconds']:8.4f} s  peak {r7['peak']:6.1f} MiB "
          f"max RSS {rss7:6.1f} MiB  {r7['what']}")
    for key, label in (("codac-deg", "Codac sivia, reachable set, phi in deg"), ("codac-rad", "Codac sivia, same box, phi in rad")):
        res, rss_c = child(key)
        if "skip" in res:
            print(f"  {label:40s} {res['skip']}")
            continue
        print(f"  {label:40s} {res['seconds']:8.4f} s  {'':17s} max RSS {rss_c:6.1f} MiB  {res['what']}"
              f"  (verify {res['seconds'] / ours['seconds']:.0f}x faster)")
    c4, rss4 = child("case4")
    print(f"Table 1's design, case 4 legs [0.412168, 2.075469]: exact reachable volume {c4['exact']:.8f} (x y deg)")
    for depth, seconds, count, ratio, bracket, bracket_w in c4["rows"]:
        print(f"  depth {depth}: reachable + det J > 0 trees {seconds:6.2f} s, {count:8d} boxes tested, inside "
              f"{ratio:.2%} of exact, bracket {'holds' if bracket and bracket_w else 'FAILS'}")
    print(f"  max RSS {rss4:.1f} MiB")
    gen, rss_g = child("general")
    print(f"general example (configs/rpr3-general.yaml), depth 7: {gen['seconds']:.2f} s, {gen['what']}, "
          f"max RSS {rss_g:.1f} MiB")


if __name__ == "__main__":
    if len(sys.argv) == 3 and sys.argv[1] == "--job":
        print(json.dumps(JOBS[sys.argv[2]]()))
    else:
        main()
