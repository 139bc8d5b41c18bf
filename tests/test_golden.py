"""Golden outputs: `fivebar reproduce` regenerates every .qt and CSV file of tests/golden/.

The golden files were written by `make golden` (`fivebar reproduce -o tests/golden --no-plot`);
no command writes there by default, so running the documented examples cannot change them. The
test regenerates them in-process from another working directory (a copy of the repository), with
the example of `fivebar reproduce --help` as pasted, so it also checks that nothing depends on the
working directory, the time or the run.

Trees must be byte-identical. CSV cells must be identical too, with one allowance: numbers may
differ by a relative 1e-6 where the machine's libm differs (numpy's sin/cos take other SIMD paths
on AVX-512 and AVX2 CPUs and differ in the last ulp). Only the 3-RPR optimisers feel it: the
argmin of a flat objective is determined to about sqrt(machine epsilon), so rho_min_opt and what
follows from it move by up to 1.3e-7 relative between an Intel AVX-512 and an AMD AVX2 machine.
Every other column matches to the last digit; a real change moves numbers far more than 1e-6.
"""

from __future__ import annotations

import csv
import difflib
import math
from pathlib import Path

import pytest
from examples import ELSEWHERE, Command, run, sandbox

from fivebar_cli.analyses.compare import compare
from fivebar_cli.io.qtfile import read_qt

ROOT = Path(__file__).resolve().parents[1]
GOLDEN = ROOT / "tests" / "golden"
GOLDEN_FILES = sorted(p.relative_to(GOLDEN).as_posix() for p in GOLDEN.rglob("*") if p.suffix in (".qt", ".csv"))
RTOL = 1e-6
REPRODUCE = next(line for line, test in ELSEWHERE.items() if test == "tests/test_golden.py")


@pytest.fixture(scope="module")
def regenerated(tmp_path_factory) -> Path:
    """The example of `fivebar reproduce --help`, run as pasted in a copy of the repository (another
    working directory than the repository's)."""
    copy = sandbox(tmp_path_factory.mktemp("reproduce"))
    before = sorted(p.name for p in copy.iterdir())
    result = run(Command("`fivebar reproduce --help`", REPRODUCE), copy)
    assert result.status == 0 and result.stderr == "", result.stderr
    assert sorted(p.name for p in copy.iterdir()) == sorted([*before, "out"])  # nothing written elsewhere
    return copy / "out" / "check"


def test_same_set_of_files(regenerated: Path):
    produced = sorted(p.relative_to(regenerated).as_posix() for p in regenerated.rglob("*") if p.suffix in (".qt", ".csv"))
    assert produced == GOLDEN_FILES
    assert not list(regenerated.rglob("*.tmp")) and not list(regenerated.rglob(".*.tmp"))


def _numbers_differ(old: str, new: str) -> bool:
    try:
        a, b = float(old), float(new)
    except ValueError:
        return old != new
    return not math.isclose(a, b, rel_tol=RTOL, abs_tol=1e-12)


@pytest.mark.parametrize("name", GOLDEN_FILES)
def test_golden_file_unchanged(regenerated: Path, name: str):
    old, new = GOLDEN / name, regenerated / name
    if old.read_bytes() == new.read_bytes():
        return
    if name.endswith(".qt"):
        result = compare(read_qt(old), read_qt(new))
        pytest.fail(f"{name} changed:\n" + "\n".join(result.report(f"golden/{name}", f"new/{name}")))
    a, b = (list(csv.reader(path.read_text().splitlines())) for path in (old, new))
    bad = [] if len(a) == len(b) and a[0] == b[0] else [(1, "header or row count")]
    for line, (ra, rb) in enumerate(zip(a[1:], b[1:]), start=2):
        if len(ra) != len(rb):
            bad.append((line, "cell count"))
        bad += [(line, column) for column, x, y in zip(a[0], ra, rb) if _numbers_differ(x, y)]
    if bad:
        lines = difflib.unified_diff(old.read_text().splitlines(), new.read_text().splitlines(),
                                     f"golden/{name}", f"new/{name}", lineterm="")
        pytest.fail(f"{name} changed beyond rtol {RTOL} (line, column: {bad[:5]}):\n" + "\n".join(list(lines)[:60]))
