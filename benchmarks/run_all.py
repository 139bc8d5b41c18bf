"""Run every benchmark (what `make bench` does): paving, aspects, tolerances, constraints, path, locate
against path, 3-RPR, 3-RPR octrees and aspects, view pages, atlas. Prints their tables."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
SCRIPTS = ("bench_paving.py", "bench_aspects.py", "bench_tolerance.py", "bench_constraints.py", "bench_path.py",
           "bench_locate_path.py", "bench_rpr3.py", "bench_rpr3_octree.py", "bench_pose_aspects.py", "bench_view.py",
           "bench_atlas.py", "bench_rrr3.py")


def main() -> int:
    status = 0
    for script in SCRIPTS:
        print(f"== {script}", flush=True)
        status |= subprocess.call([sys.executable, str(HERE / script)])
    return status


if __name__ == "__main__":
    sys.exit(main())
