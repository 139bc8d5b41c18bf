"""Golden outputs: `fivebar reproduce` regenerates every committed .qt and CSV file byte for byte.

The committed files under outputs/ were written by `make reproduce` from the repository root; the
test regenerates them from another working directory, so it also checks that nothing depends on
the working directory, the time or the run. A changed tree is reported by `fivebar diff` (cells and
area), a changed CSV by a unified diff.
"""

from __future__ import annotations

import difflib
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
GOLDEN = ROOT / "outputs"
GOLDEN_FILES = sorted(
    p.relative_to(GOLDEN).as_posix() for p in GOLDEN.rglob("*") if p.suffix in (".qt", ".csv")
)


def fivebar(*args: str, cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "fivebar_cli", *args], cwd=cwd, capture_output=True, text=True)


@pytest.fixture(scope="module")
def regenerated(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("reproduce")
    elsewhere = tmp_path_factory.mktemp("another-working-directory")
    run = fivebar("reproduce", "--configs", str(ROOT / "configs"), "-o", str(out), "--no-plot", "--quiet", cwd=elsewhere)
    assert run.returncode == 0, run.stderr
    assert run.stdout == "" and run.stderr == ""  # --quiet: errors only
    return out


def test_golden_outputs_are_committed():
    assert len([f for f in GOLDEN_FILES if f.endswith(".qt")]) >= 48
    assert "kratio.csv" in GOLDEN_FILES and "rpr3-table1/synthesis.csv" in GOLDEN_FILES


def test_same_set_of_files(regenerated: Path):
    produced = sorted(p.relative_to(regenerated).as_posix() for p in regenerated.rglob("*") if p.suffix in (".qt", ".csv"))
    assert produced == GOLDEN_FILES
    assert not list(regenerated.rglob("*.tmp")) and not list(regenerated.rglob(".*.tmp"))


@pytest.mark.parametrize("name", GOLDEN_FILES)
def test_golden_file_unchanged(regenerated: Path, name: str):
    old, new = GOLDEN / name, regenerated / name
    if old.read_bytes() == new.read_bytes():
        return
    if name.endswith(".qt"):
        report = fivebar("diff", str(old), str(new), cwd=ROOT)
        pytest.fail(f"{name} changed (fivebar diff exit {report.returncode}):\n{report.stdout}{report.stderr}")
    lines = difflib.unified_diff(
        old.read_text().splitlines(), new.read_text().splitlines(), f"golden/{name}", f"new/{name}", lineterm=""
    )
    pytest.fail(f"{name} changed:\n" + "\n".join(list(lines)[:60]))
