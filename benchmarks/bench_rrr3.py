"""3-RRR (issue 23): certified workspaces, singularity-free regions and aspects of the symmetric
design (configs/rrr3-symmetric*.yaml), against Codac's sivia for the reachable set.

Run from the repository root: `.venv/bin/python benchmarks/bench_rrr3.py`. Rows:

- the reachable set at phi = 0 (a quadtree, depth 10): seconds, boxes tested, the certified inside
  area against the exact one (three annuli by arcs) and whether inside <= exact <= inside +
  undetermined; Codac 2.1.2's `sivia` of the same set (the squared distances to the three centres
  A_i - R(0) c_i in their annuli) at eps = the root's width / 2^10 on the same box (a
  benchmark-only dependency, `pip install codac==2.1.2`; its row is skipped without it);
- the aspects at phi = 0 (all 8 working modes, 16 classes) at depths 7, 9 and 10: the count and
  whether it is certified;
- over phi in [-30, 30]: the reachable octree at depth 6, one singularity-free region (+-+, det A
  < 0) at depth 5, the joint space at depth 4, `verify` of each working mode, and the aspects
  at depth 6.

Every row runs in a fresh interpreter; seconds are wall time, memory the child's max RSS.
"""

from __future__ import annotations

import json
import os
import sys
import time
from pathlib import Path

from bench_rpr3_octree import child as fresh_child

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

PHI0 = ROOT / "configs" / "rrr3-symmetric-phi0.yaml"
RANGE = ROOT / "configs" / "rrr3-symmetric.yaml"


def timed(fn):
    t0 = time.perf_counter()
    value = fn()
    return time.perf_counter() - t0, value


def job_reachable() -> dict:
    from fivebar_cli.analyses.spaces import pave_space
    from fivebar_cli.mechanisms.registry import load_config

    m = load_config(PHI0)
    exact = m.exact_measure("workspace")
    seconds, p = timed(lambda: pave_space(m, "workspace", 10))
    inside, und = p.inside.area, p.undetermined_area
    return {"seconds": seconds, "what": f"{p.evaluations} boxes tested, inside {inside / exact:.2%} of exact "
                                        f"{exact:.6f}, bracket {'holds' if inside <= exact <= inside + und else 'FAILS'}"}


def job_codac() -> dict:
    from codac_peer import import_codac

    from fivebar_cli.mechanisms.registry import load_config
    from fivebar_cli.mechanisms.rrr3.model import annuli

    m = load_config(PHI0)  # before codac: it rounds upward from its import on (codac_peer.py)
    (xlo, xhi), (ylo, yhi) = m.spaces()["workspace"].root
    centres, radii, _ = annuli(m, 0.0)
    codac = import_codac()
    if codac is None:
        return {"skip": "codac not installed: pip install codac==2.1.2"}
    x = codac.VectorVar(2)
    f = codac.AnalyticFunction([x], codac.vec(*(codac.sqr(x[0] - cx) + codac.sqr(x[1] - cy)
                                               for cx, cy in centres[::2])))
    y = codac.IntervalVector([[radii[2 * i + 1] ** 2, radii[2 * i] ** 2] for i in range(3)])
    eps = (xhi - xlo) / 2 ** 10
    seconds, p = timed(lambda: codac.sivia(codac.IntervalVector([[xlo, xhi], [ylo, yhi]]), f, y, eps, False))
    inner = len(p.boxes(codac.PavingInOut.inner))
    outer = len(p.boxes(codac.PavingInOut.outer))
    return {"seconds": seconds, "what": f"{inner} inner boxes, {outer - inner} boundary boxes (eps {eps:.4g})"}


def job_aspects(depth: int) -> dict:
    from fivebar_cli.analyses.pose_aspects import analyse_pose_aspects
    from fivebar_cli.mechanisms.registry import load_config

    m = load_config(PHI0)
    seconds, a = timed(lambda: analyse_pose_aspects(m, depth))
    return {"seconds": seconds, "what": a.headline().split(": ", 1)[1]}


def job_octrees() -> dict:
    from fivebar_cli.analyses.spaces import pave_space
    from fivebar_cli.mechanisms.registry import load_config
    from fivebar_cli.mechanisms.rrr3.model import sign_region

    m = load_config(RANGE)
    rows = []
    for what, space, depth, region in (("reachable octree", "workspace", 6, None),
                                       ("+-+ det A < 0 octree", "workspace", 5, sign_region("+-+", "-")),
                                       ("joint space (3-torus)", "jointspace", 4, None)):
        seconds, p = timed(lambda: pave_space(m, space, depth, region=region))
        rows.append(f"{what}, depth {depth}: {seconds:.2f} s, {p.evaluations} boxes tested, {len(p.inside)} inside "
                    f"cells, {len(p.undetermined)} undetermined")
    return {"rows": rows}


def job_verify() -> dict:
    from fivebar_cli.analyses.pose_verify import verify
    from fivebar_cli.mechanisms.registry import load_config

    m = load_config(RANGE)
    seconds, results = timed(lambda: [verify(m, 14, sheet) for sheet in range(8)])
    statuses = sorted({r.status for r in results})
    return {"seconds": seconds, "what": f"8 working modes: {', '.join(statuses)}; "
                                        f"{sum(r.evaluations for r in results)} boxes tested"}


def job_aspects_range() -> dict:
    from fivebar_cli.analyses.pose_aspects import analyse_pose_aspects
    from fivebar_cli.mechanisms.registry import load_config

    m = load_config(RANGE)
    seconds, a = timed(lambda: analyse_pose_aspects(m, 6))
    return {"seconds": seconds, "what": a.headline().split(": ", 1)[1]}


JOBS = {"reachable": job_reachable, "codac": job_codac, **{f"aspects{d}": (lambda d=d: job_aspects(d)) for d in (7, 9, 10)},
        "octrees": job_octrees, "verify": job_verify, "aspects-range": job_aspects_range}


def child(name: str) -> tuple[dict, float]:
    """One job in a fresh interpreter: its result and max RSS (MiB)."""
    return fresh_child(name, __file__)


def main() -> None:
    import platform

    print(f"3-RRR benchmark ({platform.machine()}, {os.cpu_count()} cores, Python {platform.python_version()}, "
          f"load average {os.getloadavg()[0]:.1f})")
    print("symmetric 3-RRR at phi = 0 (configs/rrr3-symmetric-phi0.yaml)")
    for key, label in (("reachable", "fivebar reachable quadtree, depth 10"), ("codac", "Codac sivia, same set")):
        res, rss = child(key)
        if "skip" in res:
            print(f"  {label:38s} {res['skip']}")
            continue
        print(f"  {label:38s} {res['seconds']:8.3f} s  max RSS {rss:6.1f} MiB  {res['what']}")
    for depth in (7, 9, 10):
        res, rss = child(f"aspects{depth}")
        print(f"  aspects, depth {depth}  {res['seconds']:8.2f} s  max RSS {rss:6.1f} MiB  {res['what']}")
    print("symmetric 3-RRR over phi in [-30, 30] (configs/rrr3-symmetric.yaml)")
    res, rss = child("octrees")
    for row in res["rows"]:
        print(f"  {row}")
    print(f"  (max RSS {rss:.1f} MiB)")
    res, rss = child("verify")
    print(f"  verify: {res['seconds']:.2f} s, max RSS {rss:.1f} MiB, {res['what']}")
    res, rss = child("aspects-range")
    print(f"  aspects, depth 6  {res['seconds']:8.2f} s  max RSS {rss:6.1f} MiB  {res['what']}")


if __name__ == "__main__":
    if len(sys.argv) == 3 and sys.argv[1] == "--job":
        print(json.dumps(JOBS[sys.argv[2]]()))
    else:
        main()
