"""`fivebar path` speed, and the largest circles and squares, against uncertified peers.

1. `fivebar path`: a certified motion across aspect 1 of M1, cold (nothing saved: the one
   joint-space paving the motion needs) and warm (reusing the aspect trees an `aspects` run saved
   into -o), with and without the figure; also a motion that does not exist (different aspects:
   the aspect analysis runs to say so). Each run is a whole `fivebar path` command, in this
   process after a warm-up (imports loaded once; a fresh process adds about 0.3 s of imports).
   Peer: A* on the 8-connected grid of the 4^d cell centres classified by the point kinematics
   (dense grid, torus), the usual motion planner; it samples centres, so its path is not
   certified, and it is a staircase (its length is given for comparison).
2. Short motions: the length of the certified motion against the shortest polyline through the
   same certified cells, computed independently by shapely (a visibility graph on the reflex
   corners of the union of the cells, Dijkstra; tests/reference_paths.py). The issue's two cases
   (2-RPR (5, 6) -> (10, 12): the straight 7.81; M1 (0, 1) -> (0.6, 0.6): 0.72), then random
   pairs of joint values in one mode set of M1, M2 and the 2-RPR; also the string pulled through
   A*'s chain of cells alone (what `path` returned before issue 20) for comparison.
3. Largest circle and square of the ten aspects of M1 (`inscribed.py`, certified, within 1 %),
   against shapely's maximum_inscribed_circle (GEOS, tolerance 1e-3 r) and polylabel on the
   same cells made a polygon (io/geojson.py; the polygon's build time is its own column). shapely
   has no largest square. Neither peer certifies its disc.

Seconds are the best of --repeat runs; peak memory from tracemalloc (numpy and Python heap) on
one more run.

    python benchmarks/bench_path.py [--depths 10,12] [--repeat 3] [--pairs 20] [--pair-depth 10]
"""

from __future__ import annotations

import argparse
import contextlib
import heapq
import io
import math
import sys
import tempfile
import time
import tracemalloc
from itertools import product
from pathlib import Path

import numpy as np
from bench_paving import measured  # (result, seconds, peak MiB); benchmarks/ is on sys.path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from reference_paths import shortest_through_tree  # noqa: E402

from fivebar_cli.analyses.aspects import analyse_aspects
from fivebar_cli.analyses.channel import containing_leaves, find_chain, lift, portals, pull_string, string_length
from fivebar_cli.analyses.inscribed import largest_disc, largest_square
from fivebar_cli.cli import main as cli_main
from fivebar_cli.io.geojson import tree_geometry
from fivebar_cli.analyses.paths import Endpoint, NoPath, find_path, mode_cells, resolve
from fivebar_cli.mechanisms.registry import load_config

CONFIGS = Path(__file__).resolve().parents[1] / "configs"
CONFIG = CONFIGS / "m1.yaml"
MOTION = ["--joints", "-0.09817477", "-2.06167018", "--joints", "0.88357293", "1.47262156", "--assembly-mode", "+"]
NO_MOTION = ["--joints", "-2.25801972", "-2.06167018", "--joints", "1.05537878", "2.03712649", "--assembly-mode", "+"]


def run(args: list[str]) -> int:
    try:
        with contextlib.redirect_stderr(io.StringIO()):  # the one-line reasons of the failing case
            cli_main([str(a) for a in args])
    except SystemExit as exc:
        return int(exc.code or 0)
    return 0


def mode_grid(m, depth: int) -> np.ndarray:
    """Free cells of working mode ++, det A > 0 on the 2^d x 2^d grid of joint-space cell centres."""
    n = 1 << depth
    model = m.aspect_model()
    centres = -math.pi + (np.arange(n) + 0.5) * (2 * math.pi / n)
    free = np.zeros((n, n), bool)
    for r in range(0, n, max(1, (1 << 20) // n)):
        rows = np.arange(r, min(n, r + max(1, (1 << 20) // n)))
        t1, t2 = np.meshgrid(centres, centres[rows])  # row index is theta2
        joints = np.column_stack([t1.ravel(), t2.ravel()])
        poses, ok = model.dkp(joints, 1)
        values = model.mode_values(joints, np.where(ok[:, None], poses, 0.0))
        free[rows] = (ok & np.all(values > 0, axis=1)).reshape(len(rows), n)
    return free


def grid_astar(free: np.ndarray, start, goal) -> tuple[int, float, int]:
    """A* on the 8-connected torus grid from joint values `start` to `goal`: (expanded, length in
    radians, path cells), length -1 when there is no path."""
    n = free.shape[0]
    h = 2 * math.pi / n
    cell = lambda q: (int((q[1] + math.pi) // h) % n, int((q[0] + math.pi) // h) % n)
    s, g = cell(start), cell(goal)

    def dist(a, b):
        dy, dx = abs(a[0] - b[0]), abs(a[1] - b[1])
        dy, dx = min(dy, n - dy), min(dx, n - dx)
        return (max(dx, dy) - min(dx, dy) + math.sqrt(2) * min(dx, dy)) * h

    steps = [(dy, dx, math.hypot(dy, dx) * h) for dy in (-1, 0, 1) for dx in (-1, 0, 1) if dy or dx]
    best, parent, heap, expanded = {s: 0.0}, {s: None}, [(dist(s, g), 0.0, s)], 0
    done = set()
    while heap:
        _, cost, c = heapq.heappop(heap)
        if c in done:
            continue
        done.add(c)
        expanded += 1
        if c == g:
            length, k = 0, c
            while k is not None:
                length, k = length + 1, parent[k]
            return expanded, cost, length
        for dy, dx, w in steps:
            nb = ((c[0] + dy) % n, (c[1] + dx) % n)
            if free[nb] and cost + w < best.get(nb, math.inf):
                best[nb], parent[nb] = cost + w, c
                heapq.heappush(heap, (cost + w + dist(nb, g), cost + w, nb))
    return expanded, -1.0, 0


def joints_of(motion: list[str]) -> tuple[tuple[float, float], tuple[float, float]]:
    k = [i for i, a in enumerate(motion) if a == "--joints"]
    return tuple((float(motion[i + 1]), float(motion[i + 2])) for i in k)


def path_length(csv_file: Path) -> tuple[int, float]:
    rows = np.loadtxt(csv_file, delimiter=",", skiprows=1, ndmin=2)[:, :2]
    steps = (np.diff(rows, axis=0) + math.pi) % (2 * math.pi) - math.pi
    return len(rows), float(np.hypot(*steps.T).sum())


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


def chain_only(cells, start, end) -> float:
    """The string pulled through A*'s chain of cells alone (the motion before issue 20)."""
    chain = find_chain(cells, containing_leaves(cells, start)[0], containing_leaves(cells, end)[0], start)
    grid = cells.grid
    return string_length(pull_string(start - grid.lo, lift(chain, end).unwrapped(grid) - grid.lo, portals(chain)))


def short_motion(m, depth: int, start, end, assembly: str, cells_of: dict):
    """(ours, seconds, waypoints, shapely's, seconds, chain only) for one pair, or None."""
    try:
        first, last = resolve(m, [Endpoint("joints", tuple(start)), Endpoint("joints", tuple(end))], assembly, "bench")
        key = (first.working, first.assembly)
        if key not in cells_of:
            cells_of[key] = mode_cells(m, depth, *key)
        t0 = time.perf_counter()
        result = find_path(m, depth, first, last, cells=cells_of[key], aspects=[])
        ours_s = time.perf_counter() - t0
    except NoPath:
        return None
    t0 = time.perf_counter()
    best = shortest_through_tree(cells_of[key], first.joints, last.joints, result.length * (1 + 1e-9))
    return (result.length, ours_s, len(result.joints), best, time.perf_counter() - t0,
            chain_only(cells_of[key], first.joints, last.joints))


def short_motions(depth: int, pairs: int) -> None:
    print(f"{'short motions (depth ' + str(depth) + ')':34s} {'pairs':>5s} {'ours':>8s} {'shapely':>8s} "
          f"{'max ratio':>9s} {'mean':>7s} {'chain only':>10s} {'waypts':>6s} {'ours s':>7s} {'shapely s':>9s}")
    cases = (("2-RPR (5, 6) -> (10, 12)", "rpr2", [((5, 6), (10, 12), "+")]),
             ("M1 (0, 1) -> (0.6, 0.6)", "m1", [((0, 1), (0.6, 0.6), "+")]))
    rng = np.random.default_rng(20)
    randoms = []
    for name in ("m1", "m2", "rpr2"):  # two points of the cells of one mode set (one aspect, or two)
        m = load_config(CONFIGS / f"{name}.yaml")
        model = m.aspect_model()
        todo = []
        for wm, am in product(model.working_modes, model.assembly_modes):
            cells = mode_cells(m, depth, "".join("+" if s > 0 else "-" for s in wm), "+" if am > 0 else "-")
            if not len(cells):
                continue
            lo, hi = cells.bounds()
            area = np.prod(hi - lo, axis=1)
            picks = rng.choice(len(lo), size=(2 * pairs, 2), p=area / area.sum())
            points = lo[picks] + rng.uniform(0.02, 0.98, picks.shape + (2,)) * (hi - lo)[picks]
            todo += [(tuple(a), tuple(b), "+" if am > 0 else "-") for a, b in points]
        order = rng.permutation(len(todo))
        randoms.append((f"{name} random pairs", name, [todo[k] for k in order]))
    for label, name, todo in (*cases, *randoms):
        m = load_config(CONFIGS / f"{name}.yaml")
        cells_of, rows = {}, []
        for start, end, assembly in todo:
            row = short_motion(m, depth, start, end, assembly, cells_of)
            if row is not None:
                rows.append(row)
            if len(rows) == (pairs if len(todo) > 1 else 1):
                break
        a = np.array(rows)
        ratio = a[:, 0] / a[:, 3]
        print(f"{label:34s} {len(a):5d} {a[:, 0].max() if len(a) == 1 else a[:, 0].mean():8.4f} "
              f"{a[:, 3].max() if len(a) == 1 else a[:, 3].mean():8.4f} {ratio.max():9.6f} {ratio.mean():7.5f} "
              f"{(a[:, 5] / a[:, 3]).max():10.4f} {int(a[:, 2].max()):6d} {a[:, 1].max():7.3f} {a[:, 4].max():9.3f}")
    print("(lengths: the one case, or the mean over the pairs; ratios: ours / shapely's; chain only: the max "
          "ratio of the string through A*'s chain alone; seconds: the slowest pair)")
    print()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--depths", default="12")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--pairs", type=int, default=12, help="random pairs per mechanism for the short motions")
    parser.add_argument("--pair-depth", type=int, default=10, help="depth of the short motions")
    args = parser.parse_args()
    short_motions(args.pair_depth, args.pairs)
    with tempfile.TemporaryDirectory() as tmp:
        warm_up = Path(tmp) / "warm-up"
        run(["path", CONFIG, *MOTION, "--depth", 8, "-o", warm_up, "-q"])  # imports, matplotlib
        depths = [int(d) for d in args.depths.split(",")]
        print(f"{'case':42s} {'d':>2s} {'seconds':>8s} {'peak MiB':>8s} {'exit':>4s}")
        for depth in depths:
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
        print()
        m = load_config(CONFIG)
        start, goal = joints_of(MOTION)
        print(f"{'motion across aspect 1 of M1':42s} {'d':>2s} {'seconds':>8s} {'peak MiB':>8s} {'waypoints':>9s} "
              f"{'length':>7s} {'expanded':>9s}")
        for depth in depths:
            cold = Path(tmp) / f"cold-{depth}"
            _, seconds, peak = measured(lambda: run(["path", CONFIG, *MOTION, "--depth", depth, "-o", cold, "-q",
                                                      "--no-plot"]))
            waypoints, length = path_length(cold / "path.csv")
            print(f"{'fivebar path (certified, string-pulled)':42s} {depth:2d} {seconds:8.3f} {peak:8.1f} "
                  f"{waypoints:9d} {length:7.4f} {'':>9s}")
            (expanded, length, cells), seconds, peak = measured(lambda: grid_astar(mode_grid(m, depth), start, goal))
            print(f"{'grid A* 8-connected (centres, uncertified)':42s} {depth:2d} {seconds:8.3f} {peak:8.1f} "
                  f"{cells:9d} {length:7.4f} {expanded:9d}")
        print()
        print(f"{'M1 aspects':10s} {'d':>2s} {'ours s':>7s} {'peak MiB':>8s} {'min r/mic':>9s} {'polygon s':>9s} "
              f"{'mic s':>7s} {'polylabel s':>11s} {'min r/pl':>8s} {'squares s':>9s}")
        for depth in depths:
            aspects = analyse_aspects(m, depth, shapes=False).aspects
            discs, disc_s, peak = measured(lambda: [largest_disc(a.workspace) for a in aspects])
            squares, square_s, _ = measured(lambda: [largest_square(a.workspace) for a in aspects])
            shapes, poly_s, _ = measured(lambda: [tree_geometry(a.workspace) for a in aspects])
            import shapely
            from shapely.ops import polylabel

            mic, mic_s, _ = measured(lambda: [shapely.maximum_inscribed_circle(g, tolerance=d.r * 1e-3).length
                                              for g, d in zip(shapes, discs)])

            def labels():
                out = []
                for g, d in zip(shapes, discs):
                    part = max(shapely.get_parts(g), key=lambda p: p.area)
                    out.append(polylabel(part, tolerance=d.r * 1e-3).distance(part.boundary))
                return out

            pl, pl_s, _ = measured(labels)
            ratio_mic = min(d.r / r for d, r in zip(discs, mic))
            ratio_pl = min(d.r / r for d, r in zip(discs, pl))
            print(f"{'discs':10s} {depth:2d} {disc_s:7.3f} {peak:8.1f} {ratio_mic:9.4f} {poly_s:9.3f} {mic_s:7.3f} "
                  f"{pl_s:11.3f} {ratio_pl:8.4f} {square_s:9.3f}")


if __name__ == "__main__":
    main()
