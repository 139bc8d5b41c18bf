"""`locate` against `path` on random pairs of configurations (issue 20): 200 pairs per mechanism
over depths 4 to 12, for M1, M2, M1 with a tolerance of 0.02 (robust aspects) and random
five-bars (L0 in [0.2, 2], the other lengths in [0.5, 2]; a few designs, each pair drawing one).

Each pair (tests/locate_pairs.py: two points of one aspect's cells, of two aspects of the same
modes, two poses, or two joint values anywhere) is judged by `locate.decide` with the aspects at
its depth and by `paths.find_path` with the joint-space paving of its modes. Printed per mechanism:
the answers (yes, no from the modes, no from two certified aspects, not decided), the motions path
certified, the pairs where locate proves a motion that path's cells at that depth do not show,
disagreements (must be 0: a motion where locate says anything but yes, or a failure of path whose
reason is not locate's verdict), every "no" from two aspects re-run with path at depth 14 (it must
find no motion), and every pair decided again at depth 12 (a yes at one depth and a no at the
other would be a contradiction: must be 0).

    python benchmarks/bench_locate_path.py [--pairs 200] [--seed 20]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from locate_pairs import (  # noqa: E402
    M1, M2, ROBUST_M1, Setting, disagreement, judge, random_five_bars, random_pair, recheck,
)

from fivebar_cli.analyses.locate import NO, UNDECIDED, YES, decide  # noqa: E402

DEPTHS = range(4, 13)
DEEPEST = 12
RECHECK = 14


def family(label: str, designs: list, pairs: int, rng) -> list:
    """One row of the table for `pairs` pairs over the designs and DEPTHS."""
    t0 = time.perf_counter()
    settings: dict = {}

    def setting(m, depth):
        if (id(m), depth) not in settings:
            settings[(id(m), depth)] = Setting.of(m, depth)
        return settings[(id(m), depth)]

    outcomes = []
    while len(outcomes) < pairs:
        m = designs[rng.integers(len(designs))]
        s = setting(m, int(rng.choice(DEPTHS)))
        o = judge(s, *random_pair(rng, s))
        if o is not None:
            outcomes.append((s, o))
    bad = [disagreement(o) for _, o in outcomes]
    separated = [(s, o) for s, o in outcomes if o.separated]
    still_apart = sum(recheck(s.mechanism, RECHECK, o) for s, o in separated)
    contradictions = 0
    for s, o in outcomes:
        deep = setting(s.mechanism, DEEPEST)
        robust = getattr(s.mechanism, "is_interval", False)
        again = decide(s.mechanism.aspect_model(), deep.analysis.aspects, *o.endpoints, DEEPEST, robust).answer
        contradictions += {o.verdict.answer, again} == {YES, NO}
    answers = [o.verdict.answer for _, o in outcomes]
    no_modes = sum(a == NO and not o.separated for a, (_, o) in zip(answers, outcomes))
    return [label, len(outcomes), answers.count(YES), no_modes, len(separated), answers.count(UNDECIDED),
            sum(o.result is not None for _, o in outcomes),
            sum(o.result is None and o.verdict.answer == YES for _, o in outcomes),
            sum(b is not None for b in bad), f"{still_apart}/{len(separated)}", contradictions,
            time.perf_counter() - t0], [b for b in bad if b]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--pairs", type=int, default=200)
    parser.add_argument("--seed", type=int, default=20)
    args = parser.parse_args()
    rng = np.random.default_rng(args.seed)
    print(f"{'mechanism':26s} {'pairs':>5s} {'yes':>4s} {'no:modes':>8s} {'no:aspects':>10s} {'undecided':>9s} "
          f"{'motions':>7s} {'yes,no chain':>12s} {'disagree':>8s} {f'no at d{RECHECK}':>9s} {'contradict':>10s} "
          f"{'seconds':>8s}")
    families = (("M1", [M1]), ("M2", [M2]), ("M1, tolerance 0.02 (robust)", [ROBUST_M1]),
                ("random five-bars (10)", random_five_bars(10, args.seed)))
    for label, designs in families:
        row, bad = family(label, designs, args.pairs, rng)
        print(f"{row[0]:26s} {row[1]:5d} {row[2]:4d} {row[3]:8d} {row[4]:10d} {row[5]:9d} {row[6]:7d} {row[7]:12d} "
              f"{row[8]:8d} {row[9]:>9s} {row[10]:10d} {row[11]:8.1f}", flush=True)
        for line in bad:
            print(f"    disagreement: {line}")


if __name__ == "__main__":
    main()
