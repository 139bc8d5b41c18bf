"""`fivebar view` pages: file size, and the time headless Chromium takes to decode and paint them.

    python benchmarks/bench_view.py [--depths 10,12] [--runs 5]

For M1's aspects folder at each depth (`fivebar aspects --no-plot`, all 20 aspect trees) and for
an octree pair like `rpr3 pave` writes (the cone of tests/test_view.py at depth 7, with its
complement): black leaves, page size, and the median over the runs of what the page measures
itself: `paint ms` (decoding every tree and the first paint of every panel, performance.now()
around them) and `load ms` (from navigation start to the end of that paint: reading and parsing
the file too). Needs Chromium (tests/browser.py); prints a note and exits 0 without it.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))

from browser import body_attributes, find_chromium  # noqa: E402
from cli_helpers import ok, run_cli  # noqa: E402
from test_view import sphere_octree  # noqa: E402


def measure(chromium: str, page: Path, runs: int) -> tuple[int, float, float]:
    states = [body_attributes(chromium, page) for _ in range(runs)]
    assert all(s.get("data-ready") == "true" for s in states), states
    return (int(states[0]["data-cells"]), statistics.median(float(s["data-paint-ms"]) for s in states),
            statistics.median(float(s["data-load-ms"]) for s in states))


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--depths", default="10,12")
    parser.add_argument("--runs", type=int, default=5)
    args = parser.parse_args()
    chromium = find_chromium()
    if chromium is None:
        print("chromium not found: no page timings (make install installs it where apt-get is available)")
        return 0
    print(f"{'page':28s} {'leaves':>8s} {'size KiB':>9s} {'paint ms':>9s} {'load ms':>8s}")
    with tempfile.TemporaryDirectory(prefix="bench-view-") as tmp:
        cases = []
        for depth in (int(d) for d in args.depths.split(",")):
            folder = Path(tmp) / f"m1-d{depth}"
            ok(run_cli("aspects", ROOT / "configs" / "m1.yaml", "--depth", depth, "-o", folder, "--no-plot", "-q"))
            cases.append((f"M1 aspects, depth {depth}", folder))
        octree = Path(tmp) / "octree"
        octree.mkdir()
        sphere_octree(octree, depth=7)
        cases.append(("octree pair + 1, depth 7", octree))
        for name, folder in cases:
            page = folder / "view.html"
            ok(run_cli("view", folder, "-o", page, "-q"))
            cells, paint, load = measure(chromium, page, args.runs)
            print(f"{name:28s} {cells:8d} {page.stat().st_size / 1024:9.0f} {paint:9.0f} {load:8.0f}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
