"""`locate` against `path` on random pairs of configurations (tests/test_locate_path.py and
benchmarks/bench_locate_path.py).

For one mechanism and depth, one aspect analysis (what `locate` decides with) and one joint-space
paving per mode set (what `path` searches a chain of cells in) serve every pair. A pair is two
endpoints as the command line gives them (joints with an assembly mode, or poses with a working
mode): two points of one aspect's joint-space cells, points of two aspects of the same modes,
poses drawn from the workspace root, or joints drawn from the whole torus. Each pair is judged
twice, by `locate.decide` and by `paths.find_path`, and the two must agree:

- path finds a motion -> locate says yes (a chain of cells of one mode set lies in one aspect);
- path finds none -> its one line is locate's verdict (yes then means the aspect proves a motion
  that the cells at this depth do not show: "not decided", and why);
- locate says no -> the modes differ (checked with the independent kinematics of
  tests/reference_kinematics.py), or two certified aspects hold the two configurations: then
  `path` deeper (`recheck`) must find no motion either.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fivebar_cli.analyses.aspects import AspectAnalysis, analyse_aspects
from fivebar_cli.analyses.locate import NO, UNDECIDED, YES, Verdict, decide, mode_verdict
from fivebar_cli.analyses.paths import Endpoint, NoPath, PathResult, find_path, mode_cells, resolve
from fivebar_cli.mechanisms.fivebar.model import FiveBar, assembles

M1 = FiveBar("M1", 9.0, 8.0, 5.0, 5.0, 8.0)
M2 = FiveBar("M2", 2.55, 2.3, 2.3, 2.3, 2.3)
ROBUST_M1 = M1.widened(0.02, "--tolerance")
MAX_DEPTH = 16


def random_five_bars(count: int, seed: int) -> list[FiveBar]:
    """Five-bars with L0 in [0.2, 2] and the other lengths in [0.5, 2] that close (bench_aspects's
    range), drawn from a seed."""
    rng = np.random.default_rng(seed)
    out = []
    while len(out) < count:
        lengths = dict(zip(("L0", "L1", "L2", "L3", "L4"), [rng.uniform(0.2, 2)] + list(rng.uniform(0.5, 2, 4))))
        if assembles(lengths) is None:
            out.append(FiveBar(f"random-{seed}-{len(out)}", *(float(v) for v in lengths.values())))
    return out


@dataclass
class Setting:
    """One mechanism at one depth: its aspects and, lazily, its mode pavings."""

    mechanism: FiveBar
    depth: int
    analysis: AspectAnalysis
    cells: dict

    @classmethod
    def of(cls, m, depth: int) -> "Setting":
        return cls(m, depth, analyse_aspects(m, depth, shapes=False), {})

    def mode_cells(self, working: str, assembly: str):
        if (working, assembly) not in self.cells:
            self.cells[(working, assembly)] = mode_cells(self.mechanism, self.depth, working, assembly)
        return self.cells[(working, assembly)]


@dataclass
class Outcome:
    endpoints: tuple
    verdict: Verdict
    result: PathResult | None
    message: str  # path's one line when it found no motion
    separated: bool = False  # locate's no came from two certified aspects (not from the modes)


def _signs(text: str) -> str:
    return "".join("+" if s > 0 else "-" for s in text)


def _in_cells(rng, tree) -> tuple[float, float]:
    lo, hi = tree.bounds()
    k = rng.integers(len(lo))
    return tuple(float(v) for v in lo[k] + rng.uniform(0.02, 0.98, 2) * (hi[k] - lo[k]))


def random_pair(rng, s: Setting) -> tuple[list[Endpoint], str | None]:
    """Two endpoints and the assembly mode to give (None for poses)."""
    aspects = [a for a in s.analysis.aspects if len(a.jointspace)]
    kind = rng.integers(4) if aspects else 3
    grid = s.mechanism.spaces()["jointspace"].grid(s.depth)
    if kind == 0:  # two points of one aspect
        a = aspects[rng.integers(len(aspects))]
        points, assembly = [_in_cells(rng, a.jointspace) for _ in range(2)], a.assembly
    elif kind == 1:  # points of two aspects of the same modes, if there are any
        a = aspects[rng.integers(len(aspects))]
        twins = [b for b in aspects if (b.working, b.assembly) == (a.working, a.assembly)]
        b = twins[rng.integers(len(twins))]
        points, assembly = [_in_cells(rng, a.jointspace), _in_cells(rng, b.jointspace)], a.assembly
    elif kind == 2:  # two poses of the workspace root, one working mode
        ws = s.mechanism.spaces()["workspace"].grid(s.depth)
        working = ["++", "+-", "-+", "--"][rng.integers(4)]
        poses = [tuple(float(v) for v in ws.lo + rng.random(2) * ws.size) for _ in range(2)]
        return [Endpoint("pose", p, working) for p in poses], None
    else:  # joints anywhere on the torus
        points = [tuple(float(v) for v in grid.lo + rng.random(2) * grid.size) for _ in range(2)]
        assembly = 1 if rng.random() < 0.5 else -1
    return [Endpoint("joints", p) for p in points], "+" if assembly > 0 else "-"


def judge(s: Setting, endpoints: list[Endpoint], assembly: str | None) -> Outcome | None:
    """Locate's verdict and path's answer for one pair (None when an endpoint does not exist)."""
    m = s.mechanism
    try:
        start, end = resolve(m, endpoints, assembly, "pair")
    except (NoPath, ValueError):
        return None
    robust = getattr(m, "is_interval", False)
    verdict = decide(m.aspect_model(), s.analysis.aspects, start, end, s.depth, robust, MAX_DEPTH, offer_serial=True)
    separated = verdict.answer == NO and mode_verdict(m.aspect_model(), start, end, s.depth) is None
    cells = None if "0" in start.working + start.assembly else s.mode_cells(start.working, start.assembly)
    try:
        result = find_path(m, s.depth, start, end, max_depth=MAX_DEPTH, cells=cells, aspects=s.analysis.aspects)
        return Outcome((start, end), verdict, result, "", separated)
    except NoPath as exc:
        return Outcome((start, end), verdict, None, str(exc), separated)


def disagreement(o: Outcome) -> str | None:
    """Why locate and path disagree on this pair, or None."""
    if o.result is not None:
        return None if o.verdict.answer == YES else f"path found a motion, locate says {o.verdict.line()}"
    if o.verdict.answer == YES:
        ok = o.message.startswith(f"not decided at depth {o.verdict.depth}: {o.verdict.reason}, so a singularity-free")
        return None if ok else f"locate says yes, path says: {o.message}"
    return None if o.message == o.verdict.text() else f"locate: {o.verdict.text()} / path: {o.message}"


def recheck(m, depth: int, o: Outcome) -> bool:
    """True when path, at `depth`, finds no motion for the pair either (a separated no stays no)."""
    start, end = o.endpoints
    try:
        find_path(m, depth, start, end, max_depth=MAX_DEPTH, aspects=[])
    except NoPath:
        return True
    return False


def answers(outcomes: list[Outcome]) -> dict:
    counts = {YES: 0, NO: 0, UNDECIDED: 0}
    for o in outcomes:
        counts[o.verdict.answer] += 1
    return counts
