"""Then and now on this machine: the test suite and M1's aspects of a past revision against this
checkout's, in turns, in one run (issues 21 and 22 state their time budgets as figures measured on
the machine they were filed on; a machine two times slower, or drifting by 1.5x from one minute to
the next, says nothing against such a figure, but the same work of both revisions side by side
does).

    python benchmarks/bench_then_now.py                       # suite and aspects 12,14,16, 2 turns
    python benchmarks/bench_then_now.py --rev 0f6e153 --no-suite --aspects 14 --repeat 3
    python benchmarks/bench_then_now.py --fresh --aspects '' --repeat 1     # the suites as CI runs them

The past revision (default 0f6e153: the main on which issues 18 to 23 were filed, 1201 tests) is
cloned from this repository into --work and installed in a venv of its own once (as `make install`
does; pip needs the package index), then reused. Each turn runs the past revision first, then this
checkout (with this interpreter, which is this checkout's venv under `make bench`):
- suite: `python -m pytest` as `make test` runs it (the project's own options: xdist on every
  core), seconds as pytest prints them, and the counts it prints;
- aspects D: `python -m fivebar_cli aspects configs/m1.yaml --depth D --no-plot --quiet` into a new
  folder, with FIVEBAR_JOBS=1 (the past revision has no workers), wall seconds and max RSS.
Best of the turns, and the median with 3 turns or more. With the suites, their test seconds by
file too (every test's setup, call and teardown as pytest's --durations gives them, summed over the
workers; each file's least over the turns): the files the past revision had, then against now, and
the files added since (`--files`: every file, not only the largest). Not part of `make bench`: it
clones, installs and runs two test suites (10 minutes or more on 2 cores).

`--fresh` runs the suites as CI does instead: each turn clones both revisions anew (this checkout
as committed: HEAD) and runs `make install` then `make test` in each, in this environment as it is
(PYTHONDONTWRITEBYTECODE included where it is set, as on this project's machines): the suite's
seconds as pytest prints them, and the wall seconds of install and tests together.
"""

from __future__ import annotations

import argparse
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
FILED_ON = "0f6e153"  # main when issues 18-23 were filed: their "today"
SUMMARY = re.compile(r"(?P<counts>\d+ (?:failed|passed).*?) in (?P<seconds>[\d.]+)s")
DURATIONS = ["--durations=0", "--durations-min=0"]  # every test's phases: the seconds by file
DURATION = re.compile(r"^(?P<seconds>[\d.]+)s (?:setup|call|teardown) +(?P<file>[^:\s]+)::", re.M)


def checkout(rev: str, tree: Path) -> None:
    """This repository at `rev` in `tree` (cloned there unless it already is)."""
    if not tree.exists():
        subprocess.run(["git", "clone", "--quiet", str(ROOT), str(tree)], check=True)
    subprocess.run(["git", "-C", str(tree), "checkout", "--quiet", rev], check=True)


def past_tree(rev: str, work: Path) -> Path:
    """A clone of this repository at `rev` with its own venv (made once, reused)."""
    tree = work / rev
    python = tree / ".venv" / "bin" / "python"
    if not (tree / ".venv" / ".bench-installed").exists():
        checkout(rev, tree)
        subprocess.run([sys.executable, "-m", "venv", str(tree / ".venv")], check=True)
        subprocess.run([str(python), "-m", "pip", "install", "--quiet", "-e", ".[test]"], cwd=tree, check=True)
        (tree / ".venv" / ".bench-installed").touch()
    return tree


def timed(argv: list[str], cwd: Path, env: dict, failed: tuple[int, ...] = (1,)) -> tuple[float, float, str]:
    """Run argv to its end: (wall seconds, max RSS MiB of the process, its standard output). An exit
    status in `failed` (a test failed: pytest's 1, make's 2) still counts; any other is an error."""
    with tempfile.TemporaryFile() as out:
        t0 = time.perf_counter()
        child = subprocess.Popen(argv, cwd=cwd, env=env, stdout=out, stderr=subprocess.STDOUT)
        _, status, usage = os.wait4(child.pid, 0)
        seconds = time.perf_counter() - t0
        out.seek(0)
        text = out.read().decode(errors="replace")
    code = os.waitstatus_to_exitcode(status)
    if code != 0 and code not in failed:
        raise SystemExit(f"{' '.join(argv)} exited {code} in {cwd}:\n{text[-2000:]}")
    return seconds, usage.ru_maxrss / 1024, text


def suite(python: str, tree: Path) -> tuple[float, str, dict]:
    """The test suite's seconds and counts, as pytest prints them, and its test seconds by file."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    _, _, text = timed([python, "-m", "pytest", "-p", "no:cacheprovider", *DURATIONS], tree, env)
    return (*summary(text, tree), by_file(text))


def by_file(text: str) -> dict[str, float]:
    """Test seconds by file in pytest's --durations report: setup, call and teardown summed."""
    files: dict[str, float] = {}
    for m in DURATION.finditer(text):
        files[m["file"]] = files.get(m["file"], 0.0) + float(m["seconds"])
    return files


def summary(text: str, tree: Path) -> tuple[float, str]:
    """The seconds and counts of pytest's closing line in `text`."""
    found = [m for line in text.splitlines()[-5:] for m in SUMMARY.findall(line)]
    if not found:
        raise SystemExit(f"no pytest summary in {tree}:\n{text[-2000:]}")
    counts, seconds = found[-1]
    return float(seconds), counts


def fresh_suite(rev: str) -> tuple[float, float, str, dict]:
    """CI's run of `rev`: a new clone, `make install`, `make test`, in this environment as it is
    (pytest's --durations added): (the suite's seconds as pytest prints them, wall seconds of
    install and tests, the counts, the test seconds by file)."""
    with tempfile.TemporaryDirectory(prefix="fivebar-fresh-") as work:
        tree, env = Path(work) / "clone", dict(os.environ)
        checkout(rev, tree)
        install, _, _ = timed(["make", "install"], tree, env, failed=())
        env["PYTEST_ADDOPTS"] = " ".join([env.get("PYTEST_ADDOPTS", ""), *DURATIONS]).strip()
        tests, _, text = timed(["make", "test"], tree, env, failed=(2,))
        seconds, counts = summary(text, tree)
    return seconds, install + tests, counts, by_file(text)


def aspects(python: str, tree: Path, depth: int) -> tuple[float, float]:
    with tempfile.TemporaryDirectory() as out:
        env = dict(os.environ, FIVEBAR_JOBS="1")
        seconds, rss, _ = timed([python, "-m", "fivebar_cli", "aspects", "configs/m1.yaml", "--depth", str(depth),
                                 "--no-plot", "--quiet", "-o", out], tree, env)
    return seconds, rss


def main() -> int:
    parser = argparse.ArgumentParser(description="A past revision's test suite and M1 aspects against this "
                                                 "checkout's, in turns, on this machine.")
    parser.add_argument("--rev", default=FILED_ON, help=f"the past revision (default {FILED_ON})")
    parser.add_argument("--aspects", default="12,14,16", help="M1 aspects depths ('' for none)")
    parser.add_argument("--no-suite", action="store_true", help="leave the test suites out")
    parser.add_argument("--fresh", action="store_true",
                        help="the suites as CI runs them: new clones, make install, make test (HEAD for now)")
    parser.add_argument("--files", action="store_true", help="the suites' test seconds of every file")
    parser.add_argument("--repeat", type=int, default=2, help="turns of each pair of runs")
    parser.add_argument("--work", type=Path, default=Path(tempfile.gettempdir()) / "fivebar-then",
                        help="where the past revision is cloned and installed")
    args = parser.parse_args()
    depths = [int(d) for d in args.aspects.split(",") if d.strip()]
    # the past revision's own venv serves its aspects and its warm suite (--fresh installs clones of its own)
    then = past_tree(args.rev, args.work) if depths or not (args.fresh or args.no_suite) else None
    now_rev = subprocess.run(["git", "-C", str(ROOT), "log", "-1", "--format=%h"], capture_output=True,
                             text=True).stdout.strip() or "this checkout"
    trees = {"then": (str(then / ".venv" / "bin" / "python"), then), "now": (sys.executable, ROOT)} if then else {}
    print(f"then: {args.rev} ({then or 'fresh clones'}), now: {now_rev} ({ROOT}); "
          f"load average {os.getloadavg()[0]:.1f}", flush=True)

    rows: dict = {}  # (what, then or now): [(seconds, max RSS MiB or None)] of each turn
    counts: dict = {}  # then or now: the suite's counts, as pytest printed them
    files: dict = {"then": {}, "now": {}}  # then or now: test seconds by file, least over the turns
    for _ in range(args.repeat):
        for depth in depths:
            for when, (python, tree) in trees.items():
                rows.setdefault((f"aspects d{depth}", when), []).append(aspects(python, tree, depth))
        if args.fresh and not args.no_suite:
            for when, rev in (("then", args.rev), ("now", "HEAD")):
                seconds, wall, tally, by = fresh_suite(rev)
                rows.setdefault(("fresh suite", when), []).append((seconds, None))
                rows.setdefault(("+ install", when), []).append((wall, None))
                counts[when] = tally
                least(files[when], by)
        elif not args.no_suite:
            for when, (python, tree) in trees.items():
                seconds, tally, by = suite(python, tree)
                rows.setdefault(("suite", when), []).append((seconds, None))
                counts[when] = tally
                least(files[when], by)

    medians = args.repeat >= 3
    columns = ["then best", "now best", "now/then"] + (["then median", "now median", "now/then"] if medians else [])
    print(f"{'':12s}" + "".join(f"{c:>12s}" for c in columns) + "   max RSS then -> now")
    suites = [] if args.no_suite else ["fresh suite", "+ install"] if args.fresh else ["suite"]
    for what in [f"aspects d{d}" for d in depths] + suites:
        then_runs, now_runs = rows[(what, "then")], rows[(what, "now")]
        t, n = [s for s, _ in then_runs], [s for s, _ in now_runs]
        cells = [f"{min(t):.2f} s", f"{min(n):.2f} s", f"{min(n) / min(t):.2f}x"]
        if medians:
            cells += [f"{statistics.median(t):.2f} s", f"{statistics.median(n):.2f} s",
                      f"{statistics.median(n) / statistics.median(t):.2f}x"]
        rss = "" if then_runs[0][1] is None else (f"   {max(r for _, r in then_runs):.0f} -> "
                                                 f"{max(r for _, r in now_runs):.0f} MiB")
        print(f"{what:12s}" + "".join(f"{c:>12s}" for c in cells) + rss)
    if not args.no_suite:
        print(f"tests: then {counts['then']}; now {counts['now']}")
        print_files(files["then"], files["now"], every=args.files)
    return 0


def least(into: dict[str, float], turn: dict[str, float]) -> None:
    """Each file's least test seconds so far."""
    for name, seconds in turn.items():
        into[name] = min(into.get(name, seconds), seconds)


def print_files(then: dict[str, float], now: dict[str, float], every: bool, largest: int = 8) -> None:
    """Test seconds by file: the files of then (then against now), those added since."""
    kept, added = sorted(f for f in now if f in then), sorted(f for f in now if f not in then)
    t, n, a = (sum(d[f] for f in fs) for d, fs in ((then, kept), (now, kept), (now, added)))
    gone = len(then) - len(kept)
    print("test seconds by file (setup + call + teardown, summed over the workers, least over the turns; "
          "pytest leaves out phases under 5 ms, and files with none):")
    print(f"  the {len(kept)} files of then: {t:.1f} s then, {n:.1f} s now ({n / t if t else 0:.2f}x); "
          f"the {len(added)} files added since: {a:.1f} s"
          + (f"; {gone} files gone: {sum(then.values()) - t:.1f} s then" if gone else ""))
    for name in sorted(now, key=lambda f: -now[f])[:None if every else largest]:
        print(f"  {name:44s} {f'{then[name]:.1f} s' if name in then else 'new':>9s} -> {now[name]:6.1f} s")


if __name__ == "__main__":
    sys.exit(main())
